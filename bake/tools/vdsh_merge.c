/*
 * vdsh-merge - join the parts of a sharded bake (vdsh-bake --shard I/N)
 * into the file the whole bake writes, byte for byte (VDSH.md "Parts").
 *
 *     vdsh-merge part-0.vdsh part-1.vdsh ... -o scene.vdsh
 *
 * Every part is read and checked against the first: same inputs (SRCS:
 * names, sizes, SHA-256; a .gltf recorded without its external buffers,
 * by a bake before 2026-11-30, and with them, when both records match
 * the file its name finds), same options (HEAD and every stream header),
 * same receivers (positions, oriented normals, triangles), same shard
 * count and merged encoding; each shard exactly once, with the receiver
 * range vb_shard_range gives it. A refusal names the part (and, for
 * missing shards, their numbers). The coefficients are then copied range
 * by range and encoded as vdsh-bake encodes them (f16: scaled by the
 * stream's largest |coefficient|; s8, s8s6: vdsh_encode_quantised_drawn's
 * scale per coefficient index, over the drawn receivers, which
 * vb_drawn_receivers finds from the merged POSN and TRIS as vdsh-bake does
 * from its receivers), the ray counts summed, and the file and its basis
 * cubemaps written atomically.
 *
 * Memory: one part at a time is read (the first stays, to check the
 * others against). For f16, s8 and s8s6, whose scales are largest
 * |coefficient|s over all (s8, s8s6: all drawn) receivers, each part's f32 rows go to a spill
 * file beside the output (unlinked when made) while the largest |c|s are
 * gathered, then come back range by range to be encoded into the merged
 * streams. So memory is the merged file (receivers and encoded streams;
 * f32: the coefficients) plus two parts (each the receiver mesh and its
 * range's rows), never every receiver's f32 coefficients; the spill holds
 * them on disk (152 bytes per receiver at orders 2, 3, 5); while it is
 * written, the encoded file is held once more (vb_write_outputs stages it
 * with the cubemaps, all or none). A variable-order
 * stream (--adaptive-order) is decoded into f32 rows of every receiver and
 * encoded at the end, as before: its records' offsets and scales are over
 * all receivers too, and it is opt-in.
 * Exit status: 0 merged, 1 refused or failed (nothing written), 2 usage.
 */
#include <errno.h>
#include <getopt.h>
#include <libgen.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cubemap.h"
#include "job.h"
#include "mesh.h"
#include "vdsh.h"
#include "vdsh_cpca.h"
#include "vt_cli.h"

static void usage(FILE *f)
{
    fputs("usage: vdsh-merge PART.vdsh... -o OUT.vdsh\n"
          "Join the parts written by 'vdsh-bake ... --shard I/N' (every I of one N,\n"
          "in any order) into the file the whole bake writes, byte for byte, and\n"
          "its SH basis cubemaps beside it.\n"
          "\n"
          "  -o, --output FILE   the merged .vdsh (written atomically)\n"
          "  -q, --quiet         nothing on stderr but errors (no summary or notes)\n"
          "      --threads N     cpca streams: the encoder's threads (1..256;\n"
          "                      default: one per CPU); the bytes do not depend on it\n"
          "  -h, --help          this help\n"
          "  -V, --version       version\n"
          "\n"
          "Exit status: 0 merged, 1 refused or failed (nothing written), 2 usage error.\n",
          f);
}

static int same_header(const vdsh_header *a, const vdsh_header *b)
{
    return a->vertex_count == b->vertex_count && a->triangle_count == b->triangle_count &&
           a->rays == b->rays && a->sampling == b->sampling && a->seed == b->seed &&
           memcmp(&a->max_distance, &b->max_distance, 4) == 0 &&
           memcmp(&a->max_edge, &b->max_edge, 4) == 0 && a->offset_rule == b->offset_rule &&
           a->load_flags == b->load_flags && a->cube_size == b->cube_size &&
           a->occluder_vertex_count == b->occluder_vertex_count &&
           a->occluder_triangle_count == b->occluder_triangle_count &&
           a->trace_flags == b->trace_flags &&
           memcmp(a->bounds_min, b->bounds_min, sizeof a->bounds_min) == 0 &&
           memcmp(a->bounds_max, b->bounds_max, sizeof a->bounds_max) == 0;
}

/* A glTF source's two records (formats/VDSH.md, SRCS): bakes before
 * 2026-11-30 hashed the .gltf alone, later ones the file and its external
 * buffers. Parts of one bake from both kinds of baker differ there only;
 * they belong together when both records verify against the same file
 * (found by its recorded name, as given, else beside the part), which is
 * read once per source. The merged file records the file with its
 * buffers, as the whole bake now writes it. */
