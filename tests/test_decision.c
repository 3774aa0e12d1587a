/* The decision fit (decision.h) on a synthetic receiver: it lowers its
 * loss, classifies held-out lights better than its least-squares start,
 * gives the same bits on every call, and handles the degenerate cases;
 * and the calibration's quantile. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "decision.h"
#include "test_util.h"
#include "vdsh_sh.h"

enum { ORDER = 5, N = ORDER * ORDER, M = 256 };

/* The true distance: a slab of ceiling at 1 above the receiver for
 * directions within ~45 degrees of +z, open (10) elsewhere. */
static float truth(const float d[3])
{
    return d[2] > 0.7f ? 1.0f : 10.0f;
}

/* m pairs: directions on the upper hemisphere, light distances uniform
 * in ln between 0.3 and 30, labels from the truth; Y at stride M. */
static void pairs(uint64_t *s, uint32_t m, float *Y, float *logd, uint8_t *lab)
{
    float x[M], y[M], z[M];
    for (uint32_t i = 0; i < m; i++) {
        float d[3];
        do
            test_rand_dir(s, d);
        while (d[2] <= 0.0f);
        x[i] = d[0], y[i] = d[1], z[i] = d[2];
        float dl = 0.3f * expf((float)test_rand(s) * logf(100.0f));
        logd[i] = logf(dl);
        lab[i] = truth(d) < dl;
    }
    vdsh_sh_eval_soa(ORDER, m, x, y, z, Y, M);
}

/* Weighted misclassification at margin 0 (lit pairs weight 8). */
static double errors(const float *c, uint32_t m, const float *Y, const float *logd,
                     const uint8_t *lab)
{
    double e = 0.0;
    for (uint32_t i = 0; i < m; i++) {
        double s = 0.0;
        for (int j = 0; j < N; j++)
            s += c[j] * Y[(size_t)j * M + i];
        int shadow = s < logd[i];
        e += shadow != lab[i] ? (lab[i] ? 1.0 : 8.0) : 0.0;
    }
    return e;
}

static void test_fit_beats_start(void)
{
    uint64_t s = 12345;
    static float Y[N * M], Yh[N * M];
    float logd[M], logdh[M];
    uint8_t lab[M], labh[M];
    pairs(&s, M, Y, logd, lab);
    pairs(&s, M, Yh, logdh, labh);
    /* The start: the constant fit of the mean ln distance, as a smooth
     * least-squares fit would give far from the slab's edge. */
    float c[N] = {0}, start[N];
    c[0] = (logf(1.0f) * 0.29f + logf(10.0f) * 0.71f) / 0.28209479f;
    memcpy(start, c, sizeof c);
    vb_decision_params p;
    vb_decision_defaults(&p);
    double *scratch = malloc(vb_decision_scratch_doubles(ORDER) * sizeof *scratch);
    int steps = vb_decision_fit(ORDER, M, Y, M, logd, lab, &p, c, scratch);
    CHECK(steps >= 1, "took %d Newton steps", steps);
    double e0 = errors(start, M, Yh, logdh, labh), e1 = errors(c, M, Yh, logdh, labh);
    CHECK(e1 < 0.6 * e0, "held-out weighted errors %g, the start's %g", e1, e0);
    for (int j = 0; j < N; j++)
        CHECK(isfinite(c[j]), "coefficient %d finite", j);

    /* The same bits on a second call. */
    float again[N];
    memcpy(again, start, sizeof again);
    vb_decision_fit(ORDER, M, Y, M, logd, lab, &p, again, scratch);
    CHECK(memcmp(again, c, sizeof c) == 0, "a second fit gives the same bits");

    /* No pairs: the start stays. */
    memcpy(again, start, sizeof again);
    CHECK(vb_decision_fit(ORDER, 0, Y, M, logd, lab, &p, again, scratch) == 0, "no pairs");
    CHECK(memcmp(again, start, sizeof start) == 0, "no pairs: the start kept");

    /* Every pair lit: the fit stays finite, near the start (the ridge and
     * the saturating loss), and no lit pair ends shadowed. */
    uint8_t lit[M] = {0};
    memcpy(again, start, sizeof again);
    vb_decision_fit(ORDER, M, Y, M, logd, lit, &p, again, scratch);
    double e = errors(again, M, Y, logd, lit);
    for (int j = 0; j < N; j++)
        CHECK(isfinite(again[j]) && fabsf(again[j]) < 100.0f, "all lit: coefficient %d %g", j,
              again[j]);
    CHECK(e <= errors(start, M, Y, logd, lit), "all lit: no more false shadows (%g)", e);
    free(scratch);
}

