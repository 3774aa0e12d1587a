/*
 * vdsh-info - print what a .vdsh file holds, or verify it chunk by chunk.
 *
 *     vdsh-info room.vdsh               summary for people
 *     vdsh-info --json - room.vdsh      the same as JSON on stdout (--json FILE:
 *                                       in FILE), one object, an array of
 *                                       them for several files
 *     vdsh-info --verify *.vdsh         every chunk's CRC, then full validation
 *
 * Exit status: 0 when every file was read (and verified), 1 when any file
 * failed (the message on stderr names the file), 2 for a usage error.
 *
 * Everything about the byte layout comes from vdsh.h; this file only reads
 * the decoded structs (and, for --verify, vdsh_scan_chunks' list).
 */
#include "vdsh.h"
#include "vdsh_cpca.h"
#include "vdsh_output.h"
#include "vt_cli.h"
#include "vt_json.h"
#include "vt_record.h"

#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef VDSH_VERSION_STRING
#define VDSH_VERSION_STRING "unknown"
#endif

static const char *prog = "vdsh-info";

static void usage(FILE *to)
{
    fprintf(to,
            "usage: %s [--json OUT.json] [--verify] FILE.vdsh...\n"
            "\n"
            "Print what a .vdsh file holds: counts, bounds, every bake "
            "parameter,\n"
            "sources, coefficient streams, statistics and timings.\n"
            "\n"
            "  -j, --json OUT.json  write the same as JSON to OUT.json (-: on "
            "stdout):\n"
            "                 one object, an array of them for several files\n"
            "      --verify   list every chunk with its stored and computed "
            "CRC, then\n"
            "                 validate the whole file; fail if anything is "
            "wrong\n"
            "  -h, --help     print this help and exit\n"
            "  -V, --version  print the version and exit\n"
            "\n"
            "Exit status: 0 every file is fine, 1 a file could not be read "
            "or\n"
            "failed verification, 2 usage error.\n",
            prog);
}

/* ------------------------------------------------------------------ */
/* JSON output: vt_json.h (cJSON; strings of any bytes parse, numbers   */
/* read back exactly, NaN and Inf are null), one document per file      */
/* ------------------------------------------------------------------ */

static void json_vec3(vt_json *j, cJSON *parent, const char *key, const float v[3])
{
    cJSON *a = vt_json_array(j, parent, key);
    for (int k = 0; k < 3; k++)
        vt_json_f32(j, a, NULL, v[k]);
}

static void json_bounds(vt_json *j, cJSON *parent, const char *key, const float lo[3],
                        const float hi[3])
{
    cJSON *b = vt_json_object(j, parent, key);
    json_vec3(j, b, "min", lo);
    json_vec3(j, b, "max", hi);
}

/* --json FILE: the documents of every file, written together at the end
 * (json_write). */
static char *json_text;
static size_t json_len, json_docs;

/* Keep the document for json_write and free it; 0 if it could not be built. */
static int json_emit(vt_json *j, const char *path)
{
    char *text = vt_json_print(j);
    vt_json_free(j);
    size_t n = text ? strlen(text) : 0;
    char *grown = text ? realloc(json_text, json_len + n + 3) : NULL;
    if (!grown) {
        fprintf(stderr, "%s: %s: JSON not built: out of memory\n", prog, path);
        free(text);
        return 0;
    }
    json_text = grown;
    if (json_docs++)
        json_text[json_len++] = ','; /* after the previous document's newline */
    memcpy(json_text + json_len, text, n + 1);
    json_len += n;
    free(text);
    return 1;
}

/* One document as it is; several as an array. 0 on a failed write (said). */
static int json_write(const char *out)
{
    const char *open = json_docs > 1 ? "[\n" : "", *close = json_docs > 1 ? "]\n" : "";
    size_t n = strlen(open) + json_len + strlen(close);
    char *all = malloc(n + 1);
    if (!all) {
        fprintf(stderr, "%s: %s: out of memory\n", prog, out);
        return 0;
    }
    snprintf(all, n + 1, "%s%s%s", open, json_text ? json_text : "", close);
    int ok = 1;
    if (strcmp(out, "-") == 0) {
        ok = fputs(all, stdout) >= 0;
    } else {
        vdsh_error err;
        if (vdsh_output_write(out, all, n, &err) != VDSH_OK) {
            fprintf(stderr, "%s: %s\n", prog, err.msg);
            ok = 0;
        }
    }
    free(all);
    return ok;
}

/* ------------------------------------------------------------------ */
/* Derived numbers                                                     */
/* ------------------------------------------------------------------ */

typedef struct coef0_stats {
    double min, max, mean;
} coef0_stats;

