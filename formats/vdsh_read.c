/*
 * vdsh_read.c - the .vdsh reader (see vdsh.h for the API and VDSH.md for
 * the byte layout and the reading rules).
 *
 * Reading is two passes over one buffer that holds the whole file: the
 * first walks the chunk headers and checks every CRC, the second checks
 * every rule of VDSH.md "Reading rules" on the bytes (vdsh_check.c). Only
 * then is the vdsh_file allocated; its arrays point into the buffer, which
 * is 16-byte aligned, so every data array (all of which start at a
 * multiple of 16 in the file) is aligned too.
 */
#include "vdsh_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

/* ------------------------------------------------------------------ */
/* Reading                                                             */
/* ------------------------------------------------------------------ */

/* One chunk as found by the walk (offsets of the payload in the file). */
typedef struct chunk_ref {
    char id[5];
    uint64_t offset; /* of the chunk header */
    uint64_t size;   /* payload */
} chunk_ref;

enum { WALK_OK, WALK_NO_HEADER, WALK_PAST_END };

/*
 * Look at the chunk whose header starts at `off` (a multiple of 16, at most
 * `size`): fill *c and the stored/computed CRCs. WALK_NO_HEADER when its
 * 16-byte header does not fit, WALK_PAST_END when payload and padding run
 * past `size` (then only the id, size and stored CRC are filled).
 * Every comparison is written as `need > size - have` so nothing can wrap.
 */
static int walk_chunk(const uint8_t *d, size_t size, uint64_t off, chunk_ref *c,
                      uint32_t *crc_stored, uint32_t *crc_computed)
{
    if (CHUNK_HEADER_SIZE > size - off)
        return WALK_NO_HEADER;
    const uint8_t *h = d + off;
    memcpy(c->id, h, 4);
    c->id[4] = 0;
    c->offset = off;
    c->size = get_u64(h + 8);
    *crc_stored = get_u32(h + 4);
    *crc_computed = 0;
    uint64_t room = size - off - CHUNK_HEADER_SIZE;
    if (c->size > room || pad16(c->size) > room - c->size)
        return WALK_PAST_END;
    uint32_t crc = vdsh_crc32(0, h, 4);
    crc = vdsh_crc32(crc, h + 8, 8);
    crc = vdsh_crc32(crc, h + CHUNK_HEADER_SIZE, (size_t)(c->size + pad16(c->size)));
    *crc_computed = crc;
    return WALK_OK;
}

static int is_letter(uint8_t c)
{
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z');
}

/* The id as it may appear in a message: non-letters shown as '?'. */
static void printable_id(const uint8_t *p, char out[5])
{
    for (int k = 0; k < 4; k++)
        out[k] = is_letter(p[k]) ? (char)p[k] : '?';
    out[4] = 0;
}

/* Everything the validation learnt, so that building the vdsh_file needs
 * no further checks. */
typedef struct layout {
    vdsh_header header;
    uint64_t posn, norm, tris; /* payload offsets */
    uint32_t source_count;
    uint64_t source_name[VDSH_MAX_SOURCES]; /* offsets of the name bytes */
    uint32_t source_name_len[VDSH_MAX_SOURCES];
    uint64_t source_size[VDSH_MAX_SOURCES];
    uint64_t source_sha[VDSH_MAX_SOURCES];
    size_t names_bytes; /* sum of name_length + 1 */
    uint32_t stream_count;
    vdsh_stream streams[VDSH_MAX_STREAMS]; /* data = offset, as an integer */
    uint64_t stream_data[VDSH_MAX_STREAMS];
    uint64_t stream_table[VDSH_MAX_STREAMS];  /* s8: offset of the scales; else 0 */
    uint64_t stream_bytes[VDSH_MAX_STREAMS];  /* COEF payload after the stream header */
    uint64_t stream_orders[VDSH_MAX_STREAMS]; /* variable order: its order table's bytes */
    uint64_t offset_words; /* the variable-order streams' offsets, rows + 1 each */
    int has_stats;
    vdsh_stats stats;
    int has_timings;
    vdsh_timings timings;
    int has_part;
    vdsh_part part;
    int has_adaptive;
    vdsh_adaptive adaptive;
    int has_light_box;
    vdsh_light_box light_box;
    int has_light_pool;
    vdsh_light_pool light_pool; /* lights: set by load_owned */
    uint64_t lpol;              /* offset of the lights */
} layout;

typedef struct reader {
    const uint8_t *d;
    size_t size;
    const char *name;
    vdsh_error *err;
} reader;

static vdsh_result invalid(const reader *r, const why *w)
{
    return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name, "%s", w->msg);
}

/* The hint after a mesh's name: the tools that read a .vdsh read a bake. */
#define BAKE_IT_FIRST "; bake it first: vdsh-bake MODEL -o MODEL.vdsh"

/* 1 when NAME's last extension is EXT (lower case), in any case. */
static int has_extension(const char *name, const char *ext)
{
    const char *dot = strrchr(name, '.');
    const char *slash = strrchr(name, '/');
    if (!dot || (slash && dot < slash))
        return 0;
    for (dot++; *dot && *ext; dot++, ext++)
        if ((*dot >= 'A' && *dot <= 'Z' ? *dot - 'A' + 'a' : *dot) != *ext)
            return 0;
    return *dot == 0 && *ext == 0;
}

