/*
 * vdsh_export.c - vdsh-export: a .vdsh as glTF 2.0 binary (.glb), in the
 * layout of formats/GLTF.md: the receiver mesh (POSITION, NORMAL,
 * indices) and each coefficient stream as custom vertex attributes
 * _VDSH<order>_<k> (VEC4, k = 0 .. ceil(order^2 / 4) - 1, the last padded
 * with zeros), normalised int16 with the stream's scale in extras (or
 * float with --float); the bake's method, quantity, order, max distance
 * and source hashes in the mesh's extras.vdsh, and the default view
 * vdsh-view opens the scene with (formats/vdsh_scene_view.h: camera,
 * default lights in free space, interior or object) in extras.vdsh.view,
 * so that the web viewer (runtime/web) starts where vdsh-view does.
 *
 *     vdsh-export scene.vdsh -o scene.glb [--orders 2,3,5] [--float] [--compress] [-q]
 *     vdsh-export scene.vdsh --source scene.gltf -o scene.glb [--compress]  (the source's
 *         own scene: vdsh_export_source.h; formats/GLTF.md; --compress: its VDSH
 *         attributes meshopt-compressed)
 *
 * Errors: a message naming the file and the problem on stderr, exit 1 (2
 * for a usage error); the output is written atomically
 * (formats/vdsh_output.h): a failed export leaves no partial file.
 */
#include <getopt.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <cjson/cJSON.h>
#include <meshoptimizer.h>

#include "vdsh.h"
#include "vdsh_export_source.h"
#include "vdsh_output.h"
#include "vdsh_scene_view.h"
#include "vt_args.h"
#include "vt_cli.h"

typedef struct blob {
    uint8_t *data;
    size_t size, cap;
} blob;

static int blob_put(blob *b, const void *p, size_t n)
{
    if (b->size + n + 4 > b->cap) {
        size_t cap = b->cap ? b->cap : 1 << 20;
        while (cap < b->size + n + 4)
            cap *= 2;
        uint8_t *d = realloc(b->data, cap);
        if (!d)
            return -1;
        b->data = d;
        b->cap = cap;
    }
    memcpy(b->data + b->size, p, n);
    b->size += n;
    return 0;
}

static int blob_align4(blob *b)
{
    static const uint8_t zero[4] = {0};
    return b->size % 4 ? blob_put(b, zero, 4 - b->size % 4) : 0;
}

/* The buffer views, kept until the end: written as they are, or each
 * compressed with meshoptimizer (--compress: EXT_meshopt_compression,
 * ATTRIBUTES for vertex data, TRIANGLES for indices). */
typedef struct pending_view {
    uint8_t *data;
    size_t size, stride; /* stride: bytes per element (index size for indices) */
    int target;
} pending_view;

typedef struct view_list {
    pending_view *v;
    int n, cap;
} view_list;

/* Append a buffer view over `n` bytes at `p` (copied) with elements of
 * `stride` bytes; returns its index or -1. */
static int add_view(view_list *vl, const void *p, size_t n, size_t stride, int target)
{
    if (n == 0)
        return -1;
    if (vl->n == vl->cap) {
        int cap = vl->cap ? 2 * vl->cap : 32;
        pending_view *v = realloc(vl->v, (size_t)cap * sizeof *v);
        if (!v)
            return -1;
        vl->v = v;
        vl->cap = cap;
    }
    uint8_t *d = malloc(n);
    if (!d)
        return -1;
    memcpy(d, p, n);
    vl->v[vl->n] = (pending_view){d, n, stride, target};
    return vl->n++;
}

static void view_list_free(view_list *vl)
{
    for (int i = 0; i < vl->n; i++)
        free(vl->v[i].data);
    free(vl->v);
}

/* The "buffers" array of g: buffer 0 (the blob's size) and, with
 * fallback, buffer 1 of fallback_size bytes that the file does not hold:
 * the meshopt-compressed views' uncompressed form (EXT_meshopt_compression). */
static void add_buffers(cJSON *g, size_t size, int fallback, size_t fallback_size)
{
    cJSON *bufs = cJSON_AddArrayToObject(g, "buffers");
    cJSON *buf = cJSON_CreateObject();
    cJSON_AddNumberToObject(buf, "byteLength", (double)size);
    cJSON_AddItemToArray(bufs, buf);
    if (!fallback)
        return;
    cJSON *fb = cJSON_CreateObject();
    cJSON_AddNumberToObject(fb, "byteLength", (double)fallback_size);
    cJSON_AddBoolToObject(cJSON_AddObjectToObject(cJSON_AddObjectToObject(fb, "extensions"),
                                                  "EXT_meshopt_compression"),
                          "fallback", 1);
    cJSON_AddItemToArray(bufs, fb);
}

/* name in g's array `list` (extensionsUsed, extensionsRequired), made
 * when absent; once. */
static void list_extension(cJSON *g, const char *list, const char *name)
{
    cJSON *l = cJSON_GetObjectItemCaseSensitive(g, list);
    if (!l)
        l = cJSON_AddArrayToObject(g, list);
    cJSON *e;
    cJSON_ArrayForEach(e, l) if (cJSON_IsString(e) && strcmp(e->valuestring, name) == 0) return;
    cJSON_AddItemToArray(l, cJSON_CreateString(name));
}

/* The views into the blob and the JSON: plain, or meshopt-compressed
 * (the views then live in a fallback buffer 1 that holds no bytes; the
 * compressed bytes are buffer 0, the BIN chunk). Returns 0, or -1 out of
 * memory. *raw_size: the uncompressed bytes. */
static int write_views(const view_list *vl, int compress, blob *b, cJSON *views, size_t *raw_size)
{
    size_t raw = 0;
    for (int i = 0; i < vl->n; i++) {
        const pending_view *pv = &vl->v[i];
        cJSON *v = cJSON_CreateObject();
        cJSON_AddItemToArray(views, v);
        raw = (raw + 3) & ~(size_t)3;
        if (!compress) {
            if (blob_align4(b) || blob_put(b, pv->data, pv->size))
                return -1;
            cJSON_AddNumberToObject(v, "buffer", 0);
            cJSON_AddNumberToObject(v, "byteOffset", (double)(b->size - pv->size));
            cJSON_AddNumberToObject(v, "byteLength", (double)pv->size);
            if (pv->target)
                cJSON_AddNumberToObject(v, "target", pv->target);
            raw += pv->size;
            continue;
        }
        const int index = pv->target == 34963;
        const size_t count = pv->size / pv->stride;
        size_t bound =
            index ? meshopt_encodeIndexBufferBound(count, count) /* vertex count <= index count */
                  : meshopt_encodeVertexBufferBound(count, pv->stride);
        uint8_t *enc = malloc(bound);
        if (!enc)
            return -1;
        size_t got;
        if (index) {
            uint32_t *ix = malloc(count * sizeof *ix);
            if (!ix) {
                free(enc);
                return -1;
            }
            for (size_t k = 0; k < count; k++) {
                if (pv->stride == 2) {
                    uint16_t s16;
                    memcpy(&s16, pv->data + 2 * k, 2);
                    ix[k] = s16;
                } else {
                    memcpy(&ix[k], pv->data + 4 * k, 4);
                }
            }
            got = meshopt_encodeIndexBuffer(enc, bound, ix, count);
            free(ix);
        } else {
            got = meshopt_encodeVertexBuffer(enc, bound, pv->data, count, pv->stride);
        }
        if (got == 0 || blob_align4(b) || blob_put(b, enc, got)) {
            free(enc);
            return -1;
        }
        free(enc);
        cJSON_AddNumberToObject(v, "buffer", 1);
        cJSON_AddNumberToObject(v, "byteOffset", (double)raw);
        cJSON_AddNumberToObject(v, "byteLength", (double)pv->size);
        if (!index)
            cJSON_AddNumberToObject(v, "byteStride", (double)pv->stride);
        if (pv->target)
            cJSON_AddNumberToObject(v, "target", pv->target);
        cJSON *x = cJSON_AddObjectToObject(cJSON_AddObjectToObject(v, "extensions"),
                                           "EXT_meshopt_compression");
        cJSON_AddNumberToObject(x, "buffer", 0);
        cJSON_AddNumberToObject(x, "byteOffset", (double)(b->size - got));
        cJSON_AddNumberToObject(x, "byteLength", (double)got);
        cJSON_AddNumberToObject(x, "byteStride", (double)pv->stride);
        cJSON_AddNumberToObject(x, "count", (double)count);
        cJSON_AddStringToObject(x, "mode", index ? "TRIANGLES" : "ATTRIBUTES");
        raw += pv->size;
    }
    *raw_size = (raw + 3) & ~(size_t)3;
    return 0;
}