static coef0_stats stream_coef0(const vdsh_file *f, const vdsh_stream *s)
{
    float c[VDSH_MAX_COEFFS];
    coef0_stats st = {INFINITY, -INFINITY, 0.0};
    double sum = 0.0;
    const uint32_t rows = vdsh_file_stream_vertices(f); /* a part: its range */
    for (uint32_t v = 0; v < rows; v++) {
        vdsh_stream_decode(s, v, c);
        st.min = c[0] < st.min ? c[0] : st.min;
        st.max = c[0] > st.max ? c[0] : st.max;
        sum += c[0];
    }
    st.mean = sum / rows;
    return st;
}

static void receiver_bounds(const vdsh_file *f, float lo[3], float hi[3])
{
    for (int k = 0; k < 3; k++) {
        lo[k] = INFINITY;
        hi[k] = -INFINITY;
    }
    for (uint32_t v = 0; v < f->header.vertex_count; v++)
        for (int k = 0; k < 3; k++) {
            float x = f->positions[3 * v + k];
            lo[k] = x < lo[k] ? x : lo[k];
            hi[k] = x > hi[k] ? x : hi[k];
        }
}

static double diagonal(const float lo[3], const float hi[3])
{
    double d = 0.0;
    for (int k = 0; k < 3; k++)
        d += ((double)hi[k] - lo[k]) * ((double)hi[k] - lo[k]);
    return sqrt(d);
}

static void sha_hex(const uint8_t sha[32], char out[65])
{
    for (int i = 0; i < 32; i++)
        snprintf(out + 2 * i, 3, "%02x", sha[i]);
}

static const char *or_unknown(const char *name)
{
    return strcmp(name, "?") == 0 ? "unknown" : name;
}

static uint64_t file_size_of(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (uint64_t)st.st_size : 0;
}

/* ------------------------------------------------------------------ */
/* Summary                                                             */
/* ------------------------------------------------------------------ */

/* The receivers and the occluders: counts, bounds and diagonals. */
static void print_meshes(const vdsh_file *f)
{
    const vdsh_header *h = &f->header;
    float lo[3], hi[3];
    receiver_bounds(f, lo, hi);
    printf("  receivers    %u %s, %u triangle%s\n", h->vertex_count,
           vdsh_plural(h->vertex_count, "vertex", "vertices"), h->triangle_count,
           vdsh_s(h->triangle_count));
    printf("               bounds (%g, %g, %g) .. (%g, %g, %g), diagonal "
           "%g\n",
           lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], diagonal(lo, hi));
    printf("  occluders    %u %s, %u triangle%s\n", h->occluder_vertex_count,
           vdsh_plural(h->occluder_vertex_count, "vertex", "vertices"), h->occluder_triangle_count,
           vdsh_s(h->occluder_triangle_count));
    printf("               bounds (%g, %g, %g) .. (%g, %g, %g), diagonal "
           "%g\n",
           h->bounds_min[0], h->bounds_min[1], h->bounds_min[2], h->bounds_max[0], h->bounds_max[1],
           h->bounds_max[2], diagonal(h->bounds_min, h->bounds_max));
}

/* The bake's parameters the header records. */
static void print_bake(const vdsh_header *h)
{
    printf("  bake         rays %u per receiver, sampling %s, seed %llu\n", h->rays,
           or_unknown(vdsh_sampling_name(h->sampling)), (unsigned long long)h->seed);
    printf("               max_distance %g, max_edge %g%s\n", h->max_distance, h->max_edge,
           h->max_edge == 0.0f ? " (not refined)" : "");
    printf("               offset_rule %s, welded %s, robust trace %s\n",
           or_unknown(vdsh_offset_rule_name(h->offset_rule)),
           (h->load_flags & VDSH_LOAD_WELD) ? "yes" : "no",
           (h->trace_flags & VDSH_TRACE_ROBUST) ? "yes" : "no");
    if (h->load_flags & VDSH_LOAD_UP_MASK)
        printf("               up axis %s (the sources turned into +y: vdsh-bake --up-axis)\n",
               or_unknown(
                   vdsh_up_axis_name((h->load_flags & VDSH_LOAD_UP_MASK) >> VDSH_LOAD_UP_SHIFT)));
    if (VDSH_LOAD_CREASE(h->load_flags))
        printf("               crease %u degrees (computed normals split at sharper edges)\n",
               VDSH_LOAD_CREASE(h->load_flags));
    if (h->cube_size)
        printf("               basis cubemaps %u x %u per face\n", h->cube_size, h->cube_size);
    else
        printf("               basis cubemaps none\n");
}

static void print_sources(const vdsh_file *f)
{
    printf("  sources      %u\n", f->source_count);
    for (uint32_t i = 0; i < f->source_count; i++) {
        char hex[65];
        sha_hex(f->sources[i].sha256, hex);
        printf("    [%u] %s\n        %llu byte%s, sha256 %s\n", i, f->sources[i].name,
               (unsigned long long)f->sources[i].size, vdsh_s(f->sources[i].size), hex);
    }
}

