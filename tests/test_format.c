/*
 * test_format.c - unit tests of formats/vdsh.h: CRC, binary16, write/read
 * round trips, the reader's rules (every truncation, every changed byte,
 * one crafted file per rule), the writer's checks, atomic writing.
 *
 * Runs in a fresh directory from mkdtemp() that it removes at the end.
 * `test_format --exhaustive-f16` also checks vdsh_f16_from_f32 against a
 * reference on all 2^32 floats (about a minute; not part of ctest).
 *
 * The test knows the byte layout on purpose (helpers tf_* below re-encode
 * chunks and CRCs independently of the library) so that it can build the
 * files a buggy or malicious writer would produce.
 */
#include "test_dir.h"
#include "vdsh.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <float.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static int failures;
static int checks;

#define CHECK(c)                                                                                   \
    do {                                                                                           \
        checks++;                                                                                  \
        if (!(c)) {                                                                                \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #c);                  \
            failures++;                                                                            \
        }                                                                                          \
    } while (0)

/* Expect result `want` from `expr`; print the message when it differs. */
#define CHECK_RES(expr, want, err)                                                                 \
    do {                                                                                           \
        vdsh_result got_ = (expr);                                                                 \
        checks++;                                                                                  \
        if (got_ != (want)) {                                                                      \
            fprintf(stderr, "%s:%d: %s gave %d (%s), want %d (%s): %s\n", __FILE__, __LINE__,      \
                    #expr, (int)got_, vdsh_result_str(got_), (int)(want), vdsh_result_str(want),   \
                    got_ != VDSH_OK ? (err)->msg : "");                                            \
            failures++;                                                                            \
        }                                                                                          \
    } while (0)

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Deterministic pseudo-random numbers (xorshift64*). */
static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static uint64_t rnd(void)
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return rng_state * 0x2545F4914F6CDD1Dull;
}
static float rndf(float lo, float hi)
{
    return lo + (hi - lo) * (float)((double)(rnd() >> 11) * 0x1p-53);
}

static uint32_t bits_of(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return u;
}
static float float_of(uint32_t u)
{
    float f;
    memcpy(&f, &u, 4);
    return f;
}

/* Test-side little-endian access, independent of the library's. */
static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static uint64_t rd64(const uint8_t *p)
{
    return rd32(p) | (uint64_t)rd32(p + 4) << 32;
}
static void wr32(uint8_t *p, uint32_t v)
{
    for (int k = 0; k < 4; k++)
        p[k] = (uint8_t)(v >> (8 * k));
}
static void wr64(uint8_t *p, uint64_t v)
{
    wr32(p, (uint32_t)v);
    wr32(p + 4, (uint32_t)(v >> 32));
}
static void wrf32(uint8_t *p, float f)
{
    wr32(p, bits_of(f));
}

/* ------------------------------------------------------------------ */
/* Temporary directory                                                 */
/* ------------------------------------------------------------------ */

static char tmpdir[512];

static void path_in(char *out, size_t n, const char *name)
{
    snprintf(out, n, "%s/%s", tmpdir, name);
}

static int file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Names in the directory that contain ".tmp" (left-over temporaries). */
static int count_tmp_files(const char *dir)
{
    return test_count_names(dir, ".tmp");
}

static void remove_tree(const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    char p[1024];
    if (!d)
        return;
    chmod(dir, 0700);
    while ((e = readdir(d))) {
        struct stat st;
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
        if (lstat(p, &st) == 0 && S_ISDIR(st.st_mode))
            remove_tree(p);
        else
            unlink(p);
    }
    closedir(d);
    rmdir(dir);
}

static uint8_t *load_file(const char *path, size_t *size)
{
    FILE *fp = fopen(path, "rb");
    struct stat st;
    if (!fp)
        return NULL;
    fstat(fileno(fp), &st);
    uint8_t *b = malloc((size_t)st.st_size + 1);
    *size = fread(b, 1, (size_t)st.st_size, fp);
    fclose(fp);
    return b;
}

static int save_file(const char *path, const void *d, size_t n)
{
    FILE *fp = fopen(path, "wb");
    if (!fp)
        return 0;
    int ok = fwrite(d, 1, n, fp) == n;
    return fclose(fp) == 0 && ok;
}

/* ------------------------------------------------------------------ */
/* Sample files                                                        */
/* ------------------------------------------------------------------ */

typedef struct sample {
    vdsh_file f;
    float *pos, *nrm;
    uint32_t *idx;
    vdsh_stream streams[VDSH_MAX_STREAMS];
    void *data[VDSH_MAX_STREAMS];
    vdsh_source sources[8];
    char *long_name;
} sample;

static void random_unit(float *n)
{
    double x, y, z, l;
    do {
        x = rndf(-1, 1), y = rndf(-1, 1), z = rndf(-1, 1);
        l = sqrt(x * x + y * y + z * z);
    } while (l < 0.1 || l > 1.0);
    n[0] = (float)(x / l), n[1] = (float)(y / l), n[2] = (float)(z / l);
}

static void add_stream(sample *s, uint32_t order, uint32_t enc, uint32_t q, uint32_t method,
                       uint32_t window, float wp, float mp, float scale)
{
    uint32_t i = s->f.stream_count++;
    uint32_t v = s->f.header.vertex_count;
    size_t n = (size_t)v * order * order;
    vdsh_stream *st = &s->streams[i];
    st->order = order;
    st->encoding = enc;
    st->quantity = q;
    st->method = method;
    st->window = window;
    st->window_param = wp;
    st->method_param = mp;
    st->scale = scale;
    /* The log floor is the one quantity parameter (0 for the others). */
    st->quantity_param = q == VDSH_QUANTITY_LOG_DISTANCE ? 0.0625f * (float)(i + 1) : 0.0f;
    if (enc == VDSH_ENCODING_F16) {
        uint16_t *d = malloc(n * 2 + 2);
        for (size_t k = 0; k < n; k++)
            d[k] = vdsh_f16_from_f32(rndf(-8.0f, 8.0f));
        /* Edge patterns: -0, smallest subnormal, largest finite. */
        d[0] = 0x8000;
        if (n > 1)
            d[1] = 0x0001;
        if (n > 2)
            d[2] = 0x7bff;
        if (n > 3)
            d[3] = 0xfbff;
        s->data[i] = d;
    } else if (vdsh_encoding_quantised(enc)) {
        /* The scale table, then the bytes (one block, as the baker's). */
        uint32_t nc = order * order;
        size_t bpv = vdsh_encoding_bytes(enc, nc);
        float *t = malloc(VDSH_MAX_COEFFS * sizeof(float) + v * bpv + 1);
        uint8_t *b = (uint8_t *)(t + VDSH_MAX_COEFFS);
        for (uint32_t k = 0; k < nc; k++)
            t[k] = rndf(0.0f, 20.0f);
        t[0] = 0.0f; /* an all-zero index */
        if (nc > 1)
            t[1] = 3.4e38f; /* huge: |stored| <= 127 keeps it finite */
        if (nc > 2)
            t[2] = float_of(1); /* subnormal */
        if (enc == VDSH_ENCODING_S8) {
            for (size_t k = 0; k < n; k++)
                b[k] = (uint8_t)(int8_t)((int)(rnd() % 255u) - 127);
            b[0] = (uint8_t)-127;
            if (n > 1)
                b[1] = 127;
        } else {
            /* random valid values through the encoder: fields -31..31,
             * unused bits 0; the extremes from +-scale */
            float *c = malloc(n * sizeof *c + 4);
            for (size_t k = 0; k < n; k++)
                c[k] = rndf(-1.0f, 1.0f);
            c[0] = -1.0f;
            c[n - 1] = 1.0f;
            float sc[VDSH_MAX_COEFFS];
            if (vdsh_encode_quantised(enc, c, v, nc, sc, b) != VDSH_OK)
                abort();
            free(c);
        }
        st->scale = 1.0f;
        st->coef_scales = t;
        s->data[i] = t;
        st->data = b;
        return;
    } else {
        float *d = malloc(n * 4 + 4);
        for (size_t k = 0; k < n; k++)
            d[k] = rndf(-20.0f, 20.0f);
        d[0] = -0.0f;
        if (n > 1)
            d[1] = float_of(1); /* a float subnormal is finite, kept exact */
        if (n > 2)
            d[2] = 1e30f;
        s->data[i] = d;
    }
    st->data = s->data[i];
}

/*
 * kind 0: small (4 vertices, 2 triangles, two streams, one source, stat
 *         and time): every chunk type in under 700 bytes.
 * kind 1: full (v vertices, every encoding, several orders, sources with
 *         every name padding and a 4096-byte name).
 * kind 2: big (v vertices, one order-5 f32 stream) for timing.
 */
static void sample_init(sample *s, int kind, uint32_t v)
{
    memset(s, 0, sizeof *s);
    rng_state = 0x9E3779B97F4A7C15ull + (uint64_t)kind;
    if (kind == 0)
        v = 4;
    uint32_t t = kind == 0 ? 2 : 2 * v;
    vdsh_header *h = &s->f.header;
    h->vertex_count = v;
    h->triangle_count = t;
    h->rays = 2500;
    h->sampling = VDSH_SAMPLING_HEMISPHERE;
    h->seed = 0x0123456789abcdefull;
    h->max_distance = 15.0f;
    h->max_edge = 0.2f;
    h->offset_rule = VDSH_OFFSET_WB_AVG;
    h->load_flags = VDSH_LOAD_WELD | 60u << VDSH_LOAD_CREASE_SHIFT;
    h->cube_size = 64;
    h->occluder_vertex_count = 1200;
    h->occluder_triangle_count = 2400;
    h->trace_flags = VDSH_TRACE_ROBUST;
    h->bounds_min[0] = -9.5f, h->bounds_min[1] = 0.0f, h->bounds_min[2] = -9.5f;
    h->bounds_max[0] = 9.5f, h->bounds_max[1] = 6.0f, h->bounds_max[2] = 9.5f;

    s->pos = malloc((size_t)v * 12);
    s->nrm = malloc((size_t)v * 12);
    s->idx = malloc((size_t)t * 12 + 4);
    for (uint32_t i = 0; i < v; i++) {
        for (int k = 0; k < 3; k++)
            s->pos[3 * i + k] = rndf(-9.5f, 9.5f);
        random_unit(s->nrm + 3 * i);
    }
    s->pos[0] = -0.0f;
    s->pos[1] = float_of(3);                              /* subnormal */
    s->nrm[3] = 0.0f, s->nrm[4] = 0.0f, s->nrm[5] = 0.0f; /* undefined */
    if (v > 2)
        s->nrm[6] = -0.0f, s->nrm[7] = 0.0f, s->nrm[8] = 0.0f;
    for (uint32_t i = 0; i < 3 * t; i++)
        s->idx[i] = (uint32_t)(rnd() % v);
    s->idx[0] = v - 1;
    s->f.positions = s->pos;
    s->f.normals = s->nrm;
    s->f.indices = s->idx;
    s->f.streams = s->streams;
    s->f.sources = s->sources;

    if (kind == 0) {
        add_stream(s, 2, VDSH_ENCODING_F32, VDSH_QUANTITY_DISTANCE, VDSH_METHOD_PAPER,
                   VDSH_WINDOW_NONE, 0, 0, 1);
        add_stream(s, 1, VDSH_ENCODING_F16, VDSH_QUANTITY_LOG_DISTANCE, VDSH_METHOD_FULL,
                   VDSH_WINDOW_HANN, 2.5f, 0.01f, 15);
        s->sources[0].name = "a.obj";
    } else if (kind == 1) {
        /* order, encoding, quantity, method, window, its parameter,
         * method parameter, coefficient scale */
        static const struct {
            uint32_t order, enc, q, method, window;
            float wp, mp, scale;
        } streams[] = {
            {5, VDSH_ENCODING_F16, VDSH_QUANTITY_DISTANCE, VDSH_METHOD_PAPER, VDSH_WINDOW_HANN,
             2.5f, 0, 15},
            {3, VDSH_ENCODING_F32, VDSH_QUANTITY_DISTANCE, VDSH_METHOD_FULL, VDSH_WINDOW_NONE, 0, 0,
             1},
            {2, VDSH_ENCODING_F16, VDSH_QUANTITY_LOG_DISTANCE, VDSH_METHOD_PAPER,
             VDSH_WINDOW_LANCZOS, 1.0f, 0.01f, 0.5f},
            {1, VDSH_ENCODING_F32, VDSH_QUANTITY_DISTANCE2, VDSH_METHOD_FULL, VDSH_WINDOW_NONE, 0,
             0, 3},
            {5, VDSH_ENCODING_F32, VDSH_QUANTITY_DISTANCE2, VDSH_METHOD_PAPER, VDSH_WINDOW_NONE, 0,
             -1.5f, 1},
            {4, VDSH_ENCODING_S8, VDSH_QUANTITY_DISTANCE, VDSH_METHOD_LSQ, VDSH_WINDOW_NONE, 0, 0,
             1},
            {3, VDSH_ENCODING_S8, VDSH_QUANTITY_LOG_DISTANCE, VDSH_METHOD_SHADOW, VDSH_WINDOW_NONE,
             0, 0.8f, 1},
            {5, VDSH_ENCODING_S8S6, VDSH_QUANTITY_LOG_DISTANCE, VDSH_METHOD_SHADOW,
             VDSH_WINDOW_NONE, 0, 0.8f, 1},
            {4, VDSH_ENCODING_S8S6, VDSH_QUANTITY_LOG_DISTANCE, VDSH_METHOD_SHADOW,
             VDSH_WINDOW_NONE, 0, 0.8f, 1},
        };
        for (size_t i = 0; i < sizeof streams / sizeof streams[0]; i++)
            add_stream(s, streams[i].order, streams[i].enc, streams[i].q, streams[i].method,
                       streams[i].window, streams[i].wp, streams[i].mp, streams[i].scale);
        s->long_name = malloc(VDSH_MAX_NAME + 1);
        memset(s->long_name, 'n', VDSH_MAX_NAME);
        s->long_name[VDSH_MAX_NAME] = 0;
        s->sources[0].name = "builtin:room"; /* 12: no padding */
        s->sources[1].name = "x";            /* 1 */
        s->sources[2].name = "scenes/\xc3\xbc"
                             "bung/\xe2\x82\xac.obj";
        s->sources[3].name = "ab";  /* 2 */
        s->sources[4].name = "abc"; /* 3 */
        s->sources[5].name = s->long_name;
        s->f.source_count = 6;
    } else {
        add_stream(s, 5, VDSH_ENCODING_F32, VDSH_QUANTITY_DISTANCE, VDSH_METHOD_PAPER,
                   VDSH_WINDOW_NONE, 0, 0, 1);
        s->sources[0].name = "big";
    }
    if (kind != 1)
        s->f.source_count = 1;
    for (uint32_t i = 0; i < s->f.source_count; i++) {
        s->sources[i].size = 1000003ull * (i + 1) + (1ull << 40);
        for (int k = 0; k < 32; k++)
            s->sources[i].sha256[k] = (uint8_t)(i * 37 + k * 11 + 1);
    }
    if (kind != 2) {
        s->f.has_stats = 1;
        s->f.stats.rays_traced = 136250000000ull;
        s->f.stats.rays_missed = 12345;
        /* Counts of receivers: at most the smallest sample's 4. */
        s->f.stats.degenerate_receivers = 3;
        s->f.stats.undefined_normals = 2;
        s->f.stats.moved_origins = 1;
        s->f.stats.flipped_normals = 4;
        s->f.has_timings = 1;
        s->f.timings.load = 0.125;
        s->f.timings.refine = 1.0 / 3.0;
        s->f.timings.build = 0.0;
        s->f.timings.trace = 351.75;
        s->f.timings.total = 353.2;
        s->f.timings.threads = 2;
        s->f.has_adaptive = kind == 1;
        s->f.adaptive = (vdsh_adaptive){.tolerance = 0.08f,
                                        .min_edge = 0.1f,
                                        .max_receivers = 0,
                                        .lights = 32,
                                        .max_rounds = 8,
                                        .start_receivers = 1,
                                        .rounds = 8,
                                        .candidates = 100000};
        s->f.has_light_box = kind == 1; /* vdsh-bake --light-region */
        s->f.light_box = (vdsh_light_box){.rule = VDSH_LIGHT_REGION_BOX,
                                          .min = {-1.5f, 0.0f, -2.25f},
                                          .max = {1.5f, 3.0e5f, 0.125f}};
    }
}

