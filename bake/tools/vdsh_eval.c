/*
 * vdsh-eval - how far a baked .vdsh is from the truth (docs/DESIGN.md §3).
 *
 * The story of an evaluation: read the file; rebuild the occluder scene the
 * bake traced (its recorded sources, or meshes given on the command line,
 * each checked against the recorded SHA-256); run the evaluator (eval.h:
 * an independent Embree ray cast from held-out directions, lights and
 * points); print a table, and write the JSON and per-vertex files if asked.
 * Every report carries the bake's parameters and time beside the errors.
 *
 * --per-vertex FILE, for a heat map in a viewer (little-endian):
 *
 *   offset  type      field
 *   0       u8[8]     magic "VDSHPVE1"
 *   8       u32       version = 1
 *   12      u32       vertex_count V (the .vdsh file's)
 *   16      u32       stream_count K (the streams scored, in file order)
 *   20      u32       fields per record F = 2 + 5K
 *   24      u32       data_offset = 64 + 16K
 *   28      u8[36]    zero
 *   64      K x u32[4] per stream: order, quantity, method, encoding
 *   data_offset       V records of F f32, vertex-major:
 *           [0] fraction of the vertex's truth at ~0 distance (< 1e-3 diag)
 *           [1] fraction of its truth rays that hit nothing
 *           [2 + 5k + 0] distance RMS (relative) of stream k
 *           [2 + 5k + 1] smooth shadow MAE
 *           [2 + 5k + 2] false-shadow rate (NaN: no truly visible light)
 *           [2 + 5k + 3] light-leak rate (NaN: no truly occluded light)
 *           [2 + 5k + 4] binary shadow MAE
 *   Every field of a vertex that was not evaluated (--points sample,
 *   undefined normal) is NaN. Interior points are not in this file; the
 *   JSON lists the worst of them.
 */
#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bake.h"
#include "eval.h"
#include "vdsh_shadow.h"
#include "scene.h"
#include "vdsh.h"
#include "vdsh_output.h"
#include "vt_args.h"
#include "vt_cli.h"
#include "vt_json.h"
#include "vt_record.h"

#define PV_MAGIC "VDSHPVE1"
#define PV_VERSION 1u
#define PV_HEADER 64u
#define PV_STREAM 16u

static void usage(FILE *f)
{
    fprintf(f,
            "usage: vdsh-eval [options] FILE.vdsh [MESH...]\n"
            "Measure a bake's error against an independent Embree ray cast.\n"
            "\n"
            "The occluder scene is rebuilt from the sources recorded in FILE (looked\n"
            "up as recorded, then beside FILE), or from the MESHes given, one per\n"
            "recorded source and in the same order; each must have the SHA-256 the\n"
            "bake recorded. Receivers are vertices and random points inside triangles\n"
            "(coefficients interpolated as the GPU does). The primary shadow metric:\n"
            "point lights placed uniformly in the scene's free space (formats/\n"
            "vdsh_light.h), each scored at every receiver it lights, as a viewer sees\n"
            "them. Secondary (earlier figures): each receiver's own held-out upper-\n"
            "hemisphere directions (never the bake's), one light per direction at\n"
            "d_L = u * 2 * d_T, u uniform in (0.05, 1]; also the distance error.\n"
            "\n"
            "Sampling:\n"
            "      --points N          vertices evaluated: a deterministic sample of N\n"
            "                          (default: all)\n"
            "      --interior N        random points inside triangles (default 65536;\n"
            "                          0: none)\n"
            "      --directions N      held-out directions (and lights) per receiver\n"
            "                          (default 64 = 8 x 8 grid over the hemisphere)\n"
            "      --seed N            the evaluator's seed (default %u; 0 is the\n"
            "                          default); any seed, even the bake's, gives other\n"
            "                          directions than the bake's\n"
            "      --lights N          scene lights (default 32)\n"
            "      --light-rule R      where they go, all in free space: uniform (default),\n"
            "                          ceiling (the top fifth of the height, +y up), near\n"
            "                          (a surface within 5%% of the diagonal) or path (a\n"
            "                          walk along x at 2/3 of the height, swinging in z);\n"
            "                          heights of the light region: the bounds, or around a\n"
            "                          closed object the bounds grown (formats/vdsh_light.h);\n"
            "                          grown (the bounds grown by a quarter of their\n"
            "                          diagonal, not below an open floor) or around\n"
            "                          (grown by a diagonal, outside\n"
            "                          the bounds: where a viewer puts lights around an\n"
            "                          object) or shell (grown by a quarter diagonal,\n"
            "                          outside the bounds: vdsh-bake's --decision-shell);\n"
            "                          around and shell not below an open floor either\n"
            "                          (nor past any side a one-sided surface closes)\n"
            "      --light-region SPEC the light region of uniform, ceiling, near and path:\n"
            "                          file (default: the bake's --light-region, recorded\n"
            "                          in the file, else auto), auto (the scene's rule),\n"
            "                          grown (the bounds grown by a quarter diagonal, not\n"
            "                          below an open floor: vdsh-bake's) or a box\n"
            "                          XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX\n"
            "      --orders LIST       only these orders, e.g. 3,5 (default: every stream)\n"
            "      --offsets LIST      the trade between recall and false shadows as a\n"
            "                          curve: each stream is also scored with each\n"
            "                          offset added to its ln D (distance streams: D\n"
            "                          times e^offset), e.g. -0.2,0.2,0.4 (at most %d\n"
            "                          streams in all: pick orders with --orders)\n"
            "      --oracle            score the ray-cast truth instead of the streams:\n"
            "                          every error must come out exactly 0 (not with\n"
            "                          --offsets)\n"
            "      --interp M          how interior points get a stream's value from the\n"
            "                          triangle's vertices: runtime (default: the path\n"
            "                          vdsh-view draws the stream with), coefficients,\n"
            "                          distance, visibility or split (vdsh_shadow.h;\n"
            "                          not with --interior 0)\n"
            "      --fast-truth        Embree's default traversal for the truth (default:\n"
            "                          robust, so truth rays do not leak through edges)\n"
            "      --allow-mismatch    use sources whose SHA-256 differs (with a warning)\n"
            "\n"
            "Output:\n"
            "      --json FILE         everything as JSON (bake parameters and timings too;\n"
            "                          -: on stdout, instead of the table)\n"
            "      --per-vertex FILE   per-vertex errors for a heat map (layout below)\n"
            "      --bake-report FILE  take the bake time from vdsh-bake --report JSON\n"
            "                          of this file's bake (its receivers and sources\n"
            "                          must match; default: the file's time chunk, if\n"
            "                          recorded)\n"
            "      --worst N           worst receivers listed (default 10, at most 64)\n"
            "      --threads N         worker threads (default: all cores)\n"
            "  -q, --quiet             nothing on stderr but errors (no progress or\n"
            "                          warnings; the results still go to stdout)\n"
            "  -h, --help              this text\n"
            "  -V, --version           version\n"
            "\n"
            "Errors (per stream, for vertices and interior points separately):\n"
            "  scene     smooth shadow MAE, false-shadow rate P(s_hat < .5 | d_T >= d_L),\n"
            "            recall P(s_hat < .5 | s_ideal < .5) (the shadows a viewer sees\n"
            "            drawn); binary: P(D < d_L | d_T >= d_L), P(D < d_L | d_T < d_L);\n"
            "            the JSON's mae_parts split the MAE by pair class (false, lit\n"
            "            partial, missed, drawn, penumbra: they add up to it)\n"
            "  distance  |D - d_T| / max(d_T, 0.01 diag): RMS, p50, p90, p99\n"
            "  shadow    smooth ramp(d / d_L): MAE |s_hat - s_ideal|, false-shadow rate\n"
            "            P(s_hat < .5 | d_T >= d_L), light-leak rate P(s_hat > .5 |\n"
            "            s_ideal < .5); and the same with the binary comparison\n"
            "  +- is a 95%% interval (1.96 standard errors, receivers as clusters).\n"
            "\n"
            "--per-vertex layout (little-endian): a 64-byte header: magic \"%s\",\n"
            "u32 version (1), u32 vertex_count V, u32 stream_count K, u32 fields F\n"
            "(= 2 + 5K), u32 data_offset (= 64 + 16K), zero to 64; then K stream\n"
            "descriptors of 4 u32: order, quantity, method, encoding; then V records\n"
            "of F f32 at data_offset, vertex-major: [0] fraction of the truth at ~0\n"
            "distance, [1] fraction of truth rays that escaped, then per stream k at\n"
            "2 + 5k: distance RMS, smooth shadow MAE, false-shadow rate, light-leak\n"
            "rate, binary shadow MAE. NaN: vertex not evaluated (or, for the two\n"
            "rates, no light of that kind).\n"
            "\n"
            "Exit status: 0 success, 1 error, 2 usage error.\n"
            "Example: vdsh-bake builtin:room --max-edge 0.5 -o room.vdsh --record-timings\n"
            "         vdsh-eval room.vdsh --json room.eval.json\n",
            VB_EVAL_DEFAULT_SEED, VDSH_MAX_STREAMS, PV_MAGIC);
}