/* A quantised stream's per-index table: coefficient i = stored * scale_i
 * / levels_i. */
static void print_coef_scales(const vdsh_stream *s)
{
    uint32_t nc = s->order * s->order;
    printf("        %s scales (largest |coefficient| per index):", vdsh_encoding_name(s->encoding));
    for (uint32_t k = 0; k < nc; k++)
        printf("%s%g", k % 9 == 0 && k ? "\n          " : " ", s->coef_scales[k]);
    putchar('\n');
}

/* A cpca stream: clusters, basis, weights, bytes with and without the
 * model, the weights' widths and the vertices in each cluster. */
static void print_cpca(const vdsh_file *f, const vdsh_stream *s)
{
    const vdsh_cpca *m = &s->cpca;
    uint32_t rows = vdsh_file_stream_vertices(f);
    vdsh_stream_size z = vdsh_stream_size_of(s, rows);
    char wbits[16];
    snprintf(wbits, sizeof wbits, "%u-bit", m->bits);
    size_t bpv = vdsh_stream_bytes_per_vertex(s);
    unsigned long long model = (unsigned long long)vdsh_cpca_stream_model_bytes(m, s->order);
    printf("        cpca: %u cluster%s, %u basis vector%s of %s weights; %zu byte%s "
           "per vertex, %.1f with the model (%llu byte%s, %s bases)\n",
           m->clusters, vdsh_s(m->clusters), m->basis, vdsh_s(m->basis),
           m->bits ? wbits : "per-vector", bpv, vdsh_s(bpv), z.mean_bytes, model, vdsh_s(model),
           m->bases_s8 ? "s8" : "f16");
    if (!m->bits) { /* runs, vector 1 first: 7x3 is three vectors of 7 bits */
        printf("        widths:");
        for (uint32_t j = 0; j < m->basis;) {
            uint32_t e = j;
            while (e < m->basis && m->widths[e] == m->widths[j])
                e++;
            printf("%s%ux%u", j ? "," : " ", m->widths[j], e - j);
            j = e;
        }
        putchar('\n');
    }
    printf("        vertices per cluster:");
    for (uint32_t c = 0; c < m->clusters; c++) {
        uint32_t count = 0;
        for (uint32_t v = 0; v < rows; v++)
            count += vdsh_cpca_cluster(s, v) == c;
        printf(" %u", count);
    }
    putchar('\n');
}

/* A variable-order stream: its bytes per vertex and vertices per order. */
static void print_variable(const vdsh_file *f, const vdsh_stream *s)
{
    vdsh_stream_size z = vdsh_stream_size_of(s, vdsh_file_stream_vertices(f));
    printf("        variable order: %.1f bytes per vertex on average, %u at most; "
           "vertices per order:",
           z.mean_bytes, z.max_bytes);
    for (uint32_t k = 1; k <= s->order; k++)
        if (z.rows_per_order[k])
            printf(" %u: %u", k, z.rows_per_order[k]);
    putchar('\n');
}

/* Stream i: its order, encoding, fit and quantity, window and scale,
 * its encoding's own figures, and coefficient 0's range. */
static void print_stream(const vdsh_file *f, uint32_t i)
{
    const vdsh_stream *s = &f->streams[i];
    coef0_stats st = stream_coef0(f, s);
    printf("    [%u] order %s%u (%u coefficient%s%s), %s, method %s", i,
           s->flags & VDSH_STREAM_VARIABLE ? "1.." : "", s->order, s->order * s->order,
           vdsh_s(s->order * s->order), s->flags & VDSH_STREAM_VARIABLE ? " at most" : "",
           vdsh_encoding_name(s->encoding), or_unknown(vdsh_method_name(s->method)));
    if (strcmp(vdsh_method_name(s->method), "?") == 0)
        printf(" (%u)", s->method);
    printf(", quantity %s", vdsh_quantity_name(s->quantity));
    if (s->quantity == VDSH_QUANTITY_LOG_DISTANCE)
        printf(" (floor %g)", s->quantity_param);
    putchar('\n');
    printf("        window %s", vdsh_window_name(s->window));
    if (s->window != VDSH_WINDOW_NONE)
        printf(" (param %g)", s->window_param);
    printf(", method_param %g, scale %g\n", s->method_param, s->scale);
    if (vdsh_encoding_quantised(s->encoding) && s->coef_scales)
        print_coef_scales(s);
    if (s->encoding == VDSH_ENCODING_CPCA) {
        print_cpca(f, s);
    } else if (s->flags & VDSH_STREAM_VARIABLE) {
        print_variable(f, s);
    } else {
        size_t bpv = vdsh_stream_bytes_per_vertex(s);
        printf("        %zu byte%s per vertex\n", bpv, vdsh_s(bpv));
    }
    printf("        coefficient 0: min %g, max %g, mean %g\n", st.min, st.max, st.mean);
}

