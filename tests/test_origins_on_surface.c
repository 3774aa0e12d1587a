/*
 * test_origins_on_surface.c - no receiver ray of the bake starts on a
 * surface. Embree promises nothing of a hit at a ray's start (the free-space
 * probes start PROBE_BACK behind their point for it, bake/lib/scene.c); the
 * bake's receiver rays (traced, and the decision fit's training rays) and
 * vdsh-eval's vertex truth rays all start at vb_ray_origins' origins, which
 * are offset along the normal and then inset into the receiver's own
 * triangles (origins.h), so that none lies on an adjacent or coplanar face.
 *
 * Scenes where a vertex lies on another face's plane: an unwelded L
 * corner (a floor in two quads whose edges lie on a wall's foot), a thin
 * panel standing on a floor (a T junction), a lone flat quad and a unit
 * cube resting on a floor. For every receiver and 256 directions above its
 * horizon, a ray started 16 ulps behind the origin must meet no face
 * within 2 ulps of the origin (a face the ray from the origin could miss
 * at t = 0, or meet at 0: a self-hit), and the ray from the origin no face
 * nearer than that; with Embree's robust traversal (the bake's default)
 * and its fast one (--fast-traversal). The control: the same vertices
 * offset along the normal only (no inset) do put origins on the wall's
 * and the floor's planes in the L corner, the T junction and at the
 * cube's foot, where robust traversal meets the face at t ~ 0 (a shadow
 * at distance 0 above the horizon) and fast traversal misses it (measured
 * on Embree 3.13): the test sees the case it guards against. With a
 * creased bake's corner lift (scene.h corner_lift) the same holds, the L
 * corner's corner receivers are offset at least 8 times as far and every
 * other origin keeps its bits.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh.h"
#include "origins.h"
#include "scene.h"
#include "test_util.h"

#define DIRS 256

typedef struct counts {
    long receivers, rays;   /* receivers with a normal; upper rays cast */
    long at_face;           /* receivers with a face at the origin along some upper ray */
    long self_hits, misses; /* of those rays: the origin's ray met it at ~0, or not */
} counts;

/* Upper rays from each origin: faces within 2 ulps of it. */
static counts probe(const vb_scene *s, uint32_t n, const float *origins, const float *normals)
{
    counts c = {0};
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (uint32_t v = 0; v < n; v++) {
        const float *o = origins + 3 * (size_t)v, *nv = normals + 3 * (size_t)v;
        if (nv[0] == 0.0f && nv[1] == 0.0f && nv[2] == 0.0f)
            continue;
        c.receivers++;
        const float m = fmaxf(fabsf(o[0]), fmaxf(fabsf(o[1]), fabsf(o[2])));
        const float eps = fmaxf(16.0f * m * 1.1920929e-7f, 1e-9f), near = eps / 8.0f;
        int found = 0;
        for (int k = 0; k < DIRS; k++) {
            const double z = 1.0 - (k + 0.5) * 2.0 / DIRS, r = sqrt(1.0 - z * z);
            const double phi = k * 2.399963229728653;
            const float d[3] = {(float)(r * cos(phi)), (float)(r * sin(phi)), (float)z};
            if (d[0] * nv[0] + d[1] * nv[1] + d[2] * nv[2] <= 0.0f)
                continue;
            c.rays++;
            const float b[3] = {o[0] - eps * d[0], o[1] - eps * d[1], o[2] - eps * d[2]};
            struct RTCRayHit fw, bh;
            vb_ray_init(&fw, o, d, INFINITY, 0);
            rtcIntersect1(s->scene, &ctx, &fw);
            vb_ray_init(&bh, b, d, INFINITY, 0);
            rtcIntersect1(s->scene, &ctx, &bh);
            const int fw_near = fw.hit.geomID != RTC_INVALID_GEOMETRY_ID && fw.ray.tfar <= near;
            const int on =
                bh.hit.geomID != RTC_INVALID_GEOMETRY_ID && fabsf(bh.ray.tfar - eps) <= near;
            if (on || fw_near) {
                found = 1;
                c.self_hits += fw_near;
                c.misses += !fw_near;
            }
        }
        c.at_face += found;
    }
    return c;
}

typedef struct scene_case {
    const char *name, *obj;
    int control_on_face; /* the normal-only offset puts origins on faces */
} scene_case;

/* A creased bake's corners (scene.h corner_lift, origins.h "Corners"):
 * with the flag, no origin on a face either; a corner receiver (another
 * normal at its position) is offset at least 8 times as far from its
 * position as without it (VB_CORNER_LIFT: 16), every other one's origin is
 * the same bits. org, nrm: the origins and normals without the flag. */
