/*
 * vdsh_cpca.h - fit a `cpca` stream (clustered principal components,
 * formats/VDSH.md "cpca streams", issue 29) to a bake's coefficients.
 *
 * Purpose: the one encoder of the `cpca` encoding: vdsh-bake calls it
 * after the fit, over all receivers, and vdsh-merge over the joined parts'
 * rows, so a merged file is byte-identical with the whole bake's.
 *
 * Method (VDSH.md has the rule in words; auto: vdsh_cpca_encode): k-means over [c, 10 sigma n]
 * (coefficients, then the vertex normal scaled to dominate), k-means++
 * seeding from a fixed seed, Lloyd rounds until no vertex moves (at most
 * 25); per cluster the mean (f16) and the B leading principal directions
 * of the deviations in the mean of the members' own upper-hemisphere
 * metrics plus 0.01 of the whole sphere (each member's hemisphere weighted
 * by the light density of a pool when settings say: light_mix); then 3
 * rounds of CPCA refinement
 * (each vertex to the cluster whose mean and basis reconstruct it with the
 * least error over its own hemisphere, then every cluster fitted again,
 * stopping early when no vertex moves); weights quantised
 * to `bits` bits with a scale per cluster and vector, chosen among the
 * largest |weight| x 1, 0.95, ..., 0.35 by least squared error. f64, each
 * cluster's fit and each vertex's reassignment in a fixed order of its
 * own: the same bytes on any x86-64 CPU and thread count.
 *
 * Does not: read or write files (vdsh.h does), handle variable-order
 * streams (callers refuse them).
 *
 * Usage:
 *     vdsh_cpca_fit fit;
 *     vdsh_cpca_settings st = vdsh_cpca_settings_default();
 *     if (vdsh_cpca_encode(coefs, normals, rows, order, &st, &fit, &err) != VDSH_OK) ...
 *     stream.encoding = VDSH_ENCODING_CPCA; stream.scale = 1;
 *     stream.cpca = fit.model; stream.data = fit.records;
 *     ... vdsh_write ...
 *     vdsh_cpca_fit_free(&fit);
 *
 * Threading: no shared state. A fit's clusters (their means and bases)
 * and its refinement's vertices (each one's new cluster) are split over
 * up to settings->threads threads (vdsh-bake --threads; vdsh-merge: one
 * per CPU), the starts of K,alloc:BYTES,starts:N over the same threads
 * (each start's fit on its share): every cluster's and vertex's result
 * its own, so the bytes are the same on any number.
 */
#ifndef VDSH_CPCA_H
#define VDSH_CPCA_H

