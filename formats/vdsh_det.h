/* vdsh_det.h - sin, cos, exp, log, atan2 and acos that give the same bits
 * on every x86-64 CPU (internal to the bake and formats).
 *
 * glibc's libm picks its code path by CPU: on one with FMA, cos, sin, exp,
 * log, log10, atan2 and acos (double) come from builds that fuse multiply
 * and add, elsewhere from SSE2 builds, and the two differ in the last bit
 * for about one argument in 1,500 (cos, sin, exp; measured over 2e7
 * arguments, GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX2,-FMA,-AVX against the
 * default on this machine). The float functions (sinf, cosf) round such a
 * difference away except at a rounding boundary, about once in 5e8 calls,
 * which a bake of 1e8 rays can meet. A bake must decide the same on any CPU
 * (tests/test_same_bytes_any_cpu.sh), so what feeds its output uses these:
 * only +, -, *, /, sqrt, floor and ldexp (each correctly rounded or exact),
 * no fused multiply-add (C11 and C++17 modes do not contract, and no target
 * of the bake enables FMA), within 1-4 ulp of libm over every range the
 * bake uses (test det_math_matches_libm).
 *
 * Arguments: sin and cos for |x| < 2^20 (Cody-Waite reduction by pi/2 in
 * three parts, exact there); exp and log over all doubles (overflow to
 * inf and 0, log of 0 is -inf, of a negative or NaN is NaN). */
#ifndef VDSH_DET_H
#define VDSH_DET_H

#include <math.h>

/* pi/2 in three parts: the first two of 33 bits each, so k * part is
 * exact for |k| < 2^20 (fdlibm's pio2_1, pio2_2, pio2_2t) */
#define VDSH_DET_PIO2_1 1.57079632673412561417e+00
#define VDSH_DET_PIO2_2 6.07710050630396597660e-11
#define VDSH_DET_PIO2_3 2.02226624879595063154e-21
#define VDSH_DET_LN2_HI 6.93147180369123816490e-01 /* ln 2, 32 bits ... */
#define VDSH_DET_LN2_LO 1.90821492927058770002e-10 /* ... and the rest */
#define VDSH_DET_PI 3.14159265358979311600e+00
#define VDSH_DET_PI_LO 1.22464679914735317720e-16 /* pi - VDSH_DET_PI */

/* sin r and cos r for |r| <= pi/4 + a little: Taylor series to r^17 and
 * r^18 (the next terms are below 1e-19) */
static inline double vdsh_det_sin_poly(double r)
{
    double z = r * r;
    double p = 1.0 / 355687428096000.0; /* 1/17! */
    p = p * z - 1.0 / 1307674368000.0;
    p = p * z + 1.0 / 6227020800.0;
    p = p * z - 1.0 / 39916800.0;
    p = p * z + 1.0 / 362880.0;
    p = p * z - 1.0 / 5040.0;
    p = p * z + 1.0 / 120.0;
    p = p * z - 1.0 / 6.0;
    return r + r * z * p;
}

static inline double vdsh_det_cos_poly(double r)
{
    double z = r * r;
    double p = -1.0 / 6402373705728000.0; /* -1/18! */
    p = p * z + 1.0 / 20922789888000.0;
    p = p * z - 1.0 / 87178291200.0;
    p = p * z + 1.0 / 479001600.0;
    p = p * z - 1.0 / 3628800.0;
    p = p * z + 1.0 / 40320.0;
    p = p * z - 1.0 / 720.0;
    p = p * z + 1.0 / 24.0;
    /* 1 - z/2 + z^2 p, the 1 added last */
    return 1.0 + (z * z * p - 0.5 * z);
}

/* sin x (which 0) or cos x (which 1) */
static inline double vdsh_det_sincos(double x, int which)
{
    double k = floor(x * (2.0 / VDSH_DET_PI) + 0.5);
    double r = ((x - k * VDSH_DET_PIO2_1) - k * VDSH_DET_PIO2_2) - k * VDSH_DET_PIO2_3;
    long q = ((long)k + which) & 3;
    double v = (q & 1) ? vdsh_det_cos_poly(r) : vdsh_det_sin_poly(r);
    return (q & 2) ? -v : v;
}

static inline double vdsh_det_sin(double x)
{
    return vdsh_det_sincos(x, 0);
}

static inline double vdsh_det_cos(double x)
{
    return vdsh_det_sincos(x, 1);
}

