/*
 * origins.h - where each receiver's rays start, and which way it faces.
 *
 * The rule (vb_ray_origins): the receiver position in the scene's
 * normalised frame (scene.h), offset twice with vb_offset_origin: along
 * the normal averaged over the receiver vertices at the same position that
 * face the same side (vb_offset_normals), then along the inset vector into
 * the vertex's own triangles. The first keeps the unwelded corners of a
 * closed room from leaking rays between their faces' planes; the second
 * lifts vertices on a boundary off any other surface whose plane they lie
 * in (a floor's edge on the wall it meets, a pillar's foot on the floor):
 * without it, half of such a vertex's rays start on the wall's plane and
 * escape the room.
 *
 * The repair: every receiver is probed with 16 short rays above its
 * horizon and their 16 mirror images below. "Short" is the receiver's
 * near distance (vb_receiver_near: 1e-3 of the scene diagonal, or a tenth
 * of its own mean edge where that is smaller, so that small parts of a
 * large scene are judged at their own scale). A receiver left inside or
 * squeezed against other geometry (~90% of the upper probes hit), or
 * pushed through a surface it touches (a quarter of the probes end on the
 * back of a surface) is moved along its own triangles toward their
 * centroids, to the first point that passes (else the least bad).
 *
 * Coincident faces. Two faces in one plane with opposite orientation (a
 * box resting on a floor: its bottom and the floor; a double-sided sheet)
 * meet a ray at the same distance to within an ulp, and which of them an
 * Embree kernel reports first depends on its arithmetic and traversal
 * order: SSE, AVX2 and AVX-512 kernels answer differently. So every probe
 * sees all the faces within its window (a context filter), and a ray
 * whose nearest faces include both orientations within a few ulps of
 * its distance is classified as such, never by whichever came first. A
 * receiver flagged only by such ties (a sheet's two sides, a box bottom on
 * a floor) is repaired only if its full-length upper probes all escape:
 * the box bottom looks through the floor into the void, a sheet does not.
 *
 * Corners (vb_scene.corner_lift: bakes whose computed normals split at
 * creases). A receiver with another normal at its position (a split
 * vertex's fans, an unwelded box corner) faces its own triangles only, so
 * its hemisphere holds rays toward the faces beside it, which pass their
 * shared edges within the offset (~2^-17 of the frame) of the origin:
 * whether such a ray hits a face beside it at distance ~0 or slips past
 * its edge is Embree's rounding, and each kernel set (SSE4.2 to AVX-512)
 * answers differently for some ray (Sponza with --crease 60: one ray of
 * 256 at 3 receivers, moving their fits by up to 0.28 of the largest
 * coefficient). The share of such rays falls with the origin's distance
 * from those edges, so a corner's standard origin is offset VB_CORNER_LIFT
 * times as far (still ~1e-4 of the frame, under its near distance).
 * Without creases (the flag 0) origins are as before, bit for bit.
 *
 * A receiver whose triangles all have no area (cross product exactly 0,
 * the loader's test; its normal came from the file) is drawn nowhere: it
 * keeps the standard origin and is not probed (stats: skipped_zero_area).
 *
 * Cost: the first probe is 32 short rays per receiver. A flagged receiver
 * tries at most VB_REPAIR_CANDIDATES points (short probes each), and at
 * most three full-length escape tests; vb_origins_stats counts every ray.
 *
 * Determinism: every decision depends on the receiver's own data and
 * the scene only; the output does not depend on the thread count. It can
 * depend on the Embree kernel (ISA) where a probe grazes an edge or ends
 * exactly at its window: tests/test_hard.c runs under every ISA.
 *
 * Errors: vb_result. Threading: `threads` workers as vb_parallel_for.
 */
#ifndef VB_ORIGINS_H
#define VB_ORIGINS_H

#include <stdint.h>

#include "mesh.h"
#include "scene.h"
#include "vb.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VB_REPAIR_CANDIDATES 24

