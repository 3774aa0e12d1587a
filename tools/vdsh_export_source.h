/*
 * vdsh_export_source.h - vdsh-export --source: the baked glTF's own scene
 * (nodes, meshes, materials, textures, UVs and every other attribute)
 * with the VDSH attributes added to the primitives the receivers came from
 * (formats/GLTF.md "Keeping the source scene").
 *
 * The source is read again here (its JSON with cJSON, its buffers from the
 * .glb's BIN chunk, data: URIs or files beside it) and walked as the
 * baker's glTF reader walks it (bake/lib/mesh_gltf.cpp: the default scene,
 * each node's matrix or TRS in double, the same primitives skipped); each
 * primitive vertex's world position (and normal) finds the receiver with
 * the bit-identical position (the closest normal among several). A mesh
 * used by several nodes is copied for each further use (each instance sees
 * its own shadows).
 *
 * Errors: returns -1 after writing a message naming the file and the
 * problem into msg.
 */
#ifndef VDSH_EXPORT_SOURCE_H
#define VDSH_EXPORT_SOURCE_H

#include <stddef.h>
#include <stdint.h>

#include <cjson/cJSON.h>

typedef struct vdsh_src_buffer {
    uint8_t *data;
    size_t size;
} vdsh_src_buffer;

typedef struct vdsh_src {
    cJSON *json;              /* the source's glTF JSON, modified in place */
    vdsh_src_buffer *buffers; /* its buffers' bytes, one per buffers[] */
    int buffer_count;
    char *dir; /* the source's directory, for relative URIs */
    /* What a bake records of it (formats/VDSH.md, SRCS): the file's bytes
     * followed by each external buffer's (no external buffer: the file's
     * alone), and the file's alone (what bakes before 2026-11-30 recorded). */
    uint8_t sha256[32], file_sha256[32];
    uint64_t size, file_size;
} vdsh_src;

/* One primitive instance reached by the walk: node, its mesh, primitive
 * index, and map[i] = the receiver of the primitive's vertex i (or
 * UINT32_MAX where none has its position). */
typedef struct vdsh_src_prim {
    int node, mesh, prim;
    uint32_t vertex_count, matched;
    uint32_t *map;
} vdsh_src_prim;

/* The file a relative URI of the source names: its directory plus the URI
 * decoded as the baker (tinygltf) decodes it, formats/vdsh_gltf_uri.h:
 * "a%20b+c.bin" is "a b c.bin". Malloc'ed; NULL with *why when out of
 * memory or when the URI decodes to a NUL byte ("%00"). */
char *vdsh_src_file(const vdsh_src *s, const char *uri, const char **why);

/* Read the source (its JSON, every buffer) and hash it as the baker does
 * (sha256, size above). */
int vdsh_src_load(const char *path, vdsh_src *s, char *msg, size_t cap);
void vdsh_src_free(vdsh_src *s);

/* Walk the default scene and map each primitive's vertices to receivers
 * (positions/normals: 3 floats per receiver). *prims is malloc'ed. */
int vdsh_src_map(const char *path, vdsh_src *s, const float *positions, const float *normals,
                 uint32_t nv, vdsh_src_prim **prims, int *prim_count, char *msg, size_t cap);

#endif
