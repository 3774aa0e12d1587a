#include "vdsh_sh.h"
#include "vdsh.h"

#include <assert.h>
#include <math.h>
#include <pthread.h>
#include <string.h>

/* An AVX2 clone of the batch loops, chosen at run time where the CPU has
 * it (Debian builds for baseline x86-64, i.e. SSE2). No FMA: every lane
 * does the same IEEE operations in the same order either way, so results
 * are bit-identical whichever clone runs. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) &&                             \
    !defined(__SANITIZE_ADDRESS__)
#define VDSH_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define VDSH_CLONES
#endif

/* Constants: K_l^m normalisation, sqrt(2) folded in for m != 0
 * (vdsh_sh.h: the same literals go into the runtime's GLSL). */
#define C00 VDSH_SH_C00
#define C1 VDSH_SH_C1
#define C2A VDSH_SH_C2A
#define C20 VDSH_SH_C20
#define C22 VDSH_SH_C22
#define C33 VDSH_SH_C33
#define C32 VDSH_SH_C32
#define C31 VDSH_SH_C31
#define C30 VDSH_SH_C30
#define C32B VDSH_SH_C32B
#define C44 VDSH_SH_C44
#define C43 VDSH_SH_C43
#define C42 VDSH_SH_C42
#define C41 VDSH_SH_C41
#define C40 VDSH_SH_C40
#define C42B VDSH_SH_C42B
#define C44B VDSH_SH_C44B

/* The one kernel. With acc = 0, o[i * s] = Y_i; with acc = 1,
 * o[i * s] += w * Y_i (the callers pass constants, so each use compiles to
 * straight-line code). */
#define EMIT(i, value)                                                                             \
    do {                                                                                           \
        if (acc)                                                                                   \
            o[(i)*s] += w * (value);                                                               \
        else                                                                                       \
            o[(i)*s] = (value);                                                                    \
    } while (0)

/* The closed forms below are written out for bands 0..KERNEL_ORDER-1 (the
 * paper's orders); eval_high_bands' recurrence gives the bands above, up
 * to VDSH_MAX_ORDER - 1. */
#define KERNEL_ORDER 5
_Static_assert(KERNEL_ORDER <= VDSH_MAX_ORDER, "sh_kernel covers the paper's orders");

static inline __attribute__((always_inline)) void sh_kernel(int order, float x, float y, float z,
                                                            float *o, size_t s, int acc, float w)
{
    EMIT(0, C00);
    if (order < 2)
        return;
    EMIT(1, -C1 * y);
    EMIT(2, C1 * z);
    EMIT(3, -C1 * x);
    if (order < 3)
        return;
    float x2 = x * x, y2 = y * y, z2 = z * z;
    EMIT(4, C2A * x * y);
    EMIT(5, -C2A * y * z);
    EMIT(6, C20 * (3.0f * z2 - 1.0f));
    EMIT(7, -C2A * x * z);
    EMIT(8, C22 * (x2 - y2));
    if (order < 4)
        return;
    EMIT(9, -C33 * y * (3.0f * x2 - y2));
    EMIT(10, C32 * x * y * z);
    EMIT(11, -C31 * y * (5.0f * z2 - 1.0f));
    EMIT(12, C30 * z * (5.0f * z2 - 3.0f));
    EMIT(13, -C31 * x * (5.0f * z2 - 1.0f));
    EMIT(14, C32B * z * (x2 - y2));
    EMIT(15, -C33 * x * (x2 - 3.0f * y2));
    if (order < KERNEL_ORDER)
        return;
    EMIT(16, C44 * x * y * (x2 - y2));
    EMIT(17, -C43 * y * z * (3.0f * x2 - y2));
    EMIT(18, C42 * x * y * (7.0f * z2 - 1.0f));
    EMIT(19, -C41 * y * z * (7.0f * z2 - 3.0f));
    EMIT(20, C40 * (35.0f * z2 * z2 - 30.0f * z2 + 3.0f));
    EMIT(21, -C41 * x * z * (7.0f * z2 - 3.0f));
    EMIT(22, C42B * (x2 - y2) * (7.0f * z2 - 1.0f));
    EMIT(23, -C43 * x * z * (x2 - 3.0f * y2));
    EMIT(24, C44B * (x2 * x2 - 6.0f * x2 * y2 + y2 * y2));
}

void vdsh_sh_eval(int order, const float d[3], float *out)
{
    assert(order >= 1 && order <= VDSH_MAX_ORDER);
    if (order > KERNEL_ORDER) {
        vdsh_sh_eval_soa(order, 1, &d[0], &d[1], &d[2], out, 1);
        return;
    }
    sh_kernel(order, d[0], d[1], d[2], out, 1, 0, 0.0f);
}