/* How many times further a corner's standard origin is offset when the
 * scene asks (vb_scene.corner_lift; "Corners" above). */
#define VB_CORNER_LIFT 16.0f

typedef struct vb_origins_stats {
    uint32_t moved;             /* receivers whose origin the repair moved */
    uint32_t flagged;           /* receivers the first probe sent to the repair */
    uint32_t ties;              /* receivers whose probes met coincident faces */
    uint32_t skipped_zero_area; /* receivers with a normal whose triangles all have
                                 * no area: drawn nowhere, not probed */
    uint64_t probe_rays;        /* rays traced by the probes and the repair */
    double seconds;             /* wall time of vb_ray_origins */
} vb_origins_stats;

/* The ray-offset normals: for every receiver vertex, the normalised sum of
 * the normals of the receiver vertices at its bit-identical position that
 * face its own side (n_u . n_v >= 0; its own included). out has
 * 3 * vertex_count floats. */
vb_result vb_offset_normals(const vb_mesh *m, float *out, vb_error *err);

/* "~0 distance" for a receiver whose adjacent edges have mean length
 * `mean_edge` (scene units; 0 when it has none) in a scene of diagonal
 * `diag`: min(1e-3 diag, 0.1 mean_edge). */
float vb_receiver_near(float diag, float mean_edge);

/* Ray origins in the scene's traced frame for every receiver (3 floats
 * each) by the rule and the repair above. near_out (may be NULL) receives
 * each receiver's near distance in scene units; stats (may be NULL) what
 * the repair did. */
vb_result vb_ray_origins(const vb_mesh *m, const vb_scene *s, unsigned threads, float *out,
                         float *near_out, vb_origins_stats *stats, vb_error *err);

/* Face receivers toward free space: a receiver whose normal points into a
 * solid - full-length probes toward +n mostly (14 of 16) hit the backs of
 * faces, while from just behind its surface toward -n as many hit the
 * fronts of faces (escaping rays do not count: a floor under a crate has
 * a solid above it and the void outside the room below) - has an inverted
 * normal (common in imported meshes). Its normal is flipped in place, so
 * the hemisphere the bake fits and the normal stored for shading face
 * where it can be seen from. Back faces are judged by triangle winding, so
 * a mesh turned inside out as a whole (winding and normals both inverted)
 * is left alone; a ray meeting coincident faces of both orientations sees
 * a front face. `flipped` (may be NULL) receives how many. */
vb_result vb_orient_receivers(vb_mesh *m, const vb_scene *s, unsigned threads, uint32_t *flipped,
                              vb_error *err);

/* The bake's receivers in one pass over their frames (built once):
 * vb_orient_receivers (when `normals` is not NULL: m's normals are copied
 * there and oriented in the copy; m is not changed) then vb_ray_origins
 * with the oriented normals. `flipped` and `stats` may be NULL; stats'
 * seconds count the origins only. The same results as the two calls.
 * set (NULL: every receiver, set_count ignored) lists, ascending, the
 * receivers a bake traces (a shard's range and the quantity choice's
 * sample, the midpoints of adaptive refinement): only they get an origin,
 * a near distance and an oriented normal, at their slot j (receiver
 * set[j]) of out (3 floats), near_out and normals (3 floats), each bit for
 * bit what the whole set would give them. The frames are built for them
 * and the receivers at their positions only (those are oriented too, since
 * their normals enter the set's ray-offset normals), so the memory is the
 * set's, plus 1.5 bits per receiver of m. `flipped` and `stats` count the
 * receivers in [count_begin, count_end) (with set NULL: every one). */
vb_result vb_receivers_prepare(const vb_mesh *m, const vb_scene *s, unsigned threads,
                               const uint32_t *set, uint32_t set_count, uint32_t count_begin,
                               uint32_t count_end, float *normals, uint32_t *flipped, float *out,
                               float *near_out, vb_origins_stats *stats, vb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* VB_ORIGINS_H */
