/* Adaptive receivers: adaptive.h says what and why. */
#include "adaptive.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "parallel.h"
#include "scene.h"
#include "vdsh_shadow.h"

/* The lights' seed: a fixed sequence of its own, whatever the bake's. */
#define ADAPTIVE_LIGHT_SEED 0x61646170746976ull /* "adaptiv" */

static uint64_t edge_key(uint32_t a, uint32_t b)
{
    return a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static int contains(const uint64_t *sorted, size_t n, uint64_t key)
{
    return n && bsearch(&key, sorted, n, sizeof key, cmp_u64) != NULL;
}

/* The candidates: each triangle's longest edge (ties: the lower key), if
 * at least `len` long and not in `judged`; sorted by key (its ends'
 * numbers). Splitting only longest edges (longest-edge bisection, as
 * vb_mesh_refine) keeps the triangles' angles bounded: splitting any edge
 * the error asks for would fan ever thinner slivers around the corner
 * opposite it. *out is malloc'ed. */
static vb_result candidate_edges(const vb_mesh *m, float len, const uint64_t *judged,
                                 size_t judged_n, uint64_t **out, size_t *count, vb_error *err)
{
    const double len2 = (double)len * len;
    uint64_t *k = malloc((size_t)m->triangle_count * sizeof *k + 1);
    if (!k)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "adaptive: out of memory for edges");
    size_t n = 0;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        double best = -1.0;
        uint64_t best_key = 0;
        for (int e = 0; e < 3; e++) {
            uint32_t a = m->indices[3 * (size_t)t + e], b = m->indices[3 * (size_t)t + (e + 1) % 3];
            const float *pa = m->positions + 3 * (size_t)a, *pb = m->positions + 3 * (size_t)b;
            double d2 = 0.0;
            for (int c = 0; c < 3; c++)
                d2 += ((double)pa[c] - pb[c]) * ((double)pa[c] - pb[c]);
            uint64_t key = edge_key(a, b);
            if (a != b && (d2 > best || (d2 == best && key < best_key)))
                best = d2, best_key = key;
        }
        if (best >= len2)
            k[n++] = best_key;
    }
    qsort(k, n, sizeof *k, cmp_u64);
    size_t u = 0;
    for (size_t i = 0; i < n; i++)
        if ((u == 0 || k[i] != k[u - 1]) && !contains(judged, judged_n, k[i]))
            k[u++] = k[i];
    *out = k;
    *count = u;
    return VB_OK;
}

/* A shadow to compare at a point: a fit there (c), or else the
 * interpolation of its triangle's corner fits (corners at pv, barycentric
 * coordinates bary, vdsh_shadow_interior's interp). */
typedef struct shadow_fit {
    const float *c;
    const float *const *corners;
    const float *const *pv;
    const float *bary;
    uint32_t interp;
    float max_distance;
} shadow_fit;

static float fit_shadow(const shadow_fit *s, int order, uint32_t quantity, const float p[3],
                        const float L[3])
{
    if (s->c)
        return vdsh_shadow((uint32_t)order, quantity, s->max_distance, s->c, p, L,
                           VDSH_COMPARE_SMOOTH);
    return vdsh_shadow_interior((uint32_t)order, quantity, s->max_distance, s->interp, s->corners,
                                s->pv, s->bary, L, VDSH_COMPARE_SMOOTH, NULL);
}

/* The mean |shadow a - shadow b| at p (normal n) over the lights above its
 * horizon (below it, unlit either way); `none` when no light is above it.
 * The split test's measure and the noise floor's. */
static double mean_shadow_gap(int order, uint32_t quantity, const float (*lights)[3],
                              uint32_t light_count, const float p[3], const float n[3],
                              const shadow_fit *a, const shadow_fit *b, double none)
{
    double sum = 0.0;
    uint32_t seen = 0;
    for (uint32_t l = 0; l < light_count; l++) {
        const float *L = lights[l];
        float dx = L[0] - p[0], dy = L[1] - p[1], dz = L[2] - p[2];
        if (dx * n[0] + dy * n[1] + dz * n[2] <= 0.0f)
            continue;
        sum += fabs((double)fit_shadow(a, order, quantity, p, L) -
                    fit_shadow(b, order, quantity, p, L));
        seen++;
    }
    return seen ? sum / seen : none;
}