static int add_accessor(cJSON *accs, int view, int ctype, int normalized, size_t count,
                        const char *type)
{
    cJSON *a = cJSON_CreateObject();
    cJSON_AddNumberToObject(a, "bufferView", view);
    cJSON_AddNumberToObject(a, "componentType", ctype);
    if (normalized)
        cJSON_AddBoolToObject(a, "normalized", 1);
    cJSON_AddNumberToObject(a, "count", (double)count);
    cJSON_AddStringToObject(a, "type", type);
    cJSON_AddItemToArray(accs, a);
    return cJSON_GetArraySize(accs) - 1;
}

/* --source: the source glTF's JSON becomes *root, its buffers (and the
 * images it names by file) the one BIN buffer *b, each primitive the bake
 * reached gets the VDSH attributes of its vertices' receivers (taken from
 * the per-receiver views in vl, named in attrs), the metadata (*vx) goes
 * to the root's extension VDSH_visibility_distance. Returns 0, or 1 after
 * a message. */
#define VDSH_EXT "VDSH_visibility_distance"

/* cJSON prints a number with 15 digits when that is within its epsilon of
 * the value: the source's numbers (matrices, colours) would lose bits.
 * Each non-integer number becomes raw text of the fewest digits (15..17)
 * that read back as the same double. */
static int exact_numbers(cJSON *n)
{
    for (; n; n = n->next) {
        if (cJSON_IsNumber(n) && n->valuedouble != floor(n->valuedouble) &&
            isfinite(n->valuedouble)) {
            char t[40];
            for (int digits = 15; digits <= 17; digits++) {
                snprintf(t, sizeof t, "%.*g", digits, n->valuedouble);
                if (strtod(t, NULL) == n->valuedouble)
                    break;
            }
            char *c = strdup(t);
            if (!c)
                return -1;
            n->type = cJSON_Raw;
            n->valuestring = c;
        }
        if (n->child && exact_numbers(n->child))
            return -1;
    }
    return 0;
}
/* Whether source file `src` is one the bake recorded (formats/VDSH.md,
 * SRCS: size and SHA-256, the file's external buffers included; or the
 * file's bytes alone, as bakes before 2026-11-30 recorded a glTF with
 * external buffers). Matching vertices by position alone took an edited
 * copy of the model (one vertex moved) with a warning that blamed the
 * bake ("unreferenced, or dropped by the bake") and exit 0. */
static int source_recorded(const vdsh_file *f, const vdsh_src *src)
{
    for (uint32_t i = 0; i < f->source_count; i++) {
        const vdsh_source *r = &f->sources[i];
        if ((r->size == src->size && memcmp(r->sha256, src->sha256, 32) == 0) ||
            (r->size == src->file_size && memcmp(r->sha256, src->file_sha256, 32) == 0))
            return 1;
    }
    return 0;
}

/* Whether the source may be exported against f: one the bake recorded,
 * or one whose geometry is the bake's (materials edited since: every
 * vertex at a receiver); else an edited model (a vertex moved or added)
 * whose vertices would silently get no shadows: refused unless
 * allow_mismatch. Returns -1 (refused, after a message), else whether the
 * bake recorded it. */
static int source_accepted(const char *in, const char *path, const vdsh_file *f,
                           const vdsh_src *src, uint64_t vertices, uint64_t matched,
                           int allow_mismatch, int quiet)
{
    if (source_recorded(f, src))
        return 1;
    char names[512] = "";
    for (uint32_t i = 0, at = 0; i < f->source_count && at < sizeof names; i++)
        at += (uint32_t)snprintf(names + at, sizeof names - at, "%s%s (%llu bytes)", i ? ", " : "",
                                 f->sources[i].name, (unsigned long long)f->sources[i].size);
    if (matched == vertices) {
        if (!quiet)
            fprintf(stderr,
                    "vdsh-export: %s: note: not the file %s recorded (%s; this one %llu bytes, "
                    "its SHA-256 other), but every vertex is at a receiver: its geometry is the "
                    "bake's\n",
                    path, in, names, (unsigned long long)src->size);
    } else if (!allow_mismatch || !quiet) {
        fprintf(stderr,
                "vdsh-export: %s: %s: not the file %s was baked from (%s; this one %llu "
                "bytes, its SHA-256 other) and %llu of its %llu vertices are at no receiver: "
                "its geometry was edited; %s\n",
                path, allow_mismatch ? "warning" : "error", in, names,
                (unsigned long long)src->size, (unsigned long long)(vertices - matched),
                (unsigned long long)vertices,
                allow_mismatch ? "exported anyway (--allow-mismatch), their VDSH attributes 0"
                               : "give the glTF it was baked from (--allow-mismatch exports it "
                                 "anyway, those vertices' VDSH attributes 0)");
        if (!allow_mismatch)
            return -1;
    }
    return 0;
}

/* One BIN buffer: the source's buffers one after the other in b, each
 * of its views moved onto it. Returns 0, 1 after a message (a view past
 * its buffer's end) or -1 (out of memory). */
static int join_buffers(const char *path, const vdsh_src *src, blob *b, cJSON *views)
{
    size_t *base = calloc((size_t)src->buffer_count + 1, sizeof *base);
    if (!base)
        return -1;
    for (int i = 0; i < src->buffer_count; i++) {
        if (blob_align4(b)) {
            free(base);
            return -1;
        }
        base[i] = b->size;
        if (blob_put(b, src->buffers[i].data, src->buffers[i].size)) {
            free(base);
            return -1;
        }
    }
    cJSON *v;
    int view_index = 0;
    cJSON_ArrayForEach(v, views)
    {
        int bi = (int)cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(v, "buffer"));
        cJSON *off = cJSON_GetObjectItemCaseSensitive(v, "byteOffset");
        /* A view past its buffer's end (one no primitive uses, which the
         * bake never read) would read the next buffer, or the VDSH
         * attributes, once the buffers are one: refused, as invalid. */
        double vo = cJSON_IsNumber(off) ? off->valuedouble : 0;
        double vl_len = cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(v, "byteLength"));
        if (bi < 0 || bi >= src->buffer_count || !(vo >= 0) || !(vl_len >= 0) ||
            vo + vl_len > (double)src->buffers[bi].size) {
            if (bi < 0 || bi >= src->buffer_count)
                fprintf(stderr,
                        "vdsh-export: %s: bufferView %d names buffer %d, which does not exist: "
                        "not a valid glTF (--source copies every view)\n",
                        path, view_index, bi);
            else
                fprintf(stderr,
                        "vdsh-export: %s: bufferView %d (bytes %.0f..%.0f) does not fit buffer %d "
                        "(%zu bytes): not a valid glTF (--source copies every view)\n",
                        path, view_index, vo, vo + vl_len, bi, src->buffers[bi].size);
            free(base);
            return 1;
        }
        view_index++;
        double o = (cJSON_IsNumber(off) ? off->valuedouble : 0) +
                   (double)base[bi >= 0 && bi < src->buffer_count ? bi : 0];
        cJSON_DeleteItemFromObjectCaseSensitive(v, "byteOffset");
        cJSON_AddNumberToObject(v, "byteOffset", o);
        cJSON_ReplaceItemInObjectCaseSensitive(v, "buffer", cJSON_CreateNumber(0));
    }
    free(base);
    return 0;
}

