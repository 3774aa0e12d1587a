/*
 * vr_buffer.c - upload a coefficient stream as a buffer texture for
 * VR_MODE_VDSH_BUFFER (vr.h): any order, where vertex attributes stop at
 * order 5 (16 attributes of 4 components at most, 25 coefficients).
 *
 * A vertex's record keeps the file's encoding and values; only their
 * order changes, to the order the shader's recurrence consumes them
 * (vr_buffer_sequence: m outside, l inside, then +m before -m), so that
 * the vertex stage reads its record front to back, four coefficients per
 * texel fetch (RGBA32F for f32, RGBA16F for f16: the texture unit widens
 * each half exactly, RGBA8I for s8: the integer itself) or five per
 * R32UI word (s8s6: the first word holds coefficients 0-3 as bytes, as
 * in the file, then the 6-bit fields of the others, five to a word).
 * Records are padded to whole texels (f16, s8: to 8 and 4 bytes, at most
 * 6 and 3 bytes; f32 and s8s6 need none). Measured against one fetch per
 * coefficient in file order, the texel fetches were most of the buffer
 * path's cost on llvmpipe (docs/BENCHMARKS.md). GPU bytes are then the
 * file's: an f16 order-12 stream is 288 bytes per vertex, against 576 as
 * decoded floats (desc->buffer_floats, kept for comparisons).
 *
 * Per coefficient index i the shader multiplies by a factor (KS, a
 * constant table in the program's source, one program per table; the
 * program key holds its hash): K_l^|m| of the basis (sqrt 2 folded in for
 * m != 0, computed in double as formats/vdsh_sh.c does) times, for s8 and
 * s8s6, the step vdsh_quant_step(scale_i, levels_i), so that q_i * step_i
 * is the coefficient vdsh_stream_decode computes.
 *
 * A fixed stream's vertex v starts at texel v * stride (the shader reads
 * gl_VertexID); a stream with an order per vertex carries each vertex's
 * first texel and order as integer attributes.
 *
 * A cpca stream (VDSH.md "cpca streams") keeps its records as stored,
 * W u32 words per vertex (R32UI: the cluster index and the packed weight
 * levels), and its model goes up once as a second buffer texture
 * (RGBA32F, build_model): per cluster c and record texel t (four
 * coefficients in the sequence above) B + 1 texels in a row, the mean's
 * then each basis vector's times its step (scale_{c,j} / L), at
 * ((c * T + t) * (B + 1) + j), T = stride of the order as f32. The
 * vertex stage decodes its coefficients four at a time as mean + sum of
 * level_j * texel_j (vdsh_buffer.glsl, BUF_KIND 4), then sums them as
 * the other kinds do: once per vertex, not once per light. A stream with
 * a width per basis vector (bits 0) gets each step from its vector's
 * width and its unpacking written out into the programs
 * (cpca_unpack_define, BUF_CPCA_UNPACK), one program per widths table
 * (ks_hash covers it). The model is
 * K * (B + 1) * T * 16 bytes (8, 54, 4 at order 12: 253 KB), the records
 * the file's (28 bytes per vertex at the default).
 *
 * With desc->cpca_decode = VR_CPCA_PER_FRAME a cpca stream also gets a
 * scratch of T f32 texels per vertex and a decode program (make_decoder:
 * shaders/vdsh_cpca_decode.glsl with the sums written out,
 * cpca_dot_define) that vr_draw runs once before its passes
 * (vr_buffer_decode: a draw of points, the rasteriser off), the passes
 * then reading the scratch as an f32 stream.
 *
 * Does not: draw (vr_render.c), choose the stream (vr_scene.c), convert
 * values (only the floats variant decodes).
 * Errors: VR_ERR_FORMAT for an encoding it cannot draw or a record that
 * is not where the stream says, VR_ERR_GL for a stream over
 * GL_MAX_TEXTURE_BUFFER_SIZE texels, VR_ERR_OUT_OF_MEMORY; messages name
 * the file. On failure nothing stays allocated.
 */
#include "vr_internal.h"
#include "vr_glsl_files.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int vr_buffer_sequence(int order, int *out)
{
    int n = 0;
    for (int m = 0; m < order; m++)
        for (int l = m; l < order; l++) {
            out[n++] = l * (l + 1) + m;
            if (m > 0)
                out[n++] = l * (l + 1) - m;
        }
    return n;
}

int vr_buffer_stride(int order, vr_buf_kind kind)
{
    int nc = order * order;
    if (kind == VR_BUF_S8S6)
        return nc <= VDSH_S8S6_BYTES ? 1 : 1 + (nc - VDSH_S8S6_BYTES + 4) / 5;
    return (nc + 3) / 4;
}

/* Bytes of a texel, and its texture format. */
static size_t texel_bytes(vr_buf_kind k)
{
    return k == VR_BUF_F32 ? 16 : k == VR_BUF_F16 ? 8 : 4;
}

static GLenum texel_format(vr_buf_kind k)
{
    switch (k) {
    case VR_BUF_F16: return GL_RGBA16F;
    case VR_BUF_S8: return GL_RGBA8I;
    case VR_BUF_S8S6: return GL_R32UI;
    case VR_BUF_CPCA: return GL_R32UI;
    default: return GL_RGBA32F;
    }
}