/* Scoring the candidates of one round. */
typedef struct score_job {
    const vb_mesh *fine; /* the tentative mesh: candidate i is vertex base + i */
    uint32_t base;
    const uint64_t *edges;
    const vb_bake_output *b; /* the midpoints' bake: range base.., candidate i's row i */
    const float *coarse_c;   /* the ends' coefficients (order `order`), vertex-major */
    int order;
    uint32_t quantity, interp;
    const float (*lights)[3];
    uint32_t light_count;
    double *error; /* per candidate */
} score_job;

static void score_block(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    score_job *J = ctx;
    (void)worker;
    const size_t nc = (size_t)J->order * J->order;
    const float b[3] = {0.5f, 0.5f, 0.0f};
    for (uint32_t i = begin; i < end; i++) {
        uint32_t a = (uint32_t)(J->edges[i] >> 32), e = (uint32_t)J->edges[i];
        uint32_t v = J->base + i;
        const float *p = J->fine->positions + 3 * (size_t)v;
        const float *n = J->b->normals ? J->b->normals + 3 * (size_t)i /* the range's row i */
                                       : J->fine->normals + 3 * (size_t)v;
        const float *cm = J->b->coeffs[J->order] + nc * i; /* the range's row i: vertex v */
        const float *c[3] = {J->coarse_c + nc * a, J->coarse_c + nc * e, J->coarse_c + nc * e};
        const float *pv[3] = {J->fine->positions + 3 * (size_t)a,
                              J->fine->positions + 3 * (size_t)e,
                              J->fine->positions + 3 * (size_t)e};
        const shadow_fit mid = {.c = cm, .max_distance = J->b->max_distance};
        const shadow_fit ends = {.corners = c,
                                 .pv = pv,
                                 .bary = b,
                                 .interp = J->interp,
                                 .max_distance = J->b->max_distance};
        J->error[i] = mean_shadow_gap(J->order, J->quantity, J->lights, J->light_count, p, n, &mid,
                                      &ends, 0.0);
    }
}

static double edge_len2(const vb_mesh *m, uint64_t key)
{
    const float *a = m->positions + 3 * (size_t)(uint32_t)(key >> 32);
    const float *b = m->positions + 3 * (size_t)(uint32_t)key;
    double d2 = 0.0;
    for (int c = 0; c < 3; c++)
        d2 += ((double)a[c] - b[c]) * ((double)a[c] - b[c]);
    return d2;
}

/* Append `count` rows of `width` floats from src (rows rows[i] - first:
 * src's first row is row `first`) to *dst, which holds `have` rows. */
static int append_rows(float **dst, uint32_t have, const float *src, uint32_t first, size_t width,
                       const uint32_t *rows, uint32_t count)
{
    float *p = realloc(*dst, ((size_t)have + count) * width * sizeof *p + 1);
    if (!p)
        return 0;
    for (uint32_t i = 0; i < count; i++)
        memcpy(p + ((size_t)have + i) * width, src + (size_t)(rows[i] - first) * width,
               width * sizeof *p);
    *dst = p;
    return 1;
}

/* The noise floor (issue 26): the split test compares three fits of
 * traced rays (the midpoint's and its ends'), each with its own rays and
 * training lights, so part of what it measures is the fits' noise, not
 * interpolation error. Measured per bake: a sample of the start mesh's
 * receivers (every (V / n)-th, n = VB_ADAPTIVE_NOISE_SAMPLE at most) is
 * baked a second time under other vertex numbers (a copy of the mesh
 * with the sample moved to its end, in reverse order: other rays and
 * lights, the same seed, origins and orientations), and each receiver's
 * two bakes are compared with the split test's own measure. The floor is a quantile of
 * that spread over the receivers that see a light. */
typedef struct noise_job {
    const vb_mesh *m;
    const uint32_t *sample;
    uint32_t n;
    const vb_bake_output *b;  /* the start's bake (every vertex) */
    const vb_bake_output *b2; /* the sample's second bake: row n-1-k is sample k's */
    int order;
    uint32_t quantity;
    const float (*lights)[3];
    uint32_t light_count;
    double *spread; /* per sample; -1: no light above its horizon */
} noise_job;

