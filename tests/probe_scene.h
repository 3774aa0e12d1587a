/*
 * probe_scene.h - what the probe programs (light_region_probe,
 * object_rule_probe) share: the scene of a mesh as vdsh-bake builds it,
 * and Embree's own distances along the free-space probes (vdsh_light.h).
 */
#ifndef VDSH_PROBE_SCENE_H
#define VDSH_PROBE_SCENE_H

#include <math.h>
#include <stdio.h>

#include "mesh.h"
#include "scene.h"
#include "vdsh_light.h"

/* The scene of the mesh at `path`, loaded into *m, with the robust
 * traversal (vdsh-bake's default); NULL after a message naming `prog` and
 * what failed (*m then freed). */
static inline vb_scene *probe_scene(const char *prog, const char *path, vb_mesh *m)
{
    vb_error err;
    vb_load_desc ld = {0};
    if (vb_mesh_load(path, &ld, m, NULL, &err) != VB_OK) {
        fprintf(stderr, "%s: %s\n", prog, err.msg);
        return NULL;
    }
    vb_scene *s = NULL;
    vb_scene_desc sd = {.robust = 1};
    if (vb_scene_create(m, &sd, &s, &err) != VB_OK) {
        fprintf(stderr, "%s: %s\n", prog, err.msg);
        vb_mesh_free(m);
        return NULL;
    }
    return s;
}

/* Embree's own hit distance along each free-space probe from p (the
 * scene's local units; INFINITY where the probe meets nothing). The
 * free-space test measures its hits itself (bake/lib/scene.c probe_hit):
 * these are what differ between Embree's kernel sets. */
static inline void probe_embree_t(const vb_scene *s, const float p[3], float t[VDSH_FREE_PROBES])
{
    float dirs[VDSH_FREE_PROBES][3], o[3];
    vdsh_free_probe_dirs(dirs);
    vb_scene_to_local(s, p, o);
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (int i = 0; i < VDSH_FREE_PROBES; i++) {
        struct RTCRayHit rh = {.ray = {.org_x = o[0],
                                       .org_y = o[1],
                                       .org_z = o[2],
                                       .dir_x = dirs[i][0],
                                       .dir_y = dirs[i][1],
                                       .dir_z = dirs[i][2],
                                       .tfar = INFINITY,
                                       .mask = 0xffffffffu},
                               .hit = {.geomID = RTC_INVALID_GEOMETRY_ID}};
        rtcIntersect1(s->scene, &ctx, &rh);
        t[i] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? INFINITY : rh.ray.tfar;
    }
}

#endif
