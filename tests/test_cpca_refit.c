/*
 * test_cpca_refit.c - the cpca encoder's quantisation-aware refit (issue
 * 29, docs/ACCURACY.md "Quantisation-aware refit of the model") on a real
 * baked stream.
 *
 *   test_cpca_refit IN.vdsh [POOL.f32]
 *
 * IN: a whole file with a fixed-order f32 stream of order 12 (scale 1);
 * POOL.f32 (optional): a light pool (tests/light_pool_tool's), fitted
 * with light mix 1 as the default does; without it the uniform metric.
 * Encodes --cpca 16,alloc:32 with no refit and with 1 and 2 rounds
 * (vdsh_cpca_study.h's vdsh_cpca_encode_refit) and checks: the refit
 * never raises the clusters' metric error it reports, and lowers it on
 * this stream; the no-refit encode's error is where every refit starts;
 * the format is unchanged (the same clusters per row, vectors, widths,
 * record words); each stream's records decode (vdsh_stream_decode) to
 * the RMS error the encoder reports; vdsh_cpca_encode is the default
 * refit's stream byte for byte, and the same twice.
 * Exit 0 when every check passes, 1 otherwise, 2 for bad usage.
 */
#include "cpca_tool.h"
#include "vdsh.h"
#include "vdsh_cpca_study.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures, checks;
#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        checks++;                                                                                  \
        if (!(cond)) {                                                                             \
            failures++;                                                                            \
            printf("FAIL: ");                                                                      \
            printf(__VA_ARGS__);                                                                   \
            printf("\n");                                                                          \
        }                                                                                          \
    } while (0)

/* RMS over rows of |decoded - src|, decoded by the reader's rule. */
static double decoded_rms(const vdsh_cpca_fit *fit, const float *src, uint32_t rows, uint32_t order)
{
    const uint32_t n = order * order;
    const vdsh_stream s = {.order = order,
                           .encoding = VDSH_ENCODING_CPCA,
                           .scale = 1.0f,
                           .data = fit->records,
                           .cpca = fit->model};
    float dec[VDSH_MAX_COEFFS];
    double e2 = 0.0;
    for (uint32_t v = 0; v < rows; v++) {
        vdsh_stream_decode(&s, v, dec);
        for (uint32_t i = 0; i < n; i++) {
            double e = (double)dec[i] - src[(size_t)v * n + i];
            e2 += e * e;
        }
    }
    return sqrt(e2 / rows);
}

static size_t fit_size(const vdsh_cpca_fit *f, uint32_t rows, uint32_t order)
{
    return (size_t)vdsh_cpca_stream_model_bytes(&f->model, order) +
           (size_t)rows * 4 * f->model.record_words;
}

/* Whether a and b are the same stream: model and records, byte for byte. */
static int same_stream(const vdsh_cpca_fit *a, const vdsh_cpca_fit *b, uint32_t rows,
                       uint32_t order)
{
    const vdsh_cpca *x = &a->model, *y = &b->model;
    const uint32_t n = order * order, k = x->clusters, kb = x->basis;
    return x->clusters == y->clusters && x->basis == y->basis && x->bits == y->bits &&
           x->record_words == y->record_words && !memcmp(x->widths, y->widths, kb) &&
           !memcmp(x->scales, y->scales, sizeof(float) * k * kb) &&
           !memcmp(x->means, y->means, sizeof(uint16_t) * k * n) &&
           !memcmp(x->bases, y->bases, sizeof(uint16_t) * k * kb * n) &&
           !memcmp(a->records, b->records, sizeof(uint32_t) * rows * x->record_words);
}

