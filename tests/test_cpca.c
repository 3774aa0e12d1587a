/*
 * test_cpca.c - the cpca encoding (formats/VDSH.md "cpca streams", issue
 * 29): encoder, writer, reader and decoder.
 *
 * Usage: test_cpca [OUT_DIR]   (with OUT_DIR: also writes cpca.vdsh and
 *                               cpca.f32, its C decode, and the same of the
 *                               widths stream, cpca-widths.vdsh and
 *                               cpca-widths.f32, for the Python test)
 *
 *   round trip     a synthetic order-7 stream (clusters by normal, low rank
 *                  plus noise) encoded, written, read: the same model and
 *                  records, decode = mean + sum of weight x basis in f32 to
 *                  the bit, the error far below the spread and below one
 *                  global vector's; the encoder's rms_error is the decode's
 *   determinism    the same inputs give the same bytes
 *   reading rules  every cpca rule broken in a valid file (CRCs fixed)
 *                  is refused with VDSH_ERR_INVALID or _CHUNK naming it;
 *                  every truncation is refused; the writer refuses a model
 *                  without arrays
 *   curved cluster one cluster whose members face +x, -x and +z, one
 *                  basis vector: a spike under +z's horizon that only
 *                  the +x members vary by, and a weaker spike at +z that
 *                  all vary by. The fit must serve each member in its
 *                  own hemisphere: its error there, summed, below what
 *                  capturing the weaker spike leaves (the mean normal's
 *                  hemisphere, +z, would choose that one)
 *   line and blob  two clusters of one vector for a long line and a tight
 *                  blob near its end: k-means gives the blob the line's
 *                  end; the refinement (reassignment by reconstruction
 *                  error) must split them: error under 2% of the spread
 *                  (0.25% refined, 7.6% with k-means alone)
 *   auto           --cpca auto:BYTES (the round trip's data): within the
 *                  budget, model included; K one of 4, 8, 16 at 4 bits with
 *                  the largest B that fits; the same bytes twice; a budget
 *                  no K,B fits is refused with VDSH_ERR_ARGUMENT
 *   widths         the study's width per vector (vdsh_cpca_study.h): 4 bits
 *                  on each of the B vectors decode as vdsh_cpca_encode's
 *                  stream to the bit; a table allocated for that file's
 *                  bytes stays within them and its words, the same twice;
 *                  widths of 1 and a budget nothing fits are refused
 *   widths stream  a width per basis vector (bits 0 and the widths
 *                  table): mixed widths written and read back unchanged,
 *                  decoded to the bit, widths of 1 and 9, padding, W and a
 *                  field's -L - 1 refused
 *   alloc          --cpca K,alloc:BYTES: widths 2..8 within the budget,
 *                  the same bytes twice, read back, too small refused
 *   light metric   the light-density metric: mix 0, no pool or no light
 *                  above any horizon give the uniform metric's bytes, a
 *                  pool another fit (the same twice), bad mixes and pools
 *                  refused; parse's ,light:A
 *   settings       vdsh_cpca_parse accepts K,B,BITS, auto and auto:BYTES
 *                  and refuses the rest
 *   pool score     vdsh_cpca_pool_score (vdsh_cpca_study.h) of a
 *                  lossy fit: its pairs, differing decisions and squared
 *                  ln D error the same as summed here with libm's log;
 *                  the same twice; refused without a pool
 */
#include "vdsh.h"
#include "vdsh_cpca.h"
#include "vdsh_plural.h"
#include "vdsh_cpca_study.h"
#include "vdsh_sh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures, checks;
#define CHECK(c, ...)                                                                              \
    do {                                                                                           \
        checks++;                                                                                  \
        if (!(c)) {                                                                                \
            failures++;                                                                            \
            fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__);                                   \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fputc('\n', stderr);                                                                   \
        }                                                                                          \
    } while (0)

static uint64_t rng = 0x1234567887654321ull;
static double rnd(void) /* uniform [-1, 1) */
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * 0x1.0p-52 - 1.0;
}

/* Whether a and b are the same settings, field by field (the struct has
 * padding). */
static int same_settings(const vdsh_cpca_settings *a, const vdsh_cpca_settings *b)
{
    return a->clusters == b->clusters && a->basis == b->basis && a->bits == b->bits &&
           a->budget == b->budget && a->light_mix == b->light_mix &&
           a->light_count == b->light_count && a->lights == b->lights &&
           a->positions == b->positions && a->light_cache == b->light_cache &&
           a->margin == b->margin && a->starts == b->starts && a->bases_s8 == b->bases_s8 &&
           a->threads == b->threads && a->start == b->start;
}

static uint32_t rd32(const uint8_t *p)
{
    return p[0] | p[1] << 8 | p[2] << 16 | (uint32_t)p[3] << 24;
}
static void wr32(uint8_t *p, uint32_t v)
{
    for (int k = 0; k < 4; k++)
        p[k] = (uint8_t)(v >> (8 * k));
}

/* Every chunk CRC and the header CRC recomputed (after a change). */
static void fix_crcs(uint8_t *d, size_t size)
{
    size_t off = 32;
    while (off + 16 <= size) {
        uint64_t n = rd32(d + off + 8) | (uint64_t)rd32(d + off + 12) << 32;
        uint64_t padded = (n + 15) & ~15ull;
        if (off + 16 + padded > size)
            break;
        uint32_t crc = vdsh_crc32(0, d + off, 4);
        crc = vdsh_crc32(crc, d + off + 8, 8);
        wr32(d + off + 4, vdsh_crc32(crc, d + off + 16, (size_t)padded));
        off += 16 + (size_t)padded;
    }
    wr32(d + 28, vdsh_crc32(0, d, 28));
}

/* Offset of the COEF payload in d. */
static size_t coef_at(const uint8_t *d, size_t size)
{
    size_t off = 32;
    while (off + 16 <= size) {
        uint64_t n = rd32(d + off + 8) | (uint64_t)rd32(d + off + 12) << 32;
        if (memcmp(d + off, "COEF", 4) == 0)
            return off + 16;
        off += 16 + (size_t)((n + 15) & ~15ull);
    }
    return 0;
}

enum { ORDER = 7, NC = ORDER * ORDER, ROWS = 600, K = 3, B = 13, BITS = 4 };

static float src[ROWS * NC], normals[ROWS * 3], positions[ROWS * 3];

/* Four normal directions; per direction a mean and 5 directions of
 * variation (rank 5) plus 1% noise. */
static void make_data(void)
{
    static const float dirs[4][3] = {{0, 1, 0}, {0, -1, 0}, {1, 0, 0}, {0, 0, 1}};
    double mean[4][NC], var[4][5][NC];
    for (int g = 0; g < 4; g++)
        for (int i = 0; i < NC; i++) {
            mean[g][i] = 2.0 * rnd() / (1 + i);
            for (int r = 0; r < 5; r++)
                var[g][r][i] = rnd() / (1 + 0.2 * i);
        }
    for (int v = 0; v < ROWS; v++) {
        int g = v % 4;
        double a[5];
        for (int r = 0; r < 5; r++)
            a[r] = rnd() / (1 + r);
        for (int i = 0; i < NC; i++) {
            double x = mean[g][i] + 0.01 * rnd();
            for (int r = 0; r < 5; r++)
                x += a[r] * var[g][r][i];
            src[v * NC + i] = (float)x;
        }
        memcpy(normals + 3 * v, dirs[g], sizeof dirs[g]);
        positions[3 * v] = (float)v;
        positions[3 * v + 1] = positions[3 * v + 2] = 0.0f;
    }
}

/* Sum over rows of the squared error e (rows x nc) over each row's own
 * hemisphere (normal n), on a Fibonacci set of directions. */
enum { CURVED_ORDER = 8, CURVED_NC = 64, CURVED_ROWS = 300, FIB = 4000 };
static double own_hemisphere(const double *e, const float *n, int rows)
{
    double total = 0.0;
    for (int d = 0; d < FIB; d++) {
        double z = 1.0 - (2.0 * d + 1.0) / FIB, r = sqrt(1.0 - z * z), phi = 2.39996322972865 * d;
        float dir[3] = {(float)(r * cos(phi)), (float)(r * sin(phi)), (float)z}, y[CURVED_NC];
        vdsh_sh_eval(CURVED_ORDER, dir, y);
        for (int v = 0; v < rows; v++) {
            const float *nv = n + 3 * v;
            if (!(nv[0] * dir[0] + nv[1] * dir[1] + nv[2] * dir[2] > 0.0f))
                continue;
            double f = 0.0;
            for (int i = 0; i < CURVED_NC; i++)
                f += e[(size_t)v * CURVED_NC + i] * y[i];
            total += f * f * (4.0 * 3.14159265358979 / FIB);
        }
    }
    return total;
}

