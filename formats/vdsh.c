/*
 * vdsh.c - the .vdsh reader and writer (see vdsh.h for the API and
 * VDSH.md for the byte layout and the reading rules).
 *
 * Reading is two passes over one buffer that holds the whole file: the
 * first walks the chunk headers and checks every CRC, the second checks
 * every rule of VDSH.md "Reading rules" on the bytes. Only then is the
 * vdsh_file allocated; its arrays point into the buffer, which is 16-byte
 * aligned, so every data array (all of which start at a multiple of 16 in
 * the file) is aligned too.
 *
 * Writing checks the caller's vdsh_file with the same value checks the
 * reader uses (check_* below), so the writer cannot produce a file that
 * the reader rejects, then emits the chunks from the caller's arrays
 * without copying them.
 */
#include "vdsh.h"
#include "vdsh_failf.h"
#include "vdsh_output.h"

#include <errno.h>
#include <fcntl.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

/*
 * Headers are encoded field by field, but the data arrays (POSN, NORM,
 * TRIS, COEF) are pointed at in the read buffer and written straight from
 * the caller's arrays: that is only correct on a little-endian host with
 * IEEE-754 floats.
 */
#if defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__)
#if __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "vdsh.c supports little-endian hosts only (the file is little-endian)"
#endif
#elif !defined(_WIN32)
#error "vdsh.c: cannot tell this target's byte order; it must be little-endian"
#endif
_Static_assert(sizeof(float) == 4 && FLT_MANT_DIG == 24 && FLT_MAX_EXP == 128,
               "float must be IEEE-754 binary32");
_Static_assert(sizeof(double) == 8 && DBL_MANT_DIG == 53,
               "double must be IEEE-754 binary64");

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
    SOURCE_FIXED_SIZE = 44, /* sha256, size, name_length */
    MAX_CHUNKS = 64
};

static const uint8_t vdsh_magic[8] = {0x56, 0x44, 0x53, 0x48,
                                      0x0D, 0x0A, 0x1A, 0x0A};

/* ------------------------------------------------------------------ */
/* Little-endian field access                                          */
/* ------------------------------------------------------------------ */

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 |
           (uint32_t)p[3] << 24;
}

static uint64_t get_u64(const uint8_t *p)
{
    return (uint64_t)get_u32(p) | (uint64_t)get_u32(p + 4) << 32;
}

static float get_f32(const uint8_t *p)
{
    uint32_t u = get_u32(p);
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

static double get_f64(const uint8_t *p)
{
    uint64_t u = get_u64(p);
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
}

static void put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static void put_u64(uint8_t *p, uint64_t v)
{
    put_u32(p, (uint32_t)v);
    put_u32(p + 4, (uint32_t)(v >> 32));
}

static void put_f32(uint8_t *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    put_u32(p, u);
}

static void put_f64(uint8_t *p, double d)
{
    uint64_t u;
    memcpy(&u, &d, sizeof u);
    put_u64(p, u);
}

static uint32_t f32_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static float f32_from_bits(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

static uint64_t pad16(uint64_t n) { return (16 - (n & 15)) & 15; }

static size_t round16(size_t n) { return (n + 15) & ~(size_t)15; }

static int all_zero(const uint8_t *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (p[i])
            return 0;
    return 1;
}

/* ------------------------------------------------------------------ */
/* Messages                                                            */
/* ------------------------------------------------------------------ */

vdsh_result vdsh_failf(vdsh_error *err, vdsh_result r, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
    }
    return r;
}

vdsh_result vdsh_failf_at(vdsh_error *err, vdsh_result r, const char *name, const char *fmt,
                          ...)
{
    if (err) {
        int n = snprintf(err->msg, sizeof err->msg, "%s: ",
                         name ? name : "memory");
        if (n < 0 || (size_t)n >= sizeof err->msg)
            n = 0;
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg + n, sizeof err->msg - (size_t)n, fmt, ap);
        va_end(ap);
    }
    return r;
}

/* A short description of a failed check, filled by the check_* functions
 * and turned into a vdsh_error by the reader (VDSH_ERR_INVALID) or the
 * writer (VDSH_ERR_ARGUMENT). */
typedef struct why {
    char msg[400];
} why;

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
static int bad(why *w, const char *fmt, ...)
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
    static const char *const n[] = {[VDSH_METHOD_PAPER] = "paper", [VDSH_METHOD_FULL] = "full",
                                    [VDSH_METHOD_MIRROR] = "mirror", [VDSH_METHOD_LSQ] = "lsq",
                                    [VDSH_METHOD_SHADOW] = "shadow",
                                    [VDSH_METHOD_DECISION] = "decision"};
    return NAME_OF(method, n);
}

static size_t bytes_f32(uint32_t nc) { return (size_t)nc * 4; }
static size_t bytes_f16(uint32_t nc) { return (size_t)nc * 2; }
static size_t bytes_s8(uint32_t nc) { return nc; }
static size_t bytes_s8s6(uint32_t nc)
{
    return nc <= VDSH_S8S6_BYTES
               ? nc
               : VDSH_S8S6_BYTES + 4 * (size_t)((nc - VDSH_S8S6_BYTES + VDSH_S8S6_PER_WORD - 1) /
                                                VDSH_S8S6_PER_WORD);
}
static size_t bytes_model(uint32_t nc) { (void)nc; return 0; }

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
                                   i == 0 ? "" : i + 1 == ENCODING_COUNT ? " or " : ", ",
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

/* ------------------------------------------------------------------ */
/* IEEE binary16                                                       */
/* ------------------------------------------------------------------ */

/* Integer-only, so the result does not depend on the FPU's rounding mode
 * or on flush-to-zero settings of whoever calls us. */
uint16_t vdsh_f16_from_f32(float f)
{
    uint32_t x = f32_bits(f);
    uint16_t sign = (uint16_t)((x >> 16) & 0x8000u);
    uint32_t ax = x & 0x7fffffffu;

    if (ax > 0x7f800000u) /* NaN: keep the top payload bits, make it quiet */
        return (uint16_t)(sign | 0x7e00u | ((ax >> 13) & 0x3ffu));
    if (ax >= 0x477ff000u) /* >= 65520 rounds to +-Inf (65504 is odd) */
        return (uint16_t)(sign | 0x7c00u);
    if (ax >= 0x38800000u) {
        /* Normal half: rebias the exponent (127 -> 15) and round the 23-bit
         * mantissa to 10 bits, ties to even; a carry out of the mantissa
         * correctly bumps the exponent. */
        uint32_t r = ax - 0x38000000u;
        uint32_t q = r >> 13, rem = r & 0x1fffu;
        if (rem > 0x1000u || (rem == 0x1000u && (q & 1u)))
            q++;
        return (uint16_t)(sign | q);
    }
    if (ax <= 0x33000000u) /* <= 2^-25: rounds to zero (the tie goes to 0) */
        return sign;
    /* Subnormal half: the value in units of 2^-24, rounded to nearest even.
     * 2^-25 < |f| < 2^-14, so the float is normal with exponent 102..112. */
    uint32_t e = ax >> 23;
    uint32_t m = (ax & 0x7fffffu) | 0x800000u;
    uint32_t shift = 126u - e; /* 14 .. 24 */
    uint32_t q = m >> shift, rem = m & ((1u << shift) - 1u);
    uint32_t half = 1u << (shift - 1u);
    if (rem > half || (rem == half && (q & 1u)))
        q++;
    return (uint16_t)(sign | q);
}

float vdsh_f32_from_f16(uint16_t h)
{
    uint32_t sign = (uint32_t)(h & 0x8000u) << 16;
    uint32_t e = (h >> 10) & 0x1fu;
    uint32_t m = h & 0x3ffu;
    if (e == 0x1f) /* Inf, NaN (payload and quiet bit kept) */
        return f32_from_bits(sign | 0x7f800000u | (m << 13));
    if (e != 0)
        return f32_from_bits(sign | ((e + 112u) << 23) | (m << 13));
    if (m == 0)
        return f32_from_bits(sign);
    /* Subnormal half: normalise; every one is a normal float. */
    e = 113;
    while (!(m & 0x400u)) {
        m <<= 1;
        e--;
    }
    return f32_from_bits(sign | (e << 23) | ((m & 0x3ffu) << 13));
}

vdsh_result vdsh_encode_f16(const float *src, size_t n, float scale,
                            uint16_t *dst)
{
    if (!(scale > 0.0f) || !isfinite(scale))
        return VDSH_ERR_ARGUMENT;
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(src[i]))
            return VDSH_ERR_INVALID;
        uint16_t h = vdsh_f16_from_f32(src[i] / scale);
        if ((h & 0x7c00u) == 0x7c00u)
            return VDSH_ERR_INVALID;
        dst[i] = h;
    }
    return VDSH_OK;
}

size_t vdsh_encoding_bytes(uint32_t e, uint32_t nc)
{
    const vdsh_encoding_info *info = vdsh_encoding_info_of(e);
    return info ? info->bytes(nc) : 0;
}

/* s8s6: where coefficient i >= 4 of a vertex lies: its word's byte
 * offset in the vertex and the field's shift. */
static void s8s6_field(uint32_t i, size_t *byte, unsigned *shift)
{
    uint32_t k = i - VDSH_S8S6_BYTES;
    *byte = VDSH_S8S6_BYTES + 4 * (size_t)(k / VDSH_S8S6_PER_WORD);
    *shift = VDSH_S8S6_BITS * (k % VDSH_S8S6_PER_WORD);
}

/* Stored value of coefficient i of the vertex at p (quantised encoding e). */
static int32_t quant_stored(uint32_t e, const uint8_t *p, uint32_t i)
{
    if (e == VDSH_ENCODING_S8 || i < VDSH_S8S6_BYTES)
        return (int8_t)p[i];
    size_t byte;
    unsigned shift;
    s8s6_field(i, &byte, &shift);
    uint32_t f = (get_u32(p + byte) >> shift) & 63u;
    return f >= 32u ? (int32_t)f - 64 : (int32_t)f;
}

vdsh_result vdsh_encode_s8(const float *src, size_t vertices, uint32_t nc, float *scales,
                           int8_t *dst)
{
    return vdsh_encode_quantised(VDSH_ENCODING_S8, src, vertices, nc, scales, dst);
}

/* One quantised record: nc coefficients c with per-index scales amax into
 * p (zeroed by the caller): stored = round(levels c / scale) in double
 * (the quotient of two finite floats is finite in double, subnormal
 * scales too), ties away from 0, clamped to +-levels: a drawn receiver's
 * |c| <= scale never needs it, an undrawn one's (vdsh_encode_quantised_drawn)
 * may exceed its scale. */
static void quantise_record(uint32_t encoding, const float *c, uint32_t nc, const float *amax,
                            uint8_t *p)
{
    for (uint32_t i = 0; i < nc; i++) {
        double l = (double)vdsh_quant_levels(encoding, i);
        double q = amax[i] > 0.0f ? round(l * ((double)c[i] / (double)amax[i])) : 0.0;
        q = q > l ? l : q < -l ? -l : q;
        if (encoding == VDSH_ENCODING_S8 || i < VDSH_S8S6_BYTES) {
            p[i] = (uint8_t)(int8_t)q;
        } else {
            size_t byte;
            unsigned shift;
            s8s6_field(i, &byte, &shift);
            put_u32(p + byte, get_u32(p + byte) | ((uint32_t)(int32_t)q & 63u) << shift);
        }
    }
}