/* What a file that is not a .vdsh is: the files the tools write beside a
 * bake by their first bytes (the distance volume's magic begins with
 * "VDSH", and was called a .vdsh damaged in transfer), and every mesh
 * format vdsh-bake reads by the same rule (python/vdsh/__init__.py says
 * the same): by its magic where it has one (PLY, glb), else by the name's
 * extension, as vdsh-bake picks the reader (.obj, .off, .stl, .gltf).
 * NULL: unknown. */
static const char *other_format(const char *name, const uint8_t *d, size_t size)
{
    static const struct {
        const char *magic;
        size_t len;
        const char *what;
    } known[] = {
        {"VDSHSDF\0", 8, "a VDSH distance volume (vdsh-bake --sdf; vdsh-view --sdf reads it)"},
        {"glTF", 4, "a binary glTF mesh (.glb, as vdsh-export writes)" BAKE_IT_FIRST},
        {"\x76\x2f\x31\x01", 4, "an OpenEXR image (the bake's basis cubemaps)"},
        {"ply\n", 4, "a PLY mesh" BAKE_IT_FIRST},
        {"ply\r", 4, "a PLY mesh" BAKE_IT_FIRST},
        {"\x89PNG", 4, "a PNG image"},
    };
    static const struct {
        const char *ext;
        const char *what;
    } meshes[] = {
        {"obj", "a Wavefront OBJ mesh" BAKE_IT_FIRST},
        {"ply", "a PLY mesh" BAKE_IT_FIRST},
        {"off", "an OFF mesh" BAKE_IT_FIRST},
        {"stl", "an STL mesh" BAKE_IT_FIRST},
        {"gltf", "a glTF mesh" BAKE_IT_FIRST},
        {"glb", "a binary glTF mesh (.glb, as vdsh-export writes)" BAKE_IT_FIRST},
    };
    for (size_t i = 0; i < sizeof known / sizeof known[0]; i++)
        if (size >= known[i].len && memcmp(d, known[i].magic, known[i].len) == 0)
            return known[i].what;
    for (size_t i = 0; name && i < sizeof meshes / sizeof meshes[0]; i++)
        if (has_extension(name, meshes[i].ext))
            return meshes[i].what;
    return NULL;
}

/* "not a .vdsh file", and what it is where its first bytes say so, then
 * a .vdsh's magic damaged in transfer, then a mesh by its name. */
static vdsh_result not_vdsh(vdsh_error *err, const char *name, const uint8_t *d, size_t size)
{
    const char *what = other_format(NULL, d, size);
    if (!what && size >= sizeof vdsh_magic && memcmp(d, vdsh_magic, 4) == 0)
        return vdsh_failf_at(err, VDSH_ERR_NOT_VDSH, name,
                             "not a .vdsh file: magic bytes 4..7 damaged (a "
                             "text-mode transfer changes CR, LF and ^Z)");
    if (!what)
        what = other_format(name, d, size);
    if (what)
        return vdsh_failf_at(err, VDSH_ERR_NOT_VDSH, name, "not a .vdsh file: %s", what);
    return vdsh_failf_at(err, VDSH_ERR_NOT_VDSH, name, "not a .vdsh file (wrong magic)");
}