typedef struct source_check {
    int done;  /* looked for and hashed */
    int found; /* the file was found and read: info holds both records */
    vb_source_info info;
    char path[PATH_MAX];
} source_check;

static source_check checks[VDSH_MAX_SOURCES];
static int quiet_merge;

static int record_is(const vdsh_source *r, uint64_t size, const uint8_t sha[32])
{
    return r->size == size && memcmp(r->sha256, sha, 32) == 0;
}

/* Source i's file: its name as given, else beside the part at `part`. */
static void check_source(uint32_t i, const char *name, const char *part)
{
    source_check *c = &checks[i];
    if (c->done)
        return;
    c->done = 1;
    char tmp[PATH_MAX];
    snprintf(tmp, sizeof tmp, "%s", part);
    const char *cands[2] = {name, NULL};
    char beside[PATH_MAX];
    if (name[0] != '/' &&
        snprintf(beside, sizeof beside, "%s/%s", dirname(tmp), name) < (int)sizeof beside)
        cands[1] = beside;
    for (int k = 0; k < 2 && !c->found; k++) {
        if (!cands[k] || access(cands[k], R_OK) != 0)
            continue;
        vb_mesh m = {0};
        vb_error err;
        if (vb_mesh_load(cands[k], &(vb_load_desc){0}, &m, &c->info, &err) == VB_OK) {
            c->found = 1;
            snprintf(c->path, sizeof c->path, "%s", cands[k]);
        }
        vb_mesh_free(&m);
    }
}

/* Whether b's sources are a's (a: the first part, whose record of a
 * source is upgraded to the file with its buffers when b recorded it so
 * and both verify); else *why says what differs. */
static int same_sources(vdsh_file *a, const char *a_path, const vdsh_file *b, const char *b_path,
                        char *why, size_t why_size)
{
    snprintf(why, why_size, "%s", "other inputs (SRCS: names, sizes or SHA-256 differ)");
    if (a->source_count != b->source_count)
        return 0;
    for (uint32_t i = 0; i < a->source_count; i++)
        if (strcmp(a->sources[i].name, b->sources[i].name) != 0)
            return 0;
    for (uint32_t i = 0; i < a->source_count; i++) {
        vdsh_source *ra = &a->sources[i];
        const vdsh_source *rb = &b->sources[i];
        if (record_is(ra, rb->size, rb->sha256))
            continue;
        /* the file alone is the shorter record (formats/VDSH.md) */
        if (ra->size == rb->size)
            return 0;
        check_source(i, ra->name, b_path);
        if (!checks[i].found)
            check_source(i, ra->name, a_path);
        const source_check *c = &checks[i];
        if (!c->found) {
            snprintf(why, why_size,
                     "source %u, '%s', recorded with and without its external buffers (a bake "
                     "before 2026-11-30 hashed the .gltf alone), and the file is not found to "
                     "check both against (give the parts where its name, as recorded, finds it)",
                     i + 1, ra->name);
            return 0;
        }
        const vb_source_info *f = &c->info;
        const int a_full = record_is(ra, f->size, f->sha256),
                  a_alone = record_is(ra, f->file_size, f->file_sha256);
        const int b_full = record_is(rb, f->size, f->sha256),
                  b_alone = record_is(rb, f->file_size, f->file_sha256);
        if (!((a_full && b_alone) || (a_alone && b_full))) {
            snprintf(why, why_size,
                     "other inputs (SRCS: source %u, '%s', recorded as %llu and %llu bytes: "
                     "%s is not the file both parts baked)",
                     i + 1, ra->name, (unsigned long long)ra->size, (unsigned long long)rb->size,
                     c->path);
            return 0;
        }
        if (!quiet_merge)
            fprintf(stderr,
                    "vdsh-merge: %s: source %u, '%s', recorded without its external buffers "
                    "(a bake before 2026-11-30); both records match %s: the merged file "
                    "records it with them\n",
                    a_alone ? a_path : b_path, i + 1, ra->name, c->path);
        if (a_alone) {
            ra->size = f->size;
            memcpy(ra->sha256, f->sha256, 32);
        }
    }
    return 1;
}

