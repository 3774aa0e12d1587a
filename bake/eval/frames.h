/*
 * frames.h - what a viewer sees, ray-traced: per-pixel truth for a camera
 * and point lights given exactly as the GL viewer takes them, the file's
 * streams evaluated in C on the runtime's path at the same pixels, and the
 * image scores of docs/DESIGN.md §3 ("Image error"). The core of the
 * vdsh-frames tool (prefix vb_frames_).
 *
 * The truth of one pixel, in one paragraph: the primary ray through the
 * pixel's centre (formats/vdsh_camera.h, the camera the runtime projects
 * with) is traced against the RECEIVER mesh, the .vdsh's own positions and
 * triangles (what the GL draws), in a second Embree scene. Its hit gives
 * the triangle and barycentrics, the point p = sum b_k p_k and the vertex
 * normal interpolated and normalised as the GPU interpolates v_normal.
 * From p, offset with vb_offset_origin along the triangle's geometric
 * normal turned toward the camera, a ray toward each light is traced
 * against the OCCLUDER scene (vb_eval_scene_create: what the bake traced);
 * its first hit is d_T (none before the light: visible), and with
 * d_L = |L - p|:
 *   hard    vdsh_shadow_compare(d_T, d_L, binary): 1 visible, 0 blocked
 *   ideal   vdsh_shadow_compare(d_T, d_L, compare): the ramp of the exact
 *           distance (docs/DESIGN.md §3\'s s_ideal; with the binary compare, hard)
 *   mask    1 where the pixel counts: the primary ray hits a triangle and
 *           the interpolated normal faces the light (N . (L - p) > 0)
 *   stream  vdsh_shadow_interior with the triangle's three vertices, the
 *           barycentrics and vdsh_runtime_interp(order, quantity): the
 *           shadow the runtime draws there, computed in C (orders
 *           1..16; on the DISTANCE path each vertex's distance is
 *           reconstructed once per light, with its own order in a
 *           variable-order stream, which is drawn only on that path)
 * Pixels whose ray meets nothing hold hard = ideal = stream = 1, mask 0.
 *
 * Scores (per frame, over mask pixels, pooled by adding tallies): RMSE
 * and PSNR (peak 1) against ideal and against hard; shadow recall: of
 * pixels with hard = 0 and ideal < 0.5, the share drawn at s < 0.5;
 * false-shadow area: of pixels with hard = 1, the share drawn at s < 0.5;
 * blotches: 4-connected regions of false-shadow pixels larger than
 * VB_FRAMES_BLOTCH of the frame's pixels, their count and area (aggregate
 * rates can hide one large blotch).
 *
 * Views (vb_frames_make_views): view 0 is the viewer's default camera for
 * the scene; the others look from eyes in the scene's free space
 * (vdsh_light.h's rule, the one for lights, in the light region: the
 * bounds, or around a closed object) at surface points they see,
 * kept when a low-resolution frame shows no surface nearer than 5% of the
 * diagonal and, for each light, at least VB_FRAMES_MIN_SHARE of the
 * frame's pixels lit and as many hard-shadowed. Lights come from one pool
 * placed in free space (vb_scene_place_lights, or another rule of
 * vb_scene_place_lights_rule: light_rule). Everything is a function of
 * the seed.
 *
 * Does not: read or write files (vdsh-frames does, with tools/), know GL.
 *
 * Usage (bake/vdsh_frames.c; tests/test_frames.c):
 *     vb_frames_scene *fs = NULL;
 *     vb_frames_scene_create(file, occluders, 0, &fs, &err);
 *     vb_frames_hits h = {0};
 *     vb_frames_trace_primary(fs, &camera, 512, 384, 0, &h, &err);
 *     vb_frames_light l = {0};
 *     vb_frames_trace_light(fs, &h, light, VDSH_COMPARE_SMOOTH, 0, &l, &err);
 *     ... l.hard, l.ideal, l.mask; vb_frames_eval_stream(...) per stream ...
 *     vb_frames_light_free(&l); vb_frames_hits_free(&h);
 *     vb_frames_scene_destroy(fs);
 *
 * Determinism: every pixel is computed alone into its own slot and every
 * sum runs in pixel order, so images and scores are byte-identical for
 * any thread count.
 *
 * Errors: vb_result with a message; outputs untouched on failure.
 * Ownership: vb_frames_scene borrows the file and the occluder scene
 * (they must outlive it) and owns the receiver scene; hits and lights own
 * their arrays (their _free accept zeroed or half-built ones).
 * Threading: the trace functions start `threads` workers (0: every core);
 * a created scene may be used from several threads.
 */
