#include "fit.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vdsh.h"
#include "vdsh_sh.h"
#include "vdsh_det.h"

#define PI 3.14159265358979323846

static int band_of(int i)
{
    int l = 0;
    while ((l + 1) * (l + 1) <= i)
        l++;
    return l;
}

/* Bands 5 .. order-1 of the basis at d, in double: the associated-Legendre
 * recurrence of formats/vdsh_sh.c (same convention), so that the high
 * bands' rotations are exact to double precision. */
static void eval_high_d(int order, const double d[3], double *y)
{
    double c = 1.0, sn = 0.0, pmm = 1.0;
    for (int m = 0; m < order; m++) {
        if (m > 0) {
            double cc = d[0] * c - d[1] * sn;
            sn = d[0] * sn + d[1] * c;
            c = cc;
            pmm *= -(2.0 * m - 1.0);
        }
        double p0 = 0.0, p1 = 0.0;
        for (int l = m; l < order; l++) {
            double pl = l == m       ? pmm
                        : l == m + 1 ? d[2] * (2.0 * m + 1.0) * pmm
                                     : ((2.0 * l - 1.0) * d[2] * p1 - (l + m - 1.0) * p0) / (l - m);
            p0 = p1;
            p1 = pl;
            if (l < 5)
                continue;
            double kk = (2.0 * l + 1.0) / (4.0 * PI);
            for (int f = l - m + 1; f <= l + m; f++)
                kk /= f;
            if (m == 0)
                y[l * (l + 1)] = sqrt(kk) * pl;
            else {
                y[l * (l + 1) + m] = sqrt(2.0 * kk) * pl * c;
                y[l * (l + 1) - m] = sqrt(2.0 * kk) * pl * sn;
            }
        }
    }
}

/* The basis at d: bands 0-4 as the float kernel gives them (the fits of
 * orders 1..5 keep the bits they always had), bands 5 and up in double. */
static void eval_d(int order, const double d[3], double *y)
{
    float f[3] = {(float)d[0], (float)d[1], (float)d[2]}, yy[25];
    int low = order < 5 ? order : 5;
    vdsh_sh_eval(low, f, yy);
    for (int i = 0; i < low * low; i++)
        y[i] = yy[i];
    if (order > 5)
        eval_high_d(order, d, y);
}

/* Gauss-Jordan inverse with partial pivoting of an n x n matrix (n <= VB_FIT_MAX).
 * Returns 0 if singular. */
static int invert(int n, const double *a, double *inv)
{
    double(*m)[2 * VB_FIT_MAX] = malloc((size_t)n * sizeof *m);
    if (!m)
        return -1;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < 2 * n; j++)
            m[i][j] = j < n ? a[i * n + j] : (j - n == i);
    for (int c = 0; c < n; c++) {
        int p = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(m[r][c]) > fabs(m[p][c]))
                p = r;
        if (fabs(m[p][c]) < 1e-14) {
            free(m);
            return 0;
        }
        if (p != c)
            for (int j = 0; j < 2 * n; j++) {
                double t = m[c][j];
                m[c][j] = m[p][j];
                m[p][j] = t;
            }
        double s = 1.0 / m[c][c];
        for (int j = 0; j < 2 * n; j++)
            m[c][j] *= s;
        for (int r = 0; r < n; r++)
            if (r != c && m[r][c] != 0.0) {
                double f = m[r][c];
                for (int j = 0; j < 2 * n; j++)
                    m[r][j] -= f * m[c][j];
            }
    }
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            inv[i * n + j] = m[i][n + j];
    free(m);
    return 1;
}

void vb_gauss_legendre(int n, double *x, double *w)
{
    for (int i = 0; i < n; i++) {
        double z = vdsh_det_cos(PI * (i + 0.75) / (n + 0.5)), pp = 1.0;
        for (int it = 0; it < 100; it++) {
            double p1 = 1.0, p2 = 0.0;
            for (int j = 1; j <= n; j++) {
                double p3 = p2;
                p2 = p1;
                p1 = ((2.0 * j - 1.0) * z * p2 - (j - 1.0) * p3) / j;
            }
            pp = n * (z * p1 - p2) / (z * z - 1.0);
            double z1 = z;
            z = z1 - p1 / pp;
            if (fabs(z - z1) < 1e-15)
                break;
        }
        x[i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * pp * pp);
    }
}