static int bad_usage(const char *fmt, const char *arg)
{
    return vt_usage_error("vdsh-eval", fmt, arg);
}

/* ---- progress on a terminal -------------------------------------------- */

typedef struct progress {
    int enabled;
    double t0;
} progress;

static void on_progress(void *user, uint32_t done, uint32_t total)
{
    progress *p = user;
    if (!p->enabled)
        return;
    double t = vb_now() - p->t0;
    double frac = total ? (double)done / total : 1.0;
    double eta = frac > 0.0 ? t * (1.0 - frac) / frac : 0.0;
    fprintf(stderr, "\r  %5.1f%%  %u/%u receiver%s  ETA %.1f s   ", 100.0 * frac, done, total,
            vdsh_s(total), eta);
    if (done == total)
        fputs("\r                                                        \r", stderr);
    fflush(stderr);
}

typedef struct warnings {
    const char *path;
    int count;
    int quiet; /* -q: counted, not said */
} warnings;

static void on_warn(void *user, const char *msg)
{
    warnings *w = user;
    w->count++;
    if (!w->quiet)
        fprintf(stderr, "vdsh-eval: %s: warning: %s\n", w->path, msg);
}

/* ---- bake time ------------------------------------------------------------- */

typedef struct bake_time {
    double total, trace;
    unsigned threads;
    const char *source; /* "time chunk", "bake report" or NULL */
} bake_time;

/* vdsh-bake --report: "seconds": {..., "trace": T, ..., "total": T} and
 * "threads": N, read with the JSON parser every tool shares (vt_json.h). */
/* 1 when the report's receivers and sources are the file's (a report of
 * another bake gave its time as this file's, exit 0); else 0 with msg. */
static int report_is_of(const cJSON *root, const char *path, const vdsh_file *f,
                        const char *vdsh_path, char *msg, size_t cap)
{
    double receivers = vt_json_number(root, "receivers");
    const cJSON *src = cJSON_GetObjectItemCaseSensitive(root, "sources");
    int same = receivers == (double)f->header.vertex_count && cJSON_IsArray(src) &&
               cJSON_GetArraySize(src) == (int)f->source_count;
    for (uint32_t i = 0; same && i < f->source_count; i++) {
        const cJSON *n = cJSON_GetArrayItem(src, (int)i);
        same = cJSON_IsString(n) && strcmp(n->valuestring, f->sources[i].name) == 0;
    }
    if (!same)
        snprintf(msg, cap,
                 "%s: the report of another bake (%.0f receivers, first source '%s'), not "
                 "of %s (%u receivers, first source '%s')",
                 path, receivers >= 0.0 ? receivers : -1.0,
                 cJSON_IsArray(src) && cJSON_IsString(cJSON_GetArrayItem(src, 0))
                     ? cJSON_GetArrayItem(src, 0)->valuestring
                     : "?",
                 vdsh_path, f->header.vertex_count, f->source_count ? f->sources[0].name : "?");
    return same;
}

static int read_bake_report(const char *path, const vdsh_file *f, const char *vdsh_path,
                            bake_time *bt, char *msg, size_t cap)
{
    cJSON *root = vt_json_read_file(path, msg, cap);
    if (!root)
        return 0;
    const cJSON *sec = cJSON_GetObjectItemCaseSensitive(root, "seconds");
    double total = vt_json_number(sec, "total");
    if (!cJSON_IsObject(root) || !cJSON_IsObject(sec) || !(total >= 0.0)) {
        snprintf(msg, cap, "%s: no \"seconds\": {\"total\": ...} (not a vdsh-bake --report?)",
                 path);
        cJSON_Delete(root);
        return 0;
    }
    if (!report_is_of(root, path, f, vdsh_path, msg, cap)) {
        cJSON_Delete(root);
        return 0;
    }
    double threads = vt_json_number(root, "threads");
    bt->total = total;
    bt->trace = vt_json_number(sec, "trace");
    bt->threads = threads >= 1.0 && threads <= 65536.0 ? (unsigned)threads : 0;
    bt->source = "bake report";
    cJSON_Delete(root);
    return 1;
}

/* ---- JSON (vt_json.h: cJSON, exact numbers, NaN as null) ------------------ */

static void json_vec(vt_json *j, cJSON *parent, const char *key, const float *v)
{
    cJSON *a = vt_json_array(j, parent, key);
    for (int i = 0; i < 3; i++)
        vt_json_f32(j, a, NULL, v[i]);
}

static void json_receiver(vt_json *j, cJSON *list, const vb_eval_receiver *r, int kind)
{
    cJSON *o = vt_json_object(j, list, NULL);
    vt_json_u64(j, o, "index", r->index);
    if (kind == VB_EVAL_INTERIOR) {
        vt_json_u64(j, o, "triangle", r->triangle);
        json_vec(j, o, "bary", r->bary);
    }
    json_vec(j, o, "position", r->position);
    json_vec(j, o, "normal", r->normal);
    vt_json_f64(j, o, "shadow_mae", r->shadow_mae);
    vt_json_f64(j, o, "distance_rms", r->distance_rms);
    vt_json_f64(j, o, "false_shadow", r->false_shadow);
    vt_json_f64(j, o, "near_zero", r->near_zero);
    vt_json_f64(j, o, "escaped", r->escaped);
}

/* Numbers under their keys, in order. */
typedef struct named_f64 {
    const char *key;
    double v;
} named_f64;

static void json_f64s(vt_json *j, cJSON *o, const named_f64 *x, size_t n)
{
    for (size_t i = 0; i < n; i++)
        vt_json_f64(j, o, x[i].key, x[i].v);
}

static void json_metrics(vt_json *j, cJSON *o, const vb_eval_metrics *m, int kind)
{
    vt_json_u64(j, o, "samples", m->samples);
    const named_f64 num[] = {{"distance_rms", m->distance_rms},
                             {"distance_rms_se", m->distance_rms_se},
                             {"distance_mean", m->distance_mean},
                             {"distance_p50", m->distance_p50},
                             {"distance_p90", m->distance_p90},
                             {"distance_p99", m->distance_p99},
                             {"shadow_mae", m->shadow_mae},
                             {"shadow_mae_se", m->shadow_mae_se},
                             {"false_shadow", m->false_shadow},
                             {"false_shadow_se", m->false_shadow_se},
                             {"light_leak", m->light_leak},
                             {"light_leak_se", m->light_leak_se},
                             {"binary_mae", m->binary_mae},
                             {"binary_mae_se", m->binary_mae_se},
                             {"binary_false_shadow", m->binary_false_shadow},
                             {"binary_false_shadow_se", m->binary_false_shadow_se},
                             {"binary_light_leak", m->binary_light_leak},
                             {"binary_light_leak_se", m->binary_light_leak_se},
                             {"ringing", m->ringing},
                             {"receiver_mae_p50", m->receiver_mae_p50},
                             {"receiver_mae_p90", m->receiver_mae_p90},
                             {"receiver_mae_p99", m->receiver_mae_p99}};
    json_f64s(j, o, num, sizeof num / sizeof num[0]);
    vt_json_u64(j, o, "visible", m->visible);
    vt_json_u64(j, o, "occluded", m->occluded);
    vt_json_u64(j, o, "occluded_binary", m->occluded_binary);
    cJSON *worst = vt_json_array(j, o, "worst");
    for (uint32_t i = 0; i < m->worst_count; i++)
        json_receiver(j, worst, &m->worst[i], kind);
}

/* A count for the table, readably: whole below 10,000, else k, M or G with
 * three figures (88, 9999, 12.3k, 456k, 1.23M; was "8.8e-05M"). */
