/*
 * fit_shadow.h - the shadow fit (method `shadow`): the log-distance
 * coefficients that minimise the expected shadow error itself, rather than
 * a squared error that only stands in for it. Pure C on small arrays.
 *
 * The error: DESIGN.md section 3 scores a stream by lights at d_L = 2 u d,
 * u uniform in (0.05, 1], in each direction whose true distance is d. The
 * mean |ramp(r / 2u) - ramp(1 / 2u)| over u is a function e(r) of the
 * ratio r = D / d of the reconstructed to the true distance alone: 0 at
 * r = 1, about 0.55 |ln r| near it, flat from r = 2 on (every light is lit
 * either way) and rising to 0.76 as r -> 0. In the log domain,
 * x = c . Y(w) - ln d, the loss is eps(x) = e(exp x) down to r = 2/3 and
 * from there a straight line in x with e's slope at 2/3: an L1-like
 * error that stops growing where an overestimate no longer matters (every
 * light lit either way) but keeps growing with an underestimate. Least
 * squares of ln d gives the directions a fit of few coefficients cannot
 * follow the largest say; this fit lets it overestimate them, and spends
 * the coefficients where the shadows are. (With e itself below 2/3, which
 * saturates, the fit also gave up directions it underestimated, and
 * neighbouring receivers gave up different ones: blotches of false shadow
 * on flat walls at orders 2 and 3, and a higher error on the test scenes.)
 *
 * Solve: iteratively reweighted least squares from the lsq fit, with
 * weights eps'(x) / x (x clamped away from 0 by a width that narrows over
 * the iterations, 0.5 to 0.1: the early wide steps keep the fit from
 * locking onto the L1 kink), and the lsq regularisation lambda
 * sum (l(l+1))^2 c^2. Each step is a small weighted normal equation solved
 * by Cholesky. On the traced directions of the paper-sized room, Cornell,
 * Sponza, the Newell teapot and the rocker arm, eight steps on a quarter
 * of the 1225 directions reach within a few percent of the same fit made
 * on the held-out truth itself (docs/ACCURACY.md).
 *
 * Determinism: every sum runs in a fixed order; same inputs, same bits.
 * Threading: a vb_shadow_fit is read-only once made; share it.
 * Errors: vb_shadow_fit_init can run out of memory; the fit itself has
 * none (inputs are finite by contract; a singular step keeps the
 * previous coefficients).
 */
#ifndef VB_FIT_SHADOW_H
#define VB_FIT_SHADOW_H

#include <stdint.h>

#include "vb.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VB_SHADOW_TABLE 1024   /* tabulated points of e(r) and eps'(x) */
#define VB_SHADOW_STEPS 8      /* IRLS steps: 2 per weight width */
#define VB_SHADOW_MAX_DIRS 640 /* directions a fit may use (a subset of the traced ones) */

#define VB_SHADOW_TAIL 0.02f   /* loss slope past e's flat end, r > 2 (see irls_weight8) */
#define VB_SHADOW_TERMS 4096 /* non-zero triple products (about 2,900) */

typedef struct vb_shadow_fit {
    double e[VB_SHADOW_TABLE + 1];       /* e(r), r in [0, 2] */
    /* The normal matrix from moments: for the pair (i, j), j <= i < 25,
     * p = i (i + 1) / 2 + j, G_ij = sum over its terms of value * m_L. */
    uint32_t pair_start[326];
    uint8_t term_moment[VB_SHADOW_TERMS];
    double term_value[VB_SHADOW_TERMS];
} vb_shadow_fit;

/* Fill the tables (a few milliseconds). VB_ERR_OUT_OF_MEMORY. */
vb_result vb_shadow_fit_init(vb_shadow_fit *f, vb_error *err);

/* e(r): the expected shadow error of a direction reconstructed at r times
 * its true distance (r >= 0; flat from 2 on). */
double vb_shadow_error(const vb_shadow_fit *f, double r);

/* Refine c (order^2 coefficients of ln d, world frame, in and out) on n
 * directions (n <= VB_SHADOW_MAX_DIRS). y holds their basis values up to
 * twice the order less one (vdsh_sh_eval_soa of order 2 order - 1, 81
 * rows for order 5): y[i * stride + k] = Y_i(direction k); lnd[k] the log
 * of the true distance, floored as the stream's log floor. stride is a
 * multiple of 8 and at least n; y and lnd are 32-byte aligned and finite
 * up to stride (the entries from n on are ignored). With n < order^2 + 1
 * there is nothing to fit and c is left as it is. lambda weighs the
 * regularisation lambda sum (l(l+1))^2 c^2 (as lsq's). */
void vb_shadow_fit_apply(const vb_shadow_fit *f, int order, float lambda, uint32_t n,
                         const float *y, uint32_t stride, const float *lnd, float *c);

#ifdef __cplusplus
}
#endif

#endif /* VB_FIT_SHADOW_H */
