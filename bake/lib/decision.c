/* decision.c - the decision fit (decision.h). */
#include "decision.h"

#include <stdlib.h>
#include <string.h>

void vb_decision_defaults(vb_decision_params *p)
{
    p->tau = 0.5f;
    p->lit_weight = 8.0f;
    p->ridge = 1e-5f;
    p->ridge0 = 1e-4f;
    p->steps = 3;
    p->hessians = 0;
}

/* ---- e^x and ln x, eight at a time --------------------------------------- */

/* GCC's vector extension: each lane is computed as the scalar code would,
 * mul and add apart (never fused), so SSE, AVX2 and scalar code give the
 * same bits. */
typedef float v8f __attribute__((vector_size(32)));
typedef int32_t v8i __attribute__((vector_size(32)));

#define VINLINE static inline __attribute__((always_inline))
#pragma GCC diagnostic ignored "-Wpsabi" /* inlined: no vector crosses a call */

VINLINE v8f v8(float x)
{
    return (v8f){x, x, x, x, x, x, x, x};
}

/* a where mask (-1), else b. */
VINLINE v8f sel(v8i mask, v8f a, v8f b)
{
    return (v8f)((mask & (v8i)a) | (~mask & (v8i)b));
}

/* bake.c's fast_exp per lane: x clamped to [-80, 80]. */
VINLINE v8f exp8(v8f x)
{
    x = sel(x < v8(-80.0f), v8(-80.0f), x);
    x = sel(x > v8(80.0f), v8(80.0f), x);
    v8f t = x * v8(1.44269504f);
    v8i i = __builtin_convertvector(t + v8(128.5f), v8i) - 128; /* round: t + 128.5 > 0 */
    v8f r = (t - __builtin_convertvector(i, v8f)) * v8(0.693147181f);
    v8f p = v8(1.0f / 720);
    p = p * r + v8(1.0f / 120);
    p = p * r + v8(1.0f / 24);
    p = p * r + v8(1.0f / 6);
    p = p * r + v8(0.5f);
    p = p * r + v8(1.0f);
    p = p * r + v8(1.0f);
    v8i b = (i + 127) << 23;
    return p * (v8f)b;
}

/* bake.c's fast_log per lane: x finite and > 0. */
VINLINE v8f log8(v8f x)
{
    v8i u = (v8i)x;
    v8i e = ((u >> 23) & 0xff) - 127;
    u = (u & 0x007fffff) | 0x3f800000;
    v8f m = (v8f)u;
    v8i big = m > v8(1.41421356f); /* -1 or 0 */
    m = sel(big, m * v8(0.5f), m);
    e -= big;
    v8f s = (m - v8(1.0f)) / (m + v8(1.0f)), s2 = s * s;
    v8f p = v8(2.0f / 9);
    p = p * s2 + v8(2.0f / 7);
    p = p * s2 + v8(2.0f / 5);
    p = p * s2 + v8(2.0f / 3);
    p = p * s2 + v8(2.0f);
    return s * p + __builtin_convertvector(e, v8f) * v8(0.69314718f);
}

/* ---- the fit ---------------------------------------------------------------- */

size_t vb_decision_scratch_doubles(int order)
{
    size_t n = (size_t)order * order;
    /* H, its factor, g, step, c, c0, trial c, r; then floats per pair:
     * margin, trial margin, q, h, loss, sign, weight, sqrt(h), e^-|z|,
     * then Z = sqrt(h) Y (n rows) */
    return 2 * n * n + 6 * n + ((size_t)VB_DECISION_MAX_PAIRS * (n + 9) + 1) / 2;
}

enum { LANES = 8 };

/* An unaligned load of 8 floats. */
typedef float v8fu __attribute__((vector_size(32), aligned(4)));

VINLINE v8f load8(const float *p)
{
    return *(const v8fu *)p;
}

VINLINE void store8(float *p, v8f x)
{
    *(v8fu *)p = x;
}

/* t_i = sum_j c_j Y_ji - logd_i, in float, coefficient by coefficient
 * (-logd_i, then + c_j Y_ji for j = 0, 1, ...). 32 pairs at a time held
 * in registers across the coefficients (Y's rows are read once, t not
 * at all): the same operations per pair as the plain loop. */