static void corner_lift(const scene_case *sc, const vb_mesh *m, int robust, const float *org,
                        const float *nrm)
{
    const uint32_t n = m->vertex_count;
    vb_scene *s = NULL;
    vb_error err;
    vb_scene_desc sd = {.robust = robust, .threads = 1, .corner_lift = 1};
    float *lo = malloc(12 * (size_t)n + 4), *ln = malloc(12 * (size_t)n + 4);
    if (!lo || !ln || vb_scene_create(m, &sd, &s, &err) != VB_OK ||
        vb_receivers_prepare(m, s, 1, NULL, 0, 0, n, ln, NULL, lo, NULL, NULL, &err) != VB_OK) {
        CHECK(0, "%s, corner lift: %s", sc->name, s ? err.msg : "scene or memory");
    } else {
        const counts c = probe(s, n, lo, ln);
        CHECK(c.at_face == 0, "%s, corner lift: %ld receivers' origins on a face", sc->name,
              c.at_face);
        long corners = 0, short_lift = 0, moved_other = 0;
        for (uint32_t v = 0; v < n; v++) {
            int corner = 0;
            for (uint32_t u = 0; u < n && !corner; u++)
                corner = !memcmp(m->positions + 3 * (size_t)u, m->positions + 3 * (size_t)v, 12) &&
                         memcmp(nrm + 3 * (size_t)u, nrm + 3 * (size_t)v, 12);
            float p[3];
            vb_scene_to_local(s, m->positions + 3 * (size_t)v, p);
            double d0 = 0.0, d1 = 0.0;
            for (int i = 0; i < 3; i++) {
                d0 += ((double)org[3 * (size_t)v + i] - p[i]) * (org[3 * (size_t)v + i] - p[i]);
                d1 += ((double)lo[3 * (size_t)v + i] - p[i]) * (lo[3 * (size_t)v + i] - p[i]);
            }
            if (corner) {
                corners++;
                short_lift += !(d1 >= 64.0 * d0 && d0 > 0.0);
            } else {
                moved_other += memcmp(org + 3 * (size_t)v, lo + 3 * (size_t)v, 12) != 0;
            }
        }
        CHECK(short_lift == 0 && moved_other == 0,
              "%s, corner lift: %ld of %ld corners lifted less than 8 times as far; %ld other "
              "receivers moved",
              sc->name, short_lift, corners, moved_other);
        printf("%s, corner lift: %ld corners, origins on a face %ld\n", sc->name, corners,
               c.at_face);
    }
    vb_scene_destroy(s);
    free(lo);
    free(ln);
}

static void run_case(const scene_case *sc, int robust)
{
    vb_mesh m;
    vb_error err;
    memset(&m, 0, sizeof m);
    if (vb_mesh_load_memory(sc->obj, strlen(sc->obj), sc->name, NULL, &m, NULL, &err) != VB_OK) {
        CHECK(0, "%s: %s", sc->name, err.msg);
        return;
    }
    vb_scene *s = NULL;
    vb_scene_desc sd = {.robust = robust, .threads = 1};
    const uint32_t n = m.vertex_count;
    float *org = malloc(12 * (size_t)n + 4), *nrm = malloc(12 * (size_t)n + 4),
          *plain = malloc(12 * (size_t)n + 4);
    if (!org || !nrm || !plain || vb_scene_create(&m, &sd, &s, &err) != VB_OK ||
        vb_receivers_prepare(&m, s, 1, NULL, 0, 0, n, nrm, NULL, org, NULL, NULL, &err) != VB_OK) {
        CHECK(0, "%s: %s", sc->name, s ? err.msg : "scene or memory");
    } else {
        const counts bake = probe(s, n, org, nrm);
        CHECK(bake.receivers > 0 && bake.at_face == 0,
              "%s: %ld of %ld receivers' origins on a face (%ld upper rays met it at ~0, %ld "
              "missed it)",
              sc->name, bake.at_face, bake.receivers, bake.self_hits, bake.misses);
        /* The control: the position offset along the normal alone. */
        for (uint32_t v = 0; v < n; v++) {
            float p[3];
            vb_scene_to_local(s, m.positions + 3 * (size_t)v, p);
            vb_offset_origin(p, nrm + 3 * (size_t)v, plain + 3 * (size_t)v);
        }
        const counts ctl = probe(s, n, plain, nrm);
        if (sc->control_on_face)
            CHECK(ctl.at_face > 0, "%s: the control (normal offset only) put no origin on a face",
                  sc->name);
        printf("%s, %s traversal: %ld receivers, %ld upper rays: bake origins on a face %ld; "
               "normal offset only: %ld (%ld rays met it at ~0, %ld missed it)\n",
               sc->name, robust ? "robust" : "fast", bake.receivers, bake.rays, bake.at_face,
               ctl.at_face, ctl.self_hits, ctl.misses);
        corner_lift(sc, &m, robust, org, nrm);
    }
    vb_scene_destroy(s);
    vb_mesh_free(&m);
    free(org);
    free(nrm);
    free(plain);
}

int main(void)
{
    static const scene_case cases[] = {
        {"l_corner.obj",
         "v 0 0 0\nv 2 0 0\nv 2 0 4\nv 0 0 4\nv 4 0 0\nv 4 0 4\n"
         "v 0 0 0\nv 0 0 4\nv 0 3 4\nv 0 3 0\n"
         "f 1 4 3 2\nf 2 3 6 5\nf 7 10 9 8\n",
         1},
        {"t_junction.obj",
         "v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\nv -1 0 0\nv 1 0 0\nv 1 1 0\nv -1 1 0\n"
         "f 1 4 3 2\nf 5 6 7 8\n",
         1},
        {"flat_quad.obj", "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 4 3 2\n", 0},
        {"cube_on_floor.obj",
         "v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\n"
         "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nv 0 1 0\nv 1 1 0\nv 1 1 1\nv 0 1 1\n"
         "f 1 4 3 2\nf 9 12 11 10\nf 5 6 10 9\nf 6 7 11 10\nf 7 8 12 11\nf 8 5 9 12\n",
         1},
    };
    for (int robust = 1; robust >= 0; robust--) /* the bake's default, --fast-traversal */
        for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
            run_case(&cases[i], robust);
    return test_report("bake_origins_off_surfaces");
}
