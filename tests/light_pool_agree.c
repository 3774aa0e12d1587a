/*
 * light_pool_agree SCENE.vdsh [COUNT]: the light pool vdsh-view places
 * (runtime/vr_view.c vr_scene_place_pool, called here: vdsh_light_region,
 * then vdsh_light_place, the candidates of vdsh_light_candidate seed 1
 * that pass vdsh_view_free_space, formats/vdsh_scene_view.c's grid
 * tracer) against
 * the bake side's placement with the same seed (bake/lib/scene.c
 * vb_scene_place_lights: the same region and candidates, vdsh_free_space
 * on Embree's probes measured in double), both on the file's receiver
 * mesh. Prints how many of COUNT (default 64) positions are equal bit for
 * bit, and the first that differs with its candidates' probe distances
 * against the clearance. Exit 0 when every position and the diagonal
 * (vdsh_free_diagonal: the clearance) are the same, 1 when one differs
 * (or the runtime places fewer), 2 on an error.
 * They agree on every scene tried but one kind: coincident faces of
 * opposite sides (a concave polygon fanned into overlapping triangles):
 * which of two faces at the same distance a probe meets is each tracer's
 * own tie, and the two see a front or a back there. A point on a face (a
 * flat scene's candidates) is on it for both (bake/lib/scene.c,
 * PROBE_BACK).
 * light_pool_agree --pockets OUT.obj H: writes the pocket scene below.
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
#include "vr_internal.h"

/* A scene whose free space is small pockets (inward-facing boxes of half
 * size h, in a solid unit cube) around the first VDSH_REGION_PROBES
 * candidates of the region test: the region stays the bounds (most of
 * those candidates are free), while about one candidate in several hundred
 * of the placement's own sequence is, so that a pool giving up at 256
 * per light (the runtime's before) placed fewer than the bake's 1000. */