/* The bake's own ray statistics (the stat chunk). */
static void print_stats(const vdsh_stats *t)
{
    printf("  stats        rays traced %llu, missed %llu", (unsigned long long)t->rays_traced,
           (unsigned long long)t->rays_missed);
    if (t->rays_traced)
        printf(" (%.2f%%)", 100.0 * (double)t->rays_missed / (double)t->rays_traced);
    printf("\n               degenerate receivers %u, undefined normals %u, "
           "origins moved %u, normals flipped %u\n",
           t->degenerate_receivers, t->undefined_normals, t->moved_origins, t->flipped_normals);
}

/* A shard's part: its range, how it is merged, and for cpca the
 * settings and the light mix the merge fits with. */
static void print_part(const vdsh_file *f)
{
    printf("  part         shard %u of %u: receivers %u..%u (its streams' rows), merged "
           "as %s\n",
           f->part.index, f->part.count, f->part.range_begin, f->part.range_end,
           vdsh_encoding_name(f->part.encoding));
    if (f->part.encoding != VDSH_ENCODING_CPCA)
        return;
    /* the settings, the light mix and its pool the lpol chunk's (none: light:0) */
    const vdsh_cpca_settings st = vdsh_cpca_part_settings(f);
    char text[192];
    vdsh_cpca_settings_text(&st, text, sizeof text);
    printf("               cpca %s", text);
    printf(" (fitted at the merge");
    if (f->has_light_pool)
        printf("; light pool of %u light%s", f->light_pool.count, vdsh_s(f->light_pool.count));
    printf(")\n");
}

/* The adaptive receivers' parameters and rounds (the adpt chunk). */
static void print_adaptive(const vdsh_file *f)
{
    const vdsh_adaptive *a = &f->adaptive;
    printf("  adaptive     tolerance %g, min edge %g, budget %u (0: none), %u light%s\n"
           "               %u receiver%s from %u in %u of at most %u round%s, %u midpoint%s "
           "baked\n",
           a->tolerance, a->min_edge, a->max_receivers, a->lights, vdsh_s(a->lights),
           f->header.vertex_count, vdsh_s(f->header.vertex_count), a->start_receivers, a->rounds,
           a->max_rounds, vdsh_s(a->max_rounds), a->candidates, vdsh_s(a->candidates));
}

/* The light region vdsh-bake --light-region recorded. */
static void print_light_box(const vdsh_light_box *b)
{
    printf("  lights       region %s: %g %g %g .. %g %g %g (vdsh-bake --light-region)\n",
           b->rule == VDSH_LIGHT_REGION_GROWN ? "grown" : "box", (double)b->min[0],
           (double)b->min[1], (double)b->min[2], (double)b->max[0], (double)b->max[1],
           (double)b->max[2]);
}

static void print_timings(const vdsh_timings *t)
{
    printf("  timings      load %.3f s, refine %.3f s, build %.3f s, "
           "trace %.3f s\n               total %.3f s, %u thread%s\n",
           t->load, t->refine, t->build, t->trace, t->total, t->threads, vdsh_s(t->threads));
}

/* The summary of one file: meshes, bake, sources, streams, then the
 * optional chunks it has, and its size. */
static void print_summary(const char *path, const vdsh_file *f, uint64_t size)
{
    printf("%s\n", path);
    print_meshes(f);
    print_bake(&f->header);
    print_sources(f);
    printf("  streams      %u\n", f->stream_count);
    for (uint32_t i = 0; i < f->stream_count; i++)
        print_stream(f, i);
    if (f->has_stats)
        print_stats(&f->stats);
    if (f->has_part)
        print_part(f);
    int whole_cpca = 0;
    for (uint32_t i = 0; i < f->stream_count && !f->has_part; i++)
        whole_cpca |= f->streams[i].encoding == VDSH_ENCODING_CPCA;
    if (whole_cpca) /* VDSH.md "cpca streams": only a part's lpol records A */
        printf("  cpca         light mix and pool not recorded in a whole file (vdsh-bake "
               "--report: cpca.light_mix, cpca.light_pool)\n");
    if (f->has_adaptive)
        print_adaptive(f);
    if (f->has_light_box)
        print_light_box(&f->light_box);
    if (f->has_timings)
        print_timings(&f->timings);
    printf("  size         %llu bytes, %.2f bytes per vertex\n", (unsigned long long)size,
           (double)size / f->header.vertex_count);
}

