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
 * sequence, uniform in the scene's bounding box, that pass the test, in
 * sequence order (vdsh_light_candidate): deterministic, the same on every
 * machine.
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

/* The probe directions (unit vectors). */
void vdsh_free_probe_dirs(float dirs[VDSH_FREE_PROBES][3]);

/* The clearance for a scene whose bounding box has this diagonal. */
float vdsh_free_clearance(float diagonal);

/* The decision from the probes' first hits: t[i] the distance (INFINITY:
 * nothing), back[i] nonzero when the face was met from behind (its normal
 * along the ray). Returns 1 for free space. */
int vdsh_free_space(const float t[VDSH_FREE_PROBES], const int back[VDSH_FREE_PROBES],
                    float clearance);

/* Candidate k of the sequence with this seed: uniform in the box lo..hi
 * (a counter-based hash: candidate k does not depend on the others). */
void vdsh_light_candidate(const float lo[3], const float hi[3], uint64_t seed, uint32_t k,
                          float out[3]);

#ifdef __cplusplus
}
#endif

#endif /* VDSH_LIGHT_H */
