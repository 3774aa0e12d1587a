/*
 * frames.c - ray-traced frames (frames.h): the receiver scene, the
 * primary and shadow passes in 16-wide packets over 4 x 4 pixel tiles,
 * the streams on the runtime's path, the shading, the scores and the
 * choice of views.
 */
#include "frames.h"

#include "vdsh_scene_view.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "eval.h"
#include "parallel.h"
#include "sampling.h"
#include "vdsh_light.h"
#include "vdsh_math.h"
#include "vdsh_shadow.h"

#define NONE UINT32_MAX
#define TILE 4             /* pixels a side: 16 rays, one packet */
#define TILES_PER_BLOCK 16 /* work item of the pool */

/* Every purpose gets its own random stream from the one seed. */
enum {
    PURPOSE_EYES = 0x45594553u,   /* "EYES" */
    PURPOSE_LOOK = 0x4c4f4f4bu,   /* "LOOK" */
    PURPOSE_LIGHTS = 0x4c475453u, /* "LGTS" */
    PURPOSE_ORDER = 0x4f524452u   /* "ORDR" */
};

/* ---- the receiver scene ---------------------------------------------------- */

void vb_frames_scene_destroy(vb_frames_scene *s)
{
    if (!s)
        return;
    vb_scene_destroy(s->receivers);
    free(s);
}

vb_result vb_frames_scene_create(const vdsh_file *f, const vb_scene *occluders, unsigned threads,
                                 vb_frames_scene **out, vb_error *err)
{
    const vdsh_header *h = &f->header;
    if (h->triangle_count == 0 || h->vertex_count == 0)
        return vb_fail(err, VB_ERR_INVALID, "the file has no triangles to draw");
    vb_frames_scene *s = calloc(1, sizeof *s);
    if (!s)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    s->file = f;
    s->occluders = occluders;
    /* The bounds the runtime frames its default view with: every vertex. */
    vdsh_view_bounds(f->positions, h->vertex_count, s->bounds_min, s->bounds_max);
    const float diag = vdsh_free_diagonal(s->bounds_min, s->bounds_max);
    s->diagonal = diag > 0.0f ? diag : 1.0f;
    /* The scene only reads the arrays (vb_scene_create copies them). The
     * robust traversal, as a rasteriser's coverage rules: no primary ray
     * slips between two triangles that share an edge. */
    vb_mesh m = {.vertex_count = h->vertex_count,
                 .triangle_count = h->triangle_count,
                 .positions = (float *)f->positions,
                 .normals = (float *)f->normals,
                 .indices = (uint32_t *)f->indices};
    vb_scene_desc sd = {.robust = 1, .threads = threads};
    vb_error e;
    if (vb_scene_create(&m, &sd, &s->receivers, &e) != VB_OK) {
        vb_frames_scene_destroy(s);
        return vb_fail(err, VB_ERR_EMBREE, "the receiver mesh: %s", e.msg);
    }
    *out = s;
    return VB_OK;
}

/* ---- primary rays ------------------------------------------------------------ */

void vb_frames_hits_free(vb_frames_hits *h)
{
    if (!h)
        return;
    free(h->triangle);
    free(h->bary);
    free(h->position);
    free(h->normal);
    free(h->origin);
    free(h->depth);
    memset(h, 0, sizeof *h);
}

typedef struct pass {
    const vb_frames_scene *s;
    const vdsh_camera *camera;
    const vb_frames_hits *hits;
    vb_frames_hits *out_hits;
    vb_frames_light *out_light;
    float *out_stream;
    const float *light;
    uint32_t compare, stream;
    int tiles_x;
} pass;

/* Pixel k (0..15) of tile t: its coordinates, or 0 when off the image. */
static int tile_pixel(const pass *P, int width, int height, uint32_t t, int k, int *x, int *y)
{
    *x = (int)(t % (uint32_t)P->tiles_x) * TILE + (k & 3);
    *y = (int)(t / (uint32_t)P->tiles_x) * TILE + (k >> 2);
    return *x < width && *y < height;
}

static void ray_reset(struct RTCRayHit16 *rh, int k)
{
    static const float zero[3] = {0.0f, 0.0f, 0.0f};
    vb_ray16_init(rh, k, zero, 0.0f);
    rh->ray.dir_x[k] = 0.0f, rh->ray.dir_y[k] = 0.0f, rh->ray.dir_z[k] = 1.0f;
}