static int same_stream(const vdsh_stream *a, const vdsh_stream *b)
{
    return a->order == b->order && a->flags == b->flags && a->encoding == b->encoding &&
           a->method == b->method && a->quantity == b->quantity && a->window == b->window &&
           memcmp(&a->window_param, &b->window_param, 4) == 0 &&
           memcmp(&a->method_param, &b->method_param, 4) == 0 &&
           memcmp(&a->scale, &b->scale, 4) == 0 &&
           memcmp(&a->quantity_param, &b->quantity_param, 4) == 0;
}

/* Why part b does not belong with part a (the first), or NULL. */
static const char *mismatch(vdsh_file *a, const char *a_path, const vdsh_file *b,
                            const char *b_path)
{
    static char why[PATH_MAX + 512];
    if (!same_sources(a, a_path, b, b_path, why, sizeof why))
        return why;
    if (!same_header(&a->header, &b->header))
        return "other options or receivers (HEAD differs)";
    /* before the streams: another region calibrates other log offsets */
    if (a->has_light_box != b->has_light_box ||
        (a->has_light_box && memcmp(&a->light_box, &b->light_box, sizeof a->light_box) != 0))
        return "another --light-region (lreg chunk differs)";
    if (a->stream_count != b->stream_count)
        return "other orders (stream count differs)";
    for (uint32_t s = 0; s < a->stream_count; s++)
        if (!same_stream(&a->streams[s], &b->streams[s]))
            return "other options (a COEF stream header differs)";
    if (a->part.count != b->part.count)
        return "another shard count";
    if (a->part.encoding != b->part.encoding)
        return "another --encoding";
    if (a->part.cpca_clusters != b->part.cpca_clusters ||
        a->part.cpca_basis != b->part.cpca_basis || a->part.cpca_bits != b->part.cpca_bits)
        return "another --cpca";
    const vdsh_light_pool *la = &a->light_pool, *lb = &b->light_pool;
    if (a->has_light_pool != b->has_light_pool ||
        (a->has_light_pool && (memcmp(&la->mix, &lb->mix, 4) != 0 || la->count != lb->count ||
                               memcmp(la->lights, lb->lights, (size_t)la->count * 12) != 0)))
        return "another cpca light pool (lpol chunk differs: another --cpca light:A, seed or scene)";
    if (a->has_light_pool && (memcmp(&la->margin, &lb->margin, 4) != 0 || la->starts != lb->starts))
        return "another --cpca margin:S or starts:N (lpol chunk differs)";
    uint64_t v = a->header.vertex_count, t = a->header.triangle_count;
    if (memcmp(a->positions, b->positions, v * 12) != 0 ||
        memcmp(a->indices, b->indices, t * 12) != 0)
        return "other receivers (POSN or TRIS differ)";
    if (a->has_stats != b->has_stats ||
        (a->has_stats && a->stats.undefined_normals != b->stats.undefined_normals))
        return "other statistics of the whole receiver set (stat differs)";
    return NULL;
}

/* Read part `path` and check it: a part, belonging with `first` (at
 * first_path; NULL: it is the first), f32 streams. 0, or 1 after saying why (*out then
 * NULL). */
static int read_part(const char *path, vdsh_file *first, const char *first_path, vdsh_file **out)
{
    vdsh_error verr;
    vdsh_file *p = NULL;
    *out = NULL;
    if (vdsh_read(path, &p, &verr) != VDSH_OK) {
        fprintf(stderr, "vdsh-merge: %s\n", verr.msg);
        return 1;
    }
    if (!p->has_part) {
        fprintf(stderr,
                "vdsh-merge: %s: not a part (no part chunk: a whole bake, not "
                "'vdsh-bake --shard I/N')\n",
                path);
        vdsh_free(p);
        return 1;
    }
    const char *why = first ? mismatch(first, first_path, p, path) : NULL;
    if (why) {
        fprintf(stderr, "vdsh-merge: %s: does not belong with %s: %s\n", path, first_path, why);
        vdsh_free(p);
        return 1;
    }
    for (uint32_t s = 0; s < p->stream_count; s++)
        if (p->streams[s].encoding != VDSH_ENCODING_F32) {
            fprintf(stderr, "vdsh-merge: %s: stream %u is not f32 (parts hold f32)\n", path, s);
            vdsh_free(p);
            return 1;
        }
    *out = p;
    return 0;
}

#define ENCODE_ROWS 4096 /* receivers encoded per call */

/* The spill: every part's f32 rows, in a temporary file beside the output,
 * unlinked as soon as it is made (no exit, a kill included, leaves it).
 * NULL after saying why. */
