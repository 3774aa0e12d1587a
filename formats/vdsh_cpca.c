/* vdsh_cpca.c - the cpca encoder (vdsh_cpca.h; VDSH.md "cpca streams").
 *
 * Everything is f64 in a fixed order on one thread, with only +, -, *, /
 * and sqrt (correctly rounded; no libm transcendental, whose results may
 * depend on the CPU's code path), and the file is compiled as ISO C
 * (-std=c11: no fused multiply-add contraction): the same bytes on any
 * x86-64 CPU and whatever the caller's thread count. */
#include "vdsh_cpca.h"
#include "vdsh_cpca_study.h"
#include "vdsh_failf.h"
#include "vdsh_internal.h"

#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "vdsh_sh.h"

enum {
    KMEANS_ROUNDS = 25,
    CUBE_N = 37, /* metric directions: 6 * 37^2 = 8214 texel centres of a cube */
    /* CPCA refinement after k-means: rounds of reassigning each vertex to
     * the cluster that reconstructs it best in its own hemisphere, on a
     * coarser cube of directions (6 * 12^2 = 864), then fitting again */
    REFINE_ROUNDS = 3,
    REFINE_CUBE_N = 12
};
#define NORMAL_WEIGHT 10.0 /* normals at ten times the coefficients' spread */
#define SPHERE_EPS 0.01    /* the whole sphere's weight in the metric */
#define KMEANS_SEED 0x5eed5eed12345678ull

vdsh_cpca_settings vdsh_cpca_settings_default(void)
{
    vdsh_cpca_settings s = {.clusters = VDSH_CPCA_DEFAULT_CLUSTERS,
                            .budget = VDSH_CPCA_DEFAULT_BUDGET,
                            .light_mix = VDSH_CPCA_DEFAULT_LIGHT_MIX,
                            .margin = VDSH_CPCA_DEFAULT_MARGIN,
                            .starts = VDSH_CPCA_DEFAULT_STARTS,
                            .bases_s8 = VDSH_CPCA_DEFAULT_BASES_S8};
    return s;
}

void vdsh_cpca_settings_text(const vdsh_cpca_settings *s, char *buf, size_t size)
{
    char t[192]; /* the longest: 10-digit numbers, %g at most 13 characters */
    int n;
    if (!s->clusters)
        n = snprintf(t, sizeof t, "auto:%u", s->budget);
    else if (s->budget)
        n = snprintf(t, sizeof t, "%u,alloc:%u", s->clusters, s->budget);
    else
        n = snprintf(t, sizeof t, "%u,%u,%u", s->clusters, s->basis, s->bits);
    n += snprintf(t + n, sizeof t - (size_t)n, ",light:%g", (double)s->light_mix);
    if (s->margin > 0.0f)
        n += snprintf(t + n, sizeof t - (size_t)n, ",margin:%g", (double)s->margin);
    if (s->starts)
        n += snprintf(t + n, sizeof t - (size_t)n, ",starts:%u", s->starts);
    if (s->bases_s8)
        snprintf(t + n, sizeof t - (size_t)n, ",bases:8");
    snprintf(buf, size, "%s", t);
}

static int check_light(const vdsh_cpca_settings *s, vdsh_error *err)
{
    if (!(s->light_mix >= 0.0f && s->light_mix <= 1.0f)) {
        vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca: light mix %g out of range 0..1",
                   (double)s->light_mix);
        return 0;
    }
    if (s->light_count && (!s->lights || !s->positions)) {
        vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca: %u light%s without %s", s->light_count,
                   vdsh_s(s->light_count), !s->lights ? "the lights" : "the receiver positions");
        return 0;
    }
    for (size_t x = 0; x < 3 * (size_t)s->light_count; x++)
        if (!isfinite(s->lights[x])) {
            vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca: light %zu is not finite", x / 3);
            return 0;
        }
    if (!(s->margin == 0.0f || (s->margin > 0.0f && s->margin <= VDSH_CPCA_MAX_MARGIN))) {
        vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca: margin %g out of range (0, %g]",
                   (double)s->margin, (double)VDSH_CPCA_MAX_MARGIN);
        return 0;
    }
    if (s->starts > VDSH_CPCA_MAX_STARTS) {
        vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca: %u starts out of range 1..%d", s->starts,
                   VDSH_CPCA_MAX_STARTS);
        return 0;
    }
    return 1;
}

static int check_settings(const vdsh_cpca_settings *s, vdsh_error *err)
{
    if (!check_light(s, err))
        return 0;
    if (s->budget) {
        if (s->budget > VDSH_CPCA_MAX_BUDGET) {
            vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca: auto budget %u out of range 1..%d", s->budget,
                       VDSH_CPCA_MAX_BUDGET);
            return 0;
        }
        if (s->clusters > VDSH_CPCA_MAX_CLUSTERS) {
            vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca: clusters %u out of range 1..%d", s->clusters,
                       VDSH_CPCA_MAX_CLUSTERS);
            return 0;
        }
        return 1;
    }
    if (s->clusters < 1 || s->clusters > VDSH_CPCA_MAX_CLUSTERS) {
        vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca: clusters %u out of range 1..%d", s->clusters,
                   VDSH_CPCA_MAX_CLUSTERS);
        return 0;
    }
    if (s->basis < 1 || s->basis > VDSH_MAX_COEFFS) {
        vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca: basis %u out of range 1..%d", s->basis,
                   VDSH_MAX_COEFFS);
        return 0;
    }
    if (s->bits < VDSH_CPCA_MIN_BITS || s->bits > VDSH_CPCA_MAX_BITS) {
        vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca: bits %u out of range %d..%d", s->bits,
                   VDSH_CPCA_MIN_BITS, VDSH_CPCA_MAX_BITS);
        return 0;
    }
    return 1;
}

static vdsh_result parse_base(const char *text, vdsh_cpca_settings *out, vdsh_error *err);

/* A decimal of at most 16 characters, digits and one point only (no
 * sign, exponent, inf or nan), into *x; 0 when malformed. */
static int parse_decimal(const char *p, double *x)
{
    const char *q = p;
    int digits = 0, points = 0;
    for (; *q; q++) {
        if (*q >= '0' && *q <= '9')
            digits++;
        else if (*q != '.' || points++)
            return 0;
    }
    if (!digits || q - p > 16)
        return 0;
    char *end;
    *x = strtod(p, &end);
    return *end == '\0';
}

/* The options a setting may end in (vdsh_cpca_parse), each once. */
static const char *const OPTIONS[] = {"light:", "margin:", "starts:", "bases:"};
enum { NOPTIONS = 4 };

/* The option token p names (its index in OPTIONS), or -1. */
static int option_of(const char *p)
{
    for (int i = 0; i < NOPTIONS; i++)
        if (strncmp(p, OPTIONS[i], strlen(OPTIONS[i])) == 0)
            return i;
    return -1;
}

vdsh_result vdsh_cpca_parse(const char *text, vdsh_cpca_settings *out, vdsh_error *err)
{
    const char *p = text ? text : "";
    char buf[128];
    if (strlen(p) >= sizeof buf)
        return vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca settings '%s': too long", p);
    strcpy(buf, p);
    /* the options: from the first comma-separated token that names one */
    char *opts = option_of(buf) >= 0 ? buf : NULL;
    for (char *c = strchr(buf, ','); c && !opts; c = strchr(c + 1, ','))
        if (option_of(c + 1) >= 0)
            opts = c + 1;
    vdsh_cpca_settings s = vdsh_cpca_settings_default();
    if (opts != buf) {
        if (opts)
            opts[-1] = 0;
        vdsh_result r = parse_base(buf, &s, err);
        if (r != VDSH_OK)
            return r;
    }
    double value[NOPTIONS];
    int said[NOPTIONS] = {0, 0, 0, 0};
    for (char *tok = opts; tok;) {
        char *next = strchr(tok, ',');
        if (next)
            *next++ = 0;
        const int o = option_of(tok);
        const int ok =
            o >= 0 && !said[o] && parse_decimal(tok + strlen(OPTIONS[o]), &value[o]) &&
            (o == 0   ? value[0] <= 1.0
             : o == 1 ? value[1] > 0.0 && value[1] <= VDSH_CPCA_MAX_MARGIN
             : o == 2 ? value[2] >= 1.0 && value[2] <= VDSH_CPCA_MAX_STARTS && !strchr(tok, '.')
                      : (value[3] == 8.0 || value[3] == 16.0) && !strchr(tok, '.'));
        if (!ok)
            return vdsh_failf(err, VDSH_ERR_ARGUMENT,
                              "cpca settings '%s': '%s': expected options at the end, each "
                              "once: light:A (the light mix, 0..1), margin:S (S > 0, at most 1e6), "
                              "starts:N (1..%d) or bases:8|16 (the bases' bits) (for example "
                              "16,alloc:32,margin:0.25,starts:3)",
                              p, tok, VDSH_CPCA_MAX_STARTS);
        said[o] = 1;
        tok = next;
    }
    /* Not said: the light density for the byte-budget forms, the uniform
     * hemisphere for fixed widths; the default's margin and starts with
     * the options alone and the light density, none with a base said; the
     * default's s8 bases with the options alone, f16 with a base said
     * (vdsh_cpca.h). */
    const int base = opts != buf;
    s.light_mix = said[0] ? (float)value[0] : s.budget ? VDSH_CPCA_DEFAULT_LIGHT_MIX : 0.0f;
    const int deflt = !base && s.light_mix > 0.0f;
    s.margin = said[1] ? (float)value[1] : deflt ? VDSH_CPCA_DEFAULT_MARGIN : 0.0f;
    s.starts = said[2] ? (uint32_t)value[2] : deflt ? VDSH_CPCA_DEFAULT_STARTS : 0;
    s.bases_s8 = said[3] ? value[3] == 8.0 : base ? 0 : VDSH_CPCA_DEFAULT_BASES_S8;
    if ((said[1] || said[2]) && !(s.budget && s.clusters && s.light_mix > 0.0f))
        return vdsh_failf(err, VDSH_ERR_ARGUMENT,
                          "cpca settings '%s': margin:S and starts:N need K,alloc:BYTES with a "
                          "light mix above 0 (they use the light pool)",
                          p);
    if (said[3] && !(s.budget && s.clusters))
        return vdsh_failf(err, VDSH_ERR_ARGUMENT,
                          "cpca settings '%s': bases:8|16 needs K,alloc:BYTES", p);
    *out = s;
    return VDSH_OK;
}

static vdsh_result parse_base(const char *text, vdsh_cpca_settings *out, vdsh_error *err)
{
    unsigned long v[3];
    const char *p = text ? text : "";
    if (strncmp(p, "auto", 4) == 0) {
        unsigned long budget = VDSH_CPCA_DEFAULT_BUDGET;
        if (p[4] == ':') {
            char *end;
            budget = p[5] >= '0' && p[5] <= '9' ? strtoul(p + 5, &end, 10) : 0;
            if (!budget || *end || budget > VDSH_CPCA_MAX_BUDGET)
                return vdsh_failf(err, VDSH_ERR_ARGUMENT,
                                  "cpca settings '%s': expected auto:BYTES, bytes per vertex "
                                  "1..%d (for example auto:32)",
                                  text, VDSH_CPCA_MAX_BUDGET);
        } else if (p[4]) {
            return vdsh_failf(err, VDSH_ERR_ARGUMENT,
                              "cpca settings '%s': expected auto or auto:BYTES", text);
        }
        vdsh_cpca_settings s = {0};
        s.budget = (uint32_t)budget;
        *out = s;
        return VDSH_OK;
    }
    {
        /* K,alloc:BYTES: a width per basis vector */
        char *end;
        const char *comma = strchr(p, ',');
        if (*p >= '0' && *p <= '9' && comma && strncmp(comma + 1, "alloc:", 6) == 0) {
            unsigned long k = strtoul(p, &end, 10);
            const char *q = comma + 7;
            unsigned long budget = *q >= '0' && *q <= '9' ? strtoul(q, &end, 10) : 0;
            if (end == q || *end || !budget || budget > VDSH_CPCA_MAX_BUDGET || k < 1 ||
                k > VDSH_CPCA_MAX_CLUSTERS)
                return vdsh_failf(err, VDSH_ERR_ARGUMENT,
                                  "cpca settings '%s': expected K,alloc:BYTES, K 1..%d, bytes "
                                  "per vertex 1..%d (for example 8,alloc:32)",
                                  text, VDSH_CPCA_MAX_CLUSTERS, VDSH_CPCA_MAX_BUDGET);
            vdsh_cpca_settings s = {0};
            s.clusters = (uint32_t)k;
            s.budget = (uint32_t)budget;
            *out = s;
            return VDSH_OK;
        }
    }
    for (int k = 0; k < 3; k++) {
        char *end;
        if (*p < '0' || *p > '9')
            return vdsh_failf(err, VDSH_ERR_ARGUMENT,
                              "cpca settings '%s': expected K,B,BITS (for example 8,54,4)",
                              text ? text : "");
        v[k] = strtoul(p, &end, 10);
        if (v[k] > 100000 || *end != (k < 2 ? ',' : '\0'))
            return vdsh_failf(err, VDSH_ERR_ARGUMENT,
                              "cpca settings '%s': expected K,B,BITS (for example 8,54,4)", text);
        p = end + (k < 2);
    }
    vdsh_cpca_settings s = {0};
    s.clusters = (uint32_t)v[0];
    s.basis = (uint32_t)v[1];
    s.bits = (uint32_t)v[2];
    if (!check_settings(&s, err))
        return VDSH_ERR_ARGUMENT;
    *out = s;
    return VDSH_OK;
}

void vdsh_cpca_fit_free(vdsh_cpca_fit *fit)
{
    if (!fit)
        return;
    free(fit->storage_);
    memset(fit, 0, sizeof *fit);
}

/* ---- linear algebra (f64, fixed order) ---- */

/* Cholesky: G (n x n, symmetric) = L L^T, L lower-triangular in l. 0 when
 * G is not positive definite. */
static int cholesky(const double *g, uint32_t n, double *l)
{
    memset(l, 0, sizeof(double) * n * n);
    for (uint32_t j = 0; j < n; j++) {
        double d = g[(size_t)j * n + j];
        for (uint32_t k = 0; k < j; k++)
            d -= l[(size_t)j * n + k] * l[(size_t)j * n + k];
        if (!(d > 0.0))
            return 0;
        double r = sqrt(d);
        l[(size_t)j * n + j] = r;
        for (uint32_t i = j + 1; i < n; i++) {
            double s = g[(size_t)i * n + j];
            for (uint32_t k = 0; k < j; k++)
                s -= l[(size_t)i * n + k] * l[(size_t)j * n + k];
            l[(size_t)i * n + j] = s / r;
        }
    }
    return 1;
}

/* Cyclic Jacobi: a (n x n, symmetric, destroyed) = V diag(a_ii) V^T; v
 * receives the eigenvectors as columns. */
