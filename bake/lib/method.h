/*
 * method.h - the one table of fit methods: for each vdsh_method, everything
 * the bake, the fit and the command line need to know about it (how it
 * samples, which linear map fits it, which quantities it may store, which
 * parameters apply and their defaults, and its help text).
 *
 * Adding a method: a value in formats/vdsh.h's vdsh_method (the file's
 * vocabulary: a stored value never changes once shipped) and its name in
 * formats/vdsh.c's table, a value in vb_method below and its row in
 * method.c, and, if no existing base fit does, the map in fit.c
 * (vb_fit_base). The CLI's parsing, help and
 * compatibility checks, bake.c's sampling and parameters and fit.c's map
 * all read the row.
 *
 * Errors: none (lookups return NULL for unknown values).
 * Ownership: the table is static. Threading: read-only, thread-safe.
 */
#ifndef VB_METHOD_H
#define VB_METHOD_H

#include <stdint.h>

#include "vdsh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The bake's methods. Zero is the tools' default, so that a zeroed
 * vb_bake_desc bakes what vdsh-bake does; each row records the value the
 * file stores (vdsh_method, whose numbers never change). The table is in
 * this order, which is also the CLI's. */
typedef enum vb_method {
    VB_METHOD_DECISION = 0, /* the default (issue 25) */
    VB_METHOD_SHADOW,
    VB_METHOD_LSQ,
    VB_METHOD_MIRROR,
    VB_METHOD_PAPER,
    VB_METHOD_FULL,
    VB_METHOD_COUNT
} vb_method;

/* What the bake stores: zero chooses per order (or the method's only
 * one). vb_quantity_stored gives the file's vdsh_quantity. */
typedef enum vb_quantity {
    VB_QUANTITY_AUTO = 0, /* the default */
    VB_QUANTITY_DISTANCE,
    VB_QUANTITY_LOG
} vb_quantity;

/* The file's value of a quantity other than auto. */
vdsh_quantity vb_quantity_stored(vb_quantity q);

/* The linear map from a receiver's projection to its coefficients
 * (fit.h). */
typedef enum vb_fit_base {
    VB_FIT_IDENTITY = 0, /* the projection as it is */
    VB_FIT_MIRROR,       /* the upper hemisphere mirrored below */
    VB_FIT_LSQ           /* regularised least squares to the hemisphere */
} vb_fit_base;

/* What a stream's method_param records (VDSH.md). */
typedef enum vb_method_param {
    VB_PARAM_NONE = 0,  /* 0 */
    VB_PARAM_LAMBDA,    /* the regularisation weight */
    VB_PARAM_LOG_OFFSET /* the per-order offset added to the fitted ln d */
} vb_method_param;

/* Bits of vb_method_info.quantities. */
#define VB_QUANTITY_BIT(q) (1u << (q))

typedef struct vb_method_info {
    vb_method method;
    vdsh_method stored; /* the value in the file's streams */
    /* Sampling: the upper hemisphere about each receiver's normal, with
     * half the directions; otherwise the whole sphere. */
    int hemisphere;
    /* Sphere sampling whose directions below the horizon count as
     * distance 0 (and are not traced). */
    int horizon;
    vb_fit_base fit;
    /* The fit uses lambda (VB_FIT_LSQ). */
    int regularised;
    /* The user may not set lambda: the method uses the default. */
    int lambda_fixed;
    vb_method_param param;
    /* VB_QUANTITY_BIT of each vdsh_quantity it may store. A single one
     * is also what "auto" means; with several, auto chooses per order. */
    uint32_t quantities;
    /* Why each refused quantity is refused (the CLI's message), by
     * vdsh_quantity; NULL where allowed. */
    const char *refused[3];
    /* Per order 1..VDSH_MAX_ORDER ([0] unused): the default log offset
     * (VB_PARAM_LOG_OFFSET), chosen on the validation scenes; NULL
     * otherwise. */
    const float *default_log_offset;
    /* The decision fit (decision.h): the lsq fit of ln d is the start of a
     * per-receiver fit of the shadow decision over lights in the scene's
     * free space, and the log offset is calibrated per scene and order at
     * bake time (an explicit --log-offset overrides it). */
    int decision;
    /* Help on the command line, after "NAME: ": lines of at most 48
     * columns, no indentation, no final newline. */
    const char *help;
} vb_method_info;

/* The regularisation when none is given (lsq and shadow): chosen on the
 * validation split (docs/ACCURACY.md). */
#define VB_DEFAULT_LAMBDA 1e-4f

/* The row of a method, or NULL for a value this version does not know. */
const vb_method_info *vb_method_get(vb_method method);

/* The row of the method a file's stream records (vdsh_method), or NULL. */
const vb_method_info *vb_method_stored(uint32_t stored);

/* The row named `name` (vdsh_method_name's names), or NULL. */
const vb_method_info *vb_method_by_name(const char *name);

/* Its name: the file's (vdsh_method_name). */
const char *vb_method_name(vb_method method);

#ifdef __cplusplus
}
#endif

#endif /* VB_METHOD_H */
