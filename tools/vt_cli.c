/*
 * vt_cli.c - strict decimal numbers for every vdsh program (vt_cli.h).
 */
#include "vt_cli.h"

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "vdsh_output.h"

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

/* Digits of s[0..n) as a u64; 0 on overflow or no digit. */
static int digits_u64(const char *s, size_t n, uint64_t *out)
{
    uint64_t v = 0;
    if (n == 0)
        return 0;
    for (size_t i = 0; i < n; i++) {
        if (!is_digit(s[i]))
            return 0;
        unsigned d = (unsigned)(s[i] - '0');
        if (v > (UINT64_MAX - d) / 10)
            return 0;
        v = v * 10 + d;
    }
    *out = v;
    return 1;
}

int vt_parse_u64(const char *s, uint64_t lo, uint64_t hi, uint64_t *out)
{
    uint64_t v;
    if (!s || !digits_u64(s, strlen(s), &v) || v < lo || v > hi)
        return 0;
    *out = v;
    return 1;
}

int vt_parse_u32(const char *s, uint32_t lo, uint32_t hi, uint32_t *out)
{
    uint64_t v;
    if (!vt_parse_u64(s, lo, hi, &v))
        return 0;
    *out = (uint32_t)v;
    return 1;
}

int vt_parse_int(const char *s, int lo, int hi, int *out)
{
    if (!s)
        return 0;
    int neg = s[0] == '-';
    uint64_t m;
    if (!digits_u64(s + neg, strlen(s + neg), &m))
        return 0;
    /* |INT_MIN| fits in u64: compare magnitudes before converting. */
    long long v;
    if (neg) {
        if (m > (uint64_t)INT64_MAX)
            return 0;
        v = -(long long)m;
    } else {
        if (m > (uint64_t)INT64_MAX)
            return 0;
        v = (long long)m;
    }
    if (v < lo || v > hi)
        return 0;
    *out = (int)v;
    return 1;
}

/* Is s[0..n) a decimal real: [+-] (d+ [. d*] | . d+) [(e|E) [+-] d+]? */
static int decimal_syntax(const char *s, size_t n)
{
    size_t i = 0, int_digits = 0, frac_digits = 0;
    if (i < n && (s[i] == '+' || s[i] == '-'))
        i++;
    while (i < n && is_digit(s[i]))
        i++, int_digits++;
    if (i < n && s[i] == '.') {
        i++;
        while (i < n && is_digit(s[i]))
            i++, frac_digits++;
    }
    if (int_digits + frac_digits == 0)
        return 0;
    if (i < n && (s[i] == 'e' || s[i] == 'E')) {
        i++;
        if (i < n && (s[i] == '+' || s[i] == '-'))
            i++;
        size_t exp_digits = 0;
        while (i < n && is_digit(s[i]))
            i++, exp_digits++;
        if (exp_digits == 0)
            return 0;
    }
    return i == n;
}

/* A finite float that is normal (or zero): what strtof gives without
 * ERANGE, checked again for the subnormals some libcs return quietly. */
static int fits_float(float v)
{
    float a = fabsf(v);
    return isfinite(v) && (a == 0.0f || a >= FLT_MIN);
}

/* s[0..n), which must be followed by ',' or the end: the syntax of the
 * n characters first, then strtof, which stops exactly at n (no ',' can
 * continue a decimal number). */
static int float_n(const char *s, size_t n, float *out)
{
    if (!decimal_syntax(s, n))
        return 0;
    char *end;
    errno = 0;
    float v = strtof(s, &end);
    if (errno || end != s + n || !fits_float(v))
        return 0;
    *out = v;
    return 1;
}

int vt_parse_float(const char *s, float *out)
{
    return s && float_n(s, strlen(s), out);
}

size_t vt_list_item(const char *p, const char **next)
{
    const char *comma = strchr(p, ',');
    *next = comma ? comma + 1 : NULL;
    return comma ? (size_t)(comma - p) : strlen(p);
}

