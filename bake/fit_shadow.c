#include "fit_shadow.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fit.h"
#include "vdsh_sh.h"
#include "vdsh_shadow.h"

/* The vector helpers below pass 32-byte vectors by value; they are all
 * inlined, so the ABI note GCC gives for them does not apply. */
#pragma GCC diagnostic ignored "-Wpsabi"


/* e(r) by the mean over 512 lights, u at the midpoints of (0.05, 1]. */
static double expected_error(double r)
{
    enum { U = 512 };
    double s = 0.0;
    for (int k = 0; k < U; k++) {
        double u = 0.05 + 0.95 * (k + 0.5) / U;
        s += fabs((double)vdsh_ramp((float)(r / (2.0 * u))) -
                  (double)vdsh_ramp((float)(1.0 / (2.0 * u))));
    }
    return s / U;
}

double vb_shadow_error(const vb_shadow_fit *f, double r)
{
    double x = r * (VB_SHADOW_TABLE / 2.0);
    if (!(x < VB_SHADOW_TABLE))
        return f->e[VB_SHADOW_TABLE];
    if (x < 0.0)
        x = 0.0;
    int i = (int)x;
    return f->e[i] + (x - i) * (f->e[i + 1] - f->e[i]);
}

/* Eight floats in one vector (GCC/Clang vector extension): the loops
 * below run eight directions at a time whatever the target, in the same
 * IEEE operations in the same order, so the bits do not depend on which
 * clone runs. */
typedef float v8 __attribute__((vector_size(32), aligned(32)));
typedef int32_t v8i __attribute__((vector_size(32), aligned(32)));

static inline v8 splat(float a)
{
    return (v8){a, a, a, a, a, a, a, a};
}

/* m ? a : b, lane by lane, for a comparison's mask m (all ones or zero). */
static inline v8 select8(v8i m, v8 a, v8 b)
{
    return (v8)((m & (v8i)a) | (~m & (v8i)b));
}

static inline v8 max8(v8 a, v8 b) { return select8(a > b, a, b); }
static inline v8 min8(v8 a, v8 b) { return select8(a < b, a, b); }

/* 2^t for t in [-16, 16], to about 2e-7 relative: t = n + f with
 * f in [-0.5, 0.5], 2^f by its Taylor series, 2^n in the exponent bits. */
static inline v8 exp2_8(v8 t)
{
    v8i n = __builtin_convertvector(t + 16.5f, v8i) - 16; /* round(t) */
    v8 f = (t - __builtin_convertvector(n, v8)) * 0.69314718f;
    v8 p = 1.0f + f * (1.0f + f * (0.5f + f * (1.0f / 6 + f * (1.0f / 24 + f * (1.0f / 120)))));
    return p * (v8)((n + 127) << 23);
}

/* The IRLS weight eps'(x) / x, in closed form. With v = 1 / 2u the
 * lights' u integral of e(r) becomes one over v in [0.5, 10] of
 * |ramp(r v) - ramp(v)| / (1.9 v^2), and its r-derivative the log of the
 * v-interval where ramp(r v) is on its slope (1/3r, 1/r), cut to [0.5, 10]:
 *     e'(x) = r de/dr = 0.7895 r h(x),  r = e^x,
 *     h = ln 2 - x           on [0, ln 2)       (r in [1, 2))
 *       = x - ln 2           on [ln 2/3, 0)
 *       = 0                  from ln 2 on (every light lit either way).
 * Below r = 2/3 the loss goes on as a straight line in x, with the slope
 * e'(ln 2/3) = -0.7895 (2/3) ln 3 (fit_shadow.h: e saturates there, and a
 * fit free to give up the directions it underestimates gave up different
 * ones at neighbouring receivers: blotches of false shadow on walls).
 * Beyond r = 2 (lights further off than the evaluator's would still see
 * the error) a small constant slope VB_SHADOW_TAIL keeps a given-up
 * direction from drifting by orders of magnitude.
 * x is held at least `width` away from 0 (the L1 kink), and the weight at
 * least 1e-4 (no direction drops out entirely: the normal matrix stays
 * positive definite). */
static inline v8 irls_weight8(v8 x, float width)
{
    const float ln2 = 0.69314718f, ln23 = -0.40546511f;
    const float under = -0.78947368f * 0.66666667f * 1.09861229f; /* e'(ln 2/3) */
    v8 zero = splat(0.0f);
    v8i neg = x < zero;
    v8 ax = max8(select8(neg, -x, x), splat(width));
    v8 sx = select8(neg, -ax, ax);
    v8 h = select8(neg, sx - ln2, max8(ln2 - sx, zero));
    v8 e = exp2_8(max8(sx, splat(ln23)) * 1.44269504f);
    v8 psi = select8(sx < ln23, splat(under), 0.78947368f * e * h) +
             select8(sx > ln2, splat(VB_SHADOW_TAIL), zero);
    return max8(psi / sx, splat(1e-4f));
}

