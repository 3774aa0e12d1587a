/*
 * eval.c - the evaluator core (eval.h): receivers, held-out samples, the
 * ground-truth ray cast and the scores.
 *
 * The story of a run: pick the receivers (a hashed sample of vertices,
 * area-weighted interior points) and give each its truth origin; workers
 * take blocks of receivers, trace each one's held-out directions in 16-wide
 * packets and score every stream against the truth into per-receiver sums
 * (and per-worker integer histograms); the calling thread then reduces the
 * sums in receiver order, so no result depends on which worker did what.
 */
#include "eval.h"
#include "parallel.h"

#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "bake.h"
#include "sampling.h"
#include "vdsh_sh.h"
#include "vdsh_shadow.h"
#include "vdsh_light.h"

#define BLOCK 32 /* receivers per work item */

/* Every purpose gets its own random stream from the one seed, so that
 * adding directions does not move the lights, and so that no stream can
 * coincide with the bake's jitter even when the seeds are equal. */
enum {
    PURPOSE_DIRECTIONS = 0x44495253u,  /* "DIRS" */
    PURPOSE_LIGHTS = 0x4c474854u,      /* "LGHT" */
    PURPOSE_VERTICES = 0x56525453u,    /* "VRTS" */
    PURPOSE_INTERIOR = 0x494e5452u,    /* "INTR" */
    PURPOSE_SCENE_LIGHTS = 0x53434e4cu /* "SCNL" */
};