/* Images named by file: into the BIN (the glb is written elsewhere), each
 * by a new view; one that is not PNG or JPEG, or cannot be read, stays a
 * URI (a note). Returns 0, or -1 (out of memory). */
static int embed_images(const char *path, const vdsh_src *src, cJSON *g, blob *b, cJSON *views,
                        int quiet)
{
    cJSON *img;
    cJSON_ArrayForEach(img, cJSON_GetObjectItemCaseSensitive(g, "images"))
    {
        cJSON *uri = cJSON_GetObjectItemCaseSensitive(img, "uri");
        if (!cJSON_IsString(uri) || strncmp(uri->valuestring, "data:", 5) == 0)
            continue;
        const char *dot = strrchr(uri->valuestring, '.');
        const char *mime = !dot                                                      ? NULL
                           : !strcasecmp(dot, ".png")                                ? "image/png"
                           : (!strcasecmp(dot, ".jpg") || !strcasecmp(dot, ".jpeg")) ? "image/jpeg"
                                                                                     : NULL;
        const char *why = "cannot be read";
        char *p = vdsh_src_file(src, uri->valuestring, &why);
        if (!p && strcmp(why, "out of memory") == 0)
            return -1;
        FILE *fp = p ? fopen(p, "rb") : NULL;
        free(p);
        if (!fp || !mime) {
            if (fp)
                fclose(fp);
            if (!quiet)
                fprintf(stderr,
                        "vdsh-export: %s: image %s %s: kept as a URI relative to the output\n",
                        path, uri->valuestring, fp ? "is neither PNG nor JPEG" : why);
            continue;
        }
        if (blob_align4(b)) {
            fclose(fp);
            return -1;
        }
        size_t start = b->size, got;
        uint8_t chunk[65536];
        while ((got = fread(chunk, 1, sizeof chunk, fp)) > 0)
            if (blob_put(b, chunk, got)) {
                fclose(fp);
                return -1;
            }
        fclose(fp);
        cJSON *nv = cJSON_CreateObject();
        cJSON_AddNumberToObject(nv, "buffer", 0);
        cJSON_AddNumberToObject(nv, "byteOffset", (double)start);
        cJSON_AddNumberToObject(nv, "byteLength", (double)(b->size - start));
        cJSON_AddItemToArray(views, nv);
        cJSON_DeleteItemFromObjectCaseSensitive(img, "uri");
        cJSON_DeleteItemFromObjectCaseSensitive(img, "mimeType"); /* a uri's may have one */
        cJSON_AddNumberToObject(img, "bufferView", cJSON_GetArraySize(views) - 1);
        cJSON_AddStringToObject(img, "mimeType", mime);
    }
    return 0;
}

/* Primitive sp's VDSH attributes (those of attrs, from the per-receiver
 * views in vl): for each of its vertices its receiver's values, a view in
 * nl (numbered after the source's view_base views) and an accessor in
 * the source's accs; its extension says how many vertices matched.
 * Returns 0, or -1 (out of memory). */
static int prim_attributes(const vdsh_src_prim *sp, cJSON *prim, cJSON *accs, const cJSON *my_accs,
                           const view_list *vl, const cJSON *attrs, int view_base, view_list *nl)
{
    cJSON *pattrs = cJSON_GetObjectItemCaseSensitive(prim, "attributes");
    cJSON *a;
    cJSON_ArrayForEach(a, attrs)
    {
        if (strncmp(a->string, "_VDSH", 5) != 0)
            continue;
        cJSON *acc = cJSON_GetArrayItem(my_accs, (int)a->valuedouble);
        const pending_view *pv =
            &vl->v[(int)cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(acc, "bufferView"))];
        uint8_t *d = calloc((size_t)sp->vertex_count + 1, pv->stride);
        if (!d)
            return -1;
        for (uint32_t k = 0; k < sp->vertex_count; k++)
            if (sp->map[k] != UINT32_MAX)
                memcpy(d + (size_t)k * pv->stride, pv->data + (size_t)sp->map[k] * pv->stride,
                       pv->stride);
        int vi = add_view(nl, d, (size_t)sp->vertex_count * pv->stride, pv->stride, 34962);
        free(d);
        if (vi < 0)
            return -1;
        cJSON *na = cJSON_Duplicate(acc, 1);
        cJSON_ReplaceItemInObjectCaseSensitive(na, "bufferView",
                                               cJSON_CreateNumber(view_base + vi));
        cJSON_ReplaceItemInObjectCaseSensitive(na, "count", cJSON_CreateNumber(sp->vertex_count));
        cJSON_AddItemToArray(accs, na);
        cJSON_DeleteItemFromObjectCaseSensitive(pattrs, a->string);
        cJSON_AddNumberToObject(pattrs, a->string, cJSON_GetArraySize(accs) - 1);
    }
    cJSON *ext = cJSON_GetObjectItemCaseSensitive(prim, "extensions");
    if (!ext)
        ext = cJSON_AddObjectToObject(prim, "extensions");
    cJSON_DeleteItemFromObjectCaseSensitive(ext, VDSH_EXT);
    cJSON *pe = cJSON_AddObjectToObject(ext, VDSH_EXT);
    cJSON_AddNumberToObject(pe, "vertices", sp->vertex_count);
    cJSON_AddNumberToObject(pe, "matched", sp->matched);
    return 0;
}

/* The VDSH attributes per primitive instance (prim_attributes); a mesh a
 * second node uses is copied (each instance has its own receivers).
 * Returns 0, or -1 (out of memory). */
static int add_vdsh_attributes(cJSON *g, const cJSON *root, const vdsh_src_prim *prims, int np,
                               const view_list *vl, const cJSON *attrs, const cJSON *views,
                               view_list *nl)
{
    cJSON *meshes = cJSON_GetObjectItemCaseSensitive(g, "meshes");
    cJSON *nodes = cJSON_GetObjectItemCaseSensitive(g, "nodes");
    cJSON *accs = cJSON_GetObjectItemCaseSensitive(g, "accessors");
    const cJSON *my_accs = cJSON_GetObjectItemCaseSensitive(root, "accessors");
    const int nm = cJSON_GetArraySize(meshes), nn = cJSON_GetArraySize(nodes);
    int rc = -1;
    int *node_mesh = malloc(((size_t)nn + 1) * sizeof *node_mesh);
    int *mesh_node = malloc(((size_t)nm + 1) * sizeof *mesh_node);
    cJSON **orig = calloc((size_t)nm + 1, sizeof *orig);
    int orig_n = 0;
    if (!node_mesh || !mesh_node || !orig)
        goto out;
    for (int i = 0; i < nn; i++)
        node_mesh[i] = -1;
    for (int i = 0; i < nm; i++) {
        mesh_node[i] = -1;
        orig[i] = cJSON_Duplicate(cJSON_GetArrayItem(meshes, i), 1);
    }
    orig_n = nm;
    const int view_base = cJSON_GetArraySize(views);
    for (int i = 0; i < np; i++) {
        const vdsh_src_prim *sp = &prims[i];
        int mi = node_mesh[sp->node];
        if (mi < 0) {
            if (mesh_node[sp->mesh] < 0) {
                mi = sp->mesh;
                mesh_node[mi] = sp->node;
            } else {
                cJSON_AddItemToArray(meshes, cJSON_Duplicate(orig[sp->mesh], 1));
                mi = cJSON_GetArraySize(meshes) - 1;
                cJSON_ReplaceItemInObjectCaseSensitive(cJSON_GetArrayItem(nodes, sp->node), "mesh",
                                                       cJSON_CreateNumber(mi));
            }
            node_mesh[sp->node] = mi;
        }
        cJSON *prim = cJSON_GetArrayItem(
            cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(meshes, mi), "primitives"),
            sp->prim);
        if (prim_attributes(sp, prim, accs, my_accs, vl, attrs, view_base, nl))
            goto out;
    }
    rc = 0;
