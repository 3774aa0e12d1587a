/*
 * vdsh_internal.h - internal to the formats library (not installed): what
 * the pieces of the .vdsh reader and writer share (vdsh.c: messages, names,
 * the encoding table and the fixed-size chunks' fields; vdsh_encode.c: the coefficient encodings and
 * stream decoding; vdsh_check.c: the value checks the reader and the
 * writer both apply; vdsh_read.c; vdsh_write.c). The byte layout itself
 * is VDSH.md's.
 */
#ifndef VDSH_INTERNAL_H
#define VDSH_INTERNAL_H

#include "vdsh.h"
#include "vdsh_failf.h"

#include <float.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/*
 * Headers are encoded field by field, but the data arrays (POSN, NORM,
 * TRIS, COEF) are pointed at in the read buffer and written straight from
 * the caller's arrays: that is only correct on a little-endian host with
 * IEEE-754 floats.
 */
#if defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__)
#if __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the formats library supports little-endian hosts only (the file is little-endian)"
#endif
#elif !defined(_WIN32)
#error "formats: cannot tell this target's byte order; it must be little-endian"
#endif
_Static_assert(sizeof(float) == 4 && FLT_MANT_DIG == 24 && FLT_MAX_EXP == 128,
               "float must be IEEE-754 binary32");
_Static_assert(sizeof(double) == 8 && DBL_MANT_DIG == 53, "double must be IEEE-754 binary64");

enum {
    FILE_HEADER_SIZE = 32,
    CHUNK_HEADER_SIZE = 16,
    HEAD_SIZE = 128,
    STREAM_HEADER_SIZE = 48,
    /* an s8 stream's scale table, order^2 f32 padded to 16 bytes, at most */
    S8_TABLE_MAX = (4 * VDSH_MAX_COEFFS + 15) & ~15,
    STAT_SIZE = 32,
    TIME_SIZE = 64,
    PART_SIZE = 32,
    ADPT_SIZE = 32,
    LREG_SIZE = 32,
    SOURCE_FIXED_SIZE = 44, /* sha256, size, name_length */
    MAX_CHUNKS = 64,
    CPCA_HEADER_SIZE = 16 /* clusters, basis, bits, record_words */
};

static const uint8_t vdsh_magic[8] = {0x56, 0x44, 0x53, 0x48, 0x0D, 0x0A, 0x1A, 0x0A};

/* ------------------------------------------------------------------ */
/* Little-endian field access                                          */
/* ------------------------------------------------------------------ */

static inline uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static inline uint64_t get_u64(const uint8_t *p)
{
    return (uint64_t)get_u32(p) | (uint64_t)get_u32(p + 4) << 32;
}