static void jacobi(double *a, uint32_t n, double *v)
{
    for (uint32_t i = 0; i < n; i++)
        for (uint32_t j = 0; j < n; j++)
            v[(size_t)i * n + j] = i == j;
    for (int sweep = 0; sweep < 50; sweep++) {
        double off = 0.0, all = 0.0;
        for (uint32_t i = 0; i < n; i++)
            for (uint32_t j = 0; j < n; j++) {
                double x = a[(size_t)i * n + j] * a[(size_t)i * n + j];
                all += x;
                if (i != j)
                    off += x;
            }
        if (!(off > 1e-24 * all))
            break;
        for (uint32_t p = 0; p + 1 < n; p++)
            for (uint32_t q = p + 1; q < n; q++) {
                double apq = a[(size_t)p * n + q];
                if (apq == 0.0)
                    continue;
                double theta = (a[(size_t)q * n + q] - a[(size_t)p * n + p]) / (2.0 * apq);
                double t = (theta >= 0.0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (uint32_t k = 0; k < n; k++) { /* columns p, q */
                    double kp = a[(size_t)k * n + p], kq = a[(size_t)k * n + q];
                    a[(size_t)k * n + p] = c * kp - s * kq;
                    a[(size_t)k * n + q] = s * kp + c * kq;
                }
                for (uint32_t k = 0; k < n; k++) { /* rows p, q */
                    double pk = a[(size_t)p * n + k], qk = a[(size_t)q * n + k];
                    a[(size_t)p * n + k] = c * pk - s * qk;
                    a[(size_t)q * n + k] = s * pk + c * qk;
                }
                a[(size_t)p * n + q] = a[(size_t)q * n + p] = 0.0;
                for (uint32_t k = 0; k < n; k++) {
                    double kp = v[(size_t)k * n + p], kq = v[(size_t)k * n + q];
                    v[(size_t)k * n + p] = c * kp - s * kq;
                    v[(size_t)k * n + q] = s * kp + c * kq;
                }
            }
    }
}

/* A study knob (vdsh_cpca_study.h): the number in environment variable
 * `name`, 0 (off: the encoder's own bytes) when unset or empty; one that is
 * not a number in (0, most] is ignored, with a message. Read at every use:
 * no state kept. */
static double study_knob(const char *name, double most)
{
    const char *e = getenv(name);
    if (!e || !*e)
        return 0.0;
    char *end;
    const double s = strtod(e, &end);
    if (*end == '\0' && s > 0.0 && s <= most)
        return s;
    fprintf(stderr, "cpca: %s='%s' is not a number in (0, %g]: ignored\n", name, e, most);
    return 0.0;
}

/* ln x for x > 0 finite: frexp (exact) and the atanh series, +, -, x, /
 * only (no libm transcendental): the same bits on any CPU. */
static double det_ln(double x)
{
    int e;
    double m = frexp(x, &e); /* x = m 2^e, m in [0.5, 1) */
    if (m < 0.70710678118654752) {
        m *= 2.0;
        e--;
    }
    const double s = (m - 1.0) / (m + 1.0), s2 = s * s; /* |s| < 0.172 */
    double t = s, sum = 0.0;
    for (int k = 1; k <= 25; k += 2) {
        sum += t / k;
        t *= s2;
    }
    return 2.0 * sum + e * 0.69314718055994530942;
}

/* ---- SH over a batch of light directions ----
 *
 * The margin weights and the pool score evaluate order n's SH at every
 * (row, pool light above its horizon) pair: vdsh_sh_eval_soa over a batch
 * of directions (the arithmetic of vdsh_sh_eval per direction: the same
 * bits) and the dot products with a row's coefficients summed over the
 * coefficients in order for each direction, as the one-direction loop
 * did: the same bytes, several times faster. */
enum { SH_BATCH = 64 };
typedef struct sh_batch {
    uint32_t count;
    float x[SH_BATCH], y[SH_BATCH], z[SH_BATCH];
    double r[SH_BATCH];                   /* each direction's distance */
    double a[SH_BATCH];                   /* scratch of sh_batch_dots */
    float yk[VDSH_MAX_COEFFS * SH_BATCH]; /* Y_i(direction k) at [i * SH_BATCH + k] */
} sh_batch;

/* Stage direction d (not 0) into b: 1 when b is full. */
static int sh_batch_add(sh_batch *b, const double d[3])
{
    const double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    b->x[b->count] = (float)(d[0] / r);
    b->y[b->count] = (float)(d[1] / r);
    b->z[b->count] = (float)(d[2] / r);
    b->r[b->count] = r;
    return ++b->count == SH_BATCH;
}

static void sh_batch_eval(sh_batch *b, uint32_t order)
{
    vdsh_sh_eval_soa((int)order, b->count, b->x, b->y, b->z, b->yk, SH_BATCH);
}

/* out[k] = sum over i < n, in order, of c[i] * Y_i(direction k) (f64). */
static void sh_batch_dots(const sh_batch *b, const float *c, uint32_t n, double *out)
{
    const uint32_t cnt = b->count;
    for (uint32_t k = 0; k < cnt; k++)
        out[k] = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        const double ci = c[i];
        const float *yi = b->yk + (size_t)i * SH_BATCH;
        for (uint32_t k = 0; k < cnt; k++)
            out[k] += ci * yi[k];
    }
}

/* ---- the metric: the SH's Gram matrix over cube texel directions ---- */

typedef struct metric_dirs {
    uint32_t count, n, cube_n;
    double *dir;  /* 3 per direction */
    double *w;    /* per direction: its texel's solid angle */
    double *wy;   /* per direction: sqrt(weight) * Y_i, n values */
    double *full; /* n x n: sum over all directions of weight * Y Y^T */
} metric_dirs;

static int metric_init(metric_dirs *m, uint32_t order, uint32_t cube_n)
{
    uint32_t n = order * order, count = 6 * cube_n * cube_n;
    m->count = count;
    m->n = n;
    m->cube_n = cube_n;
    m->dir = malloc(sizeof(double) * 3 * count);
    m->w = malloc(sizeof(double) * count);
    m->wy = malloc(sizeof(double) * (size_t)n * count);
    m->full = calloc((size_t)n * n, sizeof(double));
    if (!m->dir || !m->w || !m->wy || !m->full)
        return 0;
    float y[VDSH_MAX_COEFFS];
    uint32_t at = 0;
    for (uint32_t face = 0; face < 6; face++)
        for (uint32_t j = 0; j < cube_n; j++)
            for (uint32_t i = 0; i < cube_n; i++, at++) {
                double u = 2.0 * (i + 0.5) / cube_n - 1.0, v = 2.0 * (j + 0.5) / cube_n - 1.0;
                double d[3];
                uint32_t axis = face / 2;
                double sign = face % 2 ? -1.0 : 1.0;
                d[axis] = sign;
                d[(axis + 1) % 3] = u;
                d[(axis + 2) % 3] = v;
                double r2 = 1.0 + u * u + v * v, r = sqrt(r2);
                /* solid angle of the texel, to first order */
                double w = 4.0 / ((double)cube_n * cube_n) / (r2 * r);
                m->w[at] = w;
                float df[3];
                for (int k = 0; k < 3; k++) {
                    m->dir[3 * at + k] = d[k] / r;
                    df[k] = (float)(d[k] / r);
                }
                vdsh_sh_eval((int)order, df, y);
                double sw = sqrt(w);
                for (uint32_t k = 0; k < n; k++)
                    m->wy[(size_t)at * n + k] = sw * (double)y[k];
            }
    for (uint32_t d = 0; d < count; d++) {
        const double *y2 = m->wy + (size_t)d * n;
        for (uint32_t a = 0; a < n; a++)
            for (uint32_t b = 0; b <= a; b++)
                m->full[(size_t)a * n + b] += y2[a] * y2[b];
    }
    for (uint32_t a = 0; a < n; a++)
        for (uint32_t b = 0; b < a; b++)
            m->full[(size_t)b * n + a] = m->full[(size_t)a * n + b];
    return 1;
}

static void metric_free(metric_dirs *m)
{
    free(m->dir);
    free(m->w);
    free(m->wy);
    free(m->full);
}

/* ---- the light-density metric (vdsh_cpca.h, settings light_mix; docs/
 * ACCURACY.md "A light-density metric") ----
 *
 * Every vertex's hemisphere weight of a direction is (1 - a) + a * rho,
 * rho the share of the pool's lights above the vertex's horizon whose
 * direction from the vertex falls in that direction's cube texel, over the
 * texel's share of the hemisphere's solid angle (2 pi): the density of
 * possible lights seen from the vertex, with the uniform weight's
 * integral. A vertex with no light above its horizon keeps the uniform
 * weight. +, -, x, / and comparisons only (no libm): the same bytes on any
 * CPU. */
typedef struct lightmix {
    double a;
    uint32_t nl;
    const float *lights, *pos; /* nl x 3, rows x 3 */
    /* The margin (settings margin, vdsh_cpca.h): when wt is set, each
     * light's weight 1 / (1 + m^2 inv_sigma2), m its margin from the
     * source's coefficients src (order^2 per row), parallel to tex. */
    const float *src;
    uint32_t order;
    double inv_sigma2;
    float *wt;
    /* Every row's texels of its lights above its horizon, in pool order
     * (packed: light_texel), found once by lightmix_load: row v's at
     * tex[at[v]..at[v + 1]), for the rows v < cached (the first that fit
     * in LIGHT_CACHE texels); the later rows' are found again at every
     * use, into the scratch stex (and swt). */
    uint32_t rows, cached;
    size_t *at;
    uint16_t *tex;
    uint16_t ref[6 * CUBE_N * CUBE_N]; /* refine_texel's of each fit texel */
    /* Scratch, each user's own (lightmix_view): a row past the cache's
     * texels and weights (nl each), and the margin weights' batch. */
    uint16_t *stex;
    float *swt;
    sh_batch *sb;
    int view; /* 1: the arrays above the scratch are another's */
} lightmix;

/* The most texels lightmix_load keeps (x 2 bytes) unless the settings
 * say (light_cache): 128 MiB, the rows of about 2^16 receivers with half a
 * 2048-light pool above each horizon. */
#define LIGHT_CACHE ((size_t)1 << 26)

static void lightmix_free(lightmix *lm)
{
    if (!lm->view) {
        free(lm->at);
        free(lm->tex);
        free(lm->wt);
    }
    free(lm->stex);
    free(lm->swt);
    free(lm->sb);
    memset(lm, 0, sizeof *lm);
}

/* The index along a side of cube_n texels of face coordinate u (-1..1). */
static uint32_t cube_index(double u, uint32_t cube_n)
{
    double f = (u + 1.0) * 0.5 * cube_n;
    return f <= 0.0 ? 0u : f >= cube_n ? cube_n - 1u : (uint32_t)f;
}

/* The texel of direction d (not 0) on the fit's cube (CUBE_N) and on the
 * refinement's (REFINE_CUBE_N), metric_init's layout, in 16 bits: the
 * fit's texel (bits 0-13: 6 x 37^2 = 8214 texels) and the refinement's as
 * 0 or 1 more than the refinement's index holding the fit texel's first
 * corner along i (bit 14) and j (bit 15): with i = floor(37 x), x =
 * (u + 1) / 2, floor(12 x) is floor(12 i / 37) or one more (12/37 < 1),
 * also as rounded, since 12 i / 37 (i = 1..36) is never within rounding
 * of an integer. +, -, x, / and comparisons only (no libm). */
#define FIT_TEXEL 0x3fffu
static uint16_t light_texel(const double d[3])
{
    double ax = fabs(d[0]), ay = fabs(d[1]), az = fabs(d[2]);
    uint32_t axis = ax >= ay && ax >= az ? 0u : ay >= az ? 1u : 2u;
    double m = fabs(d[axis]);
    double u = d[(axis + 1) % 3] / m, v = d[(axis + 2) % 3] / m;
    uint32_t face = axis * 2u + (d[axis] < 0.0);
    uint32_t i = cube_index(u, CUBE_N), j = cube_index(v, CUBE_N);
    uint32_t di = cube_index(u, REFINE_CUBE_N) - i * REFINE_CUBE_N / CUBE_N;
    uint32_t dj = cube_index(v, REFINE_CUBE_N) - j * REFINE_CUBE_N / CUBE_N;
    return (uint16_t)(((face * CUBE_N + j) * CUBE_N + i) | di << 14 | dj << 15);
}

/* The refinement cube's texel of a packed light_texel (bits 14, 15 0:
 * the one holding the fit texel's first corner). */
static uint32_t refine_texel(uint32_t t)
{
    const uint32_t fit = t & FIT_TEXEL, face = fit / (CUBE_N * CUBE_N);
    const uint32_t j = fit / CUBE_N % CUBE_N, i = fit % CUBE_N;
    return (face * REFINE_CUBE_N + j * REFINE_CUBE_N / CUBE_N + (t >> 15 & 1u)) * REFINE_CUBE_N +
           i * REFINE_CUBE_N / CUBE_N + (t >> 14 & 1u);
}

/* Whether light l is above the horizon of the vertex at p with normal nv;
 * d its direction from p. */
static int light_above(const lightmix *lm, uint32_t l, const float *p, const float *nv, double d[3])
{
    const float *q = lm->lights + 3 * (size_t)l;
    for (int i = 0; i < 3; i++)
        d[i] = (double)q[i] - p[i];
    return d[0] * nv[0] + d[1] * nv[1] + d[2] * nv[2] > 0.0;
}

/* The margin weights of the lights staged in lm->sb for row v into
 * wt[0 .. count): 1 / (1 + m^2 / sigma^2), m = ln D of the row's
 * coefficients at the light's direction less ln of its distance (the
 * decision's margin). +, -, x, /, sqrt and det_ln only. */
static void margin_weights(const lightmix *lm, uint32_t v, float *wt)
{
    sh_batch *b = lm->sb;
    const uint32_t n = lm->order * lm->order;
    sh_batch_eval(b, lm->order);
    sh_batch_dots(b, lm->src + (size_t)v * n, n, b->a);
    for (uint32_t k = 0; k < b->count; k++) {
        const double m = b->a[k] - det_ln(b->r[k]);
        wt[k] = (float)(1.0 / (1.0 + m * m * lm->inv_sigma2));
    }
    b->count = 0;
}

/* Row v's texels (normal nv) into tex (and their margin weights into wt,
 * with a margin; else wt is NULL): their count. */
static uint32_t row_texels(const lightmix *lm, uint32_t v, const float *nv, uint16_t *tex,
                           float *wt)
{
    const float *p = lm->pos + 3 * (size_t)v;
    uint32_t t = 0;
    for (uint32_t l = 0; l < lm->nl; l++) {
        double d[3];
        if (!light_above(lm, l, p, nv, d))
            continue;
        tex[t++] = light_texel(d);
        if (wt && sh_batch_add(lm->sb, d))
            margin_weights(lm, v, wt + t - SH_BATCH);
    }
    if (wt && lm->sb->count)
        margin_weights(lm, v, wt + t - lm->sb->count);
    return t;
}

/* lm's own scratch (stex, swt, sb) for the rows past its cache and the
 * margin: 1, or 0 out of memory. */
static int lightmix_scratch(lightmix *lm)
{
    if (lm->cached < lm->rows && (!(lm->stex = malloc(sizeof(uint16_t) * lm->nl)) ||
                                  (lm->wt && !(lm->swt = malloc(sizeof(float) * lm->nl)))))
        return 0;
    return !lm->wt || lm->sb || (lm->sb = calloc(1, sizeof *lm->sb)) != NULL;
}

/* *view: lm's texels and weights, shared (read only), with scratch of its
 * own, for a thread of its own: 1, or 0 out of memory (free it with
 * lightmix_free either way). */
static int lightmix_view(const lightmix *lm, lightmix *view)
{
    *view = *lm;
    view->view = 1;
    view->stex = NULL;
    view->swt = NULL;
    view->sb = NULL;
    return lightmix_scratch(view);
}

/* Whether settings st turn the light-density metric on: a mix above 0
 * and a pool with the rows' positions. */
static int lightmix_on(const vdsh_cpca_settings *st)
{
    return st && st->light_mix > 0.0f && st->light_count && st->lights && st->positions;
}

/* lm from the settings, the rows' texels found (normals, rows x 3): 1 when
 * on, 0 when off (lm zeroed), -1 out of memory. */