#include "vdsh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vdsh_cpca_settings {
    uint32_t clusters; /* K asked for, 1..VDSH_CPCA_MAX_CLUSTERS (capped at rows) */
    uint32_t basis;    /* B asked for, 1..VDSH_MAX_COEFFS (capped at order^2) */
    uint32_t bits;     /* VDSH_CPCA_MIN_BITS..VDSH_CPCA_MAX_BITS */
    /* auto (vdsh-bake --cpca auto[:BYTES], clusters 0): 1..VDSH_CPCA_MAX_BUDGET
     * bytes per vertex, the model included; B and bits are then ignored and
     * the encoder picks K, B (vdsh_cpca_encode). With clusters K
     * (--cpca K,alloc:BYTES): a width per basis vector within the budget
     * (bits 0 in the stream). 0: the fixed K, B, bits. */
    uint32_t budget;
    /* The light-density metric (docs/ACCURACY.md "A light-density metric";
     * VDSH.md "cpca streams"): vertex v's weight of cube direction w is
     * (1 - light_mix) + light_mix * rho_v(w), rho_v the share of the pool's
     * lights above v's horizon whose direction from v falls in w's texel,
     * over the texel's share of the hemisphere (a vertex that sees no light
     * above its horizon keeps the uniform weight). light_mix 0..1
     * (vdsh-bake --cpca ...,light:A); 0, light_count 0 or NULL lights: the
     * uniform metric, the bytes of the encoder without it. The pool is an
     * input (vdsh-bake places it by the scene's light rule, a part carries
     * it for vdsh-merge: VDSH.md `lpol`); positions are the rows' receiver
     * positions, 3 per row, in the pool's space. */
    float light_mix;
    uint32_t light_count;
    const float *lights;    /* 3 per light, finite */
    const float *positions; /* 3 per row */
    /* The most light texels the metric keeps between passes (2 bytes
     * each; 0: 2^26, 128 MiB): the rows past it are found again at every
     * pass, the same bytes more slowly (vdsh_cpca_encode). A memory cap
     * only; the tests lower it to check that the output does not move. */
    size_t light_cache;
    /* The decision margin's weight (--cpca ...,margin:S; docs/ACCURACY.md
     * "Weighting the light metric by the decision margin"; VDSH.md "cpca
     * streams"): with the light-density metric, each pool light of a row
     * weighs 1 / (1 + (m / S)^2), m the light's margin, ln D of the row's
     * own coefficients at the light's direction less ln of its distance
     * (the weights summed per row in place of the count). 0: every light
     * 1, the bytes without it. 0 or in (0, VDSH_CPCA_MAX_MARGIN]. */
    float margin;
    /* K,alloc:BYTES fitted from this many k-means starts (--cpca
     * ...,starts:N; docs/ACCURACY.md "Keeping the best of several k-means
     * starts"): each scored over the pool (vdsh_cpca_study.h's
     * vdsh_cpca_pool_score), the one whose shadow decisions differ from
     * the uncompressed coefficients' at the fewest (vertex, light) pairs
     * kept, the first on a tie. 0 or 1: one fit; without a pool, one fit.
     * 0..VDSH_CPCA_MAX_STARTS. */
    uint32_t starts;
    /* K,alloc:BYTES with s8 bases (--cpca ...,bases:8; VDSH.md "cpca
     * streams"; docs/ACCURACY.md "Bases in 8 bits"): each cluster's basis
     * vectors stored as s8 with the vector's scale in the weights' scales,
     * 1 byte per value where f16 takes 2, the bytes freed spent on the
     * records by the budget's rule. 0: f16. */
    uint32_t bases_s8;
    /* The most threads the encoder runs on (0: one per CPU online); the
     * bytes do not depend on it. */
    uint32_t threads;
    /* The k-means start (the seeding's draw) of a one-start fit: 0, the
     * encoder's own; start i draws as VDSH_CPCA_KMEANS_SEED=i would
     * (vdsh_cpca_study.h). With starts N: the starts start..start+N-1. */
    uint32_t start;
} vdsh_cpca_settings;

/* The light mix vdsh_cpca_parse gives when the text does not say, for
 * the byte-budget settings (K,alloc:BYTES and auto, the default among
 * them): the light density alone (docs/ACCURACY.md "A light-density
 * metric": `8,alloc:32` over ten validation bakes +4.40% -> +2.47% over
 * uncompressed order 12). The fixed K,B,BITS settings (8,54,4, the
 * default before, among them) keep the uniform hemisphere, 0: with fixed
 * widths the metric lost 0.3 points on the mean of eight validation bakes
 * (fandisk -4.7, the teapot -3.5). vdsh_cpca_encode needs the pool too:
 * without one the metric is uniform. */
#define VDSH_CPCA_DEFAULT_LIGHT_MIX 1.0f

