#include "sampling.h"
#include "vdsh_math.h"
#include "vdsh_det.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define VB_PI 3.14159265358979323846

/* A 32-bit integer hash with full avalanche (Wellons' lowbias32). 32-bit
 * so the per-lane jitter below vectorises. */
static inline uint32_t mix32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

/* The per-(seed, a) key; the per-b hashes below mix it with b. */
static inline uint32_t hash_key(uint64_t seed, uint32_t a)
{
    return mix32((uint32_t)seed ^ mix32((uint32_t)(seed >> 32) ^ mix32(a)));
}

static inline void hash_uv(uint32_t key, uint32_t b, float *u, float *v)
{
    uint32_t h1 = mix32(key ^ mix32(b));
    uint32_t h2 = mix32(h1 ^ 0x9e3779b9u);
    /* Via int32: SSE2 converts signed integers to float, not unsigned. */
    *u = (float)(int32_t)(h1 >> 8) * (1.0f / 16777216.0f);
    *v = (float)(int32_t)(h2 >> 8) * (1.0f / 16777216.0f);
}

void vb_hash2(uint64_t seed, uint32_t a, uint32_t b, float *u, float *v)
{
    hash_uv(hash_key(seed, a), b, u, v);
}

void vb_frame(const float n[3], float t[3], float b[3])
{
    float s = copysignf(1.0f, n[2]);
    float a = -1.0f / (s + n[2]);
    float c = n[0] * n[1] * a;
    t[0] = 1.0f + s * n[0] * n[0] * a;
    t[1] = s * c;
    t[2] = -s * n[0];
    b[0] = c;
    b[1] = s + n[1] * n[1] * a;
    b[2] = -n[1];
}