void vr_buffer_destroy(vr_buffer *b)
{
    if (!b)
        return;
    glDeleteVertexArrays(1, &b->vao);
    GLuint texs[3] = {b->tex, b->model_tex, b->scratch_tex};
    glDeleteTextures(3, texs);
    GLuint bufs[5] = {b->buf, b->vbo_record, b->vbo_order, b->model_buf, b->scratch_buf};
    glDeleteBuffers(5, bufs);
    if (b->decode_prog)
        glDeleteProgram(b->decode_prog);
    for (int g = 0; g <= VR_SUMS_MAX_GROUP; g++)
        if (b->sums_prog[g])
            glDeleteProgram(b->sums_prog[g]);
    free(b->ks);
    free(b->cpca_unpack);
    memset(b, 0, sizeof *b);
}

static uint32_t get_u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static void put_u32(unsigned char *p, uint32_t v)
{
    for (int k = 0; k < 4; k++)
        p[k] = (unsigned char)(v >> (8 * k));
}

/* Stored value i (>= 4) of an s8s6 record, sign-extended. */
static int s8s6_field(const unsigned char *rec, int i)
{
    int j = i - VDSH_S8S6_BYTES;
    uint32_t f = get_u32(rec + VDSH_S8S6_BYTES + 4 * (j / 5)) >> (6 * (j % 5)) & 63u;
    return f >= 32u ? (int)f - 64 : (int)f;
}

/* One vertex's record of order k (rec: as the file stores it; floats:
 * the decoded coefficients instead) into dst in the shader's order. */
static void pack_record(vr_buf_kind kind, int floats, const unsigned char *rec,
                        const float *decoded, int k, unsigned char *dst)
{
    int seq[VDSH_MAX_COEFFS];
    int n = vr_buffer_sequence(k, seq);
    memset(dst, 0, (size_t)vr_buffer_stride(k, kind) * texel_bytes(kind));
    if (floats) {
        for (int p = 0; p < n; p++)
            memcpy(dst + 4 * p, &decoded[seq[p]], 4);
        return;
    }
    if (kind != VR_BUF_S8S6) {
        size_t e = kind == VR_BUF_F32 ? 4 : kind == VR_BUF_F16 ? 2 : 1;
        for (int p = 0; p < n; p++)
            memcpy(dst + e * (size_t)p, rec + e * (size_t)seq[p], e);
        return;
    }
    /* s8s6: word 0 as stored (coefficients 0-3, fewer at order 1), then
     * the 6-bit fields in sequence, 0-3 skipped. */
    memcpy(dst, rec, (size_t)(n < VDSH_S8S6_BYTES ? n : VDSH_S8S6_BYTES));
    int f = 0;
    for (int p = 0; p < n; p++) {
        if (seq[p] < VDSH_S8S6_BYTES)
            continue;
        unsigned char *w = dst + 4 + 4 * (f / 5);
        put_u32(w, get_u32(w) | ((uint32_t)s8s6_field(rec, seq[p]) & 63u) << (6 * (f % 5)));
        f++;
    }
}

/* The texture kind of a stream as uploaded. */
static vr_buf_kind kind_of(const vdsh_stream *st, int floats)
{
    switch (floats ? VDSH_ENCODING_F32 : st->encoding) {
    case VDSH_ENCODING_F16: return VR_BUF_F16;
    case VDSH_ENCODING_S8: return VR_BUF_S8;
    case VDSH_ENCODING_S8S6: return VR_BUF_S8S6;
    case VDSH_ENCODING_CPCA: return VR_BUF_CPCA;
    default: return VR_BUF_F32;
    }
}

/* The factors of u_ks per coefficient index (see the top). */
static float *make_ks(const vdsh_stream *st, int order, int floats)
{
    float *ks = calloc((size_t)VDSH_MAX_COEFFS + 4, sizeof *ks);
    if (!ks)
        return NULL;
    for (int l = 0; l < order; l++)
        for (int m = 0; m <= l; m++) {
            double kk = (2.0 * l + 1.0) / (4.0 * 3.14159265358979323846);
            for (int f = l - m + 1; f <= l + m; f++)
                kk /= f;
            float K = m == 0 ? (float)sqrt(kk) : (float)sqrt(2.0 * kk);
            for (int sign = m ? -1 : 1; sign <= 1; sign += 2) {
                int i = l * (l + 1) + sign * m;
                float step = 1.0f;
                if (!floats && vdsh_encoding_quantised(st->encoding))
                    step = vdsh_quant_step(st->coef_scales[i],
                                           vdsh_quant_levels(st->encoding, (uint32_t)i));
                ks[i] = K * step;
            }
        }
    return ks;
}

/* The records of a fixed stream in GPU vertex order. NULL when out of
 * memory. */