static void noise_block(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    noise_job *J = ctx;
    (void)worker;
    const size_t nc = (size_t)J->order * J->order;
    for (uint32_t k = begin; k < end; k++) {
        const uint32_t v = J->sample[k];
        const float *p = J->m->positions + 3 * (size_t)v;
        const float *n =
            J->b->normals ? J->b->normals + 3 * (size_t)v : J->m->normals + 3 * (size_t)v;
        const float *c1 = J->b->coeffs[J->order] + nc * v;
        const float *c2 = J->b2->coeffs[J->order] + nc * (J->n - 1 - k); /* reversed */
        const shadow_fit first = {.c = c1, .max_distance = J->b->max_distance};
        const shadow_fit second = {.c = c2, .max_distance = J->b2->max_distance};
        J->spread[k] = mean_shadow_gap(J->order, J->quantity, J->lights, J->light_count, p, n,
                                       &first, &second, -1.0);
    }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* *floor_out: the quantile VB_ADAPTIVE_NOISE_QUANTILE of the spread (0
 * when no sampled receiver sees a light); *sampled, *rays: what it cost. */
static vb_result noise_floor(const vb_bake_desc *bd0, const vb_mesh *M, const vb_bake_output *B,
                             int order, const float (*lights)[3], uint32_t light_count,
                             double *floor_out, uint32_t *sampled, vb_bake_output *acc,
                             vb_error *err)
{
    *floor_out = 0.0;
    *sampled = 0;
    const uint32_t V = M->vertex_count;
    const uint32_t n = V < VB_ADAPTIVE_NOISE_SAMPLE ? V : VB_ADAPTIVE_NOISE_SAMPLE;
    if (n == 0)
        return VB_OK;
    vb_result r = VB_OK;
    vb_mesh P = {0};
    vb_bake_output R = {0};
    uint32_t *sample = malloc((size_t)n * sizeof *sample + 1);
    uint32_t *where = malloc((size_t)V * sizeof *where + 1); /* old vertex -> P's */
    double *spread = malloc((size_t)n * sizeof *spread + 1);
    uint8_t *in = calloc((size_t)V + 1, 1);
    if (!sample || !where || !spread || !in ||
        (r = vb_mesh_refine(M, 0.0f, &P, err)) != VB_OK) { /* a copy */
        if (r == VB_OK)
            r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "adaptive: out of memory for the noise floor");
        goto done;
    }
    for (uint32_t k = 0; k < n; k++) {
        sample[k] = (uint32_t)(((uint64_t)2 * k + 1) * V / (2 * (uint64_t)n));
        in[sample[k]] = 1;
    }
    /* P: the other vertices first, in order, then the sample. */
    uint32_t j = 0;
    for (uint32_t v = 0; v < V; v++)
        if (!in[v])
            where[v] = j++;
    for (uint32_t k = 0; k < n; k++)
        where[sample[k]] = V - 1 - k; /* reversed: moved even when n = V */
    for (uint32_t v = 0; v < V; v++) {
        memcpy(P.positions + 3 * (size_t)where[v], M->positions + 3 * (size_t)v, 12);
        memcpy(P.normals + 3 * (size_t)where[v], M->normals + 3 * (size_t)v, 12);
    }
    for (size_t i = 0; i < 3 * (size_t)M->triangle_count; i++)
        P.indices[i] = where[M->indices[i]];
    vb_bake_desc bd = *bd0;
    bd.receivers = &P;
    bd.range_begin = V - n;
    bd.range_end = V;
    if ((r = vb_bake_run(&bd, &R, err)) != VB_OK)
        goto done;
    acc->rays_traced += R.rays_traced;
    acc->rays_missed += R.rays_missed;
    acc->seconds += R.seconds;
    noise_job nj = {.m = M,
                    .sample = sample,
                    .n = n,
                    .b = B,
                    .b2 = &R,
                    .order = order,
                    .quantity = B->quantity[order],
                    .lights = lights,
                    .light_count = light_count,
                    .spread = spread};
    if (vb_parallel_for(B->threads, n, 64, noise_block, &nj, NULL, NULL) == 0) {
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "cannot start worker threads");
        goto done;
    }
    uint32_t lit = 0;
    for (uint32_t k = 0; k < n; k++)
        if (spread[k] >= 0.0)
            spread[lit++] = spread[k];
    qsort(spread, lit, sizeof *spread, cmp_double);
    if (lit)
        *floor_out = spread[(size_t)floor(VB_ADAPTIVE_NOISE_QUANTILE * (lit - 1) + 0.5)];
    *sampled = n;
