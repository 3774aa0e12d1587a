/*
 * scene.h - the occluder scene in Embree 3, in a normalised frame.
 *
 * Rays are traced in a frame where the occluders' bounding box is centred
 * on the origin and scaled by a power of two to about unit size:
 *     local = (p - centre) * scale,   distance = local distance / scale.
 * The power of two makes the scaling exact, and the centring keeps the
 * float coordinates small, so a scene translated to 1e5 or shrunk to 1e-4
 * is traced with the same relative precision as one at unit size, and the
 * ray-origin offset (Waechter & Binder, Ray Tracing Gems ch. 6, whose
 * constants assume unit-sized scenes) means the same thing in every scene.
 *
 * Does not: load meshes (mesh.h) or sample directions (sampling.h).
 *
 * Errors: vb_result; Embree's own error text is copied into the message.
 * Ownership: vb_scene_destroy frees a created scene and accepts NULL.
 * Threading: a created scene may be traced from any number of threads.
 */
#ifndef VB_SCENE_H
#define VB_SCENE_H

#include <embree3/rtcore.h>
#include <stdint.h>

#include "mesh.h"
#include "vb.h"
#include "vdsh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* robust 1: RTC_SCENE_FLAG_ROBUST (default 0); threads: Embree's build
 * threads (0: all cores). */
typedef struct vb_scene_desc {
    int robust;
    unsigned threads;
    /* 1: ray origins of corner receivers lifted further (vb_scene.corner_lift) */
    int corner_lift;
} vb_scene_desc;

/* The traced frame is (p - centre) * scale, scale a power of two; the
 * bounds and their diagonal are the occluders', in scene units. */
typedef struct vb_scene {
    RTCDevice device;
    RTCScene scene;
    float centre[3];
    float scale;
    float bounds_min[3], bounds_max[3];
    float diagonal;
    uint32_t vertex_count, triangle_count;
    /* The traced triangles (local frame), Embree's buffers, alive with the
     * scene: the free-space test measures its probes' hits on them itself. */
    const float *local_vertices;
    const unsigned *local_indices;
    /* A light region given by the user (vb_scene_set_light_region):
     * region_given 1, the box region_min..region_max; 0: the rule's. */
    int region_given;
    float region_min[3], region_max[3];
    char embree_error[256]; /* last Embree error reported on this device */
    /* 1 (a bake whose computed normals split at creases: vb_scene_desc):
     * the standard origin of a corner receiver - one with a receiver at
     * its bit-identical position whose normal differs - is offset
     * VB_CORNER_LIFT times as far (origins.h, "Corners"); 0: as any. */
    int corner_lift;
} vb_scene;

vb_result vb_scene_create(const vb_mesh *occluders, const vb_scene_desc *desc, vb_scene **out,
                          vb_error *err);
void vb_scene_destroy(vb_scene *s);

/* Scene units to the traced frame (a point, not a direction). */
static inline void vb_scene_to_local(const vb_scene *s, const float p[3], float out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = (p[i] - s->centre[i]) * s->scale;
}

/* A ray from o along d over [0, tfar] (traced frame), with no hit yet:
 * every field Embree reads is set. */