vb_result vb_shadow_fit_init(vb_shadow_fit *f, vb_error *err)
{
    memset(f, 0, sizeof *f);
    for (int i = 0; i <= VB_SHADOW_TABLE; i++)
        f->e[i] = expected_error(2.0 * i / VB_SHADOW_TABLE);

    /* T_ijL = integral over the sphere of Y_i Y_j Y_L, i, j < 25, L < 81:
     * the product of two functions of order 5 is sum_L T_ijL Y_L exactly,
     * so the weighted normal matrix sum_k w_k Y_i Y_j is sum_L T_ijL m_L
     * with the 81 moments m_L = sum_k w_k Y_L: a quarter of the products.
     * The integrands have degree <= 16: 12 Gauss-Legendre nodes in z and
     * 24 azimuths are exact. */
    enum { NZ = 12, NP = 24, NQ = NZ * NP, NL = 81 };
    double gz[NZ], gw[NZ], qw[NQ];
    float qx[NQ], qy[NQ], qz[NQ];
    float *q = malloc(sizeof(float) * NL * NQ);
    if (!q)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for the shadow fit");
    vb_gauss_legendre(NZ, gz, gw);
    for (int a = 0; a < NZ; a++)
        for (int b = 0; b < NP; b++) {
            double r = sqrt(1.0 - gz[a] * gz[a]);
            double phi = 2.0 * 3.14159265358979323846 * (b + 0.5) / NP;
            qx[a * NP + b] = (float)(r * cos(phi)), qy[a * NP + b] = (float)(r * sin(phi));
            qz[a * NP + b] = (float)gz[a];
            qw[a * NP + b] = gw[a] * 2.0 * 3.14159265358979323846 / NP;
        }
    vdsh_sh_eval_soa(9, NQ, qx, qy, qz, q, NQ);
    uint32_t e = 0;
    for (int i = 0, p = 0; i < 25; i++)
        for (int j = 0; j <= i; j++, p++) {
            f->pair_start[p] = e;
            for (int L = 0; L < NL; L++) {
                double t = 0.0;
                for (int k = 0; k < NQ; k++)
                    t += qw[k] * q[i * NQ + k] * q[j * NQ + k] * q[L * NQ + k];
                if (fabs(t) > 1e-6 && e < VB_SHADOW_TERMS) {
                    f->term_moment[e] = (uint8_t)L;
                    f->term_value[e++] = t;
                }
            }
        }
    f->pair_start[325] = e;
    free(q);
    return VB_OK;
}

static float hsum(v8 s)
{
    return ((s[0] + s[4]) + (s[1] + s[5])) + ((s[2] + s[6]) + (s[3] + s[7]));
}

/* Cholesky factor of the symmetric positive definite n x n matrix A
 * (row-major, in place: its lower triangle becomes L, A = L L^T), and Lt,
 * L transposed. Right-looking: each column's update of the rows below is
 * a loop without a running sum over a contiguous row, so it vectorises.
 * Returns 0 if A is not positive definite. */
static inline int cholesky(int n, double *A, double *Lt)
{
    for (int j = 0; j < n; j++) {
        double d = A[j * n + j];
        if (!(d > 0.0))
            return 0;
        d = sqrt(d);
        double inv = 1.0 / d;
        A[j * n + j] = d;
        Lt[j * n + j] = d;
        for (int i = j + 1; i < n; i++)
            Lt[j * n + i] = A[i * n + j] *= inv; /* column j of L, as a row of Lt */
        const double *col = Lt + j * n;
        for (int i = j + 1; i < n; i++) {
            double lij = col[i];
            double *row = A + i * n;
            for (int k = j + 1; k <= i; k++)
                row[k] -= lij * col[k];
        }
    }
    return 1;
}

/* Solve L L^T x = b with the factor (b becomes x), column by column:
 * every inner loop is an update of a contiguous row without a running
 * sum. */
static inline void cholesky_solve(int n, const double *A, const double *Lt, double *b)
{
    for (int k = 0; k < n; k++) { /* L z = b: column k of L is row k of Lt */
        b[k] /= A[k * n + k];
        const double *col = Lt + k * n;
        for (int i = k + 1; i < n; i++)
            b[i] -= col[i] * b[k];
    }
    for (int i = n - 1; i >= 0; i--) { /* L^T x = z: column i of L^T is row i of L */
        b[i] /= A[i * n + i];
        const double *row = A + i * n;
        for (int k = 0; k < i; k++)
            b[k] -= row[k] * b[i];
    }
}

/* Four sums of products over the directions at once (one sum would wait
 * on its own additions): out[q] = sum_b a[b] * r_q[b]. */