out:
    for (int i = 0; i < orig_n; i++)
        cJSON_Delete(orig[i]);
    free(orig);
    free(node_mesh);
    free(mesh_node);
    return rc;
}

/* The new views after the source's in b (--compress: meshopt-compressed,
 * lossless, living in a fallback buffer 1 without bytes; the source's own
 * views, images and geometry stay as they are: no quantisation, the
 * source's positions are kept bit for bit), the buffers, the metadata *vx
 * (taken) with the vertex counts as the root's extension, the
 * generator. Returns 0, or -1 (out of memory). */
static int finish_source(cJSON *g, blob *b, const view_list *nl, cJSON *views, int compress,
                         cJSON **vx, uint64_t vertices, uint64_t matched)
{
    size_t raw = 0;
    if (write_views(nl, compress, b, views, &raw) || blob_align4(b))
        return -1;
    cJSON_DeleteItemFromObjectCaseSensitive(g, "buffers");
    add_buffers(g, b->size, compress && nl->n > 0, raw);
    if (compress && nl->n > 0) {
        list_extension(g, "extensionsUsed", "EXT_meshopt_compression");
        list_extension(g, "extensionsRequired", "EXT_meshopt_compression");
    }
    cJSON_AddNumberToObject(*vx, "source_vertices", (double)vertices);
    cJSON_AddNumberToObject(*vx, "source_vertices_matched", (double)matched);
    cJSON *gext = cJSON_GetObjectItemCaseSensitive(g, "extensions");
    if (!gext)
        gext = cJSON_AddObjectToObject(g, "extensions");
    cJSON_DeleteItemFromObjectCaseSensitive(gext, VDSH_EXT);
    cJSON_AddItemToObject(gext, VDSH_EXT, *vx);
    *vx = NULL;
    list_extension(g, "extensionsUsed", VDSH_EXT);
    cJSON *asset = cJSON_GetObjectItemCaseSensitive(g, "asset");
    if (asset) {
        cJSON_DeleteItemFromObjectCaseSensitive(asset, "generator");
        cJSON_AddStringToObject(asset, "generator", "vdsh-export --source (formats/GLTF.md)");
    }
    return 0;
}

static int with_source(const char *in, const char *path, const vdsh_file *f, cJSON *root,
                       view_list *vl, cJSON *attrs, cJSON **vx, blob *b, int compress,
                       int allow_mismatch, int quiet)
{
    char msg[1024];
    vdsh_src src;
    vdsh_src_prim *prims = NULL;
    int np = 0, rc = 1, r;
    view_list nl = {0};
    if (vdsh_src_load(path, &src, msg, sizeof msg) ||
        vdsh_src_map(path, &src, f->positions, f->normals, f->header.vertex_count, &prims, &np, msg,
                     sizeof msg)) {
        fprintf(stderr, "vdsh-export: %s\n", msg);
        return 1;
    }
    cJSON *g = src.json;
    uint64_t vertices = 0, matched = 0;
    for (int i = 0; i < np; i++)
        vertices += prims[i].vertex_count, matched += prims[i].matched;
    if (np == 0 || matched == 0) {
        fprintf(
            stderr,
            "vdsh-export: %s: no vertex of %s is at a receiver of the bake: not the glTF it was baked "
            "from\n",
            in, path);
        goto out;
    }
    const int recorded =
        source_accepted(in, path, f, &src, vertices, matched, allow_mismatch, quiet);
    if (recorded < 0)
        goto out;
    cJSON *views = cJSON_GetObjectItemCaseSensitive(g, "bufferViews");
    if (!views)
        views = cJSON_AddArrayToObject(g, "bufferViews");
    if ((r = join_buffers(path, &src, b, views)) > 0)
        goto out;
    if (r < 0 || embed_images(path, &src, g, b, views, quiet) ||
        add_vdsh_attributes(g, root, prims, np, vl, attrs, views, &nl) ||
        finish_source(g, b, &nl, views, compress, vx, vertices, matched))
        goto oom;
    if (f->source_count > 1 && !quiet)
        fprintf(stderr,
                "vdsh-export: %s: baked from %u meshes; the glb holds %s's scene only (the "
                "other meshes' receivers are not in it)\n",
                in, f->source_count, path);
    if (matched < vertices && recorded && !quiet)
        fprintf(stderr,
                "vdsh-export: %s: %llu of %llu source vertices have no receiver at their position "
                "(unreferenced, or dropped by the bake): their VDSH attributes are 0\n",
                path, (unsigned long long)(vertices - matched), (unsigned long long)vertices);
    if (exact_numbers(g->child))
        goto oom;
    /* root becomes the source's JSON */
    cJSON *child = root->child;
    root->child = g->child;
    g->child = child;
    rc = 0;
    goto out;
oom:
    fprintf(stderr, "vdsh-export: %s: out of memory\n", path);
out:
    for (int i = 0; i < np; i++)
        free(prims[i].map);
    free(prims);
    view_list_free(&nl);
    vdsh_src_free(&src);
    return rc;
}

/* The metadata of stream s common to both layouts (formats/GLTF.md). */
static cJSON *stream_entry(const vdsh_stream *s, const char *prefix, uint32_t groups)
{
    cJSON *so = cJSON_CreateObject();
    cJSON_AddNumberToObject(so, "order", s->order);
    cJSON_AddStringToObject(so, "attribute_prefix", prefix);
    cJSON_AddNumberToObject(so, "attributes", groups);
    cJSON_AddStringToObject(so, "method", vdsh_method_name(s->method));
    cJSON_AddNumberToObject(so, "method_param", s->method_param);
    cJSON_AddStringToObject(so, "quantity", vdsh_quantity_name(s->quantity));
    cJSON_AddNumberToObject(so, "quantity_param", s->quantity_param);
    cJSON_AddStringToObject(so, "window", vdsh_window_name(s->window));
    cJSON_AddNumberToObject(so, "window_param", s->window_param);
    cJSON_AddStringToObject(so, "source_encoding", vdsh_encoding_name(s->encoding));
    return so;
}

/* A cpca stream as stored (formats/GLTF.md "cpca streams"): per vertex
 * the cluster index (<prefix>C, VEC4 unsigned byte, x) and the weight
 * levels (<prefix>W<k>, VEC4 byte, levels 4k..4k+3, 0 past B; with bits 0
 * each vector's width in "widths"); the model
 * (steps, means, bases as f32) in one buffer view named by the stream's
 * extras. tmp: room for nv * 4 bytes. Returns 0, or -1 out of memory. */
