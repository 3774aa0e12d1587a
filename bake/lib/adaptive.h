/*
 * adaptive.h - adaptive receivers: refinement driven by the error the
 * runtime would make, not by edge length (vdsh-bake --adaptive TOL).
 *
 * Start from a receiver mesh (the input, or a coarse uniform refinement of
 * it) and bake its vertices. Then, in rounds: every edge not yet judged
 * whose halves would be at least min_edge long gets its midpoint baked
 * (split tentatively, conforming, so that the midpoint's ray origin and
 * orientation see the triangles it will have); an edge is split for real
 * when the stream interpolated between its ends, on the runtime's own path
 * (vdsh_runtime_interp), differs from the midpoint's own bake by more than
 * `tolerance` plus the bake's noise floor in expected shadow error (the
 * noise floor: up to VB_ADAPTIVE_NOISE_SAMPLE start receivers, evenly
 * spread over the vertex numbers, baked a second time under other vertex
 * numbers, so other rays and training lights; the
 * VB_ADAPTIVE_NOISE_QUANTILE quantile of their two bakes' difference by
 * the same measure; none at tolerance 0, which asks for every split).
 * Without it the test split on the fits' noise, which is about 0.02 on
 * the rooms (docs/ACCURACY.md). The measure: the mean over the lights above
 * the midpoint's horizon of |s_interp - s_mid| (vdsh_shadow.h, smooth
 * comparison), the lights `lights` points in the scene's free space
 * (vdsh_light.h, the frames' primary light model). A split vertex keeps
 * its midpoint bake: no ray is traced twice. Edges judged and kept are
 * never judged again (their ends' bakes do not change); new edges are
 * judged in the next round. Rounds end when nothing is split, when the
 * receiver budget is reached (the largest errors are split first within
 * the last round), or after max_rounds rounds (stats say whether that
 * limit stopped a refinement that was still splitting).
 *
 * Never more work than the uniform bake as fine as the splits can go: the
 * receivers kept and every midpoint baked (kept or not) together are at
 * most the vertices of vb_mesh_refine(start, 2 min_edge)
 * (stats.uniform_receivers; no edge of at most 2 min_edge is split);
 * a round that would pass it bakes only its longest candidates (ties: the
 * lower key) up to it, and the refinement stops there (uniform_reached).
 *
 * Every round bakes with the first round's quantity per order, so the
 * whole mesh stores one quantity per order, as a uniform bake does.
 *
 * Determinism: the candidates are taken in order of their ends' numbers,
 * the lights are a fixed sequence, and each bake is deterministic (bake.h):
 * the output is identical for any thread count.
 *
 * Errors: vb_result. Ownership: *receivers and *out are the caller's
 * (vb_mesh_free, vb_bake_output_free). Threading: the bake's workers.
 */
#ifndef VB_ADAPTIVE_H
#define VB_ADAPTIVE_H

#include <stdint.h>

#include "bake.h"
#include "mesh.h"
#include "vb.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VB_ADAPTIVE_LIGHTS 32
#define VB_ADAPTIVE_ROUNDS 8
#define VB_ADAPTIVE_NOISE_SAMPLE 1024
#define VB_ADAPTIVE_NOISE_QUANTILE 0.9

typedef struct vb_adaptive_desc {
    float tolerance;        /* split above this expected shadow error (>= 0;
                             * +inf: nothing is split) */
    float min_edge;         /* split only edges of at least 2 min_edge (> 0) */
    uint32_t max_receivers; /* 0: no budget */
    uint32_t lights;        /* 0: VB_ADAPTIVE_LIGHTS */
    uint32_t max_rounds;    /* 0: VB_ADAPTIVE_ROUNDS */
    /* Called after each round (may be NULL). */
    void (*on_round)(void *user, uint32_t round, uint32_t receivers, uint32_t candidates,
                     uint32_t split, double seconds);
    void *user;
} vb_adaptive_desc;

typedef struct vb_adaptive_stats {
    uint32_t start_receivers; /* the start mesh's vertices */
    uint32_t rounds;          /* rounds that baked midpoints */
    uint32_t candidates;      /* midpoints baked (split or not) */
    uint32_t lights;          /* lights the error was scored with */
    uint32_t max_rounds;      /* the round limit used */
    int budget_reached;       /* the receiver budget stopped it */
    /* the round limit stopped it while its last round still split edges */
    int rounds_reached;
    uint32_t last_split; /* edges the last round split */
    /* with rounds_reached: edges not yet judged, long enough to split (the
     * next round's midpoints) */
    uint32_t pending;
    uint32_t uniform_receivers; /* the uniform refinement of the start mesh to
                                 * 2 min_edge: the cap on every vertex baked
                                 * (0: over vb_mesh_refine's limit, no cap) */
    int uniform_reached;        /* that cap stopped it */
    uint32_t noise_sample;      /* start receivers baked twice for the noise floor */
    double noise_floor;         /* their two bakes' spread (quantile) */
    /* what an edge's error had to pass: tolerance + noise floor */
    double threshold;
} vb_adaptive_stats;

/* Bake `start` with `bake` (its receivers and range are ignored), then
 * refine as above: *receivers gets the final mesh (normals as baked:
 * oriented) and *out its bake, as vb_bake_run would give for it (rays,
 * rays_traced and the times sum every round, midpoints not kept and the
 * noise floor's second bakes included). stats may be NULL. */
vb_result vb_bake_adaptive(const vb_bake_desc *bake, const vb_mesh *start,
                           const vb_adaptive_desc *ad, vb_mesh *receivers, vb_bake_output *out,
                           vb_adaptive_stats *stats, vb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* VB_ADAPTIVE_H */