uint64_t vb_eval_purpose_seed(uint64_t seed, uint32_t purpose)
{
    uint64_t z = seed ^ ((uint64_t)purpose * 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* ---- distance-error histogram ------------------------------------------
 * Bin 0: exactly 0; bin 1: (0, 1e-6); then 100 bins per decade up to 1e4;
 * the last bin: 1e4 and above (and NaN). Percentiles are read at a bin's
 * geometric centre: 2.3% resolution, plenty for p50/p90/p99, and integer
 * counts merge across workers in any order to the same totals. */
#define HIST_LOG_MIN (-6)
#define HIST_PER_DECADE 100
#define HIST_DECADES 10
#define HIST_BINS (2 + HIST_PER_DECADE * HIST_DECADES + 1)

static inline int hist_bin(float e)
{
    if (e == 0.0f)
        return 0;
    if (e < 1e-6f)
        return 1;
    if (!(e < 1e4f))
        return HIST_BINS - 1;
    int b = (int)floorf((log10f(e) - HIST_LOG_MIN) * HIST_PER_DECADE);
    b = b < 0 ? 0 : b > HIST_PER_DECADE * HIST_DECADES - 1 ? HIST_PER_DECADE * HIST_DECADES - 1 : b;
    return 2 + b;
}

static double hist_value(int b)
{
    if (b == 0)
        return 0.0;
    if (b == 1)
        return 1e-6;
    if (b == HIST_BINS - 1)
        return 1e4;
    return pow(10.0, HIST_LOG_MIN + (b - 2 + 0.5) / HIST_PER_DECADE);
}

static double hist_quantile(const uint64_t *h, double q)
{
    uint64_t total = 0;
    for (int b = 0; b < HIST_BINS; b++)
        total += h[b];
    if (total == 0)
        return NAN;
    /* The smallest value with at least q of the samples at or below it. */
    double want = q * (double)total;
    uint64_t run = 0;
    for (int b = 0; b < HIST_BINS; b++) {
        run += h[b];
        if ((double)run >= want && h[b] > 0)
            return hist_value(b);
    }
    return hist_value(HIST_BINS - 1);
}

/* The held-out directions of one receiver, one packet at a time: the
 * hemisphere grid around its normal with the evaluator's own jitter. The
 * run and vb_eval_directions (which the tests compare with the bake's
 * directions) both call this. */
static inline void heldout_packet(const vb_dirgrid *g, uint32_t packet, uint64_t dir_seed,
                                  uint32_t id, const float n[3], float *dx, float *dy, float *dz,
                                  int *valid)
{
    vb_dirgrid_packet(g, packet, dir_seed, id, n, dx, dy, dz, valid);
}

/* ---- receivers ---------------------------------------------------------- */

typedef struct receiver {
    uint32_t kind;
    uint32_t index; /* vertex, or interior point number */
    uint32_t id;    /* the random streams' receiver number */
    uint32_t triangle;
    float bary[3];
    float position[3]; /* scene units */
    float normal[3];   /* unit */
    float origin[3];   /* truth ray origin, traced frame */
    float near;        /* ~0 distance (origins.h), scene units */
} receiver;

/* One receiver's sums for one stream, in a fixed order. */
typedef struct racc {
    double sq;                    /* squared relative distance errors */
    double abs;                   /* relative distance errors */
    double mae, mae_bin;          /* |s_hat - s_ideal| */
    uint32_t n;                   /* samples */
    uint32_t vis, fals, fals_bin; /* d_T >= d_L; s_hat < .5; D < d_L */
    uint32_t occ, leak;           /* s_ideal < .5; s_hat > .5 */
    uint32_t occ_bin, leak_bin;   /* d_T < d_L; D >= d_L */
    uint32_t ringing;             /* D == 0: the sum rang to <= 0 */
} racc;

/* One receiver's sums for one stream under the scene lights. */
typedef struct sacc {
    double mae, mae_bin;
    uint32_t n;
    uint32_t vis, fals, fals_bin;   /* d_T >= d_L; s_hat < .5; D < d_L */
    uint32_t occ, hit, leak;        /* s_ideal < .5; s_hat < .5; s_hat > .5 */
    uint32_t occ_bin, hit_bin;      /* d_T < d_L; D < d_L */
    double part[VB_EVAL_MAE_PARTS]; /* mae split by pair class (eval.h) */
} sacc;

typedef struct rtruth {
    uint32_t n, near_zero, escaped;
} rtruth;

typedef struct job {
    const vb_eval_desc *d;
    const vdsh_file *f;
    const vb_scene *scene;
    const vb_dirgrid *grid;
    const receiver *rec;
    uint32_t rec_count;
    uint32_t streams;
    racc *acc;  /* rec_count * streams */
    sacc *sacc; /* rec_count * streams: scene lights */
    uint32_t light_count;
    const float (*lights)[3];       /* scene units */
    const float (*lights_local)[3]; /* traced frame */
    rtruth *truth;                  /* rec_count */
    uint64_t *hist;                 /* per worker: KINDS * streams * HIST_BINS */
    uint64_t dir_seed, light_seed;
    float max_local, inv_scale, max_distance, floor_dist;
} job;

/* The stream's coefficients at a receiver: decoded at a vertex,
 * interpolated inside a triangle. */
static void receiver_coeffs(const vdsh_file *f, const vdsh_stream *s, const receiver *r, float *c)
{
    if (r->kind == VB_EVAL_VERTICES)
        vdsh_stream_decode(s, r->index, c);
    else
        vb_eval_interpolate(f, s, r->triangle, r->bary, NULL, NULL, c);
}

/* A scene-light pair's class (vb_eval_scene_metrics.mae_part). */
static inline int mae_part(int vis, int occ, float s_hat)
{
    if (vis)
        return s_hat < 0.5f ? VB_EVAL_PART_FALSE : VB_EVAL_PART_LIT_PARTIAL;
    if (occ)
        return s_hat < 0.5f ? VB_EVAL_PART_DRAWN : VB_EVAL_PART_MISSED;
    return VB_EVAL_PART_PENUMBRA;
}

/* A receiver's streams, ready to evaluate: each stream's coefficients at
 * the receiver and, at an interior point, its triangle's corners with how
 * the runtime interpolates between them. */
typedef struct rstreams {
    float coef[VDSH_MAX_STREAMS][VDSH_MAX_COEFFS];
    float vc[VDSH_MAX_STREAMS][3][VDSH_MAX_COEFFS];
    const float *pv[3];
    uint32_t interp[VDSH_MAX_STREAMS];
    int corners;
} rstreams;

/* What stream s draws at receiver r for a light at lp, in direction w and
 * at distance dl from the point (the truth dt under --oracle): the
 * distance it compares in *D, the smooth shadow in *s_hat and, if b_hat is
 * not NULL, the binary one. */
static void stream_shadow(const job *J, const rstreams *R, const receiver *r, uint32_t s,
                          const float w[3], const float lp[3], float dl, float dt, float *D,
                          float *s_hat, float *b_hat)
{
    const vdsh_stream *st = &J->f->streams[s];
    if (J->d->oracle || !R->corners) {
        *D = J->d->oracle
                 ? dt
                 : vdsh_stream_distance(st->order, st->quantity, J->max_distance, R->coef[s], w);
        *s_hat = vdsh_shadow_compare(*D, dl, VDSH_COMPARE_SMOOTH);
        if (b_hat)
            *b_hat = vdsh_shadow_compare(*D, dl, VDSH_COMPARE_BINARY);
        return;
    }
    const float *cv[3] = {R->vc[s][0], R->vc[s][1], R->vc[s][2]};
    *s_hat = vdsh_shadow_interior(st->order, st->quantity, J->max_distance, R->interp[s], cv, R->pv,
                                  r->bary, lp, VDSH_COMPARE_SMOOTH, D);
    if (b_hat)
        *b_hat = vdsh_shadow_interior(st->order, st->quantity, J->max_distance, R->interp[s], cv,
                                      R->pv, r->bary, lp, VDSH_COMPARE_BINARY, NULL);
}

/* The scene lights at one receiver: every light above its horizon, the
 * truth traced from the receiver's origin toward it (16 at a time), the
 * streams evaluated toward it on the path the runtime draws them. */
static void eval_scene_lights(job *J, uint32_t ri, const rstreams *R)
{
    const receiver *r = J->rec + ri;
    const uint32_t S = J->streams;
    sacc *acc = J->sacc + (size_t)ri * S;
    const float scale = J->scene->scale;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (uint32_t first = 0; first < J->light_count; first += VB_PACKET) {
        struct RTCRayHit16 rh __attribute__((aligned(64)));
        int valid[VB_PACKET] __attribute__((aligned(64)));
        float dl[VB_PACKET], w[VB_PACKET][3];
        for (int k = 0; k < VB_PACKET; k++) {
            uint32_t l = first + (uint32_t)k;
            valid[k] = 0;
            vb_ray16_init(&rh, k, r->origin, 0.0f);
            rh.ray.dir_x[k] = 0.0f, rh.ray.dir_y[k] = 0.0f, rh.ray.dir_z[k] = 1.0f;
            dl[k] = 0.0f;
            if (l >= J->light_count)
                continue;
            const float *L = J->lights[l], *Ll = J->lights_local[l];
            float v[3] = {L[0] - r->position[0], L[1] - r->position[1], L[2] - r->position[2]};
            float d = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            if (!(d > 0.0f) ||
                v[0] * r->normal[0] + v[1] * r->normal[1] + v[2] * r->normal[2] <= 0.0f)
                continue; /* at the receiver, or below its horizon: not lit */
            for (int a = 0; a < 3; a++)
                w[k][a] = v[a] / d;
            /* The truth ray runs from the origin to the light itself. */
            float o2l[3] = {Ll[0] - r->origin[0], Ll[1] - r->origin[1], Ll[2] - r->origin[2]};
            float dlocal = sqrtf(o2l[0] * o2l[0] + o2l[1] * o2l[1] + o2l[2] * o2l[2]);
            if (!(dlocal > 0.0f))
                continue;
            rh.ray.dir_x[k] = o2l[0] / dlocal, rh.ray.dir_y[k] = o2l[1] / dlocal;
            rh.ray.dir_z[k] = o2l[2] / dlocal;
            rh.ray.tfar[k] = dlocal;
            dl[k] = d;
            valid[k] = -1;
        }
        rtcIntersect16(valid, J->scene->scene, &ctx, &rh);
        for (int k = 0; k < VB_PACKET; k++) {
            if (!valid[k])
                continue;
            /* Nothing before the light: visible (d_T is larger than d_L). */
            const float dt =
                rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID ? rh.ray.tfar[k] / scale : INFINITY;
            const float L0 = dl[k];
            const float s_ideal = vdsh_shadow_compare(dt, L0, VDSH_COMPARE_SMOOTH);
            const int vis = dt >= L0, occ = s_ideal < 0.5f, occ_bin = dt < L0;
            const float *L = J->lights[first + (uint32_t)k];
            for (uint32_t s = 0; s < S; s++) {
                float D, s_hat;
                stream_shadow(J, R, r, s, w[k], L, L0, dt, &D, &s_hat, NULL);
                const int b_dark = D < L0;
                sacc *a = acc + s;
                const float err_ = fabsf(s_hat - s_ideal);
                a->n++;
                a->mae += err_;
                a->part[mae_part(vis, occ, s_hat)] += err_;
                a->mae_bin += fabsf((float)!b_dark - (float)vis);
                a->vis += vis;
                a->fals += vis && s_hat < 0.5f;
                a->fals_bin += vis && b_dark;
                a->occ += occ;
                a->hit += occ && s_hat < 0.5f;
                a->leak += occ && s_hat > 0.5f;
                a->occ_bin += occ_bin;
                a->hit_bin += occ_bin && b_dark;
            }
        }
    }
}

static void eval_receiver(job *J, uint32_t ri, uint64_t *hist)
{
    const receiver *r = J->rec + ri;
    const vdsh_file *f = J->f;
    const uint32_t S = J->streams;
    rstreams R;
    for (uint32_t s = 0; s < S; s++)
        receiver_coeffs(f, &f->streams[s], r, R.coef[s]);
    /* Interior points: their triangle's corners, for the per-vertex
     * interpolation modes. */
    R.corners = r->kind == VB_EVAL_INTERIOR;
    R.pv[0] = R.pv[1] = R.pv[2] = NULL;
    for (uint32_t s = 0; s < S && R.corners; s++) {
        const uint32_t *t = f->indices + 3 * (size_t)r->triangle;
        for (int k = 0; k < 3; k++) {
            vdsh_stream_decode(&f->streams[s], t[k], R.vc[s][k]);
            R.pv[k] = f->positions + 3 * (size_t)t[k];
        }
        R.interp[s] = J->d->interp == VB_EVAL_INTERP_RUNTIME
                          ? vdsh_runtime_interp(f->streams[s].order, f->streams[s].quantity)
                          : J->d->interp - 1;
    }
    racc *acc = J->acc + (size_t)ri * S;
    rtruth *tr = J->truth + ri;
    uint64_t *h = hist + (size_t)r->kind * S * HIST_BINS;

    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;

    for (uint32_t pk = 0; pk < J->grid->packet_count; pk++) {
        struct RTCRayHit16 rh __attribute__((aligned(64)));
        int valid[VB_PACKET] __attribute__((aligned(64)));
        heldout_packet(J->grid, pk, J->dir_seed, r->id, r->normal, rh.ray.dir_x, rh.ray.dir_y,
                       rh.ray.dir_z, valid);
        for (int k = 0; k < VB_PACKET; k++)
            vb_ray16_init(&rh, k, r->origin, J->max_local);
        rtcIntersect16(valid, J->scene->scene, &ctx, &rh);

        for (int k = 0; k < VB_PACKET; k++) {
            if (!valid[k])
                continue;
            const uint32_t sample = pk * VB_PACKET + (uint32_t)k;
            const float w[3] = {rh.ray.dir_x[k], rh.ray.dir_y[k], rh.ray.dir_z[k]};
            const int hit = rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
            /* Clamped like the bake: a miss is max_distance. */
            const float dt = hit ? rh.ray.tfar[k] * J->inv_scale : J->max_distance;
            tr->n++;
            tr->escaped += !hit;
            tr->near_zero += dt < r->near;

            /* The light: vdsh_light_u (vdsh_shadow.h); 1 - u1 is in (0, 1]. */
            float u1, u2;
            vb_hash2(J->light_seed, r->id, sample, &u1, &u2);
            const float dl = vdsh_light_u_f(1.0f - u1) * 2.0f * dt;
            const float s_ideal = vdsh_shadow_compare(dt, dl, VDSH_COMPARE_SMOOTH);
            const float b_ideal = vdsh_shadow_compare(dt, dl, VDSH_COMPARE_BINARY);
            const int vis = dt >= dl, occ = s_ideal < 0.5f, occ_bin = b_ideal < 0.5f;
            const float floor_ = dt > J->floor_dist ? dt : J->floor_dist;

            /* The light, for the per-vertex modes: along w from the point. */
            const float lp[3] = {r->position[0] + w[0] * dl, r->position[1] + w[1] * dl,
                                 r->position[2] + w[2] * dl};
            for (uint32_t s = 0; s < S; s++) {
                float D, s_hat, b_hat;
                stream_shadow(J, &R, r, s, w, lp, dl, dt, &D, &s_hat, &b_hat);
                const float e = fabsf(D - dt) / floor_;
                racc *a = acc + s;
                a->n++;
                a->sq += (double)e * e;
                a->abs += e;
                a->mae += fabsf(s_hat - s_ideal);
                a->mae_bin += fabsf(b_hat - b_ideal);
                a->vis += vis;
                a->fals += vis && s_hat < 0.5f;
                a->fals_bin += vis && b_hat < 0.5f;
                a->occ += occ;
                a->leak += occ && s_hat > 0.5f;
                a->occ_bin += occ_bin;
                a->leak_bin += occ_bin && b_hat > 0.5f;
                a->ringing += D == 0.0f && dt > 0.0f;
                h[(size_t)s * HIST_BINS + hist_bin(e)]++;
            }
        }
    }
    if (J->light_count)
        eval_scene_lights(J, ri, &R);
}

static void eval_block(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    job *J = ctx;
    uint64_t *hist = J->hist + (size_t)worker * VB_EVAL_KINDS * J->streams * HIST_BINS;
    for (uint32_t i = begin; i < end; i++)
        eval_receiver(J, i, hist);
}

static void eval_progress(void *user, uint32_t done, uint32_t total)
{
    const job *J = user;
    J->d->progress(J->d->progress_user, done, total);
}

/* ---- public pieces ------------------------------------------------------- */

void vb_eval_interpolate(const vdsh_file *f, const vdsh_stream *s, uint32_t tri,
                         const float bary[3], float position[3], float normal[3], float *coeffs)
{
    const uint32_t *ix = f->indices + 3 * (size_t)tri;
    if (position || normal) {
        float p[3] = {0, 0, 0}, n[3] = {0, 0, 0};
        for (int i = 0; i < 3; i++) {
            const float *a = f->positions + 3 * (size_t)ix[0];
            const float *b = f->positions + 3 * (size_t)ix[1];
            const float *c = f->positions + 3 * (size_t)ix[2];
            const float *na = f->normals + 3 * (size_t)ix[0];
            const float *nb = f->normals + 3 * (size_t)ix[1];
            const float *nc = f->normals + 3 * (size_t)ix[2];
            p[i] = bary[0] * a[i] + bary[1] * b[i] + bary[2] * c[i];
            n[i] = bary[0] * na[i] + bary[1] * nb[i] + bary[2] * nc[i];
        }
        float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int i = 0; i < 3; i++) {
            if (position)
                position[i] = p[i];
            if (normal)
                normal[i] = len > 1e-6f ? n[i] / len : 0.0f;
        }
    }
    if (coeffs && s) {
        float ca[VDSH_MAX_COEFFS], cb[VDSH_MAX_COEFFS], cc[VDSH_MAX_COEFFS];
        vdsh_stream_decode(s, ix[0], ca);
        vdsh_stream_decode(s, ix[1], cb);
        vdsh_stream_decode(s, ix[2], cc);
        int nc = (int)(s->order * s->order);
        for (int i = 0; i < nc; i++)
            coeffs[i] = bary[0] * ca[i] + bary[1] * cb[i] + bary[2] * cc[i];
    }
}

double *vb_eval_area_cdf(const vdsh_file *f, double *total)
{
    uint32_t T = f->header.triangle_count;
    double *cdf = malloc(((size_t)T + 1) * sizeof *cdf);
    if (!cdf)
        return NULL;
    double sum = 0.0;
    for (uint32_t t = 0; t < T; t++) {
        const uint32_t *ix = f->indices + 3 * (size_t)t;
        const float *a = f->positions + 3 * (size_t)ix[0];
        const float *b = f->positions + 3 * (size_t)ix[1];
        const float *c = f->positions + 3 * (size_t)ix[2];
        double e1[3], e2[3];
        for (int i = 0; i < 3; i++)
            e1[i] = (double)b[i] - a[i], e2[i] = (double)c[i] - a[i];
        double x = e1[1] * e2[2] - e1[2] * e2[1];
        double y = e1[2] * e2[0] - e1[0] * e2[2];
        double z = e1[0] * e2[1] - e1[1] * e2[0];
        sum += 0.5 * sqrt(x * x + y * y + z * z);
        cdf[t] = sum;
    }
    for (uint32_t t = 0; t < T; t++)
        cdf[t] = sum > 0.0 ? cdf[t] / sum : 0.0;
    if (total)
        *total = sum;
    return cdf;
}

int vb_eval_interior_point(const double *cdf, uint32_t triangle_count, uint64_t seed, uint32_t j,
                           uint32_t *tri, float bary[3])
{
    if (triangle_count == 0 || !(cdf[triangle_count - 1] > 0.0))
        return 0;
    uint64_t s = vb_eval_purpose_seed(seed, PURPOSE_INTERIOR);
    float u1, u2, u3, u4;
    vb_hash2(s, j, 0, &u1, &u2);
    vb_hash2(s, j, 1, &u3, &u4);
    /* 48 bits for the triangle choice: millions of triangles. */
    double u = u1 + u3 * (1.0 / 16777216.0);
    /* First triangle whose cumulative area exceeds u: zero-area triangles
     * (cdf equal to the previous one) can never be chosen. */
    uint32_t lo = 0, hi = triangle_count - 1;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (cdf[mid] > u)
            hi = mid;
        else
            lo = mid + 1;
    }
    /* Uniform in the triangle (Osada et al.); the half-step keeps r1, r2 in
     * (0, 1), so the point is strictly inside, never on an edge. */
    double r1 = u2 + 0.5 / 16777216.0, r2 = u4 + 0.5 / 16777216.0;
    double sr = sqrt(r1);
    *tri = lo;
    bary[0] = (float)(1.0 - sr);
    bary[1] = (float)(sr * (1.0 - r2));
    bary[2] = (float)(sr * r2);
    return 1;
}