static void test_offset(void)
{
    float m[1000];
    for (int i = 0; i < 1000; i++)
        m[i] = (float)((i * 7919) % 1000) / 100.0f; /* 0 .. 9.99, shuffled */
    /* 1% of 1000 below -offset: the 10th smallest, 0.10 */
    CHECK(fabsf(vb_decision_offset(m, 1000, 0.01) + 0.10f) < 1e-6f, "offset %g",
          vb_decision_offset(m, 1000, 0.01));
    CHECK(vb_decision_offset(m, 0, 0.01) == 0.0f, "no margins: 0");
}

/* The fit's result depends on the pairs only: the same bits with the
 * basis's rows further apart (the bake pads them), and with pair counts
 * that leave partial blocks of 32, 8 and 4 (the vector loops' tails). */
static void test_stride_and_tails(void)
{
    enum { S = M + 20 };
    uint64_t s = 777;
    static float Y[N * M], Ys[N * S];
    float logd[M];
    uint8_t lab[M];
    pairs(&s, M, Y, logd, lab);
    vb_decision_params p;
    vb_decision_defaults(&p);
    double *scratch = malloc(vb_decision_scratch_doubles(ORDER) * sizeof *scratch);
    const uint32_t counts[] = {M, 250, 37, 19};
    for (int order = 1; order <= ORDER; order++)
        for (size_t k = 0; k < sizeof counts / sizeof *counts; k++) {
            uint32_t m = counts[k];
            for (int j = 0; j < N; j++) /* NaN past m: never read */
                for (uint32_t i = 0; i < S; i++)
                    Ys[j * S + i] = i < m ? Y[j * M + i] : NAN;
            float a[N] = {0}, b[N] = {0};
            a[0] = b[0] = 1.5f / 0.28209479f;
            int sa = vb_decision_fit(order, m, Y, M, logd, lab, &p, a, scratch);
            int sb = vb_decision_fit(order, m, Ys, S, logd, lab, &p, b, scratch);
            CHECK(sa == sb && memcmp(a, b, sizeof a) == 0,
                  "order %d, %u pairs: stride %d and %d differ", order, m, M, S);
            for (int j = 0; j < order * order; j++)
                CHECK(isfinite(b[j]), "order %d, %u pairs: coefficient %d finite", order, m, j);
        }
    free(scratch);
}

/* decision.h's L(c), in double, from its definition. */
static double loss(const vb_decision_params *p, int order, const float *c, const float *c0,
                   uint32_t m, const float *Y, const float *logd, const uint8_t *lab)
{
    const int n = order * order;
    double sum = 0.0, a = 0.0;
    for (uint32_t i = 0; i < m; i++) {
        double t = -logd[i];
        for (int j = 0; j < n; j++)
            t += (double)c[j] * Y[(size_t)j * M + i];
        double z = (lab[i] ? 1.0 : -1.0) * t / p->tau, w = lab[i] ? 1.0 : p->lit_weight;
        sum += w * (z > 0.0 ? z + log1p(exp(-z)) : log1p(exp(z)));
        a += w;
    }
    double r = 0.0;
    for (int j = 0; j < n; j++) {
        int l = 0;
        while ((l + 1) * (l + 1) <= j)
            l++;
        double ll = (double)l * (l + 1), d = (double)c[j] - c0[j];
        r += ((double)p->ridge * ll * ll + p->ridge0) * d * d;
    }
    return sum / a + r;
}

/* The default's few Newton steps (each with a fresh Hessian) get the loss
 * most of the way to the minimum: on the slab receiver, at every order,
 * within 0.5% of the whole decrease that 64 steps find (two
 * steps leave 0.7-0.9%), and each step more
 * never raises it. */