static unsigned char *fixed_records(const vdsh_stream *st, vr_buffer *b, uint32_t nv,
                                    const uint32_t *remap, int floats, size_t *bytes)
{
    size_t rec = (size_t)b->stride * texel_bytes(b->kind), bpv = vdsh_stream_bytes_per_vertex(st);
    unsigned char *dst = malloc((size_t)nv * rec + 16);
    if (!dst)
        return NULL;
    if (b->kind == VR_BUF_CPCA) {
        for (uint32_t v = 0; v < nv; v++)
            memcpy(dst + (size_t)remap[v] * rec, (const unsigned char *)st->data + (size_t)v * bpv,
                   rec);
        *bytes = (size_t)nv * rec;
        return dst;
    }
    float decoded[VDSH_MAX_COEFFS];
    for (uint32_t v = 0; v < nv; v++) {
        if (floats)
            vdsh_stream_decode(st, v, decoded);
        pack_record(b->kind, floats, (const unsigned char *)st->data + (size_t)v * bpv, decoded,
                    b->order, dst + (size_t)remap[v] * rec);
    }
    *bytes = (size_t)nv * rec;
    return dst;
}

/* The records of a stream with an order per vertex in GPU vertex order,
 * with each GPU vertex's first texel (start) and order. The file's
 * records are checked to be where its offsets say (a stream from memory
 * has not been through the reader). VR_ERR_FORMAT, VR_ERR_OUT_OF_MEMORY. */
static vr_result variable_records(const vdsh_stream *st, vr_buffer *b, uint32_t nv,
                                  const uint32_t *remap, int floats, unsigned char **out,
                                  size_t *bytes, uint32_t *start, uint8_t *order, const char *name,
                                  vr_error *err)
{
    uint32_t *inv = malloc((size_t)nv * sizeof *inv);
    if (!inv)
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
    size_t texels = 0, tb = texel_bytes(b->kind);
    double sum = 0.0;
    for (uint32_t v = 0; v < nv; v++) {
        uint32_t k = st->orders[v];
        if (k < 1 || k > st->order ||
            st->offsets[v + 1] - st->offsets[v] != vdsh_record_words(st->encoding, k)) {
            free(inv);
            return vr_fail(err, VR_ERR_FORMAT,
                           "%s: variable-order stream: vertex %u has "
                           "order %u and a record of %u words",
                           name, v, k, st->offsets[v + 1] - st->offsets[v]);
        }
        inv[remap[v]] = v;
        texels += (size_t)vr_buffer_stride((int)k, b->kind);
        sum += k;
    }
    unsigned char *dst = malloc(texels * tb + 16);
    if (!dst) {
        free(inv);
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
    }
    float decoded[VDSH_MAX_COEFFS];
    size_t at = 0;
    for (uint32_t g = 0; g < nv; g++) {
        uint32_t v = inv[g];
        int k = st->orders[v];
        if (floats)
            vdsh_stream_decode(st, v, decoded);
        pack_record(b->kind, floats, (const unsigned char *)st->data + 4 * (size_t)st->offsets[v],
                    decoded, k, dst + at * tb);
        start[g] = (uint32_t)at;
        order[g] = (uint8_t)k;
        at += (size_t)vr_buffer_stride(k, b->kind);
    }
    free(inv);
    b->mean_order = nv ? (float)(sum / nv) : 0.0f;
    *out = dst;
    *bytes = texels * tb;
    return VR_OK;
}

/* A cpca stream's model as the vertex stage reads it (see the top): f32
 * texels, K * T * (B + 1) of them. NULL when out of memory. */
static float *build_model(const vdsh_stream *st, int order, size_t *bytes)
{
    const vdsh_cpca *m = &st->cpca;
    int seq[VDSH_MAX_COEFFS];
    int n = vr_buffer_sequence(order, seq), nc = order * order;
    size_t T = (size_t)(n + 3) / 4, row = (size_t)m->basis + 1;
    size_t floats = (size_t)m->clusters * T * row * 4;
    float *dst = calloc(floats + 4, sizeof *dst);
    if (!dst)
        return NULL;
    for (uint32_t c = 0; c < m->clusters; c++)
        for (int p = 0; p < n; p++) {
            float *t = dst + (((size_t)c * T + (size_t)p / 4) * row) * 4 + p % 4;
            t[0] = vdsh_f32_from_f16(m->means[(size_t)c * (size_t)nc + (size_t)seq[p]]);
            for (uint32_t j = 0; j < m->basis; j++) {
                size_t v = (size_t)c * m->basis + j;
                float step = vdsh_cpca_step(m->scales[v], vdsh_cpca_width(m, j));
                t[4 * (j + 1)] = step * vdsh_cpca_basis_value(m, v * (size_t)nc + (size_t)seq[p]);
            }
        }
    *bytes = floats * sizeof *dst;
    return dst;
}

/* Create the buffer texture, the VAO and (variable) the per-vertex
 * attributes of b (GL errors are the caller's to check). */