static int lightmix_load(lightmix *lm, const vdsh_cpca_settings *st, const float *src,
                         uint32_t order, const float *normals, uint32_t rows)
{
    memset(lm, 0, sizeof *lm);
    if (!lightmix_on(st))
        return 0;
    lm->a = (double)st->light_mix;
    lm->rows = rows;
    lm->nl = st->light_count;
    lm->lights = st->lights;
    lm->pos = st->positions;
    for (uint32_t t = 0; t < 6 * CUBE_N * CUBE_N; t++)
        lm->ref[t] = (uint16_t)refine_texel(t);
    if (!(lm->at = malloc(sizeof(size_t) * ((size_t)rows + 1))))
        return -1;
    /* One walk: each row's texels written where it would be kept, until
     * the next would pass the cap; room for every row's (or the cap's)
     * and one more row's, then shrunk to what is kept (pages never
     * written are never touched). */
    const size_t cap = st->light_cache ? st->light_cache : LIGHT_CACHE;
    const size_t most = (size_t)rows * lm->nl;
    if (!(lm->tex = malloc(sizeof(uint16_t) * ((most < cap ? most : cap) + lm->nl) + 1)))
        return -1;
    const double sigma = st->margin;
    if (sigma > 0.0) {
        lm->src = src;
        lm->order = order;
        lm->inv_sigma2 = 1.0 / (sigma * sigma);
        if (!(lm->wt = malloc(sizeof(float) * ((most < cap ? most : cap) + lm->nl) + 1)) ||
            !(lm->sb = calloc(1, sizeof *lm->sb)))
            return -1;
    }
    lm->at[0] = 0;
    for (; lm->cached < rows; lm->cached++) {
        const uint32_t v = lm->cached;
        const size_t at = lm->at[v];
        const uint32_t t =
            row_texels(lm, v, normals + 3 * (size_t)v, lm->tex + at, lm->wt ? lm->wt + at : NULL);
        if (at + t > cap)
            break;
        lm->at[v + 1] = at + t;
    }
    if (!lightmix_scratch(lm))
        return -1;
    const size_t size = lm->at[lm->cached];
    uint16_t *shrunk = realloc(lm->tex, sizeof(uint16_t) * size + 1);
    if (shrunk)
        lm->tex = shrunk;
    if (lm->wt) {
        float *w = realloc(lm->wt, sizeof(float) * size + 1);
        if (w)
            lm->wt = w;
    }
    return 1;
}

/* Row v's packed texels (light_texel) in *tex, their weights in *wt (NULL:
 * each 1) and the weights' sum in *sum; their count returned. */
static uint32_t light_texels(const lightmix *lm, uint32_t v, const float *nv, const uint16_t **tex,
                             const float **wt, double *sum)
{
    uint32_t t;
    if (v < lm->cached) {
        const size_t at = lm->at[v];
        t = (uint32_t)(lm->at[v + 1] - at);
        *tex = lm->tex + at;
        *wt = lm->wt ? lm->wt + at : NULL;
    } else {
        t = row_texels(lm, v, nv, lm->stex, lm->swt);
        *tex = lm->stex;
        *wt = lm->swt;
    }
    double s = 0.0;
    if (*wt)
        for (uint32_t i = 0; i < t; i++)
            s += (*wt)[i];
    *sum = *wt ? s : (double)t;
    return t;
}

#define TWO_PI 6.283185307179586

/* g = sum over directions of weight * (the fraction of the cluster's
 * members whose hemisphere holds the direction) * Y Y^T, plus SPHERE_EPS
 * times the whole sphere's: the mean of the members' own hemisphere
 * metrics. `frac` is scratch (count). Members all facing one way (a
 * room's wall) give metric_gram of their normal; a curved patch's
 * members each keep weight on their own horizon. */
static void metric_gram_members(const metric_dirs *m, const float *normals, const uint32_t *labels,
                                uint32_t rows, uint32_t c, uint32_t members, double *frac,
                                double *g, const lightmix *lm)
{
    uint32_t n = m->n;
    for (uint32_t d = 0; d < m->count; d++)
        frac[d] = 0.0;
    for (uint32_t v = 0; v < rows; v++) {
        if (labels[v] != c)
            continue;
        const float *nv = normals + 3 * (size_t)v;
        double a = nv[0], b = nv[1], e = nv[2], u = 1.0;
        if (lm) { /* (1 - a) uniform + a light density */
            const uint16_t *tex;
            const float *wt;
            double sum;
            const uint32_t t = light_texels(lm, v, nv, &tex, &wt, &sum);
            if (t && sum > 0.0) {
                u = 1.0 - lm->a;
                for (uint32_t i = 0; i < t; i++) {
                    const uint32_t x = tex[i] & FIT_TEXEL;
                    const double wi = wt ? (double)wt[i] : 1.0;
                    frac[x] += lm->a * TWO_PI * wi / (sum * m->w[x]);
                }
            }
        }
        for (uint32_t d = 0; d < m->count; d++) {
            const double *dd = m->dir + 3 * (size_t)d;
            if (dd[0] * a + dd[1] * b + dd[2] * e > 0.0)
                frac[d] += u;
        }
    }
    for (size_t k = 0; k < (size_t)n * n; k++)
        g[k] = SPHERE_EPS * m->full[k];
    for (uint32_t d = 0; d < m->count; d++) {
        if (!(frac[d] > 0.0))
            continue;
        double f = frac[d] / members;
        const double *y = m->wy + (size_t)d * n;
        for (uint32_t a = 0; a < n; a++) {
            double fa = f * y[a];
            double *row = g + (size_t)a * n;
            for (uint32_t b = 0; b <= a; b++)
                row[b] += fa * y[b];
        }
    }
    for (uint32_t a = 0; a < n; a++)
        for (uint32_t b = 0; b < a; b++)
            g[(size_t)b * n + a] = g[(size_t)a * n + b];
}

/* ---- k-means ---- */

static uint64_t splitmix(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* Squared distance of row v's feature [c, ns * normal] to centre z. */
static double feature_dist(const float *c, const float *nrm, uint32_t n, double ns, const double *z)
{
    double d = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        double e = (double)c[i] - z[i];
        d += e * e;
    }
    for (uint32_t k = 0; k < 3; k++) {
        double e = ns * (double)nrm[k] - z[n + k];
        d += e * e;
    }
    return d;
}

static void set_centre(const float *c, const float *nrm, uint32_t n, double ns, double *z)
{
    for (uint32_t i = 0; i < n; i++)
        z[i] = c[i];
    for (uint32_t k = 0; k < 3; k++)
        z[n + k] = ns * (double)nrm[k];
}

/* labels[rows] in 0..k-1; scratch `dist` (rows) and centres k * (n + 3). */
static void kmeans(const float *src, const float *normals, uint32_t rows, uint32_t n, double ns,
                   uint32_t k, uint32_t start, uint32_t *labels, double *dist, double *cent)
{
    const uint32_t dim = n + 3;
    /* the seed study (VDSH_CPCA_KMEANS_SEED=N, vdsh_cpca_study.h) and the
     * settings' starts */
    uint64_t seed = KMEANS_SEED ^ ((uint64_t)study_knob("VDSH_CPCA_KMEANS_SEED", 65535) + start) *
                                      0x9e3779b97f4a7c15ull;
    /* k-means++ seeding */
    uint32_t first = (uint32_t)(splitmix(&seed) % rows);
    set_centre(src + (size_t)first * n, normals + 3 * (size_t)first, n, ns, cent);
    for (uint32_t v = 0; v < rows; v++)
        dist[v] = feature_dist(src + (size_t)v * n, normals + 3 * (size_t)v, n, ns, cent);
    for (uint32_t j = 1; j < k; j++) {
        double total = 0.0;
        for (uint32_t v = 0; v < rows; v++)
            total += dist[v];
        uint32_t pick;
        if (total > 0.0) {
            double r = (double)(splitmix(&seed) >> 11) * 0x1.0p-53 * total, acc = 0.0;
            pick = rows - 1;
            for (uint32_t v = 0; v < rows; v++) {
                acc += dist[v];
                if (acc > r) {
                    pick = v;
                    break;
                }
            }
        } else {
            pick = (uint32_t)(splitmix(&seed) % rows);
        }
        double *z = cent + (size_t)j * dim;
        set_centre(src + (size_t)pick * n, normals + 3 * (size_t)pick, n, ns, z);
        for (uint32_t v = 0; v < rows; v++) {
            double d = feature_dist(src + (size_t)v * n, normals + 3 * (size_t)v, n, ns, z);
            if (d < dist[v])
                dist[v] = d;
        }
    }
    /* Lloyd rounds until no vertex moves */
    double *sum = calloc((size_t)k * dim + 1, sizeof(double));
    uint32_t *count = calloc((size_t)k + 1, sizeof(uint32_t));
    for (uint32_t round = 0; round < KMEANS_ROUNDS && sum && count; round++) {
        uint32_t moved = 0;
        for (uint32_t v = 0; v < rows; v++) {
            const float *c = src + (size_t)v * n, *nr = normals + 3 * (size_t)v;
            uint32_t best = 0;
            double bd = feature_dist(c, nr, n, ns, cent);
            for (uint32_t j = 1; j < k; j++) {
                double d = feature_dist(c, nr, n, ns, cent + (size_t)j * dim);
                if (d < bd) {
                    bd = d;
                    best = j;
                }
            }
            if (round == 0 || labels[v] != best)
                moved++;
            labels[v] = best;
            dist[v] = bd;
        }
        if (!moved)
            break;
        memset(sum, 0, sizeof(double) * k * dim);
        memset(count, 0, sizeof(uint32_t) * k);
        for (uint32_t v = 0; v < rows; v++) {
            double *s = sum + (size_t)labels[v] * dim;
            const float *c = src + (size_t)v * n, *nr = normals + 3 * (size_t)v;
            for (uint32_t i = 0; i < n; i++)
                s[i] += c[i];
            for (uint32_t q = 0; q < 3; q++)
                s[n + q] += ns * (double)nr[q];
            count[labels[v]]++;
        }
        for (uint32_t j = 0; j < k; j++) {
            double *z = cent + (size_t)j * dim;
            if (count[j]) {
                for (uint32_t i = 0; i < dim; i++)
                    z[i] = sum[(size_t)j * dim + i] / count[j];
                continue;
            }
            /* an empty cluster takes the worst-served vertex */
            uint32_t far = 0;
            for (uint32_t v = 1; v < rows; v++)
                if (dist[v] > dist[far])
                    far = v;
            set_centre(src + (size_t)far * n, normals + 3 * (size_t)far, n, ns, z);
            dist[far] = 0.0;
        }
    }
    free(sum);
    free(count);
}

/* The weight of vertex x (n coefficients) on the basis vector whose
 * projection is p, in a cluster of decoded mean mu: (x - mu) . p. */
static double weight_of(const float *x, const double *mu, const double *p, uint32_t n)
{
    double w = 0.0;
    for (uint32_t a = 0; a < n; a++)
        w += ((double)x[a] - mu[a]) * p[a];
    return w;
}

/* ---- the fit: per cluster the stored mean and the basis ---- */

typedef struct fit_ctx {
    const float *src, *normals;
    uint32_t rows, n, k, b;
    const metric_dirs *md;
    uint32_t *labels;
    uint16_t *means, *bases;               /* as stored */
    uint32_t *members;                     /* k */
    double *mus;                           /* k x n: the stored means, decoded */
    double *l;                             /* n x n: the metric's Cholesky factor */
    double *proj;                          /* k x b x n: the weights' projections */
    double *g, *sc, *sy, *ev, *tmp, *frac; /* scratch */
    uint32_t *idx;
    const lightmix *lm; /* the light-density metric's, or NULL */
    uint32_t threads;   /* the most threads fit_all and reassign take (0: one per CPU) */
} fit_ctx;

/* f's scratch for fit_cluster (l, g, sc, sy, ev, tmp, frac, idx), for
 * f->n coefficients: 1, or 0 out of memory (free it with
 * fit_ctx_scratch_free either way). */
static int fit_ctx_scratch(fit_ctx *f)
{
    const size_t nn = (size_t)f->n * f->n;
    f->l = malloc(sizeof(double) * nn);
    f->g = malloc(sizeof(double) * nn);
    f->sc = malloc(sizeof(double) * nn);
    f->sy = malloc(sizeof(double) * nn);
    f->ev = malloc(sizeof(double) * nn);
    f->tmp = malloc(sizeof(double) * nn);
    f->frac = malloc(sizeof(double) * 6 * CUBE_N * CUBE_N);
    f->idx = malloc(sizeof(uint32_t) * f->n);
    return f->l && f->g && f->sc && f->sy && f->ev && f->tmp && f->frac && f->idx;
}

static void fit_ctx_scratch_free(fit_ctx *f)
{
    free(f->l);
    free(f->g);
    free(f->sc);
    free(f->sy);
    free(f->ev);
    free(f->tmp);
    free(f->frac);
    free(f->idx);
}

/* Cluster c's mean and basis from its members (labels): the mean stored
 * as f16, the basis the leading principal directions of the deviations
 * from it in the members' metric, stored as f16. */
static vdsh_result fit_cluster(fit_ctx *f, uint32_t c, vdsh_error *err)
{
    const float *src = f->src, *normals = f->normals;
    const uint32_t rows = f->rows, n = f->n, b = f->b;
    const uint32_t *labels = f->labels;
    double *mu = f->mus + (size_t)c * n, *l = f->l;
    double *proj = f->proj + (size_t)c * b * n;
    double *g = f->g, *sc = f->sc, *sy = f->sy, *ev = f->ev, *tmp = f->tmp, *frac = f->frac;
    uint32_t *idx = f->idx;
    /* members' mean (stored as f16) */
    uint32_t members = 0;
    for (uint32_t i = 0; i < n; i++)
        mu[i] = 0.0;
    for (uint32_t v = 0; v < rows; v++) {
        if (labels[v] != c)
            continue;
        members++;
        for (uint32_t i = 0; i < n; i++)
            mu[i] += src[(size_t)v * n + i];
    }
    f->members[c] = members;
    if (!members) { /* mean, basis and scales 0; no vertex refers to it */
        memset(f->means + (size_t)c * n, 0, sizeof(uint16_t) * n);
        memset(f->bases + (size_t)c * b * n, 0, sizeof(uint16_t) * b * n);
        memset(proj, 0, sizeof(double) * b * n);
        return VDSH_OK;
    }
    for (uint32_t i = 0; i < n; i++) {
        float m = (float)(mu[i] / members);
        uint16_t h = vdsh_f16_from_f32(m);
        if ((h & 0x7c00u) == 0x7c00u) {
            return vdsh_failf(err, VDSH_ERR_INVALID,
                              "cpca: cluster %u's mean coefficient %u, %g, does not fit f16", c, i,
                              (double)m);
        }
        f->means[(size_t)c * n + i] = h;
        mu[i] = vdsh_f32_from_f16(h);
    }
    metric_gram_members(f->md, normals, labels, rows, c, members, frac, g, f->lm);
    if (!cholesky(g, n, l)) {
        return vdsh_failf(err, VDSH_ERR_INVALID, "cpca: cluster %u: metric not positive definite",
                          c);
    }
    /* scatter of the deviations from the stored mean (lower half) */
    memset(sc, 0, sizeof(double) * n * n);
    for (uint32_t v = 0; v < rows; v++) {
        if (labels[v] != c)
            continue;
        const float *x = src + (size_t)v * n;
        for (uint32_t a = 0; a < n; a++) {
            double da = x[a] - mu[a];
            double *row = sc + (size_t)a * n;
            for (uint32_t e = 0; e <= a; e++)
                row[e] += da * (x[e] - mu[e]);
        }
    }
    for (uint32_t a = 0; a < n; a++)
        for (uint32_t e = 0; e < a; e++)
            sc[(size_t)e * n + a] = sc[(size_t)a * n + e];
    /* in the metric: y = L^T c, so sy = L^T sc L */
    for (uint32_t a = 0; a < n; a++) /* tmp = sc L */
        for (uint32_t e = 0; e < n; e++) {
            double s = 0.0;
            for (uint32_t q = e; q < n; q++)
                s += sc[(size_t)a * n + q] * l[(size_t)q * n + e];
            tmp[(size_t)a * n + e] = s;
        }
    for (uint32_t a = 0; a < n; a++) /* sy = L^T tmp */
        for (uint32_t e = 0; e < n; e++) {
            double s = 0.0;
            for (uint32_t q = a; q < n; q++)
                s += l[(size_t)q * n + a] * tmp[(size_t)q * n + e];
            sy[(size_t)a * n + e] = s;
        }
    for (uint32_t a = 0; a < n; a++) /* symmetric to the bit */
        for (uint32_t e = 0; e < a; e++)
            sy[(size_t)e * n + a] = sy[(size_t)a * n + e];
    jacobi(sy, n, ev);
    /* eigenvalues descending, ties by index */
    for (uint32_t i = 0; i < n; i++) {
        uint32_t at = i;
        while (at > 0 && sy[(size_t)idx[at - 1] * n + idx[at - 1]] < sy[(size_t)i * n + i]) {
            idx[at] = idx[at - 1];
            at--;
        }
        idx[at] = i;
    }
    for (uint32_t j = 0; j < b; j++) {
        uint32_t col = idx[j];
        /* projection p = L u; basis vector L^-T u (back substitution) */
        double *p = proj + (size_t)j * n;
        for (uint32_t a = 0; a < n; a++) {
            double s = 0.0;
            for (uint32_t q = 0; q <= a; q++)
                s += l[(size_t)a * n + q] * ev[(size_t)q * n + col];
            p[a] = s;
        }
        double *bv = tmp; /* L^T bv = u */
        for (uint32_t a = n; a-- > 0;) {
            double s = ev[(size_t)a * n + col];
            for (uint32_t q = a + 1; q < n; q++)
                s -= l[(size_t)q * n + a] * bv[q];
            bv[a] = s / l[(size_t)a * n + a];
        }
        for (uint32_t a = 0; a < n; a++) {
            uint16_t h = vdsh_f16_from_f32((float)bv[a]);
            if ((h & 0x7c00u) == 0x7c00u) {
                return vdsh_failf(err, VDSH_ERR_INVALID,
                                  "cpca: cluster %u basis vector %u does not fit f16", c, j);
            }
            f->bases[((size_t)c * b + j) * n + a] = h;
        }
    }
    return VDSH_OK;
}