vdsh_result vdsh_encode_quantised(uint32_t encoding, const float *src, size_t vertices,
                                  uint32_t nc, float *scales, void *dst)
{
    return vdsh_encode_quantised_drawn(encoding, src, vertices, nc, NULL, scales, dst);
}

vdsh_result vdsh_encode_quantised_drawn(uint32_t encoding, const float *src, size_t vertices,
                                        uint32_t nc, const uint8_t *drawn, float *scales,
                                        void *dst)
{
    if (nc < 1 || nc > VDSH_MAX_COEFFS || !vdsh_encoding_quantised(encoding))
        return VDSH_ERR_ARGUMENT;
    float amax[VDSH_MAX_COEFFS] = {0};
    for (size_t v = 0; v < vertices; v++)
        for (uint32_t i = 0; i < nc; i++) {
            float a = fabsf(src[v * nc + i]);
            if (!isfinite(a))
                return VDSH_ERR_INVALID;
            if (!drawn || drawn[v])
                amax[i] = a > amax[i] ? a : amax[i];
        }
    for (uint32_t i = 0; i < nc; i++) {
        int levels = vdsh_quant_levels(encoding, i);
        if (!isfinite((float)levels * vdsh_quant_step(amax[i], levels)))
            return VDSH_ERR_INVALID; /* near FLT_MAX: `levels` steps would overflow */
    }
    size_t bpv = vdsh_encoding_bytes(encoding, nc);
    uint8_t *out = (uint8_t *)dst;
    if (vertices)
        memset(out, 0, vertices * bpv);
    for (size_t v = 0; v < vertices; v++)
        quantise_record(encoding, src + v * nc, nc, amax, out + v * bpv);
    memcpy(scales, amax, nc * sizeof *scales);
    return VDSH_OK;
}

vdsh_result vdsh_encode_variable(uint32_t encoding, const float *src, size_t stride,
                                 const uint8_t *orders, uint32_t rows, uint32_t cap,
                                 float scale, const uint32_t *offsets, float *scales,
                                 void *dst)
{
    return vdsh_encode_variable_drawn(encoding, src, stride, orders, rows, cap, scale, offsets,
                                      NULL, scales, dst);
}

vdsh_result vdsh_encode_variable_drawn(uint32_t encoding, const float *src, size_t stride,
                                       const uint8_t *orders, uint32_t rows, uint32_t cap,
                                       float scale, const uint32_t *offsets,
                                       const uint8_t *drawn, float *scales, void *dst)
{
    if (cap < 1 || cap > VDSH_MAX_ORDER || stride < (size_t)cap * cap ||
        encoding > VDSH_ENCODING_LAST || !(scale > 0.0f) || !isfinite(scale))
        return VDSH_ERR_ARGUMENT;
    for (uint32_t v = 0; v < rows; v++)
        if (orders[v] < 1 || orders[v] > cap)
            return VDSH_ERR_ARGUMENT;
    uint8_t *out = (uint8_t *)dst;
    memset(out, 0, 4 * (size_t)offsets[rows]);
    float amax[VDSH_MAX_COEFFS] = {0};
    if (vdsh_encoding_quantised(encoding)) {
        for (uint32_t v = 0; v < rows; v++)
            for (uint32_t i = 0; i < (uint32_t)orders[v] * orders[v]; i++) {
                float a = fabsf(src[v * stride + i]);
                if (!isfinite(a))
                    return VDSH_ERR_INVALID;
                if (!drawn || drawn[v])
                    amax[i] = a > amax[i] ? a : amax[i];
            }
        for (uint32_t i = 0; i < cap * cap; i++) {
            int levels = vdsh_quant_levels(encoding, i);
            if (!isfinite((float)levels * vdsh_quant_step(amax[i], levels)))
                return VDSH_ERR_INVALID;
        }
        memcpy(scales, amax, (size_t)cap * cap * sizeof *scales);
    }
    for (uint32_t v = 0; v < rows; v++) {
        const float *c = src + v * stride;
        uint32_t nc = (uint32_t)orders[v] * orders[v];
        uint8_t *p = out + 4 * (size_t)offsets[v];
        if (vdsh_encoding_quantised(encoding)) {
            quantise_record(encoding, c, nc, amax, p);
        } else if (encoding == VDSH_ENCODING_F16) {
            uint16_t h[VDSH_MAX_COEFFS];
            vdsh_result r = vdsh_encode_f16(c, nc, scale, h);
            if (r != VDSH_OK)
                return r;
            memcpy(p, h, 2 * (size_t)nc);
        } else {
            for (uint32_t i = 0; i < nc; i++) {
                float x = c[i] / scale;
                if (!isfinite(x))
                    return VDSH_ERR_INVALID;
                memcpy(p + 4 * (size_t)i, &x, 4);
            }
        }
    }
    return VDSH_OK;
}

/* ------------------------------------------------------------------ */
/* Streams                                                             */
/* ------------------------------------------------------------------ */

/* Bytes between the stream header and the data: an s8 stream's scale
 * table (order^2 f32), zero-padded to a multiple of 16; else 0. */
static size_t stream_table_bytes(uint32_t encoding, uint32_t order)
{
    if (!vdsh_encoding_quantised(encoding))
        return 0;
    return ((size_t)order * order * 4 + 15) & ~(size_t)15;
}

/* ---- cpca (VDSH.md "cpca streams") ---- */

enum { CPCA_HEADER_SIZE = 16 };

uint32_t vdsh_cpca_record_words(uint32_t basis, uint32_t bits)
{
    if (bits < VDSH_CPCA_MIN_BITS || bits > VDSH_CPCA_MAX_BITS)
        return 0;
    uint32_t word = 0, used = VDSH_CPCA_INDEX_BITS;
    for (uint32_t j = 0; j < basis; j++) {
        if (used + bits > 32) {
            word++;
            used = 0;
        }
        used += bits;
    }
    return word + 1;
}

void vdsh_cpca_field(uint32_t bits, uint32_t j, uint32_t *word, uint32_t *shift)
{
    /* word 0 holds (32 - 8) / bits fields after the index, later words
     * 32 / bits each */
    uint32_t first = (32 - VDSH_CPCA_INDEX_BITS) / bits, per = 32 / bits;
    if (j < first) {
        *word = 0;
        *shift = VDSH_CPCA_INDEX_BITS + j * bits;
    } else {
        *word = 1 + (j - first) / per;
        *shift = ((j - first) % per) * bits;
    }
}

uint64_t vdsh_cpca_model_bytes(uint32_t order, uint32_t clusters, uint32_t basis)
{
    uint64_t n = (uint64_t)order * order, k = clusters, b = basis;
    return CPCA_HEADER_SIZE + ((4 * k * b + 15) & ~15ull) + ((2 * k * n + 15) & ~15ull) +
           ((2 * k * b * n + 15) & ~15ull);
}

/* Point a cpca stream's model arrays into the model block at `model` (the
 * 16-byte cpca header first; fields already set). */
static void cpca_bind(vdsh_stream *s, const uint8_t *model)
{
    uint64_t n = (uint64_t)s->order * s->order, k = s->cpca.clusters, b = s->cpca.basis;
    const uint8_t *q = model + CPCA_HEADER_SIZE;
    s->cpca.scales = (const float *)q;
    q += (4 * k * b + 15) & ~15ull;
    s->cpca.means = (const uint16_t *)q;
    q += (2 * k * n + 15) & ~15ull;
    s->cpca.bases = (const uint16_t *)q;
}

static const uint32_t *cpca_record(const vdsh_stream *s, uint32_t v)
{
    return (const uint32_t *)s->data + (size_t)v * s->cpca.record_words;
}

uint32_t vdsh_cpca_cluster(const vdsh_stream *s, uint32_t v)
{
    return cpca_record(s, v)[0] & 0xffu;
}

/* The signed level of weight j of record r. */
static int32_t cpca_level(const uint32_t *r, uint32_t bits, uint32_t j)
{
    uint32_t word, shift;
    vdsh_cpca_field(bits, j, &word, &shift);
    uint32_t u = (r[word] >> shift) & ((1u << bits) - 1u);
    return (int32_t)u - (int32_t)((u >> (bits - 1)) << bits);
}

void vdsh_cpca_weights(const vdsh_stream *s, uint32_t v, int32_t *levels, float *weights)
{
    const uint32_t *r = cpca_record(s, v);
    uint32_t c = r[0] & 0xffu, b = s->cpca.basis, bits = s->cpca.bits;
    for (uint32_t j = 0; j < b; j++) {
        int32_t q = cpca_level(r, bits, j);
        if (levels)
            levels[j] = q;
        if (weights)
            weights[j] = (float)q * vdsh_cpca_step(s->cpca.scales[(size_t)c * b + j], bits);
    }
}

/* Vertex v's coefficients: mean + sum of weight x basis, in f32, j in
 * order (VDSH.md's rule, to the bit). */
static void cpca_decode(const vdsh_stream *s, uint32_t v, float *out)
{
    uint32_t n = s->order * s->order, b = s->cpca.basis;
    uint32_t c = vdsh_cpca_cluster(s, v);
    float w[VDSH_MAX_COEFFS];
    vdsh_cpca_weights(s, v, NULL, w);
    const uint16_t *mean = s->cpca.means + (size_t)c * n;
    for (uint32_t i = 0; i < n; i++)
        out[i] = vdsh_f32_from_f16(mean[i]);
    for (uint32_t j = 0; j < b; j++) {
        const uint16_t *basis = s->cpca.bases + ((size_t)c * b + j) * n;
        /* -std=c11: no contraction into a fused multiply-add */
        for (uint32_t i = 0; i < n; i++)
            out[i] = out[i] + w[j] * vdsh_f32_from_f16(basis[i]);
    }
}

static int stream_variable(const vdsh_stream *s)
{
    return (s->flags & VDSH_STREAM_VARIABLE) != 0;
}

static const vdsh_stream *find_stream(const vdsh_file *f, uint32_t order, uint32_t quantity,
                                      uint32_t flags)
{
    if (!f || !f->streams)
        return NULL;
    for (uint32_t i = 0; i < f->stream_count; i++)
        if ((order == 0 || f->streams[i].order == order) &&
            f->streams[i].quantity == quantity && f->streams[i].flags == flags)
            return &f->streams[i];
    return NULL;
}

const vdsh_stream *vdsh_find_stream(const vdsh_file *f, uint32_t order,
                                    uint32_t quantity)
{
    return order ? find_stream(f, order, quantity, 0) : NULL;
}

const vdsh_stream *vdsh_find_variable_stream(const vdsh_file *f, uint32_t quantity)
{
    return find_stream(f, 0, quantity, VDSH_STREAM_VARIABLE);
}