static int print_json(const char *path, const vdsh_file *f, uint64_t size)
{
    const vdsh_header *h = &f->header;
    float lo[3], hi[3];
    receiver_bounds(f, lo, hi);

    vt_json j = {0};
    cJSON *root = vt_json_object(&j, NULL, NULL);
    vt_json_string(&j, root, "file", path);
    vt_json_bool(&j, root, "valid", 1);
    vt_json_u64(&j, root, "file_size", size);
    vt_json_f64(&j, root, "bytes_per_vertex", (double)size / h->vertex_count);
    vt_json_u64(&j, root, "format_version", VDSH_FORMAT_VERSION);
    vt_json_u64(&j, root, "vertex_count", h->vertex_count);
    vt_json_u64(&j, root, "triangle_count", h->triangle_count);
    json_bounds(&j, root, "receiver_bounds", lo, hi);

    cJSON *bake = vt_json_object(&j, root, "bake");
    vt_record_params(&j, bake, h);
    vt_json_u64(&j, bake, "load_flags", h->load_flags);
    vt_json_bool(&j, bake, "welded", h->load_flags & VDSH_LOAD_WELD);
    vt_json_string(
        &j, bake, "up_axis",
        or_unknown(vdsh_up_axis_name((h->load_flags & VDSH_LOAD_UP_MASK) >> VDSH_LOAD_UP_SHIFT)));
    if (VDSH_LOAD_CREASE(h->load_flags))
        vt_json_u64(&j, bake, "crease", VDSH_LOAD_CREASE(h->load_flags));
    vt_json_u64(&j, bake, "trace_flags", h->trace_flags);
    vt_json_bool(&j, bake, "robust", h->trace_flags & VDSH_TRACE_ROBUST);
    vt_json_u64(&j, bake, "cube_size", h->cube_size);
    vt_json_u64(&j, bake, "occluder_vertex_count", h->occluder_vertex_count);
    vt_json_u64(&j, bake, "occluder_triangle_count", h->occluder_triangle_count);
    json_bounds(&j, bake, "occluder_bounds", h->bounds_min, h->bounds_max);

    cJSON *sources = vt_json_array(&j, root, "sources");
    for (uint32_t i = 0; i < f->source_count; i++) {
        char hex[65];
        sha_hex(f->sources[i].sha256, hex);
        cJSON *o = vt_json_object(&j, sources, NULL);
        vt_json_string(&j, o, "name", f->sources[i].name);
        vt_json_u64(&j, o, "size", f->sources[i].size);
        vt_json_string(&j, o, "sha256", hex);
    }

    cJSON *streams = vt_json_array(&j, root, "streams");
    for (uint32_t i = 0; i < f->stream_count; i++) {
        const vdsh_stream *s = &f->streams[i];
        coef0_stats st = stream_coef0(f, s);
        cJSON *o = vt_json_object(&j, streams, NULL);
        vt_json_u64(&j, o, "order", s->order);
        vt_json_u64(&j, o, "coefficients", s->order * s->order);
        vt_json_string(&j, o, "encoding", vdsh_encoding_name(s->encoding));
        vt_json_string(&j, o, "method", or_unknown(vdsh_method_name(s->method)));
        vt_json_u64(&j, o, "method_id", s->method);
        vt_json_f32(&j, o, "method_param", s->method_param);
        vt_json_string(&j, o, "quantity", vdsh_quantity_name(s->quantity));
        vt_json_f32(&j, o, "quantity_param", s->quantity_param);
        vt_json_string(&j, o, "window", vdsh_window_name(s->window));
        vt_json_f32(&j, o, "window_param", s->window_param);
        vt_json_f32(&j, o, "scale", s->scale);
        if (vdsh_encoding_quantised(s->encoding) && s->coef_scales) {
            cJSON *t = vt_json_array(&j, o, "coef_scales");
            for (uint32_t k = 0; k < s->order * s->order; k++)
                vt_json_f32(&j, t, NULL, s->coef_scales[k]);
        }
        vt_json_u64(&j, o, "bytes_per_vertex", vdsh_stream_bytes_per_vertex(s));
        if (s->encoding == VDSH_ENCODING_CPCA) {
            cJSON *cp = vt_json_object(&j, o, "cpca");
            vt_json_u64(&j, cp, "clusters", s->cpca.clusters);
            vt_json_u64(&j, cp, "basis", s->cpca.basis);
            vt_json_u64(&j, cp, "bits", s->cpca.bits);
            vt_json_string(&j, cp, "bases", s->cpca.bases_s8 ? "s8" : "f16");
            vt_json_u64(&j, cp, "record_words", s->cpca.record_words);
            vt_json_u64(&j, cp, "model_bytes", vdsh_cpca_stream_model_bytes(&s->cpca, s->order));
            if (!s->cpca.bits) {
                cJSON *wa = vt_json_array(&j, cp, "widths");
                for (uint32_t q = 0; q < s->cpca.basis; q++)
                    vt_json_u64(&j, wa, NULL, s->cpca.widths[q]);
            }
            vt_json_f64(&j, cp, "mean_bytes_per_vertex",
                        vdsh_stream_size_of(s, vdsh_file_stream_vertices(f)).mean_bytes);
        }
        vt_json_bool(&j, o, "variable_order", (s->flags & VDSH_STREAM_VARIABLE) != 0);
        if (s->flags & VDSH_STREAM_VARIABLE) {
            vdsh_stream_size z = vdsh_stream_size_of(s, vdsh_file_stream_vertices(f));
            vt_json_f64(&j, o, "mean_bytes_per_vertex", z.mean_bytes);
            vt_json_u64(&j, o, "max_bytes_per_vertex", z.max_bytes);
            cJSON *per = vt_json_array(&j, o, "vertices_per_order"); /* [k - 1]: order k */
            for (uint32_t k = 1; k <= s->order; k++)
                vt_json_u64(&j, per, NULL, z.rows_per_order[k]);
        }
        cJSON *c0 = vt_json_object(&j, o, "coefficient0");
        vt_json_f32(&j, c0, "min", (float)st.min);
        vt_json_f32(&j, c0, "max", (float)st.max);
        vt_json_f64(&j, c0, "mean", st.mean);
    }

    vt_record_stats(&j, root, f, 1);

    if (f->has_part) {
        cJSON *pt = vt_json_object(&j, root, "part");
        vt_json_u64(&j, pt, "index", f->part.index);
        vt_json_u64(&j, pt, "count", f->part.count);
        vt_json_u64(&j, pt, "range_begin", f->part.range_begin);
        vt_json_u64(&j, pt, "range_end", f->part.range_end);
        vt_json_string(&j, pt, "encoding", vdsh_encoding_name(f->part.encoding));
        if (f->part.encoding == VDSH_ENCODING_CPCA) {
            vt_json_u64(&j, pt, "cpca_clusters", f->part.cpca_clusters);
            vt_json_u64(&j, pt, "cpca_basis", f->part.cpca_basis);
            vt_json_u64(&j, pt, "cpca_bits", f->part.cpca_bits);
            vt_json_f64(&j, pt, "cpca_light_mix",
                        f->has_light_pool ? (double)f->light_pool.mix : 0.0);
            vt_json_u64(&j, pt, "cpca_light_pool", f->has_light_pool ? f->light_pool.count : 0);
            vt_json_f64(&j, pt, "cpca_margin",
                        f->has_light_pool ? (double)f->light_pool.margin : 0.0);
            vt_json_u64(&j, pt, "cpca_starts", f->has_light_pool ? f->light_pool.starts : 0);
        }
    }
    if (f->has_adaptive) {
        const vdsh_adaptive *a = &f->adaptive;
        const struct {
            const char *key;
            uint64_t v;
        } count[] = {{"max_receivers", a->max_receivers},
                     {"lights", a->lights},
                     {"max_rounds", a->max_rounds},
                     {"start_receivers", a->start_receivers},
                     {"rounds", a->rounds},
                     {"candidates", a->candidates}};
        cJSON *ad = vt_json_object(&j, root, "adaptive");
        vt_json_f32(&j, ad, "tolerance", a->tolerance);
        vt_json_f32(&j, ad, "min_edge", a->min_edge);
        for (size_t i = 0; i < sizeof count / sizeof count[0]; i++)
            vt_json_u64(&j, ad, count[i].key, count[i].v);
    }
    if (f->has_light_box) {
        const vdsh_light_box *b = &f->light_box;
        cJSON *lr = vt_json_object(&j, root, "light_region");
        vt_json_string(&j, lr, "rule", b->rule == VDSH_LIGHT_REGION_GROWN ? "grown" : "box");
        cJSON *mn = vt_json_array(&j, lr, "min"), *mx = vt_json_array(&j, lr, "max");
        for (int a = 0; a < 3; a++) {
            vt_json_f32(&j, mn, NULL, b->min[a]);
            vt_json_f32(&j, mx, NULL, b->max[a]);
        }
    }
    vt_record_timings(&j, root, f);
    return json_emit(&j, path);
}