/* ---- refinement (CPCA; Sloan et al. 2003) ---- */

typedef struct refine_ctx {
    metric_dirs rd; /* a coarser cube of directions than the fit's */
    double *mval;   /* k x count: each cluster's mean at each direction */
    double *bval;   /* k x count x b: its basis vectors at each direction */
    double *xval;   /* count: the vertex's function */
    double *w;      /* b */
    uint32_t *hemi; /* count: the directions in the vertex's hemisphere */
    uint32_t *next; /* rows: the new labels */
    double *dw;     /* count: the light-density weights of the vertex's directions, or NULL */
} refine_ctx;

/* r's scratch for one vertex at a time (xval, w for b vectors, hemi, and
 * dw with the light-density metric) over r->rd's directions: 1, or 0 out
 * of memory (free it with refine_scratch_free either way). */
static int refine_scratch(refine_ctx *r, uint32_t b, int dw)
{
    const uint32_t count = r->rd.count;
    r->xval = malloc(sizeof(double) * count);
    r->w = malloc(sizeof(double) * b);
    r->hemi = malloc(sizeof(uint32_t) * count);
    r->dw = dw ? malloc(sizeof(double) * count) : NULL;
    return r->xval && r->w && r->hemi && (!dw || r->dw);
}

static void refine_scratch_free(refine_ctx *r)
{
    free(r->xval);
    free(r->w);
    free(r->hemi);
    free(r->dw);
}

/* dw: the light-density metric's weights too. */
static int refine_init(refine_ctx *r, uint32_t order, uint32_t k, uint32_t b, uint32_t rows, int dw)
{
    memset(r, 0, sizeof *r);
    if (!metric_init(&r->rd, order, REFINE_CUBE_N))
        return 0;
    uint32_t count = r->rd.count;
    r->mval = malloc(sizeof(double) * k * count);
    r->bval = malloc(sizeof(double) * k * count * b);
    r->next = malloc(sizeof(uint32_t) * rows);
    return refine_scratch(r, b, dw) && r->mval && r->bval && r->next;
}

static void refine_free(refine_ctx *r)
{
    metric_free(&r->rd);
    free(r->mval);
    free(r->bval);
    free(r->next);
    refine_scratch_free(r);
}

/* The squared error of a vertex's reconstruction by cluster c with the
 * weights r->w over the vertex's own hemisphere: the nh directions in
 * r->hemi, its values there in r->xval (vertex_hemisphere). */
static double hemi_error(const fit_ctx *f, const refine_ctx *r, uint32_t c, uint32_t nh)
{
    const uint32_t b = f->b, count = r->rd.count;
    const double *mv = r->mval + (size_t)c * count, *bv = r->bval + (size_t)c * count * b;
    double e = 0.0;
    for (uint32_t h = 0; h < nh; h++) {
        uint32_t d = r->hemi[h];
        double s = r->xval[d] - mv[d];
        const double *bd = bv + (size_t)d * b;
        for (uint32_t j = 0; j < b; j++)
            s -= r->w[j] * bd[j];
        e += r->dw ? r->dw[d] * s * s : s * s;
    }
    return e;
}

/* hemi_error of vertex x by cluster c, the weights the fit's projections
 * (unquantised). */
static double refine_error(const fit_ctx *f, refine_ctx *r, uint32_t c, const float *x, uint32_t nh)
{
    const uint32_t n = f->n, b = f->b;
    const double *mu = f->mus + (size_t)c * n, *proj = f->proj + (size_t)c * b * n;
    for (uint32_t j = 0; j < b; j++)
        r->w[j] = weight_of(x, mu, proj + (size_t)j * n, n);
    return hemi_error(f, r, c, nh);
}

/* Each fitted cluster's stored mean and basis at r's directions. */
static void cluster_values(const fit_ctx *f, refine_ctx *r)
{
    const uint32_t n = f->n, b = f->b, k = f->k, count = r->rd.count;
    for (uint32_t c = 0; c < k; c++) {
        if (!f->members[c])
            continue;
        const double *mu = f->mus + (size_t)c * n;
        for (uint32_t d = 0; d < count; d++) {
            const double *y = r->rd.wy + (size_t)d * n;
            double s = 0.0;
            for (uint32_t a = 0; a < n; a++)
                s += y[a] * mu[a];
            r->mval[(size_t)c * count + d] = s;
            for (uint32_t j = 0; j < b; j++) {
                const uint16_t *bj = f->bases + ((size_t)c * b + j) * n;
                double t = 0.0;
                for (uint32_t a = 0; a < n; a++)
                    t += y[a] * (double)vdsh_f32_from_f16(bj[a]);
                r->bval[((size_t)c * count + d) * b + j] = t;
            }
        }
    }
}

/* Vertex v's hemisphere of r's directions (r->hemi) and its function's
 * values there (r->xval): the count of directions. */
static uint32_t vertex_hemisphere(const fit_ctx *f, refine_ctx *r, uint32_t v)
{
    const uint32_t n = f->n, count = r->rd.count;
    const float *x = f->src + (size_t)v * n, *nv = f->normals + 3 * (size_t)v;
    uint32_t nh = 0;
    for (uint32_t d = 0; d < count; d++) {
        const double *dd = r->rd.dir + 3 * (size_t)d;
        if (!(dd[0] * nv[0] + dd[1] * nv[1] + dd[2] * nv[2] > 0.0))
            continue;
        r->hemi[nh++] = d;
        const double *y = r->rd.wy + (size_t)d * n;
        double s = 0.0;
        for (uint32_t a = 0; a < n; a++)
            s += y[a] * (double)x[a];
        r->xval[d] = s;
    }
    if (r->dw) { /* (1 - a) uniform + a light density */
        const lightmix *lm = f->lm;
        const uint16_t *tex;
        const float *wt;
        double sum;
        uint32_t t = light_texels(lm, v, nv, &tex, &wt, &sum);
        if (!(sum > 0.0))
            t = 0;
        for (uint32_t h = 0; h < nh; h++)
            r->dw[r->hemi[h]] = t ? 1.0 - lm->a : 1.0;
        for (uint32_t i = 0; i < t; i++) {
            const uint32_t d =
                lm->ref[tex[i] & FIT_TEXEL] + (tex[i] >> 15) * REFINE_CUBE_N + (tex[i] >> 14 & 1u);
            const double *dd = r->rd.dir + 3 * (size_t)d;
            const double wi = wt ? (double)wt[i] : 1.0;
            if (dd[0] * nv[0] + dd[1] * nv[1] + dd[2] * nv[2] > 0.0)
                r->dw[d] += lm->a * TWO_PI * wi / (sum * r->rd.w[d]);
        }
    }
    return nh;
}

enum { MAX_WORKERS = 64 };

/* The CPUs settings' threads stand for (0: one per CPU online), 1 ..
 * MAX_WORKERS. */
static uint32_t thread_budget(uint32_t threads)
{
    long cpus = threads ? (long)threads : sysconf(_SC_NPROCESSORS_ONLN);
    return cpus < 1 ? 1u : cpus > MAX_WORKERS ? (uint32_t)MAX_WORKERS : (uint32_t)cpus;
}

/* fn on each of n workers (items of `size` bytes from items, n at most
 * MAX_WORKERS): worker 0 on this thread, the others on threads of their
 * own; one whose thread cannot start runs here too. */
static void run_workers(void *items, size_t size, uint32_t n, void *(*fn)(void *))
{
    pthread_t tid[MAX_WORKERS];
    int started[MAX_WORKERS] = {0};
    for (uint32_t i = 1; i < n; i++)
        started[i] = pthread_create(&tid[i], NULL, fn, (char *)items + i * size) == 0;
    for (uint32_t i = 0; i < n; i++)
        if (!started[i])
            fn((char *)items + i * size);
    for (uint32_t i = 1; i < n; i++)
        if (started[i])
            pthread_join(tid[i], NULL);
}

/* ---- one fit on threads ----
 *
 * fit_all's clusters and reassign's vertices are independent: worker w of
 * W takes the items w, w + W, ..., each item's output its own (a
 * cluster's mean, basis and projections; a vertex's new label), so the
 * bytes are the same on any number of threads. Worker 0 is the caller's
 * context; the others copies with scratch of their own (and their own
 * view of the light texels, whose rows past the cache are found into
 * scratch). */
typedef struct fit_worker {
    fit_ctx f;
    refine_ctx r;
    lightmix view;
    uint32_t index, workers, moved;
    vdsh_result *res; /* fit_all: per cluster */
    vdsh_error *errs;
} fit_worker;

static void fit_workers_free(fit_worker *w, uint32_t workers)
{
    for (uint32_t i = 1; w && i < workers; i++) {
        fit_ctx_scratch_free(&w[i].f);
        refine_scratch_free(&w[i].r);
        lightmix_free(&w[i].view);
    }
    free(w);
}

/* The workers for f's clusters (jobs k) or, with r, its rows: at most
 * f->threads (0: one per CPU online) and jobs; *workers set; NULL out of
 * memory. */
static fit_worker *fit_workers(fit_ctx *f, refine_ctx *r, uint32_t jobs, uint32_t *workers)
{
    const uint32_t cpus = thread_budget(f->threads);
    const uint32_t nw = jobs < 1 ? 1u : cpus < jobs ? cpus : jobs;
    fit_worker *w = calloc(nw, sizeof *w);
    *workers = nw;
    if (!w)
        return NULL;
    int ok = 1;
    for (uint32_t i = 0; i < nw; i++) {
        w[i].f = *f;
        w[i].index = i;
        w[i].workers = nw;
        if (r)
            w[i].r = *r;
        if (i == 0)
            continue;
        fit_ctx *c = &w[i].f;
        c->l = c->g = c->sc = c->sy = c->ev = c->tmp = c->frac = NULL;
        c->idx = NULL;
        w[i].r.xval = w[i].r.w = w[i].r.dw = NULL;
        w[i].r.hemi = NULL;
        if (!ok)
            continue;
        ok = r ? refine_scratch(&w[i].r, f->b, r->dw != NULL) : fit_ctx_scratch(c);
        if (ok && f->lm) {
            ok = lightmix_view(f->lm, &w[i].view);
            c->lm = &w[i].view;
        }
    }
    if (!ok) {
        fit_workers_free(w, nw);
        return NULL;
    }
    return w;
}

static void *fit_clusters_run(void *arg)
{
    fit_worker *w = arg;
    for (uint32_t c = w->index; c < w->f.k; c += w->workers)
        w->res[c] = fit_cluster(&w->f, c, &w->errs[c]);
    return NULL;
}

/* Every cluster's fit (fit_cluster); the first cluster's error that
 * failed. */
static vdsh_result fit_all(fit_ctx *f, vdsh_error *err)
{
    const uint32_t k = f->k;
    uint32_t workers;
    vdsh_result *res = malloc(sizeof *res * k);
    vdsh_error *errs = malloc(sizeof *errs * k);
    fit_worker *w = res && errs ? fit_workers(f, NULL, k, &workers) : NULL;
    vdsh_result r = VDSH_OK;
    if (!w) {
        r = vdsh_failf(err, VDSH_ERR_OUT_OF_MEMORY, "cpca: out of memory for the fit's threads");
    } else {
        for (uint32_t i = 0; i < workers; i++) {
            w[i].res = res;
            w[i].errs = errs;
        }
        run_workers(w, sizeof *w, workers, fit_clusters_run);
        for (uint32_t c = 0; c < k && r == VDSH_OK; c++)
            if ((r = res[c]) != VDSH_OK && err)
                *err = errs[c];
        fit_workers_free(w, workers);
    }
    free(res);
    free(errs);
    return r;
}

static void *reassign_run(void *arg)
{
    fit_worker *w = arg;
    const fit_ctx *f = &w->f;
    refine_ctx *r = &w->r;
    const uint32_t n = f->n, k = f->k;
    for (uint32_t v = w->index; v < f->rows; v += w->workers) {
        const float *x = f->src + (size_t)v * n;
        uint32_t nh = vertex_hemisphere(f, r, v);
        uint32_t best = f->labels[v];
        double be = refine_error(f, r, best, x, nh);
        for (uint32_t c = 0; c < k; c++) {
            if (c == f->labels[v] || !f->members[c])
                continue;
            double e = refine_error(f, r, c, x, nh);
            if (e < be || (e == be && c < best)) {
                be = e;
                best = c;
            }
        }
        r->next[v] = best;
        w->moved += best != f->labels[v];
    }
    return NULL;
}

/* One round of reassignment: *moved, the number of vertices that moved. */
static vdsh_result reassign(fit_ctx *f, refine_ctx *r, uint32_t *moved, vdsh_error *err)
{
    cluster_values(f, r);
    uint32_t workers;
    *moved = 0;
    fit_worker *w = fit_workers(f, r, f->rows, &workers);
    if (!w)
        return vdsh_failf(err, VDSH_ERR_OUT_OF_MEMORY, "cpca: out of memory for the fit's threads");
    run_workers(w, sizeof *w, workers, reassign_run);
    for (uint32_t i = 0; i < workers; i++)
        *moved += w[i].moved;
    fit_workers_free(w, workers);
    memcpy(f->labels, r->next, sizeof(uint32_t) * f->rows);
    return VDSH_OK;
}

/* The stored fit's error: the sum over vertices of hemi_error by their
 * own cluster with the weights their records decode to (quantised), the
 * same directions as the refinement's. */
static double stored_error(const fit_ctx *f, refine_ctx *r, const float *scales,
                           const uint32_t *records, uint32_t bits, uint32_t words)
{
    const uint32_t b = f->b;
    cluster_values(f, r);
    double e = 0.0;
    for (uint32_t v = 0; v < f->rows; v++) {
        uint32_t nh = vertex_hemisphere(f, r, v), c = f->labels[v];
        const uint32_t *rec = records + (size_t)v * words;
        for (uint32_t j = 0; j < b; j++)
            r->w[j] = (double)vdsh_cpca_record_level(rec, bits, j) *
                      (double)vdsh_cpca_step(scales[(size_t)c * b + j], bits);
        e += hemi_error(f, r, c, nh);
    }
    return e;
}

/* ---- the fit ---- */

/* Candidate scales of a basis vector: its largest |weight| times 1,
 * 0.95, ..., 0.35, rounded to f32 as stored. */
enum { SCALE_CANDIDATES = 14 };
static double candidate_scale(double wmax, uint32_t t)
{
    return (double)(float)(wmax * (1.0 - 0.05 * t));
}

/* The stored level of weight w with scale s (> 0): round(L w / s), ties
 * away from 0, clamped to +-L. */
static double quantise(double w, double s, int levels)
{
    if (!(s > 0.0))
        return 0.0;
    double q = round((double)levels * w / s);
    return q > levels ? levels : q < -levels ? -levels : q;
}