uint32_t vdsh_stream_vertex_order(const vdsh_stream *s, uint32_t v)
{
    return stream_variable(s) ? s->orders[v] : s->order;
}

size_t vdsh_stream_bytes_per_vertex(const vdsh_stream *s)
{
    if (!s || s->order < 1 || s->order > VDSH_MAX_ORDER || stream_variable(s))
        return 0;
    if (s->encoding == VDSH_ENCODING_CPCA)
        return 4 * (size_t)s->cpca.record_words;
    return vdsh_encoding_bytes(s->encoding, s->order * s->order);
}

uint32_t vdsh_record_words(uint32_t encoding, uint32_t order)
{
    return (uint32_t)((vdsh_encoding_bytes(encoding, order * order) + 3) / 4);
}

/* words[k]: a record of order k (0 for order 0; orders above the maximum
 * index words[0] in the callers, so a damaged table sizes nothing). */
static void record_words_table(uint32_t encoding, uint32_t words[VDSH_ORDER_SLOTS])
{
    for (uint32_t k = 0; k <= VDSH_MAX_ORDER; k++)
        words[k] = vdsh_record_words(encoding, k);
}

void vdsh_stream_offsets(const uint8_t *orders, uint32_t rows, uint32_t encoding,
                         uint32_t *offsets)
{
    uint32_t words[VDSH_ORDER_SLOTS];
    record_words_table(encoding, words);
    uint32_t at = 0;
    for (uint32_t v = 0; v < rows; v++) {
        offsets[v] = at;
        at += words[orders[v] <= VDSH_MAX_ORDER ? orders[v] : 0];
    }
    offsets[rows] = at;
}

/* Words of all records of a variable-order stream's `rows` rows. */
static uint64_t records_words(const uint8_t *orders, uint32_t rows, uint32_t encoding)
{
    uint32_t words[VDSH_ORDER_SLOTS];
    record_words_table(encoding, words);
    uint64_t at = 0;
    for (uint32_t v = 0; v < rows; v++)
        at += words[orders[v] <= VDSH_MAX_ORDER ? orders[v] : 0];
    return at;
}

uint64_t vdsh_stream_data_bytes(const vdsh_stream *s, uint32_t rows)
{
    if (!stream_variable(s))
        return (uint64_t)rows * vdsh_stream_bytes_per_vertex(s);
    return ((uint64_t)rows + 15) / 16 * 16 + 4 * records_words(s->orders, rows, s->encoding);
}

vdsh_stream_size vdsh_stream_size_of(const vdsh_stream *s, uint32_t rows)
{
    vdsh_stream_size z = {{0}, 0.0, 0};
    if (!stream_variable(s)) {
        if (s->order <= VDSH_MAX_ORDER)
            z.rows_per_order[s->order] = rows;
        z.max_bytes = (uint32_t)vdsh_stream_bytes_per_vertex(s);
        z.mean_bytes = z.max_bytes;
        if (s->encoding == VDSH_ENCODING_CPCA && rows)
            z.mean_bytes += (double)vdsh_cpca_model_bytes(s->order, s->cpca.clusters,
                                                          s->cpca.basis) / rows;
        return z;
    }
    for (uint32_t v = 0; v < rows; v++)
        z.rows_per_order[s->orders[v] <= VDSH_MAX_ORDER ? s->orders[v] : 0]++;
    for (uint32_t k = 1; k <= VDSH_MAX_ORDER; k++) /* records grow with the order */
        if (z.rows_per_order[k])
            z.max_bytes = 4 * vdsh_record_words(s->encoding, k);
    z.mean_bytes = rows ? (double)vdsh_stream_data_bytes(s, rows) / rows : 0.0;
    return z;
}

/* n coefficients of one record at d (`encoding`, the scales of the stream). */
static void decode_record(const vdsh_stream *s, const void *d, uint32_t n, float *out)
{
    if (s->encoding == VDSH_ENCODING_F16) {
        const uint16_t *h = (const uint16_t *)d;
        for (uint32_t i = 0; i < n; i++)
            out[i] = vdsh_f32_from_f16(h[i]) * s->scale;
    } else if (s->encoding == VDSH_ENCODING_F32) {
        const float *f = (const float *)d;
        for (uint32_t i = 0; i < n; i++)
            out[i] = f[i] * s->scale;
    } else if (vdsh_encoding_quantised(s->encoding) && s->coef_scales) {
        for (uint32_t i = 0; i < n; i++)
            out[i] = (float)quant_stored(s->encoding, (const uint8_t *)d, i) *
                     vdsh_quant_step(s->coef_scales[i], vdsh_quant_levels(s->encoding, i));
    } else {
        for (uint32_t i = 0; i < n; i++)
            out[i] = 0.0f;
    }
}

void vdsh_stream_decode(const vdsh_stream *s, uint32_t v, float *out)
{
    if (s->order < 1 || s->order > VDSH_MAX_ORDER)
        return; /* programmer error; nothing sensible to write */
    uint32_t n = s->order * s->order;
    if (s->encoding == VDSH_ENCODING_CPCA) {
        cpca_decode(s, v, out);
        return;
    }
    if (stream_variable(s)) {
        uint32_t k = s->orders[v];
        k = k < s->order ? k : s->order;
        decode_record(s, (const uint32_t *)s->data + s->offsets[v], k * k, out);
        for (uint32_t i = k * k; i < n; i++)
            out[i] = 0.0f;
        return;
    }
    decode_record(s, (const uint8_t *)s->data + (size_t)v * vdsh_encoding_bytes(s->encoding, n),
                  n, out);
}

/* ------------------------------------------------------------------ */
/* Value checks shared by the reader and the writer                   */
/* ------------------------------------------------------------------ */

/* Each returns 1 when the value is acceptable, else 0 with a description
 * in *w. The reader calls them on decoded fields, the writer on the
 * caller's struct: one set of rules, so a written file always reads. */

static int check_header(const vdsh_header *h, why *w)
{
    if (h->vertex_count < 1 || h->vertex_count > VDSH_MAX_VERTICES)
        return bad(w, "HEAD: vertex_count %u out of range 1..%u",
                   h->vertex_count, VDSH_MAX_VERTICES);
    if (h->triangle_count > VDSH_MAX_TRIANGLES)
        return bad(w, "HEAD: triangle_count %u out of range 0..%u",
                   h->triangle_count, VDSH_MAX_TRIANGLES);
    if (h->rays < 1)
        return bad(w, "HEAD: rays is 0, must be at least 1");
    if (h->sampling > VDSH_SAMPLING_HEMISPHERE)
        return bad(w, "HEAD: sampling %u unknown (0 sphere, 1 hemisphere)",
                   h->sampling);
    if (!isfinite(h->max_distance) || !(h->max_distance > 0.0f))
        return bad(w, "HEAD: max_distance %g must be finite and > 0",
                   (double)h->max_distance);
    if (!isfinite(h->max_edge) || !(h->max_edge >= 0.0f))
        return bad(w, "HEAD: max_edge %g must be finite and >= 0",
                   (double)h->max_edge);
    if (h->offset_rule > VDSH_OFFSET_WB_AVG)
        return bad(w, "HEAD: offset_rule %u unknown (0 none, 1 wb-avg)",
                   h->offset_rule);
    if (h->load_flags & ~(uint32_t)VDSH_LOAD_WELD)
        return bad(w, "HEAD: load_flags 0x%x has unknown bits", h->load_flags);
    if (h->trace_flags & ~(uint32_t)VDSH_TRACE_ROBUST)
        return bad(w, "HEAD: trace_flags 0x%x has unknown bits",
                   h->trace_flags);
    for (int k = 0; k < 3; k++) {
        if (!isfinite(h->bounds_min[k]) || !isfinite(h->bounds_max[k]))
            return bad(w, "HEAD: bounds axis %d (%g .. %g) not finite", k,
                       (double)h->bounds_min[k], (double)h->bounds_max[k]);
        if (h->bounds_min[k] > h->bounds_max[k])
            return bad(w, "HEAD: bounds_min[%d] %g > bounds_max[%d] %g", k,
                       (double)h->bounds_min[k], k, (double)h->bounds_max[k]);
    }
    return 1;
}

/* Largest |x| bit pattern of n floats; >= 0x7f800000 means one is Inf or
 * NaN. One pass that vectorises, so the common all-good case is cheap; the
 * slow search for the culprit only runs to word a message. */
static uint32_t max_abs_bits_f32(const float *a, size_t n)
{
    uint32_t m = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t u;
        memcpy(&u, a + i, sizeof u);
        u &= 0x7fffffffu;
        m = u > m ? u : m;
    }
    return m;
}

static size_t first_nonfinite_f32(const float *a, size_t n)
{
    size_t i = 0;
    while (i < n && isfinite(a[i]))
        i++;
    return i;
}

static int check_positions(const float *p, uint32_t v, why *w)
{
    size_t n = (size_t)v * 3;
    if (max_abs_bits_f32(p, n) >= 0x7f800000u) {
        size_t i = first_nonfinite_f32(p, n);
        return bad(w, "POSN: vertex %zu has a non-finite coordinate (%g)",
                   i / 3, (double)p[i]);
    }
    return 1;
}

static int check_normals(const float *nrm, uint32_t v, why *w)
{
    size_t n = (size_t)v * 3;
    if (max_abs_bits_f32(nrm, n) >= 0x7f800000u) {
        size_t i = first_nonfinite_f32(nrm, n);
        return bad(w, "NORM: normal of vertex %zu has a non-finite component "
                   "(%g)", i / 3, (double)nrm[i]);
    }
    /* |len - 1| < 1e-3 without a square root: compare len^2 against the
     * squared bounds, in double so float rounding cannot move the edge. */
    const double lo = (1.0 - 1e-3) * (1.0 - 1e-3);
    const double hi = (1.0 + 1e-3) * (1.0 + 1e-3);
    for (size_t i = 0; i < v; i++) {
        const float *q = nrm + 3 * i;
        double l2 = (double)q[0] * q[0] + (double)q[1] * q[1] +
                    (double)q[2] * q[2];
        if (!(l2 > lo && l2 < hi) &&
            !(q[0] == 0.0f && q[1] == 0.0f && q[2] == 0.0f))
            return bad(w, "NORM: normal of vertex %zu (%g, %g, %g) has length "
                       "%g; must be 1 within 1e-3, or exactly (0, 0, 0)", i,
                       (double)q[0], (double)q[1], (double)q[2], sqrt(l2));
    }
    return 1;
}

static int check_indices(const uint32_t *idx, uint32_t t, uint32_t v, why *w)
{
    size_t n = (size_t)t * 3;
    uint32_t m = 0;
    for (size_t i = 0; i < n; i++)
        m = idx[i] > m ? idx[i] : m;
    if (n && m >= v) {
        size_t i = 0;
        while (idx[i] < v)
            i++;
        return bad(w, "TRIS: index %u out of range (%u vertices) in "
                   "triangle %zu", idx[i], v, i / 3);
    }
    return 1;
}

/* Offset of the first byte that breaks strict UTF-8 (no overlong forms,
 * no surrogates, nothing above U+10FFFF), or n when all is well. */