static void curved_cluster(void)
{
    static float c[CURVED_ROWS * CURVED_NC], nrm[CURVED_ROWS * 3];
    static double e[CURVED_ROWS * CURVED_NC], left[CURVED_ROWS * CURVED_NC];
    static const float faces[3][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 0, 1}};
    float d1[3] = {0.8944272f, 0.0f, -0.4472136f}, d2[3] = {0, 0, 1}, f1[CURVED_NC], f2[CURVED_NC];
    vdsh_sh_eval(CURVED_ORDER, d1, f1);
    vdsh_sh_eval(CURVED_ORDER, d2, f2);
    for (int v = 0; v < CURVED_ROWS; v++) {
        int g = v % 3;
        double a = g == 0 ? ((v / 3) % 2 ? 1.0 : -1.0) : 0.0, b = (v / 6) % 2 ? 0.4 : -0.4;
        for (int i = 0; i < CURVED_NC; i++) {
            c[v * CURVED_NC + i] = (float)(a * f1[i] + b * f2[i]);
            left[(size_t)v * CURVED_NC + i] = a * f1[i]; /* what capturing f2 leaves */
        }
        memcpy(nrm + 3 * v, faces[g], sizeof faces[g]);
    }
    vdsh_cpca_settings st = {.clusters = 1, .basis = 1, .bits = 8, .budget = 0};
    vdsh_cpca_fit fit;
    vdsh_error err = {{0}};
    CHECK(vdsh_cpca_encode(c, nrm, CURVED_ROWS, CURVED_ORDER, &st, &fit, &err) == VDSH_OK,
          "curved: %s", err.msg);
    vdsh_stream s = {.order = CURVED_ORDER,
                     .encoding = VDSH_ENCODING_CPCA,
                     .scale = 1.0f,
                     .data = fit.records,
                     .cpca = fit.model};
    for (uint32_t v = 0; v < CURVED_ROWS; v++) {
        float dec[VDSH_MAX_COEFFS];
        vdsh_stream_decode(&s, v, dec);
        for (int i = 0; i < CURVED_NC; i++)
            e[(size_t)v * CURVED_NC + i] = (double)dec[i] - c[v * CURVED_NC + i];
    }
    double got = own_hemisphere(e, nrm, CURVED_ROWS), alt = own_hemisphere(left, nrm, CURVED_ROWS);
    CHECK(got < 0.8 * alt,
          "curved: own-hemisphere error %g, not below capturing the weak "
          "spike's %g",
          got, alt);
    vdsh_cpca_fit_free(&fit);
}

/* A long line and a tight blob near one of its ends, every vertex facing
 * +z, two clusters of one basis vector each: k-means (by distance to the
 * centres) gives the blob the line's far end, whose cluster one vector
 * cannot serve; reassignment by reconstruction error (CPCA refinement)
 * gives each cluster one of them, reconstructed to the quantisation. */
enum { LINE_ORDER = 4, LINE_NC = 16, LINE_ROWS = 300 };
static void line_and_blob(void)
{
    static float c[LINE_ROWS * LINE_NC], nrm[LINE_ROWS * 3];
    float da[3] = {0.6f, 0.0f, 0.8f}, db[3] = {-0.6f, 0.0f, 0.8f}, fa[LINE_NC], fb[LINE_NC];
    vdsh_sh_eval(LINE_ORDER, da, fa);
    vdsh_sh_eval(LINE_ORDER, db, fb);
    double mean[LINE_NC] = {0}, spread = 0.0;
    for (int v = 0; v < LINE_ROWS; v++) {
        /* two thirds on the line t fa, t in [-10, 10]; a third on the
         * blob 12 fa + (3 + s) fb, s in [-1, 1] */
        double a, b;
        if (v % 3 < 2) {
            a = -10.0 + 20.0 * (v / 3 * 2 + v % 3) / (LINE_ROWS * 2 / 3 - 1);
            b = 0.0;
        } else {
            a = 12.0;
            b = 3.0 + rnd();
        }
        for (int i = 0; i < LINE_NC; i++) {
            c[v * LINE_NC + i] = (float)(a * fa[i] + b * fb[i]);
            mean[i] += c[v * LINE_NC + i] / (double)LINE_ROWS;
        }
        nrm[3 * v] = nrm[3 * v + 1] = 0.0f;
        nrm[3 * v + 2] = 1.0f;
    }
    for (int v = 0; v < LINE_ROWS; v++)
        for (int i = 0; i < LINE_NC; i++)
            spread += (c[v * LINE_NC + i] - mean[i]) * (c[v * LINE_NC + i] - mean[i]) / LINE_ROWS;
    spread = sqrt(spread);
    vdsh_cpca_settings st = {.clusters = 2, .basis = 1, .bits = 8, .budget = 0};
    vdsh_cpca_fit fit;
    vdsh_error err = {{0}};
    CHECK(vdsh_cpca_encode(c, nrm, LINE_ROWS, LINE_ORDER, &st, &fit, &err) == VDSH_OK,
          "line and blob: %s", err.msg);
    CHECK(fit.rms_error < 0.02 * spread,
          "line and blob: error %g, not below 2%% of the spread %g (clusters not refined)",
          fit.rms_error, spread);
    printf("format_cpca: line and blob: error %.4g, spread %.4g\n", fit.rms_error, spread);
    vdsh_cpca_fit_free(&fit);
}

/* A cpca stream of order ORDER (a distance fit) of these records and model. */
static vdsh_stream stream_of(const uint32_t *records, const vdsh_cpca *model)
{
    return (vdsh_stream){.order = ORDER,
                         .encoding = VDSH_ENCODING_CPCA,
                         .method = VDSH_METHOD_LSQ,
                         .quantity = VDSH_QUANTITY_DISTANCE,
                         .scale = 1.0f,
                         .data = records,
                         .cpca = *model};
}

/* For the Python reader's test: DIR/NAME.vdsh (the file's bytes) and
 * DIR/NAME.f32 (stream r's C decode, ROWS x NC floats). */
static void write_for_python(const char *dir, const char *name, const void *mem, size_t size,
                             const vdsh_stream *r)
{
    char p[4096];
    snprintf(p, sizeof p, "%s/%s.vdsh", dir, name);
    FILE *o = fopen(p, "wb");
    CHECK(o && fwrite(mem, 1, size, o) == size, "cannot write %s", p);
    if (o)
        fclose(o);
    snprintf(p, sizeof p, "%s/%s.f32", dir, name);
    o = fopen(p, "wb");
    for (uint32_t v = 0; o && v < ROWS; v++) {
        float c[VDSH_MAX_COEFFS];
        vdsh_stream_decode(r, v, c);
        CHECK(fwrite(c, 4, NC, o) == NC, "cannot write %s", p);
    }
    CHECK(o != NULL, "cannot write %s", p);
    if (o)
        fclose(o);
}

/* Whether two fits (of ROWS rows, order ORDER) are the same stream: the
 * same K, B, bits, bases and record words, and the same bytes, model
 * (widths table, scales, means, bases) and records. */
static int same_fit(const vdsh_cpca_fit *a, const vdsh_cpca_fit *b)
{
    const vdsh_cpca *x = &a->model, *y = &b->model;
    return x->clusters == y->clusters && x->basis == y->basis && x->bits == y->bits &&
           x->bases_s8 == y->bases_s8 && x->record_words == y->record_words &&
           !memcmp(a->storage_, b->storage_, (size_t)vdsh_cpca_stream_model_bytes(x, ORDER) - 16) &&
           !memcmp(a->records, b->records, (size_t)ROWS * 4 * x->record_words);
}

static double rms_vs(const vdsh_stream *s, const float *want)
{
    float c[VDSH_MAX_COEFFS];
    double e2 = 0.0;
    for (uint32_t v = 0; v < ROWS; v++) {
        vdsh_stream_decode(s, v, c);
        for (int i = 0; i < NC; i++)
            e2 += ((double)c[i] - want[v * NC + i]) * ((double)c[i] - want[v * NC + i]);
    }
    return sqrt(e2 / ROWS);
}

/* Bytes of a fit of `rows` rows, the model included. */
static uint64_t fit_bytes(const vdsh_cpca *m, uint32_t rows, uint32_t order)
{
    return (uint64_t)rows * 4 * vdsh_cpca_record_words(m->basis, m->bits) +
           vdsh_cpca_model_bytes(order, m->clusters, m->basis, m->bases_s8);
}

static void auto_settings(void)
{
    vdsh_error err = {{0}};
    static const uint32_t budgets[] = {12, 20, 32};
    for (size_t i = 0; i < sizeof budgets / sizeof *budgets; i++) {
        vdsh_cpca_settings st = {.clusters = 0, .basis = 0, .bits = 0, .budget = budgets[i]};
        vdsh_cpca_fit a, b;
        CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &st, &a, &err) == VDSH_OK, "auto:%u: %s",
              budgets[i], err.msg);
        CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &st, &b, &err) == VDSH_OK, "auto:%u: %s",
              budgets[i], err.msg);
        const vdsh_cpca *m = &a.model;
        uint64_t bytes = fit_bytes(m, ROWS, ORDER);
        CHECK(bytes <= (uint64_t)budgets[i] * ROWS, "auto:%u: %.2f bytes per vertex", budgets[i],
              (double)bytes / ROWS);
        CHECK((m->clusters == 4 || m->clusters == 8 || m->clusters == 16) && m->bits == 4,
              "auto:%u chose %u,%u,%u", budgets[i], m->clusters, m->basis, m->bits);
        vdsh_cpca more = *m;
        more.basis++;
        CHECK(m->basis == NC || fit_bytes(&more, ROWS, ORDER) > (uint64_t)budgets[i] * ROWS,
              "auto:%u: B %u not the largest that fits", budgets[i], m->basis);
        CHECK(same_fit(&a, &b), "auto:%u: other bytes the second time", budgets[i]);
        printf("auto:%u: %u,%u,%u, %.2f bytes per vertex, rms error %.4f\n", budgets[i],
               m->clusters, m->basis, m->bits, (double)bytes / ROWS, a.rms_error);
        vdsh_cpca_fit_free(&a);
        vdsh_cpca_fit_free(&b);
    }
    vdsh_cpca_settings tiny = {.clusters = 0, .basis = 0, .bits = 0, .budget = 1};
    vdsh_cpca_fit f;
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &tiny, &f, &err) == VDSH_ERR_ARGUMENT &&
              strstr(err.msg, "budget") && !f.storage_,
          "auto:1 not refused (%s)", err.msg);
}

