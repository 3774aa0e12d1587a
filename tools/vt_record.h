/*
 * vt_record.h - what a .vdsh records about its bake, as JSON written the
 * same way by every program that reports it.
 *
 * Purpose: vdsh-info --json and vdsh-eval --json both list the bake's
 * parameters, statistics and timings as the file records them; these
 * write each group once, so that a key means the same in both documents.
 *
 * Does not: choose where a group goes or what else a document holds
 * (each program keeps its own keys around these); read or check a file.
 *
 * Usage: tools/vdsh_info.c, bake/tools/vdsh_eval.c (vt_json.h for the
 * document itself).
 *
 * Errors: none of its own; a failed allocation marks the vt_json failed
 * (vt_json.h).
 *
 * Ownership and threading: borrows the file; no state.
 */
#ifndef VT_RECORD_H
#define VT_RECORD_H

#include "vdsh.h"
#include "vt_json.h"

#ifdef __cplusplus
extern "C" {
#endif

/* In object `bake`: rays, sampling, seed, max_distance, max_edge and
 * offset_rule, from the header. */
void vt_record_params(vt_json *j, cJSON *bake, const vdsh_header *h);

/* "stats" in parent: rays_traced, rays_missed, degenerate_receivers and
 * undefined_normals, and with `all` moved_origins and flipped_normals;
 * null when the file has no stats chunk. */
void vt_record_stats(vt_json *j, cJSON *parent, const vdsh_file *f, int all);

/* "timings" in parent: load, refine, build, trace, total (seconds) and
 * threads; null when the file has no time chunk. */
void vt_record_timings(vt_json *j, cJSON *parent, const vdsh_file *f);

#ifdef __cplusplus
}
#endif

#endif