static int export_cpca(const vdsh_stream *s, uint32_t nv, const char *prefix, view_list *vl,
                       cJSON *accs, cJSON *attrs, cJSON *streams, float *tmp)
{
    const vdsh_cpca *m = &s->cpca;
    const size_t K = m->clusters, B = m->basis, nc = (size_t)s->order * s->order;
    const uint32_t wgroups = (m->basis + 3) / 4;
    size_t floats = K * B + K * nc + K * B * nc;
    float *model = malloc(floats * sizeof *model);
    int32_t levels[VDSH_MAX_COEFFS];
    if (!model)
        return -1;
    for (size_t i = 0; i < K * B; i++)
        model[i] = vdsh_cpca_step(m->scales[i], vdsh_cpca_width(m, (uint32_t)(i % B)));
    for (size_t i = 0; i < K * nc; i++)
        model[K * B + i] = vdsh_f32_from_f16(m->means[i]);
    for (size_t i = 0; i < K * B * nc; i++)
        model[K * B + K * nc + i] = vdsh_cpca_basis_value(m, i);
    int mview = add_view(vl, model, floats * sizeof *model, 4, 0);
    free(model);
    if (mview < 0)
        return -1;
    cJSON *so = stream_entry(s, prefix, 0);
    cJSON_AddBoolToObject(so, "variable_order", 0);
    cJSON_AddStringToObject(so, "component", "cpca");
    cJSON_AddNumberToObject(so, "scale", 1.0);
    cJSON *cp = cJSON_AddObjectToObject(so, "cpca");
    char name[48];
    cJSON_AddNumberToObject(cp, "clusters", (double)K);
    cJSON_AddNumberToObject(cp, "basis", (double)B);
    cJSON_AddNumberToObject(cp, "bits", m->bits);
    if (!m->bits) { /* a width per basis vector (formats/GLTF.md) */
        cJSON *wa = cJSON_AddArrayToObject(cp, "widths");
        for (uint32_t j = 0; j < m->basis; j++)
            cJSON_AddItemToArray(wa, cJSON_CreateNumber(m->widths[j]));
    }
    snprintf(name, sizeof name, "%sC", prefix);
    cJSON_AddStringToObject(cp, "cluster_attribute", name);
    snprintf(name, sizeof name, "%sW", prefix);
    cJSON_AddStringToObject(cp, "weight_prefix", name);
    cJSON_AddNumberToObject(cp, "weight_attributes", wgroups);
    cJSON_AddNumberToObject(cp, "model_view", mview);
    cJSON_AddNumberToObject(cp, "steps_offset", 0);
    cJSON_AddNumberToObject(cp, "means_offset", (double)(4 * K * B));
    cJSON_AddNumberToObject(cp, "bases_offset", (double)(4 * (K * B + K * nc)));
    cJSON_AddItemToArray(streams, so);

    uint8_t *u = (uint8_t *)tmp;
    memset(u, 0, (size_t)nv * 4);
    for (uint32_t v = 0; v < nv; v++)
        u[4 * (size_t)v] = (uint8_t)vdsh_cpca_cluster(s, v);
    int view = add_view(vl, u, (size_t)nv * 4, 4, 34962);
    if (view < 0)
        return -1;
    snprintf(name, sizeof name, "%sC", prefix);
    cJSON_AddNumberToObject(attrs, name, add_accessor(accs, view, 5121, 0, nv, "VEC4"));
    for (uint32_t g = 0; g < wgroups; g++) {
        int8_t *q = (int8_t *)tmp;
        for (uint32_t v = 0; v < nv; v++) {
            vdsh_cpca_weights(s, v, levels, NULL);
            for (uint32_t k = 0; k < 4; k++)
                q[4 * (size_t)v + k] = (int8_t)(4 * g + k < B ? levels[4 * g + k] : 0);
        }
        view = add_view(vl, q, (size_t)nv * 4, 4, 34962);
        if (view < 0)
            return -1;
        snprintf(name, sizeof name, "%sW%u", prefix, g);
        cJSON_AddNumberToObject(attrs, name, add_accessor(accs, view, 5120, 0, nv, "VEC4"));
    }
    return 0;
}

static void usage(FILE *fp)
{
    fprintf(fp,
            "usage: vdsh-export [options] IN.vdsh -o OUT.glb\n"
            "Write a .vdsh as glTF 2.0 binary (layout: formats/GLTF.md): the receiver mesh and\n"
            "each SH stream as vertex attributes _VDSH<order>_<k> (VEC4).\n"
            "\n"
            "  -o, --output FILE  the .glb to write (atomically)\n"
            "      --orders LIST  orders to export, each 1..%d (default: every stream of the\n"
            "                     file)\n"
            "      --float        coefficients as float (default: normalised int16, scale in\n"
            "                     extras)\n"
            "      --decode-cpca  cpca streams (vdsh-bake --encoding cpca) as decoded\n"
            "                     coefficients in the layout above (default: as stored,\n"
            "                     cluster and weight attributes and the model in a buffer\n"
            "                     view; always decoded with --source)\n"
            "      --compress     a compact glb: positions uint16 and normals int8\n"
            "                     (KHR_mesh_quantization), every buffer view compressed with\n"
            "                     meshoptimizer (EXT_meshopt_compression; lossless: the\n"
            "                     coefficients and indices decode bit-exact); with\n"
            "                     --source: the VDSH attributes compressed, the source's own\n"
            "                     data kept as it is\n"
            "      --source FILE  the glTF the .vdsh was baked from: write its own scene (nodes,\n"
            "                     meshes, materials, textures, UVs...) with the VDSH attributes\n"
            "                     added to each primitive (formats/GLTF.md); a file other\n"
            "                     than the one the bake recorded (size and SHA-256) is taken\n"
            "                     when every vertex is at a receiver (edited materials),\n"
            "                     else refused (edited geometry)\n"
            "      --allow-mismatch  --source: export edited geometry anyway (with a\n"
            "                     warning), vertices at no receiver getting 0\n"
            "  -q, --quiet        nothing on stderr but errors (no summary, notes or\n"
            "                     warnings)\n"
            "  -h, --help         this text\n"
            "  -V, --version      version\n"
            "\n"
            "Exit status: 0 success, 1 error, 2 usage error.\n"
            "Example: vdsh-export room.vdsh -o room.glb\n",
            VDSH_MAX_ORDER);
}

/* ---- the command line ------------------------------------------------------------ */

typedef struct options {
    const char *in, *out, *source;
    int want[VDSH_ORDER_SLOTS], any_order; /* --orders, each time adding to the set */
    int use_float, quiet, compress, decode_cpca, allow_mismatch;
} options;

/* -1 with *o ready to run, else the exit status (help, version, a usage
 * error: said). */
static int parse_args(int argc, char **argv, options *o)
{
    static const struct option longopts[] = {{"output", required_argument, 0, 'o'},
                                             {"orders", required_argument, 0, 'O'},
                                             {"float", no_argument, 0, 'F'},
                                             {"compress", no_argument, 0, 'C'},
                                             {"decode-cpca", no_argument, 0, 'D'},
                                             {"source", required_argument, 0, 'S'},
                                             {"allow-mismatch", no_argument, 0, 'M'},
                                             {"quiet", no_argument, 0, 'q'},
                                             VT_CLI_LONGOPTS_END};
    memset(o, 0, sizeof *o);
    int opt, set[VDSH_ORDER_SLOTS];
    while ((opt = getopt_long(argc, argv, "o:qhV", longopts, NULL)) != -1) {
        switch (opt) {
        case 'o':
            if (!vt_opt_once("-o", optarg, &o->out))
                return VT_EXIT_USAGE;
            break;
        case 'O':
            if (!vt_parse_orders(optarg, 0, VDSH_MAX_ORDER, set))
                return vt_usage_error("vdsh-export",
                                      "--orders takes orders 1..%d such as "
                                      "2,3,5, not '%s'",
                                      VDSH_MAX_ORDER, optarg);
            for (int k = 1; k <= VDSH_MAX_ORDER; k++)
                if (set[k])
                    o->want[k] = o->any_order = 1;
            break;
        case 'F': o->use_float = 1; break;
        case 'C': o->compress = 1; break;
        case 'D': o->decode_cpca = 1; break;
        case 'M': o->allow_mismatch = 1; break;
        case 'S':
            if (!vt_opt_once("--source", optarg, &o->source))
                return VT_EXIT_USAGE;
            break;
        case 'q': o->quiet = 1; break;
        case 'h': usage(stdout); return 0;
        case 'V': return vt_cli_version(NULL);
        default: return vt_cli_try_help();
        }
    }
    o->in = vt_arg_vdsh(argc, argv, optind, NULL, 0);
    if (!o->in)
        return VT_EXIT_USAGE;
    if (!o->out)
        return vt_usage_error("vdsh-export", "%s", "no output: give -o OUT.glb");
    size_t n = strlen(o->out);
    if (n >= 5 && strcasecmp(o->out + n - 5, ".gltf") == 0) /* JSON text, not what it writes */
        return vt_usage_error("vdsh-export",
                              "-o %s: the file is binary glTF (a .glb); a .gltf is JSON text "
                              "that glTF readers would refuse: name it .glb",
                              o->out);
    return -1;
}

