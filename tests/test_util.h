/*
 * test_util.h - the few helpers every C test shares: a CHECK macro that
 * reports and counts failures (so one run shows all of them) and a
 * deterministic random stream.
 */
#ifndef VDSH_TEST_UTIL_H
#define VDSH_TEST_UTIL_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

static int test_failures;

#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            test_failures++;                                                                       \
            fprintf(stderr, "%s:%d: check failed: %s: ", __FILE__, __LINE__, #cond);               \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fputc('\n', stderr);                                                                   \
        }                                                                                          \
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

/* The whole of a regular file, followed by a NUL (so that text can be
 * searched with strstr), its size in *size (may be NULL); NULL if it
 * cannot be read. The caller frees. */
static inline unsigned char *test_read_file(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    struct stat st;
    unsigned char *buf = NULL;
    if (f && fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode) &&
        (buf = malloc((size_t)st.st_size + 1)) != NULL) {
        size_t got = fread(buf, 1, (size_t)st.st_size, f);
        if (got != (size_t)st.st_size) {
            free(buf);
            buf = NULL;
        } else {
            buf[got] = 0;
            if (size)
                *size = got;
        }
    }
    if (f)
        fclose(f);
    return buf;
}

#endif