static const char *count_label(uint64_t n, char *buf, size_t size)
{
    static const char unit[] = "kMGT";
    if (n < 10000) {
        snprintf(buf, size, "%llu", (unsigned long long)n);
        return buf;
    }
    double v = (double)n;
    int u = -1;
    do {
        v /= 1000.0, u++;
    } while (v >= 999.5 && u < 3);
    snprintf(buf, size, v < 9.995 ? "%.2f%c" : v < 99.95 ? "%.1f%c" : "%.0f%c", v, unit[u]);
    return buf;
}

static void json_scene(vt_json *j, cJSON *o, const vb_eval_scene_metrics *m)
{
    vt_json_u64(j, o, "pairs", m->pairs);
    vt_json_u64(j, o, "visible", m->visible);
    vt_json_u64(j, o, "occluded", m->occluded);
    const named_f64 f[] = {{"shadow_mae", m->shadow_mae},
                           {"shadow_mae_se", m->shadow_mae_se},
                           {"false_shadow", m->false_shadow},
                           {"false_shadow_se", m->false_shadow_se},
                           {"recall", m->recall},
                           {"recall_se", m->recall_se},
                           {"light_leak", m->light_leak},
                           {"light_leak_se", m->light_leak_se},
                           {"binary_mae", m->binary_mae},
                           {"binary_false_shadow", m->binary_false_shadow},
                           {"binary_recall", m->binary_recall}};
    json_f64s(j, o, f, sizeof f / sizeof f[0]);
    cJSON *parts = vt_json_object(j, o, "mae_parts");
    const named_f64 p[] = {{"false", m->mae_part[VB_EVAL_PART_FALSE]},
                           {"lit_partial", m->mae_part[VB_EVAL_PART_LIT_PARTIAL]},
                           {"missed", m->mae_part[VB_EVAL_PART_MISSED]},
                           {"drawn", m->mae_part[VB_EVAL_PART_DRAWN]},
                           {"penumbra", m->mae_part[VB_EVAL_PART_PENUMBRA]}};
    json_f64s(j, parts, p, sizeof p / sizeof p[0]);
}

static void json_truth(vt_json *j, cJSON *o, const vb_eval_truth *t, int kind)
{
    vt_json_u64(j, o, "receivers", t->receivers);
    vt_json_u64(j, o, "skipped_undefined_normal", t->skipped);
    vt_json_u64(j, o, "rays", t->rays);
    vt_json_u64(j, o, "escaped", t->escaped);
    vt_json_f64(j, o, "escape_rate", t->rays ? (double)t->escaped / t->rays : NAN);
    vt_json_u64(j, o, "near_zero", t->near_zero);
    vt_json_f64(j, o, "near_zero_rate", t->rays ? (double)t->near_zero / t->rays : NAN);
    vt_json_u64(j, o, "degenerate", t->degenerate);
    vt_json_f64(j, o, "degenerate_rate", t->receivers ? (double)t->degenerate / t->receivers : NAN);
    cJSON *deg = vt_json_array(j, o, "degenerate_list");
    for (uint32_t i = 0; i < t->degenerate_listed; i++)
        json_receiver(j, deg, &t->degenerate_list[i], kind);
    cJSON *esc = vt_json_array(j, o, "escaping_list");
    for (uint32_t i = 0; i < t->escaping_listed; i++)
        json_receiver(j, esc, &t->escaping_list[i], kind);
}

typedef struct context {
    const char *path;
    const vdsh_file *f;
    char **source_paths;
    long long file_bytes;
    bake_time bt;
    const vb_eval_result *r;
    const vb_eval_desc *d;
    int fast_truth;
    int mismatched;      /* sources used despite a different SHA-256 */
    const float *offset; /* per scored stream: the log offset added (--offsets) */
    int copies;          /* 1 + offsets with --offsets (scored.copies), else 0 */
} context;

/* Scored stream s as the file stores it: an --offsets copy (f32 in
 * memory) is its original's, whose bytes and encoding it reports. */
static const vdsh_stream *stored(const context *c, uint32_t s)
{
    return &c->f->streams[c->copies ? s - s % (uint32_t)c->copies : s];
}

/* "5", or "a12" for a variable-order stream of cap 12. */
static const char *order_label(const vdsh_stream *st, char *buf, size_t n)
{
    snprintf(buf, n, "%s%u", st->flags & VDSH_STREAM_VARIABLE ? "a" : "", st->order);
    return buf;
}

static const char *kind_name(int k)
{
    return k == VB_EVAL_VERTICES ? "vertices" : "interior";
}

static int write_json(const char *out, const context *c, char *msg, size_t cap)
{
    const vdsh_file *f = c->f;
    const vdsh_header *h = &f->header;
    const vb_eval_result *r = c->r;
    vt_json j = {0};
    cJSON *root = vt_json_object(&j, NULL, NULL);
    vt_json_string(&j, root, "tool", "vdsh-eval");
    vt_json_string(&j, root, "version", VDSH_VERSION_STRING);
    vt_json_string(&j, root, "file", c->path);
    vt_json_i64(&j, root, "file_bytes", c->file_bytes);

    cJSON *scene = vt_json_object(&j, root, "scene");
    cJSON *sources = vt_json_array(&j, scene, "sources");
    for (uint32_t i = 0; i < f->source_count; i++) {
        char hx[65];
        for (int k = 0; k < 32; k++)
            snprintf(hx + 2 * k, 3, "%02x", f->sources[i].sha256[k]);
        cJSON *o = vt_json_object(&j, sources, NULL);
        vt_json_string(&j, o, "name", f->sources[i].name);
        vt_json_string(&j, o, "loaded_from", c->source_paths[i]);
        vt_json_u64(&j, o, "size", f->sources[i].size);
        vt_json_string(&j, o, "sha256", hx);
    }
    vt_json_u64(&j, scene, "receiver_vertices", h->vertex_count);
    vt_json_u64(&j, scene, "receiver_triangles", h->triangle_count);
    vt_json_u64(&j, scene, "occluder_vertices", h->occluder_vertex_count);
    vt_json_u64(&j, scene, "occluder_triangles", h->occluder_triangle_count);
    json_vec(&j, scene, "bounds_min", h->bounds_min);
    json_vec(&j, scene, "bounds_max", h->bounds_max);
    vt_json_f32(&j, scene, "diagonal", r->diagonal);

    cJSON *bake = vt_json_object(&j, root, "bake");
    vt_record_params(&j, bake, h);
    vt_json_bool(&j, bake, "welded", h->load_flags & VDSH_LOAD_WELD);
    const char *up = vdsh_up_axis_name((h->load_flags & VDSH_LOAD_UP_MASK) >> VDSH_LOAD_UP_SHIFT);
    vt_json_string(&j, bake, "up_axis", up ? up : "?");
    if (VDSH_LOAD_CREASE(h->load_flags))
        vt_json_u64(&j, bake, "crease", VDSH_LOAD_CREASE(h->load_flags));
    vt_json_bool(&j, bake, "robust", h->trace_flags & VDSH_TRACE_ROBUST);
    vt_json_u64(&j, bake, "cube_size", h->cube_size);
    vt_record_stats(&j, bake, f, 0);
    vt_record_timings(&j, bake, f);
    vt_json_f64(&j, bake, "seconds", c->bt.source ? c->bt.total : NAN);
    vt_json_string(&j, bake, "seconds_from", c->bt.source);

    cJSON *ev = vt_json_object(&j, root, "eval");
    vt_json_u64(&j, ev, "seed", r->seed);
    vt_json_u64(&j, ev, "points_requested", c->d->points);
    vt_json_u64(&j, ev, "interior_requested", c->d->interior);
    vt_json_u64(&j, ev, "directions", r->directions);
    vt_json_bool(&j, ev, "oracle", r->oracle);
    vt_json_string(&j, ev, "truth_traversal", c->fast_truth ? "default" : "robust");
    vt_json_i64(&j, ev, "sources_mismatched", c->mismatched);
    vt_json_f64(&j, ev, "error_floor", 0.01 * r->diagonal);
    vt_json_u64(&j, ev, "threads", r->threads);
    vt_json_f64(&j, ev, "seconds", r->seconds);
    vt_json_u64(&j, ev, "scene_lights", r->light_count);
    vt_json_string(&j, ev, "scene_light_rule", vb_light_rule_name((vb_light_rule)c->d->light_rule));
    vt_json_u64(&j, ev, "scene_light_candidates", r->light_candidates);
    if (r->light_region_given) { /* the file's lreg, or --light-region */
        vt_json_string(&j, ev, "scene_light_region", "given");
        cJSON *box = vt_json_array(&j, ev, "scene_light_region_box");
        for (int a = 0; a < 6; a++)
            vt_json_f32(&j, box, NULL, a < 3 ? r->light_region_min[a] : r->light_region_max[a - 3]);
    } else if (r->light_region_grown) /* only then: earlier JSONs stay as they were */
        vt_json_string(&j, ev, "scene_light_region", "grown");
    cJSON *lp = vt_json_array(&j, ev, "scene_light_positions");
    for (uint32_t l = 0; l < r->light_count; l++)
        json_vec(&j, lp, NULL, r->lights[l]);

    cJSON *truth = vt_json_object(&j, root, "truth");
    for (int k = 0; k < VB_EVAL_KINDS; k++)
        json_truth(&j, vt_json_object(&j, truth, kind_name(k)), &r->truth[k], k);
    cJSON *streams = vt_json_array(&j, root, "streams");
    for (uint32_t s = 0; s < r->stream_count; s++) {
        const vdsh_stream *st = &f->streams[s];
        cJSON *o = vt_json_object(&j, streams, NULL);
        vt_json_u64(&j, o, "order", st->order);
        vt_json_u64(&j, o, "coefficients", st->order * st->order);
        vt_json_string(&j, o, "method", vdsh_method_name(st->method));
        vt_json_string(&j, o, "encoding", vdsh_encoding_name(stored(c, s)->encoding));
        vt_json_string(&j, o, "quantity", vdsh_quantity_name(st->quantity));
        vt_json_string(&j, o, "window", vdsh_window_name(st->window));
        vdsh_stream_size z = vdsh_stream_size_of(stored(c, s), vdsh_file_stream_vertices(f));
        vt_json_f64(&j, o, "bytes_per_vertex", z.mean_bytes);
        vt_json_u64(&j, o, "max_bytes_per_vertex", z.max_bytes);
        vt_json_bool(&j, o, "variable_order", (st->flags & VDSH_STREAM_VARIABLE) != 0);
        vt_json_f32(&j, o, "log_offset", c->offset[s]);
        cJSON *sl = vt_json_object(&j, o, "scene_lights");
        for (int k = 0; k < VB_EVAL_KINDS; k++)
            json_scene(&j, vt_json_object(&j, sl, kind_name(k)), &r->scene[k][s]);
        for (int k = 0; k < VB_EVAL_KINDS; k++)
            json_metrics(&j, vt_json_object(&j, o, kind_name(k)), &r->metrics[k][s], k);
    }
    int rc = vt_json_write_file(&j, out, msg, cap);
    vt_json_free(&j);
    return rc;
}

