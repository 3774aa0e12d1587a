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
#include <stdio.h>
#include "vdsh.h"
#include "vdsh_plural.h"

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

/* The length of the comma-separated item at p; *next gets the item after
 * it, NULL after the last: the one splitter of every list (an empty item
 * has length 0, for the caller to refuse). Usage:
 *     for (const char *p = s, *next; p; p = next) {
 *         size_t len = vt_list_item(p, &next); ... } */
size_t vt_list_item(const char *p, const char **next);

/* min..max comma-separated reals into out; returns the count, 0 if not
 * such a list (then out may be partly written). */
int vt_parse_floats(const char *s, float *out, int min, int max);

/* min..max comma-separated whole numbers lo..hi; returns the count or 0. */
int vt_parse_u64_list(const char *s, uint64_t lo, uint64_t hi, uint64_t *out, int min, int max);

/* WxH, each lo..hi. */
int vt_parse_size(const char *s, int lo, int hi, int *w, int *h);

/* The program's bare name for every message; also written to argv[0]
 * (when argv is not NULL) so that getopt's messages say it. Call first. */
void vt_cli_begin(const char *prog, char **argv);
const char *vt_cli_prog(void); /* "vdsh" before vt_cli_begin */

/* SIGINT, SIGTERM and SIGHUP end the program as before (the signal's own
 * exit status), but first remove the temporary files of the outputs being
 * written (vdsh_output_remove_temporaries): an interrupted program leaves
 * no "<path>.tmp..." beside its outputs, each target as it was or whole.
 * Blocks the signals and takes them in a thread of its own (sigwait), so
 * call it before the program starts any thread (every thread inherits the
 * mask). Signals ignored at start (nohup, a background job) stay ignored.
 * A signal that comes before the program exits ends it by that signal
 * (exit waits for the signal thread), never with the program's status. */
void vt_cli_clean_exit_on_signals(void);

/* A folder of temporary outputs (vdsh-frames truth's, moved into place once
 * whole): a signal that ends the program (vt_cli_clean_exit_on_signals)
 * removes every file in it and the folder too. One at a time; NULL: none. */
void vt_cli_remove_dir_on_signal(const char *dir);

/* Every file in `dir` (not recursing), then `dir` itself: best effort. */
void vt_cli_remove_dir(const char *dir);

/* Outputs that change together (a .vdsh and its basis cubemaps): between
 * vt_cli_defer_signals and vt_cli_undefer_signals such a signal waits, so
 * that the program ends with all of them written or none (their
 * temporaries removed), never some renamed and the others not. */
void vt_cli_defer_signals(void);
void vt_cli_undefer_signals(void);

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
int vt_cli_check_outputs(const char *const *outputs, int output_count, const char *const *inputs,
                         int input_count);

/* Outputs that are files or folders, never standard output: "-" (which
 * the JSON outputs take for stdout) is refused before any work, naming
 * the option, rather than written as a file named "-": "PROG: OPT -: ...".
 * opts[i] names outputs[i] (NULL entries are skipped). Returns 0, or
 * VT_EXIT_USAGE after the message. */
int vt_cli_no_stdout(const char *const *outputs, const char *const *opts, int output_count);

/* 1 when a and b name one existing regular file (device and inode). */
int vt_cli_same_file(const char *a, const char *b);

/* "PROG: <message>\nTry 'PROG --help'.\n" on stderr; returns VT_EXIT_USAGE. */
#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
int vt_usage_error(const char *prog, const char *fmt, ...);

/* ---- option checks for parse_args() ------------------------------------
 * What several programs check the same way, so that each program's
 * parse_args() says it once. The vt_opt_* functions take the option's
 * name ("--threads") and its argument; they return 1 with *out written,
 * or 0 after the usage error on stderr ("PROG: --threads takes a whole
 * number 1..256, not 'x'" and "Try 'PROG --help'.", as vt_usage_error):
 * the program then exits VT_EXIT_USAGE. *out is untouched on failure. */

/* What a parse_args() returns when the program is to run; anything else
 * is the exit status (0 after --help or --version, VT_EXIT_USAGE). */
enum { VT_CLI_RUN = -1 };

/* The end of every program's getopt_long table: --help, --version, the
 * terminator (the program includes <getopt.h>). */