uint32_t vb_eval_directions(uint64_t seed, uint32_t directions, uint32_t id, const float n[3],
                            float *d, uint32_t max)
{
    if (seed == 0)
        seed = VB_EVAL_DEFAULT_SEED;
    if (directions == 0)
        directions = VB_EVAL_DEFAULT_DIRECTIONS;
    vb_dirgrid g = {0};
    if (vb_dirgrid_create(directions, 1, &g, NULL) != VB_OK)
        return 0;
    uint64_t ds = vb_eval_purpose_seed(seed, PURPOSE_DIRECTIONS);
    uint32_t got = 0;
    for (uint32_t pk = 0; pk < g.packet_count; pk++) {
        float x[16], y[16], z[16];
        int valid[16];
        heldout_packet(&g, pk, ds, id, n, x, y, z, valid);
        for (int k = 0; k < 16; k++) {
            if (!valid[k])
                continue;
            if (got < max) {
                d[3 * got] = x[k], d[3 * got + 1] = y[k], d[3 * got + 2] = z[k];
            }
            got++;
        }
    }
    vb_dirgrid_destroy(&g);
    return got;
}

void vb_eval_result_free(vb_eval_result *r)
{
    if (!r)
        return;
    for (int k = 0; k < VB_EVAL_KINDS; k++) {
        free(r->metrics[k]);
        free(r->scene[k]);
    }
    free(r->lights);
    free(r->per_vertex);
    memset(r, 0, sizeof *r);
}