static size_t utf8_error_at(const uint8_t *s, size_t n)
{
    size_t i = 0;
    while (i < n) {
        uint32_t c = s[i], cp, min;
        size_t len;
        if (c < 0x80) {
            i++;
            continue;
        } else if ((c & 0xe0) == 0xc0) {
            len = 2, cp = c & 0x1f, min = 0x80;
        } else if ((c & 0xf0) == 0xe0) {
            len = 3, cp = c & 0x0f, min = 0x800;
        } else if ((c & 0xf8) == 0xf0) {
            len = 4, cp = c & 0x07, min = 0x10000;
        } else {
            return i;
        }
        if (len > n - i)
            return i;
        for (size_t k = 1; k < len; k++) {
            if ((s[i + k] & 0xc0) != 0x80)
                return i;
            cp = cp << 6 | (s[i + k] & 0x3fu);
        }
        if (cp < min || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff))
            return i;
        i += len;
    }
    return n;
}

static int check_name(const uint8_t *name, size_t len, uint32_t i, why *w)
{
    if (len < 1 || len > VDSH_MAX_NAME)
        return bad(w, "SRCS: source %u: name length %zu out of range 1..%d",
                   i, len, VDSH_MAX_NAME);
    if (memchr(name, 0, len))
        return bad(w, "SRCS: source %u: name contains a NUL byte", i);
    size_t at = utf8_error_at(name, len);
    if (at != len)
        return bad(w, "SRCS: source %u: name is not valid UTF-8 (byte %zu)",
                   i, at);
    return 1;
}

/* One fixed-order stream per (order, quantity), one variable-order
 * stream per quantity. */
static int same_slot(const vdsh_stream *a, const vdsh_stream *b)
{
    return a->quantity == b->quantity && a->flags == b->flags &&
           (stream_variable(a) || a->order == b->order);
}

/* "order 5 distance", "variable-order log-distance": a stream's slot. */
static const char *slot_name(const vdsh_stream *s, char *buf, size_t n)
{
    if (stream_variable(s))
        snprintf(buf, n, "variable-order %s", vdsh_quantity_name(s->quantity));
    else
        snprintf(buf, n, "order %u %s", s->order, vdsh_quantity_name(s->quantity));
    return buf;
}

/* "COEF order 5 distance": how messages name a stream. */
static void stream_label(const vdsh_stream *s, uint32_t i, char *buf,
                         size_t n)
{
    snprintf(buf, n, "COEF stream %u (order %s%u, %s)", i, stream_variable(s) ? "up to " : "",
             s->order, vdsh_quantity_name(s->quantity));
}

static int check_stream(const vdsh_stream *s, uint32_t i, why *w)
{
    char l[96];
    stream_label(s, i, l, sizeof l);
    if (s->order < 1 || s->order > VDSH_MAX_ORDER)
        return bad(w, "%s: order %u out of range 1..%d", l, s->order,
                   VDSH_MAX_ORDER);
    if (s->encoding > VDSH_ENCODING_LAST)
        return bad(w, "%s: encoding %u unknown (0 f32, 1 f16, 2 s8, 3 s8s6, 4 cpca)", l,
                   s->encoding);
    if (s->flags & ~VDSH_STREAM_VARIABLE)
        return bad(w, "%s: flags 0x%x: unknown bits (bit 0: variable order)", l, s->flags);
    /* Any method value is allowed: later bakers add methods, and the
     * coefficients still reconstruct `quantity` (VDSH.md, "Methods"). */
    if (s->quantity > VDSH_QUANTITY_LOG_DISTANCE)
        return bad(w, "%s: quantity %u unknown (0 distance, 1 distance2, "
                   "2 log-distance)", l, s->quantity);
    if (s->window > VDSH_WINDOW_LANCZOS)
        return bad(w, "%s: window %u unknown (0 none, 1 hann, 2 lanczos)", l,
                   s->window);
    if (!isfinite(s->window_param))
        return bad(w, "%s: window_param %g not finite", l,
                   (double)s->window_param);
    if (s->window == VDSH_WINDOW_NONE && s->window_param != 0.0f)
        return bad(w, "%s: window_param %g must be 0 without a window", l,
                   (double)s->window_param);
    if (s->window != VDSH_WINDOW_NONE && !(s->window_param > 0.0f))
        return bad(w, "%s: window_param %g must be > 0 with a window", l,
                   (double)s->window_param);
    if (!isfinite(s->method_param))
        return bad(w, "%s: method_param %g not finite", l,
                   (double)s->method_param);
    if (!isfinite(s->scale) || !(s->scale > 0.0f))
        return bad(w, "%s: scale %g must be finite and > 0", l,
                   (double)s->scale);
    if (vdsh_encoding_quantised(s->encoding) && s->scale != 1.0f)
        return bad(w, "%s: scale %g must be 1 for %s (its scale table scales)", l,
                   (double)s->scale, vdsh_encoding_name(s->encoding));
    if (s->encoding == VDSH_ENCODING_CPCA) {
        const vdsh_cpca *m = &s->cpca;
        if (s->scale != 1.0f)
            return bad(w, "%s: scale %g must be 1 for cpca", l, (double)s->scale);
        if (stream_variable(s))
            return bad(w, "%s: cpca streams cannot have variable order", l);
        if (m->clusters < 1 || m->clusters > VDSH_CPCA_MAX_CLUSTERS)
            return bad(w, "%s: cpca clusters %u out of range 1..%d", l, m->clusters,
                       VDSH_CPCA_MAX_CLUSTERS);
        if (m->basis < 1 || m->basis > s->order * s->order)
            return bad(w, "%s: cpca basis %u out of range 1..%u", l, m->basis,
                       s->order * s->order);
        if (m->bits < VDSH_CPCA_MIN_BITS || m->bits > VDSH_CPCA_MAX_BITS)
            return bad(w, "%s: cpca bits %u out of range %d..%d", l, m->bits,
                       VDSH_CPCA_MIN_BITS, VDSH_CPCA_MAX_BITS);
        if (m->record_words != vdsh_cpca_record_words(m->basis, m->bits))
            return bad(w, "%s: cpca record_words %u, %u weights of %u bits need %u", l,
                       m->record_words, m->basis, m->bits,
                       vdsh_cpca_record_words(m->basis, m->bits));
    }
    if (s->quantity == VDSH_QUANTITY_LOG_DISTANCE
            ? !(s->quantity_param > 0.0f) || !isfinite(s->quantity_param)
            : s->quantity_param != 0.0f)
        return bad(w, "%s: quantity_param %g must be %s", l, (double)s->quantity_param,
                   s->quantity == VDSH_QUANTITY_LOG_DISTANCE
                       ? "the log floor, finite and > 0" : "0 for this quantity");
    return 1;
}

/* A quantised record's stored values lie within +-levels, and s8s6's bits
 * that no coefficient uses (bits 30-31 of every word, the last word's
 * unused fields) are zero, so every file has one spelling. `rows` records
 * of nc coefficients at d, the first being vertex `first`. */
static int check_quant_data(const vdsh_stream *s, const char *l, const uint8_t *d, uint32_t nc,
                            size_t rows, size_t first, why *w)
{
    size_t bpv = vdsh_encoding_bytes(s->encoding, nc);
    uint32_t words = s->encoding == VDSH_ENCODING_S8S6 && nc > VDSH_S8S6_BYTES
                         ? (uint32_t)((bpv - VDSH_S8S6_BYTES) / 4)
                         : 0;
    for (size_t x = 0; x < rows; x++) {
        const uint8_t *p = d + x * bpv;
        for (uint32_t i = 0; i < nc; i++) {
            int levels = vdsh_quant_levels(s->encoding, i);
            int32_t q = quant_stored(s->encoding, p, i);
            if (q < -levels)
                return bad(w, "%s: vertex %zu coefficient %u is %d (%s stores %d..%d there)", l,
                           first + x, i, (int)q, vdsh_encoding_name(s->encoding), -levels,
                           levels);
        }
        for (uint32_t k = 0; k < words; k++) {
            uint32_t left = nc - VDSH_S8S6_BYTES - k * VDSH_S8S6_PER_WORD;
            uint32_t fields = left < VDSH_S8S6_PER_WORD ? left : VDSH_S8S6_PER_WORD;
            uint32_t used = (1u << (VDSH_S8S6_BITS * fields)) - 1u;
            if (get_u32(p + VDSH_S8S6_BYTES + 4 * k) & ~used)
                return bad(w, "%s: vertex %zu: unused bits of packed word %u not zero", l,
                           first + x, k);
        }
    }
    return 1;
}

/* A quantised stream's scales: finite and >= 0 (0: the index is 0 at
 * every vertex), and `levels` steps finite, so |coefficient| <= about its
 * scale, finite. */
static int check_scales(const vdsh_stream *s, const char *l, why *w)
{
    for (uint32_t k = 0; k < s->order * s->order; k++) {
        float sc = s->coef_scales[k];
        int levels = vdsh_quant_levels(s->encoding, k);
        if (!isfinite(sc) || !(sc >= 0.0f))
            return bad(w, "%s: scale of coefficient %zu is %g, not finite and >= 0", l,
                       (size_t)k, (double)sc);
        if (!isfinite((float)levels * vdsh_quant_step(sc, levels)))
            return bad(w, "%s: scale of coefficient %zu, %g: %d steps overflow a float", l,
                       (size_t)k, (double)sc, levels);
    }
    return 1;
}

/* `rows` records of nc coefficients at d, the first being vertex `first`:
 * stored values finite, and so must stored * scale be, which is what
 * vdsh_stream_decode() hands out (a huge scale could overflow it);
 * quantised ones within +-levels (-128, or -32 in 6 bits, would make the
 * range lopsided, and GL's normalisation rules disagree on -128). */
static int check_rows(const vdsh_stream *s, const char *l, const void *data, uint32_t nc,
                      size_t rows, size_t first, why *w)
{
    size_t n = rows * nc;
    float maxabs;
    if (vdsh_encoding_quantised(s->encoding))
        return check_quant_data(s, l, (const uint8_t *)data, nc, rows, first, w);
    if (s->encoding == VDSH_ENCODING_F16) {
        const uint16_t *d = (const uint16_t *)data;
        uint16_t m = 0;
        for (size_t k = 0; k < n; k++) {
            uint16_t a = (uint16_t)(d[k] & 0x7fffu);
            m = a > m ? a : m;
        }
        if (m >= 0x7c00u) {
            size_t k = 0;
            while ((d[k] & 0x7c00u) != 0x7c00u)
                k++;
            return bad(w, "%s: vertex %zu coefficient %zu is not finite "
                       "(f16 0x%04x)", l, first + k / nc, k % nc, d[k]);
        }
        maxabs = vdsh_f32_from_f16(m);
    } else {
        const float *d = (const float *)data;
        uint32_t m = max_abs_bits_f32(d, n);
        if (m >= 0x7f800000u) {
            size_t k = first_nonfinite_f32(d, n);
            return bad(w, "%s: vertex %zu coefficient %zu is not finite (%g)",
                       l, first + k / nc, k % nc, (double)d[k]);
        }
        maxabs = f32_from_bits(m);
    }
    if (!isfinite(maxabs * s->scale))
        return bad(w, "%s: a stored value of %g times scale %g overflows a "
                   "float", l, (double)maxabs, (double)s->scale);
    return 1;
}