/* ---- per-vertex file (layout in usage()) --------------------------------- */

static void put_u32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16), p[3] = (unsigned char)(v >> 24);
}

/* Writes the whole file to a temporary and finishes it (on disk, not yet
 * renamed): the caller commits it once the JSON is written too, or aborts
 * it, so that a failed run leaves neither. */
static int write_per_vertex(const char *out, const vdsh_file *f, const vb_eval_result *r,
                            vdsh_output *po, char *msg, size_t cap)
{
    vdsh_output o;
    vdsh_error err;
    if (vdsh_output_open(out, &o, &err) != VDSH_OK) {
        snprintf(msg, cap, "%s", err.msg);
        return -1;
    }
    unsigned char head[PV_HEADER] = {0};
    memcpy(head, PV_MAGIC, 8);
    put_u32(head + 8, PV_VERSION);
    put_u32(head + 12, f->header.vertex_count);
    put_u32(head + 16, r->stream_count);
    put_u32(head + 20, r->per_vertex_fields);
    put_u32(head + 24, PV_HEADER + PV_STREAM * r->stream_count);
    vdsh_output_put(&o, head, sizeof head);
    for (uint32_t s = 0; s < r->stream_count; s++) {
        unsigned char d[PV_STREAM];
        put_u32(d, f->streams[s].order);
        put_u32(d + 4, f->streams[s].quantity);
        put_u32(d + 8, f->streams[s].method);
        put_u32(d + 12, f->streams[s].encoding);
        vdsh_output_put(&o, d, sizeof d);
    }
    /* f32 little-endian: the host's own layout (vdsh.h supports only
     * little-endian hosts). A failed write is remembered:
     * vdsh_output_commit reports it and removes the file. */
    vdsh_output_put(&o, r->per_vertex,
                    sizeof(float) * (size_t)f->header.vertex_count * r->per_vertex_fields);
    if (vdsh_output_finish(&o, &err) != VDSH_OK) {
        snprintf(msg, cap, "%s", err.msg);
        return -1;
    }
    *po = o;
    return 0;
}

/* ---- the table ---------------------------------------------------------------- */

/* A stream's fit in the tables: its method, and the quantity when not
 * distance ("decision+log"). */
static const char *fit_label(const vdsh_stream *st, char *buf, size_t cap)
{
    snprintf(buf, cap, "%s%s", vdsh_method_name(st->method),
             st->quantity == VDSH_QUANTITY_LOG_DISTANCE ? "+log"
             : st->quantity == VDSH_QUANTITY_DISTANCE2  ? "+d2"
                                                        : "");
    return buf;
}

/* The widths of the tables' enc and fit columns: at least the usual 3 and
 * 9, else the longest of the file's streams ("cpca", "decision+log"), so
 * the columns after them stay in line with the header. */
static void enc_fit_widths(const context *c, int *enc_w, int *fit_w)
{
    *enc_w = 3;
    *fit_w = 9;
    for (uint32_t s = 0; s < c->r->stream_count; s++) {
        char fit[32];
        int e = (int)strlen(vdsh_encoding_name(stored(c, s)->encoding));
        int m = (int)strlen(fit_label(&c->f->streams[s], fit, sizeof fit));
        *enc_w = e > *enc_w ? e : *enc_w;
        *fit_w = m > *fit_w ? m : *fit_w;
    }
}

/* The table's opening lines: the scene, the bake's parameters and its own
 * ray counts, the evaluator's parameters. */
static void print_run(FILE *o, const context *c)
{
    const vdsh_file *f = c->f;
    const vdsh_header *h = &f->header;
    const vb_eval_result *r = c->r;
    fprintf(o, "vdsh-eval %s: %s\n", VDSH_VERSION_STRING, c->path);
    fprintf(o, "  scene     ");
    for (uint32_t i = 0; i < f->source_count; i++)
        fprintf(o, "%s%s", i ? ", " : "", f->sources[i].name);
    if (c->mismatched)
        fprintf(o, " (%d source(s) DIFFER from the bake's: --allow-mismatch)\n", c->mismatched);
    else
        fprintf(o, " (SHA-256 verified)\n");
    fprintf(o,
            "            %u receiver %s, %u triangle%s; %u occluder triangle%s; "
            "diagonal %.4g\n",
            h->vertex_count, vdsh_plural(h->vertex_count, "vertex", "vertices"), h->triangle_count,
            vdsh_s(h->triangle_count), h->occluder_triangle_count,
            vdsh_s(h->occluder_triangle_count), (double)r->diagonal);
    fprintf(o, "  bake      %u rays/receiver (%s), seed %llu, max distance %.4g, max edge %g",
            h->rays, vdsh_sampling_name(h->sampling), (unsigned long long)h->seed,
            (double)h->max_distance, (double)h->max_edge);
    if (c->bt.source)
        fprintf(o, "; %.2f s (%s)\n", c->bt.total, c->bt.source);
    else
        fprintf(o, "; time not recorded (bake with --record-timings or pass --bake-report)\n");
    if (f->has_stats)
        fprintf(o,
                "            bake's own rays: %.4f%% missed, %u degenerate receiver%s, "
                "%u undefined normal%s\n",
                f->stats.rays_traced ? 100.0 * f->stats.rays_missed / f->stats.rays_traced : 0.0,
                f->stats.degenerate_receivers, vdsh_s(f->stats.degenerate_receivers),
                f->stats.undefined_normals, vdsh_s(f->stats.undefined_normals));
    fprintf(o,
            "  eval      seed %llu, %u held-out directions/receiver (one light each), "
            "%s truth traversal%s; %.2f s on %u thread%s\n",
            (unsigned long long)r->seed, r->directions, c->fast_truth ? "default" : "robust",
            r->oracle ? ", ORACLE (truth scored against itself)" : "", r->seconds, r->threads,
            vdsh_s(r->threads));
}