/* Gauss-Legendre nodes and weights on [0, 1] (halving is exact). */
static void gauss01(int n, double *x, double *w)
{
    vb_gauss_legendre(n, x, w);
    for (int i = 0; i < n; i++) {
        x[i] = 0.5 * (x[i] + 1.0);
        w[i] *= 0.5;
    }
}

double vb_window_weight(vdsh_window window, int l, int order)
{
    double x = (double)l / order;
    switch (window) {
    case VDSH_WINDOW_HANN: return 0.5 * (1.0 + vdsh_det_cos(PI * x));
    case VDSH_WINDOW_LANCZOS: return l == 0 ? 1.0 : vdsh_det_sin(PI * x) / (PI * x);
    default: return 1.0;
    }
}

/* Fibonacci-sphere directions, K of them. */
static void fibonacci(int K, double (*d)[3])
{
    for (int j = 0; j < K; j++) {
        double z = 1.0 - (2.0 * j + 1.0) / K, r = sqrt(1.0 - z * z);
        double phi = j * PI * (3.0 - sqrt(5.0));
        d[j][0] = r * vdsh_det_cos(phi), d[j][1] = r * vdsh_det_sin(phi), d[j][2] = z;
    }
}

/* Band l's rotation samples: bands 0-4 the VB_FIT_ROT_DIRS of old (their
 * bits unchanged), bands 5 and up the larger set they need. */
static int rot_count(int l)
{
    return l < 5 ? VB_FIT_ROT_DIRS : VB_FIT_ROT_DIRS_HIGH;
}

static const double (*rot_set(const vb_fit *f, int l))[3]
{
    return l < 5 ? (const double(*)[3])f->rot_dirs : (const double(*)[3])f->rot_dirs_high;
}

/* h_i = integral over z > 0 of Y_i, and (G not NULL) G_ij = integral
 * over z > 0 of Y_i Y_j plus lambda (l(l+1))^2 on the diagonal:
 * Gauss-Legendre in z (exact to degree 31) times 64 azimuths (exact for
 * cos/sin of order < 64); the products have degree <= 30. */
static void hemisphere_moments(int order, double lambda, double *h, double *G)
{
    enum { NZ = 16, NP = 64 };
    int n = order * order;
    double zx[NZ], zw[NZ], y[VB_FIT_MAX];
    gauss01(NZ, zx, zw);
    memset(h, 0, (size_t)n * sizeof *h);
    if (G)
        memset(G, 0, (size_t)n * n * sizeof *G);
    for (int a = 0; a < NZ; a++)
        for (int b = 0; b < NP; b++) {
            double r = sqrt(1.0 - zx[a] * zx[a]), phi = 2.0 * PI * (b + 0.5) / NP;
            double d[3] = {r * vdsh_det_cos(phi), r * vdsh_det_sin(phi), zx[a]};
            eval_d(order, d, y);
            double w = zw[a] * 2.0 * PI / NP;
            for (int i = 0; i < n; i++) {
                h[i] += w * y[i];
                for (int j = 0; G && j < n; j++)
                    G[i * n + j] += w * y[i] * y[j];
            }
        }
    for (int i = 0; G && i < n; i++) {
        double l = band_of(i);
        G[i * n + i] += lambda * (l * (l + 1)) * (l * (l + 1));
    }
}

/* Per band l: pinv_l = B_l^T (B_l B_l^T)^-1 of the basis block at the
 * band's samples, over-determined, so each block is close to a multiple
 * of an orthogonal matrix (condition ~1) and evaluation error is not
 * amplified. Returns 0 if a band is degenerate, -1 out of memory. */
