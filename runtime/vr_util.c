/*
 * vr_util.c - result strings, error messages, mode names and the little
 * matrix arithmetic the runtime needs.
 */
#include "vr_internal.h"

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

int vr_gl_has(int major, int minor, const char *const *exts, int n)
{
    GLint ma = 0, mi = 0, count = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &ma);
    glGetIntegerv(GL_MINOR_VERSION, &mi);
    if (ma > major || (ma == major && mi >= minor))
        return 1;
    glGetIntegerv(GL_NUM_EXTENSIONS, &count);
    int found = 0;
    for (int k = 0; k < n; k++)
        for (GLint i = 0; i < count; i++) {
            const char *e = (const char *)glGetStringi(GL_EXTENSIONS, (GLuint)i);
            if (e && !strcmp(e, exts[k])) {
                found++;
                break;
            }
        }
    return found == n;
}

const char *vr_gl_renderer(void)
{
    const GLubyte *s = glGetString(GL_RENDERER);
    return s ? (const char *)s : "(no GL context)";
}

/* ------------------------------------------------------------------ */

/* The runtime's one list of its modes (vr_mode order): name (the
 * viewer's --mode spelling), label, and the VDSH order drawn (0: none or
 * any, from the stream). */
static const struct {
    const char *name, *label;
    int order;
} modes[VR_MODE_COUNT_] = {
    {"default", "the scene's default (VDSH order 5, cubemaps where it has them)", 0},
    {"none", "no shadows", 0},
    {"cube", "cube shadow map", 0},
    {"vdsh2", "VDSH order 2 (4 coeff.)", 2},
    {"vdsh3", "VDSH order 3 (9 coeff.)", 3},
    {"vdsh5", "VDSH order 5 (25 coeff., cubemaps)", 5},
    {"vdsh5poly", "VDSH order 5 (25 coeff., polynomials)", 5},
    {"buffer", "VDSH from a buffer (any order, per-vertex distance)", 0},
    {"sdf", "distance-field shadows (sphere trace)", 0}};

const char *vr_mode_name(vr_mode m)
{
    return (unsigned)m < VR_MODE_COUNT_ ? modes[m].name : "?";
}

const char *vr_mode_label(vr_mode m)
{
    return (unsigned)m < VR_MODE_COUNT_ ? modes[m].label : "?";
}

int vr_mode_from_name(const char *name, vr_mode *out)
{
    if (!name)
        return -1;
    for (int m = 1; m < VR_MODE_COUNT_; m++)
        if (strcmp(name, modes[m].name) == 0) {
            *out = (vr_mode)m;
            return 0;
        }
    return -1;
}

int vr_mode_order(vr_mode m)
{
    return (unsigned)m < VR_MODE_COUNT_ ? modes[m].order : 0;
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
    case 1: return 1; /* never drawn; uploaded as one float */
    case 2: return 1;
    case 3: return 3;
    case 4: return 3; /* bands 0-2 only: no mode draws order 4 */
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

void vr_mat4_ortho(float out[16], float half_w, float half_h, float znear, float zfar)
{
    memset(out, 0, 16 * sizeof(float));
    out[0] = 1.0f / half_w;
    out[5] = 1.0f / half_h;
    out[10] = -2.0f / (zfar - znear);
    out[14] = -(zfar + znear) / (zfar - znear);
    out[15] = 1.0f;
}