/* ---- the steps of an export ------------------------------------------------------------
 * Each returns 0, 1 after a message, or -1 out of memory (run says it). */

/* What an export builds, freed by exporter_free (also half-built). */
typedef struct exporter {
    const options *o;
    const vdsh_file *f;
    uint32_t nv, nt;
    blob b;               /* the BIN chunk */
    view_list vl;         /* the buffer views, written at the end */
    uint32_t *tri_sorted; /* --compress: the triangles in vertex cache order */
    cJSON *root, *views, *accs;
    cJSON *attrs;       /* the primitive's attributes, until the mesh takes them */
    cJSON *vx;          /* extras.vdsh, until the mesh (or the source) takes it */
    float *tmp, *coef;  /* scratch: 16 floats a vertex; one vertex's coefficients */
    int ind_acc;        /* the indices' accessor */
    float lo[3], hi[3]; /* the positions' bounds */
    double qstep;       /* --compress: the positions' quantisation step */
    int exported;       /* streams written */
} exporter;

static int exporter_begin(exporter *e, const options *o, const vdsh_file *f)
{
    memset(e, 0, sizeof *e);
    e->o = o;
    e->f = f;
    e->nv = f->header.vertex_count;
    e->nt = f->header.triangle_count;
    e->root = cJSON_CreateObject();
    cJSON *asset = cJSON_AddObjectToObject(e->root, "asset");
    cJSON_AddStringToObject(asset, "version", "2.0");
    cJSON_AddStringToObject(asset, "generator", "vdsh-export (formats/GLTF.md)");
    e->views = cJSON_AddArrayToObject(e->root, "bufferViews");
    e->accs = cJSON_AddArrayToObject(e->root, "accessors");
    e->attrs = cJSON_CreateObject();
    e->vx = cJSON_CreateObject();
    cJSON_AddNumberToObject(e->vx, "format", 1);
    e->tmp = malloc((size_t)e->nv * 4 * sizeof(float) * 4 + 16);
    e->coef = malloc(sizeof(float) * 256);
    return e->tmp && e->coef ? 0 : -1;
}

static void exporter_free(exporter *e)
{
    cJSON_Delete(e->root);
    cJSON_Delete(e->attrs);
    cJSON_Delete(e->vx);
    free(e->b.data);
    view_list_free(&e->vl);
    free(e->tri_sorted);
    free(e->tmp);
    free(e->coef);
}

/* Indices: uint16 when they fit, else uint32. --compress: the triangles
 * in meshoptimizer's vertex cache order first (its index codec needs
 * that: in the bake's order they grow by 16 %; reordered, the room's
 * shrink to about a quarter); the vertices keep their order, vertex i
 * is receiver i of the .vdsh as in the plain export. */
static int put_indices(exporter *e)
{
    const uint32_t nv = e->nv, nt = e->nt;
    const uint32_t *tri = e->f->indices;
    if (e->o->compress) {
        e->tri_sorted = malloc((size_t)nt * 12 + 4);
        if (!e->tri_sorted)
            return -1;
        meshopt_optimizeVertexCache(e->tri_sorted, e->f->indices, 3 * (size_t)nt, nv);
        tri = e->tri_sorted;
    }
    if (nv <= 65535) {
        uint16_t *buf = malloc((size_t)nt * 6 + 2);
        if (!buf)
            return -1;
        for (size_t j = 0; j < 3 * (size_t)nt; j++)
            buf[j] = (uint16_t)tri[j];
        int v = add_view(&e->vl, buf, (size_t)nt * 6, 2, 34963);
        free(buf);
        e->ind_acc = add_accessor(e->accs, v, 5123, 0, 3 * (size_t)nt, "SCALAR");
    } else {
        int v = add_view(&e->vl, tri, (size_t)nt * 12, 4, 34963);
        e->ind_acc = add_accessor(e->accs, v, 5125, 0, 3 * (size_t)nt, "SCALAR");
    }
    return 0;
}

/* Positions with their bounds; --compress: uint16 (KHR_mesh_quantization,
 * as gltfpack writes it: byteStride 8), dequantised by the node's
 * transform (one scale for the three axes, so normals stay right; a
 * translation), at most half a step (extent / 131070) from the float. */
static int put_positions(exporter *e)
{
    const vdsh_file *f = e->f;
    const uint32_t nv = e->nv;
    float *lo = e->lo, *hi = e->hi;
    for (int k = 0; k < 3; k++)
        lo[k] = INFINITY, hi[k] = -INFINITY;
    for (size_t i = 0; i < nv; i++)
        for (int k = 0; k < 3; k++) {
            float p = f->positions[3 * i + (size_t)k];
            lo[k] = p < lo[k] ? p : lo[k];
            hi[k] = p > hi[k] ? p : hi[k];
        }
    int v, a;
    double dlo[3] = {lo[0], lo[1], lo[2]}, dhi[3] = {hi[0], hi[1], hi[2]};
    if (e->o->compress) {
        double ext = 0, qstep;
        for (int k = 0; k < 3; k++)
            ext = dhi[k] - dlo[k] > ext ? dhi[k] - dlo[k] : ext;
        qstep = e->qstep = ext > 0 ? ext / 65535 : 1;
        uint16_t *q = (uint16_t *)e->tmp;
        for (size_t i = 0; i < nv; i++) {
            for (int k = 0; k < 3; k++) {
                long r = lrint((f->positions[3 * i + (size_t)k] - dlo[k]) / qstep);
                q[4 * i + (size_t)k] = (uint16_t)(r < 0 ? 0 : r > 65535 ? 65535 : r);
            }
            q[4 * i + 3] = 0;
        }
        for (int k = 0; k < 3; k++) {
            long l = lrint((dhi[k] - dlo[k]) / qstep);
            dlo[k] = 0;
            dhi[k] = (double)(l > 65535 ? 65535 : l);
        }
        /* the bounds of the stored integers */
        for (int k = 0; k < 3; k++) {
            uint16_t mn = 65535, mx = 0;
            for (size_t i = 0; i < nv; i++) {
                uint16_t c = q[4 * i + (size_t)k];
                mn = c < mn ? c : mn;
                mx = c > mx ? c : mx;
            }
            dlo[k] = mn, dhi[k] = mx;
        }
        v = add_view(&e->vl, q, (size_t)nv * 8, 8, 34962);
        a = add_accessor(e->accs, v, 5123, 0, nv, "VEC3");
    } else {
        v = add_view(&e->vl, f->positions, (size_t)nv * 12, 12, 34962);
        a = add_accessor(e->accs, v, 5126, 0, nv, "VEC3");
    }
    if (v < 0)
        return -1;
    cJSON *acc = cJSON_GetArrayItem(e->accs, a);
    cJSON_AddItemToObject(acc, "min", cJSON_CreateDoubleArray(dlo, 3));
    cJSON_AddItemToObject(acc, "max", cJSON_CreateDoubleArray(dhi, 3));
    cJSON_AddNumberToObject(e->attrs, "POSITION", a);
    return 0;
}

/* Normals: unit; an undefined (0,0,0) one is written as (0,0,1) and
 * counted in extras (glTF requires unit normals). */
