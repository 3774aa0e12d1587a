/*
 * test_det_math.c - formats/vdsh_det.h: sin, cos, exp, log, atan2 and acos
 * that give the same bits on every x86-64 CPU stay within a few ulp of
 * libm over the ranges the bake uses, and handle the edges as libm does.
 * (The same bits on every CPU is tests/test_same_bytes_any_cpu.sh's.)
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "test_util.h"
#include "vdsh_det.h"

static int64_t ulps(double a, double b)
{
    if (a == b)
        return 0;
    if (a != a || b != b)
        return INT64_MAX;
    int64_t x, y;
    memcpy(&x, &a, 8);
    memcpy(&y, &b, 8);
    if (x < 0)
        x = INT64_MIN - x;
    if (y < 0)
        y = INT64_MIN - y;
    return x > y ? x - y : y - x;
}

typedef struct {
    const char *name;
    int64_t worst;
    double at;
} track;

static void see(track *t, double got, double want, double x)
{
    int64_t d = ulps(got, want);
    if (d > t->worst)
        t->worst = d, t->at = x;
}

int main(void)
{
    track ts[6] = {{"sin", 0, 0}, {"cos", 0, 0},   {"exp", 0, 0},
                   {"log", 0, 0}, {"atan2", 0, 0}, {"acos", 0, 0}};
    const int64_t bound[6] = {1, 1, 1, 2, 4, 4};
    uint64_t s = 0x9e3779b97f4a7c15ull;
    for (int i = 0; i < 2000000; i++) {
        double u = test_rand(&s), v = test_rand(&s);
        double x = (2.0 * u - 1.0) * 1000.0; /* angles of the bake: within 2 pi */
        see(&ts[0], vdsh_det_sin(x), sin(x), x);
        see(&ts[1], vdsh_det_cos(x), cos(x), x);
        double xe = (2.0 * u - 1.0) * 700.0;
        see(&ts[2], vdsh_det_exp(xe), exp(xe), xe);
        double xl = exp((2.0 * u - 1.0) * 700.0) * (0.5 + v);
        see(&ts[3], vdsh_det_log(xl), log(xl), xl);
        double ya = (2.0 * u - 1.0) * pow(10.0, 6.0 * v - 3.0), xa = 2.0 * v - 1.0;
        see(&ts[4], vdsh_det_atan2(ya, xa), atan2(ya, xa), ya);
        double xc = 2.0 * u - 1.0;
        see(&ts[5], vdsh_det_acos(xc), acos(xc), xc);
    }
    for (int k = 0; k < 6; k++) {
        printf("%-5s within %lld ulp of libm (worst at %.17g)\n", ts[k].name,
               (long long)ts[k].worst, ts[k].at);
        CHECK(ts[k].worst <= bound[k], "%s: %lld ulp at %.17g, bound %lld", ts[k].name,
              (long long)ts[k].worst, ts[k].at, (long long)bound[k]);
    }

    /* edges, as libm */
    CHECK(vdsh_det_sin(0.0) == 0.0 && vdsh_det_cos(0.0) == 1.0, "sin 0, cos 0");
    CHECK(vdsh_det_exp(0.0) == 1.0 && vdsh_det_log(1.0) == 0.0, "exp 0, log 1");
    CHECK(vdsh_det_exp(710.0) == HUGE_VAL && vdsh_det_exp(-800.0) == 0.0, "exp range");
    CHECK(vdsh_det_exp(-INFINITY) == 0.0 && isnan(vdsh_det_exp(NAN)), "exp -inf, nan");
    CHECK(ulps(vdsh_det_exp(-740.0), exp(-740.0)) <= 1, "exp subnormal %.17g %.17g",
          vdsh_det_exp(-740.0), exp(-740.0));
    CHECK(vdsh_det_log(0.0) == -HUGE_VAL && isnan(vdsh_det_log(-1.0)), "log 0, log -1");
    CHECK(vdsh_det_log(HUGE_VAL) == HUGE_VAL && isnan(vdsh_det_log(NAN)), "log inf, nan");
    CHECK(ulps(vdsh_det_log(4.9e-324), log(4.9e-324)) <= 2, "log subnormal");
    CHECK(vdsh_det_acos(1.0) == 0.0 && vdsh_det_acos(-1.0) == acos(-1.0), "acos ends");
    CHECK(vdsh_det_acos(0.0) == acos(0.0), "acos 0");
    const double q[][2] = {{1, 1}, {1, -1}, {-1, -1}, {-1, 1},    {0, 1},      {0, -1},
                           {1, 0}, {-1, 0}, {0, 0},   {-0.0, -1}, {3, 1e-300}, {1e-300, -3}};
    for (size_t i = 0; i < sizeof q / sizeof q[0]; i++) {
        double got = vdsh_det_atan2(q[i][0], q[i][1]), want = atan2(q[i][0], q[i][1]);
        CHECK(ulps(got, want) <= 1 && signbit(got) == signbit(want), "atan2(%g, %g) %.17g %.17g",
              q[i][0], q[i][1], got, want);
    }
    /* sin and cos agree with each other: sin^2 + cos^2 = 1 to rounding */
    for (int i = 0; i < 1000; i++) {
        double x = (test_rand(&s) - 0.5) * 2e5, c = vdsh_det_cos(x), sn = vdsh_det_sin(x);
        CHECK(fabs(c * c + sn * sn - 1.0) < 4e-16, "sin^2 + cos^2 at %.17g", x);
    }
    return test_failures ? 1 : 0;
}