static inline double vdsh_det_exp(double x)
{
    if (!(x < 709.78))
        return x != x ? x : HUGE_VAL;
    if (x < -745.2)
        return 0.0;
    double k = floor(x * 1.44269504088896338700 + 0.5);         /* x / ln 2 */
    double r = (x - k * VDSH_DET_LN2_HI) - k * VDSH_DET_LN2_LO; /* |r| <= 0.35 */
    /* e^r, Taylor to r^14 (the next term is below 1e-19) */
    double p = 1.0 / 87178291200.0; /* 1/14! */
    p = p * r + 1.0 / 6227020800.0;
    p = p * r + 1.0 / 479001600.0;
    p = p * r + 1.0 / 39916800.0;
    p = p * r + 1.0 / 3628800.0;
    p = p * r + 1.0 / 362880.0;
    p = p * r + 1.0 / 40320.0;
    p = p * r + 1.0 / 5040.0;
    p = p * r + 1.0 / 720.0;
    p = p * r + 1.0 / 120.0;
    p = p * r + 1.0 / 24.0;
    p = p * r + 1.0 / 6.0;
    p = p * r + 0.5;
    double e = 1.0 + (r + r * r * p);
    /* ldexp is exact unless the result is subnormal: in two steps there,
     * the same rounding on every CPU (IEEE multiplication) */
    int n = (int)k;
    return n < -1000 ? ldexp(ldexp(e, n + 1000), -1000) : ldexp(e, n);
}

static inline double vdsh_det_log(double x)
{
    if (!(x > 0.0))
        return x == 0.0 ? -HUGE_VAL : (x - x) / (x - x);
    if (x == HUGE_VAL)
        return x;
    int e;
    double m = frexp(x, &e); /* x = m 2^e, m in [0.5, 1) */
    if (m < 0.70710678118654752440) {
        m *= 2.0;
        e--;
    }
    double f = m - 1.0, s = f / (2.0 + f), z = s * s; /* |s| < 0.172 */
    /* ln m = 2 atanh s = 2 (s + s^3/3 + ... + s^25/25): the next term is
     * below 1e-20 */
    double p = 1.0 / 25.0;
    p = p * z + 1.0 / 23.0;
    p = p * z + 1.0 / 21.0;
    p = p * z + 1.0 / 19.0;
    p = p * z + 1.0 / 17.0;
    p = p * z + 1.0 / 15.0;
    p = p * z + 1.0 / 13.0;
    p = p * z + 1.0 / 11.0;
    p = p * z + 1.0 / 9.0;
    p = p * z + 1.0 / 7.0;
    p = p * z + 1.0 / 5.0;
    p = p * z + 1.0 / 3.0;
    double ln_m = 2.0 * s + 2.0 * s * z * p;
    return e * VDSH_DET_LN2_HI + (e * VDSH_DET_LN2_LO + ln_m);
}

/* atan t for 0 <= t <= 1 */
static inline double vdsh_det_atan01(double t)
{
    /* above tan(pi/12), atan t = pi/6 + atan((t sqrt 3 - 1) / (t + sqrt 3)) */
    double base = 0.0;
    if (t > 0.26794919243112270647) {
        t = (t * 1.73205080756887719318 - 1.0) / (t + 1.73205080756887719318);
        base = 0.52359877559829881566; /* pi/6 */
    }
    /* |t| <= tan(pi/12): atan t = t - t^3/3 + ... to t^31 (next below 1e-19) */
    double z = t * t;
    double p = -1.0 / 31.0;
    p = p * z + 1.0 / 29.0;
    p = p * z - 1.0 / 27.0;
    p = p * z + 1.0 / 25.0;
    p = p * z - 1.0 / 23.0;
    p = p * z + 1.0 / 21.0;
    p = p * z - 1.0 / 19.0;
    p = p * z + 1.0 / 17.0;
    p = p * z - 1.0 / 15.0;
    p = p * z + 1.0 / 13.0;
    p = p * z - 1.0 / 11.0;
    p = p * z + 1.0 / 9.0;
    p = p * z - 1.0 / 7.0;
    p = p * z + 1.0 / 5.0;
    p = p * z - 1.0 / 3.0;
    return base + (t + t * z * p);
}

static inline double vdsh_det_atan2(double y, double x)
{
    if (y != y || x != x)
        return x + y;
    double ay = fabs(y), ax = fabs(x), a;
    if (ay == 0.0 && ax == 0.0)
        a = 0.0;
    else if (ay <= ax)
        a = vdsh_det_atan01(ay / ax);
    else /* pi/2 - atan(ax / ay) */
        a = (0.5 * VDSH_DET_PI - vdsh_det_atan01(ax / ay)) + 0.5 * VDSH_DET_PI_LO;
    if (x < 0.0 || (x == 0.0 && signbit(x)))
        a = (VDSH_DET_PI - a) + VDSH_DET_PI_LO;
    return signbit(y) ? -a : a;
}

static inline double vdsh_det_acos(double x)
{
    return vdsh_det_atan2(sqrt((1.0 - x) * (1.0 + x)), x);
}

#endif
