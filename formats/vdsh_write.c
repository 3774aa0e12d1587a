/*
 * vdsh_write.c - the .vdsh writer (see vdsh.h for the API and VDSH.md for
 * the byte layout).
 *
 * Writing checks the caller's vdsh_file with the same value checks the
 * reader uses (vdsh_check.c), so the writer cannot produce a file that
 * the reader rejects, then emits the chunks from the caller's arrays
 * without copying them.
 */
#include "vdsh_internal.h"
#include "vdsh_output.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>

/* ------------------------------------------------------------------ */
/* Writing                                                             */
/* ------------------------------------------------------------------ */

/* A chunk to emit: a small encoded prefix (header fields) and the
 * caller's array, both borrowed. */
typedef struct out_chunk {
    char id[4];
    const void *pre;
    size_t pre_size;
    const void *mid; /* then mid_size bytes and mid_pad zeros (or none) */
    size_t mid_size, mid_pad;
    const void *data;
    uint64_t data_size;
    uint32_t crc;
} out_chunk;

typedef struct plan {
    uint8_t file_header[FILE_HEADER_SIZE];
    uint8_t head[HEAD_SIZE];
    /* each stream's header, then an s8 stream's scale table and padding */
    uint8_t stream_header[VDSH_MAX_STREAMS][STREAM_HEADER_SIZE + S8_TABLE_MAX];
    uint8_t fixed[VDSH_FIXED_COUNT][TIME_SIZE]; /* stat, time, part, adpt, lreg */
    uint8_t lpol[16];                           /* the lpol chunk's head */
    uint8_t *srcs;                              /* malloc'd SRCS payload */
    uint8_t *model[VDSH_MAX_STREAMS];           /* malloc'd cpca models, padded */
    out_chunk chunks[MAX_CHUNKS];
    uint32_t count;
    uint64_t file_size;
} plan;

static vdsh_result argument(vdsh_error *err, const char *name, const why *w)
{
    return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name, "not written: %s", w->msg);
}

/* The reader's rules, applied to the caller's struct. */
static vdsh_result check_file(const vdsh_file *f, const char *name, vdsh_error *err)
{
    why w;
    if (!f)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name, "not written: no file");
    const vdsh_header *h = &f->header;
    if (!vdsh_check_header(h, &w))
        return argument(err, name, &w);
    if (!f->positions || !f->normals || (!f->indices && h->triangle_count))
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name, "not written: %s is NULL",
                             !f->positions ? "positions"
                             : !f->normals ? "normals"
                                           : "indices");
    if (!vdsh_check_positions(f->positions, h->vertex_count, &w) ||
        !vdsh_check_normals(f->normals, h->vertex_count, &w) ||
        !vdsh_check_indices(f->indices, h->triangle_count, h->vertex_count, &w))
        return argument(err, name, &w);

    if (f->source_count > VDSH_MAX_SOURCES)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                             "not written: source_count %u out of range 0..%d", f->source_count,
                             VDSH_MAX_SOURCES);
    if (f->source_count && !f->sources)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name, "not written: sources is NULL");
    for (uint32_t i = 0; i < f->source_count; i++) {
        const char *s = f->sources[i].name;
        if (!s)
            return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                                 "not written: SRCS: source %u: name is NULL", i);
        if (!vdsh_check_name((const uint8_t *)s, strnlen(s, VDSH_MAX_NAME + 1), i, &w))
            return argument(err, name, &w);
    }

    /* Before the streams: a part's are its range's rows. */
    if (f->has_part && !vdsh_check_part(&f->part, h->vertex_count, &w))
        return argument(err, name, &w);
    if (f->stream_count < 1 || f->stream_count > VDSH_MAX_STREAMS)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                             "not written: stream_count %u out of range 1..%d", f->stream_count,
                             VDSH_MAX_STREAMS);
    if (!f->streams)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name, "not written: streams is NULL");
    for (uint32_t i = 0; i < f->stream_count; i++) {
        const vdsh_stream *s = &f->streams[i];
        if (!vdsh_check_stream(s, i, &w))
            return argument(err, name, &w);
        if (!s->data)
            return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                                 "not written: COEF stream %u: data is NULL", i);
        if (vdsh_encoding_quantised(s->encoding) && !s->coef_scales)
            return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                                 "not written: COEF stream %u: %s without coef_scales", i,
                                 vdsh_encoding_name(s->encoding));
        if (vdsh_stream_variable(s) && !s->orders)
            return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                                 "not written: COEF stream %u: variable order without orders", i);
        if (s->encoding == VDSH_ENCODING_CPCA &&
            (!s->cpca.scales || !s->cpca.means ||
             !(s->cpca.bases_s8 ? (const void *)s->cpca.bases8 : (const void *)s->cpca.bases)))
            return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                                 "not written: COEF stream %u: cpca without scales, means or bases",
                                 i);
        for (uint32_t k = 0; k < i; k++)
            if (vdsh_same_slot(&f->streams[k], s)) {
                char slot[64];
                return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                                     "not written: streams %u and %u are both %s", k, i,
                                     vdsh_slot_name(s, slot, sizeof slot));
            }
        if (!vdsh_check_stream_data(s, i, vdsh_file_stream_vertices(f), &w))
            return argument(err, name, &w);
    }
    if (f->has_stats && !vdsh_check_stats(&f->stats, h->vertex_count, &w))
        return argument(err, name, &w);
    if (f->has_timings && !vdsh_check_timings(&f->timings, &w))
        return argument(err, name, &w);
    if (f->has_adaptive && !vdsh_check_adaptive(&f->adaptive, h->vertex_count, &w))
        return argument(err, name, &w);
    if (f->has_light_pool && !vdsh_check_light_pool(&f->light_pool, f->has_part, &f->part, &w))
        return argument(err, name, &w);
    if (f->has_light_box && !vdsh_check_light_box(&f->light_box, &w))
        return argument(err, name, &w);
    return VDSH_OK;
}