static int rotation_pinv(vb_fit *f)
{
    int order = f->order, ok = 1;
    double *Y = malloc((size_t)VB_FIT_ROT_DIRS_HIGH * VB_FIT_MAX * sizeof *Y);
    if (!Y)
        return -1;
    for (int l = 0; l < order && ok == 1; l++) {
        int K = rot_count(l), k = 2 * l + 1, o = l * l;
        const double(*dirs)[3] = rot_set(f, l);
        if (l == 0 || l == 5)
            for (int j = 0; j < K; j++)
                eval_d(order, dirs[j], Y + (size_t)j * VB_FIT_MAX);
        double BBt[VDSH_MAX_BAND_WIDTH * VDSH_MAX_BAND_WIDTH];
        double inv[VDSH_MAX_BAND_WIDTH * VDSH_MAX_BAND_WIDTH];
        for (int a = 0; a < k; a++)
            for (int b = 0; b < k; b++) {
                double s = 0.0;
                for (int j = 0; j < K; j++)
                    s += Y[(size_t)j * VB_FIT_MAX + o + a] * Y[(size_t)j * VB_FIT_MAX + o + b];
                BBt[a * k + b] = s;
            }
        ok = invert(k, BBt, inv);
        for (int j = 0; ok == 1 && j < K; j++)
            for (int b = 0; b < k; b++) {
                double s = 0.0;
                for (int a = 0; a < k; a++)
                    s += Y[(size_t)j * VB_FIT_MAX + o + a] * inv[a * k + b];
                f->rot_pinv[l][j * k + b] = s;
            }
    }
    free(Y);
    return ok;
}

float vb_fit_lambda(float lambda, int order)
{
    if (order <= 5)
        return lambda;
    double s = 20.0 / ((double)order * (order - 1)); /* (l(l+1)) of band 4 over the top band's */
    return (float)(lambda * s * s);
}

static inline void rotate_x(const vb_fit *f, int order, int transpose, double *v);

vb_result vb_fit_create(int order, vb_fit_base base, float lambda, vb_fit *out, vb_error *err)
{
    if (order < 1 || order > VDSH_MAX_ORDER)
        return vb_fail(err, VB_ERR_ARGUMENT, "order must be 1..%d, not %d", VDSH_MAX_ORDER, order);
    if (base != VB_FIT_IDENTITY && base != VB_FIT_MIRROR && base != VB_FIT_LSQ)
        return vb_fail(err, VB_ERR_ARGUMENT, "unknown base fit %d", (int)base);
    if (!(lambda >= 0.0f) || !isfinite(lambda))
        return vb_fail(err, VB_ERR_ARGUMENT, "regularisation must be a number >= 0");
    int n = order * order;
    vb_fit *f = calloc(1, sizeof *f);
    double *G = malloc((size_t)n * n * sizeof *G); /* the Gram matrix, then X as one matrix */
    vb_result r = VB_OK;
    if (!f || !G) {
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for an order-%d fit", order);
        goto done;
    }
    f->order = order;
    f->base = base;
    f->lambda = lambda;
    for (int i = 0; i < n; i++)
        f->window[i] = 1.0;
    hemisphere_moments(order, lambda, f->hemi, base == VB_FIT_LSQ ? G : NULL);

    int ok = 1;
    switch (base) {
    case VB_FIT_IDENTITY:
        for (int i = 0; i < n; i++)
            f->M[i * n + i] = 1.0;
        break;
    case VB_FIT_MIRROR:
        /* Y_lm(x, y, -z) = (-1)^(l+m) Y_lm(x, y, z): the mirrored lower
         * half doubles the even terms and cancels the odd ones. */
        for (int i = 0; i < n; i++) {
            int l = band_of(i), m = i - l * (l + 1);
            f->M[i * n + i] = ((l + m) % 2 == 0) ? 2.0 : 0.0;
        }
        break;
    case VB_FIT_LSQ:
        ok = invert(n, G, f->M);
        if (ok == 0) {
            r = vb_fail(err, VB_ERR_ARGUMENT,
                        "least squares at order %d is singular: use a regularisation > 0", order);
            goto done;
        }
        break;
    }

    fibonacci(VB_FIT_ROT_DIRS, f->rot_dirs);
    fibonacci(VB_FIT_ROT_DIRS_HIGH, f->rot_dirs_high);
    if (ok == 1)
        ok = rotation_pinv(f);
    if (ok == 0) {
        r = vb_fail(err, VB_ERR_ARGUMENT, "rotation samples degenerate at order %d", order);
        goto done;
    }
    if (ok < 0) {
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for an order-%d fit", order);
        goto done;
    }

    /* X: the rotation by 90 degrees about x (y to z, z to -y), whose
     * conjugate X^T Rz(beta) X is the rotation by beta about y. Most of
     * its entries are 0. Bands 0-4, built from float SH values, are off
     * by ~1e-7 and their other entries are at least 0.125 in magnitude;
     * bands 5 and up are built in double and their smallest non-zero
     * entries, 2^-l or so, are far above 1e-9. The zeros are made exact. */
    static const double Q[9] = {1, 0, 0, 0, 0, -1, 0, 1, 0};
    double *XS = G;
    vb_sh_rotation(f, Q, XS);
    for (int l = 0; l < order; l++) {
        int k = 2 * l + 1, o = l * l;
        double zero = l < 5 ? 1e-6 : 1e-9;
        for (int a = 0; a < k; a++)
            for (int b = 0; b < k; b++) {
                double x = XS[(o + a) * n + o + b];
                f->X[l][a * k + b] = f->XT[l][b * k + a] = fabs(x) < zero ? 0.0 : x;
            }
    }
    for (int i = 0; i < n; i++) /* X M X^T, X block-diagonal by band */
        for (int j = 0; j < n; j++) {
            int li = band_of(i), lj = band_of(j), ki = 2 * li + 1, kj = 2 * lj + 1;
            int oi = li * li, oj = lj * lj;
            double sum = 0.0;
            for (int a = 0; a < ki; a++)
                for (int b = 0; b < kj; b++)
                    sum += f->X[li][(i - oi) * ki + a] * f->M[(oi + a) * n + oj + b] *
                           f->X[lj][(j - oj) * kj + b];
            f->NT[j * n + i] = sum;
        }
    rotate_x(f, order, 0, f->hemi); /* into u's frame, once */
    *out = *f;
done:
    free(G);
    free(f);
    return r;
}

