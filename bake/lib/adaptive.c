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

vb_result vb_bake_adaptive(const vb_bake_desc *bake, const vb_mesh *start,
                           const vb_adaptive_desc *ad, vb_mesh *receivers, vb_bake_output *out,
                           vb_adaptive_stats *stats, vb_error *err)
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
    vb_adaptive_stats st = {.start_receivers = start->vertex_count};
    vb_mesh M = {0}, T = {0}, N = {0};
    vb_bake_output B = {0}, R = {0};
    uint64_t *judged = NULL, *cand = NULL;
    size_t judged_n = 0, cand_n = 0;
    double *error = NULL;
    vb_ranked *rank = NULL;
    uint32_t *rows = NULL, *pairs = NULL; /* per round: new rows; the candidates' ends */
    float(*lights)[3] = NULL;
    const double t_start = vb_now();
    vb_result r = vb_mesh_refine(start, 0.0f, &M, err); /* a copy */
    if (r != VB_OK)
        return r;

    vb_bake_desc bd = *bake;
    bd.receivers = &M;
    bd.range_begin = bd.range_end = 0;
    if ((r = vb_bake_run(&bd, &B, err)) != VB_OK)
        goto done;
    if (B.normals) /* the oriented normals: midpoints interpolate them */
        memcpy(M.normals, B.normals, (size_t)M.vertex_count * 3 * sizeof *M.normals);
    const int order = B.max_order;
    vdsh_quantity quantity[VDSH_ORDER_SLOTS];
    memcpy(quantity, B.quantity, sizeof quantity);
    bd.order_quantity = quantity;
    const uint32_t interp = vdsh_runtime_interp((uint32_t)order, quantity[order]);

    st.lights = ad->lights ? ad->lights : VB_ADAPTIVE_LIGHTS;
    if (!(lights = malloc((size_t)st.lights * sizeof *lights))) {
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    if ((r = vb_scene_place_lights(bake->scene, ADAPTIVE_LIGHT_SEED, st.lights, lights, NULL,
                                   err)) != VB_OK)
        goto done;

    /* The cap: the uniform refinement to 2 min_edge (adaptive.h), the
     * finest mesh the splits can reach (an edge of at most 2 min_edge is
     * never split). At min_edge itself it cost 4x the vertices to count:
     * 13.6 M on 2CylinderEngine.glb from --max-edge 8.4, minutes of the
     * bake's time, for a cap that never binds there. */
    {
        vb_mesh U = {0};
        vb_error uerr;
        if (vb_mesh_refine(start, 2.0f * ad->min_edge, &U, &uerr) == VB_OK)
            st.uniform_receivers = U.vertex_count;
        vb_mesh_free(&U);
    }
    /* The split threshold: the tolerance above the fits' noise floor
     * (tolerance 0 asks for every split: no floor). */
    double threshold = ad->tolerance;
    if (isfinite(ad->tolerance) && ad->tolerance > 0.0f) {
        if ((r = noise_floor(&bd, &M, &B, order, (const float(*)[3])lights, st.lights,
                             &st.noise_floor, &st.noise_sample, &B, err)) != VB_OK)
            goto done;
        threshold += st.noise_floor;
    }
    st.threshold = threshold;
    const uint32_t max_rounds = st.max_rounds =
        ad->max_rounds ? ad->max_rounds : VB_ADAPTIVE_ROUNDS;
    while (isfinite(ad->tolerance) && st.rounds < max_rounds) {
        const uint32_t V = M.vertex_count;
        if (ad->max_receivers && V >= ad->max_receivers) {
            st.budget_reached = 1;
            break;
        }
        free(cand);
        cand = NULL;
        if ((r = candidate_edges(&M, 2.0f * ad->min_edge, judged, judged_n, &cand, &cand_n, err)) !=
            VB_OK)
            goto done;
        if (cand_n == 0)
            break;
        const uint64_t baked = (uint64_t)st.start_receivers + st.candidates;
        if (st.uniform_receivers && baked + cand_n > st.uniform_receivers) {
            /* Bake no more than the uniform bake would: the longest
             * candidates that fit, in key order. */
            uint64_t room = st.uniform_receivers > baked ? st.uniform_receivers - baked : 0;
            st.uniform_reached = 1;
            if (room == 0)
                break;
            free(rank);
            if (!(rank = malloc(cand_n * sizeof *rank + 1))) {
                r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
                goto done;
            }
            for (size_t i = 0; i < cand_n; i++)
                rank[i] = (vb_ranked){edge_len2(&M, cand[i]), (uint32_t)i};
            qsort(rank, cand_n, sizeof *rank, vb_ranked_cmp);
            uint8_t *keep = calloc(cand_n + 1, 1);
            if (!keep) {
                r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
                goto done;
            }
            for (uint64_t k = 0; k < room; k++)
                keep[rank[k].index] = 1;
            size_t u = 0;
            for (size_t i = 0; i < cand_n; i++)
                if (keep[i])
                    cand[u++] = cand[i];
            free(keep);
            cand_n = u;
        }
        /* The tentative mesh: every candidate split; bake the midpoints. */
        free(pairs);
        if (!(pairs = malloc(cand_n * 2 * sizeof *pairs + 1))) {
            r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
            goto done;
        }
        for (size_t i = 0; i < cand_n; i++)
            pairs[2 * i] = (uint32_t)(cand[i] >> 32), pairs[2 * i + 1] = (uint32_t)cand[i];
        vb_mesh_free(&T);
        if ((r = vb_mesh_split_edges(&M, pairs, (uint32_t)cand_n, &T, err)) != VB_OK)
            goto done;
        vb_bake_output_free(&R);
        bd.receivers = &T;
        bd.range_begin = V;
        bd.range_end = T.vertex_count;
        if ((r = vb_bake_run(&bd, &R, err)) != VB_OK)
            goto done;
        st.rounds++;
        st.candidates += (uint32_t)cand_n;
        B.rays_traced += R.rays_traced;
        B.rays_missed += R.rays_missed;
        B.degenerate_receivers += R.degenerate_receivers;
        B.flipped_normals += R.flipped_normals;
        B.moved_origins += R.moved_origins;
        B.origins.moved += R.origins.moved;
        B.origins.flagged += R.origins.flagged;
        B.origins.ties += R.origins.ties;
        B.origins.skipped_zero_area += R.origins.skipped_zero_area;
        B.origins.probe_rays += R.origins.probe_rays;
        B.origins.seconds += R.origins.seconds;
        B.seconds += R.seconds;

        /* Score every candidate. */
        free(error);
        free(rank);
        error = malloc(cand_n * sizeof *error + 1);
        rank = malloc(cand_n * sizeof *rank + 1);
        if (!error || !rank) {
            r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
            goto done;
        }
        score_job sj = {.fine = &T,
                        .base = V,
                        .edges = cand,
                        .b = &R,
                        .coarse_c = B.coeffs[order],
                        .order = order,
                        .quantity = quantity[order],
                        .interp = interp,
                        .lights = (const float(*)[3])lights,
                        .light_count = st.lights,
                        .error = error};
        if (vb_parallel_for(B.threads, (uint32_t)cand_n, 64, score_block, &sj, NULL, NULL) == 0) {
            r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "cannot start worker threads");
            goto done;
        }
        /* Split those above the tolerance, largest first within the budget;
         * the others are judged for good. */
        uint32_t over = 0;
        for (size_t i = 0; i < cand_n; i++)
            if (error[i] > threshold)
                rank[over++] = (vb_ranked){error[i], (uint32_t)i};
        qsort(rank, over, sizeof *rank, vb_ranked_cmp);
        uint32_t take = over;
        if (ad->max_receivers && take > ad->max_receivers - V) {
            take = ad->max_receivers - V;
            st.budget_reached = 1;
        }
        uint8_t *chosen = calloc(cand_n + 1, 1);
        uint64_t *nj = realloc(judged, (judged_n + cand_n) * sizeof *judged + 1);
        free(rows);
        rows = malloc((size_t)take * sizeof *rows + 1);
        if (!chosen || !nj || !rows) {
            free(chosen);
            if (nj)
                judged = nj;
            r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
            goto done;
        }
        judged = nj;
        for (uint32_t k = 0; k < take; k++)
            chosen[rank[k].index] = 1;
        uint32_t s = 0;
        for (size_t i = 0; i < cand_n; i++) {
            if (chosen[i]) { /* in key order: the new vertices' order */
                pairs[2 * s] = pairs[2 * i], pairs[2 * s + 1] = pairs[2 * i + 1];
                rows[s++] = V + (uint32_t)i;
            } else if (error[i] <= threshold) {
                judged[judged_n++] = cand[i];
            }
        }
        free(chosen);
        qsort(judged, judged_n, sizeof *judged, cmp_u64);
        st.last_split = s;
        if (ad->on_round)
            ad->on_round(ad->user, st.rounds, V + s, (uint32_t)cand_n, s, vb_now() - t_start);
        if (s == 0)
            break;
        vb_mesh_free(&N);
        if ((r = vb_mesh_split_edges(&M, pairs, s, &N, err)) != VB_OK)
            goto done;
        /* The new vertices keep their midpoint bakes (and oriented normals). */
        int ok = 1;
        for (int o = 1; o <= VDSH_MAX_ORDER; o++)
            if (B.coeffs[o])
                ok &= append_rows(&B.coeffs[o], V, R.coeffs[o], R.range_begin, (size_t)o * o, rows,
                                  s); /* R holds the midpoints' rows only */
        if (B.normals)
            ok &= append_rows(&B.normals, V, R.normals, R.range_begin, 3, rows, s);
        if (!ok) {
            r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
            goto done;
        }
        for (uint32_t k = 0; k < s; k++)
            memcpy(N.normals + 3 * ((size_t)V + k),
                   R.normals ? R.normals + 3 * (size_t)(rows[k] - R.range_begin)
                             : T.normals + 3 * (size_t)rows[k],
                   3 * sizeof(float));
        vb_mesh_free(&M);
        M = N;
        memset(&N, 0, sizeof N);
        B.vertex_count = B.range_end = M.vertex_count;
        if (st.budget_reached || st.uniform_reached)
            break;
    }
    if (isfinite(ad->tolerance) && st.rounds == max_rounds && st.last_split > 0 &&
        !st.budget_reached && !st.uniform_reached) {
        /* The round limit stopped a refinement still splitting: how many
         * edges the next round would have judged. */
        free(cand);
        cand = NULL;
        if ((r = candidate_edges(&M, 2.0f * ad->min_edge, judged, judged_n, &cand, &cand_n, err)) !=
            VB_OK)
            goto done;
        st.pending = (uint32_t)cand_n;
        st.rounds_reached = cand_n > 0;
    }
    B.vertex_count = B.range_end = M.vertex_count;
    *receivers = M;
    memset(&M, 0, sizeof M);
    *out = B;
    memset(&B, 0, sizeof B);
    if (stats)
        *stats = st;
    r = VB_OK;
done:
    vb_mesh_free(&M);
    vb_mesh_free(&T);
    vb_mesh_free(&N);
    vb_bake_output_free(&B);
    vb_bake_output_free(&R);
    free(judged);
    free(cand);
    free(error);
    free(rank);
    free(rows);
    free(pairs);
    free(lights);
    return r;
}
