/*
 * vr_scene.c - load a .vdsh (formats/) and upload it with the basis
 * cubemaps it needs, made here (formats/vdsh_cube.h: they depend on their
 * face size alone); the default view is vr_view.c's.
 *
 * Coefficients go to the GPU exactly as stored: f16 streams as
 * GL_HALF_FLOAT attributes, with the stream's scale applied in the shader,
 * so nothing is converted on the CPU and an f16 scene takes half the
 * memory; s8 streams as GL_BYTE attributes read unnormalised (the integer
 * itself, exact) and multiplied in the shader by a uniform per coefficient
 * index, vdsh_s8_step of its scale, so the GPU computes the very products
 * vdsh_stream_decode does. (Normalised bytes would fold the 1/127 into the
 * fetch, but GL before 4.2 maps a signed byte c to (2c + 1) / 255, where 0
 * is not 0: the conversion would depend on the context's version.) Each order's stream gets its own VAO; attribute k of a VAO
 * points at coefficients vr_coef_first[k].. of each vertex (vr_internal.h).
 * Triangles and vertices go up in the order of vr_order_triangles
 * (vr_order.c), not the file's. Streams above order 5 (and with
 * desc->buffers every order) also go up as buffer textures for
 * VR_MODE_VDSH_BUFFER (vr_buffer.c).
 */
#include "vr_internal.h"

#include "vdsh_cube.h"
#include "vdsh_light.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* 1 when f has a stream of `quantity` that the runtime could upload. */
static int has_quantity(const vdsh_file *f, uint32_t quantity)
{
    for (uint32_t i = 0; i < f->stream_count; i++)
        if (f->streams[i].quantity == quantity && f->streams[i].order >= 1 &&
            f->streams[i].order <= VDSH_MAX_ORDER)
            return 1;
    return 0;
}

static vr_result map_vdsh_result(vdsh_result r)
{
    switch (r) {
    case VDSH_ERR_IO: return VR_ERR_IO;
    case VDSH_ERR_OUT_OF_MEMORY: return VR_ERR_OUT_OF_MEMORY;
    case VDSH_ERR_ARGUMENT: return VR_ERR_ARGUMENT;
    default: return VR_ERR_FORMAT;
    }
}

/* The four basis cubemaps of face size n (SH functions 9..24, four per
 * texture): they depend on n alone, so they are made here rather than
 * read. vdsh_cube_basis_face_gl_f16 gives, face by face and already in
 * GL's orientation, the very half floats of the bake's OpenEXR files, so
 * a lookup in direction d returns the basis functions at d. */
static vr_result make_basis(GLuint tex[4], uint32_t n32, const char *name, vr_error *err)
{
    GLint max = 0;
    glGetIntegerv(GL_MAX_CUBE_MAP_TEXTURE_SIZE, &max);
    if (n32 > (uint32_t)max)
        return vr_fail(err, VR_ERR_FORMAT,
                       "%s: cube_size %u is above this GL's largest cube map (%d)", name, n32,
                       (int)max);
    int n = (int)n32;
    size_t face = (size_t)n * (size_t)n * 4;
    uint16_t *buf = malloc(4 * face * sizeof *buf);
    if (!buf)
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory for the basis cubemaps", name);
    uint16_t *const out[4] = {buf, buf + face, buf + 2 * face, buf + 3 * face};
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    for (int f = 0; f < 6; f++) {
        vdsh_cube_basis_face_gl_f16(n, f, out);
        for (int k = 0; k < 4; k++) {
            glBindTexture(GL_TEXTURE_CUBE_MAP, tex[k]);
            glTexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f, 0, GL_RGBA16F, n, n, 0,
                         GL_RGBA, GL_HALF_FLOAT, out[k]);
        }
    }
    free(buf);
    for (int k = 0; k < 4; k++) {
        glBindTexture(GL_TEXTURE_CUBE_MAP, tex[k]);
        glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAX_LEVEL, 0);
    }
    glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
    return VR_OK;
}