static void add_chunk(plan *P, const char *id, const void *pre, size_t pre_size, const void *data,
                      uint64_t data_size)
{
    out_chunk *c = &P->chunks[P->count++];
    memcpy(c->id, id, 4);
    c->pre = pre;
    c->pre_size = pre_size;
    c->data = data;
    c->data_size = data_size;
}

static void plan_free(plan *P)
{
    if (P) {
        free(P->srcs);
        for (int i = 0; i < VDSH_MAX_STREAMS; i++)
            free(P->model[i]);
    }
}

/* Validate `f`, encode every header field and compute every CRC. */
static vdsh_result plan_build(plan *P, const vdsh_file *f, const char *name, vdsh_error *err)
{
    memset(P, 0, sizeof *P);
    vdsh_result res = check_file(f, name, err);
    if (res != VDSH_OK)
        return res;
    const vdsh_header *h = &f->header;

    uint8_t *p = P->head;
    vdsh_fields_put(&vdsh_head_chunk, p, h);
    add_chunk(P, "HEAD", P->head, HEAD_SIZE, NULL, 0);

    /* SRCS is small (at most 64 names of 4096 bytes): encode it whole. */
    size_t srcs_size = 4;
    for (uint32_t i = 0; i < f->source_count; i++)
        srcs_size += SOURCE_FIXED_SIZE + ((strlen(f->sources[i].name) + 3) & ~(size_t)3);
    P->srcs = (uint8_t *)calloc(1, srcs_size);
    if (!P->srcs)
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, name, "out of memory");
    put_u32(P->srcs, f->source_count);
    size_t off = 4;
    for (uint32_t i = 0; i < f->source_count; i++) {
        const vdsh_source *s = &f->sources[i];
        size_t len = strlen(s->name);
        memcpy(P->srcs + off, s->sha256, 32);
        put_u64(P->srcs + off + 32, s->size);
        put_u32(P->srcs + off + 40, (uint32_t)len);
        memcpy(P->srcs + off + SOURCE_FIXED_SIZE, s->name, len);
        off += SOURCE_FIXED_SIZE + ((len + 3) & ~(size_t)3);
    }
    add_chunk(P, "SRCS", P->srcs, srcs_size, NULL, 0);

    uint64_t v = h->vertex_count;
    add_chunk(P, "POSN", NULL, 0, f->positions, v * 12);
    add_chunk(P, "NORM", NULL, 0, f->normals, v * 12);
    add_chunk(P, "TRIS", NULL, 0, f->indices, (uint64_t)h->triangle_count * 12);

    for (uint32_t i = 0; i < f->stream_count; i++) {
        const vdsh_stream *s = &f->streams[i];
        p = P->stream_header[i];
        vdsh_fields_put(&vdsh_stream_header, p, s);
        size_t table = vdsh_stream_table_bytes(s->encoding, s->order);
        for (uint32_t k = 0; table && k < s->order * s->order; k++)
            put_f32(p + STREAM_HEADER_SIZE + 4 * k, s->coef_scales[k]);
        uint32_t rows = vdsh_file_stream_vertices(f);
        uint64_t data = vdsh_stream_data_bytes(s, rows);
        if (s->encoding == VDSH_ENCODING_CPCA) {
            /* the cpca header in the prefix, the padded arrays as `mid` */
            const vdsh_cpca *m = &s->cpca;
            put_u32(p + STREAM_HEADER_SIZE, m->clusters);
            put_u32(p + STREAM_HEADER_SIZE + 4, m->basis);
            put_u32(p + STREAM_HEADER_SIZE + 8, m->bits | (m->bases_s8 ? VDSH_CPCA_BASES_S8 : 0));
            put_u32(p + STREAM_HEADER_SIZE + 12, m->record_words);
            size_t mb = (size_t)vdsh_cpca_stream_model_bytes(m, s->order) - CPCA_HEADER_SIZE;
            size_t n = (size_t)s->order * s->order, k = m->clusters, b = m->basis;
            uint8_t *q = P->model[i] = (uint8_t *)calloc(1, mb + 1);
            if (!q)
                return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, name, "out of memory");
            if (!m->bits) { /* the widths table, padded */
                memcpy(q, m->widths, b);
                q += (b + 15) & ~(size_t)15;
            }
            for (size_t x = 0; x < k * b; x++)
                put_f32(q + 4 * x, m->scales[x]);
            q += (4 * k * b + 15) & ~(size_t)15;
            memcpy(q, m->means, 2 * k * n);
            q += (2 * k * n + 15) & ~(size_t)15;
            if (m->bases_s8)
                memcpy(q, m->bases8, k * b * n);
            else
                memcpy(q, m->bases, 2 * k * b * n);
            add_chunk(P, "COEF", p, STREAM_HEADER_SIZE + CPCA_HEADER_SIZE, s->data, data);
            out_chunk *c = &P->chunks[P->count - 1];
            c->mid = P->model[i];
            c->mid_size = mb;
            c->mid_pad = 0;
            continue;
        }
        add_chunk(P, "COEF", p, STREAM_HEADER_SIZE + table, s->data, data);
        if (vdsh_stream_variable(s)) { /* the order table, padded, before the records */
            out_chunk *c = &P->chunks[P->count - 1];
            c->mid = s->orders;
            c->mid_size = rows;
            c->mid_pad = round16(rows) - rows;
            c->data_size = data - round16(rows);
        }
    }

    const void *fixed[VDSH_FIXED_COUNT] = {f->has_stats ? (const void *)&f->stats : NULL,
                                           f->has_timings ? (const void *)&f->timings : NULL,
                                           f->has_part ? (const void *)&f->part : NULL,
                                           f->has_adaptive ? (const void *)&f->adaptive : NULL,
                                           f->has_light_box ? (const void *)&f->light_box : NULL};
    for (int k = 0; k < VDSH_FIXED_COUNT; k++)
        if (fixed[k]) {
            const vdsh_fixed_chunk *x = &vdsh_fixed_chunks[k];
            vdsh_fields_put(x, P->fixed[k], fixed[k]);
            add_chunk(P, x->id, P->fixed[k], x->size, NULL, 0);
        }
    if (f->has_light_pool) { /* a cpca part's light pool (VDSH.md "Parts") */
        put_u32(P->lpol, f->light_pool.count);
        put_f32(P->lpol + 4, f->light_pool.mix);
        put_f32(P->lpol + 8, f->light_pool.margin);
        put_u32(P->lpol + 12, f->light_pool.starts);
        add_chunk(P, "lpol", P->lpol, sizeof P->lpol, f->light_pool.lights,
                  12 * (uint64_t)f->light_pool.count);
    }

    /* Sizes are bounded by the checks above (2^28 vertices, 16 streams of
     * at most 100 bytes per vertex): well inside 64 bits. */
    static const uint8_t zeros[16] = {0};
    uint64_t total = FILE_HEADER_SIZE;
    for (uint32_t i = 0; i < P->count; i++) {
        out_chunk *c = &P->chunks[i];
        uint8_t sz[8];
        uint64_t n = c->pre_size + c->mid_size + c->mid_pad + c->data_size;
        put_u64(sz, n);
        uint32_t crc = vdsh_crc32(0, c->id, 4);
        crc = vdsh_crc32(crc, sz, 8);
        crc = vdsh_crc32(crc, c->pre, c->pre_size);
        crc = vdsh_crc32(crc, c->mid, c->mid_size);
        crc = vdsh_crc32(crc, zeros, c->mid_pad);
        crc = vdsh_crc32(crc, c->data, (size_t)c->data_size);
        c->crc = vdsh_crc32(crc, zeros, (size_t)pad16(n));
        total += CHUNK_HEADER_SIZE + n + pad16(n);
    }
    P->file_size = total;

    memcpy(P->file_header, vdsh_magic, 8);
    put_u32(P->file_header + 8, VDSH_FORMAT_VERSION);
    put_u32(P->file_header + 12, P->count);
    put_u64(P->file_header + 16, total);
    put_u32(P->file_header + 24, 0);
    put_u32(P->file_header + 28, vdsh_crc32(0, P->file_header, 28));
    return VDSH_OK;
}