static int print_json_error(const char *path, vdsh_result r, const char *msg)
{
    vt_json j = {0};
    cJSON *root = vt_json_object(&j, NULL, NULL);
    vt_json_string(&j, root, "file", path);
    vt_json_bool(&j, root, "valid", 0);
    vt_json_string(&j, root, "result", vdsh_result_str(r));
    vt_json_string(&j, root, "error", msg);
    return json_emit(&j, path);
}

/* ------------------------------------------------------------------ */
/* Verify                                                              */
/* ------------------------------------------------------------------ */

/* The whole file, for the chunk walk and the validation of the same bytes.
 * Plain stdio, no knowledge of the layout. */
static int slurp(const char *path, uint8_t **out, size_t *out_size, char *msg, size_t msg_size)
{
    /* Only regular files: /dev/zero would be read until memory runs out,
     * and opening a FIFO would wait for a writer (hence O_NONBLOCK, which
     * regular files ignore). */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        snprintf(msg, msg_size, "%s: cannot open: %s", path, strerror(errno));
        return 0;
    }
    struct stat st;
    int bad = fstat(fd, &st) != 0 ? errno : !S_ISREG(st.st_mode) ? -1 : 0;
    FILE *fp = bad ? NULL : fdopen(fd, "rb");
    if (!fp) {
        if (!bad)
            bad = errno;
        snprintf(msg, msg_size, "%s: %s", path, bad < 0 ? "not a regular file" : strerror(bad));
        close(fd);
        return 0;
    }
    size_t cap = 1 << 16, size = 0;
    uint8_t *buf = malloc(cap);
    while (buf) {
        size += fread(buf + size, 1, cap - size, fp);
        if (size < cap)
            break;
        uint8_t *grown = cap <= SIZE_MAX / 2 ? realloc(buf, cap * 2) : NULL;
        if (!grown) {
            free(buf);
            buf = NULL;
            break;
        }
        buf = grown;
        cap *= 2;
    }
    int failed = !buf || ferror(fp);
    int e = errno;
    fclose(fp);
    if (failed) {
        snprintf(msg, msg_size, "%s: %s", path, buf ? strerror(e) : "out of memory");
        free(buf);
        return 0;
    }
    *out = buf;
    *out_size = size;
    return 1;
}

