/*
 * test_runtime_log.c - log-distance streams on large triangles, drawn by
 * the runtime's distance path.
 *
 * The scene (argv[1], baked by a CTest fixture with vdsh-bake --method lsq
 * --log --cube-size 0): a 20 x 20 floor of two triangles, so that almost
 * every floor fragment is metres from the nearest vertex, and a box
 * hovering just above one corner A of the floor. Seen from A the box
 * fills most of the sky, seen from the other three corners almost none.
 *
 * Interpolating log-distance coefficients across a floor triangle is a
 * geometric mean of the corners' distances, which A's short ones drag
 * down: a wide dark smear that nothing casts. Interpolating the corners'
 * distances toward the light (vdsh_shadow_interior, DISTANCE) does not.
 * For every floor fragment far from the corners, in every VDSH mode
 * (orders 2, 3, 5) and both comparisons, the test checks:
 *   - the GPU against vdsh_shadow_interior on the path
 *     vdsh_runtime_interp gives (DISTANCE), to rounding;
 *   - that fragments exist where the two interpolations differ by more
 *     than 0.5 in visibility, and the GPU is on the distance side there;
 *   - against the truth (the box is axis-aligned: an exact ray-box test),
 *     the distance path's shadow error is below that of interpolated
 *     coefficients.
 * The scene loads without cubemaps (none were baked) in every mode.
 */
#include "test_runtime_util.h"

enum { PX = 160 };

/* Distance from p along unit w to the axis-aligned box [lo, hi], or
 * INFINITY when the ray misses it. */
static float ray_box(const float p[3], const float w[3], const float lo[3], const float hi[3])
{
    float t0 = 0.0f, t1 = INFINITY;
    for (int k = 0; k < 3; k++) {
        if (fabsf(w[k]) < 1e-12f) {
            if (p[k] < lo[k] || p[k] > hi[k])
                return INFINITY;
            continue;
        }
        float a = (lo[k] - p[k]) / w[k], b = (hi[k] - p[k]) / w[k];
        t0 = fmaxf(t0, fminf(a, b));
        t1 = fminf(t1, fmaxf(a, b));
    }
    return t0 <= t1 ? t0 : INFINITY;
}

/* Barycentrics of (x, z) in the floor triangle t (y = 0). */
static void floor_bary(const vdsh_file *f, uint32_t t, float x, float z, float b[3])
{
    const float *a = f->positions + 3 * f->indices[3 * t];
    const float *bb = f->positions + 3 * f->indices[3 * t + 1];
    const float *c = f->positions + 3 * f->indices[3 * t + 2];
    float d = (bb[0] - a[0]) * (c[2] - a[2]) - (c[0] - a[0]) * (bb[2] - a[2]);
    b[1] = ((x - a[0]) * (c[2] - a[2]) - (c[0] - a[0]) * (z - a[2])) / d;
    b[2] = ((bb[0] - a[0]) * (z - a[2]) - (x - a[0]) * (bb[2] - a[2])) / d;
    b[0] = 1.0f - b[1] - b[2];
}

