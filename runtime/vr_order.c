/*
 * vr_order.c - the order in which a scene's triangles and vertices go to
 * the GPU.
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
 * 2007): linear time; it emits every triangle around a fanning vertex,
 * then moves on to a vertex of those triangles that will still be in a
 * FIFO cache of CACHE entries after its own fan, else to the most recent
 * vertex with triangles left, else to the next one in file order. The
 * vertices are then numbered in the order the triangles first use them,
 * so that each stretch of the index buffer reads a compact range of every
 * vertex buffer.
 */
#include "vr_internal.h"

#include <stdlib.h>
#include <string.h>

enum { CACHE = 32 };

/* The next fanning vertex (Tipsify's Skip-Dead-End and Get-Next-Vertex),
 * or -1 when every triangle has been emitted. */
static int64_t next_vertex(const uint32_t *cand, size_t nc, const uint32_t *live,
                           const size_t *stamp, size_t now, const uint32_t *dead, size_t *nd,
                           uint32_t *cursor, uint32_t nv)
{
    int64_t best = -1;
    size_t best_p = 0;
    for (size_t i = 0; i < nc; i++) {
        uint32_t v = cand[i];
        if (!live[v])
            continue;
        /* Its age in the cache, when its fan would still find it there. */
        size_t age = now - stamp[v];
        size_t p = age + 2 * (size_t)live[v] <= CACHE ? age : 0;
        if (best < 0 || p > best_p) {
            best = v;
            best_p = p;
        }
    }
    if (best >= 0)
        return best;
    while (*nd > 0) {
        uint32_t v = dead[--*nd];
        if (live[v])
            return v;
    }
    for (; *cursor < nv; ++*cursor)
        if (live[*cursor])
            return (*cursor)++;
    return -1;
}

vr_result vr_order_triangles(const uint32_t *indices, uint32_t nt, uint32_t nv,
                             uint32_t *out, uint32_t *remap, const char *name,
                             vr_error *err)
{
    size_t ni = 3 * (size_t)nt;
    for (size_t i = 0; i < ni; i++)
        if (indices[i] >= nv)
            return vr_fail(err, VR_ERR_FORMAT, "%s: triangle %zu uses vertex %u of %u", name,
                           i / 3, indices[i], nv);

    /* The triangles of each vertex: first[v] .. first[v + 1] in tris. */
    size_t *first = calloc((size_t)nv + 1, sizeof *first);
    size_t *stamp = calloc(nv, sizeof *stamp);
    uint32_t *live = calloc(nv, sizeof *live);
    size_t n1 = ni ? ni : 1;
    uint32_t *tris = malloc(n1 * sizeof *tris);
    uint32_t *dead = malloc(n1 * sizeof *dead);
    uint32_t *cand = malloc(n1 * sizeof *cand);
    uint32_t *order = malloc(n1 * sizeof *order);
    uint8_t *done = calloc(n1, 1);
    vr_result res = VR_OK;
    if (!first || !stamp || !live || !tris || !dead || !cand || !order || !done) {
        res = vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory ordering %u triangles",
                      name, nt);
        goto done;
    }
    for (size_t i = 0; i < ni; i++)
        live[indices[i]]++;
    for (uint32_t v = 0; v < nv; v++)
        first[v + 1] = first[v] + live[v];
    /* stamp doubles as the fill count here; cleared below */
    for (size_t i = 0; i < ni; i++) {
        uint32_t v = indices[i];
        tris[first[v] + stamp[v]++] = (uint32_t)(i / 3);
    }
    memset(stamp, 0, (size_t)nv * sizeof *stamp);

    /* Fan around f, then choose the next f. */
    size_t now = CACHE + 1, nd = 0, no = 0;
    uint32_t cursor = 1;
    int64_t f = nv > 0 ? 0 : -1;
    while (f >= 0) {
        size_t nc = 0;
        for (size_t a = first[f]; a < first[f + 1]; a++) {
            uint32_t t = tris[a];
            if (done[t])
                continue;
            done[t] = 1;
            for (int c = 0; c < 3; c++) {
                uint32_t v = indices[3 * (size_t)t + (size_t)c];
                order[no++] = v;
                dead[nd++] = v;
                cand[nc++] = v;
                live[v]--;
                if (now - stamp[v] > CACHE)
                    stamp[v] = now++;
            }
        }
        f = next_vertex(cand, nc, live, stamp, now, dead, &nd, &cursor, nv);
    }

    /* Vertices numbered by first use; unused ones last, in file order. */
    for (uint32_t v = 0; v < nv; v++)
        remap[v] = UINT32_MAX;
    uint32_t next = 0;
    for (size_t i = 0; i < ni; i++) {
        uint32_t v = order[i];
        if (remap[v] == UINT32_MAX)
            remap[v] = next++;
        out[i] = remap[v];
    }
    for (uint32_t v = 0; v < nv; v++)
        if (remap[v] == UINT32_MAX)
            remap[v] = next++;

done:
    free(first);
    free(stamp);
    free(live);
    free(tris);
    free(dead);
    free(cand);
    free(order);
    free(done);
    return res;
}