static int verify(const char *path, int json)
{
    uint8_t *data = NULL;
    size_t size = 0;
    char msg[600];
    vdsh_error err;
    if (!slurp(path, &data, &size, msg, sizeof msg)) {
        fprintf(stderr, "%s: %s\n", prog, msg);
        if (json)
            print_json_error(path, VDSH_ERR_IO, msg);
        return 0;
    }

    uint32_t count = 0;
    vdsh_chunk_info *chunks = NULL;
    vdsh_result r = vdsh_scan_chunks(data, size, path, NULL, 0, &count, &err);
    if (r == VDSH_OK && count) {
        chunks = calloc(count, sizeof *chunks);
        r = chunks ? vdsh_scan_chunks(data, size, path, chunks, count, &count, &err)
                   : VDSH_ERR_OUT_OF_MEMORY;
        if (!chunks)
            snprintf(err.msg, sizeof err.msg, "%s: out of memory", path);
    }
    int bad_chunks = 0;
    for (uint32_t i = 0; r == VDSH_OK && i < count; i++)
        bad_chunks += !chunks[i].complete || chunks[i].crc_stored != chunks[i].crc_computed;

    /* The walk lists what is there; the reader judges every rule. */
    vdsh_file *f = NULL;
    vdsh_result valid = r;
    if (r == VDSH_OK)
        valid = vdsh_read_memory(data, size, path, &f, &err);
    vdsh_free(f);

    if (json) {
        vt_json j = {0};
        cJSON *root = vt_json_object(&j, NULL, NULL);
        vt_json_string(&j, root, "file", path);
        vt_json_u64(&j, root, "file_size", size);
        cJSON *list = vt_json_array(&j, root, "chunks");
        for (uint32_t i = 0; r == VDSH_OK && i < count; i++) {
            const vdsh_chunk_info *c = &chunks[i];
            char crc[2][16];
            snprintf(crc[0], sizeof crc[0], "0x%08x", c->crc_stored);
            snprintf(crc[1], sizeof crc[1], "0x%08x", c->crc_computed);
            cJSON *o = vt_json_object(&j, list, NULL);
            vt_json_u64(&j, o, "index", i);
            vt_json_string(&j, o, "id", c->id);
            vt_json_u64(&j, o, "offset", c->offset);
            vt_json_u64(&j, o, "size", c->size);
            vt_json_bool(&j, o, "complete", c->complete);
            vt_json_string(&j, o, "crc_stored", crc[0]);
            vt_json_string(&j, o, "crc_computed", crc[1]);
            vt_json_bool(&j, o, "crc_ok", c->complete && c->crc_stored == c->crc_computed);
        }
        vt_json_bool(&j, root, "valid", valid == VDSH_OK);
        vt_json_string(&j, root, "result", vdsh_result_str(valid));
        vt_json_string(&j, root, "error", valid == VDSH_OK ? NULL : err.msg);
        if (!json_emit(&j, path))
            bad_chunks = -1; /* not printed: json_emit said why */
    } else {
        printf("%s: %zu byte%s\n", path, size, vdsh_s(size));
        if (r == VDSH_OK)
            printf("  chunk  id        offset          size  crc\n");
        for (uint32_t i = 0; r == VDSH_OK && i < count; i++) {
            const vdsh_chunk_info *c = &chunks[i];
            printf("  %5u  %-4s  %12llu  %12llu  0x%08x ", i, c->id, (unsigned long long)c->offset,
                   (unsigned long long)c->size, c->crc_stored);
            if (!c->complete)
                printf("incomplete: runs past the end of the file\n");
            else if (c->crc_stored == c->crc_computed)
                printf("ok\n");
            else
                printf("MISMATCH (computed 0x%08x)\n", c->crc_computed);
        }
        if (valid == VDSH_OK)
            printf("  valid: every rule of format version %u holds\n", VDSH_FORMAT_VERSION);
        else
            printf("  INVALID (%s): %s\n", vdsh_result_str(valid), err.msg);
    }
    if (valid != VDSH_OK)
        fprintf(stderr, "%s: %s\n", prog, err.msg);
    else if (bad_chunks > 0) /* cannot happen for a file the reader accepts */
        fprintf(stderr, "%s: %s: %d %s\n", prog, path, bad_chunks,
                bad_chunks == 1 ? "chunk fails its CRC" : "chunks fail their CRC");
    free(chunks);
    free(data);
    return valid == VDSH_OK && bad_chunks == 0;
}

