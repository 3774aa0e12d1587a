/*
 * eval.h - the evaluator: how far a baked .vdsh is from the truth, measured
 * against an independent Embree ray cast (docs/DESIGN.md §3). The core of
 * the vdsh-eval tool, and what the accuracy tests call.
 *
 * Ground truth, in one paragraph: receivers are the file's vertices (all,
 * or a deterministic sample) and random points inside its triangles
 * (area-weighted), whose coefficients and normals are interpolated
 * barycentrically exactly as a GPU interpolates vertex attributes. Each
 * receiver gets its own held-out directions: a jittered stratified grid
 * over the upper hemisphere of its normal (w.n > 0), from the evaluator's
 * seed, so they are never the bake's directions (those are a sphere grid in
 * world axes with the bake's jitter). Each direction is traced with Embree
 * against the occluder scene (16-wide coherent packets) to give the true
 * distance d_T, clamped like the bake (a ray that hits nothing within the
 * file's max_distance gets max_distance: the clamp is part of what the bake
 * promises to store, so it is not counted as error), and carries one point
 * light at d_L = u * 2 * d_T, u uniform in (0.05, 1].
 *
 * Ray origins of the truth: vertices use the bake's own rule
 * (vb_ray_origins: offset along the normal averaged over coincident
 * vertices, then inset into the vertex's own triangles), so a vertex's
 * truth starts exactly where its bake started; interior points are offset
 * with vb_offset_origin along their interpolated normal, which needs no
 * inset because a point strictly inside its triangle lies on no other
 * surface's edge. The two kinds are reported separately, and the interior
 * points are an independent check of the bake's origin rule: where that
 * rule fails at a vertex (all of its rays hitting at ~0), the vertex's
 * truth fails with it, but the interior points around it see the real
 * distances and score the damage. The truth's own escape rate (rays that
 * hit nothing) is reported: in a closed scene it must be ~0.
 *
 * Scores (per stream of the file, per receiver kind), all through
 * formats/vdsh_shadow.h, the one definition of a stream's meaning:
 *   distance   e = |D(w) - d_T| / max(d_T, 0.01 diag); RMS, pooled
 *              percentiles p50/p90/p99 (log histogram, 2.3% resolution)
 *   smooth     s = ramp(d / d_L): MAE |s_hat - s_ideal|; false-shadow rate
 *              P(s_hat < 0.5 | d_T >= d_L); light-leak rate
 *              P(s_hat > 0.5 | s_ideal < 0.5)
 *   binary     s = d >= d_L ? 1 : 0: the same three
 *   ringing    the fraction of samples whose SH sum was <= 0 (read as 0)
 * with standard errors that treat receivers as clusters (the samples of
 * one receiver are correlated): ratio estimators linearised over
 * receivers. Receivers whose truth is almost all at distance ~0 (at least
 * 90% of their directions below 1e-3 diag, the bake's own test) are
 * counted as degenerate and listed: they are bake defects.
 *
 * Does not: load or write .vdsh files (formats/), print (the tool does),
 * bake. vb_eval_scene_create loads meshes; vb_eval_run only traces.
 *
 * Usage (tests/test_eval.c is a compiled example):
 *
 *     vb_scene *scene = NULL;
 *     vb_eval_scene_create(file, paths, file->source_count, NULL, &scene, &err);
 *     vb_eval_desc d = {.file = file, .scene = scene, .interior = 65536};
 *     vb_eval_result r = {0};
 *     if (vb_eval_run(&d, &r, &err) == VB_OK)
 *         ... r.metrics[VB_EVAL_INTERIOR][stream].shadow_mae ...
 *     vb_eval_result_free(&r);
 *     vb_scene_destroy(scene);
 *
 * Determinism: every random number is vb_hash2(seed mixed with a purpose,
 * receiver, sample); per-receiver sums run in a fixed order and totals are
 * summed serially in receiver order, so results are bit-identical for any
 * thread count.
 *
 * Errors: vb_result, messages name the file or source. Outputs are
 * untouched on failure.
 *
 * Ownership: the desc's pointers are borrowed. vb_eval_result owns its
 * arrays; vb_eval_result_free frees them and accepts a zeroed or
 * half-built result. vb_eval_scene_create's scene is freed with
 * vb_scene_destroy.
 *
 * Threading: vb_eval_run starts `threads` workers; no global state.
 */
#ifndef VB_EVAL_H
#define VB_EVAL_H

#include <stdint.h>

#include "scene.h"
#include "vb.h"
#include "vdsh.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VB_EVAL_DEFAULT_SEED 0x65766131u /* "eva1"; the bake's default is 1 */
#define VB_EVAL_DEFAULT_DIRECTIONS 64u
#define VB_EVAL_DEFAULT_WORST 10u
#define VB_EVAL_MAX_WORST 64u
#define VB_EVAL_MAX_RECEIVERS (1u << 28)