/* ---- reduction ----------------------------------------------------------- */

static int is_zero_normal(const float n[3])
{
    return n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f;
}

static void describe(const receiver *r, const rtruth *t, const racc *a, vb_eval_receiver *out)
{
    memset(out, 0, sizeof *out);
    out->index = r->index;
    out->triangle = r->kind == VB_EVAL_VERTICES ? UINT32_MAX : r->triangle;
    memcpy(out->bary, r->bary, sizeof out->bary);
    memcpy(out->position, r->position, sizeof out->position);
    memcpy(out->normal, r->normal, sizeof out->normal);
    out->near_zero = t->n ? (double)t->near_zero / t->n : NAN;
    out->escaped = t->n ? (double)t->escaped / t->n : NAN;
    if (a) {
        out->shadow_mae = a->n ? a->mae / a->n : NAN;
        out->distance_rms = a->n ? sqrt(a->sq / a->n) : NAN;
        out->false_shadow = a->vis ? (double)a->fals / a->vis : NAN;
    } else {
        out->shadow_mae = out->distance_rms = out->false_shadow = NAN;
    }
}

/* Ratio sum(a) / sum(b) over receivers and its standard error, linearised
 * with receivers as clusters: var = n / (n - 1) * sum (a_i - r b_i)^2 / B^2. */
typedef struct ratio {
    double a, b, res;
} ratio;

static void ratio_add(ratio *q, double a, double b)
{
    q->a += a, q->b += b;
}
static double ratio_value(const ratio *q)
{
    return q->b > 0 ? q->a / q->b : NAN;
}
static void ratio_res(ratio *q, double a, double b)
{
    double r = q->b > 0 ? q->a / q->b : 0.0, e = a - r * b;
    q->res += e * e;
}
static double ratio_se(const ratio *q, uint32_t n)
{
    if (!(q->b > 0) || n < 2)
        return NAN;
    return sqrt((double)n / (n - 1) * q->res) / q->b;
}