/* The scale, of candidate_scale's for wmax (the weights' largest |w|),
 * whose quantisation at `levels` leaves the least squared error over the
 * count weights w[idx[i] * stride], the first of equals; *err that error.
 * Where no candidate is > 0: 0, and *err = none. */
static float least_error_scale(const double *w, size_t stride, const uint32_t *idx, uint32_t count,
                               double wmax, int levels, double none, double *err)
{
    float best = 0.0f;
    *err = none;
    for (uint32_t t = 0; t < SCALE_CANDIDATES; t++) {
        double sc = candidate_scale(wmax, t), e = 0.0;
        if (!(sc > 0.0))
            break;
        double step = (double)((float)sc / (float)levels);
        for (uint32_t i = 0; i < count; i++) {
            double x = w[(size_t)idx[i] * stride];
            double d = x - quantise(x, sc, levels) * step;
            e += d * d;
        }
        if (t == 0 || e < *err) {
            *err = e;
            best = (float)sc;
        }
    }
    return best;
}

/* ---- the scratch both encoders fit with ---- */

/* The fit's context and everything it points at, the metric's and the
 * refinement's directions, and cluster_and_fit's scratch: one owner, freed
 * by fit_scratch_free (also half-built). Not moved once allocated (fc
 * points at md). */
typedef struct fit_scratch {
    fit_ctx fc;
    lightmix lm; /* the light-density metric's */
    metric_dirs md;
    refine_ctx rd;  /* allocated only with need_rd */
    double *mu;     /* n */
    double *dist;   /* rows */
    double *cent;   /* k x (n + 3) */
    uint32_t start; /* the settings' k-means start */
} fit_scratch;

static void fit_scratch_free(fit_scratch *s)
{
    fit_ctx *f = &s->fc;
    free(f->labels);
    free(f->means);
    free(f->bases);
    free(f->members);
    free(f->mus);
    free(f->proj);
    fit_ctx_scratch_free(f);
    metric_free(&s->md);
    refine_free(&s->rd);
    free(s->mu);
    free(s->dist);
    free(s->cent);
    lightmix_free(&s->lm);
    memset(s, 0, sizeof *s);
}

/* Scratch for k clusters of b vectors (fc.b), with room for the bases and
 * projections of fit_basis >= b vectors; the refinement's directions only
 * with need_rd; the light-density metric's rows found for it, or the
 * caller's (shared: encode_auto's candidates share one). 0 when out of
 * memory: free it with fit_scratch_free. */
static int fit_scratch_alloc(fit_scratch *s, const float *src, const float *normals, uint32_t rows,
                             uint32_t order, uint32_t k, uint32_t b, uint32_t fit_basis,
                             int need_rd, const vdsh_cpca_settings *light, const lightmix *shared)
{
    memset(s, 0, sizeof *s);
    const uint32_t n = order * order, bf = fit_basis;
    s->start = light ? light->start : 0;
    fit_ctx *f = &s->fc;
    *f = (fit_ctx){.src = src,
                   .normals = normals,
                   .rows = rows,
                   .n = n,
                   .k = k,
                   .b = b,
                   .md = &s->md,
                   .labels = malloc(sizeof(uint32_t) * rows),
                   .means = malloc(sizeof(uint16_t) * k * n),
                   .bases = malloc(sizeof(uint16_t) * k * bf * n),
                   .members = malloc(sizeof(uint32_t) * k),
                   .mus = malloc(sizeof(double) * k * n),
                   .proj = malloc(sizeof(double) * k * n * bf),
                   .threads = light ? light->threads : 0};
    const int scratch = fit_ctx_scratch(f);
    s->mu = malloc(sizeof(double) * n);
    s->dist = malloc(sizeof(double) * rows);
    s->cent = malloc(sizeof(double) * k * (n + 3));
    const int lm = shared ? 1 : lightmix_load(&s->lm, light, src, order, normals, rows);
    if (lm < 0)
        return 0;
    f->lm = shared ? shared : lm ? &s->lm : NULL;
    if (need_rd && !refine_init(&s->rd, order, k, b, rows, lm))
        return 0;
    return scratch && f->labels && f->means && f->bases && f->members && f->mus && f->proj &&
           s->mu && s->dist && s->cent && metric_init(&s->md, order, CUBE_N);
}

/* Clusters by k-means on the coefficients plus the normals (weighted by
 * NORMAL_WEIGHT times the coefficients' spread, sqrt of the mean over rows
 * of |c - mean c|^2), fits every cluster, then up to `rounds` rounds of
 * reassignment and fitting again (no vertex moved: the fit is the last
 * one's); rounds > 0 needs s's refinement directions. */
static vdsh_result cluster_and_fit(fit_scratch *s, uint32_t rounds, vdsh_error *err)
{
    fit_ctx *f = &s->fc;
    const float *src = f->src;
    const uint32_t n = f->n, rows = f->rows;
    double *mu = s->mu;
    for (uint32_t i = 0; i < n; i++)
        mu[i] = 0.0;
    for (uint32_t v = 0; v < rows; v++)
        for (uint32_t i = 0; i < n; i++)
            mu[i] += src[(size_t)v * n + i];
    for (uint32_t i = 0; i < n; i++)
        mu[i] /= rows;
    double spread = 0.0;
    for (uint32_t v = 0; v < rows; v++)
        for (uint32_t i = 0; i < n; i++) {
            double e = src[(size_t)v * n + i] - mu[i];
            spread += e * e;
        }
    spread = sqrt(spread / rows);
    kmeans(src, f->normals, rows, n, NORMAL_WEIGHT * spread, f->k, s->start, f->labels, s->dist,
           s->cent);
    vdsh_result res = fit_all(f, err);
    for (uint32_t round = 0; res == VDSH_OK && round < rounds; round++) {
        uint32_t moved;
        res = reassign(f, &s->rd, &moved, err);
        if (res != VDSH_OK || !moved)
            break;
        res = fit_all(f, err);
    }
    return res;
}

/* fit as a stream of `order`, for vdsh_stream_decode. */
static vdsh_stream fit_stream(const vdsh_cpca_fit *fit, uint32_t order)
{
    return (vdsh_stream){.order = order,
                         .encoding = VDSH_ENCODING_CPCA,
                         .scale = 1.0f,
                         .data = fit->records,
                         .cpca = fit->model};
}

/* The RMS error of fit's stream against src (rows x order^2), decoded as
 * every reader decodes. */
static double decode_rms(const vdsh_cpca_fit *fit, const float *src, uint32_t rows, uint32_t order)
{
    const uint32_t n = order * order;
    const vdsh_stream s = fit_stream(fit, order);
    float dec[VDSH_MAX_COEFFS];
    double e2 = 0.0;
    for (uint32_t v = 0; v < rows; v++) {
        vdsh_stream_decode(&s, v, dec);
        for (uint32_t i = 0; i < n; i++) {
            double e = (double)dec[i] - src[(size_t)v * n + i];
            e2 += e * e;
        }
    }
    return sqrt(e2 / rows);
}

/* One fit with fixed settings (checked; the sources finite); *proxy (may
 * be NULL) the stored fit's hemisphere error (stored_error). */
static vdsh_result encode_fixed(const float *src, const float *normals, uint32_t rows,
                                uint32_t order, const vdsh_cpca_settings *settings,
                                const lightmix *shared, vdsh_cpca_fit *out, double *proxy,
                                vdsh_error *err)
{
    memset(out, 0, sizeof *out);
    const uint32_t n = order * order;
    const uint32_t k = settings->clusters < rows ? settings->clusters : rows;
    const uint32_t b = settings->basis < n ? settings->basis : n;
    const uint32_t bits = settings->bits;
    const uint32_t words = vdsh_cpca_record_words(b, bits);

    /* one block: scales, means, bases, records */
    size_t o_means = ((size_t)k * b * 4 + 15) & ~(size_t)15;
    size_t o_bases = o_means + (((size_t)k * n * 2 + 15) & ~(size_t)15);
    size_t o_rec = o_bases + (((size_t)k * b * n * 2 + 15) & ~(size_t)15);
    size_t total = o_rec + (size_t)rows * words * 4;
    uint8_t *block = calloc(1, total);
    double *wmax = malloc(sizeof(double) * b);
    double *cerr = malloc(sizeof(double) * b * SCALE_CANDIDATES);
    fit_scratch fs;
    const uint32_t rounds = k > 1 ? REFINE_ROUNDS : 0;
    vdsh_result res = VDSH_OK;
    if (!fit_scratch_alloc(&fs, src, normals, rows, order, k, b, b, rounds || proxy, settings,
                           shared) ||
        !block || !wmax || !cerr) {
        res = vdsh_failf(err, VDSH_ERR_OUT_OF_MEMORY, "cpca: out of memory (%zu bytes)", total);
        goto done;
    }
    fit_ctx *fc = &fs.fc;
    float *scales = (float *)block;
    uint16_t *means = (uint16_t *)(block + o_means);
    uint16_t *bases = (uint16_t *)(block + o_bases);
    uint32_t *records = (uint32_t *)(block + o_rec);
    const uint32_t *labels = fc->labels;
    const double *mus = fc->mus, *proj = fc->proj;

    res = cluster_and_fit(&fs, rounds, err);
    if (res != VDSH_OK)
        goto done;
    memcpy(means, fc->means, sizeof(uint16_t) * k * n);
    memcpy(bases, fc->bases, sizeof(uint16_t) * k * b * n);

    const int levels = vdsh_cpca_levels(bits);
    for (uint32_t c = 0; c < k; c++) {
        if (!fc->members[c])
            continue; /* mean, basis and scales 0; no vertex refers to it */
        const double *cmu = mus + (size_t)c * n, *cproj = proj + (size_t)c * b * n;
        /* weights, in three passes: the largest |weight| per vector; the
         * squared quantisation error of each candidate scale (the largest
         * times 1, 0.95, ..., 0.35: clipping the few largest weights buys
         * a finer step for all the others); the levels with the best. The
         * weights are coordinates of an orthonormal basis of the metric,
         * so this error is the metric's. */
        for (uint32_t j = 0; j < b; j++)
            wmax[j] = 0.0;
        memset(cerr, 0, sizeof(double) * b * SCALE_CANDIDATES);
        for (int pass = 0; pass < 3; pass++) {
            for (uint32_t v = 0; v < rows; v++) {
                if (labels[v] != c)
                    continue;
                const float *x = src + (size_t)v * n;
                uint32_t *rec = records + (size_t)v * words;
                if (pass == 2)
                    rec[0] = c;
                for (uint32_t j = 0; j < b; j++) {
                    double w = weight_of(x, cmu, cproj + (size_t)j * n, n);
                    if (pass == 0) {
                        wmax[j] = fabs(w) > wmax[j] ? fabs(w) : wmax[j];
                        continue;
                    }
                    if (pass == 1) {
                        for (uint32_t t = 0; t < SCALE_CANDIDATES; t++) {
                            double s = candidate_scale(wmax[j], t), e = w;
                            if (s > 0.0)
                                e = w -
                                    quantise(w, s, levels) * (double)vdsh_cpca_step((float)s, bits);
                            cerr[(size_t)j * SCALE_CANDIDATES + t] += e * e;
                        }
                        continue;
                    }
                    double q = quantise(w, scales[(size_t)c * b + j], levels);
                    uint32_t word, shift;
                    vdsh_cpca_field(bits, j, &word, &shift);
                    rec[word] |= ((uint32_t)(int32_t)q & ((1u << bits) - 1u)) << shift;
                }
            }
            if (pass == 1)
                for (uint32_t j = 0; j < b; j++) {
                    uint32_t best = 0;
                    for (uint32_t t = 1; t < SCALE_CANDIDATES; t++)
                        if (cerr[(size_t)j * SCALE_CANDIDATES + t] <
                            cerr[(size_t)j * SCALE_CANDIDATES + best])
                            best = t;
                    scales[(size_t)c * b + j] = (float)candidate_scale(wmax[j], best);
                }
        }
    }
    out->model = (vdsh_cpca){.clusters = k,
                             .basis = b,
                             .bits = bits,
                             .record_words = words,
                             .scales = scales,
                             .means = means,
                             .bases = bases};
    out->records = records;
    out->storage_ = block;
    block = NULL;
    out->rms_error = decode_rms(out, src, rows, order);
    if (proxy)
        *proxy = stored_error(fc, &fs.rd, scales, records, bits, words);
done:
    free(block);
    free(wmax);
    free(cerr);
    fit_scratch_free(&fs);
    return res;
}

/* Bytes of a stream of `rows` rows with settings s, the model included. */
static uint64_t fit_bytes(uint32_t rows, uint32_t order, const vdsh_cpca_settings *s)
{
    return (uint64_t)rows * 4 * vdsh_cpca_record_words(s->basis, s->bits) +
           vdsh_cpca_model_bytes(order, s->clusters, s->basis, s->bases_s8);
}

/* The largest basis (at most order^2) whose stream of `rows` rows with
 * s's other settings takes at most limit bytes; 0 when none does. */
static uint32_t largest_basis(uint32_t rows, uint32_t order, const vdsh_cpca_settings *s,
                              uint64_t limit)
{
    vdsh_cpca_settings t = *s;
    for (t.basis = order * order; t.basis >= 1; t.basis--)
        if (fit_bytes(rows, order, &t) <= limit)
            return t.basis;
    return 0;
}

static vdsh_result encode_alloc(const float *src, const float *normals, uint32_t rows,
                                uint32_t order, const vdsh_cpca_settings *settings, uint32_t refit,
                                const lightmix *shared, vdsh_cpca_refit_report *rep,
                                vdsh_cpca_fit *out, vdsh_error *err);

/* auto: the candidates vdsh_cpca.h names, the least stored_error kept. */
static vdsh_result encode_auto(const float *src, const float *normals, uint32_t rows,
                               uint32_t order, const vdsh_cpca_settings *settings,
                               vdsh_cpca_fit *out, vdsh_error *err)
{
    const uint32_t budget = settings->budget;
    static const uint32_t ks[] = {4, 8, 16};
    const uint32_t bits = 4;
    const uint64_t limit = (uint64_t)budget * rows;
    double best_e = 0.0;
    uint32_t last_k = 0;
    int have = 0;
    lightmix shared; /* every candidate's: the rows' light texels found once */
    const int lm = lightmix_load(&shared, settings, src, order, normals, rows);
    if (lm < 0) {
        lightmix_free(&shared);
        return vdsh_failf(err, VDSH_ERR_OUT_OF_MEMORY, "cpca: out of memory for the light texels");
    }
    for (size_t i = 0; i < sizeof ks / sizeof ks[0]; i++) {
        vdsh_cpca_settings st = *settings;
        st.clusters = ks[i] < rows ? ks[i] : rows;
        st.basis = 0;
        st.bits = bits;
        st.budget = 0;
        if (st.clusters == last_k)
            continue; /* capped at rows: the same as the last */
        last_k = st.clusters;
        st.basis = largest_basis(rows, order, &st, limit);
        if (!st.basis)
            continue;
        vdsh_cpca_fit fit;
        double e;
        vdsh_result r =
            encode_fixed(src, normals, rows, order, &st, lm ? &shared : NULL, &fit, &e, err);
        if (r != VDSH_OK) {
            if (have)
                vdsh_cpca_fit_free(out);
            lightmix_free(&shared);
            return r;
        }
        if (!have || e < best_e) {
            if (have)
                vdsh_cpca_fit_free(out);
            *out = fit;
            best_e = e;
            have = 1;
        } else {
            vdsh_cpca_fit_free(&fit);
        }
    }
    lightmix_free(&shared);
    if (!have) {
        vdsh_cpca_settings least = {.clusters = 1, .basis = 1, .bits = bits, .budget = 0};
        return vdsh_failf(err, VDSH_ERR_ARGUMENT,
                          "cpca: auto budget %u byte%s per vertex too small for %u row%s of order "
                          "%u (the least model, 1,1,%u, takes %.1f)",
                          budget, vdsh_s(budget), rows, vdsh_s(rows), order, bits,
                          (double)fit_bytes(rows, order, &least) / rows);
    }
    return VDSH_OK;
}