void vr_scene_base_attribs(const vr_scene *s)
{
    glBindBuffer(GL_ARRAY_BUFFER, s->vbo_position);
    glVertexAttribPointer(VR_ATTR_POSITION, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), NULL);
    glEnableVertexAttribArray(VR_ATTR_POSITION);
    glBindBuffer(GL_ARRAY_BUFFER, s->vbo_normal);
    glVertexAttribPointer(VR_ATTR_NORMAL, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), NULL);
    glEnableVertexAttribArray(VR_ATTR_NORMAL);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, s->ibo);
}

/* A vertex buffer of n elements of `size` bytes in the GPU order: element
 * i of src goes to remap[i]. Returns 0, or 1 when out of memory. */
static int upload_permuted(GLuint buffer, const void *src, size_t n, size_t size,
                           const uint32_t *remap)
{
    unsigned char *dst = malloc(n * size);
    if (!dst)
        return 1;
    for (size_t i = 0; i < n; i++)
        memcpy(dst + (size_t)remap[i] * size, (const unsigned char *)src + i * size, size);
    glBindBuffer(GL_ARRAY_BUFFER, buffer);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(n * size), dst, GL_STATIC_DRAW);
    free(dst);
    return 0;
}

static vr_result upload_stream(vr_scene *s, const vdsh_stream *st, size_t vertices,
                               const uint32_t *remap, const char *name, vr_error *err)
{
    int order = (int)st->order;
    if (st->encoding > VDSH_ENCODING_S8S6 ||
        (vdsh_encoding_quantised(st->encoding) && !st->coef_scales))
        return vr_fail(err, VR_ERR_FORMAT, "%s: order %d stream: encoding %u cannot be drawn", name,
                       order, st->encoding);
    for (int k = 0; k < 4 * VR_COEF_ATTRIBS; k++)
        s->coef_step[order][k] = 1.0f;
    size_t bpv = vdsh_stream_bytes_per_vertex(st);
    size_t elem = st->encoding == VDSH_ENCODING_F16       ? 2
                  : vdsh_encoding_quantised(st->encoding) ? 1
                                                          : 4;
    glGenBuffers(1, &s->vbo_stream[order]);
    if (upload_permuted(s->vbo_stream[order], st->data, vertices, bpv, remap))
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory uploading order %d", name,
                       order);
    s->gpu_bytes += bpv * vertices;

    glGenVertexArrays(1, &s->vao[order]);
    glBindVertexArray(s->vao[order]);
    vr_scene_base_attribs(s);
    glBindBuffer(GL_ARRAY_BUFFER, s->vbo_stream[order]);
    GLenum type = st->encoding == VDSH_ENCODING_F16       ? GL_HALF_FLOAT
                  : vdsh_encoding_quantised(st->encoding) ? GL_BYTE
                                                          : GL_FLOAT;
    int n = vr_coef_attrib_count(order);
    /* Per coefficient the factor the shader applies (s8, s8s6: the step). */
    for (int k = 0; k < n; k++)
        for (int j = 0; j < vr_coef_size[k] && vr_coef_first[k] + j < order * order; j++) {
            int i = vr_coef_first[k] + j;
            s->coef_step[order][4 * k + j] =
                vdsh_encoding_quantised(st->encoding)
                    ? vdsh_quant_step(st->coef_scales[i],
                                      vdsh_quant_levels(st->encoding, (uint32_t)i))
                    : 1.0f;
        }
    if (st->encoding == VDSH_ENCODING_S8S6) {
        /* Coefficients 0..3 as bytes (attribute 0), then the packed words
         * as integer attributes: words 0..3 at attribute 1, word 4 at 2
         * (the shader unpacks them: vr_glsl.c, PACKED). */
        int bytes = order * order < VDSH_S8S6_BYTES ? order * order : VDSH_S8S6_BYTES;
        int words = (int)((bpv - (size_t)bytes) / 4);
        glVertexAttribPointer(VR_ATTR_COEF0, bytes, GL_BYTE, GL_FALSE, (GLsizei)bpv, NULL);
        glEnableVertexAttribArray(VR_ATTR_COEF0);
        for (int a = 0; a < 2 && words > 4 * a; a++) {
            int size = words - 4 * a < 4 ? words - 4 * a : 4;
            glVertexAttribIPointer(VR_ATTR_COEF0 + 1 + (GLuint)a, size, GL_UNSIGNED_INT,
                                   (GLsizei)bpv,
                                   (const void *)(uintptr_t)(VDSH_S8S6_BYTES + 16 * a));
            glEnableVertexAttribArray(VR_ATTR_COEF0 + 1 + (GLuint)a);
        }
        n = 0;
    }
    for (int k = 0; k < n; k++) {
        int size = vr_coef_size[k];
        /* Order 1 has one coefficient: only the first component. */
        if (vr_coef_first[k] + size > order * order)
            size = order * order - vr_coef_first[k];
        if (size <= 0)
            break;
        glVertexAttribPointer(VR_ATTR_COEF0 + (GLuint)k, size, type, GL_FALSE, (GLsizei)bpv,
                              (const void *)(uintptr_t)((size_t)vr_coef_first[k] * elem));
        glEnableVertexAttribArray(VR_ATTR_COEF0 + (GLuint)k);
    }
    glBindVertexArray(0);
    s->encoding[order] = st->encoding;
    s->method[order] = st->method;
    s->scale[order] = st->scale;
    return VR_OK;
}

