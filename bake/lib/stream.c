/* stream.c - a bake's coefficients as .vdsh streams (vb_bake_stream in
 * bake.h): f32 as they are, f16 scaled by the stream's largest
 * |coefficient|, encoded in chunks on the bake's workers, or s8, s8s6 with
 * a scale per coefficient index over the drawn receivers
 * (vdsh_encode_quantised_drawn, one pass: bytes, cheap). */
#include "bake.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "method.h"
#include "parallel.h"
#include "vdsh.h"

/* The f16 stream in chunks on the bake's workers: first each chunk's
 * largest |coefficient|, then, with the stream's scale, its encoding. */
#define F16_CHUNK 65536u

typedef struct f16_job {
    const float *src;
    size_t count;
    float scale;
    float *amax; /* per chunk */
    uint16_t *dst;
    vdsh_result *result; /* per chunk */
} f16_job;

static void f16_amax_block(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    f16_job *J = ctx;
    (void)worker;
    for (uint32_t c = begin; c < end; c++) {
        size_t a = (size_t)c * F16_CHUNK, b = J->count - a < F16_CHUNK ? J->count : a + F16_CHUNK;
        float m = 0.0f;
        for (size_t i = a; i < b; i++)
            m = fmaxf(m, fabsf(J->src[i]));
        J->amax[c] = m;
    }
}

static void f16_encode_block(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    f16_job *J = ctx;
    (void)worker;
    for (uint32_t c = begin; c < end; c++) {
        size_t a = (size_t)c * F16_CHUNK, b = J->count - a < F16_CHUNK ? J->count : a + F16_CHUNK;
        J->result[c] = vdsh_encode_f16(J->src + a, b - a, J->scale, J->dst + a);
    }
}

/* The stream of one order of b, without its data: checks and header. */
static vb_result stream_header(const vb_bake_output *b, int order, vdsh_encoding encoding,
                               vdsh_stream *out, vb_error *err)
{
    if (order < 1 || order > VDSH_MAX_ORDER || !b->coeffs[order])
        return vb_fail(err, VB_ERR_ARGUMENT, "order %d is not in the bake", order);
    if (encoding != VDSH_ENCODING_F16 && encoding != VDSH_ENCODING_F32 &&
        !vdsh_encoding_quantised(encoding))
        return vb_fail(err, VB_ERR_ARGUMENT, "unknown encoding %u", encoding);
    const vb_method_info *mi = vb_method_stored(b->method);
    if (!mi)
        return vb_fail(err, VB_ERR_ARGUMENT, "unknown method %u", b->method);
    *out = (vdsh_stream){
        .order = (uint32_t)order,
        .encoding = encoding,
        .method = b->method,
        .quantity = b->quantity[order],
        .method_param = mi->param == VB_PARAM_LOG_OFFSET ? b->log_offset[order] : b->lambda,
        .scale = 1.0f,
        .quantity_param = b->quantity[order] == VDSH_QUANTITY_LOG_DISTANCE ? b->log_floor : 0.0f,
        .window = b->window,
        .window_param = b->window ? (float)order : 0.0f};
    return VB_OK;
}

vb_result vb_bake_stream(const vb_bake_output *b, int order, vdsh_encoding encoding,
                         vdsh_stream *out, void **storage, vb_error *err)
{
    vdsh_stream s;
    vb_result hr = stream_header(b, order, encoding, &s, err);
    if (hr != VB_OK)
        return hr;
    int nc = order * order;
    /* A shard's range (range_end 0, as in a zeroed output: all receivers). */
    const uint32_t rows = b->range_end ? b->range_end - b->range_begin : b->vertex_count;
    size_t count = (size_t)rows * nc;
    if (encoding == VDSH_ENCODING_F32) {
        float *f = malloc(count * sizeof *f);
        if (!f)
            return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for the order %d stream",
                           order);
        memcpy(f, b->coeffs[order], count * sizeof *f);
        s.data = f;
    } else if (vdsh_encoding_quantised(encoding)) {
        /* One block: the scale table (order^2 floats), then the bytes. */
        size_t bytes_n = (size_t)rows * vdsh_encoding_bytes(encoding, (uint32_t)nc);
        float *block = malloc(VDSH_MAX_COEFFS * sizeof(float) + bytes_n + 1);
        if (!block)
            return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for the order %d stream",
                           order);
        uint8_t *bytes = (uint8_t *)(block + VDSH_MAX_COEFFS);
        if (vdsh_encode_quantised_drawn(encoding, b->coeffs[order], rows, (uint32_t)nc,
                                        b->drawn ? b->drawn + b->range_begin : NULL, block,
                                        bytes) != VDSH_OK) {
            free(block);
            return vb_fail(err, VB_ERR_INVALID, "order %d coefficients do not fit %s", order,
                           vdsh_encoding_name(encoding));
        }
        s.coef_scales = block;
        s.data = bytes;
        *storage = block;
        *out = s;
        return VB_OK;
    } else {
        /* Stored values are coefficient / (the stream's largest
         * |coefficient|): within [-1, 1] whatever the scene's size or clamp
         * distance, so f16 neither overflows nor sinks into subnormals and
         * keeps its full relative precision. */
        uint32_t chunks = (uint32_t)((count + F16_CHUNK - 1) / F16_CHUNK);
        f16_job J = {.src = b->coeffs[order], .count = count};
        J.amax = malloc(((size_t)chunks + 1) * sizeof *J.amax);
        J.result = malloc(((size_t)chunks + 1) * sizeof *J.result);
        J.dst = malloc(count * sizeof *J.dst + 1);
        int ran = J.amax && J.result && J.dst &&
                  vb_parallel_for(b->threads, chunks, 1, f16_amax_block, &J, NULL, NULL) > 0;
        float amax = 0.0f;
        for (uint32_t c = 0; ran && c < chunks; c++)
            amax = fmaxf(amax, J.amax[c]);
        J.scale = s.scale = vdsh_f16_scale(amax);
        ran = ran && vb_parallel_for(b->threads, chunks, 1, f16_encode_block, &J, NULL, NULL) > 0;
        vdsh_result r = ran ? VDSH_OK : VDSH_ERR_OUT_OF_MEMORY;
        for (uint32_t c = 0; ran && c < chunks && r == VDSH_OK; c++)
            r = J.result[c];
        free(J.amax);
        free(J.result);
        if (r != VDSH_OK) {
            free(J.dst);
            return vb_fail(err, r == VDSH_ERR_OUT_OF_MEMORY ? VB_ERR_OUT_OF_MEMORY : VB_ERR_INVALID,
                           "order %d coefficients do not fit f16", order);
        }
        s.data = J.dst;
    }
    *storage = (void *)s.data;
    *out = s;
    return VB_OK;
}