/* One line per kind of receiver: the truth's rays, how many escaped or
 * hit at ~0 distance, and the degenerate receivers. */
static void print_truth(FILE *o, const vb_eval_result *r)
{
    for (int k = 0; k < VB_EVAL_KINDS; k++) {
        const vb_eval_truth *t = &r->truth[k];
        fprintf(o, "  truth     %-8s %u receiver%s", kind_name(k), t->receivers,
                vdsh_s(t->receivers));
        if (t->skipped)
            fprintf(o, " (+%u skipped: undefined normal)", t->skipped);
        fprintf(o, ", %llu rays, %.4f%% escaped, %.3f%% at ~0 distance, %u degenerate",
                (unsigned long long)t->rays, t->rays ? 100.0 * t->escaped / t->rays : 0.0,
                t->rays ? 100.0 * t->near_zero / t->rays : 0.0, t->degenerate);
        if (t->degenerate && t->receivers)
            fprintf(o, " (%.2f%%)", 100.0 * t->degenerate / t->receivers);
        fputc('\n', o);
    }
}

/* The columns both tables open a stream's row with: kind, order, offset,
 * bytes per vertex, encoding and fit (ew, fw: enc_fit_widths). */
static void print_stream_columns(FILE *o, const context *c, int k, uint32_t s, int ew, int fw)
{
    const vdsh_stream *st = &c->f->streams[s];
    char ol[16], fit[32];
    fprintf(o, "  %-8s %5s %+6.2f %3.0f %*s %-*s", kind_name(k), order_label(st, ol, sizeof ol),
            (double)c->offset[s],
            vdsh_stream_size_of(stored(c, s), vdsh_file_stream_vertices(c->f)).mean_bytes, ew,
            vdsh_encoding_name(stored(c, s)->encoding), fw, fit_label(st, fit, sizeof fit));
}

/* The primary table: point lights in the scene's free space, where they
 * were placed, and per kind and stream the pairs scored, the smooth and
 * binary errors. */
static void print_scene_lights(FILE *o, const context *c)
{
    const vb_eval_result *r = c->r;
    const vb_light_rule rule = (vb_light_rule)c->d->light_rule;
    fprintf(o,
            "\n  SCENE LIGHTS (the primary metric): %u point lights placed %s%s%s in the "
            "scene's free space, each\n  scored at every receiver it lights; "
            "false = P(s_hat < .5 | d_T >= d_L), recall = P(s_hat < .5 | s_ideal < .5)\n\n",
            r->light_count, rule ? "by the light rule '" : "uniformly",
            rule ? vb_light_rule_name(rule) : "", rule ? "'" : "");
    if (r->light_region_given)
        fprintf(o,
                "  (the light region given: %g %g %g .. %g %g %g, the file's (vdsh-bake "
                "--light-region) or\n  vdsh-eval --light-region's)\n\n",
                (double)r->light_region_min[0], (double)r->light_region_min[1],
                (double)r->light_region_min[2], (double)r->light_region_max[0],
                (double)r->light_region_max[1], (double)r->light_region_max[2]);
    else if (r->light_region_grown)
        fprintf(o,
                "  (the scene's bounds hold too little free space, a closed object: the "
                "lights are placed\n  around it, in the bounds grown by up to a quarter of their "
                "diagonal on every side)\n\n");
    int ew, fw;
    enc_fit_widths(c, &ew, &fw);
    fprintf(o, "  %-8s %5s %6s %3s %*s %-*s | %7s | %-15s %-13s %-12s | %-6s %6s %6s\n", "",
            "order", "offset", "B/v", ew, "enc", fw, "fit", "pairs", "smooth: MAE", "false",
            "recall", "binary", "false", "recall");
    for (int k = 0; k < VB_EVAL_KINDS; k++) {
        if (r->truth[k].receivers == 0)
            continue;
        for (uint32_t s = 0; s < r->stream_count; s++) {
            const vb_eval_scene_metrics *m = &r->scene[k][s];
            char mae[32], fa[32], rc[32], pairs[32];
            snprintf(mae, sizeof mae, "%.4f+-%.4f", m->shadow_mae, 1.96 * m->shadow_mae_se);
            snprintf(fa, sizeof fa, "%.2f+-%.2f%%", 100.0 * m->false_shadow,
                     196.0 * m->false_shadow_se);
            snprintf(rc, sizeof rc, "%.1f+-%.1f%%", 100.0 * m->recall, 196.0 * m->recall_se);
            print_stream_columns(o, c, k, s, ew, fw);
            fprintf(o, " | %7s | %-15s %-13s %-12s | %6.4f %5.2f%% %5.1f%%\n",
                    count_label(m->pairs, pairs, sizeof pairs), mae, fa, rc, m->binary_mae,
                    100.0 * m->binary_false_shadow, 100.0 * m->binary_recall);
        }
    }
}

/* The secondary table: one light per held-out direction at a distance
 * relative to the truth's; the distance error and the shadow errors. */
static void print_relative_lights(FILE *o, const context *c)
{
    const vb_eval_result *r = c->r;
    fprintf(o, "\n  RELATIVE LIGHTS (secondary, as in earlier figures): one light per held-out "
               "direction at d_L = 2u d_T,\n  u uniform in (0.05, 1]\n");
    fprintf(o, "  distance = |D - d_T| / max(d_T, 0.01 diag); false = P(s_hat < .5 | d_T >= d_L), "
               "leak = P(s_hat > .5 | s_ideal < .5)\n\n");
    int ew, fw;
    enc_fit_widths(c, &ew, &fw);
    fprintf(o,
            "  %-8s %5s %6s %3s %*s %-*s | %-14s %6s %6s %6s | %-15s %-13s %-13s | %-6s %6s %6s\n",
            "", "order", "offset", "B/v", ew, "enc", fw, "fit", "distance RMS", "p50", "p90", "p99",
            "smooth: MAE", "false", "leak", "binary", "false", "leak");
    for (int k = 0; k < VB_EVAL_KINDS; k++) {
        if (r->truth[k].receivers == 0)
            continue;
        for (uint32_t s = 0; s < r->stream_count; s++) {
            const vb_eval_metrics *m = &r->metrics[k][s];
            char rms[32], mae[32], fa[32], le[32];
            snprintf(rms, sizeof rms, "%.3f+-%.3f", m->distance_rms, 1.96 * m->distance_rms_se);
            snprintf(mae, sizeof mae, "%.4f+-%.4f", m->shadow_mae, 1.96 * m->shadow_mae_se);
            snprintf(fa, sizeof fa, "%.2f+-%.2f%%", 100.0 * m->false_shadow,
                     196.0 * m->false_shadow_se);
            snprintf(le, sizeof le, "%.2f+-%.2f%%", 100.0 * m->light_leak,
                     196.0 * m->light_leak_se);
            print_stream_columns(o, c, k, s, ew, fw);
            fprintf(o, " | %-14s %6.3f %6.3f %6.3f | %-15s %-13s %-13s | %6.4f %5.2f%% %5.2f%%\n",
                    rms, m->distance_p50, m->distance_p90, m->distance_p99, mae, fa, le,
                    m->binary_mae, 100.0 * m->binary_false_shadow, 100.0 * m->binary_light_leak);
        }
    }
}

/* Per kind, the share of samples whose SH sum ranged <= 0 (read as
 * distance 0) in each stream; not for the oracle, which has no sums. */
static void print_ringing(FILE *o, const context *c)
{
    const vb_eval_result *r = c->r;
    for (int k = 0; k < VB_EVAL_KINDS; k++) {
        if (r->truth[k].receivers == 0 || r->oracle)
            continue;
        fprintf(o, "  %-8s SH sum range <= 0 (read as distance 0) on", kind_name(k));
        for (uint32_t s = 0; s < r->stream_count; s++)
            fprintf(o, "%s order %u %.3f%%", s ? "," : "", c->f->streams[s].order,
                    100.0 * r->metrics[k][s].ringing);
        fprintf(o, " of samples\n");
    }
}