/* A variable-order stream's orders (1..order) and records, each as a
 * fixed stream's one vertex, their padding zero. */
static int check_variable_rows(const vdsh_stream *s, const char *l, uint32_t v, why *w)
{
    const uint32_t *words = (const uint32_t *)s->data;
    size_t at = 0;
    for (uint32_t x = 0; x < v; x++) {
        uint32_t k = s->orders[x];
        if (k < 1 || k > s->order)
            return bad(w, "%s: vertex %u has order %u (1..%u)", l, x, k, s->order);
        uint32_t nc = k * k;
        if (!check_rows(s, l, words + at, nc, 1, x, w))
            return 0;
        size_t used = vdsh_encoding_bytes(s->encoding, nc);
        uint32_t rec = vdsh_record_words(s->encoding, k);
        if (!all_zero((const uint8_t *)(words + at) + used, 4 * (size_t)rec - used))
            return bad(w, "%s: vertex %u: padding after its record not zero", l, x);
        at += rec;
    }
    return 1;
}

/* A cpca stream's model (finite scales, means and bases, decoded values
 * bounded) and records (index < K, levels within +-L, unused bits 0). */
static int check_cpca_data(const vdsh_stream *s, const char *l, uint32_t v, why *w)
{
    const vdsh_cpca *m = &s->cpca;
    uint32_t n = s->order * s->order, b = m->basis, bits = m->bits;
    int L = vdsh_cpca_levels(bits);
    for (size_t k = 0; k < (size_t)m->clusters * b; k++) {
        float sc = m->scales[k];
        if (!isfinite(sc) || !(sc >= 0.0f))
            return bad(w, "%s: cpca scale %zu (cluster %zu vector %zu) is %g, not finite and "
                       ">= 0", l, k, k / b, k % b, (double)sc);
    }
    for (size_t k = 0; k < (size_t)m->clusters * n; k++)
        if ((m->means[k] & 0x7c00u) == 0x7c00u)
            return bad(w, "%s: cpca mean of cluster %zu coefficient %zu is not finite", l,
                       k / n, k % n);
    for (size_t k = 0; k < (size_t)m->clusters * b * n; k++)
        if ((m->bases[k] & 0x7c00u) == 0x7c00u)
            return bad(w, "%s: cpca basis vector %zu of cluster %zu, coefficient %zu, is "
                       "not finite", l, (k / n) % b, k / n / b, k % n);
    for (uint32_t c = 0; c < m->clusters; c++)
        for (uint32_t i = 0; i < n; i++) {
            double bound = fabs((double)vdsh_f32_from_f16(m->means[(size_t)c * n + i]));
            for (uint32_t j = 0; j < b; j++)
                bound += (double)L * (double)vdsh_cpca_step(m->scales[(size_t)c * b + j], bits) *
                         fabs((double)vdsh_f32_from_f16(m->bases[((size_t)c * b + j) * n + i]));
            if (!(bound <= 1e38))
                return bad(w, "%s: cpca cluster %u coefficient %u can reach %g, beyond 1e38", l,
                           c, i, bound);
        }
    /* the bits the fields use, per word */
    uint32_t used[VDSH_MAX_COEFFS + 1];
    for (uint32_t k = 0; k < m->record_words; k++)
        used[k] = 0;
    used[0] = (1u << VDSH_CPCA_INDEX_BITS) - 1u;
    for (uint32_t j = 0; j < b; j++) {
        uint32_t word, shift;
        vdsh_cpca_field(bits, j, &word, &shift);
        used[word] |= (uint32_t)(((1ull << bits) - 1u) << shift);
    }
    for (uint32_t x = 0; x < v; x++) {
        const uint32_t *r = (const uint32_t *)s->data + (size_t)x * m->record_words;
        if ((r[0] & 0xffu) >= m->clusters)
            return bad(w, "%s: vertex %u has cluster %u (0..%u)", l, x, r[0] & 0xffu,
                       m->clusters - 1);
        for (uint32_t k = 0; k < m->record_words; k++)
            if (r[k] & ~used[k])
                return bad(w, "%s: vertex %u: unused bits of record word %u not zero", l, x, k);
        for (uint32_t j = 0; j < b; j++)
            if (cpca_level(r, bits, j) < -L)
                return bad(w, "%s: vertex %u weight %u is %d (%u bits store %d..%d)", l, x, j,
                           (int)cpca_level(r, bits, j), bits, -L, L);
    }
    return 1;
}

static int check_stream_data(const vdsh_stream *s, uint32_t i, uint32_t v,
                             why *w)
{
    char l[96];
    stream_label(s, i, l, sizeof l);
    if (s->encoding == VDSH_ENCODING_CPCA)
        return check_cpca_data(s, l, v, w);
    if (vdsh_encoding_quantised(s->encoding) && !check_scales(s, l, w))
        return 0;
    if (stream_variable(s))
        return check_variable_rows(s, l, v, w);
    return check_rows(s, l, s->data, s->order * s->order, v, 0, w);
}

/* The statistics must describe a bake of vertex_count receivers. */
static int check_stats(const vdsh_stats *t, uint32_t vertex_count, why *w)
{
    if (t->rays_missed > t->rays_traced)
        return bad(w, "stat: %llu rays missed of %llu traced",
                   (unsigned long long)t->rays_missed, (unsigned long long)t->rays_traced);
    const uint32_t v[4] = {t->degenerate_receivers, t->undefined_normals, t->moved_origins,
                           t->flipped_normals};
    static const char *const n[4] = {"degenerate_receivers", "undefined_normals",
                                     "moved_origins", "flipped_normals"};
    for (int k = 0; k < 4; k++)
        if (v[k] > vertex_count)
            return bad(w, "stat: %s %u exceeds the %u receivers", n[k], v[k], vertex_count);
    return 1;
}

static int check_part(const vdsh_part *t, uint32_t vertex_count, why *w)
{
    if (t->count < 1 || t->index >= t->count)
        return bad(w, "part: shard %u of %u", t->index, t->count);
    if (t->range_begin >= t->range_end || t->range_end > vertex_count)
        return bad(w, "part: receivers %u..%u not within 0..%u", t->range_begin,
                   t->range_end, vertex_count);
    if (t->encoding > VDSH_ENCODING_LAST)
        return bad(w, "part: unknown encoding %u", t->encoding);
    if (t->encoding != VDSH_ENCODING_CPCA) {
        if (t->cpca_clusters || t->cpca_basis || t->cpca_bits)
            return bad(w, "part: cpca settings %u,%u,%u with encoding %s (must be 0)",
                       t->cpca_clusters, t->cpca_basis, t->cpca_bits,
                       vdsh_encoding_name(t->encoding));
    } else if (t->cpca_clusters < 1 || t->cpca_clusters > VDSH_CPCA_MAX_CLUSTERS ||
               t->cpca_basis < 1 || t->cpca_basis > VDSH_MAX_COEFFS ||
               t->cpca_bits < VDSH_CPCA_MIN_BITS || t->cpca_bits > VDSH_CPCA_MAX_BITS) {
        return bad(w, "part: cpca settings %u,%u,%u out of range (1..%d, 1..%d, %d..%d)",
                   t->cpca_clusters, t->cpca_basis, t->cpca_bits, VDSH_CPCA_MAX_CLUSTERS,
                   VDSH_MAX_COEFFS, VDSH_CPCA_MIN_BITS, VDSH_CPCA_MAX_BITS);
    }
    return 1;
}

static int check_adaptive(const vdsh_adaptive *a, uint32_t vertex_count, why *w)
{
    if (!(a->tolerance >= 0.0f))
        return bad(w, "adpt: tolerance %g is not a number >= 0", (double)a->tolerance);
    if (!(a->min_edge > 0.0f) || !isfinite(a->min_edge))
        return bad(w, "adpt: min_edge %g is not a finite number > 0", (double)a->min_edge);
    if (a->lights < 1 || a->max_rounds < 1 || a->rounds > a->max_rounds)
        return bad(w, "adpt: %u lights, %u of at most %u rounds", a->lights, a->rounds,
                   a->max_rounds);
    if (a->start_receivers > vertex_count || a->start_receivers < 1)
        return bad(w, "adpt: started from %u receivers of %u", a->start_receivers,
                   vertex_count);
    if (a->max_receivers && vertex_count > a->max_receivers)
        return bad(w, "adpt: %u receivers over the budget of %u", vertex_count,
                   a->max_receivers);
    if ((uint64_t)a->start_receivers + a->candidates < vertex_count)
        return bad(w, "adpt: %u receivers from %u and %u midpoints", vertex_count,
                   a->start_receivers, a->candidates);
    return 1;
}

static int check_timings(const vdsh_timings *t, why *w)
{
    const double v[5] = {t->load, t->refine, t->build, t->trace, t->total};
    static const char *const n[5] = {"load", "refine", "build", "trace",
                                     "total"};
    for (int k = 0; k < 5; k++)
        if (!isfinite(v[k]) || !(v[k] >= 0.0))
            return bad(w, "time: %s %g must be finite and >= 0", n[k], v[k]);
    return 1;
}

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
static int walk_chunk(const uint8_t *d, size_t size, uint64_t off,
                      chunk_ref *c, uint32_t *crc_stored,
                      uint32_t *crc_computed)
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
    crc = vdsh_crc32(crc, h + CHUNK_HEADER_SIZE,
                     (size_t)(c->size + pad16(c->size)));
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
    uint64_t stream_table[VDSH_MAX_STREAMS]; /* s8: offset of the scales; else 0 */
    uint64_t stream_bytes[VDSH_MAX_STREAMS]; /* COEF payload after the stream header */
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

