/*
 * vdsh_view_core.c - what every mode of vdsh-view draws with: the scene
 * defaults (lights, camera, descriptor), the session and PNG output
 * (vdsh_view.h).
 */
#include "vdsh_view.h"

#include "vdsh_output.h"
#include "vdsh_scene_view.h"

#include <stb/stb_image_write.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Row order is the order --bench times them in and the window's M key
 * steps through; --views renders its defaults in this order too. */
enum {
    OPT = VV_MODE_OPTION,
    FRM = VV_MODE_FRAMES,
    DEF = VV_MODE_FRAMES_DEFAULT,
    BEN = VV_MODE_BENCH,
    LOG = VV_MODE_BENCH_LOG
};
/* bufN: the order-N stream from its buffer; --bench times orders 5 and
 * up (on log-distance scenes, beside vdsh5's attributes). */
#define BUF(n, flags)                                                                              \
    {                                                                                              \
        "buf" #n, "buf" #n, VR_MODE_VDSH_BUFFER, 0, n, OPT | FRM | (flags), 0, 0                   \
    }

const vv_mode vv_modes[] = {
    /* name        json        mode                 pcf stream flags            grid key */
    {"none", "none", VR_MODE_NONE, 0, 0, OPT | FRM | BEN, 1, '1'},
    {"cube", "cube", VR_MODE_CUBE, 0, 0, OPT | FRM | DEF | BEN, 2, '2'},
    {"cube-pcf", "cube_pcf", VR_MODE_CUBE, 1, 0, FRM | DEF | BEN, 0, 0},
    {"vdsh2", "vdsh2", VR_MODE_VDSH2, 0, 0, OPT | FRM | DEF | BEN, 5, '3'},
    {"vdsh3", "vdsh3", VR_MODE_VDSH3, 0, 0, OPT | FRM | DEF | BEN, 4, '4'},
    {"vdsh5", "vdsh5", VR_MODE_VDSH5, 0, 0, OPT | FRM | DEF | BEN, 3, '5'},
    {"vdsh5poly", "vdsh5poly", VR_MODE_VDSH5_POLY, 0, 0, OPT | FRM | DEF | BEN, 3, '6'},
    {"sdf", "sdf", VR_MODE_SDF, 0, 0, OPT | FRM | BEN, 8, 0},
    BUF(1, 0),
    BUF(2, 0),
    BUF(3, 0),
    BUF(4, 0),
    BUF(5, LOG),
    BUF(6, LOG),
    BUF(7, LOG),
    BUF(8, LOG),
    BUF(9, LOG),
    BUF(10, LOG),
    BUF(11, LOG),
    BUF(12, LOG),
    BUF(13, LOG),
    BUF(14, LOG),
    BUF(15, LOG),
    BUF(16, LOG),
    {"adaptive", "adaptive", VR_MODE_VDSH_BUFFER, 0, VR_STREAM_VARIABLE, OPT | FRM | LOG, 7, 0},
    /* its grid column: the highest fixed stream no other column draws */
    {"buffer", "buffer", VR_MODE_VDSH_BUFFER, 0, 0, OPT, 6, '7'},
    {NULL, NULL, VR_MODE_DEFAULT, 0, 0, 0, 0, 0}};
#undef BUF

_Static_assert(sizeof vv_modes / sizeof vv_modes[0] <= VV_MAX_MODES + 1, "VV_MAX_MODES");

int vv_mode_find(const char *name, size_t len, unsigned flag)
{
    for (int i = 0; vv_modes[i].name; i++)
        if (strlen(vv_modes[i].name) == len && !strncmp(name, vv_modes[i].name, len) &&
            (!flag || (vv_modes[i].flags & flag)))
            return i;
    return -1;
}

int vv_mode_available(const vr_scene *s, const vv_mode *m)
{
    if (m->mode == VR_MODE_VDSH_BUFFER)
        return vr_scene_buffer_stream(s, m->stream) != 0;
    return vr_scene_supports(s, m->mode);
}

void vv_mode_label(const vr_scene *s, vr_mode mode, int stream, char *out, size_t size)
{
    if (mode == VR_MODE_DEFAULT)
        mode = vr_scene_default_mode(s);
    if (mode != VR_MODE_VDSH_BUFFER) {
        snprintf(out, size, "%s", vr_scene_mode_label(s, mode));
        return;
    }
    vr_scene_info info;
    vr_scene_get_info(s, &info);
    int k = vr_scene_buffer_stream(s, stream);
    if (k == VR_STREAM_VARIABLE)
        snprintf(out, size, "VDSH adaptive order (up to %d, mean %.1f; per-vertex)",
                 info.variable_order, (double)info.variable_mean_order);
    else if (k > 0)
        snprintf(out, size, "VDSH order %d (%d coeff., buffer, per-vertex%s)", k, k * k,
                 info.buffer_compute[k] ? ", summed in compute" : "");
    else
        snprintf(out, size, "VDSH from a buffer");
}