/* desc->light_region into m->light_region (region: its storage). */
static vr_result light_region_of(const vr_scene_desc *desc, vdsh_view_mesh *m, float region[6],
                                 const char *name, vr_error *err)
{
    switch (desc->light_region) {
    case VR_LIGHT_REGION_FILE: return VR_OK;
    case VR_LIGHT_REGION_AUTO: m->light_region = NULL; return VR_OK;
    case VR_LIGHT_REGION_BOX: {
        /* from the caller, not a file: the reader's check has not seen it */
        int a = vdsh_light_box_bad_axis(desc->light_box, desc->light_box + 3);
        if (a >= 0)
            return vr_fail(err, VR_ERR_ARGUMENT,
                           "%s: the light region's %c is %g..%g: it must be finite, min "
                           "below max",
                           name, "xyz"[a], (double)(desc->light_box[a]),
                           (double)(desc->light_box[a + 3]));
        memcpy(region, desc->light_box, 6 * sizeof(float));
        m->light_region = region;
        return VR_OK;
    }
    case VR_LIGHT_REGION_GROWN: {
        /* vdsh-bake --light-region grown's box, its probes against the
         * drawn mesh */
        vdsh_view_tracer *t = NULL;
        vdsh_error ve;
        if (vdsh_view_tracer_create(m, &t, &ve) != VDSH_OK)
            return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: light region: %s", name, ve.msg);
        float lo[3], hi[3];
        vdsh_view_bounds(m->positions, m->vertex_count, lo, hi);
        vdsh_view_free_ctx c = {t, vdsh_free_diagonal(lo, hi)};
        vdsh_light_grown_box(lo, hi, vdsh_view_is_free, &c, region, region + 3);
        vdsh_view_tracer_destroy(t);
        m->light_region = region;
        return VR_OK;
    }
    default:
        return vr_fail(err, VR_ERR_ARGUMENT, "%s: unknown light region rule %d", name,
                       desc->light_region);
    }
}

/* The default view (room or object, camera, lights in free space), from
 * the mesh as the file has it (formats/vdsh_scene_view.h) in desc's light
 * region, and the light pool's desc->light_pool lights (none when 0). */
static vr_result default_view(vr_scene *s, const vdsh_file *f, const vr_scene_desc *desc,
                              const char *name, vr_error *err)
{
    float region[6];
    vdsh_view_mesh vm;
    vdsh_view_file_mesh(f, region, &vm);
    vr_result r = light_region_of(desc, &vm, region, name, err);
    if (r != VR_OK)
        return r;
    vdsh_error ve;
    vdsh_result vr = vdsh_view_compute(&vm, &s->view, &ve);
    if (vr != VDSH_OK)
        return vr_fail(err, map_vdsh_result(vr), "%s: %s", name, ve.msg);
    memcpy(s->bounds_min, s->view.bounds_min, sizeof s->bounds_min);
    memcpy(s->bounds_max, s->view.bounds_max, sizeof s->bounds_max);
    return desc->light_pool > 0 ? vr_scene_place_pool(s, &vm, desc->light_pool, name, err) : VR_OK;
}

