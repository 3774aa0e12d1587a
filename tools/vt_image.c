/* PNG frames through libpng: vt_image.h says what and why. */
#include "vt_image.h"

#include <math.h>
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vdsh_output.h"

static void put(png_structp p, png_bytep data, png_size_t n)
{
    vdsh_output *o = png_get_io_ptr(p);
    vdsh_output_put(o, data, n);
}

static void flush(png_structp p)
{
    (void)p;
}

/* Write rows (png_bytep each) of the given colour type and depth. */
static int write_png(const char *path, int width, int height, int color, int depth, png_bytep *rows,
                     char *msg, size_t cap)
{
    vdsh_output o;
    vdsh_error e;
    if (vdsh_output_open(path, &o, &e) != VDSH_OK) {
        snprintf(msg, cap, "%s", e.msg);
        return -1;
    }
    png_structp p = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = p ? png_create_info_struct(p) : NULL;
    if (!p || !info || setjmp(png_jmpbuf(p))) {
        png_destroy_write_struct(&p, &info);
        vdsh_output_abort(&o);
        snprintf(msg, cap, "%s: cannot encode the PNG", path);
        return -1;
    }
    png_set_write_fn(p, &o, put, flush);
    png_set_IHDR(p, info, (png_uint_32)width, (png_uint_32)height, depth, color, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    if (depth == 16)
        png_set_gAMA_fixed(p, info, PNG_GAMMA_LINEAR); /* values, not colours */
    png_write_info(p, info);
    if (depth == 16)
        png_set_swap(p); /* rows hold host-order (little-endian) uint16 */
    png_write_image(p, rows);
    png_write_end(p, info);
    png_destroy_write_struct(&p, &info);
    if (vdsh_output_commit(&o, &e) != VDSH_OK) {
        snprintf(msg, cap, "%s", e.msg);
        return -1;
    }
    return 0;
}

int vt_png16_write(const char *path, int width, int height, const float *values, char *msg,
                   size_t cap)
{
    if (width <= 0 || height <= 0) {
        snprintf(msg, cap, "%s: empty image", path);
        return -1;
    }
    uint16_t *px = malloc((size_t)width * height * sizeof *px);
    png_bytep *rows = malloc((size_t)height * sizeof *rows);
    if (!px || !rows) {
        free(px);
        free(rows);
        snprintf(msg, cap, "%s: out of memory", path);
        return -1;
    }
    for (size_t i = 0; i < (size_t)width * height; i++) {
        float v = values[i];
        v = v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f; /* NaN: 0 */
        px[i] = (uint16_t)lrintf(v * 65535.0f);
    }
    for (int y = 0; y < height; y++)
        rows[y] = (png_bytep)(px + (size_t)y * width);
    int r = write_png(path, width, height, PNG_COLOR_TYPE_GRAY, 16, rows, msg, cap);
    free(rows);
    free(px);
    return r;
}

int vt_png_rgba_write(const char *path, int width, int height, const uint8_t *rgba, char *msg,
                      size_t cap)
{
    png_bytep *rows = malloc((size_t)(height > 0 ? height : 1) * sizeof *rows);
    if (!rows || width <= 0 || height <= 0) {
        free(rows);
        snprintf(msg, cap, "%s: empty image or out of memory", path);
        return -1;
    }
    for (int y = 0; y < height; y++)
        rows[y] = (png_bytep)(rgba + (size_t)y * width * 4);
    int r = write_png(path, width, height, PNG_COLOR_TYPE_RGBA, 8, rows, msg, cap);
    free(rows);
    return r;
}

int vt_png16_read(const char *path, int *width, int *height, float **out, char *msg, size_t cap)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&img, path)) {
        snprintf(msg, cap, "%s: not a readable PNG: %s", path, img.message);
        return -1;
    }
    /* Frames hold values, not colours: grey without alpha only. libpng's
     * simplified API would read any PNG as grey, but not as values: it
     * takes the luminance of colour, composites alpha onto black and
     * decodes 8-bit samples as sRGB (128 read as 0.22, not 0.50). */
    if (img.format & (PNG_FORMAT_FLAG_COLOR | PNG_FORMAT_FLAG_ALPHA | PNG_FORMAT_FLAG_COLORMAP)) {
        const png_uint_32 f = img.format;
        const char *kind = f & PNG_FORMAT_FLAG_COLORMAP ? "a palette"
                           : f & PNG_FORMAT_FLAG_COLOR
                               ? (f & PNG_FORMAT_FLAG_ALPHA ? "an RGBA" : "an RGB")
                               : "a grey and alpha";
        snprintf(msg, cap,
                 "%s: %s PNG, not a frame: frames are greyscale values without alpha "
                 "(16-bit grey, as vdsh-view and vdsh-frames truth write them)",
                 path, kind);
        png_image_free(&img);
        return -1;
    }
    /* 16-bit: linear (as written, gAMA 1.0), read as it is; 8-bit: the
     * samples as they are (sRGB in, sRGB out: no conversion), / 255. */
    const int wide = (img.format & PNG_FORMAT_FLAG_LINEAR) != 0;
    img.format = wide ? PNG_FORMAT_LINEAR_Y : PNG_FORMAT_GRAY;
    size_t n = (size_t)img.width * img.height;
    uint16_t *px = malloc(PNG_IMAGE_SIZE(img));
    float *v = malloc((n ? n : 1) * sizeof *v);
    if (!px || !v || !png_image_finish_read(&img, NULL, px, 0, NULL)) {
        snprintf(msg, cap, "%s: cannot decode: %s", path, px && v ? img.message : "out of memory");
        png_image_free(&img);
        free(px);
        free(v);
        return -1;
    }
    const uint8_t *px8 = (const uint8_t *)px;
    for (size_t i = 0; i < n; i++)
        v[i] = wide ? (float)px[i] / 65535.0f : (float)px8[i] / 255.0f;
    free(px);
    *width = (int)img.width;
    *height = (int)img.height;
    *out = v;
    return 0;
}