float vv_scene_diagonal(const vr_scene *s)
{
    vr_scene_info info;
    vr_scene_get_info(s, &info);
    return vdsh_view_diagonal(info.bounds_min, info.bounds_max);
}

/* n default lights of the scene: positions from vr_scene_default_lights,
 * warm/cool colours, and a fall-off that halves the light at about 0.3 of
 * the scene's diagonal in a room, and at the middle of an object (its
 * lights stand outside it). */
int vv_default_lights(const vr_scene *s, const vv_options *o, int n, vr_light *out)
{
    static const float colors[4][3] = {
        {1.0f, 0.92f, 0.8f}, {0.55f, 0.7f, 1.0f}, {1.0f, 0.62f, 0.4f}, {0.7f, 1.0f, 0.7f}};
    vr_scene_info info;
    vr_scene_get_info(s, &info);
    int want = n;
    n = vr_scene_default_lights(s, out, want < 4 ? want : 4);
    /* Beyond the four defaults: the scene's light pool (vv_open_scene
     * asks for one when more lights are wanted). */
    if (want > n)
        n += vr_scene_pool_lights(s, out + n, want - n);
    float r = 0.3f * vv_scene_diagonal(s);
    /* dimmer when there are several, so that their sum stays in range */
    float intensity = 1.6f / (1.0f + 0.6f * (float)(n - 1));
    for (int i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++)
            out[i].color[k] = intensity * colors[i % 4][k];
        if (!info.interior) {
            r = 0.0f;
            for (int k = 0; k < 3; k++) {
                float d = out[i].position[k] - 0.5f * (info.bounds_min[k] + info.bounds_max[k]);
                r += d * d;
            }
            r = sqrtf(r) > 0.0f ? sqrtf(r) : 1.0f;
        }
        if (o->have_att)
            memcpy(out[i].attenuation, o->att, sizeof o->att);
        else {
            out[i].attenuation[0] = 1.0f;
            out[i].attenuation[2] = 1.0f / (r * r);
        }
    }
    return n;
}

/* The lights of options (with --attenuation applied), else n defaults. */
int vv_scene_lights(const vr_scene *s, const vv_options *o, int n, vr_light *out)
{
    if (o->light_count == 0)
        return vv_default_lights(s, o, n, out);
    float r = 0.3f * vv_scene_diagonal(s);
    for (int i = 0; i < o->light_count; i++) {
        out[i] = o->lights[i];
        if (o->have_att)
            memcpy(out[i].attenuation, o->att, sizeof o->att);
        else {
            out[i].attenuation[0] = 1.0f;
            out[i].attenuation[2] = 1.0f / (r * r);
        }
        if (!out[i].color[0] && !out[i].color[1] && !out[i].color[2])
            out[i].color[0] = out[i].color[1] = out[i].color[2] = 1.6f;
    }
    return o->light_count;
}

void vv_scene_camera(const vr_scene *s, const vv_options *o, vr_camera *c)
{
    if (o->fit)
        vr_scene_fit_camera(s, c);
    else
        vr_scene_default_camera(s, c);
    if (o->have_camera) {
        memcpy(c->eye, o->camera, 3 * sizeof(float));
        memcpy(c->target, o->camera + 3, 3 * sizeof(float));
    }
    if (o->fov > 0.0f)
        c->fov_y = o->fov;
}

vr_draw_desc vv_base_desc(const vv_options *o, const vr_light *lights, int n)
{
    vr_draw_desc d;
    memset(&d, 0, sizeof d);
    d.mode = o->mode;
    d.stream = o->stream;
    d.compare = o->compare;
    d.pcf = o->pcf;
    d.sdf_k = o->sdf_k;
    d.lights = lights;
    d.light_count = n;
    float amb = o->have_ambient ? o->ambient : 0.03f;
    d.ambient[0] = d.ambient[1] = d.ambient[2] = amb;
    return d;
}

double vv_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

/* stb_image_write's output callback: into the atomic output (a failed
 * write is remembered; the commit reports it). */
