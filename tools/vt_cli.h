/*
 * vt_cli.h - what every vdsh program accepts as a number on its command
 * line, and how it says no.
 *
 * Purpose: one definition of an option's value for every vdsh program
 * (vdsh-bake, vdsh-eval, vdsh-view, ...), so that the same text means the
 * same number in each (`--seed 010` is ten everywhere). Numbers are
 * strictly decimal:
 *   whole numbers   digits only ("0", "010"; an int may start with '-'),
 *                   no sign for unsigned, no spaces, no "0x", no suffix;
 *                   a value past the range (also past 2^64) is refused
 *   real numbers    [+-] digits [. digits] [e|E [+-] digits] (or a leading
 *                   '.'), finite and representable: no "inf", "nan", hex
 *                   floats, spaces, trailing characters, or values that
 *                   overflow or underflow to zero or a subnormal
 *   lists           values as above separated by single commas, no empty
 *                   item, no trailing comma
 *   sizes           WxH (or WXH), two whole numbers
 * An empty string is never a number.
 *
 * Does not: print the message for a bad value (each tool says what the
 * option takes, naming it) - vt_usage_error prints it the common way.
 *
 * The command-line convention every program follows (vt_cli_begin and
 * below; tests/test_tools_cli.py checks it for every program):
 *   - messages on stderr start "PROG: " with the bare program name
 *     ("vdsh-bake"), never argv[0]'s path; getopt's own messages too
 *   - --help (-h) prints the help on stdout, first line "usage: PROG ...",
 *     and exits 0; --version (-V) prints "PROG VERSION ..." and exits 0
 *   - a usage error: "PROG: <what>" and "Try 'PROG --help'.", exit 2
 *   - --json FILE writes a JSON document to FILE ('-': stdout)
 *   - an output is never an input: vt_cli_check_outputs refuses an output
 *     that is the same file as an input (device and inode, not the name)
 *     and checks that every output can be written, before any work
 *
 * Usage: every program (bake/tools/, tools/vdsh_info.c, tools/vdsh_export.c,
 * runtime/vdsh_view.c); tests/test_tools.c checks every number rule.
 *
 * Errors: the parsers return 1 for a valid value (written to *out) and 0
 * otherwise, leaving *out untouched. vt_usage_error returns the usage exit
 * status, VT_EXIT_USAGE (2).
 *
 * Ownership and threading: no state; nothing is kept.
 */
#ifndef VT_CLI_H
#define VT_CLI_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

enum { VT_EXIT_USAGE = 2 };

/* A whole number lo..hi. */
int vt_parse_u64(const char *s, uint64_t lo, uint64_t hi, uint64_t *out);
int vt_parse_u32(const char *s, uint32_t lo, uint32_t hi, uint32_t *out);
int vt_parse_int(const char *s, int lo, int hi, int *out);

/* A finite real number (range checks are the caller's: > 0, >= 0, ...). */
int vt_parse_float(const char *s, float *out);

/* min..max comma-separated reals into out; returns the count, 0 if not
 * such a list (then out may be partly written). */
int vt_parse_floats(const char *s, float *out, int min, int max);

/* min..max comma-separated whole numbers lo..hi; returns the count or 0. */
int vt_parse_u64_list(const char *s, uint64_t lo, uint64_t hi, uint64_t *out, int min,
                      int max);

/* WxH, each lo..hi. */
int vt_parse_size(const char *s, int lo, int hi, int *w, int *h);

/* The program's bare name for every message; also written to argv[0]
 * (when argv is not NULL) so that getopt's messages say it. Call first. */
void vt_cli_begin(const char *prog, char **argv);
const char *vt_cli_prog(void); /* "vdsh" before vt_cli_begin */

/* --version: "PROG VERSION (.vdsh format N[, detail])" on stdout.
 * Returns 0, the exit status. */
int vt_cli_version(const char *detail);

/* After getopt's own message (an unknown option, a missing argument):
 * "Try 'PROG --help'." on stderr. Returns VT_EXIT_USAGE. */
int vt_cli_try_help(void);

/* The outputs a program is about to write, checked before it reads or
 * computes anything (NULL entries are skipped):
 *   - an output that is the same file as an input (an existing regular
 *     file with the same device and inode, whatever the names) or as
 *     another output is refused: "PROG: OUT is the input IN (the same
 *     file): not overwriting it";
 *   - every output must be writable: an existing directory, block device
 *     or socket is refused, and a temporary file is created (and removed)
 *     beside a regular target, as the write will (formats/vdsh_output.h),
 *     so a missing or read-only folder is found now; the message names
 *     the path. Character devices and FIFOs (/dev/stdout) pass as they are.
 * Returns 0 when all is well, else 1 (the message said on stderr). */
int vt_cli_check_outputs(const char *const *outputs, int output_count,
                         const char *const *inputs, int input_count);

/* 1 when a and b name one existing regular file (device and inode). */
int vt_cli_same_file(const char *a, const char *b);

/* "PROG: <message>\nTry 'PROG --help'.\n" on stderr; returns VT_EXIT_USAGE. */
#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
int vt_usage_error(const char *prog, const char *fmt, ...);

#ifdef __cplusplus
}
#endif

#endif