#ifndef VB_FRAMES_H
#define VB_FRAMES_H

#include <stdint.h>

#include "scene.h"
#include "vb.h"
#include "vdsh.h"
#include "vdsh_camera.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A region of false shadow is a blotch when larger than this share of
 * the frame's pixels. */
#define VB_FRAMES_BLOTCH 0.0005
/* A view is kept when each of its lights lights at least this share of
 * the frame's pixels and hard-shadows as many. */
#define VB_FRAMES_MIN_SHARE 0.05
/* Light sets of a generated view: set 0 holds 1 light, set 1 holds 3. */
#define VB_FRAMES_SETS 2
#define VB_FRAMES_VIEW_LIGHTS 4

typedef struct vb_frames_scene {
    const vdsh_file *file;              /* borrowed */
    const vb_scene *occluders;          /* borrowed */
    vb_scene *receivers;                /* owned: the drawn mesh */
    float bounds_min[3], bounds_max[3]; /* of the receivers (the runtime's) */
    float diagonal;                     /* of the receivers' bounds */
} vb_frames_scene;

vb_result vb_frames_scene_create(const vdsh_file *f, const vb_scene *occluders, unsigned threads,
                                 vb_frames_scene **out, vb_error *err);
void vb_frames_scene_destroy(vb_frames_scene *s);

/* What each pixel's primary ray meets; arrays of width * height (times 3),
 * row 0 at the top. */
typedef struct vb_frames_hits {
    int width, height;
    uint32_t *triangle; /* UINT32_MAX: nothing */
    float *bary;        /* 3 per pixel */
    float *position;    /* 3 per pixel, scene units */
    float *normal;      /* 3: interpolated vertex normal, unit (0: cancels) */
    float *origin;      /* 3: shadow-ray origin, occluders' traced frame */
    float *depth;       /* distance from the eye (INFINITY: nothing) */
} vb_frames_hits;

/* width and height 1..16384. */
vb_result vb_frames_trace_primary(const vb_frames_scene *s, const vdsh_camera *c, int width,
                                  int height, unsigned threads, vb_frames_hits *out, vb_error *err);
void vb_frames_hits_free(vb_frames_hits *h);

/* The truth of one light (scene units) at every pixel of h. */
typedef struct vb_frames_light {
    float *hard, *ideal, *mask; /* width * height each */
    float *dt;                  /* d_T (INFINITY: visible / nothing hit) */
} vb_frames_light;

vb_result vb_frames_trace_light(const vb_frames_scene *s, const vb_frames_hits *h,
                                const float light[3], uint32_t compare, unsigned threads,
                                vb_frames_light *out, vb_error *err);
void vb_frames_light_free(vb_frames_light *l);

/* Stream `stream` of the file, evaluated on the runtime's path toward the
 * light at every pixel of h, into out (width * height floats). */
vb_result vb_frames_eval_stream(const vb_frames_scene *s, const vb_frames_hits *h, uint32_t stream,
                                const float light[3], uint32_t compare, unsigned threads,
                                float *out, vb_error *err);

/* The runtime's colour output (runtime/vr_glsl.c) for white point lights:
 *   albedo * (ambient + sum_i intensity * max(N . l_i, 0) * att_i * vis_i)
 * with att = 1 / (1 + d^2 / r^2), clamped to [0, 1] and stored as 8-bit
 * RGBA (grey, alpha 255; black where nothing is hit). vis[i] holds light
 * i's visibility per pixel. */
