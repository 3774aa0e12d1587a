/*
 * cpca_kchoice_tool.c - the cpca encoder's K,alloc:BYTES fit at several K
 * with the pool score of each (issue 29, the choice of K per stream;
 * measurement: vdsh_cpca_study.h's vdsh_cpca_pool_score).
 *
 *   cpca_kchoice_tool IN.vdsh POOL.f32 MIX BYTES K1,K2,...
 *   cpca_kchoice_tool --score IN.vdsh POOL.f32 CPCA.vdsh...
 *
 * IN: a whole file with a fixed-order f32 stream of order 12 (scale 1);
 * POOL.f32: the light pool (3 little-endian f32 per light, in the file's
 * space: tests/light_pool_tool's); MIX the light mix of the fit (0..1).
 * One JSON line per K to stdout: k asked, clusters, basis, words,
 * bytes_per_vertex (records and model with its width table), rms_error,
 * pairs, disagree, missed, squared, seconds (the fit's, then the score's).
 * --score: the same score of streams already fitted (each CPCA.vdsh a
 * whole file of IN's vertices with a cpca stream, IN an f32 stream of its
 * order: the k-means starts, docs/ACCURACY.md), one JSON line per file
 * (file, pairs, disagree, missed, squared).
 * Exit 1 for a bad file or fit, 2 for bad usage.
 */
#include "cpca_tool.h"
#include "vdsh.h"
#include "vdsh_cpca_study.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static float *read_pool(const char *path, size_t *count)
{
    FILE *pf = fopen(path, "rb");
    float *pool = malloc(sizeof(float) * 3 * 65536);
    *count = pf && pool ? fread(pool, sizeof(float) * 3, 65536, pf) : 0;
    if (pf)
        fclose(pf);
    return pool;
}

/* --score IN POOL CPCA...: exit as main's */
static int score_files(int argc, char **argv)
{
    vdsh_error err;
    vdsh_file *f;
    if (vdsh_read(argv[2], &f, &err) != VDSH_OK) {
        fprintf(stderr, "cpca_kchoice_tool: %s\n", err.msg);
        return 1;
    }
    const uint32_t rows = vdsh_file_stream_vertices(f);
    size_t nl;
    float *pool = read_pool(argv[3], &nl);
    int rc = 0;
    if (!nl) {
        fprintf(stderr, "cpca_kchoice_tool: no pool in %s\n", argv[3]);
        rc = 1;
    }
    vdsh_cpca_settings st = {
        .light_count = (uint32_t)nl, .lights = pool, .positions = f->positions};
    for (int a = 4; a < argc && !rc; a++) {
        vdsh_file *g;
        if (vdsh_read(argv[a], &g, &err) != VDSH_OK) {
            fprintf(stderr, "cpca_kchoice_tool: %s\n", err.msg);
            rc = 1;
            break;
        }
        const vdsh_stream *c = NULL;
        for (uint32_t i = 0; i < g->stream_count; i++)
            if (g->streams[i].encoding == VDSH_ENCODING_CPCA)
                c = &g->streams[i];
        const vdsh_stream *s = c ? cpca_tool_stream(f, c->order) : NULL;
        vdsh_cpca_pool_scores sc;
        if (!c || !s || g->has_part || vdsh_file_stream_vertices(g) != rows) {
            fprintf(stderr,
                    "cpca_kchoice_tool: %s: no cpca stream for %s's %u vertices, or no f32 "
                    "stream of its order in %s\n",
                    argv[a], argv[2], rows, argv[2]);
            rc = 1;
        } else if (vdsh_cpca_pool_score_streams((const float *)s->data, f->normals, rows, c->order,
                                                &st, c, 1, &sc, &err) != VDSH_OK) {
            fprintf(stderr, "cpca_kchoice_tool: %s\n", err.msg);
            rc = 1;
        } else {
            printf("{\"file\": \"%s\", \"pairs\": %llu, \"disagree\": %llu, \"missed\": %llu, "
                   "\"squared\": %.9g}\n",
                   argv[a], (unsigned long long)sc.pairs, (unsigned long long)sc.disagree,
                   (unsigned long long)sc.missed, sc.squared);
            fflush(stdout);
        }
        vdsh_free(g);
    }
    free(pool);
    vdsh_free(f);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc >= 5 && !strcmp(argv[1], "--score"))
        return score_files(argc, argv);
    if (argc != 6) {
        fprintf(stderr, "usage: cpca_kchoice_tool IN.vdsh POOL.f32 MIX BYTES K1,K2,...\n"
                        "       cpca_kchoice_tool --score IN.vdsh POOL.f32 CPCA.vdsh...\n");
        return 2;
    }
    const uint32_t order = 12, n = order * order;
    vdsh_error err;
    vdsh_file *f;
    if (vdsh_read(argv[1], &f, &err) != VDSH_OK) {
        fprintf(stderr, "cpca_kchoice_tool: %s\n", err.msg);
        return 1;
    }
    const vdsh_stream *s = cpca_tool_stream(f, order);
    const uint32_t rows = vdsh_file_stream_vertices(f);
    size_t nl;
    float *pool = read_pool(argv[2], &nl);
    if (!s || !nl) {
        fprintf(stderr, "cpca_kchoice_tool: %s: no f32 stream of order 12, or no pool in %s\n",
                argv[1], argv[2]);
        vdsh_free(f);
        return 1;
    }
    const float *src = (const float *)s->data;
    char *ks = argv[5];
    for (char *tok = strtok(ks, ","); tok; tok = strtok(NULL, ",")) {
        vdsh_cpca_settings st = {.clusters = (uint32_t)atoi(tok),
                                 .budget = (uint32_t)atoi(argv[4]),
                                 .light_mix = (float)atof(argv[3]),
                                 .light_count = (uint32_t)nl,
                                 .lights = pool,
                                 .positions = f->positions};
        vdsh_cpca_fit fit;
        double t0 = now();
        if (vdsh_cpca_encode(src, f->normals, rows, order, &st, &fit, &err) != VDSH_OK) {
            fprintf(stderr, "cpca_kchoice_tool: K %s: %s\n", tok, err.msg);
            return 1;
        }
        double t1 = now();
        vdsh_cpca_pool_scores sc;
        if (vdsh_cpca_pool_score(src, f->normals, rows, order, &st, &fit, &sc, &err) != VDSH_OK) {
            fprintf(stderr, "cpca_kchoice_tool: %s\n", err.msg);
            return 1;
        }
        double t2 = now();
        const vdsh_cpca *m = &fit.model;
        double bytes = (double)rows * 4.0 * m->record_words +
                       (double)vdsh_cpca_model_bytes(order, m->clusters, m->basis, m->bases_s8) +
                       (m->widths ? (double)((m->basis + 15u) & ~15u) : 0.0);
        printf("{\"k\": %s, \"clusters\": %u, \"basis\": %u, \"words\": %u, "
               "\"bytes_per_vertex\": %.3f, \"rms_error\": %.6g, \"pairs\": %llu, "
               "\"disagree\": %llu, \"missed\": %llu, \"squared\": %.9g, \"fit_s\": %.2f, "
               "\"score_s\": %.2f}\n",
               tok, m->clusters, m->basis, m->record_words, bytes / rows, fit.rms_error,
               (unsigned long long)sc.pairs, (unsigned long long)sc.disagree,
               (unsigned long long)sc.missed, sc.squared, t1 - t0, t2 - t1);
        fflush(stdout);
        vdsh_cpca_fit_free(&fit);
    }
    (void)n;
    free(pool);
    vdsh_free(f);
    return 0;
}
