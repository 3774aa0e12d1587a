/*
 * light_region_probe SCENE [SEED]: what the light placement of a bake
 * decides for SCENE (vdsh_light.h), printed so that runs under different
 * Embree kernel sets (tests/with_each_isa.sh) can be compared line by line:
 *   region grown|bounds probes N box LO HI   vb_scene_light_region's
 *     decision, the region's corners as hexadecimal floats (how far it
 *     grew: vdsh_light_growth of the free count below)
 *   candidates: the free ones among the first 1024 region candidates
 *     of the bounds (their indices, whether or not the rule stopped early)
 *   pool: the decision fit's 256 training lights (seed SEED, default 1, as
 *     vdsh-bake places them): how many candidates were tried and an FNV-1a
 *     hash of their coordinates' bits
 * and, on stderr, the smallest relative gap |t - clearance| / clearance of
 * any probe ray of those candidates to the clearance: how near a probe
 * came to flipping its candidate, and a hash of Embree's own distances for
 * those probes (Embree's kernels differ by a few ulps; the free-space test
 * measures its hits itself: bake/lib/scene.c probe_hit), and the share of
 * the free candidates' probe rays that meet nothing (open space: an
 * object's surroundings; a closed room's free space sees walls).
 * Exit 1 on a load or scene error.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake.h"
#include "probe_scene.h"

#define POOL 256u

static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++)
        h = (h ^ b[i]) * 0x100000001b3ull;
    return h;
}

/* The smallest |t - c| / c of the 14 probes from p (scene units), with
 * Embree's own distances; *h: their bits hashed (they differ between
 * kernel sets, the free-space test's own measure does not). */
static double probe_gap(const vb_scene *s, const float p[3], uint64_t *h, uint32_t *misses)
{
    float t[VDSH_FREE_PROBES];
    probe_embree_t(s, p, t);
    const double c = vdsh_free_clearance(s->diagonal);
    double gap = INFINITY;
    for (int i = 0; i < VDSH_FREE_PROBES; i++) {
        if (t[i] == INFINITY) {
            ++*misses;
            continue;
        }
        *h = fnv(*h, &t[i], sizeof t[i]);
        double g = fabs(t[i] / s->scale - c) / c;
        gap = g < gap ? g : gap;
    }
    return gap;
}

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 3) {
        fprintf(stderr, "usage: light_region_probe SCENE [SEED]\n");
        return 2;
    }
    const uint64_t seed = argc > 2 ? strtoull(argv[2], NULL, 0) : 1u;
    vb_mesh m = {0};
    vb_scene *s = probe_scene("light_region_probe", argv[1], &m);
    if (!s)
        return 1;
    float lo[3], hi[3];
    uint32_t probes = 0;
    const int grown = vb_scene_light_region(s, lo, hi, &probes);
    printf("region %s probes %u box", grown ? "grown" : "bounds", probes);
    for (int a = 0; a < 3; a++)
        printf(" %a", (double)lo[a]);
    for (int a = 0; a < 3; a++)
        printf(" %a", (double)hi[a]);
    printf("\n");
    printf("candidates:");
    double gap = INFINITY;
    uint64_t th = 0xcbf29ce484222325ull;
    uint32_t free_count = 0, escaped = 0;
    for (uint32_t k = 0; k < VDSH_REGION_PROBES; k++) {
        float p[3];
        vdsh_light_candidate(s->bounds_min, s->bounds_max, VDSH_REGION_SEED, k, p);
        const int is_free = vb_scene_free_space(s, p);
        if (is_free) {
            printf(" %u", k);
            free_count++;
        }
        uint32_t misses = 0;
        double g = probe_gap(s, p, &th, &misses);
        escaped += is_free ? misses : 0;
        gap = g < gap ? g : gap;
    }
    printf(" (%u free)\n", free_count);
    float(*pool)[3] = malloc(POOL * sizeof *pool);
    uint32_t tried = 0;
    vb_error err;
    if (pool && vb_scene_place_lights(s, seed ^ VB_POOL_SEED, POOL, pool, &tried, &err) == VB_OK)
        printf("pool %u lights from %u candidates, hash %016llx\n", POOL, tried,
               (unsigned long long)fnv(0xcbf29ce484222325ull, pool, POOL * sizeof *pool));
    else
        printf("pool: none (%s)\n", pool ? err.msg : "out of memory");
    fprintf(stderr,
            "light_region_probe: %s: nearest probe to the clearance: %.3g of it; Embree's "
            "distances hash %016llx; free candidates' probes that meet nothing: %.1f%%\n",
            argv[1], gap, (unsigned long long)th,
            free_count ? 100.0 * escaped / (free_count * (double)VDSH_FREE_PROBES) : 0.0);
    free(pool);
    vb_scene_destroy(s);
    vb_mesh_free(&m);
    return 0;
}
