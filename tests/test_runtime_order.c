/*
 * test_runtime_order.c - vr_order_triangles (runtime/vr_order.c), the
 * upload order of a scene, without GL:
 *
 *   same      a grid of triangles given in a scrambled order: the output
 *             holds every input triangle exactly once, with its winding,
 *             and remap is a permutation that numbers vertices by first use
 *             (unused vertices last);
 *   reuse     the reordered grid misses a 32-entry FIFO vertex cache far
 *             less often than the scrambled one (the point of the order);
 *   bad       an index out of range is VR_ERR_FORMAT naming the triangle;
 *             an empty mesh is fine.
 */
#include "test_util.h"

#include "vr_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { G = 60, NV = (G + 1) * (G + 1) + 5, NT = 2 * G * G };

/* Vertex transforms per triangle of a FIFO cache of `size` entries. */
static double fifo_misses(const uint32_t *idx, uint32_t nt, uint32_t nv, int size)
{
    int64_t *when = malloc(nv * sizeof *when);
    for (uint32_t v = 0; v < nv; v++)
        when[v] = -1000000;
    int64_t t = 0, misses = 0;
    for (size_t i = 0; i < 3 * (size_t)nt; i++)
        if (t - when[idx[i]] >= size) {
            when[idx[i]] = t++;
            misses++;
        }
    free(when);
    return (double)misses / nt;
}

/* A G x G grid (two triangles per cell, counter-clockwise), its triangles
 * shuffled and its vertices numbered at random; 5 vertices unused. */
static void scrambled_grid(uint32_t *idx, uint64_t *rng)
{
    uint32_t perm[NV];
    for (uint32_t v = 0; v < NV; v++)
        perm[v] = v;
    for (uint32_t v = NV - 1; v > 0; v--) {
        uint32_t j = (uint32_t)(test_rand(rng) * (v + 1)) % (v + 1), x = perm[v];
        perm[v] = perm[j];
        perm[j] = x;
    }
    uint32_t t = 0;
    for (uint32_t y = 0; y < G; y++)
        for (uint32_t x = 0; x < G; x++) {
            uint32_t a = y * (G + 1) + x, b = a + 1, c = a + G + 1, d = c + 1;
            const uint32_t tri[2][3] = {{a, b, d}, {a, d, c}};
            for (int k = 0; k < 2; k++, t++)
                for (int c3 = 0; c3 < 3; c3++)
                    idx[3 * t + (uint32_t)c3] = perm[tri[k][c3]];
        }
    for (uint32_t i = NT - 1; i > 0; i--) {
        uint32_t j = (uint32_t)(test_rand(rng) * (i + 1)) % (i + 1), tmp[3];
        memcpy(tmp, idx + 3 * i, sizeof tmp);
        memcpy(idx + 3 * i, idx + 3 * j, sizeof tmp);
        memcpy(idx + 3 * j, tmp, sizeof tmp);
    }
}

/* Triangles as (smallest vertex first, winding kept) keys, sorted. */
static int cmp_tri(const void *a, const void *b)
{
    return memcmp(a, b, 3 * sizeof(uint32_t));
}

static void canonical(uint32_t *idx, uint32_t nt)
{
    for (uint32_t t = 0; t < nt; t++) {
        uint32_t *p = idx + 3 * t;
        while (p[0] > p[1] || p[0] > p[2]) {
            uint32_t x = p[0];
            p[0] = p[1];
            p[1] = p[2];
            p[2] = x;
        }
    }
    qsort(idx, nt, 3 * sizeof(uint32_t), cmp_tri);
}

static void test_grid(void)
{
    static uint32_t idx[3 * NT], out[3 * NT], back[3 * NT], remap[NV];
    uint64_t rng = 7;
    scrambled_grid(idx, &rng);
    vr_error err;
    vr_result r = vr_order_triangles(idx, NT, NV, out, remap, "grid", &err);
    CHECK(r == VR_OK, "%s", err.msg);
    if (r != VR_OK)
        return;

    /* remap is a permutation; first uses come in order 0, 1, 2, ... */
    static uint32_t inverse[NV];
    static uint8_t seen[NV];
    int perm_ok = 1, first_use_ok = 1;
    for (uint32_t v = 0; v < NV; v++) {
        perm_ok &= remap[v] < NV && !seen[remap[v]];
        if (remap[v] < NV) {
            seen[remap[v]] = 1;
            inverse[remap[v]] = v;
        }
    }
    CHECK(perm_ok, "remap is not a permutation");
    uint32_t next = 0;
    for (size_t i = 0; i < 3 * (size_t)NT; i++) {
        if (out[i] > next)
            first_use_ok = 0;
        if (out[i] == next)
            next++;
    }
    CHECK(first_use_ok && next == NV - 5, "vertices not numbered by first use (%u used)", next);

    /* the same triangles, windings included */
    for (size_t i = 0; i < 3 * (size_t)NT; i++)
        back[i] = inverse[out[i] < NV ? out[i] : 0];
    canonical(back, NT);
    canonical(idx, NT);
    CHECK(memcmp(back, idx, sizeof idx) == 0, "the reordered triangles are not the input's");

    scrambled_grid(idx, &rng);
    r = vr_order_triangles(idx, NT, NV, out, remap, "grid", &err);
    double before = fifo_misses(idx, NT, NV, 32), after = fifo_misses(out, NT, NV, 32);
    printf("order: grid of %d triangles, FIFO(32) vertex transforms per triangle: scrambled "
           "%.3f, ordered %.3f (ideal about 0.5)\n",
           NT, before, after);
    CHECK(r == VR_OK && after < 0.8 && after < 0.5 * before, "transforms per triangle %.3f -> %.3f",
          before, after);
}

static void test_bad(void)
{
    const uint32_t idx[6] = {0, 1, 2, 2, 1, 3};
    uint32_t out[6], remap[4];
    vr_error err;
    vr_result r = vr_order_triangles(idx, 2, 3, out, remap, "bad.vdsh", &err);
    CHECK(r == VR_ERR_FORMAT && strstr(err.msg, "bad.vdsh") && strstr(err.msg, "triangle 1"),
          "index out of range: %d (%s)", (int)r, r ? err.msg : "");
    r = vr_order_triangles(idx, 0, 0, out, remap, "empty", &err);
    CHECK(r == VR_OK, "empty mesh: %d", (int)r);
    r = vr_order_triangles(idx, 0, 4, out, remap, "no triangles", &err);
    CHECK(r == VR_OK && remap[0] == 0 && remap[3] == 3, "no triangles: %d", (int)r);
}

int main(void)
{
    test_grid();
    test_bad();
    return test_report("test_runtime_order");
}