static inline float get_f32(const uint8_t *p)
{
    uint32_t u = get_u32(p);
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

static inline double get_f64(const uint8_t *p)
{
    uint64_t u = get_u64(p);
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
}

static inline void put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static inline void put_u64(uint8_t *p, uint64_t v)
{
    put_u32(p, (uint32_t)v);
    put_u32(p + 4, (uint32_t)(v >> 32));
}

static inline void put_f32(uint8_t *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    put_u32(p, u);
}

static inline void put_f64(uint8_t *p, double d)
{
    uint64_t u;
    memcpy(&u, &d, sizeof u);
    put_u64(p, u);
}

static inline uint32_t f32_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static inline float f32_from_bits(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

static inline uint64_t pad16(uint64_t n)
{
    return (16 - (n & 15)) & 15;
}

static inline size_t round16(size_t n)
{
    return (n + 15) & ~(size_t)15;
}

static inline int all_zero(const uint8_t *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (p[i])
            return 0;
    return 1;
}

/* The optional fixed-size chunks: one list of each one's fields, which
 * the reader decodes (vdsh_fields_get) and the writer encodes
 * (vdsh_fields_put); in the order the writer emits them. */
enum {
    VDSH_FIXED_STAT,
    VDSH_FIXED_TIME,
    VDSH_FIXED_PART,
    VDSH_FIXED_ADPT,
    VDSH_FIXED_LREG,
    VDSH_FIXED_COUNT
};
typedef struct vdsh_field {
    uint8_t offset; /* in the payload */
    uint8_t size;   /* bytes: 4 (u32, f32) or 8 (u64, f64) */
    uint16_t at;    /* offsetof in the struct (vdsh_stats, vdsh_timings, ...) */
} vdsh_field;
typedef struct vdsh_fixed_chunk {
    char id[5];
    uint8_t size;
    uint8_t reserved, reserved_size; /* bytes that must be zero */
    uint8_t count;
    const vdsh_field *fields;
} vdsh_fixed_chunk;
extern const vdsh_fixed_chunk vdsh_fixed_chunks[VDSH_FIXED_COUNT];
/* HEAD's fields (vdsh_header) and a COEF chunk's stream header's
 * (vdsh_stream), through the same functions. */
extern const vdsh_fixed_chunk vdsh_head_chunk, vdsh_stream_header;
/* The VDSH_FIXED_* of a chunk id; -1 for none. */
int vdsh_fixed_kind(const char *id);
void vdsh_fields_get(const vdsh_fixed_chunk *k, const uint8_t *p, void *s);
void vdsh_fields_put(const vdsh_fixed_chunk *k, uint8_t *p, const void *s);

/* A short description of a failed check, filled by the vdsh_check_* functions
 * and turned into a vdsh_error by the reader (VDSH_ERR_INVALID) or the
 * writer (VDSH_ERR_ARGUMENT). */
typedef struct why {
    char msg[400];
} why;

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
int vdsh_bad(why *w, const char *fmt, ...);

/* The signed level of weight j of record r. */
int32_t vdsh_cpca_record_level(const uint32_t *r, uint32_t bits, uint32_t j);
/* The signed level of the `bits`-wide field at word, shift of record r. */
int32_t vdsh_cpca_field_level(const uint32_t *r, uint32_t word, uint32_t shift, uint32_t bits);

/* Bytes between the stream header and the data: an s8 stream's scale
 * table (order^2 f32), zero-padded to a multiple of 16; else 0. */
size_t vdsh_stream_table_bytes(uint32_t encoding, uint32_t order);

/* Point a cpca stream's model arrays into the model block at `model` (the
 * 16-byte cpca header first; fields already set). */
void vdsh_cpca_bind(vdsh_stream *s, const uint8_t *model);

int vdsh_stream_variable(const vdsh_stream *s);

/* Stored value of coefficient i of the vertex at p (quantised encoding e). */
int32_t vdsh_quant_stored(uint32_t e, const uint8_t *p, uint32_t i);

/* One fixed-order stream per (order, quantity), one variable-order
 * stream per quantity. */
int vdsh_same_slot(const vdsh_stream *a, const vdsh_stream *b);

/* "order 5 distance", "variable-order log-distance": a stream's slot. */
const char *vdsh_slot_name(const vdsh_stream *s, char *buf, size_t n);

/* "COEF order 5 distance": how messages name a stream. */
void vdsh_stream_label(const vdsh_stream *s, uint32_t i, char *buf, size_t n);

int vdsh_check_header(const vdsh_header *h, why *w);

int vdsh_check_positions(const float *p, uint32_t v, why *w);

int vdsh_check_normals(const float *nrm, uint32_t v, why *w);

int vdsh_check_indices(const uint32_t *idx, uint32_t t, uint32_t v, why *w);

int vdsh_check_name(const uint8_t *name, size_t len, uint32_t i, why *w);

int vdsh_check_stream(const vdsh_stream *s, uint32_t i, why *w);

int vdsh_check_stream_data(const vdsh_stream *s, uint32_t i, uint32_t v, why *w);

/* The statistics must describe a bake of vertex_count receivers. */
int vdsh_check_stats(const vdsh_stats *t, uint32_t vertex_count, why *w);

int vdsh_check_part(const vdsh_part *t, uint32_t vertex_count, why *w);

/* An `lpol` chunk's contents; with has_part (else 0) the part it is in. */
int vdsh_check_light_pool(const vdsh_light_pool *l, int has_part, const vdsh_part *part, why *w);
int vdsh_check_adaptive(const vdsh_adaptive *a, uint32_t vertex_count, why *w);
int vdsh_check_light_box(const vdsh_light_box *b, why *w);

int vdsh_check_timings(const vdsh_timings *t, why *w);

#endif