static void primary_block(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    (void)worker;
    const pass *P = ctx;
    const vb_frames_scene *s = P->s;
    const vb_scene *rs = s->receivers;
    const vdsh_file *f = s->file;
    vb_frames_hits *h = P->out_hits;
    const int w = h->width, ht = h->height;
    float eye[3];
    vb_scene_to_local(rs, P->camera->eye, eye);
    struct RTCIntersectContext ictx;
    rtcInitIntersectContext(&ictx);
    for (uint32_t t = begin; t < end; t++) {
        struct RTCRayHit16 rh __attribute__((aligned(64)));
        int valid[VB_PACKET] __attribute__((aligned(64)));
        float dirs[VB_PACKET][3];
        for (int k = 0; k < VB_PACKET; k++) {
            int x, y;
            ray_reset(&rh, k);
            valid[k] = 0;
            if (!tile_pixel(P, w, ht, t, k, &x, &y))
                continue;
            float org[3];
            vdsh_camera_ray(P->camera, w, ht, x, y, org, dirs[k]);
            rh.ray.org_x[k] = eye[0], rh.ray.org_y[k] = eye[1], rh.ray.org_z[k] = eye[2];
            rh.ray.dir_x[k] = dirs[k][0], rh.ray.dir_y[k] = dirs[k][1];
            rh.ray.dir_z[k] = dirs[k][2];
            rh.ray.tfar[k] = INFINITY;
            valid[k] = -1;
        }
        rtcIntersect16(valid, rs->scene, &ictx, &rh);
        for (int k = 0; k < VB_PACKET; k++) {
            int x, y;
            if (!valid[k] || !tile_pixel(P, w, ht, t, k, &x, &y))
                continue;
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            float *b = h->bary + 3 * i, *p = h->position + 3 * i, *n = h->normal + 3 * i,
                  *o = h->origin + 3 * i;
            if (rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) {
                h->triangle[i] = NONE;
                h->depth[i] = INFINITY;
                memset(b, 0, 3 * sizeof *b);
                memset(p, 0, 3 * sizeof *p);
                memset(n, 0, 3 * sizeof *n);
                memset(o, 0, 3 * sizeof *o);
                continue;
            }
            /* Embree's (u, v) weigh vertices 1 and 2. */
            const uint32_t tri = rh.hit.primID[k];
            b[0] = 1.0f - rh.hit.u[k] - rh.hit.v[k];
            b[1] = rh.hit.u[k];
            b[2] = rh.hit.v[k];
            h->triangle[i] = tri;
            h->depth[i] = rh.ray.tfar[k] / rs->scale;
            vb_eval_interpolate(f, NULL, tri, b, p, n, NULL);
            /* The shadow ray leaves from the side the camera sees. */
            const uint32_t *ix = f->indices + 3 * (size_t)tri;
            const float *a = f->positions + 3 * (size_t)ix[0];
            const float *bb = f->positions + 3 * (size_t)ix[1];
            const float *c = f->positions + 3 * (size_t)ix[2];
            float e1[3], e2[3], ng[3];
            for (int q = 0; q < 3; q++)
                e1[q] = bb[q] - a[q], e2[q] = c[q] - a[q];
            vdsh_cross3f(ng, e1, e2);
            float len = sqrtf(vdsh_dot3f(ng, ng));
            float sign = vdsh_dot3f(ng, dirs[k]) > 0.0f ? -1.0f : 1.0f;
            for (int q = 0; q < 3; q++)
                ng[q] = len > 0.0f ? sign * ng[q] / len : 0.0f;
            float local[3];
            vb_scene_to_local(s->occluders, p, local);
            vb_offset_origin(local, ng, o);
        }
    }
}

static int tiles(int width, int height, int *tiles_x)
{
    *tiles_x = (width + TILE - 1) / TILE;
    return *tiles_x * ((height + TILE - 1) / TILE);
}

vb_result vb_frames_trace_primary(const vb_frames_scene *s, const vdsh_camera *c, int width,
                                  int height, unsigned threads, vb_frames_hits *out, vb_error *err)
{
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        return vb_fail(err, VB_ERR_ARGUMENT, "frame size %d x %d is not in 1..16384", width,
                       height);
    size_t n = (size_t)width * (size_t)height;
    vb_frames_hits h = {.width = width, .height = height};
    h.triangle = malloc(n * sizeof *h.triangle);
    h.bary = malloc(3 * n * sizeof *h.bary);
    h.position = malloc(3 * n * sizeof *h.position);
    h.normal = malloc(3 * n * sizeof *h.normal);
    h.origin = malloc(3 * n * sizeof *h.origin);
    h.depth = malloc(n * sizeof *h.depth);
    if (!h.triangle || !h.bary || !h.position || !h.normal || !h.origin || !h.depth) {
        vb_frames_hits_free(&h);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for a %d x %d frame", width,
                       height);
    }
    pass P = {.s = s, .camera = c, .out_hits = &h};
    uint32_t count = (uint32_t)tiles(width, height, &P.tiles_x);
    if (!vb_parallel_for(threads, count, TILES_PER_BLOCK, primary_block, &P, NULL, NULL)) {
        vb_frames_hits_free(&h);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "cannot start worker threads");
    }
    *out = h;
    return VB_OK;
}