/* The batch loops. `order` is a constant in every call below, so each
 * compiles to a straight-line, vectorised loop over k. */
static inline __attribute__((always_inline)) void soa_loop(
    int order, size_t n, const float *restrict x, const float *restrict y, const float *restrict z,
    const float *restrict w, float *restrict o, size_t stride, int acc)
{
    for (size_t k = 0; k < n; k++)
        sh_kernel(order, x[k], y[k], z[k], o + k, stride, acc, acc ? w[k] : 0.0f);
}

static inline __attribute__((always_inline)) void soa_dispatch(int order, size_t n, const float *x,
                                                               const float *y, const float *z,
                                                               const float *w, float *o,
                                                               size_t stride, int acc)
{
    /* Packets of 16 with rows of 16 (the bake's layout) get their own
     * loops: with constant sizes the compiler can see that the output
     * rows never overlap, and vectorises. */
    if (n == 16 && stride == 16) {
        switch (order) {
        case 1: soa_loop(1, 16, x, y, z, w, o, 16, acc); return;
        case 2: soa_loop(2, 16, x, y, z, w, o, 16, acc); return;
        case 3: soa_loop(3, 16, x, y, z, w, o, 16, acc); return;
        case 4: soa_loop(4, 16, x, y, z, w, o, 16, acc); return;
        default: soa_loop(5, 16, x, y, z, w, o, 16, acc); return;
        }
    }
    /* Evaluation at any stride (the decision fit's rows of 1024): blocks
     * of 16 through the vectorised loop into a block of rows of 16, then
     * copied out (the same values: each lane computes what the scalar
     * loop would). */
    if (!acc && n >= 16) {
        const int rows = order * order;
        float block[KERNEL_ORDER * KERNEL_ORDER * 16];
        size_t k0 = 0;
        for (; k0 + 16 <= n; k0 += 16) {
            switch (order) {
            case 1: soa_loop(1, 16, x + k0, y + k0, z + k0, NULL, block, 16, 0); break;
            case 2: soa_loop(2, 16, x + k0, y + k0, z + k0, NULL, block, 16, 0); break;
            case 3: soa_loop(3, 16, x + k0, y + k0, z + k0, NULL, block, 16, 0); break;
            case 4: soa_loop(4, 16, x + k0, y + k0, z + k0, NULL, block, 16, 0); break;
            default: soa_loop(5, 16, x + k0, y + k0, z + k0, NULL, block, 16, 0); break;
            }
            for (int i = 0; i < rows; i++)
                memcpy(o + (size_t)i * stride + k0, block + i * 16, 16 * sizeof *block);
        }
        x += k0, y += k0, z += k0, o += k0, n -= k0;
    }
    switch (order) {
    case 1: soa_loop(1, n, x, y, z, w, o, stride, acc); break;
    case 2: soa_loop(2, n, x, y, z, w, o, stride, acc); break;
    case 3: soa_loop(3, n, x, y, z, w, o, stride, acc); break;
    case 4: soa_loop(4, n, x, y, z, w, o, stride, acc); break;
    default: soa_loop(5, n, x, y, z, w, o, stride, acc); break;
    }
}

/* K_l^m of bands 5 and up (sqrt(2) folded in for m != 0), index
 * l(l+1)+m for m >= 0, computed once in double. */
static float k_high[VDSH_MAX_COEFFS];
static pthread_once_t k_high_once = PTHREAD_ONCE_INIT;

static void k_high_init(void)
{
    for (int l = KERNEL_ORDER; l < VDSH_MAX_ORDER; l++)
        for (int m = 0; m <= l; m++) {
            double kk = (2.0 * l + 1.0) / (4.0 * 3.14159265358979323846);
            for (int f = l - m + 1; f <= l + m; f++)
                kk /= f;
            k_high[l * (l + 1) + m] = (float)sqrt(m ? 2.0 * kk : kk);
        }
}

/* Bands 5 .. order-1 (order <= VDSH_MAX_ORDER) by the standard
 * recurrence, in the same convention as bands 0-4 (Condon-Shortley phase,
 * sin for m < 0): Y_l^m = K_l^m P_l^m(z) (sqrt 2 Re or Im (x + iy)^m),
 * P_l^m here without its (1 - z^2)^(m/2) factor, which (x + iy)^m carries.
 * Directions in chunks, each step a loop over the chunk, so it vectorises
 * over directions like the kernel above. With acc, out[i] += w Y_i (the
 * projection), else out[i] = Y_i. */
