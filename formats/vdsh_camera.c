/* The pinhole camera: vdsh_camera.h says what and why. */
#include "vdsh_camera.h"

#include <math.h>
#include <string.h>

static void normalize3(float v[3])
{
    float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0.0f)
        v[0] /= l, v[1] /= l, v[2] /= l;
}

static void cross3(float o[3], const float a[3], const float b[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

void vdsh_camera_basis(const vdsh_camera *c, float s[3], float u[3], float f[3])
{
    float up[3] = {c->up[0], c->up[1], c->up[2]};
    if (!up[0] && !up[1] && !up[2])
        up[1] = 1.0f;
    f[0] = c->target[0] - c->eye[0];
    f[1] = c->target[1] - c->eye[1];
    f[2] = c->target[2] - c->eye[2];
    normalize3(f);
    cross3(s, f, up);
    normalize3(s);
    cross3(u, s, f);
}

float vdsh_camera_fov(const vdsh_camera *c)
{
    return c->fov_y > 0.0f ? c->fov_y : 60.0f;
}

void vdsh_camera_ray(const vdsh_camera *c, int width, int height, int x, int y,
                     float org[3], float dir[3])
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
    normalize3(dir);
}

void vdsh_camera_view(const vdsh_camera *c, float out[16])
{
    float s[3], u[3], f[3];
    vdsh_camera_basis(c, s, u, f);
    const float *e = c->eye;
    const float m[16] = {
        s[0], u[0], -f[0], 0.0f,
        s[1], u[1], -f[1], 0.0f,
        s[2], u[2], -f[2], 0.0f,
        -(s[0] * e[0] + s[1] * e[1] + s[2] * e[2]),
        -(u[0] * e[0] + u[1] * e[1] + u[2] * e[2]),
        f[0] * e[0] + f[1] * e[1] + f[2] * e[2], 1.0f};
    memcpy(out, m, sizeof m);
}

void vdsh_camera_projection(const vdsh_camera *c, float aspect, float znear, float zfar,
                            float out[16])
{
    float t = 1.0f / tanf(0.5f * vdsh_camera_fov(c) * 3.14159265358979f / 180.0f);
    memset(out, 0, 16 * sizeof(float));
    out[0] = t / aspect;
    out[5] = t;
    out[10] = (zfar + znear) / (znear - zfar);
    out[11] = -1.0f;
    out[14] = 2.0f * zfar * znear / (znear - zfar);
}
