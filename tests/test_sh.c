/* SH basis: orthonormality, the docs/DESIGN.md values, and bands 3-4 against an
 * independent construction from the associated Legendre recurrence. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fit.h" /* vb_gauss_legendre */
#include "test_util.h"
#include "vdsh.h"
#include "vdsh_light.h"
#include "vdsh_sh.h"
#include "vdsh_shadow.h"

/* Orthonormality: Gauss-Legendre in z times uniform phi is exact for the
 * products of two band <= 4 functions (degree 8). */
static void test_orthonormal(void)
{
    enum { NZ = 12, NP = 24, NC = 25 };
    double x[NZ], w[NZ], G[NC][NC];
    memset(G, 0, sizeof G);
    vb_gauss_legendre(NZ, x, w);
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

/* docs/DESIGN.md §2, bands 0-2, at a few directions. */
static void test_design_values(void)
{
    uint64_t s = 7;
    for (int k = 0; k < 100; k++) {
        float d[3], y[9];
        test_rand_dir(&s, d);
        vdsh_sh_eval(3, d, y);
        double x = d[0], yy = d[1], z = d[2];
        double want[9] = {0.282095,
                          -0.488603 * yy,
                          0.488603 * z,
                          -0.488603 * x,
                          1.092548 * x * yy,
                          -1.092548 * yy * z,
                          0.315392 * (3 * z * z - 1),
                          -1.092548 * x * z,
                          0.546274 * (x * x - yy * yy)};
        for (int i = 0; i < 9; i++)
            CHECK(fabs(y[i] - want[i]) < 2e-6, "Y_%d(%g,%g,%g) = %g, docs/DESIGN.md gives %g", i, x,
                  yy, z, y[i], want[i]);
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

    /* Orders 6..VDSH_MAX_ORDER (bands 5-15, by the recurrence): the
     * reference's values, and orthonormal by quadrature. */
    enum { N = 500, NC = VDSH_MAX_COEFFS };
    float x[N], yy[N], z[N], *out = malloc(sizeof(float) * NC * N);
    CHECK(out != NULL, "out of memory");
    if (!out)
        return;
    for (int k = 0; k < N; k++) {
        float d[3];
        test_rand_dir(&s, d);
        x[k] = d[0], yy[k] = d[1], z[k] = d[2];
    }
    vdsh_sh_eval_soa(VDSH_MAX_ORDER, N, x, yy, z, out, N);
    worst = 0.0;
    double worst_low = 0.0;
    for (int k = 0; k < N; k++) {
        float d[3] = {x[k], yy[k], z[k]}, y5[25];
        vdsh_sh_eval(5, d, y5);
        for (int i = 0; i < 25; i++)
            worst_low = fmax(worst_low, fabs(out[i * N + k] - y5[i]));
        float one[VDSH_MAX_COEFFS];
        vdsh_sh_eval(VDSH_MAX_ORDER, d, one);
        for (int i = 0; i < NC; i++)
            worst_low = fmax(worst_low, fabs(out[i * N + k] - one[i]));
        for (int l = 5; l < VDSH_MAX_ORDER; l++)
            for (int m = -l; m <= l; m++)
                worst = fmax(worst, fabs(out[(l * (l + 1) + m) * N + k] - sh_reference(l, m, d)) /
                                        sqrt((2.0 * l + 1.0) / (4.0 * M_PI)));
    }
    CHECK(worst_low == 0.0,
          "the batch form's first 25 differ from order 5's, or the one-"
          "direction form from the batch, by %g",
          worst_low);
    CHECK(worst < 2e-5, "bands 5-%d differ from the reference by %g (relative to the peak)",
          VDSH_MAX_ORDER - 1, worst);
    free(out);

    enum { NZ = 16, NP = 36 }; /* exact for the products' degree <= 30 */
    double gx[NZ], gw[NZ];
    vb_gauss_legendre(NZ, gx, gw);
    static double G[NC][NC];
    memset(G, 0, sizeof G);
    for (int i = 0; i < NZ; i++) {
        float qx[NP], qy[NP], qz[NP];
        static float q[NC * NP];
        for (int j = 0; j < NP; j++) {
            double phi = 2.0 * M_PI * j / NP, r = sqrt(1.0 - gx[i] * gx[i]);
            qx[j] = (float)(r * cos(phi)), qy[j] = (float)(r * sin(phi)), qz[j] = (float)gx[i];
        }
        vdsh_sh_eval_soa(VDSH_MAX_ORDER, NP, qx, qy, qz, q, NP);
        for (int j = 0; j < NP; j++)
            for (int a = 0; a < NC; a++)
                for (int b = 0; b < NC; b++)
                    G[a][b] += gw[i] * 2.0 * M_PI / NP * q[a * NP + j] * q[b * NP + j];
    }
    double off = 0.0;
    for (int a = 0; a < NC; a++)
        for (int b = 0; b < NC; b++)
            off = fmax(off, fabs(G[a][b] - (a == b)));
    CHECK(off < 1e-5, "order %d Gram matrix differs from identity by %g", VDSH_MAX_ORDER, off);
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
    /* Rows further apart than the count (the decision fit's layout): the
     * same values, and nothing written between the rows. */
    enum { S = N + 11 };
    float wide[25 * S];
    for (int order = 1; order <= 5; order++) {
        for (int i = 0; i < 25 * S; i++)
            wide[i] = -7.0f;
        vdsh_sh_eval_soa(order, N, x, y, z, wide, S);
        for (int i = 0; i < order * order; i++)
            for (int k = 0; k < S; k++)
                CHECK(k < N ? memcmp(&wide[i * S + k], &out[i * N + k], sizeof(float)) == 0
                            : wide[i * S + k] == -7.0f,
                      "order %d at stride %d: row %d, lane %d", order, S, i, k);
    }
    for (int k = 0; k < N; k++) {
        float d[3] = {x[k], y[k], z[k]}, a[25], b[9];
        vdsh_sh_eval(5, d, a);
        vdsh_sh_eval(3, d, b);
        for (int i = 0; i < 25; i++)
            CHECK(memcmp(&a[i], &out[i * N + k], sizeof(float)) == 0, "soa differs at i=%d k=%d", i,
                  k);
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

/* The shadow evaluation: the ramp, both comparisons, the defined edge
 * cases, and a stream whose reconstruction is known (a constant). */
static void test_shadow(void)
{
    /* A log-distance sum beyond any fit stays finite (VDSH_LOG_SUM_MAX),
     * so interpolating it with a zero weight is 0, not NaN. */
    {
        float big[25] = {1000.0f}, up[3] = {0.0f, 0.0f, 1.0f};
        float dv = vdsh_stream_distance(5, VDSH_QUANTITY_LOG_DISTANCE, INFINITY, big, up);
        CHECK(isfinite(dv) && dv > 1e30f, "huge log sum reads as %g", dv);
        CHECK(0.0f * dv == 0.0f, "0 * its distance is not 0");
    }

    CHECK(vdsh_ramp(1.0f / 3.0f) == 0.0f && vdsh_ramp(1.0f) == 1.0f, "ramp ends");
    CHECK(fabsf(vdsh_ramp(2.0f / 3.0f) - 0.5f) < 1e-6f, "ramp middle");
    CHECK(vdsh_ramp(-5.0f) == 0.0f && vdsh_ramp(7.0f) == 1.0f, "ramp saturates");
    CHECK(vdsh_ramp(NAN) == 0.0f, "ramp(NaN)");
    CHECK(vdsh_shadow_compare(1.0f, 0.0f, VDSH_COMPARE_SMOOTH) == 1.0f, "light at receiver");
    CHECK(vdsh_shadow_compare(1.0f, 0.0f, VDSH_COMPARE_BINARY) == 1.0f, "light at receiver");
    CHECK(vdsh_shadow_compare(INFINITY, 5.0f, VDSH_COMPARE_SMOOTH) == 1.0f, "infinite distance");
    CHECK(vdsh_shadow_compare(NAN, 5.0f, VDSH_COMPARE_SMOOTH) == 0.0f, "NaN distance");
    CHECK(vdsh_shadow_compare(1.0f, NAN, VDSH_COMPARE_SMOOTH) == 0.0f, "NaN light distance");
    CHECK(vdsh_shadow_compare(2.0f, 2.0f, VDSH_COMPARE_BINARY) == 1.0f &&
              vdsh_shadow_compare(1.99f, 2.0f, VDSH_COMPARE_BINARY) == 0.0f,
          "binary step");

    /* D = 4 everywhere: c0 = 4 sqrt(4 pi). */
    float c[25] = {0};
    c[0] = (float)(4.0 * sqrt(4.0 * M_PI));
    float p[3] = {1, 2, 3}, near[3] = {1, 2, 5}, far[3] = {1, 2, 23}, mid[3] = {1, 2, 9};
    CHECK(vdsh_shadow(5, VDSH_QUANTITY_DISTANCE, INFINITY, c, p, near, VDSH_COMPARE_SMOOTH) == 1.0f,
          "light at 2 < D = 4 must be lit");
    CHECK(vdsh_shadow(5, VDSH_QUANTITY_DISTANCE, INFINITY, c, p, far, VDSH_COMPARE_SMOOTH) == 0.0f,
          "light at 20 > 3 D must be dark");
    CHECK(fabsf(vdsh_shadow(5, VDSH_QUANTITY_DISTANCE, INFINITY, c, p, mid, VDSH_COMPARE_SMOOTH) -
                0.5f) < 1e-5f,
          "light at 6 = 1.5 D gives ramp(2/3) = 0.5");
    CHECK(vdsh_shadow(5, VDSH_QUANTITY_DISTANCE, INFINITY, c, p, p, VDSH_COMPARE_SMOOTH) == 1.0f,
          "light exactly at the receiver");
    float neg[25] = {0};
    neg[0] = -1.0f;
    CHECK(vdsh_stream_distance(3, VDSH_QUANTITY_DISTANCE, INFINITY, neg, near) == 0.0f,
          "negative rings to 0");
    float lg[25] = {0};
    lg[0] = (float)(log(4.0) * sqrt(4.0 * M_PI));
    float d[3] = {0, 0, 1};
    CHECK(fabsf(vdsh_stream_distance(2, VDSH_QUANTITY_LOG_DISTANCE, INFINITY, lg, d) - 4.0f) <
              1e-4f,
          "log-distance reconstructs exp of the sum");
    float sq[25] = {0};
    sq[0] = (float)(16.0 * sqrt(4.0 * M_PI));
    CHECK(fabsf(vdsh_stream_distance(2, VDSH_QUANTITY_DISTANCE2, INFINITY, sq, d) - 4.0f) < 1e-4f,
          "distance2 reconstructs the square root");
}

/* Interior points: every mode agrees at a vertex; coefficients and
 * distance agree for a constant linear function; for log-distance the
 * coefficients give the geometric mean of the vertices' distances and the
 * distance mode the arithmetic mean; a light at a vertex is defined. */
static void test_interior(void)
{
    float ca[25] = {0}, cb[25] = {0}, cc[25] = {0};
    uint64_t s = 5;
    for (int i = 0; i < 25; i++) {
        ca[i] = (float)(test_rand(&s) - 0.5), cb[i] = (float)(test_rand(&s) - 0.5);
        cc[i] = (float)(test_rand(&s) - 0.5);
    }
    ca[0] = cb[0] = cc[0] = 12.0f; /* keep the distances positive */
    const float pa[3] = {0, 0, 0}, pb[3] = {2, 0, 0}, pc[3] = {0, 0, 2}, l[3] = {0.7f, 3, 0.4f};
    const float *c[3] = {ca, cb, cc}, *pv[3] = {pa, pb, pc};
    for (uint32_t q = 0; q < 3; q += 2)
        for (uint32_t m = 0; m < 4; m++)
            for (int k = 0; k < 3; k++) {
                float b[3] = {0, 0, 0};
                b[k] = 1.0f;
                float want = vdsh_shadow(5, q, INFINITY, c[k], pv[k], l, VDSH_COMPARE_SMOOTH);
                float got =
                    vdsh_shadow_interior(5, q, INFINITY, m, c, pv, b, l, VDSH_COMPARE_SMOOTH, NULL);
                CHECK(fabsf(got - want) < 1e-5f, "%s, quantity %u, vertex %d: %g vs %g",
                      vdsh_interp_name(m), q, k, got, want);
            }

    float k1[25] = {0}, k2[25] = {0};
    k1[0] = k2[0] = (float)(3.0 * sqrt(4.0 * M_PI)); /* D = 3 everywhere */
    const float *kc[3] = {k1, k2, k1}, b[3] = {0.2f, 0.5f, 0.3f};
    float dc, dd, ds;
    vdsh_shadow_interior(3, VDSH_QUANTITY_DISTANCE, INFINITY, VDSH_INTERP_COEFFICIENTS, kc, pv, b,
                         l, VDSH_COMPARE_SMOOTH, &dc);
    vdsh_shadow_interior(3, VDSH_QUANTITY_DISTANCE, INFINITY, VDSH_INTERP_DISTANCE, kc, pv, b, l,
                         VDSH_COMPARE_SMOOTH, &dd);
    vdsh_shadow_interior(5, VDSH_QUANTITY_DISTANCE, INFINITY, VDSH_INTERP_SPLIT, kc, pv, b, l,
                         VDSH_COMPARE_SMOOTH, &ds);
    CHECK(fabsf(dc - 3) < 1e-5f && fabsf(dd - 3) < 1e-5f && fabsf(ds - 3) < 1e-5f,
          "constant D = 3: %g %g %g", dc, dd, ds);

    float g1[25] = {0}, g2[25] = {0};
    g1[0] = (float)(log(1.0) * sqrt(4.0 * M_PI)), g2[0] = (float)(log(100.0) * sqrt(4.0 * M_PI));
    const float *gc[3] = {g1, g2, g2}, half[3] = {0.5f, 0.5f, 0.0f};
    vdsh_shadow_interior(2, VDSH_QUANTITY_LOG_DISTANCE, INFINITY, VDSH_INTERP_COEFFICIENTS, gc, pv,
                         half, l, VDSH_COMPARE_SMOOTH, &dc);
    vdsh_shadow_interior(2, VDSH_QUANTITY_LOG_DISTANCE, INFINITY, VDSH_INTERP_DISTANCE, gc, pv,
                         half, l, VDSH_COMPARE_SMOOTH, &dd);
    CHECK(fabsf(dc - 10.0f) < 1e-3f, "log coefficients: geometric mean 10, got %g", dc);
    CHECK(fabsf(dd - 50.5f) < 1e-3f, "log distances: arithmetic mean 50.5, got %g", dd);

    for (uint32_t m = 0; m < 4; m++) {
        float at_a[3] = {1, 0, 0};
        float v = vdsh_shadow_interior(5, VDSH_QUANTITY_DISTANCE, INFINITY, m, c, pv, at_a, pa,
                                       VDSH_COMPARE_SMOOTH, &dd);
        CHECK(v == 1.0f && isfinite(dd), "%s: light at the vertex gives %g", vdsh_interp_name(m),
              v);
        float mid[3] = {0.25f, 0.25f, 0.5f};
        v = vdsh_shadow_interior(5, VDSH_QUANTITY_DISTANCE, INFINITY, m, c, pv, mid, pa,
                                 VDSH_COMPARE_SMOOTH, &dd);
        CHECK(v >= 0 && v <= 1 && isfinite(dd), "%s: light at a corner, inside: %g",
              vdsh_interp_name(m), v);
    }
    CHECK(vdsh_runtime_interp(2, VDSH_QUANTITY_DISTANCE) == VDSH_INTERP_VISIBILITY &&
              vdsh_runtime_interp(5, VDSH_QUANTITY_DISTANCE) == VDSH_INTERP_SPLIT &&
              vdsh_runtime_interp(5, VDSH_QUANTITY_LOG_DISTANCE) == VDSH_INTERP_DISTANCE,
          "runtime paths");
}

/* The fused projection is the same kernel as evaluation. */
static void test_project(void)
{
    enum { N = 16 };
    float x[N], y[N], z[N], w[N], Y[25 * N], acc[25 * N];
    uint64_t s = 21;
    for (int k = 0; k < N; k++) {
        float d[3];
        test_rand_dir(&s, d);
        x[k] = d[0], y[k] = d[1], z[k] = d[2], w[k] = (float)(3 * test_rand(&s));
    }
    for (int order = 1; order <= 5; order++) {
        vdsh_sh_eval_soa(order, N, x, y, z, Y, N);
        for (int i = 0; i < 25 * N; i++)
            acc[i] = 0.5f;
        vdsh_sh_project_soa(order, N, x, y, z, w, acc, N);
        for (int i = 0; i < order * order; i++)
            for (int k = 0; k < N; k++)
                CHECK(acc[i * N + k] == 0.5f + w[k] * Y[i * N + k],
                      "order %d: project differs at %d,%d", order, i, k);
        /* A run that is not the 16 x 16 fast path agrees too. */
        float acc2[25 * 7] = {0}, Y2[25 * 7];
        vdsh_sh_eval_soa(order, 7, x, y, z, Y2, 7);
        vdsh_sh_project_soa(order, 7, x, y, z, w, acc2, 7);
        for (int i = 0; i < order * order; i++)
            for (int k = 0; k < 7; k++)
                CHECK(acc2[i * 7 + k] == w[k] * Y2[i * 7 + k], "general path");
    }
}

/* ---- the clamp to the bake's max distance -------------------------------- */

/* Vertex a of a triangle whose light is just below a's horizon (a smooth
 * normal at a terminator: the neighbours see it above theirs), and whose
 * log-distance stream, unconstrained there by the fit, runs away toward
 * it: ln D(w) = ln 0.3 + beta (u . w), u the direction from a to the
 * light. The other two vertices see an occluder 0.3 away in every
 * direction. Order-2 coefficients (bands 0-1; higher bands 0). */
enum { HZ_ORDER = 5 };
#define HZ_MAX 4.0f
static const float HZ_A[3] = {-1, -1, 0}, HZ_B[3] = {1, -1, 0}, HZ_C[3] = {-1, 1, 0};
static const float HZ_LIGHT[3] = {0.5f, 0.5f, 1.5f};

static void horizon_streams(float beta, float ca[25], float cb[25], float n_a[3])
{
    const float c00 = 0.28209479177387814f, c1 = 0.4886025119029199f;
    float u[3], len = 0.0f;
    for (int k = 0; k < 3; k++) {
        u[k] = HZ_LIGHT[k] - HZ_A[k];
        len += u[k] * u[k];
    }
    for (int k = 0; k < 3; k++)
        u[k] /= sqrtf(len);
    /* n_a: turned from +z so that the light is 3 degrees below it */
    float z[3] = {0, 0, 1}, w[3], wl = 0.0f, eps = 3.0f * (float)M_PI / 180.0f;
    for (int k = 0; k < 3; k++) {
        w[k] = z[k] - u[2] * u[k];
        wl += w[k] * w[k];
    }
    for (int k = 0; k < 3; k++)
        n_a[k] = -sinf(eps) * u[k] + cosf(eps) * w[k] / sqrtf(wl);
    memset(ca, 0, 25 * sizeof(float));
    memset(cb, 0, 25 * sizeof(float));
    ca[0] = cb[0] = logf(0.3f) / c00;
    /* Y_1-1 = -C1 y, Y_10 = C1 z, Y_11 = -C1 x */
    ca[1] = -beta * u[1] / c1;
    ca[2] = beta * u[2] / c1;
    ca[3] = -beta * u[0] / c1;
}

static void test_clamp_horizon(void)
{
    float ca[25], cb[25], n_a[3];
    horizon_streams(14.0f, ca, cb, n_a);
    float to_light[3], dl = 0.0f;
    for (int k = 0; k < 3; k++) {
        to_light[k] = HZ_LIGHT[k] - HZ_A[k];
        dl += to_light[k] * to_light[k];
    }
    dl = sqrtf(dl);
    float cosn = 0.0f;
    for (int k = 0; k < 3; k++) {
        to_light[k] /= dl;
        cosn += to_light[k] * n_a[k];
    }
    CHECK(cosn < -0.05f && cosn > -0.06f, "the light is not just below a's horizon: %g", cosn);
    const uint32_t q = VDSH_QUANTITY_LOG_DISTANCE;
    for (uint32_t order = 2; order <= HZ_ORDER; order++) {
        /* the runaway, and the clamp */
        float wild = vdsh_stream_distance(order, q, INFINITY, ca, to_light);
        float d = vdsh_stream_distance(order, q, HZ_MAX, ca, to_light);
        CHECK(wild > 1e5f && d == HZ_MAX, "order %u: toward the light %g, clamped %g", order, wild,
              d);
        /* Near the edge b-c, which sees the occluder: dark. Unclamped,
         * a's distance interpolated over the triangle lit it. */
        const float *c[3] = {ca, cb, cb}, *pv[3] = {HZ_A, HZ_B, HZ_C};
        const float bary[3] = {0.05f, 0.475f, 0.475f};
        for (uint32_t cmp = 0; cmp < 2; cmp++) {
            float dv, dv_wild;
            float s = vdsh_shadow_interior(order, q, HZ_MAX, VDSH_INTERP_DISTANCE, c, pv, bary,
                                           HZ_LIGHT, cmp, &dv);
            float s_wild = vdsh_shadow_interior(order, q, INFINITY, VDSH_INTERP_DISTANCE, c, pv,
                                                bary, HZ_LIGHT, cmp, &dv_wild);
            CHECK(s < 0.5f && dv <= 0.05f * HZ_MAX + 0.95f * 0.3f + 1e-5f,
                  "order %u %s: a light leak near b-c: s %g, distance %g", order,
                  cmp ? "binary" : "smooth", s, dv);
            CHECK(s_wild == 1.0f, "order %u: the case does not tell the clamp apart (%g, %g)",
                  order, s_wild, dv_wild);
            /* on every path the distance compared stays within the clamp */
            for (uint32_t m = 0; m < 4; m++) {
                vdsh_shadow_interior(order, q, HZ_MAX, m, c, pv, bary, HZ_LIGHT, cmp, &dv);
                CHECK(dv >= 0.0f && dv <= HZ_MAX, "order %u %s: distance %g", order,
                      vdsh_interp_name(m), dv);
            }
        }
        /* and vdsh_shadow at a itself: the light counts as visible (it
         * is at dl < max distance) rather than whatever the sum said */
        CHECK(vdsh_shadow(order, q, HZ_MAX, ca, HZ_A, HZ_LIGHT, VDSH_COMPARE_BINARY) == 1.0f,
              "order %u: at a", order);
    }
}

/* No reconstruction exceeds max_distance, for any quantity, order, path
 * and direction (below the horizon too), wild coefficients included; it
 * is exactly max_distance where the unclamped value is above it, and
 * the unclamped value elsewhere. */
static void test_clamp_never_exceeds(void)
{
    uint64_t s = 11;
    long checked = 0, clamped = 0;
    const float md = 7.5f;
    for (int trial = 0; trial < 2000; trial++) {
        uint32_t q = (uint32_t)(trial % 3), order = 1 + (uint32_t)(trial / 3 % 5);
        float c[3][25];
        double spread = trial % 7 == 0 ? 400.0 : 6.0; /* some far past any fit */
        for (int k = 0; k < 3; k++)
            for (int i = 0; i < 25; i++)
                c[k][i] = (float)(spread * (test_rand(&s) - 0.3));
        float d[3];
        test_rand_dir(&s, d);
        float dv = vdsh_stream_distance(order, q, md, c[0], d);
        float wild = vdsh_stream_distance(order, q, INFINITY, c[0], d);
        CHECK(dv >= 0.0f && dv <= md && dv == (wild > md ? md : wild),
              "quantity %u order %u: %g (unclamped %g)", q, order, dv, wild);
        clamped += wild > md;
        const float *cp[3] = {c[0], c[1], c[2]};
        const float pa[3] = {0, 0, 0}, pb[3] = {0.5f, 0, 0}, pc[3] = {0, 0.5f, 0};
        const float *pv[3] = {pa, pb, pc};
        float b[3] = {(float)test_rand(&s), (float)test_rand(&s), 0.0f}, l[3];
        if (b[0] + b[1] > 1.0f)
            b[0] = 1.0f - b[0], b[1] = 1.0f - b[1];
        b[2] = 1.0f - b[0] - b[1];
        test_rand_dir(&s, l);
        for (int k = 0; k < 3; k++)
            l[k] *= 4.0f * (float)test_rand(&s);
        for (uint32_t m = 0; m < 4; m++) {
            float dvis = -1.0f;
            float vis =
                vdsh_shadow_interior(order, q, md, m, cp, pv, b, l, VDSH_COMPARE_SMOOTH, &dvis);
            CHECK(dvis >= 0.0f && dvis <= md * (1.0f + 1e-6f) && vis >= 0.0f && vis <= 1.0f,
                  "%s quantity %u order %u: distance %g, visibility %g", vdsh_interp_name(m), q,
                  order, dvis, vis);
        }
        checked++;
    }
    /* a log sum beyond VDSH_LOG_SUM_MAX: the clamp, not e^80 */
    float big[25] = {1000.0f}, up[3] = {0.0f, 0.0f, 1.0f};
    CHECK(vdsh_stream_distance(5, VDSH_QUANTITY_LOG_DISTANCE, md, big, up) == md, "huge log sum");
    CHECK(checked == 2000 && clamped > checked / 10 && clamped < checked * 9 / 10,
          "coverage: %ld of %ld clamped", clamped, checked);
}

static int never_free(const void *ctx, const float p[3])
{
    (void)ctx, (void)p;
    return 0;
}

/* Lights beyond the clamp (docs/DESIGN.md, "Lights beyond the clamp"):
 * a stored distance is at most the clamp D, so an unoccluded light at
 * d_L is drawn ramp(D / d_L): lit up to D, below 0.5 past 1.5 D, 0 from
 * 3 D on (binary: blocked past D) - by design. With the default clamp
 * (the bounds' diagonal) a closed object's grown light region stays
 * within 1.433 D of every point of the bounds, so none of its lights is
 * drawn shadowed unoccluded: for boxes of every shape (flat, thin, a cube),
 * the farthest corner pair is within that, and the ramp there >= 0.5. */
static void test_lights_beyond_clamp(void)
{
    const float D = 2.0f;
    CHECK(vdsh_shadow_compare(D, D, VDSH_COMPARE_SMOOTH) == 1.0f &&
              vdsh_shadow_compare(D, 1.5f * D * 1.001f, VDSH_COMPARE_SMOOTH) < 0.5f &&
              vdsh_shadow_compare(D, 3.0f * D, VDSH_COMPARE_SMOOTH) == 0.0f &&
              vdsh_shadow_compare(D, D * 1.001f, VDSH_COMPARE_BINARY) == 0.0f,
          "a light past the clamp: smooth at D, 1.5 D, 3 D and binary past D");
    uint64_t s = 5;
    double worst = 0.0;
    for (int trial = 0; trial < 500; trial++) {
        float lo[3], hi[3], glo[3], ghi[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = (float)(10.0 * test_rand(&s) - 5.0);
            double e = trial == 0 ? 1.0 : test_rand(&s); /* trial 0: a cube */
            if (trial % 5 == 1 && a == 1)
                e = 0.0; /* flat */
            hi[a] = lo[a] + (float)(e * (trial % 7 == 2 && a == 0 ? 100.0 : 3.0));
        }
        CHECK(vdsh_light_region(lo, hi, never_free, NULL, glo, ghi, NULL) == 1,
              "trial %d: no free space: the grown region", trial);
        double diag = 0.0;
        for (int a = 0; a < 3; a++)
            diag += ((double)hi[a] - lo[a]) * ((double)hi[a] - lo[a]);
        diag = sqrt(diag);
        double far = 0.0; /* the farthest pair: a corner of each box */
        for (int c = 0; c < 8; c++)
            for (int g = 0; g < 8; g++) {
                double d2 = 0.0;
                for (int a = 0; a < 3; a++) {
                    double x = c >> a & 1 ? hi[a] : lo[a], y = g >> a & 1 ? ghi[a] : glo[a];
                    d2 += (x - y) * (x - y);
                }
                far = fmax(far, sqrt(d2));
            }
        worst = fmax(worst, far / diag);
        CHECK(far <= 1.434 * diag &&
                  vdsh_shadow_compare((float)diag, (float)far, VDSH_COMPARE_SMOOTH) >= 0.5f,
              "trial %d: a light of the grown region %g from the bounds, %g x the clamp", trial,
              far, far / diag);
    }
    CHECK(worst > 1.43, "the cube reaches the bound: %g", worst);
}

/* A scene whose box holds a fraction *ctx of free space: the points
 * with x below lo + fraction * (hi - lo) of the unit box are free. */
static int free_below(const void *ctx, const float p[3])
{
    return p[0] < *(const float *)ctx;
}

/* The light region's rule (formats/vdsh_light.h) is continuous: as the
 * free space in the bounds grows from none to all, the growth never
 * jumps (a step of 1 of 1024 free moves the region by at most the
 * quarter diagonal / 192), it is the full quarter diagonal up to 64 of
 * 1024 free, and the bounds exactly from 256 free: the region of every
 * interior measured (>= 48% free). */
static void test_light_region_continuous(void)
{
    const float lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    const double diag = sqrt(3.0), step = VDSH_REGION_GROW * diag / 192.0;
    double prev = (double)VDSH_REGION_GROW * diag;
    int bounds = 0, full = 0;
    for (int i = 0; i <= 100; i++) {
        float f = (float)i / 100.0f, glo[3], ghi[3];
        uint32_t probes = 0, n = 0;
        const int grown = vdsh_light_region(lo, hi, free_below, &f, glo, ghi, &probes);
        for (uint32_t k = 0; k < probes; k++) {
            float p[3];
            vdsh_light_candidate(lo, hi, VDSH_REGION_SEED, k, p);
            n += free_below(&f, p);
        }
        const double g = -(double)glo[0];
        CHECK(fabs(g - vdsh_light_growth(n) * diag) < 1e-6 &&
                  fabs((double)ghi[0] - 1.0 - g) < 1e-6 && grown == (g > 0.0),
              "%.2f free (%u): the region grown by %g, the rule's %g", f, n, g,
              vdsh_light_growth(n) * diag);
        CHECK(g <= prev + 1e-9, "%.2f free: the growth %g rose from %g", f, g, prev);
        CHECK(n <= 64 || n >= VDSH_REGION_ROOM || probes == VDSH_REGION_PROBES,
              "%.2f free: the rule stopped early at %u free", f, n);
        bounds += !grown && n >= VDSH_REGION_ROOM && probes < VDSH_REGION_PROBES;
        full += n <= 64 && fabs(g - VDSH_REGION_GROW * diag) < 1e-6;
        prev = g;
    }
    CHECK(bounds > 60 && full >= 5, "%d fractions keep their bounds, %d fully grown", bounds, full);
    for (uint32_t n = 0; n < VDSH_REGION_PROBES; n++)
        CHECK(vdsh_light_growth(n) >= vdsh_light_growth(n + 1) &&
                  vdsh_light_growth(n) - vdsh_light_growth(n + 1) <= step / diag + 1e-12,
              "growth %u to %u free: %g to %g", n, n + 1, vdsh_light_growth(n),
              vdsh_light_growth(n + 1));
    CHECK(vdsh_light_growth(0) == VDSH_REGION_GROW &&
              vdsh_light_growth(VDSH_REGION_FULL) == VDSH_REGION_GROW &&
              vdsh_light_growth(VDSH_REGION_ROOM) == 0.0 &&
              vdsh_light_growth(VDSH_REGION_ROOM - 1) > 0.0,
          "the rule's ends");
}

/* vdsh_shadow.c's table of comparisons: names round-trip, each row
 * compares (a light just past the stored distance is blocked, one well
 * before it lit), unknown names are refused. */
static void test_compare_table(void)
{
    for (int i = 0; i < VDSH_COMPARE_COUNT; i++) {
        const char *name = vdsh_compare_name((uint32_t)i);
        CHECK(strcmp(name, "?") != 0 && vdsh_compare_by_name(name) == (vdsh_compare)i,
              "comparison %d (%s) found by its name", i, name);
        CHECK(vdsh_shadow_compare(1.0f, 4.0f, (uint32_t)i) == 0.0f &&
                  vdsh_shadow_compare(4.0f, 1.0f, (uint32_t)i) == 1.0f,
              "comparison %s: blocked and lit", name);
    }
    CHECK(vdsh_compare_by_name("bogus") == VDSH_COMPARE_COUNT, "no such comparison");
    CHECK(strcmp(vdsh_compare_name(VDSH_COMPARE_COUNT), "?") == 0, "no name past the table");
}

int main(void)
{
    test_shadow();
    test_compare_table();
    test_lights_beyond_clamp();
    test_light_region_continuous();
    test_interior();
    test_clamp_horizon();
    test_clamp_never_exceeds();
    test_project();
    test_orthonormal();
    test_design_values();
    test_recurrence();
    test_soa_and_prefix();
    return test_report("test_sh");
}
