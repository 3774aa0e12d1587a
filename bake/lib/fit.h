/*
 * fit.h - from a receiver's projected distances to the coefficients a
 * method stores. Pure C on small arrays: no Embree, no meshes.
 *
 * Every method that looks only at the upper hemisphere is one linear map of
 * the same per-receiver projection b = sum_k w f(d_k) Y(omega_k) (f the
 * quantity: d, d^2 or log d), written in a local frame whose pole is the
 * receiver's normal:
 *
 *     c_world = S M S^T b_world
 *
 * S is the SH rotation taking the pole to the normal (vb_sh_rotation). M
 * depends only on the method's base fit (method.h, vb_fit_base):
 *   identity   M = I                    paper (zero below the horizon), full
 *   mirror     M = I + P                P reflects through the tangent plane,
 *                                       Y_lm(x, y, -z) = (-1)^(l+m) Y_lm
 *   lsq        M = (G + lambda L)^-1    least squares over the hemisphere:
 *                                       G is the hemisphere's Gram matrix of
 *                                       the basis, L = diag((l(l+1))^2)
 * G is invariant under rotations about the pole, so the local frame's
 * azimuth does not matter and M is one matrix for every receiver.
 *
 * That also makes S cheap: any rotation taking the pole to n will do, so
 * S = Rz(alpha) Ry(beta) (n's azimuth and polar angle), and the rotation
 * about y is X^T Rz(beta) X with X the fixed SH rotation by 90 degrees
 * about x. Rotations about z turn each (cos m phi, sin m phi) pair of
 * coefficients by m times the angle, so per receiver only the two small
 * X products per band remain:
 *
 *     c = Rz(alpha) X^T Rz(beta) N Rz(-beta) X Rz(-alpha) b,   N = X M X^T
 *
 * Threading: a created vb_fit is read-only. Errors: vb_result.
 */
#ifndef VB_FIT_H
#define VB_FIT_H

#include <stdint.h>

#include "method.h"
#include "vb.h"
#include "vdsh.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VB_FIT_MAX VDSH_MAX_COEFFS
/* Rotation samples: bands 0-4, and bands 5 and up (2l + 1 <= 31 functions
 * each, three times over-determined). */
#define VB_FIT_ROT_DIRS 36
#define VB_FIT_ROT_DIRS_HIGH 96

typedef struct vb_fit {
    int order;                          /* coefficients kept: order^2 */
    vb_fit_base base;                   /* the map (a method's row, method.h) */
    float lambda;                       /* lsq regularisation */
    double window[VB_FIT_MAX];          /* per coefficient: its band's weight */
    double hemi[VB_FIT_MAX];            /* X times the integral over z > 0 of
                                         * Y_i: the projection of the constant 1,
                                         * in u's frame (vb_fit_unrotate) */
    double M[VB_FIT_MAX * VB_FIT_MAX];  /* local-frame map, order^2 square */
    double NT[VB_FIT_MAX * VB_FIT_MAX]; /* N = X M X^T, order^2 square,
                                       * column-major */
    /* per band l: the (2l+1)^2 block of X, and its transpose */
    double X[VDSH_MAX_ORDER][VDSH_MAX_BAND_WIDTH * VDSH_MAX_BAND_WIDTH];
    double XT[VDSH_MAX_ORDER][VDSH_MAX_BAND_WIDTH * VDSH_MAX_BAND_WIDTH];
    /* Rotations: sample directions and, per band l, the pseudo-inverse of
     * the (2l+1) x VB_FIT_ROT_DIRS basis block at them. */
    double rot_dirs[VB_FIT_ROT_DIRS][3];
    double rot_dirs_high[VB_FIT_ROT_DIRS_HIGH][3];
    double rot_pinv[VDSH_MAX_ORDER][VB_FIT_ROT_DIRS_HIGH * VDSH_MAX_BAND_WIDTH];
} vb_fit;