int vt_parse_floats(const char *s, float *out, int min, int max)
{
    int n = 0;
    for (const char *p = s, *next; p; p = next) {
        size_t len = vt_list_item(p, &next);
        float v;
        if (n == max || !float_n(p, len, &v))
            return 0;
        out[n++] = v;
    }
    return n >= min ? n : 0;
}

int vt_parse_u64_list(const char *s, uint64_t lo, uint64_t hi, uint64_t *out, int min, int max)
{
    int n = 0;
    for (const char *p = s, *next; p; p = next) {
        size_t len = vt_list_item(p, &next);
        uint64_t v;
        if (n == max || !digits_u64(p, len, &v) || v < lo || v > hi)
            return 0;
        out[n++] = v;
    }
    return n >= min ? n : 0;
}

int vt_parse_size(const char *s, int lo, int hi, int *w, int *h)
{
    if (!s)
        return 0;
    const char *x = strpbrk(s, "xX");
    uint64_t a, b;
    if (!x || !digits_u64(s, (size_t)(x - s), &a) || !digits_u64(x + 1, strlen(x + 1), &b))
        return 0;
    if (lo < 0 || a < (uint64_t)lo || a > (uint64_t)hi || b < (uint64_t)lo || b > (uint64_t)hi)
        return 0;
    *w = (int)a;
    *h = (int)b;
    return 1;
}

int vt_usage_error(const char *prog, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "%s: ", prog);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\nTry '%s --help'.\n", prog);
    return VT_EXIT_USAGE;
}

/* ---- the programs' shared conventions ------------------------------------ */

static const char *cli_prog = "vdsh";

void vt_cli_begin(const char *prog, char **argv)
{
    cli_prog = prog;
    if (argv && argv[0])
        argv[0] = (char *)prog;
}

const char *vt_cli_prog(void)
{
    return cli_prog;
}

static sigset_t clean_exit_signals;
static pthread_mutex_t defer_lock = PTHREAD_MUTEX_INITIALIZER;

static atomic_int defer_held; /* between vt_cli_defer_signals and undefer */

void vt_cli_defer_signals(void)
{
    pthread_mutex_lock(&defer_lock);
    atomic_store(&defer_held, 1);
}

static atomic_int clean_exit_taken; /* the signal thread has a signal */

/* A signal that came (pending, or taken by the signal thread) ends the
 * process now, with its status: the program does not go on, or exit 0,
 * while the signal thread waits for a lock or for the scheduler. */
static void wait_for_signal_thread(void)
{
    sigset_t pending;
    int waiting = atomic_load(&clean_exit_taken);
    if (!waiting && sigpending(&pending) == 0)
        for (int sig = 1; sig < NSIG && !waiting; sig++)
            waiting = sigismember(&clean_exit_signals, sig) == 1 && sigismember(&pending, sig) == 1;
    while (waiting)
        pause();
}

void vt_cli_undefer_signals(void)
{
    atomic_store(&defer_held, 0);
    pthread_mutex_unlock(&defer_lock);
    wait_for_signal_thread(); /* even though the outputs are complete */
}

/* At exit: an exit while deferred (an error between defer and undefer)
 * lets the signal thread go first, then waits for it as undefer does. */
static void exit_by_pending_signal(void)
{
    if (atomic_load(&defer_held))
        vt_cli_undefer_signals();
    else
        wait_for_signal_thread();
}

static pthread_mutex_t signal_dir_lock = PTHREAD_MUTEX_INITIALIZER;
static char signal_dir[PATH_MAX]; /* under signal_dir_lock */

void vt_cli_remove_dir(const char *dir)
{
    DIR *d = opendir(dir);
    if (d) {
        struct dirent *e;
        char p[PATH_MAX];
        while ((e = readdir(d)) != NULL) {
            if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
                continue;
            int len = snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
            if (len > 0 && (size_t)len < sizeof p)
                unlink(p);
        }
        closedir(d);
    }
    rmdir(dir);
}