/* The default's margin and starts (--encoding cpca without --cpca, or
 * the options alone): docs/ACCURACY.md "The margin and two starts become
 * the default": over fifteen validation bakes +1.50% over uncompressed
 * order 12 against +2.01% for one start without the margin, over 3% on
 * two against four, none decidedly worse; 1.2-1.8x the bake's wall time
 * on two cores (fandisk at 12,190 receivers to the room at 58,007; the
 * second start on the other core), 1.8-2.7x its CPU time, 2x its memory
 * (docs/BENCHMARKS.md). Three starts since "A third start" (docs/
 * ACCURACY.md, 2026-12-03): with s8 bases over the same fifteen bakes
 * within 3% on all fifteen against fourteen (the spider +2.70% against
 * +3.20%), mean +1.00% against +1.09%, one decidedly better and one
 * decidedly worse (the sphere with a hole, which stays below uncompressed
 * order 12); the third start's fit runs on both cores of two
 * (encode_starts' batches): 1.36-1.46x the bake's wall time of two starts
 * (docs/BENCHMARKS.md "The default's third start"). A base said
 * (16,alloc:32) has neither unless said. */
#define VDSH_CPCA_DEFAULT_MARGIN 0.25f
#define VDSH_CPCA_DEFAULT_STARTS 3
/* The default's bases are s8 (--cpca ...,bases:8; the options alone too,
 * a base said is f16 unless said): docs/ACCURACY.md "Bases in 8 bits"
 * (fifteen validation bakes, at the same budget). */
#define VDSH_CPCA_DEFAULT_BASES_S8 1

/* K,alloc:BYTES with K = VDSH_CPCA_DEFAULT_CLUSTERS (16) and BYTES =
 * VDSH_CPCA_DEFAULT_BUDGET (32), light mix VDSH_CPCA_DEFAULT_LIGHT_MIX,
 * margin VDSH_CPCA_DEFAULT_MARGIN, VDSH_CPCA_DEFAULT_STARTS starts and s8
 * bases, no pool: 16,alloc:32,margin:0.25,starts:3,bases:8 (K and BYTES:
 * docs/ACCURACY.md "The default of --encoding cpca": over sixteen
 * validation bakes +1.68% over uncompressed order 12, within 3% on 14,
 * against 8,alloc:32's +2.05% and 11; 8,54,4, the default before, passed
 * 32 bytes per vertex below about 32,000 receivers). K is a most: on a
 * mesh too small for 16 clusters' model within 32 bytes per vertex (a few
 * hundred receivers at order 12) vdsh_cpca_encode halves it until one
 * fits; only a mesh no single cluster fits is refused. Without a pool
 * (the caller sets it) the metric is uniform and the margin and starts
 * do nothing. */
vdsh_cpca_settings vdsh_cpca_settings_default(void);

/* s as the text vdsh_cpca_parse reads back (the pool aside): "K,B,BITS",
 * "auto:BYTES" or "K,alloc:BYTES", then ",light:A", and ",margin:S" and
 * ",starts:N" when set (16,alloc:32,light:1,margin:0.25,starts:3), into
 * buf (truncated to size). vdsh-bake's and vdsh-info's words for a fit. */
void vdsh_cpca_settings_text(const vdsh_cpca_settings *s, char *buf, size_t size);

/* Parse "K,B,BITS" (for example "8,54,4"), "auto" (budget 32),
 * "auto:BYTES" (1..VDSH_CPCA_MAX_BUDGET) or "K,alloc:BYTES", each
 * followed by options, each once, in any order: ",light:A" (A in 0..1,
 * the light mix; else VDSH_CPCA_DEFAULT_LIGHT_MIX for auto and alloc, 0
 * for K,B,BITS), and for K,alloc:BYTES with a light mix above 0
 * ",margin:S" (the margin, S in (0, VDSH_CPCA_MAX_MARGIN]) and
 * ",starts:N" (1..VDSH_CPCA_MAX_STARTS); or the options alone (the
 * default settings, vdsh_cpca_settings_default's, with the options said
 * in place of theirs: "light:0.5", "starts:1", "margin:0.5"; "light:0"
 * alone is the default K and budget with the uniform metric and neither
 * margin nor starts, which need the pool) into *out (no pool: the caller
 * sets it); VDSH_ERR_ARGUMENT with a message for a malformed string or a
 * value out of range. A base said (K,alloc:BYTES) has no margin and one
 * start unless said. */