/* Where the bytes go: a buffer of file_size bytes, or a FILE. */
typedef struct sink {
    uint8_t *buf;
    FILE *fp;
    uint64_t pos;
    int error; /* errno of the first failed fwrite */
} sink;

static void sink_put(sink *s, const void *p, uint64_t n)
{
    const uint8_t *b = (const uint8_t *)p;
    if (n == 0 || s->error)
        return;
    if (!s->fp) {
        memcpy(s->buf + s->pos, b, (size_t)n);
        s->pos += n;
        return;
    }
    while (n) {
        size_t k = n > ((size_t)1 << 30) ? ((size_t)1 << 30) : (size_t)n;
        errno = 0;
        if (fwrite(b, 1, k, s->fp) != k) {
            s->error = errno ? errno : EIO;
            return;
        }
        b += k;
        n -= k;
        s->pos += k;
    }
}

static void plan_emit(const plan *P, sink *s)
{
    static const uint8_t zeros[16] = {0};
    sink_put(s, P->file_header, FILE_HEADER_SIZE);
    for (uint32_t i = 0; i < P->count; i++) {
        const out_chunk *c = &P->chunks[i];
        uint8_t hdr[CHUNK_HEADER_SIZE];
        uint64_t n = c->pre_size + c->mid_size + c->mid_pad + c->data_size;
        memcpy(hdr, c->id, 4);
        put_u32(hdr + 4, c->crc);
        put_u64(hdr + 8, n);
        sink_put(s, hdr, CHUNK_HEADER_SIZE);
        sink_put(s, c->pre, c->pre_size);
        sink_put(s, c->mid, c->mid_size);
        sink_put(s, zeros, c->mid_pad);
        sink_put(s, c->data, c->data_size);
        sink_put(s, zeros, pad16(n));
    }
}

