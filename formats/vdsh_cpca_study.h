/*
 * vdsh_cpca_study.h - the cpca encoder with a bit width per basis vector,
 * for measurement only (issue 29, docs/ACCURACY.md "Bits per vector by its
 * variance"; not installed, no file format: the decoded coefficients are
 * returned, to be scored as an ordinary f32 stream).
 * Purpose: check the numpy study's width allocation (scripts/cpca_study
 * `K.B.wT`) on the real encoder's fit, refinement included, before the
 * format change.
 * Method: vdsh_cpca_encode's k-means, fit and refinement rounds with B
 * vectors (settings K, B), then every cluster fitted again with
 * fit_basis (> B) vectors (the first B the same). Per cluster, vector and
 * width (0, 2..8) the squared quantisation error of its weights with the
 * encoder's scale choice (1, 0.95, ..., 0.35 x the largest |weight|, the
 * least error); the errors summed over the clusters (cluster order) give
 * one width table for the stream. With a budget of T bytes per vertex:
 * for each record of W 32-bit words, the most vectors m whose model (the
 * cpca model of m vectors plus a u8 width table padded to 16 bytes) fits
 * T x rows with the records; 32 W - 8 bits spread over the first m by
 * greedy marginal allocation (from all 0, repeatedly raise the width,
 * 0 -> 2 -> 3 ... 8, that lowers the summed error most per bit spent,
 * the lowest vector on a tie), fewer bits while the fields do not pack
 * into W words (a field never straddles two words, as the format's);
 * the W with the least error (unstored vectors counting their whole
 * variance; the first on a tie) kept. f64, one thread, fixed order.
 * Does not: write a stream (no format holds the widths yet).
 * Also here: vdsh_cpca_pool_score, a fitted stream's error over its light
 * pool (docs/ACCURACY.md "Choosing K per stream at encode time": no
 * criterion measured there chose K well enough to be the encoder's).
 * Usage:
 *     vdsh_cpca_widths_fit wf;
 *     vdsh_cpca_settings st = {.clusters = 8, .basis = 54, .bits = 4, .budget = 0};
 *     vdsh_cpca_encode_widths(coefs, normals, rows, 12, &st, 108, 32.0, NULL,
 *                             decoded, &wf, &err);
 * Threading: no shared state.
 */
#ifndef VDSH_CPCA_STUDY_H
#define VDSH_CPCA_STUDY_H

#include "vdsh_cpca.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vdsh_cpca_widths_fit {
    uint32_t clusters;               /* K used (capped at rows) */
    uint32_t basis;                  /* vectors stored: the last of width > 0, plus 1 */
    uint32_t words;                  /* record words (the index and the packed fields) */
    uint8_t widths[VDSH_MAX_COEFFS]; /* per vector, 0 or 2..8 */
    double bytes_per_vertex;         /* records and model (width table included) */
    double rms_error;                /* RMS over rows of |decoded - c| */
} vdsh_cpca_widths_fit;

/* Fit src (rows x order^2, finite) with settings' K and B (bits ignored;
 * no auto), refit with fit_basis vectors (B..order^2) and allocate widths:
 * budget > 0 bytes per vertex as above, else the fixed table `widths`
 * (fit_basis entries, 0 or 2..8). decoded (rows x order^2) receives
 * every row as the format's rule decodes it (f32, mean + weight x f16
 * basis, vectors in order, width-0 vectors skipped). VDSH_ERR_ARGUMENT
 * for bad arguments or a budget nothing fits; as vdsh_cpca_encode
 * otherwise. */
vdsh_result vdsh_cpca_encode_widths(const float *src, const float *normals, uint32_t rows,
                                    uint32_t order, const vdsh_cpca_settings *settings,
                                    uint32_t fit_basis, double budget, const uint8_t *widths,
                                    float *decoded, vdsh_cpca_widths_fit *out, vdsh_error *err);

/* The pool score of a fitted stream against its source (issue 29, the
 * choice of K): over every vertex v and every light of settings' pool
 * above v's horizon (settings->positions the rows' positions), ln D at
 * the light's direction from the source's coefficients and from the
 * decoded stream's, each compared with ln of the light's distance (lit
 * when not below it, the binary comparison). pairs: the pairs counted;
 * disagree: the pairs whose decisions differ; missed: of those, lit by
 * the source and shadowed by the stream; squared: the sum over the pairs
 * of the squared difference of the two ln D. f64 (the SH basis f32, as
 * the encoder's metric), +, -, x, /, sqrt only: the same on any CPU. */
typedef struct vdsh_cpca_pool_score {
    uint64_t pairs, disagree, missed;
    double squared;
} vdsh_cpca_pool_scores;

vdsh_result vdsh_cpca_pool_score(const float *src, const float *normals, uint32_t rows,
                                 uint32_t order, const vdsh_cpca_settings *settings,
                                 const vdsh_cpca_fit *fit, vdsh_cpca_pool_scores *out,
                                 vdsh_error *err);

/* The same score of `count` streams of `order` with `rows` vertices
 * (1..VDSH_CPCA_MAX_STARTS; out[k] stream k's) in one pass, each pair's
 * SH evaluated once for all: encode's starts, and a cpca stream read from
 * a file (tests/cpca_kchoice_tool --score). Each out[k] is what a pass
 * over stream k alone gives. */
vdsh_result vdsh_cpca_pool_score_streams(const float *src, const float *normals, uint32_t rows,
                                         uint32_t order, const vdsh_cpca_settings *settings,
                                         const vdsh_stream *s, uint32_t count,
                                         vdsh_cpca_pool_scores *out, vdsh_error *err);

/* Study knobs (issue 29, docs/ACCURACY.md "Keeping the best of several
 * k-means starts" and the sections before it), read from the environment
 * at every use: VDSH_CPCA_KMEANS_SEED=N (an integer 1..65535) draws the
 * k-means++ seeding from another seed (the fit's own scatter; with
 * settings starts N, the starts S..S+N-1); VDSH_CPCA_REFIT_ROUNDS=R
 * (1..16) runs R refit rounds for K,alloc:BYTES instead of
 * VDSH_CPCA_REFIT_ROUNDS below. A value out of range is ignored with a
 * message on stderr; unset (or empty): the encoder's own bytes. The
 * margin and the starts, studied as knobs, are settings now
 * (vdsh_cpca.h: margin, starts; --cpca ...,margin:S,starts:N). */

/* The quantisation-aware refit (issue 29, docs/ACCURACY.md
 * "Quantisation-aware refit of the model"): vdsh_cpca_encode of settings
 * K,alloc:BYTES (clusters and budget set) with `rounds` refit rounds
 * instead of the encoder's own (0: none). report (may be NULL): the
 * rounds asked, the cluster rounds kept, and the clusters' summed error in
 * their metrics (each cluster's metric_gram_members Gram, the records
 * decoded as every reader decodes) before the refit and after. */
/* The refit rounds vdsh_cpca_encode runs for K,alloc:BYTES. */
#define VDSH_CPCA_REFIT_ROUNDS 2

typedef struct vdsh_cpca_refit_report {
    uint32_t rounds, kept;
    double metric_before, metric_after;
} vdsh_cpca_refit_report;

vdsh_result vdsh_cpca_encode_refit(const float *src, const float *normals, uint32_t rows,
                                   uint32_t order, const vdsh_cpca_settings *settings,
                                   uint32_t rounds, vdsh_cpca_fit *out,
                                   vdsh_cpca_refit_report *report, vdsh_error *err);

#ifdef __cplusplus
}
#endif

#endif