static int put_normals(exporter *e)
{
    const uint32_t nv = e->nv;
    const int compress = e->o->compress;
    float *tmp = e->tmp;
    uint32_t undefined = 0;
    for (size_t i = 0; i < nv; i++) {
        const float *n = e->f->normals + 3 * i;
        double l = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        if (l < 1e-6) {
            tmp[3 * i] = 0, tmp[3 * i + 1] = 0, tmp[3 * i + 2] = 1;
            undefined++;
        } else {
            for (int k = 0; k < 3; k++)
                tmp[3 * i + (size_t)k] = (float)(n[k] / l);
        }
    }
    int v;
    if (compress) { /* normalised int8 (KHR_mesh_quantization), byteStride 4 */
        int8_t *q = (int8_t *)(tmp + 3 * (size_t)nv);
        for (size_t i = 0; i < nv; i++) {
            for (int k = 0; k < 3; k++)
                q[4 * i + (size_t)k] = (int8_t)lrintf(tmp[3 * i + (size_t)k] * 127.0f);
            q[4 * i + 3] = 0;
        }
        v = add_view(&e->vl, q, (size_t)nv * 4, 4, 34962);
    } else {
        v = add_view(&e->vl, tmp, (size_t)nv * 12, 12, 34962);
    }
    if (v < 0)
        return -1;
    cJSON_AddNumberToObject(e->attrs, "NORMAL",
                            add_accessor(e->accs, v, compress ? 5120 : 5126, compress, nv, "VEC3"));
    cJSON_AddNumberToObject(e->vx, "undefined_normals", undefined);
    return 0;
}

/* extras.vdsh: the bake's parameters, the default view and the sources. */
static int describe_bake(exporter *e)
{
    const vdsh_file *f = e->f;
    cJSON *vx = e->vx;
    cJSON_AddNumberToObject(vx, "vertex_count", e->nv);
    cJSON_AddNumberToObject(vx, "triangle_count", e->nt);
    cJSON_AddNumberToObject(vx, "max_distance", f->header.max_distance);
    cJSON_AddNumberToObject(vx, "max_edge", f->header.max_edge);
    cJSON_AddNumberToObject(vx, "rays", f->header.rays);
    cJSON_AddNumberToObject(vx, "seed", (double)f->header.seed);
    /* The default view: vdsh-view's camera and lights (one definition,
     * formats/vdsh_scene_view.h), from the same mesh. */
    {
        float region[6];
        vdsh_view_mesh vm;
        vdsh_view_file_mesh(f, region, &vm);
        vdsh_view view;
        vdsh_error ve;
        if (vdsh_view_compute(&vm, &view, &ve) != VDSH_OK) {
            fprintf(stderr, "vdsh-export: %s: the default view: %s\n", e->o->in, ve.msg);
            return 1;
        }
        cJSON *vo = cJSON_AddObjectToObject(vx, "view");
        double eye[3], t[3], u[3];
        for (int k = 0; k < 3; k++)
            eye[k] = view.camera.eye[k], t[k] = view.camera.target[k], u[k] = view.camera.up[k];
        if (u[0] == 0 && u[1] == 0 && u[2] == 0)
            u[1] = 1;
        cJSON_AddBoolToObject(vo, "interior", view.interior);
        cJSON_AddNumberToObject(vo, "front_share", view.front_share);
        cJSON_AddItemToObject(vo, "eye", cJSON_CreateDoubleArray(eye, 3));
        cJSON_AddItemToObject(vo, "target", cJSON_CreateDoubleArray(t, 3));
        cJSON_AddItemToObject(vo, "up", cJSON_CreateDoubleArray(u, 3));
        cJSON_AddNumberToObject(vo, "fov_y", view.camera.fov_y > 0 ? view.camera.fov_y : 60);
        cJSON *ls = cJSON_AddArrayToObject(vo, "lights");
        cJSON *fr = cJSON_AddArrayToObject(vo, "lights_free");
        for (int i = 0; i < view.light_count; i++) {
            double l[3] = {view.lights[i][0], view.lights[i][1], view.lights[i][2]};
            cJSON_AddItemToArray(ls, cJSON_CreateDoubleArray(l, 3));
            cJSON_AddItemToArray(fr, cJSON_CreateBool(view.light_free[i]));
        }
    }
    cJSON *srcs = cJSON_AddArrayToObject(vx, "sources");
    for (uint32_t s = 0; s < f->source_count; s++) {
        cJSON *o = cJSON_CreateObject();
        char hex[65];
        for (int k = 0; k < 32; k++)
            snprintf(hex + 2 * k, 3, "%02x", f->sources[s].sha256[k]);
        cJSON_AddStringToObject(o, "name", f->sources[s].name);
        cJSON_AddNumberToObject(o, "size", (double)f->sources[s].size);
        cJSON_AddStringToObject(o, "sha256", hex);
        cJSON_AddItemToArray(srcs, o);
    }
    return 0;
}

/* One stream's coefficients as groups of four: float, or int16
 * normalised by the stream's largest magnitude (its "scale"). */
static int put_coefficients(exporter *e, const vdsh_stream *s, const char *prefix, cJSON *streams)
{
    const uint32_t nv = e->nv, nc = s->order * s->order, groups = (nc + 3) / 4;
    const int use_float = e->o->use_float;
    float *tmp = e->tmp, *coef = e->coef;
    double maxabs = 0;
    for (uint32_t v = 0; v < nv; v++) {
        vdsh_stream_decode(s, v, coef);
        for (uint32_t c = 0; c < nc; c++)
            maxabs = fabs(coef[c]) > maxabs ? fabs(coef[c]) : maxabs;
    }
    const double scale = maxabs > 0 ? maxabs : 1.0;
    cJSON *so = stream_entry(s, prefix, groups);
    /* an order per vertex (vdsh-bake --adaptive-order): coefficients
     * past a vertex's own order are exported as 0 */
    cJSON_AddBoolToObject(so, "variable_order", (s->flags & VDSH_STREAM_VARIABLE) != 0);
    cJSON_AddStringToObject(so, "component", use_float ? "float" : "int16_normalized");
    cJSON_AddNumberToObject(so, "scale", use_float ? 1.0 : scale);
    cJSON_AddItemToArray(streams, so);
    for (uint32_t g = 0; g < groups; g++) {
        size_t bytes;
        if (use_float) {
            for (uint32_t v = 0; v < nv; v++) {
                vdsh_stream_decode(s, v, coef);
                for (uint32_t k = 0; k < 4; k++)
                    tmp[4 * (size_t)v + k] = 4 * g + k < nc ? coef[4 * g + k] : 0.0f;
            }
            bytes = (size_t)nv * 16;
        } else {
            int16_t *q = (int16_t *)tmp;
            for (uint32_t v = 0; v < nv; v++) {
                vdsh_stream_decode(s, v, coef);
                for (uint32_t k = 0; k < 4; k++) {
                    double c = 4 * g + k < nc ? coef[4 * g + k] / scale : 0.0;
                    long r = lrint(c * 32767.0);
                    q[4 * (size_t)v + k] = (int16_t)(r > 32767 ? 32767 : r < -32767 ? -32767 : r);
                }
            }
            bytes = (size_t)nv * 8;
        }
        int view = add_view(&e->vl, tmp, bytes, use_float ? 16 : 8, 34962);
        if (view < 0)
            return -1;
        char name[48];
        snprintf(name, sizeof name, "%s%u", prefix, g);
        cJSON_AddNumberToObject(
            e->attrs, name,
            add_accessor(e->accs, view, use_float ? 5126 : 5122, !use_float, nv, "VEC4"));
    }
    return 0;
}