/* The two kinds of receivers, reported separately. */
enum { VB_EVAL_VERTICES = 0, VB_EVAL_INTERIOR = 1, VB_EVAL_KINDS = 2 };

/* Near-zero truth: below the receiver's near distance (origins.h); a
 * receiver is degenerate when this share of its truth is near zero (the
 * bake's rule). */
#define VB_EVAL_DEGENERATE 0.9 /* of a receiver's directions */

enum { VB_EVAL_INTERP_RUNTIME = 0 };

typedef struct vb_eval_desc {
    const vdsh_file *file; /* receivers and streams (borrowed) */
    const vb_scene *scene; /* occluders as the bake traced them (borrowed) */
    /* 0: VB_EVAL_DEFAULT_SEED. Mixed with a per-purpose constant, so even
     * the bake's seed gives other directions */
    uint64_t seed;
    /* vertices evaluated: a deterministic sample of this many; 0 or >=
     * vertex_count: all */
    uint32_t points;
    uint32_t interior; /* random interior points; 0: none */
    /* held-out directions per receiver, each with one light; 0: 64 (an 8 x 8
     * grid). Like the bake's --rays, rounded down to a grid */
    uint32_t directions;
    /* scene lights (VB_EVAL_SCENE_LIGHTS): how many are placed in free
     * space; 0: 32 */
    uint32_t lights;
    int light_rule; /* where (vb_light_rule, scene.h); 0: uniform */
    /* worst receivers kept per (kind, stream); 0: 10; at most
     * VB_EVAL_MAX_WORST */
    uint32_t worst;
    /* 1: score the truth itself (D := d_T) instead of the streams: every
     * error must be exactly 0 (tests the scoring and the sampling) */
    int oracle;
    int per_vertex; /* 1: fill result.per_vertex */
    /* How interior points get a stream's value from their triangle's
     * vertices (vdsh_shadow.h): VB_EVAL_INTERP_RUNTIME (0, the default) is
     * the path runtime/ draws that stream with (vdsh_runtime_interp), what a
     * viewer sees; or 1 + a vdsh_interp for the same mode on every stream. */
    uint32_t interp;
    unsigned threads; /* 0: every online core */
    /* Called from the calling thread a few times a second with receivers
     * done and total. May be NULL. */
    void (*progress)(void *user, uint32_t done, uint32_t total);
    void *progress_user;
} vb_eval_desc;

/* A receiver worth a look: where it is and how bad. */
typedef struct vb_eval_receiver {
    uint32_t index;    /* vertex index, or interior point number */
    uint32_t triangle; /* interior: its triangle; vertex: UINT32_MAX */
    /* interior: barycentrics of the triangle's vertices a, b, c; vertex: 1,
     * 0, 0 */
    float bary[3];
    float position[3], normal[3]; /* scene units; interpolated normal */
    double shadow_mae;            /* smooth, over its directions */
    double distance_rms;
    double false_shadow; /* NaN when it had no truly visible light */
    double near_zero;    /* fraction of its truth at ~0 distance */
    double escaped;      /* fraction of its truth rays that hit nothing */
} vb_eval_receiver;

/* One stream scored on one kind of receiver. `_se` is the standard error
 * (receiver-clustered); a 95% interval is +-1.96 se. Rates are fractions. */
typedef struct vb_eval_metrics {
    uint64_t samples; /* (receiver, direction) pairs */
    double distance_rms, distance_rms_se;
    double distance_mean;
    double distance_p50, distance_p90, distance_p99;
    double shadow_mae, shadow_mae_se;
    double false_shadow, false_shadow_se; /* P(s_hat < .5 | d_T >= d_L) */
    double light_leak, light_leak_se;     /* P(s_hat > .5 | s_ideal < .5) */
    double binary_mae, binary_mae_se;
    double binary_false_shadow, binary_false_shadow_se;
    double binary_light_leak, binary_light_leak_se; /* given d_T < d_L */
    /* fraction of samples whose SH sum was <= 0 (negative ringing, read as
     * distance 0) */
    double ringing;
    uint64_t visible;         /* samples with d_T >= d_L */
    uint64_t occluded;        /* samples with s_ideal < 0.5 */
    uint64_t occluded_binary; /* samples with d_T < d_L */
    /* Per-receiver smooth shadow MAE: percentiles over receivers. */
    double receiver_mae_p50, receiver_mae_p90, receiver_mae_p99;
    uint32_t worst_count;
    vb_eval_receiver worst[VB_EVAL_MAX_WORST]; /* by shadow MAE, worst first */
} vb_eval_metrics;