static FILE *spill_create(const char *output)
{
    char path[PATH_MAX];
    if (snprintf(path, sizeof path, "%s.spill-XXXXXX", output) >= (int)sizeof path) {
        fprintf(stderr, "vdsh-merge: %s: path too long\n", output);
        return NULL;
    }
    int fd = mkstemp(path);
    FILE *f = fd >= 0 ? fdopen(fd, "w+b") : NULL;
    if (!f) {
        fprintf(stderr, "vdsh-merge: cannot create a temporary file beside %s: %s\n", output,
                strerror(errno));
        if (fd >= 0)
            close(fd);
        if (fd >= 0)
            unlink(path);
        return NULL;
    }
    unlink(path);
    return f;
}

/* Encode rows b..e-1 of merged stream *s (f16 or quantised), read from
 * the spill at its position, into dst (every receiver's bytes) with the
 * largest |coefficient|s of all receivers, amax (f16: amax[0], the
 * stream's; else per index, over the drawn receivers, drawn[v] != 0): the
 * bytes the whole bake's stream has for them. A quantised encoding's
 * scales are its largest |c|s over the drawn vertices it is given, so each
 * call gets the rows after one row of amax itself, marked drawn: the
 * scales are then all drawn receivers' (scales receives them), and a
 * receiver's bytes depend only on its values and the scales. 0, or 1 after
 * saying why. */
static int encode_spilled(FILE *spill, const char *output, const vdsh_stream *s, void *dst,
                          uint32_t b, uint32_t e, const uint8_t *drawn, const float *amax,
                          float *scales)
{
    const uint32_t nc = s->order * s->order;
    const size_t bpv = vdsh_encoding_bytes(s->encoding, nc);
    float *rows = malloc(((size_t)ENCODE_ROWS + 1) * nc * sizeof *rows);
    uint8_t *bytes = malloc(((size_t)ENCODE_ROWS + 1) * bpv + 1);
    uint8_t mask[ENCODE_ROWS + 1];
    int bad = !rows || !bytes;
    if (bad)
        fprintf(stderr, "vdsh-merge: out of memory\n");
    for (uint32_t a = b; a < e && !bad; a += ENCODE_ROWS) {
        uint32_t k = e - a < ENCODE_ROWS ? e - a : ENCODE_ROWS;
        memcpy(rows, amax, nc * sizeof *rows);
        if (fread(rows + nc, (size_t)nc * sizeof *rows, k, spill) != k) {
            fprintf(stderr, "vdsh-merge: cannot read back the temporary file beside %s\n", output);
            bad = 1;
        } else if (s->encoding == VDSH_ENCODING_F16) {
            bad = vdsh_encode_f16(rows + nc, (size_t)k * nc, s->scale,
                                  (uint16_t *)dst + (size_t)a * nc) != VDSH_OK;
        } else {
            mask[0] = 1;
            memcpy(mask + 1, drawn + a, k);
            bad = vdsh_encode_quantised_drawn(s->encoding, rows, (size_t)k + 1, nc, mask, scales,
                                              bytes) != VDSH_OK ||
                  memcmp(scales, amax, nc * sizeof *scales) != 0;
            if (!bad)
                memcpy((uint8_t *)dst + (size_t)a * bpv, bytes + bpv, (size_t)k * bpv);
        }
        if (bad && rows && bytes && !ferror(spill) && !feof(spill))
            fprintf(stderr, "vdsh-merge: order %u coefficients do not fit %s\n", s->order,
                    vdsh_encoding_name(s->encoding));
    }
    free(rows);
    free(bytes);
    return bad;
}

/* ---- the command line ---------------------------------------------------- */

typedef struct options {
    const char *output;
    int quiet;
    uint32_t threads; /* 0: one per CPU */
    char **parts;     /* the PART arguments */
    int part_count;
} options;

/* The command line into *o: VT_CLI_RUN, or the exit status (0 after --help
 * or --version; VT_EXIT_USAGE after saying what is wrong). */
static int parse_args(int argc, char **argv, options *o)
{
    enum { O_THREADS = 256 };
    static const struct option longopts[] = {{"output", required_argument, 0, 'o'},
                                             {"quiet", no_argument, 0, 'q'},
                                             {"threads", required_argument, 0, O_THREADS},
                                             VT_CLI_LONGOPTS_END};
    *o = (options){0};
    int c;
    while ((c = getopt_long(argc, argv, "o:qhV", longopts, NULL)) != -1) {
        switch (c) {
        case 'o':
            if (!vt_opt_once("-o", optarg, &o->output))
                return VT_EXIT_USAGE;
            break;
        case 'q': o->quiet = 1; break;
        case O_THREADS:
            if (!vt_opt_u32("--threads", NULL, optarg, 1, 256, &o->threads))
                return VT_EXIT_USAGE;
            break;
        default: return vt_cli_common_option(c, usage, NULL);
        }
    }
    o->parts = argv + optind;
    o->part_count = argc - optind;
    if (o->part_count < 1)
        return vt_usage_error("vdsh-merge", "%s", "no part given");
    if (!o->output)
        return vt_usage_error("vdsh-merge", "%s", "no output: give -o OUT.vdsh");
    return VT_CLI_RUN;
}

