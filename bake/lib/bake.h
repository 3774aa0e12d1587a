/*
 * bake.h - the bake core: for every receiver vertex, trace a jittered
 * stratified set of rays against the occluder scene and project the hit
 * distances onto real SH (formats/vdsh_sh.h).
 *
 * Methods (their properties: one row each in method.h's table; the maps:
 * fit.h):
 *   paper   the paper's demo (docs/DESIGN.md §1): directions over the
 *           whole sphere; those below the receiver's horizon (w.n < 0)
 *           count as distance 0 with the same 4 pi / N weight. They are not
 *           traced at all, since their result is thrown away: about half the
 *           rays, for identical coefficients.
 *   full    every direction of the sphere traced and projected.
 *   mirror  the upper hemisphere only, the lower filled with its mirror
 *           image before projecting.
 *   lsq     regularised least squares to the upper hemisphere only.
 *   shadow  lsq of the log distance, plus a per-order log offset (the
 *           stored distances are e^offset times the fit's): under lights
 *           placed in a scene's free space, least squares of ln d
 *           underestimates next to silhouettes and draws false shadows;
 *           the offset buys most of them back for a few lost shadow
 *           pixels (docs/ACCURACY.md: the curve, and the point chosen on
 *           the validation scenes).
 * `rays` is always the density over the whole sphere: the hemisphere
 * methods trace rays / 2 directions, stratified over the hemisphere around
 * each receiver's normal, the same budget `paper` traces.
 *
 * Adaptive rays (adaptive_rays, `--rays auto`): `rays` is the cap; each
 * receiver traces nested stratified rounds of a power-of-two grid and stops
 * when a round no longer changes its fit (vb_bake_desc below; figures:
 * docs/ACCURACY.md, "Adaptive rays and receivers"). Opt-in: the default
 * path traces the fixed grid, byte-identical to bakes before it. With
 * trace_only, every round is traced.
 *
 * Quantity: the stored function is D itself, or ln(max(D, log_floor)) for
 * VDSH_QUANTITY_LOG_DISTANCE (hemisphere methods and full only: the
 * paper's zero fill has no meaning in the log domain). VB_QUANTITY_AUTO
 * chooses per order: a first pass traces an evenly spaced sample of
 * CHOOSE_RECEIVERS (1024) receivers, fits both quantities, and scores each
 * fit on the traced directions above the horizon with the shadow error
 * vdsh-eval expects there (docs/DESIGN.md §3: a light at 2 u d_T, u
 * uniform in (0.05, 1], smooth ramp: a function of the ratio of the
 * reconstructed to the true distance only); the lower mean wins, and the
 * sampled receivers keep their fit of it (nothing is traced twice). Log wins
 * in closed rooms and levels, where what matters is relative error close
 * to walls; distance on open objects, where most rays escape to the clamp
 * distance. With paper, auto means distance.
 *
 * Orientation and ray origins: origins.h (receivers whose normals point
 * into geometry turned toward free space, unless keep_normals; the rule,
 * the repair of receivers left inside or behind other geometry, and each
 * receiver's near distance, below which a traced distance counts as ~0 for
 * the degenerate count), in one pass over the receivers' frames. Rays that
 * hit nothing within max_distance get max_distance.
 *
 * The whole bake around this (load, refine, fill and write the file):
 * job.h. Encoding the coefficients as streams: vb_bake_stream (stream.c).
 *
 * Determinism: a receiver's coefficients depend only on (seed, vertex
 * index, its position/normal, the scene): every per-vertex sum runs in a
 * fixed order, so the output is bit-identical for any thread count.
 *
 * Threads: `threads` workers take blocks of receivers from a shared
 * counter; the calling thread only reports progress.
 *
 * Errors: vb_result. Ownership: vb_bake_output_free frees what
 * vb_bake_run put into *out (and accepts a zeroed output).
 */
#ifndef VB_BAKE_H
#define VB_BAKE_H

#include <stdint.h>

#include "decision.h"
#include "mesh.h"
#include "method.h"
#include "origins.h"
#include "scene.h"
#include "vb.h"
#include "vdsh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The order baked when none is asked: the paper's highest. */
#define VB_DEFAULT_ORDER 5
/* Adaptive order: the cap when none is given, the lights of the error
 * test (placed with the bake's seed) and how many of a receiver's traced
 * directions it reads at most. */
#define VB_DEFAULT_ORDER_CAP 12
#define VB_ORDER_LIGHTS 32
#define VB_ORDER_DIRECTIONS 128

/* The orders an adaptive-order receiver may get below the cap: 1, 2, 3,
 * 5, 7, 9, 12 (and the cap itself): each step about 1.4 to 2 times the
 * coefficients of the last, so that testing them all costs little. */
int vb_order_candidate(int k, int cap);