static inline __attribute__((always_inline)) void eval_high_bands(int order, size_t n,
                                                                  const float *x, const float *y,
                                                                  const float *z, const float *w,
                                                                  float *out, size_t stride,
                                                                  int acc)
{
    enum { CHUNK = 64 };
    pthread_once(&k_high_once, k_high_init);
    for (size_t k0 = 0; k0 < n; k0 += CHUNK) {
        size_t cn = n - k0 < CHUNK ? n - k0 : CHUNK;
        const float *xs = x + k0, *ys = y + k0, *zs = z + k0;
        float c[CHUNK], sn[CHUNK], pmm[CHUNK], pa[CHUNK], pb[CHUNK], pc[CHUNK];
        float *p0 = pa, *p1 = pb, *pl = pc; /* rotated, not copied */
        for (size_t k = 0; k < cn; k++)
            c[k] = 1.0f, sn[k] = 0.0f, pmm[k] = 1.0f;
        for (int m = 0; m < order; m++) {
            if (m > 0) /* (x + iy)^m, and P_m^m = -(2m - 1) P_{m-1}^{m-1} */
                for (size_t k = 0; k < cn; k++) {
                    float cc = xs[k] * c[k] - ys[k] * sn[k];
                    sn[k] = xs[k] * sn[k] + ys[k] * c[k];
                    c[k] = cc;
                    pmm[k] *= -(float)(2 * m - 1);
                }
            for (int l = m; l < order; l++) {
                /* P_l^m from P_{l-1}^m (p1) and P_{l-2}^m (p0). */
                if (l == m)
                    for (size_t k = 0; k < cn; k++)
                        pl[k] = pmm[k];
                else if (l == m + 1)
                    for (size_t k = 0; k < cn; k++)
                        pl[k] = zs[k] * (float)(2 * m + 1) * pmm[k];
                else {
                    float a = (float)(2 * l - 1) / (float)(l - m);
                    float b = (float)(l + m - 1) / (float)(l - m);
                    for (size_t k = 0; k < cn; k++)
                        pl[k] = a * zs[k] * p1[k] - b * p0[k];
                }
                float *old = p0; /* P_{l-2} is done with: P_{l-1}, P_l move down */
                p0 = p1;
                p1 = pl;
                pl = old;
                if (l < KERNEL_ORDER)
                    continue; /* the closed forms above */
                float K = k_high[l * (l + 1) + m];
                float *pos = out + (size_t)(l * (l + 1) + m) * stride + k0;
                float *neg = out + (size_t)(l * (l + 1) - m) * stride + k0;
                if (acc) {
                    const float *ws = w + k0;
                    if (m == 0)
                        for (size_t k = 0; k < cn; k++)
                            pos[k] += ws[k] * (K * p1[k]);
                    else
                        for (size_t k = 0; k < cn; k++) {
                            float kp = K * p1[k];
                            pos[k] += ws[k] * (kp * c[k]);
                            neg[k] += ws[k] * (kp * sn[k]);
                        }
                } else if (m == 0) {
                    for (size_t k = 0; k < cn; k++)
                        pos[k] = K * p1[k];
                } else {
                    for (size_t k = 0; k < cn; k++) {
                        float kp = K * p1[k];
                        pos[k] = kp * c[k];
                        neg[k] = kp * sn[k];
                    }
                }
            }
        }
    }
}

VDSH_CLONES void vdsh_sh_eval_soa(int order, size_t n, const float *x, const float *y,
                                  const float *z, float *out, size_t out_stride)
{
    assert(order >= 1 && order <= VDSH_MAX_ORDER);
    soa_dispatch(order < KERNEL_ORDER ? order : KERNEL_ORDER, n, x, y, z, NULL, out, out_stride, 0);
    if (order > KERNEL_ORDER)
        eval_high_bands(order, n, x, y, z, NULL, out, out_stride, 0);
}

VDSH_CLONES void vdsh_sh_project_soa(int order, size_t n, const float *x, const float *y,
                                     const float *z, const float *w, float *acc, size_t acc_stride)
{
    assert(order >= 1 && order <= VDSH_MAX_ORDER);
    soa_dispatch(order < KERNEL_ORDER ? order : KERNEL_ORDER, n, x, y, z, w, acc, acc_stride, 1);
    if (order <= KERNEL_ORDER)
        return;
    eval_high_bands(order, n, x, y, z, w, acc, acc_stride, 1); /* bands 5 and up */
}

float vdsh_sh_reconstruct(int order, const float *c, const float d[3])
{
    float y[VDSH_MAX_COEFFS];
    vdsh_sh_eval(order, d, y);
    float sum = 0.0f;
    for (int i = 0; i < order * order; i++)
        sum += c[i] * y[i];
    return sum;
}