vdsh_result vdsh_write_memory(const vdsh_file *f, void **out_data, size_t *out_size,
                              vdsh_error *err)
{
    plan P;
    if (!out_data || !out_size)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, "memory", "not written: NULL output pointer");
    vdsh_result res = plan_build(&P, f, "memory", err);
    if (res != VDSH_OK) {
        plan_free(&P);
        return res;
    }
    if (P.file_size > SIZE_MAX) {
        plan_free(&P);
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, "memory",
                             "%llu bytes do not fit in memory", (unsigned long long)P.file_size);
    }
    uint8_t *buf = (uint8_t *)malloc((size_t)P.file_size);
    if (!buf) {
        plan_free(&P);
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, "memory", "out of memory (%llu bytes)",
                             (unsigned long long)P.file_size);
    }
    sink s = {buf, NULL, 0, 0};
    plan_emit(&P, &s);
    plan_free(&P);
    *out_data = buf;
    *out_size = (size_t)P.file_size;
    return VDSH_OK;
}

vdsh_result vdsh_write(const char *path, const vdsh_file *f, vdsh_error *err)
{
    return vdsh_write_sized(path, f, NULL, err);
}

vdsh_result vdsh_write_sized(const char *path, const vdsh_file *f, uint64_t *size, vdsh_error *err)
{
    plan P;
    if (!path)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, "(null)", "not written: path is NULL");
    vdsh_result res = plan_build(&P, f, path, err);
    if (res != VDSH_OK) {
        plan_free(&P);
        return res;
    }

    /* A temporary file beside `path`, renamed over it once complete and
     * on disk (vdsh_output.h). */
    vdsh_output out;
    res = vdsh_output_open(path, &out, err);
    if (res != VDSH_OK) {
        plan_free(&P);
        return res;
    }
    sink s = {NULL, out.fp, 0, 0};
    plan_emit(&P, &s);
    uint64_t total = P.file_size;
    plan_free(&P);
    if (s.error) {
        res = vdsh_failf_at(err, VDSH_ERR_IO, path, "cannot write%s%s: %s",
                            out.tmp ? " temporary file " : "", out.tmp ? out.tmp : "",
                            strerror(s.error));
        vdsh_output_abort(&out);
        return res;
    }
    res = vdsh_output_commit(&out, err);
    if (res == VDSH_OK && size)
        *size = total;
    return res;
}