/* Pass 1: file header, chunk walk, every CRC and padding. */
static vdsh_result read_structure(const reader *r, chunk_ref *chunks, uint32_t *count)
{
    const uint8_t *d = r->d;
    size_t size = r->size;

    if (size < sizeof vdsh_magic) {
        if (memcmp(d, vdsh_magic, size) != 0)
            return not_vdsh(r->err, r->name, d, size);
        return vdsh_failf_at(r->err, VDSH_ERR_TRUNCATED, r->name,
                             "truncated: %zu byte%s, shorter than the %d-byte header", size,
                             vdsh_s(size), FILE_HEADER_SIZE);
    }
    if (memcmp(d, vdsh_magic, sizeof vdsh_magic) != 0)
        return not_vdsh(r->err, r->name, d, size);
    if (size < FILE_HEADER_SIZE)
        return vdsh_failf_at(r->err, VDSH_ERR_TRUNCATED, r->name,
                             "truncated: %zu byte%s, shorter than the %d-byte header", size,
                             vdsh_s(size), FILE_HEADER_SIZE);

    /* The version comes before the header CRC: a later version may lay its
     * header out differently, and "unsupported version" is then the useful
     * message. */
    uint32_t version = get_u32(d + 8);
    uint32_t crc_stored = get_u32(d + 28);
    uint32_t crc_computed = vdsh_crc32(0, d, 28);
    if (version != VDSH_FORMAT_VERSION)
        return vdsh_failf_at(
            r->err, VDSH_ERR_VERSION, r->name, "format version %u, this reader reads version %u%s",
            version, VDSH_FORMAT_VERSION,
            crc_stored == crc_computed ? ""
                                       : " (and the header CRC fails: the file may be "
                                         "damaged)");
    if (crc_stored != crc_computed)
        return vdsh_failf_at(r->err, VDSH_ERR_CRC, r->name,
                             "header CRC mismatch (stored 0x%08x, computed 0x%08x)", crc_stored,
                             crc_computed);

    uint32_t chunk_count = get_u32(d + 12);
    uint64_t file_size = get_u64(d + 16);
    uint32_t flags = get_u32(d + 24);
    if ((uint64_t)size < file_size)
        return vdsh_failf_at(r->err, VDSH_ERR_TRUNCATED, r->name,
                             "truncated: %zu byte%s, the header says %llu", size, vdsh_s(size),
                             (unsigned long long)file_size);
    if ((uint64_t)size > file_size)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                             "%zu byte%s, but the header says %llu (data after the "
                             "end)",
                             size, vdsh_s(size), (unsigned long long)file_size);
    if (flags != 0)
        return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name, "header flags 0x%x, must be 0",
                             flags);
    if (chunk_count < 1 || chunk_count > MAX_CHUNKS)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name, "chunk_count %u out of range 1..%d",
                             chunk_count, MAX_CHUNKS);

    uint64_t off = FILE_HEADER_SIZE;
    for (uint32_t i = 0; i < chunk_count; i++) {
        chunk_ref *c = &chunks[i];
        uint32_t cs, cc;
        char pid[5];
        int w = walk_chunk(d, size, off, c, &cs, &cc);
        if (w == WALK_NO_HEADER)
            return vdsh_failf_at(r->err, VDSH_ERR_TRUNCATED, r->name,
                                 "chunk %u at offset %llu: header runs past the end "
                                 "of the file (%u chunk%s announced)",
                                 i, (unsigned long long)off, chunk_count, vdsh_s(chunk_count));
        printable_id(d + off, pid);
        if (w == WALK_PAST_END)
            return vdsh_failf_at(r->err, VDSH_ERR_TRUNCATED, r->name,
                                 "chunk %u '%s' at offset %llu: payload of %llu byte%s "
                                 "runs past the end of the file",
                                 i, pid, (unsigned long long)off, (unsigned long long)c->size,
                                 vdsh_s(c->size));
        if (cs != cc)
            return vdsh_failf_at(r->err, VDSH_ERR_CRC, r->name,
                                 "chunk %u '%s' at offset %llu: CRC mismatch (stored "
                                 "0x%08x, computed 0x%08x)",
                                 i, pid, (unsigned long long)off, cs, cc);
        for (int k = 0; k < 4; k++)
            if (!is_letter(d[off + k]))
                return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                                     "chunk %u at offset %llu: id %02x %02x %02x %02x "
                                     "is not four ASCII letters",
                                     i, (unsigned long long)off, d[off], d[off + 1], d[off + 2],
                                     d[off + 3]);
        uint64_t payload = off + CHUNK_HEADER_SIZE;
        if (!all_zero(d + payload + c->size, (size_t)pad16(c->size)))
            return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                                 "chunk %u '%s' at offset %llu: padding byte not "
                                 "zero",
                                 i, pid, (unsigned long long)off);
        off = payload + c->size + pad16(c->size);
    }
    if (off != size)
        return vdsh_failf_at(
            r->err, VDSH_ERR_CHUNK, r->name, "%llu byte%s after the last of %u chunk%s",
            (unsigned long long)(size - off), vdsh_s(size - off), chunk_count, vdsh_s(chunk_count));
    *count = chunk_count;
    return VDSH_OK;
}

static vdsh_result read_head(const reader *r, const chunk_ref *c, layout *L)
{
    const uint8_t *p = r->d + c->offset + CHUNK_HEADER_SIZE;
    vdsh_header *h = &L->header;
    why w;
    if (c->size != HEAD_SIZE)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                             "HEAD: payload is %llu byte%s, must be %d",
                             (unsigned long long)c->size, vdsh_s(c->size), HEAD_SIZE);
    vdsh_fields_get(&vdsh_head_chunk, p, h);
    if (!all_zero(p + 80, 48))
        return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name,
                             "HEAD: reserved bytes 80..127 not zero");
    if (!vdsh_check_header(h, &w))
        return invalid(r, &w);
    return VDSH_OK;
}

static vdsh_result read_srcs(const reader *r, const chunk_ref *c, layout *L)
{
    const uint8_t *p = r->d + c->offset + CHUNK_HEADER_SIZE;
    uint64_t n = c->size, off = 4;
    why w;
    if (n < 4)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                             "SRCS: payload of %llu byte%s has no count", (unsigned long long)n,
                             vdsh_s(n));
    uint32_t count = get_u32(p);
    if (count > VDSH_MAX_SOURCES)
        return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name, "SRCS: count %u out of range 0..%d",
                             count, VDSH_MAX_SOURCES);
    L->names_bytes = 0;
    for (uint32_t i = 0; i < count; i++) {
        if (SOURCE_FIXED_SIZE > n - off)
            return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                                 "SRCS: source %u runs past the end of the payload", i);
        uint32_t len = get_u32(p + off + 40);
        L->source_sha[i] = c->offset + CHUNK_HEADER_SIZE + off;
        L->source_size[i] = get_u64(p + off + 32);
        off += SOURCE_FIXED_SIZE;
        if (len < 1 || len > VDSH_MAX_NAME)
            return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name,
                                 "SRCS: source %u: name_length %u out of range 1..%d", i, len,
                                 VDSH_MAX_NAME);
        uint64_t padded = ((uint64_t)len + 3) & ~(uint64_t)3;
        if (padded > n - off)
            return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                                 "SRCS: source %u: name runs past the end of the "
                                 "payload",
                                 i);
        if (!vdsh_check_name(p + off, len, i, &w))
            return invalid(r, &w);
        if (!all_zero(p + off + len, (size_t)(padded - len)))
            return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                                 "SRCS: source %u: name padding not zero", i);
        L->source_name[i] = c->offset + CHUNK_HEADER_SIZE + off;
        L->source_name_len[i] = len;
        L->names_bytes += (size_t)len + 1;
        off += padded;
    }
    if (off != n)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                             "SRCS: %llu byte%s after the last source",
                             (unsigned long long)(n - off), vdsh_s(n - off));
    L->source_count = count;
    return VDSH_OK;
}