static void sample_free(sample *s)
{
    free(s->pos);
    free(s->nrm);
    free(s->idx);
    for (int i = 0; i < VDSH_MAX_STREAMS; i++)
        free(s->data[i]);
    free(s->long_name);
}

static int same_f32(float a, float b)
{
    return bits_of(a) == bits_of(b);
}

/* Every field and every array of `got` against what was written. */
static void check_same_file(const vdsh_file *got, const vdsh_file *want)
{
    const vdsh_header *a = &got->header, *b = &want->header;
    CHECK(a->vertex_count == b->vertex_count);
    CHECK(a->triangle_count == b->triangle_count);
    CHECK(a->rays == b->rays);
    CHECK(a->sampling == b->sampling);
    CHECK(a->seed == b->seed);
    CHECK(same_f32(a->max_distance, b->max_distance));
    CHECK(same_f32(a->max_edge, b->max_edge));
    CHECK(a->offset_rule == b->offset_rule);
    CHECK(a->load_flags == b->load_flags);
    CHECK(a->cube_size == b->cube_size);
    CHECK(a->occluder_vertex_count == b->occluder_vertex_count);
    CHECK(a->occluder_triangle_count == b->occluder_triangle_count);
    CHECK(a->trace_flags == b->trace_flags);
    for (int k = 0; k < 3; k++) {
        CHECK(same_f32(a->bounds_min[k], b->bounds_min[k]));
        CHECK(same_f32(a->bounds_max[k], b->bounds_max[k]));
    }
    size_t v = b->vertex_count, t = b->triangle_count;
    CHECK(memcmp(got->positions, want->positions, v * 12) == 0);
    CHECK(memcmp(got->normals, want->normals, v * 12) == 0);
    CHECK(t == 0 || memcmp(got->indices, want->indices, t * 12) == 0);
    /* Every array is 16-byte aligned in the read buffer. */
    CHECK((uintptr_t)got->positions % 16 == 0);
    CHECK((uintptr_t)got->normals % 16 == 0);
    CHECK((uintptr_t)got->indices % 16 == 0);

    CHECK(got->source_count == want->source_count);
    for (uint32_t i = 0; i < got->source_count && i < want->source_count; i++) {
        CHECK(strcmp(got->sources[i].name, want->sources[i].name) == 0);
        CHECK(got->sources[i].size == want->sources[i].size);
        CHECK(memcmp(got->sources[i].sha256, want->sources[i].sha256, 32) == 0);
    }
    CHECK(got->stream_count == want->stream_count);
    for (uint32_t i = 0; i < got->stream_count && i < want->stream_count; i++) {
        const vdsh_stream *x = &got->streams[i], *y = &want->streams[i];
        CHECK(x->order == y->order);
        CHECK(x->encoding == y->encoding);
        CHECK(x->method == y->method);
        CHECK(x->quantity == y->quantity);
        CHECK(x->window == y->window);
        CHECK(same_f32(x->window_param, y->window_param));
        CHECK(same_f32(x->method_param, y->method_param));
        CHECK(same_f32(x->scale, y->scale));
        CHECK((uintptr_t)x->data % 16 == 0);
        CHECK(vdsh_stream_bytes_per_vertex(x) == (size_t)y->order * y->order *
                                                     (y->encoding == VDSH_ENCODING_F16  ? 2
                                                      : y->encoding == VDSH_ENCODING_S8 ? 1
                                                                                        : 4) ||
              (y->encoding == VDSH_ENCODING_S8S6 &&
               vdsh_stream_bytes_per_vertex(x) == (size_t[]){0, 1, 4, 8, 16, 24}[y->order]));
        CHECK(!x->coef_scales == !vdsh_encoding_quantised(y->encoding));
        if (x->coef_scales && y->coef_scales) {
            CHECK((uintptr_t)x->coef_scales % 16 == 0);
            CHECK(memcmp(x->coef_scales, y->coef_scales,
                         (size_t)y->order * y->order * sizeof(float)) == 0);
        }
        CHECK(memcmp(x->data, y->data, v * vdsh_stream_bytes_per_vertex(y)) == 0);
    }
    CHECK(!!got->has_stats == !!want->has_stats);
    if (want->has_stats) {
        CHECK(got->stats.rays_traced == want->stats.rays_traced);
        CHECK(got->stats.rays_missed == want->stats.rays_missed);
        CHECK(got->stats.degenerate_receivers == want->stats.degenerate_receivers);
        CHECK(got->stats.undefined_normals == want->stats.undefined_normals);
        CHECK(got->stats.moved_origins == want->stats.moved_origins);
        CHECK(got->stats.flipped_normals == want->stats.flipped_normals);
    }
    CHECK(!!got->has_timings == !!want->has_timings);
    if (want->has_timings) {
        CHECK(memcmp(&got->timings.load, &want->timings.load, 8) == 0);
        CHECK(memcmp(&got->timings.refine, &want->timings.refine, 8) == 0);
        CHECK(memcmp(&got->timings.build, &want->timings.build, 8) == 0);
        CHECK(memcmp(&got->timings.trace, &want->timings.trace, 8) == 0);
        CHECK(memcmp(&got->timings.total, &want->timings.total, 8) == 0);
        CHECK(got->timings.threads == want->timings.threads);
    }
    CHECK(!!got->has_adaptive == !!want->has_adaptive);
    if (want->has_adaptive)
        CHECK(memcmp(&got->adaptive, &want->adaptive, sizeof got->adaptive) == 0);
    CHECK(!!got->has_light_box == !!want->has_light_box);
    if (want->has_light_box)
        CHECK(memcmp(&got->light_box, &want->light_box, sizeof got->light_box) == 0);
}

/* ------------------------------------------------------------------ */
/* Test-side chunk surgery                                             */
/* ------------------------------------------------------------------ */

typedef struct tchunk {
    char id[5];
    uint8_t *data;
    size_t size;
} tchunk;

typedef struct tfile {
    tchunk c[80];
    int n;
} tfile;

/* Split a valid file into its chunks (payload copies). */
static void tf_parse(const uint8_t *d, size_t size, tfile *t)
{
    size_t off = 32;
    t->n = 0;
    while (off + 16 <= size) {
        tchunk *c = &t->c[t->n++];
        memcpy(c->id, d + off, 4);
        c->id[4] = 0;
        c->size = (size_t)rd64(d + off + 8);
        c->data = malloc(c->size + 1);
        memcpy(c->data, d + off + 16, c->size);
        off += 16 + ((c->size + 15) & ~(size_t)15);
    }
}

static void tf_free(tfile *t)
{
    for (int i = 0; i < t->n; i++)
        free(t->c[i].data);
    t->n = 0;
}

static int tf_find(const tfile *t, const char *id, int nth)
{
    for (int i = 0; i < t->n; i++)
        if (!memcmp(t->c[i].id, id, 4) && nth-- == 0)
            return i;
    return -1;
}

static void tf_insert(tfile *t, int at, const char *id, const void *p, size_t n)
{
    memmove(&t->c[at + 1], &t->c[at], (size_t)(t->n - at) * sizeof(tchunk));
    t->n++;
    memcpy(t->c[at].id, id, 4);
    t->c[at].id[4] = 0;
    t->c[at].data = malloc(n + 1);
    memcpy(t->c[at].data, p, n);
    t->c[at].size = n;
}

static void tf_remove(tfile *t, int at)
{
    free(t->c[at].data);
    memmove(&t->c[at], &t->c[at + 1], (size_t)(t->n - at - 1) * sizeof(tchunk));
    t->n--;
}

static uint32_t chunk_crc(const uint8_t *hdr, const uint8_t *payload, size_t padded)
{
    uint32_t crc = vdsh_crc32(0, hdr, 4);
    crc = vdsh_crc32(crc, hdr + 8, 8);
    return vdsh_crc32(crc, payload, padded);
}

/* Serialise with correct sizes, padding and CRCs. */
static uint8_t *tf_build(const tfile *t, size_t *size)
{
    size_t total = 32;
    for (int i = 0; i < t->n; i++)
        total += 16 + ((t->c[i].size + 15) & ~(size_t)15);
    uint8_t *d = calloc(1, total);
    static const uint8_t magic[8] = {0x56, 0x44, 0x53, 0x48, 0x0D, 0x0A, 0x1A, 0x0A};
    memcpy(d, magic, 8);
    wr32(d + 8, 1);
    wr32(d + 12, (uint32_t)t->n);
    wr64(d + 16, total);
    wr32(d + 28, vdsh_crc32(0, d, 28));
    size_t off = 32;
    for (int i = 0; i < t->n; i++) {
        const tchunk *c = &t->c[i];
        size_t padded = (c->size + 15) & ~(size_t)15;
        memcpy(d + off, c->id, 4);
        wr64(d + off + 8, c->size);
        memcpy(d + off + 16, c->data, c->size);
        wr32(d + off + 4, chunk_crc(d + off, d + off + 16, padded));
        off += 16 + padded;
    }
    *size = total;
    return d;
}

/* After patching bytes in place: recompute every chunk CRC (as far as the
 * stored sizes allow) and the header CRC, so only the rules can object. */
static void fix_crcs(uint8_t *d, size_t size)
{
    size_t off = 32;
    uint32_t count = rd32(d + 12);
    for (uint32_t i = 0; i < count && off + 16 <= size; i++) {
        uint64_t n = rd64(d + off + 8);
        if (n > size - off - 16)
            break;
        uint64_t padded = (n + 15) & ~(uint64_t)15;
        if (padded > size - off - 16)
            break;
        wr32(d + off + 4, chunk_crc(d + off, d + off + 16, (size_t)padded));
        off += 16 + (size_t)padded;
    }
    wr32(d + 28, vdsh_crc32(0, d, 28));
}

/* Offset of the payload of the nth chunk with this id, or 0. */
static size_t payload_of(const uint8_t *d, size_t size, const char *id, int nth)
{
    size_t off = 32;
    while (off + 16 <= size) {
        uint64_t n = rd64(d + off + 8);
        if (!memcmp(d + off, id, 4) && nth-- == 0)
            return off + 16;
        off += 16 + (size_t)((n + 15) & ~(uint64_t)15);
    }
    return 0;
}

static vdsh_result read_bytes(const uint8_t *d, size_t n, vdsh_error *err)
{
    vdsh_file *f = NULL;
    vdsh_result r = vdsh_read_memory(d, n, "t.vdsh", &f, err);
    if ((r == VDSH_OK) != (f != NULL)) {
        fprintf(stderr, "output not set/untouched as documented\n");
        failures++;
    }
    vdsh_free(f);
    return r;
}

/* ------------------------------------------------------------------ */
/* CRC                                                                 */
/* ------------------------------------------------------------------ */

static uint32_t crc_bitwise(const uint8_t *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++)
            c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return ~c;
}

static void test_crc(void)
{
    CHECK(vdsh_crc32(0, "123456789", 9) == 0xCBF43926u);
    CHECK(vdsh_crc32(0, NULL, 0) == 0);
    CHECK(vdsh_crc32(0, "a", 1) == 0xE8B7BE43u);
    /* An empty part, NULL or not, continues the CRC unchanged (zlib's
     * crc32_z alone answers 0 for NULL: the writer passes a chunk's
     * missing prefix that way). */
    CHECK(vdsh_crc32(0xCBF43926u, NULL, 0) == 0xCBF43926u);
    CHECK(vdsh_crc32(0xCBF43926u, "", 0) == 0xCBF43926u);

    uint8_t buf[1200];
    for (size_t i = 0; i < sizeof buf; i++)
        buf[i] = (uint8_t)rnd();
    /* Every length at every alignment against the bitwise definition. */
    int bad = 0;
    for (size_t off = 0; off < 16; off++)
        for (size_t n = 0; n + off <= sizeof buf && n < 1100; n++)
            bad += vdsh_crc32(0, buf + off, n) != crc_bitwise(buf + off, n);
    CHECK(bad == 0);
    /* Continuing a CRC over a split is the CRC of the whole. */
    uint32_t whole = vdsh_crc32(0, buf, sizeof buf);
    bad = 0;
    for (size_t k = 0; k <= sizeof buf; k++)
        bad += vdsh_crc32(vdsh_crc32(0, buf, k), buf + k, sizeof buf - k) != whole;
    CHECK(bad == 0);
}

/* ------------------------------------------------------------------ */
/* binary16                                                            */
/* ------------------------------------------------------------------ */

/* The value of a half pattern by its definition, in double. */
static double half_value(uint16_t h)
{
    int e = (h >> 10) & 31, m = h & 1023;
    double s = (h & 0x8000) ? -1.0 : 1.0;
    if (e == 31)
        return m ? NAN : s * INFINITY;
    if (e == 0)
        return s * ldexp(m, -24);
    return s * ldexp(1024 + m, e - 25);
}

static void test_f16(void)
{
    int bad_decode = 0, bad_roundtrip = 0, bad_nan = 0, nan_count = 0;
    for (uint32_t h = 0; h < 65536; h++) {
        float f = vdsh_f32_from_f16((uint16_t)h);
        int is_nan = ((h >> 10) & 31) == 31 && (h & 1023);
        if (is_nan) {
            nan_count++;
            uint16_t back = vdsh_f16_from_f32(f);
            /* NaN stays NaN, keeps its sign and payload, becomes quiet. */
            bad_nan += !isnan(f) ||
                       bits_of(f) != ((h & 0x8000u) << 16 | 0x7f800000u | (h & 1023u) << 13) ||
                       back != (h | 0x0200u);
            continue;
        }
        double want = half_value((uint16_t)h);
        bad_decode += !same_f32(f, (float)want) || !!signbit(f) != !!(h & 0x8000);
        bad_roundtrip += vdsh_f16_from_f32(f) != h;
    }
    CHECK(nan_count == 2046);
    CHECK(bad_decode == 0);
    CHECK(bad_roundtrip == 0);
    CHECK(bad_nan == 0);

    /* Rounding at every midpoint between neighbouring halves (both signs):
     * exactly half way goes to the even pattern, one float ulp either side
     * goes to the nearer one. 0x7bff's upper neighbour is 65536, which
     * rounds to Inf. */
    int bad_round = 0;
    for (uint32_t h = 0; h < 0x7c00; h++) {
        double a = half_value((uint16_t)h);
        double b = h == 0x7bff ? 65536.0 : half_value((uint16_t)(h + 1));
        float mid = (float)((a + b) / 2); /* exact: 12 significant bits */
        uint16_t even = (h & 1) ? (uint16_t)(h + 1) : (uint16_t)h;
        for (int sgn = 0; sgn < 2; sgn++) {
            float s = sgn ? -1.0f : 1.0f;
            uint16_t sb = sgn ? 0x8000 : 0;
            bad_round += vdsh_f16_from_f32(s * mid) != (even | sb);
            bad_round += vdsh_f16_from_f32(s * nextafterf(mid, (float)a)) != (h | sb);
            bad_round += vdsh_f16_from_f32(s * nextafterf(mid, (float)b)) != ((h + 1) | sb);
        }
    }
    CHECK(bad_round == 0);

    CHECK(vdsh_f16_from_f32(1.0f) == 0x3c00);
    CHECK(vdsh_f16_from_f32(0.1f) == 0x2e66);
    CHECK(vdsh_f16_from_f32(1.0f / 3.0f) == 0x3555);
    CHECK(vdsh_f16_from_f32(-2.0f) == 0xc000);
    CHECK(vdsh_f16_from_f32(65504.0f) == 0x7bff);
    CHECK(vdsh_f16_from_f32(65519.996f) == 0x7bff);
    CHECK(vdsh_f16_from_f32(65520.0f) == 0x7c00);
    CHECK(vdsh_f16_from_f32(1e10f) == 0x7c00);
    CHECK(vdsh_f16_from_f32(-3.4e38f) == 0xfc00);
    CHECK(vdsh_f16_from_f32(INFINITY) == 0x7c00);
    CHECK(vdsh_f16_from_f32(-INFINITY) == 0xfc00);
    CHECK((vdsh_f16_from_f32(NAN) & 0x7c00) == 0x7c00 && (vdsh_f16_from_f32(NAN) & 0x3ff) != 0);
    CHECK(vdsh_f16_from_f32(0x1p-14f) == 0x0400);
    CHECK(vdsh_f16_from_f32(0x1p-24f) == 0x0001);
    CHECK(vdsh_f16_from_f32(0x1p-25f) == 0x0000);
    CHECK(vdsh_f16_from_f32(0x1.000002p-25f) == 0x0001);
    CHECK(vdsh_f16_from_f32(0x3p-25f) == 0x0002);
    CHECK(vdsh_f16_from_f32(0x1.ffcp-15f) == 0x0400); /* 1023.5 units: even */
    CHECK(vdsh_f16_from_f32(-0.0f) == 0x8000);
    CHECK(vdsh_f16_from_f32(float_of(1)) == 0x0000); /* float subnormals */
    CHECK(vdsh_f16_from_f32(-float_of(0x7fffff)) == 0x8000);
    CHECK(vdsh_f16_from_f32(1.0009765625f) == 0x3c01);
    CHECK(vdsh_f16_from_f32(1.00048828125f) == 0x3c00); /* tie to even */
    CHECK(vdsh_f16_from_f32(1.00146484375f) == 0x3c02); /* tie to even */

#if defined(__FLT16_MANT_DIG__)
    /* Against the compiler's own conversion on random bit patterns. */
    int bad_cc = 0;
    for (int i = 0; i < 1 << 22; i++) {
        float f = float_of((uint32_t)rnd());
        if (isnan(f))
            continue;
        _Float16 c = (_Float16)f;
        uint16_t hb;
        memcpy(&hb, &c, 2);
        bad_cc += vdsh_f16_from_f32(f) != hb;
    }
    CHECK(bad_cc == 0);
#endif
}