void vt_cli_remove_dir_on_signal(const char *dir)
{
    pthread_mutex_lock(&signal_dir_lock);
    if (dir && strlen(dir) < sizeof signal_dir)
        memcpy(signal_dir, dir, strlen(dir) + 1);
    else
        signal_dir[0] = '\0';
    pthread_mutex_unlock(&signal_dir_lock);
}

static void *clean_exit_thread(void *unused)
{
    (void)unused;
    int sig;
    if (sigwait(&clean_exit_signals, &sig) != 0)
        return NULL;
    atomic_store(&clean_exit_taken, 1);
    pthread_mutex_lock(&defer_lock); /* a group of outputs being written: after it */
    vdsh_output_remove_temporaries();
    pthread_mutex_lock(&signal_dir_lock); /* kept: the process ends */
    if (signal_dir[0])
        vt_cli_remove_dir(signal_dir);
    sigset_t one;
    sigemptyset(&one);
    sigaddset(&one, sig);
    signal(sig, SIG_DFL);
    pthread_sigmask(SIG_UNBLOCK, &one, NULL);
    raise(sig); /* the default action: the process ends with this signal */
    _exit(128 + sig);
}

void vt_cli_clean_exit_on_signals(void)
{
    static const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
    int count = 0;
    sigemptyset(&clean_exit_signals);
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++) {
        struct sigaction sa;
        if (sigaction(sigs[i], NULL, &sa) == 0 && sa.sa_handler != SIG_IGN) {
            sigaddset(&clean_exit_signals, sigs[i]);
            count++;
        }
    }
    pthread_t t;
    if (count == 0 || pthread_sigmask(SIG_BLOCK, &clean_exit_signals, NULL) != 0)
        return;
    if (pthread_create(&t, NULL, clean_exit_thread, NULL) != 0) {
        pthread_sigmask(SIG_UNBLOCK, &clean_exit_signals, NULL); /* plain signals then */
        return;
    }
    pthread_detach(t);
    /* A signal that came before the program returns from main ends it by
     * the signal, not with status 0 (on a loaded machine the signal thread
     * may not have run yet: robust_signal_leaves_no_temporary). */
    atexit(exit_by_pending_signal);
}

int vt_cli_version(const char *detail)
{
    printf("%s %s (.vdsh format %u%s%s)\n", cli_prog, VDSH_VERSION_STRING,
           (unsigned)VDSH_FORMAT_VERSION, detail ? ", " : "", detail ? detail : "");
    return 0;
}

int vt_cli_try_help(void)
{
    fprintf(stderr, "Try '%s --help'.\n", cli_prog);
    return VT_EXIT_USAGE;
}

int vt_cli_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    return a && b && stat(a, &sa) == 0 && stat(b, &sb) == 0 && S_ISREG(sa.st_mode) &&
           S_ISREG(sb.st_mode) && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

/* Can `path` be written as vdsh_output writes it? 0, or 1 with the message. */
static int check_writable(const char *path)
{
    struct stat st;
    if (stat(path, &st) == 0) {
        if (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode))
            return 0; /* written in place as a stream */
        if (S_ISDIR(st.st_mode)) {
            fprintf(stderr, "%s: %s: cannot write: is a directory\n", cli_prog, path);
            return 1;
        }
    }
    vdsh_output o;
    vdsh_error err;
    if (vdsh_output_open(path, &o, &err) != VDSH_OK) {
        fprintf(stderr, "%s: %s\n", cli_prog, err.msg);
        return 1;
    }
    vdsh_output_abort(&o); /* removes the temporary: the target is as it was */
    return 0;
}

int vt_cli_no_stdout(const char *const *outputs, const char *const *opts, int output_count)
{
    for (int i = 0; i < output_count; i++)
        if (outputs[i] && strcmp(outputs[i], "-") == 0) {
            fprintf(stderr,
                    "%s: %s -: this output is not written to standard output: give a file "
                    "name (or /dev/stdout, for a pipe)\n",
                    cli_prog, opts[i]);
            return vt_cli_try_help();
        }
    return 0;
}

