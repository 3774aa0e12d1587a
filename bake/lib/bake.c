/*
 * bake.c - the bake core (bake.h): per receiver, trace its directions and
 * project the distances onto SH, then fit each order (fit.h).
 *
 * The story of vb_bake_run, the driver at the bottom:
 *   1. Resolve the description's defaults and check it against the
 *      method's row (method.h): sampling domain, quantity, parameters.
 *   2. Orient the receivers and place their ray origins (origins.h: one
 *      pass over their frames).
 *   3. With VB_QUANTITY_AUTO, trace a sample of receivers first and choose
 *      each order's quantity by the expected shadow error (choose_block).
 *   4. Trace and project every other receiver on the workers (bake_block,
 *      bake_vertex: packets of 16 rays, sums in a fixed order).
 * Encoding the result as .vdsh streams is stream.c's (vb_bake_stream).
 */
#include "bake.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "decision.h"
#include "fit.h"
#include "method.h"
#include "origins.h"
#include "parallel.h"
#include "sampling.h"
#include "vdsh.h"
#include "vdsh_sh.h"
#include "vdsh_shadow.h"
#include "vdsh_det.h"

#define VB_PI 3.14159265358979323846
#define BLOCK 16 /* receivers per work item */
#define GROUP 8  /* packets traced before their lanes are processed */

/* ---- the trace-and-project loop ----------------------------------------- */

typedef struct job {
    const vb_bake_desc *d;
    const vb_dirgrid *grid;
    /* The receivers traced (vb_receivers_prepare's set): set[k] at slot k;
     * set NULL: every receiver, slot = index. The range lo..hi is slots
     * set_before.. of it. */
    const uint32_t *set;
    uint32_t set_count, set_before;
    const float *origins;                /* per slot, traced frame */
    const float *near;                   /* per slot: ~0 distance, scene units */
    const float *normals;                /* per slot: oriented; NULL: the receivers' own */
    float *coeffs[VDSH_ORDER_SLOTS];     /* rows lo..hi-1 (the range's) */
    uint32_t quantity[VDSH_ORDER_SLOTS]; /* per order: what coeffs hold */
    vb_fit fits[VDSH_ORDER_SLOTS];
    int order; /* the projection's order (the highest asked) */
    float log_floor;
    float max_local; /* max distance in the traced frame */
    float inv_scale;
    int horizon; /* paper: skip w.n < 0 */
    /* Method shadow: per order, added to the fitted ln d (through c0). */
    float log_offset[VDSH_ORDER_SLOTS];
    /* Adaptive order: the log offset of each candidate order's lsq fit
     * (the method's; with method decision, shadow's: its variable-order
     * stream is method shadow's). */
    float var_offset[VDSH_ORDER_SLOTS];
    double *error_table; /* e(r), the quantity choice's score (VB_ERROR_TABLE + 1) */
    /* The quantity choice (VB_QUANTITY_AUTO): sampled receivers, and per
     * sample, order and quantity (0 distance, 1 log) its estimated error. */
    uint32_t choose_count;
    double *choose_error; /* choose_count * (VDSH_ORDER_SLOTS) * 2 */
    float *choose_coeffs; /* per sample, quantity and order: its fit */
    uint8_t *done;        /* per receiver of the range (v - lo): baked by the
                            * choice already (or NULL) */
    int adaptive;         /* adaptive rays: grid is nested */
    float ray_tol;        /* their tolerance (0: every round) */
    uint32_t lo, hi;      /* the range baked (vb_bake_desc.range_*) */
    /* Adaptive order (order_tolerance > 0): the cap (0: none), the
     * lights' positions (scene units) and the range's orders and
     * coefficients (cap^2 per receiver). */
    int var_cap;
    float var_tol;
    float (*lights)[3];
    uint32_t light_count;
    uint8_t *var_orders;
    float *var_coeffs;
    float *var_scratch; /* per worker: var_scratch_floats */
    /* Adaptive order with the decision fit (var_decision): per receiver of
     * the range, 1 where it kept the lsq choice (too few training pairs:
     * the offsets already in), and the log offset added to the
     * decision-fitted rows: one for the stream, calibrated, else the
     * given one of the cap's order (the one the file records). */
    int var_decision;
    uint8_t *var_lsq;
    float var_dec_offset;
    /* The decision fit (method.h: decision): the light pool in the traced
     * frame, lights per receiver, the fit's settings, per-worker scratch
     * (dec_scratch_bytes); the calibration's held-out margins (per sample,
     * order and held-out light: lit pairs' margins, NAN otherwise). */
    int decision;
    float (*pool)[3];     /* the training lights (mix_near) */
    float (*cal_pool)[3]; /* the calibration's: the pool before mix_near */
    uint32_t pool_count, dec_lights;
    vb_decision_params dec;
    unsigned char *dec_scratch;
    float *cal_margins;
    /* The per-receiver offset cap (vb_bake_desc.offset_cap): on, its
     * tolerance (ln units), share of lit training pairs kept lit and
     * least lit pairs; the calibration samples' caps (per sample and
     * order slot), and those of the range's samples (per receiver of the
     * range and slot), added with the calibrated offset after the bake. */
    int cap_on;
    float free_offset[VDSH_ORDER_SLOTS]; /* receivers without a cap: the
                                          * offset calibrated without caps */
    float cap_tol, cap_keep;
    uint32_t cap_min;
    float *cal_caps, *done_caps;
    _Atomic uint64_t cap_bound, lit_training, lit_false;
    _Atomic uint32_t dec_fitted, dec_fallbacks;
    _Atomic uint64_t dec_pairs, dec_rays;
    _Atomic uint64_t cal_shadowed; /* the calibration's shadowed held-out pairs */
    _Atomic uint64_t traced, missed;
    _Atomic uint32_t degenerate;
} job;

/* Where one receiver's results go: per quantity (0 distance, 1 log) and
 * order, its coefficients or NULL; and, when `n` is not NULL, the traced
 * directions above its horizon with their distances (scene units). */
typedef struct vertex_sink {
    float *coeffs[2][VDSH_ORDER_SLOTS];
    float *var_scratch;         /* adaptive order: the worker's (VAR_SCRATCH floats) */
    unsigned char *dec_scratch; /* decision fit: the worker's */
    float *cal;                 /* decision calibration: margins, VDSH_ORDER_SLOTS x CAL_LIGHTS
                                 * (slot 0: the adaptive order's chosen fit) */
    float *cal_cap;             /* and its offset caps, per order (-inf: none) */
    float *x, *y, *z, *t;
    uint32_t *n;
} vertex_sink;

/* ln(x) for finite x > 0, to about 1e-7 relative, in plain float
 * arithmetic: it vectorises (libm's logf does not), and gives the same bits
 * on every machine. x = m 2^e with m in [sqrt(1/2), sqrt(2)); ln m from
 * the series of 2 atanh(s), s = (m - 1)/(m + 1), |s| <= 0.172. */
static inline float fast_log(float x)
{
    union {
        float f;
        uint32_t u;
    } v = {x};
    int32_t e = (int32_t)((v.u >> 23) & 0xffu) - 127;
    v.u = (v.u & 0x007fffffu) | 0x3f800000u; /* m in [1, 2) */
    float m = v.f;
    int big = m > 1.41421356f;
    m *= 1.0f - 0.5f * (float)big; /* not ?: - it blocks vectorising */
    e += big;
    float s = (m - 1.0f) / (m + 1.0f), s2 = s * s;
    float p = s * (2.0f + s2 * (2.0f / 3 + s2 * (2.0f / 5 + s2 * (2.0f / 7 + s2 * (2.0f / 9)))));
    return p + (float)e * 0.69314718f;
}

/* e^x for x clamped to [-80, 80], to about 2e-7 relative, in plain float
 * arithmetic (libm's expf may take other paths on other CPUs): the
 * adaptive order's choice must not depend on the machine. */
static inline float fast_exp(float x)
{
    x = x < -80.0f ? -80.0f : x > 80.0f ? 80.0f : x;
    float t = x * 1.44269504f; /* log2 e */
    int i = (int)(t + (t >= 0.0f ? 0.5f : -0.5f));
    float r = (t - (float)i) * 0.693147181f; /* |r| <= ln2 / 2 */
    float p =
        1.0f +
        r * (1.0f +
             r * (0.5f + r * (1.0f / 6 + r * (1.0f / 24 + r * (1.0f / 120 + r * (1.0f / 720))))));
    union {
        uint32_t u;
        float f;
    } b = {(uint32_t)(i + 127) << 23};
    return p * b.f;
}

int vb_order_candidate(int k, int cap)
{
    return k == cap || (k < cap && (k <= 3 || k == 5 || k == 7 || k == 9 || k == 12));
}

/* Adaptive order (bake.h, order_tolerance): receiver v's order and
 * coefficients. For each order k = 1..cap in turn, its fit of the log
 * distance (u: the projection, unrotated; the method's log offset added)
 * reconstructs the distance D toward up to VB_ORDER_DIRECTIONS of the
 * receiver's traced directions above its horizon (every step-th), and
 * its error is the mean over those directions and the scene lights'
 * distances d_L of |ramp(D / d_L) - ramp(t / d_L)|, t the traced
 * distance: the expected shadow error of lights at the scene's light
 * distances, on the receiver's own directions. The first order at most
 * the tolerance is kept, else the one of least error. Sums run in a fixed
 * order in float (no libm), so the choice is the same on every CPU and
 * for any thread count. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) &&                             \
    !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("avx2", "default")))
#endif
static void
choose_order(const job *J, uint32_t v, const vb_fit_angles *a, const double *u, const float *tx,
             const float *ty, const float *tz, const float *tt, uint32_t count, float *scratch)
{
    enum { M = VB_ORDER_DIRECTIONS, L = VB_ORDER_LIGHTS };
    const int cap = J->var_cap;
    const uint32_t m = count < M ? count : M;
    const float max_distance = J->d->max_distance;
    float x[M], y[M], z[M], t[M], sl[L], ideal[M * L], s[M], acc[L];
    for (uint32_t i = 0; i < m; i++) {
        uint32_t k = (uint32_t)((uint64_t)i * count / m);
        x[i] = tx[k], y[i] = ty[k], z[i] = tz[k], t[i] = tt[k];
    }
    /* ramp(D / d_L) = saturate(D sl - 1/2), sl = 1.5 / d_L; lights past
     * the list's end (or at the receiver) get sl = 0: both sides 0. */
    const float *p = J->d->receivers->positions + 3 * (size_t)v;
    uint32_t nl = 0;
    for (uint32_t j = 0; j < L; j++) {
        sl[j] = 0.0f;
        if (j < J->light_count) {
            float dx = J->lights[j][0] - p[0], dy = J->lights[j][1] - p[1],
                  dz = J->lights[j][2] - p[2];
            float d = sqrtf(dx * dx + dy * dy + dz * dz);
            if (d > 0.0f)
                sl[j] = 1.5f / d, nl++;
        }
    }
    for (uint32_t i = 0; i < m; i++)
        for (uint32_t j = 0; j < L; j++) {
            float r = t[i] * sl[j] - 0.5f;
            ideal[i * L + j] = 0.5f * (fabsf(r) - fabsf(r - 1.0f) + 1.0f);
        }
    float *Y = scratch; /* cap^2 x m */
    if (m)
        vdsh_sh_eval_soa(cap, m, x, y, z, Y, m);
    float c[VDSH_ORDER_SLOTS][VDSH_MAX_COEFFS], err[VDSH_ORDER_SLOTS];
    float least = INFINITY;
    for (int k = 1; k <= cap; k++) {
        if (!vb_order_candidate(k, cap))
            continue;
        vb_fit_finish(&J->fits[k], a, u, c[k]);
        c[k][0] += J->var_offset[k] / 0.28209479177387814f;
        for (uint32_t i = 0; i < m; i++)
            s[i] = 0.0f;
        for (int j = 0; j < k * k; j++)
            for (uint32_t i = 0; i < m; i++)
                s[i] += c[k][j] * Y[(size_t)j * m + i];
        for (uint32_t j = 0; j < L; j++)
            acc[j] = 0.0f;
        /* Per light, summed over directions in order (lane-wise: the same
         * bits with or without vectors). */
        for (uint32_t i = 0; i < m; i++) {
            float D = fast_exp(s[i]);
            s[i] = D < max_distance ? D : max_distance;
        }
        for (uint32_t i = 0; i < m; i++) {
            const float D = s[i];
            for (uint32_t j = 0; j < L; j++) {
                /* saturate(r) as (|r| - |r - 1| + 1) / 2: no compares, so
                 * GCC vectorises the loop (it does not if-convert float
                 * compares that may trap) */
                float r = D * sl[j] - 0.5f;
                acc[j] += fabsf(0.5f * (fabsf(r) - fabsf(r - 1.0f) + 1.0f) - ideal[i * L + j]);
            }
        }
        float e = 0.0f;
        for (uint32_t j = 0; j < L; j++)
            e += acc[j];
        err[k] = m && nl ? e / (float)(m * nl) : 0.0f;
        least = err[k] < least ? err[k] : least;
    }
    int best_k = cap;
    for (int k = cap; k >= 1; k--)
        if (vb_order_candidate(k, cap) && err[k] <= least + J->var_tol)
            best_k = k;
    J->var_orders[v - J->lo] = (uint8_t)best_k;
    float *dst = J->var_coeffs + (size_t)(v - J->lo) * cap * cap;
    memset(dst, 0, (size_t)cap * cap * sizeof *dst);
    memcpy(dst, c[best_k], (size_t)best_k * best_k * sizeof *dst);
}