static int write_pockets(const char *path, float h)
{
    FILE *fp = fopen(path, "w");
    if (!fp)
        return fprintf(stderr, "%s: cannot write\n", path), 2;
    static const float corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                       {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    /* the outer cube, faces outward (counter-clockwise seen from outside) */
    static const int faces[6][4] = {{1, 4, 3, 2}, {5, 6, 7, 8}, {1, 2, 6, 5},
                                    {3, 4, 8, 7}, {2, 3, 7, 6}, {1, 5, 8, 4}};
    const float lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    float(*c)[3] = calloc(VDSH_REGION_PROBES, sizeof *c);
    uint32_t n = 0, base = 0;
    for (int v = 0; v < 8; v++)
        fprintf(fp, "v %g %g %g\n", corner[v][0], corner[v][1], corner[v][2]);
    for (int f = 0; f < 6; f++)
        fprintf(fp, "f %d %d %d %d\n", faces[f][0], faces[f][1], faces[f][2], faces[f][3]);
    base = 8;
    for (uint32_t k = 0; k < VDSH_REGION_PROBES; k++) {
        float p[3];
        vdsh_light_candidate(lo, hi, VDSH_REGION_SEED, k, p);
        int ok = 1;
        for (int a = 0; a < 3; a++)
            ok &= p[a] > 2 * h && p[a] < 1 - 2 * h;
        for (uint32_t j = 0; ok && j < n; j++)
            ok = fabsf(p[0] - c[j][0]) > 3 * h || fabsf(p[1] - c[j][1]) > 3 * h ||
                 fabsf(p[2] - c[j][2]) > 3 * h;
        if (!ok)
            continue;
        memcpy(c[n++], p, sizeof p);
        for (int v = 0; v < 8; v++)
            fprintf(fp, "v %.9g %.9g %.9g\n", p[0] + (2 * corner[v][0] - 1) * h,
                    p[1] + (2 * corner[v][1] - 1) * h, p[2] + (2 * corner[v][2] - 1) * h);
        /* faces inward: the outer cube's reversed */
        for (int f = 0; f < 6; f++)
            fprintf(fp, "f %u %u %u %u\n", base + faces[f][3], base + faces[f][2],
                    base + faces[f][1], base + faces[f][0]);
        base += 8;
    }
    free(c);
    if (fclose(fp) != 0)
        return fprintf(stderr, "%s: cannot write\n", path), 2;
    fprintf(stderr, "%s: %u pockets\n", path, n);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 4 && strcmp(argv[1], "--pockets") == 0)
        return write_pockets(argv[2], (float)atof(argv[3]));
    if (argc < 2)
        return fprintf(stderr, "usage: light_pool_agree SCENE.vdsh [COUNT]\n"), 2;
    uint32_t count = argc > 2 ? (uint32_t)atoi(argv[2]) : 64u;
    vdsh_file *f = NULL;
    vdsh_error ve;
    if (vdsh_read(argv[1], &f, &ve) != VDSH_OK)
        return fprintf(stderr, "%s\n", ve.msg), 2;
    const vdsh_header *h = &f->header;
    /* the runtime's pool */
    float region[6];
    vdsh_view_mesh vm;
    vdsh_view_file_mesh(f, region, &vm);
    float lo[3], hi[3];
    vdsh_view_bounds(f->positions, h->vertex_count, lo, hi);
    const float diag = vdsh_free_diagonal(lo, hi);
    vdsh_view_tracer *t = NULL;
    if (vdsh_view_tracer_create(&vm, &t, &ve) != VDSH_OK)
        return fprintf(stderr, "%s\n", ve.msg), 2;
    vdsh_view_free_ctx vf = {t, diag};
    float rlo[3], rhi[3];
    const int grown = vdsh_light_region(lo, hi, vdsh_view_is_free, &vf, rlo, rhi, NULL);
    float(*rt)[3] = calloc(count, sizeof *rt);
    uint32_t *rt_k = calloc(count, sizeof *rt_k);
    uint32_t n =
        vdsh_light_place(rlo, rhi, grown, 1, count, vdsh_view_is_free, &vf, rt, rt_k, NULL);
    /* ... and the runtime's own (vr_scene_place_pool, what vdsh-view's
     * --light-pool draws) on the same bounds: the same positions. */
    if (count > VR_MAX_POOL_LIGHTS)
        return fprintf(stderr, "COUNT above the runtime's %d\n", VR_MAX_POOL_LIGHTS), 2;
    vr_scene *vs = calloc(1, sizeof *vs);
    vr_error vre;
    memcpy(vs->bounds_min, lo, sizeof lo);
    memcpy(vs->bounds_max, hi, sizeof hi);
    if (vr_scene_place_pool(vs, &vm, (int)count, argv[1], &vre) != VR_OK)
        return fprintf(stderr, "%s\n", vre.msg), 2;
    if ((uint32_t)vs->pool_count != n || memcmp(vs->pool, rt, n * sizeof *rt) != 0) {
        printf("%s: the runtime's pool (%d positions) is not the rule's (%u)\n", argv[1],
               vs->pool_count, n);
        n = (uint32_t)vs->pool_count < n ? (uint32_t)vs->pool_count : n;
        memcpy(rt, vs->pool, n * sizeof *rt);
    }
    free(vs);
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
    uint32_t within256 = 0; /* what a pool giving up at 256 per light (before) placed */
    for (uint32_t i = 0; i < n; i++)
        within256 += rt_k[i] < 256u * count;
    printf("%s: region %s, diagonal %a (runtime) %a (bake); %u of %u pool positions equal "
           "(runtime %u placed, %u of them within 256 candidates per light; bake tried %u)\n",
           argv[1], grown ? "grown" : "bounds", (double)diag, (double)s->diagonal, same, count, n,
           within256, tried);
    if (first < count)
        printf("first difference: position %u, runtime candidate %u (%g %g %g), bake (%g %g "
               "%g); bake free at the runtime's: %d\n",
               first, rt_k[first], (double)rt[first][0], (double)rt[first][1], (double)rt[first][2],
               (double)bk[first][0], (double)bk[first][1], (double)bk[first][2],
               vb_scene_free_space(s, rt[first]));
    if (diag != s->diagonal)
        printf("%s: the runtime's diagonal is not the bake's\n", argv[1]);
    const int agree = same == count && diag == s->diagonal;
    vb_scene_destroy(s);
    vdsh_view_tracer_destroy(t);
    vdsh_free(f);
    free(rt), free(rt_k), free(bk);
    return agree ? 0 : 1;
}