/* ---- shadow rays ---------------------------------------------------------------- */

void vb_frames_light_free(vb_frames_light *l)
{
    if (!l)
        return;
    free(l->hard);
    free(l->ideal);
    free(l->mask);
    free(l->dt);
    memset(l, 0, sizeof *l);
}

static void light_block(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    (void)worker;
    const pass *P = ctx;
    const vb_scene *os = P->s->occluders;
    const vb_frames_hits *h = P->hits;
    vb_frames_light *l = P->out_light;
    const float *L = P->light;
    const int w = h->width, ht = h->height;
    float Ll[3];
    vb_scene_to_local(os, L, Ll);
    struct RTCIntersectContext ictx;
    rtcInitIntersectContext(&ictx);
    for (uint32_t t = begin; t < end; t++) {
        struct RTCRayHit16 rh __attribute__((aligned(64)));
        int valid[VB_PACKET] __attribute__((aligned(64)));
        float dl[VB_PACKET];
        int any = 0;
        for (int k = 0; k < VB_PACKET; k++) {
            int x, y;
            ray_reset(&rh, k);
            valid[k] = 0;
            dl[k] = 0.0f;
            if (!tile_pixel(P, w, ht, t, k, &x, &y))
                continue;
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            if (h->triangle[i] == NONE)
                continue;
            const float *p = h->position + 3 * i, *o = h->origin + 3 * i;
            float v[3] = {L[0] - p[0], L[1] - p[1], L[2] - p[2]};
            dl[k] = sqrtf(vdsh_dot3f(v, v));
            /* The truth ray runs from the origin to the light itself. */
            float ol[3] = {Ll[0] - o[0], Ll[1] - o[1], Ll[2] - o[2]};
            float dlocal = sqrtf(vdsh_dot3f(ol, ol));
            if (!(dl[k] > 0.0f) || !(dlocal > 0.0f))
                continue;
            rh.ray.org_x[k] = o[0], rh.ray.org_y[k] = o[1], rh.ray.org_z[k] = o[2];
            rh.ray.dir_x[k] = ol[0] / dlocal, rh.ray.dir_y[k] = ol[1] / dlocal;
            rh.ray.dir_z[k] = ol[2] / dlocal;
            rh.ray.tfar[k] = dlocal;
            valid[k] = -1;
            any = 1;
        }
        if (any)
            rtcIntersect16(valid, os->scene, &ictx, &rh);
        for (int k = 0; k < VB_PACKET; k++) {
            int x, y;
            if (!tile_pixel(P, w, ht, t, k, &x, &y))
                continue;
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            if (h->triangle[i] == NONE) {
                l->hard[i] = l->ideal[i] = 1.0f;
                l->mask[i] = 0.0f;
                l->dt[i] = INFINITY;
                continue;
            }
            /* Nothing before the light: visible (d_T larger than d_L). */
            float dt = valid[k] && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID
                           ? rh.ray.tfar[k] / os->scale
                           : INFINITY;
            const float *p = h->position + 3 * i, *n = h->normal + 3 * i;
            float v[3] = {L[0] - p[0], L[1] - p[1], L[2] - p[2]};
            l->dt[i] = dt;
            l->hard[i] = vdsh_shadow_compare(dt, dl[k], VDSH_COMPARE_BINARY);
            l->ideal[i] = vdsh_shadow_compare(dt, dl[k], P->compare);
            l->mask[i] = vdsh_dot3f(n, v) > 0.0f ? 1.0f : 0.0f;
        }
    }
}

vb_result vb_frames_trace_light(const vb_frames_scene *s, const vb_frames_hits *h,
                                const float light[3], uint32_t compare, unsigned threads,
                                vb_frames_light *out, vb_error *err)
{
    size_t n = (size_t)h->width * (size_t)h->height;
    vb_frames_light l = {0};
    l.hard = malloc(n * sizeof *l.hard);
    l.ideal = malloc(n * sizeof *l.ideal);
    l.mask = malloc(n * sizeof *l.mask);
    l.dt = malloc(n * sizeof *l.dt);
    if (!l.hard || !l.ideal || !l.mask || !l.dt) {
        vb_frames_light_free(&l);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    }
    pass P = {.s = s, .hits = h, .out_light = &l, .light = light, .compare = compare};
    uint32_t count = (uint32_t)tiles(h->width, h->height, &P.tiles_x);
    if (!vb_parallel_for(threads, count, TILES_PER_BLOCK, light_block, &P, NULL, NULL)) {
        vb_frames_light_free(&l);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "cannot start worker threads");
    }
    *out = l;
    return VB_OK;
}

/* ---- the streams on the runtime's path ----------------------------------------- */