/* The starts' workers (encode_starts): in each batch worker w fits one
 * start, index, on threads threads, with a view of the shared light
 * texels of its own. */
typedef struct start_worker {
    const float *src, *normals;
    uint32_t rows, order, refit, index;
    uint32_t threads; /* the start's fit's (fit_ctx) */
    const vdsh_cpca_settings *settings;
    lightmix view;
    vdsh_cpca_fit *fits;
    vdsh_result *res;
    vdsh_error *errs;
} start_worker;

static void *start_worker_run(void *arg)
{
    start_worker *w = arg;
    const uint32_t i = w->index;
    vdsh_cpca_settings st = *w->settings;
    st.start = w->settings->start + i;
    st.threads = w->threads;
    w->res[i] = encode_alloc(w->src, w->normals, w->rows, w->order, &st, w->refit, &w->view, NULL,
                             &w->fits[i], &w->errs[i]);
    return NULL;
}

/* K,alloc:BYTES from settings->starts k-means starts (vdsh_cpca.h): the
 * fits start, start + 1, ... (on up to settings->threads threads C, in
 * batches of up to C starts at once, each on C / starts-in-the-batch
 * threads: three starts on two cores fit two on a thread each, then the
 * third on both; each start's bytes its own whatever its threads), all
 * scored in one pass over the settings' pool
 * (vdsh_cpca_pool_score_streams: each pair's SH evaluated once for every
 * start), the fit with the fewest decisions differing from src's kept
 * (the first on a tie). The rows' light texels
 * (and margin weights) are found once for every start. */
static vdsh_result encode_starts(const float *src, const float *normals, uint32_t rows,
                                 uint32_t order, const vdsh_cpca_settings *settings, uint32_t refit,
                                 vdsh_cpca_fit *out, vdsh_error *err)
{
    const uint32_t count = settings->starts;
    vdsh_cpca_fit fits[VDSH_CPCA_MAX_STARTS];
    vdsh_stream streams[VDSH_CPCA_MAX_STARTS];
    vdsh_cpca_pool_scores sc[VDSH_CPCA_MAX_STARTS];
    vdsh_result res[VDSH_CPCA_MAX_STARTS];
    vdsh_error errs[VDSH_CPCA_MAX_STARTS];
    memset(fits, 0, sizeof fits);
    const uint32_t cpus = thread_budget(settings->threads);
    const uint32_t workers = cpus < count ? cpus : count;
    for (uint32_t i = 0; i < count; i++)
        res[i] = VDSH_ERR_OUT_OF_MEMORY;
    lightmix shared = {0};
    start_worker *work = calloc(workers, sizeof *work); /* a view is 16 KB */
    int ok = work && lightmix_load(&shared, settings, src, order, normals, rows) > 0;
    for (uint32_t w = 0; work && w < workers; w++) {
        work[w] = (start_worker){.src = src,
                                 .normals = normals,
                                 .rows = rows,
                                 .order = order,
                                 .refit = refit,
                                 .settings = settings,
                                 .fits = fits,
                                 .res = res,
                                 .errs = errs};
        ok = ok && lightmix_view(&shared, &work[w].view);
    }
    for (uint32_t first = 0, batch; ok && first < count; first += batch) {
        batch = count - first < workers ? count - first : workers;
        for (uint32_t w = 0; w < batch; w++) {
            work[w].index = first + w;
            work[w].threads = cpus / batch;
        }
        run_workers(work, sizeof *work, batch, start_worker_run);
    }
    for (uint32_t w = 0; work && w < workers; w++)
        lightmix_free(&work[w].view);
    free(work);
    lightmix_free(&shared);
    vdsh_result r = VDSH_OK;
    for (uint32_t i = 0; i < count && r == VDSH_OK; i++) {
        r = res[i];
        if (r != VDSH_OK && ok)
            vdsh_failf(err, r, "%s", errs[i].msg);
        streams[i] = fit_stream(&fits[i], order);
    }
    if (!ok)
        r = vdsh_failf(err, VDSH_ERR_OUT_OF_MEMORY, "cpca: out of memory for the light texels");
    if (r == VDSH_OK)
        r = vdsh_cpca_pool_score_streams(src, normals, rows, order, settings, streams, count, sc,
                                         err);
    uint32_t best = 0;
    for (uint32_t i = 1; r == VDSH_OK && i < count; i++)
        if (sc[i].disagree < sc[best].disagree)
            best = i;
    for (uint32_t i = 0; i < count; i++)
        if (r != VDSH_OK || i != best)
            vdsh_cpca_fit_free(&fits[i]);
    if (r == VDSH_OK)
        *out = fits[best];
    return r;
}

vdsh_result vdsh_cpca_encode(const float *src, const float *normals, uint32_t rows, uint32_t order,
                             const vdsh_cpca_settings *settings, vdsh_cpca_fit *out,
                             vdsh_error *err)
{
    memset(out, 0, sizeof *out);
    if (!src || !normals || !settings || rows < 1 || rows > VDSH_MAX_VERTICES || order < 1 ||
        order > VDSH_MAX_ORDER)
        return vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca: bad arguments (rows %u, order %u)", rows,
                          order);
    if (!check_settings(settings, err))
        return VDSH_ERR_ARGUMENT;
    if (settings->bases_s8 && !(settings->budget && settings->clusters))
        return vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca: s8 bases need K,alloc:BYTES");
    const uint32_t n = order * order;
    for (size_t x = 0; x < (size_t)rows * n; x++)
        if (!isfinite(src[x]))
            return vdsh_failf(err, VDSH_ERR_INVALID,
                              "cpca: vertex %zu coefficient %zu is not finite", x / n, x % n);
    if (settings->budget && settings->clusters) {
        /* the rounds study (VDSH_CPCA_REFIT_ROUNDS=R, vdsh_cpca_study.h) */
        const uint32_t r = (uint32_t)study_knob("VDSH_CPCA_REFIT_ROUNDS", 16);
        const uint32_t rounds = r ? r : VDSH_CPCA_REFIT_ROUNDS;
        if (settings->starts < 2 || !lightmix_on(settings))
            return encode_alloc(src, normals, rows, order, settings, rounds, NULL, NULL, out, err);
        return encode_starts(src, normals, rows, order, settings, rounds, out, err);
    }
    if (settings->budget)
        return encode_auto(src, normals, rows, order, settings, out, err);
    return encode_fixed(src, normals, rows, order, settings, NULL, out, NULL, err);
}

vdsh_result vdsh_cpca_encode_stream(const vdsh_stream *src, uint32_t rows, const float *normals,
                                    const vdsh_cpca_settings *settings, vdsh_stream *out,
                                    void **storage, double *rms_error, vdsh_error *err)
{
    if (!src || src->encoding != VDSH_ENCODING_F32 || src->scale != 1.0f ||
        (src->flags & VDSH_STREAM_VARIABLE) || !src->data)
        return vdsh_failf(err, VDSH_ERR_ARGUMENT,
                          "cpca: the source must be a fixed-order f32 stream with scale 1");
    vdsh_cpca_fit fit;
    vdsh_result r =
        vdsh_cpca_encode((const float *)src->data, normals, rows, src->order, settings, &fit, err);
    if (r != VDSH_OK)
        return r;
    *out = *src;
    out->encoding = VDSH_ENCODING_CPCA;
    out->scale = 1.0f;
    out->coef_scales = NULL;
    out->orders = NULL;
    out->offsets = NULL;
    out->data = fit.records;
    out->cpca = fit.model;
    *storage = fit.storage_;
    if (rms_error)
        *rms_error = fit.rms_error;
    return VDSH_OK;
}

void vdsh_cpca_part_record(const vdsh_cpca_settings *st, vdsh_file *f)
{
    f->part.cpca_clusters = st->clusters;
    f->part.cpca_basis = st->budget ? st->budget : st->basis;
    f->part.cpca_bits = !st->budget ? st->bits : st->bases_s8 ? VDSH_CPCA_BASES_S8 : 0;
    f->has_light_pool = st->light_mix > 0.0f && st->light_count && st->lights;
    if (f->has_light_pool)
        f->light_pool = (vdsh_light_pool){.mix = st->light_mix,
                                          .count = st->light_count,
                                          .lights = st->lights,
                                          .margin = st->margin,
                                          .starts = st->starts};
}

vdsh_cpca_settings vdsh_cpca_part_settings(const vdsh_file *f)
{
    const vdsh_part *pt = &f->part;
    vdsh_cpca_settings st = {.clusters = pt->cpca_clusters};
    if (pt->cpca_bits & ~VDSH_CPCA_BASES_S8) {
        st.basis = pt->cpca_basis;
        st.bits = pt->cpca_bits;
    } else {
        st.budget = pt->cpca_basis;
        st.bases_s8 = pt->cpca_bits == VDSH_CPCA_BASES_S8;
    }
    if (f->has_light_pool) {
        st.light_mix = f->light_pool.mix;
        st.light_count = f->light_pool.count;
        st.lights = f->light_pool.lights;
        st.margin = f->light_pool.margin;
        st.starts = f->light_pool.starts;
        st.positions = f->positions;
    }
    return st;
}

/* ---- a width per basis vector (measurement only: vdsh_cpca_study.h) ---- */

enum { NWIDTHS = 8 };
static const uint32_t WIDTH_SET[NWIDTHS] = {0, 2, 3, 4, 5, 6, 7, 8};

/* Greedy marginal allocation of `bits` bits over m vectors: dist[j *
 * NWIDTHS + i] is vector j's squared error at width WIDTH_SET[i]; level[j]
 * the chosen index into WIDTH_SET. */
static void allocate_widths(const double *dist, uint32_t m, uint32_t bits, uint32_t *level)
{
    for (uint32_t j = 0; j < m; j++)
        level[j] = 0;
    uint32_t left = bits;
    for (;;) {
        uint32_t best = m;
        double gain = 0.0;
        for (uint32_t j = 0; j < m; j++) {
            uint32_t i = level[j];
            if (i + 1 >= NWIDTHS)
                continue;
            uint32_t cost = WIDTH_SET[i + 1] - WIDTH_SET[i];
            if (cost > left)
                continue;
            double g = (dist[(size_t)j * NWIDTHS + i] - dist[(size_t)j * NWIDTHS + i + 1]) / cost;
            if (g > gain) {
                best = j;
                gain = g;
            }
        }
        if (best == m)
            break;
        left -= WIDTH_SET[level[best] + 1] - WIDTH_SET[level[best]];
        level[best]++;
    }
}

/* Bytes of the model of k clusters and m vectors (bases f16, or s8 with
 * bases_s8) with a width table. */
static uint64_t widths_model_bytes(uint32_t order, uint32_t k, uint32_t m, uint32_t bases_s8)
{
    return vdsh_cpca_model_bytes(order, k, m, bases_s8) + ((m + 15u) & ~15u);
}

static vdsh_result encode_widths(const float *src, const float *normals, uint32_t rows,
                                 uint32_t order, const vdsh_cpca_settings *settings,
                                 uint32_t fit_basis, double budget, const uint8_t *widths,
                                 float *decoded, vdsh_cpca_widths_fit *out, vdsh_cpca_fit *fit,
                                 uint32_t refit, const lightmix *shared,
                                 vdsh_cpca_refit_report *rep, vdsh_error *err);

vdsh_result vdsh_cpca_encode_widths(const float *src, const float *normals, uint32_t rows,
                                    uint32_t order, const vdsh_cpca_settings *settings,
                                    uint32_t fit_basis, double budget, const uint8_t *widths,
                                    float *decoded, vdsh_cpca_widths_fit *out, vdsh_error *err)
{
    memset(out, 0, sizeof *out);
    if (!decoded || !settings || settings->budget)
        return vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca widths: bad arguments");
    return encode_widths(src, normals, rows, order, settings, fit_basis, budget, widths, decoded,
                         out, NULL, 0, NULL, NULL, err);
}

vdsh_result vdsh_cpca_encode_refit(const float *src, const float *normals, uint32_t rows,
                                   uint32_t order, const vdsh_cpca_settings *settings,
                                   uint32_t rounds, vdsh_cpca_fit *out,
                                   vdsh_cpca_refit_report *report, vdsh_error *err)
{
    if (out)
        memset(out, 0, sizeof *out);
    if (report)
        memset(report, 0, sizeof *report);
    if (!src || !normals || !settings || !out || !settings->budget || !settings->clusters ||
        rows < 1 || rows > VDSH_MAX_VERTICES || order < 1 || order > VDSH_MAX_ORDER)
        return vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca refit: bad arguments");
    if (!check_settings(settings, err))
        return VDSH_ERR_ARGUMENT;
    return encode_alloc(src, normals, rows, order, settings, rounds, NULL, report, out, err);
}

/* --cpca K,alloc:BYTES (settings K and budget): refined with the largest
 * B whose 4-bit records and model fit the budget, widths allocated over
 * min(2B, n) vectors; *out the stream (bits 0, the widths table). */
static vdsh_result encode_alloc(const float *src, const float *normals, uint32_t rows,
                                uint32_t order, const vdsh_cpca_settings *settings, uint32_t refit,
                                const lightmix *shared, vdsh_cpca_refit_report *rep,
                                vdsh_cpca_fit *out, vdsh_error *err)
{
    const uint32_t n = order * order;
    const uint64_t limit = (uint64_t)settings->budget * rows;
    vdsh_cpca_settings st = *settings;
    st.clusters = settings->clusters < rows ? settings->clusters : rows;
    st.basis = 0;
    st.bits = 4;
    st.budget = 0;
    /* K is a most: a model too large for the budget halves it (16, 8, ...,
     * 1), so a small mesh still fits; only one no single cluster fits fails. */
    while (!(st.basis = largest_basis(rows, order, &st, limit)) && st.clusters > 1)
        st.clusters /= 2;
    if (!st.basis)
        return vdsh_failf(err, VDSH_ERR_ARGUMENT,
                          "cpca: alloc budget %u byte%s per vertex too small for %u row%s of order "
                          "%u, even at 1 cluster (give more bytes or fixed K,B,BITS: --cpca "
                          "8,54,4)",
                          settings->budget, vdsh_s(settings->budget), rows, vdsh_s(rows), order);
    uint32_t fb = 2 * st.basis < n ? 2 * st.basis : n;
    vdsh_cpca_widths_fit wf;
    return encode_widths(src, normals, rows, order, &st, fb, (double)settings->budget, NULL, NULL,
                         &wf, out, refit, shared, rep, err);
}

/* ---- the quantisation-aware refit (issue 29; docs/ACCURACY.md
 * "Quantisation-aware refit of the model") ----
 *
 * After the widths and scales are chosen, a cluster's stored mean m and
 * kept basis B are fitted again to its members' dequantised weights q_v
 * (least squares, [m B] = X Q^T (Q Q^T)^-1, Q's columns [1; q_v]: the
 * least error in any metric the members share, so in the cluster's
 * metric_gram_members Gram too), rounded to f16 (the basis to s8 with
 * s8 bases: round_basis); the weights are then
 * the metric projections onto the new (not orthonormal) basis, the
 * scales chosen again, the weights quantised again. A round is kept only
 * when the cluster's error in its metric, decoded as every reader
 * decodes, falls. f64, one thread, members in row order. */

typedef struct refit_ctx {
    const fit_ctx *f;
    uint32_t kb;
    const uint8_t *wd; /* kb widths */
    uint32_t *mem;     /* rows: the cluster's members */
    uint32_t count;    /* members */
    double *g;         /* n x n: the cluster's metric */
    double *a, *la;    /* (kb + 1)^2 */
    double *cx;        /* n x (kb + 1) */
    double *mb, *p;    /* kb x n */
    double *gb, *lb;   /* kb x kb */
    double *bd;        /* kb x n: the candidate basis, decoded */
    double *md;        /* n: the candidate mean, decoded */
    double *nw;        /* rows x kb: the candidate weights */
    uint16_t *nmean;   /* n: the candidate mean, stored */
    float *nbase;      /* kb x n: the candidate basis, its stored values */
    float *nscale;     /* kb */
    double *r;         /* n */
    uint32_t s8;       /* the bases are s8 */
} refit_ctx;

