/*
 * parallel.h - the bake module's one worker pool: a parallel for over
 * [0, count) in blocks, with progress reported from the calling thread.
 * The bake, the ray-origin probes and the evaluator all run on it.
 *
 * Determinism: which worker runs a block depends on scheduling, so callers
 * write per-item results to per-item slots (or sum per-worker partials in
 * a fixed order afterwards). Every worker sets the same floating-point
 * mode (denormals flushed to zero, as Embree recommends), so an item's
 * result does not depend on the worker that computed it.
 *
 * Errors: vb_parallel_for returns the number of workers that ran; 0 means
 * no thread could be started and nothing ran.
 */
#ifndef VB_PARALLEL_H
#define VB_PARALLEL_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Items [begin, end) of one block, on worker number `worker`. */
typedef void (*vb_parallel_fn)(void *ctx, uint32_t begin, uint32_t end, unsigned worker);

/* Called from the calling thread about five times a second while workers
 * run, and once at the end, with items done so far. */
typedef void (*vb_parallel_progress)(void *user, uint32_t done, uint32_t total);

/* 0 means every online core; capped at 256. */
unsigned vb_parallel_threads(unsigned threads);

unsigned vb_parallel_for(unsigned threads, uint32_t count, uint32_t block, vb_parallel_fn fn,
                         void *ctx, vb_parallel_progress progress, void *user);

#ifdef __cplusplus
}
#endif

#endif /* VB_PARALLEL_H */