static void make_gl(vr_scene *s, vr_buffer *b, const void *rec, size_t bytes, const uint32_t *start,
                    const uint8_t *order)
{
    glGenBuffers(1, &b->buf);
    glBindBuffer(GL_TEXTURE_BUFFER, b->buf);
    glBufferData(GL_TEXTURE_BUFFER, (GLsizeiptr)bytes, rec, GL_STATIC_DRAW);
    glGenTextures(1, &b->tex);
    glBindTexture(GL_TEXTURE_BUFFER, b->tex);
    glTexBuffer(GL_TEXTURE_BUFFER, texel_format(b->kind), b->buf);
    glBindTexture(GL_TEXTURE_BUFFER, 0);
    glBindBuffer(GL_TEXTURE_BUFFER, 0);
    glGenVertexArrays(1, &b->vao);
    glBindVertexArray(b->vao);
    vr_scene_base_attribs(s);
    if (start) {
        size_t nv = s->vertex_count;
        GLuint vbo[2];
        glGenBuffers(2, vbo);
        b->vbo_record = vbo[0];
        b->vbo_order = vbo[1];
        glBindBuffer(GL_ARRAY_BUFFER, b->vbo_record);
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * 4), start, GL_STATIC_DRAW);
        glVertexAttribIPointer(VR_ATTR_RECORD, 1, GL_UNSIGNED_INT, 4, NULL);
        glEnableVertexAttribArray(VR_ATTR_RECORD);
        glBindBuffer(GL_ARRAY_BUFFER, b->vbo_order);
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)nv, order, GL_STATIC_DRAW);
        glVertexAttribIPointer(VR_ATTR_ORDER, 1, GL_UNSIGNED_BYTE, 1, NULL);
        glEnableVertexAttribArray(VR_ATTR_ORDER);
        b->bytes += nv * 5;
    }
    glBindVertexArray(0);
    b->bytes += bytes;
}

/* "#define BUF_CPCA_UNPACK(f) w = BUF_FETCH((f) + 1).r; b_wt[0] = ...;\n"
 * for a cpca stream with a width per basis vector (bits 0): buf_begin's
 * unpacking (shaders/vdsh_buffer.glsl; word 0, already in w, holds the
 * cluster) written out, each field's word, shifts and width constants
 * (vdsh_cpca_model_field), a word fetched once. Malloc'd; NULL when out
 * of memory. */
static char *cpca_unpack_define(const vdsh_cpca *m)
{
    size_t size = 64 + (size_t)m->basis * 64;
    char *d = malloc(size);
    if (!d)
        return NULL;
    size_t n = (size_t)snprintf(d, size, "#define BUF_CPCA_UNPACK(f)");
    uint32_t last = 0;
    for (uint32_t j = 0; j < m->basis && n < size; j++) {
        uint32_t word = 0, shift = 0, width = vdsh_cpca_width(m, j);
        vdsh_cpca_model_field(m, j, &word, &shift);
        if (word != last && n < size)
            n += (size_t)snprintf(d + n, size - n, " w = BUF_FETCH((f) + %u).r;", word);
        last = word;
        if (n < size)
            n += (size_t)snprintf(d + n, size - n, " b_wt[%u] = float(int(w << %uu) >> %u);", j,
                                  32 - shift - width, 32 - width);
    }
    if (n < size)
        snprintf(d + n, size - n, "\n");
    return d;
}

/* "#define BUF_CPCA_DOT(m) (BUF_MODEL(m) + b_wt[0] * BUF_MODEL((m) + 1)
 * + ...)\n" for a cpca stream of `basis` vectors: the decode's sum of a
 * model texel (shaders/vdsh_cpca_decode.glsl) written out, the same
 * operations in the same order with constant weight indices. As a loop
 * it cost twice the decode's time on llvmpipe; in the per-pass decode
 * (vdsh_buffer.glsl's buf_next) the same macro made the pass 2.6x slower,
 * so only the decode once per frame uses it (docs/BENCHMARKS.md).
 * Malloc'd; NULL when out of memory. */
static char *cpca_dot_define(int basis)
{
    size_t size = 64 + (size_t)basis * 40;
    char *d = malloc(size);
    if (!d)
        return NULL;
    size_t n = (size_t)snprintf(d, size, "#define BUF_CPCA_DOT(m) (BUF_MODEL(m)");
    for (int j = 0; j < basis && n < size; j++)
        n += (size_t)snprintf(d + n, size - n, " + b_wt[%d] * BUF_MODEL((m) + %d)", j, j + 1);
    if (n < size)
        snprintf(d + n, size - n, ")\n");
    return d;
}

int vr_has_compute(void)
{
    static const char *const ext[2] = {"GL_ARB_compute_shader",
                                       "GL_ARB_shader_storage_buffer_object"};
    return vr_gl_has(4, 3, ext, 2);
}

/* The first lines of a compute shader: GLSL 4.30 where the GL compiles
 * it (GL 4.3, and NVIDIA's 3.3 core context, whose GLSL is 4.60:
 * compute_probe ran as 4.30 there), else 3.30 with the extensions. */
static const char *compute_version(void)
{
    const char *v = (const char *)glGetString(GL_SHADING_LANGUAGE_VERSION);
    int major = 0, minor = 0;
    if (!v || sscanf(v, "%d.%d", &major, &minor) != 2)
        major = minor = 0;
    return major > 4 || (major == 4 && minor >= 30)
               ? "#version 430 core\n"
               : "#version 330 core\n#extension GL_ARB_compute_shader : require\n"
                 "#extension GL_ARB_shader_storage_buffer_object : require\n";
}

