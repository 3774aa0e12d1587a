/* The fit core: SH rotations, the hemisphere Gram matrix, and each
 * method's map on functions it must reproduce exactly. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fit.h"
#include "sampling.h"
#include "test_util.h"
#include "vdsh.h"
#include "vdsh_sh.h"
#include "vdsh_shadow.h"

/* A random rotation from a random unit quaternion. */
static void rand_rotation(uint64_t *s, double R[9])
{
    double q[4], len = 0;
    for (int i = 0; i < 4; i++)
        q[i] = 2 * test_rand(s) - 1, len += q[i] * q[i];
    len = sqrt(len);
    double w = q[0] / len, x = q[1] / len, y = q[2] / len, z = q[3] / len;
    double m[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                   2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                   2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
    memcpy(R, m, sizeof m);
}

static double recon(int order, const double *c, const float d[3])
{
    float y[25];
    vdsh_sh_eval(order, d, y);
    double s = 0;
    for (int i = 0; i < order * order; i++)
        s += c[i] * y[i];
    return s;
}

static void test_rotation(void)
{
    vb_fit f;
    vb_error err;
    CHECK(vb_fit_create(5, VB_FIT_IDENTITY, 0, &f, &err) == VB_OK, "fit");
    uint64_t s = 3;
    double worst = 0, orth = 0;
    for (int t = 0; t < 50; t++) {
        double R[9], S[625], c[25], cw[25] = {0};
        rand_rotation(&s, R);
        vb_sh_rotation(&f, R, S);
        for (int i = 0; i < 25; i++)
            c[i] = 2 * test_rand(&s) - 1;
        for (int i = 0; i < 25; i++)
            for (int j = 0; j < 25; j++)
                cw[i] += S[i * 25 + j] * c[j];
        for (int k = 0; k < 40; k++) {
            float w[3], l[3];
            test_rand_dir(&s, w);
            for (int i = 0; i < 3; i++) /* R^T w */
                l[i] = (float)(R[0 + i] * w[0] + R[3 + i] * w[1] + R[6 + i] * w[2]);
            worst = fmax(worst, fabs(recon(5, cw, w) - recon(5, c, l)));
        }
        for (int i = 0; i < 25; i++)
            for (int j = 0; j < 25; j++) {
                double d = 0;
                for (int k = 0; k < 25; k++)
                    d += S[k * 25 + i] * S[k * 25 + j];
                orth = fmax(orth, fabs(d - (i == j)));
            }
    }
    CHECK(worst < 1e-4, "rotated function differs by %g", worst);
    CHECK(orth < 1e-5, "rotation not orthogonal: %g", orth);
}

/* The factored fit (fit.h: S = Rz(alpha) X^T Rz(beta) X, the first half
 * shared between orders) equals S M S^T b with S the SH rotation of any
 * frame about the normal, here vb_frame's: M commutes with rotations
 * about the pole. Also on the poles, where the azimuth is free. */
static void test_factored_fit(void)
{
    vb_error err;
    uint64_t s = 42;
    double worst = 0;
    /* The paper's orders, and orders for long shadows (bands 5 and up in
     * double, with their own rotation samples). */
    static const int orders[] = {1, 2, 3, 4, 5, 7, 12, 16};
    vb_fit *f = malloc(sizeof *f), *top = malloc(sizeof *top);
    double *S = malloc(sizeof(double) * VB_FIT_MAX * VB_FIT_MAX);
    CHECK(f && top && S, "out of memory");
    for (vb_fit_base method = VB_FIT_MIRROR; f && top && S && method <= VB_FIT_LSQ; method++)
        for (size_t oi = 0; oi < sizeof orders / sizeof orders[0]; oi++) {
            int order = orders[oi], top_order = order <= 5 ? 5 : VDSH_MAX_ORDER;
            CHECK(vb_fit_create(order, method, vb_fit_lambda(1e-3f, order), f, &err) == VB_OK,
                  "fit %d: %s", order, err.msg);
            CHECK(vb_fit_create(top_order, method, 1e-3f, top, &err) == VB_OK, "fit");
            int n = order * order;
            for (int t = 0; t < (order <= 5 ? 20 : 4); t++) {
                float nrm[3];
                test_rand_dir(&s, nrm);
                if (t < 2) /* the poles */
                    nrm[0] = nrm[1] = 0.0f, nrm[2] = t ? -1.0f : 1.0f;
                double b[VB_FIT_MAX], u[VB_FIT_MAX], v[VB_FIT_MAX], w[VB_FIT_MAX];
                for (int i = 0; i < VB_FIT_MAX; i++)
                    b[i] = 2 * test_rand(&s) - 1;
                float t3[3], b3[3], c[VB_FIT_MAX], ct[VB_FIT_MAX];
                vb_frame(nrm, t3, b3);
                const double R[9] = {t3[0],  b3[0], nrm[0], t3[1], b3[1],
                                     nrm[1], t3[2], b3[2],  nrm[2]};
                vb_sh_rotation(f, R, S);
                for (int i = 0; i < n; i++) { /* v = S^T b */
                    v[i] = 0;
                    for (int j = 0; j < n; j++)
                        v[i] += S[j * n + i] * b[j];
                }
                for (int i = 0; i < n; i++) { /* w = M v */
                    w[i] = 0;
                    for (int j = 0; j < n; j++)
                        w[i] += f->M[i * n + j] * v[j];
                }
                vb_fit_apply(f, nrm, b, c);
                vb_fit_angles a;
                vb_fit_frame(top, nrm, &a); /* u from the top order's fit */
                vb_fit_unrotate(top, &a, b, u);
                vb_fit_finish(f, &a, u, ct);
                for (int i = 0; i < n; i++) {
                    double want = 0; /* S w */
                    for (int j = 0; j < n; j++)
                        want += S[i * n + j] * w[j];
                    worst = fmax(worst, fabs(c[i] - want) / (1 + fabs(want)));
                    CHECK(c[i] == ct[i], "order %d from the order %d rotation: %g vs %g", order,
                          top_order, ct[i], c[i]);
                }
            }
        }
    CHECK(worst < 1e-5, "factored fit differs from S M S^T b by %g", worst);
    free(f);
    free(top);
    free(S);
}

/* The rotation of bands 5 and up is a rotation: sum c_i Y_i(R^T d) equals
 * sum (S c)_i Y_i(d) at random directions, to float precision, at the
 * highest order. */
static void test_high_rotation(void)
{
    vb_error err;
    uint64_t s = 7;
    vb_fit *f = malloc(sizeof *f);
    double *S = malloc(sizeof(double) * VB_FIT_MAX * VB_FIT_MAX);
    CHECK(f && S && vb_fit_create(VDSH_MAX_ORDER, VB_FIT_IDENTITY, 0, f, &err) == VB_OK, "fit");
    if (!f || !S) {
        free(f);
        free(S);
        return;
    }
    int n = VDSH_MAX_ORDER * VDSH_MAX_ORDER;
    double worst = 0;
    for (int t = 0; t < 5; t++) {
        float a[3], b3[3], c3[3];
        test_rand_dir(&s, a);
        vb_frame(a, b3, c3);
        const double R[9] = {b3[0], c3[0], a[0], b3[1], c3[1], a[1], b3[2], c3[2], a[2]};
        vb_sh_rotation(f, R, S);
        double c[VB_FIT_MAX], sc[VB_FIT_MAX];
        for (int i = 0; i < n; i++)
            c[i] = 2 * test_rand(&s) - 1;
        for (int i = 0; i < n; i++) {
            sc[i] = 0;
            for (int j = 0; j < n; j++)
                sc[i] += S[i * n + j] * c[j];
        }
        for (int k = 0; k < 20; k++) {
            float d[3], rd[3], y[VB_FIT_MAX], yr[VB_FIT_MAX];
            test_rand_dir(&s, d);
            for (int r = 0; r < 3; r++) /* R^T d */
                rd[r] = (float)(R[r] * d[0] + R[3 + r] * d[1] + R[6 + r] * d[2]);
            vdsh_sh_eval(VDSH_MAX_ORDER, d, y);
            vdsh_sh_eval(VDSH_MAX_ORDER, rd, yr);
            double lhs = 0, rhs = 0, mag = 0;
            for (int i = 0; i < n; i++) {
                lhs += c[i] * yr[i];
                rhs += sc[i] * y[i];
                mag += fabs(c[i] * yr[i]);
            }
            worst = fmax(worst, fabs(lhs - rhs) / mag);
        }
    }
    CHECK(worst < 1e-5, "order %d rotation off by %g (relative)", VDSH_MAX_ORDER, worst);
    free(f);
    free(S);
}

/* Least squares over the hemisphere recovers any function of the basis
 * from its upper half. The hemisphere's Gram matrix is ill-conditioned
 * (condition 14, 250, 5900, 150000 at orders 2..5), so without
 * regularisation only orders 2-4 can be checked against float data; order
 * 5 gets a small lambda and a function of bands 0-1, which the penalty
 * (lambda (l(l+1))^2) barely touches. */
static void test_lsq_recovers(void)
{
    vb_error err;
    for (int order = 2; order <= 5; order++) {
        vb_fit f;
        float lambda = order == 5 ? 1e-4f : 0.0f;
        CHECK(vb_fit_create(order, VB_FIT_LSQ, lambda, &f, &err) == VB_OK, "lsq %d: %s", order,
              err.msg);
        int n = order * order;
        uint64_t s = 10 + order;
        double c[25] = {0};
        for (int i = 0; i < (order == 5 ? 4 : n); i++)
            c[i] = 2 * test_rand(&s) - 1;
        float nrm[3];
        test_rand_dir(&s, nrm);
        /* b = integral over the hemisphere around nrm of f Y: dense
         * quadrature (midpoint rule in cos theta and phi, 400 x 400). */
        double b[25] = {0};
        float t[3], bt[3];
        vb_frame(nrm, t, bt);
        const int NZ = 400, NP = 400;
        for (int a = 0; a < NZ; a++)
            for (int p = 0; p < NP; p++) {
                double z = (a + 0.5) / NZ, r = sqrt(1 - z * z), ph = 2 * M_PI * (p + 0.5) / NP;
                double lx = r * cos(ph), ly = r * sin(ph);
                float d[3];
                for (int k = 0; k < 3; k++)
                    d[k] = (float)(lx * t[k] + ly * bt[k] + z * nrm[k]);
                float y[25];
                vdsh_sh_eval(order, d, y);
                double fv = recon(order, c, d), w = 2 * M_PI / ((double)NZ * NP);
                for (int i = 0; i < n; i++)
                    b[i] += w * fv * y[i];
            }
        float out[25];
        vb_fit_apply(&f, nrm, b, out);
        /* Compare where the fit looked: the upper hemisphere. */
        double worst = 0, cd[25];
        for (int i = 0; i < n; i++)
            cd[i] = out[i];
        uint64_t s2 = 99;
        for (int k = 0; k < 500; k++) {
            float d[3];
            test_rand_dir(&s2, d);
            float up = d[0] * nrm[0] + d[1] * nrm[1] + d[2] * nrm[2];
            if (up < 0)
                for (int i = 0; i < 3; i++)
                    d[i] -= 2 * up * nrm[i];
            worst = fmax(worst, fabs(recon(order, cd, d) - recon(order, c, d)));
        }
        CHECK(worst < (order == 5 ? 5e-3 : 2e-3),
              "order %d: least squares reproduces the function on the hemisphere to %g", order,
              worst);
    }
}

static void test_mirror_and_paper(void)
{
    vb_error err;
    vb_fit f, p;
    CHECK(vb_fit_create(5, VB_FIT_MIRROR, 0, &f, &err) == VB_OK, "mirror");
    CHECK(vb_fit_create(5, VB_FIT_IDENTITY, 0, &p, &err) == VB_OK, "paper");
    uint64_t s = 77;
    float nrm[3];
    test_rand_dir(&s, nrm);
    float t[3], bt[3];
    vb_frame(nrm, t, bt);
    /* f(w) = g(w.t, w.b, |w.n|): symmetric. */
    double b[25] = {0};
    const int NZ = 300, NP = 300;
    for (int a = 0; a < NZ; a++)
        for (int q = 0; q < NP; q++) {
            double z = (a + 0.5) / NZ, r = sqrt(1 - z * z), ph = 2 * M_PI * (q + 0.5) / NP;
            double lx = r * cos(ph), ly = r * sin(ph);
            float d[3];
            for (int k = 0; k < 3; k++)
                d[k] = (float)(lx * t[k] + ly * bt[k] + z * nrm[k]);
            float y[25];
            vdsh_sh_eval(5, d, y);
            double fv = 1.0 + 0.5 * lx * ly + 0.3 * z * z + 0.2 * lx,
                   w = 2 * M_PI / ((double)NZ * NP);
            for (int i = 0; i < 25; i++)
                b[i] += w * fv * y[i];
        }
    float c[25], cp[25];
    vb_fit_apply(&f, nrm, b, c);
    vb_fit_apply(&p, nrm, b, cp);
    double worst = 0;
    uint64_t s2 = 5;
    for (int k = 0; k < 300; k++) {
        float d[3];
        test_rand_dir(&s2, d);
        double lx = d[0] * t[0] + d[1] * t[1] + d[2] * t[2];
        double ly = d[0] * bt[0] + d[1] * bt[1] + d[2] * bt[2];
        double lz = d[0] * nrm[0] + d[1] * nrm[1] + d[2] * nrm[2];
        double want = 1.0 + 0.5 * lx * ly + 0.3 * lz * lz + 0.2 * lx;
        worst = fmax(worst, fabs(vdsh_sh_reconstruct(5, c, d) - want));
    }
    CHECK(worst < 1e-3, "mirror reproduces a symmetric function to %g", worst);
    for (int i = 0; i < 25; i++)
        CHECK(cp[i] == (float)b[i], "paper changes the projection");
    float zero[3] = {0, 0, 0};
    vb_fit_apply(&f, zero, b, c);
    for (int i = 0; i < 25; i++)
        CHECK(c[i] == (float)b[i], "no normal: the projection as it is");
}

/* A window scales each band of the final coefficients, whatever the
 * method, and is 1 for band 0. */
static void test_window(void)
{
    vb_error err;
    uint64_t s = 123;
    double b[25];
    for (int i = 0; i < 25; i++)
        b[i] = 2 * test_rand(&s) - 1;
    float nrm[3];
    test_rand_dir(&s, nrm);
    for (vb_fit_base method = VB_FIT_IDENTITY; method <= VB_FIT_LSQ; method++)
        for (uint32_t win = VDSH_WINDOW_HANN; win <= VDSH_WINDOW_LANCZOS; win++) {
            vb_fit plain, windowed;
            CHECK(vb_fit_create(5, method, 1e-3f, &plain, &err) == VB_OK, "fit");
            CHECK(vb_fit_create(5, method, 1e-3f, &windowed, &err) == VB_OK, "fit");
            vb_fit_window(&windowed, win);
            float a[25], c[25];
            vb_fit_apply(&plain, nrm, b, a);
            vb_fit_apply(&windowed, nrm, b, c);
            for (int i = 0; i < 25; i++) {
                int l = i < 1 ? 0 : i < 4 ? 1 : i < 9 ? 2 : i < 16 ? 3 : 4;
                double w = vb_window_weight(win, l, 5);
                CHECK(fabs(c[i] - w * a[i]) < 1e-5 * (1 + fabs(a[i])),
                      "method %u window %u coefficient %d: %g vs %g x %g", method, win, i, c[i], w,
                      a[i]);
            }
        }
    CHECK(vb_window_weight(VDSH_WINDOW_HANN, 0, 3) == 1 &&
              vb_window_weight(VDSH_WINDOW_LANCZOS, 0, 3) == 1,
          "band 0 untouched");
    CHECK(fabs(vb_window_weight(VDSH_WINDOW_HANN, 2, 4) - 0.5) < 1e-12, "Hann at half width");
}

static void test_errors(void)
{
    vb_fit f;
    vb_error err;
    CHECK(vb_fit_create(VDSH_MAX_ORDER + 1, VB_FIT_LSQ, 0, &f, &err) == VB_ERR_ARGUMENT,
          "order 17");
    CHECK(vb_fit_create(3, VB_FIT_LSQ, -1, &f, &err) == VB_ERR_ARGUMENT, "lambda < 0");
    CHECK(vb_fit_create(3, (vb_fit_base)99, 0, &f, &err) == VB_ERR_ARGUMENT, "unknown base fit");
}

/* method.h's table: one row per known method, found by value and by name,
 * each refused quantity explained, its parameters consistent. */
static void test_method_table(void)
{
    CHECK(vb_method_name((vb_method)0) == vdsh_method_name(VDSH_METHOD_DECISION),
          "zero is the default method, decision");
    int rows = 0;
    for (uint32_t v = 0; v < 64; v++) {
        const char *name = vdsh_method_name(v);
        const vb_method_info *row = vb_method_stored(v);
        CHECK((strcmp(name, "?") != 0) == (row != NULL), "stored method %u: named iff it has a row",
              v);
        if (!row)
            continue;
        rows++;
        CHECK(vb_method_get(row->method) == row, "method %s: its row by its id", name);
        CHECK(vb_method_by_name(name) == row, "method %s found by its name", name);
        CHECK(row->quantities != 0, "method %s stores some quantity", name);
        for (uint32_t q = VDSH_QUANTITY_DISTANCE; q <= VDSH_QUANTITY_LOG_DISTANCE; q += 2)
            CHECK((row->quantities & VB_QUANTITY_BIT(q)) || row->refused[q],
                  "method %s: refusing %s says why", name, vdsh_quantity_name(q));
        CHECK((row->param == VB_PARAM_LOG_OFFSET) == (row->default_log_offset != NULL),
              "method %s: a log offset has defaults", name);
        CHECK(!(row->param == VB_PARAM_LAMBDA) || row->regularised,
              "method %s: a recorded lambda is used", name);
        CHECK(!row->horizon || !row->hemisphere, "method %s: horizon means sphere sampling", name);
        vb_fit f;
        vb_error err;
        CHECK(vb_fit_create(3, row->fit, 1e-3f, &f, &err) == VB_OK && f.base == row->fit,
              "method %s: fit.c builds its row's map", name);
    }
    CHECK(rows == VB_METHOD_COUNT, "%d rows for %d methods", rows, VB_METHOD_COUNT);
    CHECK(vb_method_get(VB_METHOD_COUNT) == NULL, "no row past the table");
    CHECK(vb_method_by_name("bogus") == NULL, "no such method");
    CHECK(vb_quantity_stored(VB_QUANTITY_LOG) == VDSH_QUANTITY_LOG_DISTANCE &&
              vb_quantity_stored(VB_QUANTITY_DISTANCE) == VDSH_QUANTITY_DISTANCE,
          "quantities as stored");
}

int main(void)
{
    test_rotation();
    test_factored_fit();
    test_high_rotation();
    test_lsq_recovers();
    test_mirror_and_paper();
    test_window();
    test_errors();
    test_method_table();
    return test_report("test_fit");
}
