/*
 * cubemap.h - SH basis cubemaps as OpenEXR cube environment maps
 * (prefix vb_cubemap_). The bake writes them for other engines; the tests
 * read them back. The runtime reads none: it computes the same half
 * floats (formats/vdsh_cube.h, vdsh_cube_basis_face_gl_f16).
 *
 * Purpose: write and read one cube map (n wide, 6n tall, faces +X, -X,
 * +Y, -Y, +Z, -Z from top to bottom, header attribute envmap = cube,
 * half-float channels R, G, B, A) and the set of four basis cubemaps that
 * sit beside a .vdsh file (formats/VDSH.md, last section):
 *     <stem>.sh09-12.exr  <stem>.sh13-16.exr
 *     <stem>.sh17-20.exr  <stem>.sh21-24.exr
 * Pixels are in OpenEXR face orientation; vdsh_cube.h converts to GL's.
 *
 * Does not: know face orientation (vdsh_cube.h does), read tiled, deep or
 * mip-mapped EXR files, or resample.
 *
 * Pixel layout, in memory and in the file: the n x 6n image row-major,
 * 4 floats per texel,
 *     rgba[((face * n + j) * n + i) * 4 + c]     c: 0 R, 1 G, 2 B, 3 A
 * (face-major because the faces are stacked vertically), the layout
 * vdsh_cube_fill_basis() produces.
 *
 * Usage (tests/test_cube.c is a compiled example):
 *
 *     vb_error err;
 *     if (vb_cubemap_write_basis("out", "room", 64, &err) != VB_OK) ...
 *     vb_cubemap *maps[VB_CUBEMAP_BASIS_FILES];
 *     if (vb_cubemap_read_basis("out", "room", 64, maps, &err) != VB_OK)
 *         fprintf(stderr, "%s\n", err.msg);
 *     ... maps[k]->rgba holds SH basis functions 9+4k .. 12+4k ...
 *     for (int k = 0; k < VB_CUBEMAP_BASIS_FILES; k++)
 *         vb_cubemap_free(maps[k]);
 *
 * Files written: scanline, ZIP, values converted to half (round to
 * nearest even) by OpenEXR; no timestamp or other varying data, so the
 * same pixels give byte-identical files. Each file is written to a
 * temporary file in the destination's directory, flushed to disk
 * (fsync), then renamed over the destination: a reader never sees a
 * partial file, and on any failure the temporary file is removed and the
 * destination is left as it was.
 *
 * Errors: every fallible function returns a vb_result and, when err is
 * not NULL, a message naming the file and the problem, e.g.
 * "out/a.exr: not a cube environment map (no envmap attribute)".
 * Messages from OpenEXR are captured into it, never printed. Outputs are
 * untouched on failure. VB_ERR_IO: the OS refused to open, read, write or
 * rename; VB_ERR_FORMAT: not an OpenEXR file, corrupt or truncated, or
 * not a cube map of the supported kind; VB_ERR_INVALID: a value that is
 * not finite (reading) or not representable as a half (writing);
 * VB_ERR_ARGUMENT: bad size or NULL argument.
 *
 * Ownership: writers borrow their arguments. vb_cubemap_read*() return
 * vb_cubemap objects owned by the caller, freed with vb_cubemap_free().
 *
 * Threading: no shared state; different files may be read and written
 * from different threads at once.
 */
#ifndef VB_CUBEMAP_H
#define VB_CUBEMAP_H

#include "vb.h"
#include "vdsh_output.h"

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Face sizes n accepted by every function: 1 .. VB_CUBEMAP_MAX_SIZE. */
#define VB_CUBEMAP_MAX_SIZE 4096

/* Basis files per bake; file k holds SH functions 9+4k .. 12+4k. */
#define VB_CUBEMAP_BASIS_FILES 4