/* The n values x of one basis vector as the stream stores them, into out
 * (each exactly an f16, or with s8 an integer -127..127: x over its
 * largest |value|, times 127, rounded as weights are); 0 when a value does
 * not fit f16. *gain (gain may be NULL): with s8 the vector's step, what
 * the integers are multiplied by to give x (0 for a vector of zeros);
 * else 1. */
static int round_basis(const double *x, uint32_t n, uint32_t s8, float *out, double *gain)
{
    if (!s8) {
        if (gain)
            *gain = 1.0;
        for (uint32_t a = 0; a < n; a++) {
            uint16_t h = vdsh_f16_from_f32((float)x[a]);
            if ((h & 0x7c00u) == 0x7c00u)
                return 0;
            out[a] = vdsh_f32_from_f16(h);
        }
        return 1;
    }
    double big = 0.0;
    for (uint32_t a = 0; a < n; a++)
        big = fabs(x[a]) > big ? fabs(x[a]) : big;
    for (uint32_t a = 0; a < n; a++)
        out[a] = (float)quantise(x[a], big, 127);
    if (gain)
        *gain = big / 127.0;
    return 1;
}

/* The dequantised weight of w (scale s, width bits), as decoders have it. */
static float dequantised(double w, float s, uint32_t bits)
{
    const int levels = vdsh_cpca_levels(bits);
    return (float)quantise(w, (double)s, levels) * vdsh_cpca_step(s, bits);
}

/* The cluster's error in its metric: the sum over its members of r^T G r,
 * r the source less the decoding of (mean, basis, scales, weights w, kb
 * per row). */
static double refit_error(refit_ctx *rc, const uint16_t *mean, const float *basis,
                          const float *scales, const double *w)
{
    const fit_ctx *f = rc->f;
    const uint32_t n = f->n, kb = rc->kb;
    float o[VDSH_MAX_COEFFS], wq[VDSH_MAX_COEFFS];
    double e = 0.0;
    for (uint32_t i = 0; i < rc->count; i++) {
        const uint32_t v = rc->mem[i];
        for (uint32_t a = 0; a < n; a++)
            o[a] = vdsh_f32_from_f16(mean[a]);
        for (uint32_t q = 0; q < kb; q++)
            wq[q] = dequantised(w[(size_t)v * kb + q], scales[q], rc->wd[q]);
        for (uint32_t q = 0; q < kb; q++) {
            const float *bq = basis + (size_t)q * n;
            for (uint32_t a = 0; a < n; a++)
                o[a] = o[a] + wq[q] * bq[a];
        }
        const float *x = f->src + (size_t)v * n;
        for (uint32_t a = 0; a < n; a++)
            rc->r[a] = (double)x[a] - (double)o[a];
        for (uint32_t a = 0; a < n; a++) {
            const double *ga = rc->g + (size_t)a * n;
            double s = 0.0;
            for (uint32_t b = 0; b < n; b++)
                s += ga[b] * rc->r[b];
            e += rc->r[a] * s;
        }
    }
    return e;
}

/* Solve L L^T z = y in place (L lower, m x m). */
static void chol_solve(const double *l, uint32_t m, double *y)
{
    for (uint32_t i = 0; i < m; i++) {
        double s = y[i];
        for (uint32_t q = 0; q < i; q++)
            s -= l[(size_t)i * m + q] * y[q];
        y[i] = s / l[(size_t)i * m + i];
    }
    for (uint32_t i = m; i-- > 0;) {
        double s = y[i];
        for (uint32_t q = i + 1; q < m; q++)
            s -= l[(size_t)q * m + i] * y[q];
        y[i] = s / l[(size_t)i * m + i];
    }
}

/* One round for the cluster whose model is (mean, basis, scales) and
 * weights w: the candidate in rc->nmean, nbase, nscale, nw; 0 when none
 * (a singular system, or a value that does not fit f16). */
static int refit_round(refit_ctx *rc, const uint16_t *mean, const float *basis, const float *scales,
                       const double *w)
{
    const fit_ctx *f = rc->f;
    const uint32_t n = f->n, kb = rc->kb, m = kb + 1;
    double qt[VDSH_MAX_COEFFS + 1];
    /* the normal equations: A = sum qt qt^T, C = sum x qt^T */
    memset(rc->a, 0, sizeof(double) * m * m);
    memset(rc->cx, 0, sizeof(double) * n * m);
    for (uint32_t i = 0; i < rc->count; i++) {
        const uint32_t v = rc->mem[i];
        qt[0] = 1.0;
        for (uint32_t q = 0; q < kb; q++)
            qt[q + 1] = (double)dequantised(w[(size_t)v * kb + q], scales[q], rc->wd[q]);
        for (uint32_t j = 0; j < m; j++) {
            double *aj = rc->a + (size_t)j * m;
            for (uint32_t q = 0; q <= j; q++)
                aj[q] += qt[j] * qt[q];
        }
        const float *x = f->src + (size_t)v * n;
        for (uint32_t a = 0; a < n; a++) {
            double *ca = rc->cx + (size_t)a * m;
            const double xa = x[a];
            for (uint32_t j = 0; j < m; j++)
                ca[j] += xa * qt[j];
        }
    }
    /* a vector no member uses (every level 0) keeps its basis vector and
     * leaves the system (its row and column the identity's) */
    int unused[VDSH_MAX_COEFFS + 1] = {0};
    for (uint32_t j = 1; j < m; j++)
        if (!(rc->a[(size_t)j * m + j] > 0.0)) {
            unused[j] = 1;
            for (uint32_t q = 0; q < m; q++)
                rc->a[(size_t)j * m + q] = rc->a[(size_t)q * m + j] = 0.0;
            rc->a[(size_t)j * m + j] = 1.0;
        }
    for (uint32_t j = 0; j < m; j++)
        for (uint32_t q = 0; q < j; q++)
            rc->a[(size_t)q * m + j] = rc->a[(size_t)j * m + q];
    if (!cholesky(rc->a, m, rc->la))
        return 0;
    for (uint32_t a = 0; a < n; a++) {
        double *z = rc->cx + (size_t)a * m; /* row a of [m B] */
        for (uint32_t j = 1; j < m; j++)
            if (unused[j])
                z[j] = 0.0;
        chol_solve(rc->la, m, z);
    }
    for (uint32_t a = 0; a < n; a++) {
        uint16_t h = vdsh_f16_from_f32((float)rc->cx[(size_t)a * m]);
        if ((h & 0x7c00u) == 0x7c00u)
            return 0;
        rc->nmean[a] = h;
        rc->md[a] = vdsh_f32_from_f16(h);
    }
    for (uint32_t q = 0; q < kb; q++) {
        float *nq = rc->nbase + (size_t)q * n;
        double col[VDSH_MAX_COEFFS];
        for (uint32_t a = 0; a < n; a++)
            col[a] = rc->cx[(size_t)a * m + q + 1];
        if (unused[q + 1])
            memcpy(nq, basis + (size_t)q * n, sizeof(float) * n);
        else if (!round_basis(col, n, rc->s8, nq, NULL))
            return 0;
        for (uint32_t a = 0; a < n; a++)
            rc->bd[(size_t)q * n + a] = nq[a];
    }
    /* the metric projection: w = (B G B^T)^-1 B G (x - m) */
    for (uint32_t q = 0; q < kb; q++) /* mb = B G */
        for (uint32_t a = 0; a < n; a++) {
            const double *bq = rc->bd + (size_t)q * n;
            double s = 0.0;
            for (uint32_t e = 0; e < n; e++)
                s += bq[e] * rc->g[(size_t)e * n + a];
            rc->mb[(size_t)q * n + a] = s;
        }
    for (uint32_t q = 0; q < kb; q++) /* gb = mb B^T (lower half, mirrored) */
        for (uint32_t j = 0; j <= q; j++) {
            double s = 0.0;
            for (uint32_t a = 0; a < n; a++)
                s += rc->mb[(size_t)q * n + a] * rc->bd[(size_t)j * n + a];
            rc->gb[(size_t)q * kb + j] = rc->gb[(size_t)j * kb + q] = s;
        }
    if (!cholesky(rc->gb, kb, rc->lb))
        return 0;
    double col[VDSH_MAX_COEFFS];
    for (uint32_t a = 0; a < n; a++) { /* p = gb^-1 mb, column by column */
        for (uint32_t q = 0; q < kb; q++)
            col[q] = rc->mb[(size_t)q * n + a];
        chol_solve(rc->lb, kb, col);
        for (uint32_t q = 0; q < kb; q++)
            rc->p[(size_t)q * n + a] = col[q];
    }
    for (uint32_t i = 0; i < rc->count; i++) {
        const uint32_t v = rc->mem[i];
        const float *x = f->src + (size_t)v * n;
        for (uint32_t q = 0; q < kb; q++)
            rc->nw[(size_t)v * kb + q] = weight_of(x, rc->md, rc->p + (size_t)q * n, n);
    }
    /* the scales again, as encode_widths chooses them */
    for (uint32_t q = 0; q < kb; q++) {
        double wmax = 0.0, e;
        for (uint32_t i = 0; i < rc->count; i++) {
            double x = fabs(rc->nw[(size_t)rc->mem[i] * kb + q]);
            wmax = x > wmax ? x : wmax;
        }
        rc->nscale[q] = least_error_scale(rc->nw + q, kb, rc->mem, rc->count, wmax,
                                          vdsh_cpca_levels(rc->wd[q]), 0.0, &e);
    }
    return 1;
}

/* Up to `rounds` refit rounds of every cluster of the stream's model
 * (means k x n, bases k x kb x n, scales k x kb, as stored) and the rows'
 * weights w (rows x kb), in place; *before and *after (may be NULL) the
 * clusters' summed metric error before and after. 0 when out of memory. */
static int refit_model(const fit_ctx *f, uint32_t kb, const uint8_t *wd, uint32_t rounds,
                       uint32_t s8, uint16_t *means, float *bases, float *scales, double *w,
                       double *before, double *after, uint32_t *kept)
{
    const uint32_t n = f->n, m = kb + 1, rows = f->rows;
    refit_ctx rc = {.f = f, .kb = kb, .wd = wd, .s8 = s8};
    rc.mem = malloc(sizeof(uint32_t) * rows);
    rc.g = malloc(sizeof(double) * n * n);
    rc.a = malloc(sizeof(double) * m * m);
    rc.la = malloc(sizeof(double) * m * m);
    rc.cx = malloc(sizeof(double) * n * m);
    rc.mb = malloc(sizeof(double) * kb * n);
    rc.p = malloc(sizeof(double) * kb * n);
    rc.gb = malloc(sizeof(double) * kb * kb);
    rc.lb = malloc(sizeof(double) * kb * kb);
    rc.bd = malloc(sizeof(double) * kb * n);
    rc.md = malloc(sizeof(double) * n);
    rc.nw = malloc(sizeof(double) * rows * kb);
    rc.nmean = malloc(sizeof(uint16_t) * n);
    rc.nbase = malloc(sizeof(float) * kb * n);
    rc.nscale = malloc(sizeof(float) * kb);
    rc.r = malloc(sizeof(double) * n);
    double *frac = malloc(sizeof(double) * f->md->count);
    int ok = rc.mem && rc.g && rc.a && rc.la && rc.cx && rc.mb && rc.p && rc.gb && rc.lb && rc.bd &&
             rc.md && rc.nw && rc.nmean && rc.nbase && rc.nscale && rc.r && frac;
    double e0 = 0.0, e1 = 0.0;
    uint32_t nk = 0;
    for (uint32_t c = 0; ok && c < f->k; c++) {
        if (!f->members[c])
            continue;
        rc.count = 0;
        for (uint32_t v = 0; v < rows; v++)
            if (f->labels[v] == c)
                rc.mem[rc.count++] = v;
        metric_gram_members(f->md, f->normals, f->labels, rows, c, rc.count, frac, rc.g, f->lm);
        uint16_t *mc = means + (size_t)c * n;
        float *bc = bases + (size_t)c * kb * n, *sc = scales + (size_t)c * kb;
        double e = refit_error(&rc, mc, bc, sc, w);
        e0 += e;
        for (uint32_t round = 0; round < rounds; round++) {
            if (!refit_round(&rc, mc, bc, sc, w))
                break;
            double en = refit_error(&rc, rc.nmean, rc.nbase, rc.nscale, rc.nw);
            if (!(en < e))
                break;
            e = en;
            nk++;
            memcpy(mc, rc.nmean, sizeof(uint16_t) * n);
            memcpy(bc, rc.nbase, sizeof(float) * kb * n);
            memcpy(sc, rc.nscale, sizeof(float) * kb);
            for (uint32_t i = 0; i < rc.count; i++)
                memcpy(w + (size_t)rc.mem[i] * kb, rc.nw + (size_t)rc.mem[i] * kb,
                       sizeof(double) * kb);
        }
        e1 += e;
    }
    if (before)
        *before = e0;
    if (after)
        *after = e1;
    if (kept)
        *kept = nk;
    free(rc.mem);
    free(rc.g);
    free(rc.a);
    free(rc.la);
    free(rc.cx);
    free(rc.mb);
    free(rc.p);
    free(rc.gb);
    free(rc.lb);
    free(rc.bd);
    free(rc.md);
    free(rc.nw);
    free(rc.nmean);
    free(rc.nbase);
    free(rc.nscale);
    free(rc.r);
    free(frac);
    return ok;
}