static void stream_block(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    (void)worker;
    const pass *P = ctx;
    const vdsh_file *f = P->s->file;
    const vdsh_stream *st = &f->streams[P->stream];
    const vb_frames_hits *h = P->hits;
    const uint32_t interp = vdsh_runtime_interp(st->order, st->quantity);
    float c[3][VDSH_MAX_COEFFS];
    const float *cp[3] = {c[0], c[1], c[2]};
    for (uint32_t i = begin; i < end; i++) {
        uint32_t tri = h->triangle[i];
        if (tri == NONE) {
            P->out_stream[i] = 1.0f;
            continue;
        }
        const uint32_t *ix = f->indices + 3 * (size_t)tri;
        const float *pv[3];
        for (int k = 0; k < 3; k++) {
            vdsh_stream_decode(st, ix[k], c[k]);
            pv[k] = f->positions + 3 * (size_t)ix[k];
        }
        P->out_stream[i] =
            vdsh_shadow_interior(st->order, st->quantity, f->header.max_distance, interp, cp, pv,
                                 h->bary + 3 * (size_t)i, P->light, P->compare, NULL);
    }
}

/* The DISTANCE path in two steps, as the runtime draws it: each vertex a
 * pixel needs reconstructs its distance toward the light once, with its
 * own order (a variable-order stream's vertices have their own), then
 * each pixel interpolates its triangle's three. The same bits as
 * vdsh_shadow_interior (it calls the same two functions), many times
 * fewer reconstructions: a vertex serves every pixel around it. */
typedef struct vertex_pass {
    const vdsh_file *f;
    const vdsh_stream *st;
    const uint8_t *need; /* per vertex: some pixel's triangle has it */
    const float *light;
    float *dv; /* per vertex: its distance toward the light */
} vertex_pass;

static void vertex_block(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    (void)worker;
    const vertex_pass *V = ctx;
    float c[VDSH_MAX_COEFFS];
    for (uint32_t v = begin; v < end; v++) {
        if (!V->need[v])
            continue;
        vdsh_stream_decode(V->st, v, c);
        V->dv[v] = vdsh_vertex_distance(vdsh_stream_vertex_order(V->st, v), V->st->quantity,
                                        V->f->header.max_distance, c,
                                        V->f->positions + 3 * (size_t)v, V->light);
    }
}

typedef struct distance_pass {
    const vdsh_file *f;
    const vb_frames_hits *hits;
    const float *dv, *light;
    uint32_t compare;
    float *out;
} distance_pass;

static void distance_block(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    (void)worker;
    const distance_pass *D = ctx;
    for (uint32_t i = begin; i < end; i++) {
        uint32_t tri = D->hits->triangle[i];
        if (tri == NONE) {
            D->out[i] = 1.0f;
            continue;
        }
        const uint32_t *ix = D->f->indices + 3 * (size_t)tri;
        const float *pv[3];
        float dv[3];
        for (int k = 0; k < 3; k++) {
            pv[k] = D->f->positions + 3 * (size_t)ix[k];
            dv[k] = D->dv[ix[k]];
        }
        D->out[i] = vdsh_shadow_interior_distance(dv, pv, D->hits->bary + 3 * (size_t)i, D->light,
                                                  D->compare, NULL);
    }
}

static vb_result eval_distance(const vb_frames_scene *s, const vb_frames_hits *h,
                               const vdsh_stream *st, const float light[3], uint32_t compare,
                               unsigned threads, float *out, vb_error *err)
{
    const vdsh_file *f = s->file;
    const uint32_t rows = f->header.vertex_count;
    const uint32_t n = (uint32_t)((size_t)h->width * (size_t)h->height);
    uint8_t *need = calloc(rows ? rows : 1, 1);
    float *dv = malloc((rows ? rows : 1) * sizeof *dv);
    vb_result r = VB_OK;
    if (!need || !dv) {
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for %u vertex distances", rows);
        goto done;
    }
    for (uint32_t i = 0; i < n; i++) {
        if (h->triangle[i] == NONE)
            continue;
        const uint32_t *ix = f->indices + 3 * (size_t)h->triangle[i];
        need[ix[0]] = need[ix[1]] = need[ix[2]] = 1;
    }
    vertex_pass V = {.f = f, .st = st, .need = need, .light = light, .dv = dv};
    distance_pass D = {.f = f, .hits = h, .dv = dv, .light = light, .compare = compare, .out = out};
    if (!vb_parallel_for(threads, rows, 256, vertex_block, &V, NULL, NULL) ||
        !vb_parallel_for(threads, n, 1024, distance_block, &D, NULL, NULL))
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "cannot start worker threads");
done:
    free(need);
    free(dv);
    return r;
}