void vb_fit_window(vb_fit *f, vdsh_window window)
{
    /* A window scales whole bands, and rotations keep bands apart, so it
     * commutes with S: it applies to the final coefficients. */
    for (int i = 0; i < f->order * f->order; i++)
        f->window[i] = vb_window_weight(window, band_of(i), f->order);
}

void vb_sh_rotation(const vb_fit *f, const double R[9], double *out)
{
    int n = f->order * f->order;
    memset(out, 0, (size_t)n * n * sizeof *out);
    /* Band by band: Y_l(R^T s_j) = S_l^T Y_l(s_j) at the band's sample
     * directions s_j, i.e. [Y_l(R^T s_j)]_j = S_l^T B_l, so S_l^T =
     * [Y_l(R^T s_j)]_j pinv_l (exact: the basis of a band is closed under
     * rotation). Each entry sums over j in order, one direction at a time. */
    for (int set = 0; set < 2; set++) {
        int l0 = set ? 5 : 0, l1 = set ? f->order : (f->order < 5 ? f->order : 5);
        if (l0 >= l1)
            continue;
        int K = rot_count(l0);
        const double(*dirs)[3] = rot_set(f, l0);
        for (int j = 0; j < K; j++) {
            const double *s = dirs[j];
            double d[3] = {R[0] * s[0] + R[3] * s[1] + R[6] * s[2],
                           R[1] * s[0] + R[4] * s[1] + R[7] * s[2],
                           R[2] * s[0] + R[5] * s[1] + R[8] * s[2]};
            double y[VB_FIT_MAX];
            eval_d(l1, d, y);
            for (int l = l0; l < l1; l++) {
                int k = 2 * l + 1, o = l * l;
                const double *pinv = f->rot_pinv[l] + (size_t)j * k;
                for (int a = 0; a < k; a++) /* row a of S_l^T, into column a of S */
                    for (int b = 0; b < k; b++)
                        out[(o + b) * n + (o + a)] += y[o + a] * pinv[b];
            }
        }
    }
}

int vb_fit_constant_exact(const vb_fit_angles *a, int hemisphere)
{
    return !hemisphere || a->rotates;
}