/* Where to look: the worst receivers of the highest order, both kinds. */
static void print_worst(FILE *o, const context *c)
{
    const vdsh_file *f = c->f;
    const vb_eval_result *r = c->r;
    uint32_t best = 0;
    for (uint32_t s = 1; s < r->stream_count; s++)
        if (f->streams[s].order > f->streams[best].order)
            best = s;
    for (int k = 0; k < VB_EVAL_KINDS && r->stream_count; k++) {
        const vb_eval_metrics *m = &r->metrics[k][best];
        if (m->worst_count == 0)
            continue;
        fprintf(o,
                "\n  worst %s, order %u (shadow MAE; per-receiver p50 %.4f, p90 %.4f, "
                "p99 %.4f):\n",
                kind_name(k), f->streams[best].order, m->receiver_mae_p50, m->receiver_mae_p90,
                m->receiver_mae_p99);
        uint32_t n = m->worst_count < 5 ? m->worst_count : 5;
        for (uint32_t i = 0; i < n; i++) {
            const vb_eval_receiver *w = &m->worst[i];
            if (k == VB_EVAL_VERTICES)
                fprintf(o, "    vertex %-9u", w->index);
            else
                fprintf(o, "    point %-6u tri %-8u", w->index, w->triangle);
            fprintf(o,
                    " at (%.4g, %.4g, %.4g) n (%.2f, %.2f, %.2f): shadow MAE %.3f, "
                    "distance RMS %.3f, %.0f%% truth at ~0\n",
                    (double)w->position[0], (double)w->position[1], (double)w->position[2],
                    (double)w->normal[0], (double)w->normal[1], (double)w->normal[2], w->shadow_mae,
                    w->distance_rms, 100.0 * w->near_zero);
        }
    }
}

/* The first five receivers of each kind whose truth rays mostly escape
 * (a leak if the scene is closed). */
static void print_escaping(FILE *o, const vb_eval_result *r)
{
    for (int k = 0; k < VB_EVAL_KINDS; k++) {
        const vb_eval_truth *t = &r->truth[k];
        if (t->escaping_listed == 0 || t->escaping_list[0].escaped < 0.5)
            continue;
        fprintf(o, "\n  %s whose truth mostly escapes (a leak if the scene is closed):\n",
                kind_name(k));
        for (uint32_t i = 0; i < t->escaping_listed && i < 5; i++) {
            const vb_eval_receiver *w = &t->escaping_list[i];
            if (w->escaped < 0.5)
                break;
            fprintf(o, "    %s %u at (%.4g, %.4g, %.4g) n (%.2f, %.2f, %.2f): %.0f%% escaped\n",
                    k == VB_EVAL_VERTICES ? "vertex" : "point", w->index, (double)w->position[0],
                    (double)w->position[1], (double)w->position[2], (double)w->normal[0],
                    (double)w->normal[1], (double)w->normal[2], 100.0 * w->escaped);
        }
    }
}

/* The first five degenerate receivers of each kind (truth almost all at
 * ~0 distance: a bake defect). */
static void print_degenerate(FILE *o, const vb_eval_result *r)
{
    for (int k = 0; k < VB_EVAL_KINDS; k++) {
        const vb_eval_truth *t = &r->truth[k];
        if (t->degenerate_listed == 0)
            continue;
        fprintf(o,
                "\n  degenerate %s (truth almost all at ~0 distance: a bake defect), "
                "first %u:\n",
                kind_name(k), t->degenerate_listed < 5 ? t->degenerate_listed : 5);
        for (uint32_t i = 0; i < t->degenerate_listed && i < 5; i++) {
            const vb_eval_receiver *w = &t->degenerate_list[i];
            fprintf(o, "    %s %u at (%.4g, %.4g, %.4g) n (%.2f, %.2f, %.2f)\n",
                    k == VB_EVAL_VERTICES ? "vertex" : "point", w->index, (double)w->position[0],
                    (double)w->position[1], (double)w->position[2], (double)w->normal[0],
                    (double)w->normal[1], (double)w->normal[2]);
        }
    }
}

/* The text report: the run, the truth, the two tables, then where to
 * look (ringing, worst, escaping and degenerate receivers). */
static void print_table(FILE *o, const context *c)
{
    print_run(o, c);
    print_truth(o, c->r);
    fprintf(o, "\n  order = n bands, n^2 coefficients (aN: adaptive, each vertex 1..N); B/v = "
               "bytes of coefficients per vertex (adaptive: on average); +- = 95%% interval\n");
    print_scene_lights(o, c);
    print_relative_lights(o, c);
    print_ringing(o, c);
    print_worst(o, c);
    print_escaping(o, c->r);
    print_degenerate(o, c->r);
}

/* ---- the command line ------------------------------------------------------------ */

typedef struct options {
    vb_eval_desc d;   /* the evaluator's settings; file and scene: run's */
    const char *path; /* FILE.vdsh */
    char **meshes;    /* MESH...: the recorded sources, given */
    uint32_t nmesh;
    const char *json, *per_vertex, *bake_report;
    int want_order[VDSH_ORDER_SLOTS], filter; /* --orders */
    float offsets[VDSH_MAX_STREAMS];          /* --offsets */
    int noffsets;
    int quiet, fast_truth, allow_mismatch;
    /* --light-region: rule 0 auto, grown, the box, or VT_LIGHT_REGION_FILE
     * (the file's, the default) */
    vdsh_light_box light_region;
} options;

/* --interp: runtime, or a path of vdsh_shadow.h (1 + its number). */
static int parse_interp(const char *s, uint32_t *out)
{
    uint32_t interp = UINT32_MAX;
    if (strcmp(s, "runtime") == 0)
        interp = VB_EVAL_INTERP_RUNTIME;
    for (uint32_t m = 0; m < 4; m++)
        if (strcmp(s, vdsh_interp_name(m)) == 0)
            interp = m + 1;
    *out = interp;
    return interp != UINT32_MAX;
}

/* 1..VDSH_MAX_STREAMS - 1 offsets in -5..5 (the copies and the streams
 * themselves must fit in VDSH_MAX_STREAMS). */
static int parse_offsets(const char *s, float *out)
{
    int n = vt_parse_floats(s, out, 1, VDSH_MAX_STREAMS - 1);
    for (int i = 0; i < n; i++)
        if (fabsf(out[i]) > 5.0f)
            return 0;
    return n;
}

/* -1 with *o ready to run, else the exit status (help, version, a usage
 * error: said). */