/* Interleave the bits of two 16-bit numbers. */
static uint32_t morton2(uint32_t a, uint32_t b)
{
    uint32_t r = 0;
    for (int i = 0; i < 16; i++)
        r |= ((a >> i) & 1u) << (2 * i + 1) | ((b >> i) & 1u) << (2 * i);
    return r;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Direction at fractional grid coordinates (w along rows, c along columns)
 * of the sphere domain, in double: used only to bound packets. */
static void sphere_dir(const vb_dirgrid *g, double w, double c, double d[3])
{
    double z = 1.0 - 2.0 * w / g->nu, r = sqrt(fmax(0.0, 1.0 - z * z));
    double phi = 2.0 * VB_PI * c / g->nv;
    d[0] = r * vdsh_det_cos(phi), d[1] = r * vdsh_det_sin(phi), d[2] = z;
}

static double angle(const double a[3], const double b[3])
{
    double d = vdsh_dot3d(a, b);
    return vdsh_det_acos(fmax(-1.0, fmin(1.0, d)));
}

/* A cone containing every direction a packet can produce. Each cell is
 * cut into S x S sub-cells; the axis is the normalised mean of their
 * corners. Every direction lies in some sub-cell, so within the sub-cell's
 * longest diagonal (its diameter on the sphere, for cells this small) of
 * one of its corners: the half-angle is the largest corner angle plus the
 * largest diagonal, plus 1e-4 rad for rounding. */
static void packet_cone(const vb_dirgrid *g, const uint32_t *cells, float cone[4])
{
    enum { S = 8, P = (S + 1) * (S + 1) };
    /* Corner directions of every sub-cell of every live cell. */
    double pts[VB_PACKET][P][3];
    int live[VB_PACKET];
    double axis[3] = {0, 0, 0};
    for (int k = 0; k < VB_PACKET; k++) {
        live[k] = cells[k] != UINT32_MAX;
        if (!live[k])
            continue;
        uint32_t row = cells[k] / g->nv, col = cells[k] % g->nv;
        for (int i = 0; i <= S; i++)
            for (int j = 0; j <= S; j++) {
                double *d = pts[k][i * (S + 1) + j];
                sphere_dir(g, row + (double)i / S, col + (double)j / S, d);
                for (int c = 0; c < 3; c++)
                    axis[c] += d[c];
            }
    }
    double len = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    if (len < 1e-9) {
        cone[0] = cone[1] = cone[2] = 0.0f, cone[3] = 2.0f;
        return;
    }
    for (int c = 0; c < 3; c++)
        axis[c] /= len;
    double worst = 0.0, diag = 0.0;
    for (int k = 0; k < VB_PACKET; k++) {
        if (!live[k])
            continue;
        for (int i = 0; i <= S; i++)
            for (int j = 0; j <= S; j++) {
                const double *d = pts[k][i * (S + 1) + j];
                worst = fmax(worst, angle(axis, d));
                if (i < S && j < S) {
                    const double *r = pts[k][i * (S + 1) + j + 1];
                    const double *u = pts[k][(i + 1) * (S + 1) + j];
                    const double *ru = pts[k][(i + 1) * (S + 1) + j + 1];
                    diag = fmax(diag, fmax(angle(d, ru), angle(r, u)));
                }
            }
    }
    double alpha = worst + diag + 1e-4;
    cone[0] = (float)axis[0], cone[1] = (float)axis[1], cone[2] = (float)axis[2];
    cone[3] = alpha >= VB_PI / 2 ? 2.0f : (float)vdsh_det_sin(alpha);
}

vb_result vb_dirgrid_create(uint32_t rays, int hemisphere, vb_dirgrid *out, vb_error *err)
{
    if (rays == 0 || rays > VB_MAX_RAYS)
        return vb_fail(err, VB_ERR_ARGUMENT, "rays per receiver must be 1..%u, not %u", VB_MAX_RAYS,
                       rays);
    vb_dirgrid g = {0};
    g.nu = (uint32_t)floor(sqrt((double)rays));
    while ((uint64_t)(g.nu + 1) * (g.nu + 1) <= rays)
        g.nu++;
    while ((uint64_t)g.nu * g.nu > rays)
        g.nu--;
    g.nv = rays / g.nu;
    g.count = g.nu * g.nv;
    g.packet_count = (g.count + VB_PACKET - 1) / VB_PACKET;
    g.hemisphere = hemisphere;
    g.cells = malloc((size_t)g.packet_count * VB_PACKET * sizeof *g.cells);
    g.cone = malloc((size_t)g.packet_count * 4 * sizeof *g.cone);
    size_t lanes = (size_t)g.packet_count * VB_PACKET;
    g.lane_row = malloc(lanes * sizeof *g.lane_row);
    g.lane_cos = malloc(lanes * sizeof *g.lane_cos);
    g.lane_sin = malloc(lanes * sizeof *g.lane_sin);
    if (!g.cells || !g.cone || !g.lane_row || !g.lane_cos || !g.lane_sin) {
        vb_dirgrid_destroy(&g);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for %u ray directions", rays);
    }
    /* Morton order over (row, column): any 16 consecutive cells are a
     * compact patch (a 4 x 4 block where the grid allows), also in grids
     * whose sides are not powers of two. */
    uint64_t *key = malloc((size_t)g.count * sizeof *key);
    if (!key) {
        vb_dirgrid_destroy(&g);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for %u ray directions", rays);
    }
    for (uint32_t u = 0; u < g.nu; u++)
        for (uint32_t v = 0; v < g.nv; v++)
            key[u * g.nv + v] = ((uint64_t)morton2(u, v) << 32) | (u * g.nv + v);
    qsort(key, g.count, sizeof *key, cmp_u64);
    uint32_t k = 0;
    for (; k < g.count; k++)
        g.cells[k] = (uint32_t)key[k];
    free(key);
    while (k < g.packet_count * VB_PACKET)
        g.cells[k++] = UINT32_MAX;
    for (size_t i = 0; i < lanes; i++) {
        uint32_t cell = g.cells[i] == UINT32_MAX ? 0 : g.cells[i];
        double phi = 2.0 * VB_PI * (cell % g.nv) / g.nv;
        g.lane_row[i] = (float)(cell / g.nv);
        g.lane_cos[i] = (float)vdsh_det_cos(phi);
        g.lane_sin[i] = (float)vdsh_det_sin(phi);
    }
    for (uint32_t p = 0; p < g.packet_count; p++)
        packet_cone(&g, g.cells + (size_t)p * VB_PACKET, g.cone + 4 * (size_t)p);
    *out = g;
    return VB_OK;
}

void vb_dirgrid_destroy(vb_dirgrid *g)
{
    if (!g)
        return;
    free(g->cells);
    free(g->cone);
    free(g->lane_row);
    free(g->lane_cos);
    free(g->lane_sin);
    memset(g, 0, sizeof *g);
}

/* An AVX2 clone where the CPU has it (as formats/vdsh_sh.c does): no FMA
 * (-std=c11 does not contract), so the same bits either way. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) &&                             \
    !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("avx2", "default")))
#endif
void vb_dirgrid_packet(const vb_dirgrid *g, uint32_t packet, uint64_t seed,
                       uint32_t vertex, const float n[3], float dx[16],
                       float dy[16], float dz[16], int valid[16])
{
    const size_t base = (size_t)packet * VB_PACKET;
    const uint32_t *cells = g->cells + base;
    const float *row = g->lane_row + base;
    const float *c0 = g->lane_cos + base, *s0 = g->lane_sin + base;
    const float du = 1.0f / (float)g->nu;
    const float dphi = (float)(2.0 * VB_PI) / (float)g->nv;
    const float zscale = g->hemisphere ? 1.0f : 2.0f;
    const uint32_t key = hash_key(seed, vertex);
    float x[VB_PACKET], y[VB_PACKET], z[VB_PACKET];

    /* Branch-free over the lanes so the compiler vectorises it. Jitter in
     * phi is an angle inside one cell: for 8 or more columns at most pi/4,
     * where a short Taylor series is exact to float precision and much
     * cheaper than sinf/cosf. Empty lanes compute garbage, masked below. */
    for (int k = 0; k < VB_PACKET; k++) {
        float ju, jv;
        hash_uv(key, cells[k], &ju, &jv);
        float zz = 1.0f - zscale * (row[k] + ju) * du;
        float q = 1.0f - zz * zz;
        float r = sqrtf(q > 0.0f ? q : 0.0f); /* not fmaxf: it blocks vectorising */
        float d = jv * dphi, d2 = d * d;
        float cd = 1.0f - d2 * (1.0f / 2) *
                              (1.0f - d2 * (1.0f / 12) *
                                          (1.0f - d2 * (1.0f / 30) * (1.0f - d2 * (1.0f / 56))));
        float sd =
            d * (1.0f - d2 * (1.0f / 6) *
                            (1.0f - d2 * (1.0f / 20) *
                                        (1.0f - d2 * (1.0f / 42) * (1.0f - d2 * (1.0f / 72)))));
        x[k] = r * (c0[k] * cd - s0[k] * sd);
        y[k] = r * (s0[k] * cd + c0[k] * sd);
        z[k] = zz;
    }
    if (g->nv < 8) { /* wide cells: the series is not exact there */
        for (int k = 0; k < VB_PACKET; k++) {
            float ju, jv;
            hash_uv(key, cells[k], &ju, &jv);
            float r = sqrtf(fmaxf(0.0f, 1.0f - z[k] * z[k]));
            float phi = (float)(2.0 * VB_PI) * ((float)(cells[k] % g->nv) + jv) / (float)g->nv;
            x[k] = r * (float)vdsh_det_cos(phi);
            y[k] = r * (float)vdsh_det_sin(phi);
        }
    }
    if (g->hemisphere) {
        float t[3], b[3];
        vb_frame(n, t, b);
        for (int k = 0; k < VB_PACKET; k++) {
            dx[k] = x[k] * t[0] + y[k] * b[0] + z[k] * n[0];
            dy[k] = x[k] * t[1] + y[k] * b[1] + z[k] * n[1];
            dz[k] = x[k] * t[2] + y[k] * b[2] + z[k] * n[2];
        }
    } else {
        for (int k = 0; k < VB_PACKET; k++)
            dx[k] = x[k], dy[k] = y[k], dz[k] = z[k];
    }
    for (int k = 0; k < VB_PACKET; k++) {
        int live = cells[k] != UINT32_MAX;
        valid[k] = -live;
        dx[k] = live ? dx[k] : 0.0f;
        dy[k] = live ? dy[k] : 0.0f;
        dz[k] = live ? dz[k] : 0.0f;
    }
}

