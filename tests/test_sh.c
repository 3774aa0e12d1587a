/* SH basis: orthonormality, the DESIGN.md values, and bands 3-4 against an
 * independent construction from the associated Legendre recurrence. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "test_util.h"
#include "vdsh_sh.h"

/* Gauss-Legendre nodes/weights on [-1, 1] by Newton iteration. */
static void gauss_legendre(int n, double *x, double *w)
{
    for (int i = 0; i < n; i++) {
        double z = cos(M_PI * (i + 0.75) / (n + 0.5)), pp = 0.0;
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

/* Orthonormality: Gauss-Legendre in z times uniform phi is exact for the
 * products of two band <= 4 functions (degree 8). */
static void test_orthonormal(void)
{
    enum { NZ = 12, NP = 24, NC = 25 };
    double x[NZ], w[NZ], G[NC][NC];
    memset(G, 0, sizeof G);
    gauss_legendre(NZ, x, w);
    for (int i = 0; i < NZ; i++)
        for (int j = 0; j < NP; j++) {
            double phi = 2.0 * M_PI * j / NP, r = sqrt(1.0 - x[i] * x[i]);
            float d[3] = {(float)(r * cos(phi)), (float)(r * sin(phi)), (float)x[i]};
            float y[NC];
            vdsh_sh_eval(5, d, y);
            double wt = w[i] * 2.0 * M_PI / NP;
            for (int a = 0; a < NC; a++)
                for (int b = 0; b < NC; b++)
                    G[a][b] += wt * y[a] * y[b];
        }
    double worst = 0.0;
    for (int a = 0; a < NC; a++)
        for (int b = 0; b < NC; b++)
            worst = fmax(worst, fabs(G[a][b] - (a == b)));
    CHECK(worst < 2e-6, "Gram matrix differs from identity by %g", worst);
}

/* DESIGN.md section 2, bands 0-2, at a few directions. */
static void test_design_values(void)
{
    uint64_t s = 7;
    for (int k = 0; k < 100; k++) {
        float d[3], y[9];
        test_rand_dir(&s, d);
        vdsh_sh_eval(3, d, y);
        double x = d[0], yy = d[1], z = d[2];
        double want[9] = {0.282095,
                          -0.488603 * yy, 0.488603 * z, -0.488603 * x,
                          1.092548 * x * yy, -1.092548 * yy * z,
                          0.315392 * (3 * z * z - 1), -1.092548 * x * z,
                          0.546274 * (x * x - yy * yy)};
        for (int i = 0; i < 9; i++)
            CHECK(fabs(y[i] - want[i]) < 2e-6, "Y_%d(%g,%g,%g) = %g, DESIGN gives %g",
                  i, x, yy, z, y[i], want[i]);
    }
}

/* Real SH from the associated Legendre recurrence with the Condon-Shortley
 * phase, in double: Y_l^m = sqrt2 K P_l^m cos(m phi) (m > 0),
 * sqrt2 K P_l^|m| sin(|m| phi) (m < 0), K P_l^0 (m = 0). */
static double legendre(int l, int m, double x)
{
    double pmm = 1.0, somx2 = sqrt((1.0 - x) * (1.0 + x)), fact = 1.0;
    for (int i = 1; i <= m; i++) {
        pmm *= -fact * somx2; /* the (-1)^m Condon-Shortley phase */
        fact += 2.0;
    }
    if (l == m)
        return pmm;
    double pmmp1 = x * (2.0 * m + 1.0) * pmm;
    if (l == m + 1)
        return pmmp1;
    double pll = 0.0;
    for (int ll = m + 2; ll <= l; ll++) {
        pll = ((2.0 * ll - 1.0) * x * pmmp1 - (ll + m - 1.0) * pmm) / (ll - m);
        pmm = pmmp1;
        pmmp1 = pll;
    }
    return pll;
}

static double factorial(int n)
{
    double f = 1.0;
    for (int i = 2; i <= n; i++)
        f *= i;
    return f;
}

static double sh_reference(int l, int m, const float d[3])
{
    double theta = acos(fmax(-1.0, fmin(1.0, d[2]))), phi = atan2(d[1], d[0]);
    int am = abs(m);
    double K = sqrt((2.0 * l + 1.0) / (4.0 * M_PI) * factorial(l - am) / factorial(l + am));
    double P = legendre(l, am, cos(theta));
    if (m == 0)
        return K * P;
    return sqrt(2.0) * K * P * (m > 0 ? cos(m * phi) : sin(am * phi));
}

static void test_recurrence(void)
{
    uint64_t s = 11;
    double worst = 0.0;
    for (int k = 0; k < 2000; k++) {
        float d[3], y[25];
        test_rand_dir(&s, d);
        vdsh_sh_eval(5, d, y);
        for (int l = 0; l <= 4; l++)
            for (int m = -l; m <= l; m++)
                worst = fmax(worst, fabs(y[l * (l + 1) + m] - sh_reference(l, m, d)));
    }
    CHECK(worst < 5e-6, "largest difference from the recurrence: %g", worst);
}

/* The batch form is the same kernel: bit-identical results, and lower
 * orders are prefixes of higher ones. */
static void test_soa_and_prefix(void)
{
    enum { N = 37 };
    float x[N], y[N], z[N], out[25 * N];
    uint64_t s = 3;
    for (int k = 0; k < N; k++) {
        float d[3];
        test_rand_dir(&s, d);
        x[k] = d[0], y[k] = d[1], z[k] = d[2];
    }
    vdsh_sh_eval_soa(5, N, x, y, z, out, N);
    for (int k = 0; k < N; k++) {
        float d[3] = {x[k], y[k], z[k]}, a[25], b[9];
        vdsh_sh_eval(5, d, a);
        vdsh_sh_eval(3, d, b);
        for (int i = 0; i < 25; i++)
            CHECK(memcmp(&a[i], &out[i * N + k], sizeof(float)) == 0,
                  "soa differs at i=%d k=%d", i, k);
        for (int i = 0; i < 9; i++)
            CHECK(a[i] == b[i], "order 3 is not a prefix of order 5 at %d", i);
        float c[25];
        for (int i = 0; i < 25; i++)
            c[i] = (float)(i + 1);
        double want = 0.0;
        for (int i = 0; i < 25; i++)
            want += c[i] * a[i];
        CHECK(fabs(vdsh_sh_reconstruct(5, c, d) - want) < 1e-4, "reconstruct");
    }
}

int main(void)
{
    test_orthonormal();
    test_design_values();
    test_recurrence();
    test_soa_and_prefix();
    return test_report("test_sh");
}