done:
    vb_mesh_free(&P);
    vb_bake_output_free(&R);
    free(sample);
    free(where);
    free(spread);
    free(in);
    return r;
}

/* What every round of vb_bake_adaptive shares. */
typedef struct refinement {
    const vb_adaptive_desc *ad;
    /* the bake's description, its receivers and range set per bake */
    vb_bake_desc bd;
    /* the receivers so far (M), a round's tentative mesh (T: every
     * candidate split) and its next receivers (N: the chosen splits) */
    vb_mesh M, T, N;
    /* M's bake (B), a round's midpoints' (R) */
    vb_bake_output B, R;
    /* the edges judged for good (sorted), a round's candidates (in key
     * order) */
    uint64_t *judged, *cand;
    size_t judged_n, cand_n;
    /* per candidate: its score, its rank */
    double *error;
    vb_ranked *rank;
    /* per round: the chosen midpoints' rows of T; the candidates' ends */
    uint32_t *rows, *pairs;
    /* the lights the scores are taken under */
    float (*lights)[3];
    /* B's quantity per order, held for the rounds' bakes */
    vdsh_quantity quantity[VDSH_ORDER_SLOTS];
    int order;
    uint32_t interp;
    double threshold, t_start;
    vb_adaptive_stats st;
} refinement;

static void refinement_free(refinement *x)
{
    vb_mesh_free(&x->M);
    vb_mesh_free(&x->T);
    vb_mesh_free(&x->N);
    vb_bake_output_free(&x->B);
    vb_bake_output_free(&x->R);
    free(x->judged);
    free(x->cand);
    free(x->error);
    free(x->rank);
    free(x->rows);
    free(x->pairs);
    free(x->lights);
}

static vb_result check_adaptive_desc(const vb_adaptive_desc *ad, const vb_mesh *start,
                                     vb_error *err)
{
    if (!(ad->tolerance >= 0.0f))
        return vb_fail(err, VB_ERR_ARGUMENT, "adaptive: the tolerance must be a number >= 0");
    if (!(ad->min_edge > 0.0f) || !isfinite(ad->min_edge))
        return vb_fail(err, VB_ERR_ARGUMENT, "adaptive: the minimum edge must be > 0");
    if (ad->max_receivers && ad->max_receivers < start->vertex_count)
        return vb_fail(err, VB_ERR_ARGUMENT,
                       "adaptive: the budget of %u receivers is below the %u the refinement "
                       "starts from (raise --max-receivers or --max-edge)",
                       ad->max_receivers, start->vertex_count);
    return VB_OK;
}

/* The cap: the receivers of the uniform refinement to 2 min_edge
 * (adaptive.h), the finest mesh the splits can reach (an edge of at most
 * 2 min_edge is never split); 0 when it cannot be made. At min_edge
 * itself it cost 4x the vertices to count: 13.6 M on 2CylinderEngine.glb
 * from --max-edge 8.4, minutes of the bake's time, for a cap that never
 * binds there. */
static uint32_t uniform_receivers(const vb_mesh *start, float min_edge)
{
    uint32_t n = 0;
    vb_mesh U = {0};
    vb_error uerr;
    if (vb_mesh_refine(start, 2.0f * min_edge, &U, &uerr) == VB_OK)
        n = U.vertex_count;
    vb_mesh_free(&U);
    return n;
}

/* Bake no more than the uniform bake would: the `room` longest
 * candidates that fit, in key order. */