/* Widths (vdsh_cpca_study.h, measurement only): the uniform table
 * reproduces vdsh_cpca_encode's decode to the bit; an allocated table
 * fits its budget and its words, and is no worse in the fit's own
 * measure than the uniform record of the same bytes. */
static void widths_study(void)
{
    vdsh_error err = {{0}};
    vdsh_cpca_settings st = {.clusters = K, .basis = B, .bits = BITS, .budget = 0};
    vdsh_cpca_fit fit;
    static float dec[ROWS * NC], dec2[ROWS * NC];
    vdsh_cpca_widths_fit wf, wf2;
    uint8_t uni[VDSH_MAX_COEFFS] = {0};
    for (int j = 0; j < B; j++)
        uni[j] = BITS;
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &st, &fit, &err) == VDSH_OK, "%s", err.msg);
    CHECK(vdsh_cpca_encode_widths(src, normals, ROWS, ORDER, &st, 2 * B, 0.0, uni, dec, &wf,
                                  &err) == VDSH_OK,
          "widths, uniform: %s", err.msg);
    vdsh_stream s = stream_of(fit.records, &fit.model);
    int same = wf.basis == B && wf.words == fit.model.record_words;
    for (uint32_t v = 0; v < ROWS; v++) {
        float c[VDSH_MAX_COEFFS];
        vdsh_stream_decode(&s, v, c);
        same &= memcmp(c, dec + (size_t)v * NC, sizeof(float) * NC) == 0;
    }
    CHECK(same, "uniform widths do not decode as vdsh_cpca_encode's stream");
    CHECK(fabs(wf.rms_error - fit.rms_error) <= 1e-12 * (1 + fit.rms_error), "rms %g against %g",
          wf.rms_error, fit.rms_error);
    /* allocated for the uniform file's bytes */
    double budget = (double)fit_bytes(&fit.model, ROWS, ORDER) / ROWS;
    CHECK(vdsh_cpca_encode_widths(src, normals, ROWS, ORDER, &st, 2 * B, budget, NULL, dec, &wf,
                                  &err) == VDSH_OK,
          "widths, budget: %s", err.msg);
    CHECK(vdsh_cpca_encode_widths(src, normals, ROWS, ORDER, &st, 2 * B, budget, NULL, dec2, &wf2,
                                  &err) == VDSH_OK &&
              memcmp(dec, dec2, sizeof dec) == 0 && memcmp(wf.widths, wf2.widths, B * 2) == 0,
          "widths: other results the second time");
    int range = wf.basis >= 1 && wf.widths[wf.basis - 1] >= 2;
    for (uint32_t j = 0; j < 2 * B; j++)
        range &= wf.widths[j] == 0 || (wf.widths[j] >= 2 && wf.widths[j] <= 8);
    CHECK(range, "widths out of range");
    CHECK(wf.bytes_per_vertex <= budget && wf.words == vdsh_cpca_widths_words(wf.widths, 2 * B),
          "widths: %.3f bytes per vertex over the budget %.3f, or %u words", wf.bytes_per_vertex,
          budget, wf.words);
    printf("widths: uniform %.3f B rms %.4f; allocated %.3f B, %u vectors, %u words, rms %.4f\n",
           budget, fit.rms_error, wf.bytes_per_vertex, wf.basis, wf.words, wf.rms_error);
    /* no field straddles a word: eight 7-bit fields and the index are 64
     * bits but three words (3 fields, then 4, then 1) */
    uint8_t w7[8] = {7, 7, 7, 7, 7, 7, 7, 7}, w8[4] = {8, 8, 8, 8};
    CHECK(vdsh_cpca_widths_words(w7, 8) == 3 && vdsh_cpca_widths_words(w7, 7) == 2 &&
              vdsh_cpca_widths_words(w8, 3) == 1 && vdsh_cpca_widths_words(w8, 4) == 2,
          "widths_words");
    uint8_t bad[2 * B] = {1};
    CHECK(vdsh_cpca_encode_widths(src, normals, ROWS, ORDER, &st, 2 * B, 0.0, bad, dec, &wf,
                                  &err) == VDSH_ERR_ARGUMENT,
          "a width of 1 not refused");
    CHECK(vdsh_cpca_encode_widths(src, normals, ROWS, ORDER, &st, 2 * B, 0.5, NULL, dec, &wf,
                                  &err) == VDSH_ERR_ARGUMENT,
          "a budget nothing fits not refused");
    vdsh_cpca_fit_free(&fit);
}

static vdsh_file file_of(vdsh_stream *s)
{
    vdsh_file f;
    memset(&f, 0, sizeof f);
    f.header.vertex_count = ROWS;
    f.header.rays = 64;
    f.header.max_distance = 10.0f;
    f.positions = positions;
    f.normals = normals;
    f.stream_count = 1;
    f.streams = s;
    return f;
}

/* Change the file image by `edit` (bytes from the COEF payload start), fix
 * the CRCs, and expect refusal with `want` in the message. */
static void expect_refused(const uint8_t *good, size_t size, size_t at, const void *bytes, size_t n,
                           const char *want)
{
    uint8_t *d = malloc(size);
    memcpy(d, good, size);
    memcpy(d + coef_at(d, size) + at, bytes, n);
    fix_crcs(d, size);
    vdsh_file *f = NULL;
    vdsh_error err = {{0}};
    vdsh_result r = vdsh_read_memory(d, size, "bad.vdsh", &f, &err);
    CHECK(r == VDSH_ERR_INVALID || r == VDSH_ERR_CHUNK, "%s: accepted (%d)", want, (int)r);
    CHECK(strstr(err.msg, want) != NULL, "message '%s' lacks '%s'", err.msg, want);
    vdsh_free(f);
    free(d);
}

/* A stream with a width per basis vector (bits 0, VDSH.md "cpca
 * streams"): the fit's levels repacked into mixed widths (clamped to each
 * width's levels) are written and read back unchanged, decode to the bit
 * as mean + sum of level x scale / L_j x basis in f32, and every widths
 * rule broken is refused. */