/* Dispatch invocations of a compute shader of 64 per group, in rows of at
 * most 65535 groups (the shaders number them row by row). */
static void dispatch(size_t invocations)
{
    size_t groups = (invocations + 63) / 64, x = groups < 65535 ? groups : 65535;
    if (groups)
        glDispatchCompute((GLuint)x, (GLuint)((groups + x - 1) / x), 1);
}

/* The decode program and the scratch of b (VR_CPCA_PER_FRAME, or a cpca
 * stream's VR_SUMS_COMPUTE; vr.h, shaders/vdsh_cpca_decode.glsl).
 * VR_ERR_GL where this GL has no compute shaders or the scratch is over
 * its limits, VR_ERR_SHADER, VR_ERR_OUT_OF_MEMORY. */
static vr_result make_decoder(const vr_scene *s, vr_buffer *b, const char *name, vr_error *err)
{
    GLint max_texels = 0;
    GLint64 max_block = 0;
    if (!vr_has_compute())
        return vr_fail(err, VR_ERR_GL,
                       "%s: order %d cpca stream: decoding once per frame needs compute shaders "
                       "and shader storage buffers (GL 4.3), which this GL has not",
                       name, b->order);
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_texels);
    glGetError();
    b->scratch_stride = vr_buffer_stride(b->order, VR_BUF_F32);
    size_t texels = (size_t)s->vertex_count * (size_t)b->scratch_stride;
    if (texels > (size_t)max_texels || (double)texels * 16.0 > (double)max_block)
        return vr_fail(err, VR_ERR_GL,
                       "%s: order %d cpca stream: a scratch of %zu texels is above this GL's "
                       "limits (GL_MAX_TEXTURE_BUFFER_SIZE %d, GL_MAX_SHADER_STORAGE_BLOCK_SIZE "
                       "%lld)",
                       name, b->order, texels, (int)max_texels, (long long)max_block);
    char *dot = cpca_dot_define(b->cpca_basis);
    char defines[512];
    snprintf(defines, sizeof defines,
             "%s"
             "#define BUFFER 1\n#define NUM_LIGHTS 0\n#define BUF_ORDER %d\n#define BUF_KIND 4\n"
             "#define BUF_VARIABLE 0\n#define BUF_STRIDE %d\n#define BUF_CPCA_BASIS %d\n"
             "#define BUF_CPCA_BITS %d\n#define BUF_CPCA_T %d\n"
             "const float KS[1] = float[1](1.0);\n",
             compute_version(), b->order, b->stride, b->cpca_basis, b->cpca_bits,
             b->scratch_stride);
    size_t size = strlen(defines) + (dot ? strlen(dot) : 0) +
                  (b->cpca_unpack ? strlen(b->cpca_unpack) : 0) + vr_buffer_glsl_size +
                  vr_cpca_decode_glsl_size + 1;
    char *cs = dot ? malloc(size) : NULL;
    if (!cs) {
        free(dot);
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
    }
    snprintf(cs, size, "%s%s%s%s%s", defines, dot, b->cpca_unpack ? b->cpca_unpack : "",
             vr_buffer_glsl, vr_cpca_decode_glsl);
    free(dot);
    char what[256];
    snprintf(what, sizeof what, "%s: cpca decode program", name);
    vr_result r = vr_link_compute(what, cs, &b->decode_prog, err);
    free(cs);
    if (r != VR_OK)
        return r;
    glUseProgram(b->decode_prog);
    glUniform1i(glGetUniformLocation(b->decode_prog, "u_coef"), VR_UNIT_COEF);
    glUniform1i(glGetUniformLocation(b->decode_prog, "u_model"), VR_UNIT_MODEL);
    glUniform1i(glGetUniformLocation(b->decode_prog, "u_vertices"), (GLint)s->vertex_count);
    glUseProgram(0);
    glGenBuffers(1, &b->scratch_buf);
    glBindBuffer(GL_TEXTURE_BUFFER, b->scratch_buf);
    glBufferData(GL_TEXTURE_BUFFER, (GLsizeiptr)(texels * 16), NULL, GL_DYNAMIC_COPY);
    glGenTextures(1, &b->scratch_tex);
    glBindTexture(GL_TEXTURE_BUFFER, b->scratch_tex);
    glTexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32F, b->scratch_buf);
    glBindTexture(GL_TEXTURE_BUFFER, 0);
    glBindBuffer(GL_TEXTURE_BUFFER, 0);
    b->bytes += texels * 16;
    return vr_check_gl(err, name);
}

void vr_buffer_decode(const vr_scene *s, const vr_buffer *b)
{
    glUseProgram(b->decode_prog);
    glActiveTexture(GL_TEXTURE0 + VR_UNIT_COEF);
    glBindTexture(GL_TEXTURE_BUFFER, b->tex);
    glActiveTexture(GL_TEXTURE0 + VR_UNIT_MODEL);
    glBindTexture(GL_TEXTURE_BUFFER, b->model_tex);
    glActiveTexture(GL_TEXTURE0);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, b->scratch_buf);
    dispatch((size_t)s->vertex_count * (size_t)b->scratch_stride);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, 0);
    /* the sums or the passes read the scratch as a buffer texture */
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
}

