/*
 * vdsh_light.h - where point lights may go: the one definition of "a light
 * in the scene's free space", shared by the evaluator (bake/eval/eval.c, which
 * casts the probes with Embree) and the runtime's default lights
 * (runtime/, which casts them on the CPU against the drawn mesh).
 *
 * A point is in free space when, of VDSH_FREE_PROBES rays from it in fixed
 * directions (the 6 axes and the 8 cube diagonals), none first meets the
 * back of a face, or more meet the front of one than the back (a point
 * inside a solid, or outside a closed room - above it, or in the notch of
 * an L-shaped room's bounds - sees the backs of the faces around it and
 * the void), and none meets anything nearer than the clearance (1% of the
 * scene's diagonal: a light on a surface lights nothing but that surface's
 * neighbourhood). Rays that meet nothing count for neither: an open
 * scene's sky, and the space around an object, are free.
 *
 * Lights "placed uniformly in free space" are the candidates of a seeded
 * sequence, uniform in the scene's light region, that pass the test, in
 * sequence order (vdsh_light_candidate): deterministic, the same on every
 * machine.
 *
 * The light region (vdsh_light_region) is the scene's bounding box grown on
 * every side by a share of its diagonal that falls continuously with the
 * free space in the box: n of the first VDSH_REGION_PROBES candidates of
 * the seed VDSH_REGION_SEED in the box are free; at n <= VDSH_REGION_FULL
 * (a closed convex object fills its bounds: a box; a box turned by a few
 * degrees leaves only slivers between its faces and its bounds) the share
 * is VDSH_REGION_GROW, the object seen from around it; at n >=
 * VDSH_REGION_ROOM it is 0, the bounds; between, linear in n
 * (vdsh_light_growth), so a slightly different object gets a slightly
 * different region, never a jump from slivers to a shell. The grown box
 * holds the box's own free space and the shell around it. The test stops
 * at the VDSH_REGION_ROOM-th free candidate: every interior and open
 * scene measured has at least 48% of its box free (docs/ACCURACY.md,
 * "Closed convex objects"), about twice the 25% where growing starts, and
 * keeps its bounds: its lights are the ones placed before the rule. n is
 * a count of free-space decisions, the same under every Embree kernel set
 * (docs/DESIGN.md, "Across CPUs"), and the share a function of it alone.
 * Placement (vdsh_light_place) gives up after 1000 candidates per light (and
 * VDSH_REGION_TRIES more in a grown region): a scene whose own free space
 * is small and enclosed (an inside-out object, a crowded interior, under
 * 25% of its box free) may be grown, and its lights are still found only
 * inside it, among fewer free candidates.
 *
 * Does not: cast rays (the caller does, with whatever it has).
 * Errors: none. Threading: pure functions.
 */
#ifndef VDSH_LIGHT_H
#define VDSH_LIGHT_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define VDSH_FREE_PROBES 14

/* The light region's rule (above). */
#define VDSH_REGION_SEED 0x6f626a6563747321ull /* "object!" */
#define VDSH_REGION_PROBES 1024u
#define VDSH_REGION_FULL 64u  /* free of the PROBES: fully grown at or below */
#define VDSH_REGION_ROOM 256u /* free of the PROBES: the bounds at or above */
#define VDSH_REGION_GROW 0.25f
#define VDSH_REGION_TRIES 4096u

/* The free-space test of a caller (its probes cast with whatever it has):
 * nonzero for free space at p. */
typedef int (*vdsh_free_fn)(const void *ctx, const float p[3]);

/* The probe directions (unit vectors). */
void vdsh_free_probe_dirs(float dirs[VDSH_FREE_PROBES][3]);

/* The clearance for a scene whose bounding box has this diagonal. */
float vdsh_free_clearance(float diagonal);

/* The diagonal of the box lo..hi as both sides take it (summed in double,
 * then rounded to float once): the bake's scene (bake/lib/scene.c) and the
 * runtime's light pool (runtime/vr_view.c) the same bits, so the same
 * clearance (a float sum was an ulp off on some scenes). */
