/*
 * libm_probe.c - a hash of libm's cos, sin, exp and log (double) over 2e5
 * arguments: it differs between glibc's FMA and SSE2 code paths on a CPU
 * with FMA, so test_same_bytes_any_cpu.sh can check that its
 * GLIBC_TUNABLES really changed the path (else its comparison proves
 * nothing).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

int main(void)
{
    uint64_t h = 1469598103934665603ull;
    for (uint32_t i = 0; i < 200000; i++) {
        volatile double x = (double)i * 6.283185307179586 / 200000.0;
        double r[4] = {cos(x), sin(x), exp(-x), log(x + 0.5)};
        for (int k = 0; k < 4; k++) {
            uint64_t u;
            memcpy(&u, &r[k], 8);
            h = (h ^ u) * 1099511628211ull;
        }
    }
    printf("%016llx\n", (unsigned long long)h);
    return 0;
}