/* The pool of lights of the decision fit (its training lights: all
 * VB_DECISION_POOL) and of the cpca light-density metric (its first
 * VB_CPCA_POOL; bake/lib/job.c), placed once per bake by the scene's rule
 * (vb_scene_place_pool) with the bake's seed ^ VB_POOL_SEED. */
#define VB_POOL_SEED 0xdec15105ull
#define VB_DECISION_POOL 4096u
/* Method decision: for the training lights, one in
 * VB_DEFAULT_DECISION_NEAR of the decision pool's lights (slots K-1,
 * 2K-1, ...) is placed by the near rule instead (free space with a
 * surface nearer than 5% of the diagonal along a probe: scene.h,
 * VB_LIGHTS_NEAR, vdsh-eval's --light-rule near), seed bake seed ^
 * VB_POOL_SEED ^ VB_NEAR_SEED, so that the fit sees lights where they
 * often go: beside walls and furniture. The calibration's held-out
 * lights stay uniform in free space (the same slots of the pool as
 * placed), and so does the cpca metric's pool (docs/ACCURACY.md, "Lights
 * near surfaces in the decision pool"). */
#define VB_DEFAULT_DECISION_NEAR 2
#define VB_NEAR_SEED 0x6e656172ull  /* "near" */
#define VB_SHELL_SEED 0x7368656cull /* "shel": vb_bake_desc.decision_shell */
#define VB_CPCA_POOL 2048u

typedef struct vb_bake_desc {
    const vb_mesh *receivers; /* positions and normals (borrowed) */
    const vb_scene *scene;    /* the occluders (borrowed) */
    /* directions per receiver; 0: 2500. With adaptive_rays: the cap */
    uint32_t rays;
    /* Adaptive rays (--rays auto): 1 traces nested stratified rounds
     * (vb_dirgrid_create_nested: 1/16, 1/8, ... of the cap's power-of-two
     * grid) and stops a receiver once a round changed its fit of the
     * highest order by less than ray_tolerance in expected shadow error
     * (the mean over the round's directions above the horizon of e(r), r
     * the new fit's distance over the last one's: the quantity choice's
     * score below). The decision reads the receiver's own rays only. */
    int adaptive_rays;
    /* 0: VB_DEFAULT_RAY_TOLERANCE; < 0: tolerance 0 (every round); inf: stop
     * at the first check */
    float ray_tolerance;
    uint64_t seed;        /* 0 is a valid seed */
    float max_distance;   /* clamp; 0: the occluders' bbox diagonal */
    vb_method method;     /* method.h; 0: shadow (the default) */
    vb_quantity quantity; /* method.h; 0: auto (the default) */
    /* Per order (index 1..VDSH_MAX_ORDER): the quantity it stores, over
     * `quantity` (adaptive receivers bake later rounds with the first
     * round's choice); NULL: as `quantity` says. */
    const vdsh_quantity *order_quantity;
    float lambda; /* lsq and shadow regularisation; 0: 1e-4 */
    /* method shadow: per order (index 1..VDSH_MAX_ORDER), added to the
     * fitted ln d; NULL: vb_shadow_log_offset */
    const float *log_offsets;
    float log_floor;    /* log-distance floor; 0: 1% of max_distance */
    vdsh_window window; /* on each order's bands; 0: none */
    /* bit n: produce order n; 0: max_order only (none with a variable order
     * and no mask) */
    uint32_t order_mask;
    /* Adaptive order (issue 16): > 0 adds a variable-order stream of the
     * quantity of order `variable_cap`: each receiver gets the lowest
     * order 1..variable_cap whose expected shadow error on its own traced
     * directions, under VB_ORDER_LIGHTS lights in the scene's free space,
     * is at most this tolerance, else the order of least error. 0: none. */
    float order_tolerance;
    int variable_cap; /* 0: VB_DEFAULT_ORDER_CAP */
    /* Method decision (method.h): the fit's settings (NULL: the
     * defaults, vb_decision_defaults), training lights per receiver (0:
     * VB_DEFAULT_DECISION_LIGHTS; at most VB_DECISION_MAX_PAIRS) and the
     * share of lit pairs the calibrated log offset leaves in false shadow
     * (0: VB_DEFAULT_FALSE_RATE). An explicit log_offsets skips the
     * calibration. */
    const vb_decision_params *decision;
    uint32_t decision_lights;
    float false_rate;
    /* Method decision: one in decision_near of the training pool's
     * lights placed by the near rule (VB_DEFAULT_DECISION_NEAR above); 0:
     * the default; < 0: none (uniform in free space, as before). */
    int decision_near;
    /* Method decision: one in decision_shell of the training pool's
     * lights (slots 0, K, 2K, ...; after the near rule's, so they win
     * where the slots meet) placed in the shell around the bounds
     * (VB_LIGHTS_SHELL: outside them, inside them grown by
     * VDSH_REGION_GROW of the diagonal), seed bake seed ^ VB_POOL_SEED ^
     * VB_SHELL_SEED: for an object lit from around it. The calibration's
     * held-out lights stay in the light region. 0: none (the default;
     * docs/ACCURACY.md, "A mixed pool for objects"). No room in the shell
     * is an error. */
    int decision_shell;
    /* Method decision, its training pool as placed (VB_DECISION_POOL
     * above; 3 floats per light, scene units, borrowed): pool_count
     * VB_DECISION_POOL, or 0 where there was no room (the lsq fits are
     * kept). NULL: the bake places it. */
    const float *pool;
    uint32_t pool_count;
    /* Method decision, the per-receiver offset cap (issue 25; 0: off):
     * each receiver's log offset is raised (never above 0) to keep all
     * but 1 - offset_cap_keep of its lit training pairs lit, less
     * offset_cap_tol ln units (negative: lit by that much more), where
     * it has at least offset_cap_min lit pairs; the calibration measures
     * its held-out lights through the capped offsets. Receivers without a
     * cap keep the offset calibrated without caps. Fixed orders only
     * (not the adaptive order's stream). keep 0: 1; min 0: 1. */
    int offset_cap;
    float offset_cap_tol, offset_cap_keep;
    uint32_t offset_cap_min;
    /* 0: the highest order in order_mask, or VB_DEFAULT_ORDER */
    int max_order;
    unsigned threads; /* 0: every online core */
    /* 0 (the tools' default): receivers whose normals point into geometry
     * are turned toward free space first (vb_orient_receivers, on a copy:
     * vb_bake_output.normals); 1: the normals as given. */
    int keep_normals;
    int trace_only; /* benchmark: trace the same rays, nothing else */
    /* A shard (vdsh-bake --shard): only receivers [range_begin, range_end)
     * get coefficients (vb_bake_output.coeffs holds their rows only) and
     * only they count in
     * rays_traced, rays_missed and degenerate_receivers; everything decided
     * over all receivers (orientation, origins, the quantity choice) is
     * decided as in the whole bake, so a range's coefficients are the whole
     * bake's bit for bit. 0, 0: every receiver. */
    uint32_t range_begin, range_end;
    /* Called from the calling thread a few times a second, and once at the
     * end, with receivers done and rays traced so far. May be NULL. */
    void (*progress)(void *user, uint32_t done, uint32_t total, uint64_t rays_traced);
    void *progress_user;
} vb_bake_desc;