static void widths_stream(const vdsh_cpca_fit *fit, const char *out_dir)
{
    static const uint8_t wd[B] = {8, 7, 6, 5, 4, 4, 4, 3, 3, 3, 2, 2, 2};
    vdsh_cpca m = fit->model;
    m.bits = 0;
    m.widths = wd;
    m.record_words = vdsh_cpca_widths_words(wd, B);
    CHECK(m.record_words == 2, "widths words %u (8,7,6 in word 0, the rest in word 1)",
          m.record_words);
    static uint32_t rec[ROWS * 2];
    static int32_t lv[ROWS][B];
    memset(rec, 0, sizeof rec);
    vdsh_stream u = stream_of(fit->records, &fit->model);
    for (uint32_t v = 0; v < ROWS; v++) {
        int32_t q[VDSH_MAX_COEFFS];
        vdsh_cpca_weights(&u, v, q, NULL);
        rec[v * 2] = vdsh_cpca_cluster(&u, v);
        for (uint32_t j = 0; j < B; j++) {
            int L = vdsh_cpca_levels(wd[j]);
            lv[v][j] = q[j] > L ? L : q[j] < -L ? -L : q[j];
            uint32_t word, shift;
            vdsh_cpca_model_field(&m, j, &word, &shift);
            rec[v * 2 + word] |= ((uint32_t)lv[v][j] & ((1u << wd[j]) - 1u)) << shift;
        }
    }
    vdsh_stream s = stream_of(rec, &m);
    vdsh_file f = file_of(&s);
    void *mem = NULL;
    size_t size = 0;
    vdsh_error err = {{0}};
    CHECK(vdsh_write_memory(&f, &mem, &size, &err) == VDSH_OK, "widths: write: %s", err.msg);
    vdsh_file *back = NULL;
    CHECK(mem && vdsh_read_memory(mem, size, "widths", &back, &err) == VDSH_OK, "widths: read: %s",
          err.msg);
    if (back) {
        const vdsh_stream *r = &back->streams[0];
        CHECK(r->cpca.bits == 0 && r->cpca.widths && memcmp(r->cpca.widths, wd, B) == 0 &&
                  r->cpca.record_words == 2 && memcmp(r->data, rec, sizeof rec) == 0 &&
                  memcmp(r->cpca.scales, m.scales, 4 * K * B) == 0 &&
                  memcmp(r->cpca.bases, m.bases, 2 * K * B * NC) == 0,
              "widths: read back differs");
        vdsh_stream_size z = vdsh_stream_size_of(r, ROWS);
        CHECK(fabs(z.mean_bytes -
                   (8.0 + (double)(vdsh_cpca_model_bytes(ORDER, K, B, 0) + 16) / ROWS)) < 1e-9,
              "widths: mean bytes %g", z.mean_bytes);
        int exact = 1;
        for (uint32_t v = 0; v < ROWS; v += 5) {
            float c[VDSH_MAX_COEFFS];
            int32_t q[VDSH_MAX_COEFFS];
            vdsh_stream_decode(r, v, c);
            vdsh_cpca_weights(r, v, q, NULL);
            uint32_t cl = vdsh_cpca_cluster(r, v);
            for (int i = 0; i < NC; i++) {
                float a = vdsh_f32_from_f16(m.means[cl * NC + i]);
                for (int j = 0; j < B; j++) {
                    float wj =
                        (float)lv[v][j] * (m.scales[cl * B + j] / (float)vdsh_cpca_levels(wd[j]));
                    a = a + wj * vdsh_f32_from_f16(m.bases[(cl * B + j) * NC + i]);
                }
                exact &= memcmp(&a, &c[i], 4) == 0;
            }
            for (int j = 0; j < B; j++)
                exact &= q[j] == lv[v][j];
        }
        CHECK(exact, "widths: decode is not mean + sum of level x step_j x basis in f32");
        if (out_dir) /* for the Python reader's test */
            write_for_python(out_dir, "cpca-widths", mem, size, r);
    }
    vdsh_free(back);
    if (mem) { /* widths table at payload 64, scales from 80 */
        const uint8_t *g = mem;
        uint8_t b1 = 1, b9 = 9, b4[4];
        expect_refused(g, size, 64, &b1, 1, "width of vector 0 is 1");
        expect_refused(g, size, 64 + 12, &b9, 1, "width of vector 12 is 9");
        expect_refused(g, size, 64 + B, &b1, 1, "padding after the cpca widths");
        wr32(b4, 3);
        expect_refused(g, size, 60, b4, 4, "record_words 3, its widths need 2");
        size_t recs = 64 + 16 + 160 + 304 + 3824;
        /* vector 10 (2 bits) at word 1 bits 26..27: -2 is out of -1..1 */
        wr32(b4, (rd32(g + coef_at(g, size) + recs + 4) & ~(3u << 26)) | (2u << 26));
        expect_refused(g, size, recs + 4, b4, 4, "weight 10 is -2 (2 bits");
    }
    free(mem);
    /* the writer refuses bits 0 without a table */
    m.widths = NULL;
    s.cpca = m;
    f = file_of(&s);
    mem = NULL;
    CHECK(vdsh_write_memory(&f, &mem, &size, &err) != VDSH_OK && strstr(err.msg, "widths"),
          "widths: bits 0 without a table written (%s)", err.msg);
    free(mem);
}

/* --cpca K,alloc:BYTES: a stream with a width per vector within the
 * budget (model and widths table included), the same bytes twice, its
 * rms_error its decode's, written and read back; a budget the 1-vector
 * record cannot meet refused. */
static void alloc_settings(void)
{
    vdsh_error err = {{0}};
    vdsh_cpca_settings st;
    CHECK(vdsh_cpca_parse("3,alloc:16", &st, &err) == VDSH_OK && st.clusters == 3 &&
              st.budget == 16 && !st.bits && !st.basis,
          "parse 3,alloc:16: %s", err.msg);
    vdsh_cpca_fit a, b;
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &st, &a, &err) == VDSH_OK, "alloc: %s",
          err.msg);
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &st, &b, &err) == VDSH_OK, "alloc 2: %s",
          err.msg);
    const vdsh_cpca *m = &a.model;
    vdsh_stream s = stream_of(a.records, m);
    uint64_t bytes = (uint64_t)ROWS * 4 * m->record_words + vdsh_cpca_stream_model_bytes(m, ORDER);
    int ok = m->bits == 0 && m->widths && m->clusters == 3 && m->basis >= 1 &&
             m->record_words == vdsh_cpca_widths_words(m->widths, m->basis);
    for (uint32_t j = 0; ok && j < m->basis; j++)
        ok = m->widths[j] >= 2 && m->widths[j] <= 8;
    CHECK(ok, "alloc: model %u,%u,%u, W %u", m->clusters, m->basis, m->bits, m->record_words);
    CHECK(bytes <= 16u * ROWS, "alloc: %.2f bytes per vertex over 16", (double)bytes / ROWS);
    CHECK(same_fit(&a, &b), "alloc: other bytes the second time");
    CHECK(fabs(rms_vs(&s, src) - a.rms_error) <= 1e-9 * (1 + a.rms_error), "alloc: rms %g vs %g",
          a.rms_error, rms_vs(&s, src));
    vdsh_file f = file_of(&s);
    void *mem = NULL;
    size_t size = 0;
    vdsh_file *back = NULL;
    CHECK(vdsh_write_memory(&f, &mem, &size, &err) == VDSH_OK &&
              vdsh_read_memory(mem, size, "alloc", &back, &err) == VDSH_OK &&
              rms_vs(&back->streams[0], src) == rms_vs(&s, src),
          "alloc: write and read back: %s", err.msg);
    printf("alloc:16 at K 3: %u vectors, %u words, %.2f bytes per vertex, rms error %.4f\n",
           m->basis, m->record_words, (double)bytes / ROWS, a.rms_error);
    vdsh_free(back);
    free(mem);
    vdsh_cpca_fit_free(&a);
    vdsh_cpca_fit_free(&b);
    vdsh_cpca_settings tiny = {.clusters = 3, .basis = 0, .bits = 0, .budget = 1};
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &tiny, &a, &err) == VDSH_ERR_ARGUMENT &&
              strstr(err.msg, "budget") && !a.storage_,
          "alloc:1 not refused (%s)", err.msg);
    CHECK(vdsh_cpca_parse("3,alloc:0", &st, &err) == VDSH_ERR_ARGUMENT &&
              vdsh_cpca_parse("0,alloc:16", &st, &err) == VDSH_ERR_ARGUMENT &&
              vdsh_cpca_parse("3,alloc:", &st, &err) == VDSH_ERR_ARGUMENT &&
              vdsh_cpca_parse("3,alloc:16x", &st, &err) == VDSH_ERR_ARGUMENT,
          "bad alloc settings accepted");
}

/* --cpca K,alloc:BYTES,bases:8: the bases stored s8 (VDSH.md "cpca
 * streams"): parsed and written back as text, refused without
 * K,alloc:BYTES; the stream within the budget, its bytes freed spent on
 * more vectors or words than f16's at the same budget and a lower error
 * here; every non-zero vector reaching +-127; the same bytes twice and on
 * 1 and 3 threads; its rms_error its decode's; the header's bits word
 * with VDSH_CPCA_BASES_S8, written and read back to the same decode
 * (dir: the file and its C decode for the Python reader's test); a basis
 * value of -128 refused. */
