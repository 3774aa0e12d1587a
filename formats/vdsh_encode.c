/*
 * vdsh_encode.c - the coefficient encodings (f32, f16, s8, s8s6, cpca
 * records): encoding, sizes and offsets of records, and decoding a
 * stream's rows (VDSH.md "COEF").
 */
#include "vdsh_internal.h"

#include <math.h>
#include <stdlib.h>

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

vdsh_result vdsh_encode_f16(const float *src, size_t n, float scale, uint16_t *dst)
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
int32_t vdsh_quant_stored(uint32_t e, const uint8_t *p, uint32_t i)
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

vdsh_result vdsh_encode_quantised(uint32_t encoding, const float *src, size_t vertices, uint32_t nc,
                                  float *scales, void *dst)
{
    return vdsh_encode_quantised_drawn(encoding, src, vertices, nc, NULL, scales, dst);
}

vdsh_result vdsh_encode_quantised_drawn(uint32_t encoding, const float *src, size_t vertices,
                                        uint32_t nc, const uint8_t *drawn, float *scales, void *dst)
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
                                 const uint8_t *orders, uint32_t rows, uint32_t cap, float scale,
                                 const uint32_t *offsets, float *scales, void *dst)
{
    return vdsh_encode_variable_drawn(encoding, src, stride, orders, rows, cap, scale, offsets,
                                      NULL, scales, dst);
}

vdsh_result vdsh_encode_variable_drawn(uint32_t encoding, const float *src, size_t stride,
                                       const uint8_t *orders, uint32_t rows, uint32_t cap,
                                       float scale, const uint32_t *offsets, const uint8_t *drawn,
                                       float *scales, void *dst)
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
size_t vdsh_stream_table_bytes(uint32_t encoding, uint32_t order)
{
    if (!vdsh_encoding_quantised(encoding))
        return 0;
    return ((size_t)order * order * 4 + 15) & ~(size_t)15;
}

/* ---- cpca (VDSH.md "cpca streams") ---- */

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

uint32_t vdsh_cpca_widths_words(const uint8_t *widths, uint32_t basis)
{
    uint32_t word = 0, used = VDSH_CPCA_INDEX_BITS;
    for (uint32_t j = 0; j < basis; j++) {
        if (!widths[j])
            continue;
        if (used + widths[j] > 32) {
            word++;
            used = 0;
        }
        used += widths[j];
    }
    return word + 1;
}

void vdsh_cpca_model_field(const vdsh_cpca *m, uint32_t j, uint32_t *word, uint32_t *shift)
{
    if (m->bits) {
        vdsh_cpca_field(m->bits, j, word, shift);
        return;
    }
    uint32_t wd = 0, used = VDSH_CPCA_INDEX_BITS;
    for (uint32_t q = 0;; q++) {
        if (used + m->widths[q] > 32) {
            wd++;
            used = 0;
        }
        if (q == j)
            break;
        used += m->widths[q];
    }
    *word = wd;
    *shift = used;
}

uint64_t vdsh_cpca_stream_model_bytes(const vdsh_cpca *m, uint32_t order)
{
    return vdsh_cpca_model_bytes(order, m->clusters, m->basis, m->bases_s8) +
           (m->bits ? 0 : ((uint64_t)m->basis + 15) & ~15ull);
}

uint64_t vdsh_cpca_model_bytes(uint32_t order, uint32_t clusters, uint32_t basis, uint32_t bases_s8)
{
    uint64_t n = (uint64_t)order * order, k = clusters, b = basis, e = bases_s8 ? 1 : 2;
    return CPCA_HEADER_SIZE + ((4 * k * b + 15) & ~15ull) + ((2 * k * n + 15) & ~15ull) +
           ((e * k * b * n + 15) & ~15ull);
}

/* Point a cpca stream's model arrays into the model block at `model` (the
 * 16-byte cpca header first; fields already set). */