static int cmp_double(const void *x, const void *y)
{
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

/* Linear interpolation between order statistics of sorted v[0..n-1]. */
static double quantile_sorted(const double *v, size_t n, double q)
{
    if (n == 0)
        return NAN;
    double pos = q * (double)(n - 1);
    size_t i = (size_t)pos;
    if (i + 1 >= n)
        return v[n - 1];
    return v[i] + (pos - (double)i) * (v[i + 1] - v[i]);
}

static vb_result reduce(const job *J, uint32_t first, uint32_t count, int kind, unsigned workers,
                        uint32_t worst_n, vb_eval_metrics *m, vb_error *err)
{
    const uint32_t S = J->streams;
    double *mae = malloc(((size_t)count + 1) * sizeof *mae);
    vb_ranked *items = malloc(((size_t)count + 1) * sizeof *items);
    if (!mae || !items) {
        free(mae);
        free(items);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for the scores");
    }
    for (uint32_t s = 0; s < S; s++) {
        vb_eval_metrics *o = m + s;
        memset(o, 0, sizeof *o);
        ratio sq = {0}, ab = {0}, mae_r = {0}, mb = {0}, fa = {0}, le = {0}, fb = {0}, lb = {0};
        uint32_t n_used = 0, nm = 0;
        uint64_t ringing = 0;
        /* Pass 0 sums the ratios; pass 1, with the sums known, the
         * residuals of those with a standard error (ratio_se: not the
         * mean distance, ab). */
        for (int pass = 0; pass < 2; pass++) {
            for (uint32_t i = first; i < first + count; i++) {
                const racc *a = J->acc + (size_t)i * S + s;
                if (a->n == 0)
                    continue;
                void (*f)(ratio *, double, double) = pass ? ratio_res : ratio_add;
                f(&sq, a->sq, a->n);
                if (!pass)
                    ratio_add(&ab, a->abs, a->n);
                f(&mae_r, a->mae, a->n);
                f(&mb, a->mae_bin, a->n);
                f(&fa, a->fals, a->vis);
                f(&le, a->leak, a->occ);
                f(&fb, a->fals_bin, a->vis);
                f(&lb, a->leak_bin, a->occ_bin);
                if (pass)
                    continue;
                n_used++;
                o->visible += a->vis;
                o->occluded += a->occ;
                o->occluded_binary += a->occ_bin;
                ringing += a->ringing;
                mae[nm] = a->mae / a->n;
                items[nm].key = mae[nm];
                items[nm].index = i;
                nm++;
            }
        }
        o->samples = (uint64_t)sq.b;
        o->ringing = o->samples ? (double)ringing / o->samples : NAN;
        double ms = ratio_value(&sq);
        o->distance_rms = sqrt(ms);
        /* Delta method: se(sqrt(x)) = se(x) / (2 sqrt(x)). */
        o->distance_rms_se =
            ms > 0 ? ratio_se(&sq, n_used) / (2.0 * o->distance_rms) : (n_used > 1 ? 0.0 : NAN);
        o->distance_mean = ratio_value(&ab);
        o->shadow_mae = ratio_value(&mae_r), o->shadow_mae_se = ratio_se(&mae_r, n_used);
        o->binary_mae = ratio_value(&mb), o->binary_mae_se = ratio_se(&mb, n_used);
        o->false_shadow = ratio_value(&fa), o->false_shadow_se = ratio_se(&fa, n_used);
        o->light_leak = ratio_value(&le), o->light_leak_se = ratio_se(&le, n_used);
        o->binary_false_shadow = ratio_value(&fb);
        o->binary_false_shadow_se = ratio_se(&fb, n_used);
        o->binary_light_leak = ratio_value(&lb);
        o->binary_light_leak_se = ratio_se(&lb, n_used);

        uint64_t h[HIST_BINS] = {0};
        for (unsigned w = 0; w < workers; w++) {
            const uint64_t *src =
                J->hist + (((size_t)w * VB_EVAL_KINDS + kind) * S + s) * HIST_BINS;
            for (int b = 0; b < HIST_BINS; b++)
                h[b] += src[b];
        }
        o->distance_p50 = hist_quantile(h, 0.50);
        o->distance_p90 = hist_quantile(h, 0.90);
        o->distance_p99 = hist_quantile(h, 0.99);

        qsort(mae, nm, sizeof *mae, cmp_double);
        o->receiver_mae_p50 = quantile_sorted(mae, nm, 0.50);
        o->receiver_mae_p90 = quantile_sorted(mae, nm, 0.90);
        o->receiver_mae_p99 = quantile_sorted(mae, nm, 0.99);
        qsort(items, nm, sizeof *items, vb_ranked_cmp);
        o->worst_count = nm < worst_n ? nm : worst_n;
        for (uint32_t w = 0; w < o->worst_count; w++) {
            uint32_t i = items[w].index;
            describe(J->rec + i, J->truth + i, J->acc + (size_t)i * S + s, &o->worst[w]);
        }
    }
    free(mae);
    free(items);
    return VB_OK;
}

/* The scene-light scores of one kind of receiver, summed in receiver
 * order. */
static void reduce_scene(const job *J, uint32_t first, uint32_t count, vb_eval_scene_metrics *m)
{
    const uint32_t S = J->streams;
    for (uint32_t s = 0; s < S; s++) {
        vb_eval_scene_metrics *o = m + s;
        memset(o, 0, sizeof *o);
        ratio mae = {0}, fa = {0}, rc = {0}, le = {0}, mb = {0}, fb = {0}, rb = {0};
        uint32_t n_used = 0;
        for (int pass = 0; pass < 2; pass++)
            for (uint32_t i = first; i < first + count; i++) {
                const sacc *a = J->sacc + (size_t)i * S + s;
                if (a->n == 0)
                    continue;
                void (*f)(ratio *, double, double) = pass ? ratio_res : ratio_add;
                n_used += !pass;
                f(&mae, a->mae, a->n);
                f(&fa, a->fals, a->vis);
                f(&rc, a->hit, a->occ);
                f(&le, a->leak, a->occ);
                f(&mb, a->mae_bin, a->n);
                f(&fb, a->fals_bin, a->vis);
                f(&rb, a->hit_bin, a->occ_bin);
                if (!pass) {
                    o->visible += a->vis, o->occluded += a->occ;
                    for (int c = 0; c < VB_EVAL_MAE_PARTS; c++)
                        o->mae_part[c] += a->part[c];
                }
            }
        for (int c = 0; c < VB_EVAL_MAE_PARTS; c++)
            o->mae_part[c] = mae.b > 0 ? o->mae_part[c] / mae.b : NAN;
        o->pairs = (uint64_t)mae.b;
        o->shadow_mae = ratio_value(&mae), o->shadow_mae_se = ratio_se(&mae, n_used);
        o->false_shadow = ratio_value(&fa), o->false_shadow_se = ratio_se(&fa, n_used);
        o->recall = ratio_value(&rc), o->recall_se = ratio_se(&rc, n_used);
        o->light_leak = ratio_value(&le), o->light_leak_se = ratio_se(&le, n_used);
        o->binary_mae = ratio_value(&mb);
        o->binary_false_shadow = ratio_value(&fb);
        o->binary_recall = ratio_value(&rb);
    }
}

static vb_result list_escaping(const job *J, uint32_t first, uint32_t count, uint32_t max,
                               vb_eval_truth *t, vb_error *err)
{
    vb_ranked *items = malloc(((size_t)count + 1) * sizeof *items);
    if (!items)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for the scores");
    uint32_t n = 0;
    for (uint32_t i = first; i < first + count; i++) {
        const rtruth *x = J->truth + i;
        if (x->escaped > 0) {
            items[n].key = (double)x->escaped / x->n;
            items[n++].index = i;
        }
    }
    qsort(items, n, sizeof *items, vb_ranked_cmp);
    t->escaping_listed = n < max ? n : max;
    for (uint32_t w = 0; w < t->escaping_listed; w++) {
        uint32_t i = items[w].index;
        describe(J->rec + i, J->truth + i, NULL, &t->escaping_list[w]);
    }
    free(items);
    return VB_OK;
}

/* ---- the run ------------------------------------------------------------- */

static int cmp_ranked_key(const void *x, const void *y)
{
    const vb_ranked *a = x, *b = y;
    if (a->key != b->key)
        return a->key < b->key ? -1 : 1;
    return (a->index > b->index) - (a->index < b->index);
}

static int cmp_u32(const void *x, const void *y)
{
    uint32_t a = *(const uint32_t *)x, b = *(const uint32_t *)y;
    return (a > b) - (a < b);
}

/* The vertices to evaluate, in index order: all, or the `want` whose hash
 * is smallest (a uniform sample without replacement that does not depend
 * on anything but the seed and the vertex count). */
static vb_result pick_vertices(uint32_t V, uint32_t want, uint64_t seed, uint32_t **out,
                               uint32_t *count, vb_error *err)
{
    uint32_t n = (want == 0 || want >= V) ? V : want;
    uint32_t *v = malloc(((size_t)n + 1) * sizeof *v);
    if (!v)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for %u receivers", n);
    if (n == V) {
        for (uint32_t i = 0; i < V; i++)
            v[i] = i;
    } else {
        vb_ranked *it = malloc((size_t)V * sizeof *it);
        if (!it) {
            free(v);
            return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for %u vertices", V);
        }
        uint64_t s = vb_eval_purpose_seed(seed, PURPOSE_VERTICES);
        for (uint32_t i = 0; i < V; i++) {
            float a, b;
            vb_hash2(s, i, 0, &a, &b);
            it[i].key = a + b * (1.0 / 16777216.0);
            it[i].index = i;
        }
        qsort(it, V, sizeof *it, cmp_ranked_key);
        for (uint32_t i = 0; i < n; i++)
            v[i] = it[i].index;
        free(it);
        qsort(v, n, sizeof *v, cmp_u32); /* back to index order */
    }
    *out = v;
    *count = n;
    return VB_OK;
}

/* ---- vb_eval_run, step by step ------------------------------------------- */

/* One vb_eval_run: the resolved description, what the run allocates
 * (run_free frees it, also half-built) and the result it fills. */
typedef struct eval_run {
    vb_eval_desc d;
    float diag; /* the file's bounds' diagonal, else the scene's */
    double t0;
    vb_dirgrid grid;
    uint32_t *vsel, nv;     /* the vertices picked */
    float *vorigin, *vnear; /* per vertex: truth origins, near distances */
    float (*lights_local)[3];
    double *cdf;
    receiver *rec; /* the vertices', then the interior points' */
    uint32_t nr;
    uint32_t count[VB_EVAL_KINDS], skipped[VB_EVAL_KINDS];
    job *J;
    unsigned started;
    vb_eval_result o;
} eval_run;

/* The diagonal of the file's bounds (the bake's, vdsh_light.h); the
 * scene's when they are empty. */
static float file_diagonal(const vdsh_file *f, const vb_scene *scene)
{
    float diag = vdsh_free_diagonal(f->header.bounds_min, f->header.bounds_max);
    return diag > 0.0f ? diag : scene->diagonal;
}

/* The description checked against the file, its defaults filled in; the
 * run's clock started. */
static vb_result resolve_desc(eval_run *e, vb_error *err)
{
    vb_eval_desc *d = &e->d;
    const vdsh_file *f = d->file;
    if (!f || !d->scene)
        return vb_fail(err, VB_ERR_ARGUMENT, "nothing to evaluate: no file or no scene");
    if (f->stream_count == 0 && !d->oracle)
        return vb_fail(err, VB_ERR_ARGUMENT, "the file has no coefficient streams");
    if (f->stream_count > VDSH_MAX_STREAMS)
        return vb_fail(err, VB_ERR_ARGUMENT, "too many streams (%u)", f->stream_count);
    for (uint32_t s = 0; s < f->stream_count; s++)
        if (f->streams[s].order < 1 || f->streams[s].order > VDSH_MAX_ORDER)
            return vb_fail(err, VB_ERR_ARGUMENT, "stream %u: order %u out of range", s,
                           f->streams[s].order);
    if (d->seed == 0)
        d->seed = VB_EVAL_DEFAULT_SEED;
    if (d->directions == 0)
        d->directions = VB_EVAL_DEFAULT_DIRECTIONS;
    if (d->worst == 0)
        d->worst = VB_EVAL_DEFAULT_WORST;
    if (d->worst > VB_EVAL_MAX_WORST)
        d->worst = VB_EVAL_MAX_WORST;
    if (d->interior > VB_EVAL_MAX_RECEIVERS)
        return vb_fail(err, VB_ERR_ARGUMENT, "at most %u interior points, not %u",
                       VB_EVAL_MAX_RECEIVERS, d->interior);
    if (d->interior > 0 && f->header.triangle_count == 0)
        d->interior = 0; /* a point cloud has no inside: vertices only */
    d->threads = vb_parallel_threads(d->threads);
    e->t0 = vb_now();
    e->diag = file_diagonal(f, d->scene);
    return VB_OK;
}

/* The held-out directions' grid and the vertices picked. */
static vb_result pick_receivers(eval_run *e, vb_error *err)
{
    const vb_eval_desc *d = &e->d;
    vb_result r = vb_dirgrid_create(d->directions, 1, &e->grid, err);
    if (r != VB_OK)
        return r;
    return pick_vertices(d->file->header.vertex_count, d->points, d->seed, &e->vsel, &e->nv, err);
}

/* The picked vertices as receivers, with their truth origins (those with
 * no normal are skipped and counted). */
static vb_result vertex_receivers(eval_run *e, vb_error *err)
{
    const vb_eval_desc *d = &e->d;
    const vdsh_file *f = d->file;
    const uint32_t V = f->header.vertex_count;
    e->vorigin = malloc((size_t)V * 3 * sizeof *e->vorigin);
    e->vnear = malloc((size_t)V * sizeof *e->vnear + 1);
    e->rec = calloc((size_t)e->nv + d->interior + 1, sizeof *e->rec);
    if (!e->vorigin || !e->vnear || !e->rec)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for %u receivers",
                       e->nv + d->interior);
    vb_mesh m = {.vertex_count = V,
                 .triangle_count = f->header.triangle_count,
                 .positions = (float *)f->positions,
                 .normals = (float *)f->normals,
                 .indices = (uint32_t *)f->indices};
    vb_result r = vb_ray_origins(&m, d->scene, d->threads, e->vorigin, e->vnear, NULL, err);
    if (r != VB_OK)
        return r;
    uint32_t nr = 0;
    for (uint32_t i = 0; i < e->nv; i++) {
        uint32_t v = e->vsel[i];
        const float *n = f->normals + 3 * (size_t)v;
        if (is_zero_normal(n)) {
            e->skipped[VB_EVAL_VERTICES]++;
            continue;
        }
        receiver *x = e->rec + nr++;
        x->kind = VB_EVAL_VERTICES;
        x->index = v;
        x->id = v;
        x->triangle = UINT32_MAX;
        x->bary[0] = 1.0f;
        memcpy(x->position, f->positions + 3 * (size_t)v, sizeof x->position);
        memcpy(x->normal, n, sizeof x->normal);
        memcpy(x->origin, e->vorigin + 3 * (size_t)v, sizeof x->origin);
        x->near = e->vnear[v];
    }
    e->nr = e->count[VB_EVAL_VERTICES] = nr;
    return VB_OK;
}