float vdsh_free_diagonal(const float lo[3], const float hi[3]);

/* The decision from the probes' first hits: t[i] the distance (INFINITY:
 * nothing), back[i] nonzero when the face was met from behind (its normal
 * along the ray). Returns 1 for free space. */
int vdsh_free_space(const float t[VDSH_FREE_PROBES], const int back[VDSH_FREE_PROBES],
                    float clearance);

/* Candidate k of the sequence with this seed: uniform in the box lo..hi
 * (a counter-based hash: candidate k does not depend on the others). */
void vdsh_light_candidate(const float lo[3], const float hi[3], uint64_t seed, uint32_t k,
                          float out[3]);

/* The share of the diagonal the bounds grow by when free_count of the
 * first VDSH_REGION_PROBES candidates are free (above): VDSH_REGION_GROW
 * down to 0, linear between VDSH_REGION_FULL and VDSH_REGION_ROOM. */
double vdsh_light_growth(uint32_t free_count);

/* The light region of the scene with bounds lo..hi (above), into
 * out_lo..out_hi (may alias lo, hi); is_free(ctx, p) the caller's test.
 * Returns 1 when the region is a grown box (by any share), 0 when it is
 * the bounds.
 * *probes (may be NULL): the candidates tested. */
int vdsh_light_region(const float lo[3], const float hi[3], vdsh_free_fn is_free, const void *ctx,
                      float out_lo[3], float out_hi[3], uint32_t *probes);

/* The bounds lo..hi grown on every side by VDSH_REGION_GROW of their
 * diagonal (vdsh_free_diagonal; in double, rounded once): the box of
 * vdsh-bake --light-region grown and of the `grown` light rule; but not
 * on a side closed by a one-sided surface, where none of a
 * VDSH_SIDE_GRID x VDSH_SIDE_GRID grid of points two clearances outside
 * that face of the bounds (cell centres) is free (is_free(ctx, p)): below
 * an open floor that spans the bounds (its probes see the floor's back
 * and nothing's front), behind a room's walls. Lights there light none of
 * the surfaces (they face away) and shadow the rest behind the floor:
 * about one in six of the cube-on-a-floor's grown region's lights stood
 * below its floor (docs/ACCURACY.md, "Where your lights go"). A closed
 * object's sides are open (its faces' fronts are seen from outside).
 * Returns a mask of the closed sides: bit 2a for the min side of axis a,
 * 2a + 1 for the max side. */
#define VDSH_SIDE_GRID 5
int vdsh_light_grown_box(const float lo[3], const float hi[3], vdsh_free_fn is_free,
                         const void *ctx, float out_lo[3], float out_hi[3]);

/* The most candidates a placement of count lights tries: 1000 per light
 * in the bounds, VDSH_REGION_TRIES more in a grown region. */
uint64_t vdsh_light_tries(uint32_t count, int grown);

/* Lights placed uniformly in free space: candidates k = 0, 1, ... of seed
 * (vdsh_light_candidate in the region lo..hi) that pass is_free(ctx, p),
 * in sequence order, into out[0..count), until count are found or
 * vdsh_light_tries(count, grown) were tried. The one placement of the
 * bake side (bake/lib/scene.c) and of the runtime's light pool
 * (runtime/vr_view.c: it gave up at 256 candidates per light where the
 * baker tried 1000). Returns how many were placed; *tried (may be NULL)
 * the candidates tried; out_k (may be NULL) each one's candidate index. */
uint32_t vdsh_light_place(const float lo[3], const float hi[3], int grown, uint64_t seed,
                          uint32_t count, vdsh_free_fn is_free, const void *ctx, float (*out)[3],
                          uint32_t *out_k, uint32_t *tried);

#ifdef __cplusplus
}
#endif

#endif /* VDSH_LIGHT_H */
