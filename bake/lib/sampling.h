/*
 * sampling.h - the bake's ray directions: jittered stratified grids in
 * packet order. Pure C, no Embree.
 *
 * A grid of nu x nv cells covers the sampling domain with equal-area cells
 * (uniform in cos(theta) and in phi), so every direction carries the same
 * weight (4 pi / N on the sphere, 2 pi / N on the hemisphere). Each cell
 * gets one direction, jittered inside the cell by a hash of (seed, vertex,
 * cell): the same for a given receiver whatever thread or order computes
 * it, different between receivers so that sampling error does not repeat
 * from one vertex to the next.
 *
 * Packets: Embree's 16-wide coherent traversal pays off only when a
 * packet's directions are neighbours, so the cells are taken in Morton
 * order of (row, column) and a packet is 16 consecutive cells: a 4 x 4
 * block wherever the grid allows, a compact patch at its edges; the last
 * packet may have empty lanes. Each packet also has a bounding cone, so a
 * bake that ignores directions below a receiver's horizon can skip whole
 * packets without generating them (vb_dirgrid_packet_below).
 *
 * Rays: the grid has nu = floor(sqrt(N)) rows and nv = floor(N / nu)
 * columns, so N = 2500 gives 50 x 50; other N may give slightly fewer
 * directions (count says how many).
 *
 * Errors: vb_result (VB_ERR_ARGUMENT for N = 0 or absurdly large,
 * VB_ERR_OUT_OF_MEMORY). Ownership: vb_dirgrid_destroy frees a created or
 * zeroed grid. Threading: a created grid is read-only; share it freely.
 */
#ifndef VB_SAMPLING_H
#define VB_SAMPLING_H

#include <stddef.h>
#include <stdint.h>

#include "vb.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VB_PACKET 16
#define VB_MAX_RAYS (1u << 20)
#define VB_MAX_ROUNDS 24

typedef struct vb_dirgrid {
    uint32_t nu, nv;            /* rows (cos theta) x columns (phi) */
    uint32_t count;             /* nu * nv directions per receiver */
    uint32_t packet_count;      /* ceil(count / 16) */
    int hemisphere;             /* 0: whole sphere; 1: hemisphere around n */
    uint32_t *cells;            /* packet_count * 16 cell indices (row * nv +
                                column) in packet order; UINT32_MAX = empty */
    float *cone;                /* per packet: axis x, y, z, sin(half-angle) or 2
                                if the half-angle reaches 90 degrees (sphere
                                domain only) */
    float *lane_row;            /* per lane (packet order): the cell's row */
    float *lane_cos, *lane_sin; /* per lane: cos, sin of the cell's first phi */
    /* Nested grids (vb_dirgrid_create_nested) only, else 0: the packets
     * end of each round (round r is packets [round_end[r-1], round_end[r])). */
    uint32_t rounds;
    uint32_t round_end[VB_MAX_ROUNDS];
} vb_dirgrid;

vb_result vb_dirgrid_create(uint32_t rays, int hemisphere, vb_dirgrid *out, vb_error *err);
void vb_dirgrid_destroy(vb_dirgrid *g);

/* A nested grid for adaptive rays: nu x nv = 2^a x 2^b cells (b = a or
 * a + 1), the most that fit in `rays`, taken in rounds of 1/16, 1/8, ...,
 * 1 of them (at least 64 cells in the first). The cells up to the end of
 * any round are the cells whose Morton code (row, column) has its low bits
 * equal to a per-receiver shift: a regular sub-grid, one cell in each
 * block of 2^i x 2^j cells, so every prefix of rounds is a stratified sample
 * with equal weights, and each round's set contains the last. Within a
 * round the cells are in Morton order (packets are compact patches of the
 * sub-grid); every round is a whole number of full packets. Packets:
 * vb_dirgrid_packet_nested (not vb_dirgrid_packet, nor packet cones). */
vb_result vb_dirgrid_create_nested(uint32_t rays, int hemisphere, vb_dirgrid *out, vb_error *err);

/* vb_dirgrid_packet for a nested grid: the grid's cells XORed with the
 * receiver's shift (a hash of seed and vertex), so that the sub-grids
 * differ from one receiver to the next. Every lane valid. */
void vb_dirgrid_packet_nested(const vb_dirgrid *g, uint32_t packet, uint64_t seed, uint32_t vertex,
                              const float n[3], float dx[16], float dy[16], float dz[16],
                              int valid[16]);

/* The 16 directions of `packet` for receiver `vertex`. For the hemisphere
 * domain, `n` is the receiver's unit normal (the local pole); for the
 * sphere it is ignored and the pole is +z. Empty lanes get valid = 0 and a
 * zero direction; the others valid = -1 (Embree's convention). */
void vb_dirgrid_packet(const vb_dirgrid *g, uint32_t packet, uint64_t seed, uint32_t vertex,
                       const float n[3], float dx[16], float dy[16], float dz[16], int valid[16]);

/* 1 if every direction the packet can produce (whatever the jitter) has
 * w.n < 0: it lies wholly below the horizon of normal n. Sphere domain. */
static inline int vb_dirgrid_packet_below(const vb_dirgrid *g, uint32_t packet, const float n[3])
{
    const float *c = g->cone + 4 * (size_t)packet;
    return c[0] * n[0] + c[1] * n[1] + c[2] * n[2] < -c[3];
}

/* Two uniform numbers in [0, 1) for (seed, a, b): the jitter source, also
 * used by the evaluator (with its own seed) for held-out samples. */
void vb_hash2(uint64_t seed, uint32_t a, uint32_t b, float *u, float *v);

/* An orthonormal frame (t, b) completing unit n (Duff et al. 2017). */
void vb_frame(const float n[3], float t[3], float b[3]);

#ifdef __cplusplus
}
#endif

#endif /* VB_SAMPLING_H */