/* ---- the merge ----------------------------------------------------------- */

/* The merge under way: the first part (kept, to check the others against,
 * and for its receivers) and what the parts add to the whole file. */
typedef struct merge {
    vdsh_file *p0, *part;              /* the first part; the current other one */
    float *merged[VDSH_MAX_STREAMS];   /* f32 and variable: every receiver's rows */
    uint8_t *orders[VDSH_MAX_STREAMS]; /* variable-order streams' */
    uint32_t *offsets[VDSH_MAX_STREAMS];
    void *encoded[VDSH_MAX_STREAMS];               /* f16, s8, s8s6: the merged stream */
    float amax[VDSH_MAX_STREAMS][VDSH_MAX_COEFFS]; /* largest |c|s, zero */
    float s8_scales[VDSH_MAX_STREAMS][VDSH_MAX_COEFFS];
    uint32_t target; /* the merged encoding */
    FILE *spill;     /* f16, s8, s8s6: the parts' f32 rows */
    off_t *spill_at; /* per shard: where its rows start */
    int *owner;
    float *normals;
    uint8_t *drawn; /* per receiver, from the first part's POSN and TRIS */
    vb_cubemap_basis basis;
    vdsh_file f;
    vdsh_stream streams[VDSH_MAX_STREAMS];
    uint32_t count, V;
    uint32_t threads; /* the cpca encoder's (0: one per CPU) */
} merge;

/* The whole file from the first part, m->p0: its receivers, with every
 * shard's coefficients and oriented normals to come. 0, or 1 after saying
 * why. */
static int merge_begin(merge *m, const char *output)
{
    m->count = m->p0->part.count;
    m->V = m->p0->header.vertex_count;
    m->target = m->p0->part.encoding;
    m->f = *m->p0;
    m->f.has_part = 0;
    m->f.has_light_pool = 0; /* parts only */
    m->f.has_timings = 0;
    m->f.storage_ = NULL;
    m->f.streams = m->streams;
    m->f.stats.rays_traced = m->f.stats.rays_missed = 0;
    m->f.stats.degenerate_receivers = m->f.stats.moved_origins = m->f.stats.flipped_normals = 0;
    int missing = !(m->owner = malloc((size_t)m->count * sizeof *m->owner)) ||
                  !(m->normals = malloc((size_t)m->V * 12 + 1)) ||
                  !(m->drawn = malloc((size_t)m->V + 1)) ||
                  !(m->spill_at = malloc((size_t)m->count * sizeof *m->spill_at));
    for (uint32_t s = 0; s < m->p0->stream_count && !missing; s++) {
        m->streams[s] = m->p0->streams[s];
        size_t nc = (size_t)m->streams[s].order * m->streams[s].order;
        if (m->streams[s].flags & VDSH_STREAM_VARIABLE) /* rows of nc, zero-padded */
            missing = !(m->merged[s] = malloc((size_t)m->V * nc * sizeof(float) + 1)) ||
                      !(m->orders[s] = malloc((size_t)m->V + 1)) ||
                      !(m->offsets[s] = malloc(((size_t)m->V + 1) * sizeof(uint32_t)));
        else if (m->target == VDSH_ENCODING_F32 || m->target == VDSH_ENCODING_CPCA)
            missing = !(m->merged[s] = malloc((size_t)m->V * nc * sizeof(float) + 1));
        else if (m->target == VDSH_ENCODING_F16)
            missing = !(m->encoded[s] = malloc((size_t)m->V * nc * sizeof(uint16_t) + 1));
        else
            missing = !(m->encoded[s] = malloc(
                            (size_t)m->V * vdsh_encoding_bytes(m->target, (uint32_t)nc) + 1));
    }
    if (missing) {
        fprintf(stderr, "vdsh-merge: out of memory for %u receivers\n", m->V);
        return 1;
    }
    for (uint32_t k = 0; k < m->count; k++)
        m->owner[k] = -1;
    /* As vb_bake_fill_file: the receivers the s8, s8s6 scales are over
     * (every part has the same POSN and TRIS: mismatch). */
    vb_drawn_receivers(m->p0->positions, m->V, m->p0->indices, m->p0->header.triangle_count,
                       m->drawn);
    if (m->target != VDSH_ENCODING_F32 && m->target != VDSH_ENCODING_CPCA &&
        !(m->spill = spill_create(output)))
        return 1;
    return 0;
}