static double expected_error(const double *e, double r);

/* Receiver v's slot among the traced ones (job.set): v is one of them. */
static uint32_t slot_of(const job *J, uint32_t v)
{
    if (!J->set)
        return v;
    if (v >= J->lo && v < J->hi)
        return J->set_before + (v - J->lo);
    uint32_t a = 0, b = J->set_count; /* a sample outside the range */
    while (a < b) {
        uint32_t mid = a + (b - a) / 2;
        if (J->set[mid] < v)
            a = mid + 1;
        else
            b = mid;
    }
    return a;
}

/* Adaptive rays: the highest order's fit of accumulated projection `acc`
 * (a quantity's per-lane sums) over `cells` directions, into c. */
static void adapt_fit(const job *J, const float n[3], float acc[VDSH_MAX_COEFFS][VB_PACKET],
                      uint32_t cells, double level, float c[VDSH_MAX_COEFFS])
{
    double w = (J->grid->hemisphere ? 2.0 : 4.0) * VB_PI / cells;
    int nb = J->order * J->order;
    double b[VDSH_MAX_COEFFS], u[VDSH_MAX_COEFFS];
    for (int i = 0; i < nb; i++) {
        double s = 0.0;
        for (int k = 0; k < VB_PACKET; k++)
            s += acc[i][k];
        b[i] = s * w;
    }
    const vb_fit *top = &J->fits[J->order];
    vb_fit_angles angles;
    vb_fit_frame(top, n, &angles);
    vb_fit_unrotate(top, &angles, b, u);
    if (level != 0.0)
        vb_fit_add_constant(top, J->grid->hemisphere, level, u);
    vb_fit_finish(top, &angles, u, c);
}

/* ---- the decision fit's pairs ------------------------------------------- */

/* Held-out lights per calibration receiver, and the least pairs a receiver
 * needs for its own decision fit (fewer: it keeps its lsq fit). */
#define CAL_LIGHTS 64
#define DEC_MIN_PAIRS 16
#define DEC_BOUNDARY -0.40546511f /* ln(2/3) */

/* A worker's decision scratch: the pairs (x, y, z, ln d: K floats each),
 * the basis at them (order^2 rows of K), the labels (K bytes), then, from
 * dec_doubles_at (64-byte aligned within it), the fit's doubles. */
static size_t dec_doubles_at(const job *J)
{
    size_t k = VB_DECISION_MAX_PAIRS, n = (size_t)J->order * J->order;
    return ((4 * k + n * k) * sizeof(float) + k + 63) & ~(size_t)63;
}

static size_t dec_scratch_bytes(const job *J)
{
    return dec_doubles_at(J) + vb_decision_scratch_doubles(J->order) * sizeof(double);
}

/* A hash of (seed, k). */
static uint64_t dec_hash(const job *J, uint64_t k)
{
    uint64_t z = J->d->seed * 0x9e3779b97f4a7c15ull + k + 0x632be59bd9b4e019ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* Every receiver's first training light in the pool: one start for the
 * bake, so that neighbours fit the same lights and their fits differ
 * where the scene does, not by which lights each drew (a start per
 * receiver drew order 12 mottled on lit surfaces: docs/ACCURACY.md,
 * "Order 12 mottling"). */
static uint32_t dec_start(const job *J)
{
    return (uint32_t)(dec_hash(J, 0) % J->pool_count);
}

/* Receiver v's held-out lights start this many lights past its training
 * lights (scanned of the pool read so far): per receiver, so that the
 * calibration sees many lights, and within the first half of the rest,
 * so that they are never training lights and enough remain. */
static uint32_t dec_skip(const job *J, uint32_t v, uint32_t scanned)
{
    uint32_t span = (J->pool_count - scanned) / 2;
    return span ? (uint32_t)(dec_hash(J, (uint64_t)v + 1) % span) : 0;
}

/* Pairs of receiver v (traced origin org, normal n): the pool's lights
 * from *at on, above the horizon, up to `want`, each with a ray toward it
 * (its label: shadowed when anything is in the way). x, y, z: the unit
 * direction; logd: ln of the light's distance (scene units, the fits'
 * floor); lab: 1 shadowed. *at moves past the lights read. */
static uint32_t dec_pairs(const job *J, float (*pool)[3], uint32_t *at, uint32_t *scanned,
                          const float *org, const float n[3], uint32_t want, float *x, float *y,
                          float *z, float *logd, uint8_t *lab, uint64_t *traced)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    uint32_t m = 0;
    /* One ray at a time: rays toward scattered lights are incoherent, and
     * a 16-wide packet would walk the union of their paths (measured: the
     * same labels, about a third less time). */
    while (m < want && *scanned < J->pool_count) {
        const float *L = pool[*at];
        *at = *at + 1 == J->pool_count ? 0 : *at + 1;
        ++*scanned;
        float dx = L[0] - org[0], dy = L[1] - org[1], dz = L[2] - org[2];
        /* The horizon first: half the pool is below it, and needs no root. */
        if (dx * n[0] + dy * n[1] + dz * n[2] <= 0.0f)
            continue;
        float len = sqrtf(dx * dx + dy * dy + dz * dz);
        if (!(len > 0.0f))
            continue;
        float inv = 1.0f / len;
        struct RTCRay r = {.org_x = org[0],
                           .org_y = org[1],
                           .org_z = org[2],
                           .dir_x = dx * inv,
                           .dir_y = dy * inv,
                           .dir_z = dz * inv,
                           .tnear = 0.0f,
                           .tfar = len,
                           .mask = 0xffffffffu};
        rtcOccluded1(J->d->scene->scene, &ctx, &r);
        ++*traced;
        x[m] = r.dir_x, y[m] = r.dir_y, z[m] = r.dir_z;
        float d = len * J->inv_scale;
        /* The margin is read at the drawn boundary: the ramp's s = 1/2 at
         * D = 2/3 d_L (vdsh_shadow.h). */
        logd[m] = fast_log(d > J->log_floor ? d : J->log_floor) + DEC_BOUNDARY;
        lab[m] = r.tfar < 0.0f; /* Embree sets tfar to -inf on a hit */
        m++;
    }
    return m;
}

/* The log offset a receiver's fit draws with: the bake's, raised to the
 * receiver's cap (<= 0); where it has none (-inf), `uncapped` (the offset
 * calibrated without caps). */
static inline float capped_offset(float off, float cap, float uncapped)
{
    return cap == -INFINITY ? uncapped : off < cap ? cap : off;
}