/* The streams of the orders asked for (every stream without --orders). */
static int put_streams(exporter *e)
{
    const options *o = e->o;
    const vdsh_file *f = e->f;
    cJSON *streams = cJSON_AddArrayToObject(e->vx, "streams");
    for (uint32_t si = 0; si < f->stream_count; si++) {
        const vdsh_stream *s = &f->streams[si];
        if (o->any_order && (s->order > VDSH_MAX_ORDER || !o->want[s->order]))
            continue;
        /* Two streams of one order (distance and log): the second gets a
         * suffix so attribute names stay unique. */
        int dup = 0;
        for (uint32_t sj = 0; sj < si; sj++)
            dup += f->streams[sj].order == s->order && (!o->any_order || o->want[s->order]);
        char prefix[32];
        if (dup)
            snprintf(prefix, sizeof prefix, "_VDSH%u%c_", s->order, 'a' + dup);
        else
            snprintf(prefix, sizeof prefix, "_VDSH%u_", s->order);
        int rc = s->encoding == VDSH_ENCODING_CPCA && !o->source && !o->decode_cpca
                     ? export_cpca(s, e->nv, prefix, &e->vl, e->accs, e->attrs, streams, e->tmp)
                     : put_coefficients(e, s, prefix, streams);
        if (rc)
            return rc;
        e->exported++;
    }
    if (o->any_order && !e->exported) {
        char have[128] = "";
        size_t n = 0;
        for (uint32_t si = 0; si < f->stream_count && n < sizeof have; si++)
            n += (size_t)snprintf(
                have + n, sizeof have - n, "%s%u%s", si ? ", " : "", f->streams[si].order,
                f->streams[si].flags & VDSH_STREAM_VARIABLE ? " (adaptive order)" : "");
        fprintf(stderr,
                "vdsh-export: %s: no stream of the orders asked for (--orders); the file has "
                "order%s %s\n",
                o->in, f->stream_count == 1 ? "" : "s", have);
        return 1;
    }
    return 0;
}

/* The receiver mesh's own scene: the views in the BIN chunk, one mesh of
 * one primitive with extras.vdsh, one node (--compress: dequantising). */
static int assemble(exporter *e)
{
    const int compress = e->o->compress;
    cJSON *root = e->root;
    size_t raw_size = 0;
    if (write_views(&e->vl, compress, &e->b, e->views, &raw_size) || blob_align4(&e->b))
        return -1;
    add_buffers(root, e->b.size, compress, raw_size);
    if (compress) {
        const char *names[2] = {"KHR_mesh_quantization", "EXT_meshopt_compression"};
        for (int k = 0; k < 2; k++) {
            list_extension(root, "extensionsUsed", names[k]);
            list_extension(root, "extensionsRequired", names[k]);
        }
    }
    cJSON *prim = cJSON_CreateObject();
    cJSON_AddItemToObject(prim, "attributes", e->attrs);
    e->attrs = NULL;
    cJSON_AddNumberToObject(prim, "indices", e->ind_acc);
    cJSON_AddNumberToObject(prim, "mode", 4);
    cJSON *mesh = cJSON_CreateObject();
    cJSON *prims = cJSON_AddArrayToObject(mesh, "primitives");
    cJSON_AddItemToArray(prims, prim);
    cJSON *extras = cJSON_AddObjectToObject(mesh, "extras");
    cJSON_AddItemToObject(extras, "vdsh", e->vx);
    e->vx = NULL;
    cJSON *meshes = cJSON_AddArrayToObject(root, "meshes");
    cJSON_AddItemToArray(meshes, mesh);
    cJSON *node = cJSON_CreateObject();
    cJSON_AddNumberToObject(node, "mesh", 0);
    if (compress) {
        double t[3] = {e->lo[0], e->lo[1], e->lo[2]}, sc[3] = {e->qstep, e->qstep, e->qstep};
        cJSON_AddItemToObject(node, "translation", cJSON_CreateDoubleArray(t, 3));
        cJSON_AddItemToObject(node, "scale", cJSON_CreateDoubleArray(sc, 3));
    }
    cJSON *nodes = cJSON_AddArrayToObject(root, "nodes");
    cJSON_AddItemToArray(nodes, node);
    cJSON *scene = cJSON_CreateObject();
    cJSON *sn = cJSON_AddArrayToObject(scene, "nodes");
    cJSON_AddItemToArray(sn, cJSON_CreateNumber(0));
    cJSON *scenes = cJSON_AddArrayToObject(root, "scenes");
    cJSON_AddItemToArray(scenes, scene);
    cJSON_AddNumberToObject(root, "scene", 0);
    return 0;
}

/* The .glb: header, JSON chunk, BIN chunk, written atomically. */
static int write_glb(exporter *e)
{
    const char *in = e->o->in, *out = e->o->out;
    char *json = cJSON_PrintUnformatted(e->root);
    if (!json)
        return -1;
    size_t jl = strlen(json), jpad = (4 - jl % 4) % 4;
    uint64_t total = 12 + 8 + jl + jpad + 8 + e->b.size;
    if (total > 0xffffffffu) {
        fprintf(stderr, "vdsh-export: %s: the glb would be %llu bytes (over glTF's 4 GiB)\n", in,
                (unsigned long long)total);
        free(json);
        return 1;
    }
    vdsh_output o;
    vdsh_error verr;
    if (vdsh_output_open(out, &o, &verr) != VDSH_OK) {
        fprintf(stderr, "vdsh-export: %s\n", verr.msg);
        free(json);
        return 1;
    }
    uint32_t h[3] = {0x46546C67u, 2, (uint32_t)total};
    uint32_t jh[2] = {(uint32_t)(jl + jpad), 0x4E4F534Au};
    uint32_t bh[2] = {(uint32_t)e->b.size, 0x004E4942u};
    vdsh_output_put(&o, h, 12);
    vdsh_output_put(&o, jh, 8);
    vdsh_output_put(&o, json, jl);
    vdsh_output_put(&o, "   ", jpad);
    vdsh_output_put(&o, bh, 8);
    vdsh_output_put(&o, e->b.data, e->b.size);
    free(json);
    if (vdsh_output_commit(&o, &verr) != VDSH_OK) {
        fprintf(stderr, "vdsh-export: %s\n", verr.msg);
        return 1;
    }
    if (!e->o->quiet)
        fprintf(stderr, "vdsh-export: wrote %s (%llu bytes, %d stream%s)\n", out,
                (unsigned long long)total, e->exported, e->exported == 1 ? "" : "s");
    return 0;
}

/* Read, build the glTF step by step, write. */
static int run(const options *o)
{
    const char *ins[2] = {o->in, o->source}, *opt = "-o";
    int usage = vt_cli_no_stdout(&o->out, &opt, 1);
    if (usage)
        return usage;
    if (vt_cli_check_outputs(&o->out, 1, ins, o->source ? 2 : 1) != 0)
        return 1;
    vdsh_file *f = vt_read_whole(o->in);
    if (!f)
        return 1;
    exporter e;
    int rc = exporter_begin(&e, o, f);
    if (!rc)
        rc = put_indices(&e);
    if (!rc)
        rc = put_positions(&e);
    if (!rc)
        rc = put_normals(&e);
    if (!rc)
        rc = describe_bake(&e);
    if (!rc)
        rc = put_streams(&e);
    if (!rc && o->source)
        rc = with_source(o->in, o->source, f, e.root, &e.vl, e.attrs, &e.vx, &e.b, o->compress,
                         o->allow_mismatch, o->quiet) != 0;
    else if (!rc)
        rc = assemble(&e);
    if (!rc)
        rc = write_glb(&e);
    if (rc < 0)
        fprintf(stderr, "vdsh-export: %s: out of memory\n", o->in);
    exporter_free(&e);
    vdsh_free(f);
    return rc ? 1 : 0;
}

int main(int argc, char **argv)
{
    vt_cli_begin("vdsh-export", argv);
    vt_cli_clean_exit_on_signals(); /* no temporary file left by a signal */
    options o;
    int status = parse_args(argc, argv, &o);
    return status >= 0 ? status : run(&o);
}