static inline __attribute__((always_inline)) void margins(int n, uint32_t m, const float *Y,
                                                          uint32_t stride, const float *logd,
                                                          const double *c, float *t)
{
    float cf[VDSH_MAX_COEFFS];
    for (int j = 0; j < n; j++)
        cf[j] = (float)c[j];
    uint32_t i = 0;
    for (; i + 32 <= m; i += 32) {
        v8f a0 = -load8(logd + i), a1 = -load8(logd + i + 8), a2 = -load8(logd + i + 16),
            a3 = -load8(logd + i + 24);
        const float *y = Y + i;
        for (int j = 0; j < n; j++, y += stride) {
            v8f cj = v8(cf[j]);
            a0 += cj * load8(y), a1 += cj * load8(y + 8);
            a2 += cj * load8(y + 16), a3 += cj * load8(y + 24);
        }
        store8(t + i, a0), store8(t + i + 8, a1), store8(t + i + 16, a2), store8(t + i + 24, a3);
    }
    for (; i + 8 <= m; i += 8) {
        v8f a0 = -load8(logd + i);
        const float *y = Y + i;
        for (int j = 0; j < n; j++, y += stride)
            a0 += v8(cf[j]) * load8(y);
        store8(t + i, a0);
    }
    for (; i < m; i++) {
        float a0 = -logd[i];
        for (int j = 0; j < n; j++)
            a0 += cf[j] * Y[(size_t)j * stride + i];
        t[i] = a0;
    }
}

/* Per pair, from its margin: z = s t / tau (s = +1 shadowed, -1 lit);
 * the weighted softplus(z) into sp and e^-|z| into e (for pair_weights).
 * One exp and one log per pair, eight at a time. m8: m rounded up to 8;
 * the arrays hold m8 values (sgn and wt 0 past m, so those lanes add 0). */
static inline __attribute__((always_inline)) void pair_loss(uint32_t m8, const float *t,
                                                            const float *sgn, const float *wt,
                                                            float inv_tau, float *sp, float *e)
{
    for (uint32_t i = 0; i < m8; i += 8) {
        v8f tv, sv, wv;
        memcpy(&tv, t + i, sizeof tv);
        memcpy(&sv, sgn + i, sizeof sv);
        memcpy(&wv, wt + i, sizeof wv);
        v8f z = sv * tv * v8(inv_tau), az = sel(z < v8(0.0f), -z, z);
        v8f ev = exp8(-az), one = v8(1.0f) + ev;
        v8f out = wv * (v8(0.5f) * (z + az) + log8(one));
        memcpy(sp + i, &out, sizeof out);
        memcpy(e + i, &ev, sizeof ev);
    }
}

/* The gradient's and the Hessian's weights per pair from its margin t and
 * pair_loss's e: a sigma(z) s / tau and a sigma(z) (1 - sigma(z)) / tau^2
 * (a the pair's weight over the weights' sum); no exp or log again. */
static inline __attribute__((always_inline)) void pair_weights(uint32_t m8, const float *t,
                                                               const float *sgn, const float *wt,
                                                               float inv_tau, const float *e,
                                                               float *q, float *h)
{
    for (uint32_t i = 0; i < m8; i += 8) {
        v8f tv, sv, wv, ev;
        memcpy(&tv, t + i, sizeof tv);
        memcpy(&sv, sgn + i, sizeof sv);
        memcpy(&wv, wt + i, sizeof wv);
        memcpy(&ev, e + i, sizeof ev);
        v8f z = sv * tv * v8(inv_tau), one = v8(1.0f) + ev;
        /* sigma(z): 1 / (1 + e) for z >= 0, e / (1 + e) below */
        v8f s = sel(z >= v8(0.0f), v8(1.0f), ev) / one;
        v8f qv = wv * sv * s * v8(inv_tau);
        v8f hv = wv * s * (v8(1.0f) - s) * v8(inv_tau * inv_tau);
        memcpy(q + i, &qv, sizeof qv);
        memcpy(h + i, &hv, sizeof hv);
    }
}

/* Four floats and four doubles (unaligned loads), for the lane-wise sums
 * below: lane k of the vector sums is lane k of the scalar loop's. */
typedef float v4fu __attribute__((vector_size(16), aligned(4)));
typedef double v4d __attribute__((vector_size(32)));

VINLINE v4d load4d(const float *p)
{
    return __builtin_convertvector(*(const v4fu *)p, v4d);
}

