/*
 * vr_view.c - a scene's default view (vr.h): thin wrappers of
 * formats/vdsh_scene_view.h, which decides at load (vr_scene_create) from
 * the mesh whether the scene is a room or an object, its camera, and
 * default lights moved into free space; the bake side's tools
 * (vdsh-frames) compute the same view from the same .vdsh mesh. And the
 * light pool, many lights in free space for benchmarks (vr_scene_pool_lights),
 * placed at load only when asked for: a second grid of the triangles.
 *
 * Load cost, one core: the interior test's 128 rays and the lights'
 * free-space probes (14 rays per position tried) run against a uniform
 * grid of the triangles, about 2 us a ray where testing every triangle
 * took 0.3-2 ms. Measured on the two-core test machine (noisy): Lost
 * Empire (225,000 triangles, 394 light positions tried) 45-65 ms, most of
 * it building the grid; the paper-sized room (113,000) 18-23 ms; Sponza
 * 10-14 ms. Testing every triangle, the interior test alone took 60-160 ms
 * on these scenes, and each light position tried would add 4-30 ms.
 */
#include "vr_internal.h"

#include "vdsh_light.h"

#include <math.h>
#include <string.h>

static void from_vdsh(const vdsh_camera *c, vr_camera *out)
{
    vr_camera cam;
    memset(&cam, 0, sizeof cam);
    memcpy(cam.eye, c->eye, sizeof cam.eye);
    memcpy(cam.target, c->target, sizeof cam.target);
    memcpy(cam.up, c->up, sizeof cam.up);
    cam.fov_y = c->fov_y;
    *out = cam;
}

void vr_scene_default_camera(const vr_scene *s, vr_camera *out)
{
    from_vdsh(&s->view.camera, out);
}

void vr_scene_fit_camera(const vr_scene *s, vr_camera *out)
{
    from_vdsh(&s->view.fit, out);
}

int vr_scene_default_lights(const vr_scene *s, vr_light *out, int max)
{
    int n = 0;
    for (; n < max && n < s->view.light_count; n++) {
        memset(&out[n], 0, sizeof out[n]);
        memcpy(out[n].position, s->view.lights[n], sizeof out[n].position);
    }
    return n;
}

/* The light pool: candidates of the seeded uniform sequence in the
 * bounds, kept when in free space (vdsh_light.h), in sequence order. */
vr_result vr_scene_place_pool(vr_scene *s, const vdsh_view_mesh *m, int count, const char *name,
                              vr_error *err)
{
    vdsh_view_tracer *t = NULL;
    vdsh_error ve;
    if (vdsh_view_tracer_create(m, &t, &ve) != VDSH_OK)
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: light pool: %s", name, ve.msg);
    const float diag = vdsh_free_diagonal(s->bounds_min, s->bounds_max); /* the bake's */
    s->pool_count = 0;
    vdsh_view_free_ctx c = {t, diag};
    float lo[3], hi[3];
    int grown = 1;
    if (m->light_region) { /* the file's (lreg): where the bake's lights went */
        memcpy(lo, m->light_region, sizeof lo);
        memcpy(hi, m->light_region + 3, sizeof hi);
    } else {
        grown =
            vdsh_light_region(s->bounds_min, s->bounds_max, vdsh_view_is_free, &c, lo, hi, NULL);
    }
    /* The bake side's placement, limit included (vdsh_light_tries: it
     * gave up here at 256 candidates per light, the baker at 1000). */
    s->pool_count = (int)vdsh_light_place(lo, hi, grown, 1, (uint32_t)count, vdsh_view_is_free, &c,
                                          s->pool, NULL, NULL);
    vdsh_view_tracer_destroy(t);
    return VR_OK;
}

int vr_scene_pool_lights(const vr_scene *s, vr_light *out, int max)
{
    int n = 0;
    for (; n < max && n < s->pool_count; n++) {
        memset(&out[n], 0, sizeof out[n]);
        memcpy(out[n].position, s->pool[n], sizeof out[n].position);
    }
    return n;
}