/* Part i, p (read_part checked it against the first): its receiver range,
 * once, and what it adds: counts, oriented normals and, per stream, f32
 * rows or the largest |coefficient|s the encoding's scales are (f16: the
 * stream's; s8, s8s6: per coefficient index). 0, or 1 after saying why. */
static int merge_part(merge *m, const options *o, int i, const vdsh_file *p)
{
    const vdsh_part *pt = &p->part;
    uint32_t b, e;
    vb_shard_range(m->V, pt->index, m->count, &b, &e);
    if (pt->range_begin != b || pt->range_end != e) {
        fprintf(stderr, "vdsh-merge: %s: receivers %u..%u, but shard %u of %u is %u..%u\n",
                o->parts[i], pt->range_begin, pt->range_end, pt->index, m->count, b, e);
        return 1;
    }
    if (m->owner[pt->index] >= 0) {
        fprintf(stderr, "vdsh-merge: %s: shard %u of %u again (also %s)\n", o->parts[i], pt->index,
                m->count, o->parts[m->owner[pt->index]]);
        return 1;
    }
    m->owner[pt->index] = i;
    /* Each part oriented its own range's normals, counts its own, and its
     * streams hold its range's rows only. */
    m->f.stats.rays_traced += p->stats.rays_traced;
    m->f.stats.rays_missed += p->stats.rays_missed;
    m->f.stats.degenerate_receivers += p->stats.degenerate_receivers;
    m->f.stats.moved_origins += p->stats.moved_origins;
    m->f.stats.flipped_normals += p->stats.flipped_normals;
    memcpy(m->normals + 3 * (size_t)b, p->normals + 3 * (size_t)b, (size_t)(e - b) * 12);
    if (m->spill)
        m->spill_at[pt->index] = ftello(m->spill);
    for (uint32_t s = 0; s < p->stream_count; s++) {
        size_t nc = (size_t)m->streams[s].order * m->streams[s].order;
        const float *src = p->streams[s].data;
        if (m->orders[s]) { /* each row's own order, decoded with zeros past it */
            memcpy(m->orders[s] + b, p->streams[s].orders, e - b);
            for (uint32_t r = 0; r < e - b; r++)
                vdsh_stream_decode(&p->streams[s], r, m->merged[s] + (b + r) * nc);
            continue;
        }
        if (m->spill && fwrite(src, nc * sizeof(float), e - b, m->spill) != e - b) {
            fprintf(stderr, "vdsh-merge: cannot write the temporary file beside %s: %s\n",
                    o->output, strerror(errno));
            return 1;
        }
        if (m->target == VDSH_ENCODING_F32 || m->target == VDSH_ENCODING_CPCA)
            memcpy(m->merged[s] + b * nc, src, (e - b) * nc * sizeof(float));
        else if (m->target == VDSH_ENCODING_F16)
            for (size_t k = 0; k < (e - b) * nc; k++)
                m->amax[s][0] = fmaxf(m->amax[s][0], fabsf(src[k]));
        else
            for (size_t r = 0; r < e - b; r++)
                for (size_t k = 0; k < nc && m->drawn[b + r]; k++)
                    m->amax[s][k] = fmaxf(m->amax[s][k], fabsf(src[r * nc + k]));
    }
    return 0;
}

/* After the last part: the spill complete, and every shard there. 0, or 1
 * after saying why. */
static int merge_complete(merge *m, const options *o)
{
    if (m->spill && fflush(m->spill) != 0) {
        fprintf(stderr, "vdsh-merge: cannot write the temporary file beside %s: %s\n", o->output,
                strerror(errno));
        return 1;
    }
    if ((uint32_t)o->part_count != m->count) {
        fprintf(stderr, "vdsh-merge: %u of %u shards missing:", m->count - (uint32_t)o->part_count,
                m->count);
        for (uint32_t k = 0, shown = 0; k < m->count; k++)
            if (m->owner[k] < 0 && shown++ < 32)
                fprintf(stderr, " %u", k);
        fprintf(stderr, "%s (rerun 'vdsh-bake ... --shard I/%u' for each)\n",
                m->count - (uint32_t)o->part_count > 32 ? " ..." : "", m->count);
        return 1;
    }
    return 0;
}