static int cmp_margin(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* The margins ln D - ln d_L of fit c (order o) at the receiver's lit
 * training pairs (the first m of Y, logd, lab) into mg (room for m); their count into
 * *lit. Returns its offset cap (vb_bake_desc.offset_cap): the least
 * offset that keeps the cap's share of them lit, less its tolerance,
 * at most 0; -inf where the cap is off or too few pairs are lit. mg
 * comes back sorted when a cap was computed. */
static float dec_cap(const job *J, int o, const float *c, uint32_t m, const float *Y, uint32_t ys,
                     const float *logd, const uint8_t *lab, float *mg, uint32_t *lit)
{
    /* ln D at every pair, coefficient by coefficient along Y's rows (each
     * pair's sum in the order j = 0, 1, ...), then the lit pairs' margins
     * gathered to the front */
    for (uint32_t i = 0; i < m; i++)
        mg[i] = 0.0f;
    for (int j = 0; j < o * o; j++) {
        const float cj = c[j], *row = Y + (size_t)j * ys;
        for (uint32_t i = 0; i < m; i++)
            mg[i] += cj * row[i];
    }
    uint32_t n = 0;
    for (uint32_t i = 0; i < m; i++)
        if (!lab[i])
            mg[n++] = mg[i] - logd[i];
    *lit = n;
    if (!J->cap_on || n == 0 || n < J->cap_min)
        return -INFINITY;
    qsort(mg, n, sizeof *mg, cmp_margin);
    uint32_t q = (uint32_t)((1.0 - (double)J->cap_keep) * n);
    q = q < n ? q : n - 1;
    float cap = -mg[q] - J->cap_tol;
    return cap < 0.0f ? cap : 0.0f;
}

/* Adaptive order with the decision fit: each candidate order's lsq fit
 * (varc[k], no offset) scored by the decision loss on the receiver's
 * training pairs at the offset that suits it best (vb_decision_score:
 * one number per candidate, no Newton fit), then the lowest candidate
 * within the tolerance of the least loss refitted to the decision from
 * its lsq fit (vb_decision_fit, as a fixed order is, but with one fresh
 * Hessian), into varc[k]. Returns k. Deterministic as the decision fit
 * is (decision.h). */
static int choose_decision(const job *J, uint32_t m, const float *Y, uint32_t ys, const float *logd,
                           const uint8_t *lab, float (*varc)[VDSH_MAX_COEFFS], double *ds)
{
    const int cap = J->var_cap;
    float err[VDSH_ORDER_SLOTS], least = INFINITY;
    for (int k = 1; k <= cap; k++) {
        if (!vb_order_candidate(k, cap))
            continue;
        float b;
        err[k] = vb_decision_score(k, m, Y, ys, logd, lab, &J->dec, varc[k], &b, ds);
        least = err[k] < least ? err[k] : least;
    }
    int best_k = cap;
    for (int k = cap; k >= 1; k--)
        if (vb_order_candidate(k, cap) && err[k] <= least + J->var_tol)
            best_k = k;
    /* One fresh Hessian, then its factor kept for the other steps: as
     * good per sample as a fresh one at every step on the validation
     * rooms, for a third of the Hessians (docs/ACCURACY.md, "Adaptive
     * order by the decision loss"). */
    vb_decision_params p = J->dec;
    p.hessians = 1;
    vb_decision_fit(best_k, m, Y, ys, logd, lab, &p, varc[best_k], ds);
    return best_k;
}

/* The decision fit of receiver v (decision.h): its pairs, then each asked
 * order's log fit in `out` refitted from its lsq start. With out->cal
 * (the calibration's samples), the margins of each order's fit on
 * CAL_LIGHTS further lights, held out from the fit: lit pairs' ln D - ln
 * d_L, NAN for shadowed ones and missing lights. With varc (the adaptive
 * order: its candidates' lsq fits), the chosen order into *var_k and its
 * fit into varc[*var_k] (choose_decision), its margins in slot 0.
 * Returns 1 if the receiver had enough pairs to fit, 0 if it keeps its
 * lsq fits. */
static int decision_vertex(job *J, uint32_t v, const float *org, const float n[3],
                           const vertex_sink *out, float (*varc)[VDSH_MAX_COEFFS], int *var_k,
                           float cap[VDSH_ORDER_SLOTS])
{
    const uint32_t K = VB_DECISION_MAX_PAIRS, top = J->order;
    float *x = (float *)out->dec_scratch, *y = x + K, *z = y + K, *logd = z + K, *Y = logd + K;
    uint8_t *lab = (uint8_t *)(Y + (size_t)top * top * K);
    double *ds = (double *)(out->dec_scratch + dec_doubles_at(J));
    uint32_t at = dec_start(J), scanned = 0;
    uint64_t rays = 0;
    uint32_t m =
        dec_pairs(J, J->pool, &at, &scanned, org, n, J->dec_lights, x, y, z, logd, lab, &rays);
    if (m >= DEC_MIN_PAIRS) {
        /* The basis's rows m (rounded up) + 16 floats apart, not K: rows
         * 4 KiB apart share the L1's sets, and the fit reads them all on
         * every pass. */
        uint32_t ys = ((m + 15) & ~15u) + 16;
        ys = ys < K ? ys : K;
        vdsh_sh_eval_soa((int)top, m, x, y, z, Y, ys);
        for (int o = 1; o <= VDSH_MAX_ORDER; o++)
            if (out->coeffs[1][o]) {
                vb_decision_fit(o, m, Y, ys, logd, lab, &J->dec, out->coeffs[1][o], ds);
                /* Its cap, and, outside the calibration (whose offset is
                 * not known yet), its lit training pairs that the offset
                 * draws in shadow (lit without it; 1e-5: the cap's own
                 * rounding). */
                float mg[VB_DECISION_MAX_PAIRS];
                uint32_t lit = 0;
                cap[o] = dec_cap(J, o, out->coeffs[1][o], m, Y, ys, logd, lab, mg, &lit);
                if (!out->cal) {
                    float off = capped_offset(J->log_offset[o], cap[o], J->free_offset[o]);
                    uint64_t bad = 0;
                    for (uint32_t i = 0; i < lit; i++)
                        bad += mg[i] >= 0.0f && mg[i] + off < -J->cap_tol - 1e-5f;
                    atomic_fetch_add(&J->lit_training, lit);
                    atomic_fetch_add(&J->lit_false, bad);
                }
            }
        if (varc)
            *var_k = choose_decision(J, m, Y, ys, logd, lab, varc, ds);
        atomic_fetch_add(&J->dec_pairs, m);
        atomic_fetch_add(&J->dec_fitted, 1);
    } else {
        atomic_fetch_add(&J->dec_fallbacks, 1);
    }
    const int fitted = m >= DEC_MIN_PAIRS;
    if (!out->cal) {
        atomic_fetch_add(&J->dec_rays, rays);
        return fitted;
    }
    for (size_t i = 0; i < (size_t)VDSH_ORDER_SLOTS * CAL_LIGHTS; i++)
        out->cal[i] = NAN;
    uint32_t skip = dec_skip(J, v, scanned);
    at = (uint32_t)(((uint64_t)at + skip) % J->pool_count);
    scanned += skip;
    uint32_t h =
        dec_pairs(J, J->cal_pool, &at, &scanned, org, n, CAL_LIGHTS, x, y, z, logd, lab, &rays);
    atomic_fetch_add(&J->dec_rays, rays);
    if (!h)
        return fitted;
    uint64_t shadowed = 0;
    for (uint32_t i = 0; i < h; i++)
        shadowed += lab[i] != 0;
    atomic_fetch_add(&J->cal_shadowed, shadowed);
    vdsh_sh_eval_soa((int)top, h, x, y, z, Y, K);
    for (int o = 0; o <= VDSH_MAX_ORDER; o++) {
        const float *c = o ? out->coeffs[1][o] : varc && fitted ? varc[*var_k] : NULL;
        const int k = o ? o : varc && fitted ? *var_k : 0;
        if (!c)
            continue;
        for (uint32_t i = 0; i < h; i++) {
            if (lab[i])
                continue;
            float s = 0.0f;
            for (int j = 0; j < k * k; j++)
                s += c[j] * Y[(size_t)j * K + i];
            out->cal[o * CAL_LIGHTS + i] = s - logd[i];
        }
    }
    return fitted;
}

/* ---- one receiver: bake_vertex and its steps ------------------------------ */

/* Every step below is inlined into bake_vertex, and so into each of its
 * target clones: a step left out of line would be compiled once, for the
 * baseline ISA, and the lane loops would lose the AVX2 clone. */
#define VERTEX_STEP static inline __attribute__((always_inline))

/* One receiver's bake in progress: what it asks for, its frame, and the
 * sums and counts its traced packets add to. */
typedef struct vertex_state {
    job *J;
    uint32_t v, slot;
    const vertex_sink *out;
    const float *n, *org; /* oriented normal (or the pole), ray origin */
    /* Per quantity (0 distance, 1 log distance): projected or not. */
    int want[2];
    /* Adaptive order: the log distance's fits, chosen on the traced
     * directions above the horizon (var_buf: x, y, z, t, then scratch);
     * dvar: chosen by the decision fit instead. */
    int var, dvar;
    float *var_buf;
    uint32_t var_n;
    /* The log distance's level (vertex_begin): projected less it, put
     * back after the fit. */
    const vb_fit *top;
    vb_fit_angles angles;
    int centre, have_level;
    float level;
    float acc[2][VDSH_MAX_COEFFS][VB_PACKET]; /* per quantity: per-lane sums */
    uint32_t near_zero, upper;                /* for the degenerate count */
    /* Adaptive rays: directions used, this round's directions above the
     * horizon (ax..az from adapt_from), the last round's fit. */
    uint32_t cells_used, adapt_from, adapt_n;
    float adapt_prev[VDSH_MAX_COEFFS];
    float *ax, *ay, *az;
    float adapt_buf[3 * 4096];
} vertex_state;

/* GROUP packets traced together (trace_group). */
typedef struct packet_group {
    struct RTCRayHit16 rh[GROUP] __attribute__((aligned(64)));
    int valid[GROUP][VB_PACKET] __attribute__((aligned(64)));
    int np;
} packet_group;

/* A group's values per lane (lane_distances, lane_log_distances): apart
 * from the packets, so that GCC sees the lane loops' stores cannot alias
 * their loads, and vectorises them with no run-time checks. */
typedef struct group_lanes {
    float dist[GROUP][VB_PACKET], logd[GROUP][VB_PACKET];
    int up_lane[GROUP][VB_PACKET];
} group_lanes;

/* Receiver v's state before its first ray: its frame, what `out` and the
 * job ask of it, and the sums at zero. */
VERTEX_STEP void vertex_begin(vertex_state *s, job *J, uint32_t v, const vertex_sink *out)
{
    const vb_bake_desc *d = J->d;
    s->J = J;
    s->v = v;
    s->out = out;
    s->slot = slot_of(J, v);
    s->n = J->normals ? J->normals + 3 * (size_t)s->slot : d->receivers->normals + 3 * (size_t)v;
    s->org = J->origins + 3 * (size_t)s->slot;
    static const float pole[3] = {0.0f, 0.0f, 1.0f};
    if (J->grid->hemisphere && s->n[0] == 0.0f && s->n[1] == 0.0f && s->n[2] == 0.0f)
        s->n = pole; /* no surface: a hemisphere about +z, fitted as such */

    for (int q = 0; q < 2; q++) {
        s->want[q] = 0;
        for (int o = 1; o <= VDSH_MAX_ORDER; o++)
            s->want[q] |= out->coeffs[q][o] != NULL;
    }
    s->var = J->var_cap && v >= J->lo && v < J->hi && !d->trace_only && !out->n;
    s->var_buf = s->var ? out->var_scratch : NULL;
    s->var_n = 0;
    /* With the decision fit, the choice is made on the training pairs
     * (choose_decision), also for a calibration sample outside the range
     * (its held-out margins count toward the stream's offset). */
    s->dvar =
        J->var_decision && !d->trace_only && !out->n && (s->var || (out->cal && out->var_scratch));
    s->want[1] |= s->var | s->dvar;
    /* The log distance is projected less a level of its own (the mean of
     * the first traced packets' values), put back exactly after the fit:
     * the fit then does not depend on the units the scene is in (the
     * projection's sampling error acts on ln d - level, not on ln d, whose
     * level is set by the units). */
    s->top = &J->fits[J->order];
    vb_fit_frame(s->top, s->n, &s->angles);
    s->centre = s->want[1] && vb_fit_constant_exact(&s->angles, J->grid->hemisphere);
    s->have_level = 0;
    s->level = 0.0f;
    for (int q = 0; q < 2; q++)
        memset(s->acc[q], 0, (size_t)J->order * J->order * sizeof s->acc[q][0]);
    s->near_zero = 0;
    s->upper = 0;

    s->cells_used = J->grid->count;
    s->adapt_from = 0;
    s->adapt_n = 0;
    s->ax = s->ay = s->az = NULL;
    if (J->adaptive) {
        s->ax = s->adapt_buf;
        s->ay = s->ax + J->grid->count;
        s->az = s->ay + J->grid->count;
    }
}

/* Traces up to GROUP packets from pk (before pk_end) into g, skipping
 * those with no ray above the horizon. Returns the packet after the last
 * one looked at. */
VERTEX_STEP uint32_t trace_group(const vertex_state *s, struct RTCIntersectContext *ctx,
                                 uint32_t pk, uint32_t pk_end, packet_group *g, uint64_t *traced)
{
    const job *J = s->J;
    const vb_bake_desc *d = J->d;
    /* Loop invariants in locals (org's values too: read through the
     * pointer, the packet's stores would need too many alias checks), so
     * that the lane loop vectorises. */
    const float *n = s->n;
    const float org[3] = {s->org[0], s->org[1], s->org[2]}, nx = n[0], ny = n[1], nz = n[2];
    const int horizon = J->horizon;
    const float max_local = J->max_local;
    int np = 0;
    for (; pk < pk_end && np < GROUP; pk++) {
        if (horizon && !J->adaptive && vb_dirgrid_packet_below(J->grid, pk, n))
            continue;
        struct RTCRayHit16 *r = &g->rh[np];
        int *ok = g->valid[np];
        if (J->adaptive)
            vb_dirgrid_packet_nested(J->grid, pk, d->seed, s->v, n, r->ray.dir_x, r->ray.dir_y,
                                     r->ray.dir_z, ok);
        else
            vb_dirgrid_packet(J->grid, pk, d->seed, s->v, n, r->ray.dir_x, r->ray.dir_y,
                              r->ray.dir_z, ok);
        int any = 0;
        for (int k = 0; k < VB_PACKET; k++) {
            if (horizon && ok[k]) {
                float c = r->ray.dir_x[k] * nx + r->ray.dir_y[k] * ny + r->ray.dir_z[k] * nz;
                if (c < 0.0f)
                    ok[k] = 0;
            }
            any |= ok[k];
            vb_ray16_init(r, k, org, max_local);
        }
        if (!any)
            continue;
        rtcIntersect16(ok, d->scene->scene, ctx, r);
        for (int k = 0; k < VB_PACKET; k++)
            *traced += ok[k] != 0;
        np++;
    }
    g->np = np;
    return pk;
}

/* The group's distance per lane (scene units; a miss: max_distance),
 * which lanes are above the horizon, and the counts of misses, lanes
 * above the horizon and those of them near zero. Branch-free over the
 * lanes, so it vectorises; lanes not traced (empty, or below the
 * horizon) count as distance 0. */
VERTEX_STEP void lane_distances(vertex_state *s, const packet_group *g, group_lanes *l,
                                uint64_t *missed)
{
    /* Loop invariants in locals: the lane loop vectorises. */
    const float inv_scale = s->J->inv_scale, max_distance = s->J->d->max_distance;
    const float degenerate_dist = s->J->near[s->slot];
    const float nx = s->n[0], ny = s->n[1], nz = s->n[2];
    for (int p = 0; p < g->np; p++) {
        int miss = 0, upper_pk = 0, near_pk = 0;
        const int *ok = g->valid[p];
        const uint32_t *gid = g->rh[p].hit.geomID;
        const float *tfar = g->rh[p].ray.tfar, *dx = g->rh[p].ray.dir_x, *dy = g->rh[p].ray.dir_y,
                    *dz = g->rh[p].ray.dir_z;
        for (int k = 0; k < VB_PACKET; k++) {
            /* Selects as arithmetic (exact for these finite values), in
             * int: GCC if-converts and vectorises this loop only so. */
            int live = ok[k] & 1; /* valid: 0 or -1 */
            int hit = gid[k] != RTC_INVALID_GEOMETRY_ID;
            float fh = (float)hit, fl = (float)live;
            float t = tfar[k] * inv_scale * fh + max_distance * (1.0f - fh);
            float c = dx[k] * nx + dy[k] * ny + dz[k] * nz;
            int up = live & (c > 0.0f);
            l->dist[p][k] = t * fl;
            l->up_lane[p][k] = up;
            miss += live & (hit ^ 1);
            upper_pk += up;
            near_pk += up & (t < degenerate_dist);
        }
        s->upper += (uint32_t)upper_pk;
        s->near_zero += (uint32_t)near_pk;
        *missed += (uint64_t)miss;
    }
}

/* The group's log distance per lane (0 where not traced), less the
 * receiver's level: with `centre`, the first group with a traced lane
 * sets it to the mean of its values. */
VERTEX_STEP void lane_log_distances(vertex_state *s, const packet_group *g, group_lanes *l)
{
    const float log_floor = s->J->log_floor;
    const int np = g->np;
    for (int p = 0; p < np; p++)
        for (int k = 0; k < VB_PACKET; k++) {
            float ln = fast_log(l->dist[p][k] > log_floor ? l->dist[p][k] : log_floor);
            l->logd[p][k] = ln * (float)(g->valid[p][k] & 1);
        }
    if (s->centre && !s->have_level) {
        float sum = 0.0f;
        uint32_t cnt = 0;
        for (int p = 0; p < np; p++)
            for (int k = 0; k < VB_PACKET; k++)
                if (g->valid[p][k]) {
                    sum += l->logd[p][k];
                    cnt++;
                }
        if (cnt) {
            s->level = sum / (float)cnt;
            s->have_level = 1;
        }
    }
    if (s->have_level) {
        const float level = s->level;
        for (int p = 0; p < np; p++)
            for (int k = 0; k < VB_PACKET; k++)
                l->logd[p][k] -= level * (float)(g->valid[p][k] & 1);
    }
}

/* The directions of a packet's lanes above the horizon (up), and their
 * distances where t is not NULL, appended at x[*n], y[*n], ... */
VERTEX_STEP void append_up_lanes(const int *up, const float *dx, const float *dy, const float *dz,
                                 const float *dist, float *x, float *y, float *z, float *t,
                                 uint32_t *n)
{
    for (int k = 0; k < VB_PACKET; k++)
        if (up[k]) {
            uint32_t i = (*n)++;
            x[i] = dx[k];
            y[i] = dy[k];
            z[i] = dz[k];
            if (t)
                t[i] = dist[k];
        }
}

/* The group's packets, in order, into the projections' sums, and their
 * lanes above the horizon into the per-ray outputs: the sink's rays
 * (out->n), the adaptive order's directions (var_buf), the adaptive rays'
 * directions (ax..az). */
VERTEX_STEP void accumulate_group(vertex_state *s, const packet_group *g, const group_lanes *l)
{
    const job *J = s->J;
    const vertex_sink *out = s->out;
    const uint32_t c = J->grid->count; /* var_buf's column stride */
    for (int p = 0; p < g->np; p++) {
        const float *dx = g->rh[p].ray.dir_x, *dy = g->rh[p].ray.dir_y, *dz = g->rh[p].ray.dir_z;
        const int *up_lane = l->up_lane[p];
        const float *dist = l->dist[p];
        if (s->want[0])
            vdsh_sh_project_soa(J->order, VB_PACKET, dx, dy, dz, dist, &s->acc[0][0][0], VB_PACKET);
        if (s->want[1])
            vdsh_sh_project_soa(J->order, VB_PACKET, dx, dy, dz, l->logd[p], &s->acc[1][0][0],
                                VB_PACKET);
        if (out->n)
            append_up_lanes(up_lane, dx, dy, dz, dist, out->x, out->y, out->z, out->t, out->n);
        if (s->var_buf)
            append_up_lanes(up_lane, dx, dy, dz, dist, s->var_buf, s->var_buf + c,
                            s->var_buf + 2 * c, s->var_buf + 3 * c, &s->var_n);
        if (J->adaptive)
            append_up_lanes(up_lane, dx, dy, dz, dist, s->ax, s->ay, s->az, NULL, &s->adapt_n);
    }
}

/* Adaptive rays, after round `round` (not the last): the round's fit of
 * the highest order, and, from the second round, the expected shadow
 * error between it and the last round's on this round's directions.
 * Returns 1 when that is below the tolerance: the receiver stops. */
VERTEX_STEP int adapt_round_stops(vertex_state *s, uint32_t round)
{
    const job *J = s->J;
    const int aq = s->want[1]; /* the quantity the stopping rule reads */
    float cur[VDSH_MAX_COEFFS];
    /* s->level is 0 unless aq: only the log distance is centred. */
    adapt_fit(J, s->n, s->acc[aq], s->cells_used, s->level, cur);
    int stop = 0;
    if (round > 0) {
        double sum = 0.0;
        for (uint32_t i = s->adapt_from; i < s->adapt_n; i++) {
            float dir[3] = {s->ax[i], s->ay[i], s->az[i]}, y[VDSH_MAX_COEFFS];
            vdsh_sh_eval(J->order, dir, y);
            double s1 = 0.0, s0 = 0.0;
            for (int j = 0; j < J->order * J->order; j++)
                s1 += (double)cur[j] * y[j], s0 += (double)s->adapt_prev[j] * y[j];
            double ratio;
            if (aq)
                ratio = vdsh_det_exp(s1 - s0);
            else {
                double tmin = 1e-4 * J->d->max_distance;
                ratio = (s1 > tmin ? s1 : tmin) / (s0 > tmin ? s0 : tmin);
            }
            sum += expected_error(J->error_table, ratio);
        }
        uint32_t m = s->adapt_n - s->adapt_from;
        stop = m == 0 || sum / m < J->ray_tol;
    }
    memcpy(s->adapt_prev, cur, sizeof cur);
    s->adapt_from = s->adapt_n;
    return stop;
}

/* Traces the receiver's directions, round by round with adaptive rays
 * (a round's fit from the second on decides whether to go on), and,
 * unless trace_only, projects them into s->acc. */
VERTEX_STEP void trace_vertex(vertex_state *s, uint64_t *traced, uint64_t *missed)
{
    const job *J = s->J;
    const int trace_only = J->d->trace_only;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    /* Packets are traced GROUP at a time, then their lanes are processed
     * together: the log's division and series are a long dependency
     * chain, which independent packets side by side keep the core busy
     * through. Every sum still runs in packet order. */
    const uint32_t rounds = J->adaptive ? J->grid->rounds : 1;
    for (uint32_t round = 0, pk = 0; round < rounds; round++) {
        const uint32_t pk_end = J->adaptive ? J->grid->round_end[round] : J->grid->packet_count;
        while (pk < pk_end) {
            packet_group g;
            pk = trace_group(s, &ctx, pk, pk_end, &g, traced);
            if (trace_only)
                continue;
            group_lanes l;
            lane_distances(s, &g, &l, missed);
            if (s->want[1])
                lane_log_distances(s, &g, &l);
            accumulate_group(s, &g, &l);
        }
        if (!J->adaptive || trace_only)
            continue;
        s->cells_used = pk * VB_PACKET;
        if (round + 1 < rounds && (s->want[0] || s->want[1]) && adapt_round_stops(s, round))
            break;
    }
}

/* The adaptive order's lsq choice (choose_order) on the receiver's
 * traced directions above its horizon. */
VERTEX_STEP void choose_var_order(const vertex_state *s, const double *u)
{
    uint32_t c = s->J->grid->count;
    float *b = s->var_buf;
    choose_order(s->J, s->v, &s->angles, u, b, b + c, b + 2 * c, b + 3 * c, s->var_n,
                 b + 4 * (size_t)c);
}

/* Each asked order's fit of each projected quantity into the sink, from
 * the projection b (in double: it sums over thousands of rays) through
 * the rotation's first half, done once for every order (the highest
 * order's leading bands are the lower orders'; fit.h). With the adaptive
 * order, the candidates' log fits into varc (decision), or the lsq choice
 * made (choose_order). u: the log distance's unrotated projection. */
VERTEX_STEP void fit_vertex(vertex_state *s, double u[VDSH_MAX_COEFFS],
                            float varc[VDSH_ORDER_SLOTS][VDSH_MAX_COEFFS])
{
    job *J = s->J;
    const vertex_sink *out = s->out;
    double w = (J->grid->hemisphere ? 2.0 : 4.0) * VB_PI / s->cells_used;
    int nb = J->order * J->order;
    for (int q = 0; q < 2; q++) {
        if (!s->want[q])
            continue;
        double b[VDSH_MAX_COEFFS];
        for (int i = 0; i < nb; i++) {
            double sum = 0.0;
            for (int k = 0; k < VB_PACKET; k++)
                sum += s->acc[q][i][k];
            b[i] = sum * w;
        }
        vb_fit_unrotate(s->top, &s->angles, b, u);
        if (q == 1 && s->have_level)
            vb_fit_add_constant(s->top, J->grid->hemisphere, s->level, u);
        for (int o = 1; o <= VDSH_MAX_ORDER; o++)
            if (out->coeffs[q][o])
                vb_fit_finish(&J->fits[o], &s->angles, u, out->coeffs[q][o]);
        if (q == 1 && s->dvar)
            for (int k = 1; k <= J->var_cap; k++)
                if (vb_order_candidate(k, J->var_cap))
                    vb_fit_finish(&J->fits[k], &s->angles, u, varc[k]);
        if (q == 1 && s->var_buf && !s->dvar)
            choose_var_order(s, u);
    }
}

/* The decision fit (method decision) and the adaptive order's outcome:
 * each order's offset cap into cap (-inf: none; also to out->cal_cap),
 * and, for a receiver of the range choosing its order by the decision
 * fit, that order and fit, or, with too few training pairs, the lsq
 * choice. */
VERTEX_STEP void decide_vertex(vertex_state *s, const double *u,
                               float varc[VDSH_ORDER_SLOTS][VDSH_MAX_COEFFS],
                               float cap[VDSH_ORDER_SLOTS])
{
    job *J = s->J;
    const vertex_sink *out = s->out;
    int var_k = 0;
    for (int o = 0; o <= VDSH_MAX_ORDER; o++)
        cap[o] = -INFINITY;
    const int fitted =
        J->decision && s->want[1]
            ? decision_vertex(J, s->v, s->org, s->n, out, s->dvar ? varc : NULL, &var_k, cap)
            : 0;
    if (out->cal_cap)
        memcpy(out->cal_cap, cap, VDSH_ORDER_SLOTS * sizeof *cap);
    if (!(s->var && s->dvar))
        return;
    uint32_t r = s->v - J->lo;
    J->var_lsq[r] = !fitted;
    if (fitted) { /* the decision's choice; its offset added after the bake */
        J->var_orders[r] = (uint8_t)var_k;
        float *dst = J->var_coeffs + (size_t)r * J->var_cap * J->var_cap;
        memset(dst, 0, (size_t)J->var_cap * J->var_cap * sizeof *dst);
        memcpy(dst, varc[var_k], (size_t)var_k * var_k * sizeof *dst);
    } else { /* too few training pairs: the lsq choice, shadow's offsets */
        choose_var_order(s, u);
    }
}

/* Methods shadow and decision: the log offset, through c0 (Y00 is a
 * constant), raised to the receiver's cap (outside the calibration: its
 * samples get theirs after it). */
VERTEX_STEP void add_log_offsets(const vertex_state *s, const float cap[VDSH_ORDER_SLOTS])
{
    job *J = s->J;
    const vertex_sink *out = s->out;
    for (int o = 1; o <= VDSH_MAX_ORDER; o++) {
        if (!out->coeffs[1][o])
            continue;
        float off = out->cal ? J->log_offset[o]
                             : capped_offset(J->log_offset[o], cap[o], J->free_offset[o]);
        if (!out->cal && cap[o] > J->log_offset[o])
            atomic_fetch_add(&J->cap_bound, 1);
        if (off != 0.0f)
            out->coeffs[1][o][0] += off / 0.28209479177387814f;
    }
}

/* Receiver v: trace its directions, project them, fit each asked order
 * into `out`; its traced and missed rays added to *traced and *missed,
 * and *degenerate counted up if nearly all its rays above the horizon
 * end at about zero distance. An AVX2 clone where the CPU has it, for
 * the lane loops (the log's division above all): no FMA, so the same
 * bits either way. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) &&                             \
    !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("avx2", "default")))
#endif
static void
bake_vertex(job *J, uint32_t v, const vertex_sink *out, uint64_t *traced, uint64_t *missed,
            uint32_t *degenerate)
{
    vertex_state s;
    vertex_begin(&s, J, v, out);
    trace_vertex(&s, traced, missed);
    if (J->d->trace_only)
        return;
    double u[VDSH_MAX_COEFFS];
    float varc[VDSH_ORDER_SLOTS][VDSH_MAX_COEFFS];
    fit_vertex(&s, u, varc);
    float cap[VDSH_ORDER_SLOTS];
    decide_vertex(&s, u, varc, cap);
    add_log_offsets(&s, cap);
    if (s.upper > 0 && s.near_zero >= 0.9 * s.upper)
        (*degenerate)++;
}

/* Floats of a worker's adaptive-order scratch: a receiver's traced
 * directions above its horizon (x, y, z, distance), then the basis at the
 * tested ones. */
static size_t var_scratch_floats(const job *J)
{
    return (size_t)4 * J->grid->count + (size_t)VDSH_MAX_COEFFS * VB_ORDER_DIRECTIONS;
}

static void bake_block(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    job *J = ctx;
    uint64_t traced = 0, missed = 0;
    uint32_t degenerate = 0;
    for (uint32_t v = begin < J->lo ? J->lo : begin; v < end && v < J->hi; v++) {
        if (J->done && J->done[v - J->lo])
            continue;
        vertex_sink out = {0};
        if (J->var_scratch)
            out.var_scratch = J->var_scratch + (size_t)worker * var_scratch_floats(J);
        if (J->dec_scratch)
            out.dec_scratch = J->dec_scratch + (size_t)worker * dec_scratch_bytes(J);
        for (int o = 1; o <= VDSH_MAX_ORDER; o++)
            if (J->coeffs[o])
                out.coeffs[J->quantity[o] == VDSH_QUANTITY_LOG_DISTANCE][o] =
                    J->coeffs[o] + (size_t)(v - J->lo) * o * o;
        bake_vertex(J, v, &out, &traced, &missed, &degenerate);
    }
    atomic_fetch_add(&J->traced, traced);
    atomic_fetch_add(&J->missed, missed);
    atomic_fetch_add(&J->degenerate, degenerate);
}

/* ---- the quantity choice's score ----------------------------------------- */

#define ERROR_TABLE 1024 /* e(r) tabulated on r in [0, 2] */

/* e(r): the mean over lights at d_L = 2u d (vdsh_light_u), of
 * |ramp(r / 2u) - ramp(1 / 2u)| - the expected shadow error of a direction
 * reconstructed at r times its true distance under vdsh-eval's relative
 * lights (flat from r = 2 on). By the mean over 512 u at the midpoints. */
static double *error_table_create(void)
{
    double *e = malloc((ERROR_TABLE + 1) * sizeof *e);
    for (int i = 0; e && i <= ERROR_TABLE; i++) {
        double r = 2.0 * i / ERROR_TABLE, sum = 0.0;
        for (int k = 0; k < 512; k++) {
            double u = vdsh_light_u((k + 0.5) / 512);
            sum += fabs((double)vdsh_ramp((float)(r / (2.0 * u))) -
                        (double)vdsh_ramp((float)(1.0 / (2.0 * u))));
        }
        e[i] = sum / 512;
    }
    return e;
}

static double expected_error(const double *e, double r)
{
    double x = r * (ERROR_TABLE / 2.0);
    if (!(x < ERROR_TABLE))
        return e[ERROR_TABLE];
    if (x < 0.0)
        x = 0.0;
    int i = (int)x;
    return e[i] + (x - i) * (e[i + 1] - e[i]);
}

float vb_shadow_log_offset(int order)
{
    const float *table = vb_method_get(VB_METHOD_SHADOW)->default_log_offset;
    return order >= 1 && order <= VDSH_MAX_ORDER ? table[order] : 0.0f;
}

/* ---- choosing the quantity (VB_QUANTITY_AUTO) --------------------------- */

#define CHOOSE_RECEIVERS 1024

/* How many receivers the choice samples, and the i-th of them. */
static uint32_t choose_count(uint32_t receivers)
{
    return receivers < CHOOSE_RECEIVERS ? receivers : CHOOSE_RECEIVERS;
}

static uint32_t choose_receiver(uint32_t i, uint32_t receivers, uint32_t count)
{
    return (uint32_t)((uint64_t)i * receivers / count);
}
#define CHOOSE_STRIDE VDSH_COEFFS_THROUGH(VDSH_MAX_ORDER) /* coefficients of orders 1..max */

/* Where order o starts among one sample's coefficients of one quantity. */
static size_t choose_offset(int o)
{
    return (size_t)(o - 1) * o * (2 * o - 1) / 6;
}

/* Add to e[o][q] the expected error of each asked order's fit of each
 * quantity, c[q][o], in each of the `count` traced directions of `out`.
 * A pass per fit over all directions, so that the sums vectorise: each
 * is still accumulated in the same order as one direction at a time
 * would, so the scores keep their bits. Scratch: `basis` holds
 * VDSH_MAX_COEFFS * grid count floats, `t` and `s` grid count doubles each. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) &&                             \
    !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("avx2", "default")))
#endif
static void
score_fits(const job *J, uint32_t count, const vertex_sink *out,
           float c[2][VDSH_ORDER_SLOTS][VDSH_MAX_COEFFS], float *basis, double *t, double *s,
           double e[VDSH_ORDER_SLOTS][2])
{
    const uint32_t cap = J->grid->count;
    const float tmin = 1e-4f * J->d->max_distance;
    vdsh_sh_eval_soa(J->order, count, out->x, out->y, out->z, basis, cap);
    for (uint32_t k = 0; k < count; k++)
        t[k] = out->t[k] > tmin ? out->t[k] : tmin;
    for (int o = 1; o <= VDSH_MAX_ORDER; o++) {
        if (!J->coeffs[o])
            continue;
        for (int q = 0; q < 2; q++) {
            for (uint32_t k = 0; k < count; k++)
                s[k] = 0.0;
            for (int j = 0; j < o * o; j++) {
                const double cj = c[q][o][j];
                const float *yj = basis + (size_t)j * cap;
                for (uint32_t k = 0; k < count; k++)
                    s[k] += cj * yj[k];
            }
            double sum = 0.0;
            for (uint32_t k = 0; k < count; k++) {
                double dv = q ? vdsh_det_exp(s[k]) : (s[k] > 0.0 ? s[k] : 0.0);
                sum += expected_error(J->error_table, dv / t[k]);
            }
            e[o][q] += sum;
        }
    }
}

/* Sampled receiver i: trace it, fit both quantities at every asked order,
 * and score each fit on the traced directions above the horizon. */
static void choose_block(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    job *J = ctx;
    (void)worker;
    uint32_t nrec = J->d->receivers->vertex_count, cap = J->grid->count;
    /* Per traced direction: x, y, z, distance, then the basis. */
    float *buf = malloc((size_t)cap * (4 + VDSH_MAX_COEFFS) * sizeof *buf);
    double *sums = malloc((size_t)cap * 2 * sizeof *sums);
    uint64_t traced = 0, missed = 0;
    uint32_t degenerate = 0;
    if (!sums) {
        free(buf);
        buf = NULL;
    }
    for (uint32_t i = begin; i < end && buf; i++) {
        uint32_t v = choose_receiver(i, nrec, J->choose_count), count = 0;
        float c[2][VDSH_ORDER_SLOTS][VDSH_MAX_COEFFS];
        vertex_sink out = {
            .x = buf, .y = buf + cap, .z = buf + 2 * cap, .t = buf + 3 * cap, .n = &count};
        for (int o = 1; o <= VDSH_MAX_ORDER; o++)
            if (J->coeffs[o])
                out.coeffs[0][o] = c[0][o], out.coeffs[1][o] = c[1][o];
        uint64_t t = 0, m = 0;
        uint32_t g = 0;
        bake_vertex(J, v, &out, &t, &m, &g);
        if (v >= J->lo && v < J->hi) /* a shard counts its own receivers */
            traced += t, missed += m, degenerate += g;
        float *keep = J->choose_coeffs + (size_t)i * 2 * CHOOSE_STRIDE;
        for (int q = 0; q < 2; q++)
            for (int o = 1; o <= VDSH_MAX_ORDER; o++)
                if (J->coeffs[o])
                    memcpy(keep + q * CHOOSE_STRIDE + choose_offset(o), c[q][o],
                           (size_t)o * o * sizeof(float));
        double e[VDSH_ORDER_SLOTS][2] = {{0}};
        score_fits(J, count, &out, c, buf + 4 * (size_t)cap, sums, sums + cap, e);
        double *dst = J->choose_error + (size_t)i * (VDSH_ORDER_SLOTS)*2;
        for (int o = 0; o <= VDSH_MAX_ORDER; o++)
            for (int q = 0; q < 2; q++)
                dst[2 * o + q] = count ? e[o][q] / count : 0.0;
    }
    if (!buf) /* out of memory: no vote from these receivers */
        for (uint32_t i = begin; i < end; i++)
            memset(J->choose_error + (size_t)i * (VDSH_ORDER_SLOTS)*2, 0,
                   (VDSH_ORDER_SLOTS)*2 * sizeof(double));
    else if (!J->var_cap) /* their coefficients are kept: the main pass skips them
                             * (with an adaptive order it bakes them again: the
                             * variable stream's quantity was not chosen yet) */
        for (uint32_t i = begin; i < end; i++) {
            uint32_t v = choose_receiver(i, nrec, J->choose_count);
            if (v >= J->lo && v < J->hi)
                J->done[v - J->lo] = 1;
        }
    atomic_fetch_add(&J->traced, traced);
    atomic_fetch_add(&J->missed, missed);
    atomic_fetch_add(&J->degenerate, degenerate);
    free(buf);
    free(sums);
}

/* The decision fit's calibration: sampled receiver i baked (kept, when in
 * the range: the main pass skips it), and its fits' margins on held-out
 * lights into cal_margins. */
static void calibrate_block(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    job *J = ctx;
    uint32_t nrec = J->d->receivers->vertex_count;
    uint64_t traced = 0, missed = 0;
    uint32_t degenerate = 0;
    for (uint32_t i = begin; i < end; i++) {
        uint32_t v = choose_receiver(i, nrec, J->choose_count);
        float c[VDSH_ORDER_SLOTS][VDSH_MAX_COEFFS];
        vertex_sink out = {.dec_scratch = J->dec_scratch + (size_t)worker * dec_scratch_bytes(J),
                           .cal = J->cal_margins + (size_t)i * VDSH_ORDER_SLOTS * CAL_LIGHTS,
                           .cal_cap = J->cal_caps + (size_t)i * VDSH_ORDER_SLOTS};
        if (J->var_scratch) /* its adaptive order too: the main pass skips it */
            out.var_scratch = J->var_scratch + (size_t)worker * var_scratch_floats(J);
        for (int o = 1; o <= VDSH_MAX_ORDER; o++)
            if (J->coeffs[o])
                out.coeffs[1][o] = c[o];
        uint64_t t = 0, m = 0;
        uint32_t g = 0;
        bake_vertex(J, v, &out, &t, &m, &g);
        if (v < J->lo || v >= J->hi)
            continue;
        traced += t, missed += m, degenerate += g; /* a shard counts its own */
        for (int o = 1; o <= VDSH_MAX_ORDER; o++)
            if (J->coeffs[o])
                memcpy(J->coeffs[o] + (size_t)(v - J->lo) * o * o, c[o],
                       (size_t)o * o * sizeof(float));
        memcpy(J->done_caps + (size_t)(v - J->lo) * VDSH_ORDER_SLOTS, out.cal_cap,
               VDSH_ORDER_SLOTS * sizeof(float));
        J->done[v - J->lo] = 1;
    }
    atomic_fetch_add(&J->traced, traced);
    atomic_fetch_add(&J->missed, missed);
    atomic_fetch_add(&J->degenerate, degenerate);
}

static void bake_progress(void *user, uint32_t done, uint32_t total)
{
    job *J = user;
    J->d->progress(J->d->progress_user, done, total, atomic_load(&J->traced));
}

void vb_bake_output_free(vb_bake_output *out)
{
    if (!out)
        return;
    for (int o = 0; o <= VDSH_MAX_ORDER; o++)
        free(out->coeffs[o]);
    free(out->variable_orders);
    free(out->variable_coeffs);
    free(out->normals);
    memset(out, 0, sizeof *out);
}

/* ---- vb_bake_run, step by step ------------------------------------------- */

/* One vb_bake_run: the resolved description, the method's row, what the
 * run allocates (run_free frees it, also half-built) and what it counts. */
typedef struct bake_run {
    vb_bake_desc d;
    const vb_method_info *mi;
    int var_cap;          /* adaptive order's cap; 0: none */
    int choose;           /* each order's quantity chosen on a sample */
    int calibrate;        /* the decision's log offsets calibrated */
    vdsh_quantity stored; /* the quantity when not chosen */
    vb_decision_params dec;
    uint32_t lo, hi; /* the range baked */
    vb_dirgrid grid;
    uint32_t *set, set_count, set_before; /* job's */
    float *origins, *near, *normals;
    float *coeffs[VDSH_ORDER_SLOTS];
    uint8_t *var_orders; /* adaptive order: the range's */
    float *var_coeffs;
    float (*lights)[3];
    vb_origins_stats ost;
    uint32_t flipped;
    job *J;
    double t0; /* when the tracing began */
    double auto_error[VDSH_ORDER_SLOTS][2];
    uint32_t auto_receivers, cal_count;
    uint32_t near_lights;  /* the decision pool's lights placed by the near rule */
    uint32_t shell_lights; /* ... and in the shell (vb_bake_desc.decision_shell) */
    unsigned started;      /* the workers of the bake */
} bake_run;

typedef vb_result (*bake_step)(bake_run *b, vb_error *err);

/* The orders: the fixed ones (order_mask), the projection's (max_order)
 * and adaptive order's cap. */
static vb_result resolve_orders(bake_run *b, vb_error *err)
{
    vb_bake_desc *d = &b->d;
    if (!d->receivers || !d->scene || d->receivers->vertex_count == 0)
        return vb_fail(err, VB_ERR_ARGUMENT, "nothing to bake: no receivers or no scene");
    if (d->rays == 0)
        d->rays = VB_DEFAULT_RAYS;
    if (d->order_mask & ~(uint32_t)(((1u << VDSH_MAX_ORDER) - 1) << 1))
        return vb_fail(err, VB_ERR_ARGUMENT, "orders must be 1..%d", VDSH_MAX_ORDER);
    /* Adaptive order: its cap is the projection's order at least; with no
     * fixed order asked, it is the only stream. */
    if (isnan(d->order_tolerance) || d->order_tolerance < 0.0f)
        return vb_fail(err, VB_ERR_ARGUMENT, "the order tolerance must be a number >= 0");
    if (d->order_tolerance > 0.0f) {
        b->var_cap = d->variable_cap ? d->variable_cap : VB_DEFAULT_ORDER_CAP;
        if (b->var_cap < 1 || b->var_cap > VDSH_MAX_ORDER)
            return vb_fail(err, VB_ERR_ARGUMENT, "the order cap must be 1..%d, not %d",
                           VDSH_MAX_ORDER, b->var_cap);
        if (d->max_order < b->var_cap)
            for (int o = b->var_cap; o <= VDSH_MAX_ORDER; o++)
                if (d->order_mask >> o)
                    d->max_order = o; /* the highest fixed order, if above the cap */
        if (d->max_order < b->var_cap)
            d->max_order = b->var_cap;
    }
    if (d->max_order == 0)
        for (int o = VDSH_MAX_ORDER; o >= 1 && !d->max_order; o--)
            if (d->order_mask & (1u << o))
                d->max_order = o;
    if (d->max_order == 0)
        d->max_order = VB_DEFAULT_ORDER;
    if (d->max_order < 1 || d->max_order > VDSH_MAX_ORDER)
        return vb_fail(err, VB_ERR_ARGUMENT, "order must be 1..%d, not %d", VDSH_MAX_ORDER,
                       d->max_order);
    if (d->order_mask == 0 && !b->var_cap)
        d->order_mask = 1u << d->max_order;
    if (d->order_mask >> (d->max_order + 1))
        return vb_fail(err, VB_ERR_ARGUMENT, "an order above max_order %d was asked for",
                       d->max_order);
    return VB_OK;
}

/* The method's row, and the quantity: what the method allows; auto is its
 * only one, if it has one, or the per-order choice (choose_quantities). */
static vb_result resolve_quantity(bake_run *b, vb_error *err)
{
    vb_bake_desc *d = &b->d;
    const vb_method_info *mi = b->mi = vb_method_get(d->method);
    if (!mi)
        return vb_fail(err, VB_ERR_ARGUMENT, "unknown method %d", (int)d->method);
    if (d->window > VDSH_WINDOW_LANCZOS)
        return vb_fail(err, VB_ERR_ARGUMENT, "unknown window %u", d->window);
    if (d->quantity != VB_QUANTITY_AUTO && d->quantity != VB_QUANTITY_DISTANCE &&
        d->quantity != VB_QUANTITY_LOG)
        return vb_fail(err, VB_ERR_ARGUMENT, "unknown quantity %d", (int)d->quantity);
    b->choose = d->quantity == VB_QUANTITY_AUTO;
    b->stored = vb_quantity_stored(d->quantity);
    if (b->choose && (mi->quantities & (mi->quantities - 1)) == 0) {
        b->choose = 0; /* the method's only one */
        b->stored = (vdsh_quantity)__builtin_ctz(mi->quantities);
    }
    if (!b->choose && !(mi->quantities & VB_QUANTITY_BIT(b->stored)))
        return vb_fail(err, VB_ERR_ARGUMENT, "%s", mi->refused[b->stored]);
    if (b->var_cap && !(mi->quantities & VB_QUANTITY_BIT(VDSH_QUANTITY_LOG_DISTANCE)))
        return vb_fail(err, VB_ERR_ARGUMENT,
                       "adaptive order fits the log distance: method %s does not (use shadow)",
                       vdsh_method_name(mi->stored));
    if (d->order_quantity) {
        b->choose = 0;
        for (int o = 1; o <= VDSH_MAX_ORDER; o++)
            if ((d->order_mask & (1u << o) || o == d->max_order) &&
                (d->order_quantity[o] > VDSH_QUANTITY_LOG_DISTANCE ||
                 !(mi->quantities & VB_QUANTITY_BIT(d->order_quantity[o]))))
                return vb_fail(err, VB_ERR_ARGUMENT, "order %d: quantity %u is not the method's", o,
                               (unsigned)d->order_quantity[o]);
    }
    return VB_OK;
}

/* The fit's regularisation, the distances and the thread count. */
static vb_result resolve_parameters(bake_run *b, vb_error *err)
{
    vb_bake_desc *d = &b->d;
    if (d->lambda == 0.0f)
        d->lambda = VB_DEFAULT_LAMBDA;
    if (!(d->lambda > 0.0f) || !isfinite(d->lambda))
        return vb_fail(err, VB_ERR_ARGUMENT, "the regularisation must be a positive number");
    if (d->max_distance == 0.0f)
        d->max_distance = d->scene->diagonal;
    if (!(d->max_distance > 0.0f) || !isfinite(d->max_distance))
        return vb_fail(err, VB_ERR_ARGUMENT,
                       "max distance must be finite and > 0 (scene diagonal %g)",
                       (double)d->scene->diagonal);
    if (d->log_floor == 0.0f)
        d->log_floor = 0.01f * d->max_distance;
    if (!(d->log_floor > 0.0f) || !isfinite(d->log_floor))
        return vb_fail(err, VB_ERR_ARGUMENT, "the log-distance floor must be a positive number");
    d->threads = vb_parallel_threads(d->threads);
    return VB_OK;
}

/* Finite receivers, indices in range, and the range baked (lo..hi). */
static vb_result check_receivers(bake_run *b, vb_error *err)
{
    const vb_mesh *R = b->d.receivers;
    for (size_t i = 0; i < 3 * (size_t)R->vertex_count; i++)
        if (!isfinite(R->positions[i]) || !isfinite(R->normals[i]))
            return vb_fail(err, VB_ERR_INVALID, "receiver %zu has a non-finite position or normal",
                           i / 3);
    for (size_t i = 0; i < 3 * (size_t)R->triangle_count; i++)
        if (R->indices[i] >= R->vertex_count)
            return vb_fail(err, VB_ERR_INVALID,
                           "receiver triangle %zu: index %u out of range (%u vertices)", i / 3,
                           R->indices[i], R->vertex_count);
    b->lo = b->d.range_begin;
    b->hi = b->d.range_end ? b->d.range_end : R->vertex_count;
    if (b->lo >= b->hi || b->hi > R->vertex_count)
        return vb_fail(err, VB_ERR_ARGUMENT, "receiver range %u..%u is not within 0..%u",
                       b->d.range_begin, b->d.range_end, R->vertex_count);
    return VB_OK;
}

/* Method decision: the log offsets calibrated on a sample of receivers
 * (unless given), whose receivers every shard bakes too; the fit's
 * settings. */
static vb_result resolve_decision(bake_run *b, vb_error *err)
{
    vb_bake_desc *d = &b->d;
    b->calibrate = b->mi->decision && !d->log_offsets && !d->trace_only;
    b->choose = b->choose && !d->trace_only;
    if (d->decision_lights == 0)
        d->decision_lights = VB_DEFAULT_DECISION_LIGHTS;
    if (d->decision_lights > VB_DECISION_MAX_PAIRS)
        return vb_fail(err, VB_ERR_ARGUMENT, "decision lights must be 1..%u, not %u",
                       VB_DECISION_MAX_PAIRS, d->decision_lights);
    if (d->false_rate == 0.0f)
        d->false_rate = VB_DEFAULT_FALSE_RATE;
    if (d->decision_near == 0)
        d->decision_near = VB_DEFAULT_DECISION_NEAR;
    if (d->decision_near > (int)VB_DECISION_POOL)
        return vb_fail(err, VB_ERR_ARGUMENT, "decision near share must be 1 in 1..%u, not 1 in %d",
                       VB_DECISION_POOL, d->decision_near);
    if (d->decision_shell < 0 || d->decision_shell > (int)VB_DECISION_POOL)
        return vb_fail(err, VB_ERR_ARGUMENT,
                       "decision shell share must be 1 in 1..%u (0: none), not 1 in %d",
                       VB_DECISION_POOL, d->decision_shell);
    if (!(d->false_rate > 0.0f && d->false_rate < 0.5f))
        return vb_fail(err, VB_ERR_ARGUMENT, "the false rate must be in (0, 0.5)");
    if (d->offset_cap_keep == 0.0f)
        d->offset_cap_keep = 1.0f;
    if (d->offset_cap_min == 0)
        d->offset_cap_min = 1;
    if (d->offset_cap && !b->mi->decision)
        return vb_fail(err, VB_ERR_ARGUMENT, "the offset cap is method decision's");
    if (d->offset_cap && (!(fabsf(d->offset_cap_tol) <= 5.0f) ||
                          !(d->offset_cap_keep > 0.0f && d->offset_cap_keep <= 1.0f)))
        return vb_fail(err, VB_ERR_ARGUMENT,
                       "the offset cap's tolerance must be in -5..5 and its share in (0, 1]");
    vb_decision_defaults(&b->dec);
    if (d->decision)
        b->dec = *d->decision;
    const vb_decision_params *dec = &b->dec;
    if (!(dec->tau > 0.0f) || !(dec->lit_weight > 0.0f) || !(dec->ridge >= 0.0f) ||
        !(dec->ridge0 > 0.0f) || dec->steps < 0 || dec->steps > 64)
        return vb_fail(err, VB_ERR_ARGUMENT, "decision settings out of range");
    return VB_OK;
}

/* The sampling domain (the method's row): the whole sphere (paper's
 * horizon culls half of it), or the hemisphere above each receiver, with
 * half the directions (the same traced budget); nested for adaptive rays. */
static vb_result create_grid(bake_run *b, vb_error *err)
{
    vb_bake_desc *d = &b->d;
    int hemisphere = b->mi->hemisphere;
    uint32_t domain_rays = hemisphere ? (d->rays + 1) / 2 : d->rays;
    if (!d->adaptive_rays)
        return vb_dirgrid_create(domain_rays, hemisphere, &b->grid, err);
    if (d->ray_tolerance == 0.0f)
        d->ray_tolerance = VB_DEFAULT_RAY_TOLERANCE;
    if (d->ray_tolerance < 0.0f)
        d->ray_tolerance = 0.0f;
    if (isnan(d->ray_tolerance))
        return vb_fail(err, VB_ERR_ARGUMENT, "the ray tolerance must be a number >= 0");
    if (domain_rays > 4096)
        return vb_fail(err, VB_ERR_ARGUMENT,
                       "adaptive rays: the cap must be at most %u rays, not %u",
                       hemisphere ? 8192u : 4096u, d->rays);
    return vb_dirgrid_create_nested(domain_rays, hemisphere, &b->grid, err);
}

/* A range: only its receivers, and the quantity choice's sample, are
 * oriented and given origins (counted: the range's), and the arrays hold
 * them only (vb_receivers_prepare's set), so a shard's memory is its
 * range's. The whole bake: set NULL, every receiver. */
static vb_result select_receivers(bake_run *b, vb_error *err)
{
    const uint32_t V = b->d.receivers->vertex_count, lo = b->lo, hi = b->hi;
    b->set_count = V;
    b->set_before = 0;
    if (lo == 0 && hi >= V)
        return VB_OK;
    uint32_t samples = (b->choose || b->calibrate) ? choose_count(V) : 0;
    if (!(b->set = malloc(((size_t)(hi - lo) + samples) * sizeof *b->set)))
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for %u receivers", hi - lo);
    /* Ascending: the samples before the range, the range, those after. */
    uint32_t *set = b->set, n = 0;
    for (uint32_t i = 0; i < samples; i++) {
        uint32_t v = choose_receiver(i, V, samples);
        if (v < lo)
            set[n++] = v;
    }
    b->set_before = n;
    for (uint32_t v = lo; v < hi; v++)
        set[n++] = v;
    for (uint32_t i = 0; i < samples; i++) {
        uint32_t v = choose_receiver(i, V, samples);
        if (v >= hi)
            set[n++] = v;
    }
    b->set_count = n;
    return VB_OK;
}

/* The per-receiver arrays, the job, adaptive order's arrays and lights,
 * and the fits of every order the bake projects. */
static vb_result allocate_arrays(bake_run *b, vb_error *err)
{
    const vb_bake_desc *d = &b->d;
    const uint32_t V = d->receivers->vertex_count, n = b->hi - b->lo;
    b->origins = malloc((size_t)b->set_count * 3 * sizeof *b->origins);
    b->near = malloc((size_t)b->set_count * sizeof *b->near + 1);
    /* Oriented receivers: a copy of their normals, turned toward free
     * space (origins.h); the bake then reads the copy. */
    b->normals = d->keep_normals ? NULL : malloc((size_t)b->set_count * 3 * sizeof *b->normals + 1);
    int missing = !d->keep_normals && !b->normals;
    /* A range: its rows only (bake.h), so a shard's coefficients are its
     * own range's size. */
    for (int o = 1; o <= VDSH_MAX_ORDER && !d->trace_only; o++)
        if (d->order_mask & (1u << o))
            missing |= !(b->coeffs[o] = malloc((size_t)n * o * o * sizeof(float)));
    b->J = calloc(1, sizeof *b->J);
    if (!b->origins || !b->near || missing || !b->J)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for %u receivers", V);
    const int cap = b->var_cap;
    if (cap && !d->trace_only) {
        b->var_orders = malloc((size_t)n + 1);
        b->var_coeffs = malloc((size_t)n * cap * cap * sizeof(float));
        b->lights = malloc(VB_ORDER_LIGHTS * sizeof *b->lights);
        if (!b->var_orders || !b->var_coeffs || !b->lights)
            return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for %u receivers", V);
        vb_result r =
            vb_scene_place_lights(d->scene, d->seed, VB_ORDER_LIGHTS, b->lights, NULL, err);
        if (r != VB_OK)
            return r;
    }
    for (int o = 1; o <= VDSH_MAX_ORDER; o++) {
        if (!b->coeffs[o] && o != d->max_order && o > cap) /* the top one rotates for all */
            continue;
        vb_result r =
            vb_fit_create(o, b->mi->fit, vb_fit_lambda(d->lambda, o), &b->J->fits[o], err);
        if (r != VB_OK)
            return r;
        vb_fit_window(&b->J->fits[o], d->window);
    }
    return VB_OK;
}

/* Orient the receivers and place their ray origins (origins.h). */
static vb_result prepare_receivers(bake_run *b, vb_error *err)
{
    return vb_receivers_prepare(b->d.receivers, b->d.scene, b->d.threads, b->set, b->set_count,
                                b->lo, b->hi, b->normals, &b->flipped, b->origins, b->near, &b->ost,
                                err);
}

/* The job the workers read: the run's settings and arrays, adaptive
 * order's scratch. */
static vb_result setup_job(bake_run *b, vb_error *err)
{
    vb_bake_desc *d = &b->d;
    const vb_method_info *mi = b->mi;
    job *J = b->J;
    J->lo = b->lo;
    J->hi = b->hi;
    J->set = b->set;
    J->set_count = b->set_count;
    J->set_before = b->set_before;
    J->normals = b->normals;
    J->d = d;
    J->grid = &b->grid;
    J->origins = b->origins;
    J->near = b->near;
    memcpy(J->coeffs, b->coeffs, sizeof b->coeffs);
    J->order = d->max_order;
    J->log_floor = d->log_floor;
    J->max_local = d->max_distance * d->scene->scale;
    J->inv_scale = 1.0f / d->scene->scale;
    J->horizon = mi->horizon;
    J->adaptive = d->adaptive_rays != 0;
    J->ray_tol = d->ray_tolerance;
    J->var_cap = b->var_orders ? b->var_cap : 0;
    J->var_tol = d->order_tolerance;
    J->lights = b->lights;
    J->light_count = VB_ORDER_LIGHTS;
    J->var_orders = b->var_orders;
    J->var_coeffs = b->var_coeffs;
    if (b->var_orders &&
        !(J->var_scratch = malloc(d->threads * var_scratch_floats(J) * sizeof(float))))
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    return VB_OK;
}

/* Slots first, first + every, ... of the training pool (traced frame)
 * replaced by VB_DECISION_POOL / every lights placed by `rule` with
 * `seed`; *placed their count (0 on failure, the pool unchanged). */
static vb_result mix_rule(const vb_bake_desc *d, float (*pool)[3], vb_light_rule rule,
                          uint64_t seed, uint32_t every, uint32_t first, uint32_t *placed,
                          vb_error *err)
{
    const uint32_t n = VB_DECISION_POOL / every;
    *placed = 0;
    float(*lights)[3] = malloc((size_t)n * sizeof *lights + 1);
    if (!lights)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    vb_result r = vb_scene_place_lights_rule(d->scene, seed, n, rule, lights, NULL, err);
    if (r == VB_OK) {
        for (uint32_t i = 0; i < n; i++)
            vb_scene_to_local(d->scene, lights[i], pool[(size_t)i * every + first]);
        *placed = n;
    }
    free(lights);
    return r;
}

/* The training pool: the pool with one in d->decision_near of its slots
 * (K-1, 2K-1, ...) replaced by a light placed by the near rule (bake.h,
 * VB_DEFAULT_DECISION_NEAR); the calibration keeps the pool as placed.
 * Where the near rule finds no room for them all (or no memory), the
 * training pool is the pool. Returns the lights placed. */
static uint32_t mix_near(const vb_bake_desc *d, float (*pool)[3])
{
    uint32_t placed = 0;
    vb_error ignored;
    if (d->decision_near > 0) {
        const uint32_t every = (uint32_t)d->decision_near;
        mix_rule(d, pool, VB_LIGHTS_NEAR, d->seed ^ VB_POOL_SEED ^ VB_NEAR_SEED, every, every - 1,
                 &placed, &ignored);
    }
    return placed;
}

/* Slots 0, K, 2K, ... of the training pool (K = d->decision_shell)
 * replaced by lights in the shell around the bounds (bake.h,
 * vb_bake_desc.decision_shell). No room is an error: a closed room (faces
 * inward) whose bounds are about as deep as they are wide, seen from
 * anywhere in the shell, shows some probe the back of a wall
 * (tests/data/cube_room.obj). */
static vb_result mix_shell(const vb_bake_desc *d, float (*pool)[3], uint32_t *placed, vb_error *err)
{
    const uint32_t every = (uint32_t)d->decision_shell;
    vb_result r = mix_rule(d, pool, VB_LIGHTS_SHELL, d->seed ^ VB_POOL_SEED ^ VB_SHELL_SEED, every,
                           0, placed, err);
    if (r != VB_OK && r != VB_ERR_OUT_OF_MEMORY) {
        vb_error why = *err;
        vb_fail(err, r,
                "decision shell (one in %u training lights): no room for %u light%s in the shell "
                "around the scene's bounds (%s); outside a closed room every point sees the "
                "backs of its walls, so the shell is for objects",
                every, VB_DECISION_POOL / every, vdsh_s(VB_DECISION_POOL / every), why.msg);
    }
    return r;
}

/* The per-order log offsets, for the methods that have them; method
 * decision: the pool of lights in free space (traced frame) and the
 * workers' scratch (no free space: the lsq fits are kept); adaptive
 * order's offsets; the quantity choice's error table. */
static vb_result setup_offsets(bake_run *b, vb_error *err)
{
    const vb_bake_desc *d = &b->d;
    const vb_method_info *mi = b->mi;
    job *J = b->J;
    for (int o = 1; o <= VDSH_MAX_ORDER && mi->param == VB_PARAM_LOG_OFFSET; o++) {
        J->log_offset[o] = J->free_offset[o] =
            d->log_offsets ? d->log_offsets[o] : mi->default_log_offset[o];
        if (!isfinite(J->log_offset[o]) || fabsf(J->log_offset[o]) > 5.0f)
            return vb_fail(err, VB_ERR_ARGUMENT, "order %d: log offset %g is not in -5..5", o,
                           (double)J->log_offset[o]);
    }
    J->dec = b->dec;
    J->dec_lights = d->decision_lights;
    J->cap_on = d->offset_cap;
    J->cap_tol = d->offset_cap ? d->offset_cap_tol : 0.0f;
    J->cap_keep = d->offset_cap_keep;
    J->cap_min = d->offset_cap_min;
    if (mi->decision && !d->trace_only) {
        J->pool = malloc(VB_DECISION_POOL * sizeof *J->pool);
        if (!J->pool)
            return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
        vb_error perr;
        if (d->pool ? d->pool_count == VB_DECISION_POOL
                    : vb_scene_place_pool(d->scene, d->seed ^ VB_POOL_SEED, VB_DECISION_POOL,
                                          J->pool, 0, NULL, &perr) == VB_OK) {
            for (uint32_t k = 0; k < VB_DECISION_POOL; k++)
                vb_scene_to_local(d->scene, d->pool ? d->pool + 3 * k : J->pool[k], J->pool[k]);
            J->cal_pool = J->pool;
            if (d->decision_near > 0 || d->decision_shell > 0) {
                if (!(J->pool = malloc(VB_DECISION_POOL * sizeof *J->pool)))
                    return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
                memcpy(J->pool, J->cal_pool, VB_DECISION_POOL * sizeof *J->pool);
                b->near_lights = mix_near(d, J->pool);
                if (d->decision_shell > 0) {
                    vb_result r = mix_shell(d, J->pool, &b->shell_lights, err);
                    if (r != VB_OK)
                        return r;
                }
            }
            J->pool_count = VB_DECISION_POOL;
            J->decision = 1;
            size_t bytes = dec_scratch_bytes(J) * d->threads;
            if (!(J->dec_scratch = aligned_alloc(64, (bytes + 63) & ~(size_t)63)))
                return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
        }
    }
    /* Adaptive order with the decision fit: its choice and fits are the
     * decision's (choose_decision), with the decision's offsets (one
     * calibrated for the stream, else the given ones). */
    J->var_decision = J->var_cap && J->decision;
    if (J->var_decision && !(J->var_lsq = calloc((size_t)(b->hi - b->lo), 1)))
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    J->var_dec_offset = J->log_offset[J->var_cap];
    for (int o = 1; o <= VDSH_MAX_ORDER; o++)
        J->var_offset[o] = mi->decision && !d->log_offsets
                               ? vb_method_get(VB_METHOD_SHADOW)->default_log_offset[o]
                               : J->log_offset[o];
    /* The quantity choice's score: the expected shadow error e(r). */
    if ((b->choose || J->adaptive) && !(J->error_table = error_table_create()))
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    return VB_OK;
}

/* Per order, the quantity whose fits reconstruct the traced distances of a
 * sample of receivers with the lower expected shadow error; sums in sample
 * order, so the choice does not depend on the thread count. Without the
 * choice: the asked or the method's quantity. */
static vb_result choose_quantities(bake_run *b, vb_error *err)
{
    const vb_bake_desc *d = &b->d;
    job *J = b->J;
    const uint32_t V = d->receivers->vertex_count;
    b->t0 = vb_now();
    if (!b->choose || d->trace_only) {
        for (int o = 1; o <= VDSH_MAX_ORDER; o++)
            J->quantity[o] = d->order_quantity ? d->order_quantity[o]
                             : b->choose       ? VDSH_QUANTITY_DISTANCE
                                               : b->stored;
        return VB_OK;
    }
    b->auto_receivers = J->choose_count = choose_count(V);
    J->choose_error = calloc((size_t)J->choose_count * (VDSH_ORDER_SLOTS)*2, sizeof(double));
    J->choose_coeffs = malloc((size_t)J->choose_count * 2 * CHOOSE_STRIDE * sizeof(float));
    J->done = calloc((size_t)(b->hi - b->lo), 1);
    if (!J->choose_error || !J->choose_coeffs || !J->done)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    if (vb_parallel_for(d->threads, J->choose_count, 4, choose_block, J, NULL, NULL) == 0)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "cannot start worker threads");
    double(*auto_error)[2] = b->auto_error;
    for (uint32_t i = 0; i < J->choose_count; i++)
        for (int o = 1; o <= VDSH_MAX_ORDER; o++)
            for (int q = 0; q < 2; q++)
                auto_error[o][q] += J->choose_error[((size_t)i * (VDSH_ORDER_SLOTS) + o) * 2 + q];
    for (int o = 1; o <= VDSH_MAX_ORDER; o++) {
        auto_error[o][0] /= J->choose_count;
        auto_error[o][1] /= J->choose_count;
        J->quantity[o] = auto_error[o][1] < auto_error[o][0] ? VDSH_QUANTITY_LOG_DISTANCE
                                                             : VDSH_QUANTITY_DISTANCE;
    }
    /* The sampled receivers are baked: keep the chosen fits. */
    for (uint32_t i = 0; i < J->choose_count; i++) {
        uint32_t v = choose_receiver(i, V, J->choose_count);
        const float *keep = J->choose_coeffs + (size_t)i * 2 * CHOOSE_STRIDE;
        for (int o = 1; o <= VDSH_MAX_ORDER; o++)
            if (b->coeffs[o] && v >= J->lo && v < J->hi && J->done[v - J->lo])
                memcpy(b->coeffs[o] + (size_t)(v - J->lo) * o * o,
                       keep + (J->quantity[o] == VDSH_QUANTITY_LOG_DISTANCE) * CHOOSE_STRIDE +
                           choose_offset(o),
                       (size_t)o * o * sizeof(float));
    }
    return VB_OK;
}