#define VB_DEFAULT_RAY_TOLERANCE 0.06f /* validation room: docs/ACCURACY.md */
#define VB_DEFAULT_DECISION_LIGHTS 256
#define VB_DEFAULT_FALSE_RATE 0.008f

typedef struct vb_bake_output {
    int max_order;
    vdsh_method method;                       /* the method as stored */
    vdsh_quantity quantity[VDSH_ORDER_SLOTS]; /* per order: the quantity stored */
    uint32_t auto_receivers;                  /* VB_QUANTITY_AUTO: receivers sampled (else 0) */
    /* their expected shadow error per order, distance [0] and log [1] */
    double auto_error[VDSH_ORDER_SLOTS][2];
    float lambda;                       /* lsq or shadow regularisation used (0 otherwise) */
    float log_offset[VDSH_ORDER_SLOTS]; /* method shadow: per order, as used */
    float log_floor;                    /* log-distance floor used (0 otherwise) */
    /* Method decision: receivers fitted (the others, with fewer than 16
     * lights above their horizon, keep the lsq fit), their mean training
     * pairs, the calibration's target false rate and its receivers (0:
     * the log offsets were given). decision_lights 0: no free space for
     * lights, every receiver kept its lsq fit. */
    uint32_t decision_fitted, decision_fallbacks, decision_lights, calibration_receivers;
    uint64_t decision_rays; /* rays toward the lights (not in rays_traced) */
    /* Method decision: the pool's lights placed by the near rule (0: none,
     * or no room for them: the pool is uniform). */
    uint32_t decision_near_lights;
    /* Method decision: the pool's lights placed in the shell
     * (vb_bake_desc.decision_shell; 0: none). */
    uint32_t decision_shell_lights;
    double decision_pairs;
    float false_rate;
    /* The offset cap (vb_bake_desc.offset_cap): (receiver, order) rows
     * whose offset it raised, and over the fitted receivers outside the
     * calibration sample, their lit training pairs and those of them
     * that the log offset turns false: drawn lit without it, in shadow
     * by more than the cap's tolerance (0 without the cap) with it
     * (counted with or without the cap). */
    uint64_t cap_bound, lit_training, lit_training_false;
    /* Method decision with lights: the light region of the training pool
     * (vb_scene_light_region: 1 grown around a closed object, 0 the
     * bounds) and the candidates its rule tested; the calibration's
     * held-out pairs that were shadowed (0: its offsets are kept >= 0). */
    int light_region_grown;
    int light_region_given; /* the region given (vb_scene_set_light_region) */
    uint32_t light_region_probes;
    uint64_t calibration_shadowed;
    vdsh_window window;    /* applied */
    uint32_t vertex_count; /* all receivers */
    /* The receivers baked: vb_bake_desc's range, or 0, vertex_count
     * (vb_bake_stream reads range_end 0 as every receiver). */
    uint32_t range_begin, range_end;
    /* Per order n (1..VDSH_MAX_ORDER): (range_end - range_begin) * n^2
     * coefficients, vertex-major, the first row receiver range_begin's (a
     * shard holds its own range only: its memory is its range's); or NULL
     * where the order was not asked for (and with trace_only). */
    float *coeffs[VDSH_ORDER_SLOTS];
    /* Borrowed, may be NULL (every receiver): per receiver (all
     * vertex_count, not the range's) 1 when drawn (vb_drawn_receivers).
     * vb_bake_stream's s8, s8s6 scales are over the drawn rows only;
     * vb_bake_fill_file sets it from the receivers it writes. */
    const uint8_t *drawn;
    /* Adaptive order (order_tolerance > 0), else NULL and 0: per receiver
     * of the range its order 1..variable_cap, and variable_cap^2
     * coefficients (those past its order 0), vertex-major. */
    uint8_t *variable_orders;
    float *variable_coeffs;
    int variable_cap;
    float order_tolerance;
    /* The variable-order stream's method and parameter as stored (method
     * decision: shadow's lsq fits and log offsets, the candidates' fits
     * not refitted; docs/ACCURACY.md). */
    vdsh_method variable_method;
    float variable_param;
    /* directions per receiver actually used (the cap with adaptive rays) */
    uint32_t rays;
    float ray_tolerance; /* adaptive rays: the tolerance used, else 0 */
    int hemisphere;      /* sampling domain: 0 sphere, 1 hemisphere */
    float max_distance;  /* the clamp used, scene units */
    unsigned threads;    /* workers used */
    uint64_t rays_traced;
    uint64_t rays_missed;
    uint32_t degenerate_receivers;
    uint32_t undefined_normals;
    /* The receivers' normals as baked (3 per vertex), turned toward free
     * space, or NULL with keep_normals (then the receivers' own). A range
     * (vb_bake_desc.range_*): its rows only, like coeffs. */
    float *normals;
    uint32_t flipped_normals; /* receivers whose normal was turned */
    uint32_t moved_origins;   /* receivers whose origin the repair moved */
    vb_origins_stats origins; /* the ray origins' repair: what it did and cost */
    /* wall time of the trace-and-project loop (the origins' time is
     * origins.seconds) */
    double seconds;
} vb_bake_output;

