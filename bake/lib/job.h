/*
 * job.h - a whole bake as one straight line: load every mesh into one
 * occluder scene, refine a copy into the receivers, build the BVH and bake
 * (bake.h: orientation, ray origins, trace and project), fill the .vdsh
 * file, write the basis cubemaps and the file. vdsh-bake's main() is the
 * command line around these calls; a program that bakes without it calls
 * them in the same order:
 *
 *     vb_job j = {0};
 *     vb_job_desc d = {.paths = paths, .path_count = n, .output = "room.vdsh"};
 *     ok = vb_job_load(&j, &d, &err) == VB_OK && vb_job_refine(&j, &d, &err) == VB_OK &&
 *          vb_job_bake(&j, &d, &err) == VB_OK && vb_bake_fill_file(&j, &d, &err) == VB_OK &&
 *          vb_job_write(&j, &d, NULL, 0, &err) == VB_OK;
 *     vb_job_free(&j);
 *
 * A zero vb_job_desc (apart from paths and output) is vdsh-bake's defaults
 * (bake.h's for the bake; VB_DEFAULT_ENCODING coefficients; 64 x 64 basis
 * cubemaps).
 * The basis cubemaps depend on their size only: vb_job_load starts a
 * helper thread that encodes them in memory while the bake runs.
 *
 * Does not: parse command lines, print (except through on_mesh), or defer
 * signals (the caller holds its own lock around vb_job_write).
 * Errors: vb_result, with err naming the file. Ownership: the job owns
 * everything in it; vb_job_free frees it at any stage (also a zeroed job).
 * Threading: one job per thread; the bake runs on bake.threads workers.
 */
#ifndef VB_JOB_H
#define VB_JOB_H

#include <pthread.h>
#include <stdint.h>

#include "adaptive.h"
#include "bake.h"
#include "cubemap.h"
#include "mesh.h"
#include "scene.h"
#include "vb.h"
#include "vdsh_output.h"
#include "vdsh.h"
#include "vdsh_cpca.h"