/* All 2^32 floats against a reference that rounds in double with
 * nearbyint (ties to even in the default mode): slow, on request. */
static int exhaustive_f16(void)
{
    uint64_t bad = 0;
    for (uint64_t u = 0; u < (1ull << 32); u++) {
        float f = float_of((uint32_t)u);
        if (isnan(f))
            continue;
        double a = fabs((double)f), want = a;
        if (a != 0.0 && !isinf(a)) {
            int e = ilogb(a) < -14 ? -14 : ilogb(a);
            double ulp = ldexp(1.0, e - 10); /* half spacing at |f| */
            want = nearbyint(a / ulp) * ulp;
            if (want > 65504.0)
                want = INFINITY;
        }
        uint16_t got = vdsh_f16_from_f32(f);
        double v = (double)vdsh_f32_from_f16(got);
        bad += fabs(v) != want || !!signbit(v) != !!signbit(f);
    }
    printf("exhaustive f32 -> f16: %llu mismatches in 2^32 floats\n", (unsigned long long)bad);
    return bad == 0;
}

static void test_encode(void)
{
    float src[6] = {0.0f, 1.5f, -15.0f, 30.0f, 1e-3f, 65504.0f * 15};
    uint16_t dst[6];
    CHECK_RES(vdsh_encode_f16(src, 6, 15.0f, dst), VDSH_OK, &(vdsh_error){""});
    CHECK(dst[1] == vdsh_f16_from_f32(0.1f));
    CHECK(dst[2] == 0xbc00 && dst[3] == 0x4000);
    CHECK(dst[5] == 0x7bff);
    CHECK(vdsh_encode_f16(src, 6, 1.0f, dst) == VDSH_ERR_INVALID);
    src[5] = NAN;
    CHECK(vdsh_encode_f16(src, 6, 15.0f, dst) == VDSH_ERR_INVALID);
    src[5] = INFINITY;
    CHECK(vdsh_encode_f16(src, 6, 15.0f, dst) == VDSH_ERR_INVALID);
    CHECK(vdsh_encode_f16(src, 5, 0.0f, dst) == VDSH_ERR_ARGUMENT);
    CHECK(vdsh_encode_f16(src, 5, NAN, dst) == VDSH_ERR_ARGUMENT);
    CHECK(vdsh_encode_f16(NULL, 0, 1.0f, NULL) == VDSH_OK);
}

/* vdsh_encode_s8 on v vertices of nc coefficients: every decoded value
 * within half a step of its input (plus what a subnormal step loses),
 * scales the per-index largest |c|, stored values within -127..127. */
static void check_s8_roundtrip(const float *src, size_t v, uint32_t nc, const char *what)
{
    float scales[VDSH_MAX_COEFFS];
    int8_t *b = malloc(v * nc + 1);
    checks++;
    if (vdsh_encode_s8(src, v, nc, scales, b) != VDSH_OK) {
        fprintf(stderr, "%s:%d: s8 %s: not encoded\n", __FILE__, __LINE__, what);
        failures++;
        free(b);
        return;
    }
    long bad = 0;
    for (uint32_t i = 0; i < nc; i++) {
        float m = 0.0f;
        for (size_t k = 0; k < v; k++)
            m = fmaxf(m, fabsf(src[k * nc + i]));
        bad += scales[i] != m;
    }
    for (size_t k = 0; k < v * nc; k++) {
        float sc = scales[k % nc], step = vdsh_s8_step(sc);
        float dec = (float)b[k] * step;
        /* half a step, the step's own rounding (127 of them), and the
         * precision a subnormal step lacks */
        float tol =
            0.5f * step * (1.0f + 1e-6f) + 127.0f * fabsf(step) * 1e-7f + 128.0f * float_of(1);
        bad += b[k] == -128 || !isfinite(dec) || fabsf(dec - src[k]) > tol ||
               (src[k] == 0.0f && b[k] != 0) || (sc == 0.0f && b[k] != 0);
        if (sc > 0.0f && fabsf(src[k]) == sc)
            bad += b[k] != (src[k] > 0.0f ? 127 : -127); /* the extremes exact */
    }
    if (bad) {
        fprintf(stderr, "%s:%d: s8 %s: %ld values off\n", __FILE__, __LINE__, what, bad);
        failures++;
    }
    free(b);
}

/* vdsh_encode_quantised of encoding enc at order `order` (the first
 * order^2 of every NC = 25 values of src), decoded by vdsh_stream_decode:
 * within half a step of the input (plus what a subnormal step loses), the
 * extremes +-scale exact to the step's rounding, zeros zero. */
static void check_quant_roundtrip(uint32_t enc, const float *src25, size_t v, uint32_t order,
                                  const char *what)
{
    uint32_t nc = order * order;
    float *src = malloc(v * nc * sizeof *src + 4), out[VDSH_MAX_COEFFS];
    for (size_t k = 0; k < v; k++)
        memcpy(src + k * nc, src25 + k * 25, nc * sizeof *src);
    float scales[VDSH_MAX_COEFFS];
    uint8_t *b = malloc(v * vdsh_encoding_bytes(enc, nc) + 1);
    vdsh_stream st = {
        .order = order, .encoding = enc, .scale = 1.0f, .data = b, .coef_scales = scales};
    long bad = 0;
    checks++;
    if (vdsh_encode_quantised(enc, src, v, nc, scales, b) != VDSH_OK) {
        bad = 1;
    } else {
        for (size_t k = 0; k < v; k++) {
            vdsh_stream_decode(&st, (uint32_t)k, out);
            for (uint32_t i = 0; i < nc; i++) {
                int levels = vdsh_quant_levels(enc, i);
                float step = vdsh_quant_step(scales[i], levels), c = src[k * nc + i];
                float tol = 0.5f * step * (1.0f + 1e-6f) + (float)levels * step * 1e-7f +
                            128.0f * float_of(1);
                bad +=
                    !isfinite(out[i]) || fabsf(out[i] - c) > tol || (c == 0.0f && out[i] != 0.0f);
                if (scales[i] > 0.0f && fabsf(c) == scales[i])
                    bad += out[i] != (c > 0.0f ? 1.0f : -1.0f) * (float)levels * step;
            }
        }
    }
    if (bad) {
        fprintf(stderr, "%s:%d: %s order %u %s: %ld values off\n", __FILE__, __LINE__,
                vdsh_encoding_name(enc), order, what, bad);
        failures++;
    }
    free(src);
    free(b);
}

/* The s8 quantiser's hard cases (VDSH.md, COEF). */
static void test_encode_s8(void)
{
    enum { V = 64, NC = 25 };
    static float c[V * NC];
    int8_t b[V * NC];
    float sc[NC];
    (void)check_quant_roundtrip;
    /* all zero: scales 0, bytes 0, decoded 0 */
    memset(c, 0, sizeof c);
    check_s8_roundtrip(c, V, NC, "all zero");
    check_quant_roundtrip(VDSH_ENCODING_S8S6, c, V, 5, "s8s6 all zero");
    /* huge and tiny magnitudes, per index, side by side */
    for (int k = 0; k < V * NC; k++) {
        float u = rndf(-1.0f, 1.0f);
        switch (k % NC) {
        case 0: c[k] = u * 3.4e38f; break;
        case 1: c[k] = u * 1e-40f; break;      /* subnormal */
        case 2: c[k] = u * float_of(3); break; /* a few ulps of 0 */
        case 3: c[k] = 0.0f; break;
        case 4: c[k] = u * 1e30f; break;
        default: c[k] = u * (float)(k % NC); break;
        }
    }
    c[0] = -3.4e38f;
    check_s8_roundtrip(c, V, NC, "huge and tiny");
    check_s8_roundtrip(c, V, 9, "order 3 view");
    check_s8_roundtrip(c, 1, NC, "one vertex");
    for (uint32_t o = 1; o <= 5; o++) {
        check_quant_roundtrip(VDSH_ENCODING_S8, c, V, o, "s8 decoded");
        check_quant_roundtrip(VDSH_ENCODING_S8S6, c, V, o, "s8s6 huge and tiny");
    }
    /* s8s6 rounds bands 2+ to 31 levels: at scale 31, step 1 */
    {
        float r6[9 * 2] = {0, 0, 0, 0, 30.5f, 2.5f,  -2.5f, 0.49f, -0.51f,
                           0, 0, 0, 0, 31.0f, 31.0f, 31.0f, 31.0f, -31.0f};
        uint8_t p6[16];
        CHECK(vdsh_encode_quantised(VDSH_ENCODING_S8S6, r6, 2, 9, sc, p6) == VDSH_OK &&
              sc[4] == 31.0f && sc[0] == 0.0f);
        /* vertex 0's word: 31 (30.5, ties away), 3, -3, 0, -1 in fields
         * 0..4; vertex 1's: 31, 31, 31, 31, -31 */
        uint32_t w0 = rd32(p6 + 4), w1 = rd32(p6 + 12);
        CHECK(w0 == (31u | 3u << 6 | 61u << 12 | 0u << 18 | 63u << 24));
        CHECK(w1 == (31u | 31u << 6 | 31u << 12 | 31u << 18 | 33u << 24));
        CHECK(rd32(p6) == 0 && rd32(p6 + 8) == 0);
    }
    /* drawn rows only set the scales; an undrawn row's values are clamped
     * (huge past a subnormal scale too), the drawn rows' bytes are theirs
     * alone, and an undrawn row must still be finite */
    {
        float q[9 * 3] = {1,  -2,  0.5f, 1e-40f, 3,  -31, 4,  0, 2,  -3e38f, 7, -5,   3e38f, 1e30f,
                          62, -62, 0,    -1,     -4, 1,   -1, 0, -6, 31,     2, 0.5f, -2},
                    d[9 * 2], sq[9], sd[9];
        memcpy(d, q, sizeof d[0] * 9);
        memcpy(d + 9, q + 18, sizeof d[0] * 9);
        const uint8_t drawn[3] = {1, 0, 1};
        uint8_t pq[3 * 9], pd[2 * 9];
        for (int e = 0; e < 2; e++) {
            uint32_t enc = e ? VDSH_ENCODING_S8S6 : VDSH_ENCODING_S8;
            size_t bpv = vdsh_encoding_bytes(enc, 9);
            CHECK(vdsh_encode_quantised_drawn(enc, q, 3, 9, drawn, sq, pq) == VDSH_OK &&
                  vdsh_encode_quantised(enc, d, 2, 9, sd, pd) == VDSH_OK);
            CHECK(memcmp(sq, sd, sizeof sq) == 0 && sq[0] == 4.0f && sq[3] == 1e-40f &&
                  sq[4] == 6.0f);
            CHECK(memcmp(pq, pd, bpv) == 0 && memcmp(pq + 2 * bpv, pd + bpv, bpv) == 0);
            float row[9];
            vdsh_stream st = {
                .order = 3, .encoding = enc, .scale = 1.0f, .coef_scales = sq, .data = pq};
            vdsh_stream_decode(&st, 1, row);
            for (int i = 0; i < 9; i++) {
                float step = vdsh_quant_step(sq[i], vdsh_quant_levels(enc, i));
                float want = q[9 + i] == 0.0f
                                 ? 0.0f
                                 : (q[9 + i] > 0 ? 1.0f : -1.0f) * fminf(fabsf(q[9 + i]), sq[i]);
                CHECK(fabsf(row[i] - want) <= 0.5f * step * 1.0001f);
            }
            CHECK(vdsh_encode_quantised_drawn(enc, q, 3, 9, NULL, sq, pq) == VDSH_OK &&
                  sq[0] == 3e38f);
            q[10] = NAN;
            CHECK(vdsh_encode_quantised_drawn(enc, q, 3, 9, drawn, sq, pq) == VDSH_ERR_INVALID);
            q[10] = 7;
        }
    }
    CHECK(vdsh_encode_quantised(VDSH_ENCODING_F16, c, V, NC, sc, b) == VDSH_ERR_ARGUMENT);
    /* round to nearest, ties away from zero, at scale 127 (step 1) */
    float r[8] = {127.0f, 2.5f, -2.5f, 0.49f, -0.51f, 126.5f, -127.0f, 1e-30f};
    CHECK(vdsh_encode_s8(r, 8, 1, sc, b) == VDSH_OK && sc[0] == 127.0f);
    CHECK(b[0] == 127 && b[1] == 3 && b[2] == -3 && b[3] == 0 && b[4] == -1 && b[5] == 127 &&
          b[6] == -127 && b[7] == 0);
    /* refused: FLT_MAX's step times 127 rounds to infinity */
    c[0] = -FLT_MAX;
    CHECK(vdsh_encode_s8(c, V, NC, sc, b) == VDSH_ERR_INVALID);
    c[0] = 0.0f;
    c[7] = NAN;
    CHECK(vdsh_encode_s8(c, V, NC, sc, b) == VDSH_ERR_INVALID);
    c[7] = -INFINITY;
    CHECK(vdsh_encode_s8(c, V, NC, sc, b) == VDSH_ERR_INVALID);
    CHECK(vdsh_encode_s8(c, V, 0, sc, b) == VDSH_ERR_ARGUMENT);
    CHECK(vdsh_encode_s8(c, V, VDSH_MAX_COEFFS + 1, sc, b) == VDSH_ERR_ARGUMENT);
    CHECK(vdsh_encode_s8(NULL, 0, 4, sc, NULL) == VDSH_OK && sc[0] == 0.0f);
}

