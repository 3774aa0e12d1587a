/*
 * vr_order.c - the order in which a scene's triangles and vertices go to
 * the GPU, by meshoptimizer (Debian libmeshoptimizer-dev).
 *
 * Every pass draws the whole index buffer, and a vertex is shaded again
 * whenever the triangles that use it lie far apart in it. GPUs keep a
 * small FIFO of recently shaded vertices; Mesa's llvmpipe (the renderer of
 * machines without a GPU) shades in segments of 1024 indices and reuses a
 * vertex only within its segment. Baked meshes come in the order the
 * mesh splitting left them: the built-in room at --max-edge 0.2 shaded
 * each vertex 3.7 times per draw in file order and 1.2 times in this one
 * (GL_VERTEX_SHADER_INVOCATIONS_ARB), which halves the single-threaded
 * vertex and setup work of every pass on llvmpipe (docs/BENCHMARKS.md).
 *
 * The triangle order is Tipsify (Sander, Nehab and Barczak, "Fast
 * Triangle Reordering for Vertex Locality and Reduced Overdraw", SIGGRAPH
 * 2007) for a FIFO of CACHE entries: meshopt_optimizeVertexCacheFifo. The
 * vertices are then numbered in the order the triangles first use them
 * (meshopt_optimizeVertexFetchRemap), so that each stretch of the index
 * buffer reads a compact range of every vertex buffer; vertices no
 * triangle uses go last, in file order.
 *
 * Why the FIFO optimiser and not meshoptimizer's default
 * (meshopt_optimizeVertexCache, tuned for GPU caches), measured on the
 * scenes of scripts/bench_runtime (built-in room at --max-edge 0.2: 58,007
 * vertices, 112,648 triangles; Sponza: 60,848 and 66,450), llvmpipe of
 * Mesa 22.3.6 on 2 cores:
 *
 *                         vertex shader runs     ACMR / ATVR       ACMR / ATVR
 *                         per lighting pass      FIFO of 32        1024-index
 *                                                                  segments
 *   room, file order      212,642 (3.67/vertex)  1.913 / 3.715     1.858 / 3.608
 *   room, FIFO (32)        69,060 (1.19)         0.583 / 1.131     0.611 / 1.186
 *   room, default          72,817 (1.26)         0.637 / 1.238     0.639 / 1.241
 *   Sponza, file order     75,999 (1.25)         1.196 / 1.307     1.131 / 1.235
 *   Sponza, FIFO (32)      63,465 (1.04)         0.960 / 1.048     0.953 / 1.041
 *   Sponza, default        63,240 (1.04)         0.959 / 1.048     0.950 / 1.038
 *
 * The default order shades 5% more vertices in the room (and as many in
 * Sponza); frame times of the two (vdsh-view --bench, 3 x 9 rounds of
 * every mode with 1 and 3 lights, alternating processes) were the same
 * within the noise of the shared machine: per-scene geometric means of the
 * process-CPU-time ratios 0.99 to 1.02, single modes 0.94 to 1.10. (For a
 * GPU-like cache of 32 entries in warps of 32 the default is better, ACMR
 * 0.789 against 0.943 in the room; there is no GPU here to time it on.)
 * The FIFO optimiser is the algorithm of the hand-written code it
 * replaced, and gives the very same index buffer and numbering on every
 * scene tried (room, Sponza, Cornell box, the test rooms): renders are
 * unchanged.
 *
 * Memory: the buffer allocated here fails with VR_ERR_OUT_OF_MEMORY;
 * meshoptimizer's own temporary allocations (a few times the index
 * buffer's size) go through operator new, which aborts the process when
 * memory runs out.
 */
#include "vr_internal.h"

#include <meshoptimizer.h>

#include <stdlib.h>

enum { CACHE = 32 };

vr_result vr_order_triangles(const uint32_t *indices, uint32_t nt, uint32_t nv, uint32_t *out,
                             uint32_t *remap, const char *name, vr_error *err)
{
    size_t ni = 3 * (size_t)nt;
    /* meshoptimizer asserts this (or reads out of bounds without asserts):
     * data from a file is checked here. */
    for (size_t i = 0; i < ni; i++)
        if (indices[i] >= nv)
            return vr_fail(err, VR_ERR_FORMAT, "%s: triangle %zu uses vertex %u of %u", name, i / 3,
                           indices[i], nv);
    uint32_t *order = malloc((ni ? ni : 1) * sizeof *order);
    if (!order)
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory ordering %u triangles", name,
                       nt);
    meshopt_optimizeVertexCacheFifo(order, indices, ni, nv, CACHE);
    /* First use numbers the used vertices 0..used-1 and marks the others
     * ~0u: they follow, in file order. */
    uint32_t next = (uint32_t)meshopt_optimizeVertexFetchRemap(remap, order, ni, nv);
    for (uint32_t v = 0; v < nv; v++)
        if (remap[v] == ~0u)
            remap[v] = next++;
    meshopt_remapIndexBuffer(out, order, ni, remap);
    free(order);
    return VR_OK;
}