/* Lights per invocation of the sums (shaders/vr_sums.glsl), by what was
 * measured (docs/BENCHMARKS.md "Sums in a compute shader"). On llvmpipe
 * a group fetches each coefficient once for its lights: at 16 lights in
 * the built-in room at order 12 (s8s6) the frame took 388 ms of CPU with
 * 1, 200 with 4, 164 with 8 and 155 with 16, against the vertex stage's
 * 178; 8 is the vertex stage's own group. On a GPU one light per
 * invocation was measured (tests/compute_probe on an NVIDIA H200: 0.13
 * ms at 16 lights, 28-45x under the vertex stage, whose per-light arrays
 * a GPU compiler may keep in memory), and a group was not. A cpca
 * stream decoded in the sums (in_sums) takes all the frame's lights, up to
 * VR_SUMS_MAX_GROUP, in one invocation, which then decodes each
 * coefficient once for them: 0, the frame's (at 16 lights in the room,
 * 211 ms of CPU with 16, 293 with 8). The environment's VR_SUMS_GROUP
 * (1..16) overrides it, for the tests (which draw both on llvmpipe) and
 * for measuring another GL. */
static int sums_group(int in_sums)
{
    const char *e = getenv("VR_SUMS_GROUP");
    char *end = NULL;
    long g = e ? strtol(e, &end, 10) : 0;
    if (e && end != e && !*end && g >= 1 && g <= VR_SUMS_MAX_GROUP)
        return (int)g;
    if (in_sums)
        return 0;
    const char *r = (const char *)glGetString(GL_RENDERER);
    return r && strstr(r, "llvmpipe") ? VR_MAX_LIGHTS_PER_PASS : 1;
}

/* A cpca stream decoded at load (VR_CPCA_AT_LOAD): its records, model
 * and decode program deleted; the scratch stays. */
static void release_decoded(vr_buffer *b)
{
    GLuint texs[2] = {b->tex, b->model_tex}, bufs[2] = {b->buf, b->model_buf};
    glDeleteTextures(2, texs);
    glDeleteBuffers(2, bufs);
    glDeleteProgram(b->decode_prog);
    b->tex = b->model_tex = b->buf = b->model_buf = b->decode_prog = 0;
}

/* VR_SUMS_COMPUTE: the sums program of fixed-order stream b for `group`
 * lights per invocation (shaders/vr_sums.glsl), b->sums_prog[group],
 * reading its scratch where it has one, else its records as stored (a
 * cpca stream's decoded as they are read, from the model). VR_ERR_GL
 * without compute shaders, VR_ERR_SHADER, VR_ERR_OUT_OF_MEMORY. */
static vr_result make_summer(const vr_scene *s, vr_buffer *b, int group, const char *name,
                             vr_error *err)
{
    if (!vr_has_compute())
        return vr_fail(err, VR_ERR_GL,
                       "%s: order %d stream: sums in a compute shader need compute shaders and "
                       "shader storage buffers (GL 4.3), which this GL has not",
                       name, b->order);
    int scratch = b->scratch_tex != 0;
    vr_buf_kind kind = scratch ? VR_BUF_F32 : b->kind;
    const char *unpack = !scratch && b->cpca_unpack ? b->cpca_unpack : "";
    char defines[512];
    snprintf(defines, sizeof defines,
             "%s#define BUFFER 1\n#define NUM_LIGHTS %d\n#define BUF_ORDER %d\n"
             "#define BUF_KIND %d\n#define BUF_VARIABLE 0\n#define BUF_STRIDE %d\n"
             "#define BUF_CPCA_BASIS %d\n#define BUF_CPCA_BITS %d\n#define BUF_CPCA_T %d\n",
             compute_version(), group, b->order, (int)kind, scratch ? b->scratch_stride : b->stride,
             b->cpca_basis, b->cpca_bits, vr_buffer_stride(b->order, VR_BUF_F32));
    char *table = vr_ks_table(b->ks, b->order * b->order);
    size_t size = strlen(defines) + strlen(unpack) + (table ? strlen(table) : 0) +
                  vr_sums_glsl_size + vr_buffer_glsl_size + vr_sums_main_glsl_size + 1;
    char *cs = table ? malloc(size) : NULL;
    if (!cs) {
        free(table);
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
    }
    snprintf(cs, size, "%s%s%s%s%s%s", defines, unpack, table, vr_sums_glsl, vr_buffer_glsl,
             vr_sums_main_glsl);
    free(table);
    char what[256];
    snprintf(what, sizeof what, "%s: order %d sums program (%d light%s per invocation)", name,
             b->order, group, group == 1 ? "" : "s");
    GLuint prog = 0;
    vr_result r = vr_link_compute(what, cs, &prog, err);
    free(cs);
    if (r != VR_OK)
        return r;
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_coef"), VR_UNIT_COEF);
    glUniform1i(glGetUniformLocation(prog, "u_model"), VR_UNIT_MODEL);
    glUniform1i(glGetUniformLocation(prog, "u_vertices"), (GLint)s->vertex_count);
    glUniform1f(glGetUniformLocation(prog, "u_scale"), b->scale);
    b->sums_prog[group] = prog;
    b->sums_u_lights[group] = glGetUniformLocation(prog, "u_lights");
    b->sums_u_frame[group] = glGetUniformLocation(prog, "u_frame");
    glUseProgram(0);
    return vr_check_gl(err, name);
}