/* The sum of m floats in LANES lane-wise double sums, in lane order. */
static inline __attribute__((always_inline)) double sum_lanes(uint32_t m, const float *x)
{
    v4d lo = {0}, hi = {0};
    uint32_t i = 0;
    for (; i + LANES <= m; i += LANES) {
        lo += load4d(x + i);
        hi += load4d(x + i + 4);
    }
    double lane[LANES] = {lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3]};
    for (; i < m; i++)
        lane[i % LANES] += x[i];
    double s = 0.0;
    for (int k = 0; k < LANES; k++)
        s += lane[k];
    return s;
}

/* The pairs' signs (+1 shadowed, -1 lit) and weights (lit ones
 * lit_weight times a shadowed one's, all summing to 1), zero from m to
 * m8, and the margins t and tt cleared. */
static inline __attribute__((always_inline)) void pair_setup(uint32_t m, uint32_t m8,
                                                             const uint8_t *shadowed,
                                                             float lit_weight, float *sgn,
                                                             float *wt, float *t, float *tt)
{
    double a = 0.0;
    for (uint32_t i = 0; i < m; i++)
        a += shadowed[i] ? 1.0 : lit_weight;
    const float w_shadowed = (float)(1.0 / a), w_lit = (float)(lit_weight / a);
    for (uint32_t i = 0; i < m8; i++) {
        sgn[i] = i >= m ? 0.0f : shadowed[i] ? 1.0f : -1.0f;
        wt[i] = i >= m ? 0.0f : shadowed[i] ? w_shadowed : w_lit;
        t[i] = tt[i] = 0.0f;
    }
}

static double ridge_term(int n, const double *c, const double *c0, const double *r)
{
    double s = 0.0;
    for (int j = 0; j < n; j++)
        s += r[j] * (c[j] - c0[j]) * (c[j] - c0[j]);
    return s;
}

/* sum_i w_i a_i in LANES lane-wise sums, added in lane order: the same
 * bits with or without vectors (each product rounded to float, then
 * added in double, as the scalar loop would). */
static inline __attribute__((always_inline)) double dot2(uint32_t m, const float *w, const float *a)
{
    v4d lo = {0}, hi = {0};
    uint32_t i = 0;
    for (; i + LANES <= m; i += LANES) {
        v4fu w0 = *(const v4fu *)(w + i), w1 = *(const v4fu *)(w + i + 4);
        v4fu a0 = *(const v4fu *)(a + i), a1 = *(const v4fu *)(a + i + 4);
        lo += __builtin_convertvector(w0 * a0, v4d);
        hi += __builtin_convertvector(w1 * a1, v4d);
    }
    double lane[LANES] = {lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3]};
    for (; i < m; i++)
        lane[i % LANES] += w[i] * a[i];
    double s = 0.0;
    for (int k = 0; k < LANES; k++)
        s += lane[k];
    return s;
}

/* dot2 of w with four rows a, a + stride, ... at once into out[0..3]:
 * each the same bits as dot2 (w read once for the four). */
static inline __attribute__((always_inline)) void dot2x4(uint32_t m, const float *w, const float *a,
                                                         uint32_t stride, double *out)
{
    const float *a0 = a, *a1 = a0 + stride, *a2 = a1 + stride, *a3 = a2 + stride;
    v4d l0 = {0}, h0 = {0}, l1 = {0}, h1 = {0}, l2 = {0}, h2 = {0}, l3 = {0}, h3 = {0};
    uint32_t i = 0;
#define DOT2_ROW(lo, hi, ar)                                                                       \
    lo += __builtin_convertvector(w0 * *(const v4fu *)(ar + i), v4d),                              \
        hi += __builtin_convertvector(w1 * *(const v4fu *)(ar + i + 4), v4d)
    for (; i + LANES <= m; i += LANES) {
        v4fu w0 = *(const v4fu *)(w + i), w1 = *(const v4fu *)(w + i + 4);
        DOT2_ROW(l0, h0, a0);
        DOT2_ROW(l1, h1, a1);
        DOT2_ROW(l2, h2, a2);
        DOT2_ROW(l3, h3, a3);
    }
#undef DOT2_ROW
    const v4d lo[4] = {l0, l1, l2, l3}, hi[4] = {h0, h1, h2, h3};
    for (int r = 0; r < 4; r++) {
        const float *ar = a + (size_t)r * stride;
        double lane[LANES] = {lo[r][0], lo[r][1], lo[r][2], lo[r][3],
                              hi[r][0], hi[r][1], hi[r][2], hi[r][3]};
        for (uint32_t k = i; k < m; k++)
            lane[k % LANES] += w[k] * ar[k];
        double s = 0.0;
        for (int k = 0; k < LANES; k++)
            s += lane[k];
        out[r] = s;
    }
}

