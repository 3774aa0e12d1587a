/* Free space for lights: vdsh_light.h says what and why. */
#include "vdsh_light.h"

#include <math.h>
#include <string.h>

void vdsh_free_probe_dirs(float dirs[VDSH_FREE_PROBES][3])
{
    int n = 0;
    for (int a = 0; a < 3; a++)
        for (int s = -1; s <= 1; s += 2, n++) {
            dirs[n][0] = dirs[n][1] = dirs[n][2] = 0.0f;
            dirs[n][a] = (float)s;
        }
    const float d = 0.57735026918962576f; /* 1 / sqrt(3) */
    for (int k = 0; k < 8; k++, n++) {
        dirs[n][0] = (k & 1) ? d : -d;
        dirs[n][1] = (k & 2) ? d : -d;
        dirs[n][2] = (k & 4) ? d : -d;
    }
}

float vdsh_free_clearance(float diagonal)
{
    return 0.01f * diagonal;
}

float vdsh_free_diagonal(const float lo[3], const float hi[3])
{
    double d2 = 0.0;
    for (int a = 0; a < 3; a++) {
        const double e = (double)hi[a] - lo[a];
        d2 += e * e;
    }
    return (float)sqrt(d2);
}

int vdsh_free_space(const float t[VDSH_FREE_PROBES], const int back[VDSH_FREE_PROBES],
                    float clearance)
{
    int backs = 0, fronts = 0;
    for (int i = 0; i < VDSH_FREE_PROBES; i++) {
        if (t[i] < clearance)
            return 0;
        backs += t[i] < INFINITY && back[i];
        fronts += t[i] < INFINITY && !back[i];
    }
    return backs == 0 || fronts > backs;
}

/* SplitMix64 on (seed, k, axis): a counter-based stream. */
static double unit(uint64_t seed, uint32_t k, uint32_t axis)
{
    uint64_t z = seed + 0x9e3779b97f4a7c15ull * ((uint64_t)k * 4u + axis + 1u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0); /* [0, 1) */
}

void vdsh_light_candidate(const float lo[3], const float hi[3], uint64_t seed, uint32_t k,
                          float out[3])
{
    for (int a = 0; a < 3; a++)
        out[a] = (float)((double)lo[a] + unit(seed, k, (uint32_t)a) * ((double)hi[a] - lo[a]));
}

double vdsh_light_growth(uint32_t free_count)
{
    if (free_count <= VDSH_REGION_FULL)
        return (double)VDSH_REGION_GROW;
    if (free_count >= VDSH_REGION_ROOM)
        return 0.0;
    return (double)VDSH_REGION_GROW * (double)(VDSH_REGION_ROOM - free_count) /
           (double)(VDSH_REGION_ROOM - VDSH_REGION_FULL);
}

int vdsh_light_region(const float lo[3], const float hi[3], vdsh_free_fn is_free, const void *ctx,
                      float out_lo[3], float out_hi[3], uint32_t *probes)
{
    float l[3] = {lo[0], lo[1], lo[2]}, h[3] = {hi[0], hi[1], hi[2]};
    uint32_t found = 0, k = 0;
    while (found < VDSH_REGION_ROOM && k < VDSH_REGION_PROBES) {
        float p[3];
        vdsh_light_candidate(l, h, VDSH_REGION_SEED, k++, p);
        found += is_free(ctx, p) != 0;
    }
    if (probes)
        *probes = k;
    const double share = vdsh_light_growth(found);
    const int grown = share > 0.0;
    double diag = 0.0;
    for (int a = 0; a < 3; a++)
        diag += ((double)h[a] - l[a]) * ((double)h[a] - l[a]);
    const double g = share * sqrt(diag);
    for (int a = 0; a < 3; a++) {
        out_lo[a] = grown ? (float)((double)l[a] - g) : l[a];
        out_hi[a] = grown ? (float)((double)h[a] + g) : h[a];
    }
    return grown;
}

int vdsh_light_grown_box(const float lo[3], const float hi[3], vdsh_free_fn is_free,
                         const void *ctx, float out_lo[3], float out_hi[3])
{
    const float diag = vdsh_free_diagonal(lo, hi);
    const double g = (double)VDSH_REGION_GROW * (double)diag;
    const double out = 2.0 * (double)vdsh_free_clearance(diag);
    int closed = 0;
    for (int a = 0; a < 3; a++)
        for (int side = 0; side < 2; side++) {
            const int b = (a + 1) % 3, c = (a + 2) % 3;
            int any = 0;
            for (int i = 0; i < VDSH_SIDE_GRID && !any; i++)
                for (int j = 0; j < VDSH_SIDE_GRID && !any; j++) {
                    float p[3];
                    p[a] = side ? (float)((double)hi[a] + out) : (float)((double)lo[a] - out);
                    p[b] = (float)((double)lo[b] +
                                   ((double)hi[b] - lo[b]) * (i + 0.5) / VDSH_SIDE_GRID);
                    p[c] = (float)((double)lo[c] +
                                   ((double)hi[c] - lo[c]) * (j + 0.5) / VDSH_SIDE_GRID);
                    any = is_free(ctx, p) != 0;
                }
            closed |= !any << (2 * a + side);
        }
    for (int a = 0; a < 3; a++) {
        const float l = lo[a], h = hi[a]; /* out may alias lo, hi */
        out_lo[a] = closed >> (2 * a) & 1 ? l : (float)((double)l - g);
        out_hi[a] = closed >> (2 * a + 1) & 1 ? h : (float)((double)h + g);
    }
    return closed;
}

uint64_t vdsh_light_tries(uint32_t count, int grown)
{
    const uint64_t per_light = 1000ull * (count ? count : 1);
    return grown ? VDSH_REGION_TRIES + per_light : per_light;
}

uint32_t vdsh_light_place(const float lo[3], const float hi[3], int grown, uint64_t seed,
                          uint32_t count, vdsh_free_fn is_free, const void *ctx, float (*out)[3],
                          uint32_t *out_k, uint32_t *tried)
{
    const uint64_t limit = vdsh_light_tries(count, grown);
    uint32_t n = 0, k = 0;
    while (n < count && k < limit) {
        float p[3];
        vdsh_light_candidate(lo, hi, seed, k, p);
        if (is_free(ctx, p)) {
            if (out_k)
                out_k[n] = k;
            memcpy(out[n++], p, sizeof p);
        }
        k++;
    }
    if (tried)
        *tried = k;
    return n;
}