static void s8_bases(const char *dir)
{
    vdsh_error err = {{0}};
    vdsh_cpca_settings st, f16, p;
    CHECK(vdsh_cpca_parse("3,alloc:16,bases:8", &st, &err) == VDSH_OK && st.bases_s8 &&
              st.clusters == 3 && st.budget == 16,
          "parse 3,alloc:16,bases:8: %s", err.msg);
    CHECK(vdsh_cpca_parse("3,alloc:16,bases:16", &f16, &err) == VDSH_OK && !f16.bases_s8,
          "parse 3,alloc:16,bases:16: %s", err.msg);
    CHECK(vdsh_cpca_parse("bases:8", &p, &err) == VDSH_OK && p.bases_s8 &&
              p.clusters == VDSH_CPCA_DEFAULT_CLUSTERS && p.margin == VDSH_CPCA_DEFAULT_MARGIN &&
              p.starts == VDSH_CPCA_DEFAULT_STARTS,
          "bases:8 alone: the default with s8 bases (%s)", err.msg);
    char text[192];
    vdsh_cpca_settings_text(&st, text, sizeof text);
    CHECK(strstr(text, ",bases:8") && vdsh_cpca_parse(text, &p, &err) == VDSH_OK &&
              same_settings(&p, &st),
          "3,alloc:16,bases:8's text %s", text);
    static const char *const refuse[] = {"8,52,4,bases:8", "auto,bases:8", "3,alloc:16,bases:4",
                                         "3,alloc:16,bases:8,bases:8", "3,alloc:16,bases:8.0"};
    for (size_t k = 0; k < sizeof refuse / sizeof *refuse; k++)
        CHECK(vdsh_cpca_parse(refuse[k], &p, &err) == VDSH_ERR_ARGUMENT && strstr(err.msg, "bases"),
              "'%s' accepted or bases not named (%s)", refuse[k], err.msg);
    vdsh_cpca_settings fixed = {.clusters = K, .basis = B, .bits = BITS, .bases_s8 = 1};
    vdsh_cpca_fit a, b, h;
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &fixed, &a, &err) == VDSH_ERR_ARGUMENT &&
              strstr(err.msg, "s8") && !a.storage_,
          "s8 bases with K,B,BITS not refused (%s)", err.msg);

    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &st, &a, &err) == VDSH_OK, "s8: %s", err.msg);
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &f16, &h, &err) == VDSH_OK, "f16: %s",
          err.msg);
    const vdsh_cpca *m = &a.model;
    const size_t model = (size_t)vdsh_cpca_stream_model_bytes(m, ORDER);
    const uint64_t bytes = (uint64_t)ROWS * 4 * m->record_words + model;
    CHECK(m->bases_s8 && m->bases8 && !m->bases && !h.model.bases_s8 && h.model.bases &&
              model == vdsh_cpca_model_bytes(ORDER, m->clusters, m->basis, 1) +
                           (((size_t)m->basis + 15) & ~(size_t)15),
          "s8: the model's form");
    CHECK(bytes <= 16u * ROWS, "s8: %.2f bytes per vertex over 16", (double)bytes / ROWS);
    CHECK(m->basis > h.model.basis || m->record_words > h.model.record_words,
          "s8: %u vectors in %u words, f16 %u in %u: no byte spent", m->basis, m->record_words,
          h.model.basis, h.model.record_words);
    CHECK(a.rms_error < h.rms_error, "s8: rms error %g, f16 %g", a.rms_error, h.rms_error);
    int reach = 1;
    for (uint32_t v = 0; v < m->clusters * m->basis; v++) {
        int big = 0;
        for (uint32_t i = 0; i < NC; i++) {
            int x = m->bases8[(size_t)v * NC + i];
            big = x < 0 ? (-x > big ? -x : big) : (x > big ? x : big);
        }
        reach &= big == 0 || big == 127;
    }
    CHECK(reach, "s8: a vector whose largest |value| is not 127");
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &st, &b, &err) == VDSH_OK && same_fit(&a, &b),
          "s8: other bytes the second time");
    vdsh_cpca_fit_free(&b);
    for (uint32_t t = 1; t <= 3; t += 2) {
        vdsh_cpca_settings ts = st;
        ts.threads = t;
        CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &ts, &b, &err) == VDSH_OK &&
                  same_fit(&a, &b),
              "s8: other bytes on %u thread%s", t, vdsh_s(t));
        vdsh_cpca_fit_free(&b);
    }
    vdsh_stream s = stream_of(a.records, m);
    CHECK(fabs(rms_vs(&s, src) - a.rms_error) <= 1e-9 * (1 + a.rms_error), "s8: rms %g vs %g",
          a.rms_error, rms_vs(&s, src));
    vdsh_file f = file_of(&s);
    void *mem = NULL;
    size_t size = 0;
    vdsh_file *back = NULL;
    CHECK(
        vdsh_write_memory(&f, &mem, &size, &err) == VDSH_OK &&
            vdsh_read_memory(mem, size, "s8", &back, &err) == VDSH_OK &&
            back->streams[0].cpca.bases_s8 && back->streams[0].cpca.bits == 0 &&
            !memcmp(back->streams[0].cpca.bases8, m->bases8, (size_t)m->clusters * m->basis * NC) &&
            rms_vs(&back->streams[0], src) == rms_vs(&s, src),
        "s8: write and read back: %s", err.msg);
    if (mem) {
        const uint8_t *g = mem;
        const size_t at = coef_at(g, size);
        CHECK(at && rd32(g + at + 56) == VDSH_CPCA_BASES_S8, "s8: the header's bits word %#x",
              at ? rd32(g + at + 56) : 0);
        /* the first basis value: after the headers, widths, scales and means */
        size_t b0 = 64 + ((m->basis + 15) & ~15u) + ((4 * m->clusters * m->basis + 15) & ~15u) +
                    ((2 * m->clusters * NC + 15) & ~15u);
        const uint8_t minus128 = 0x80;
        expect_refused(g, size, b0, &minus128, 1, "is -128");
        uint8_t b4[4];
        wr32(b4, VDSH_CPCA_BASES_S8 | 0x200u);
        expect_refused(g, size, 56, b4, 4, "bits 512");
    }
    if (dir && back) /* for the Python reader's test */
        write_for_python(dir, "cpca-s8", mem, size, &back->streams[0]);
    printf("s8 bases, alloc:16 at K 3: %u vectors, %u words, %.2f bytes per vertex, rms error "
           "%.4f (f16: %u vectors, %u words, %.4f)\n",
           m->basis, m->record_words, (double)bytes / ROWS, a.rms_error, h.model.basis,
           h.model.record_words, h.rms_error);
    vdsh_free(back);
    free(mem);
    vdsh_cpca_fit_free(&a);
    vdsh_cpca_fit_free(&h);
}

/* The light-density metric (settings light_mix and the pool): a mix of 0,
 * no pool, or a pool no vertex sees above its horizon (every light at
 * every vertex's position) give the uniform metric's bytes; a pool around
 * the vertices another fit, valid, the same twice; bad light settings
 * refused; vdsh_cpca_parse's ,light:A. */