vb_result vb_frames_eval_stream(const vb_frames_scene *s, const vb_frames_hits *h, uint32_t stream,
                                const float light[3], uint32_t compare, unsigned threads,
                                float *out, vb_error *err)
{
    if (stream >= s->file->stream_count)
        return vb_fail(err, VB_ERR_ARGUMENT, "no stream %u (the file has %u)", stream,
                       s->file->stream_count);
    const vdsh_stream *st = &s->file->streams[stream];
    if (vdsh_runtime_interp(st->order, st->quantity) == VDSH_INTERP_DISTANCE)
        return eval_distance(s, h, st, light, compare, threads, out, err);
    if (st->flags & VDSH_STREAM_VARIABLE)
        return vb_fail(err, VB_ERR_ARGUMENT,
                       "stream %u: a variable-order stream of quantity %u is not drawn per "
                       "vertex distance (only log-distance ones are)",
                       stream, st->quantity);
    pass P = {
        .s = s, .hits = h, .out_stream = out, .light = light, .compare = compare, .stream = stream};
    uint32_t n = (uint32_t)((size_t)h->width * (size_t)h->height);
    if (!vb_parallel_for(threads, n, 1024, stream_block, &P, NULL, NULL))
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "cannot start worker threads");
    return VB_OK;
}

/* ---- shading ------------------------------------------------------------------ */

void vb_frames_shading_default(const vb_frames_scene *s, int n, vb_frames_shading *out)
{
    out->albedo = 0.8f;
    out->ambient = 0.03f;
    out->intensity = 1.6f / (1.0f + 0.6f * (float)(n > 1 ? n - 1 : 0));
    out->radius = 0.3f * s->diagonal;
}

void vb_frames_shade(const vb_frames_hits *h, const float (*lights)[3], int n,
                     const float *const *vis, const vb_frames_shading *sh, uint8_t *rgba)
{
    size_t count = (size_t)h->width * (size_t)h->height;
    const float inv_r2 = 1.0f / (sh->radius * sh->radius);
    for (size_t i = 0; i < count; i++) {
        uint8_t *o = rgba + 4 * i;
        o[3] = 255;
        if (h->triangle[i] == NONE) {
            o[0] = o[1] = o[2] = 0;
            continue;
        }
        const float *p = h->position + 3 * i, *nn = h->normal + 3 * i;
        float acc = 0.0f;
        for (int j = 0; j < n; j++) {
            float lv[3] = {lights[j][0] - p[0], lights[j][1] - p[1], lights[j][2] - p[2]};
            float dl = sqrtf(vdsh_dot3f(lv, lv));
            /* runtime/vr_glsl.c's light_term, attenuation (1, 0, 1 / r^2) */
            float ndl = dl > 0.0f ? fmaxf(vdsh_dot3f(nn, lv) / dl, 0.0f) : 1.0f;
            float att = 1.0f / (1.0f + dl * dl * inv_r2);
            acc += vis[j][i] * sh->intensity * ndl * att;
        }
        float c = sh->albedo * (sh->ambient + acc);
        c = c < 0.0f ? 0.0f : c > 1.0f ? 1.0f : c;
        o[0] = o[1] = o[2] = (uint8_t)lrintf(c * 255.0f);
    }
}

/* ---- scores ------------------------------------------------------------------------ */

vb_result vb_frames_score_frame(const float *s, const float *hard, const float *ideal,
                                const float *mask, int width, int height, vb_frames_tally *t,
                                vb_error *err)
{
    size_t n = (size_t)width * (size_t)height;
    uint8_t *fs = calloc(n ? n : 1, 1);
    uint32_t *stack = malloc((n ? n : 1) * sizeof *stack);
    if (!fs || !stack) {
        free(fs);
        free(stack);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    }
    vb_frames_tally a = {.frames = 1, .pixels = n};
    for (size_t i = 0; i < n; i++) {
        if (!(mask[i] >= 0.5f))
            continue;
        a.counted++;
        double di = (double)s[i] - ideal[i], dh = (double)s[i] - hard[i];
        a.se_ideal += di * di;
        a.se_hard += dh * dh;
        const int dark = s[i] < 0.5f;
        if (hard[i] < 0.5f) {
            if (ideal[i] < 0.5f) {
                a.shadowed++;
                a.recalled += dark;
            }
        } else {
            a.lit++;
            a.false_shadow += dark;
            fs[i] = (uint8_t)dark;
        }
    }
    /* Blotches: 4-connected regions of false shadow, by flood fill in
     * pixel order (each pixel is pushed once: it is cleared when pushed). */
    const double big = VB_FRAMES_BLOTCH * (double)n;
    for (size_t i = 0; i < n; i++) {
        if (!fs[i])
            continue;
        size_t top = 0, size = 0;
        stack[top++] = (uint32_t)i;
        fs[i] = 0;
        while (top) {
            uint32_t q = stack[--top];
            size++;
            int x = (int)(q % (uint32_t)width), y = (int)(q / (uint32_t)width);
            const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
            for (int k = 0; k < 4; k++) {
                if (nx[k] < 0 || ny[k] < 0 || nx[k] >= width || ny[k] >= height)
                    continue;
                size_t r = (size_t)ny[k] * (size_t)width + (size_t)nx[k];
                if (fs[r]) {
                    fs[r] = 0;
                    stack[top++] = (uint32_t)r;
                }
            }
        }
        if ((double)size > big) {
            a.blotches++;
            a.blotch_pixels += size;
        }
    }
    free(fs);
    free(stack);
    vb_frames_tally_add(t, &a);
    return VB_OK;
}