enum {
    VB_EVAL_PART_FALSE,
    VB_EVAL_PART_LIT_PARTIAL,
    VB_EVAL_PART_MISSED,
    VB_EVAL_PART_DRAWN,
    VB_EVAL_PART_PENUMBRA,
    VB_EVAL_MAE_PARTS
};

/* Scene lights, the primary shadow metric (docs/DESIGN.md §3): point
 * lights placed uniformly in the scene's free space (vdsh_light.h), as a
 * user places them, each scored at every receiver it lights (above the
 * receiver's horizon: (L - p).n > 0). The truth is the first hit of the
 * ray from the receiver toward the light, d_T (none before the light: the
 * light is visible). Rates are fractions. */
typedef struct vb_eval_scene_metrics {
    uint64_t pairs;                       /* (receiver, light) pairs scored */
    double shadow_mae, shadow_mae_se;     /* |s_hat - s_ideal|, smooth */
    double false_shadow, false_shadow_se; /* P(s_hat < .5 | d_T >= d_L) */
    /* P(s_hat < .5 | s_ideal < .5): the shadows drawn */
    double recall, recall_se;
    double light_leak, light_leak_se; /* P(s_hat > .5 | s_ideal < .5) */
    double binary_mae;
    double binary_false_shadow; /* P(D < d_L | d_T >= d_L) */
    double binary_recall;       /* P(D < d_L | d_T < d_L) */
    uint64_t visible;           /* pairs with d_T >= d_L */
    uint64_t occluded;          /* pairs with s_ideal < 0.5 */
    /* shadow_mae split by pair class, each a sum of |s_hat - s_ideal| over
     * its pairs divided by all pairs (the parts add up to shadow_mae):
     * false (lit, s_hat < .5), lit_partial (lit, s_hat >= .5), missed
     * (s_ideal < .5, s_hat >= .5), drawn (s_ideal < .5, s_hat < .5),
     * penumbra (.5 <= s_ideal < 1). NaN: no pairs. */
    double mae_part[VB_EVAL_MAE_PARTS];
} vb_eval_scene_metrics;

/* The truth's own record for one kind of receiver. */
typedef struct vb_eval_truth {
    uint32_t receivers;  /* evaluated */
    uint32_t skipped;    /* undefined (zero) normal: no hemisphere */
    uint64_t rays;       /* traced */
    uint64_t escaped;    /* hit nothing within max_distance */
    uint64_t near_zero;  /* d_T < 1e-3 diag */
    uint32_t degenerate; /* receivers with >= 90% near-zero truth */
    uint32_t degenerate_listed;
    vb_eval_receiver degenerate_list[VB_EVAL_MAX_WORST]; /* first ones, by index */
    /* The receivers whose truth escapes most (escaped > 0 only), most
     * first: in a closed scene every one is a leak, usually a ray origin
     * on the wrong side of a surface it touches. */
    uint32_t escaping_listed;
    vb_eval_receiver escaping_list[VB_EVAL_MAX_WORST];
} vb_eval_truth;

/* Fields of one per-vertex record (vb_eval_result.per_vertex): two for the
 * truth, then five per stream, in the file's stream order. */
enum {
    VB_EVAL_PV_NEAR_ZERO = 0, /* fraction of the truth at ~0 distance */
    VB_EVAL_PV_ESCAPED = 1,   /* fraction of truth rays that hit nothing */
    VB_EVAL_PV_TRUTH_FIELDS = 2,
    VB_EVAL_PV_DISTANCE_RMS = 0, /* + 2 + 5 * stream */
    VB_EVAL_PV_SHADOW_MAE = 1,
    VB_EVAL_PV_FALSE_SHADOW = 2, /* NaN: no truly visible light */
    VB_EVAL_PV_LIGHT_LEAK = 3,   /* NaN: no truly occluded light */
    VB_EVAL_PV_BINARY_MAE = 4,
    VB_EVAL_PV_STREAM_FIELDS = 5
};

typedef struct vb_eval_result {
    uint32_t stream_count; /* = the file's; metrics[k][i] is stream i */
    /* stream_count each: lights relative to each direction's truth (d_L = 2u
     * d_T), the secondary metric */
    vb_eval_metrics *metrics[VB_EVAL_KINDS];
    /* stream_count each: scene lights, the primary metric */
    vb_eval_scene_metrics *scene[VB_EVAL_KINDS];
    uint32_t light_count;      /* scene lights placed */
    float (*lights)[3];        /* their positions, scene units */
    uint32_t light_candidates; /* candidates tried to place them */
    /* 1: placed around a closed object, in the bounds grown (vdsh_light.h:
     * vb_scene_light_region) */
    int light_region_grown;
    /* 1: the region was given (the file's lreg, or vdsh-eval
     * --light-region): light_region_min..max */
    int light_region_given;
    float light_region_min[3], light_region_max[3]; /* the region placed in */
    vb_eval_truth truth[VB_EVAL_KINDS];
    uint64_t seed;       /* as used */
    uint32_t directions; /* per receiver, as used */
    float diagonal;      /* of the occluders' bounds (error floor 1%) */
    float max_distance;  /* the file's clamp, also the truth's */
    int oracle;
    unsigned threads;
    double seconds; /* wall time of the run */
    /* With desc.per_vertex: vertex_count records of per_vertex_fields
     * floats (2 + 5 * stream_count), NaN for vertices not evaluated. */
    uint32_t per_vertex_fields;
    float *per_vertex;
} vb_eval_result;