/* POSN, NORM and TRIS: 12 bytes per vertex or triangle. */
static vdsh_result read_array(const reader *r, const chunk_ref *c, uint32_t count, const char *one,
                              const char *many)
{
    if (c->size != (uint64_t)count * 12)
        return vdsh_failf_at(
            r->err, VDSH_ERR_CHUNK, r->name, "%s: payload is %llu byte%s, %u %s need%s %llu", c->id,
            (unsigned long long)c->size, vdsh_s(c->size), count, count == 1 ? one : many,
            count == 1 ? "s" : "", (unsigned long long)count * 12);
    return VDSH_OK;
}

static vdsh_result read_coef(const reader *r, const chunk_ref *c, layout *L)
{
    char slot[64];
    const uint8_t *p = r->d + c->offset + CHUNK_HEADER_SIZE;
    uint32_t i = L->stream_count;
    vdsh_stream *s = &L->streams[i];
    char l[96];
    why w;
    if (i >= VDSH_MAX_STREAMS)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name, "more than %d COEF chunks",
                             VDSH_MAX_STREAMS);
    if (c->size < STREAM_HEADER_SIZE)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                             "COEF stream %u: payload of %llu byte%s is shorter than "
                             "the %d-byte stream header",
                             i, (unsigned long long)c->size, vdsh_s(c->size), STREAM_HEADER_SIZE);
    vdsh_fields_get(&vdsh_stream_header, p, s);
    s->data = NULL;
    s->orders = NULL;
    s->offsets = NULL;
    memset(&s->cpca, 0, sizeof s->cpca);
    vdsh_stream_label(s, i, l, sizeof l);
    if (!all_zero(p + 40, 8))
        return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name,
                             "%s: reserved bytes 40..47 not zero", l);
    if (s->encoding == VDSH_ENCODING_CPCA) {
        if (c->size - STREAM_HEADER_SIZE < CPCA_HEADER_SIZE)
            return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                                 "%s: %llu byte%s of data, shorter than the %d-byte cpca header", l,
                                 (unsigned long long)(c->size - STREAM_HEADER_SIZE),
                                 vdsh_s(c->size - STREAM_HEADER_SIZE), CPCA_HEADER_SIZE);
        s->cpca.clusters = get_u32(p + STREAM_HEADER_SIZE);
        s->cpca.basis = get_u32(p + STREAM_HEADER_SIZE + 4);
        /* the bits word: the width (or 0), VDSH_CPCA_BASES_S8 for s8 bases */
        const uint32_t bits_word = get_u32(p + STREAM_HEADER_SIZE + 8);
        s->cpca.bases_s8 = (bits_word & VDSH_CPCA_BASES_S8) != 0;
        s->cpca.bits = bits_word & ~VDSH_CPCA_BASES_S8;
        s->cpca.record_words = get_u32(p + STREAM_HEADER_SIZE + 12);
        /* bits 0: the widths table follows the cpca header (checked with
         * the header; B out of range is refused there first) */
        uint64_t b = s->cpca.basis;
        if (!s->cpca.bits && b >= 1 && b <= VDSH_MAX_COEFFS) {
            if (c->size - STREAM_HEADER_SIZE - CPCA_HEADER_SIZE < ((b + 15) & ~15ull))
                return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                                     "%s: %llu byte%s of data, shorter than the cpca widths table",
                                     l, (unsigned long long)(c->size - STREAM_HEADER_SIZE),
                                     vdsh_s(c->size - STREAM_HEADER_SIZE));
            s->cpca.widths = p + STREAM_HEADER_SIZE + CPCA_HEADER_SIZE;
        }
    }
    if (!vdsh_check_stream(s, i, &w))
        return invalid(r, &w);
    uint64_t table = s->encoding == VDSH_ENCODING_CPCA
                         ? vdsh_cpca_stream_model_bytes(&s->cpca, s->order)
                         : vdsh_stream_table_bytes(s->encoding, s->order);
    if (c->size - STREAM_HEADER_SIZE < table)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                             "%s: %llu byte%s of data, shorter than its %llu-byte scale table", l,
                             (unsigned long long)(c->size - STREAM_HEADER_SIZE),
                             vdsh_s(c->size - STREAM_HEADER_SIZE), (unsigned long long)table);
    if (table && s->encoding == VDSH_ENCODING_CPCA) {
        uint64_t n = (uint64_t)s->order * s->order, k = s->cpca.clusters, b = s->cpca.basis;
        uint64_t sizes[4] = {s->cpca.bits ? 0 : b, 4 * k * b, 2 * k * n,
                             (s->cpca.bases_s8 ? 1 : 2) * k * b * n};
        static const char *const what[4] = {"widths", "scales", "means", "bases"};
        const uint8_t *q = p + STREAM_HEADER_SIZE + CPCA_HEADER_SIZE;
        for (int a = 0; a < 4; a++) {
            uint64_t padded = (sizes[a] + 15) & ~15ull;
            if (!all_zero(q + sizes[a], (size_t)(padded - sizes[a])))
                return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name,
                                     "%s: padding after the cpca %s not zero", l, what[a]);
            q += padded;
        }
    } else if (table) {
        size_t used = (size_t)s->order * s->order * 4;
        if (!all_zero(p + STREAM_HEADER_SIZE + used, (size_t)table - used))
            return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name,
                                 "%s: padding after the scale table not zero", l);
    }
    for (uint32_t k = 0; k < i; k++)
        if (vdsh_same_slot(&L->streams[k], s))
            return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name,
                                 "%s: a second stream for %s (stream %u is "
                                 "the first)",
                                 l, vdsh_slot_name(s, slot, sizeof slot), k);
    L->stream_table[i] = table ? c->offset + CHUNK_HEADER_SIZE + STREAM_HEADER_SIZE : 0;
    L->stream_data[i] = c->offset + CHUNK_HEADER_SIZE + STREAM_HEADER_SIZE + table;
    L->stream_bytes[i] = c->size - STREAM_HEADER_SIZE;
    L->stream_count = i + 1;
    return VDSH_OK;
}