#define VT_CLI_LONGOPTS_END                                                                        \
    {"help", no_argument, 0, 'h'}, {"version", no_argument, 0, 'V'},                               \
    {                                                                                              \
        0, 0, 0, 0                                                                                 \
    }

/* The getopt switch's default: -h prints usage(stdout) and returns 0, -V
 * returns vt_cli_version(version_detail), anything else (getopt's '?' or
 * ':' after its own message) returns vt_cli_try_help(). */
int vt_cli_common_option(int c, void (*usage)(FILE *), const char *version_detail);

/* A whole number lo..hi. The message says "takes WHAT LO..HI", WHAT being
 * `what` or, when NULL, "a whole number"; an empty `what` says "takes
 * LO..HI". With hi UINT64_MAX it says "WHAT >= LO", or just "WHAT" when lo
 * is 0 too. vt_opt_int with lo >= 0 takes digits only, no sign, as
 * vt_parse_u64 ("-0" is refused). */
int vt_opt_u64(const char *option, const char *what, const char *arg, uint64_t lo, uint64_t hi,
               uint64_t *out);
int vt_opt_u32(const char *option, const char *what, const char *arg, uint32_t lo, uint32_t hi,
               uint32_t *out);
int vt_opt_int(const char *option, const char *what, const char *arg, int lo, int hi, int *out);

/* Plurals in messages: formats/vdsh_plural.h (vdsh_s, vdsh_plural). */

/* An option that names one thing (-o FILE): *slot = arg the first time;
 * given again, "OPTION given twice ('A', then 'B'): give it once", even
 * with the same value (before, the last silently won). */
int vt_opt_once(const char *option, const char *arg, const char **slot);

/* A real number > 0 ("takes a positive number") or >= 0 ("takes a number
 * >= 0"); -0 counts as 0. */
int vt_opt_positive(const char *option, const char *arg, float *out);
int vt_opt_nonnegative(const char *option, const char *arg, float *out);

/* A tolerance: the one option value that is not strictly decimal, for it
 * may be "inf" (strtod's syntax, the whole string), > 0, or >= 0 when
 * zero_ok. Says "takes a tolerance > 0 (or inf)" ("a tolerance >= 0", or
 * with `noun` "a number": "takes a number >= 0 (or inf)"). */
int vt_opt_tolerance(const char *option, const char *noun, const char *arg, int zero_ok,
                     double *out);

/* Where the lights go (--light-region SPEC of vdsh-bake, vdsh-eval,
 * vdsh-frames views, vdsh-view): `auto` (out->rule 0), `grown`
 * (VDSH_LIGHT_REGION_GROWN, its box left to the scene:
 * vb_scene_use_light_box), XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX
 * (VDSH_LIGHT_REGION_BOX, finite, each min below its max) or, when file_ok,
 * `file` (VT_LIGHT_REGION_FILE). Says what is wrong, naming the option. */
enum { VT_LIGHT_REGION_FILE = 3 };
int vt_opt_light_region(const char *option, const char *arg, int file_ok, vdsh_light_box *out);

/* One of a list of names, each standing for a value; the list ends with
 * {NULL, 0}. Says "takes A, B or C". */
typedef struct vt_choice {
    const char *name;
    int value;
} vt_choice;
int vt_opt_choice(const char *option, const char *arg, const vt_choice *choices, int *out);

/* Orders 1..max_order, a vt_parse_u64_list list of at most max_order
 * entries in any order, each at most once when `distinct`: want[k] = 1
 * for each order k given, 0 for the others (want holds max_order + 1
 * entries; want[0] is 0); 1, or 0 (want untouched, no message) when it is
 * not such a list. */
int vt_parse_orders(const char *s, int distinct, int max_order, int *want);

/* Distinct orders 1..max_order, a vt_parse_u64_list list in any order:
 * want[k] = 1 for each order k given, 0 for the others (want holds
 * max_order + 1 entries; want[0] is 0). Says "takes distinct orders
 * 1..MAX such as EXAMPLE". */
int vt_opt_orders(const char *option, const char *example, const char *arg, int max_order,
                  int *want);

#ifdef __cplusplus
}
#endif

#endif