int vt_cli_check_outputs(const char *const *outputs, int output_count, const char *const *inputs,
                         int input_count)
{
    for (int i = 0; i < output_count; i++) {
        const char *out = outputs[i];
        if (!out || strcmp(out, "-") == 0) /* stdout */
            continue;
        for (int k = 0; k < input_count; k++)
            if (inputs[k] && vt_cli_same_file(out, inputs[k])) {
                fprintf(stderr, "%s: %s is the input %s (the same file): not overwriting it\n",
                        cli_prog, out, inputs[k]);
                return 1;
            }
        for (int k = 0; k < i; k++)
            if (outputs[k] && (strcmp(outputs[k], out) == 0 || vt_cli_same_file(outputs[k], out))) {
                fprintf(stderr, "%s: %s is also the output %s (the same file)\n", cli_prog, out,
                        outputs[k]);
                return 1;
            }
    }
    for (int i = 0; i < output_count; i++)
        if (outputs[i] && strcmp(outputs[i], "-") != 0 && check_writable(outputs[i]))
            return 1;
    return 0;
}

/* ---- option checks for parse_args() ------------------------------------ */

int vt_cli_common_option(int c, void (*usage)(FILE *), const char *version_detail)
{
    if (c == 'h') {
        usage(stdout);
        return 0;
    }
    if (c == 'V')
        return vt_cli_version(version_detail);
    return vt_cli_try_help();
}

/* "OPTION takes WHAT LO..HI, not 'ARG'" (hi NULL: "WHAT >= LO", both NULL:
 * "WHAT"). Returns 0, for the vt_opt_* functions to return. */
static int refuse_range(const char *option, const char *what, const char *arg, const char *lo,
                        const char *hi)
{
    const char *w = what ? what : "a whole number";
    const char *space = *w ? " " : "";
    if (lo && hi)
        vt_usage_error(cli_prog, "%s takes %s%s%s..%s, not '%s'", option, w, space, lo, hi, arg);
    else if (lo)
        vt_usage_error(cli_prog, "%s takes %s >= %s, not '%s'", option, w, lo, arg);
    else
        vt_usage_error(cli_prog, "%s takes %s, not '%s'", option, w, arg);
    return 0;
}

int vt_opt_u64(const char *option, const char *what, const char *arg, uint64_t lo, uint64_t hi,
               uint64_t *out)
{
    if (vt_parse_u64(arg, lo, hi, out))
        return 1;
    char l[24], h[24];
    snprintf(l, sizeof l, "%llu", (unsigned long long)lo);
    snprintf(h, sizeof h, "%llu", (unsigned long long)hi);
    return refuse_range(option, what, arg, hi == UINT64_MAX && lo == 0 ? NULL : l,
                        hi == UINT64_MAX ? NULL : h);
}

int vt_opt_u32(const char *option, const char *what, const char *arg, uint32_t lo, uint32_t hi,
               uint32_t *out)
{
    uint64_t v;
    if (!vt_opt_u64(option, what, arg, lo, hi, &v))
        return 0;
    *out = (uint32_t)v;
    return 1;
}

int vt_opt_int(const char *option, const char *what, const char *arg, int lo, int hi, int *out)
{
    if (lo >= 0) {
        uint64_t u;
        if (vt_parse_u64(arg, (uint64_t)lo, (uint64_t)hi, &u)) {
            *out = (int)u;
            return 1;
        }
    } else if (vt_parse_int(arg, lo, hi, out)) {
        return 1;
    }
    char l[16], h[16];
    snprintf(l, sizeof l, "%d", lo);
    snprintf(h, sizeof h, "%d", hi);
    return refuse_range(option, what, arg, l, h);
}

int vt_opt_once(const char *option, const char *arg, const char **slot)
{
    if (*slot) {
        vt_usage_error(cli_prog, "%s given twice ('%s', then '%s'): give it once", option, *slot,
                       arg);
        return 0;
    }
    *slot = arg;
    return 1;
}

int vt_opt_positive(const char *option, const char *arg, float *out)
{
    float v;
    if (vt_parse_float(arg, &v) && v > 0.0f) {
        *out = v;
        return 1;
    }
    vt_usage_error(cli_prog, "%s takes a positive number, not '%s'", option, arg);
    return 0;
}