/* Every stream's size and values, once all chunks are read: a part's
 * streams hold its range's rows only, and `part` may follow the COEF
 * chunks. */
static vdsh_result check_coef_sizes(const reader *r, layout *L)
{
    uint32_t rows = L->has_part ? L->part.range_end - L->part.range_begin : L->header.vertex_count;
    why w;
    for (uint32_t i = 0; i < L->stream_count; i++) {
        vdsh_stream *s = &L->streams[i];
        char l[96];
        vdsh_stream_label(s, i, l, sizeof l);
        int cpca = s->encoding == VDSH_ENCODING_CPCA;
        uint64_t table = cpca ? vdsh_cpca_stream_model_bytes(&s->cpca, s->order)
                              : vdsh_stream_table_bytes(s->encoding, s->order);
        uint64_t orders = 0; /* a variable-order stream's order table */
        if (vdsh_stream_variable(s)) {
            orders = round16(rows);
            if (L->stream_bytes[i] < table + orders)
                return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                                     "%s: %llu byte%s of data, shorter than its scale and order "
                                     "tables (%llu bytes)",
                                     l, (unsigned long long)L->stream_bytes[i],
                                     vdsh_s(L->stream_bytes[i]),
                                     (unsigned long long)(table + orders));
            s->orders = r->d + L->stream_data[i];
            if (!all_zero(s->orders + rows, orders - rows))
                return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name,
                                     "%s: padding after the order table not zero", l);
            for (uint32_t v = 0; v < rows; v++) /* before the sizes they imply */
                if (s->orders[v] < 1 || s->orders[v] > s->order)
                    return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name,
                                         "%s: vertex %u has order %u (1..%u)", l, v, s->orders[v],
                                         s->order);
        }
        uint64_t need = table + vdsh_stream_data_bytes(s, rows);
        if (L->stream_bytes[i] != need)
            return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                                 "%s: %llu byte%s of data, %u %s of %s need%s %llu%s", l,
                                 (unsigned long long)L->stream_bytes[i], vdsh_s(L->stream_bytes[i]),
                                 rows, rows == 1 ? "vertex" : "vertices",
                                 vdsh_encoding_name(s->encoding), rows == 1 ? "s" : "",
                                 (unsigned long long)need,
                                 L->has_part ? " (a part: its range's receivers)" : "");
        s->coef_scales = table && !cpca ? (const float *)(r->d + L->stream_table[i]) : NULL;
        if (cpca)
            vdsh_cpca_bind(s, r->d + L->stream_table[i]);
        s->data = r->d + L->stream_data[i] + orders;
        int ok = vdsh_check_stream_data(s, i, rows, &w);
        s->data = NULL;
        s->orders = NULL;
        s->coef_scales = NULL;
        s->cpca.scales = NULL;
        s->cpca.means = s->cpca.bases = NULL;
        s->cpca.bases8 = NULL;
        L->stream_orders[i] = orders;
        if (orders)
            L->offset_words += (uint64_t)rows + 1;
        if (!ok)
            return invalid(r, &w);
    }
    return VDSH_OK;
}

/* stat, time, part, adpt, lreg: at most one each, of a fixed size, decoded by
 * the table the writer encodes with, then checked as the writer checks. */