/* The merged streams: cpca and variable-order streams encoded, the f16,
 * s8 and s8s6 scales set. 0, or 1 after saying why. */
static int merge_streams(merge *m)
{
    m->f.normals = m->normals;
    for (uint32_t s = 0; s < m->f.stream_count; s++) {
        size_t nc = (size_t)m->streams[s].order * m->streams[s].order;
        m->streams[s].data = m->target == VDSH_ENCODING_F32 ? (void *)m->merged[s] : m->encoded[s];
        m->streams[s].encoding = m->target;
        if (m->target == VDSH_ENCODING_CPCA) {
            /* As vb_bake_fill_file: the global step over every receiver,
             * with the merged (oriented) normals, one encoder. A
             * variable-order stream's rows (zeros past each vertex's
             * order) become a fixed stream of its cap, as cpca_variable
             * (bake/lib/job.c) writes it. */
            /* as the bake's, with the pool it placed (lpol) */
            vdsh_cpca_settings st = vdsh_cpca_part_settings(m->p0);
            st.threads = m->threads;
            vdsh_stream f32 = m->streams[s];
            f32.encoding = VDSH_ENCODING_F32;
            f32.scale = 1.0f;
            f32.flags = 0;
            f32.orders = NULL;
            f32.offsets = NULL;
            f32.coef_scales = NULL;
            f32.data = m->merged[s];
            vdsh_error e;
            if (vdsh_cpca_encode_stream(&f32, m->V, m->normals, &st, &m->streams[s], &m->encoded[s],
                                        NULL, &e) != VDSH_OK) {
                fprintf(stderr, "vdsh-merge: order %u stream: %s\n", m->streams[s].order, e.msg);
                return 1;
            }
            free(m->merged[s]);
            m->merged[s] = NULL;
        } else if (m->orders[s]) {
            /* As vb_bake_variable_stream: the same scale rule, one encoder. */
            uint32_t e = m->target;
            float scale = 1.0f, vmax = 0.0f;
            if (e == VDSH_ENCODING_F16) {
                for (size_t k = 0; k < (size_t)m->V * nc; k++)
                    vmax = fmaxf(vmax, fabsf(m->merged[s][k]));
                scale = vdsh_f16_scale(vmax);
            }
            vdsh_stream_offsets(m->orders[s], m->V, e, m->offsets[s]);
            m->streams[s].scale = scale;
            m->streams[s].orders = m->orders[s];
            m->streams[s].offsets = m->offsets[s];
            m->streams[s].coef_scales = vdsh_encoding_quantised(e) ? m->s8_scales[s] : NULL;
            if (!(m->encoded[s] = malloc(4 * (size_t)m->offsets[s][m->V] + 1)) ||
                vdsh_encode_variable_drawn(e, m->merged[s], nc, m->orders[s], m->V,
                                           m->streams[s].order, scale, m->offsets[s], m->drawn,
                                           m->s8_scales[s], m->encoded[s]) != VDSH_OK) {
                fprintf(stderr, "vdsh-merge: adaptive-order coefficients do not fit %s\n",
                        vdsh_encoding_name(e));
                return 1;
            }
            free(m->merged[s]);
            m->merged[s] = NULL;
            m->streams[s].data = m->encoded[s];
        } else if (m->target == VDSH_ENCODING_F16) {
            /* As vb_bake_stream: the same scale rule, vdsh_f16_scale. */
            m->streams[s].scale = vdsh_f16_scale(m->amax[s][0]);
        } else if (vdsh_encoding_quantised(m->target)) {
            m->streams[s].scale = 1.0f;
            m->streams[s].coef_scales = m->s8_scales[s];
        }
    }
    return 0;
}

/* Pass 2 (f16, s8, s8s6): each range's rows back from the spill, encoded
 * into the merged streams with the scales of all receivers, as vdsh-bake
 * encodes the whole bake's. 0, or 1 after saying why. */
static int merge_spilled(merge *m, const char *output)
{
    for (uint32_t k = 0; k < m->count && m->spill; k++) {
        uint32_t b, e;
        vb_shard_range(m->V, k, m->count, &b, &e);
        if (fseeko(m->spill, m->spill_at[k], SEEK_SET) != 0) {
            fprintf(stderr, "vdsh-merge: cannot read back the temporary file beside %s\n", output);
            return 1;
        }
        for (uint32_t s = 0; s < m->f.stream_count; s++)
            if (!m->orders[s] && encode_spilled(m->spill, output, &m->streams[s], m->encoded[s], b,
                                                e, m->drawn, m->amax[s], m->s8_scales[s]) != 0)
                return 1;
    }
    return 0;
}

