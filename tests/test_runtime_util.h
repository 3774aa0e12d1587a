/*
 * test_runtime_util.h - what the runtime tests share: a headless context
 * or "skipped" (exit 77), synthetic .vdsh files built in memory (written
 * with vdsh_write when a test needs them on disk; the runtime needs no
 * other file: it makes the basis cubemaps), and reading back float
 * targets.
 */
#ifndef TEST_RUNTIME_UTIL_H
#define TEST_RUNTIME_UTIL_H

#include "test_util.h"

#include "vdsh.h"
#include "vdsh_sh.h"
#include "vdsh_shadow.h"
#include "vr.h"
#include "vr_context.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* A headless context, or exit 77 when this machine has no EGL display
 * (or cannot make a context on it): GL tests are skipped, not failed. */
static inline vr_context *rt_context_or_skip(const char *test)
{
    vr_context *ctx = NULL;
    vr_error err;
    vr_context_desc d = {.kind = VR_CONTEXT_HEADLESS};
    if (vr_context_create(&d, &ctx, &err) != VR_OK) {
        printf("%s: skipped: %s\n", test, err.msg);
        exit(TEST_SKIP);
    }
    return ctx;
}

/* A .vdsh in memory with its own storage. */
typedef struct rt_file {
    vdsh_file f;
    float *pos, *nrm;
    uint32_t *idx;
    vdsh_stream streams[VDSH_MAX_STREAMS];
    float *coef[VDSH_MAX_STREAMS]; /* the coefficients as floats */
    void *data[VDSH_MAX_STREAMS];  /* as stored */
    vdsh_source source;
} rt_file;

/* v vertices (positions and normals to be filled by the caller), t
 * triangles (indices likewise), no streams yet. */
static inline void rt_file_init(rt_file *r, uint32_t v, uint32_t t)
{
    memset(r, 0, sizeof *r);
    vdsh_header *h = &r->f.header;
    h->vertex_count = v;
    h->triangle_count = t;
    h->rays = 400;
    h->sampling = VDSH_SAMPLING_SPHERE;
    h->seed = 1;
    h->max_distance = 100.0f;
    h->cube_size = 64;
    h->occluder_vertex_count = v;
    h->occluder_triangle_count = t;
    r->pos = calloc((size_t)v * 3, sizeof(float));
    r->nrm = calloc((size_t)v * 3, sizeof(float));
    r->idx = calloc((size_t)t * 3 + 1, sizeof(uint32_t));
    r->f.positions = r->pos;
    r->f.normals = r->nrm;
    r->f.indices = r->idx;
    r->f.streams = r->streams;
    r->source.name = "test";
    r->f.sources = &r->source;
    r->f.source_count = 1;
}

/* Bounds from the positions (call once they are filled). */
static inline void rt_file_bounds(rt_file *r)
{
    vdsh_header *h = &r->f.header;
    for (int k = 0; k < 3; k++) {
        h->bounds_min[k] = INFINITY;
        h->bounds_max[k] = -INFINITY;
    }
    for (uint32_t i = 0; i < h->vertex_count; i++)
        for (int k = 0; k < 3; k++) {
            h->bounds_min[k] = fminf(h->bounds_min[k], r->pos[3 * i + k]);
            h->bounds_max[k] = fmaxf(h->bounds_max[k], r->pos[3 * i + k]);
        }
}

/* A renderer of w x h float (RGBA32F) pixels; NULL, and a failed check,
 * when none can be made. */
static inline vr_renderer *rt_float_renderer(int w, int h)
{
    vr_renderer *r = NULL;
    vr_error err;
    vr_renderer_desc rd = {.width = w, .height = h, .color_format = VR_COLOR_RGBA32F};
    CHECK(vr_renderer_create(&rd, &r, &err) == VR_OK, "%s", err.msg);
    return r;
}

/* rt_file_init for one quad: corners p, one normal n at each, triangles
 * idx; bounds set. */
static inline void rt_file_quad(rt_file *r, const float p[4][3], const float n[3],
                                const uint32_t idx[6])
{
    rt_file_init(r, 4, 2);
    for (int i = 0; i < 4; i++) {
        memcpy(r->pos + 3 * i, p[i], 3 * sizeof(float));
        memcpy(r->nrm + 3 * i, n, 3 * sizeof(float));
    }
    memcpy(r->idx, idx, 6 * sizeof(uint32_t));
    rt_file_bounds(r);
}