static vdsh_result read_fixed(const reader *r, const chunk_ref *c, uint32_t i, int kind, layout *L)
{
    const vdsh_fixed_chunk *k = &vdsh_fixed_chunks[kind];
    int *has[VDSH_FIXED_COUNT] = {&L->has_stats, &L->has_timings, &L->has_part, &L->has_adaptive,
                                  &L->has_light_box};
    void *out[VDSH_FIXED_COUNT] = {&L->stats, &L->timings, &L->part, &L->adaptive, &L->light_box};
    const uint8_t *p = r->d + c->offset + CHUNK_HEADER_SIZE;
    uint32_t vc = L->header.vertex_count;
    why w;
    if (*has[kind])
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                             "chunk %u at offset %llu: a second %s chunk", i,
                             (unsigned long long)c->offset, k->id);
    if (c->size != k->size)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                             "%s: payload is %llu byte%s, must be %d", k->id,
                             (unsigned long long)c->size, vdsh_s(c->size), (int)k->size);
    if (!all_zero(p + k->reserved, k->reserved_size))
        return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name,
                             "%s: reserved bytes %u..%u not zero", k->id, (unsigned)k->reserved,
                             k->reserved + k->reserved_size - 1u);
    vdsh_fields_get(k, p, out[kind]);
    int ok = kind == VDSH_FIXED_STAT   ? vdsh_check_stats(&L->stats, vc, &w)
             : kind == VDSH_FIXED_TIME ? vdsh_check_timings(&L->timings, &w)
             : kind == VDSH_FIXED_PART ? vdsh_check_part(&L->part, vc, &w)
             : kind == VDSH_FIXED_ADPT ? vdsh_check_adaptive(&L->adaptive, vc, &w)
                                       : vdsh_check_light_box(&L->light_box, &w);
    if (!ok)
        return invalid(r, &w);
    *has[kind] = 1;
    return VDSH_OK;
}

/* lpol (VDSH.md "Parts"): 16 bytes (u32 count, f32 mix, f32 margin, u32
 * starts), then count lights of 3 f32; checked against the part chunk once
 * every chunk is read. */
static vdsh_result read_lpol(const reader *r, const chunk_ref *c, uint32_t i, layout *L)
{
    const uint8_t *p = r->d + c->offset + CHUNK_HEADER_SIZE;
    if (L->has_light_pool)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                             "chunk %u at offset %llu: a second lpol chunk", i,
                             (unsigned long long)c->offset);
    uint32_t count = c->size >= 16 ? get_u32(p) : 0;
    if (c->size < 16 || c->size != 16 + 12 * (uint64_t)count)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                             "lpol: payload is %llu byte%s, must be 16 + 12 x its %u light%s",
                             (unsigned long long)c->size, vdsh_s(c->size), count, vdsh_s(count));
    L->light_pool.count = count;
    L->light_pool.mix = get_f32(p + 4);
    L->light_pool.margin = get_f32(p + 8);
    L->light_pool.starts = get_u32(p + 12);
    L->light_pool.lights = (const float *)(p + 16);
    L->lpol = c->offset + CHUNK_HEADER_SIZE + 16;
    L->has_light_pool = 1;
    return VDSH_OK;
}

/* Pass 2: which chunks, in which numbers, with which contents. */
static vdsh_result read_contents(const reader *r, const chunk_ref *chunks, uint32_t count,
                                 layout *L)
{
    const char *required[4] = {"SRCS", "POSN", "NORM", "TRIS"};
    int seen[4] = {0, 0, 0, 0};
    vdsh_result res;
    why w;

    if (memcmp(chunks[0].id, "HEAD", 4) != 0)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                             "chunk 0 is '%s'; HEAD must come first", chunks[0].id);
    if ((res = read_head(r, &chunks[0], L)) != VDSH_OK)
        return res;
    const vdsh_header *h = &L->header;

    for (uint32_t i = 1; i < count; i++) {
        const chunk_ref *c = &chunks[i];
        const uint8_t *p = r->d + c->offset + CHUNK_HEADER_SIZE;
        int req = -1, fixed;
        for (int k = 0; k < 4; k++)
            if (memcmp(c->id, required[k], 4) == 0)
                req = k;
        if (req >= 0 && seen[req]++)
            return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                                 "chunk %u at offset %llu: a second %s chunk", i,
                                 (unsigned long long)c->offset, c->id);

        if (memcmp(c->id, "HEAD", 4) == 0) {
            return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                                 "chunk %u at offset %llu: a second HEAD chunk", i,
                                 (unsigned long long)c->offset);
        } else if (req == 0) {
            res = read_srcs(r, c, L);
        } else if (req == 1 || req == 2) { /* POSN, NORM */
            int (*check)(const float *, uint32_t, why *) =
                req == 1 ? vdsh_check_positions : vdsh_check_normals;
            if ((res = read_array(r, c, h->vertex_count, "vertex", "vertices")) == VDSH_OK &&
                !check((const float *)p, h->vertex_count, &w))
                res = invalid(r, &w);
            *(req == 1 ? &L->posn : &L->norm) = c->offset + CHUNK_HEADER_SIZE;
        } else if (req == 3) {
            if ((res = read_array(r, c, h->triangle_count, "triangle", "triangles")) == VDSH_OK &&
                !vdsh_check_indices((const uint32_t *)p, h->triangle_count, h->vertex_count, &w))
                res = invalid(r, &w);
            L->tris = c->offset + CHUNK_HEADER_SIZE;
        } else if (memcmp(c->id, "COEF", 4) == 0) {
            res = read_coef(r, c, L);
        } else if ((fixed = vdsh_fixed_kind(c->id)) >= 0) {
            res = read_fixed(r, c, i, fixed, L);
        } else if (memcmp(c->id, "lpol", 4) == 0) {
            res = read_lpol(r, c, i, L);
        } else if (c->id[0] >= 'A' && c->id[0] <= 'Z') {
            res = vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                                "chunk %u '%s' at offset %llu: unknown critical chunk "
                                "(a newer writer?)",
                                i, c->id, (unsigned long long)c->offset);
        } else {
            res = VDSH_OK; /* unknown ancillary: its CRC was checked; skip */
        }
        if (res != VDSH_OK)
            return res;
    }
    for (int k = 0; k < 4; k++)
        if (!seen[k])
            return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name, "no %s chunk", required[k]);
    if (L->stream_count == 0)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name, "no COEF chunk");
    if (L->has_light_pool && !vdsh_check_light_pool(&L->light_pool, L->has_part, &L->part, &w))
        return invalid(r, &w);
    return check_coef_sizes(r, L);
}