static inline void vb_ray_init(struct RTCRayHit *rh, const float o[3], const float d[3], float tfar,
                               unsigned id)
{
    rh->ray.org_x = o[0], rh->ray.org_y = o[1], rh->ray.org_z = o[2];
    rh->ray.dir_x = d[0], rh->ray.dir_y = d[1], rh->ray.dir_z = d[2];
    rh->ray.tnear = 0.0f, rh->ray.tfar = tfar, rh->ray.time = 0.0f;
    rh->ray.mask = 0xffffffffu, rh->ray.id = id, rh->ray.flags = 0;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

/* Ray k of a packet from o over [0, tfar] (traced frame), id k, with no
 * hit yet; its direction is the caller's to set. */
static inline void vb_ray16_init(struct RTCRayHit16 *rh, int k, const float o[3], float tfar)
{
    rh->ray.org_x[k] = o[0], rh->ray.org_y[k] = o[1], rh->ray.org_z[k] = o[2];
    rh->ray.tnear[k] = 0.0f, rh->ray.tfar[k] = tfar, rh->ray.time[k] = 0.0f;
    rh->ray.mask[k] = 0xffffffffu, rh->ray.id[k] = (unsigned)k, rh->ray.flags[k] = 0;
    rh->hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
}

/* A ray origin just off the surface at local point p along unit normal n
 * (Waechter & Binder): a few hundred ulps for coordinates above 1/32,
 * a fixed 2^-16 below, so the offset grows with the coordinates' float
 * spacing instead of being a fixed world distance. n = 0 leaves p. */
void vb_offset_origin(const float p[3], const float n[3], float out[3]);

/* `count` lights placed uniformly in the free space of scene s
 * (vdsh_light.h): the candidates of the sequence `seed` in the scene's
 * light region (vb_scene_light_region) that pass, in order. *tried (may be
 * NULL) gets how many candidates were drawn. Fails (VB_ERR_INVALID) when
 * vdsh_light_tries candidates are not enough (1000 per light in the
 * bounds; a few thousand in a grown region). */
vb_result vb_scene_place_lights(const vb_scene *s, uint64_t seed, uint32_t count, float (*out)[3],
                                uint32_t *tried, vb_error *err);

/* vb_scene_place_lights (no *tried), and whether its first `first` lights
 * (1 <= first <= count; out[0..first-1] whenever *first_ok) are those of
 * a placement of `first` lights with this seed that succeeds (*first_ok
 * 1): the candidates are one sequence, so a pool's first lights are a
 * smaller pool's, but the smaller one gives up sooner (vdsh_light_tries). */
vb_result vb_scene_place_pool(const vb_scene *s, uint64_t seed, uint32_t count, float (*out)[3],
                              uint32_t first, int *first_ok, vb_error *err);

/* The region lights are placed in (vdsh_light_region): the bounds, or,
 * when they hold too little free space (a closed object), the bounds grown
 * by up to a quarter of their diagonal, the less free space the more; or
 * the region given (vb_scene_set_light_region). Returns 1 when grown or
 * given (placements then try vdsh_light_tries(count, 1) candidates).
 * *probes (may be NULL): the candidates the rule tested (0 when given). */
int vb_scene_light_region(const vb_scene *s, float lo[3], float hi[3], uint32_t *probes);

/* Where the user says the lights go (vdsh-bake --light-region, or a file's
 * `lreg` chunk): every placement on s (the decision fit's pool and its
 * near lights, the calibration's, the cpca metric's, vdsh-eval's uniform
 * and near rules, vdsh-frames' lights and eyes) uses the box lo..hi
 * instead of the rule's region, still in free space. The box must be
 * finite with lo < hi on every axis (VB_ERR_ARGUMENT), and hold free
 * space: one of its first VDSH_REGION_PROBES candidates (seed
 * VDSH_REGION_SEED) at least (VB_ERR_INVALID). `what` names the box in
 * messages ("--light-region"). */
vb_result vb_scene_set_light_region(vb_scene *s, const float lo[3], const float hi[3],
                                    const char *what, vb_error *err);

/* The bounds of s grown on every side by VDSH_REGION_GROW of its
 * diagonal (in double, rounded once), but not on a side a one-sided
 * surface closes (below an open floor that spans the bounds:
 * vdsh_light_grown_box, its probes cast with Embree): the `grown` light
 * rule's box, and vdsh-bake --light-region grown's. Returns the mask of
 * closed sides. */
int vb_scene_grown_box(const vb_scene *s, float lo[3], float hi[3]);

/* A --light-region rule (tools/vt_cli.h's vt_opt_light_region: vdsh-bake,
 * vdsh-eval, vdsh-frames views) applied to s: rule 0 (auto) drops any region
 * for the scene's rule, whatever the file says; VDSH_LIGHT_REGION_GROWN sets
 * s's grown box (vb_scene_grown_box) and VDSH_LIGHT_REGION_BOX the box as
 * given, both through vb_scene_set_light_region (its errors, `what` naming
 * the option), the box set written into box on success (untouched on
 * failure); any other rule (a reader's `file`) keeps the region s has (the
 * file's `lreg`, vb_eval_scene_create). */
vb_result vb_scene_use_light_box(vb_scene *s, vdsh_light_box *box, const char *what, vb_error *err);

/* Other ways to place lights, for reports that a figure does not hang on
 * one light distribution (issue 25): all in free space, from the same
 * seeded candidates in the light region: uniform (vb_scene_place_lights),
 * near the ceiling (the top fifth of the region's height, +y up), near surfaces (a surface
 * within 5% of the diagonal along a probe direction), along a path (a
 * walk along x at two thirds of the height, swinging across z); and,
 * for lights around an object as a viewer puts them, outside the light
 * region: grown (uniform in the bounds grown by VDSH_REGION_GROW of
 * their diagonal, the bounds' inside too) and around (uniform in the
 * bounds grown by a whole diagonal, outside the bounds only: where
 * vdsh-view's default lights for an object stood, about 1.08 diagonals
 * from its centre) and shell (the bounds grown by VDSH_REGION_GROW of
 * their diagonal, outside the bounds only: vb_bake_desc.decision_shell's
 * training lights). Candidates tried, by every rule but uniform
 * (vdsh_light_place's): vdsh_light_tries(count, grown) at
 * most, and only the first vdsh_light_tries(1, grown) when those hold no
 * light at all (a rule that finds no room gives up early). */
typedef enum vb_light_rule {
    VB_LIGHTS_UNIFORM = 0,
    VB_LIGHTS_CEILING,
    VB_LIGHTS_NEAR,
    VB_LIGHTS_PATH,
    VB_LIGHTS_GROWN,
    VB_LIGHTS_AROUND,
    VB_LIGHTS_SHELL
} vb_light_rule;

vb_result vb_scene_place_lights_rule(const vb_scene *s, uint64_t seed, uint32_t count,
                                     vb_light_rule rule, float (*out)[3], uint32_t *tried,
                                     vb_error *err);
const char *vb_light_rule_name(vb_light_rule rule);
/* The rule of that name (vb_light_rule_name's), -1 when none is. */
int vb_light_rule_by_name(const char *name);

/* The nearest surface from p (scene units) along the VDSH_FREE_PROBES
 * probe directions of the free-space rule, INFINITY when none is met:
 * VB_LIGHTS_NEAR keeps a light when it is under 5% of the diagonal. */
float vb_scene_probe_nearest(const vb_scene *s, const float p[3]);

/* Whether p (scene units) is in the free space of scene s: vdsh_light.h's
 * rule, its probes cast with Embree. The test vb_scene_place_lights applies
 * to every candidate (vdsh-frames applies it to eyes too). Each probe's
 * distance and side are measured on the triangle Embree found, in double
 * arithmetic: the same under every Embree kernel set (docs/DESIGN.md,
 * "Across CPUs, decision by decision"). */
int vb_scene_free_space(const vb_scene *s, const float p[3]);

#ifdef __cplusplus
}
#endif

#endif /* VB_SCENE_H */
