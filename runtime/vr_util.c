/*
 * vr_util.c - result strings, error messages, mode names and the little
 * matrix arithmetic the runtime needs.
 */
#include "vr_internal.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

const char *vr_result_str(vr_result r)
{
    switch (r) {
    case VR_OK: return "success";
    case VR_ERR_IO: return "I/O error";
    case VR_ERR_FORMAT: return "corrupt or unsupported file";
    case VR_ERR_MISSING: return "missing stream or file";
    case VR_ERR_GL: return "GL error";
    case VR_ERR_SHADER: return "shader compile or link error";
    case VR_ERR_OUT_OF_MEMORY: return "out of memory";
    case VR_ERR_ARGUMENT: return "invalid argument";
    }
    return "unknown result";
}

vr_result vr_fail(vr_error *err, vr_result r, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
    }
    return r;
}

static const char *gl_error_name(GLenum e)
{
    switch (e) {
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    default: return "GL error";
    }
}

vr_result vr_check_gl(vr_error *err, const char *what)
{
    GLenum first = glGetError();
    if (first == GL_NO_ERROR)
        return VR_OK;
    /* glGetError reports one flag per call; clear the rest (bounded, a
     * lost context can keep returning errors). */
    for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; i++)
        ;
    return vr_fail(err, first == GL_OUT_OF_MEMORY ? VR_ERR_OUT_OF_MEMORY : VR_ERR_GL,
                   "%s: %s (0x%04x)", what, gl_error_name(first), (unsigned)first);
}

const char *vr_gl_renderer(void)
{
    const GLubyte *s = glGetString(GL_RENDERER);
    return s ? (const char *)s : "(no GL context)";
}

/* ------------------------------------------------------------------ */

static const char *const mode_names[VR_MODE_COUNT_] = {
    "default", "none", "cube", "vdsh2", "vdsh3", "vdsh5", "vdsh5poly", "buffer", "sdf"};

static const char *const mode_labels[VR_MODE_COUNT_] = {
    "the scene's default (VDSH order 5, cubemaps where it has them)",
    "no shadows",
    "cube shadow map",
    "VDSH order 2 (4 coeff.)",
    "VDSH order 3 (9 coeff.)",
    "VDSH order 5 (25 coeff., cubemaps)",
    "VDSH order 5 (25 coeff., polynomials)",
    "VDSH from a buffer (any order, per-vertex distance)",
    "distance-field shadows (sphere trace)"};

const char *vr_mode_name(vr_mode m)
{
    return (unsigned)m < VR_MODE_COUNT_ ? mode_names[m] : "?";
}

const char *vr_mode_label(vr_mode m)
{
    return (unsigned)m < VR_MODE_COUNT_ ? mode_labels[m] : "?";
}

int vr_mode_from_name(const char *name, vr_mode *out)
{
    if (!name)
        return -1;
    for (int m = 1; m < VR_MODE_COUNT_; m++)
        if (strcmp(name, mode_names[m]) == 0) {
            *out = (vr_mode)m;
            return 0;
        }
    return -1;
}

int vr_mode_order(vr_mode m)
{
    switch (m) {
    case VR_MODE_VDSH2: return 2;
    case VR_MODE_VDSH3: return 3;
    case VR_MODE_VDSH5:
    case VR_MODE_VDSH5_POLY: return 5;
    default: return 0;
    }
}

int vr_mode_interp(vr_mode m, uint32_t quantity)
{
    if (m == VR_MODE_VDSH_BUFFER)
        return VDSH_INTERP_DISTANCE;
    int order = vr_mode_order(m);
    return order ? (int)vdsh_runtime_interp((uint32_t)order, quantity) : -1;
}

/* ------------------------------------------------------------------ */

const int vr_coef_first[VR_COEF_ATTRIBS] = {0, 4, 8, 9, 13, 17, 21};
const int vr_coef_size[VR_COEF_ATTRIBS] = {4, 4, 1, 4, 4, 4, 4};

int vr_coef_attrib_count(int order)
{
    switch (order) {
    case 1: return 1;   /* never drawn; uploaded as one float */
    case 2: return 1;
    case 3: return 3;
    case 4: return 3;   /* bands 0-2 only: no mode draws order 4 */
    default: return VR_COEF_ATTRIBS;
    }
}

/* ------------------------------------------------------------------ */

void vr_mat4_mul(float out[16], const float a[16], const float b[16])
{
    float r[16];
    for (int c = 0; c < 4; c++)
        for (int row = 0; row < 4; row++) {
            float s = 0.0f;
            for (int k = 0; k < 4; k++)
                s += a[k * 4 + row] * b[c * 4 + k];
            r[c * 4 + row] = s;
        }
    memcpy(out, r, sizeof r);
}

static void normalize3(float v[3])
{
    float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0.0f) {
        v[0] /= l;
        v[1] /= l;
        v[2] /= l;
    }
}

static void cross3(float o[3], const float a[3], const float b[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

void vr_mat4_look_at(float out[16], const float eye[3], const float target[3],
                     const float up[3])
{
    float f[3] = {target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]};
    normalize3(f);
    float s[3], u[3];
    cross3(s, f, up);
    normalize3(s);
    cross3(u, s, f);
    const float m[16] = {
        s[0], u[0], -f[0], 0.0f,
        s[1], u[1], -f[1], 0.0f,
        s[2], u[2], -f[2], 0.0f,
        -(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]),
        -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]),
        f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2], 1.0f};
    memcpy(out, m, sizeof m);
}

void vr_mat4_perspective(float out[16], float fov_y_rad, float aspect,
                         float znear, float zfar)
{
    float t = 1.0f / tanf(0.5f * fov_y_rad);
    memset(out, 0, 16 * sizeof(float));
    out[0] = t / aspect;
    out[5] = t;
    out[10] = (zfar + znear) / (znear - zfar);
    out[11] = -1.0f;
    out[14] = 2.0f * zfar * znear / (znear - zfar);
}

void vr_mat4_ortho(float out[16], float half_w, float half_h, float znear,
                   float zfar)
{
    memset(out, 0, 16 * sizeof(float));
    out[0] = 1.0f / half_w;
    out[5] = 1.0f / half_h;
    out[10] = -2.0f / (zfar - znear);
    out[14] = -(zfar + znear) / (zfar - znear);
    out[15] = 1.0f;
}