/* The descriptor's own checks, before a file is read. */
static vr_result check_desc(const vr_scene_desc *desc, const char *name, vr_error *err)
{
    if ((unsigned)desc->quantity > VDSH_QUANTITY_LOG_DISTANCE)
        return vr_fail(err, VR_ERR_ARGUMENT, "%s: unknown quantity %u", name,
                       (unsigned)desc->quantity);
    if (desc->cpca_decode != VR_CPCA_PER_PASS && desc->cpca_decode != VR_CPCA_PER_FRAME &&
        desc->cpca_decode != VR_CPCA_AT_LOAD)
        return vr_fail(
            err, VR_ERR_ARGUMENT,
            "%s: cpca_decode %d is not VR_CPCA_PER_PASS, VR_CPCA_PER_FRAME or VR_CPCA_AT_LOAD",
            name, desc->cpca_decode);
    if (desc->sums != VR_SUMS_AUTO && desc->sums != VR_SUMS_VERTEX && desc->sums != VR_SUMS_COMPUTE)
        return vr_fail(err, VR_ERR_ARGUMENT,
                       "%s: sums %d is not VR_SUMS_AUTO, VR_SUMS_VERTEX or VR_SUMS_COMPUTE", name,
                       desc->sums);
    if (desc->light_pool < 0 || desc->light_pool > VR_MAX_POOL_LIGHTS)
        return vr_fail(err, VR_ERR_ARGUMENT, "%s: light_pool %d not in 0..%d", name,
                       desc->light_pool, VR_MAX_POOL_LIGHTS);
    if (!glGetString(GL_VERSION))
        return vr_fail(err, VR_ERR_GL, "%s: no current GL context", name);
    return VR_OK;
}

/* What a valid file must also be to be drawn: triangles, a whole bake
 * rather than one shard's part, a usable max_distance. */
static vr_result check_drawable(const vdsh_file *f, const char *name, vr_error *err)
{
    const vdsh_header *h = &f->header;
    if (h->vertex_count == 0 || h->triangle_count == 0)
        return vr_fail(err, VR_ERR_FORMAT, "%s: no triangles to draw", name);
    if (f->has_part) /* its streams hold one range's receivers */
        return vr_fail(err, VR_ERR_FORMAT,
                       "%s: a part of a sharded bake (shard %u of %u): "
                       "join the parts with vdsh-merge first",
                       name, f->part.index, f->part.count);
    /* Checked by the reader for a file, not for one from memory: every
     * reconstructed distance is clamped to it. */
    if (!isfinite(h->max_distance) || !(h->max_distance > 0.0f))
        return vr_fail(err, VR_ERR_FORMAT, "%s: max_distance %g must be finite and > 0", name,
                       (double)h->max_distance);
    return VR_OK;
}

/* The quantity to draw: the one asked for, else the file's own (a file
 * baked with --log has only log-distance streams). */
static vdsh_quantity drawn_quantity(const vdsh_file *f, vdsh_quantity asked)
{
    if (!has_quantity(f, asked))
        for (uint32_t i = 0; i < f->stream_count; i++)
            if (f->streams[i].order >= 1 && f->streams[i].order <= VDSH_MAX_ORDER)
                return f->streams[i].quantity;
    return asked;
}

/* Everything per vertex goes up in the order of vr_order_triangles (the
 * same vertices and triangles, arranged for the vertex cache): the GPU's
 * indices and remap, a file vertex's place on the GPU. Both allocated
 * here, freed by the caller, also on failure. */
static vr_result order_vertices(const vdsh_file *f, uint32_t **gpu_indices, uint32_t **remap,
                                const char *name, vr_error *err)
{
    const vdsh_header *h = &f->header;
    *gpu_indices = malloc(3 * (size_t)h->triangle_count * sizeof **gpu_indices);
    *remap = malloc((size_t)h->vertex_count * sizeof **remap);
    if (!*gpu_indices || !*remap)
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
    return vr_order_triangles(f->indices, h->triangle_count, h->vertex_count, *gpu_indices, *remap,
                              name, err);
}

/* Positions, normals and indices in the GPU's order (order_vertices),
 * and vao[0] over them. */
