/*
 * vdsh_shadow.h - the C evaluation of a VDSH shadow: reconstruct the
 * visibility distance toward a light from a coefficient stream and compare
 * it with the light's distance. The evaluator (vdsh-eval) scores with it
 * and the runtime's shaders are tested against it, so there is exactly one
 * definition of what a stored stream means.
 *
 *   v   = (L - p) / |L - p|,  d_L = |L - p|
 *   d_V = clamp(D_p(v), 0, max_distance)   (vdsh_stream_distance)
 *   s   = ramp(d_V / d_L)                  smooth: ramp(x) = saturate((x - 1/3) * 1.5)
 *   s   = d_V >= d_L ? 1 : 0               binary
 *
 * max_distance is the bake's clamp distance (vdsh_header.max_distance):
 * no stored distance exceeded it (a ray that missed got it), so no
 * reconstruction may either. The fit only constrains the upper
 * hemisphere; below a vertex's horizon, and near it for low orders, a
 * log-distance sum can run away to millions of times the scene's size,
 * and the runtime does evaluate there (smooth normals, terminators), where
 * one huge vertex distance interpolated across a triangle leaks light.
 *
 * Defined everywhere: a reconstructed distance that rings negative counts
 * as 0; a light at the receiver (d_L = 0) is unshadowed (s = 1), as is
 * any light when d_V is +Inf; NaN inputs give s = 0, never NaN.
 *
 * libc only. Pure functions, thread-safe.
 */
#ifndef VDSH_SHADOW_H
#define VDSH_SHADOW_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* How a reconstructed distance d_V is compared with the light's d_L. One
 * row per value in vdsh_shadow.c's table (its name and its function);
 * adding one: a value here, its row there, its GLSL in runtime/vr_glsl.c
 * (tested against this file by tests/test_runtime_glsl.c). */
typedef enum vdsh_compare {
    VDSH_COMPARE_SMOOTH = 0, /* the paper's ramp (the default) */
    VDSH_COMPARE_BINARY = 1, /* the paper's reference step */
    VDSH_COMPARE_COUNT
} vdsh_compare;

/* "smooth", "binary"; "?" for an unknown value. */
const char *vdsh_compare_name(uint32_t compare);

/* The comparison named `name`, or VDSH_COMPARE_COUNT for none. */
vdsh_compare vdsh_compare_by_name(const char *name);

/* saturate((x - 1/3) * 1.5), computed as saturate(VDSH_RAMP_SLOPE * x -
 * VDSH_RAMP_OFFSET) so that x = 1/3 and x = 1 give exactly 0 and 1 in
 * float; NaN gives 0. */
float vdsh_ramp(float x);

/* The constants of this file that the runtime's shaders also compute with,
 * as float literals that both C and GLSL 3.30 read: runtime/vr_glsl.c
 * writes these very macros into its source, so the ramp and the clamp of
 * the GLSL cannot drift from the C definition (and tests/
 * test_runtime_glsl.c checks the result by rendering). */
#define VDSH_RAMP_SLOPE 1.5f
#define VDSH_RAMP_OFFSET 0.5f
/* A log-distance sum above this reads as exp(VDSH_LOG_SUM_MAX), about
 * 5.5e34, before the clamp to max_distance: finite even with no clamp
 * (max_distance +Inf), so that the runtime's interpolation of per-vertex
 * distances never meets 0 * inf. */
#define VDSH_LOG_SUM_MAX 80.0f

/* The relative light model, the evaluator's secondary metric and the
 * bake's choice of quantity (bake.h, VB_QUANTITY_AUTO): one light per
 * direction at d_L = 2 u d_T, d_T the true distance, u uniform in
 * (VDSH_LIGHT_U_MIN, 1]. vdsh_light_u maps t in (0, 1] onto u, in double
 * (the bake) and in float (the evaluator), each with the literals it has
 * always used, so the results keep their bits. */
#define VDSH_LIGHT_U_MIN 0.05
static inline double vdsh_light_u(double t)
{
    return VDSH_LIGHT_U_MIN + (1.0 - VDSH_LIGHT_U_MIN) * t;
}
static inline float vdsh_light_u_f(float t)
{
    return (float)VDSH_LIGHT_U_MIN + (float)(1.0 - VDSH_LIGHT_U_MIN) * t;
}