static int parse_args(int argc, char **argv, options *o)
{
    enum {
        O_POINTS = 256,
        O_INTERIOR,
        O_DIRECTIONS,
        O_SEED,
        O_ORDERS,
        O_ORACLE,
        O_INTERP,
        O_FAST,
        O_ALLOW,
        O_JSON,
        O_PV,
        O_BAKE_REPORT,
        O_WORST,
        O_THREADS,
        O_LIGHTS,
        O_OFFSETS,
        O_LIGHT_RULE,
        O_LIGHT_REGION
    };
    static const struct option longopts[] = {{"points", required_argument, 0, O_POINTS},
                                             {"interior", required_argument, 0, O_INTERIOR},
                                             {"directions", required_argument, 0, O_DIRECTIONS},
                                             {"seed", required_argument, 0, O_SEED},
                                             {"orders", required_argument, 0, O_ORDERS},
                                             {"oracle", no_argument, 0, O_ORACLE},
                                             {"interp", required_argument, 0, O_INTERP},
                                             {"fast-truth", no_argument, 0, O_FAST},
                                             {"allow-mismatch", no_argument, 0, O_ALLOW},
                                             {"json", required_argument, 0, O_JSON},
                                             {"per-vertex", required_argument, 0, O_PV},
                                             {"bake-report", required_argument, 0, O_BAKE_REPORT},
                                             {"worst", required_argument, 0, O_WORST},
                                             {"threads", required_argument, 0, O_THREADS},
                                             {"lights", required_argument, 0, O_LIGHTS},
                                             {"light-rule", required_argument, 0, O_LIGHT_RULE},
                                             {"light-region", required_argument, 0, O_LIGHT_REGION},
                                             {"offsets", required_argument, 0, O_OFFSETS},
                                             {"quiet", no_argument, 0, 'q'},
                                             VT_CLI_LONGOPTS_END};
    memset(o, 0, sizeof *o);
    o->d.interior = 65536;
    o->light_region.rule = VT_LIGHT_REGION_FILE;
    vb_eval_desc *d = &o->d;
    int c, ok = 1, interp_given = 0;
    while (ok && (c = getopt_long(argc, argv, "qhV", longopts, NULL)) != -1) {
        switch (c) {
        case O_POINTS:
            ok = vt_opt_u32("--points", NULL, optarg, 1, VB_EVAL_MAX_RECEIVERS, &d->points);
            break;
        case O_INTERIOR:
            ok = vt_opt_u32("--interior", NULL, optarg, 0, VB_EVAL_MAX_RECEIVERS, &d->interior);
            break;
        case O_DIRECTIONS:
            ok = vt_opt_u32("--directions", NULL, optarg, 1, 65536, &d->directions);
            break;
        case O_WORST:
            ok = vt_opt_u32("--worst", NULL, optarg, 1, VB_EVAL_MAX_WORST, &d->worst);
            break;
        case O_LIGHTS: ok = vt_opt_u32("--lights", NULL, optarg, 1, 4096, &d->lights); break;
        case O_THREADS: ok = vt_opt_u32("--threads", NULL, optarg, 1, 256, &d->threads); break;
        case O_SEED:
            if (!vt_parse_u64(optarg, 0, UINT64_MAX, &d->seed))
                return bad_usage("--seed takes a whole number, not '%s'", optarg);
            break;
        case O_ORDERS:
            if (!vt_opt_orders("--orders", "3,5", optarg, VDSH_MAX_ORDER, o->want_order))
                return VT_EXIT_USAGE;
            o->filter = 1;
            break;
        case O_INTERP:
            if (!parse_interp(optarg, &d->interp))
                return bad_usage("--interp takes runtime, coefficients, distance, "
                                 "visibility or split, not '%s'",
                                 optarg);
            interp_given = 1;
            break;
        case O_LIGHT_RULE:
            if ((d->light_rule = vb_light_rule_by_name(optarg)) < 0)
                return bad_usage(
                    "--light-rule takes uniform, ceiling, near, path, grown, around or shell, not '%s'",
                    optarg);
            break;
        case O_LIGHT_REGION:
            ok = vt_opt_light_region("--light-region", optarg, 1, &o->light_region);
            break;
        case O_OFFSETS:
            o->noffsets = parse_offsets(optarg, o->offsets);
            if (!o->noffsets)
                return bad_usage("--offsets takes 1..15 numbers in -5..5 such as -0.4,-0.2,0.2, "
                                 "not '%s'",
                                 optarg);
            break;
        case O_ORACLE: d->oracle = 1; break;
        case O_FAST: o->fast_truth = 1; break;
        case O_ALLOW: o->allow_mismatch = 1; break;
        case O_JSON: ok = vt_opt_once("--json", optarg, &o->json); break;
        case O_PV: ok = vt_opt_once("--per-vertex", optarg, &o->per_vertex); break;
        case O_BAKE_REPORT: ok = vt_opt_once("--bake-report", optarg, &o->bake_report); break;
        case 'q': o->quiet = 1; break;
        case 'h': usage(stdout); return 0;
        case 'V': return vt_cli_version("Embree " RTC_VERSION_STRING);
        default: return vt_cli_try_help();
        }
    }
    if (!ok)
        return VT_EXIT_USAGE;
    /* Options that would do nothing: said, not silently ignored. */
    if (interp_given && d->interior == 0)
        return bad_usage("%s", "--interp chooses how interior points are scored, and "
                               "--interior 0 scores none: drop one of them");
    if (o->noffsets && d->oracle)
        return bad_usage("%s", "--offsets scores the streams with offsets added, and "
                               "--oracle scores the ray-cast truth instead of the streams: "
                               "drop one of them");
    o->path = vt_arg_vdsh(argc, argv, optind, NULL, 1);
    if (!o->path)
        return VT_EXIT_USAGE;
    o->meshes = argv + optind + 1;
    o->nmesh = (uint32_t)(argc - optind - 1);
    return -1;
}

/* ---- the streams to score ------------------------------------------------------------ */

typedef struct scored {
    vdsh_file view;                 /* the file with the streams to score; the file stays as read */
    vdsh_stream *kept;              /* view.streams when not the file's own (owned) */
    int copies;                     /* 1 + offsets once kept holds --offsets copies, whose data
                                  (each stream but every copies-th) is ours; else 0 */
    float offset[VDSH_MAX_STREAMS]; /* per scored stream: the log offset added */
} scored;

static void scored_free(scored *s)
{
    if (s->kept && s->copies)
        for (uint32_t i = 0; i < s->view.stream_count; i++)
            if (i % (uint32_t)s->copies != 0)
                free((void *)s->kept[i].data);
    free(s->kept);
}

/* --orders: only the streams of those orders, each order present. */
static int select_orders(const options *o, const vdsh_file *f, scored *s)
{
    vdsh_stream *kept = calloc(f->stream_count + 1, sizeof *kept);
    if (!kept) {
        fprintf(stderr, "vdsh-eval: out of memory\n");
        return 1;
    }
    s->kept = kept;
    uint32_t n = 0;
    for (uint32_t i = 0; i < f->stream_count; i++)
        if (f->streams[i].order <= VDSH_MAX_ORDER && o->want_order[f->streams[i].order])
            kept[n++] = f->streams[i];
    for (int k = 1; k <= VDSH_MAX_ORDER; k++) {
        int found = 0;
        for (uint32_t i = 0; i < n; i++)
            found |= o->want_order[k] && kept[i].order == (uint32_t)k;
        if (o->want_order[k] && !found) {
            fprintf(stderr, "vdsh-eval: %s: no stream of order %d\n", o->path, k);
            return 1;
        }
    }
    s->view.streams = kept;
    s->view.stream_count = n;
    return 0;
}

/* --offsets, the trade as a curve: each stream again with every offset
 * added to its log distance (a distance stream: times e^offset), decoded
 * to f32 in memory (a variable-order stream's copy keeps its orders: f32
 * records of k^2 coefficients, its own record offsets after them in the
 * same block). 0, 1 (an error) or VT_EXIT_USAGE (too many streams). */
static int add_offsets(const options *o, const vdsh_file *f, scored *s)
{
    const int noffsets = o->noffsets;
    uint32_t n0 = s->view.stream_count, total = n0 * (uint32_t)(1 + noffsets);
    if (total > VDSH_MAX_STREAMS) {
        fprintf(stderr,
                "vdsh-eval: %u streams with %d offsets each make %u, more than %d: "
                "fewer offsets, or pick orders with --orders\n",
                n0, noffsets, total, VDSH_MAX_STREAMS);
        return VT_EXIT_USAGE;
    }
    vdsh_stream *all = calloc(total, sizeof *all);
    if (!all) {
        fprintf(stderr, "vdsh-eval: out of memory\n");
        return 1;
    }
    uint32_t n = 0, V = f->header.vertex_count;
    for (uint32_t i = 0; i < n0; i++) {
        s->offset[n] = 0.0f;
        all[n++] = s->view.streams[i];
        for (int k = 0; k < noffsets; k++) {
            vdsh_stream x = s->view.streams[i];
            const int variable = (x.flags & VDSH_STREAM_VARIABLE) != 0;
            uint32_t nc = x.order * x.order;
            uint64_t words = 0; /* an f32 record of order k: k^2 words */
            for (uint32_t v = 0; v < V; v++)
                words += variable ? (uint64_t)x.orders[v] * x.orders[v] : nc;
            float *data = malloc((size_t)words * sizeof *data +
                                 (variable ? ((size_t)V + 1) * sizeof(uint32_t) : 1));
            if (!data) {
                fprintf(stderr, "vdsh-eval: out of memory\n");
                for (uint32_t j = 0; j < n; j++)
                    if (j % (uint32_t)(1 + noffsets) != 0)
                        free((void *)all[j].data);
                free(all);
                return 1;
            }
            uint32_t *offs = variable ? (uint32_t *)(data + words) : NULL;
            if (offs)
                vdsh_stream_offsets(x.orders, V, VDSH_ENCODING_F32, offs);
            for (uint32_t v = 0; v < V; v++) {
                float cv[VDSH_MAX_COEFFS];
                vdsh_stream_decode(&s->view.streams[i], v, cv);
                if (x.quantity == VDSH_QUANTITY_LOG_DISTANCE)
                    cv[0] += o->offsets[k] / 0.28209479177387814f; /* Y00 */
                else
                    for (uint32_t c = 0; c < nc; c++)
                        cv[c] *= x.quantity == VDSH_QUANTITY_DISTANCE2 ? expf(2.0f * o->offsets[k])
                                                                       : expf(o->offsets[k]);
                uint32_t kv = variable ? (uint32_t)x.orders[v] * x.orders[v] : nc;
                memcpy(data + (variable ? offs[v] : (size_t)v * nc), cv, kv * sizeof *cv);
            }
            x.encoding = VDSH_ENCODING_F32, x.scale = 1.0f, x.data = data, x.offsets = offs;
            x.coef_scales = NULL;
            x.cpca = (vdsh_cpca){0};
            s->offset[n] = o->offsets[k];
            all[n++] = x;
        }
    }
    free(s->kept);
    s->kept = all;
    s->copies = 1 + noffsets;
    s->view.streams = all;
    s->view.stream_count = n;
    return 0;
}

