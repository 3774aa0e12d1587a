/*
 * vdsh_failf.h - internal to the formats library (not installed): write a
 * printf-style message into err (when not NULL) and return r. One helper
 * for vdsh_output.c, vdsh_scene_view.c and vdsh_cpca.c.
 */
#ifndef VDSH_FAILF_H
#define VDSH_FAILF_H

#include "vdsh.h"

#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
vdsh_result vdsh_failf(vdsh_error *err, vdsh_result r, const char *fmt, ...);

#endif