static inline void dot4v(const v8 *a, const v8 *r0, const v8 *r1, const v8 *r2, const v8 *r3,
                         uint32_t nb, double out[4])
{
    v8 s0 = splat(0.0f), s1 = s0, s2 = s0, s3 = s0;
    for (uint32_t b = 0; b < nb; b++) {
        v8 v = a[b];
        s0 += v * r0[b], s1 += v * r1[b], s2 += v * r2[b], s3 += v * r3[b];
    }
    out[0] = hsum(s0), out[1] = hsum(s1), out[2] = hsum(s2), out[3] = hsum(s3);
}

/* out[i] = sum_b a[b] rows[i][b] for i < count, four at a time. */
static inline void dots(const v8 *a, const float *rows, uint32_t stride, int count,
                        uint32_t nb, double *out)
{
    for (int i = 0; i < count; i += 4) {
        const v8 *r[4];
        for (int q = 0; q < 4; q++)
            r[q] = (const v8 *)(rows + (size_t)(i + q < count ? i + q : i) * stride);
        double t[4];
        dot4v(a, r[0], r[1], r[2], r[3], nb, t);
        for (int q = 0; q < 4 && i + q < count; q++)
            out[i + q] = t[q];
    }
}

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && \
    !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("avx2", "default")))
#endif
void vb_shadow_fit_apply(const vb_shadow_fit *f, int order, float lambda, uint32_t n,
                         const float *y, uint32_t stride, const float *lnd, float *c)
{
    /* Each weight width in turn, narrowing: early wide steps keep the fit
     * from locking onto the L1 kink. */
    static const float widths[VB_SHADOW_STEPS / 2] = {0.5f, 0.3f, 0.2f, 0.1f};
    enum { B = VB_SHADOW_MAX_DIRS / 8 };
    int nc = order * order, nm = (2 * order - 1) * (2 * order - 1);
    if (order < 1 || order > 5 || n < (uint32_t)nc + 1 || n > VB_SHADOW_MAX_DIRS ||
        stride % 8 || stride < n)
        return;
    uint32_t nb = stride / 8; /* whole vectors; weight 0 beyond n */
    const v8 *L = (const v8 *)lnd;
    double lam[25], cd[25], H[25 * 25], Ht[25 * 25], m[81];
    for (int i = 0; i < nc; i++) {
        int l = 0;
        while ((l + 1) * (l + 1) <= i)
            l++;
        lam[i] = (double)lambda * (double)(l * (l + 1)) * (l * (l + 1));
        cd[i] = c[i];
    }
    const double scale = 2.0 * 3.14159265358979323846 / n; /* the hemisphere's 2 pi / n */

    /* Every step a full IRLS step, c += H^-1 g with H = scale sum w y y^T
     * + lambda L and g = -scale sum w x y - lambda L c for the current
     * weights: w(x) does not grow with |x|, so each step lowers the
     * weighted loss (a majorise-minimise step). Steps that reused an
     * earlier H, cheaper, were not: they oscillated and, on about one
     * receiver in 50,000, diverged to distances of 10^5 and more. */
    for (int step = 0; step < VB_SHADOW_STEPS; step++) {
        const float width = widths[step / 2];
        /* Residuals of ln d, then their weights (0 on padding). */
        v8 X[B], W[B], U[B];
        for (uint32_t b = 0; b < nb; b++)
            X[b] = -L[b];
        for (int i = 0; i < nc; i++) {
            const v8 *Yi = (const v8 *)(y + (size_t)i * stride);
            float ci = (float)cd[i];
            for (uint32_t b = 0; b < nb; b++)
                X[b] += ci * Yi[b];
        }
        for (uint32_t b = 0; b < nb; b++)
            W[b] = irls_weight8(X[b], width);
        for (uint32_t k = n; k < stride; k++)
            W[k / 8][k % 8] = 0.0f;
        for (uint32_t b = 0; b < nb; b++)
            U[b] = W[b] * X[b];
        {
            /* H from the moments of the weights (vb_shadow_fit_init). */
            dots(W, y, stride, nm, nb, m);
            for (int i = 0, p = 0; i < nc; i++)
                for (int j = 0; j <= i; j++, p++) {
                    double h = 0.0;
                    for (uint32_t e = f->pair_start[p]; e < f->pair_start[p + 1]; e++)
                        h += f->term_value[e] * m[f->term_moment[e]];
                    H[i * nc + j] = H[j * nc + i] = scale * h;
                }
            for (int i = 0; i < nc; i++)
                H[i * nc + i] += lam[i];
            if (!cholesky(nc, H, Ht))
                break; /* keep the last good coefficients */
        }
        double g[25];
        dots(U, y, stride, nc, nb, g);
        for (int i = 0; i < nc; i++)
            g[i] = -scale * g[i] - lam[i] * cd[i];
        cholesky_solve(nc, H, Ht, g);
        for (int i = 0; i < nc; i++)
            cd[i] += g[i];
    }
    for (int i = 0; i < nc; i++)
        c[i] = (float)cd[i];
}