/* H = Z Z^T (lower triangle, then mirrored; n x n, double) from the
 * n rows of Z (float, `stride` apart, zero from m to m8 = m rounded up
 * to 8). Tiles of 4 x 4 rows, each entry eight lane-wise float sums added
 * in lane order: vector code (GCC's vector extension, mul and add apart,
 * never fused) gives the same bits as scalar code on every CPU. */
static inline __attribute__((always_inline)) void syrk(int n, uint32_t m8, const float *Z,
                                                       uint32_t stride, double *H)
{
    static const float zeros[VB_DECISION_MAX_PAIRS] = {0};
    for (int j0 = 0; j0 < n; j0 += 2)
        for (int k0 = 0; k0 <= j0 + 1 && k0 < n; k0 += 4) {
            const float *a0 = Z + (size_t)j0 * stride;
            const float *a1 = j0 + 1 < n ? a0 + stride : zeros;
            const float *b0 = Z + (size_t)k0 * stride;
            const float *b1 = k0 + 1 < n ? b0 + stride : zeros;
            const float *b2 = k0 + 2 < n ? b0 + 2 * (size_t)stride : zeros;
            const float *b3 = k0 + 3 < n ? b0 + 3 * (size_t)stride : zeros;
            v8f s00 = v8(0.0f), s01 = s00, s02 = s00, s03 = s00;
            v8f s10 = s00, s11 = s00, s12 = s00, s13 = s00;
            for (uint32_t i = 0; i < m8; i += 8) {
                v8f x0 = load8(a0 + i), x1 = load8(a1 + i);
                v8f y0 = load8(b0 + i), y1 = load8(b1 + i), y2 = load8(b2 + i), y3 = load8(b3 + i);
                s00 += x0 * y0, s01 += x0 * y1, s02 += x0 * y2, s03 += x0 * y3;
                s10 += x1 * y0, s11 += x1 * y1, s12 += x1 * y2, s13 += x1 * y3;
            }
            v8f acc[2][4] = {{s00, s01, s02, s03}, {s10, s11, s12, s13}};
            for (int a = 0; a < 2 && j0 + a < n; a++)
                for (int b = 0; b < 4 && k0 + b <= j0 + a && k0 + b < n; b++) {
                    double s = 0.0;
                    for (int l = 0; l < 8; l++)
                        s += acc[a][b][l];
                    H[(j0 + a) * n + k0 + b] = H[(k0 + b) * n + j0 + a] = s;
                }
        }
}

/* Four doubles, unaligned. */
typedef double v4du __attribute__((vector_size(32), aligned(8)));

/* Cholesky of the n x n symmetric positive definite A (both triangles
 * set) into its lower factor L, stored by columns: C[k * n + i] = L_ik.
 * Each entry is the textbook sum, L_ij = (A_ij - sum_{k<j} L_ik L_jk) /
 * L_jj with k ascending, four rows i at a time in vector lanes (the same
 * operations per entry as one at a time). Returns 0 if A is not positive
 * definite. */
static inline __attribute__((always_inline)) int cholesky_factor(int n, const double *A, double *C)
{
    for (int j = 0; j < n; j++) {
        double d = A[j * n + j];
        for (int k = 0; k < j; k++)
            d -= C[k * n + j] * C[k * n + j];
        if (!(d > 0.0))
            return 0;
        const double ljj = __builtin_sqrt(d); /* IEEE-exact on every CPU */
        C[j * n + j] = ljj;
        int i = j + 1;
        for (; i + 4 <= n; i += 4) {
            v4d s = *(const v4du *)(A + j * n + i); /* A_ij = A_ji */
            for (int k = 0; k < j; k++) {
                const double ljk = C[k * n + j];
                s -= *(const v4du *)(C + k * n + i) * (v4d){ljk, ljk, ljk, ljk};
            }
            *(v4du *)(C + j * n + i) = s / (v4d){ljj, ljj, ljj, ljj};
        }
        for (; i < n; i++) {
            double s = A[j * n + i];
            for (int k = 0; k < j; k++)
                s -= C[k * n + i] * C[k * n + j];
            C[j * n + i] = s / ljj;
        }
    }
    return 1;
}

/* Solve L L^T x = b, L by columns as cholesky_factor leaves it (C). The
 * forward pass subtracts column by column, four rows at a time: each x_i
 * still gets b_i - L_i0 x_0 - L_i1 x_1 - ... in that order. */