vb_result vb_eval_run(const vb_eval_desc *desc, vb_eval_result *out, vb_error *err);
void vb_eval_result_free(vb_eval_result *r);

/* ---- scene reconstruction --------------------------------------------- */

typedef struct vb_eval_scene_desc {
    /* 1: Embree's default traversal; 0 (default): RTC_SCENE_FLAG_ROBUST, so
     * the truth does not leak through shared edges */
    int fast;
    /* 1: a source whose SHA-256 or size differs from the file's is used
     * anyway */
    int allow_mismatch;
    unsigned threads; /* Embree build threads; 0 = all cores */
    /* With allow_mismatch, called once per mismatching source. May be NULL. */
    void (*warn)(void *user, const char *message);
    void *warn_user;
} vb_eval_scene_desc;

/* Rebuild the bake's occluder scene: load paths[0 .. count-1] (the file's
 * sources, in its order, or replacements for them) with the file's load
 * flags, append them, check each source's size and SHA-256 against the
 * file (the error names the source, its number and both hashes) and the
 * totals against the file's occluder counts and bounds, then build the
 * scene. `desc` may be NULL (defaults). count must equal the file's
 * source_count. A file with an `lreg` chunk (vdsh-bake --light-region)
 * gives the scene its light region (vb_scene_set_light_region): lights
 * placed on it go where the bake's went. */
vb_result vb_eval_scene_create(const vdsh_file *f, const char *const *paths, uint32_t count,
                               const vb_eval_scene_desc *desc, vb_scene **out, vb_error *err);

/* Where source `name`, as a .vdsh records it, is now: "builtin:..." as it
 * is; a path as recorded (relative to the working directory), else beside
 * the .vdsh file at vdsh_path. A malloc'ed path (the caller frees), or NULL
 * when neither exists or memory ran out. */
char *vb_eval_find_source(const char *name, const char *vdsh_path);

/* ---- the pieces, for tests and tools ---------------------------------- */

/* What the GPU does between vertices: position, normal (normalised; 0 if it
 * cancels) and the stream's coefficients at barycentrics `bary` of triangle
 * `tri`, each as bary[0] * a + bary[1] * b + bary[2] * c of the decoded
 * vertex values (f16 is decoded first, then mixed in float). `coeffs` gets
 * order^2 floats; any output may be NULL. tri < triangle_count. */
void vb_eval_interpolate(const vdsh_file *f, const vdsh_stream *s, uint32_t tri,
                         const float bary[3], float position[3], float normal[3], float *coeffs);

/* Interior point `j` of a run with this seed: its triangle (area-weighted
 * over the file's triangles) and barycentrics. `cdf` is the normalised
 * cumulative triangle area (vb_eval_area_cdf). Returns 0 when the mesh has
 * no area. */
int vb_eval_interior_point(const double *cdf, uint32_t triangle_count, uint64_t seed, uint32_t j,
                           uint32_t *tri, float bary[3]);

/* cdf[t] = area of triangles 0..t / total area (triangle_count doubles,
 * malloc'ed; NULL when out of memory). *total gets the total area. */
double *vb_eval_area_cdf(const vdsh_file *f, double *total);

/* The held-out directions of receiver `id` (a vertex index, or
 * VB_EVAL_INTERIOR_ID(j) for interior point j) with unit normal n: the
 * first `max` of the run's directions (d must hold 3 * max floats). Returns
 * how many the run uses per receiver. */
uint32_t vb_eval_directions(uint64_t seed, uint32_t directions, uint32_t id, const float n[3],
                            float *d, uint32_t max);
#define VB_EVAL_INTERIOR_ID(j) (0x40000000u + (uint32_t)(j))

/* The seed of one purpose's random stream (a tag such as "DIRS" as four
 * bytes): a splitmix64 finaliser over (seed, purpose), so that each
 * purpose of the evaluator and of vb_frames gets its own stream from the
 * one seed. */
uint64_t vb_eval_purpose_seed(uint64_t seed, uint32_t purpose);

#ifdef __cplusplus
}
#endif

#endif /* VB_EVAL_H */