static vr_result upload_geometry(vr_scene *s, const vdsh_file *f, const uint32_t *gpu_indices,
                                 const uint32_t *remap, const char *name, vr_error *err)
{
    size_t nv = f->header.vertex_count, ni = 3 * (size_t)f->header.triangle_count;
    glGenBuffers(1, &s->vbo_position);
    glGenBuffers(1, &s->vbo_normal);
    if (upload_permuted(s->vbo_position, f->positions, nv, 12, remap) ||
        upload_permuted(s->vbo_normal, f->normals, nv, 12, remap))
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
    glGenVertexArrays(1, &s->vao[0]);
    glBindVertexArray(s->vao[0]);
    glGenBuffers(1, &s->ibo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, s->ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(ni * sizeof *gpu_indices), gpu_indices,
                 GL_STATIC_DRAW);
    vr_scene_base_attribs(s);
    glBindVertexArray(0);
    s->gpu_bytes = nv * 24 + (size_t)f->header.triangle_count * 12;
    return VR_OK;
}

/* Vertex attributes: the first fixed-order stream of each order 1..5 in
 * the drawn quantity (not cpca, decoded only from buffer textures). */
static vr_result upload_attribute_streams(vr_scene *s, const vdsh_file *f, const uint32_t *remap,
                                          const char *name, vr_error *err)
{
    vr_result r = VR_OK;
    for (uint32_t i = 0; i < f->stream_count && r == VR_OK; i++) {
        const vdsh_stream *st = &f->streams[i];
        if (st->quantity != s->quantity || st->order < 1 || st->order > 5 ||
            (st->flags & VDSH_STREAM_VARIABLE) || s->vbo_stream[st->order] ||
            st->encoding == VDSH_ENCODING_CPCA)
            continue;
        r = upload_stream(s, st, f->header.vertex_count, remap, name, err);
    }
    return r;
}

/* Buffer textures (VR_MODE_VDSH_BUFFER): what attributes cannot hold or
 * no attribute mode draws (orders 1, 4 and above 5, the stream with an
 * order per vertex, cpca streams of any order: decoded in the vertex
 * stage), and with desc->buffers orders 2, 3 and 5 too; the first stream
 * of each. */
static vr_result upload_buffer_streams(vr_scene *s, const vdsh_file *f, const vr_scene_desc *desc,
                                       const uint32_t *remap, const char *name, vr_error *err)
{
    vr_result r = VR_OK;
    for (uint32_t i = 0; i < f->stream_count && r == VR_OK; i++) {
        const vdsh_stream *st = &f->streams[i];
        int variable = (st->flags & VDSH_STREAM_VARIABLE) != 0;
        if (st->quantity != s->quantity || st->order < 1 || st->order > VDSH_MAX_ORDER ||
            (variable ? s->variable.order != 0
                      : s->buffer[st->order].order ||
                            ((st->order == 2 || st->order == 3 || st->order == 5) &&
                             !desc->buffers && st->encoding != VDSH_ENCODING_CPCA)))
            continue;
        r = vr_buffer_upload(s, st, remap, desc->buffer_floats, desc->cpca_decode, desc->sums, name,
                             err);
        if (!variable && !s->vbo_stream[st->order])
            s->method[st->order] = st->method;
    }
    return r;
}

/* The basis cubemaps of order 5's split path, at the face size the bake
 * chose. */
static vr_result upload_basis(vr_scene *s, uint32_t cube_size, const char *name, vr_error *err)
{
    glGenTextures(4, s->basis);
    vr_result r = make_basis(s->basis, cube_size, name, err);
    if (r != VR_OK)
        return r;
    s->cube_size = (int)cube_size;
    s->gpu_bytes += 4 * 6 * (size_t)s->cube_size * (size_t)s->cube_size * 8;
    return VR_OK;
}