int main(int argc, char **argv)
{
    if (argc != 2 && argc != 3) {
        fprintf(stderr, "usage: test_cpca_refit IN.vdsh [POOL.f32]\n");
        return 2;
    }
    const uint32_t order = 12;
    vdsh_error err;
    vdsh_file *f;
    if (vdsh_read(argv[1], &f, &err) != VDSH_OK) {
        fprintf(stderr, "test_cpca_refit: %s\n", err.msg);
        return 1;
    }
    const vdsh_stream *s = cpca_tool_stream(f, order);
    if (!s) {
        fprintf(stderr, "test_cpca_refit: %s: no f32 stream of order 12\n", argv[1]);
        vdsh_free(f);
        return 1;
    }
    const uint32_t rows = vdsh_file_stream_vertices(f);
    const float *src = (const float *)s->data;
    float *pool = NULL;
    size_t nl = 0;
    if (argc == 3) {
        FILE *pf = fopen(argv[2], "rb");
        pool = malloc(sizeof(float) * 3 * 65536);
        nl = pf && pool ? fread(pool, sizeof(float) * 3, 65536, pf) : 0;
        if (pf)
            fclose(pf);
        if (!nl) {
            fprintf(stderr, "test_cpca_refit: %s: no lights\n", argv[2]);
            free(pool);
            vdsh_free(f);
            return 1;
        }
    }
    vdsh_cpca_settings st = {.clusters = 16, .budget = 32};
    if (nl) {
        st.light_mix = 1.0f;
        st.light_count = (uint32_t)nl;
        st.lights = pool;
        st.positions = f->positions;
    }
    /* no refit, and the default's rounds (each round's own test, that it
     * lowers its clusters' error or is not kept, is inside the refit) */
    enum { R = 2 };
    static const uint32_t rounds[R] = {0, VDSH_CPCA_REFIT_ROUNDS};
    vdsh_cpca_fit fit[R];
    vdsh_cpca_refit_report rep[R];
    for (uint32_t r = 0; r < R; r++) {
        vdsh_result res = vdsh_cpca_encode_refit(src, f->normals, rows, order, &st, rounds[r],
                                                 &fit[r], &rep[r], &err);
        CHECK(res == VDSH_OK, "refit %u rounds: %s", r, res == VDSH_OK ? "" : err.msg);
        if (res != VDSH_OK) {
            printf("%d of %d checks failed\n", failures, checks);
            return 1;
        }
        const double d = decoded_rms(&fit[r], src, rows, order);
        printf("test_cpca_refit: %u rows, %u round%s: metric error %.6g -> %.6g (%u cluster "
               "rounds kept), coefficient RMS error %.6g, %zu bytes\n",
               rows, rounds[r], rounds[r] == 1 ? "" : "s", rep[r].metric_before,
               rep[r].metric_after, rep[r].kept, fit[r].rms_error, fit_size(&fit[r], rows, order));
        CHECK(d == fit[r].rms_error, "%u rounds: the records decode to RMS %.9g, reported %.9g",
              rounds[r], d, fit[r].rms_error);
        CHECK(rep[r].rounds == rounds[r], "%u rounds: report says %u", rounds[r], rep[r].rounds);
    }
    CHECK(rep[0].kept == 0 && rep[0].metric_before == 0.0 && rep[0].metric_after == 0.0,
          "no refit: nothing reported");
    for (uint32_t r = 1; r < R; r++) {
        CHECK(rep[r].metric_before > 0.0, "%u rounds: a metric error before", r);
        CHECK(rep[r].metric_after <= rep[r].metric_before,
              "%u rounds: the refit raised the metric error %.9g -> %.9g", r, rep[r].metric_before,
              rep[r].metric_after);
        CHECK(rep[r].metric_after < rep[r].metric_before && rep[r].kept > 0,
              "%u rounds: the refit did not lower the metric error on this stream", r);
        /* the format unchanged: clusters per row, vectors, widths, words */
        const vdsh_cpca *a = &fit[0].model, *b = &fit[r].model;
        int same = a->clusters == b->clusters && a->basis == b->basis && a->bits == b->bits &&
                   a->record_words == b->record_words && !memcmp(a->widths, b->widths, a->basis);
        for (uint32_t v = 0; same && v < rows; v++)
            same = (fit[0].records[(size_t)v * a->record_words] & 0xffu) ==
                   (fit[r].records[(size_t)v * b->record_words] & 0xffu);
        CHECK(same, "%u rounds: another model shape or cluster labels than no refit's", r);
        CHECK(fit_size(&fit[r], rows, order) == fit_size(&fit[0], rows, order),
              "%u rounds: %zu bytes, no refit %zu", r, fit_size(&fit[r], rows, order),
              fit_size(&fit[0], rows, order));
    }
    /* the encoder's own behaviour: its default rounds (the same bytes on
     * every run and CPU: bake_cpca, bake_same_bytes_any_cpu) */
    vdsh_cpca_fit d1;
    CHECK(vdsh_cpca_encode(src, f->normals, rows, order, &st, &d1, &err) == VDSH_OK,
          "vdsh_cpca_encode: %s", err.msg);
    CHECK(same_stream(&d1, &fit[1], rows, order) && !same_stream(&d1, &fit[0], rows, order),
          "vdsh_cpca_encode is not the stream of the default's %d refit rounds",
          VDSH_CPCA_REFIT_ROUNDS);
    vdsh_cpca_fit_free(&d1);
    for (uint32_t r = 0; r < R; r++)
        vdsh_cpca_fit_free(&fit[r]);
    free(pool);
    vdsh_free(f);
    printf("%d of %d checks failed\n", failures, checks);
    return failures ? 1 : 0;
}