vdsh_result vdsh_cpca_parse(const char *text, vdsh_cpca_settings *out, vdsh_error *err);

/* A fitted stream: model (its pointers into storage_) and records
 * (rows * model.record_words words). Also the fit's coefficient error,
 * RMS over rows of |decoded - c| (f32 decode, as vdsh_stream_decode). */
typedef struct vdsh_cpca_fit {
    vdsh_cpca model;
    uint32_t *records;
    double rms_error;
    void *storage_;
} vdsh_cpca_fit;

/* Fit `rows` rows of order^2 coefficients (src, row-major, finite) with
 * their unit (or zero) normals (3 per row) to a cpca model and records.
 * With settings->budget (auto): for each K of 4, 8, 16 (capped at rows)
 * and 4 bits, the largest B whose records and model take at most `budget`
 * bytes per vertex; each such K,B fitted in full, and the one kept whose
 * decoded (quantised) functions differ least from the sources over each
 * vertex's own hemisphere (the refinement's error; first in that order on
 * a tie). VDSH_ERR_ARGUMENT when none fits the budget. With K and a
 * budget (alloc): K, B refined as above with the largest B whose 4-bit
 * records and model fit (K halved while no B fits; VDSH_ERR_ARGUMENT when
 * none fits at K = 1), then a width per vector over min(2B, n) vectors
 * (vdsh_cpca_study.h's allocation; VDSH.md "cpca streams"), vectors of
 * width 0 dropped: model.bits 0 and model.widths set.
 * With the light-density metric, each row's texels of the pool's lights
 * above its horizon are found once and kept for the whole encode (2 bytes
 * per light; at most 128 MiB, the rows past that found again at every
 * pass; settings->light_cache lowers that cap): docs/BENCHMARKS.md "cpca
 * light-density metric: encode time".
 * VDSH_ERR_ARGUMENT for bad settings, order or rows; VDSH_ERR_INVALID for
 * a value that is not finite or a model that does not fit f16;
 * VDSH_ERR_OUT_OF_MEMORY. On failure *out is zeroed. */
vdsh_result vdsh_cpca_encode(const float *src, const float *normals, uint32_t rows, uint32_t order,
                             const vdsh_cpca_settings *settings, vdsh_cpca_fit *out,
                             vdsh_error *err);

void vdsh_cpca_fit_free(vdsh_cpca_fit *fit);

/* A cpca part's record of its settings (VDSH.md "Parts"), into f:
 * part.cpca_clusters, cpca_basis, cpca_bits (K,B,BITS: K, B, BITS; auto:
 * 0, budget, 0; K,alloc:BYTES: K, budget, 0) and, with a light mix > 0 and
 * a pool, the `lpol` chunk's light_pool (borrowing st->lights), the
 * margin and starts with it. */
void vdsh_cpca_part_record(const vdsh_cpca_settings *st, vdsh_file *f);

/* The settings cpca part f records, as vdsh_cpca_part_record wrote them,
 * for the merge: with its pool and f's receiver positions when it has
 * one (every part has the same). */
vdsh_cpca_settings vdsh_cpca_part_settings(const vdsh_file *f);

/* The same for a whole stream: `src` a fixed-order f32 stream of `rows`
 * rows with scale 1 (a bake's or a merge's), *out its header with
 * encoding cpca, data and model set; *storage the one block to free()
 * once written; *rms_error (may be NULL) the fit's coefficient error. */
vdsh_result vdsh_cpca_encode_stream(const vdsh_stream *src, uint32_t rows, const float *normals,
                                    const vdsh_cpca_settings *settings, vdsh_stream *out,
                                    void **storage, double *rms_error, vdsh_error *err);

#ifdef __cplusplus
}
#endif

#endif /* VDSH_CPCA_H */
