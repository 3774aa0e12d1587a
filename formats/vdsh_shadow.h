/*
 * vdsh_shadow.h - the C evaluation of a VDSH shadow: reconstruct the
 * visibility distance toward a light from a coefficient stream and compare
 * it with the light's distance. The evaluator (vdsh-eval) scores with it
 * and the runtime's shaders are tested against it, so there is exactly one
 * definition of what a stored stream means.
 *
 *   v   = (L - p) / |L - p|,  d_L = |L - p|
 *   d_V = D_p(v)                           (vdsh_stream_distance)
 *   s   = ramp(d_V / d_L)                  smooth: ramp(x) = saturate((x - 1/3) * 1.5)
 *   s   = d_V >= d_L ? 1 : 0               binary
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

typedef enum vdsh_compare {
    VDSH_COMPARE_SMOOTH = 0, /* the paper's ramp */
    VDSH_COMPARE_BINARY = 1  /* the paper's reference step */
} vdsh_compare;

/* saturate((x - 1/3) * 1.5); NaN gives 0. */
float vdsh_ramp(float x);

/* The distance a stream reconstructs toward unit direction d, >= 0:
 * quantity distance: the SH sum; distance2: sqrt of the sum; log-distance:
 * exp of the sum. Negative sums (ringing) give 0. */
float vdsh_stream_distance(uint32_t order, uint32_t quantity, const float *c,
                           const float d[3]);

/* Visibility in [0, 1] of a light at distance d_light when the stored
 * distance toward it is d_vis (see the top of this file). */
float vdsh_shadow_compare(float d_vis, float d_light, uint32_t compare);

/* The whole evaluation for one receiver p and light position l. */
float vdsh_shadow(uint32_t order, uint32_t quantity, const float *c,
                  const float p[3], const float l[3], uint32_t compare);

#ifdef __cplusplus
}
#endif

#endif /* VDSH_SHADOW_H */
