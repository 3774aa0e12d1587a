#include "fit.h"

#include <math.h>
#include <string.h>

#include "vdsh.h"
#include "vdsh_sh.h"

#define PI 3.14159265358979323846

static int band_of(int i)
{
    int l = 0;
    while ((l + 1) * (l + 1) <= i)
        l++;
    return l;
}

static void eval_d(int order, const double d[3], double *y)
{
    float f[3] = {(float)d[0], (float)d[1], (float)d[2]}, yy[VB_FIT_MAX];
    vdsh_sh_eval(order, f, yy);
    for (int i = 0; i < order * order; i++)
        y[i] = yy[i];
}

/* Gauss-Jordan inverse with partial pivoting of an n x n matrix (n <= VB_FIT_MAX).
 * Returns 0 if singular. */
static int invert(int n, const double *a, double *inv)
{
    double m[VB_FIT_MAX][2 * VB_FIT_MAX];
    for (int i = 0; i < n; i++)
        for (int j = 0; j < 2 * n; j++)
            m[i][j] = j < n ? a[i * n + j] : (j - n == i);
    for (int c = 0; c < n; c++) {
        int p = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(m[r][c]) > fabs(m[p][c]))
                p = r;
        if (fabs(m[p][c]) < 1e-14)
            return 0;
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
    return 1;
}

void vb_gauss_legendre(int n, double *x, double *w)
{
    for (int i = 0; i < n; i++) {
        double z = cos(PI * (i + 0.75) / (n + 0.5)), pp = 1.0;
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
    case VDSH_WINDOW_HANN:
        return 0.5 * (1.0 + cos(PI * x));
    case VDSH_WINDOW_LANCZOS:
        return l == 0 ? 1.0 : sin(PI * x) / (PI * x);
    default:
        return 1.0;
    }
}