/* Pass 1: file header, chunk walk, every CRC and padding. */
static vdsh_result read_structure(const reader *r, chunk_ref *chunks,
                                  uint32_t *count)
{
    const uint8_t *d = r->d;
    size_t size = r->size;

    if (size < sizeof vdsh_magic) {
        if (memcmp(d, vdsh_magic, size) != 0)
            return vdsh_failf_at(r->err, VDSH_ERR_NOT_VDSH, r->name,
                        "not a .vdsh file (wrong magic)");
        return vdsh_failf_at(r->err, VDSH_ERR_TRUNCATED, r->name,
                    "truncated: %zu bytes, shorter than the %d-byte header",
                    size, FILE_HEADER_SIZE);
    }
    if (memcmp(d, vdsh_magic, sizeof vdsh_magic) != 0) {
        if (memcmp(d, vdsh_magic, 4) == 0)
            return vdsh_failf_at(r->err, VDSH_ERR_NOT_VDSH, r->name,
                        "not a .vdsh file: magic bytes 4..7 damaged (a "
                        "text-mode transfer changes CR, LF and ^Z)");
        return vdsh_failf_at(r->err, VDSH_ERR_NOT_VDSH, r->name,
                    "not a .vdsh file (wrong magic)");
    }
    if (size < FILE_HEADER_SIZE)
        return vdsh_failf_at(r->err, VDSH_ERR_TRUNCATED, r->name,
                    "truncated: %zu bytes, shorter than the %d-byte header",
                    size, FILE_HEADER_SIZE);

    /* The version comes before the header CRC: a later version may lay its
     * header out differently, and "unsupported version" is then the useful
     * message. */
    uint32_t version = get_u32(d + 8);
    uint32_t crc_stored = get_u32(d + 28);
    uint32_t crc_computed = vdsh_crc32(0, d, 28);
    if (version != VDSH_FORMAT_VERSION)
        return vdsh_failf_at(r->err, VDSH_ERR_VERSION, r->name,
                    "format version %u, this reader reads version %u%s",
                    version, VDSH_FORMAT_VERSION,
                    crc_stored == crc_computed
                        ? ""
                        : " (and the header CRC fails: the file may be "
                          "damaged)");
    if (crc_stored != crc_computed)
        return vdsh_failf_at(r->err, VDSH_ERR_CRC, r->name,
                    "header CRC mismatch (stored 0x%08x, computed 0x%08x)",
                    crc_stored, crc_computed);

    uint32_t chunk_count = get_u32(d + 12);
    uint64_t file_size = get_u64(d + 16);
    uint32_t flags = get_u32(d + 24);
    if ((uint64_t)size < file_size)
        return vdsh_failf_at(r->err, VDSH_ERR_TRUNCATED, r->name,
                    "truncated: %zu bytes, the header says %llu", size,
                    (unsigned long long)file_size);
    if ((uint64_t)size > file_size)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                    "%zu bytes, but the header says %llu (data after the "
                    "end)", size, (unsigned long long)file_size);
    if (flags != 0)
        return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name,
                    "header flags 0x%x, must be 0", flags);
    if (chunk_count < 1 || chunk_count > MAX_CHUNKS)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                    "chunk_count %u out of range 1..%d", chunk_count,
                    MAX_CHUNKS);

    uint64_t off = FILE_HEADER_SIZE;
    for (uint32_t i = 0; i < chunk_count; i++) {
        chunk_ref *c = &chunks[i];
        uint32_t cs, cc;
        char pid[5];
        int w = walk_chunk(d, size, off, c, &cs, &cc);
        if (w == WALK_NO_HEADER)
            return vdsh_failf_at(r->err, VDSH_ERR_TRUNCATED, r->name,
                        "chunk %u at offset %llu: header runs past the end "
                        "of the file (%u chunks announced)", i,
                        (unsigned long long)off, chunk_count);
        printable_id(d + off, pid);
        if (w == WALK_PAST_END)
            return vdsh_failf_at(r->err, VDSH_ERR_TRUNCATED, r->name,
                        "chunk %u '%s' at offset %llu: payload of %llu bytes "
                        "runs past the end of the file", i, pid,
                        (unsigned long long)off,
                        (unsigned long long)c->size);
        if (cs != cc)
            return vdsh_failf_at(r->err, VDSH_ERR_CRC, r->name,
                        "chunk %u '%s' at offset %llu: CRC mismatch (stored "
                        "0x%08x, computed 0x%08x)", i, pid,
                        (unsigned long long)off, cs, cc);
        for (int k = 0; k < 4; k++)
            if (!is_letter(d[off + k]))
                return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                            "chunk %u at offset %llu: id %02x %02x %02x %02x "
                            "is not four ASCII letters", i,
                            (unsigned long long)off, d[off], d[off + 1],
                            d[off + 2], d[off + 3]);
        uint64_t payload = off + CHUNK_HEADER_SIZE;
        if (!all_zero(d + payload + c->size, (size_t)pad16(c->size)))
            return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                        "chunk %u '%s' at offset %llu: padding byte not "
                        "zero", i, pid, (unsigned long long)off);
        off = payload + c->size + pad16(c->size);
    }
    if (off != size)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                    "%llu bytes after the last of %u chunks",
                    (unsigned long long)(size - off), chunk_count);
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
                    "HEAD: payload is %llu bytes, must be %d",
                    (unsigned long long)c->size, HEAD_SIZE);
    h->vertex_count = get_u32(p + 0);
    h->triangle_count = get_u32(p + 4);
    h->rays = get_u32(p + 8);
    h->sampling = get_u32(p + 12);
    h->seed = get_u64(p + 16);
    h->max_distance = get_f32(p + 24);
    h->max_edge = get_f32(p + 28);
    h->offset_rule = get_u32(p + 32);
    h->load_flags = get_u32(p + 36);
    h->cube_size = get_u32(p + 40);
    h->occluder_vertex_count = get_u32(p + 44);
    h->occluder_triangle_count = get_u32(p + 48);
    h->trace_flags = get_u32(p + 52);
    for (int k = 0; k < 3; k++) {
        h->bounds_min[k] = get_f32(p + 56 + 4 * k);
        h->bounds_max[k] = get_f32(p + 68 + 4 * k);
    }
    if (!all_zero(p + 80, 48))
        return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name,
                    "HEAD: reserved bytes 80..127 not zero");
    if (!check_header(h, &w))
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
                    "SRCS: payload of %llu bytes has no count",
                    (unsigned long long)n);
    uint32_t count = get_u32(p);
    if (count > VDSH_MAX_SOURCES)
        return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name,
                    "SRCS: count %u out of range 0..%d", count,
                    VDSH_MAX_SOURCES);
    L->names_bytes = 0;
    for (uint32_t i = 0; i < count; i++) {
        if (SOURCE_FIXED_SIZE > n - off)
            return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                        "SRCS: source %u runs past the end of the payload",
                        i);
        uint32_t len = get_u32(p + off + 40);
        L->source_sha[i] = c->offset + CHUNK_HEADER_SIZE + off;
        L->source_size[i] = get_u64(p + off + 32);
        off += SOURCE_FIXED_SIZE;
        if (len < 1 || len > VDSH_MAX_NAME)
            return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name,
                        "SRCS: source %u: name_length %u out of range 1..%d",
                        i, len, VDSH_MAX_NAME);
        uint64_t padded = ((uint64_t)len + 3) & ~(uint64_t)3;
        if (padded > n - off)
            return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                        "SRCS: source %u: name runs past the end of the "
                        "payload", i);
        if (!check_name(p + off, len, i, &w))
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
                    "SRCS: %llu bytes after the last source",
                    (unsigned long long)(n - off));
    L->source_count = count;
    return VDSH_OK;
}

/* POSN, NORM and TRIS: 12 bytes per vertex or triangle. */
static vdsh_result read_array(const reader *r, const chunk_ref *c,
                              uint32_t count, const char *what)
{
    if (c->size != (uint64_t)count * 12)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                    "%s: payload is %llu bytes, %u %s need %llu", c->id,
                    (unsigned long long)c->size, count, what,
                    (unsigned long long)count * 12);
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
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                    "more than %d COEF chunks", VDSH_MAX_STREAMS);
    if (c->size < STREAM_HEADER_SIZE)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                    "COEF stream %u: payload of %llu bytes is shorter than "
                    "the %d-byte stream header", i,
                    (unsigned long long)c->size, STREAM_HEADER_SIZE);
    s->order = get_u32(p + 0);
    s->encoding = get_u32(p + 4);
    s->method = get_u32(p + 8);
    s->quantity = get_u32(p + 12);
    s->window = get_u32(p + 16);
    s->window_param = get_f32(p + 20);
    s->method_param = get_f32(p + 24);
    s->scale = get_f32(p + 28);
    s->quantity_param = get_f32(p + 32);
    s->flags = get_u32(p + 36);
    s->data = NULL;
    s->orders = NULL;
    s->offsets = NULL;
    memset(&s->cpca, 0, sizeof s->cpca);
    stream_label(s, i, l, sizeof l);
    if (!all_zero(p + 40, 8))
        return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name,
                    "%s: reserved bytes 40..47 not zero", l);
    if (s->encoding == VDSH_ENCODING_CPCA) {
        if (c->size - STREAM_HEADER_SIZE < CPCA_HEADER_SIZE)
            return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                        "%s: %llu bytes of data, shorter than the %d-byte cpca header", l,
                        (unsigned long long)(c->size - STREAM_HEADER_SIZE), CPCA_HEADER_SIZE);
        s->cpca.clusters = get_u32(p + STREAM_HEADER_SIZE);
        s->cpca.basis = get_u32(p + STREAM_HEADER_SIZE + 4);
        s->cpca.bits = get_u32(p + STREAM_HEADER_SIZE + 8);
        s->cpca.record_words = get_u32(p + STREAM_HEADER_SIZE + 12);
    }
    if (!check_stream(s, i, &w))
        return invalid(r, &w);
    uint64_t table = s->encoding == VDSH_ENCODING_CPCA
                         ? vdsh_cpca_model_bytes(s->order, s->cpca.clusters, s->cpca.basis)
                         : stream_table_bytes(s->encoding, s->order);
    if (c->size - STREAM_HEADER_SIZE < table)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                    "%s: %llu bytes of data, shorter than its %llu-byte scale table", l,
                    (unsigned long long)(c->size - STREAM_HEADER_SIZE),
                    (unsigned long long)table);
    if (table && s->encoding == VDSH_ENCODING_CPCA) {
        uint64_t n = (uint64_t)s->order * s->order, k = s->cpca.clusters, b = s->cpca.basis;
        uint64_t sizes[3] = {4 * k * b, 2 * k * n, 2 * k * b * n};
        static const char *const what[3] = {"scales", "means", "bases"};
        const uint8_t *q = p + STREAM_HEADER_SIZE + CPCA_HEADER_SIZE;
        for (int a = 0; a < 3; a++) {
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
        if (same_slot(&L->streams[k], s))
            return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name,
                        "%s: a second stream for %s (stream %u is "
                        "the first)", l, slot_name(s, slot, sizeof slot), k);
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
    uint32_t rows = L->has_part ? L->part.range_end - L->part.range_begin
                                : L->header.vertex_count;
    why w;
    for (uint32_t i = 0; i < L->stream_count; i++) {
        vdsh_stream *s = &L->streams[i];
        char l[96];
        stream_label(s, i, l, sizeof l);
        int cpca = s->encoding == VDSH_ENCODING_CPCA;
        uint64_t table = cpca ? vdsh_cpca_model_bytes(s->order, s->cpca.clusters, s->cpca.basis)
                              : stream_table_bytes(s->encoding, s->order);
        uint64_t orders = 0; /* a variable-order stream's order table */
        if (stream_variable(s)) {
            orders = round16(rows);
            if (L->stream_bytes[i] < table + orders)
                return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                            "%s: %llu bytes of data, shorter than its scale and order "
                            "tables (%llu bytes)", l, (unsigned long long)L->stream_bytes[i],
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
                        "%s: %llu bytes of data, %u vertices of %s need %llu%s", l,
                        (unsigned long long)L->stream_bytes[i], rows,
                        vdsh_encoding_name(s->encoding), (unsigned long long)need,
                        L->has_part ? " (a part: its range's receivers)" : "");
        s->coef_scales = table && !cpca ? (const float *)(r->d + L->stream_table[i]) : NULL;
        if (cpca)
            cpca_bind(s, r->d + L->stream_table[i]);
        s->data = r->d + L->stream_data[i] + orders;
        int ok = check_stream_data(s, i, rows, &w);
        s->data = NULL;
        s->orders = NULL;
        s->coef_scales = NULL;
        s->cpca.scales = NULL;
        s->cpca.means = s->cpca.bases = NULL;
        L->stream_orders[i] = orders;
        if (orders)
            L->offset_words += (uint64_t)rows + 1;
        if (!ok)
            return invalid(r, &w);
    }
    return VDSH_OK;
}