/*
 * Validate `buf` (which the caller allocated with alloc_file_buffer and
 * hands over: it is owned by the result, or freed on failure) and build
 * the vdsh_file around it.
 */
static vdsh_result load_owned(uint8_t *buf, size_t size, const char *name, vdsh_file **out,
                              vdsh_error *err)
{
    reader r = {buf, size, name ? name : "memory", err};
    chunk_ref chunks[MAX_CHUNKS];
    uint32_t count = 0;
    layout L;
    memset(&L, 0, sizeof L);

    vdsh_result res = read_structure(&r, chunks, &count);
    if (res == VDSH_OK)
        res = read_contents(&r, chunks, count, &L);
    if (res != VDSH_OK) {
        free(buf);
        return res;
    }

    /* One block for the vdsh_file, its stream and source arrays and the
     * names; the file bytes stay in `buf`, which becomes storage_. */
    size_t off_streams = round16(sizeof(vdsh_file));
    size_t off_sources = off_streams + round16(L.stream_count * sizeof(vdsh_stream));
    size_t off_names = off_sources + round16(L.source_count * sizeof(vdsh_source));
    size_t off_offsets = off_names + round16(L.names_bytes);
    if (L.offset_words > (SIZE_MAX - off_offsets) / 4) {
        free(buf);
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, r.name, "out of memory (offsets)");
    }
    size_t block_size = off_offsets + (size_t)L.offset_words * 4;
    uint8_t *block = (uint8_t *)calloc(1, block_size);
    if (!block) {
        free(buf);
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, r.name, "out of memory (%zu bytes)",
                             block_size);
    }
    vdsh_file *f = (vdsh_file *)block;
    f->storage_ = buf;
    f->header = L.header;
    f->positions = (const float *)(buf + L.posn);
    f->normals = (const float *)(buf + L.norm);
    f->indices = (const uint32_t *)(buf + L.tris);

    f->stream_count = L.stream_count;
    f->streams = (vdsh_stream *)(block + off_streams);
    uint32_t *offsets = (uint32_t *)(block + off_offsets);
    uint32_t rows = L.has_part ? L.part.range_end - L.part.range_begin : L.header.vertex_count;
    for (uint32_t i = 0; i < L.stream_count; i++) {
        vdsh_stream *st = &f->streams[i];
        *st = L.streams[i];
        st->data = buf + L.stream_data[i] + L.stream_orders[i];
        st->coef_scales = L.stream_table[i] && st->encoding != VDSH_ENCODING_CPCA
                              ? (const float *)(buf + L.stream_table[i])
                              : NULL;
        if (st->encoding == VDSH_ENCODING_CPCA)
            vdsh_cpca_bind(st, buf + L.stream_table[i]);
        if (vdsh_stream_variable(st)) {
            st->orders = buf + L.stream_data[i];
            vdsh_stream_offsets(st->orders, rows, st->encoding, offsets);
            st->offsets = offsets;
            offsets += (size_t)rows + 1;
        }
    }

    f->source_count = L.source_count;
    f->sources = L.source_count ? (vdsh_source *)(block + off_sources) : NULL;
    char *names = (char *)(block + off_names);
    for (uint32_t i = 0; i < L.source_count; i++) {
        vdsh_source *s = &f->sources[i];
        memcpy(s->sha256, buf + L.source_sha[i], 32);
        s->size = L.source_size[i];
        s->name = names;
        memcpy(names, buf + L.source_name[i], L.source_name_len[i]);
        names[L.source_name_len[i]] = 0;
        names += L.source_name_len[i] + 1;
    }
    f->has_stats = L.has_stats;
    f->stats = L.stats;
    f->has_timings = L.has_timings;
    f->timings = L.timings;
    f->has_part = L.has_part;
    f->part = L.part;
    f->has_adaptive = L.has_adaptive;
    f->adaptive = L.adaptive;
    f->has_light_box = L.has_light_box;
    f->light_box = L.light_box;
    f->has_light_pool = L.has_light_pool;
    f->light_pool = L.light_pool;
    if (L.has_light_pool)
        f->light_pool.lights = (const float *)(buf + L.lpol);
    *out = f;
    return VDSH_OK;
}