vr_result vr_scene_create(const vr_scene_desc *desc, vr_scene **out, vr_error *err)
{
    if (!desc || !out || (!desc->path && !desc->file))
        return vr_fail(err, VR_ERR_ARGUMENT, "vr_scene_create: no path or file given");
    const char *name = desc->path ? desc->path : "(memory)";
    vr_result r = check_desc(desc, name, err);
    if (r != VR_OK)
        return r;

    /* 1. The file: read and validated by formats/ (every CRC and range). */
    vdsh_file *owned = NULL;
    const vdsh_file *f = desc->file;
    if (!f) {
        vdsh_error ve;
        vdsh_result vr = vdsh_read(desc->path, &owned, &ve);
        if (vr != VDSH_OK)
            return vr_fail(err, map_vdsh_result(vr), "%s", ve.msg);
        f = owned;
    }
    const vdsh_header *h = &f->header;
    vr_scene *s = NULL;
    uint32_t *gpu_indices = NULL, *remap = NULL;
    if ((r = check_drawable(f, name, err)) != VR_OK)
        goto done;

    /* 2. The quantity to draw. */
    vdsh_quantity quantity = drawn_quantity(f, desc->quantity);

    /* 3. The basis cubemaps, when order 5 is drawn with them (the paper's
     * split path; a log-distance stream is summed whole per vertex), at
     * the face size the bake chose (0: none). */
    int want_basis = vdsh_find_stream(f, 5, quantity) &&
                     vdsh_runtime_interp(5, quantity) == VDSH_INTERP_SPLIT && h->cube_size > 0 &&
                     !desc->skip_cubemaps;

    /* 4. The scene: its vertices ordered for the vertex cache, its default
     * view, then everything uploaded. */
    s = calloc(1, sizeof *s);
    if (!s) {
        r = vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
        goto done;
    }
    s->vertex_count = h->vertex_count;
    s->triangle_count = h->triangle_count;
    s->quantity = quantity;
    s->max_distance = h->max_distance;

    r = order_vertices(f, &gpu_indices, &remap, name, err);
    if (r == VR_OK)
        r = default_view(s, f, desc, name, err);
    if (r == VR_OK)
        r = upload_geometry(s, f, gpu_indices, remap, name, err);
    if (r == VR_OK)
        r = upload_attribute_streams(s, f, remap, name, err);
    if (r == VR_OK)
        r = upload_buffer_streams(s, f, desc, remap, name, err);
    if (r == VR_OK && want_basis)
        r = upload_basis(s, h->cube_size, name, err);
    if (r == VR_OK)
        r = vr_sdf_load(s, desc, h->vertex_count, h->triangle_count, err);
    if (r == VR_OK)
        r = vr_check_gl(err, name);

done:
    free(gpu_indices);
    free(remap);
    vdsh_free(owned);
    if (r != VR_OK) {
        vr_scene_destroy(s);
        return r;
    }
    *out = s;
    return VR_OK;
}

void vr_scene_destroy(vr_scene *s)
{
    if (!s)
        return;
    /* glDelete* ignore the name 0, so a half-built scene is fine. */
    glDeleteVertexArrays(6, s->vao);
    glDeleteBuffers(6, s->vbo_stream);
    glDeleteBuffers(1, &s->vbo_position);
    glDeleteBuffers(1, &s->vbo_normal);
    glDeleteBuffers(1, &s->ibo);
    glDeleteTextures(4, s->basis);
    glDeleteTextures(1, &s->sdf_tex);
    for (int o = 0; o < VDSH_ORDER_SLOTS; o++)
        vr_buffer_destroy(&s->buffer[o]);
    vr_buffer_destroy(&s->variable);
    free(s);
}

void vr_scene_get_info(const vr_scene *s, vr_scene_info *out)
{
    vr_scene_info i;
    memset(&i, 0, sizeof i);
    i.vertex_count = s->vertex_count;
    i.triangle_count = s->triangle_count;
    memcpy(i.bounds_min, s->bounds_min, sizeof i.bounds_min);
    memcpy(i.bounds_max, s->bounds_max, sizeof i.bounds_max);
    for (int o = 1; o <= 5; o++) {
        i.has_order[o] = s->vbo_stream[o] != 0;
        i.encoding[o] = s->encoding[o];
        i.scale[o] = s->scale[o];
    }
    i.has_cubemaps = s->basis[0] != 0;
    i.cube_size = s->cube_size;
    i.quantity = s->quantity;
    i.max_distance = s->max_distance;
    i.gpu_bytes = s->gpu_bytes;
    i.has_sdf = s->sdf_tex != 0;
    memcpy(i.sdf_dim, s->sdf.dim, sizeof i.sdf_dim);
    i.sdf_bytes = s->sdf_bytes;
    i.interior = s->view.interior;
    for (int o = 1; o < VDSH_ORDER_SLOTS; o++) {
        i.method[o] = s->method[o];
        i.has_buffer[o] = s->buffer[o].order != 0;
        i.buffer_encoding[o] = s->buffer[o].encoding;
        i.buffer_per_frame[o] = s->buffer[o].decode_prog != 0;
        i.buffer_compute[o] = s->buffer[o].summed;
        i.buffer_bytes += s->buffer[o].bytes;
    }
    i.variable_order = s->variable.order;
    i.variable_mean_order = s->variable.mean_order;
    i.variable_method = s->variable.method;
    i.buffer_bytes += s->variable.bytes;
    *out = i;
}