int vt_opt_light_region(const char *option, const char *arg, int file_ok, vdsh_light_box *out)
{
    const char *names = file_ok ? "auto, grown, file" : "auto, grown";
    if (strcmp(arg, "auto") == 0 || strcmp(arg, "grown") == 0 ||
        (file_ok && strcmp(arg, "file") == 0)) {
        out->rule = arg[0] == 'a'   ? 0
                    : arg[0] == 'g' ? VDSH_LIGHT_REGION_GROWN
                                    : VT_LIGHT_REGION_FILE;
        return 1;
    }
    float v[6];
    if (vt_parse_floats(arg, v, 6, 6) != 6) {
        vt_usage_error(cli_prog,
                       "%s takes %s or a box XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX (six numbers, scene "
                       "units), not '%s'",
                       option, names, arg);
        return 0;
    }
    int a = vdsh_light_box_bad_axis(v, v + 3); /* v is finite: min below max */
    if (a >= 0) {
        vt_usage_error(cli_prog,
                       "%s '%s': the box's %c runs %g..%g: each min must be below its max", option,
                       arg, "xyz"[a], (double)v[a], (double)v[a + 3]);
        return 0;
    }
    out->rule = VDSH_LIGHT_REGION_BOX;
    memcpy(out->min, v, sizeof out->min);
    memcpy(out->max, v + 3, sizeof out->max);
    return 1;
}

int vt_opt_nonnegative(const char *option, const char *arg, float *out)
{
    float v;
    if (vt_parse_float(arg, &v) && !(v < 0.0f)) {
        *out = v;
        return 1;
    }
    vt_usage_error(cli_prog, "%s takes a number >= 0, not '%s'", option, arg);
    return 0;
}

int vt_opt_tolerance(const char *option, const char *noun, const char *arg, int zero_ok,
                     double *out)
{
    char *end = NULL;
    double t = strtod(arg, &end);
    if (end != arg && !*end && (zero_ok ? t >= 0.0 : t > 0.0)) {
        *out = t;
        return 1;
    }
    vt_usage_error(cli_prog, "%s takes %s %s (or inf), not '%s'", option,
                   noun ? noun : "a tolerance", zero_ok ? ">= 0" : "> 0", arg);
    return 0;
}

int vt_parse_orders(const char *s, int distinct, int max_order, int *want)
{
    /* At most max_order entries (a longer list repeats an order); 64
     * entries stand for any max_order <= 64. */
    uint64_t v[64];
    int n = max_order >= 1 && max_order <= 64
                ? vt_parse_u64_list(s, 1, (uint64_t)max_order, v, 1, max_order)
                : 0;
    int seen[65] = {0};
    for (int i = 0; i < n; i++) {
        if (distinct && seen[v[i]])
            return 0;
        seen[v[i]] = 1;
    }
    if (n == 0)
        return 0;
    for (int k = 0; k <= max_order; k++)
        want[k] = seen[k];
    return 1;
}

int vt_opt_orders(const char *option, const char *example, const char *arg, int max_order,
                  int *want)
{
    if (vt_parse_orders(arg, 1, max_order, want))
        return 1;
    vt_usage_error(cli_prog, "%s takes distinct orders 1..%d such as %s, not '%s'", option,
                   max_order, example, arg);
    return 0;
}

int vt_opt_choice(const char *option, const char *arg, const vt_choice *choices, int *out)
{
    int n = 0;
    for (; choices[n].name; n++)
        if (strcmp(arg, choices[n].name) == 0) {
            *out = choices[n].value;
            return 1;
        }
    char list[512];
    size_t at = 0;
    for (int i = 0; i < n && at < sizeof list; i++)
        at += (size_t)snprintf(list + at, sizeof list - at, "%s%s",
                               i == 0       ? ""
                               : i + 1 == n ? " or "
                                            : ", ",
                               choices[i].name);
    vt_usage_error(cli_prog, "%s takes %s, not '%s'", option, list, arg);
    return 0;
}