void vb_frames_tally_add(vb_frames_tally *to, const vb_frames_tally *from)
{
    to->frames += from->frames;
    to->pixels += from->pixels;
    to->counted += from->counted;
    to->se_ideal += from->se_ideal;
    to->se_hard += from->se_hard;
    to->shadowed += from->shadowed;
    to->recalled += from->recalled;
    to->lit += from->lit;
    to->false_shadow += from->false_shadow;
    to->blotches += from->blotches;
    to->blotch_pixels += from->blotch_pixels;
}

static double psnr(double se, uint64_t n)
{
    if (n == 0)
        return NAN;
    return se > 0.0 ? 10.0 * log10((double)n / se) : INFINITY;
}

void vb_frames_scores_get(const vb_frames_tally *t, vb_frames_scores *out)
{
    vb_frames_scores r;
    r.rmse_ideal = t->counted ? sqrt(t->se_ideal / (double)t->counted) : NAN;
    r.rmse_hard = t->counted ? sqrt(t->se_hard / (double)t->counted) : NAN;
    r.psnr_ideal = psnr(t->se_ideal, t->counted);
    r.psnr_hard = psnr(t->se_hard, t->counted);
    r.recall = t->shadowed ? (double)t->recalled / (double)t->shadowed : NAN;
    r.false_area = t->lit ? (double)t->false_shadow / (double)t->lit : NAN;
    r.blotches = t->blotches;
    r.blotch_area = t->pixels ? (double)t->blotch_pixels / (double)t->pixels : NAN;
    *out = r;
}

/* ---- the viewer's default camera -------------------------------------------------------
 * The camera vdsh-view opens a scene with: formats/vdsh_scene_view.h's,
 * from the file's mesh, the one definition the runtime uses too. */

static vb_result default_camera(const vb_frames_scene *s, vdsh_camera *out, vb_error *err)
{
    float region[6];
    vdsh_view_mesh m;
    vdsh_view_file_mesh(s->file, region, &m);
    vdsh_view v;
    vdsh_error ve;
    if (vdsh_view_compute(&m, &v, &ve) != VDSH_OK)
        return vb_fail(err, VB_ERR_INVALID, "the default view: %s", ve.msg);
    *out = v.camera;
    return VB_OK;
}

/* ---- views ------------------------------------------------------------------------ */

#define LIGHT_POOL 128u
#define EYE_TRIES_PER_VIEW 400u
#define CHECK_SIZE 64       /* the check frame's longer side, pixels */
#define NEAREST_SHARE 0.05f /* of the diagonal: no surface nearer to the eye */

typedef struct view_check {
    const vb_frames_scene *s;
    const float (*pool)[3];
    int width, height; /* the check frame */
    unsigned threads;
} view_check;

/* Light `light`'s shares of the check frame lit and hard-shadowed. */
static vb_result light_shares(const view_check *V, const vb_frames_hits *h, const float light[3],
                              float *lit, float *shadowed, vb_error *err)
{
    vb_frames_light l = {0};
    vb_result r = vb_frames_trace_light(V->s, h, light, VDSH_COMPARE_SMOOTH, V->threads, &l, err);
    if (r != VB_OK)
        return r;
    size_t n = (size_t)h->width * (size_t)h->height, a = 0, b = 0;
    for (size_t i = 0; i < n; i++) {
        if (l.mask[i] < 0.5f)
            continue;
        a += l.hard[i] >= 0.5f;
        b += l.hard[i] < 0.5f;
    }
    vb_frames_light_free(&l);
    *lit = (float)a / (float)n;
    *shadowed = (float)b / (float)n;
    return VB_OK;
}

/* Lights for a view: the pool's lights from `start` on, in order, that
 * light and shadow enough of it. With `strict`, *ok is 0 unless four are
 * found; otherwise the best of the others (by the smaller share) fill in. */