/* ---- nested grids (adaptive rays) ---------------------------------------- */

static uint32_t bit_reverse(uint32_t x, int bits)
{
    uint32_t r = 0;
    for (int i = 0; i < bits; i++)
        r |= ((x >> i) & 1u) << (bits - 1 - i);
    return r;
}

vb_result vb_dirgrid_create_nested(uint32_t rays, int hemisphere, vb_dirgrid *out, vb_error *err)
{
    if (rays < 128 || rays > VB_MAX_RAYS)
        return vb_fail(err, VB_ERR_ARGUMENT,
                       "adaptive rays need a cap of 128..%u directions, not %u", VB_MAX_RAYS, rays);
    int a = 0, b = 0; /* nu = 2^a rows, nv = 2^b columns, b = a or a + 1 */
    while (((uint64_t)1 << (a + b + 1)) <= rays) {
        if (b == a)
            b++;
        else
            a++;
    }
    vb_dirgrid g = {0};
    g.nu = 1u << a;
    g.nv = 1u << b;
    g.count = g.nu * g.nv;
    g.packet_count = g.count / VB_PACKET;
    g.hemisphere = hemisphere;
    g.cells = malloc((size_t)g.count * sizeof *g.cells);
    uint64_t *key = malloc((size_t)g.count * sizeof *key);
    if (!g.cells || !key) {
        free(key);
        vb_dirgrid_destroy(&g);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for %u ray directions", rays);
    }
    int bits = a + b;
    /* Round sizes: 2^p cells for p from bits - 4 (at least 64) to bits. */
    int first = bits - 4 < 6 ? 6 : bits - 4;
    for (uint32_t u = 0; u < g.nu; u++)
        for (uint32_t v = 0; v < g.nv; v++) {
            uint32_t code = morton2(u, v);
            uint32_t rank = bit_reverse(code, bits);
            uint32_t round = 0;
            while (rank >= (1u << (first + round)))
                round++;
            key[u * g.nv + v] = ((uint64_t)round << 56) | ((uint64_t)code << 24) | (u * g.nv + v);
        }
    qsort(key, g.count, sizeof *key, cmp_u64);
    for (uint32_t k = 0; k < g.count; k++)
        g.cells[k] = (uint32_t)(key[k] & 0xffffffu);
    free(key);
    g.rounds = (uint32_t)(bits - first + 1);
    for (uint32_t r = 0; r < g.rounds; r++)
        g.round_end[r] = (1u << (first + r)) / VB_PACKET;
    *out = g;
    return VB_OK;
}