vr_result vr_cull_make(vr_cull_prog *c, vr_error *err)
{
    const char *version = compute_version();
    size_t size = strlen(version) + vr_cull_glsl_size + 1;
    char *cs = malloc(size);
    if (!cs)
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "vr_draw: out of memory");
    snprintf(cs, size, "%s%s", version, vr_cull_glsl);
    vr_result r = vr_link_compute("vr_draw: the sums' cull program", cs, &c->prog, err);
    free(cs);
    if (r != VR_OK)
        return r;
    c->u_view_proj = glGetUniformLocation(c->prog, "u_view_proj");
    c->u_triangles = glGetUniformLocation(c->prog, "u_triangles");
    c->u_frame = glGetUniformLocation(c->prog, "u_frame");
    return VR_OK;
}

void vr_cull(const vr_scene *s, const vr_cull_prog *c, GLuint seen, const float vp[16],
             uint32_t frame)
{
    glUseProgram(c->prog);
    glUniformMatrix4fv(c->u_view_proj, 1, GL_FALSE, vp);
    glUniform1i(c->u_triangles, (GLint)s->triangle_count);
    glUniform1ui(c->u_frame, frame);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, s->vbo_position);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, s->ibo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, seen);
    dispatch(s->triangle_count);
    for (GLuint i = 0; i < 3; i++)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, i, 0);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

vr_result vr_buffer_sums(const vr_scene *s, vr_buffer *b, GLuint lights, GLuint sums, int n,
                         GLuint seen, uint32_t frame, vr_error *err)
{
    int group = b->sums_group ? b->sums_group : n < VR_SUMS_MAX_GROUP ? n : VR_SUMS_MAX_GROUP;
    if (!b->sums_prog[group]) {
        vr_result r = make_summer(s, b, group, "vr_draw", err);
        if (r != VR_OK)
            return r;
    }
    glUseProgram(b->sums_prog[group]);
    glUniform1i(b->sums_u_lights[group], n);
    glUniform1ui(b->sums_u_frame[group], frame);
    glActiveTexture(GL_TEXTURE0 + VR_UNIT_COEF);
    glBindTexture(GL_TEXTURE_BUFFER, b->scratch_tex ? b->scratch_tex : b->tex);
    glActiveTexture(GL_TEXTURE0 + VR_UNIT_MODEL);
    glBindTexture(GL_TEXTURE_BUFFER, b->scratch_tex ? 0 : b->model_tex);
    glActiveTexture(GL_TEXTURE0);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, s->vbo_position);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, lights);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, sums);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, seen);
    dispatch((size_t)s->vertex_count * (size_t)((n + group - 1) / group));
    for (GLuint i = 0; i < 4; i++)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, i, 0);
    /* the passes read the sums as a buffer texture */
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    return VR_OK;
}

