/*
 * vdsh.c - the formats library's messages, the names of the header
 * values, the encoding table, the fixed-size chunks' fields and the CRC
 * (see vdsh.h for the API and VDSH.md for the byte layout). The reader
 * and writer are vdsh_read.c and vdsh_write.c; the value checks they
 * share, vdsh_check.c; the coefficient encodings, vdsh_encode.c.
 */
#include "vdsh_internal.h"

#include <stdarg.h>
#include <stdio.h>
#include <zlib.h>

/* ------------------------------------------------------------------ */
/* Messages                                                            */
/* ------------------------------------------------------------------ */

vdsh_result vdsh_failf_at(vdsh_error *err, vdsh_result r, const char *name, const char *fmt, ...)
{
    if (err) {
        int n = snprintf(err->msg, sizeof err->msg, "%s: ", name ? name : "memory");
        if (n < 0 || (size_t)n >= sizeof err->msg)
            n = 0;
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg + n, sizeof err->msg - (size_t)n, fmt, ap);
        va_end(ap);
    }
    return r;
}

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
int vdsh_bad(why *w, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(w->msg, sizeof w->msg, fmt, ap);
    va_end(ap);
    return 0;
}

const char *vdsh_library_version(void)
{
    return VDSH_VERSION_STRING;
}

const char *vdsh_up_axis_name(uint32_t code)
{
    static const char *const names[VDSH_UP_AXES] = {"y", "z", "-z", "x", "-x", "-y"};
    return code < VDSH_UP_AXES ? names[code] : NULL;
}

const char *vdsh_result_str(vdsh_result r)
{
    switch (r) {
    case VDSH_OK: return "success";
    case VDSH_ERR_IO: return "I/O error";
    case VDSH_ERR_OUT_OF_MEMORY: return "out of memory";
    case VDSH_ERR_NOT_VDSH: return "not a .vdsh file";
    case VDSH_ERR_VERSION: return "unsupported version";
    case VDSH_ERR_TRUNCATED: return "truncated";
    case VDSH_ERR_CRC: return "CRC mismatch";
    case VDSH_ERR_CHUNK: return "bad chunk structure";
    case VDSH_ERR_INVALID: return "invalid value";
    case VDSH_ERR_ARGUMENT: return "invalid argument";
    }
    return "unknown result";
}

static const char *name_of(uint32_t v, const char *const *names, size_t n)
{
    return v < n ? names[v] : "?";
}

/* The names of an enum's values, by value: the count is the table's. */
#define NAME_OF(v, names) name_of((v), (names), sizeof(names) / sizeof((names)[0]))

const char *vdsh_method_name(uint32_t method)
{
    static const char *const n[] = {
        [VDSH_METHOD_PAPER] = "paper",   [VDSH_METHOD_FULL] = "full",
        [VDSH_METHOD_MIRROR] = "mirror", [VDSH_METHOD_LSQ] = "lsq",
        [VDSH_METHOD_SHADOW] = "shadow", [VDSH_METHOD_DECISION] = "decision"};
    return NAME_OF(method, n);
}

static size_t bytes_f32(uint32_t nc)
{
    return (size_t)nc * 4;
}
static size_t bytes_f16(uint32_t nc)
{
    return (size_t)nc * 2;
}
static size_t bytes_s8(uint32_t nc)
{
    return nc;
}
static size_t bytes_s8s6(uint32_t nc)
{
    return nc <= VDSH_S8S6_BYTES
               ? nc
               : VDSH_S8S6_BYTES + 4 * (size_t)((nc - VDSH_S8S6_BYTES + VDSH_S8S6_PER_WORD - 1) /
                                                VDSH_S8S6_PER_WORD);
}
static size_t bytes_model(uint32_t nc)
{
    (void)nc;
    return 0;
}

static const vdsh_encoding_info encodings[] = {
    {"f16", VDSH_ENCODING_F16, bytes_f16, "IEEE half floats, one scale per stream"},
    {"f32", VDSH_ENCODING_F32, bytes_f32, "IEEE floats, one scale per stream"},
    {"s8", VDSH_ENCODING_S8, bytes_s8, "signed 8-bit, a scale per coefficient index"},
    {"s8s6", VDSH_ENCODING_S8S6, bytes_s8s6,
     "bands 0-1 signed 8-bit, bands 2+ signed 6-bit, a scale per coefficient index"},
    {"cpca", VDSH_ENCODING_CPCA, bytes_model,
     "clustered PCA: per cluster a mean and basis vectors, per vertex packed weights"},
};
enum { ENCODING_COUNT = sizeof encodings / sizeof encodings[0] };