/* The distance a stream reconstructs toward unit direction d, in
 * [0, max_distance]: quantity distance: the SH sum; distance2: sqrt of the
 * sum; log-distance: exp of the sum. Negative sums (ringing) give 0, and
 * anything above max_distance gives max_distance. max_distance is the
 * file's vdsh_header.max_distance (> 0), here and in every function
 * below; +INFINITY clamps nothing. */
float vdsh_stream_distance(uint32_t order, uint32_t quantity, float max_distance, const float *c,
                           const float d[3]);

/* Visibility in [0, 1] of a light at distance d_light when the stored
 * distance toward it is d_vis (see the top of this file). */
float vdsh_shadow_compare(float d_vis, float d_light, uint32_t compare);

/* The whole evaluation for one receiver p and light position l. */
float vdsh_shadow(uint32_t order, uint32_t quantity, float max_distance, const float *c,
                  const float p[3], const float l[3], uint32_t compare);

/* How a renderer carries the stream from a triangle's vertices to a point
 * p = sum b_k p_k inside it (the GPU interpolates linearly):
 *   COEFFICIENTS  the coefficients are interpolated; the distance is
 *                 reconstructed at p toward the light
 *   DISTANCE      each vertex reconstructs its distance toward the light
 *                 from where it is; the distances are interpolated and
 *                 compared at p with p's own light distance
 *   VISIBILITY    each vertex compares too; visibility is interpolated
 *                 (the paper's orders 2 and 3, all in the vertex stage)
 *   SPLIT         bands 0-2 are summed per vertex toward the light and the
 *                 sums interpolated; bands 3-4 at p from interpolated
 *                 coefficients (the paper's order 5: 9 coefficients in the
 *                 vertex stage, 16 in the fragment stage)
 * For a linear quantity and a distant light they all agree; they differ
 * where a triangle is large next to its distance to the light, and for
 * log-distance, where interpolating coefficients is a geometric mean of the
 * vertices' distances (dominated by the smallest). */
typedef enum vdsh_interp {
    VDSH_INTERP_COEFFICIENTS = 0,
    VDSH_INTERP_DISTANCE = 1,
    VDSH_INTERP_VISIBILITY = 2,
    VDSH_INTERP_SPLIT = 3
} vdsh_interp;

/* "coefficients", "distance", "visibility", "split"; "?" otherwise. */
const char *vdsh_interp_name(uint32_t interp);

/* The path runtime/ draws a stream with: log-distance per vertex and
 * interpolated as DISTANCE (its exp cannot be split across stages);
 * otherwise the paper's: VISIBILITY for orders 1-3, SPLIT for 4-5. */
uint32_t vdsh_runtime_interp(uint32_t order, uint32_t quantity);

/* Visibility at p = sum b_k pv[k] for a light at l, carried by `interp`;
 * c[k] holds vertex k's order^2 coefficients. Every distance is clamped
 * where it is reconstructed (per vertex, or at p), before it is
 * interpolated, so d_vis never exceeds max_distance. If d_vis is not NULL
 * it receives the distance compared (for VISIBILITY: the interpolated
 * vertex distances, for scoring). Defined for every input as vdsh_shadow
 * is. */
float vdsh_shadow_interior(uint32_t order, uint32_t quantity, float max_distance, uint32_t interp,
                           const float *const c[3], const float *const pv[3], const float b[3],
                           const float l[3], uint32_t compare, float *d_vis);

/* The per-vertex half of the DISTANCE and VISIBILITY paths: the distance
 * vertex pv reconstructs toward the light at l from its order^2
 * coefficients c (vdsh_stream_distance toward l from pv; 0 for a light at
 * the vertex). It depends on the vertex and the light only, so a caller
 * may compute it once per vertex and light, as the runtime's vertex stage
 * does, and a variable-order stream's vertex with its own order. */
float vdsh_vertex_distance(uint32_t order, uint32_t quantity, float max_distance, const float *c,
                           const float pv[3], const float l[3]);

/* The rest of the DISTANCE path: dv[k], vertex k's vdsh_vertex_distance,
 * interpolated at p = sum b_k pv[k] and compared with p's own light
 * distance. vdsh_shadow_interior computes its DISTANCE path with these two
 * functions, so the result is the same to the bit. d_vis as there. */
float vdsh_shadow_interior_distance(const float dv[3], const float *const pv[3], const float b[3],
                                    const float l[3], uint32_t compare, float *d_vis);

#ifdef __cplusplus
}
#endif

#endif /* VDSH_SHADOW_H */
