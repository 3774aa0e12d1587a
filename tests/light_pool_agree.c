/*
 * light_pool_agree SCENE.vdsh [COUNT]: the light pool vdsh-view places
 * (runtime/vr_view.c vr_scene_place_pool: vdsh_light_region, then the
 * candidates of vdsh_light_candidate seed 1 that pass
 * vdsh_view_free_space, formats/vdsh_scene_view.c's grid tracer) against
 * the bake side's placement with the same seed (bake/lib/scene.c
 * vb_scene_place_lights: the same region and candidates, vdsh_free_space
 * on Embree's probes measured in double), both on the file's receiver
 * mesh. Prints how many of COUNT (default 64) positions are equal bit for
 * bit, and the first that differs with its candidates' probe distances
 * against the clearance. Exit 0 when every position is the same, 1 when
 * one differs, 2 on an error.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh.h"
#include "scene.h"
#include "vdsh.h"
#include "vdsh_light.h"
#include "vdsh_scene_view.h"

typedef struct view_free {
    const vdsh_view_tracer *t;
    float diag;
} view_free;

static int is_free_view(const void *ctx, const float p[3])
{
    const view_free *c = ctx;
    return vdsh_view_free_space(c->t, p, c->diag);
}

int main(int argc, char **argv)
{
    if (argc < 2)
        return fprintf(stderr, "usage: light_pool_agree SCENE.vdsh [COUNT]\n"), 2;
    uint32_t count = argc > 2 ? (uint32_t)atoi(argv[2]) : 64u;
    vdsh_file *f = NULL;
    vdsh_error ve;
    if (vdsh_read(argv[1], &f, &ve) != VDSH_OK)
        return fprintf(stderr, "%s\n", ve.msg), 2;
    const vdsh_header *h = &f->header;
    /* the runtime's pool */
    vdsh_view_mesh vm = {f->positions, f->normals, f->indices, h->vertex_count, h->triangle_count};
    float lo[3], hi[3];
    vdsh_view_bounds(f->positions, h->vertex_count, lo, hi);
    float diag = 0.0f;
    for (int a = 0; a < 3; a++)
        diag += (hi[a] - lo[a]) * (hi[a] - lo[a]);
    diag = sqrtf(diag);
    vdsh_view_tracer *t = NULL;
    if (vdsh_view_tracer_create(&vm, &t, &ve) != VDSH_OK)
        return fprintf(stderr, "%s\n", ve.msg), 2;
    view_free vf = {t, diag};
    float rlo[3], rhi[3];
    const int grown = vdsh_light_region(lo, hi, is_free_view, &vf, rlo, rhi, NULL);
    float(*rt)[3] = calloc(count, sizeof *rt);
    uint32_t *rt_k = calloc(count, sizeof *rt_k);
    uint32_t n = 0;
    const uint64_t limit = grown ? vdsh_light_tries(count, 1) : 256u * (uint64_t)count;
    for (uint32_t k = 0; n < count && k < limit; k++) {
        float p[3];
        vdsh_light_candidate(rlo, rhi, 1, k, p);
        if (vdsh_view_free_space(t, p, diag))
            rt_k[n] = k, memcpy(rt[n++], p, sizeof p);
    }
    /* the bake side's */
    vb_mesh m = {0};
    m.vertex_count = h->vertex_count;
    m.triangle_count = h->triangle_count;
    m.positions = (float *)f->positions;
    m.normals = (float *)f->normals;
    m.indices = (uint32_t *)f->indices;
    vb_scene *s = NULL;
    vb_error err;
    if (vb_scene_create(&m, &(vb_scene_desc){.threads = 1}, &s, &err) != VB_OK)
        return fprintf(stderr, "%s\n", err.msg), 2;
    float(*bk)[3] = calloc(count, sizeof *bk);
    uint32_t tried = 0;
    if (vb_scene_place_lights(s, 1, count, bk, &tried, &err) != VB_OK)
        return fprintf(stderr, "%s\n", err.msg), 2;
    uint32_t same = 0, first = count;
    for (uint32_t i = 0; i < count && i < n; i++) {
        if (!memcmp(rt[i], bk[i], sizeof rt[i]))
            same++;
        else if (first == count)
            first = i;
    }
    printf("%s: region %s, diagonal %a (runtime) %a (bake); %u of %u pool positions equal\n",
           argv[1], grown ? "grown" : "bounds", (double)diag, (double)s->diagonal, same, count);
    if (first < count)
        printf("first difference: position %u, runtime candidate %u (%g %g %g), bake (%g %g "
               "%g); bake free at the runtime's: %d\n",
               first, rt_k[first], (double)rt[first][0], (double)rt[first][1], (double)rt[first][2],
               (double)bk[first][0], (double)bk[first][1], (double)bk[first][2],
               vb_scene_free_space(s, rt[first]));
    vb_scene_destroy(s);
    vdsh_view_tracer_destroy(t);
    vdsh_free(f);
    free(rt), free(rt_k), free(bk);
    return same == count ? 0 : 1;
}