static vdsh_result encode_widths(const float *src, const float *normals, uint32_t rows,
                                 uint32_t order, const vdsh_cpca_settings *settings,
                                 uint32_t fit_basis, double budget, const uint8_t *widths,
                                 float *decoded, vdsh_cpca_widths_fit *out, vdsh_cpca_fit *fit,
                                 uint32_t refit, const lightmix *shared,
                                 vdsh_cpca_refit_report *rep, vdsh_error *err)
{
    memset(out, 0, sizeof *out);
    if (fit)
        memset(fit, 0, sizeof *fit);
    const uint32_t n = order * order;
    if (!src || !normals || !settings || rows < 1 || rows > VDSH_MAX_VERTICES || order < 1 ||
        order > VDSH_MAX_ORDER || settings->budget || !(budget >= 0.0) ||
        (budget == 0.0 && !widths))
        return vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca widths: bad arguments (rows %u, order %u)",
                          rows, order);
    if (!check_settings(settings, err))
        return VDSH_ERR_ARGUMENT;
    const uint32_t k = settings->clusters < rows ? settings->clusters : rows;
    const uint32_t b = settings->basis < n ? settings->basis : n;
    if (fit_basis < b || fit_basis > n)
        return vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca widths: fit basis %u out of range %u..%u",
                          fit_basis, b, n);
    if (widths && budget == 0.0)
        for (uint32_t j = 0; j < fit_basis; j++)
            if (widths[j] == 1 || widths[j] > 8)
                return vdsh_failf(err, VDSH_ERR_ARGUMENT,
                                  "cpca widths: vector %u's width %u (0 or 2..8)", j, widths[j]);
    for (size_t x = 0; x < (size_t)rows * n; x++)
        if (!isfinite(src[x]))
            return vdsh_failf(err, VDSH_ERR_INVALID,
                              "cpca: vertex %zu coefficient %zu is not finite", x / n, x % n);
    const uint32_t bf = fit_basis;
    double *wts = malloc(sizeof(double) * rows * bf);          /* each row's weights */
    double *cdist = malloc(sizeof(double) * k * bf * NWIDTHS); /* per cluster */
    float *cscale = malloc(sizeof(float) * k * bf * NWIDTHS);  /* the best scale */
    double *tot = malloc(sizeof(double) * bf * NWIDTHS);       /* over clusters */
    uint32_t *level = malloc(sizeof(uint32_t) * bf), *best_level = malloc(sizeof(uint32_t) * bf);
    uint32_t *mem = malloc(sizeof(uint32_t) * rows); /* one cluster's rows */
    fit_scratch fs;
    const uint32_t rounds = k > 1 ? REFINE_ROUNDS : 0;
    vdsh_result res = VDSH_OK;
    if (!fit_scratch_alloc(&fs, src, normals, rows, order, k, b, bf, rounds, settings, shared) ||
        !wts || !cdist || !cscale || !tot || !level || !best_level || !mem) {
        res = vdsh_failf(err, VDSH_ERR_OUT_OF_MEMORY, "cpca widths: out of memory");
        goto done;
    }
    fit_ctx *fc = &fs.fc;
    const uint32_t *labels = fc->labels, *members = fc->members;
    const uint16_t *means = fc->means, *bases = fc->bases;
    const double *mus = fc->mus, *proj = fc->proj;
    /* k-means, fit and refinement exactly as encode_fixed */
    res = cluster_and_fit(&fs, rounds, err);
    /* the final labels' fit with bf vectors (its first b the same) */
    fc->b = bf;
    if (res == VDSH_OK)
        res = fit_all(fc, err);
    if (res != VDSH_OK)
        goto done;

    /* weights; per cluster, vector and width the least squared error over
     * the candidate scales */
    for (uint32_t v = 0; v < rows; v++) {
        uint32_t c = labels[v];
        for (uint32_t j = 0; j < bf; j++)
            wts[(size_t)v * bf + j] = weight_of(src + (size_t)v * n, mus + (size_t)c * n,
                                                proj + ((size_t)c * bf + j) * n, n);
    }
    memset(cdist, 0, sizeof(double) * k * bf * NWIDTHS);
    memset(cscale, 0, sizeof(float) * k * bf * NWIDTHS);
    for (uint32_t c = 0; c < k; c++) {
        if (!members[c])
            continue;
        uint32_t count = 0;
        for (uint32_t v = 0; v < rows; v++)
            if (labels[v] == c)
                mem[count++] = v;
        for (uint32_t j = 0; j < bf; j++) {
            double wmax = 0.0, e0 = 0.0;
            for (uint32_t i = 0; i < count; i++) {
                double w = wts[(size_t)mem[i] * bf + j];
                wmax = fabs(w) > wmax ? fabs(w) : wmax;
                e0 += w * w;
            }
            double *cd = cdist + ((size_t)c * bf + j) * NWIDTHS;
            float *cs = cscale + ((size_t)c * bf + j) * NWIDTHS;
            cd[0] = e0;
            for (uint32_t i = 1; i < NWIDTHS; i++)
                cs[i] = least_error_scale(wts + j, bf, mem, count, wmax,
                                          (1 << (WIDTH_SET[i] - 1)) - 1, e0, &cd[i]);
        }
    }
    for (uint32_t x = 0; x < bf * NWIDTHS; x++) {
        double s = 0.0;
        for (uint32_t c = 0; c < k; c++)
            s += cdist[(size_t)c * bf * NWIDTHS + x];
        tot[x] = s;
    }

    /* the width table */
    if (budget > 0.0) {
        const double limit = budget * rows;
        double best_e = 0.0;
        int have = 0;
        for (uint32_t words = 1; words <= 64; words++) {
            uint32_t m = 0;
            while (m < bf &&
                   (double)rows * 4.0 * words +
                           (double)widths_model_bytes(order, k, m + 1, settings->bases_s8) <=
                       limit)
                m++;
            if (!m)
                break;
            uint32_t bits = 32 * words - VDSH_CPCA_INDEX_BITS;
            uint8_t wd[VDSH_MAX_COEFFS];
            for (;;) {
                allocate_widths(tot, m, bits, level);
                for (uint32_t j = 0; j < m; j++)
                    wd[j] = (uint8_t)WIDTH_SET[level[j]];
                if (vdsh_cpca_widths_words(wd, m) <= words || !bits)
                    break;
                bits--;
            }
            double e = 0.0;
            for (uint32_t j = 0; j < bf; j++)
                e += tot[(size_t)j * NWIDTHS + (j < m ? level[j] : 0)];
            if (!have || e < best_e) {
                best_e = e;
                have = 1;
                for (uint32_t j = 0; j < bf; j++)
                    best_level[j] = j < m ? level[j] : 0;
            }
        }
        if (!have) {
            res = vdsh_failf(err, VDSH_ERR_ARGUMENT,
                             "cpca widths: %g byte%s per vertex: nothing fits", budget,
                             budget == 1.0 ? "" : "s");
            goto done;
        }
        for (uint32_t j = 0; j < bf; j++)
            out->widths[j] = (uint8_t)WIDTH_SET[best_level[j]];
    } else {
        for (uint32_t j = 0; j < bf; j++) {
            out->widths[j] = widths[j];
            uint32_t i = 0;
            while (WIDTH_SET[i] != widths[j])
                i++;
            best_level[j] = i;
        }
    }
    out->clusters = k;
    out->basis = 0;
    for (uint32_t j = 0; j < bf; j++)
        if (out->widths[j])
            out->basis = j + 1;
    out->words = vdsh_cpca_widths_words(out->widths, bf);
    out->bytes_per_vertex = ((double)rows * 4.0 * out->words +
                             (double)widths_model_bytes(order, k, out->basis, settings->bases_s8)) /
                            rows;

    if (fit) { /* the stream: the vectors of width > 0, in order */
        uint32_t kb = 0, keep[VDSH_MAX_COEFFS];
        for (uint32_t j = 0; j < bf; j++)
            if (best_level[j])
                keep[kb++] = j;
        uint8_t wd[VDSH_MAX_COEFFS];
        for (uint32_t q = 0; q < kb; q++)
            wd[q] = (uint8_t)WIDTH_SET[best_level[keep[q]]];
        const uint32_t words = vdsh_cpca_widths_words(wd, kb), s8 = settings->bases_s8;
        size_t o_sc = ((size_t)kb + 15) & ~(size_t)15;
        size_t o_means = o_sc + (((size_t)k * kb * 4 + 15) & ~(size_t)15);
        size_t o_bases = o_means + (((size_t)k * n * 2 + 15) & ~(size_t)15);
        size_t o_rec = o_bases + (((size_t)k * kb * n * (s8 ? 1 : 2) + 15) & ~(size_t)15);
        uint8_t *block = kb ? calloc(1, o_rec + (size_t)rows * words * 4) : NULL;
        /* the rows' weights on the kept vectors, the kept bases' stored values */
        double *kw = malloc(sizeof(double) * rows * kb + 1);
        float *bv = malloc(sizeof(float) * k * kb * n + 1);
        double *gain = s8 ? malloc(sizeof(double) * k * kb + 1) : NULL; /* s8: each vector's step */
        if (!block || !kw || !bv || (s8 && !gain)) {
            free(block);
            free(kw);
            free(bv);
            free(gain);
            res = vdsh_failf(err, kb ? VDSH_ERR_OUT_OF_MEMORY : VDSH_ERR_ARGUMENT,
                             kb ? "cpca: out of memory" : "cpca: alloc kept no basis vector");
            goto done;
        }
        memcpy(block, wd, kb);
        float *sc_out = (float *)(block + o_sc);
        uint16_t *me_out = (uint16_t *)(block + o_means);
        uint32_t *rec = (uint32_t *)(block + o_rec);
        memcpy(me_out, means, sizeof(uint16_t) * k * n);
        for (uint32_t c = 0; c < k; c++)
            for (uint32_t q = 0; q < kb; q++) {
                uint32_t j = keep[q];
                sc_out[(size_t)c * kb + q] = cscale[((size_t)c * bf + j) * NWIDTHS + best_level[j]];
                for (uint32_t a = 0; a < n; a++)
                    bv[((size_t)c * kb + q) * n + a] =
                        vdsh_f32_from_f16(bases[((size_t)c * bf + j) * n + a]);
            }
        for (uint32_t v = 0; v < rows; v++)
            for (uint32_t q = 0; q < kb; q++)
                kw[(size_t)v * kb + q] = wts[(size_t)v * bf + keep[q]];
        if (s8) { /* each vector to s8, its step (gain) moved into its scale and weights */
            for (size_t x = 0; x < (size_t)k * kb; x++) {
                float *bq = bv + x * n;
                double xs[VDSH_MAX_COEFFS];
                for (uint32_t a = 0; a < n; a++)
                    xs[a] = bq[a];
                round_basis(xs, n, 1, bq, &gain[x]);
                sc_out[x] = (float)(sc_out[x] * gain[x]);
            }
            for (uint32_t v = 0; v < rows; v++)
                for (uint32_t q = 0; q < kb; q++)
                    kw[(size_t)v * kb + q] *= gain[(size_t)labels[v] * kb + q];
        }
        if (rep)
            memset(rep, 0, sizeof *rep);
        free(gain);
        if (refit) {
            double e0, e1;
            uint32_t nk;
            if (!refit_model(fc, kb, wd, refit, s8, me_out, bv, sc_out, kw, &e0, &e1, &nk)) {
                free(kw);
                free(bv);
                free(block);
                res = vdsh_failf(err, VDSH_ERR_OUT_OF_MEMORY, "cpca: out of memory");
                goto done;
            }
            if (rep)
                *rep = (vdsh_cpca_refit_report){
                    .rounds = refit, .kept = nk, .metric_before = e0, .metric_after = e1};
        }
        /* the bases as stored: every value of bv is exactly an f16, or an s8 */
        int8_t *b8_out = s8 ? (int8_t *)(block + o_bases) : NULL;
        uint16_t *ba_out = s8 ? NULL : (uint16_t *)(block + o_bases);
        for (size_t x = 0; x < (size_t)k * kb * n; x++) {
            if (s8)
                b8_out[x] = (int8_t)bv[x];
            else
                ba_out[x] = vdsh_f16_from_f32(bv[x]);
        }
        free(bv);
        fit->model = (vdsh_cpca){.clusters = k,
                                 .basis = kb,
                                 .bits = 0,
                                 .bases_s8 = s8,
                                 .record_words = words,
                                 .widths = block,
                                 .scales = sc_out,
                                 .means = me_out,
                                 .bases = ba_out,
                                 .bases8 = b8_out};
        for (uint32_t v = 0; v < rows; v++) {
            uint32_t *r = rec + (size_t)v * words, c = labels[v];
            r[0] = c;
            for (uint32_t q = 0; q < kb; q++) {
                uint32_t word, shift;
                const int levels = vdsh_cpca_levels(wd[q]);
                double lq = quantise(kw[(size_t)v * kb + q], sc_out[(size_t)c * kb + q], levels);
                vdsh_cpca_model_field(&fit->model, q, &word, &shift);
                r[word] |= ((uint32_t)(int32_t)lq & ((1u << wd[q]) - 1u)) << shift;
            }
        }
        free(kw);
        fit->records = rec;
        fit->storage_ = block;
        fit->rms_error = out->rms_error = decode_rms(fit, src, rows, order);
        goto done;
    }

    /* decode as the format's rule: f32, mean + sum_j weight_j x basis_j */
    double e2 = 0.0;
    for (uint32_t v = 0; v < rows; v++) {
        uint32_t c = labels[v];
        float *o = decoded + (size_t)v * n;
        for (uint32_t i = 0; i < n; i++)
            o[i] = vdsh_f32_from_f16(means[(size_t)c * n + i]);
        for (uint32_t j = 0; j < bf; j++) {
            uint32_t i = best_level[j];
            if (!i)
                continue;
            const int levels = (1 << (WIDTH_SET[i] - 1)) - 1;
            float s = cscale[((size_t)c * bf + j) * NWIDTHS + i];
            float step = s / (float)levels;
            float w = (float)quantise(wts[(size_t)v * bf + j], s, levels) * step;
            const uint16_t *bj = bases + ((size_t)c * bf + j) * n;
            for (uint32_t a = 0; a < n; a++)
                o[a] = o[a] + w * vdsh_f32_from_f16(bj[a]);
        }
        for (uint32_t i = 0; i < n; i++) {
            double e = (double)o[i] - src[(size_t)v * n + i];
            e2 += e * e;
        }
    }
    out->rms_error = sqrt(e2 / rows);
done:
    free(wts);
    free(cdist);
    free(cscale);
    free(tot);
    free(level);
    free(best_level);
    free(mem);
    fit_scratch_free(&fs);
    return res;
}

/* ---- the pool score of a fitted stream (vdsh_cpca_study.h) ---- */

vdsh_result vdsh_cpca_pool_score(const float *src, const float *normals, uint32_t rows,
                                 uint32_t order, const vdsh_cpca_settings *settings,
                                 const vdsh_cpca_fit *fit, vdsh_cpca_pool_scores *out,
                                 vdsh_error *err)
{
    memset(out, 0, sizeof *out);
    if (!fit || order < 1 || order > VDSH_MAX_ORDER)
        return vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca pool score: bad arguments");
    const vdsh_stream s = fit_stream(fit, order);
    return vdsh_cpca_pool_score_streams(src, normals, rows, order, settings, &s, 1, out, err);
}

/* The pairs staged in b for one row (its coefficients x, the streams'
 * decoded rows dec) added to out[0 .. count), in light order; b emptied. */
static void score_batch(sh_batch *b, uint32_t order, const float *x, float (*dec)[VDSH_MAX_COEFFS],
                        uint32_t count, double (*bk)[SH_BATCH], vdsh_cpca_pool_scores *out)
{
    const uint32_t n = order * order;
    sh_batch_eval(b, order);
    sh_batch_dots(b, x, n, b->a);
    for (uint32_t k = 0; k < count; k++)
        sh_batch_dots(b, dec[k], n, bk[k]);
    for (uint32_t j = 0; j < b->count; j++) {
        const double a = b->a[j], t = det_ln(b->r[j]);
        for (uint32_t k = 0; k < count; k++) {
            const double bb = bk[k][j];
            out[k].pairs++;
            out[k].disagree += (a >= t) != (bb >= t);
            out[k].missed += (a >= t) && !(bb >= t);
            out[k].squared += (bb - a) * (bb - a);
        }
    }
    b->count = 0;
}

vdsh_result vdsh_cpca_pool_score_streams(const float *src, const float *normals, uint32_t rows,
                                         uint32_t order, const vdsh_cpca_settings *settings,
                                         const vdsh_stream *s, uint32_t count,
                                         vdsh_cpca_pool_scores *out, vdsh_error *err)
{
    if (out && count <= VDSH_CPCA_MAX_STARTS)
        memset(out, 0, sizeof *out * count);
    if (!src || !normals || !settings || !s || !out || count < 1 || count > VDSH_CPCA_MAX_STARTS ||
        !settings->light_count || !settings->lights || !settings->positions || order < 1 ||
        order > VDSH_MAX_ORDER)
        return vdsh_failf(err, VDSH_ERR_ARGUMENT, "cpca pool score: bad arguments");
    for (uint32_t k = 0; k < count; k++)
        if (s[k].order != order)
            return vdsh_failf(err, VDSH_ERR_ARGUMENT,
                              "cpca pool score: stream %u of order %u, "
                              "not %u",
                              k, s[k].order, order);
    const uint32_t n = order * order;
    float dec[VDSH_CPCA_MAX_STARTS][VDSH_MAX_COEFFS];
    double(*bk)[SH_BATCH] = malloc(sizeof(double) * SH_BATCH * count);
    sh_batch *b = calloc(1, sizeof *b);
    if (!b || !bk) {
        free(b);
        free(bk);
        return vdsh_failf(err, VDSH_ERR_OUT_OF_MEMORY, "cpca pool score: out of memory");
    }
    for (uint32_t v = 0; v < rows; v++) {
        for (uint32_t k = 0; k < count; k++)
            vdsh_stream_decode(&s[k], v, dec[k]);
        const float *x = src + (size_t)v * n, *p = settings->positions + 3 * (size_t)v;
        const float *nv = normals + 3 * (size_t)v;
        for (uint32_t l = 0; l < settings->light_count; l++) {
            const float *q = settings->lights + 3 * (size_t)l;
            double d[3];
            for (int i = 0; i < 3; i++)
                d[i] = (double)q[i] - p[i];
            if (d[0] * nv[0] + d[1] * nv[1] + d[2] * nv[2] > 0.0 && sh_batch_add(b, d))
                score_batch(b, order, x, dec, count, bk, out);
        }
        if (b->count)
            score_batch(b, order, x, dec, count, bk, out);
    }
    free(b);
    free(bk);
    return VDSH_OK;
}