static vdsh_result read_stat(const reader *r, const chunk_ref *c, layout *L)
{
    const uint8_t *p = r->d + c->offset + CHUNK_HEADER_SIZE;
    why w;
    if (c->size != STAT_SIZE)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                    "stat: payload is %llu bytes, must be %d",
                    (unsigned long long)c->size, STAT_SIZE);
    L->stats.rays_traced = get_u64(p + 0);
    L->stats.rays_missed = get_u64(p + 8);
    L->stats.degenerate_receivers = get_u32(p + 16);
    L->stats.undefined_normals = get_u32(p + 20);
    L->stats.moved_origins = get_u32(p + 24);
    L->stats.flipped_normals = get_u32(p + 28);
    if (!check_stats(&L->stats, L->header.vertex_count, &w))
        return invalid(r, &w);
    L->has_stats = 1;
    return VDSH_OK;
}

static vdsh_result read_time(const reader *r, const chunk_ref *c, layout *L)
{
    const uint8_t *p = r->d + c->offset + CHUNK_HEADER_SIZE;
    why w;
    if (c->size != TIME_SIZE)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                    "time: payload is %llu bytes, must be %d",
                    (unsigned long long)c->size, TIME_SIZE);
    if (!all_zero(p + 44, 20))
        return vdsh_failf_at(r->err, VDSH_ERR_INVALID, r->name,
                    "time: reserved bytes 44..63 not zero");
    L->timings.load = get_f64(p + 0);
    L->timings.refine = get_f64(p + 8);
    L->timings.build = get_f64(p + 16);
    L->timings.trace = get_f64(p + 24);
    L->timings.total = get_f64(p + 32);
    L->timings.threads = get_u32(p + 40);
    if (!check_timings(&L->timings, &w))
        return invalid(r, &w);
    L->has_timings = 1;
    return VDSH_OK;
}

static vdsh_result read_adpt(const reader *r, const chunk_ref *c, layout *L)
{
    const uint8_t *p = r->d + c->offset + CHUNK_HEADER_SIZE;
    why w;
    if (c->size != ADPT_SIZE)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name, "adpt: payload is %llu bytes, must be %d",
                    (unsigned long long)c->size, ADPT_SIZE);
    L->adaptive.tolerance = get_f32(p + 0);
    L->adaptive.min_edge = get_f32(p + 4);
    L->adaptive.max_receivers = get_u32(p + 8);
    L->adaptive.lights = get_u32(p + 12);
    L->adaptive.max_rounds = get_u32(p + 16);
    L->adaptive.start_receivers = get_u32(p + 20);
    L->adaptive.rounds = get_u32(p + 24);
    L->adaptive.candidates = get_u32(p + 28);
    if (!check_adaptive(&L->adaptive, L->header.vertex_count, &w))
        return invalid(r, &w);
    L->has_adaptive = 1;
    return VDSH_OK;
}

static vdsh_result read_part(const reader *r, const chunk_ref *c, layout *L)
{
    const uint8_t *p = r->d + c->offset + CHUNK_HEADER_SIZE;
    why w;
    if (c->size != PART_SIZE)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name, "part: payload is %llu bytes, must be %d",
                    (unsigned long long)c->size, PART_SIZE);
    L->part.cpca_clusters = get_u32(p + 20);
    L->part.cpca_basis = get_u32(p + 24);
    L->part.cpca_bits = get_u32(p + 28);
    L->part.index = get_u32(p + 0);
    L->part.count = get_u32(p + 4);
    L->part.range_begin = get_u32(p + 8);
    L->part.range_end = get_u32(p + 12);
    L->part.encoding = get_u32(p + 16);
    if (!check_part(&L->part, L->header.vertex_count, &w))
        return invalid(r, &w);
    L->has_part = 1;
    return VDSH_OK;
}

/* Pass 2: which chunks, in which numbers, with which contents. */
static vdsh_result read_contents(const reader *r, const chunk_ref *chunks,
                                 uint32_t count, layout *L)
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
        int req = -1;
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
        } else if (req == 1) {
            if ((res = read_array(r, c, h->vertex_count, "vertices")) ==
                    VDSH_OK &&
                !check_positions((const float *)p, h->vertex_count, &w))
                res = invalid(r, &w);
            L->posn = c->offset + CHUNK_HEADER_SIZE;
        } else if (req == 2) {
            if ((res = read_array(r, c, h->vertex_count, "vertices")) ==
                    VDSH_OK &&
                !check_normals((const float *)p, h->vertex_count, &w))
                res = invalid(r, &w);
            L->norm = c->offset + CHUNK_HEADER_SIZE;
        } else if (req == 3) {
            if ((res = read_array(r, c, h->triangle_count, "triangles")) ==
                    VDSH_OK &&
                !check_indices((const uint32_t *)p, h->triangle_count,
                               h->vertex_count, &w))
                res = invalid(r, &w);
            L->tris = c->offset + CHUNK_HEADER_SIZE;
        } else if (memcmp(c->id, "COEF", 4) == 0) {
            res = read_coef(r, c, L);
        } else if (memcmp(c->id, "stat", 4) == 0) {
            res = L->has_stats
                      ? vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                             "chunk %u at offset %llu: a second stat chunk",
                             i, (unsigned long long)c->offset)
                      : read_stat(r, c, L);
        } else if (memcmp(c->id, "time", 4) == 0) {
            res = L->has_timings
                      ? vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                             "chunk %u at offset %llu: a second time chunk",
                             i, (unsigned long long)c->offset)
                      : read_time(r, c, L);
        } else if (memcmp(c->id, "adpt", 4) == 0) {
            res = L->has_adaptive
                      ? vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                             "chunk %u at offset %llu: a second adpt chunk",
                             i, (unsigned long long)c->offset)
                      : read_adpt(r, c, L);
        } else if (memcmp(c->id, "part", 4) == 0) {
            res = L->has_part
                      ? vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                             "chunk %u at offset %llu: a second part chunk",
                             i, (unsigned long long)c->offset)
                      : read_part(r, c, L);
        } else if (c->id[0] >= 'A' && c->id[0] <= 'Z') {
            res = vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name,
                       "chunk %u '%s' at offset %llu: unknown critical chunk "
                       "(a newer writer?)", i, c->id,
                       (unsigned long long)c->offset);
        } else {
            res = VDSH_OK; /* unknown ancillary: its CRC was checked; skip */
        }
        if (res != VDSH_OK)
            return res;
    }
    for (int k = 0; k < 4; k++)
        if (!seen[k])
            return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name, "no %s chunk",
                        required[k]);
    if (L->stream_count == 0)
        return vdsh_failf_at(r->err, VDSH_ERR_CHUNK, r->name, "no COEF chunk");
    return check_coef_sizes(r, L);
}

/*
 * Validate `buf` (which the caller allocated with alloc_file_buffer and
 * hands over: it is owned by the result, or freed on failure) and build
 * the vdsh_file around it.
 */
static vdsh_result load_owned(uint8_t *buf, size_t size, const char *name,
                              vdsh_file **out, vdsh_error *err)
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
    size_t off_sources =
        off_streams + round16(L.stream_count * sizeof(vdsh_stream));
    size_t off_names =
        off_sources + round16(L.source_count * sizeof(vdsh_source));
    size_t off_offsets = off_names + round16(L.names_bytes);
    if (L.offset_words > (SIZE_MAX - off_offsets) / 4) {
        free(buf);
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, r.name, "out of memory (offsets)");
    }
    size_t block_size = off_offsets + (size_t)L.offset_words * 4;
    uint8_t *block = (uint8_t *)calloc(1, block_size);
    if (!block) {
        free(buf);
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, r.name,
                    "out of memory (%zu bytes)", block_size);
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
                              ? (const float *)(buf + L.stream_table[i]) : NULL;
        if (st->encoding == VDSH_ENCODING_CPCA)
            cpca_bind(st, buf + L.stream_table[i]);
        if (stream_variable(st)) {
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

vdsh_result vdsh_read_memory(const void *data, size_t size, const char *name,
                             vdsh_file **out, vdsh_error *err)
{
    const char *nm = name ? name : "memory";
    if (!out || (!data && size))
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, nm, "vdsh_read_memory: NULL %s",
                    out ? "data" : "out");
    uint8_t *buf = alloc_file_buffer(size);
    if (!buf)
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, nm,
                    "out of memory (%zu bytes)", size);
    if (size)
        memcpy(buf, data, size);
    return load_owned(buf, size, nm, out, err);
}

vdsh_result vdsh_read(const char *path, vdsh_file **out, vdsh_error *err)
{
    if (!path || !out)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, path ? path : "(null)",
                    "vdsh_read: NULL %s", path ? "out" : "path");
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
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, path,
                    "%jd bytes do not fit in memory", (intmax_t)st.st_size);
    }
    size_t size = (size_t)st.st_size;
    uint8_t *buf = alloc_file_buffer(size);
    if (!buf) {
        fclose(fp);
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, path,
                    "out of memory (%zu bytes)", size);
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
            return vdsh_failf_at(err, VDSH_ERR_IO, path, "read error: %s",
                        strerror(e));
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

vdsh_result vdsh_scan_chunks(const void *data, size_t size, const char *name,
                             vdsh_chunk_info *out, uint32_t max,
                             uint32_t *count, vdsh_error *err)
{
    const uint8_t *d = (const uint8_t *)data;
    const char *nm = name ? name : "memory";
    if (!count || (!data && size) || (!out && max))
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, nm, "vdsh_scan_chunks: NULL "
                    "argument");
    if (size && memcmp(d, vdsh_magic,
                       size < sizeof vdsh_magic ? size : sizeof vdsh_magic))
        return vdsh_failf_at(err, VDSH_ERR_NOT_VDSH, nm,
                    "not a .vdsh file (wrong magic)");
    if (size < FILE_HEADER_SIZE)
        return vdsh_failf_at(err, VDSH_ERR_TRUNCATED, nm,
                    "truncated: %zu bytes, shorter than the %d-byte header",
                    size, FILE_HEADER_SIZE);
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
    uint8_t stat[STAT_SIZE];
    uint8_t time[TIME_SIZE];
    uint8_t part[PART_SIZE];
    uint8_t adpt[ADPT_SIZE];
    uint8_t *srcs; /* malloc'd SRCS payload */
    uint8_t *model[VDSH_MAX_STREAMS]; /* malloc'd cpca models, padded */
    out_chunk chunks[MAX_CHUNKS];
    uint32_t count;
    uint64_t file_size;
} plan;