/* Lit pairs (margins m[i] of receivers with caps cap[i]) drawn in shadow
 * at log offset off: m + max(off, cap) < 0. */
static uint32_t capped_false(const float *m, const float *cap, uint32_t count, float off,
                             float uncapped)
{
    uint32_t f = 0;
    for (uint32_t i = 0; i < count; i++)
        f += m[i] + capped_offset(off, cap[i], uncapped) < 0.0f;
    return f;
}

/* vb_decision_offset through the receivers' caps: the least offset -m[j]
 * that leaves at most rate * count of the lit pairs in false shadow,
 * each at its receiver's capped offset (capped_offset; receivers without
 * a cap at `uncapped`, whatever the offset). The count falls as the offset
 * rises, so a bisection over the candidates, sorted; the greatest where
 * none is within the rate. */
static float capped_rate_offset(const float *m, const float *cap, uint32_t count, double rate,
                                float uncapped)
{
    if (count == 0)
        return 0.0f;
    float *cand = malloc((size_t)count * sizeof *cand);
    if (!cand)
        return 0.0f;
    for (uint32_t i = 0; i < count; i++)
        cand[i] = -m[i];
    qsort(cand, count, sizeof *cand, cmp_margin);
    uint32_t k = (uint32_t)(rate * count);
    if (k >= count)
        k = count - 1;
    /* The first candidate whose false count is within k, else the last. */
    uint32_t lo = 0, hi = count - 1;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (capped_false(m, cap, count, cand[mid], uncapped) <= k)
            hi = mid;
        else
            lo = mid + 1;
    }
    float off = cand[lo];
    free(cand);
    return off;
}

