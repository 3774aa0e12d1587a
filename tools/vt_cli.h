/*
 * vt_cli.h - what every vdsh program accepts as a number on its command
 * line, and how it says no.
 *
 * Purpose: one definition of an option's value for vdsh-bake, vdsh-eval,
 * vdsh-info, vdsh-view and vdsh-raydump, so that the same text means the
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
 * Usage: bake/tools/vdsh_bake.c, bake/tools/vdsh_eval.c, tools/vdsh_info.c,
 * runtime/vdsh_view.c; tests/test_tools.c checks every rule.
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

/* "PROG: <message>\nTry 'PROG --help'.\n" on stderr; returns VT_EXIT_USAGE. */
#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
int vt_usage_error(const char *prog, const char *fmt, ...);

#ifdef __cplusplus
}
#endif

#endif
