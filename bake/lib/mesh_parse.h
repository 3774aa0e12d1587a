/*
 * mesh_parse.h - the strict readers behind vb_mesh_load: the bytes of an
 * OBJ, PLY, OFF or STL file in, the file's own arrays out (positions, file
 * normals per vertex and per face corner, triangulated faces), before
 * any cleaning. Internal to bake/ (mesh.c and the tests); tools use mesh.h.
 *
 * Does not: open files, hash, split creases, compute normals or compact
 * (mesh.c does all that), nor use OpenMesh. The readers read exactly what OpenMesh 9's readers read from the
 * same bytes (the baker used those until issue 13, and every recorded bake
 * depends on it: the same positions, the same vertex numbering, the same
 * normals; one exception: concave polygons are ear-clipped, not fanned
 * across their outside), and refuse what those readers would have read wrongly or
 * without a word: numbers that do not parse or are NaN/Inf, faces with fewer
 * than 3 vertices, out-of-range indices, truncated files, counts that do
 * not fit the file, properties and lines the readers would have misread
 * (mesh.h lists them).
 *
 * Usage (bake/mesh.c, load_bytes; tests/test_fuzz_mesh.c, the fuzz target,
 * calls it directly and checks these promises):
 *
 *     vb_mesh_raw raw;
 *     if (vb_mesh_parse("x.obj", VB_MESH_OBJ, bytes, size, &raw, &err) != VB_OK) ...
 *     ...
 *     vb_mesh_raw_free(&raw);
 *
 * Errors: VB_ERR_FORMAT (cannot be parsed, unsupported), VB_ERR_INVALID
 * (NaN/Inf, index out of range), VB_ERR_OUT_OF_MEMORY, VB_ERR_ARGUMENT
 * (NULL arguments, unknown format); the message names `name`, and the line
 * for text formats ("x.obj: line 12: face index 40 out of range (30
 * vertices)"). Element numbers follow the format's own convention: 1-based
 * for OBJ, 0-based for PLY, OFF and STL.
 *
 * Ownership: `bytes` is borrowed; *out is written only on success and owns
 * malloc'ed arrays, freed by vb_mesh_raw_free (which accepts a zeroed or
 * freed struct).
 *
 * Threading: no shared state; any number of calls may run at once.
 */
#ifndef VB_MESH_PARSE_H
#define VB_MESH_PARSE_H

#include <stddef.h>
#include <stdint.h>

#include "vb.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum vb_mesh_format {
    VB_MESH_OBJ,
    VB_MESH_PLY,
    VB_MESH_OFF,
    VB_MESH_STL,
    VB_MESH_GLTF, /* mesh_gltf.cpp (vb_mesh_parse_gltf) */
    VB_MESH_GLB
} vb_mesh_format;

/* A file as read, before cleaning: polygons triangulated (fanned from
 * their first vertex where that fan lies inside them, as OpenMesh did,
 * else ear-clipped: mesh_read.h triangulate_polygon; each polygon's n - 2
 * triangles consecutive, triangles that repeat a vertex included), every index in range, positions finite,
 * file normals per vertex (one given normal as is, several: their unit
 * average; (0,0,0) where none was given) and, for OBJ, per triangle corner
 * (as given, finite). */
typedef struct vb_mesh_raw {
    uint32_t vertex_count;
    uint32_t triangle_count;
    float *positions;      /* 3 * vertex_count */
    float *normals;        /* 3 * vertex_count or NULL (file has none) */
    uint8_t *has_normal;   /* vertex_count or NULL: file gave a normal */
    int64_t *indices;      /* 3 * triangle_count */
    uint32_t *faces;       /* triangle_count: 0-based polygon in the file */
    float *corner_normals; /* 9 * triangle_count or NULL (none given) */
    uint8_t *corner_given; /* 3 * triangle_count or NULL: corner has one */
    /* unclipped_count polygons (file numbers as in `faces`, ascending)
     * fanned because the ear clipping's time bound ran out, not tried (NULL
     * when none) */
    uint32_t *unclipped_faces;
    uint32_t unclipped_count;
    /* OBJ faces dropped for fewer than 3 distinct vertices (see
     * vb_mesh_report) */
    uint32_t dropped_triangles;
    uint32_t gltf_skipped_modes; /* glTF primitives skipped: points, lines */
    uint32_t gltf_skipped_morph; /* glTF primitives with morph targets: base pose baked */
    uint32_t gltf_skipped_skin;  /* glTF primitives of skinned nodes: bind pose baked */
    /* glTF triangle lists whose count is not a multiple of 3: the last 1 or 2
     * ignored */
    uint32_t gltf_ragged;
    /* glTF with external buffers: the source's hash and size are these, not
     * the file's */
    int gltf_hashed;
    uint64_t gltf_size; /* the file's bytes plus its external buffers' */
    /* SHA-256 of the file's bytes, then of each external buffer's in `buffers`
     * order */
    uint8_t gltf_sha256[32];
} vb_mesh_raw;

/* Read `size` bytes (the whole file) of `format`; `name` is for messages. */
vb_result vb_mesh_parse(const char *name, vb_mesh_format format, const uint8_t *bytes, size_t size,
                        vb_mesh_raw *out, vb_error *err);

void vb_mesh_raw_free(vb_mesh_raw *raw);

/* The whole of a regular file into *bytes (malloc'ed, *size bytes): a
 * FIFO, a directory or a device is refused ("not a regular file") without
 * waiting for a writer. mesh.c's, for the meshes and the glTF reader's
 * external buffers. */
vb_result vb_mesh_read_file(const char *path, uint8_t **bytes, size_t *size, vb_error *err);

/* glTF 2.0 (binary = 0: .gltf JSON, 1: .glb) from mesh_gltf.cpp: scene
 * `scene`, or the default scene when < 0; see that file's top comment. */
vb_result vb_mesh_parse_gltf(const char *name, int binary, int scene, const uint8_t *bytes,
                             size_t size, vb_mesh_raw *out, vb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* VB_MESH_PARSE_H */