static vb_result pick_lights(const view_check *V, const vb_frames_hits *h, uint32_t start,
                             int strict, vb_frames_view *view, uint32_t *found, int *ok,
                             vb_error *err)
{
    float lit[LIGHT_POOL], sh[LIGHT_POOL];
    uint8_t taken[LIGHT_POOL] = {0};
    uint32_t n = 0, tried = 0;
    for (uint32_t i = 0; i < LIGHT_POOL && n < VB_FRAMES_VIEW_LIGHTS; i++, tried++) {
        uint32_t j = (start + i) % LIGHT_POOL;
        vb_result r = light_shares(V, h, V->pool[j], &lit[j], &sh[j], err);
        if (r != VB_OK)
            return r;
        if (lit[j] >= VB_FRAMES_MIN_SHARE && sh[j] >= VB_FRAMES_MIN_SHARE) {
            memcpy(view->lights[n], V->pool[j], sizeof view->lights[n]);
            view->lit[n] = lit[j], view->shadowed[n] = sh[j];
            taken[j] = 1;
            n++;
        }
    }
    *found = n;
    *ok = n == VB_FRAMES_VIEW_LIGHTS;
    if (strict || *ok)
        return VB_OK;
    /* Every light was tried: the best of the rest, in pool order on ties. */
    for (; n < VB_FRAMES_VIEW_LIGHTS; n++) {
        uint32_t best = UINT32_MAX;
        for (uint32_t j = 0; j < LIGHT_POOL; j++) {
            if (taken[j])
                continue;
            if (best == UINT32_MAX || fminf(lit[j], sh[j]) > fminf(lit[best], sh[best]))
                best = j;
        }
        taken[best] = 1;
        memcpy(view->lights[n], V->pool[best], sizeof view->lights[n]);
        view->lit[n] = lit[best], view->shadowed[n] = sh[best];
    }
    *ok = 1;
    return VB_OK;
}

/* The check frame: CHECK_SIZE pixels on the longer side, the view set's
 * aspect, at least 4 a side. */
static void check_frame_size(const vb_frames_views_desc *d, int *width, int *height)
{
    if (d->width >= d->height) {
        *width = CHECK_SIZE;
        *height = (int)lround((double)CHECK_SIZE * d->height / d->width);
    } else {
        *height = CHECK_SIZE;
        *width = (int)lround((double)CHECK_SIZE * d->width / d->height);
    }
    *width = *width < 4 ? 4 : *width;
    *height = *height < 4 ? 4 : *height;
}

/* View 0: the viewer's own camera; its lights are the best there are
 * (*found: how many of them light and shadow enough of it). */
static vb_result make_default_view(const view_check *V, vb_frames_view *v, uint32_t *found,
                                   vb_error *err)
{
    vb_frames_hits h = {0};
    vb_result r = default_camera(V->s, &v->camera, err);
    if (r == VB_OK)
        r = vb_frames_trace_primary(V->s, &v->camera, V->width, V->height, V->threads, &h, err);
    if (r == VB_OK) {
        int ok;
        r = pick_lights(V, &h, 0, 0, v, found, &ok, err);
    }
    vb_frames_hits_free(&h);
    return r;
}

/* What the search for the other views' eyes shares between candidates. */
typedef struct eye_search {
    const view_check *V;
    uint64_t eye_seed, look_seed, order_seed;
    /* Eyes go where lights go (vdsh_light.h): the light region. */
    float lo[3], hi[3];
    /* No surface nearer to the eye: NEAREST_SHARE of the diagonal. */
    float nearest;
    struct RTCIntersectContext ictx;
} eye_search;

static void eye_search_init(eye_search *E, const view_check *V, uint64_t seed)
{
    E->V = V;
    E->eye_seed = vb_eval_purpose_seed(seed, PURPOSE_EYES);
    E->look_seed = vb_eval_purpose_seed(seed, PURPOSE_LOOK);
    E->order_seed = vb_eval_purpose_seed(seed, PURPOSE_ORDER);
    vb_scene_light_region(V->s->occluders, E->lo, E->hi, NULL);
    E->nearest = NEAREST_SHARE * V->s->diagonal;
    rtcInitIntersectContext(&E->ictx);
}

/* Candidate eye k, when in free space, looking at the surface point it
 * sees in a direction between 53 degrees below the horizon and 12 above
 * (as a visitor looks: along and down, where shadows fall); 0 when it is
 * not in free space or sees no surface at least E->nearest away. */