static inline __attribute__((always_inline)) void cholesky_solve(int n, const double *C,
                                                                 const double *b, double *x)
{
    for (int i = 0; i < n; i++)
        x[i] = b[i];
    for (int k = 0; k < n; k++) {
        const double xk = x[k] / C[k * n + k];
        x[k] = xk;
        int i = k + 1;
        for (; i + 4 <= n; i += 4)
            *(v4du *)(x + i) -= *(const v4du *)(C + k * n + i) * (v4d){xk, xk, xk, xk};
        for (; i < n; i++)
            x[i] -= C[k * n + i] * xk;
    }
    for (int i = n - 1; i >= 0; i--) {
        double s = x[i];
        for (int k = i + 1; k < n; k++)
            s -= C[i * n + k] * x[k];
        x[i] = s / C[i * n + i];
    }
}

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) &&                             \
    !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("avx2", "default"))) /* no FMA: the same bits */
#endif
int vb_decision_fit(int order, uint32_t m, const float *Y, uint32_t stride,
                    const float *logd, const uint8_t *shadowed,
                    const vb_decision_params *p, float *cf, double *scratch)
{
    const int n = order * order;
    if (m == 0 || n == 0)
        return 0;
    if (m > VB_DECISION_MAX_PAIRS)
        m = VB_DECISION_MAX_PAIRS;
    enum { K = VB_DECISION_MAX_PAIRS };
    double *H = scratch, *L = H + (size_t)n * n, *g = L + (size_t)n * n, *dx = g + n, *c = dx + n,
           *c0 = c + n, *ct = c0 + n, *r = ct + n;
    float *t = (float *)(r + n), *tt = t + K, *q = tt + K, *h = q + K, *sp = h + K, *sgn = sp + K,
          *wt = sgn + K, *sh = wt + K, *ex = sh + K, *Z = ex + K;
    const uint32_t m8 = (m + 7) & ~7u;
    const float inv_tau = 1.0f / p->tau;
    pair_setup(m, m8, shadowed, p->lit_weight, sgn, wt, t, tt);
    for (int j = 0; j < n; j++) {
        int l = 0;
        while ((l + 1) * (l + 1) <= j)
            l++;
        double ll = (double)l * (l + 1);
        r[j] = (double)p->ridge * ll * ll + (double)p->ridge0;
        c[j] = c0[j] = cf[j];
    }
    margins(n, m, Y, stride, logd, c, t);
    pair_loss(m8, t, sgn, wt, inv_tau, sp, ex);
    pair_weights(m8, t, sgn, wt, inv_tau, ex, q, h);
    double f = sum_lanes(m, sp);
    /* Every pair already on its side by a wide margin (sigma(z) < 1/400 in
     * each): the start is the fit to within the ridge. */
    float most = -1e30f;
    for (uint32_t i = 0; i < m; i++) {
        float s = sgn[i] * t[i] * inv_tau;
        most = s > most ? s : most;
    }
    int steps = 0;
    if (most < -6.0f)
        return 0;
    for (int it = 0; it < p->steps; it++) {
        /* Newton: H = Y diag(h) Y^T + 2 R, g = Y q + 2 R (c - c0), the
         * Hessian afresh at every step: three such steps reach the loss
         * that two fresh and four kept Hessians reached (median over the
         * fits of validation room 1; docs/ACCURACY.md, "Bake time"), for
         * about 20% less time. The step halving keeps each a descent. */
        int j4 = 0;
        for (; j4 + 4 <= n; j4 += 4)
            dot2x4(m, q, Y + (size_t)j4 * stride, stride, g + j4);
        for (; j4 < n; j4++)
            g[j4] = dot2(m, q, Y + (size_t)j4 * stride);
        for (int j = 0; j < n; j++)
            g[j] += 2.0 * r[j] * (c[j] - c0[j]);
        if (p->hessians <= 0 || it < p->hessians) {
            for (uint32_t i = 0; i < m; i++)
                sh[i] = __builtin_sqrtf(h[i]);
            for (int j = 0; j < n; j++) {
                const float *yj = Y + (size_t)j * stride;
                float *zj = Z + (size_t)j * m8;
                for (uint32_t i = 0; i < m; i++)
                    zj[i] = sh[i] * yj[i];
                for (uint32_t i = m; i < m8; i++)
                    zj[i] = 0.0f;
            }
            syrk(n, m8, Z, m8, H);
            for (int j = 0; j < n; j++)
                H[j * n + j] += 2.0 * r[j];
            if (!cholesky_factor(n, H, L))
                break;
        }
        cholesky_solve(n, L, g, dx);
        /* Step halving until the loss falls. */
        double step = 1.0, fn = f;
        int ok = 0;
        for (int half = 0; half < 8 && !ok; half++, step *= 0.5) {
            for (int j = 0; j < n; j++)
                ct[j] = c[j] - step * dx[j];
            margins(n, m, Y, stride, logd, ct, tt);
            pair_loss(m8, tt, sgn, wt, inv_tau, sp, ex);
            fn = sum_lanes(m, sp) + ridge_term(n, ct, c0, r);
            ok = fn < f;
        }
        if (!ok)
            break;
        double biggest = 0.0;
        for (int j = 0; j < n; j++) {
            double d = ct[j] - c[j];
            biggest = d > biggest ? d : -d > biggest ? -d : biggest;
            c[j] = ct[j];
        }
        steps++;
        double drop = f - fn;
        f = fn;
        if (biggest < 1e-3 || drop < 1e-6 * f || it + 1 == p->steps)
            break;
        float *swap = t;
        t = tt;
        tt = swap;
        pair_weights(m8, t, sgn, wt, inv_tau, ex, q, h); /* ex: the accepted trial's */
    }
    for (int j = 0; j < n; j++)
        cf[j] = (float)c[j];
    return steps;
}