static void png_put(void *user, void *data, int size)
{
    vdsh_output_put(user, data, (size_t)size);
}

int vv_write_png(const char *path, int w, int h, const unsigned char *rgba)
{
    /* Opaque PNGs: the framebuffer's alpha is whatever blending left. */
    size_t n = (size_t)w * (size_t)h;
    unsigned char *copy = malloc(n * 4);
    if (!copy) {
        fprintf(stderr, "vdsh-view: %s: out of memory\n", path);
        return 1;
    }
    for (size_t i = 0; i < n; i++) {
        memcpy(copy + 4 * i, rgba + 4 * i, 3);
        copy[4 * i + 3] = 255;
    }
    /* The file appears complete or not at all (formats/vdsh_output.h). */
    vdsh_output out;
    vdsh_error err;
    int rc = 1;
    if (vdsh_output_open(path, &out, &err) != VDSH_OK)
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
    else if (!stbi_write_png_to_func(png_put, &out, w, h, 4, copy, w * 4)) {
        fprintf(stderr, "vdsh-view: %s: cannot encode the PNG\n", path);
        vdsh_output_abort(&out);
    } else if (vdsh_output_commit(&out, &err) != VDSH_OK)
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
    else
        rc = 0;
    free(copy);
    return rc;
}

void vv_session_close(vv_session *s)
{
    vr_renderer_destroy(s->r);
    vr_scene_destroy(s->scene);
    vr_context_destroy(s->ctx);
    memset(s, 0, sizeof *s);
}

int vv_open_scene(const vv_options *o, const char *path, vr_scene **out)
{
    vr_error err;
    /* More than the four default lights come from the scene's pool. */
    int pool = o->bench ? VR_MAX_POOL_LIGHTS : o->default_lights > 4 ? o->default_lights - 4 : 0;
    vr_scene_desc sd = {.path = path,
                        .skip_cubemaps = o->no_cubemaps,
                        .light_pool = pool,
                        .buffers = o->buffers,
                        .cpca_decode = o->bench        ? VR_CPCA_PER_PASS
                                       : o->cpca_frame ? VR_CPCA_PER_FRAME
                                       : o->cpca_load  ? VR_CPCA_AT_LOAD
                                                       : VR_CPCA_PER_PASS,
                        /* --bench: its buffer modes are the vertex
                         * stage's, the copies the others */
                        .sums = o->bench         ? VR_SUMS_VERTEX
                                : o->compute     ? VR_SUMS_COMPUTE
                                : o->vertex_sums ? VR_SUMS_VERTEX
                                                 : VR_SUMS_AUTO,
                        .sdf_path = o->sdf_path,
                        .light_region = o->light_region};
    memcpy(sd.light_box, o->light_box, sizeof sd.light_box);
    if (vr_scene_create(&sd, out, &err) != VR_OK) {
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
        return 1;
    }
    return 0;
}

int vv_session_open(const vv_options *o, vr_context_kind kind, int w, int h, vv_session *s)
{
    vr_error err;
    memset(s, 0, sizeof *s);
    vr_context_desc cd = {.kind = kind, .egl_platform = o->egl, .width = w, .height = h};
    if (vr_context_create(&cd, &s->ctx, &err) != VR_OK) {
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
        return 1;
    }
    if (vv_open_scene(o, o->files[0], &s->scene)) {
        vv_session_close(s);
        return 1;
    }
    vr_renderer_desc rd = {.width = w, .height = h, .shadow_map_size = o->shadow_size};
    if (vr_renderer_create(&rd, &s->r, &err) != VR_OK) {
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
        vv_session_close(s);
        return 1;
    }
    return 0;
}

/* A headless context (of w x h when `sized`, else the platform's default
 * surface) and a w x h renderer on it; 0, or 1 after printing why. */
int vv_open_headless(const vv_options *o, int w, int h, int sized, vr_context **ctx,
                     vr_renderer **r)
{
    vr_error err;
    vr_context_desc cd = {.kind = VR_CONTEXT_HEADLESS,
                          .egl_platform = o->egl,
                          .width = sized ? w : 0,
                          .height = sized ? h : 0};
    if (vr_context_create(&cd, ctx, &err) != VR_OK) {
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
        return 1;
    }
    vr_renderer_desc rd = {.width = w, .height = h, .shadow_map_size = o->shadow_size};
    if (vr_renderer_create(&rd, r, &err) != VR_OK) {
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
        vr_context_destroy(*ctx);
        *ctx = NULL;
        return 1;
    }
    return 0;
}