/* The calibrated log offset of margin slot `slot` (an order; 0: the
 * adaptive order's chosen fits): the lit held-out margins of the
 * cal_count samples gathered into lit, offset for false_rate, within
 * -5..5; and not below 0 when no held-out light was shadowed (an offset
 * below 0 trades false shadows for recall, and there is nothing to
 * recall: a closed object's corners, which then shortened every
 * distance by up to e^-2.3). */
static float slot_offset(const job *J, uint32_t cal_count, int slot, float false_rate, float *lit,
                         float *lit_cap, int capped)
{
    uint32_t k = 0;
    for (uint32_t i = 0; i < cal_count; i++)
        for (uint32_t j = 0; j < CAL_LIGHTS; j++) {
            float m =
                J->cal_margins[((size_t)i * VDSH_ORDER_SLOTS + (size_t)slot) * CAL_LIGHTS + j];
            if (!isnan(m)) {
                lit_cap[k] = J->cal_caps[(size_t)i * VDSH_ORDER_SLOTS + (size_t)slot];
                lit[k++] = m;
            }
        }
    float off = capped ? capped_rate_offset(lit, lit_cap, k, false_rate, J->free_offset[slot])
                       : vb_decision_offset(lit, k, false_rate);
    if (atomic_load(&J->cal_shadowed) == 0 && off < 0.0f)
        off = 0.0f;
    return off < -5.0f ? -5.0f : off > 5.0f ? 5.0f : off;
}