static void light_metric(void)
{
    enum { NL = 64 };
    static float pool[NL * 3], origin[ROWS * 3], at_origin[NL * 3];
    for (int l = 0; l < NL; l++) { /* around the vertices (x 0..599, y = z = 0) */
        pool[3 * l] = (float)(l * 10 % ROWS);
        pool[3 * l + 1] = (float)(l % 7) - 3.0f;
        pool[3 * l + 2] = (float)(l % 5) - 2.0f;
    }
    vdsh_cpca_settings st = {.clusters = K, .basis = B, .bits = BITS, .budget = 0};
    vdsh_cpca_fit u, f, g;
    vdsh_error err;
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &st, &u, &err) == VDSH_OK, "uniform: %s",
          err.msg);
    const struct {
        const char *what;
        float mix;
        uint32_t count;
        const float *lights, *pos;
    } same[] = {{"mix 0 with a pool", 0.0f, NL, pool, positions},
                {"mix 1 without lights", 1.0f, 0, NULL, NULL},
                {"mix 1, no light above a horizon", 1.0f, NL, at_origin, origin}};
    for (size_t k = 0; k < sizeof same / sizeof *same; k++) {
        vdsh_cpca_settings l = st;
        l.light_mix = same[k].mix;
        l.light_count = same[k].count;
        l.lights = same[k].lights;
        l.positions = same[k].pos;
        CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &l, &f, &err) == VDSH_OK, "%s: %s",
              same[k].what, err.msg);
        CHECK(same_fit(&u, &f), "%s: not the uniform metric's bytes", same[k].what);
        vdsh_cpca_fit_free(&f);
    }
    vdsh_cpca_settings l = st;
    l.light_mix = 1.0f;
    l.light_count = NL;
    l.lights = pool;
    l.positions = positions;
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &l, &f, &err) == VDSH_OK, "mix 1: %s",
          err.msg);
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &l, &g, &err) == VDSH_OK, "mix 1 again");
    CHECK(!same_fit(&u, &f), "mix 1 with a pool: the uniform metric's bytes");
    CHECK(same_fit(&f, &g), "mix 1: two encodings differ");
    /* The texel cache's cap hit (light_cache: no row kept, or some of
     * them; the pool puts thousands of texels above the rows' horizons):
     * the rows past it found again at every pass, the same bytes, for the
     * fixed settings and for a budget's candidates (one cache shared). */
    vdsh_cpca_settings alloc = l;
    alloc.bits = 0;
    alloc.budget = 48;
    vdsh_cpca_fit fa;
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &alloc, &fa, &err) == VDSH_OK,
          "mix 1, alloc:48: %s", err.msg);
    for (size_t cap = 1; cap <= 4096; cap *= 4096) {
        vdsh_cpca_settings c = l, ca = alloc;
        c.light_cache = ca.light_cache = cap;
        vdsh_cpca_fit h, ha;
        CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &c, &h, &err) == VDSH_OK &&
                  same_fit(&f, &h),
              "mix 1, a cache of %zu texels: not the uncapped bytes (%s)", cap, err.msg);
        CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &ca, &ha, &err) == VDSH_OK &&
                  same_fit(&ha, &fa),
              "mix 1, alloc:48, a cache of %zu texels: not the uncapped bytes (%s)", cap, err.msg);
        vdsh_cpca_fit_free(&h);
        vdsh_cpca_fit_free(&ha);
    }
    /* The margin and 3 starts, on 1 thread with the whole cache against 3
     * threads (each with its own scratch for the rows past the cap) and a
     * cap of 1 or 4096 texels: the same bytes; another fit than one start. */
    vdsh_cpca_settings ms = alloc;
    ms.margin = 0.25f;
    ms.starts = 3;
    ms.threads = 1;
    vdsh_cpca_fit fm;
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &ms, &fm, &err) == VDSH_OK,
          "margin 0.25, 3 starts: %s", err.msg);
    CHECK(fm.records &&
              (fm.model.record_words != fa.model.record_words ||
               memcmp(fm.records, fa.records, (size_t)ROWS * 4 * fa.model.record_words) != 0),
          "margin 0.25, 3 starts: the one start's records");
    for (size_t cap = 1; cap <= 1u << 24; cap *= 4096) {
        vdsh_cpca_settings c = ms;
        c.light_cache = cap;
        c.threads = 3;
        vdsh_cpca_fit h;
        CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &c, &h, &err) == VDSH_OK &&
                  same_fit(&h, &fm),
              "margin 0.25, 3 starts, 3 threads, a cache of %zu texels: not 1 thread's bytes (%s)",
              cap, err.msg);
        vdsh_cpca_fit_free(&h);
    }
    /* One fit on threads (its clusters' fits and its vertices'
     * reassignment split): 1 start with the margin on 1 thread against 2
     * and 5, and 3 starts on 7 (2 threads each), with the whole cache and
     * a cap of 1 texel: the same bytes. */
    {
        vdsh_cpca_settings one = ms;
        one.starts = 1;
        vdsh_cpca_fit f1;
        CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &one, &f1, &err) == VDSH_OK,
              "margin 0.25, 1 start: %s", err.msg);
        const struct {
            uint32_t starts, threads;
            size_t cap;
        } runs[] = {{1, 2, 0}, {1, 5, 0}, {1, 5, 1}, {3, 7, 0}, {3, 7, 1}};
        for (size_t i = 0; i < sizeof runs / sizeof runs[0]; i++) {
            vdsh_cpca_settings c = ms;
            c.starts = runs[i].starts;
            c.threads = runs[i].threads;
            c.light_cache = runs[i].cap;
            const vdsh_cpca_fit *want = runs[i].starts == 1 ? &f1 : &fm;
            vdsh_cpca_fit h;
            CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &c, &h, &err) == VDSH_OK &&
                      same_fit(&h, want),
                  "margin 0.25, %u start%s on %u threads, a cache of %zu texels: not 1 "
                  "thread's bytes (%s)",
                  runs[i].starts, vdsh_s(runs[i].starts), runs[i].threads, runs[i].cap, err.msg);
            vdsh_cpca_fit_free(&h);
        }
        vdsh_cpca_fit_free(&f1);
    }
    vdsh_cpca_fit_free(&fm);
    vdsh_cpca_fit_free(&fa);
    CHECK(isfinite(f.rms_error) && f.rms_error < 4.0 * u.rms_error, "mix 1: error %g, uniform %g",
          f.rms_error, u.rms_error);
    printf("format_cpca: light mix 1: error %.4g, uniform %.4g\n", f.rms_error, u.rms_error);
    vdsh_cpca_fit_free(&f);
    vdsh_cpca_fit_free(&g);
    vdsh_cpca_fit_free(&u);
    /* refused */
    static float inf_pool[NL * 3];
    memcpy(inf_pool, pool, sizeof pool);
    inf_pool[7] = INFINITY;
    const struct {
        const char *what;
        float mix;
        uint32_t count;
        const float *lights, *pos;
    } bad[] = {{"mix 1.5", 1.5f, NL, pool, positions},
               {"mix -0.5", -0.5f, NL, pool, positions},
               {"mix nan", NAN, NL, pool, positions},
               {"lights NULL", 1.0f, NL, NULL, positions},
               {"positions NULL", 1.0f, NL, pool, NULL},
               {"a light not finite", 1.0f, NL, inf_pool, positions}};
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
        vdsh_cpca_settings b = st;
        b.light_mix = bad[k].mix;
        b.light_count = bad[k].count;
        b.lights = bad[k].lights;
        b.positions = bad[k].pos;
        CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &b, &f, &err) == VDSH_ERR_ARGUMENT &&
                  strstr(err.msg, "light"),
              "%s accepted or not said: %s", bad[k].what, err.msg);
    }
    /* the grammar */
    vdsh_cpca_settings p, d = vdsh_cpca_settings_default();
    CHECK(vdsh_cpca_parse("3,alloc:16,light:0.5", &p, &err) == VDSH_OK && p.clusters == 3 &&
              p.budget == 16 && p.light_mix == 0.5f,
          "3,alloc:16,light:0.5");
    CHECK(vdsh_cpca_parse("light:0", &p, &err) == VDSH_OK && p.clusters == d.clusters &&
              p.basis == d.basis && p.bits == d.bits && p.budget == d.budget &&
              p.light_mix == 0.0f && p.margin == 0.0f && p.starts == 0,
          "light:0 alone: the default K and budget, uniform, no margin, one start");
    /* the default: K,alloc:BYTES (16,alloc:32) with the default light mix,
     * margin and starts (docs/ACCURACY.md "The default of --encoding cpca",
     * "The margin and two starts become the default"), what the text
     * "16,alloc:32,margin:0.25,starts:3,bases:8" gives; the base said alone
     * has neither margin nor starts and f16 bases; an option alone keeps
     * the default's others */
    CHECK(d.clusters == VDSH_CPCA_DEFAULT_CLUSTERS && d.budget == VDSH_CPCA_DEFAULT_BUDGET &&
              d.basis == 0 && d.bits == 0 && d.light_mix == VDSH_CPCA_DEFAULT_LIGHT_MIX &&
              d.margin == VDSH_CPCA_DEFAULT_MARGIN && d.starts == VDSH_CPCA_DEFAULT_STARTS &&
              d.margin > 0.0f && d.starts > 1 && d.bases_s8 == VDSH_CPCA_DEFAULT_BASES_S8 &&
              !d.light_count && !d.lights && !d.positions,
          "the default settings: K,alloc:BYTES with the default light mix, margin, starts and "
          "bases");
    {
        char text[64];
        snprintf(text, sizeof text, "%u,alloc:%u,margin:%g,starts:%u%s", (unsigned)d.clusters,
                 (unsigned)d.budget, (double)d.margin, (unsigned)d.starts,
                 d.bases_s8 ? ",bases:8" : "");
        CHECK(vdsh_cpca_parse(text, &p, &err) == VDSH_OK && same_settings(&p, &d),
              "the default settings are %s's", text);
        snprintf(text, sizeof text, "%u,alloc:%u", (unsigned)d.clusters, (unsigned)d.budget);
        CHECK(vdsh_cpca_parse(text, &p, &err) == VDSH_OK && p.clusters == d.clusters &&
                  p.budget == d.budget && p.light_mix == d.light_mix && p.margin == 0.0f &&
                  p.starts == 0 && !p.bases_s8,
              "%s said: not one start without the margin, f16 bases", text);
    }
    /* vdsh_cpca_settings_text: what parse reads back as the same settings */
    {
        static const char *const texts[] = {"8,52,4,light:.25",     "auto:24",
                                            "margin:0.5",           "3,alloc:16,light:0",
                                            "16,alloc:32,starts:3", "light:0"};
        for (size_t i = 0; i < sizeof texts / sizeof texts[0]; i++) {
            vdsh_cpca_settings a, b;
            char text[192];
            CHECK(vdsh_cpca_parse(texts[i], &a, &err) == VDSH_OK, "%s: %s", texts[i], err.msg);
            vdsh_cpca_settings_text(&a, text, sizeof text);
            CHECK(vdsh_cpca_parse(text, &b, &err) == VDSH_OK && same_settings(&a, &b),
                  "%s: its text %s reads back as other settings (%s)", texts[i], text, err.msg);
        }
        char text[192], small[8];
        vdsh_cpca_settings_text(&d, text, sizeof text);
        vdsh_cpca_settings_text(&d, small, sizeof small);
        CHECK(!strcmp(text, "16,alloc:32,light:1,margin:0.25,starts:3,bases:8") &&
                  !strcmp(small, "16,allo"),
              "the default's text %s (truncated: %s)", text, small);
    }
    CHECK(vdsh_cpca_parse("starts:1", &p, &err) == VDSH_OK && p.clusters == d.clusters &&
              p.budget == d.budget && p.margin == d.margin && p.starts == 1,
          "starts:1 alone: not the default's margin with one start");
    CHECK(vdsh_cpca_parse("light:0.5,margin:0.5", &p, &err) == VDSH_OK && p.light_mix == 0.5f &&
              p.margin == 0.5f && p.starts == d.starts,
          "light:0.5,margin:0.5 alone: not the default's starts");
    CHECK(vdsh_cpca_parse("auto,light:0", &p, &err) == VDSH_OK && p.budget == 32 &&
              p.light_mix == 0.0f,
          "auto,light:0");
    CHECK(vdsh_cpca_parse("8,52,4,light:.25", &p, &err) == VDSH_OK && p.light_mix == 0.25f,
          "8,52,4,light:.25");
    CHECK(vdsh_cpca_parse("8,52,4", &p, &err) == VDSH_OK && p.light_mix == 0.0f && !p.light_count &&
              !p.lights && !p.positions,
          "fixed widths: the uniform metric unless said");
    CHECK(vdsh_cpca_parse("8,alloc:32", &p, &err) == VDSH_OK &&
              p.light_mix == VDSH_CPCA_DEFAULT_LIGHT_MIX && !p.light_count,
          "alloc: the default light mix");
    CHECK(vdsh_cpca_parse("auto", &p, &err) == VDSH_OK &&
              p.light_mix == VDSH_CPCA_DEFAULT_LIGHT_MIX,
          "auto: the default light mix");
    static const char *const refuse[] = {
        "light:2", "light:", "light:-0", "light:1e0", "light:inf", "light:1,8,52,4",
        "8,52,4,light:x", "8,52,4,light:1,", "8,52,4light:1", "auto,light:0.5.1",
        "3,alloc:0,light:1", "8,52,4,light:1,light:0",
        /* the margin and the starts: K,alloc:BYTES with a light mix only */
        "3,alloc:16,margin:0", "3,alloc:16,margin:-1", "3,alloc:16,margin:1e3",
        "3,alloc:16,starts:0", "3,alloc:16,starts:17", "3,alloc:16,starts:2.0",
        "8,52,4,margin:0.25", "auto,starts:2", "3,alloc:16,light:0,margin:0.25",
        "3,alloc:16,starts:2,starts:2", "3,alloc:16,margin:0.25,x:1", "margin:0.25,3,alloc:16"};
    for (size_t k = 0; k < sizeof refuse / sizeof *refuse; k++)
        CHECK(vdsh_cpca_parse(refuse[k], &p, &err) == VDSH_ERR_ARGUMENT, "'%s' accepted",
              refuse[k]);
    CHECK(vdsh_cpca_parse("3,alloc:16,starts:2,light:0.5,margin:0.25", &p, &err) == VDSH_OK &&
              p.clusters == 3 && p.budget == 16 && p.light_mix == 0.5f && p.margin == 0.25f &&
              p.starts == 2,
          "the options in any order");
    CHECK(vdsh_cpca_parse("margin:.5,starts:16", &p, &err) == VDSH_OK && p.clusters == d.clusters &&
              p.budget == d.budget && p.light_mix == d.light_mix && p.margin == 0.5f &&
              p.starts == 16,
          "margin and starts alone: the default K and budget");
    CHECK(vdsh_cpca_parse("3,alloc:16", &p, &err) == VDSH_OK && p.margin == 0.0f && !p.starts,
          "no margin, one start unless said");
    /* a part's record of the settings and back (VDSH.md "Parts": the
     * bake writes it, vdsh-merge encodes with what it reads) */
    static const char *const kinds[] = {"8,52,4",
                                        "light:1",
                                        "auto:24",
                                        "auto:24,light:1",
                                        "3,alloc:16",
                                        "3,alloc:16,light:0.5",
                                        "3,alloc:16,margin:0.25,starts:3"};
    for (size_t k = 0; k < sizeof kinds / sizeof *kinds; k++) {
        CHECK(vdsh_cpca_parse(kinds[k], &p, &err) == VDSH_OK, "'%s' refused", kinds[k]);
        if (p.light_mix > 0.0f) {
            p.light_count = NL;
            p.lights = pool;
            p.positions = positions;
        }
        vdsh_file part = {.has_part = 1, .positions = positions};
        vdsh_cpca_part_record(&p, &part);
        vdsh_cpca_settings q = vdsh_cpca_part_settings(&part);
        CHECK(part.has_light_pool == (p.light_mix > 0.0f) && q.clusters == p.clusters &&
                  q.budget == p.budget && (p.budget || (q.basis == p.basis && q.bits == p.bits)) &&
                  q.light_mix == p.light_mix && q.light_count == p.light_count &&
                  q.lights == p.lights && q.positions == p.positions && q.margin == p.margin &&
                  q.starts == p.starts,
              "'%s': the part's record reads back as other settings", kinds[k]);
    }
}