void vdsh_cpca_bind(vdsh_stream *s, const uint8_t *model)
{
    uint64_t n = (uint64_t)s->order * s->order, k = s->cpca.clusters, b = s->cpca.basis;
    const uint8_t *q = model + CPCA_HEADER_SIZE;
    s->cpca.widths = s->cpca.bits ? NULL : q;
    if (!s->cpca.bits)
        q += (b + 15) & ~15ull;
    s->cpca.scales = (const float *)q;
    q += (4 * k * b + 15) & ~15ull;
    s->cpca.means = (const uint16_t *)q;
    q += (2 * k * n + 15) & ~15ull;
    s->cpca.bases = s->cpca.bases_s8 ? NULL : (const uint16_t *)q;
    s->cpca.bases8 = s->cpca.bases_s8 ? (const int8_t *)q : NULL;
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
int32_t vdsh_cpca_record_level(const uint32_t *r, uint32_t bits, uint32_t j)
{
    uint32_t word, shift;
    vdsh_cpca_field(bits, j, &word, &shift);
    return vdsh_cpca_field_level(r, word, shift, bits);
}

int32_t vdsh_cpca_field_level(const uint32_t *r, uint32_t word, uint32_t shift, uint32_t bits)
{
    uint32_t u = (r[word] >> shift) & ((1u << bits) - 1u);
    return (int32_t)u - (int32_t)((u >> (bits - 1)) << bits);
}

void vdsh_cpca_weights(const vdsh_stream *s, uint32_t v, int32_t *levels, float *weights)
{
    const uint32_t *r = cpca_record(s, v);
    const vdsh_cpca *m = &s->cpca;
    uint32_t c = r[0] & 0xffu, b = m->basis, word = 0, used = VDSH_CPCA_INDEX_BITS;
    for (uint32_t j = 0; j < b; j++) {
        uint32_t bits = vdsh_cpca_width(m, j);
        if (used + bits > 32) { /* no field straddles two words */
            word++;
            used = 0;
        }
        int32_t q = vdsh_cpca_field_level(r, word, used, bits);
        used += bits;
        if (levels)
            levels[j] = q;
        if (weights)
            weights[j] = (float)q * vdsh_cpca_step(m->scales[(size_t)c * b + j], bits);
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
        const size_t basis = ((size_t)c * b + j) * n;
        /* -std=c11: no contraction into a fused multiply-add */
        for (uint32_t i = 0; i < n; i++)
            out[i] = out[i] + w[j] * vdsh_cpca_basis_value(&s->cpca, basis + i);
    }
}

int vdsh_stream_variable(const vdsh_stream *s)
{
    return (s->flags & VDSH_STREAM_VARIABLE) != 0;
}

static const vdsh_stream *find_stream(const vdsh_file *f, uint32_t order, uint32_t quantity,
                                      uint32_t flags)
{
    if (!f || !f->streams)
        return NULL;
    for (uint32_t i = 0; i < f->stream_count; i++)
        if ((order == 0 || f->streams[i].order == order) && f->streams[i].quantity == quantity &&
            f->streams[i].flags == flags)
            return &f->streams[i];
    return NULL;
}

const vdsh_stream *vdsh_find_stream(const vdsh_file *f, uint32_t order, uint32_t quantity)
{
    return order ? find_stream(f, order, quantity, 0) : NULL;
}

const vdsh_stream *vdsh_find_variable_stream(const vdsh_file *f, uint32_t quantity)
{
    return find_stream(f, 0, quantity, VDSH_STREAM_VARIABLE);
}

uint32_t vdsh_stream_vertex_order(const vdsh_stream *s, uint32_t v)
{
    return vdsh_stream_variable(s) ? s->orders[v] : s->order;
}

size_t vdsh_stream_bytes_per_vertex(const vdsh_stream *s)
{
    if (!s || s->order < 1 || s->order > VDSH_MAX_ORDER || vdsh_stream_variable(s))
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

void vdsh_stream_offsets(const uint8_t *orders, uint32_t rows, uint32_t encoding, uint32_t *offsets)
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
    if (!vdsh_stream_variable(s))
        return (uint64_t)rows * vdsh_stream_bytes_per_vertex(s);
    return ((uint64_t)rows + 15) / 16 * 16 + 4 * records_words(s->orders, rows, s->encoding);
}

vdsh_stream_size vdsh_stream_size_of(const vdsh_stream *s, uint32_t rows)
{
    vdsh_stream_size z = {{0}, 0.0, 0};
    if (!vdsh_stream_variable(s)) {
        if (s->order <= VDSH_MAX_ORDER)
            z.rows_per_order[s->order] = rows;
        z.max_bytes = (uint32_t)vdsh_stream_bytes_per_vertex(s);
        z.mean_bytes = z.max_bytes;
        if (s->encoding == VDSH_ENCODING_CPCA && rows)
            z.mean_bytes += (double)vdsh_cpca_stream_model_bytes(&s->cpca, s->order) / rows;
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
            out[i] = (float)vdsh_quant_stored(s->encoding, (const uint8_t *)d, i) *
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
    if (vdsh_stream_variable(s)) {
        uint32_t k = s->orders[v];
        k = k < s->order ? k : s->order;
        decode_record(s, (const uint32_t *)s->data + s->offsets[v], k * k, out);
        for (uint32_t i = k * k; i < n; i++)
            out[i] = 0.0f;
        return;
    }
    decode_record(s, (const uint8_t *)s->data + (size_t)v * vdsh_encoding_bytes(s->encoding, n), n,
                  out);
}