vb_result vb_bake_run(const vb_bake_desc *desc, vb_bake_output *out, vb_error *err);

/* Method shadow's default log offset for an order: how much longer than
 * the least-squares fit of ln d the stored distances are (a factor
 * e^offset), trading drawn shadows for fewer false ones: a band-limited
 * fit undershoots next to silhouettes, where a light would draw a false
 * shadow on a lit wall. Chosen on the validation scenes by frames. */
float vb_shadow_log_offset(int order);
void vb_bake_output_free(vb_bake_output *out);

/* The .vdsh stream of one order (1 .. max_order) of a bake: its first
 * order^2 coefficients per vertex of its range (all receivers but a
 * shard's), as f32, or as f16 scaled by the
 * stream's largest |coefficient| (stored values in [-1, 1]), encoded on
 * b->threads workers, or as s8 or s8s6 (vdsh_encode_quantised_drawn with
 * b->drawn: scales over the drawn receivers). *storage receives the
 * block the stream points into (data, and an s8 stream's coef_scales);
 * the caller frees it. */
/* The variable-order stream of an adaptive-order bake (b->variable_orders),
 * as vb_bake_stream; its offsets point into *storage too. */
vb_result vb_bake_variable_stream(const vb_bake_output *b, vdsh_encoding encoding, vdsh_stream *out,
                                  void **storage, vb_error *err);

vb_result vb_bake_stream(const vb_bake_output *b, int order, vdsh_encoding encoding,
                         vdsh_stream *out, void **storage, vb_error *err);

/* vb_bake_stream, then b's coefficients of that order are freed (NULL):
 * peak memory holds one order's two copies, not every order's. An f32
 * stream takes the bake's array itself (*storage is it): no second copy
 * at all (a shard's part). On failure b is unchanged. */
vb_result vb_bake_stream_take(vb_bake_output *b, int order, vdsh_encoding encoding,
                              vdsh_stream *out, void **storage, vb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* VB_BAKE_H */