static vb_result keep_longest(refinement *x, uint64_t room, vb_error *err)
{
    free(x->rank);
    if (!(x->rank = malloc(x->cand_n * sizeof *x->rank + 1)))
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    for (size_t i = 0; i < x->cand_n; i++)
        x->rank[i] = (vb_ranked){edge_len2(&x->M, x->cand[i]), (uint32_t)i};
    qsort(x->rank, x->cand_n, sizeof *x->rank, vb_ranked_cmp);
    uint8_t *keep = calloc(x->cand_n + 1, 1);
    if (!keep)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    for (uint64_t k = 0; k < room; k++)
        keep[x->rank[k].index] = 1;
    size_t u = 0;
    for (size_t i = 0; i < x->cand_n; i++)
        if (keep[i])
            x->cand[u++] = x->cand[i];
    free(keep);
    x->cand_n = u;
    return VB_OK;
}

/* R's counts added to B's. */
static void add_counts(vb_bake_output *B, const vb_bake_output *R)
{
    B->rays_traced += R->rays_traced;
    B->rays_missed += R->rays_missed;
    B->degenerate_receivers += R->degenerate_receivers;
    B->flipped_normals += R->flipped_normals;
    B->moved_origins += R->moved_origins;
    B->origins.moved += R->origins.moved;
    B->origins.flagged += R->origins.flagged;
    B->origins.ties += R->origins.ties;
    B->origins.skipped_zero_area += R->origins.skipped_zero_area;
    B->origins.probe_rays += R->origins.probe_rays;
    B->origins.seconds += R->origins.seconds;
    B->seconds += R->seconds;
}

/* The tentative mesh T: every candidate split (pairs: their ends), and
 * the bake of its midpoints, the rows from V, in R. */
static vb_result bake_midpoints(refinement *x, uint32_t V, vb_error *err)
{
    free(x->pairs);
    if (!(x->pairs = malloc(x->cand_n * 2 * sizeof *x->pairs + 1)))
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    for (size_t i = 0; i < x->cand_n; i++)
        x->pairs[2 * i] = (uint32_t)(x->cand[i] >> 32), x->pairs[2 * i + 1] = (uint32_t)x->cand[i];
    vb_mesh_free(&x->T);
    vb_result r = vb_mesh_split_edges(&x->M, x->pairs, (uint32_t)x->cand_n, &x->T, err);
    if (r != VB_OK)
        return r;
    vb_bake_output_free(&x->R);
    x->bd.receivers = &x->T;
    x->bd.range_begin = V;
    x->bd.range_end = x->T.vertex_count;
    if ((r = vb_bake_run(&x->bd, &x->R, err)) != VB_OK)
        return r;
    x->st.rounds++;
    x->st.candidates += (uint32_t)x->cand_n;
    add_counts(&x->B, &x->R);
    return VB_OK;
}

/* Every candidate's score (score_block) into x->error. */
static vb_result score_candidates(refinement *x, uint32_t V, vb_error *err)
{
    free(x->error);
    free(x->rank);
    x->error = malloc(x->cand_n * sizeof *x->error + 1);
    x->rank = malloc(x->cand_n * sizeof *x->rank + 1);
    if (!x->error || !x->rank)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    score_job sj = {.fine = &x->T,
                    .base = V,
                    .edges = x->cand,
                    .b = &x->R,
                    .coarse_c = x->B.coeffs[x->order],
                    .order = x->order,
                    .quantity = x->quantity[x->order],
                    .interp = x->interp,
                    .lights = (const float(*)[3])x->lights,
                    .light_count = x->st.lights,
                    .error = x->error};
    if (vb_parallel_for(x->B.threads, (uint32_t)x->cand_n, 64, score_block, &sj, NULL, NULL) == 0)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "cannot start worker threads");
    return VB_OK;
}

/* Split those above the tolerance, largest first within the budget; the
 * others are judged for good. *s: how many, their ends the first of
 * x->pairs, their rows of T in x->rows (in key order: the new vertices'
 * order). */