vb_result vb_bake_variable_stream(const vb_bake_output *b, vdsh_encoding encoding, vdsh_stream *out,
                                  void **storage, vb_error *err)
{
    const int cap = b->variable_cap;
    if (!b->variable_orders || cap < 1 || cap > VDSH_MAX_ORDER)
        return vb_fail(err, VB_ERR_ARGUMENT, "the bake has no adaptive order");
    if (encoding > VDSH_ENCODING_LAST)
        return vb_fail(err, VB_ERR_ARGUMENT, "unknown encoding %u", encoding);
    const uint32_t rows = b->range_end ? b->range_end - b->range_begin : b->vertex_count;
    const size_t nc = (size_t)cap * cap;
    /* One block: the scale table, the offsets (rows + 1), the orders (in
     * words), the records: the stream owns copies, so the bake's arrays
     * may be freed. */
    vdsh_stream sized = {
        .encoding = encoding, .flags = VDSH_STREAM_VARIABLE, .orders = b->variable_orders};
    size_t words = (vdsh_stream_data_bytes(&sized, rows) - ((size_t)rows + 15) / 16 * 16) / 4;
    size_t table = VDSH_MAX_COEFFS, head = table + (size_t)rows + 1 + ((size_t)rows + 3) / 4;
    uint32_t *block = malloc((head + words) * sizeof *block + 1);
    if (!block)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for the variable-order stream");
    float *scales = (float *)block;
    uint32_t *offsets = block + table;
    vdsh_stream_offsets(b->variable_orders, rows, encoding, offsets);
    uint8_t *orders = (uint8_t *)(offsets + rows + 1);
    memcpy(orders, b->variable_orders, rows);
    float scale = 1.0f;
    if (encoding == VDSH_ENCODING_F16) { /* stored values within [-1, 1], as vb_bake_stream */
        float amax = 0.0f;
        for (size_t i = 0; i < (size_t)rows * nc; i++)
            amax = fmaxf(amax, fabsf(b->variable_coeffs[i]));
        scale = vdsh_f16_scale(amax);
    }
    if (vdsh_encode_variable_drawn(encoding, b->variable_coeffs, nc, b->variable_orders, rows,
                                   (uint32_t)cap, scale, offsets,
                                   b->drawn ? b->drawn + b->range_begin : NULL, scales,
                                   block + head) != VDSH_OK) {
        free(block);
        return vb_fail(err, VB_ERR_INVALID, "adaptive-order coefficients do not fit %s",
                       vdsh_encoding_name(encoding));
    }
    *out = (vdsh_stream){.order = (uint32_t)cap,
                         .encoding = encoding,
                         .method = b->variable_method,
                         .quantity = VDSH_QUANTITY_LOG_DISTANCE,
                         .method_param = b->variable_param,
                         .scale = scale,
                         .quantity_param = b->log_floor,
                         .window = b->window,
                         .window_param = b->window ? (float)cap : 0.0f,
                         .coef_scales = vdsh_encoding_quantised(encoding) ? scales : NULL,
                         .flags = VDSH_STREAM_VARIABLE,
                         .orders = orders,
                         .offsets = offsets,
                         .data = block + head};
    *storage = block;
    return VB_OK;
}

vb_result vb_bake_stream_take(vb_bake_output *b, int order, vdsh_encoding encoding,
                              vdsh_stream *out, void **storage, vb_error *err)
{
    vb_result r;
    if (encoding != VDSH_ENCODING_F32) {
        if ((r = vb_bake_stream(b, order, encoding, out, storage, err)) == VB_OK) {
            free(b->coeffs[order]);
            b->coeffs[order] = NULL;
        }
        return r;
    }
    /* f32: the bake's rows as they are, handed over, not copied. */
    if ((r = stream_header(b, order, encoding, out, err)) != VB_OK)
        return r;
    out->data = b->coeffs[order];
    *storage = b->coeffs[order];
    b->coeffs[order] = NULL;
    return VB_OK;
}
