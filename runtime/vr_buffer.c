/*
 * vr_buffer.c - upload a coefficient stream as a buffer texture for
 * VR_MODE_VDSH_BUFFER (vr.h): any order, where vertex attributes stop at
 * order 5 (16 attributes of 4 components at most, 25 coefficients).
 *
 * The records go up as the file stores them, only reordered into the GPU
 * vertex order (vr_order.c): f32 as R32F texels, f16 as R16F (the texture
 * unit widens each half exactly), s8 as R8I (the integer itself, times a
 * step per coefficient index from a small R32F buffer: the products
 * vdsh_stream_decode computes), s8s6 as R32UI words (four bytes, then
 * 6-bit fields five to a word, unpacked in the shader; an order-1 s8s6
 * record is one plain byte and goes up as s8). GPU bytes are then the
 * file's: an f16 order-12 stream is 288 bytes per vertex, against 576 as
 * decoded floats (desc->buffer_floats, kept for comparisons:
 * docs/BENCHMARKS.md measured both). A fixed stream's vertex v starts at
 * texel v * stride (the shader reads gl_VertexID).
 *
 * Does not: draw (vr_render.c), choose the stream (vr_scene.c), convert
 * anything but the floats variant.
 * Errors: VR_ERR_FORMAT for an encoding it cannot draw, VR_ERR_GL for a
 * stream over GL_MAX_TEXTURE_BUFFER_SIZE texels, VR_ERR_OUT_OF_MEMORY;
 * messages name the file. On failure nothing stays allocated in *b.
 */
#include "vr_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int vr_buffer_stride(int order, vr_buf_kind kind)
{
    int nc = order * order;
    if (kind == VR_BUF_S8S6)
        return (int)(vdsh_encoding_bytes(VDSH_ENCODING_S8S6, (uint32_t)nc) / 4);
    return nc;
}

/* The texture format of a kind. */
static GLenum texel_format(vr_buf_kind k)
{
    switch (k) {
    case VR_BUF_F16: return GL_R16F;
    case VR_BUF_S8: return GL_R8I;
    case VR_BUF_S8S6: return GL_R32UI;
    default: return GL_R32F;
    }
}

void vr_buffer_destroy(vr_buffer *b)
{
    if (!b)
        return;
    glDeleteVertexArrays(1, &b->vao);
    glDeleteTextures(1, &b->tex);
    glDeleteTextures(1, &b->steps_tex);
    GLuint bufs[4] = {b->buf, b->steps_buf, b->vbo_record, b->vbo_order};
    glDeleteBuffers(4, bufs);
    memset(b, 0, sizeof *b);
}

/* A buffer of `bytes` and a buffer texture of `format` over it. */
static void make_texture(GLuint *buf, GLuint *tex, const void *data, size_t bytes,
                         GLenum format)
{
    glGenBuffers(1, buf);
    glBindBuffer(GL_TEXTURE_BUFFER, *buf);
    glBufferData(GL_TEXTURE_BUFFER, (GLsizeiptr)bytes, data, GL_STATIC_DRAW);
    glGenTextures(1, tex);
    glBindTexture(GL_TEXTURE_BUFFER, *tex);
    glTexBuffer(GL_TEXTURE_BUFFER, format, *buf);
    glBindTexture(GL_TEXTURE_BUFFER, 0);
    glBindBuffer(GL_TEXTURE_BUFFER, 0);
}

/* The records of a fixed stream in GPU vertex order: as stored, or
 * decoded to floats. Returns NULL when out of memory. */
static void *fixed_records(const vdsh_stream *st, uint32_t nv, const uint32_t *remap,
                           int floats, size_t *bytes)
{
    uint32_t nc = st->order * st->order;
    size_t rec = floats ? 4 * (size_t)nc : vdsh_stream_bytes_per_vertex(st);
    unsigned char *dst = malloc((size_t)nv * rec + 4);
    if (!dst)
        return NULL;
    for (uint32_t v = 0; v < nv; v++) {
        unsigned char *out = dst + (size_t)remap[v] * rec;
        if (floats)
            vdsh_stream_decode(st, v, (float *)(void *)out);
        else
            memcpy(out, (const unsigned char *)st->data + (size_t)v * rec, rec);
    }
    *bytes = (size_t)nv * rec;
    return dst;
}

vr_result vr_buffer_upload(vr_scene *s, const vdsh_stream *st, const uint32_t *remap,
                           int floats, const char *name, vr_error *err)
{
    int order = (int)st->order;
    if (order < 1 || order > VDSH_MAX_ORDER || st->encoding > VDSH_ENCODING_S8S6 ||
        (vdsh_encoding_quantised(st->encoding) && !st->coef_scales))
        return vr_fail(err, VR_ERR_FORMAT, "%s: order %d stream: encoding %u cannot be drawn",
                       name, order, st->encoding);
    vr_buffer b;
    memset(&b, 0, sizeof b);
    b.order = order;
    b.encoding = (vdsh_encoding)st->encoding;
    b.scale = 1.0f;
    switch (floats ? VDSH_ENCODING_F32 : st->encoding) {
    case VDSH_ENCODING_F16: b.kind = VR_BUF_F16; break;
    case VDSH_ENCODING_S8: b.kind = VR_BUF_S8; break;
    case VDSH_ENCODING_S8S6: b.kind = order == 1 ? VR_BUF_S8 : VR_BUF_S8S6; break;
    default: b.kind = VR_BUF_F32; break;
    }
    if (!floats && !vdsh_encoding_quantised(st->encoding))
        b.scale = st->scale; /* decoded floats carry it already */
    b.stride = vr_buffer_stride(order, b.kind);

    uint32_t nv = s->vertex_count;
    size_t bytes = 0;
    GLint max_texels = 0;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_texels);
    size_t texels = (size_t)nv * (size_t)b.stride;
    if (texels > (size_t)max_texels)
        return vr_fail(err, VR_ERR_GL, "%s: order %d stream: %zu texels, above this GL's "
                       "GL_MAX_TEXTURE_BUFFER_SIZE (%d)", name, order, texels, (int)max_texels);
    void *rec = fixed_records(st, nv, remap, floats, &bytes);
    if (!rec)
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory uploading order %d", name,
                       order);
    make_texture(&b.buf, &b.tex, rec, bytes, texel_format(b.kind));
    free(rec);
    b.bytes = bytes;
    if (b.kind == VR_BUF_S8 || b.kind == VR_BUF_S8S6) {
        float steps[VDSH_MAX_COEFFS];
        int nc = order * order;
        for (int i = 0; i < nc; i++)
            steps[i] = vdsh_quant_step(st->coef_scales[i],
                                       vdsh_quant_levels(st->encoding, (uint32_t)i));
        make_texture(&b.steps_buf, &b.steps_tex, steps, (size_t)nc * sizeof(float), GL_R32F);
        b.bytes += (size_t)nc * sizeof(float);
    }
    glGenVertexArrays(1, &b.vao);
    glBindVertexArray(b.vao);
    vr_scene_base_attribs(s);
    glBindVertexArray(0);
    vr_result r = vr_check_gl(err, name);
    if (r != VR_OK) {
        vr_buffer_destroy(&b);
        return r;
    }
    s->buffer[order] = b;
    s->gpu_bytes += b.bytes;
    return VR_OK;
}
