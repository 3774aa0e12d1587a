/*
 * sdf.h - bake the signed distance volume of the occluders (the runtime's
 * distance-field shadow mode; the file is formats/vdsh_sdf.h's).
 *
 * Distances: exact closest point on each triangle (Ericson, Real-Time
 * Collision Detection 5.1.5, in double precision, in this file), found
 * with Embree's point queries (rtcPointQuery) in the scene's traced frame
 * (the power-of-two scaling is exact). The minimum does not depend on the
 * order Embree visits triangles in, so the volume is the same on every ISA
 * and for any thread count.
 * Sign: scenes are not always closed (a room is seen from inside, an
 * object from outside), so no parity count: of the 14 probe rays of
 * formats/vdsh_light.h from the sample (turned by one fixed rotation, so
 * that no probe runs along an axis-aligned wall or through its corners), a sample is inside a solid
 * (negative) when more first meet the back of a face than the front;
 * rays that meet nothing count for neither. Free space in an open room,
 * around an object or under a sky is positive; inside a closed object and
 * behind a room's walls negative.
 * Grid: `resolution` samples per longest side of the occluders' bounds,
 * one more spacing of margin on every side, at most VDSH_SDF_MAX_DIM per
 * axis; max_distance the bounds' diagonal.
 *
 * Errors: vb_result (VB_ERR_ARGUMENT for a resolution out of range,
 * VB_ERR_OUT_OF_MEMORY). Ownership: *out's samples are the caller's
 * (vdsh_sdf_free). Threading: runs on vb_parallel_for's workers.
 */
#ifndef VB_SDF_H
#define VB_SDF_H

#include "scene.h"
#include "vdsh_sdf.h"

#ifdef __cplusplus
extern "C" {
#endif

enum { VB_SDF_MIN_RESOLUTION = 4, VB_SDF_MAX_RESOLUTION = 512 };

/* s must have been created from `occluders` (vb_scene_create). */
vb_result vb_sdf_bake(const vb_scene *s, const vb_mesh *occluders, int resolution, unsigned threads,
                      vdsh_sdf *out, vb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* VB_SDF_H */
