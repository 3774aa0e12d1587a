/*
 * vdsh_sh.h - the one C evaluation of the real SH basis used everywhere.
 *
 * Purpose: evaluate the real, orthonormal spherical-harmonic basis up to
 * order VDSH_MAX_ORDER in the D3DX/DirectXMath convention that the paper
 * used (Condon-Shortley phase, index i = l(l+1)+m). Bands 0-4 (order 5,
 * 25 functions) by the closed forms below; bands 5 and up by the
 * associated-Legendre recurrence in the same convention:
 *
 *   band 0   0.282095
 *   band 1   0.488603 * (-y, z, -x)
 *   band 2   1.092548 xy, -1.092548 yz, 0.315392 (3z^2-1), -1.092548 xz,
 *            0.546274 (x^2-y^2)
 *   band 3   -0.590044 y(3x^2-y^2), 2.890611 xyz, -0.457046 y(5z^2-1),
 *            0.373176 z(5z^2-3), -0.457046 x(5z^2-1), 1.445306 z(x^2-y^2),
 *            -0.590044 x(x^2-3y^2)
 *   band 4   2.503343 xy(x^2-y^2), -1.770131 yz(3x^2-y^2),
 *            0.946175 xy(7z^2-1), -0.669047 yz(7z^2-3),
 *            0.105786 (35z^4-30z^2+3), -0.669047 xz(7z^2-3),
 *            0.473087 (x^2-y^2)(7z^2-1), -1.770131 xz(x^2-3y^2),
 *            0.625836 (x^4-6x^2y^2+y^4)
 *
 * The bake, the evaluator, the tests and (by a rendering test) the GLSL in
 * runtime/ all agree with this file.
 *
 * Does not: normalise directions (callers pass unit vectors), rotate or
 * window coefficients.
 *
 * Errors: none; orders outside 1..VDSH_MAX_ORDER are programmer errors
 * (asserted).
 * Threading: pure functions.
 */
#ifndef VDSH_SH_H
#define VDSH_SH_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The normalisation constants K_l^m of the basis above (sqrt(2) folded in
 * for m != 0), named by band and |m| (C2A: band 2, the xy/yz/xz terms;
 * B: the second use of a band's |m|), as float literals that both C and
 * GLSL 3.30 read. vdsh_sh.c evaluates with them and runtime/vr_glsl.c
 * writes them into its shaders: one definition of the basis. */
#define VDSH_SH_C00 0.28209479177387814f
#define VDSH_SH_C1 0.4886025119029199f
#define VDSH_SH_C2A 1.0925484305920792f
#define VDSH_SH_C20 0.31539156525252005f
#define VDSH_SH_C22 0.5462742152960396f
#define VDSH_SH_C33 0.5900435899266435f
#define VDSH_SH_C32 2.890611442640554f
#define VDSH_SH_C31 0.4570457994644658f
#define VDSH_SH_C30 0.3731763325901154f
#define VDSH_SH_C32B 1.445305721320277f
#define VDSH_SH_C44 2.5033429417967046f
#define VDSH_SH_C43 1.7701307697799304f
#define VDSH_SH_C42 0.9461746957575601f
#define VDSH_SH_C41 0.6690465435572892f
#define VDSH_SH_C40 0.10578554691520431f
#define VDSH_SH_C42B 0.47308734787878004f
#define VDSH_SH_C44B 0.6258357354491761f

/* Number of coefficients of an order (bands): order * order. */
static inline int vdsh_sh_count(int order)
{
    return order * order;
}

/* out[0 .. order^2-1] = Y_i(d) for a unit direction d. */
void vdsh_sh_eval(int order, const float d[3], float *out);

/* Batch form for n directions given as separate x, y, z arrays:
 * out[i * out_stride + k] = Y_i(direction k). Same arithmetic as
 * vdsh_sh_eval (one kernel), laid out so the compiler vectorises over k.
 * `out` must not overlap the inputs. */
void vdsh_sh_eval_soa(int order, size_t n, const float *x, const float *y, const float *z,
                      float *out, size_t out_stride);

/* Projection step for n directions with weights w (the bake's distances):
 * acc[i * acc_stride + k] += w[k] * Y_i(direction k). The same kernel;
 * the caller sums acc over k (in a fixed order) and scales. `acc` must not
 * overlap the inputs. */
void vdsh_sh_project_soa(int order, size_t n, const float *x, const float *y, const float *z,
                         const float *w, float *acc, size_t acc_stride);

/* Reconstruct sum_i c[i] * Y_i(d). */
float vdsh_sh_reconstruct(int order, const float *c, const float d[3]);

#ifdef __cplusplus
}
#endif

#endif /* VDSH_SH_H */
