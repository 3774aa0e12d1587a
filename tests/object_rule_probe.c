/*
 * object_rule_probe SCENE: statistics for telling an object (seen from
 * outside) from a room or interior (issue 25; docs/ACCURACY.md, "Objects
 * or rooms: a rule for auto, not adopted"), each a count of free-space
 * decisions or of probe rays that meet nothing (vdsh_light.h, the same
 * probes as the free-space test; the same output under the four Embree
 * kernel sets on the scenes measured there; one thread):
 *   line 1: in N      free of the first VDSH_REGION_PROBES candidates in
 *                     the bounds (vdsh_light_region's count, not stopped
 *                     early)
 *           esc E     their probe rays (of 14 N) that meet nothing
 *           open O    of the N, those with at least 7 probes meeting nothing
 *           shell S/T of the first VDSH_REGION_PROBES candidates in the
 *                     bounds grown by VDSH_REGION_GROW, the T outside the
 *                     bounds, S free
 *           below B/U of those, the U below the bounds' middle height
 *                     (y), B free
 *   line 2: dirs      per probe direction (x, y, z signs, 2 = axis), how
 *                     many of the N free candidates' probes meet nothing
 *   line 3: hist      how many of the N have 0, 1, ..., 14 probes that
 *                     meet nothing (the first: enclosed free space)
 * Exit 1 on a load or scene error.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "bake.h"
#include "probe_scene.h"

static uint32_t dir_esc[VDSH_FREE_PROBES], hist[VDSH_FREE_PROBES + 1];

static uint32_t misses_from(const vb_scene *s, const float p[3])
{
    float t[VDSH_FREE_PROBES];
    probe_embree_t(s, p, t);
    uint32_t n = 0;
    for (int i = 0; i < VDSH_FREE_PROBES; i++) {
        n += t[i] == INFINITY;
        dir_esc[i] += t[i] == INFINITY;
    }
    return n;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: object_rule_probe SCENE\n");
        return 2;
    }
    vb_mesh m = {0};
    vb_scene *s = probe_scene("object_rule_probe", argv[1], &m);
    if (!s)
        return 1;
    const float *lo = s->bounds_min, *hi = s->bounds_max;
    uint32_t in = 0, esc = 0, open = 0;
    for (uint32_t k = 0; k < VDSH_REGION_PROBES; k++) {
        float p[3];
        vdsh_light_candidate(lo, hi, VDSH_REGION_SEED, k, p);
        if (!vb_scene_free_space(s, p))
            continue;
        in++;
        uint32_t mi = misses_from(s, p);
        esc += mi;
        hist[mi]++;
        open += mi >= VDSH_FREE_PROBES / 2;
    }
    const float g = VDSH_REGION_GROW * vdsh_free_diagonal(lo, hi);
    float glo[3], ghi[3];
    for (int a = 0; a < 3; a++) {
        glo[a] = lo[a] - g;
        ghi[a] = hi[a] + g;
    }
    const float mid = 0.5f * (lo[1] + hi[1]);
    uint32_t shell = 0, shell_free = 0, below = 0, below_free = 0;
    for (uint32_t k = 0; k < VDSH_REGION_PROBES; k++) {
        float p[3];
        vdsh_light_candidate(glo, ghi, VDSH_REGION_SEED, k, p);
        int inside = 1;
        for (int a = 0; a < 3; a++)
            inside &= p[a] >= lo[a] && p[a] <= hi[a];
        if (inside)
            continue;
        const int f = vb_scene_free_space(s, p);
        shell++;
        shell_free += f;
        if (p[1] < mid) {
            below++;
            below_free += f;
        }
    }
    printf("in %u esc %u (%.1f%%) open %u (%.1f%%) shell %u/%u (%.1f%%) below %u/%u (%.1f%%)\n", in,
           esc, in ? 100.0 * esc / (14.0 * in) : 0.0, open, in ? 100.0 * open / in : 0.0,
           shell_free, shell, shell ? 100.0 * shell_free / shell : 0.0, below_free, below,
           below ? 100.0 * below_free / below : 0.0);
    float dirs[VDSH_FREE_PROBES][3];
    vdsh_free_probe_dirs(dirs);
    printf("dirs");
    for (int i = 0; i < VDSH_FREE_PROBES; i++)
        printf(" %+.0f%+.0f%+.0f:%u", dirs[i][0] * 1.5, dirs[i][1] * 1.5, dirs[i][2] * 1.5,
               dir_esc[i]);
    printf("\nhist");
    for (int i = 0; i <= VDSH_FREE_PROBES; i++)
        printf(" %u", hist[i]);
    printf("\n");
    vb_scene_destroy(s);
    vb_mesh_free(&m);
    return 0;
}