static vdsh_result argument(vdsh_error *err, const char *name, const why *w)
{
    return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name, "not written: %s", w->msg);
}

/* The reader's rules, applied to the caller's struct. */
static vdsh_result check_file(const vdsh_file *f, const char *name,
                              vdsh_error *err)
{
    why w;
    if (!f)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name, "not written: no file");
    const vdsh_header *h = &f->header;
    if (!check_header(h, &w))
        return argument(err, name, &w);
    if (!f->positions || !f->normals || (!f->indices && h->triangle_count))
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                    "not written: %s is NULL",
                    !f->positions ? "positions"
                    : !f->normals ? "normals"
                                  : "indices");
    if (!check_positions(f->positions, h->vertex_count, &w) ||
        !check_normals(f->normals, h->vertex_count, &w) ||
        !check_indices(f->indices, h->triangle_count, h->vertex_count, &w))
        return argument(err, name, &w);

    if (f->source_count > VDSH_MAX_SOURCES)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                    "not written: source_count %u out of range 0..%d",
                    f->source_count, VDSH_MAX_SOURCES);
    if (f->source_count && !f->sources)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                    "not written: sources is NULL");
    for (uint32_t i = 0; i < f->source_count; i++) {
        const char *s = f->sources[i].name;
        if (!s)
            return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                        "not written: SRCS: source %u: name is NULL", i);
        if (!check_name((const uint8_t *)s, strnlen(s, VDSH_MAX_NAME + 1), i,
                        &w))
            return argument(err, name, &w);
    }

    /* Before the streams: a part's are its range's rows. */
    if (f->has_part && !check_part(&f->part, h->vertex_count, &w))
        return argument(err, name, &w);
    if (f->stream_count < 1 || f->stream_count > VDSH_MAX_STREAMS)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                    "not written: stream_count %u out of range 1..%d",
                    f->stream_count, VDSH_MAX_STREAMS);
    if (!f->streams)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                    "not written: streams is NULL");
    for (uint32_t i = 0; i < f->stream_count; i++) {
        const vdsh_stream *s = &f->streams[i];
        if (!check_stream(s, i, &w))
            return argument(err, name, &w);
        if (!s->data)
            return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                        "not written: COEF stream %u: data is NULL", i);
        if (vdsh_encoding_quantised(s->encoding) && !s->coef_scales)
            return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                        "not written: COEF stream %u: %s without coef_scales", i,
                        vdsh_encoding_name(s->encoding));
        if (stream_variable(s) && !s->orders)
            return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                        "not written: COEF stream %u: variable order without orders", i);
        if (s->encoding == VDSH_ENCODING_CPCA &&
            (!s->cpca.scales || !s->cpca.means || !s->cpca.bases))
            return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                        "not written: COEF stream %u: cpca without scales, means or bases", i);
        for (uint32_t k = 0; k < i; k++)
            if (same_slot(&f->streams[k], s)) {
                char slot[64];
                return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, name,
                            "not written: streams %u and %u are both %s", k, i,
                            slot_name(s, slot, sizeof slot));
            }
        if (!check_stream_data(s, i, vdsh_file_stream_vertices(f), &w))
            return argument(err, name, &w);
    }
    if (f->has_stats && !check_stats(&f->stats, h->vertex_count, &w))
        return argument(err, name, &w);
    if (f->has_timings && !check_timings(&f->timings, &w))
        return argument(err, name, &w);
    if (f->has_adaptive && !check_adaptive(&f->adaptive, h->vertex_count, &w))
        return argument(err, name, &w);
    return VDSH_OK;
}

static void add_chunk(plan *P, const char *id, const void *pre,
                      size_t pre_size, const void *data, uint64_t data_size)
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
static vdsh_result plan_build(plan *P, const vdsh_file *f, const char *name,
                              vdsh_error *err)
{
    memset(P, 0, sizeof *P);
    vdsh_result res = check_file(f, name, err);
    if (res != VDSH_OK)
        return res;
    const vdsh_header *h = &f->header;

    uint8_t *p = P->head;
    put_u32(p + 0, h->vertex_count);
    put_u32(p + 4, h->triangle_count);
    put_u32(p + 8, h->rays);
    put_u32(p + 12, h->sampling);
    put_u64(p + 16, h->seed);
    put_f32(p + 24, h->max_distance);
    put_f32(p + 28, h->max_edge);
    put_u32(p + 32, h->offset_rule);
    put_u32(p + 36, h->load_flags);
    put_u32(p + 40, h->cube_size);
    put_u32(p + 44, h->occluder_vertex_count);
    put_u32(p + 48, h->occluder_triangle_count);
    put_u32(p + 52, h->trace_flags);
    for (int k = 0; k < 3; k++) {
        put_f32(p + 56 + 4 * k, h->bounds_min[k]);
        put_f32(p + 68 + 4 * k, h->bounds_max[k]);
    }
    add_chunk(P, "HEAD", P->head, HEAD_SIZE, NULL, 0);

    /* SRCS is small (at most 64 names of 4096 bytes): encode it whole. */
    size_t srcs_size = 4;
    for (uint32_t i = 0; i < f->source_count; i++)
        srcs_size += SOURCE_FIXED_SIZE +
                     ((strlen(f->sources[i].name) + 3) & ~(size_t)3);
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
        put_u32(p + 0, s->order);
        put_u32(p + 4, s->encoding);
        put_u32(p + 8, s->method);
        put_u32(p + 12, s->quantity);
        put_u32(p + 16, s->window);
        put_f32(p + 20, s->window_param);
        put_f32(p + 24, s->method_param);
        put_f32(p + 28, s->scale);
        put_f32(p + 32, s->quantity_param);
        put_u32(p + 36, s->flags);
        size_t table = stream_table_bytes(s->encoding, s->order);
        for (uint32_t k = 0; table && k < s->order * s->order; k++)
            put_f32(p + STREAM_HEADER_SIZE + 4 * k, s->coef_scales[k]);
        uint32_t rows = vdsh_file_stream_vertices(f);
        uint64_t data = vdsh_stream_data_bytes(s, rows);
        if (s->encoding == VDSH_ENCODING_CPCA) {
            /* the cpca header in the prefix, the padded arrays as `mid` */
            const vdsh_cpca *m = &s->cpca;
            put_u32(p + STREAM_HEADER_SIZE, m->clusters);
            put_u32(p + STREAM_HEADER_SIZE + 4, m->basis);
            put_u32(p + STREAM_HEADER_SIZE + 8, m->bits);
            put_u32(p + STREAM_HEADER_SIZE + 12, m->record_words);
            size_t mb = (size_t)vdsh_cpca_model_bytes(s->order, m->clusters, m->basis) -
                        CPCA_HEADER_SIZE;
            size_t n = (size_t)s->order * s->order, k = m->clusters, b = m->basis;
            uint8_t *q = P->model[i] = (uint8_t *)calloc(1, mb + 1);
            if (!q)
                return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, name, "out of memory");
            for (size_t x = 0; x < k * b; x++)
                put_f32(q + 4 * x, m->scales[x]);
            q += (4 * k * b + 15) & ~(size_t)15;
            memcpy(q, m->means, 2 * k * n);
            q += (2 * k * n + 15) & ~(size_t)15;
            memcpy(q, m->bases, 2 * k * b * n);
            add_chunk(P, "COEF", p, STREAM_HEADER_SIZE + CPCA_HEADER_SIZE, s->data, data);
            out_chunk *c = &P->chunks[P->count - 1];
            c->mid = P->model[i];
            c->mid_size = mb;
            c->mid_pad = 0;
            continue;
        }
        add_chunk(P, "COEF", p, STREAM_HEADER_SIZE + table, s->data, data);
        if (stream_variable(s)) { /* the order table, padded, before the records */
            out_chunk *c = &P->chunks[P->count - 1];
            c->mid = s->orders;
            c->mid_size = rows;
            c->mid_pad = round16(rows) - rows;
            c->data_size = data - round16(rows);
        }
    }

    if (f->has_stats) {
        p = P->stat;
        put_u64(p + 0, f->stats.rays_traced);
        put_u64(p + 8, f->stats.rays_missed);
        put_u32(p + 16, f->stats.degenerate_receivers);
        put_u32(p + 20, f->stats.undefined_normals);
        put_u32(p + 24, f->stats.moved_origins);
        put_u32(p + 28, f->stats.flipped_normals);
        add_chunk(P, "stat", p, STAT_SIZE, NULL, 0);
    }
    if (f->has_timings) {
        p = P->time;
        put_f64(p + 0, f->timings.load);
        put_f64(p + 8, f->timings.refine);
        put_f64(p + 16, f->timings.build);
        put_f64(p + 24, f->timings.trace);
        put_f64(p + 32, f->timings.total);
        put_u32(p + 40, f->timings.threads);
        add_chunk(P, "time", p, TIME_SIZE, NULL, 0);
    }
    if (f->has_part) {
        p = P->part;
        put_u32(p + 0, f->part.index);
        put_u32(p + 4, f->part.count);
        put_u32(p + 8, f->part.range_begin);
        put_u32(p + 12, f->part.range_end);
        put_u32(p + 16, f->part.encoding);
        put_u32(p + 20, f->part.cpca_clusters);
        put_u32(p + 24, f->part.cpca_basis);
        put_u32(p + 28, f->part.cpca_bits);
        add_chunk(P, "part", p, PART_SIZE, NULL, 0);
    }
    if (f->has_adaptive) {
        p = P->adpt;
        put_f32(p + 0, f->adaptive.tolerance);
        put_f32(p + 4, f->adaptive.min_edge);
        put_u32(p + 8, f->adaptive.max_receivers);
        put_u32(p + 12, f->adaptive.lights);
        put_u32(p + 16, f->adaptive.max_rounds);
        put_u32(p + 20, f->adaptive.start_receivers);
        put_u32(p + 24, f->adaptive.rounds);
        put_u32(p + 28, f->adaptive.candidates);
        add_chunk(P, "adpt", p, ADPT_SIZE, NULL, 0);
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

vdsh_result vdsh_write_memory(const vdsh_file *f, void **out_data,
                              size_t *out_size, vdsh_error *err)
{
    plan P;
    if (!out_data || !out_size)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, "memory",
                    "not written: NULL output pointer");
    vdsh_result res = plan_build(&P, f, "memory", err);
    if (res != VDSH_OK) {
        plan_free(&P);
        return res;
    }
    if (P.file_size > SIZE_MAX) {
        plan_free(&P);
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, "memory",
                    "%llu bytes do not fit in memory",
                    (unsigned long long)P.file_size);
    }
    uint8_t *buf = (uint8_t *)malloc((size_t)P.file_size);
    if (!buf) {
        plan_free(&P);
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, "memory",
                    "out of memory (%llu bytes)",
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

vdsh_result vdsh_write_sized(const char *path, const vdsh_file *f, uint64_t *size,
                             vdsh_error *err)
{
    plan P;
    if (!path)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, "(null)",
                    "not written: path is NULL");
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