typedef struct tally {
    long far, bad, differ, wrong_side;
    double err_gpu, err_coef;
} tally;

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_runtime_log FLOOR.vdsh\n");
        return 2;
    }
    vr_context *ctx = rt_context_or_skip("test_runtime_log");
    vdsh_file *f = NULL;
    vdsh_error ve;
    if (vdsh_read(argv[1], &f, &ve) != VDSH_OK) {
        fprintf(stderr, "%s\n", ve.msg);
        return 1;
    }
    const vdsh_header *h = &f->header;

    /* The floor: the triangles with every vertex at y = 0; the box: the
     * bounds of every other vertex (the receivers are the mesh's). */
    uint32_t floor_tri[4], nfloor = 0;
    float box_lo[3] = {INFINITY, INFINITY, INFINITY}, box_hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t t = 0; t < h->triangle_count; t++) {
        int flat = 1;
        for (int k = 0; k < 3; k++)
            flat = flat && f->positions[3 * f->indices[3 * t + k] + 1] == 0.0f;
        if (flat && nfloor < 4)
            floor_tri[nfloor++] = t;
    }
    for (uint32_t v = 0; v < h->vertex_count; v++)
        if (f->positions[3 * v + 1] > 0.0f)
            for (int k = 0; k < 3; k++) {
                box_lo[k] = fminf(box_lo[k], f->positions[3 * v + k]);
                box_hi[k] = fmaxf(box_hi[k], f->positions[3 * v + k]);
            }
    CHECK(nfloor == 2 && box_lo[1] > 0.0f, "the scene is not a two-triangle floor and a box: %u",
          nfloor);

    vr_scene *s = NULL;
    vr_renderer *r = NULL;
    vr_error err;
    vr_scene_desc sd = {.path = argv[1]};
    CHECK(vr_scene_create(&sd, &s, &err) == VR_OK, "%s", err.msg);
    vr_renderer_desc rd = {.width = PX, .height = PX, .color_format = VR_COLOR_RGBA32F};
    CHECK(vr_renderer_create(&rd, &r, &err) == VR_OK, "%s", err.msg);
    if (!s || !r || nfloor != 2) {
        vr_scene_destroy(s);
        vr_renderer_destroy(r);
        vdsh_free(f);
        vr_context_destroy(ctx);
        return test_report("test_runtime_log");
    }
    vr_scene_info info;
    vr_scene_get_info(s, &info);
    CHECK(info.quantity == VDSH_QUANTITY_LOG_DISTANCE && !info.has_cubemaps,
          "quantity %s, cubemaps %d", vdsh_quantity_name(info.quantity), info.has_cubemaps);

    /* Looking straight down at the whole floor. */
    vr_light light = {0};
    vr_draw_desc view = {.lights = &light, .light_count = 1};
    view.camera.eye[1] = 30.0f;
    view.camera.up[2] = -1.0f;
    view.camera.ortho_height = 20.5f;
    vr_draw_desc d = view;
    d.mode = VR_MODE_NONE;
    d.output = VR_OUTPUT_POSITION;
    rt_draw_or_die(r, s, &d);
    float *pos = rt_read(r, PX, PX);

    /* Lights: high over the middle, and low near the box. */
    static const float lights[2][3] = {{0.0f, 3.0f, 0.0f}, {-5.0f, 1.5f, -4.0f}};
    static const vr_mode modes[4] = {VR_MODE_VDSH2, VR_MODE_VDSH3, VR_MODE_VDSH5,
                                     VR_MODE_VDSH5_POLY};
    static const int mode_order[4] = {2, 3, 5, 5};
    for (int li = 0; li < 2; li++)
        for (int m = 0; m < 4; m++)
            for (uint32_t cmp = 0; cmp < 2; cmp++) {
                int order = mode_order[m];
                uint32_t q = VDSH_QUANTITY_LOG_DISTANCE;
                uint32_t interp = vdsh_runtime_interp((uint32_t)order, q);
                const vdsh_stream *st = vdsh_find_stream(f, (uint32_t)order, q);
                CHECK(st && interp == VDSH_INTERP_DISTANCE, "order %d: no log-distance stream",
                      order);
                if (!st)
                    continue;
                memcpy(light.position, lights[li], sizeof light.position);
                d = view;
                d.mode = modes[m];
                d.compare = cmp;
                d.output = VR_OUTPUT_SHADOW;
                rt_draw_or_die(r, s, &d);
                float *px = rt_read(r, PX, PX);
                tally t;
                memset(&t, 0, sizeof t);
                for (int k = 0; k < PX * PX; k++) {
                    const float *p = pos + 4 * k, *g = px + 4 * k;
                    if (p[3] != 1.0f || p[1] != 0.0f)
                        continue; /* the box, or nothing */
                    /* the floor triangle under the fragment */
                    uint32_t tri = UINT32_MAX;
                    float b[3];
                    for (uint32_t i = 0; i < nfloor && tri == UINT32_MAX; i++) {
                        floor_bary(f, floor_tri[i], p[0], p[2], b);
                        if (b[0] >= -1e-5f && b[1] >= -1e-5f && b[2] >= -1e-5f)
                            tri = floor_tri[i];
                    }
                    if (tri == UINT32_MAX)
                        continue;
                    float c[3][25];
                    const float *cp[3], *pv[3];
                    float near = INFINITY;
                    for (int v = 0; v < 3; v++) {
                        uint32_t vi = f->indices[3 * tri + v];
                        vdsh_stream_decode(st, vi, c[v]);
                        cp[v] = c[v];
                        pv[v] = f->positions + 3 * vi;
                        float dx = p[0] - pv[v][0], dz = p[2] - pv[v][2];
                        near = fminf(near, sqrtf(dx * dx + dz * dz));
                    }
                    if (near < 4.0f)
                        continue; /* only fragments far from every vertex */
                    float dv;
                    float s_dist = vdsh_shadow_interior((uint32_t)order, q, h->max_distance, interp,
                                                        cp, pv, b, lights[li], cmp, &dv);
                    float sc = vdsh_shadow_interior((uint32_t)order, q, h->max_distance,
                                                    VDSH_INTERP_COEFFICIENTS, cp, pv, b, lights[li],
                                                    cmp, NULL);
                    /* the truth: the box toward the light, or nothing */
                    float w[3] = {lights[li][0] - p[0], lights[li][1] - p[1], lights[li][2] - p[2]};
                    float dl = sqrtf(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
                    for (int a = 0; a < 3; a++)
                        w[a] /= dl;
                    float st_true = vdsh_shadow_compare(ray_box(p, w, box_lo, box_hi), dl, cmp);
                    t.far++;
                    /* GPU against the definition: float rounding of a
                     * 25-term sum and its exp, and of the interpolation */
                    int tie = cmp == VDSH_COMPARE_BINARY && fabsf(dv - dl) <= 1e-3f * dl;
                    int ok =
                        fabsf(g[1] - dv) <= 1e-4f * dv + 1e-6f && fabsf(g[2] - dl) <= 1e-5f * dl;
                    if (!tie)
                        ok = ok && fabsf(g[0] - s_dist) <= 2e-4f * (dv / dl) + 1e-5f;
                    if (!ok && t.bad++ < 5)
                        fprintf(stderr,
                                "%s light %d %s at (%g, %g): GPU s %g d %g dl %g, "
                                "distance path s %g d %g dl %g\n",
                                vr_mode_name(modes[m]), li, cmp ? "binary" : "smooth", p[0], p[2],
                                g[0], g[1], g[2], s_dist, dv, dl);
                    if (fabsf(s_dist - sc) > 0.5f) {
                        t.differ++;
                        t.wrong_side += fabsf(g[0] - sc) < fabsf(g[0] - s_dist);
                    }
                    t.err_gpu += fabsf(g[0] - st_true);
                    t.err_coef += fabsf(sc - st_true);
                }
                free(px);
                double mae_gpu = t.far ? t.err_gpu / (double)t.far : 0.0;
                double mae_coef = t.far ? t.err_coef / (double)t.far : 0.0;
                printf("%-9s light %d %s: %ld far fragments, %ld wrong; %ld (%.1f%%) where "
                       "interpolated coefficients differ by > 0.5; shadow error against the "
                       "truth: %.4f (distance path) vs %.4f (coefficients)\n",
                       vr_mode_name(modes[m]), li, cmp ? "binary" : "smooth", t.far, t.bad,
                       t.differ, t.far ? 100.0 * (double)t.differ / (double)t.far : 0.0, mae_gpu,
                       mae_coef);
                CHECK(t.far > PX * PX / 4, "only %ld far fragments", t.far);
                CHECK(t.bad == 0, "%s light %d: %ld fragments off the distance path",
                      vr_mode_name(modes[m]), li, t.bad);
                CHECK(t.wrong_side == 0, "%ld fragments on the coefficient side", t.wrong_side);
                CHECK(mae_gpu < mae_coef,
                      "%s light %d %s: the distance path is no closer to the "
                      "truth (%.4f) than coefficients (%.4f)",
                      vr_mode_name(modes[m]), li, cmp ? "binary" : "smooth", mae_gpu, mae_coef);
                /* the case must tell the two apart, strongly */
                CHECK(t.differ > t.far / 20,
                      "%s light %d: the interpolations differ in only "
                      "%ld fragments",
                      vr_mode_name(modes[m]), li, t.differ);
            }
    free(pos);
    vr_renderer_destroy(r);
    vr_scene_destroy(s);
    vdsh_free(f);
    vr_context_destroy(ctx);
    return test_report("test_runtime_log");
}