/* The mean edge length of triangle t, for its interior points' near
 * distance. */
static double mean_edge(const vdsh_file *f, uint32_t t)
{
    double edges = 0.0;
    for (int k = 0; k < 3; k++) {
        const float *a = f->positions + 3 * (size_t)f->indices[3 * (size_t)t + k];
        const float *b = f->positions + 3 * (size_t)f->indices[3 * (size_t)t + (k + 1) % 3];
        edges +=
            sqrt(((double)a[0] - b[0]) * (a[0] - b[0]) + ((double)a[1] - b[1]) * (a[1] - b[1]) +
                 ((double)a[2] - b[2]) * (a[2] - b[2]));
    }
    return edges / 3.0;
}

/* Area-weighted interior points as receivers, after the vertices. */
static vb_result interior_receivers(eval_run *e, vb_error *err)
{
    const vb_eval_desc *d = &e->d;
    const vdsh_file *f = d->file;
    if (d->interior == 0)
        return VB_OK;
    double area = 0.0;
    e->cdf = vb_eval_area_cdf(f, &area);
    if (!e->cdf)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for the triangle areas");
    for (uint32_t j = 0; j < d->interior && area > 0.0; j++) {
        receiver x = {.kind = VB_EVAL_INTERIOR, .index = j, .id = VB_EVAL_INTERIOR_ID(j)};
        vb_eval_interior_point(e->cdf, f->header.triangle_count, d->seed, j, &x.triangle, x.bary);
        vb_eval_interpolate(f, NULL, x.triangle, x.bary, x.position, x.normal, NULL);
        if (is_zero_normal(x.normal)) {
            e->skipped[VB_EVAL_INTERIOR]++;
            continue;
        }
        float p[3];
        vb_scene_to_local(d->scene, x.position, p);
        vb_offset_origin(p, x.normal, x.origin);
        x.near = vb_receiver_near(d->scene->diagonal, (float)mean_edge(f, x.triangle));
        e->rec[e->nr++] = x;
    }
    e->count[VB_EVAL_INTERIOR] = e->nr - e->count[VB_EVAL_VERTICES];
    return VB_OK;
}

/* The job the workers read: the receivers and their sums. */
static vb_result create_job(eval_run *e, vb_error *err)
{
    const vb_eval_desc *d = &e->d;
    const uint32_t S = d->file->stream_count, nr = e->nr;
    free(e->vorigin); /* the receivers have theirs */
    free(e->vnear);
    e->vorigin = NULL, e->vnear = NULL;
    job *J = e->J = calloc(1, sizeof *J);
    if (!J)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    J->d = d;
    J->f = d->file;
    J->scene = d->scene;
    J->grid = &e->grid;
    J->rec = e->rec;
    J->rec_count = nr;
    J->streams = S;
    J->acc = calloc((size_t)nr * (S ? S : 1) + 1, sizeof *J->acc);
    J->truth = calloc((size_t)nr + 1, sizeof *J->truth);
    J->hist = calloc((size_t)d->threads * VB_EVAL_KINDS * (S ? S : 1) * HIST_BINS, sizeof *J->hist);
    if (!J->acc || !J->truth || !J->hist)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for %u receivers", nr);
    return VB_OK;
}