void vb_fit_frame(const vb_fit *f, const float n[3], vb_fit_angles *a)
{
    memset(a, 0, sizeof *a);
    double x = n[0], y = n[1], z = n[2], r = sqrt(x * x + y * y), len = sqrt(r * r + z * z);
    a->rotates = f->base != VB_FIT_IDENTITY && len > 0.0;
    if (!a->rotates)
        return;
    /* n = (sin beta cos alpha, sin beta sin alpha, cos beta); on the
     * poles alpha is free: 0. Multiples by the angle-sum formulas. */
    double ca = r > 0.0 ? x / r : 1.0, sa = r > 0.0 ? y / r : 0.0;
    double cb = z / len, sb = r / len;
    a->ca[0] = a->cb[0] = 1.0;
    for (int m = 1; m < VDSH_MAX_ORDER; m++) {
        a->ca[m] = a->ca[m - 1] * ca - a->sa[m - 1] * sa;
        a->sa[m] = a->sa[m - 1] * ca + a->ca[m - 1] * sa;
        a->cb[m] = a->cb[m - 1] * cb - a->sb[m - 1] * sb;
        a->sb[m] = a->sb[m - 1] * cb + a->cb[m - 1] * sb;
    }
}

/* v = Rz(sign * gamma) v over bands 0..order-1, given cos and sin of
 * m gamma: coefficient l(l+1)+m goes with cos m phi, l(l+1)-m with
 * sin m phi (the same factor on both, phase included), and f(phi - gamma)
 * turns each pair by m gamma. */
static void rotate_z(int order, const double *cm, const double *sm, double sign, double *v)
{
    for (int l = 1; l < order; l++) {
        int c = l * (l + 1);
        for (int m = 1; m <= l; m++) {
            double p = v[c + m], q = v[c - m], s = sign * sm[m];
            v[c + m] = p * cm[m] - q * s;
            v[c - m] = p * s + q * cm[m];
        }
    }
}

/* v = X v, or X^T v, over bands 0..order-1. The products here and in
 * vb_fit_finish run down columns (a column-major copy where needed), so
 * they vectorise over the rows while each row sums in column order. */
static inline void rotate_x(const vb_fit *f, int order, int transpose, double *v)
{
    for (int l = 1; l < order; l++) {
        int k = 2 * l + 1, o = l * l;
        const double *cols = transpose ? f->X[l] : f->XT[l];
        double in[VDSH_MAX_BAND_WIDTH], *out = v + o;
        memcpy(in, out, (size_t)k * sizeof *in);
        for (int i = 0; i < k; i++)
            out[i] = 0.0;
        for (int j = 0; j < k; j++)
            for (int i = 0; i < k; i++)
                out[i] += cols[j * k + i] * in[j];
    }
}

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) &&                             \
    !defined(__SANITIZE_ADDRESS__)
#define VB_CLONES __attribute__((target_clones("avx2", "default"))) /* no FMA: same bits */
#else
#define VB_CLONES
#endif

VB_CLONES void vb_fit_unrotate(const vb_fit *f, const vb_fit_angles *a, const double *b, double *u)
{
    memcpy(u, b, (size_t)f->order * f->order * sizeof *u);
    if (!a->rotates)
        return;
    rotate_z(f->order, a->ca, a->sa, -1.0, u);
    rotate_x(f, f->order, 0, u);
    rotate_z(f->order, a->cb, a->sb, -1.0, u);
}

VB_CLONES void vb_fit_finish(const vb_fit *f, const vb_fit_angles *a, const double *u, float *c)
{
    int n = f->order * f->order;
    if (!a->rotates) {
        for (int i = 0; i < n; i++)
            c[i] = (float)(f->window[i] * u[i]);
        return;
    }
    double v[VB_FIT_MAX];
    for (int i = 0; i < n; i++)
        v[i] = 0.0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++)
            v[i] += f->NT[j * n + i] * u[j];
    rotate_z(f->order, a->cb, a->sb, 1.0, v);
    rotate_x(f, f->order, 1, v);
    rotate_z(f->order, a->ca, a->sa, 1.0, v);
    for (int i = 0; i < n; i++)
        c[i] = (float)(f->window[i] * v[i]);
}

void vb_fit_add_constant(const vb_fit *f, int hemisphere, double m, double *u)
{
    if (!hemisphere) {
        u[0] += m * sqrt(4.0 * PI); /* the whole sphere: 1 is sqrt(4 pi) Y_0 */
        return;
    }
    for (int i = 0; i < f->order * f->order; i++)
        u[i] += m * f->hemi[i];
}

void vb_fit_apply(const vb_fit *f, const float n[3], const double *b, float *c)
{
    vb_fit_angles a;
    double u[VB_FIT_MAX];
    vb_fit_frame(f, n, &a);
    vb_fit_unrotate(f, &a, b, u);
    vb_fit_finish(f, &a, u, c);
}