/* vdsh_cpca_pool_score against the same sums done here with libm's log:
 * the pairs (vertex, light above its horizon), the decisions that differ
 * (lit when ln D is not below ln of the distance), those lit by the
 * source, and the squared ln D difference; the same twice; refused
 * without a pool. */
static void pool_score(void)
{
    enum { NL = 64 };
    static float pool[NL * 3];
    for (int l = 0; l < NL; l++) { /* around the vertices (x 0..599, y = z = 0) */
        pool[3 * l] = (float)(l * 10 % ROWS) + 0.5f;
        pool[3 * l + 1] = (float)(l % 7) - 3.0f;
        pool[3 * l + 2] = (float)(l % 5) - 2.0f;
    }
    vdsh_cpca_settings st = {.clusters = K, /* lossy: one vector of 2 bits */
                             .basis = 1,
                             .bits = 2,
                             .light_mix = 1.0f,
                             .light_count = NL,
                             .lights = pool,
                             .positions = positions};
    vdsh_cpca_fit f;
    vdsh_error err;
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &st, &f, &err) == VDSH_OK, "pool score: %s",
          err.msg);
    vdsh_cpca_pool_scores a, b;
    CHECK(vdsh_cpca_pool_score(src, normals, ROWS, ORDER, &st, &f, &a, &err) == VDSH_OK,
          "pool score: %s", err.msg);
    CHECK(vdsh_cpca_pool_score(src, normals, ROWS, ORDER, &st, &f, &b, &err) == VDSH_OK &&
              memcmp(&a, &b, sizeof a) == 0,
          "pool score: not the same twice");
    vdsh_stream s = stream_of(f.records, &f.model);
    uint64_t pairs = 0, differ = 0, missed = 0;
    double sq = 0.0;
    float dec[VDSH_MAX_COEFFS], y[VDSH_MAX_COEFFS];
    for (uint32_t v = 0; v < ROWS; v++) {
        vdsh_stream_decode(&s, v, dec);
        for (int l = 0; l < NL; l++) {
            double d[3], r2 = 0.0, up = 0.0;
            for (int i = 0; i < 3; i++) {
                d[i] = (double)pool[3 * l + i] - positions[3 * v + i];
                r2 += d[i] * d[i];
                up += d[i] * normals[3 * v + i];
            }
            if (!(up > 0.0))
                continue;
            const double r = sqrt(r2), t = log(r);
            float df[3] = {(float)(d[0] / r), (float)(d[1] / r), (float)(d[2] / r)};
            vdsh_sh_eval(ORDER, df, y);
            double x0 = 0.0, x1 = 0.0;
            for (int i = 0; i < NC; i++) {
                x0 += (double)src[v * NC + i] * y[i];
                x1 += (double)dec[i] * y[i];
            }
            pairs++;
            differ += (x0 >= t) != (x1 >= t);
            missed += (x0 >= t) && !(x1 >= t);
            sq += (x1 - x0) * (x1 - x0);
        }
    }
    CHECK(pairs > 0 && a.pairs == pairs && a.disagree == differ && a.missed == missed &&
              fabs(a.squared - sq) <= 1e-9 * sq,
          "pool score: pairs %llu (%llu), differing %llu (%llu), lit by the source %llu (%llu), "
          "squared %g (%g)",
          (unsigned long long)a.pairs, (unsigned long long)pairs, (unsigned long long)a.disagree,
          (unsigned long long)differ, (unsigned long long)a.missed, (unsigned long long)missed,
          a.squared, sq);
    CHECK(a.disagree > 0 && a.disagree < a.pairs && a.squared > 0.0,
          "pool score: a lossy fit with no decision differing (%llu of %llu)",
          (unsigned long long)a.disagree, (unsigned long long)a.pairs);
    printf("format_cpca: pool score: %llu pairs, %llu decisions differ, squared %.4g\n",
           (unsigned long long)a.pairs, (unsigned long long)a.disagree, a.squared);
    vdsh_cpca_settings none = st;
    none.light_count = 0;
    CHECK(vdsh_cpca_pool_score(src, normals, ROWS, ORDER, &none, &f, &a, &err) == VDSH_ERR_ARGUMENT,
          "pool score without a pool not refused");
    vdsh_cpca_fit_free(&f);
}