static void test_names(void)
{
    CHECK(!strcmp(vdsh_method_name(0), "paper"));
    CHECK(!strcmp(vdsh_method_name(1), "full"));
    CHECK(!strcmp(vdsh_method_name(2), "mirror"));
    CHECK(!strcmp(vdsh_method_name(3), "lsq"));
    CHECK(!strcmp(vdsh_method_name(4), "shadow"));
    CHECK(!strcmp(vdsh_method_name(5), "decision"));
    CHECK(!strcmp(vdsh_method_name(6), "?"));
    CHECK(!strcmp(vdsh_encoding_name(0), "f32"));
    CHECK(!strcmp(vdsh_encoding_name(1), "f16"));
    CHECK(!strcmp(vdsh_encoding_name(2), "s8"));
    CHECK(!strcmp(vdsh_encoding_name(3), "s8s6"));
    CHECK(!strcmp(vdsh_encoding_name(4), "cpca"));
    CHECK(!strcmp(vdsh_encoding_name(5), "?"));
    /* The encoding table: every row found by its name and its value. */
    size_t ne = 0;
    const vdsh_encoding_info *enc = vdsh_encodings(&ne);
    CHECK(ne == VDSH_ENCODING_LAST + 1);
    for (size_t i = 0; i < ne; i++) {
        CHECK(vdsh_encoding_from_name(enc[i].name) == &enc[i]);
        CHECK(vdsh_encoding_info_of(enc[i].encoding) == &enc[i]);
        CHECK(vdsh_encoding_bytes(enc[i].encoding, 25) == enc[i].bytes(25));
    }
    CHECK(!vdsh_encoding_from_name("s9") && !vdsh_encoding_from_name(NULL) &&
          !vdsh_encoding_info_of(VDSH_ENCODING_LAST + 1));
    CHECK(!strcmp(vdsh_encoding_names(), "f16, f32, s8, s8s6 or cpca"));
    CHECK(!strcmp(vdsh_quantity_name(0), "distance"));
    CHECK(!strcmp(vdsh_quantity_name(1), "distance2"));
    CHECK(!strcmp(vdsh_quantity_name(2), "log-distance"));
    CHECK(!strcmp(vdsh_quantity_name(3), "?"));
    CHECK(!strcmp(vdsh_window_name(0), "none"));
    CHECK(!strcmp(vdsh_window_name(1), "hann"));
    CHECK(!strcmp(vdsh_window_name(2), "lanczos"));
    CHECK(!strcmp(vdsh_window_name(99), "?"));
    CHECK(!strcmp(vdsh_sampling_name(0), "sphere"));
    CHECK(!strcmp(vdsh_sampling_name(1), "hemisphere"));
    CHECK(!strcmp(vdsh_sampling_name(2), "?"));
    CHECK(!strcmp(vdsh_offset_rule_name(0), "none"));
    CHECK(!strcmp(vdsh_offset_rule_name(1), "wb-avg"));
    CHECK(!strcmp(vdsh_offset_rule_name(UINT32_MAX), "?"));
    for (int r = VDSH_OK; r <= VDSH_ERR_ARGUMENT; r++)
        CHECK(vdsh_result_str((vdsh_result)r) &&
              strcmp(vdsh_result_str((vdsh_result)r), "unknown result"));
    CHECK(!strcmp(vdsh_result_str(VDSH_ERR_CRC), "CRC mismatch"));
    CHECK(vdsh_result_str((vdsh_result)99) != NULL);
}

/* ------------------------------------------------------------------ */
/* Round trips                                                         */
/* ------------------------------------------------------------------ */