/* The regularisation weight an order's lsq fit uses for a method's
 * `lambda`: lambda itself at orders 1..5; above, scaled so that the top
 * band's penalty lambda (l(l+1))^2 stays order 5's (band 4's): the
 * paper's orders keep their fits, and the high bands that long shadows
 * need are not damped away (lambda 1e-4 would shrink band 15 to 8%). */
float vb_fit_lambda(float lambda, int order);

/* Gauss-Legendre nodes and weights on [-1, 1]. */
void vb_gauss_legendre(int n, double *x, double *w);

/* Prepare the map for (order, base fit, lambda); lambda matters for
 * VB_FIT_LSQ only. A method's base fit is its row's (method.h). The
 * hemisphere Gram matrix is computed by Gauss-Legendre x uniform-azimuth
 * quadrature (exact for these polynomials). */
vb_result vb_fit_create(int order, vb_fit_base base, float lambda, vb_fit *out, vb_error *err);

/* The per-band window applied to a fit's coefficients: Hann
 * (1 + cos(pi l / order)) / 2, Lanczos sinc(l / order), 1 for none; band
 * l of `order` bands (vdsh_window values). */
double vb_window_weight(vdsh_window window, int l, int order);

/* Scale the map's rows by the window (c_lm *= w_l). */
void vb_fit_window(vb_fit *f, vdsh_window window);

/* c = S M S^T b for a receiver with unit normal n (b and c: order^2
 * values, world frame; b in double for the sums it comes from). A zero
 * normal has no hemisphere: c = b (the projection as it is). */
void vb_fit_apply(const vb_fit *f, const float n[3], const double *b, float *c);

/* vb_fit_apply in two steps, so that fits of several orders for one
 * receiver share the first (the leading bands of the highest order's u
 * are the lower orders' u). vb_fit_frame: the angles of unit normal n,
 * and whether f rotates at all (base fit mirror or lsq, and a non-zero normal).
 * vb_fit_unrotate: u = Rz(-beta) X Rz(-alpha) b over f's bands (u = b
 * if f does not rotate). vb_fit_finish: c = window * (the rest of the
 * product above), from the first order^2 values of a u made by a fit of
 * the same method and any order >= f->order. */
typedef struct vb_fit_angles {
    int rotates;
    /* cos, sin of m alpha and of m beta, m = 0..VDSH_MAX_ORDER - 1 */
    double ca[VDSH_MAX_ORDER], sa[VDSH_MAX_ORDER];
    double cb[VDSH_MAX_ORDER], sb[VDSH_MAX_ORDER];
} vb_fit_angles;

void vb_fit_frame(const vb_fit *f, const float n[3], vb_fit_angles *a);
void vb_fit_unrotate(const vb_fit *f, const vb_fit_angles *a, const double *b, double *u);
void vb_fit_finish(const vb_fit *f, const vb_fit_angles *a, const double *u, float *c);

/* A constant m taken out of the projected values (f - m projected, for a
 * fit that does not depend on the units f's level is in), put back
 * exactly: u += m times the exact projection of 1 over the directions
 * projected (the hemisphere about the normal, or the whole sphere).
 * vb_fit_constant_exact says whether it can be (a fit that rotates, or a
 * whole-sphere projection, in which frame the constant is the same);
 * then a constant in, m sqrt(4 pi) on c_0 out of vb_fit_finish (times
 * the window's band 0), the other coefficients untouched. */
int vb_fit_constant_exact(const vb_fit_angles *a, int hemisphere);
void vb_fit_add_constant(const vb_fit *f, int hemisphere, double m, double *u);

/* SH rotation for bands 0..order-1: out (order^2 x order^2, row-major,
 * block-diagonal) such that if f(w) = sum c_i Y_i(R^T w) then
 * f(w) = sum (out c)_i Y_i(w). R is row-major 3x3, columns the images of
 * the local x, y, z axes. */
void vb_sh_rotation(const vb_fit *f, const double R[9], double *out);

#ifdef __cplusplus
}
#endif

#endif /* VB_FIT_H */
