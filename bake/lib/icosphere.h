/*
 * icosphere.h - the unit icosphere of the built-in scenes' spheres
 * (builtin.c), also drawn by test_runtime_render: the icosahedron, each
 * triangle split into four with its edges' midpoints pushed onto the
 * sphere, `levels` times. Pure C (libm's sqrtf only), no allocation.
 *
 * Midpoints are shared between the two triangles of an edge, so the
 * facets meet exactly and the triangles share vertices (a smooth mesh).
 * The numbering is part of the built-in scenes' bytes (and so of every
 * bake's source hash): triangle f of one level becomes triangles 4f..4f+3
 * of the next (its three corners, then the middle), and midpoints are
 * numbered in the order the triangles' edges are met.
 *
 * Usage: float pos[VB_ICOSPHERE_VERTICES(2)][3];
 *        uint32_t tri[VB_ICOSPHERE_TRIANGLES(2)][3], nv, nt;
 *        vb_icosphere(2, pos, &nv, tri, &nt);
 *
 * Errors: none; levels above VB_ICOSPHERE_MAX_LEVELS is a programmer error
 * (asserted). Ownership: the caller's arrays, of at least the counts
 * below. Threading: reentrant.
 */
#ifndef VB_ICOSPHERE_H
#define VB_ICOSPHERE_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

enum { VB_ICOSPHERE_MAX_LEVELS = 3 };

/* Vertices and triangles of an icosphere of `levels` levels. */
#define VB_ICOSPHERE_VERTICES(levels) (10u * (1u << (2 * (levels))) + 2u)
#define VB_ICOSPHERE_TRIANGLES(levels) (20u << (2 * (levels)))

/* Writes the VB_ICOSPHERE_VERTICES(levels) unit vertices to pos and the
 * VB_ICOSPHERE_TRIANGLES(levels) triangles to tri, and their counts to
 * *nv and *nt. */
void vb_icosphere(uint32_t levels, float pos[][3], uint32_t *nv, uint32_t tri[][3], uint32_t *nt);

#ifdef __cplusplus
}
#endif

#endif