#ifdef __cplusplus
extern "C" {
#endif

/* vdsh-bake's coefficient encoding when none is asked for. */
#define VB_DEFAULT_ENCODING VDSH_ENCODING_S8S6

/* The largest scene a bake takes: a bounding-box diagonal up to this many
 * units. The bake's frame, light region and distances are single
 * precision: a scene near FLT_MAX across (3.4e38) has a diagonal, or a
 * light region, of inf (vb_job_load refuses it, naming the files, where
 * Embree aborted on the infinite rays). */
#define VB_MAX_DIAGONAL 1e37

typedef struct vb_job_desc {
    const char *const *paths; /* meshes (mesh.h names), borrowed */
    uint32_t path_count;      /* 1..VDSH_MAX_SOURCES */
    const char *output;       /* the .vdsh file; NULL: none (vb_job_write refuses) */
    const char *cubemap_dir;  /* NULL: beside output */
    int weld;                 /* vb_load_desc.weld */
    int up_axis;              /* vb_load_desc.up_axis, recorded in HEAD load_flags */
    int crease;               /* vb_load_desc.crease: 0 or 180+ = off */
    /* receivers refined to it; 0: the vertices as they are. With adaptive:
     * where the refinement starts */
    float max_edge;
    /* receivers read from this mesh as they are (a plan: vdsh-bake
     * --receivers); NULL: the occluders, refined */
    const char *receivers_path;
    int adaptive; /* 1: adaptive receivers (adaptive.h) from there */
    vb_adaptive_desc adapt;
    int fast_traversal; /* 0: Embree's robust traversal (default) */
    /* Where the lights go (vdsh-bake --light-region): rule 0, the scene's
     * rule (vdsh_light_region; no `lreg` chunk); VDSH_LIGHT_REGION_GROWN,
     * the bounds grown by VDSH_REGION_GROW of their diagonal (min, max
     * unused); VDSH_LIGHT_REGION_BOX, min..max. Every placement of the
     * bake uses it (vb_scene_set_light_region), and the file records it
     * (`lreg`). */
    vdsh_light_box light_region;
    /* The bake (receivers and scene are the job's). Its orders give the
     * streams, in increasing order. */
    vb_bake_desc bake;
    /* The coefficient encoding: `encoding` when encoding_given, else
     * VB_DEFAULT_ENCODING (s8s6: within 0.02% of f16's shadow and image
     * error on the validation rooms at half the size or less;
     * docs/ACCURACY.md, "Compact streams"). */
    int encoding_given;
    vdsh_encoding encoding;
    /* encoding cpca: K, B, bits (zero: vdsh_cpca_settings_default()) */
    vdsh_cpca_settings cpca;
    int cube_size;      /* basis cubemap face; 0: 64; < 0: none */
    int record_timings; /* store the timings in the file */
    /* A shard (vdsh-bake --shard I/N): shard_count 0 is the whole bake;
     * else receivers vb_shard_range(V, shard_index, shard_count) only, and
     * the file is a part (VDSH.md "Parts": f32 streams, a `part` chunk, no
     * basis cubemaps; vdsh-merge joins the parts). */
    uint32_t shard_index, shard_count;
    /* Called after each mesh loads (may be NULL). */
    void (*on_mesh)(void *user, const char *path, const vb_mesh *m, const vb_source_info *info,
                    double seconds);
    void *user;
} vb_job_desc;

typedef struct vb_job {
    vb_mesh occluders, receivers;
    vdsh_source *sources; /* names borrowed from the desc's paths */
    uint32_t source_count;
    vb_scene *scene;
    vb_bake_output bake;
    uint8_t *drawn; /* per receiver (vb_drawn_receivers): bake.drawn */
    vdsh_stream streams[VDSH_MAX_STREAMS];
    void *stream_data[VDSH_MAX_STREAMS];
    size_t coefficient_bytes; /* per vertex, all fixed-order streams */
    /* per vertex on average, the variable-order stream's (order table
     * included; 0: none) */
    double variable_bytes;
    vdsh_file file;      /* filled by vb_bake_fill_file (borrows the above) */
    uint64_t file_bytes; /* the written file's size (vb_job_write) */
    vdsh_timings timings;
    /* The light pool (job.c: job_pool; bake.h, VB_POOL_SEED), scene
     * units: the decision fit's (pool_count VB_DECISION_POOL; 0 where it
     * found no room) and, with encoding cpca and a light mix > 0, the
     * light-density metric's first cpca_lights (VB_CPCA_POOL; 0: none),
     * which a part carries for the merge (`lpol`). */
    float (*pool)[3];
    uint32_t pool_count, cpca_lights;
    /* Its placement's seconds (0: none placed), between the BVH build
     * and the trace: in timings.total, not in the `time` chunk's parts
     * (vdsh-bake --report: seconds.pool). */
    double pool_seconds;
    vb_adaptive_stats adaptive;  /* with d->adaptive */
    vdsh_light_box light_region; /* the desc's, its box filled in (rule 0: none) */
    /* 1 when the crease angle split a vertex of some source: only then is it
     * recorded (HEAD load_flags), so that bakes it left alone keep their
     * bytes */
    int creased;
    double t_start;
    /* The basis cubemaps' helper thread. */
    pthread_t basis_thread;
    int basis_running;
    int basis_size;
    vb_cubemap_basis basis;
    vb_result basis_result;
    vb_error basis_err;
} vb_job;

/* The face size of the basis cubemaps the job writes: 0 when none (the
 * orders need none: only orders 4 and up evaluate bands 3-4 from them). */
int vb_job_cube_size(const vb_job_desc *d);

/* Load every mesh into one occluder scene and record its source. */
vb_result vb_job_load(vb_job *j, const vb_job_desc *d, vb_error *err);

/* The receivers: the occluders' vertices, refined to max_edge, or the
 * mesh at receivers_path as it is. */
vb_result vb_job_refine(vb_job *j, const vb_job_desc *d, vb_error *err);

/* The shard (d->shard_index of d->shard_count) fits the receivers
 * vb_job_refine made: index < count <= receivers; VB_OK when not sharded.
 * vb_job_bake checks it too; a caller that stops before baking (vdsh-bake
 * --export-obj, bake-slurm's check of a sharded bake) calls it itself. */
vb_result vb_job_check_shard(const vb_job *j, const vb_job_desc *d, vb_error *err);

/* Build the BVH and bake (bake.h); timings recorded. */
vb_result vb_job_bake(vb_job *j, const vb_job_desc *d, vb_error *err);

/* Encode one stream per order (freeing the bake's coefficients of each
 * order once its stream holds them) and fill j->file: the header, sources,
 * receivers (with the bake's oriented normals), streams, statistics and,
 * if asked, timings. */
vb_result vb_bake_fill_file(vb_job *j, const vb_job_desc *d, vb_error *err);

/* The cpca settings the job encodes with (after vb_job_bake): what was
 * asked (d->cpca, or vdsh_cpca_settings_default()) with the light pool it
 * placed, light_count 0 where the mix is 0 or the rule found no room (the
 * uniform metric). A whole file does not record them (formats/VDSH.md,
 * "cpca streams"): vdsh-bake's --report says them. Borrows j's pool. */
vdsh_cpca_settings vb_job_cpca_settings(const vb_job *j, const vb_job_desc *d);

/* Write the basis cubemaps (if any) and the .vdsh file together, with
 * the caller's staged side files `also` (vb_write_outputs);
 * j->file_bytes receives the file's size. */
vb_result vb_job_write(vb_job *j, const vb_job_desc *d, vdsh_output *also, int also_count,
                       vb_error *err);

/* The path of basis cubemap k (0..3) that goes with the .vdsh `output`:
 * in cubemap_dir, or beside output when it is NULL; the stem is output's
 * name less ".vdsh" (vb_cubemap_basis_path). For checks before a bake. */
vb_result vb_output_cubemap_path(const char *output, const char *cubemap_dir, int k, char *buf,
                                 size_t cap, vb_error *err);

/* 1 when a bake's basis cubemaps go with the .vdsh `output`: written to
 * cubemap_dir when it is not NULL, else beside output unless output is
 * written in place (a device or pipe such as /dev/null or /dev/stdout:
 * vdsh_output_is_stream), where they would land in /dev; 0 then, and
 * vb_write_outputs leaves them out. */
int vb_output_has_cubemaps(const char *output, const char *cubemap_dir);

/* A bake's outputs, all or none: the .vdsh file f to `output` and, when b
 * is not NULL, its basis cubemaps (cubemap_dir, NULL: beside output),
 * and the also_count files `also` the caller has staged (finished, not
 * committed: vdsh_output.h; entries without a path are skipped), such as
 * vdsh-bake's plan, OBJ export and distance volume. Every file is first
 * written to a temporary beside its target and put on disk; only when all
 * are complete are they renamed over their targets (the caller's, the
 * cubemaps, then the .vdsh file, last). A failure before that leaves
 * every target as it was and no temporary of this function's behind (the
 * caller's staged files stay the caller's: it removes them with
 * vdsh_output_abort, a no-op for those already renamed); only a failing
 * rename, which the message then says, can leave a mix. *bytes (may be NULL) receives the .vdsh file's
 * size. The encoded file is held in memory while staged. */
vb_result vb_write_outputs(const vdsh_file *f, const char *output, const char *cubemap_dir,
                           const vb_cubemap_basis *b, vdsh_output *also, int also_count,
                           uint64_t *bytes, vb_error *err);

void vb_job_free(vb_job *j);

/* Shard i of n of v receivers: [v*i/n, v*(i+1)/n), contiguous, sizes
 * differing by at most one (receivers cost alike). Needs n <= v. */
void vb_shard_range(uint32_t v, uint32_t i, uint32_t n, uint32_t *begin, uint32_t *end);

#ifdef __cplusplus
}
#endif

#endif /* VB_JOB_H */