/* The decision fit's log offsets: per order, the one that leaves
 * false_rate of the lit pairs of held-out lights in false shadow, over a
 * sample of receivers, in sample order. */
static vb_result calibrate_offsets(bake_run *b, vb_error *err)
{
    const vb_bake_desc *d = &b->d;
    job *J = b->J;
    if (!b->calibrate || !J->decision)
        return VB_OK;
    const uint32_t cal_count = b->cal_count = J->choose_count =
        choose_count(d->receivers->vertex_count);
    J->done = calloc((size_t)(b->hi - b->lo), 1);
    J->cal_margins = malloc((size_t)cal_count * VDSH_ORDER_SLOTS * CAL_LIGHTS * sizeof(float));
    J->cal_caps = malloc((size_t)cal_count * VDSH_ORDER_SLOTS * sizeof(float));
    J->done_caps = malloc((size_t)(b->hi - b->lo) * VDSH_ORDER_SLOTS * sizeof(float));
    float *lit = malloc((size_t)cal_count * CAL_LIGHTS * sizeof(float) + 1);
    float *lit_cap = malloc((size_t)cal_count * CAL_LIGHTS * sizeof(float) + 1);
    vb_result r = VB_OK;
    if (!J->done || !J->cal_margins || !J->cal_caps || !J->done_caps || !lit || !lit_cap)
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    else if (vb_parallel_for(d->threads, cal_count, 4, calibrate_block, J, NULL, NULL) == 0)
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "cannot start worker threads");
    for (int o = 1; o <= VDSH_MAX_ORDER && r == VB_OK; o++)
        if (b->coeffs[o])
            J->log_offset[o] = J->free_offset[o] =
                slot_offset(J, cal_count, o, d->false_rate, lit, lit_cap, 0);
    /* With the cap: that offset stays the uncapped receivers' (free_offset),
     * and the others' is calibrated again through their caps. */
    for (int o = 1; o <= VDSH_MAX_ORDER && r == VB_OK && J->cap_on; o++)
        if (b->coeffs[o])
            J->log_offset[o] = slot_offset(J, cal_count, o, d->false_rate, lit, lit_cap, 1);
    /* The adaptive order's stream: one offset, from each sample's chosen
     * fit (slot 0), whatever its order. */
    if (J->var_decision && r == VB_OK)
        J->var_dec_offset = slot_offset(J, cal_count, 0, d->false_rate, lit, lit_cap, 0);
    free(lit);
    free(lit_cap);
    return r;
}