/* The scene lights: placed once, scored at every receiver. */
static vb_result place_scene_lights(eval_run *e, vb_error *err)
{
    const vb_eval_desc *d = &e->d;
    const uint32_t S = d->file->stream_count;
    vb_eval_result *o = &e->o;
    job *J = e->J;
    uint32_t nl = d->lights ? d->lights : 32;
    o->lights = malloc(((size_t)nl + 1) * sizeof *o->lights);
    e->lights_local = malloc(((size_t)nl + 1) * sizeof *e->lights_local);
    J->sacc = calloc((size_t)e->nr * (S ? S : 1) + 1, sizeof *J->sacc);
    if (!o->lights || !e->lights_local || !J->sacc)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for the scene lights");
    uint64_t seed = vb_eval_purpose_seed(d->seed, PURPOSE_SCENE_LIGHTS);
    vb_result r = vb_scene_place_lights_rule(d->scene, seed, nl, (vb_light_rule)d->light_rule,
                                             o->lights, &o->light_candidates, err);
    if (r != VB_OK)
        return r;
    float lo[3], hi[3];
    const int grown = vb_scene_light_region(d->scene, lo, hi, NULL);
    /* a given region (the file's lreg, --light-region) is reported where
     * the rule places in the region (not grown, around, shell: their own
     * boxes) and is not "grown around a closed object" */
    o->light_region_given = d->scene->region_given && d->light_rule < VB_LIGHTS_GROWN;
    o->light_region_grown = grown && !d->scene->region_given;
    memcpy(o->light_region_min, lo, sizeof lo);
    memcpy(o->light_region_max, hi, sizeof hi);
    o->light_count = nl;
    for (uint32_t l = 0; l < nl; l++)
        vb_scene_to_local(d->scene, o->lights[l], e->lights_local[l]);
    J->light_count = nl;
    J->lights = (const float(*)[3])o->lights;
    J->lights_local = (const float(*)[3])e->lights_local;
    return VB_OK;
}

/* Trace and score every receiver on the workers. */
static vb_result trace_receivers(eval_run *e, vb_error *err)
{
    const vb_eval_desc *d = &e->d;
    const vdsh_file *f = d->file;
    job *J = e->J;
    J->dir_seed = vb_eval_purpose_seed(d->seed, PURPOSE_DIRECTIONS);
    J->light_seed = vb_eval_purpose_seed(d->seed, PURPOSE_LIGHTS);
    J->max_distance = f->header.max_distance;
    J->max_local = f->header.max_distance * d->scene->scale;
    J->inv_scale = 1.0f / d->scene->scale;
    J->floor_dist = 0.01f * e->diag;
    e->started = vb_parallel_for(d->threads, e->nr, BLOCK, eval_block, J,
                                 d->progress ? eval_progress : NULL, J);
    if (e->started == 0)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "cannot start worker threads");
    return VB_OK;
}

/* Per kind of receiver, the truth's counts, the degenerate and escaping
 * receivers and every stream's scores, reduced in receiver order. */
static vb_result reduce_kinds(eval_run *e, vb_error *err)
{
    const vb_eval_desc *d = &e->d;
    const uint32_t S = d->file->stream_count;
    vb_eval_result *o = &e->o;
    const job *J = e->J;
    o->stream_count = S;
    for (int k = 0; k < VB_EVAL_KINDS; k++) {
        o->metrics[k] = calloc(S ? S : 1, sizeof *o->metrics[k]);
        o->scene[k] = calloc(S ? S : 1, sizeof *o->scene[k]);
        if (!o->metrics[k] || !o->scene[k])
            return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    }
    for (int k = 0; k < VB_EVAL_KINDS; k++) {
        uint32_t first = k == VB_EVAL_VERTICES ? 0 : e->count[VB_EVAL_VERTICES];
        vb_eval_truth *t = &o->truth[k];
        t->receivers = e->count[k];
        t->skipped = e->skipped[k];
        for (uint32_t i = first; i < first + e->count[k]; i++) {
            const rtruth *x = J->truth + i;
            t->rays += x->n;
            t->escaped += x->escaped;
            t->near_zero += x->near_zero;
            if (x->n > 0 && x->near_zero >= VB_EVAL_DEGENERATE * x->n) {
                if (t->degenerate_listed < d->worst)
                    describe(e->rec + i, x, NULL, &t->degenerate_list[t->degenerate_listed++]);
                t->degenerate++;
            }
        }
        vb_result r = list_escaping(J, first, e->count[k], d->worst, t, err);
        if (r != VB_OK)
            return r;
        r = reduce(J, first, e->count[k], k, e->started, d->worst, o->metrics[k], err);
        if (r != VB_OK)
            return r;
        reduce_scene(J, first, e->count[k], o->scene[k]);
    }
    return VB_OK;
}

/* With per_vertex: each vertex's errors (NaN where it was not picked). */
static vb_result per_vertex_errors(eval_run *e, vb_error *err)
{
    const vb_eval_desc *d = &e->d;
    const uint32_t V = d->file->header.vertex_count, S = d->file->stream_count;
    vb_eval_result *o = &e->o;
    const job *J = e->J;
    if (!d->per_vertex)
        return VB_OK;
    o->per_vertex_fields = VB_EVAL_PV_TRUTH_FIELDS + VB_EVAL_PV_STREAM_FIELDS * S;
    o->per_vertex = malloc(((size_t)V * o->per_vertex_fields + 1) * sizeof *o->per_vertex);
    if (!o->per_vertex)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for the per-vertex errors");
    for (size_t i = 0; i < (size_t)V * o->per_vertex_fields; i++)
        o->per_vertex[i] = NAN;
    for (uint32_t i = 0; i < e->count[VB_EVAL_VERTICES]; i++) {
        const rtruth *x = J->truth + i;
        float *pv = o->per_vertex + (size_t)e->rec[i].index * o->per_vertex_fields;
        if (x->n == 0)
            continue;
        pv[VB_EVAL_PV_NEAR_ZERO] = (float)x->near_zero / (float)x->n;
        pv[VB_EVAL_PV_ESCAPED] = (float)x->escaped / (float)x->n;
        for (uint32_t s = 0; s < S; s++) {
            const racc *a = J->acc + (size_t)i * S + s;
            float *q = pv + VB_EVAL_PV_TRUTH_FIELDS + VB_EVAL_PV_STREAM_FIELDS * s;
            q[VB_EVAL_PV_DISTANCE_RMS] = (float)sqrt(a->sq / a->n);
            q[VB_EVAL_PV_SHADOW_MAE] = (float)(a->mae / a->n);
            q[VB_EVAL_PV_FALSE_SHADOW] = a->vis ? (float)a->fals / (float)a->vis : NAN;
            q[VB_EVAL_PV_LIGHT_LEAK] = a->occ ? (float)a->leak / (float)a->occ : NAN;
            q[VB_EVAL_PV_BINARY_MAE] = (float)(a->mae_bin / a->n);
        }
    }
    return VB_OK;
}

/* The result's settings, then the result moved out of the run. */
static void finish_result(eval_run *e, vb_eval_result *out)
{
    vb_eval_result *o = &e->o;
    o->seed = e->d.seed;
    o->directions = e->grid.count;
    o->diagonal = e->diag;
    o->max_distance = e->d.file->header.max_distance;
    o->oracle = e->d.oracle;
    o->threads = e->started;
    o->seconds = vb_now() - e->t0;
    *out = *o;
    memset(o, 0, sizeof *o);
}