vr_mode vr_scene_default_mode(const vr_scene *s)
{
    static const vr_mode best_first[5] = {VR_MODE_VDSH5, VR_MODE_VDSH5_POLY, VR_MODE_VDSH3,
                                          VR_MODE_VDSH2, VR_MODE_VDSH_BUFFER};
    for (int i = 0; i < 5; i++)
        if (vr_scene_supports(s, best_first[i]))
            return best_first[i];
    return VR_MODE_VDSH5;
}

int vr_scene_supports(const vr_scene *s, vr_mode m)
{
    switch (m) {
    case VR_MODE_NONE:
    case VR_MODE_CUBE: return 1;
    case VR_MODE_VDSH2: return s->vbo_stream[2] != 0;
    case VR_MODE_VDSH3: return s->vbo_stream[3] != 0;
    case VR_MODE_VDSH5:
        /* the cubemaps only on the paper's split path */
        return s->vbo_stream[5] != 0 &&
               (s->basis[0] != 0 || vr_mode_interp(m, s->quantity) != VDSH_INTERP_SPLIT);
    case VR_MODE_DEFAULT: return vr_scene_supports(s, vr_scene_default_mode(s));
    case VR_MODE_VDSH5_POLY: return s->vbo_stream[5] != 0;
    case VR_MODE_VDSH_BUFFER: return vr_scene_buffer_stream(s, 0) != 0;
    case VR_MODE_SDF: return s->sdf_tex != 0;
    default: return 0;
    }
}

int vr_scene_interp(const vr_scene *s, vr_mode m)
{
    return vr_mode_interp(m == VR_MODE_DEFAULT ? vr_scene_default_mode(s) : m, s->quantity);
}

int vr_scene_buffer_stream(const vr_scene *s, int stream)
{
    if (stream == 0) {
        if (s->variable.order)
            return VR_STREAM_VARIABLE;
        for (int o = VDSH_MAX_ORDER; o >= 1; o--)
            if (s->buffer[o].order)
                return o;
        return 0;
    }
    return vr_scene_buffer(s, stream) ? stream : 0;
}

size_t vr_scene_buffer_bytes(const vr_scene *s, int stream)
{
    const vr_buffer *b = vr_scene_buffer(s, stream);
    return b ? b->bytes : 0;
}

const vr_buffer *vr_scene_buffer(const vr_scene *s, int stream)
{
    if (stream == 0)
        stream = vr_scene_buffer_stream(s, 0);
    if (stream == VR_STREAM_VARIABLE)
        return s->variable.order ? &s->variable : NULL;
    if (stream >= 1 && stream <= VDSH_MAX_ORDER && s->buffer[stream].order)
        return &s->buffer[stream];
    return NULL;
}

const char *vr_scene_mode_label(const vr_scene *s, vr_mode m)
{
    if (m == VR_MODE_DEFAULT)
        m = vr_scene_default_mode(s);
    if (m == VR_MODE_VDSH_BUFFER)
        return vr_mode_label(m);
    if (vr_scene_interp(s, m) != VDSH_INTERP_DISTANCE || s->quantity != VDSH_QUANTITY_LOG_DISTANCE)
        return vr_mode_label(m);
    /* Orders 2, 3 and both order-5 modes: the same per-vertex path. */
    switch (vr_mode_order(m)) {
    case 2: return "VDSH order 2 (4 coeff., log, per-vertex)";
    case 3: return "VDSH order 3 (9 coeff., log, per-vertex)";
    default: return "VDSH order 5 (25 coeff., log, per-vertex)";
    }
}
