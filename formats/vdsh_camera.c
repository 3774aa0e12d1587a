/* The pinhole camera: vdsh_camera.h says what and why. */
#include "vdsh_camera.h"
#include "vdsh_math.h"

#include <math.h>
#include <string.h>

void vdsh_camera_basis(const vdsh_camera *c, float s[3], float u[3], float f[3])
{
    float up[3] = {c->up[0], c->up[1], c->up[2]};
    if (!up[0] && !up[1] && !up[2])
        up[1] = 1.0f;
    vdsh_look_at(c->eye, c->target, up, s, u, f);
}

int vdsh_camera_degenerate(const vdsh_camera *c)
{
    double f[3], u[3] = {c->up[0], c->up[1], c->up[2]};
    if (!u[0] && !u[1] && !u[2])
        u[1] = 1.0;
    for (int i = 0; i < 3; i++)
        f[i] = (double)c->target[i] - (double)c->eye[i];
    const double x[3] = {f[1] * u[2] - f[2] * u[1], f[2] * u[0] - f[0] * u[2],
                         f[0] * u[1] - f[1] * u[0]};
    const double ff = f[0] * f[0] + f[1] * f[1] + f[2] * f[2];
    const double uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    const double xx = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
    /* sin of the angle between f and up below 1e-6, or no f at all */
    return !(ff > 0.0) || !(xx > 1e-12 * ff * uu);
}

float vdsh_camera_fov(const vdsh_camera *c)
{
    return c->fov_y > 0.0f ? c->fov_y : 60.0f;
}

void vdsh_camera_ray(const vdsh_camera *c, int width, int height, int x, int y, float org[3],
                     float dir[3])
{
    float s[3], u[3], f[3];
    vdsh_camera_basis(c, s, u, f);
    float t = tanf(0.5f * vdsh_camera_fov(c) * 3.14159265358979f / 180.0f);
    float aspect = (float)width / (float)height;
    float nx = (2.0f * ((float)x + 0.5f) / (float)width - 1.0f) * t * aspect;
    float ny = (1.0f - 2.0f * ((float)y + 0.5f) / (float)height) * t;
    for (int i = 0; i < 3; i++) {
        org[i] = c->eye[i];
        dir[i] = f[i] + nx * s[i] + ny * u[i];
    }
    vdsh_normalize3f(dir);
}

void vdsh_camera_view(const vdsh_camera *c, float out[16])
{
    float s[3], u[3], f[3];
    vdsh_camera_basis(c, s, u, f);
    vdsh_view_matrix(s, u, f, c->eye, out);
}

void vdsh_camera_projection(const vdsh_camera *c, float aspect, float znear, float zfar,
                            float out[16])
{
    float t = 1.0f / tanf(0.5f * vdsh_camera_fov(c) * 3.14159265358979f / 180.0f);
    vdsh_perspective(t, aspect, znear, zfar, out);
}