/* ---- the steps of an evaluation ------------------------------------------------------- */

/* --bake-report, else the file's time chunk, else none. */
static int bake_time_of(const options *o, const vdsh_file *f, bake_time *bt)
{
    memset(bt, 0, sizeof *bt);
    if (o->bake_report) {
        char msg[PATH_MAX + 128];
        if (!read_bake_report(o->bake_report, f, o->path, bt, msg, sizeof msg)) {
            fprintf(stderr, "vdsh-eval: %s\n", msg);
            return 1;
        }
    } else if (f->has_timings) {
        bt->total = f->timings.total;
        bt->trace = f->timings.trace;
        bt->threads = f->timings.threads;
        bt->source = "time chunk";
    }
    return 0;
}

static void sources_free(char **spath, uint32_t n)
{
    if (spath)
        for (uint32_t i = 0; i < n; i++)
            free(spath[i]);
    free(spath);
}

/* The occluders' files: the meshes given, or each recorded source found.
 * NULL after the message. */
static char **find_sources(const options *o, const vdsh_file *f)
{
    char **spath = calloc(f->source_count + 1, sizeof *spath);
    if (!spath) {
        fprintf(stderr, "vdsh-eval: out of memory\n");
        return NULL;
    }
    for (uint32_t i = 0; i < f->source_count; i++) {
        spath[i] =
            o->nmesh ? strdup(o->meshes[i]) : vb_eval_find_source(f->sources[i].name, o->path);
        if (!spath[i]) {
            fprintf(stderr,
                    "vdsh-eval: %s: cannot find source %u of %u, '%s' (looked as "
                    "recorded and beside the file); give the bake's meshes after "
                    "the file name\n",
                    o->path, i + 1, f->source_count, f->sources[i].name);
            sources_free(spath, f->source_count);
            return NULL;
        }
    }
    return spath;
}

/* The table (unless the JSON has stdout), the JSON and the per-vertex file. */
static int report(const options *o, const context *ctx)
{
    if (!o->json || strcmp(o->json, "-") != 0) /* stdout is the JSON's */
        print_table(stdout, ctx);
    fflush(stdout);
    char msg[PATH_MAX + 256];
    /* both files complete before either is renamed into place, and a
     * signal meanwhile waits for both (vt_cli_defer_signals) */
    vt_cli_defer_signals();
    vdsh_output pv = {.fd = -1};
    int status = 1;
    if (o->per_vertex &&
        write_per_vertex(o->per_vertex, ctx->f, ctx->r, &pv, msg, sizeof msg) != 0) {
        fprintf(stderr, "vdsh-eval: %s\n", msg);
        goto out;
    }
    if (o->json && write_json(o->json, ctx, msg, sizeof msg) != 0) {
        fprintf(stderr, "vdsh-eval: %s\n", msg);
        vdsh_output_abort(&pv);
        goto out;
    }
    vdsh_error err;
    if (o->per_vertex && vdsh_output_commit(&pv, &err) != VDSH_OK) {
        fprintf(stderr, "vdsh-eval: %s\n", err.msg);
        goto out;
    }
    status = 0;
out:
    vt_cli_undefer_signals();
    return status;
}

/* Steps 2 to 5 of run: the bake time, the occluders, the evaluation, the
 * report. */
static int evaluate(const options *o, const vdsh_file *f, const scored *sc)
{
    int status = 1;
    vb_scene *scene = NULL;
    vb_eval_result res = {0};
    char **spath = NULL;
    vb_error err;

    /* 2. The bake time. */
    bake_time bt;
    if (bake_time_of(o, f, &bt))
        goto out;

    /* 3. The occluders, as the bake traced them. */
    spath = find_sources(o, f);
    if (!spath)
        goto out;
    { /* the sources found from the file's record are inputs too */
        const char *outs[] = {o->json, o->per_vertex};
        if (vt_cli_check_outputs(outs, 2, (const char *const *)spath, (int)f->source_count) != 0)
            goto out;
    }
    warnings warned = {.path = o->path, .quiet = o->quiet};
    vb_eval_scene_desc sd = {.fast = o->fast_truth,
                             .allow_mismatch = o->allow_mismatch,
                             .threads = o->d.threads,
                             .warn = on_warn,
                             .warn_user = &warned};
    if (vb_eval_scene_create(f, (const char *const *)spath, f->source_count, &sd, &scene, &err) !=
        VB_OK) {
        fprintf(stderr, "vdsh-eval: %s: %s\n", o->path, err.msg);
        goto out;
    }
    vdsh_light_box region = o->light_region;
    if (vb_scene_use_light_box(scene, &region, "--light-region", &err) != VB_OK) {
        fprintf(stderr, "vdsh-eval: %s: %s\n", o->path, err.msg);
        goto out;
    }

    /* 4. Evaluate. */
    progress pr = {.enabled = !o->quiet && isatty(STDERR_FILENO), .t0 = vb_now()};
    vb_eval_desc d = o->d;
    d.file = &sc->view;
    d.scene = scene;
    d.per_vertex = o->per_vertex != NULL;
    d.progress = on_progress;
    d.progress_user = &pr;
    if (vb_eval_run(&d, &res, &err) != VB_OK) {
        fprintf(stderr, "vdsh-eval: %s: %s\n", o->path, err.msg);
        goto out;
    }

    /* 5. Report. */
    context ctx = {.path = o->path,
                   .f = &sc->view,
                   .source_paths = spath,
                   .file_bytes = -1,
                   .bt = bt,
                   .r = &res,
                   .d = &d,
                   .fast_truth = o->fast_truth,
                   .mismatched = warned.count,
                   .offset = sc->offset,
                   .copies = sc->copies};
    struct stat st;
    if (stat(o->path, &st) == 0)
        ctx.file_bytes = (long long)st.st_size;
    status = report(o, &ctx);

out:
    sources_free(spath, f->source_count);
    vb_eval_result_free(&res);
    vb_scene_destroy(scene);
    return status;
}

/* The story of an evaluation (the top of this file). */
static int run(const options *o)
{
    /* 0. Every output can be written, and none is an input. */
    {
        const char *opt = "--per-vertex";
        int rc = vt_cli_no_stdout(&o->per_vertex, &opt, 1);
        if (rc)
            return rc;

        const char *outs[] = {o->json, o->per_vertex};
        const char *ins[VDSH_MAX_SOURCES + 2] = {o->path, o->bake_report};
        int nin = 2;
        for (uint32_t i = 0; i < o->nmesh && nin < VDSH_MAX_SOURCES + 2; i++)
            ins[nin++] = o->meshes[i];
        if (vt_cli_check_outputs(outs, 2, ins, nin) != 0)
            return 1;
    }

    /* 1. The file, and the streams to score. */
    vdsh_file *f = vt_read_whole(o->path);
    if (!f)
        return 1;
    if (o->nmesh && o->nmesh != f->source_count) {
        fprintf(stderr, "vdsh-eval: %s: %u mesh(es) given but the bake used %u source(s):", o->path,
                o->nmesh, f->source_count);
        for (uint32_t i = 0; i < f->source_count; i++)
            fprintf(stderr, " '%s'", f->sources[i].name);
        fputc('\n', stderr);
        vdsh_free(f);
        return VT_EXIT_USAGE;
    }
    scored sc = {.view = *f};
    int status = o->filter ? select_orders(o, f, &sc) : 0;
    if (status == 0 && o->noffsets)
        status = add_offsets(o, f, &sc);
    if (status == 0)
        status = evaluate(o, f, &sc);
    scored_free(&sc);
    vdsh_free(f);
    return status;
}

int main(int argc, char **argv)
{
    vt_cli_begin("vdsh-eval", argv);
    vt_cli_clean_exit_on_signals(); /* no temporary file left by a signal */
    options o;
    int status = parse_args(argc, argv, &o);
    return status >= 0 ? status : run(&o);
}
