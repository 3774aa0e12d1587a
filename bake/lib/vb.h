/*
 * vb.h - result codes and error messages shared by the whole bake module
 * (prefix vb_): mesh loading, the Embree scene, the bake core, cubemaps,
 * the evaluator; and the little they all use (a clock, a ranking).
 *
 * Errors: fallible functions return a vb_result (VB_OK = 0) and, when `err`
 * is not NULL, write a message naming the file (or the input) and the
 * problem into err->msg. Outputs are untouched on failure. There is no
 * global error state.
 */
#ifndef VB_H
#define VB_H

#include <stdarg.h>
#include <stdint.h>
#include "vdsh_plural.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum vb_result {
    VB_OK = 0,
    VB_ERR_IO, /* cannot open, read, write or rename a file */
    VB_ERR_OUT_OF_MEMORY,
    VB_ERR_FORMAT,  /* a file's content cannot be parsed / unsupported */
    VB_ERR_INVALID, /* parsed but unusable: NaN/Inf, bad index, empty */
    VB_ERR_EMBREE,  /* Embree device or scene failure */
    VB_ERR_ARGUMENT /* bad option value or inconsistent request */
} vb_result;

const char *vb_result_str(vb_result r);

typedef struct vb_error {
    char msg[512];
} vb_error;

/* Plurals in messages: formats/vdsh_plural.h (vdsh_s, vdsh_plural). */

/* Format a message into err (if not NULL) and return r. */
#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
vb_result
vb_fail(vb_error *err, vb_result r, const char *fmt, ...);

/* Add to the message in err (if not NULL), after what it says. */
#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
void vb_append(vb_error *err, const char *fmt, ...);

/* A value and its place in a list. qsort with vb_ranked_cmp ranks the
 * largest value first and equal values in place order, so that a ranking
 * is the same on every run. */
typedef struct vb_ranked {
    double key;
    uint32_t index;
} vb_ranked;

int vb_ranked_cmp(const void *a, const void *b);

/* Monotonic wall clock in seconds. */
double vb_now(void);

/* Named defaults that the bake library and more than one program (or help
 * text) share: one number each, spelled once. */
#define VB_DEFAULT_RAYS 2500u   /* directions per receiver, a 50 x 50 grid */
#define VB_DEFAULT_CUBE_SIZE 64 /* basis cubemap face, texels */
#define VB_DEFAULT_SEED 1u      /* vdsh-bake --seed */
/* vdsh-bake --crease: computed normals split where faces meet at more than
 * this many degrees; 0: off. 60 measured best on the validation meshes but
 * is not the default: with it Sponza's bakes differ between Embree's kernel
 * sets beyond bake_isa_agree's bounds (docs/ACCURACY.md, "Creases of
 * computed normals") */
#define VB_DEFAULT_CREASE 0

#ifdef __cplusplus
}
#endif

#endif /* VB_H */