/* Trace and project every receiver of the range on the workers; the
 * calibration's receivers were baked before their offset, which is added
 * to them here. */
static vb_result bake_receivers(bake_run *b, vb_error *err)
{
    const vb_bake_desc *d = &b->d;
    job *J = b->J;
    const uint32_t lo = b->lo, hi = b->hi;
    b->started = vb_parallel_for(d->threads, d->receivers->vertex_count, BLOCK, bake_block, J,
                                 d->progress ? bake_progress : NULL, J);
    for (uint32_t v = lo; b->cal_count && J->done && v < hi; v++)
        if (J->done[v - lo])
            for (int o = 1; o <= VDSH_MAX_ORDER; o++)
                if (b->coeffs[o]) {
                    float cap = J->done_caps[(size_t)(v - lo) * VDSH_ORDER_SLOTS + o];
                    float off = capped_offset(J->log_offset[o], cap, J->free_offset[o]);
                    atomic_fetch_add(&J->cap_bound, cap > J->log_offset[o]);
                    b->coeffs[o][(size_t)(v - lo) * o * o] += off / 0.28209479177387814f;
                }
    /* The adaptive order's decision fits: their offset, now known. */
    for (uint32_t v = lo; J->var_decision && v < hi; v++)
        if (!J->var_lsq[v - lo])
            b->var_coeffs[(size_t)(v - lo) * b->var_cap * b->var_cap] +=
                J->var_dec_offset / 0.28209479177387814f;
    if (b->started == 0)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "cannot start worker threads");
    return VB_OK;
}

