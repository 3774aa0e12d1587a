/*
 * light_pool_tool SCENE COUNT SEED OUT [box]: COUNT point lights placed in
 * SCENE's free space by the project's rule (vb_scene_place_lights: seeded
 * candidates, uniform in the light region, that pass the free-space test;
 * vdsh_light.h), written to OUT as little-endian f32 x, y, z per light,
 * and the region on stdout. SEED is a number, or bake:N for the seed of
 * the pool a bake of seed N places, N ^ VB_POOL_SEED (bake.h).
 * Measurement only: with COUNT 2048 and SEED bake:N the pool vdsh-bake
 * --seed N --cpca ...,light:A places (bake/lib/job.c); scripts/cpca_study
 * passes it to vdsh-merge in a part's lpol chunk (docs/ACCURACY.md, "A
 * light-density metric").
 * With `box`: the first COUNT candidates in the light region, no
 * free-space test (a pool a merge could draw from the region alone).
 * Exit 1 on a load, scene or placement error, 2 on bad usage.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake.h"
#include "mesh.h"
#include "scene.h"
#include "vdsh_light.h"

int main(int argc, char **argv)
{
    if (argc < 5 || argc > 6 || (argc == 6 && strcmp(argv[5], "box") != 0)) {
        fprintf(stderr, "usage: light_pool_tool SCENE COUNT SEED OUT [box]\n");
        return 2;
    }
    const int box = argc == 6;
    const unsigned long count = strtoul(argv[2], NULL, 0);
    const int bake = strncmp(argv[3], "bake:", 5) == 0;
    const uint64_t seed = strtoull(argv[3] + (bake ? 5 : 0), NULL, 0) ^ (bake ? VB_POOL_SEED : 0);
    if (count < 1 || count > 1000000) {
        fprintf(stderr, "light_pool_tool: COUNT must be 1..1000000, not '%s'\n", argv[2]);
        return 2;
    }
    vb_error err;
    vb_mesh m = {0};
    vb_load_desc ld = {0};
    if (vb_mesh_load(argv[1], &ld, &m, NULL, &err) != VB_OK) {
        fprintf(stderr, "light_pool_tool: %s\n", err.msg);
        return 1;
    }
    vb_scene *s = NULL;
    vb_scene_desc sd = {.robust = 1}; /* vdsh-bake's default */
    if (vb_scene_create(&m, &sd, &s, &err) != VB_OK) {
        fprintf(stderr, "light_pool_tool: %s\n", err.msg);
        vb_mesh_free(&m);
        return 1;
    }
    float lo[3], hi[3];
    const int grown = vb_scene_light_region(s, lo, hi, NULL);
    float(*pool)[3] = malloc(count * sizeof *pool);
    uint32_t tried = 0;
    int rc = 1;
    int placed = 0;
    if (!pool) {
        fprintf(stderr, "light_pool_tool: out of memory\n");
    } else if (box) {
        for (uint32_t k = 0; k < count; k++)
            vdsh_light_candidate(lo, hi, seed, k, pool[k]);
        tried = (uint32_t)count;
        placed = 1;
    } else if (vb_scene_place_lights(s, seed, (uint32_t)count, pool, &tried, &err) != VB_OK) {
        fprintf(stderr, "light_pool_tool: %s\n", err.msg);
    } else {
        placed = 1;
    }
    if (placed) {
        FILE *f = fopen(argv[4], "wb");
        int ok = f && fwrite(pool, sizeof *pool, count, f) == count;
        ok = f && fclose(f) == 0 && ok;
        if (!ok) {
            fprintf(stderr, "light_pool_tool: cannot write %s\n", argv[4]);
            remove(argv[4]);
        } else {
            printf("%sregion %s %g %g %g %g %g %g: %lu lights from %u candidates\n",
                   box ? "box of the " : "", grown ? "grown" : "bounds", lo[0], lo[1], lo[2], hi[0],
                   hi[1], hi[2], count, tried);
            rc = 0;
        }
    }
    free(pool);
    vb_scene_destroy(s);
    vb_mesh_free(&m);
    return rc;
}
