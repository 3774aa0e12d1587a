#include "scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vdsh_light.h"
#include "vdsh_det.h"

static void on_embree_error(void *user, enum RTCError code, const char *str)
{
    vb_scene *s = user;
    snprintf(s->embree_error, sizeof s->embree_error, "Embree error %d: %s", (int)code,
             str ? str : "(no message)");
}

void vb_scene_destroy(vb_scene *s)
{
    if (!s)
        return;
    if (s->scene)
        rtcReleaseScene(s->scene);
    if (s->device)
        rtcReleaseDevice(s->device);
    free(s);
}

vb_result vb_scene_create(const vb_mesh *occ, const vb_scene_desc *desc, vb_scene **out,
                          vb_error *err)
{
    vb_scene_desc d = desc ? *desc : (vb_scene_desc){0};
    if (!occ || occ->triangle_count == 0)
        return vb_fail(err, VB_ERR_INVALID, "no occluder triangles");

    for (size_t i = 0; i < 3 * (size_t)occ->vertex_count; i++)
        if (!isfinite(occ->positions[i]))
            return vb_fail(err, VB_ERR_INVALID, "occluder vertex %zu has a non-finite coordinate",
                           i / 3);
    for (size_t i = 0; i < 3 * (size_t)occ->triangle_count; i++)
        if (occ->indices[i] >= occ->vertex_count)
            return vb_fail(err, VB_ERR_INVALID,
                           "occluder triangle %zu: index %u out of range (%u vertices)", i / 3,
                           occ->indices[i], occ->vertex_count);

    vb_scene *s = calloc(1, sizeof *s);
    if (!s)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    s->vertex_count = occ->vertex_count;
    s->corner_lift = d.corner_lift != 0;
    s->triangle_count = occ->triangle_count;
    vb_mesh_bounds(occ, s->bounds_min, s->bounds_max);
    double extent = 0.0;
    for (int i = 0; i < 3; i++) {
        double e = (double)s->bounds_max[i] - s->bounds_min[i];
        extent = fmax(extent, e);
        s->centre[i] = (float)(0.5 * ((double)s->bounds_min[i] + s->bounds_max[i]));
    }
    s->diagonal = vdsh_free_diagonal(s->bounds_min, s->bounds_max); /* the runtime's too */
    /* Largest power of two with extent * scale <= 2: local coordinates in
     * [-1, 1]. A zero extent (all points equal) keeps scale 1. */
    s->scale = 1.0f;
    if (extent > 0.0) {
        int e2;
        frexp(extent, &e2); /* extent = m * 2^e2, m in [0.5, 1) */
        s->scale = ldexpf(1.0f, 1 - e2);
    }

    /* VDSH_EMBREE_CONFIG is appended to Embree's device configuration
     * (rtcNewDevice), e.g. "isa=avx2": the tests run the hard cases under
     * every kernel set the CPU supports. */
    const char *extra = getenv("VDSH_EMBREE_CONFIG");
    char config[256];
    snprintf(config, sizeof config, "threads=%u,verbose=0%s%.200s", d.threads,
             extra && extra[0] ? "," : "", extra ? extra : "");
    s->device = rtcNewDevice(config);
    if (!s->device) {
        enum RTCError code = rtcGetDeviceError(NULL);
        vb_scene_destroy(s);
        return vb_fail(err, VB_ERR_EMBREE, "cannot create Embree device (error %d)", (int)code);
    }
    rtcSetDeviceErrorFunction(s->device, on_embree_error, s);

    s->scene = rtcNewScene(s->device);
    RTCGeometry geom = s->scene ? rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_TRIANGLE) : NULL;
    float *v = geom ? rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                              3 * sizeof(float), occ->vertex_count)
                    : NULL;
    unsigned *ix = v ? rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                               3 * sizeof(unsigned), occ->triangle_count)
                     : NULL;
    if (!ix) {
        if (geom)
            rtcReleaseGeometry(geom);
        vb_result r = vb_fail(err, VB_ERR_EMBREE, "cannot create the Embree scene: %s",
                              s->embree_error[0] ? s->embree_error : "unknown error");
        vb_scene_destroy(s);
        return r;
    }
    for (uint32_t i = 0; i < occ->vertex_count; i++)
        vb_scene_to_local(s, occ->positions + 3 * i, v + 3 * i);
    memcpy(ix, occ->indices, (size_t)occ->triangle_count * 3 * sizeof *ix);
    s->local_vertices = v;
    s->local_indices = ix;
    rtcCommitGeometry(geom);
    rtcAttachGeometry(s->scene, geom);
    rtcReleaseGeometry(geom);
    rtcSetSceneFlags(s->scene, (d.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE) |
                                   RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    rtcSetSceneBuildQuality(s->scene, RTC_BUILD_QUALITY_HIGH);
    rtcCommitScene(s->scene);
    if (s->embree_error[0]) {
        vb_result r = vb_fail(err, VB_ERR_EMBREE, "building the BVH failed: %s", s->embree_error);
        vb_scene_destroy(s);
        return r;
    }
    *out = s;
    return VB_OK;
}