/* 16-byte aligned, as the format's arrays assume; at least 16 bytes so an
 * empty file still gets a buffer. */
static uint8_t *alloc_file_buffer(size_t size)
{
    if (size > SIZE_MAX - 15)
        return NULL;
    return (uint8_t *)aligned_alloc(16, size ? round16(size) : 16);
}

uint32_t vdsh_file_stream_vertices(const vdsh_file *f)
{
    return f->has_part ? f->part.range_end - f->part.range_begin : f->header.vertex_count;
}

vdsh_result vdsh_read_memory(const void *data, size_t size, const char *name, vdsh_file **out,
                             vdsh_error *err)
{
    const char *nm = name ? name : "memory";
    if (!out || (!data && size))
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, nm, "vdsh_read_memory: NULL %s",
                             out ? "data" : "out");
    uint8_t *buf = alloc_file_buffer(size);
    if (!buf)
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, nm, "out of memory (%zu bytes)", size);
    if (size)
        memcpy(buf, data, size);
    return load_owned(buf, size, nm, out, err);
}

vdsh_result vdsh_read(const char *path, vdsh_file **out, vdsh_error *err)
{
    if (!path || !out)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, path ? path : "(null)", "vdsh_read: NULL %s",
                             path ? "out" : "path");
    /* O_NONBLOCK: opening a FIFO must not wait for a writer (it is refused
     * below, as anything but a regular file); regular files ignore it. */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    FILE *fp = fd >= 0 ? fdopen(fd, "rb") : NULL;
    if (!fp) {
        int e = errno;
        if (fd >= 0)
            close(fd);
        return vdsh_failf_at(err, VDSH_ERR_IO, path, "cannot open: %s", strerror(e));
    }
    struct stat st;
    if (fstat(fileno(fp), &st) != 0) {
        int e = errno;
        fclose(fp);
        return vdsh_failf_at(err, VDSH_ERR_IO, path, "cannot stat: %s", strerror(e));
    }
    if (!S_ISREG(st.st_mode)) {
        fclose(fp);
        return vdsh_failf_at(err, VDSH_ERR_IO, path, "not a regular file");
    }
    if ((uintmax_t)st.st_size > (uintmax_t)(SIZE_MAX - 15)) {
        fclose(fp);
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, path, "%jd bytes do not fit in memory",
                             (intmax_t)st.st_size);
    }
    size_t size = (size_t)st.st_size;
    uint8_t *buf = alloc_file_buffer(size);
    if (!buf) {
        fclose(fp);
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, path, "out of memory (%zu bytes)", size);
    }
    size_t got = size ? fread(buf, 1, size, fp) : 0;
    int read_error = ferror(fp), e = errno;
    /* A file that changes while it is read (someone writing it in place)
     * would be judged on bytes that no longer exist: refuse. */
    int grew = !read_error && got == size && fgetc(fp) != EOF;
    fclose(fp);
    if (read_error || got != size || grew) {
        free(buf);
        if (read_error)
            return vdsh_failf_at(err, VDSH_ERR_IO, path, "read error: %s", strerror(e));
        return vdsh_failf_at(err, VDSH_ERR_IO, path,
                             "the file changed size while it was being read");
    }
    return load_owned(buf, size, path, out, err);
}

void vdsh_free(vdsh_file *f)
{
    if (!f)
        return;
    free(f->storage_);
    free(f); /* streams, sources and names live in the same block */
}

/* ------------------------------------------------------------------ */
/* Chunk listing (vdsh-info --verify)                                  */
/* ------------------------------------------------------------------ */

vdsh_result vdsh_scan_chunks(const void *data, size_t size, const char *name, vdsh_chunk_info *out,
                             uint32_t max, uint32_t *count, vdsh_error *err)
{
    const uint8_t *d = (const uint8_t *)data;
    const char *nm = name ? name : "memory";
    if (!count || (!data && size) || (!out && max))
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, nm,
                             "vdsh_scan_chunks: NULL "
                             "argument");
    if (size && memcmp(d, vdsh_magic, size < sizeof vdsh_magic ? size : sizeof vdsh_magic))
        return not_vdsh(err, nm, d, size);
    if (size < FILE_HEADER_SIZE)
        return vdsh_failf_at(err, VDSH_ERR_TRUNCATED, nm,
                             "truncated: %zu byte%s, shorter than the %d-byte header", size,
                             vdsh_s(size), FILE_HEADER_SIZE);
    uint64_t off = FILE_HEADER_SIZE;
    uint32_t n = 0;
    while (off < size && n < UINT32_MAX) {
        chunk_ref c;
        uint32_t cs, cc;
        int w = walk_chunk(d, size, off, &c, &cs, &cc);
        if (w == WALK_NO_HEADER)
            break;
        if (n < max) {
            vdsh_chunk_info *o = &out[n];
            printable_id(d + off, o->id);
            o->complete = w == WALK_OK;
            o->offset = off;
            o->size = c.size;
            o->crc_stored = cs;
            o->crc_computed = cc;
        }
        n++;
        if (w != WALK_OK)
            break;
        off += CHUNK_HEADER_SIZE + c.size + pad16(c.size);
    }
    *count = n;
    return VDSH_OK;
}