vb_result vb_fit_create(int order, vb_fit_base base, float lambda, vb_fit *out,
                        vb_error *err)
{
    if (order < 1 || order > VDSH_MAX_ORDER)
        return vb_fail(err, VB_ERR_ARGUMENT, "order must be 1..%d, not %d", VDSH_MAX_ORDER,
                       order);
    if (base != VB_FIT_IDENTITY && base != VB_FIT_MIRROR && base != VB_FIT_LSQ)
        return vb_fail(err, VB_ERR_ARGUMENT, "unknown base fit %d", (int)base);
    if (!(lambda >= 0.0f) || !isfinite(lambda))
        return vb_fail(err, VB_ERR_ARGUMENT, "regularisation must be a number >= 0");
    vb_fit f;
    memset(&f, 0, sizeof f);
    f.order = order;
    f.base = base;
    f.lambda = lambda;
    int n = order * order;
    for (int i = 0; i < n; i++)
        f.window[i] = 1.0;

    switch (base) {
    case VB_FIT_IDENTITY:
        for (int i = 0; i < n; i++)
            f.M[i * n + i] = 1.0;
        break;
    case VB_FIT_MIRROR:
        /* Y_lm(x, y, -z) = (-1)^(l+m) Y_lm(x, y, z): the mirrored lower
         * half doubles the even terms and cancels the odd ones. */
        for (int i = 0; i < n; i++) {
            int l = band_of(i), m = i - l * (l + 1);
            f.M[i * n + i] = ((l + m) % 2 == 0) ? 2.0 : 0.0;
        }
        break;
    case VB_FIT_LSQ: {
        /* G_ij = integral over z > 0 of Y_i Y_j: Gauss-Legendre in z
         * (exact to degree 31) times 64 azimuths (exact for cos/sin of
         * order < 64); the products here have degree <= 8. */
        enum { NZ = 16, NP = 64 };
        double zx[NZ], zw[NZ], G[VB_FIT_MAX * VB_FIT_MAX] = {0};
        gauss01(NZ, zx, zw);
        for (int a = 0; a < NZ; a++)
            for (int b = 0; b < NP; b++) {
                double r = sqrt(1.0 - zx[a] * zx[a]), phi = 2.0 * PI * (b + 0.5) / NP;
                double d[3] = {r * cos(phi), r * sin(phi), zx[a]}, y[VB_FIT_MAX];
                eval_d(order, d, y);
                double w = zw[a] * 2.0 * PI / NP;
                for (int i = 0; i < n; i++)
                    for (int j = 0; j < n; j++)
                        G[i * n + j] += w * y[i] * y[j];
            }
        for (int i = 0; i < n; i++) {
            double l = band_of(i);
            G[i * n + i] += (double)lambda * (l * (l + 1)) * (l * (l + 1));
        }
        if (!invert(n, G, f.M))
            return vb_fail(err, VB_ERR_ARGUMENT,
                           "least squares at order %d is singular: use a regularisation > 0",
                           order);
        break;
    }
    }

    /* Rotation samples: a Fibonacci sphere, over-determined for every
     * band, so each band's basis block is close to a multiple of an
     * orthogonal matrix (condition ~1) and float evaluation error is not
     * amplified. pinv_l = B_l^T (B_l B_l^T)^-1. */
    const int K = VB_FIT_ROT_DIRS;
    for (int j = 0; j < K; j++) {
        double z = 1.0 - (2.0 * j + 1.0) / K, r = sqrt(1.0 - z * z);
        double phi = j * PI * (3.0 - sqrt(5.0));
        f.rot_dirs[j][0] = r * cos(phi), f.rot_dirs[j][1] = r * sin(phi), f.rot_dirs[j][2] = z;
    }
    double Y[VB_FIT_ROT_DIRS][VB_FIT_MAX];
    for (int j = 0; j < K; j++)
        eval_d(order, f.rot_dirs[j], Y[j]);
    for (int l = 0; l < order; l++) {
        int k = 2 * l + 1, o = l * l;
        double BBt[VDSH_MAX_BAND_WIDTH * VDSH_MAX_BAND_WIDTH];
        double inv[VDSH_MAX_BAND_WIDTH * VDSH_MAX_BAND_WIDTH];
        for (int a = 0; a < k; a++)
            for (int b = 0; b < k; b++) {
                double s = 0.0;
                for (int j = 0; j < K; j++)
                    s += Y[j][o + a] * Y[j][o + b];
                BBt[a * k + b] = s;
            }
        if (!invert(k, BBt, inv))
            return vb_fail(err, VB_ERR_ARGUMENT, "rotation samples degenerate at band %d", l);
        for (int j = 0; j < K; j++)
            for (int b = 0; b < k; b++) {
                double s = 0.0;
                for (int a = 0; a < k; a++)
                    s += Y[j][o + a] * inv[a * k + b];
                f.rot_pinv[l][j * k + b] = s;
            }
    }

    /* X: the rotation by 90 degrees about x (y to z, z to -y), whose
     * conjugate X^T Rz(beta) X is the rotation by beta about y. Most of
     * its entries are 0, the others at least 0.125 in magnitude. Built
     * from float SH values it is off by ~1e-7 (as the per-receiver
     * rotations built the same way were); the zeros are made exact. */
    static const double Q[9] = {1, 0, 0, 0, 0, -1, 0, 1, 0};
    double XS[VB_FIT_MAX * VB_FIT_MAX];
    vb_sh_rotation(&f, Q, XS);
    for (int l = 0; l < order; l++) {
        int k = 2 * l + 1, o = l * l;
        for (int a = 0; a < k; a++)
            for (int b = 0; b < k; b++) {
                double x = XS[(o + a) * n + o + b];
                f.X[l][a * k + b] = f.XT[l][b * k + a] = fabs(x) < 1e-6 ? 0.0 : x;
            }
    }
    for (int i = 0; i < n; i++) /* X M X^T, X block-diagonal by band */
        for (int j = 0; j < n; j++) {
            int li = band_of(i), lj = band_of(j), ki = 2 * li + 1, kj = 2 * lj + 1;
            int oi = li * li, oj = lj * lj;
            double sum = 0.0;
            for (int a = 0; a < ki; a++)
                for (int b = 0; b < kj; b++)
                    sum += f.X[li][(i - oi) * ki + a] * f.M[(oi + a) * n + oj + b] *
                           f.X[lj][(j - oj) * kj + b];
            f.NT[j * n + i] = sum;
        }
    *out = f;
    return VB_OK;
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
    /* Band by band: Y_l(R^T s_j) = S_l^T Y_l(s_j) at the sample directions
     * s_j, i.e. [Y_l(R^T s_j)]_j = S_l^T B_l, so S_l^T = [Y_l(R^T s_j)]_j
     * pinv_l (exact: the basis of a band is closed under rotation). */
    double yr[VB_FIT_ROT_DIRS][VB_FIT_MAX];
    for (int j = 0; j < VB_FIT_ROT_DIRS; j++) {
        const double *s = f->rot_dirs[j];
        double d[3] = {R[0] * s[0] + R[3] * s[1] + R[6] * s[2],
                       R[1] * s[0] + R[4] * s[1] + R[7] * s[2],
                       R[2] * s[0] + R[5] * s[1] + R[8] * s[2]};
        eval_d(f->order, d, yr[j]);
    }
    for (int l = 0; l < f->order; l++) {
        int k = 2 * l + 1, o = l * l;
        const double *pinv = f->rot_pinv[l];
        for (int a = 0; a < k; a++) { /* row a of S_l^T, all columns at once */
            double s[VDSH_MAX_BAND_WIDTH] = {0}; /* each sums over j in order: it vectorises over b */
            for (int j = 0; j < VB_FIT_ROT_DIRS; j++) {
                double y = yr[j][o + a];
                for (int b = 0; b < k; b++)
                    s[b] += y * pinv[j * k + b];
            }
            for (int b = 0; b < k; b++)
                out[(o + b) * n + (o + a)] = s[b]; /* transpose into S */
        }
    }
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

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && \
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

void vb_fit_apply(const vb_fit *f, const float n[3], const double *b, float *c)
{
    vb_fit_angles a;
    double u[VB_FIT_MAX];
    vb_fit_frame(f, n, &a);
    vb_fit_unrotate(f, &a, b, u);
    vb_fit_finish(f, &a, u, c);
}