/* The loss at the start c alone, its offset free: the same pairs and
 * weights as vb_decision_fit, no ridge, minimised over b added to every
 * margin by 1-D Newton steps (convex in b; step halving keeps each a
 * descent). */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) &&                             \
    !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("avx2", "default"))) /* no FMA: the same bits */
#endif
float vb_decision_score(int order, uint32_t m, const float *Y, uint32_t stride, const float *logd,
                        const uint8_t *shadowed, const vb_decision_params *p, const float *cf,
                        float *offset, double *scratch)
{
    const int n = order * order;
    *offset = 0.0f;
    if (m == 0 || n == 0)
        return 0.0f;
    if (m > VB_DECISION_MAX_PAIRS)
        m = VB_DECISION_MAX_PAIRS;
    enum { K = VB_DECISION_MAX_PAIRS };
    double *c = scratch;
    float *t = (float *)(c + VDSH_MAX_COEFFS), *tt = t + K, *q = tt + K, *h = q + K, *sp = h + K,
          *sgn = sp + K, *wt = sgn + K, *ex = wt + K;
    const uint32_t m8 = (m + 7) & ~7u;
    const float inv_tau = 1.0f / p->tau;
    pair_setup(m, m8, shadowed, p->lit_weight, sgn, wt, t, tt);
    for (int j = 0; j < n; j++)
        c[j] = cf[j];
    margins(n, m, Y, stride, logd, c, t);
    float b = 0.0f;
    pair_loss(m8, t, sgn, wt, inv_tau, sp, ex);
    pair_weights(m8, t, sgn, wt, inv_tau, ex, q, h);
    double f = sum_lanes(m, sp);
    for (int it = 0; it < 6; it++) {
        double g = sum_lanes(m, q), hh = sum_lanes(m, h);
        if (!(hh > 1e-12))
            break;
        double step = g / hh, fn = f;
        float bt = b;
        int ok = 0;
        for (int half = 0; half < 8 && !ok; half++, step *= 0.5) {
            bt = b - (float)step;
            for (uint32_t i = 0; i < m8; i++)
                tt[i] = t[i] + bt;
            pair_loss(m8, tt, sgn, wt, inv_tau, sp, ex);
            fn = sum_lanes(m, sp);
            ok = fn < f;
        }
        if (!ok)
            break;
        float moved = bt - b;
        double drop = f - fn;
        b = bt;
        f = fn;
        if ((moved < 1e-3f && moved > -1e-3f) || drop < 1e-6 * f)
            break;
        pair_weights(m8, tt, sgn, wt, inv_tau, ex, q, h); /* the accepted trial's */
    }
    *offset = b;
    return (float)f;
}

/* ---- the offset's calibration --------------------------------------------- */

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

float vb_decision_offset(float *margins_, uint32_t count, double rate)
{
    if (count == 0)
        return 0.0f;
    qsort(margins_, count, sizeof *margins_, cmp_float);
    double pos = rate * count;
    uint32_t k = (uint32_t)pos;
    if (k >= count)
        k = count - 1;
    return -margins_[k];
}