/* The basis cubemaps (the whole bake writes them beside its file) and the
 * file, all or none. 0, or 1 after saying why. */
static int merge_write(merge *m, const options *o)
{
    vb_error err;
    /* None beside a device or pipe (-o /dev/null): they would land in /dev. */
    const int cubes = m->f.header.cube_size > 0 && vb_output_has_cubemaps(o->output, NULL);
    if (cubes && vb_cubemap_basis_encode((int)m->f.header.cube_size, &m->basis, &err) != VB_OK) {
        fprintf(stderr, "vdsh-merge: %s\n", err.msg);
        return 1;
    }
    uint64_t bytes = 0;
    vt_cli_defer_signals(); /* all of them, or none: not cubemaps beside an old file */
    vb_result r =
        vb_write_outputs(&m->f, o->output, NULL, cubes ? &m->basis : NULL, NULL, 0, &bytes, &err);
    vt_cli_undefer_signals();
    if (r != VB_OK) {
        fprintf(stderr, "vdsh-merge: %s\n", err.msg);
        return 1;
    }
    if (!o->quiet)
        fprintf(stderr, "vdsh-merge: wrote %s (%u shard%s, %u receiver%s, %.2f MB)%s\n", o->output,
                m->count, vdsh_s(m->count), m->V, vdsh_s(m->V), bytes / 1e6,
                m->f.header.cube_size > 0 && !cubes
                    ? ", without its basis cubemaps: a device or pipe"
                    : "");
    return 0;
}

static void merge_free(merge *m)
{
    vb_cubemap_basis_free(&m->basis);
    for (int s = 0; s < VDSH_MAX_STREAMS; s++)
        free(m->merged[s]), free(m->encoded[s]), free(m->orders[s]), free(m->offsets[s]);
    if (m->spill)
        fclose(m->spill);
    free(m->spill_at);
    free(m->owner);
    free(m->normals);
    free(m->drawn);
    vdsh_free(m->part);
    vdsh_free(m->p0);
}

/* Every output (the file and the cubemaps that may go beside it) writable
 * and none of them a part, before any part is read. 0, or 1 after saying
 * why. */
static int check_outputs(const options *o)
{
    char cube[VB_CUBEMAP_BASIS_FILES][PATH_MAX];
    const char *outs[1 + VB_CUBEMAP_BASIS_FILES] = {o->output};
    vb_error e;
    const char *opt = "-o";
    int rc = vt_cli_no_stdout(outs, &opt, 1);
    if (rc)
        return rc;
    int n = 1;
    if (vb_output_has_cubemaps(o->output, NULL)) /* not beside /dev/null */
        for (int k = 0; k < VB_CUBEMAP_BASIS_FILES; k++)
            if (vb_output_cubemap_path(o->output, NULL, k, cube[k], sizeof cube[k], &e) == VB_OK)
                outs[n++] = cube[k];
    return vt_cli_check_outputs(outs, n, (const char *const *)o->parts, o->part_count) != 0;
}

/* Pass 1, one part at a time, then the streams, pass 2 and the files: the
 * exit status (0 merged, 1 refused or failed: said on stderr). */
static int run(const options *o)
{
    int rc = check_outputs(o);
    if (rc)
        return rc;
    merge m = {.threads = o->threads};
    int status = 1;
    quiet_merge = o->quiet;
    for (int i = 0; i < o->part_count; i++) {
        vdsh_file *p = NULL;
        if (read_part(o->parts[i], i ? m.p0 : NULL, o->parts[0], &p) != 0)
            goto out;
        if (i == 0)
            m.p0 = p;
        else
            m.part = p;
        if ((i == 0 && merge_begin(&m, o->output) != 0) || merge_part(&m, o, i, p) != 0)
            goto out;
        vdsh_free(m.part);
        m.part = NULL;
    }
    if (merge_complete(&m, o) == 0 && merge_streams(&m) == 0 && merge_spilled(&m, o->output) == 0 &&
        merge_write(&m, o) == 0)
        status = 0;
out:
    merge_free(&m);
    return status;
}

int main(int argc, char **argv)
{
    vt_cli_begin("vdsh-merge", argv);
    vt_cli_clean_exit_on_signals(); /* no temporary file left by a signal */
    options o;
    int status = parse_args(argc, argv, &o);
    return status == VT_CLI_RUN ? run(&o) : status;
}