vr_result vr_buffer_upload(vr_scene *s, const vdsh_stream *st, const uint32_t *remap, int floats,
                           int cpca_decode, int sums, const char *name, vr_error *err)
{
    int order = (int)st->order;
    int cpca = st->encoding == VDSH_ENCODING_CPCA;
    if (order < 1 || order > VDSH_MAX_ORDER || (st->encoding > VDSH_ENCODING_S8S6 && !cpca) ||
        (cpca &&
         (!st->cpca.scales || !st->cpca.means ||
          !(st->cpca.bases_s8 ? (const void *)st->cpca.bases8 : (const void *)st->cpca.bases) ||
          (st->flags & VDSH_STREAM_VARIABLE))) ||
        (vdsh_encoding_quantised(st->encoding) && !st->coef_scales))
        return vr_fail(err, VR_ERR_FORMAT, "%s: order %d stream: encoding %u cannot be drawn", name,
                       order, st->encoding);
    vr_buffer b;
    memset(&b, 0, sizeof b);
    b.order = order;
    b.encoding = (vdsh_encoding)st->encoding;
    b.kind = kind_of(st, floats);
    /* quantised and decoded coefficients carry their scale already */
    b.scale = floats || vdsh_encoding_quantised(st->encoding) ? 1.0f : st->scale;
    b.stride = vr_buffer_stride(order, b.kind);
    if (b.kind == VR_BUF_CPCA) {
        b.cpca_basis = (int)st->cpca.basis;
        b.cpca_bits = (int)st->cpca.bits;
        b.stride = (int)st->cpca.record_words;
    }
    if (b.kind == VR_BUF_CPCA && !b.cpca_bits) {
        /* a width per vector: each checked 2..8 by the reader; the words
         * they fill are the stream's (vdsh_check_stream) */
        b.cpca_unpack = st->cpca.widths ? cpca_unpack_define(&st->cpca) : NULL;
        if (!b.cpca_unpack)
            return vr_fail(err, st->cpca.widths ? VR_ERR_OUT_OF_MEMORY : VR_ERR_FORMAT,
                           "%s: order %d cpca stream: %s", name, order,
                           st->cpca.widths ? "out of memory" : "bits 0 without its widths table");
    }
    b.ks = make_ks(st, order, floats);
    if (!b.ks) {
        free(b.cpca_unpack);
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
    }
    /* FNV-1a over the order, the table's bits and (a width per vector)
     * the unpacking, which the program's source holds too */
    b.ks_hash = 1469598103934665603ull ^ (uint64_t)order;
    for (size_t i = 0; i < (size_t)order * (size_t)order * sizeof(float); i++) {
        b.ks_hash ^= ((const unsigned char *)b.ks)[i];
        b.ks_hash *= 1099511628211ull;
    }
    for (const char *c = b.cpca_unpack; c && *c; c++) {
        b.ks_hash ^= (unsigned char)*c;
        b.ks_hash *= 1099511628211ull;
    }

    b.variable = (st->flags & VDSH_STREAM_VARIABLE) != 0;
    b.method = (vdsh_method)st->method;

    uint32_t nv = s->vertex_count;
    size_t bytes = 0;
    unsigned char *rec = NULL;
    uint32_t *start = NULL;
    uint8_t *korder = NULL;
    vr_result r = VR_OK;
    if (b.variable) {
        start = malloc((size_t)nv * sizeof *start);
        korder = malloc((size_t)nv + 1);
        r = start && korder && st->orders && st->offsets
                ? variable_records(st, &b, nv, remap, floats, &rec, &bytes, start, korder, name,
                                   err)
                : vr_fail(err, start && korder ? VR_ERR_FORMAT : VR_ERR_OUT_OF_MEMORY,
                          "%s: variable-order stream without its orders", name);
    } else {
        rec = fixed_records(st, &b, nv, remap, floats, &bytes);
        if (!rec)
            r = vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory uploading order %d", name,
                        order);
    }
    GLint max_texels = 0;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_texels);
    size_t texels = bytes / texel_bytes(b.kind);
    if (r == VR_OK && texels > (size_t)max_texels)
        r = vr_fail(err, VR_ERR_GL,
                    "%s: order %d stream: %zu texels, above this GL's "
                    "GL_MAX_TEXTURE_BUFFER_SIZE (%d)",
                    name, order, texels, (int)max_texels);
    float *model = NULL;
    size_t model_bytes = 0;
    if (r == VR_OK && b.kind == VR_BUF_CPCA) {
        model = build_model(st, order, &model_bytes);
        if (!model)
            r = vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory uploading order %d", name,
                        order);
        else if (model_bytes / 16 > (size_t)max_texels)
            r = vr_fail(err, VR_ERR_GL,
                        "%s: order %d cpca model: %zu texels, above this GL's "
                        "GL_MAX_TEXTURE_BUFFER_SIZE (%d)",
                        name, order, model_bytes / 16, (int)max_texels);
    }
    if (r == VR_OK) {
        make_gl(s, &b, rec, bytes, start, korder);
        if (model) {
            glGenBuffers(1, &b.model_buf);
            glBindBuffer(GL_TEXTURE_BUFFER, b.model_buf);
            glBufferData(GL_TEXTURE_BUFFER, (GLsizeiptr)model_bytes, model, GL_STATIC_DRAW);
            glGenTextures(1, &b.model_tex);
            glBindTexture(GL_TEXTURE_BUFFER, b.model_tex);
            glTexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32F, b.model_buf);
            glBindTexture(GL_TEXTURE_BUFFER, 0);
            glBindBuffer(GL_TEXTURE_BUFFER, 0);
            b.bytes += model_bytes;
        }
        r = vr_check_gl(err, name);
        int at_load = model && cpca_decode == VR_CPCA_AT_LOAD;
        if (r == VR_OK && model && (cpca_decode == VR_CPCA_PER_FRAME || at_load))
            r = make_decoder(s, &b, name, err);
        /* decoded here, once: the scratch then holds the same texels every
         * frame, and the records, the model and the decode program are
         * not needed again (36 B per vertex in the room at the default
         * --cpca) */
        if (r == VR_OK && at_load) {
            vr_buffer_decode(s, &b);
            r = vr_check_gl(err, name);
            release_decoded(&b);
            b.bytes -= bytes + model_bytes;
        }
        b.summed =
            (sums == VR_SUMS_COMPUTE || (sums == VR_SUMS_AUTO && model && vr_has_compute())) &&
            !b.variable;
        b.sums_group = b.summed ? sums_group(model && !b.scratch_tex) : 0;
        /* the first frame's program now, so that a GL that cannot build
         * it fails the load */
        if (r == VR_OK && b.summed)
            r = make_summer(s, &b, b.sums_group ? b.sums_group : VR_SUMS_MAX_GROUP, name, err);
    }
    free(model);
    free(rec);
    free(start);
    free(korder);
    if (r != VR_OK) {
        vr_buffer_destroy(&b);
        return r;
    }
    if (b.variable)
        s->variable = b;
    else
        s->buffer[order] = b;
    s->gpu_bytes += b.bytes;
    return VR_OK;
}