/* The quad [-1, 1]^2 at z = 0, facing +z, as two triangles. */
static inline void rt_file_unit_quad(rt_file *r)
{
    static const float p[4][3] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, n[3] = {0, 0, 1};
    static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    rt_file_quad(r, p, n, idx);
}

/* Add a stream whose coefficients coef (vertex-major, order^2 each, taken
 * over) are stored in `enc`: f16 as coef / scale rounded (coef is then
 * replaced by what the file really holds, so references use the exact
 * stored values), f32 as coef / scale too (scale need not be 1), s8 and
 * s8s6 by vdsh_encode_quantised (scale ignored: 1; coef replaced by the
 * decoded values as for f16). */
static inline void rt_file_add_stream(rt_file *r, uint32_t order, uint32_t enc, uint32_t quantity,
                                      float *coef, float scale)
{
    uint32_t i = r->f.stream_count++;
    size_t n = (size_t)r->f.header.vertex_count * order * order;
    vdsh_stream *s = &r->streams[i];
    memset(s, 0, sizeof *s);
    s->order = order;
    s->encoding = enc;
    s->quantity = quantity;
    s->scale = scale;
    /* The floor is only a record of the bake; the test streams are synthetic. */
    s->quantity_param = quantity == VDSH_QUANTITY_LOG_DISTANCE ? 0.01f : 0.0f;
    if (enc == VDSH_ENCODING_F16) {
        uint16_t *d = malloc(n * 2 + 2);
        for (size_t k = 0; k < n; k++) {
            d[k] = vdsh_f16_from_f32(coef[k] / scale);
            coef[k] = vdsh_f32_from_f16(d[k]) * scale;
        }
        r->data[i] = d;
    } else if (vdsh_encoding_quantised(enc)) {
        /* vdsh_encode_quantised picks the scales (scale must be 1) */
        uint32_t nv = r->f.header.vertex_count, nc = order * order;
        float *d = malloc(VDSH_MAX_COEFFS * sizeof(float) + nv * vdsh_encoding_bytes(enc, nc) + 1);
        uint8_t *b = (uint8_t *)(d + VDSH_MAX_COEFFS);
        if (vdsh_encode_quantised(enc, coef, nv, nc, d, b) != VDSH_OK)
            abort();
        s->scale = 1.0f;
        s->coef_scales = d;
        s->data = b;
        for (uint32_t v = 0; v < nv; v++)
            vdsh_stream_decode(s, v, coef + (size_t)v * nc);
        r->data[i] = d;
        r->coef[i] = coef;
        return;
    } else {
        float *d = malloc(n * 4 + 4);
        for (size_t k = 0; k < n; k++) {
            d[k] = coef[k] / scale;
            coef[k] = d[k] * scale;
        }
        r->data[i] = d;
    }
    s->data = r->data[i];
    r->coef[i] = coef;
}

static inline void rt_file_free(rt_file *r)
{
    free(r->pos);
    free(r->nrm);
    free(r->idx);
    for (int i = 0; i < VDSH_MAX_STREAMS; i++) {
        free(r->coef[i]);
        free(r->data[i]);
    }
    memset(r, 0, sizeof *r);
}

/* Write dir/stem.vdsh (the .vdsh alone). */
static inline int rt_file_write(const rt_file *r, const char *dir, const char *stem, char *path,
                                size_t path_size)
{
    mkdir(dir, 0777);
    snprintf(path, path_size, "%s/%s.vdsh", dir, stem);
    vdsh_error ve;
    if (vdsh_write(path, &r->f, &ve) != VDSH_OK) {
        fprintf(stderr, "vdsh_write: %s\n", ve.msg);
        return -1;
    }
    return 0;
}

/* Read a renderer's RGBA32F framebuffer (malloc'd, top row first). */
static inline float *rt_read(vr_renderer *r, int w, int h)
{
    size_t size = (size_t)w * (size_t)h * 4 * sizeof(float);
    float *px = malloc(size);
    vr_error err;
    if (!px || vr_read_pixels(r, px, size, &err) != VR_OK) {
        fprintf(stderr, "vr_read_pixels: %s\n", px ? err.msg : "out of memory");
        exit(1);
    }
    return px;
}

static inline void rt_draw_or_die(vr_renderer *r, const vr_scene *s, const vr_draw_desc *d)
{
    vr_error err;
    if (vr_draw(r, s, d, &err) != VR_OK) {
        fprintf(stderr, "vr_draw: %s\n", err.msg);
        exit(1);
    }
}

#endif