/* A cube map in memory. */
typedef struct vb_cubemap {
    int size;    /* n: texels per face edge */
    float *rgba; /* n * 6n * 4 floats, layout above; owned */
} vb_cubemap;

/* Write one cube map of face size n (1..VB_CUBEMAP_MAX_SIZE) to `path`,
 * atomically. Every value must be finite and round to a finite half
 * (|v| < 65520), else VB_ERR_INVALID names the texel and nothing is
 * written. */
vb_result vb_cubemap_write(const char *path, int n, const float *rgba, vb_error *err);

/* Read one cube map. The file must be a single-level scanline OpenEXR
 * image with envmap = cube, height == 6 * width, width in
 * 1..VB_CUBEMAP_MAX_SIZE, and channels R, G, B, A of type half or float
 * (other channels are ignored; the data window may start anywhere).
 * Every value read must be finite. On success *out is a new vb_cubemap. */
vb_result vb_cubemap_read(const char *path, vb_cubemap **out, vb_error *err);

/* Free a cube map from vb_cubemap_read*(); NULL is fine. */
void vb_cubemap_free(vb_cubemap *map);

/* Path of basis file k (0..3) for a bake: "<dir>/<stem>.sh09-12.exr" for
 * k = 0, and so on. dir NULL or "" means the stem alone (relative to the
 * working directory); a trailing '/' in dir is not doubled. Writes the
 * NUL-terminated path into buf[size]; VB_ERR_ARGUMENT if it does not
 * fit (buf untouched). */
vb_result vb_cubemap_basis_path(const char *dir, const char *stem, int k, char *buf, size_t size,
                                vb_error *err);

/* Fill (vdsh_cube_fill_basis) and write the four basis files of face
 * size n into dir. All four are written to temporary files first and
 * renamed only when all four succeeded, so a failure leaves every
 * destination as it was (only a failing rename, after the first one
 * succeeded, can leave a mix; the message says so). */
vb_result vb_cubemap_write_basis(const char *dir, const char *stem, int n, vb_error *err);

/* vb_cubemap_write_basis in two steps, so that the encoding (mostly
 * deflate) can run while the caller does other work: the four files of
 * face size n encoded into memory (nothing is written), then written to
 * dir, staged and renamed as vb_cubemap_write_basis does.
 * vb_cubemap_basis_free frees an encoded or zeroed set. */
typedef struct vb_cubemap_basis {
    int size;                                     /* n */
    unsigned char *bytes[VB_CUBEMAP_BASIS_FILES]; /* the files; owned */
    size_t length[VB_CUBEMAP_BASIS_FILES];
} vb_cubemap_basis;

vb_result vb_cubemap_basis_encode(int n, vb_cubemap_basis *out, vb_error *err);
vb_result vb_cubemap_basis_write(const vb_cubemap_basis *b, const char *dir, const char *stem,
                                 vb_error *err);
/* The first half of vb_cubemap_basis_write, for files that must change
 * together with others (job.h, vb_write_outputs): the four files written
 * to temporaries beside their targets and on disk, nothing renamed yet.
 * The caller commits (vdsh_output_commit) or aborts (vdsh_output_abort)
 * each of staged[0..3]; on failure every one is aborted already. */
vb_result vb_cubemap_basis_stage(const vb_cubemap_basis *b, const char *dir, const char *stem,
                                 vdsh_output staged[VB_CUBEMAP_BASIS_FILES], vb_error *err);
void vb_cubemap_basis_free(vb_cubemap_basis *b);

/* Read the four basis files. expected_size > 0 requires that face size
 * (the cube_size of the .vdsh header); 0 accepts any size as long as all
 * four agree. On success out[k] holds SH functions 9+4k .. 12+4k; on
 * failure out is untouched and nothing stays allocated. */
vb_result vb_cubemap_read_basis(const char *dir, const char *stem, int expected_size,
                                vb_cubemap *out[VB_CUBEMAP_BASIS_FILES], vb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* VB_CUBEMAP_H */