static vb_result choose_splits(refinement *x, uint32_t V, uint32_t *s, vb_error *err)
{
    const vb_adaptive_desc *ad = x->ad;
    uint32_t over = 0;
    for (size_t i = 0; i < x->cand_n; i++)
        if (x->error[i] > x->threshold)
            x->rank[over++] = (vb_ranked){x->error[i], (uint32_t)i};
    qsort(x->rank, over, sizeof *x->rank, vb_ranked_cmp);
    uint32_t take = over;
    if (ad->max_receivers && take > ad->max_receivers - V) {
        take = ad->max_receivers - V;
        x->st.budget_reached = 1;
    }
    uint8_t *chosen = calloc(x->cand_n + 1, 1);
    uint64_t *nj = realloc(x->judged, (x->judged_n + x->cand_n) * sizeof *x->judged + 1);
    free(x->rows);
    x->rows = malloc((size_t)take * sizeof *x->rows + 1);
    if (!chosen || !nj || !x->rows) {
        free(chosen);
        if (nj)
            x->judged = nj;
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    }
    x->judged = nj;
    for (uint32_t k = 0; k < take; k++)
        chosen[x->rank[k].index] = 1;
    uint32_t n = 0;
    for (size_t i = 0; i < x->cand_n; i++) {
        if (chosen[i]) {
            x->pairs[2 * n] = x->pairs[2 * i], x->pairs[2 * n + 1] = x->pairs[2 * i + 1];
            x->rows[n++] = V + (uint32_t)i;
        } else if (x->error[i] <= x->threshold) {
            x->judged[x->judged_n++] = x->cand[i];
        }
    }
    free(chosen);
    qsort(x->judged, x->judged_n, sizeof *x->judged, cmp_u64);
    *s = n;
    return VB_OK;
}

/* The s chosen splits made: M becomes N, whose new vertices keep their
 * midpoint bakes (and oriented normals). */
static vb_result keep_midpoints(refinement *x, uint32_t V, uint32_t s, vb_error *err)
{
    vb_mesh_free(&x->N);
    vb_result r = vb_mesh_split_edges(&x->M, x->pairs, s, &x->N, err);
    if (r != VB_OK)
        return r;
    vb_bake_output *B = &x->B;
    const vb_bake_output *R = &x->R;
    int ok = 1;
    for (int o = 1; o <= VDSH_MAX_ORDER; o++)
        if (B->coeffs[o])
            ok &= append_rows(&B->coeffs[o], V, R->coeffs[o], R->range_begin, (size_t)o * o,
                              x->rows, s); /* R holds the midpoints' rows only */
    if (B->normals)
        ok &= append_rows(&B->normals, V, R->normals, R->range_begin, 3, x->rows, s);
    if (!ok)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    for (uint32_t k = 0; k < s; k++)
        memcpy(x->N.normals + 3 * ((size_t)V + k),
               R->normals ? R->normals + 3 * (size_t)(x->rows[k] - R->range_begin)
                          : x->T.normals + 3 * (size_t)x->rows[k],
               3 * sizeof(float));
    vb_mesh_free(&x->M);
    x->M = x->N;
    memset(&x->N, 0, sizeof x->N);
    B->vertex_count = B->range_end = x->M.vertex_count;
    return VB_OK;
}

/* One round: the candidates (within the budget and the uniform cap),
 * their midpoints baked and scored, the chosen ones split. *more: whether
 * another round may split more. */
static vb_result refine_round(refinement *x, int *more, vb_error *err)
{
    const vb_adaptive_desc *ad = x->ad;
    vb_adaptive_stats *st = &x->st;
    const uint32_t V = x->M.vertex_count;
    *more = 0;
    if (ad->max_receivers && V >= ad->max_receivers) {
        st->budget_reached = 1;
        return VB_OK;
    }
    free(x->cand);
    x->cand = NULL;
    vb_result r = candidate_edges(&x->M, 2.0f * ad->min_edge, x->judged, x->judged_n, &x->cand,
                                  &x->cand_n, err);
    if (r != VB_OK || x->cand_n == 0)
        return r;
    const uint64_t baked = (uint64_t)st->start_receivers + st->candidates;
    if (st->uniform_receivers && baked + x->cand_n > st->uniform_receivers) {
        uint64_t room = st->uniform_receivers > baked ? st->uniform_receivers - baked : 0;
        st->uniform_reached = 1;
        if (room == 0)
            return VB_OK;
        if ((r = keep_longest(x, room, err)) != VB_OK)
            return r;
    }
    uint32_t s = 0;
    if ((r = bake_midpoints(x, V, err)) != VB_OK || (r = score_candidates(x, V, err)) != VB_OK ||
        (r = choose_splits(x, V, &s, err)) != VB_OK)
        return r;
    st->last_split = s;
    if (ad->on_round)
        ad->on_round(ad->user, st->rounds, V + s, (uint32_t)x->cand_n, s, vb_now() - x->t_start);
    if (s == 0)
        return VB_OK;
    if ((r = keep_midpoints(x, V, s, err)) != VB_OK)
        return r;
    *more = !(st->budget_reached || st->uniform_reached);
    return VB_OK;
}

