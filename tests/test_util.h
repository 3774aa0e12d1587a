/*
 * test_util.h - the few helpers every C test shares: a CHECK macro that
 * reports and counts failures (so one run shows all of them) and a
 * deterministic random stream.
 */
#ifndef VDSH_TEST_UTIL_H
#define VDSH_TEST_UTIL_H

#include <stdint.h>
#include <stdio.h>

static int test_failures;

#define CHECK(cond, ...)                                                   \
    do {                                                                   \
        if (!(cond)) {                                                     \
            test_failures++;                                               \
            fprintf(stderr, "%s:%d: check failed: %s: ", __FILE__,         \
                    __LINE__, #cond);                                      \
            fprintf(stderr, __VA_ARGS__);                                  \
            fputc('\n', stderr);                                           \
        }                                                                  \
    } while (0)

#define TEST_SKIP 77

/* xorshift64*: deterministic test data. */
static inline double test_rand(uint64_t *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 0x2545F4914F6CDD1Dull) >> 11) * (1.0 / 9007199254740992.0);
}

/* A uniformly random unit vector. */
static inline void test_rand_dir(uint64_t *s, float d[3])
{
    double z = 2.0 * test_rand(s) - 1.0, phi = 6.283185307179586 * test_rand(s);
    double r = __builtin_sqrt(1.0 - z * z);
    d[0] = (float)(r * __builtin_cos(phi));
    d[1] = (float)(r * __builtin_sin(phi));
    d[2] = (float)z;
}

static inline int test_report(const char *name)
{
    if (test_failures) {
        fprintf(stderr, "%s: %d check(s) failed\n", name, test_failures);
        return 1;
    }
    printf("%s: all checks passed\n", name);
    return 0;
}

#endif