void vb_dirgrid_packet_nested(const vb_dirgrid *g, uint32_t packet, uint64_t seed, uint32_t vertex,
                              const float n[3], float dx[16], float dy[16], float dz[16],
                              int valid[16])
{
    const uint32_t *cells = g->cells + (size_t)packet * VB_PACKET;
    const uint32_t key = hash_key(seed, vertex);
    const uint32_t shift = mix32(key ^ 0x5bd1e995u);
    const uint32_t hr = shift & (g->nu - 1), hc = (shift >> 16) & (g->nv - 1);
    const float zscale = g->hemisphere ? 1.0f : 2.0f;
    float t[3], b[3];
    if (g->hemisphere)
        vb_frame(n, t, b);
    for (int k = 0; k < VB_PACKET; k++) {
        uint32_t row = (cells[k] / g->nv) ^ hr, col = (cells[k] % g->nv) ^ hc;
        float ju, jv;
        hash_uv(key, row * g->nv + col, &ju, &jv);
        float z = 1.0f - zscale * ((float)row + ju) / (float)g->nu;
        float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
        float phi = (float)(2.0 * VB_PI) * ((float)col + jv) / (float)g->nv;
        float x = r * (float)vdsh_det_cos(phi), y = r * (float)vdsh_det_sin(phi);
        if (g->hemisphere) {
            dx[k] = x * t[0] + y * b[0] + z * n[0];
            dy[k] = x * t[1] + y * b[1] + z * n[1];
            dz[k] = x * t[2] + y * b[2] + z * n[2];
        } else {
            dx[k] = x, dy[k] = y, dz[k] = z;
        }
        valid[k] = -1;
    }
}