static int aim_eye(eye_search *E, uint32_t k, vdsh_camera *cam, vb_frames_views_stats *st)
{
    const vb_frames_scene *s = E->V->s;
    st->eyes_tried++;
    float eye[3];
    vdsh_light_candidate(E->lo, E->hi, E->eye_seed, k, eye);
    if (!vb_scene_free_space(s->occluders, eye))
        return 0;
    st->eyes_free++;
    float u1, u2;
    vb_hash2(E->look_seed, k, 0, &u1, &u2);
    float y = -0.8f + 1.0f * u1, rho = sqrtf(1.0f - y * y);
    float dir[3] = {rho * cosf(6.28318531f * u2), y, rho * sinf(6.28318531f * u2)};
    const vb_scene *rs = s->receivers;
    float o[3];
    vb_scene_to_local(rs, eye, o);
    struct RTCRayHit rh;
    vb_ray_init(&rh, o, dir, INFINITY, 0);
    rtcIntersect1(rs->scene, &E->ictx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return 0;
    float t = rh.ray.tfar / rs->scale;
    if (t < E->nearest)
        return 0;
    memcpy(cam->eye, eye, sizeof eye);
    for (int q = 0; q < 3; q++)
        cam->target[q] = eye[q] + t * dir[q];
    cam->fov_y = 60.0f;
    return 1;
}

/* The nearest surface a check frame shows (its smallest depth). */
static float nearest_depth(const view_check *V, const vb_frames_hits *h)
{
    float near = INFINITY;
    for (size_t i = 0; i < (size_t)V->width * (size_t)V->height; i++)
        near = fminf(near, h->depth[i]);
    return near;
}

/* View v from candidate eye k: *ok when the eye is aimed, its check frame
 * shows no surface nearer than E->nearest and four of the pool's lights,
 * from a start of its own, light and shadow enough of it. */
static vb_result try_eye(eye_search *E, uint32_t k, vb_frames_view *v, int *ok,
                         vb_frames_views_stats *st, vb_error *err)
{
    const view_check *V = E->V;
    *ok = 0;
    vdsh_camera cam = {0};
    if (!aim_eye(E, k, &cam, st))
        return VB_OK;
    memset(v, 0, sizeof *v);
    v->camera = cam;
    vb_frames_hits h = {0};
    vb_result r =
        vb_frames_trace_primary(V->s, &v->camera, V->width, V->height, V->threads, &h, err);
    if (r == VB_OK && nearest_depth(V, &h) >= E->nearest) {
        uint32_t found;
        uint32_t start = (uint32_t)(vb_eval_purpose_seed(E->order_seed, k) % LIGHT_POOL);
        r = pick_lights(V, &h, start, 1, v, &found, ok, err);
    }
    vb_frames_hits_free(&h);
    return r;
}

static vb_result too_few_views(uint32_t have, uint32_t cameras, const vb_frames_views_stats *st,
                               vb_error *err)
{
    return vb_fail(err, VB_ERR_INVALID,
                   "found %u of %u views (%u candidate eyes, %u in free space): too few "
                   "views show at least %.0f%% of their pixels lit and as many "
                   "hard-shadowed by one light with no surface nearer than %.0f%% of the "
                   "diagonal; %s",
                   have, cameras, st->eyes_tried, st->eyes_free, 100.0 * VB_FRAMES_MIN_SHARE,
                   100.0 * NEAREST_SHARE,
                   have ? "ask for fewer cameras or try another seed"
                        : "none did: the scene may cast no shadow one light shows (a lone "
                          "plane or convex object), which no seed changes");
}

vb_result vb_frames_make_views(const vb_frames_scene *s, const vb_frames_views_desc *desc,
                               vb_frames_view *out, vb_frames_views_stats *stats, vb_error *err)
{
    vb_frames_views_desc d = *desc;
    if (d.cameras == 0)
        d.cameras = 6;
    if (d.seed == 0)
        d.seed = 1;
    if (d.width <= 0 || d.height <= 0)
        d.width = 512, d.height = 384;
    vb_frames_views_stats st = {0};
    view_check V = {.s = s, .threads = d.threads};
    check_frame_size(&d, &V.width, &V.height);

    /* The pool the views' lights are drawn from, placed as vdsh-eval's. */
    float(*pool)[3] = malloc(LIGHT_POOL * sizeof *pool);
    vb_frames_view *views = calloc(1 + (size_t)d.cameras, sizeof *views);
    vb_result r = VB_OK;
    if (!pool || !views) {
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    r = vb_scene_place_lights_rule(s->occluders, vb_eval_purpose_seed(d.seed, PURPOSE_LIGHTS),
                                   LIGHT_POOL, (vb_light_rule)d.light_rule, pool, NULL, err);
    if (r != VB_OK)
        goto done;
    V.pool = (const float(*)[3])pool;

    r = make_default_view(&V, &views[0], &st.default_lights_ok, err);
    if (r != VB_OK)
        goto done;

    /* The others: candidate eyes in order, until enough views are kept. */
    eye_search E;
    eye_search_init(&E, &V, d.seed);
    uint32_t have = 0;
    const uint32_t limit = EYE_TRIES_PER_VIEW * d.cameras;
    for (uint32_t k = 0; have < d.cameras && k < limit; k++) {
        int ok;
        r = try_eye(&E, k, &views[1 + have], &ok, &st, err);
        if (r != VB_OK)
            goto done;
        have += ok;
    }
    if (have < d.cameras) {
        r = too_few_views(have, d.cameras, &st, err);
        goto done;
    }
    memcpy(out, views, (1 + (size_t)d.cameras) * sizeof *views);
    if (stats)
        *stats = st;
done:
    free(pool);
    free(views);
    return r;
}