void vb_offset_origin(const float p[3], const float n[3], float out[3])
{
    const float origin = 1.0f / 32.0f;
    const float float_scale = 1.0f / 65536.0f;
    const float int_scale = 256.0f;
    for (int i = 0; i < 3; i++) {
        int32_t of = (int32_t)(int_scale * n[i]);
        /* In unsigned arithmetic: -0 is INT_MIN as an int, and the signed
         * sum would overflow (the result is unused there, but undefined). */
        uint32_t bits;
        memcpy(&bits, &p[i], sizeof bits);
        bits += (uint32_t)(p[i] < 0.0f ? -of : of);
        float pi;
        memcpy(&pi, &bits, sizeof pi);
        out[i] = fabsf(p[i]) < origin ? p[i] + float_scale * n[i] : pi;
    }
}

/* ---- lights in free space (vdsh_light.h) ---- */

/* Embree promises nothing of a hit at the ray's start (rtcIntersect1: at
 * tnear it may be hit or missed; 3.13 misses it): a point on a face, as
 * every candidate of a flat scene's bounds is (a single quad, a flat
 * panel), saw none of it and was free, where the runtime's tracer
 * (vdsh_view_trace, t >= 0) meets it at 0: the two placed other lights
 * (tests/light_pool_agree). Each probe starts this far (local units, the
 * scene within [-1, 1]) behind the point; a face met before the point is
 * at distance 0, nearer than any clearance. */
#define PROBE_BACK 0x1p-16f

/* A probe's hit, measured on the triangle Embree found (primID) in plain
 * double arithmetic: its distance (scene units) and side do not depend on
 * the kernel set that found it. Embree's kernels round t and Ng each their
 * own way (FMA or not, lane order): a free-space decision - a probe at the
 * clearance, a grazing face's side - would hinge on those last bits.
 * Only which triangle a probe meets is Embree's. A hit the plane measure
 * cannot place (the ray along the plane) keeps Embree's t and side. */
static void probe_hit(const vb_scene *s, const float o[3], const float d[3], unsigned prim,
                      float tfar, float *t, int *back)
{
    const unsigned *ix = s->local_indices + 3 * (size_t)prim;
    const float *a = s->local_vertices + 3 * (size_t)ix[0];
    const float *b = s->local_vertices + 3 * (size_t)ix[1];
    const float *c = s->local_vertices + 3 * (size_t)ix[2];
    double e1[3], e2[3], n[3];
    for (int k = 0; k < 3; k++)
        e1[k] = (double)b[k] - a[k], e2[k] = (double)c[k] - a[k];
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    const double den = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
    const double num =
        n[0] * ((double)a[0] - o[0]) + n[1] * ((double)a[1] - o[1]) + n[2] * ((double)a[2] - o[2]);
    const double tt = den != 0.0 ? num / den : NAN;
    if (!isfinite(tt)) { /* along the plane: Embree's word, from the probe's start */
        *t = tfar > PROBE_BACK ? (tfar - PROBE_BACK) / s->scale : 0.0f;
        *back = 0;
        return;
    }
    *t = tt > 0.0 ? (float)(tt / s->scale) : 0.0f; /* met before o: o is on it */
    *back = den > 0.0;
}

