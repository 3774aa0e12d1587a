/*
 * vt_args.h - the .vdsh argument several vdsh programs take, with the
 * one message every program gives for it.
 *
 * Purpose: vdsh-eval, vdsh-frames and vdsh-export (and any program that
 * takes one .vdsh) check the one .vdsh argument and the file it names the
 * same way, so the same mistake gets the same words in each. Number and
 * order options are vt_cli.h's (vt_opt_*).
 *
 * Does not: parse the command line (each program's parse_args() does,
 * with getopt), or decide what a program does with the values.
 *
 * Usage: bake/tools/vdsh_eval.c, bake/tools/vdsh_frames.c,
 * tools/vdsh_export.c; tests/test_tools_cli.py runs their refusals.
 *
 * Errors: a check that fails has said why on stderr, "PROG: ..." with
 * vt_cli_begin's name (a usage error also "Try 'PROG --help'."), and
 * leaves its outputs untouched; see each function for what it returns.
 *
 * Ownership and threading: no state; vt_read_whole's file is the
 * caller's (vdsh_free).
 */
#ifndef VT_ARGS_H
#define VT_ARGS_H

#include <stdint.h>

#include "vdsh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The FILE.vdsh argument at argv[first]: NULL after the usage error
 * "[CMD: ]no .vdsh file given", or, unless `more` (arguments after it
 * are the program's), "[CMD: ]one .vdsh file, not also 'NEXT'". */
const char *vt_arg_vdsh(int argc, char **argv, int first, const char *cmd, int more);

/* The whole .vdsh at path, read and checked (vdsh_read), refusing a part
 * of a sharded bake (its streams hold one range's receivers); NULL after
 * the message, which names the file. */
vdsh_file *vt_read_whole(const char *path);

#ifdef __cplusplus
}
#endif

#endif