static void test_converges(void)
{
    uint64_t s = 4242;
    static float Y[N * M];
    float logd[M];
    uint8_t lab[M];
    pairs(&s, M, Y, logd, lab);
    vb_decision_params p;
    vb_decision_defaults(&p);
    double *scratch = malloc(vb_decision_scratch_doubles(ORDER) * sizeof *scratch);
    for (int order = 2; order <= ORDER; order++) {
        float start[N] = {0};
        start[0] = 1.5f / 0.28209479f;
        double f0 = loss(&p, order, start, start, M, Y, logd, lab), prev = f0, fdef = 0.0;
        for (int steps = 1; steps <= 8; steps++) {
            vb_decision_params q = p;
            q.steps = steps;
            float c[N];
            memcpy(c, start, sizeof c);
            vb_decision_fit(order, M, Y, M, logd, lab, &q, c, scratch);
            double f = loss(&q, order, c, start, M, Y, logd, lab);
            CHECK(f <= prev * (1.0 + 1e-6), "order %d: %d steps' loss %g above %d steps' %g", order,
                  steps, f, steps - 1, prev);
            prev = f;
            if (steps == p.steps)
                fdef = f;
        }
        vb_decision_params q = p;
        q.steps = 64;
        float c[N];
        memcpy(c, start, sizeof c);
        vb_decision_fit(order, M, Y, M, logd, lab, &q, c, scratch);
        double fmin = loss(&q, order, c, start, M, Y, logd, lab);
        CHECK(fdef - fmin <= 0.005 * (f0 - fmin),
              "order %d: %d steps leave %g of the decrease %g (start %g)", order, p.steps,
              fdef - fmin, f0 - fmin, f0);
        fprintf(stderr, "order %d: start %g, %d steps %g, 64 steps %g\n", order, f0, p.steps, fdef,
                fmin);
    }
    free(scratch);
}

/* vb_decision_score: the loss without the ridge at the coefficients with
 * one offset b added to every margin (through c0), b the minimum (the loss
 * no lower at b +- 0.05), and the score at most the loss at b = 0. And
 * the fit with one fresh Hessian (the adaptive order's refit): each step
 * more never raises the loss, and it ends below the start. */
static void test_score_and_kept_hessian(void)
{
    uint64_t s = 99;
    static float Y[N * M];
    float logd[M];
    uint8_t lab[M];
    pairs(&s, M, Y, logd, lab);
    vb_decision_params p, flat;
    vb_decision_defaults(&p);
    flat = p;
    flat.ridge = flat.ridge0 = 0.0f;
    double *scratch = malloc(vb_decision_scratch_doubles(ORDER) * sizeof *scratch);
    for (int order = 1; order <= ORDER; order++) {
        float c[N] = {0}, at[N];
        c[0] = 1.5f / 0.28209479f;
        for (int j = 1; j < order * order; j++)
            c[j] = 0.3f * (float)((j * 37) % 11 - 5) / (float)(j + 1);
        float b = 0.0f;
        float sc = vb_decision_score(order, M, Y, M, logd, lab, &p, c, &b, scratch);
        memcpy(at, c, sizeof at);
        double f0 = loss(&flat, order, at, c, M, Y, logd, lab);
        at[0] = c[0] + b / 0.28209479f;
        double fb = loss(&flat, order, at, c, M, Y, logd, lab);
        CHECK(fabs(sc - fb) <= 1e-4 * fb, "order %d: score %g, the loss at its offset %g", order,
              (double)sc, fb);
        CHECK(sc <= f0 * (1.0 + 1e-6), "order %d: score %g above the loss at 0, %g", order,
              (double)sc, f0);
        for (int side = -1; side <= 1; side += 2) {
            at[0] = c[0] + (b + 0.05f * side) / 0.28209479f;
            double f = loss(&flat, order, at, c, M, Y, logd, lab);
            CHECK(f >= fb * (1.0 - 1e-5), "order %d: offset %g +- 0.05 lowers the loss %g to %g",
                  order, (double)b, fb, f);
        }
        vb_decision_params q = p;
        q.hessians = 1;
        double prev = loss(&q, order, c, c, M, Y, logd, lab), start = prev;
        for (int steps = 1; steps <= 4; steps++) {
            q.steps = steps;
            memcpy(at, c, sizeof at);
            vb_decision_fit(order, M, Y, M, logd, lab, &q, at, scratch);
            double f = loss(&q, order, at, c, M, Y, logd, lab);
            CHECK(f <= prev * (1.0 + 1e-6), "order %d, one Hessian: %d steps' loss %g above %g",
                  order, steps, f, prev);
            prev = f;
        }
        CHECK(prev < start, "order %d, one Hessian: loss %g not below the start's %g", order, prev,
              start);
    }
    free(scratch);
}

int main(void)
{
    test_fit_beats_start();
    test_stride_and_tails();
    test_converges();
    test_offset();
    test_score_and_kept_hessian();
    if (test_failures)
        fprintf(stderr, "%d checks failed\n", test_failures);
    return test_failures != 0;
}