/* The 14 probes from p (vdsh_free_probe_dirs): each one's hit distance
 * (scene units, INFINITY when it meets nothing) and side, by probe_hit. */
static void cast_probes(const vb_scene *s, const float p[3], float t[VDSH_FREE_PROBES],
                        int back[VDSH_FREE_PROBES])
{
    float dirs[VDSH_FREE_PROBES][3];
    vdsh_free_probe_dirs(dirs);
    float o[3];
    vb_scene_to_local(s, p, o);
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (int i = 0; i < VDSH_FREE_PROBES; i++) {
        struct RTCRayHit rh;
        float start[3];
        for (int a = 0; a < 3; a++)
            start[a] = o[a] - PROBE_BACK * dirs[i][a];
        vb_ray_init(&rh, start, dirs[i], INFINITY, 0);
        rtcIntersect1(s->scene, &ctx, &rh);
        t[i] = INFINITY, back[i] = 0;
        if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID)
            probe_hit(s, o, dirs[i], rh.hit.primID, rh.ray.tfar, &t[i], &back[i]);
    }
}

int vb_scene_free_space(const vb_scene *s, const float p[3])
{
    float t[VDSH_FREE_PROBES];
    int back[VDSH_FREE_PROBES];
    cast_probes(s, p, t, back);
    return vdsh_free_space(t, back, vdsh_free_clearance(s->diagonal));
}

float vb_scene_probe_nearest(const vb_scene *s, const float p[3])
{
    float t[VDSH_FREE_PROBES], best = INFINITY;
    int back[VDSH_FREE_PROBES];
    cast_probes(s, p, t, back);
    for (int i = 0; i < VDSH_FREE_PROBES; i++)
        best = t[i] < best ? t[i] : best;
    return best;
}

static int free_cb(const void *ctx, const float p[3])
{
    return vb_scene_free_space((const vb_scene *)ctx, p);
}

int vb_scene_light_region(const vb_scene *s, float lo[3], float hi[3], uint32_t *probes)
{
    if (s->region_given) {
        memcpy(lo, s->region_min, sizeof s->region_min);
        memcpy(hi, s->region_max, sizeof s->region_max);
        if (probes)
            *probes = 0;
        return 1;
    }
    return vdsh_light_region(s->bounds_min, s->bounds_max, free_cb, s, lo, hi, probes);
}

/* The bounds of s grown on every side by `share` of its diagonal. */
static void grow_bounds(const vb_scene *s, double share, float lo[3], float hi[3])
{
    const double g = share * (double)s->diagonal;
    for (int a = 0; a < 3; a++) {
        lo[a] = (float)((double)s->bounds_min[a] - g);
        hi[a] = (float)((double)s->bounds_max[a] + g);
    }
}

int vb_scene_grown_box(const vb_scene *s, float lo[3], float hi[3])
{
    return vdsh_light_grown_box(s->bounds_min, s->bounds_max, free_cb, s, lo, hi);
}

vb_result vb_scene_use_light_box(vb_scene *s, vdsh_light_box *box, const char *what, vb_error *err)
{
    if (box->rule == 0) { /* auto: the scene's rule, whatever the file says */
        s->region_given = 0;
        return VB_OK;
    }
    if (box->rule != VDSH_LIGHT_REGION_GROWN && box->rule != VDSH_LIGHT_REGION_BOX)
        return VB_OK; /* a reader's `file`: the region the scene has */
    vdsh_light_box b = *box;
    if (b.rule == VDSH_LIGHT_REGION_GROWN)
        vb_scene_grown_box(s, b.min, b.max);
    vb_result r = vb_scene_set_light_region(s, b.min, b.max, what, err);
    if (r == VB_OK)
        *box = b;
    return r;
}

