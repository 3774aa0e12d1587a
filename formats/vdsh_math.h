/*
 * vdsh_math.h - internal (not installed; formats/CMakeLists.txt lists the
 * public headers): the small vector and matrix helpers that the formats
 * library, the runtime, the baker and the tools each had a copy of. All
 * static inline; C and C++.
 *
 * Each helper does the exact operations, in the exact order, of the
 * copies it replaced, so that every result is bit for bit what it was
 * (bakes, frames and renders depend on them). Normalising comes in three
 * kinds on purpose, because their results differ: in float (the camera
 * and the GL view matrix), in double rounded once to float (mesh normals),
 * and the same keeping a vector that is already unit to float precision
 * (normals given by a file, so that writing and reading back a mesh
 * reproduces them).
 */
#ifndef VDSH_MATH_H
#define VDSH_MATH_H

#include <float.h>
#include <math.h>
#include <string.h>

static inline float vdsh_dot3f(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline double vdsh_dot3d(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void vdsh_cross3f(float o[3], const float a[3], const float b[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

/* v scaled to unit length in float; unchanged when it has no length. */
static inline void vdsh_normalize3f(float v[3])
{
    float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0.0f)
        v[0] /= l, v[1] /= l, v[2] /= l;
}

/* t scaled to unit length in double, then rounded to float; (0,0,0) when
 * its length is 0 or not finite. */
static inline void vdsh_unit3d_to_f(const double t[3], float out[3])
{
    double l = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    for (int k = 0; k < 3; k++)
        out[k] = l > 0.0 && isfinite(l) ? (float)(t[k] / l) : 0.0f;
}

/* n as vdsh_unit3d_to_f scales it, in place. */
static inline void vdsh_normalize3f_in_double(float n[3])
{
    const double t[3] = {n[0], n[1], n[2]};
    vdsh_unit3d_to_f(t, n);
}

/* n as vdsh_normalize3f_in_double scales it, unless it is already unit to
 * float precision (|len - 1| <= 4 FLT_EPSILON): then left as it is. */
static inline void vdsh_unit3f_keep(float n[3])
{
    const double t[3] = {n[0], n[1], n[2]};
    double l = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    if (fabs(l - 1.0) <= 4.0 * FLT_EPSILON)
        return;
    vdsh_unit3d_to_f(t, n);
}

/* The right-handed view basis of a camera at `eye` looking at `target`:
 * f forward, s right, u up (all unit unless degenerate). */
static inline void vdsh_look_at(const float eye[3], const float target[3], const float up[3],
                                float s[3], float u[3], float f[3])
{
    f[0] = target[0] - eye[0];
    f[1] = target[1] - eye[1];
    f[2] = target[2] - eye[2];
    vdsh_normalize3f(f);
    vdsh_cross3f(s, f, up);
    vdsh_normalize3f(s);
    vdsh_cross3f(u, s, f);
}

/* The GL view matrix (column-major) of that basis and eye. */
static inline void vdsh_view_matrix(const float s[3], const float u[3], const float f[3],
                                    const float e[3], float out[16])
{
    const float m[16] = {s[0],
                         u[0],
                         -f[0],
                         0.0f,
                         s[1],
                         u[1],
                         -f[1],
                         0.0f,
                         s[2],
                         u[2],
                         -f[2],
                         0.0f,
                         -(s[0] * e[0] + s[1] * e[1] + s[2] * e[2]),
                         -(u[0] * e[0] + u[1] * e[1] + u[2] * e[2]),
                         f[0] * e[0] + f[1] * e[1] + f[2] * e[2],
                         1.0f};
    memcpy(out, m, sizeof m);
}

/* The GL projection matrix (column-major) for t = 1 / tan(fov_y / 2). */
static inline void vdsh_perspective(float t, float aspect, float znear, float zfar, float out[16])
{
    memset(out, 0, 16 * sizeof(float));
    out[0] = t / aspect;
    out[5] = t;
    out[10] = (zfar + znear) / (znear - zfar);
    out[11] = -1.0f;
    out[14] = 2.0f * zfar * znear / (znear - zfar);
}

/* c = a b for column-major 4 x 4 matrices in double; c may be a or b. */
static inline void vdsh_mat4d_mul(const double *a, const double *b, double *c)
{
    double t[16];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double s = 0;
            for (int k = 0; k < 4; k++)
                s += a[k * 4 + i] * b[j * 4 + k];
            t[j * 4 + i] = s;
        }
    memcpy(c, t, sizeof t);
}

/* glTF's node matrix T R S (column-major) from its translation t, rotation
 * q (x, y, z, w) and scale s, each NULL when the node has none. */
static inline void vdsh_mat4d_trs(const double *t, const double *q, const double *s, double m[16])
{
    static const double id[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    double mt[16], mr[16], ms[16];
    memcpy(mt, id, sizeof id), memcpy(mr, id, sizeof id), memcpy(ms, id, sizeof id);
    if (t)
        mt[12] = t[0], mt[13] = t[1], mt[14] = t[2];
    if (q) {
        const double x = q[0], y = q[1], z = q[2], w = q[3];
        const double r[16] = {1 - 2 * (y * y + z * z),
                              2 * (x * y + z * w),
                              2 * (x * z - y * w),
                              0,
                              2 * (x * y - z * w),
                              1 - 2 * (x * x + z * z),
                              2 * (y * z + x * w),
                              0,
                              2 * (x * z + y * w),
                              2 * (y * z - x * w),
                              1 - 2 * (x * x + y * y),
                              0,
                              0,
                              0,
                              0,
                              1};
        memcpy(mr, r, sizeof r);
    }
    if (s)
        ms[0] = s[0], ms[5] = s[1], ms[10] = s[2];
    vdsh_mat4d_mul(mr, ms, ms);
    vdsh_mat4d_mul(mt, ms, m);
}

#endif /* VDSH_MATH_H */
