/*
 * vt_image.h - images the programs exchange: shadow-only frames as 16-bit
 * greyscale PNG (a value v in [0, 1] stored as round(v * 65535); the
 * ray-traced truth of vdsh-frames and the GL frames of vdsh-view), read
 * back as floats; and 8-bit RGB(A) PNG for pictures. Through libpng; files
 * are written atomically (formats/vdsh_output.h).
 *
 * Errors: 0, or -1 with a message naming the file in msg.
 * Ownership: vt_png16_read's *out is malloc'ed; the caller frees it.
 * Threading: no shared state.
 */
#ifndef VT_IMAGE_H
#define VT_IMAGE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* width x height values, row 0 at the top; each clamped to [0, 1] (NaN: 0). */
int vt_png16_write(const char *path, int width, int height, const float *values, char *msg,
                   size_t cap);

/* A 16-bit (or 8-bit) greyscale PNG as floats in [0, 1]: each sample / 65535
 * (or / 255), no gamma conversion. A PNG with colour, alpha or a palette is
 * refused (-1, the message says which): no frame is written so, and reading
 * it as grey would weigh colours, composite alpha onto black or decode
 * sRGB. */
int vt_png16_read(const char *path, int *width, int *height, float **out, char *msg, size_t cap);

/* 8-bit RGBA, row 0 at the top. */
int vt_png_rgba_write(const char *path, int width, int height, const uint8_t *rgba, char *msg,
                      size_t cap);

#ifdef __cplusplus
}
#endif

#endif /* VT_IMAGE_H */