const vdsh_encoding_info *vdsh_encodings(size_t *count)
{
    if (count)
        *count = ENCODING_COUNT;
    return encodings;
}

const vdsh_encoding_info *vdsh_encoding_info_of(uint32_t encoding)
{
    for (size_t i = 0; i < ENCODING_COUNT; i++)
        if (encodings[i].encoding == encoding)
            return &encodings[i];
    return NULL;
}

const vdsh_encoding_info *vdsh_encoding_from_name(const char *name)
{
    for (size_t i = 0; name && i < ENCODING_COUNT; i++)
        if (strcmp(encodings[i].name, name) == 0)
            return &encodings[i];
    return NULL;
}

const char *vdsh_encoding_names(void)
{
    static char text[8 * ENCODING_COUNT + 64];
    if (!text[0]) {
        size_t at = 0;
        for (size_t i = 0; i < ENCODING_COUNT; i++)
            at += (size_t)snprintf(text + at, sizeof text - at, "%s%s",
                                   i == 0                    ? ""
                                   : i + 1 == ENCODING_COUNT ? " or "
                                                             : ", ",
                                   encodings[i].name);
    }
    return text;
}

const char *vdsh_encoding_name(uint32_t encoding)
{
    const vdsh_encoding_info *e = vdsh_encoding_info_of(encoding);
    return e ? e->name : "?";
}

const char *vdsh_quantity_name(uint32_t quantity)
{
    static const char *const n[] = {"distance", "distance2", "log-distance"};
    return NAME_OF(quantity, n);
}

const char *vdsh_window_name(uint32_t window)
{
    static const char *const n[] = {"none", "hann", "lanczos"};
    return NAME_OF(window, n);
}

const char *vdsh_sampling_name(uint32_t sampling)
{
    static const char *const n[] = {"sphere", "hemisphere"};
    return NAME_OF(sampling, n);
}

const char *vdsh_offset_rule_name(uint32_t rule)
{
    static const char *const n[] = {"none", "wb-avg"};
    return NAME_OF(rule, n);
}

/* ------------------------------------------------------------------ */
/* The fixed-size headers' and chunks' fields (VDSH.md)               */
/* ------------------------------------------------------------------ */

#define FIELD(off, st, member)                                                                     \
    {                                                                                              \
        (off), (uint8_t)sizeof(((st *)0)->member), (uint16_t)offsetof(st, member)                  \
    }

