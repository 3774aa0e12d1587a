/*
 * vdsh_sdf.h - the signed distance volume of a scene (the distance-field
 * shadow baseline, issue 27): its companion file SCENE.sdf beside
 * SCENE.vdsh (formats/VDSH.md, "Companion files: the distance volume"),
 * and the one definition of what the runtime's mode `sdf` computes with it
 * (vdsh_sdf_sample, vdsh_sdf_shadow), which vdsh-frames' C frames use and
 * the GLSL in runtime/vr_glsl_sdf.c repeats (tests/frames.cmake's
 * frames_gl_vs_c compares them by rendering).
 *
 * The volume: nx * ny * nz samples of the signed distance from the sample
 * point to the nearest occluder triangle, in scene units, positive in
 * free space and negative inside solids; sample (i, j, k) at
 *     origin + cell * (i, j, k)
 * (origin is sample (0,0,0)'s point, not a box corner), x fastest. Stored
 * as unorm16: u = round((clamp(d, -m, m) / m + 1) / 2 * 65535), m =
 * max_distance. Between samples the distance is trilinear; outside the
 * samples' box the box's nearest sample point is used (clamp to edge).
 *
 * Does not: compute the distances (bake/lib/sdf.c does, with Embree) or
 * upload anything (runtime/vr_sdf.c).
 *
 * Usage (tests/test_sdf.c is a compiled example):
 *     vdsh_sdf v;
 *     vdsh_error err;
 *     if (vdsh_sdf_read("room.sdf", &v, &err) != VDSH_OK) { print err.msg }
 *     float s = vdsh_sdf_shadow(&v, p, n, light, VDSH_SDF_DEFAULT_K);
 *     vdsh_sdf_free(&v);
 *
 * Errors: vdsh_result as vdsh.h (VDSH_ERR_NOT_VDSH for a wrong magic,
 * VDSH_ERR_TRUNCATED, VDSH_ERR_CRC, VDSH_ERR_INVALID for a size or value
 * out of range); the message names the file. Outputs untouched on failure.
 * Ownership: vdsh_sdf_read fills a vdsh_sdf whose samples it allocates;
 * vdsh_sdf_free frees them and accepts a zeroed struct. Threading: pure
 * functions, any thread.
 */
#ifndef VDSH_SDF_H
#define VDSH_SDF_H

#include <stddef.h>
#include <stdint.h>

#include "vdsh.h"

#ifdef __cplusplus
extern "C" {
#endif

enum {
    VDSH_SDF_HEADER_SIZE = 64,
    VDSH_SDF_MAX_DIM = 1024, /* samples along one axis */
    VDSH_SDF_MAX_STEPS = 64  /* sphere-trace steps per light */
};

/* The softness k of vdsh_sdf_shadow: a light of radius diagonal / k.
 * 400: chosen on validation room 1 (docs/BENCHMARKS.md, "Distance-field
 * shadows"): RMSE against the ideal falls with k, 0.36 at 50, 0.29 at
 * 400, 0.28 at 800; 400 keeps a visible penumbra. */
#define VDSH_SDF_DEFAULT_K 400.0f

typedef struct vdsh_sdf {
    uint32_t dim[3];         /* nx, ny, nz: 2..VDSH_SDF_MAX_DIM */
    float origin[3];         /* sample (0,0,0), scene units */
    float cell;              /* sample spacing, > 0 */
    float max_distance;      /* distances clamped to +-this, > 0 */
    uint32_t vertex_count;   /* of the .vdsh it was baked beside */
    uint32_t triangle_count; /* (0, 0: not recorded) */
    uint16_t *samples;       /* nx * ny * nz, unorm16 as above */
} vdsh_sdf;

/* The companion path of a .vdsh: "X.vdsh" -> "X.sdf", anything else gets
 * ".sdf" appended. Returns 0, or -1 when cap is too small. */
int vdsh_sdf_path(const char *vdsh_path, char *out, size_t cap);

/* Encode one distance (clamped) and decode one sample. */
uint16_t vdsh_sdf_encode(float d, float max_distance);
float vdsh_sdf_decode(uint16_t u, float max_distance);

vdsh_result vdsh_sdf_read(const char *path, vdsh_sdf *out, vdsh_error *err);
/* From memory (what the fuzz target calls); name for messages, may be NULL. */
vdsh_result vdsh_sdf_read_memory(const void *data, size_t size, const char *name, vdsh_sdf *out,
                                 vdsh_error *err);
/* Atomically (vdsh_output.h); validates with the reader's rules first. */
vdsh_result vdsh_sdf_write(const char *path, const vdsh_sdf *v, vdsh_error *err);
/* The same, staged: written beside `path` and put on disk, not yet
 * renamed; the caller commits or aborts *out (vdsh_output.h), so that the
 * volume appears together with its .vdsh file (vdsh-bake --sdf). On
 * failure *out is released. */
struct vdsh_output;
vdsh_result vdsh_sdf_stage(const char *path, const vdsh_sdf *v, struct vdsh_output *out,
                           vdsh_error *err);
/* The file's bytes in a malloc'd buffer. */
vdsh_result vdsh_sdf_write_memory(const vdsh_sdf *v, void **out, size_t *size, vdsh_error *err);
void vdsh_sdf_free(vdsh_sdf *v);

/* 1 when v was baked beside another scene: it records the counts of the
 * .vdsh it was baked beside, and they are not these (0: the same, or not
 * recorded). vdsh-view refuses such a volume when named and skips it as a
 * companion; vdsh-frames truth does the same. */
int vdsh_sdf_other_scene(const vdsh_sdf *v, uint32_t vertex_count, uint32_t triangle_count);

/* The volume's bytes on disk (header and samples). */
size_t vdsh_sdf_file_size(const vdsh_sdf *v);

/* Trilinear signed distance at p (scene units), as above. */
float vdsh_sdf_sample(const vdsh_sdf *v, const float p[3]);

/* The shadow factor (0 shadowed .. 1 lit) of a surface point p with unit
 * normal n for a point light at `light`: a sphere trace from
 *     o = p + n * 1.5 cell
 * toward the light, t from 0.5 cell, at most VDSH_SDF_MAX_STEPS steps of
 * max(h, cell / 8), h the distance at o + t dir less 0.35 cell (surfaces
 * thickened: a sheet of no thickness between two samples interpolates to
 * up to cell / 2 and would let traces through), s = min(k' h / t)
 * (Quilez, "soft shadows in raymarched SDFs", with k' = k |light - o| /
 * max_distance: the cone from the receiver to a light of radius
 * max_distance / k, as Unreal's source radius; a constant k' would darken
 * everything a light near a wall lights, the trace ending within the
 * light's clearance of the wall); s = 0 once h < cell / 64 (a hit), the
 * trace ends at the light (t >= |light - o|). Returns saturate(s). A
 * light at o (|light - o| = 0) lights: 1. The normal offset is 1.5 cell
 * (the thickening plus a spacing: the surface does not shadow itself).
 */
float vdsh_sdf_shadow(const vdsh_sdf *v, const float p[3], const float n[3], const float light[3],
                      float k);

#ifdef __cplusplus
}
#endif

#endif /* VDSH_SDF_H */