int main(int argc, char **argv)
{
    make_data();
    vdsh_cpca_settings st = {.clusters = K, .basis = B, .bits = BITS, .budget = 0};
    vdsh_cpca_fit fit, again, one;
    vdsh_error err;
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &st, &fit, &err) == VDSH_OK, "encode: %s",
          err.msg);
    CHECK(fit.model.clusters == K && fit.model.basis == B && fit.model.bits == BITS &&
              fit.model.record_words == vdsh_cpca_record_words(B, BITS) &&
              fit.model.record_words == 2,
          "model %u,%u,%u,%u", fit.model.clusters, fit.model.basis, fit.model.bits,
          fit.model.record_words);
    /* determinism: the same bytes again */
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &st, &again, &err) == VDSH_OK, "encode 2");
    CHECK(same_fit(&fit, &again), "two encodings of the same input differ");
    vdsh_cpca_fit_free(&again);
    /* the same bytes on 1 and 4 threads (the uniform metric) */
    for (uint32_t t = 1; t <= 4; t += 3) {
        vdsh_cpca_settings ts = st;
        ts.threads = t;
        CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &ts, &again, &err) == VDSH_OK &&
                  same_fit(&fit, &again),
              "the encoding on %u thread%s differs", t, vdsh_s(t));
        vdsh_cpca_fit_free(&again);
    }

    vdsh_stream s = stream_of(fit.records, &fit.model);
    /* the clusters follow the normals: each cluster's vertices share one */
    for (uint32_t v = 0; v < ROWS; v++) {
        uint32_t c = vdsh_cpca_cluster(&s, v);
        CHECK(c < K, "vertex %u cluster %u", v, c);
    }
    /* decode to the bit: mean + sum_j w_j basis_j in f32, j in order */
    float c[VDSH_MAX_COEFFS], w[VDSH_MAX_COEFFS];
    int32_t q[VDSH_MAX_COEFFS];
    int exact = 1;
    for (uint32_t v = 0; v < ROWS; v += 7) {
        vdsh_stream_decode(&s, v, c);
        vdsh_cpca_weights(&s, v, q, w);
        uint32_t cl = vdsh_cpca_cluster(&s, v);
        for (int i = 0; i < NC; i++) {
            float a = vdsh_f32_from_f16(fit.model.means[cl * NC + i]);
            for (int j = 0; j < B; j++) {
                float wj = (float)q[j] * (fit.model.scales[cl * B + j] / 7.0f);
                exact &= wj == w[j];
                a = a + wj * vdsh_f32_from_f16(fit.model.bases[(cl * B + j) * NC + i]);
            }
            exact &= memcmp(&a, &c[i], 4) == 0;
        }
        for (int j = 0; j < B; j++)
            exact &= q[j] >= -7 && q[j] <= 7;
    }
    CHECK(exact, "decode is not mean + sum of weight x basis in f32");
    /* error: far below the spread, the encoder's own figure, and below one
     * global vector's (K = 1, B = 1) */
    double mean[NC] = {0}, spread = 0.0;
    for (int v = 0; v < ROWS; v++)
        for (int i = 0; i < NC; i++)
            mean[i] += src[v * NC + i] / (double)ROWS;
    for (int v = 0; v < ROWS; v++)
        for (int i = 0; i < NC; i++)
            spread += (src[v * NC + i] - mean[i]) * (src[v * NC + i] - mean[i]) / ROWS;
    spread = sqrt(spread);
    double e = rms_vs(&s, src);
    CHECK(fabs(e - fit.rms_error) <= 1e-9 * (1 + e), "rms_error %g, decode %g", fit.rms_error, e);
    CHECK(e < 0.1 * spread, "error %g not below a tenth of the spread %g", e, spread);
    vdsh_cpca_settings small = {.clusters = 1, .basis = 1, .bits = 4, .budget = 0};
    CHECK(vdsh_cpca_encode(src, normals, ROWS, ORDER, &small, &one, &err) == VDSH_OK, "K=1");
    CHECK(one.rms_error > 2.0 * e, "one vector %g, not worse than %g", one.rms_error, e);
    printf("format_cpca: error %.4g, spread %.4g, one vector %.4g\n", e, spread, one.rms_error);
    vdsh_cpca_fit_free(&one);

    /* write, read: the same model and records */
    vdsh_file f = file_of(&s);
    void *mem = NULL;
    size_t size = 0;
    CHECK(vdsh_write_memory(&f, &mem, &size, &err) == VDSH_OK, "write: %s", err.msg);
    vdsh_file *back = NULL;
    CHECK(mem && vdsh_read_memory(mem, size, "cpca", &back, &err) == VDSH_OK, "read: %s", err.msg);
    if (back) {
        const vdsh_stream *r = &back->streams[0];
        CHECK(r->encoding == VDSH_ENCODING_CPCA && r->cpca.clusters == K && r->cpca.basis == B &&
                  r->cpca.bits == BITS &&
                  memcmp(r->cpca.scales, fit.model.scales, 4 * K * B) == 0 &&
                  memcmp(r->cpca.means, fit.model.means, 2 * K * NC) == 0 &&
                  memcmp(r->cpca.bases, fit.model.bases, 2 * K * B * NC) == 0 &&
                  memcmp(r->data, fit.records, (size_t)ROWS * 8) == 0,
              "read back differs");
        CHECK(fabs(rms_vs(r, src) - e) == 0.0, "read-back decode differs");
        CHECK(vdsh_stream_bytes_per_vertex(r) == 8, "bytes per vertex %zu",
              vdsh_stream_bytes_per_vertex(r));
        vdsh_stream_size z = vdsh_stream_size_of(r, ROWS);
        CHECK(fabs(z.mean_bytes - (8.0 + (double)vdsh_cpca_model_bytes(ORDER, K, B, 0) / ROWS)) <
                  1e-9,
              "mean bytes %g", z.mean_bytes);
        if (argc > 1) /* for the Python reader's test */
            write_for_python(argv[1], "cpca", mem, size, r);
    }
    vdsh_free(back);
    widths_stream(&fit, argc > 1 ? argv[1] : NULL);

    /* reading rules (offsets in the COEF payload: header 48, cpca header
     * 48..63, scales from 64 (K*B*4 = 156, padded to 160), means from 224
     * (294, padded to 304), bases from 528 (3822, padded to 3824), records
     * from 4352) */
    if (mem) {
        const uint8_t *g = mem;
        size_t rec = 64 + 160 + 304 + 3824;
        uint8_t b4[4];
        wr32(b4, K);
        expect_refused(g, size, rec, b4, 1, "cluster 3");
        wr32(b4, (rd32(g + coef_at(g, size) + rec) & ~0xf000u) | 0x8000u); /* weight 1: -8 */
        expect_refused(g, size, rec, b4, 4, "weight 1 is -8");
        wr32(b4, rd32(g + coef_at(g, size) + rec + 4) | 0x80000000u); /* past the last field */
        expect_refused(g, size, rec + 4, b4, 4, "unused bits");
        wr32(b4, 3);
        expect_refused(g, size, 60, b4, 4, "record_words");
        wr32(b4, 9);
        expect_refused(g, size, 56, b4, 4, "bits 9");
        wr32(b4, 0);
        expect_refused(g, size, 48, b4, 4, "clusters 0");
        wr32(b4, NC + 1);
        expect_refused(g, size, 52, b4, 4, "basis 50");
        wr32(b4, 1);
        expect_refused(g, size, 36, b4, 4, "variable order");
        const float neg = -1.0f;
        expect_refused(g, size, 64, &neg, 4, "cpca scale 0");
        const float big = 3e38f;
        expect_refused(g, size, 64, &big, 4, "beyond 1e38");
        const uint8_t nan16[2] = {0x00, 0x7e};
        expect_refused(g, size, 224, nan16, 2, "mean of cluster 0");
        expect_refused(g, size, 528 + 2, nan16, 2, "basis vector 0 of cluster 0");
        const uint8_t one_byte = 1;
        expect_refused(g, size, 64 + 156, &one_byte, 1, "padding after the cpca scales");
        expect_refused(g, size, 224 + 294, &one_byte, 1, "padding after the cpca means");
        expect_refused(g, size, 528 + 3822, &one_byte, 1, "padding after the cpca bases");
        /* every truncation refused, none read past its buffer */
        int refused = 0;
        for (size_t n = 0; n < size; n++) {
            uint8_t *d = malloc(n + 1);
            memcpy(d, g, n);
            vdsh_file *t = NULL;
            refused += vdsh_read_memory(d, n, "cut", &t, NULL) != VDSH_OK;
            vdsh_free(t);
            free(d);
        }
        CHECK(refused == (int)size, "%d of %zu truncations refused", refused, size);
        free(mem);
    }
    /* the writer refuses a model without its arrays */
    vdsh_stream bad = s;
    bad.cpca.bases = NULL;
    vdsh_file fb = file_of(&bad);
    CHECK(vdsh_write_memory(&fb, &mem, &size, &err) == VDSH_ERR_ARGUMENT && strstr(err.msg, "cpca"),
          "writer accepted a model without bases");
    vdsh_cpca_fit_free(&fit);

    curved_cluster();
    line_and_blob();
    auto_settings();
    widths_study();
    alloc_settings();
    s8_bases(argc > 1 ? argv[1] : NULL);
    light_metric();
    pool_score();

    /* settings */
    vdsh_cpca_settings p;
    CHECK(vdsh_cpca_parse("8,52,4", &p, NULL) == VDSH_OK && p.clusters == 8 && p.basis == 52 &&
              p.bits == 4,
          "8,52,4");
    static const char *const refuse[] = {"",         "8,52",  "8,52,4,1", "0,52,4",
                                         "257,52,4", "8,0,4", "8,52,1",   "8,52,9",
                                         "8,,4",     "a,b,c", "8,52,4x",  "-1,52,4"};
    CHECK(vdsh_cpca_parse("auto", &p, NULL) == VDSH_OK && p.budget == VDSH_CPCA_DEFAULT_BUDGET,
          "auto");
    CHECK(vdsh_cpca_parse("auto:24", &p, NULL) == VDSH_OK && p.budget == 24, "auto:24");
    CHECK(vdsh_cpca_parse("auto:4096", &p, NULL) == VDSH_OK && p.budget == 4096, "auto:4096");
    CHECK(vdsh_cpca_parse("8,52,4", &p, NULL) == VDSH_OK && p.budget == 0, "8,52,4 not auto");
    static const char *const refuse_auto[] = {"auto:0",  "auto:x",   "auto:",   "auto:4097",
                                              "auto32",  "autox",    "auto:-1", "auto: 5",
                                              "auto:5x", "auto:32,", "Auto"};
    for (size_t k = 0; k < sizeof refuse_auto / sizeof *refuse_auto; k++)
        CHECK(vdsh_cpca_parse(refuse_auto[k], &p, &err) == VDSH_ERR_ARGUMENT &&
                  strstr(err.msg, refuse_auto[k]),
              "'%s' accepted or not named", refuse_auto[k]);
    for (size_t k = 0; k < sizeof refuse / sizeof *refuse; k++)
        CHECK(vdsh_cpca_parse(refuse[k], &p, &err) == VDSH_ERR_ARGUMENT, "'%s' accepted",
              refuse[k]);

    printf("format_cpca: %d checks, %d failures\n", checks, failures);
    return failures ? 1 : 0;
}