/* The output: the settings as resolved, the counts, and the arrays (moved
 * out of the run, so that run_free leaves them). */
static void fill_output(bake_run *b, vb_bake_output *out)
{
    const vb_bake_desc *d = &b->d;
    const vb_method_info *mi = b->mi;
    const vb_mesh *R = d->receivers;
    job *J = b->J;
    uint32_t undefined = 0;
    for (uint32_t v = 0; v < R->vertex_count; v++) {
        const float *n = R->normals + 3 * (size_t)v;
        undefined += n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f;
    }

    vb_bake_output o = {0};
    o.max_order = d->max_order;
    o.method = mi->stored;
    int any_log = 0;
    for (int k = 0; k <= VDSH_MAX_ORDER; k++) {
        o.quantity[k] = J->quantity[k];
        any_log |= b->coeffs[k] && J->quantity[k] == VDSH_QUANTITY_LOG_DISTANCE;
    }
    o.auto_receivers = b->auto_receivers;
    memcpy(o.auto_error, b->auto_error, sizeof b->auto_error);
    o.lambda = mi->regularised ? d->lambda : 0.0f;
    memcpy(o.log_offset, J->log_offset, sizeof o.log_offset);
    any_log |= b->var_orders != NULL;
    o.log_floor = any_log ? d->log_floor : 0.0f;
    if (mi->decision) {
        o.decision_lights = J->decision ? d->decision_lights : 0;
        o.decision_near_lights = J->decision ? b->near_lights : 0;
        o.decision_shell_lights = J->decision ? b->shell_lights : 0;
        o.decision_fitted = atomic_load(&J->dec_fitted);
        o.decision_fallbacks = atomic_load(&J->dec_fallbacks);
        o.decision_pairs =
            o.decision_fitted ? (double)atomic_load(&J->dec_pairs) / o.decision_fitted : 0.0;
        o.calibration_receivers = b->cal_count;
        o.decision_rays = atomic_load(&J->dec_rays);
        o.false_rate = b->cal_count ? d->false_rate : 0.0f;
        o.cap_bound = atomic_load(&J->cap_bound);
        o.lit_training = atomic_load(&J->lit_training);
        o.lit_training_false = atomic_load(&J->lit_false);
        o.calibration_shadowed = atomic_load(&J->cal_shadowed);
        if (J->decision) {
            float lo[3], hi[3];
            o.light_region_grown = vb_scene_light_region(d->scene, lo, hi, &o.light_region_probes);
            o.light_region_given = d->scene->region_given;
        }
    }
    o.window = d->window;
    o.vertex_count = R->vertex_count;
    o.range_begin = J->lo;
    o.range_end = J->hi;
    memcpy(o.coeffs, b->coeffs, sizeof b->coeffs);
    memset(b->coeffs, 0, sizeof b->coeffs);
    o.variable_orders = b->var_orders;
    o.variable_coeffs = b->var_coeffs;
    o.variable_cap = b->var_orders ? b->var_cap : 0;
    o.order_tolerance = b->var_orders ? d->order_tolerance : 0.0f;
    o.variable_method = J->var_decision ? VDSH_METHOD_DECISION
                        : mi->decision  ? VDSH_METHOD_SHADOW
                                        : mi->stored;
    o.variable_param = J->var_decision ? J->var_dec_offset
                       : b->var_orders && mi->param == VB_PARAM_LOG_OFFSET
                           ? J->var_offset[b->var_cap]
                           : o.lambda;
    b->var_orders = NULL;
    b->var_coeffs = NULL;
    o.rays = b->grid.count;
    o.ray_tolerance = J->adaptive ? d->ray_tolerance : 0.0f;
    o.hemisphere = b->grid.hemisphere;
    o.max_distance = d->max_distance;
    o.threads = b->started;
    o.rays_traced = atomic_load(&J->traced);
    o.rays_missed = atomic_load(&J->missed);
    o.degenerate_receivers = atomic_load(&J->degenerate);
    o.undefined_normals = undefined;
    const size_t rows = (size_t)(b->hi - b->lo);
    if (b->normals && b->set) { /* the range's rows (bake.h) */
        memmove(b->normals, b->normals + 3 * (size_t)b->set_before, rows * 3 * sizeof *b->normals);
        float *shrunk = realloc(b->normals, rows * 3 * sizeof *b->normals);
        if (shrunk)
            b->normals = shrunk;
    }
    o.normals = b->normals;
    b->normals = NULL;
    o.flipped_normals = b->flipped;
    o.moved_origins = b->ost.moved;
    o.origins = b->ost;
    o.seconds = vb_now() - b->t0;
    *out = o;
}

static void run_free(bake_run *b)
{
    job *J = b->J;
    if (J) {
        free(J->error_table);
        free(J->choose_error);
        free(J->choose_coeffs);
        free(J->done);
        free(J->var_scratch);
        free(J->var_lsq);
        if (J->pool != J->cal_pool)
            free(J->cal_pool);
        free(J->pool);
        free(J->dec_scratch);
        free(J->cal_margins);
        free(J->cal_caps);
        free(J->done_caps);
    }
    free(J);
    for (int k = 0; k <= VDSH_MAX_ORDER; k++)
        free(b->coeffs[k]);
    free(b->origins);
    free(b->near);
    free(b->normals);
    free(b->set);
    free(b->var_orders);
    free(b->var_coeffs);
    free(b->lights);
    vb_dirgrid_destroy(&b->grid);
}

/* vb_bake_run's steps, in order. */
static const bake_step bake_steps[] = {
    resolve_orders, resolve_quantity,  resolve_parameters, check_receivers,   resolve_decision,
    create_grid,    select_receivers,  allocate_arrays,    prepare_receivers, setup_job,
    setup_offsets,  choose_quantities, calibrate_offsets,  bake_receivers,
};

vb_result vb_bake_run(const vb_bake_desc *desc, vb_bake_output *out, vb_error *err)
{
    bake_run b = {.d = *desc};
    vb_result r = VB_OK;
    for (size_t k = 0; r == VB_OK && k < sizeof bake_steps / sizeof *bake_steps; k++)
        r = bake_steps[k](&b, err);
    if (r == VB_OK)
        fill_output(&b, out);
    run_free(&b);
    return r;
}