vb_result vb_scene_set_light_region(vb_scene *s, const float lo[3], const float hi[3],
                                    const char *what, vb_error *err)
{
    int a = vdsh_light_box_bad_axis(lo, hi);
    if (a >= 0)
        return vb_fail(err, VB_ERR_ARGUMENT,
                       "%s: the box's %c is %g..%g: it must be finite, min below max", what,
                       "xyz"[a], (double)lo[a], (double)hi[a]);
    uint32_t k = 0;
    for (; k < VDSH_REGION_PROBES; k++) {
        float p[3];
        vdsh_light_candidate(lo, hi, VDSH_REGION_SEED, k, p);
        if (vb_scene_free_space(s, p))
            break;
    }
    if (k == VDSH_REGION_PROBES)
        return vb_fail(err, VB_ERR_INVALID,
                       "%s: no free space for lights in %g %g %g .. %g %g %g: none of %u points "
                       "tested there is outside the solids and %g or more from a surface",
                       what, (double)lo[0], (double)lo[1], (double)lo[2], (double)hi[0],
                       (double)hi[1], (double)hi[2], VDSH_REGION_PROBES,
                       (double)vdsh_free_clearance(s->diagonal));
    memcpy(s->region_min, lo, sizeof s->region_min);
    memcpy(s->region_max, hi, sizeof s->region_max);
    s->region_given = 1;
    return VB_OK;
}

/* Where the candidates went, for the messages. */
static const char *region_name(const vb_scene *s, int grown)
{
    if (s->region_given)
        return "the light region given (--light-region)";
    return grown ? "the scene's bounds grown by up to a quarter of their diagonal (too little "
                   "free space inside them)"
                 : "the scene's bounds";
}

const char *vb_light_rule_name(vb_light_rule rule)
{
    static const char *const names[] = {"uniform", "ceiling", "near", "path",
                                        "grown",   "around",  "shell"};
    return (unsigned)rule < sizeof names / sizeof names[0] ? names[rule] : "?";
}

int vb_light_rule_by_name(const char *name)
{
    for (int k = VB_LIGHTS_UNIFORM; k <= VB_LIGHTS_SHELL; k++)
        if (strcmp(name, vb_light_rule_name((vb_light_rule)k)) == 0)
            return k;
    return -1;
}

