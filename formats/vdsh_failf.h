/*
 * vdsh_failf.h - internal to the formats library (not installed): write a
 * printf-style message into err (when not NULL) and return r. The one
 * message helper of the library (vdsh_output.c and vdsh.c hold them), and
 * vdsh_plural.h for plurals.
 */
#ifndef VDSH_FAILF_H
#define VDSH_FAILF_H

#include "vdsh.h"
#include "vdsh_plural.h"

#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
vdsh_result
vdsh_failf(vdsh_error *err, vdsh_result r, const char *fmt, ...);

/* The same, the message preceded by "NAME: " (the file it is about;
 * "memory" when name is NULL; dropped when it fills the message). */
#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
vdsh_result
vdsh_failf_at(vdsh_error *err, vdsh_result r, const char *name, const char *fmt, ...);

/* Plurals in messages: vdsh_plural.h (vdsh_s, vdsh_plural). */

#endif
