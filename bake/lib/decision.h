/*
 * decision.h - the decision fit: per receiver, the coefficients of ln D
 * that minimise a smooth loss of the shadow decision itself, not the
 * squared error of the distance (issue 25; docs/DESIGN.md, "The decision
 * fit").
 *
 * Given pairs i = (direction w_i above the horizon, light distance d_i,
 * label: lit or shadowed, traced), with s_i = +1 for shadowed and -1 for
 * lit pairs and m_i(c) = c . Y(w_i) - ln d_i,
 *
 *     L(c) = sum_i a_i softplus(s_i m_i / tau) / sum_i a_i
 *          + sum_j r_j (c_j - c0_j)^2
 *
 * a_i the label's weight (lit pairs higher: a false shadow on a lit wall
 * costs more than a missed one), r_j = ridge (l(l+1))^2 + ridge0 on
 * coefficient j of band l, toward the least-squares fit c0, which is also
 * the start. L is convex in c; Newton steps with the exact Hessian
 * (Cholesky, step halving) find its minimum in a few steps.
 *
 * Pure C on small arrays: no Embree (the bake traces the labels). All
 * arithmetic is plain float and double with fixed-order sums and its own
 * exp and log (no libm: glibc picks other code on FMA-capable CPUs), so
 * the result is the same bits on every x86-64 CPU and for any thread
 * count.
 *
 * Errors: none (a degenerate system keeps the start). Threading: pure.
 */
#ifndef VB_DECISION_H
#define VB_DECISION_H

#include <stdint.h>

#include "vdsh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The settings (docs/ACCURACY.md, "The decision fit: settings"). */
typedef struct vb_decision_params {
    float tau;        /* softplus temperature, ln units */
    float lit_weight; /* a_i of lit pairs (shadowed: 1) */
    float ridge;      /* times (l(l+1))^2, toward the lsq fit */
    float ridge0;     /* on every coefficient, toward the lsq fit */
    int steps;        /* Newton steps at most */
    int hessians;     /* steps with a fresh Hessian (0: every step); later
                       * steps keep the last one's factor */
} vb_decision_params;

/* The defaults: chosen on the validation scenes. */
void vb_decision_defaults(vb_decision_params *p);

/* Largest number of pairs one fit takes. */
#define VB_DECISION_MAX_PAIRS 1024

/* Fit order `order` (n = order^2 coefficients) from `m` pairs.
 * Y: the basis at the pairs' directions, row j (coefficient j) at
 * Y + j * stride, at least n rows. logd: ln d_i. shadowed: 1 for a
 * shadowed pair, 0 for a lit one. c: in, the start (the least-squares
 * fit); out, the fit. scratch: vb_decision_scratch_floats(order) floats.
 * Returns the Newton steps taken (0: the start kept). */
int vb_decision_fit(int order, uint32_t m, const float *Y, uint32_t stride, const float *logd,
                    const uint8_t *shadowed, const vb_decision_params *p, float *c,
                    double *scratch);

/* The decision loss of the coefficients c (order^2 of them, as
 * vb_decision_fit's start) on the same pairs, without the ridge, at the
 * offset b added to every margin that minimises it (into *offset): how
 * well the shape of c alone draws the pairs' decisions. The adaptive
 * order scores its least-squares candidates so. scratch:
 * vb_decision_scratch_doubles(order) doubles suffice. */
float vb_decision_score(int order, uint32_t m, const float *Y, uint32_t stride, const float *logd,
                        const uint8_t *shadowed, const vb_decision_params *p, const float *c,
                        float *offset, double *scratch);

/* Doubles of scratch for vb_decision_fit at this order. */
size_t vb_decision_scratch_doubles(int order);

/* The offset to add to every fitted ln D so that `rate` (e.g. 0.008) of
 * the lit pairs' margins m_i = ln D(w_i) - ln d_i end below 0: minus the
 * rate-quantile of `margins` (count values; sorted in place). 0 when
 * count is 0. */
float vb_decision_offset(float *margins, uint32_t count, double rate);

#ifdef __cplusplus
}
#endif

#endif /* VB_DECISION_H */