/* The usage example of vdsh.h, compiled. */
static int header_example(const char *path)
{
    vdsh_file *f = NULL;
    vdsh_error err;
    vdsh_result r = vdsh_read(path, &f, &err);
    if (r != VDSH_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    const vdsh_stream *s = vdsh_find_stream(f, 5, VDSH_QUANTITY_DISTANCE);
    float c[25];
    vdsh_stream_decode(s, 0, c); /* vertex 0's 25 coefficients */
    vdsh_free(f);
    return 0;
}

static void test_roundtrip(void)
{
    char path[1024], path2[1024];
    vdsh_error err;
    sample s;
    sample_init(&s, 1, 300);
    path_in(path, sizeof path, "full.vdsh");
    CHECK_RES(vdsh_write(path, &s.f, &err), VDSH_OK, &err);

    vdsh_file *f = NULL;
    CHECK_RES(vdsh_read(path, &f, &err), VDSH_OK, &err);
    if (f) {
        check_same_file(f, &s.f);

        /* Decoding applies the scale; f16 goes through the exact
         * conversion. */
        const vdsh_stream *st = vdsh_find_stream(f, 5, VDSH_QUANTITY_DISTANCE);
        CHECK(st == &f->streams[0]);
        CHECK(vdsh_find_stream(f, 5, VDSH_QUANTITY_DISTANCE2) == &f->streams[4]);
        CHECK(vdsh_find_stream(f, 4, VDSH_QUANTITY_DISTANCE2) == NULL);
        CHECK(vdsh_find_stream(NULL, 5, 0) == NULL);
        float c[25];
        int bad = 0;
        for (uint32_t v = 0; v < 300; v++) {
            vdsh_stream_decode(st, v, c);
            const uint16_t *d = (const uint16_t *)s.data[0] + v * 25;
            for (int i = 0; i < 25; i++)
                bad += !same_f32(c[i], vdsh_f32_from_f16(d[i]) * 15.0f);
            vdsh_stream_decode(&f->streams[1], v, c);
            const float *e = (const float *)s.data[1] + v * 9;
            for (int i = 0; i < 9; i++)
                bad += !same_f32(c[i], e[i]);
        }
        CHECK(bad == 0);
        CHECK(vdsh_stream_bytes_per_vertex(&f->streams[0]) == 50);
        CHECK(vdsh_stream_bytes_per_vertex(&f->streams[1]) == 36);
        CHECK(vdsh_stream_bytes_per_vertex(&f->streams[3]) == 4);
        CHECK(vdsh_stream_bytes_per_vertex(NULL) == 0);

        /* A read file writes back to the same bytes. */
        size_t n1 = 0, n2 = 0;
        uint8_t *disk = load_file(path, &n1);
        void *mem = NULL;
        CHECK_RES(vdsh_write_memory(f, &mem, &n2, &err), VDSH_OK, &err);
        CHECK(disk && mem && n1 == n2 && memcmp(disk, mem, n1) == 0);
        free(mem);
        free(disk);
        vdsh_free(f);
    }

    /* vdsh_write_memory gives exactly the bytes vdsh_write put on disk,
     * and vdsh_read_memory reads them the same. */
    {
        size_t n1 = 0, n2 = 0;
        void *mem = NULL;
        uint8_t *disk = load_file(path, &n1);
        CHECK_RES(vdsh_write_memory(&s.f, &mem, &n2, &err), VDSH_OK, &err);
        CHECK(disk && mem && n1 == n2 && memcmp(disk, mem, n1) == 0);
        CHECK(n2 % 16 == 0);
        CHECK(rd64((const uint8_t *)mem + 16) == n2);
        f = NULL;
        CHECK_RES(vdsh_read_memory(mem, n2, NULL, &f, &err), VDSH_OK, &err);
        if (f)
            check_same_file(f, &s.f);
        vdsh_free(f);
        free(mem);
        free(disk);
    }
    CHECK(header_example(path) == 0);

    /* Determinism: the same input twice gives the same bytes. */
    path_in(path2, sizeof path2, "full2.vdsh");
    CHECK_RES(vdsh_write(path2, &s.f, &err), VDSH_OK, &err);
    {
        size_t n1 = 0, n2 = 0;
        uint8_t *a = load_file(path, &n1), *b = load_file(path2, &n2);
        CHECK(a && b && n1 == n2 && memcmp(a, b, n1) == 0);
        free(a);
        free(b);
    }

    /* Without the optional chunks, with no sources, no triangles. */
    s.f.has_stats = 0;
    s.f.has_timings = 0;
    s.f.source_count = 0;
    s.f.header.triangle_count = 0;
    s.f.indices = NULL;
    CHECK_RES(vdsh_write(path2, &s.f, &err), VDSH_OK, &err);
    f = NULL;
    CHECK_RES(vdsh_read(path2, &f, &err), VDSH_OK, &err);
    if (f) {
        check_same_file(f, &s.f);
        CHECK(f->has_stats == 0 && f->stats.rays_traced == 0);
        CHECK(f->has_timings == 0 && f->timings.threads == 0);
        CHECK(f->source_count == 0);
    }
    vdsh_free(f);
    vdsh_free(NULL);
    sample_free(&s);

    /* Every order, every encoding but cpca (tests/test_cpca.c: it needs a
     * model), one stream each. */
    for (uint32_t order = 1; order <= 5; order++)
        for (uint32_t enc = 0; enc <= VDSH_ENCODING_S8S6; enc++) {
            sample t;
            sample_init(&t, 0, 0);
            for (int i = 0; i < 2; i++) {
                free(t.data[i]);
                t.data[i] = NULL;
            }
            t.f.stream_count = 0;
            add_stream(&t, order, enc, VDSH_QUANTITY_DISTANCE2, VDSH_METHOD_FULL, VDSH_WINDOW_NONE,
                       0, 0, 2.0f);
            void *mem = NULL;
            size_t n = 0;
            CHECK_RES(vdsh_write_memory(&t.f, &mem, &n, &err), VDSH_OK, &err);
            f = NULL;
            CHECK_RES(vdsh_read_memory(mem, n, "o.vdsh", &f, &err), VDSH_OK, &err);
            if (f)
                check_same_file(f, &t.f);
            vdsh_free(f);
            free(mem);
            sample_free(&t);
        }
}

/* ------------------------------------------------------------------ */
/* The reader's rules                                                  */
/* ------------------------------------------------------------------ */

static uint8_t *small_file(size_t *n)
{
    sample s;
    void *mem = NULL;
    vdsh_error err;
    sample_init(&s, 0, 0);
    CHECK_RES(vdsh_write_memory(&s.f, &mem, n, &err), VDSH_OK, &err);
    sample_free(&s);
    return mem;
}

static void test_truncation(void)
{
    size_t n;
    uint8_t *d = small_file(&n);
    vdsh_error err;
    char path[1024];
    int rejected = 0, truncated = 0, file_rejected = 0;
    path_in(path, sizeof path, "trunc.vdsh");
    for (size_t len = 0; len < n; len++) {
        /* An exact-size copy, so ASan sees any read past the end. */
        uint8_t *c = malloc(len ? len : 1);
        memcpy(c, d, len);
        vdsh_result r = read_bytes(c, len, &err);
        rejected += r != VDSH_OK;
        truncated += r == VDSH_ERR_TRUNCATED;
        free(c);
        /* The same through a file. */
        vdsh_file *f = (vdsh_file *)&err; /* sentinel: must stay */
        save_file(path, d, len);
        r = vdsh_read(path, &f, &err);
        file_rejected += r == VDSH_ERR_TRUNCATED && f == (vdsh_file *)&err;
    }
    printf("truncation: %d of %zu lengths rejected (%d as TRUNCATED; "
           "%d through files)\n",
           rejected, n, truncated, file_rejected);
    CHECK(rejected == (int)n);
    CHECK(truncated == (int)n);
    CHECK(file_rejected == (int)n);
    CHECK_RES(read_bytes(d, n, &err), VDSH_OK, &err);
    free(d);
}

static void test_byte_changes(void)
{
    size_t n;
    uint8_t *d = small_file(&n);
    vdsh_error err;
    long cases = 0, rejected = 0, untouched = 0;
    long by_result[VDSH_ERR_ARGUMENT + 1] = {0};
    uint8_t *c = malloc(n);
    /* Every byte to every other value (CRC-32 catches every error within
     * 32 bits, the magic and version are checked before it), then every
     * single bit. */
    for (size_t i = 0; i < n; i++) {
        for (int b = 0; b < 256; b++) {
            if (b == d[i])
                continue;
            memcpy(c, d, n);
            c[i] = (uint8_t)b;
            vdsh_file *f = (vdsh_file *)c; /* sentinel */
            vdsh_result r = vdsh_read_memory(c, n, "flip.vdsh", &f, &err);
            cases++;
            rejected += r != VDSH_OK;
            untouched += f == (vdsh_file *)c;
            if (r >= 0 && r <= VDSH_ERR_ARGUMENT)
                by_result[r]++;
            if (r == VDSH_OK)
                vdsh_free(f);
        }
    }
    long bit_cases = 0, bit_rejected = 0;
    for (size_t i = 0; i < 8 * n; i++) {
        memcpy(c, d, n);
        c[i / 8] ^= (uint8_t)(1u << (i % 8));
        bit_cases++;
        bit_rejected += read_bytes(c, n, &err) != VDSH_OK;
    }
    printf("byte changes: %ld of %ld rejected in a %zu-byte file "
           "(NOT_VDSH %ld, VERSION %ld, CRC %ld, TRUNCATED %ld, CHUNK %ld, "
           "INVALID %ld); single-bit flips: %ld of %ld rejected\n",
           rejected, cases, n, by_result[VDSH_ERR_NOT_VDSH], by_result[VDSH_ERR_VERSION],
           by_result[VDSH_ERR_CRC], by_result[VDSH_ERR_TRUNCATED], by_result[VDSH_ERR_CHUNK],
           by_result[VDSH_ERR_INVALID], bit_rejected, bit_cases);
    CHECK(cases == (long)n * 255);
    CHECK(rejected == cases);
    CHECK(untouched == cases);
    CHECK(bit_rejected == bit_cases);
    free(c);
    free(d);
}

/* Patch the small file, fix the CRCs, expect `want`; `needle`, when not
 * NULL, must appear in the message. */
static void expect_patched(const uint8_t *d, size_t n, size_t at, const void *bytes, size_t k,
                           int fix, vdsh_result want, const char *needle, int line)
{
    uint8_t *c = malloc(n);
    vdsh_error err = {""};
    memcpy(c, d, n);
    memcpy(c + at, bytes, k);
    if (fix)
        fix_crcs(c, n);
    vdsh_result r = read_bytes(c, n, &err);
    checks++;
    if (r != want || (needle && !strstr(err.msg, needle))) {
        fprintf(stderr,
                "%s:%d: patch at %zu gave %s (\"%s\"), want %s "
                "with \"%s\"\n",
                __FILE__, line, at, vdsh_result_str(r), err.msg, vdsh_result_str(want),
                needle ? needle : "");
        failures++;
    }
    free(c);
}

#define PATCH32(off, v, fix, want, needle)                                                         \
    do {                                                                                           \
        uint8_t b_[4];                                                                             \
        wr32(b_, (v));                                                                             \
        expect_patched(d, n, (off), b_, 4, (fix), (want), (needle), __LINE__);                     \
    } while (0)
#define PATCHF(off, v, want, needle)                                                               \
    do {                                                                                           \
        uint8_t b_[4];                                                                             \
        wrf32(b_, (v));                                                                            \
        expect_patched(d, n, (off), b_, 4, 1, (want), (needle), __LINE__);                         \
    } while (0)

/* An s8 stream read back (pointers, decode) and what the reader refuses
 * in one: scale != 1, a scale that is negative or not finite, padding
 * after the table, a stored -128. */
static void test_s8_reading(void)
{
    sample t;
    sample_init(&t, 0, 0);
    for (int i = 0; i < 2; i++) {
        free(t.data[i]);
        t.data[i] = NULL;
    }
    t.f.stream_count = 0;
    add_stream(&t, 5, VDSH_ENCODING_S8, VDSH_QUANTITY_LOG_DISTANCE, VDSH_METHOD_SHADOW,
               VDSH_WINDOW_NONE, 0, 0.8f, 1);
    add_stream(&t, 3, VDSH_ENCODING_S8, VDSH_QUANTITY_LOG_DISTANCE, VDSH_METHOD_SHADOW,
               VDSH_WINDOW_NONE, 0, 1.1f, 1);
    add_stream(&t, 3, VDSH_ENCODING_S8S6, VDSH_QUANTITY_DISTANCE, VDSH_METHOD_LSQ, VDSH_WINDOW_NONE,
               0, 0, 1);
    void *mem = NULL;
    size_t n = 0;
    vdsh_error err;
    CHECK_RES(vdsh_write_memory(&t.f, &mem, &n, &err), VDSH_OK, &err);
    uint8_t *d = mem;
    size_t coef = payload_of(d, n, "COEF", 0), coef1 = payload_of(d, n, "COEF", 1);
    /* 48-byte header, 25 scales + 12 bytes of padding, 4 x 25 bytes */
    CHECK(coef && rd64(d + coef - 8) == 48 + 112 + 4 * 25);
    CHECK(coef1 && rd64(d + coef1 - 8) == 48 + 48 + 4 * 9);
    size_t coef2 = payload_of(d, n, "COEF", 2);
    /* s8s6 order 3: 4 bytes and one word per vertex */
    CHECK(coef2 && rd64(d + coef2 - 8) == 48 + 48 + 4 * 8);
    vdsh_file *f = NULL;
    CHECK_RES(vdsh_read_memory(d, n, "s.vdsh", &f, &err), VDSH_OK, &err);
    if (f) {
        const vdsh_stream *st = vdsh_find_stream(f, 5, VDSH_QUANTITY_LOG_DISTANCE);
        CHECK(st && st->encoding == VDSH_ENCODING_S8 && st->scale == 1.0f &&
              vdsh_stream_bytes_per_vertex(st) == 25);
        CHECK(st && st->coef_scales && (uintptr_t)st->coef_scales % 16 == 0 &&
              (uintptr_t)st->data % 16 == 0);
        for (uint32_t v = 0; st && v < 4; v++) {
            float out[25];
            vdsh_stream_decode(st, v, out);
            const int8_t *b = (const int8_t *)t.streams[0].data + 25 * v;
            for (int i = 0; i < 25; i++)
                CHECK(bits_of(out[i]) ==
                      bits_of((float)b[i] * vdsh_s8_step(t.streams[0].coef_scales[i])));
        }
        vdsh_free(f);
    }
    PATCHF(coef + 28, 2.0f, VDSH_ERR_INVALID, "scale 2 must be 1 for s8");
    PATCHF(coef + 48 + 12, NAN, VDSH_ERR_INVALID, "scale of coefficient 3 is nan");
    PATCHF(coef + 48 + 12, -1.0f, VDSH_ERR_INVALID, "scale of coefficient 3 is -1");
    PATCHF(coef + 48 + 96, INFINITY, VDSH_ERR_INVALID, "scale of coefficient 24");
    PATCHF(coef + 48 + 96, FLT_MAX, VDSH_ERR_INVALID, "127 steps overflow");
    PATCHF(coef + 48 + 96, 3.4e38f, VDSH_OK, NULL);
    PATCHF(coef + 48 + 12, 0.0f, VDSH_OK, NULL);
    PATCHF(coef + 48 + 12, -0.0f, VDSH_OK, NULL); /* -0 >= 0 */
    PATCH32(coef + 48 + 100, 1, 1, VDSH_ERR_INVALID, "padding after the scale table");
    PATCH32(coef1 + 48 + 44, 0x100, 1, VDSH_ERR_INVALID, "padding after the scale table");
    expect_patched(d, n, coef + 48 + 112 + 30, "\x80", 1, 1, VDSH_ERR_INVALID,
                   "vertex 1 coefficient 5 is -128", __LINE__);
    expect_patched(d, n, coef + 48 + 112 + 30, "\x81", 1, 1, VDSH_OK, NULL, __LINE__);
    /* s8s6: vertex 1's word (fields 4..8), a byte, the table */
    size_t w1 = coef2 + 48 + 48 + 8 + 4;
    PATCH32(w1, 32u << 6, 1, VDSH_ERR_INVALID,
            "vertex 1 coefficient 5 is -32 (s8s6 stores -31..31");
    PATCH32(w1, 1u << 30, 1, VDSH_ERR_INVALID, "vertex 1: unused bits of packed word 0");
    PATCH32(w1, 1u << 31, 1, VDSH_ERR_INVALID, "unused bits");
    PATCH32(w1, 0x3fffffffu, 1, VDSH_OK, NULL);     /* every field -1 */
    PATCH32(w1, 31u | 33u << 24, 1, VDSH_OK, NULL); /* 31 and -31 */
    expect_patched(d, n, w1 - 4, "\x80", 1, 1, VDSH_ERR_INVALID, "vertex 1 coefficient 0 is -128",
                   __LINE__);
    PATCHF(coef2 + 48 + 16, 1e38f, VDSH_OK, NULL);
    PATCHF(coef2 + 48 + 16, FLT_MAX, VDSH_ERR_INVALID, "31 steps overflow");
    PATCHF(coef2 + 28, 0.5f, VDSH_ERR_INVALID, "must be 1 for s8s6");
    free(mem);
    sample_free(&t);
}

static void expect_tf(const tfile *t, vdsh_result want, const char *needle, int line)
{
    size_t n;
    uint8_t *c = tf_build(t, &n);
    vdsh_error err = {""};
    vdsh_result r = read_bytes(c, n, &err);
    checks++;
    if (r != want || (needle && !strstr(err.msg, needle))) {
        fprintf(stderr,
                "%s:%d: crafted file gave %s (\"%s\"), want %s with "
                "\"%s\"\n",
                __FILE__, line, vdsh_result_str(r), err.msg, vdsh_result_str(want),
                needle ? needle : "");
        failures++;
    }
    free(c);
}

static void test_rules(void)
{
    size_t n;
    uint8_t *d = small_file(&n);
    vdsh_error err;
    tfile t;
    char want[256];

    size_t head = payload_of(d, n, "HEAD", 0);
    size_t srcs = payload_of(d, n, "SRCS", 0);
    size_t posn = payload_of(d, n, "POSN", 0);
    size_t norm = payload_of(d, n, "NORM", 0);
    size_t tris = payload_of(d, n, "TRIS", 0);
    size_t coef0 = payload_of(d, n, "COEF", 0);
    size_t coef1 = payload_of(d, n, "COEF", 1);
    size_t stat = payload_of(d, n, "stat", 0);
    size_t tim = payload_of(d, n, "time", 0);
    CHECK(head == 48 && srcs && posn && norm && tris && coef0 && coef1 && stat && tim);

    /* File header. */
    expect_patched(d, n, 0, "X", 1, 0, VDSH_ERR_NOT_VDSH, "wrong magic", __LINE__);
    expect_patched(d, n, 4, "\n", 1, 0, VDSH_ERR_NOT_VDSH, "text-mode", __LINE__);
    CHECK(read_bytes((const uint8_t *)"PK\3\4 not a vdsh file at all, no", 32, &err) ==
          VDSH_ERR_NOT_VDSH);
    CHECK(read_bytes((const uint8_t *)"V", 1, &err) == VDSH_ERR_TRUNCATED);
    CHECK(read_bytes((const uint8_t *)"W", 1, &err) == VDSH_ERR_NOT_VDSH);
    PATCH32(8, 2, 1, VDSH_ERR_VERSION, "format version 2");
    PATCH32(8, 2, 0, VDSH_ERR_VERSION, "header CRC fails");
    PATCH32(8, 0, 1, VDSH_ERR_VERSION, NULL);
    CHECK(read_bytes(d, 31, &err) == VDSH_ERR_TRUNCATED);
    CHECK(read_bytes(d, n - 16, &err) == VDSH_ERR_TRUNCATED);
    PATCH32(24, 1, 0, VDSH_ERR_CRC, "header CRC mismatch");
    PATCH32(24, 1, 1, VDSH_ERR_INVALID, "flags");
    PATCH32(12, 0, 1, VDSH_ERR_CHUNK, "chunk_count 0");
    PATCH32(12, 65, 1, VDSH_ERR_CHUNK, "chunk_count 65");
    PATCH32(12, rd32(d + 12) - 1, 1, VDSH_ERR_CHUNK, "after the last");
    PATCH32(12, rd32(d + 12) + 1, 1, VDSH_ERR_TRUNCATED, "past the end");
    {
        uint8_t b[8];
        wr64(b, n + 16);
        expect_patched(d, n, 16, b, 8, 1, VDSH_ERR_TRUNCATED, "header says", __LINE__);
        wr64(b, n - 16);
        expect_patched(d, n, 16, b, 8, 1, VDSH_ERR_CHUNK, "after the end", __LINE__);
        /* Trailing bytes that the header counts but no chunk covers. */
        uint8_t *c = calloc(1, n + 16);
        memcpy(c, d, n);
        wr64(c + 16, n + 16);
        fix_crcs(c, n + 16);
        CHECK(read_bytes(c, n + 16, &err) == VDSH_ERR_CHUNK);
        CHECK(read_bytes(c, n + 15, &err) == VDSH_ERR_TRUNCATED);
        free(c);
        /* A chunk size that would wrap any unchecked sum. */
        wr64(b, UINT64_MAX - 7);
        expect_patched(d, n, coef0 - 8, b, 8, 1, VDSH_ERR_TRUNCATED, "runs past the end", __LINE__);
        wr64(b, (uint64_t)n);
        expect_patched(d, n, coef0 - 8, b, 8, 1, VDSH_ERR_TRUNCATED, "runs past the end", __LINE__);
    }

    /* A flipped payload byte: CRC, and the message says where. */
    snprintf(want, sizeof want,
             "t.vdsh: chunk 5 'COEF' at offset %zu: CRC "
             "mismatch",
             coef0 - 16);
    expect_patched(d, n, coef0 + 50, "\x55", 1, 0, VDSH_ERR_CRC, want, __LINE__);
    expect_patched(d, n, coef0 - 12, "\1\2\3\4", 4, 0, VDSH_ERR_CRC, "CRC mismatch", __LINE__);
    /* Padding: TRIS has 24 bytes of payload, then 8 of padding. */
    expect_patched(d, n, tris + 24, "\1", 1, 1, VDSH_ERR_CHUNK, "TRIS' at offset", __LINE__);
    expect_patched(d, n, tris - 16, "TR1S", 4, 1, VDSH_ERR_CHUNK, "not four ASCII letters",
                   __LINE__);

    /* HEAD values. */
    PATCH32(head + 0, 0, 1, VDSH_ERR_INVALID, "vertex_count 0");
    PATCH32(head + 0, VDSH_MAX_VERTICES + 1, 1, VDSH_ERR_INVALID, "vertex_count");
    PATCH32(head + 4, VDSH_MAX_TRIANGLES + 1, 1, VDSH_ERR_INVALID, "triangle_count");
    PATCH32(head + 8, 0, 1, VDSH_ERR_INVALID, "rays");
    PATCH32(head + 12, 2, 1, VDSH_ERR_INVALID, "sampling 2");
    PATCHF(head + 24, NAN, VDSH_ERR_INVALID, "max_distance");
    PATCHF(head + 24, 0.0f, VDSH_ERR_INVALID, "max_distance");
    PATCHF(head + 24, INFINITY, VDSH_ERR_INVALID, "max_distance");
    PATCHF(head + 28, -1.0f, VDSH_ERR_INVALID, "max_edge");
    PATCH32(head + 32, 2, 1, VDSH_ERR_INVALID, "offset_rule 2");
    PATCH32(head + 36, 16, 1, VDSH_ERR_INVALID, "load_flags");
    PATCH32(head + 36, 6u << 1, 1, VDSH_ERR_INVALID, "up axis 6 unknown");
    PATCH32(head + 36, 1u | 5u << 1, 1, VDSH_OK, NULL); /* welded, -y up */
    PATCH32(head + 52, 0x80000000u, 1, VDSH_ERR_INVALID, "trace_flags");
    PATCHF(head + 60, NAN, VDSH_ERR_INVALID, "bounds");
    PATCHF(head + 68, -100.0f, VDSH_ERR_INVALID, "bounds_min[0]");
    PATCH32(head + 124, 1, 1, VDSH_ERR_INVALID, "reserved");
    /* The vertex count must match the arrays. */
    PATCH32(head + 0, 5, 1, VDSH_ERR_CHUNK, "POSN: payload is 48 bytes");
    PATCH32(head + 4, 3, 1, VDSH_ERR_CHUNK, "TRIS: payload is 24 bytes");

    /* Arrays. */
    PATCHF(posn + 12, NAN, VDSH_ERR_INVALID, "t.vdsh: POSN: vertex 1 has a non-finite coordinate");
    PATCHF(posn + 44, -INFINITY, VDSH_ERR_INVALID, "POSN: vertex 3");
    PATCHF(norm + 0, INFINITY, VDSH_ERR_INVALID, "NORM");
    PATCHF(norm + 0, 0.5f, VDSH_ERR_INVALID, "NORM: normal of vertex 0");
    PATCHF(norm + 12, 1e-30f, VDSH_ERR_INVALID, "NORM: normal of vertex 1");
    PATCH32(tris + 8, 4, 1, VDSH_ERR_INVALID,
            "t.vdsh: TRIS: index 4 out of range (4 vertices) in triangle 0");
    PATCH32(tris + 20, UINT32_MAX, 1, VDSH_ERR_INVALID,
            "index 4294967295 out of range (4 vertices) in triangle 1");

    /* Streams. */
    PATCH32(coef0 + 0, VDSH_MAX_ORDER + 1, 1, VDSH_ERR_INVALID, "order 17");
    PATCH32(coef0 + 0, 0, 1, VDSH_ERR_INVALID, "order 0");
    PATCH32(coef0 + 0, 1, 1, VDSH_ERR_CHUNK, "need 16");
    PATCH32(coef0 + 4, 5, 1, VDSH_ERR_INVALID, "encoding 5");
    /* f32 -> s8: 16 bytes of table and 32 of data make 48, not 32 + 16 */
    PATCH32(coef0 + 4, 2, 1, VDSH_ERR_CHUNK, "of s8 need 32");
    PATCH32(coef0 + 4, 1, 1, VDSH_ERR_CHUNK, "need 32");
    PATCH32(coef0 + 12, 3, 1, VDSH_ERR_INVALID, "quantity 3");
    /* A log-distance stream needs its floor; a distance stream has none. */
    PATCH32(coef0 + 12, 2, 1, VDSH_ERR_INVALID, "quantity_param 0 must be the log floor");
    PATCHF(coef0 + 32, 0.5f, VDSH_ERR_INVALID, "quantity_param 0.5 must be 0");
    PATCH32(coef0 + 16, 3, 1, VDSH_ERR_INVALID, "window 3");
    PATCHF(coef0 + 20, 1.0f, VDSH_ERR_INVALID, "without a window");
    PATCHF(coef1 + 20, NAN, VDSH_ERR_INVALID, "window_param");
    PATCHF(coef0 + 24, INFINITY, VDSH_ERR_INVALID, "method_param");
    PATCHF(coef0 + 28, 0.0f, VDSH_ERR_INVALID, "scale");
    PATCHF(coef0 + 28, -1.0f, VDSH_ERR_INVALID, "scale");
    PATCHF(coef0 + 28, 1e30f, VDSH_ERR_INVALID, "overflows"); /* 1e30 data */
    PATCH32(coef0 + 44, 1, 1, VDSH_ERR_INVALID, "reserved");
    PATCHF(coef0 + 48 + 4 * 5, NAN, VDSH_ERR_INVALID, "vertex 1 coefficient 1 is not finite");
    {
        uint8_t h[2] = {0x00, 0x7c}; /* f16 +Inf */
        expect_patched(d, n, coef1 + 48 + 2 * 3, h, 2, 1, VDSH_ERR_INVALID,
                       "vertex 3 coefficient 0 is not finite", __LINE__);
        h[0] = 0x01; /* f16 NaN */
        expect_patched(d, n, coef1 + 48, h, 2, 1, VDSH_ERR_INVALID, "not finite", __LINE__);
    }
    /* A method this reader does not know is still readable. */
    PATCH32(coef0 + 8, 7, 1, VDSH_OK, NULL);

    /* SRCS. */
    PATCH32(srcs + 0, 65, 1, VDSH_ERR_INVALID, "count 65");
    PATCH32(srcs + 0, 2, 1, VDSH_ERR_CHUNK, "source 1 runs past");
    PATCH32(srcs + 0, 0, 1, VDSH_ERR_CHUNK, "after the last source");
    PATCH32(srcs + 44, 0, 1, VDSH_ERR_INVALID, "name_length 0");
    PATCH32(srcs + 44, 4097, 1, VDSH_ERR_INVALID, "name_length 4097");
    PATCH32(srcs + 44, UINT32_MAX, 1, VDSH_ERR_INVALID, "name_length");
    PATCH32(srcs + 44, 9, 1, VDSH_ERR_CHUNK, "name runs past");
    PATCH32(srcs + 44, 4, 1, VDSH_ERR_CHUNK, "after the last source");
    expect_patched(d, n, srcs + 49, "", 1, 1, VDSH_ERR_INVALID, "NUL", __LINE__);
    expect_patched(d, n, srcs + 48, "\xff", 1, 1, VDSH_ERR_INVALID, "UTF-8", __LINE__);
    expect_patched(d, n, srcs + 48, "\xc0\xaf", 2, 1, VDSH_ERR_INVALID, "UTF-8", __LINE__);
    expect_patched(d, n, srcs + 48, "\xed\xa0\x80", 3, 1, VDSH_ERR_INVALID, "UTF-8", __LINE__);
    expect_patched(d, n, srcs + 48 + 5, "z", 1, 1, VDSH_ERR_CHUNK, "name padding", __LINE__);

    /* Ancillary chunks we know. */
    PATCH32(stat + 28, 0xffffffffu, 1, VDSH_ERR_INVALID,
            "stat: flipped_normals 4294967295 exceeds");
    PATCH32(stat + 12, 0x7fffffffu, 1, VDSH_ERR_INVALID, "rays missed of");
    PATCH32(tim + 4, 0x7ff80000u, 1, VDSH_ERR_INVALID, "time: load"); /* NaN */
    PATCH32(tim + 20, 0x7ff00000u, 1, VDSH_ERR_INVALID, "time: build");
    PATCH32(tim + 60, 1, 1, VDSH_ERR_INVALID, "time: reserved");
    {
        uint8_t b[8];
        double neg = -1.0;
        memcpy(b, &neg, 8);
        expect_patched(d, n, tim + 32, b, 8, 1, VDSH_ERR_INVALID, "time: total", __LINE__);
    }

    /* Chunk structure, rebuilt with correct CRCs. */
    tf_parse(d, n, &t);
    CHECK(t.n == 9);
    {
        size_t m;
        uint8_t *c = tf_build(&t, &m);
        CHECK(m == n && memcmp(c, d, n) == 0); /* the test's encoder agrees */
        free(c);
    }
    tchunk tmp;

    tmp = t.c[0], t.c[0] = t.c[1], t.c[1] = tmp; /* SRCS, HEAD, ... */
    expect_tf(&t, VDSH_ERR_CHUNK, "HEAD must come first", __LINE__);
    tmp = t.c[0], t.c[0] = t.c[1], t.c[1] = tmp;
    expect_tf(&t, VDSH_OK, NULL, __LINE__);

    /* Other chunks in any order are fine (only HEAD's place is fixed). */
    tmp = t.c[2], t.c[2] = t.c[7], t.c[7] = tmp;
    expect_tf(&t, VDSH_OK, NULL, __LINE__);
    tmp = t.c[2], t.c[2] = t.c[7], t.c[7] = tmp;

    static const char *const required[] = {"SRCS", "POSN", "NORM", "TRIS"};
    for (int k = 0; k < 4; k++) {
        int at = tf_find(&t, required[k], 0);
        tchunk saved = t.c[at];
        tf_insert(&t, at, required[k], saved.data, saved.size);
        expect_tf(&t, VDSH_ERR_CHUNK, "a second", __LINE__);
        tf_remove(&t, at);
        /* Missing: the chunk renamed to an (unknown, skipped) ancillary. */
        t.c[at].id[0] = (char)(t.c[at].id[0] + 32);
        snprintf(want, sizeof want, "no %s chunk", required[k]);
        expect_tf(&t, VDSH_ERR_CHUNK, want, __LINE__);
        t.c[at].id[0] = (char)(t.c[at].id[0] - 32);
    }
    tf_insert(&t, 3, "HEAD", t.c[0].data, t.c[0].size);
    expect_tf(&t, VDSH_ERR_CHUNK, "second HEAD", __LINE__);
    tf_remove(&t, 3);
    {
        int s = tf_find(&t, "stat", 0), ti = tf_find(&t, "time", 0);
        tf_insert(&t, t.n, "stat", t.c[s].data, t.c[s].size);
        expect_tf(&t, VDSH_ERR_CHUNK, "second stat", __LINE__);
        tf_remove(&t, t.n - 1);
        tf_insert(&t, t.n, "time", t.c[ti].data, t.c[ti].size);
        expect_tf(&t, VDSH_ERR_CHUNK, "second time", __LINE__);
        tf_remove(&t, t.n - 1);
        t.c[s].size = 31;
        expect_tf(&t, VDSH_ERR_CHUNK, "stat: payload is 31", __LINE__);
        t.c[s].size = 32;
        t.c[ti].size = 63;
        expect_tf(&t, VDSH_ERR_CHUNK, "time: payload is 63", __LINE__);
        t.c[ti].size = 64;
    }
    /* Duplicate (order, quantity). */
    {
        int c0 = tf_find(&t, "COEF", 0);
        tf_insert(&t, c0, "COEF", t.c[c0].data, t.c[c0].size);
        expect_tf(&t, VDSH_ERR_INVALID, "second stream for order 2 distance", __LINE__);
        tf_remove(&t, c0);
        int c1 = tf_find(&t, "COEF", 1);
        t.c[c1].id[0] = 'c';
        t.c[c0].id[0] = 'c';
        expect_tf(&t, VDSH_ERR_CHUNK, "no COEF chunk", __LINE__);
        t.c[c1].id[0] = 'C';
        t.c[c0].id[0] = 'C';
        t.c[c0].size = 40;
        expect_tf(&t, VDSH_ERR_CHUNK, "shorter than the 48-byte", __LINE__);
        t.c[c0].size = 48 + 64;
        int h = tf_find(&t, "HEAD", 0);
        t.c[h].size = 127;
        expect_tf(&t, VDSH_ERR_CHUNK, "HEAD: payload is 127", __LINE__);
        t.c[h].size = 128;
        int s = tf_find(&t, "SRCS", 0);
        t.c[s].size = 3;
        expect_tf(&t, VDSH_ERR_CHUNK, "SRCS: payload of 3", __LINE__);
        t.c[s].size = 4 + 44 + 8;
    }
    /* Unknown chunks: critical rejects, ancillary is skipped. */
    tf_insert(&t, t.n, "ABCD", "xyz", 3);
    expect_tf(&t, VDSH_ERR_CHUNK, "chunk 9 'ABCD' at offset", __LINE__);
    t.c[t.n - 1].id[0] = 'a';
    expect_tf(&t, VDSH_OK, NULL, __LINE__);
    tf_insert(&t, 3, "zzzz", "", 0); /* empty ancillary, between arrays */
    expect_tf(&t, VDSH_OK, NULL, __LINE__);
    {
        size_t m;
        uint8_t *c = tf_build(&t, &m);
        vdsh_file *f = NULL;
        CHECK_RES(vdsh_read_memory(c, m, "anc.vdsh", &f, &err), VDSH_OK, &err);
        if (f) {
            sample s;
            sample_init(&s, 0, 0);
            check_same_file(f, &s.f);
            sample_free(&s);
        }
        vdsh_free(f);
        free(c);
    }
    {
        int s = tf_find(&t, "stat", 0);
        t.c[s].id[0] = 'S'; /* "Stat": critical and unknown */
        expect_tf(&t, VDSH_ERR_CHUNK, "unknown critical", __LINE__);
        t.c[s].id[0] = 's';
    }
    /* More than 64 chunks. */
    while (t.n <= 64)
        tf_insert(&t, t.n, "junk", "", 0);
    expect_tf(&t, VDSH_ERR_CHUNK, "chunk_count 65", __LINE__);
    tf_free(&t);

    /* Reading errors that are not about the bytes. */
    vdsh_file *f = (vdsh_file *)&t; /* sentinel */
    char path[1024];
    path_in(path, sizeof path, "does-not-exist.vdsh");
    CHECK(vdsh_read(path, &f, &err) == VDSH_ERR_IO);
    CHECK(strstr(err.msg, path) && strstr(err.msg, strerror(ENOENT)));
    CHECK(vdsh_read(tmpdir, &f, &err) == VDSH_ERR_IO);
    CHECK(strstr(err.msg, "not a regular file"));
    CHECK(f == (vdsh_file *)&t);
    CHECK(vdsh_read_memory(NULL, 0, NULL, &f, &err) == VDSH_ERR_TRUNCATED);
    CHECK(strncmp(err.msg, "memory: ", 8) == 0);
    CHECK(vdsh_read_memory(d, n, NULL, NULL, &err) == VDSH_ERR_ARGUMENT);
    CHECK(vdsh_read_memory(d, 1, NULL, &f, NULL) == VDSH_ERR_TRUNCATED);
    CHECK(f == (vdsh_file *)&t);
    free(d);
}

/* Random byte changes with the CRCs recomputed, so the value rules are
 * what stands between the data and the caller. Whatever the reader
 * accepts, the writer must accept too and write back identically. */
static void test_mutations(void)
{
    size_t n;
    uint8_t *d = small_file(&n);
    uint8_t *c = malloc(n);
    vdsh_error err;
    long accepted = 0, rounds = 40000, consistent = 0;
    rng_state = 12345;
    for (long i = 0; i < rounds; i++) {
        memcpy(c, d, n);
        int k = 1 + (int)(rnd() % 4);
        for (int j = 0; j < k; j++) {
            size_t at = 32 + (size_t)(rnd() % (n - 32));
            uint64_t r = rnd();
            /* Mostly small numbers and special floats, which the rules
             * care about, rather than uniform noise. */
            static const uint8_t special[] = {0x00, 0x01, 0x02, 0x7f, 0x80,
                                              0xff, 0x7c, 0xfe, 0x3f, 0xc0};
            c[at] = (r & 1) ? special[(r >> 8) % sizeof special] : (uint8_t)(r >> 16);
        }
        fix_crcs(c, n);
        vdsh_file *f = NULL;
        if (vdsh_read_memory(c, n, "m.vdsh", &f, &err) != VDSH_OK)
            continue;
        accepted++;
        void *mem = NULL, *mem2 = NULL;
        size_t m = 0, m2 = 0;
        vdsh_file *g = NULL;
        if (vdsh_write_memory(f, &mem, &m, &err) == VDSH_OK &&
            vdsh_read_memory(mem, m, "m2.vdsh", &g, &err) == VDSH_OK &&
            vdsh_write_memory(g, &mem2, &m2, &err) == VDSH_OK && m == m2 &&
            memcmp(mem, mem2, m) == 0) {
            consistent++;
        } else {
            fprintf(stderr,
                    "mutation %ld: accepted but not rewritable: "
                    "%s\n",
                    i, err.msg);
        }
        vdsh_free(g);
        vdsh_free(f);
        free(mem);
        free(mem2);
    }
    printf("mutations with fixed CRCs: %ld rounds, %ld accepted, all "
           "rewritable: %s\n",
           rounds, accepted, consistent == accepted ? "yes" : "NO");
    CHECK(consistent == accepted);
    CHECK(accepted > 0 && accepted < rounds);
    free(c);
    free(d);
}

static void test_scan(void)
{
    size_t n;
    uint8_t *d = small_file(&n);
    vdsh_error err;
    vdsh_chunk_info info[16];
    uint32_t count = 0;
    static const char *const ids[9] = {"HEAD", "SRCS", "POSN", "NORM", "TRIS",
                                       "COEF", "COEF", "stat", "time"};
    CHECK_RES(vdsh_scan_chunks(d, n, "s.vdsh", info, 16, &count, &err), VDSH_OK, &err);
    CHECK(count == 9);
    uint64_t off = 32;
    for (uint32_t i = 0; i < count && i < 9; i++) {
        CHECK(!strcmp(info[i].id, ids[i]));
        CHECK(info[i].complete);
        CHECK(info[i].offset == off);
        CHECK(info[i].crc_stored == info[i].crc_computed);
        off += 16 + ((info[i].size + 15) & ~(uint64_t)15);
    }
    CHECK(off == n);
    CHECK(info[0].size == 128);

    count = 0;
    CHECK(vdsh_scan_chunks(d, n, NULL, info, 2, &count, &err) == VDSH_OK);
    CHECK(count == 9);
    CHECK(vdsh_scan_chunks(d, n, NULL, NULL, 0, &count, &err) == VDSH_OK);
    CHECK(count == 9);

    /* A changed payload byte shows as exactly one mismatch. */
    uint8_t *c = malloc(n);
    memcpy(c, d, n);
    c[payload_of(d, n, "NORM", 0) + 3] ^= 0x10;
    wr32(c + 12, 77); /* and a broken header does not stop the walk */
    CHECK(vdsh_scan_chunks(c, n, NULL, info, 16, &count, &err) == VDSH_OK);
    int mism = 0;
    for (uint32_t i = 0; i < count; i++)
        mism += info[i].crc_stored != info[i].crc_computed;
    CHECK(count == 9 && mism == 1 && info[3].crc_stored != info[3].crc_computed);
    /* Cut in the middle of a chunk: listed as incomplete, walk stops. */
    size_t cut = payload_of(d, n, "TRIS", 0) + 4;
    CHECK(vdsh_scan_chunks(d, cut, NULL, info, 16, &count, &err) == VDSH_OK);
    CHECK(count == 5 && !info[4].complete && info[4].crc_computed == 0);
    count = 1234;
    CHECK(vdsh_scan_chunks(d, 20, NULL, info, 16, &count, &err) == VDSH_ERR_TRUNCATED);
    CHECK(vdsh_scan_chunks("hello", 5, NULL, info, 16, &count, &err) == VDSH_ERR_NOT_VDSH);
    CHECK(vdsh_scan_chunks(NULL, 0, NULL, info, 16, &count, &err) == VDSH_ERR_TRUNCATED);
    CHECK(count == 1234); /* untouched on failure */
    CHECK(vdsh_scan_chunks(d, 32, NULL, info, 16, &count, &err) == VDSH_OK);
    CHECK(count == 0);
    free(c);
    free(d);
}

/* ------------------------------------------------------------------ */
/* The writer's checks and atomic writing                              */
/* ------------------------------------------------------------------ */

static void expect_rejected(sample *s, const char *needle, int line)
{
    char path[1024];
    vdsh_error err = {""};
    void *mem = (void *)&err;
    size_t size = 4321;
    path_in(path, sizeof path, "rejected.vdsh");
    vdsh_result r = vdsh_write(path, &s->f, &err);
    checks++;
    if (r != VDSH_ERR_ARGUMENT || !strstr(err.msg, needle) ||
        !strstr(err.msg, "rejected.vdsh: not written: ") || file_exists(path) ||
        count_tmp_files(tmpdir) != 0) {
        fprintf(stderr,
                "%s:%d: writer gave %s (\"%s\"), want ARGUMENT with "
                "\"%s\" and no file\n",
                __FILE__, line, vdsh_result_str(r), err.msg, needle);
        failures++;
    }
    r = vdsh_write_memory(&s->f, &mem, &size, &err);
    CHECK(r == VDSH_ERR_ARGUMENT && mem == (void *)&err && size == 4321);
    sample_free(s);
}

#define REJECT(needle, ...)                                                                        \
    do {                                                                                           \
        sample s_;                                                                                 \
        sample_init(&s_, 0, 0);                                                                    \
        __VA_ARGS__;                                                                               \
        expect_rejected(&s_, (needle), __LINE__);                                                  \
    } while (0)

static void test_writer_checks(void)
{
    char long_name[VDSH_MAX_NAME + 2];
    memset(long_name, 'q', sizeof long_name - 1);
    long_name[sizeof long_name - 1] = 0;

    REJECT("vertex_count 0", s_.f.header.vertex_count = 0);
    REJECT("adpt: tolerance", s_.f.has_adaptive = 1, s_.f.adaptive.tolerance = NAN);
    REJECT("adpt: tolerance", s_.f.has_adaptive = 1, s_.f.adaptive.tolerance = -0.5f);
    REJECT("adpt: min_edge", s_.f.has_adaptive = 1, s_.f.adaptive.min_edge = 0.0f);
    REJECT("adpt: min_edge", s_.f.has_adaptive = 1, s_.f.adaptive.min_edge = INFINITY);
    REJECT("over the budget", s_.f.has_adaptive = 1, s_.f.adaptive.max_receivers = 3);
    REJECT("adpt: started from", s_.f.has_adaptive = 1, s_.f.adaptive.start_receivers = 0);
    REJECT("adpt: started from", s_.f.has_adaptive = 1, s_.f.adaptive.start_receivers = 5);
    REJECT("rounds", s_.f.has_adaptive = 1, s_.f.adaptive.rounds = 9);
    REJECT("lights", s_.f.has_adaptive = 1, s_.f.adaptive.lights = 0);
    REJECT("midpoints", s_.f.has_adaptive = 1, s_.f.adaptive.candidates = 0);
#define LBOX(...)                                                                                  \
    s_.f.has_light_box = 1,                                                                        \
    s_.f.light_box = (vdsh_light_box){.rule = 2, .min = {0, 0, 0}, .max = {1, 1, 1}}, __VA_ARGS__
    REJECT("lreg: rule", LBOX(s_.f.light_box.rule = 0));
    REJECT("lreg: rule", LBOX(s_.f.light_box.rule = 3));
    REJECT("lreg: axis 0", LBOX(s_.f.light_box.min[0] = NAN));
    REJECT("lreg: axis 1", LBOX(s_.f.light_box.max[1] = 0.0f));
    REJECT("lreg: axis 2", LBOX(s_.f.light_box.max[2] = INFINITY));
#undef LBOX
    /* The same rule as the readers of --light-region and the runtime
     * apply it to a box they are given: the first axis that fails. */
    {
        const float lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, flat[3] = {1, 0, 1};
        const float nan_y[3] = {1, NAN, 1}, inf_z[3] = {1, 1, INFINITY};
        CHECK(vdsh_light_box_bad_axis(lo, hi) == -1);
        CHECK(vdsh_light_box_bad_axis(hi, lo) == 0);
        CHECK(vdsh_light_box_bad_axis(lo, flat) == 1);
        CHECK(vdsh_light_box_bad_axis(lo, nan_y) == 1);
        CHECK(vdsh_light_box_bad_axis(lo, inf_z) == 2);
    }
    REJECT("triangle_count", s_.f.header.triangle_count = (1u << 28) + 1);
    REJECT("rays", s_.f.header.rays = 0);
    REJECT("sampling", s_.f.header.sampling = 2);
    REJECT("max_distance", s_.f.header.max_distance = 0);
    REJECT("max_distance", s_.f.header.max_distance = NAN);
    REJECT("max_edge", s_.f.header.max_edge = -1);
    REJECT("offset_rule", s_.f.header.offset_rule = 9);
    REJECT("load_flags", s_.f.header.load_flags = 16);
    REJECT("up axis 7", s_.f.header.load_flags = 7u << 1);
    REJECT("crease angle 180", s_.f.header.load_flags = 180u << VDSH_LOAD_CREASE_SHIFT);
    REJECT("unknown bits", s_.f.header.load_flags = 1u << 16);
    REJECT("trace_flags", s_.f.header.trace_flags = 3);
    REJECT("bounds", s_.f.header.bounds_min[2] = INFINITY);
    REJECT("bounds_min[1]", s_.f.header.bounds_min[1] = 7);
    REJECT("positions is NULL", s_.f.positions = NULL);
    REJECT("normals is NULL", s_.f.normals = NULL);
    REJECT("indices is NULL", s_.f.indices = NULL);
    REJECT("POSN: vertex 2", s_.pos[7] = NAN);
    REJECT("NORM: normal of vertex 1", s_.nrm[4] = INFINITY);
    REJECT("NORM: normal of vertex 3", s_.nrm[9] = 0.5f; s_.nrm[10] = 0.5f; s_.nrm[11] = 0.5f);
    REJECT("TRIS: index 4 out of range (4 vertices) in triangle 1", s_.idx[4] = 4);
    REJECT("source_count 65", s_.f.source_count = 65);
    REJECT("sources is NULL", s_.f.sources = NULL);
    REJECT("name is NULL", s_.sources[0].name = NULL);
    REJECT("name length 0", s_.sources[0].name = "");
    REJECT("name length 4097", s_.sources[0].name = long_name);
    REJECT("UTF-8", s_.sources[0].name = "caf\xe9.obj");
    REJECT("UTF-8", s_.sources[0].name = "\xf4\x90\x80\x80"); /* >10FFFF */
    REJECT("stream_count 0", s_.f.stream_count = 0);
    REJECT("stream_count 17", s_.f.stream_count = 17);
    REJECT("streams is NULL", s_.f.streams = NULL);
    REJECT("order 0", s_.streams[0].order = 0);
    REJECT("order 17", s_.streams[1].order = VDSH_MAX_ORDER + 1);
    REJECT("encoding 5", s_.streams[0].encoding = 5);
    REJECT("s8s6 without coef_scales", s_.streams[0].encoding = VDSH_ENCODING_S8S6);
    REJECT("s8 without coef_scales", s_.streams[0].encoding = VDSH_ENCODING_S8);
    REJECT("quantity 3", s_.streams[0].quantity = 3);
    REJECT("window 3", s_.streams[0].window = 3);
    REJECT("without a window", s_.streams[0].window_param = 0.5f);
    REJECT("with a window",
           (s_.streams[0].window = VDSH_WINDOW_HANN, s_.streams[0].window_param = 0.0f));
    REJECT("with a window",
           (s_.streams[0].window = VDSH_WINDOW_LANCZOS, s_.streams[0].window_param = -3.0f));
    REJECT("window_param", s_.streams[1].window_param = NAN);
    REJECT("method_param", s_.streams[1].method_param = -INFINITY);
    REJECT("scale", s_.streams[0].scale = 0);
    REJECT("scale", s_.streams[0].scale = -2);
    REJECT("scale", s_.streams[0].scale = INFINITY);
    REJECT("quantity_param 0.5 must be 0", s_.streams[0].quantity_param = 0.5f);
    REJECT("data is NULL", s_.streams[1].data = NULL);
    REJECT("streams 0 and 1 are both order 2 distance", s_.streams[1] = s_.streams[0]);
    REJECT("vertex 2 coefficient 3 is not finite", ((float *)s_.data[0])[11] = NAN);
    REJECT("vertex 3 coefficient 0 is not finite (f16 0x7c00)",
           ((uint16_t *)s_.data[1])[3] = 0x7c00);
    REJECT("not finite", ((uint16_t *)s_.data[1])[0] = 0xfe00);
    REJECT("overflows", ((float *)s_.data[0])[5] = 3e38f; s_.streams[0].scale = 10);
    REJECT("time: trace", s_.f.timings.trace = NAN);
    REJECT("time: load", s_.f.timings.load = -0.5);

    /* Optional chunks and unknown methods are fine. */
    {
        sample s;
        vdsh_error err;
        void *mem = NULL;
        size_t n = 0;
        sample_init(&s, 0, 0);
        s.streams[0].method = 42;
        s.f.has_timings = 0;
        s.f.timings.load = NAN; /* ignored without has_timings */
        CHECK_RES(vdsh_write_memory(&s.f, &mem, &n, &err), VDSH_OK, &err);
        free(mem);
        sample_free(&s);
    }
    vdsh_error err = {""};
    void *mem = (void *)&err;
    size_t size = 1;
    CHECK(vdsh_write_memory(NULL, &mem, &size, &err) == VDSH_ERR_ARGUMENT);
    CHECK(mem == (void *)&err && size == 1);
    CHECK(vdsh_write(NULL, NULL, &err) == VDSH_ERR_ARGUMENT);
    CHECK(count_tmp_files(tmpdir) == 0);
}

static int same_file_bytes(const char *path, const void *want, size_t n)
{
    size_t m = 0;
    uint8_t *b = load_file(path, &m);
    int same = b && m == n && memcmp(b, want, n) == 0;
    free(b);
    return same;
}

static void test_atomic(void)
{
    char sub[1024], path[1100];
    vdsh_error err;
    sample a, b;
    void *old = NULL;
    size_t old_n = 0;
    sample_init(&a, 0, 0);
    sample_init(&b, 1, 2000);
    CHECK_RES(vdsh_write_memory(&a.f, &old, &old_n, &err), VDSH_OK, &err);

    path_in(sub, sizeof sub, "atomic");
    CHECK(mkdir(sub, 0700) == 0);
    snprintf(path, sizeof path, "%s/scene.vdsh", sub);

    /* A new file gets the permissions any new file gets (umask). */
    mode_t old_mask = umask(022);
    CHECK_RES(vdsh_write(path, &a.f, &err), VDSH_OK, &err);
    struct stat st;
    CHECK(stat(path, &st) == 0 && (st.st_mode & 0777) == 0644);
    umask(old_mask);
    CHECK(same_file_bytes(path, old, old_n));

    /* Overwriting works and replaces the whole file. */
    CHECK_RES(vdsh_write(path, &b.f, &err), VDSH_OK, &err);
    vdsh_file *f = NULL;
    CHECK_RES(vdsh_read(path, &f, &err), VDSH_OK, &err);
    if (f)
        check_same_file(f, &b.f);
    vdsh_free(f);
    CHECK_RES(vdsh_write(path, &a.f, &err), VDSH_OK, &err);
    CHECK(same_file_bytes(path, old, old_n));

    /* Read-only directory: the old file must survive. Privileged users
     * (root in a container) can write anyway; then there is nothing to
     * observe and the case is reported as skipped. */
    CHECK(chmod(sub, 0555) == 0);
    char probe[1200];
    snprintf(probe, sizeof probe, "%s/probe", sub);
    int pfd = open(probe, O_WRONLY | O_CREAT | O_EXCL, 0600);
    if (pfd >= 0) {
        close(pfd);
        unlink(probe);
        printf("atomic: read-only directory case skipped (privileged user "
               "can write there)\n");
    } else {
        CHECK(vdsh_write(path, &b.f, &err) == VDSH_ERR_IO);
        CHECK(strstr(err.msg, path) && strstr(err.msg, strerror(EACCES)));
        CHECK(same_file_bytes(path, old, old_n));
        printf("atomic: read-only directory refused, old file intact\n");
    }
    CHECK(chmod(sub, 0700) == 0);
    CHECK(count_tmp_files(sub) == 0);

    /* A write that fails half way (file size limit): old file intact, no
     * temporary left. This works for root too. */
    {
        struct rlimit saved, small;
        void (*old_handler)(int) = signal(SIGXFSZ, SIG_IGN);
        getrlimit(RLIMIT_FSIZE, &saved);
        small = saved;
        small.rlim_cur = 4096;
        CHECK(setrlimit(RLIMIT_FSIZE, &small) == 0);
        vdsh_result r = vdsh_write(path, &b.f, &err);
        setrlimit(RLIMIT_FSIZE, &saved);
        signal(SIGXFSZ, old_handler);
        CHECK(r == VDSH_ERR_IO);
        CHECK(strstr(err.msg, "cannot write temporary file") != NULL);
        CHECK(same_file_bytes(path, old, old_n));
        CHECK(count_tmp_files(sub) == 0);
    }

    /* The target is a (non-empty) directory: refused before anything is
     * written (vdsh_output.h; tests/test_output.c makes the rename itself
     * fail), no temporary left, directory untouched. */
    {
        char dirpath[1200], inner[1300];
        snprintf(dirpath, sizeof dirpath, "%s/adir.vdsh", sub);
        snprintf(inner, sizeof inner, "%s/keep", dirpath);
        CHECK(mkdir(dirpath, 0700) == 0);
        CHECK(save_file(inner, "x", 1));
        CHECK(vdsh_write(dirpath, &a.f, &err) == VDSH_ERR_IO);
        CHECK(strstr(err.msg, dirpath) && strstr(err.msg, "is a directory"));
        CHECK(stat(dirpath, &st) == 0 && S_ISDIR(st.st_mode));
        CHECK(file_exists(inner));
        CHECK(count_tmp_files(sub) == 0);
    }

    /* No such directory. */
    {
        char nodir[1200];
        snprintf(nodir, sizeof nodir, "%s/no/such/dir/x.vdsh", sub);
        CHECK(vdsh_write(nodir, &a.f, &err) == VDSH_ERR_IO);
        CHECK(strstr(err.msg, nodir) != NULL);
    }
    CHECK(count_tmp_files(sub) == 0);
    CHECK(same_file_bytes(path, old, old_n));
    free(old);
    sample_free(&a);
    sample_free(&b);
}

/* ------------------------------------------------------------------ */
/* Speed                                                               */
/* ------------------------------------------------------------------ */

static void test_speed(void)
{
    char path[1024];
    vdsh_error err;
    sample s;
    sample_init(&s, 2, 70000);
    path_in(path, sizeof path, "big.vdsh");
    double t0 = now_s();
    CHECK_RES(vdsh_write(path, &s.f, &err), VDSH_OK, &err);
    double t_write = now_s() - t0;
    struct stat st;
    stat(path, &st);

    double best = 1e9, best_mem = 1e9;
    size_t n = 0;
    uint8_t *bytes = load_file(path, &n);
    for (int i = 0; i < 5; i++) {
        vdsh_file *f = NULL;
        t0 = now_s();
        CHECK_RES(vdsh_read(path, &f, &err), VDSH_OK, &err);
        double t = now_s() - t0;
        best = t < best ? t : best;
        if (i == 0 && f)
            check_same_file(f, &s.f);
        vdsh_free(f);
        f = NULL;
        t0 = now_s();
        CHECK_RES(vdsh_read_memory(bytes, n, "big", &f, &err), VDSH_OK, &err);
        t = now_s() - t0;
        best_mem = t < best_mem ? t : best_mem;
        vdsh_free(f);
    }
    t0 = now_s();
    uint32_t crc = 0;
    for (int i = 0; i < 5; i++)
        crc ^= vdsh_crc32(0, bytes, n);
    double t_crc = (now_s() - t0) / 5;
    CHECK(crc == vdsh_crc32(0, bytes, n)); /* 5 times: xor of odd count */
    printf("speed: %.1f MB file: read+validate %.2f ms from a file, %.2f ms "
           "from memory; CRC alone %.2f ms (%.2f GB/s); write %.1f ms\n",
           (double)st.st_size / 1e6, best * 1e3, best_mem * 1e3, t_crc * 1e3,
           (double)n / t_crc / 1e9, t_write * 1e3);
    free(bytes);
    sample_free(&s);
}

/* Parts (VDSH.md "Parts"): COEF streams hold the range's rows only, the
 * size checked against the `part` chunk wherever it lies; a whole file's
 * streams hold every vertex. */
static void test_parts(void)
{
    sample s;
    sample_init(&s, 0, 0);
    const uint32_t V = s.f.header.vertex_count, b = 1, e = V;
    vdsh_error err;
    void *whole = NULL, *mem = NULL;
    size_t wn = 0, n = 0;
    CHECK_RES(vdsh_write_memory(&s.f, &whole, &wn, &err), VDSH_OK, &err);
    CHECK(vdsh_file_stream_vertices(&s.f) == V);
    s.f.has_part = 1;
    s.f.part = (vdsh_part){
        .index = 1, .count = 2, .range_begin = b, .range_end = e, .encoding = VDSH_ENCODING_F16};
    CHECK(vdsh_file_stream_vertices(&s.f) == e - b);
    /* The writer takes the range's rows: the first e - b of each stream. */
    CHECK_RES(vdsh_write_memory(&s.f, &mem, &n, &err), VDSH_OK, &err);
    CHECK(mem && whole);
    vdsh_file *f = NULL;
    if (mem)
        CHECK_RES(vdsh_read_memory(mem, n, "part", &f, &err), VDSH_OK, &err);
    if (f) {
        CHECK(f->has_part && f->part.range_begin == b && f->part.range_end == e);
        CHECK(vdsh_file_stream_vertices(f) == e - b);
        CHECK(f->stream_count == s.f.stream_count);
        for (uint32_t i = 0; i < f->stream_count && i < s.f.stream_count; i++) {
            size_t bytes = (size_t)(e - b) * vdsh_stream_bytes_per_vertex(&s.f.streams[i]);
            CHECK(memcmp(f->streams[i].data, s.f.streams[i].data, bytes) == 0);
        }
        vdsh_free(f);
    }
    /* `part` before the COEF chunks reads the same. */
    tfile t;
    if (mem) {
        tf_parse(mem, n, &t);
        int pi = tf_find(&t, "part", 0), ci = tf_find(&t, "COEF", 0);
        CHECK(pi > ci && ci > 0);
        for (uint32_t i = 0; i < s.f.stream_count; i++) { /* 48: the stream header */
            int k = tf_find(&t, "COEF", (int)i);
            const vdsh_stream *st = &s.f.streams[i];
            size_t table = vdsh_encoding_quantised(st->encoding)
                               ? ((size_t)st->order * st->order * 4 + 15) & ~(size_t)15
                               : 0;
            CHECK(k >= 0 && t.c[k].size == 48 + table + (e - b) * vdsh_stream_bytes_per_vertex(st));
        }
        if (pi > ci && ci > 0) {
            tchunk moved = t.c[pi];
            memmove(&t.c[ci + 1], &t.c[ci], (size_t)(pi - ci) * sizeof(tchunk));
            t.c[ci] = moved;
            expect_tf(&t, VDSH_OK, NULL, __LINE__);
        }
        tf_free(&t);
    }
    /* A whole file's streams (every vertex) with a part chunk, after them
     * or before: refused, naming the part's size. */
    uint8_t pp[32] = {0};
    wr32(pp + 0, 1), wr32(pp + 4, 2), wr32(pp + 8, b), wr32(pp + 12, e), wr32(pp + 16, 1);
    if (whole) {
        tf_parse(whole, wn, &t);
        tf_insert(&t, t.n, "part", pp, sizeof pp);
        expect_tf(&t, VDSH_ERR_CHUNK, "a part: its range's receivers", __LINE__);
        tf_remove(&t, t.n - 1);
        tf_insert(&t, tf_find(&t, "COEF", 0), "part", pp, sizeof pp);
        expect_tf(&t, VDSH_ERR_CHUNK, "a part: its range's receivers", __LINE__);
        tf_free(&t);
    }
    free(mem);
    free(whole);
    sample_free(&s);
}

/* Variable-order streams (VDSH.md): every encoding written and read back
 * (orders, offsets, decode within the encoding's error and zeros past a
 * vertex's own order), the slot rules, and what the reader refuses: an
 * order 0 or above the cap, padding after the order table or a record that
 * is not zero, unknown flag bits. */
#define VCHECK(c, ...)                                                                             \
    do {                                                                                           \
        checks++;                                                                                  \
        if (!(c)) {                                                                                \
            fprintf(stderr, "%s:%d: ", __FILE__, __LINE__);                                        \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fputc('\n', stderr);                                                                   \
            failures++;                                                                            \
        }                                                                                          \
    } while (0)

static void test_variable_streams(void)
{
    enum { V = 53, CAP = 12, NC = CAP * CAP };
    uint8_t orders[V];
    float *src = malloc(sizeof(float) * V * NC);
    for (uint32_t v = 0; v < V; v++) {
        orders[v] = (uint8_t)(v < 2 ? (v ? CAP : 1) : 1 + rnd() % CAP);
        for (uint32_t i = 0; i < NC; i++)
            src[v * NC + i] = i < (uint32_t)orders[v] * orders[v] ? rndf(-3.0f, 3.0f) : 0.0f;
    }
    uint32_t offsets[V + 1];
    for (uint32_t enc = 0; enc <= VDSH_ENCODING_S8S6; enc++) { /* cpca: fixed order only */
        vdsh_stream_offsets(orders, V, enc, offsets);
        uint32_t words = 0;
        for (uint32_t v = 0; v < V; v++) {
            CHECK(offsets[v] == words);
            words +=
                (uint32_t)((vdsh_encoding_bytes(enc, (uint32_t)orders[v] * orders[v]) + 3) / 4);
        }
        CHECK(offsets[V] == words);
        uint32_t *rec = malloc(4 * (size_t)words + 4);
        float scales[NC];
        float scale = enc == VDSH_ENCODING_F16 ? 4.0f : 1.0f;
        VCHECK(vdsh_encode_variable(enc, src, NC, orders, V, CAP, scale, offsets, scales, rec) ==
                   VDSH_OK,
               "encode %s", vdsh_encoding_name(enc));
        sample t;
        sample_init(&t, 2, V);
        vdsh_stream *st = &t.streams[t.f.stream_count++];
        *st = (vdsh_stream){.order = CAP,
                            .encoding = enc,
                            .method = VDSH_METHOD_SHADOW,
                            .quantity = VDSH_QUANTITY_LOG_DISTANCE,
                            .scale = scale,
                            .quantity_param = 0.01f,
                            .flags = VDSH_STREAM_VARIABLE,
                            .orders = orders,
                            .data = rec,
                            .coef_scales = vdsh_encoding_quantised(enc) ? scales : NULL};
        void *mem = NULL;
        size_t n = 0;
        vdsh_error err;
        vdsh_file *f = NULL;
        VCHECK(vdsh_write_memory(&t.f, &mem, &n, &err) == VDSH_OK, "%s", err.msg);
        VCHECK(mem && vdsh_read_memory(mem, n, "v.vdsh", &f, &err) == VDSH_OK, "%s", err.msg);
        const vdsh_stream *r = f ? vdsh_find_variable_stream(f, VDSH_QUANTITY_LOG_DISTANCE) : NULL;
        VCHECK(r && r->order == CAP && r->flags == VDSH_STREAM_VARIABLE &&
                   !vdsh_find_stream(f, CAP, VDSH_QUANTITY_LOG_DISTANCE) &&
                   vdsh_stream_bytes_per_vertex(r) == 0 &&
                   vdsh_stream_data_bytes(r, V) == 64 + 4 * (uint64_t)words,
               "%s read back", vdsh_encoding_name(enc));
        if (r) { /* rows per order, the average as the data's size, the cap's record */
            vdsh_stream_size z = vdsh_stream_size_of(r, V);
            uint32_t per[VDSH_ORDER_SLOTS] = {0};
            for (uint32_t v = 0; v < V; v++)
                per[orders[v]]++;
            VCHECK(memcmp(z.rows_per_order, per, sizeof per) == 0 &&
                       z.mean_bytes == (64.0 + 4.0 * words) / V &&
                       z.max_bytes == 4 * vdsh_record_words(enc, CAP),
                   "%s: stream size %g / %u", vdsh_encoding_name(enc), z.mean_bytes, z.max_bytes);
        }
        double worst = 0.0;
        for (uint32_t v = 0; r && v < V; v++) {
            CHECK(vdsh_stream_vertex_order(r, v) == orders[v] && r->offsets[v] == offsets[v]);
            CHECK((uintptr_t)((const uint32_t *)r->data + r->offsets[v]) % 4 == 0);
            float out[NC];
            vdsh_stream_decode(r, v, out);
            for (uint32_t i = 0; i < NC; i++) {
                double tol =
                    vdsh_encoding_quantised(enc)
                        ? 0.5 * vdsh_quant_step(scales[i], vdsh_quant_levels(enc, i)) * 1.0001
                    : enc == VDSH_ENCODING_F16 ? fabs(src[v * NC + i]) / 2048.0 + 1e-7
                                               : 0.0;
                worst = fmax(worst, fabs(out[i] - src[v * NC + i]) - tol);
            }
        }
        VCHECK(worst <= 0.0, "%s: decoded values off by %g beyond the encoding's step",
               vdsh_encoding_name(enc), worst);
        /* Byte patches of the written file. */
        const uint8_t *d = mem;
        size_t coef = payload_of(d, n, "COEF", 1);
        size_t table = vdsh_encoding_quantised(enc) ? (NC * 4 + 15) / 16 * 16 : 0;
        size_t otab = coef + 48 + table, recs = otab + 64;
        CHECK(coef && d[otab] == orders[0] && rd32(d + coef + 36) == VDSH_STREAM_VARIABLE);
        if (coef) {
            uint8_t b0 = 0, big = CAP + 1, one = 1;
            expect_patched(d, n, otab, &b0, 1, 1, VDSH_ERR_INVALID, "vertex 0 has order 0",
                           __LINE__);
            expect_patched(d, n, otab + 3, &big, 1, 1, VDSH_ERR_INVALID, "has order 13", __LINE__);
            expect_patched(d, n, otab + V, &one, 1, 1, VDSH_ERR_INVALID,
                           "padding after the order table", __LINE__);
            PATCH32(coef + 36, 3, 1, VDSH_ERR_INVALID, "flags 0x3");
            PATCH32(coef + 40, 1, 1, VDSH_ERR_INVALID, "reserved bytes 40..47");
            /* vertex 0 is order 1: its record's last byte is padding for
             * every encoding but f32 */
            if (enc != VDSH_ENCODING_F32)
                expect_patched(d, n, recs + 3, &one, 1, 1, VDSH_ERR_INVALID,
                               "vertex 0: padding after its record", __LINE__);
            /* an order raised within the cap: the records no longer fit */
            uint8_t three = 3;
            expect_patched(d, n, otab, &three, 1, 1, VDSH_ERR_CHUNK, "bytes of data", __LINE__);
        }
        /* Slots: a second variable stream of the quantity is refused, one
         * of another quantity and a fixed stream of the same order are not. */
        t.streams[t.f.stream_count] = *st;
        t.streams[t.f.stream_count].quantity = VDSH_QUANTITY_DISTANCE;
        t.streams[t.f.stream_count].quantity_param = 0.0f;
        t.f.stream_count++;
        void *m2 = NULL;
        size_t n2 = 0;
        VCHECK(vdsh_write_memory(&t.f, &m2, &n2, &err) == VDSH_OK, "%s", err.msg);
        free(m2);
        t.streams[t.f.stream_count - 1].quantity = VDSH_QUANTITY_LOG_DISTANCE;
        t.streams[t.f.stream_count - 1].quantity_param = 0.01f;
        m2 = NULL;
        VCHECK(vdsh_write_memory(&t.f, &m2, &n2, &err) == VDSH_ERR_ARGUMENT &&
                   strstr(err.msg, "both variable-order log-distance"),
               "two variable streams: %s", err.msg);
        t.streams[t.f.stream_count - 1].orders = NULL;
        t.streams[t.f.stream_count - 1].quantity = VDSH_QUANTITY_DISTANCE;
        t.streams[t.f.stream_count - 1].quantity_param = 0.0f;
        VCHECK(vdsh_write_memory(&t.f, &m2, &n2, &err) == VDSH_ERR_ARGUMENT &&
                   strstr(err.msg, "variable order without orders"),
               "%s", err.msg);
        t.f.stream_count--;
        vdsh_free(f);
        free(mem);
        t.f.stream_count--; /* the streams' data are not the sample's */
        sample_free(&t);
        free(rec);
    }
    uint8_t bad[2] = {1, CAP + 1};
    uint32_t off2[3] = {0, 1, 2};
    float sc[NC];
    uint32_t out[8];
    CHECK(vdsh_encode_variable(VDSH_ENCODING_S8, src, NC, bad, 2, CAP, 1.0f, off2, sc, out) ==
          VDSH_ERR_ARGUMENT);
    free(src);
}

/* A mesh handed to a .vdsh reader (vdsh-view model.obj) is named for what
 * it is, with the bake that makes a .vdsh of it, for every format vdsh-bake
 * reads: by the first bytes where the format has a magic (PLY, glb), else
 * by the name's extension in any case (was "wrong magic" for .obj, .off,
 * .stl and .gltf). vdsh_scan_chunks (vdsh-info --verify) says the same. */
static void test_mesh_named(void)
{
    static const struct {
        const char *name, *bytes, *what;
    } cases[] = {
        {"model.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "a Wavefront OBJ mesh"},
        {"MODEL.OBJ", "# exported\nv 0 0 0\n", "a Wavefront OBJ mesh"},
        {"model.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "an OFF mesh"},
        {"3DSMaxExport.STL", "solid 3DSMaxExport\n  facet normal 0 0 1\n", "an STL mesh"},
        {"model.stl", "binary STL header, eighty bytes of anything at all", "an STL mesh"},
        {"dir.v/model.gltf", "{\"asset\": {\"version\": \"2.0\"}}\n", "a glTF mesh"},
        {"model.ply", "ply\nformat ascii 1.0\n", "a PLY mesh"},
        {"a.vdsh", "ply\r\nformat binary_little_endian 1.0\r\n", "a PLY mesh"},
        {"model.ply", "not a ply header but named one\n", "a PLY mesh"},
        {"model.vdsh", "glTF\2\0\0\0\100\0\0\0\0\0\0\0\0\0\0", "a binary glTF mesh"},
        {"model.glb", "glTF", "a binary glTF mesh"},
        {"ob", "v", NULL},
        {"model.objx", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", NULL},
        {"obj/model", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", NULL},
        {"model.obj", "VDSH\r\n\x1a\r damaged by a transfer, not a mesh", "text-mode"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const uint8_t *d = (const uint8_t *)cases[i].bytes;
        size_t n = i == 9 ? 16 : strlen(cases[i].bytes);
        vdsh_file *f = NULL;
        vdsh_error err;
        char want[256];
        snprintf(want, sizeof want, "%s: not a .vdsh file%s%s", cases[i].name,
                 cases[i].what ? ": " : " (wrong magic)", cases[i].what ? cases[i].what : "");
        vdsh_result r = vdsh_read_memory(d, n, cases[i].name, &f, &err);
        int ok = r == VDSH_ERR_NOT_VDSH && !f;
        if (cases[i].what && !strcmp(cases[i].what, "text-mode"))
            ok = ok && strstr(err.msg, "magic bytes 4..7 damaged");
        else
            ok = ok && strstr(err.msg, want) &&
                 !!strstr(err.msg, "; bake it first: vdsh-bake MODEL -o MODEL.vdsh") ==
                     (cases[i].what != NULL);
        if (!ok)
            fprintf(stderr, "%s: got %d '%s', want '%s'\n", cases[i].name, (int)r, err.msg, want);
        CHECK(ok);
        vdsh_free(f);
        uint32_t count = 0;
        r = vdsh_scan_chunks(d, n, cases[i].name, NULL, 0, &count, &err);
        CHECK(r == VDSH_ERR_NOT_VDSH &&
              strstr(err.msg, !cases[i].what                        ? "wrong magic"
                              : !strcmp(cases[i].what, "text-mode") ? "magic bytes 4..7 damaged"
                                                                    : cases[i].what));
    }
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "--exhaustive-f16"))
        return exhaustive_f16() ? 0 : 1;

    const char *base = getenv("TMPDIR");
    snprintf(tmpdir, sizeof tmpdir, "%s/vdsh_test_format_XXXXXX", base && *base ? base : "/tmp");
    if (!mkdtemp(tmpdir)) {
        fprintf(stderr, "mkdtemp %s: %s\n", tmpdir, strerror(errno));
        return 1;
    }

    test_crc();
    test_f16();
    test_encode();
    test_encode_s8();
    test_s8_reading();
    test_names();
    test_roundtrip();
    test_truncation();
    test_byte_changes();
    test_rules();
    test_mesh_named();
    test_parts();
    test_variable_streams();
    test_mutations();
    test_scan();
    test_writer_checks();
    test_atomic();
    test_speed();

    CHECK(count_tmp_files(tmpdir) == 0);
    remove_tree(tmpdir);
    printf("%d checks, %d failed\n", checks, failures);
    return failures ? 1 : 0;
}
