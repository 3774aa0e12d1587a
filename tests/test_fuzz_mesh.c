/*
 * test_fuzz_mesh.c - fuzz target for mesh loading (bake/mesh.h) from
 * memory: the strict pre-pass, OpenMesh's reader behind it and the
 * cleaning, then welding and refinement of whatever was accepted.
 *
 * One source, one binary per format: VDSH_FUZZ_EXT ("obj", "ply", "off",
 * "stl") names the bytes "fuzz.<ext>", which picks the format, so each
 * fuzzer and its corpus (tests/corpus/mesh_<ext>/) stay on one format.
 * Built by tests/robust.cmake: test_fuzz_mesh_<ext> with the replay main()
 * of test_fuzz_main.c (ctest), fuzz_mesh_<ext> with libFuzzer when
 * VDSH_FUZZ=ON (scripts/fuzz mesh_obj 600).
 *
 * Properties checked beyond "no crash, no leak, no sanitizer report":
 * a rejection names the input, and an accepted mesh is as clean as
 * mesh.h promises, also after welding and refinement.
 */
#include "mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef VDSH_FUZZ_EXT
#error "define VDSH_FUZZ_EXT (obj, ply, off or stl)"
#endif
#define NAME "fuzz." VDSH_FUZZ_EXT

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define REQUIRE(cond, what)                                                   \
    do {                                                                      \
        if (!(cond)) {                                                        \
            fprintf(stderr, "%s: %s\n", NAME, what);                          \
            abort();                                                          \
        }                                                                     \
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

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    vb_mesh m = {0}, fine = {0};
    vb_error err;
    if (vb_mesh_load_memory(data, size, NAME, NULL, &m, NULL, &err) != VB_OK) {
        REQUIRE(strncmp(err.msg, NAME ":", strlen(NAME ":")) == 0, "message does not name the input");
        return 0;
    }
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