static const vdsh_field stat_fields[] = {
    FIELD(0, vdsh_stats, rays_traced),           FIELD(8, vdsh_stats, rays_missed),
    FIELD(16, vdsh_stats, degenerate_receivers), FIELD(20, vdsh_stats, undefined_normals),
    FIELD(24, vdsh_stats, moved_origins),        FIELD(28, vdsh_stats, flipped_normals),
};
static const vdsh_field time_fields[] = {
    FIELD(0, vdsh_timings, load),   FIELD(8, vdsh_timings, refine),
    FIELD(16, vdsh_timings, build), FIELD(24, vdsh_timings, trace),
    FIELD(32, vdsh_timings, total), FIELD(40, vdsh_timings, threads),
};
static const vdsh_field part_fields[] = {
    FIELD(0, vdsh_part, index),       FIELD(4, vdsh_part, count),
    FIELD(8, vdsh_part, range_begin), FIELD(12, vdsh_part, range_end),
    FIELD(16, vdsh_part, encoding),   FIELD(20, vdsh_part, cpca_clusters),
    FIELD(24, vdsh_part, cpca_basis), FIELD(28, vdsh_part, cpca_bits),
};
static const vdsh_field adpt_fields[] = {
    FIELD(0, vdsh_adaptive, tolerance),     FIELD(4, vdsh_adaptive, min_edge),
    FIELD(8, vdsh_adaptive, max_receivers), FIELD(12, vdsh_adaptive, lights),
    FIELD(16, vdsh_adaptive, max_rounds),   FIELD(20, vdsh_adaptive, start_receivers),
    FIELD(24, vdsh_adaptive, rounds),       FIELD(28, vdsh_adaptive, candidates),
};
static const vdsh_field lreg_fields[] = {
    FIELD(0, vdsh_light_box, rule),
    FIELD(4, vdsh_light_box, min),
    FIELD(16, vdsh_light_box, max),
};
static const vdsh_field head_fields[] = {
    FIELD(0, vdsh_header, vertex_count),
    FIELD(4, vdsh_header, triangle_count),
    FIELD(8, vdsh_header, rays),
    FIELD(12, vdsh_header, sampling),
    FIELD(16, vdsh_header, seed),
    FIELD(24, vdsh_header, max_distance),
    FIELD(28, vdsh_header, max_edge),
    FIELD(32, vdsh_header, offset_rule),
    FIELD(36, vdsh_header, load_flags),
    FIELD(40, vdsh_header, cube_size),
    FIELD(44, vdsh_header, occluder_vertex_count),
    FIELD(48, vdsh_header, occluder_triangle_count),
    FIELD(52, vdsh_header, trace_flags),
    FIELD(56, vdsh_header, bounds_min),
    FIELD(68, vdsh_header, bounds_max),
};
static const vdsh_field stream_fields[] = {
    FIELD(0, vdsh_stream, order),           FIELD(4, vdsh_stream, encoding),
    FIELD(8, vdsh_stream, method),          FIELD(12, vdsh_stream, quantity),
    FIELD(16, vdsh_stream, window),         FIELD(20, vdsh_stream, window_param),
    FIELD(24, vdsh_stream, method_param),   FIELD(28, vdsh_stream, scale),
    FIELD(32, vdsh_stream, quantity_param), FIELD(36, vdsh_stream, flags),
};
#define FIELDS(f) (uint8_t)(sizeof(f) / sizeof((f)[0])), (f)

const vdsh_fixed_chunk vdsh_head_chunk = {"HEAD", HEAD_SIZE, 80, 48, FIELDS(head_fields)};
const vdsh_fixed_chunk vdsh_stream_header = {"COEF", STREAM_HEADER_SIZE, 40, 8,
                                             FIELDS(stream_fields)};

const vdsh_fixed_chunk vdsh_fixed_chunks[VDSH_FIXED_COUNT] = {
    [VDSH_FIXED_STAT] = {"stat", STAT_SIZE, 0, 0, FIELDS(stat_fields)},
    [VDSH_FIXED_TIME] = {"time", TIME_SIZE, 44, 20, FIELDS(time_fields)},
    [VDSH_FIXED_PART] = {"part", PART_SIZE, 0, 0, FIELDS(part_fields)},
    [VDSH_FIXED_ADPT] = {"adpt", ADPT_SIZE, 0, 0, FIELDS(adpt_fields)},
    [VDSH_FIXED_LREG] = {"lreg", LREG_SIZE, 28, 4, FIELDS(lreg_fields)},
};

int vdsh_fixed_kind(const char *id)
{
    for (int k = 0; k < VDSH_FIXED_COUNT; k++)
        if (memcmp(id, vdsh_fixed_chunks[k].id, 4) == 0)
            return k;
    return -1;
}

/* The host is little-endian with IEEE floats (vdsh_internal.h): a field's
 * bytes are its value's. */
void vdsh_fields_get(const vdsh_fixed_chunk *k, const uint8_t *p, void *s)
{
    for (uint32_t i = 0; i < k->count; i++)
        memcpy((char *)s + k->fields[i].at, p + k->fields[i].offset, k->fields[i].size);
}

void vdsh_fields_put(const vdsh_fixed_chunk *k, uint8_t *p, const void *s)
{
    for (uint32_t i = 0; i < k->count; i++)
        memcpy(p + k->fields[i].offset, (const char *)s + k->fields[i].at, k->fields[i].size);
}

/* ------------------------------------------------------------------ */
/* CRC-32 (ISO-HDLC, reflected 0xEDB88320): zlib's                      */
/* ------------------------------------------------------------------ */

uint32_t vdsh_crc32(uint32_t crc, const void *data, size_t size)
{
    /* zlib answers 0 for a NULL buffer whatever crc is; an empty part
     * (a chunk without a prefix: pre NULL, pre_size 0) must leave the
     * running CRC as it is. */
    if (size == 0)
        return crc;
    return (uint32_t)crc32_z(crc, (const Bytef *)data, (z_size_t)size);
}