static void run_free(eval_run *e)
{
    free(e->lights_local);
    free(e->rec);
    free(e->cdf);
    vb_dirgrid_destroy(&e->grid);
    free(e->vorigin);
    free(e->vnear);
    free(e->vsel);
    vb_eval_result_free(&e->o);
    if (e->J) {
        free(e->J->sacc);
        free(e->J->acc);
        free(e->J->truth);
        free(e->J->hist);
    }
    free(e->J);
}

vb_result vb_eval_run(const vb_eval_desc *desc, vb_eval_result *out, vb_error *err)
{
    eval_run e = {.d = *desc};
    vb_result r;
    if ((r = resolve_desc(&e, err)) == VB_OK && (r = pick_receivers(&e, err)) == VB_OK &&
        (r = vertex_receivers(&e, err)) == VB_OK && (r = interior_receivers(&e, err)) == VB_OK &&
        (r = create_job(&e, err)) == VB_OK && (r = place_scene_lights(&e, err)) == VB_OK &&
        (r = trace_receivers(&e, err)) == VB_OK && (r = reduce_kinds(&e, err)) == VB_OK &&
        (r = per_vertex_errors(&e, err)) == VB_OK)
        finish_result(&e, out);
    run_free(&e);
    return r;
}

/* ---- scene reconstruction ------------------------------------------------ */

static void hex(const uint8_t *h, int n, char *out)
{
    static const char digits[] = "0123456789abcdef";
    for (int i = 0; i < n; i++) {
        out[2 * i] = digits[h[i] >> 4];
        out[2 * i + 1] = digits[h[i] & 15];
    }
    out[2 * n] = '\0';
}

static int regular_file(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

char *vb_eval_find_source(const char *name, const char *vdsh_path)
{
    if (strncmp(name, "builtin:", 8) == 0 || regular_file(name))
        return strdup(name);
    if (name[0] == '/')
        return NULL;
    char *tmp = strdup(vdsh_path);
    if (!tmp)
        return NULL;
    const char *dir = dirname(tmp);
    size_t n = strlen(dir) + strlen(name) + 2;
    char *p = malloc(n);
    if (p)
        snprintf(p, n, "%s/%s", dir, name);
    free(tmp);
    if (p && regular_file(p))
        return p;
    free(p);
    return NULL;
}

vb_result vb_eval_scene_create(const vdsh_file *f, const char *const *paths, uint32_t count,
                               const vb_eval_scene_desc *desc, vb_scene **out, vb_error *err)
{
    vb_eval_scene_desc d = desc ? *desc : (vb_eval_scene_desc){0};
    if (count != f->source_count)
        return vb_fail(err, VB_ERR_ARGUMENT, "%u mesh(es) given but the bake used %u source(s)",
                       count, f->source_count);
    if (count == 0)
        return vb_fail(err, VB_ERR_INVALID,
                       "the file records no source meshes: give the bake's meshes");
    /* the sources loaded as the bake loaded them: welded, turned from
     * their up axis into +y and split at creases (HEAD load_flags) */
    vb_load_desc ld = {.weld = (f->header.load_flags & VDSH_LOAD_WELD) != 0,
                       .up_axis =
                           (int)((f->header.load_flags & VDSH_LOAD_UP_MASK) >> VDSH_LOAD_UP_SHIFT),
                       .crease = (int)VDSH_LOAD_CREASE(f->header.load_flags)};
    vb_mesh occ = {0};
    vb_result r = VB_OK;
    for (uint32_t i = 0; i < count; i++) {
        vb_mesh m = {0};
        vb_source_info info;
        r = vb_mesh_load(paths[i], &ld, &m, &info, err);
        if (r != VB_OK)
            goto fail;
        const vdsh_source *src = &f->sources[i];
        /* a bake before 2026-11-30 recorded a .gltf's hash without its
         * external buffers (formats/VDSH.md, SRCS): still accepted, with a
         * warning that the buffers could not be checked */
        int file_only =
            (info.file_size != info.size || memcmp(info.file_sha256, info.sha256, 32) != 0) &&
            info.file_size == src->size && memcmp(info.file_sha256, src->sha256, 32) == 0;
        if (file_only && d.warn) {
            char msg[768];
            snprintf(msg, sizeof msg,
                     "source %u of %u, '%s': the bake recorded the hash of the .gltf alone "
                     "(a bake before 2026-11-30): its external buffers were not checked, only "
                     "the counts and bounds",
                     i + 1, count, paths[i]);
            d.warn(d.warn_user, msg);
        }
        if (!file_only && (info.size != src->size || memcmp(info.sha256, src->sha256, 32) != 0)) {
            char now[65], then[65], msg[768];
            hex(info.sha256, 32, now);
            hex(src->sha256, 32, then);
            snprintf(msg, sizeof msg,
                     "source %u of %u, '%s' (recorded as '%s'), is not the mesh the bake "
                     "used: %llu bytes, SHA-256 %.16s..., but the bake recorded %llu "
                     "bytes, SHA-256 %.16s...",
                     i + 1, count, paths[i], src->name, (unsigned long long)info.size, now,
                     (unsigned long long)src->size, then);
            if (!d.allow_mismatch) {
                vb_mesh_free(&m);
                r = vb_fail(err, VB_ERR_INVALID, "%s", msg);
                goto fail;
            }
            if (d.warn)
                d.warn(d.warn_user, msg);
        }
        r = vb_mesh_append(&occ, &m, err);
        vb_mesh_free(&m);
        if (r != VB_OK)
            goto fail;
    }
    if (!d.allow_mismatch && (occ.vertex_count != f->header.occluder_vertex_count ||
                              occ.triangle_count != f->header.occluder_triangle_count)) {
        r = vb_fail(err, VB_ERR_INVALID,
                    "the sources load as %u %s and %u triangle%s, but the bake traced "
                    "%u and %u (the mesh loader changed since the bake?)",
                    occ.vertex_count, vdsh_plural(occ.vertex_count, "vertex", "vertices"),
                    occ.triangle_count, vdsh_s(occ.triangle_count), f->header.occluder_vertex_count,
                    f->header.occluder_triangle_count);
        goto fail;
    }
    float lo[3], hi[3];
    vb_mesh_bounds(&occ, lo, hi);
    if (!d.allow_mismatch && (memcmp(lo, f->header.bounds_min, sizeof lo) != 0 ||
                              memcmp(hi, f->header.bounds_max, sizeof hi) != 0)) {
        r = vb_fail(err, VB_ERR_INVALID,
                    "the sources' bounds (%g %g %g .. %g %g %g) differ from the bake's",
                    (double)lo[0], (double)lo[1], (double)lo[2], (double)hi[0], (double)hi[1],
                    (double)hi[2]);
        goto fail;
    }
    /* The bake's corner origins (scene.h corner_lift): its load flags
     * record a crease only when one split a vertex. */
    vb_scene_desc sd = {.robust = !d.fast,
                        .threads = d.threads,
                        .corner_lift = VDSH_LOAD_CREASE(f->header.load_flags) > 0};
    r = vb_scene_create(&occ, &sd, out, err);
    if (r == VB_OK && f->has_light_box && /* where the bake's lights went (lreg) */
        (r = vb_scene_set_light_region(*out, f->light_box.min, f->light_box.max,
                                       "the file's light region (lreg)", err)) != VB_OK) {
        vb_scene_destroy(*out);
        *out = NULL;
    }
fail:
    vb_mesh_free(&occ);
    return r;
}
