/*
 * vdsh_camera.h - the one definition of a pinhole camera, so that the GL
 * runtime's frame and a ray-traced frame of the same view see the same
 * surface point at every pixel.
 *
 * A camera looks from `eye` at `target` with `up` (zero: +y) and a
 * vertical field of view `fov_y` in degrees (0: 60). Its basis is
 * right-handed as gluLookAt's: f = normalize(target - eye),
 * s = normalize(f x up), u = s x f. An image is `width` x `height` pixels,
 * row 0 at the top (as PNG files and vr_read_pixels store it); pixel
 * (x, y) is the square [x, x + 1] x [y, y + 1] and is sampled at its
 * centre (x + 1/2, y + 1/2), where a GL rasteriser samples it:
 *     ndc_x = 2 (x + 1/2) / width - 1,   ndc_y = 1 - 2 (y + 1/2) / height
 *     dir   = f + ndc_x tan(fov_y / 2) (width / height) s
 *               + ndc_y tan(fov_y / 2) u                (normalised)
 * which is exactly the ray the perspective projection below maps to that
 * pixel centre.
 *
 * Does not: know about scenes (the runtime's default camera lives in
 * runtime/), trace rays or touch GL.
 * Errors: none (degenerate input gives a finite but meaningless basis:
 * vdsh_camera_degenerate tells, for the programs that take a camera).
 * Threading: pure functions.
 */
#ifndef VDSH_CAMERA_H
#define VDSH_CAMERA_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vdsh_camera {
    float eye[3];
    float target[3];
    float up[3]; /* zero: (0, 1, 0) */
    float fov_y; /* degrees; 0: 60 */
} vdsh_camera;

/* The basis (s, u, f): right, up and forward unit vectors. */
void vdsh_camera_basis(const vdsh_camera *c, float s[3], float u[3], float f[3]);

/* 1 when the camera has no basis: eye and target are the same point, or
 * it looks along its up vector (straight down or up with the default +y),
 * where f x up vanishes and the frame is meaningless (black); else 0. */
int vdsh_camera_degenerate(const vdsh_camera *c);

/* The field of view with its default applied, in degrees. */
float vdsh_camera_fov(const vdsh_camera *c);

/* The primary ray through the centre of pixel (x, y): origin (the eye)
 * and unit direction. */
void vdsh_camera_ray(const vdsh_camera *c, int width, int height, int x, int y, float org[3],
                     float dir[3]);

/* The view matrix (column-major, as GL takes it): world to eye space. */
void vdsh_camera_view(const vdsh_camera *c, float out[16]);

/* The perspective projection (column-major) of this camera's fov for an
 * aspect ratio width / height and clip planes znear < zfar. */
void vdsh_camera_projection(const vdsh_camera *c, float aspect, float znear, float zfar,
                            float out[16]);

#ifdef __cplusplus
}
#endif

#endif /* VDSH_CAMERA_H */
