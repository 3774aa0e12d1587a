/*
 * test_fuzz_mesh.c - fuzz target for mesh input: the strict readers
 * (bake/lib/mesh_parse.h, vb_mesh_parse) on their own, then loading from
 * memory (bake/lib/mesh.h: the same readers and the cleaning), then welding
 * and refinement (OpenMesh) of whatever was accepted.
 *
 * One source, one binary per format: VDSH_FUZZ_EXT ("obj", "ply", "off",
 * "stl") names the bytes "fuzz.<ext>", which picks the format, so each
 * fuzzer and its corpus (tests/corpus/mesh_<ext>/) stay on one format.
 * Built by tests/robust.cmake: test_fuzz_mesh_<ext> with the replay main()
 * of test_fuzz_main.c (ctest), fuzz_mesh_<ext> with libFuzzer when
 * VDSH_FUZZ=ON (scripts/fuzz mesh_obj 600).
 *
 * Properties checked beyond "no crash, no leak, no sanitizer report":
 * a rejection names the input; the readers' arrays are what mesh_parse.h
 * says (consistent counts, finite positions, unit or zero normals where
 * given) and loading accepts exactly what they accept; an accepted mesh is
 * as clean as mesh.h promises, also after welding and refinement.
 */
#include "mesh.h"
#include "mesh_parse.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef VDSH_FUZZ_EXT
#error "define VDSH_FUZZ_EXT (obj, ply, off, stl, gltf or glb)"
#endif
#define NAME "fuzz." VDSH_FUZZ_EXT

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define REQUIRE(cond, what)                                                                        \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "%s: %s\n", NAME, what);                                               \
            abort();                                                                               \
        }                                                                                          \
    } while (0)

/* mesh.h's promise for loaded meshes (refined ones may keep the input's
 * undefined normals, and are otherwise the same). */
static void check_clean(const vb_mesh *m)
{
    REQUIRE(m->vertex_count > 0 && m->triangle_count > 0, "accepted an empty mesh");
    for (size_t i = 0; i < 3 * (size_t)m->vertex_count; i++)
        REQUIRE(isfinite(m->positions[i]) && isfinite(m->normals[i]), "non-finite value");
    for (uint32_t i = 0; i < m->vertex_count; i++) {
        const float *n = m->normals + 3 * (size_t)i;
        double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        REQUIRE(len == 0.0 || fabs(len - 1.0) < 1e-3, "normal neither unit nor zero");
    }
    for (size_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *v = m->indices + 3 * t;
        REQUIRE(v[0] < m->vertex_count && v[1] < m->vertex_count && v[2] < m->vertex_count,
                "index out of range");
        REQUIRE(v[0] != v[1] && v[1] != v[2] && v[0] != v[2], "triangle repeats a vertex");
    }
}

static vb_mesh_format format_of_name(void)
{
    static const char *const ext[6] = {"obj", "ply", "off", "stl", "gltf", "glb"};
    for (int i = 0; i < 6; i++)
        if (!strcmp(VDSH_FUZZ_EXT, ext[i]))
            return (vb_mesh_format)i;
    abort();
}

/* mesh_parse.h's promise for the readers' arrays. */
static void check_raw(const vb_mesh_raw *r)
{
    REQUIRE(r->positions && r->indices && r->faces, "arrays missing");
    for (size_t i = 0; i < 3 * (size_t)r->vertex_count; i++)
        REQUIRE(isfinite(r->positions[i]), "non-finite position");
    REQUIRE((r->normals == NULL) == (r->has_normal == NULL),
            "normals without has_normal or the reverse");
    for (uint32_t i = 0; r->normals && i < r->vertex_count; i++) {
        const float *n = r->normals + 3 * (size_t)i;
        double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        REQUIRE(r->has_normal[i] <= 1 && isfinite(len), "bad file normal");
        REQUIRE(len == 0.0 || fabs(len - 1.0) < 1e-3, "file normal neither unit nor zero");
        REQUIRE(r->has_normal[i] || len == 0.0, "a normal where none was given");
    }
    REQUIRE((r->corner_normals == NULL) == (r->corner_given == NULL),
            "corner normals without flags");
    for (size_t c = 0; r->corner_normals && c < 3 * (size_t)r->triangle_count; c++)
        for (int k = 0; k < 3; k++)
            REQUIRE(isfinite(r->corner_normals[3 * c + (size_t)k]), "non-finite corner normal");
    for (size_t t = 0; t < r->triangle_count; t++) {
        REQUIRE(t == 0 || r->faces[t] >= r->faces[t - 1], "faces out of order");
        for (int k = 0; k < 3; k++)
            REQUIRE(r->indices[3 * t + (size_t)k] >= 0 &&
                        r->indices[3 * t + (size_t)k] < (int64_t)r->vertex_count,
                    "raw index out of range");
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    vb_mesh m = {0}, fine = {0};
    vb_error err;
    vb_mesh_raw raw;
    memset(&raw, 0, sizeof raw);
    vb_mesh_format format = format_of_name();
    int parsed = size > 0 &&
                 (format == VB_MESH_GLTF || format == VB_MESH_GLB
                      ? vb_mesh_parse_gltf(NAME, format == VB_MESH_GLB, -1, data, size, &raw, &err)
                      : vb_mesh_parse(NAME, format, data, size, &raw, &err)) == VB_OK;
    if (parsed)
        check_raw(&raw);
    else if (size > 0)
        REQUIRE(strncmp(err.msg, NAME ":", strlen(NAME ":")) == 0,
                "reader's message does not name the input");
    vb_mesh_raw_free(&raw);
    if (vb_mesh_load_memory(data, size, NAME, NULL, &m, NULL, &err) != VB_OK) {
        REQUIRE(strncmp(err.msg, NAME ":", strlen(NAME ":")) == 0,
                "message does not name the input");
        return 0;
    }
    REQUIRE(parsed, "loading accepted what the reader refused");
    check_clean(&m);
    /* Refinement to a quarter of the diagonal: a bounded amount of work
     * whatever the scale, on a mesh that may be anything but clean in
     * topology (non-manifold, duplicate and zero-area triangles). */
    float lo[3], hi[3];
    vb_mesh_bounds(&m, lo, hi);
    float diag = sqrtf((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                       (hi[2] - lo[2]) * (hi[2] - lo[2]));
    if (vb_mesh_refine(&m, diag / 4.0f, &fine, &err) == VB_OK)
        check_clean(&fine);
    if (vb_mesh_weld(&m, &err) == VB_OK && m.triangle_count > 0)
        check_clean(&m);
    vb_mesh_free(&fine);
    vb_mesh_free(&m);
    return 0;
}