typedef struct vb_frames_shading {
    float albedo;    /* 0.8, the runtime's default */
    float ambient;   /* 0.03, vdsh-view's default */
    float intensity; /* per light */
    float radius;    /* r of the attenuation */
} vb_frames_shading;

/* vdsh-view's defaults for n lights: intensity 1.6 / (1 + 0.6 (n - 1))
 * (its default lights' dimming), r = 0.3 x the receivers' diagonal. */
void vb_frames_shading_default(const vb_frames_scene *s, int n, vb_frames_shading *out);

void vb_frames_shade(const vb_frames_hits *h, const float (*lights)[3], int n,
                     const float *const *vis, const vb_frames_shading *sh, uint8_t *rgba);

/* ---- scores --------------------------------------------------------------- */

/* Sums that pool by adding (one frame, a light set, a scene). */
typedef struct vb_frames_tally {
    uint64_t frames;
    uint64_t pixels;             /* every pixel of the frames */
    uint64_t counted;            /* mask pixels */
    double se_ideal, se_hard;    /* sums of squared differences */
    uint64_t shadowed, recalled; /* hard 0 and ideal < .5; of those s < .5 */
    uint64_t lit, false_shadow;  /* hard 1; of those s < .5 */
    uint64_t blotches, blotch_pixels;
} vb_frames_tally;

typedef struct vb_frames_scores {
    double rmse_ideal, psnr_ideal; /* PSNR +INFINITY for no error */
    double rmse_hard, psnr_hard;
    double recall;     /* NaN: nothing shadowed */
    double false_area; /* NaN: nothing lit */
    uint64_t blotches;
    double blotch_area; /* blotch pixels / frame pixels */
} vb_frames_scores;

/* Add one frame (s: the frame scored; hard, ideal, mask: the truth; all
 * width * height) to *t. Fails only when out of memory (the blotch
 * labelling), leaving *t untouched. */
vb_result vb_frames_score_frame(const float *s, const float *hard, const float *ideal,
                                const float *mask, int width, int height, vb_frames_tally *t,
                                vb_error *err);
void vb_frames_tally_add(vb_frames_tally *to, const vb_frames_tally *from);
void vb_frames_scores_get(const vb_frames_tally *t, vb_frames_scores *out);

/* ---- views ----------------------------------------------------------------- */

typedef struct vb_frames_view {
    vdsh_camera camera;
    /* lights[0]: set 0 (one light); lights[1..3]: set 1 (three). */
    float lights[VB_FRAMES_VIEW_LIGHTS][3];
    /* At the check resolution, per light: shares of the frame's pixels
     * lit and hard-shadowed. */
    float lit[VB_FRAMES_VIEW_LIGHTS], shadowed[VB_FRAMES_VIEW_LIGHTS];
} vb_frames_view;

typedef struct vb_frames_views_desc {
    uint32_t cameras;  /* views besides the default; 0: 6 */
    uint64_t seed;     /* 0: 1 */
    int width, height; /* the frames' size (only the aspect
                                    matters here); 0: 512 x 384 */
    unsigned threads;
    int light_rule; /* where the pool of lights goes (vb_light_rule, scene.h;
                       the eyes stay uniform); 0: uniform */
} vb_frames_views_desc;

typedef struct vb_frames_views_stats {
    uint32_t eyes_tried;        /* candidate eyes drawn */
    uint32_t eyes_free;         /* of those in free space */
    uint32_t default_lights_ok; /* default view's lights meeting the share */
} vb_frames_views_stats;

/* 1 + cameras views into out (caller's array). VB_ERR_INVALID when the
 * scene does not give that many views (the message says how many). */
vb_result vb_frames_make_views(const vb_frames_scene *s, const vb_frames_views_desc *d,
                               vb_frames_view *out, vb_frames_views_stats *stats, vb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* VB_FRAMES_H */