/* ------------------------------------------------------------------ */

static int info(const char *path, int json, int first)
{
    vdsh_file *f = NULL;
    vdsh_error err;
    vdsh_result r = vdsh_read(path, &f, &err);
    if (r != VDSH_OK) {
        fprintf(stderr, "%s: %s\n", prog, err.msg);
        if (json)
            print_json_error(path, r, err.msg);
        return 0;
    }
    uint64_t size = file_size_of(path);
    int ok = 1;
    if (json) {
        ok = print_json(path, f, size);
    } else {
        if (!first)
            putchar('\n');
        print_summary(path, f, size);
    }
    vdsh_free(f);
    return ok;
}

/* ------------------------------------------------------------------ */
/* The command line                                                    */
/* ------------------------------------------------------------------ */

typedef struct options {
    const char *json_out; /* --json FILE ('-': stdout), or NULL */
    int check;            /* --verify */
    char **files;         /* FILE.vdsh... */
    int file_count;
} options;

/* -1 with *o ready to run, else the exit status (help, version, a usage
 * error: said). */
static int parse_args(int argc, char **argv, options *o)
{
    static const struct option longopts[] = {
        {"json", required_argument, NULL, 'j'},
        {"verify", no_argument, NULL, 'c'},
        {"help", no_argument, NULL, 'h'},
        {"version", no_argument, NULL, 'V'},
        {NULL, 0, NULL, 0},
    };
    memset(o, 0, sizeof *o);
    int opt;
    while ((opt = getopt_long(argc, argv, "j:hV", longopts, NULL)) != -1) {
        switch (opt) {
        case 'j':
            if (!vt_opt_once("--json", optarg, &o->json_out))
                return VT_EXIT_USAGE;
            break;
        case 'c': o->check = 1; break;
        case 'h': usage(stdout); return 0;
        case 'V': return vt_cli_version(NULL);
        default: return vt_cli_try_help();
        }
    }
    if (optind >= argc) {
        size_t n = o->json_out ? strlen(o->json_out) : 0;
        if (n > 5 && strcmp(o->json_out + n - 5, ".vdsh") == 0)
            return vt_usage_error(prog,
                                  "no input file (--json takes the JSON file to write: "
                                  "--json - %s prints it)",
                                  o->json_out);
        return vt_usage_error(prog, "%s", "no input file");
    }
    o->files = argv + optind;
    o->file_count = argc - optind;
    return -1;
}

/* Every file in turn (each failure said, the others still done), then
 * the JSON of them all. */
static int run(const options *o)
{
    const int json = o->json_out != NULL;
    if (json &&
        vt_cli_check_outputs(&o->json_out, 1, (const char *const *)o->files, o->file_count) != 0)
        return 1;

    int ok = 1;
    for (int i = 0; i < o->file_count; i++) {
        if (o->check && !json && i > 0)
            putchar('\n');
        ok &= o->check ? verify(o->files[i], json) : info(o->files[i], json, i == 0);
    }
    if (json && !json_write(o->json_out))
        ok = 0;
    free(json_text);
    if (fflush(stdout) != 0 || ferror(stdout)) {
        fprintf(stderr, "%s: cannot write output: %s\n", prog, strerror(errno));
        return 1;
    }
    return ok ? 0 : 1;
}

int main(int argc, char **argv)
{
    vt_cli_begin(prog, argv);
    vt_cli_clean_exit_on_signals(); /* no temporary file left by a signal */
    options o;
    int status = parse_args(argc, argv, &o);
    return status >= 0 ? status : run(&o);
}
