/*
 * vdsh_cube.h - cube-map face conventions: the one place that knows how an
 * OpenEXR cube environment map's faces are oriented and how that differs
 * from GL's cube-map faces; and the SH basis cubemaps' texels in both.
 * libc only.
 *
 * Both conventions stack/number the faces +X, -X, +Y, -Y, +Z, -Z (0..5).
 * Within a face of n x n texels, texel (i, j) has its centre at
 *     u = 2 (i + 0.5) / n - 1,   v = 2 (j + 0.5) / n - 1
 * where i is the column and j the row (row 0 first in memory: the top row
 * of the EXR face image, and the first row passed to glTexImage2D).
 *
 * GL (OpenGL 4.6 core spec, section 8.13, table 8.19, which gives sc, tc
 * and ma per major axis), direction of texel (i, j), writing s = sc/|ma|
 * = u and t = tc/|ma| = v (the spec's [0,1] coordinates are (s+1)/2 and
 * (t+1)/2):
 *     +X (1, -t, -s)   -X (-1, -t, s)   +Y (s, 1, t)
 *     -Y (s, -1, -t)   +Z (s, -t, 1)    -Z (-s, -t, -1)
 * OpenEXR (ImfEnvmap.cpp, CubeMap::direction and pixelPosition, image x
 * to the right, y down within the face), direction of texel (u, v):
 *     +X (1, -v, u)    -X (-1, -v, -u)  +Y (u, 1, -v)
 *     -Y (u, -1, v)    +Z (-u, -v, 1)   -Z (u, -v, -1)
 * So every face is mirrored: on the X and Z faces GL's column s = -u
 * (left-right flip), on the Y faces GL's row t = -v (top-bottom flip).
 *
 * One difference is deliberate: OpenEXR's CubeMap::direction puts the
 * first and last pixel of a row exactly on the face edges (x / (n-1));
 * VDSH stores values at GL texel centres (formula above), so that a GL
 * lookup at a texel centre returns exactly the stored basis value.
 * OpenEXR's own lookup still finds the right texel: faceAndPixelPosition
 * of texel i's centre direction gives pixel position (i + 0.5)(n-1)/n,
 * strictly within half a pixel of i (tests/test_cube_openexr.cpp checks
 * every texel against the OpenEXR library).
 *
 * The basis cubemaps depend on the face size alone: the bake writes them
 * as OpenEXR files for other engines (vdsh_cube_fill_basis), the runtime
 * computes its GL textures itself (vdsh_cube_basis_face_gl_f16); both
 * hold the same half floats.
 *
 * Errors: none; arguments out of range are programmer errors (asserted).
 * Threading: pure functions.
 */
#ifndef VDSH_CUBE_H
#define VDSH_CUBE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Unnormalised direction through the centre of texel (i, j) of `face` in
 * an OpenEXR cube map of face size n (one coordinate is +-1). */
void vdsh_cube_exr_dir(int face, int i, int j, int n, float dir[3]);

/* The same for a GL cube-map face (i = column s, j = row t). */
void vdsh_cube_gl_dir(int face, int i, int j, int n, float dir[3]);

/* The OpenEXR texel (*ei, *ej) of the same face that holds GL texel
 * (i, j): the conversion the runtime uses when uploading. */
void vdsh_cube_gl_to_exr(int face, int i, int j, int n, int *ei, int *ej);

/* Fill the basis cubemap holding SH basis functions first..first+3
 * (first = 9, 13, 17 or 21) in OpenEXR layout: n wide, 6n tall, faces
 * stacked, 4 floats (R, G, B, A = first+0..3) per texel, row-major:
 * rgba[((face * n + j) * n + i) * 4 + c]. Values are vdsh_sh_eval at the
 * texel-centre direction of vdsh_cube_exr_dir normalised in float
 * (d / sqrtf(d.d)). */
void vdsh_cube_fill_basis(int n, int first, float *rgba);

/* One face of all four basis cubemaps in GL orientation, as half floats
 * (binary16 bits): out[k][(j * n + i) * 4 + c] = the half of basis
 * function 9 + 4k + c at GL texel (i, j), that is vdsh_cube_fill_basis's
 * value at the OpenEXR texel vdsh_cube_gl_to_exr names, rounded to
 * nearest even (vdsh_f16_from_f32): texel for texel the bits of the
 * OpenEXR files, which OpenEXR rounds the same way (tests/test_cube.c
 * compares them). Each out[k] holds n * n * 4 values, ready for
 * glTexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + face, 0, GL_RGBA16F, n, n,
 * 0, GL_RGBA, GL_HALF_FLOAT, out[k]): the runtime makes its textures so,
 * without the files. */
void vdsh_cube_basis_face_gl_f16(int n, int face, uint16_t *const out[4]);

#ifdef __cplusplus
}
#endif

#endif /* VDSH_CUBE_H */