vb_result vb_scene_place_lights_rule(const vb_scene *s, uint64_t seed, uint32_t count,
                                     vb_light_rule rule, float (*out)[3], uint32_t *tried,
                                     vb_error *err)
{
    if ((unsigned)rule > VB_LIGHTS_SHELL)
        return vb_fail(err, VB_ERR_ARGUMENT, "unknown light rule %d", (int)rule);
    if (rule == VB_LIGHTS_UNIFORM) /* the runtime's placement too */
        return vb_scene_place_lights(s, seed, count, out, tried, err);
    float lo[3], hi[3];
    int grown = vb_scene_light_region(s, lo, hi, NULL);
    if (rule == VB_LIGHTS_GROWN)
        vb_scene_grown_box(s, lo, hi);
    else if (rule == VB_LIGHTS_AROUND || rule == VB_LIGHTS_SHELL) {
        /* Outside the bounds, but not beyond a side a one-sided surface
         * closes (vdsh_light_grown_box's rule: below an open floor, lights
         * light none of what a viewer sees and shadow everything). */
        float glo[3], ghi[3];
        const int closed = vb_scene_grown_box(s, glo, ghi);
        grow_bounds(s, rule == VB_LIGHTS_AROUND ? 1.0 : (double)VDSH_REGION_GROW, lo, hi);
        for (int a = 0; a < 3; a++) {
            if (closed >> (2 * a) & 1)
                lo[a] = s->bounds_min[a];
            if (closed >> (2 * a + 1) & 1)
                hi[a] = s->bounds_max[a];
        }
    }
    grown |= rule >= VB_LIGHTS_GROWN;
    uint32_t n = 0, k = 0;
    const uint64_t limit = vdsh_light_tries(count, grown);
    /* A rule whose first light's share of the candidates holds none gives
     * up there: a lone panel's region is its plane, where the near rule
     * never holds (no probe meets the panel edge-on), and the bake's
     * decision pool of 2048 near lights spent 2M candidates, 3-5 s, on a
     * single triangle. A rule that finds room finds it in far fewer. */
    const uint64_t first = vdsh_light_tries(1, grown);
    while (n < count && k < limit && (n > 0 || k < first)) {
        float p[3];
        vdsh_light_candidate(lo, hi, seed, k++, p);
        float u = hi[1] > lo[1] ? (p[1] - lo[1]) / (hi[1] - lo[1]) : 0.5f;
        if (rule == VB_LIGHTS_CEILING) { /* the top fifth of the height (+y up) */
            p[1] = lo[1] + (0.8f + 0.2f * u) * (hi[1] - lo[1]);
        } else if (rule == VB_LIGHTS_PATH) {
            /* a walk along x at two thirds of the height, swinging across z */
            float t = hi[0] > lo[0] ? (p[0] - lo[0]) / (hi[0] - lo[0]) : 0.5f;
            p[1] = lo[1] + 0.66f * (hi[1] - lo[1]);
            p[2] = 0.5f * (lo[2] + hi[2]) +
                   0.3f * (hi[2] - lo[2]) * (float)vdsh_det_sin(6.2831853f * t);
        }
        if ((rule == VB_LIGHTS_AROUND || rule == VB_LIGHTS_SHELL) && p[0] >= s->bounds_min[0] &&
            p[0] <= s->bounds_max[0] && p[1] >= s->bounds_min[1] && p[1] <= s->bounds_max[1] &&
            p[2] >= s->bounds_min[2] && p[2] <= s->bounds_max[2])
            continue;
        if (!vb_scene_free_space(s, p))
            continue;
        if (rule == VB_LIGHTS_NEAR && !(vb_scene_probe_nearest(s, p) < 0.05f * s->diagonal))
            continue;
        memcpy(out[n++], p, sizeof out[0]);
    }
    if (tried)
        *tried = k;
    if (n < count)
        return vb_fail(err, VB_ERR_INVALID,
                       "no room for %u light%s by rule %s: %u found in %u "
                       "candidate%s in %s",
                       count, vdsh_s(count), vb_light_rule_name(rule), n, k, vdsh_s(k),
                       rule >= VB_LIGHTS_GROWN ? "the bounds grown for the rule"
                                               : region_name(s, grown));
    return VB_OK;
}

static vb_result place_uniform(const vb_scene *s, uint64_t seed, uint32_t count, float (*out)[3],
                               uint32_t *tried, uint32_t first, int *first_ok, vb_error *err)
{
    /* Give up when a thousand candidates per light find no room: a scene
     * without free space (a solid, or everything closer than clearance). */
    float lo[3], hi[3];
    const int grown = vb_scene_light_region(s, lo, hi, NULL);
    uint32_t k = 0, *at = NULL; /* with first_ok: each light's candidate */
    if (first_ok && !(at = malloc(sizeof *at * (size_t)count + 1)))
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for %u lights", count);
    const uint32_t n = vdsh_light_place(lo, hi, grown, seed, count, free_cb, s, out, at, &k);
    if (first_ok) /* placing `first` stops at its last light, if in time */
        *first_ok = first >= 1 && n >= first && at[first - 1] < vdsh_light_tries(first, grown);
    free(at);
    if (tried)
        *tried = k;
    if (n < count)
        return vb_fail(err, VB_ERR_INVALID,
                       "no free space for lights: %u of %u candidate%s in %s "
                       "%s inside solids or nearer than %g to a surface",
                       k - n, k, vdsh_s(k), region_name(s, grown), k - n == 1 ? "was" : "were",
                       (double)vdsh_free_clearance(s->diagonal));
    return VB_OK;
}

vb_result vb_scene_place_lights(const vb_scene *s, uint64_t seed, uint32_t count, float (*out)[3],
                                uint32_t *tried, vb_error *err)
{
    return place_uniform(s, seed, count, out, tried, 0, NULL, err);
}

vb_result vb_scene_place_pool(const vb_scene *s, uint64_t seed, uint32_t count, float (*out)[3],
                              uint32_t first, int *first_ok, vb_error *err)
{
    return place_uniform(s, seed, count, out, NULL, first, first_ok, err);
}