vb_result vb_bake_adaptive(const vb_bake_desc *bake, const vb_mesh *start,
                           const vb_adaptive_desc *ad, vb_mesh *receivers, vb_bake_output *out,
                           vb_adaptive_stats *stats, vb_error *err)
{
    vb_result r = check_adaptive_desc(ad, start, err);
    if (r != VB_OK)
        return r;
    refinement x = {.ad = ad, .st = {.start_receivers = start->vertex_count}};
    vb_adaptive_stats *st = &x.st;
    x.t_start = vb_now();
    if ((r = vb_mesh_refine(start, 0.0f, &x.M, err)) != VB_OK) /* a copy */
        return r;

    x.bd = *bake;
    x.bd.receivers = &x.M;
    x.bd.range_begin = x.bd.range_end = 0;
    if ((r = vb_bake_run(&x.bd, &x.B, err)) != VB_OK)
        goto done;
    if (x.B.normals) /* the oriented normals: midpoints interpolate them */
        memcpy(x.M.normals, x.B.normals, (size_t)x.M.vertex_count * 3 * sizeof *x.M.normals);
    x.order = x.B.max_order;
    memcpy(x.quantity, x.B.quantity, sizeof x.quantity);
    x.bd.order_quantity = x.quantity;
    x.interp = vdsh_runtime_interp((uint32_t)x.order, x.quantity[x.order]);

    st->lights = ad->lights ? ad->lights : VB_ADAPTIVE_LIGHTS;
    if (!(x.lights = malloc((size_t)st->lights * sizeof *x.lights))) {
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    if ((r = vb_scene_place_lights(bake->scene, ADAPTIVE_LIGHT_SEED, st->lights, x.lights, NULL,
                                   err)) != VB_OK)
        goto done;
    st->uniform_receivers = uniform_receivers(start, ad->min_edge);
    /* The split threshold: the tolerance above the fits' noise floor
     * (tolerance 0 asks for every split: no floor). */
    x.threshold = ad->tolerance;
    if (isfinite(ad->tolerance) && ad->tolerance > 0.0f) {
        if ((r = noise_floor(&x.bd, &x.M, &x.B, x.order, (const float(*)[3])x.lights, st->lights,
                             &st->noise_floor, &st->noise_sample, &x.B, err)) != VB_OK)
            goto done;
        x.threshold += st->noise_floor;
    }
    st->threshold = x.threshold;
    const uint32_t max_rounds = st->max_rounds =
        ad->max_rounds ? ad->max_rounds : VB_ADAPTIVE_ROUNDS;
    for (int more = 1; more && isfinite(ad->tolerance) && st->rounds < max_rounds;)
        if ((r = refine_round(&x, &more, err)) != VB_OK)
            goto done;
    if (isfinite(ad->tolerance) && st->rounds == max_rounds && st->last_split > 0 &&
        !st->budget_reached && !st->uniform_reached) {
        /* The round limit stopped a refinement still splitting: how many
         * edges the next round would have judged. */
        free(x.cand);
        x.cand = NULL;
        if ((r = candidate_edges(&x.M, 2.0f * ad->min_edge, x.judged, x.judged_n, &x.cand,
                                 &x.cand_n, err)) != VB_OK)
            goto done;
        st->pending = (uint32_t)x.cand_n;
        st->rounds_reached = x.cand_n > 0;
    }
    x.B.vertex_count = x.B.range_end = x.M.vertex_count;
    *receivers = x.M;
    memset(&x.M, 0, sizeof x.M);
    *out = x.B;
    memset(&x.B, 0, sizeof x.B);
    if (stats)
        *stats = *st;
    r = VB_OK;
done:
    refinement_free(&x);
    return r;
}
