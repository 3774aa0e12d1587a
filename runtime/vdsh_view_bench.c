/*
 * vdsh_view_bench.c - vdsh-view --bench: frame times of every shadow mode
 * with 1, 3, 16 and 64 lights on each scene, in one process, as one JSON
 * document on stdout (scripts/bench_runtime reads it). Lights beyond the
 * scene's four defaults come from its light pool (vr_scene_pool_lights).
 * Frames with many lights are long (the cube maps re-render six faces per
 * light), and the work of one such frame averages over many passes: they
 * get fewer rounds (bench_rounds).
 */
#include "vdsh_view.h"

#include "vt_cli.h"
#include "vt_json.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifndef VDSH_VERSION_STRING
#define VDSH_VERSION_STRING "0"
#endif

typedef struct bench_mode {
    vr_mode mode;
    int pcf;
    const char *name;
    int stream;    /* VR_MODE_VDSH_BUFFER's */
    int from_copy; /* drawn from a copy of the scene (bench_scene.copy):
                                1 decoded-f32, 2 cpca decoded once per frame,
                                3 sums in a compute shader, 4 the same
                                decoded at load */
    int renderer;  /* index into the renderers: 0, or 1 + the
                                --bench-cube-sizes entry of a sized cube */
    int cube_size; /* VR_MODE_CUBE: its face size */
} bench_mode;

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void json_series(vt_json *j, cJSON *o, const char *key, const double *v, int n)
{
    cJSON *a = vt_json_array(j, o, key);
    for (int i = 0; i < n; i++)
        vt_json_f64(j, a, NULL, v[i]);
}

enum { BENCH_MODES = 48, BENCH_ROUNDS = 64, BENCH_SETS = 4 };

/* The light counts timed, and the rounds each gets out of `rounds`: all
 * for 1 and 3 lights, a third for 16, a fifth for 64, at least 3. */
static const int bench_light_sets[BENCH_SETS] = {1, 3, 16, 64};

/* Whether light set `set` is timed (--bench-lights; none given: all). */
static int bench_set_on(const vv_options *o, int set)
{
    return !o->bench_sets || (o->bench_sets >> set & 1);
}

static int bench_rounds(int set, int rounds)
{
    static const int divisor[BENCH_SETS] = {1, 1, 3, 5};
    int n = rounds / divisor[set];
    return n < 3 ? (rounds < 3 ? rounds : 3) : n;
}

/* CPU time of the whole process (every thread: llvmpipe's rasterizer
 * threads render in this process), milliseconds. */
static double process_cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

/* One scene of a benchmark: what it times and the results. */
typedef struct bench_scene {
    const char *path;
    vr_scene *scene;
    /* copies of the scene for the buffer modes: [0] --buffer-floats
     * (buffers as decoded f32), [1] --cpca-frame (cpca decoded once per
     * frame), [2] --compute (sums in a compute shader), [3] the same with
     * a cpca stream decoded at load */
    vr_scene *copy[4];
    bench_mode modes[BENCH_MODES];
    int nm;
    vr_light lights[BENCH_SETS][VR_MAX_POOL_LIGHTS];
    int nl[BENCH_SETS];
    /* [light set][mode][round] */
    double cpu[BENCH_SETS][BENCH_MODES][BENCH_ROUNDS], gpu[BENCH_SETS][BENCH_MODES][BENCH_ROUNDS];
    double shadow[BENCH_SETS][BENCH_MODES][BENCH_ROUNDS];
    double lighting[BENCH_SETS][BENCH_MODES][BENCH_ROUNDS];
    double proc[BENCH_SETS][BENCH_MODES][BENCH_ROUNDS];
    vr_counts counts[BENCH_SETS][BENCH_MODES]; /* --bench-counts */
} bench_scene;

/* Whether --bench-modes keeps the mode `name` (none given: every mode). */
static int bench_keeps(const vv_options *o, const char *name)
{
    if (!o->bench_modes)
        return 1;
    size_t len = strlen(name);
    for (const char *p = o->bench_modes, *next; p; p = next) {
        size_t n = vt_list_item(p, &next);
        if (n == len && !strncmp(p, name, len))
            return 1;
    }
    return 0;
}

/* Keep only the modes --bench-modes names. */
static void bench_filter(const vv_options *o, bench_scene *b)
{
    int k = 0;
    for (int m = 0; m < b->nm; m++)
        if (bench_keeps(o, b->modes[m].name))
            b->modes[k++] = b->modes[m];
    b->nm = k;
}

/* A row of vv_modes as a timed mode (its JSON name), drawn by renderer 0. */
static bench_mode bench_row(const vv_mode *m, const char *name)
{
    return (bench_mode){m->mode, m->pcf, name, m->stream, 0, 0, 0};
}

/* --bench-cube-sizes: each cube mode at each size (cubeN and cube_pcfN),
 * drawn by renderer 1 + i. */
static void add_cube_sizes(const vv_options *o, bench_scene *b)
{
    static char names[8][VV_MAX_MODES][24];
    for (int i = 0; i < o->bench_cube_count && b->nm < BENCH_MODES - 1; i++)
        for (int k = 0; vv_modes[k].name; k++) {
            const vv_mode *m = &vv_modes[k];
            if (!(m->flags & VV_MODE_BENCH) || m->mode != VR_MODE_CUBE)
                continue;
            snprintf(names[i][k], sizeof names[i][k], "%s%d", m->json, o->bench_cube_sizes[i]);
            b->modes[b->nm] = bench_row(m, names[i][k]);
            b->modes[b->nm].renderer = 1 + i;
            b->modes[b->nm++].cube_size = o->bench_cube_sizes[i];
        }
}

/* The buffer modes of a log-distance scene (those are drawn per vertex
 * by every mode, so buf5 times the buffer's fetches against vdsh5's
 * attributes): buf5, each order above 5 (at most 6 of them), adaptive. */
static void add_buffer_modes(bench_scene *b)
{
    vr_scene_info info;
    vr_scene_get_info(b->scene, &info);
    if (info.quantity != VDSH_QUANTITY_LOG_DISTANCE)
        return;
    for (int k = 0; vv_modes[k].name && b->nm < BENCH_MODES - 1; k++)
        if ((vv_modes[k].flags & VV_MODE_BENCH_LOG) && vv_mode_available(b->scene, &vv_modes[k]))
            b->modes[b->nm++] = bench_row(&vv_modes[k], vv_modes[k].json);
}

/* --buffer-floats (copy 1): each buffer mode again, from a copy of the
 * scene whose buffers hold decoded f32 ("buf12-f32"): the same images,
 * 2-4x the bytes, no unpacking in the shader. --cpca-frame (copy 2): each
 * buffer mode of a cpca stream again, from a copy that decodes it once
 * per frame into a scratch (vr_scene_desc.cpca_decode, "buf12-frame").
 * --compute (copy 3): each buffer mode again, from a copy whose sums are
 * computed in a compute shader (vr_scene_desc.sums, "buf12-compute"; a
 * cpca stream decoded in the sums), and (copy 4) each cpca one again with
 * the stream decoded at load ("buf12-compute-load"). */
/* Whether buffer stream st of a scene with info is a cpca stream. */
static int cpca_stream(const vr_scene_info *info, int st)
{
    return st >= 1 && st < VDSH_ORDER_SLOTS && info->buffer_encoding[st] == VDSH_ENCODING_CPCA;
}

static int add_copy_modes(bench_scene *b, int copy)
{
    static const char *suffix[4] = {"f32", "frame", "compute", "compute-load"};
    static char names[4][VV_MAX_MODES][32];
    int n = b->nm, any = 0;
    vr_scene_info info;
    vr_scene_get_info(b->scene, &info);
    /* copies 2 and 4 differ from the scene in their cpca streams only */
    const int cpca_only = copy == 2 || copy == 4;
    for (int m = 0; m < n; m++)
        any |= b->modes[m].mode == VR_MODE_VDSH_BUFFER && !b->modes[m].from_copy &&
               (!cpca_only || cpca_stream(&info, b->modes[m].stream));
    if (!any)
        return 0;
    vr_error err;
    vr_scene_desc sd = {.path = b->path,
                        .skip_cubemaps = 1,
                        .buffers = 1,
                        .buffer_floats = copy == 1,
                        .cpca_decode = copy == 2   ? VR_CPCA_PER_FRAME
                                       : copy == 4 ? VR_CPCA_AT_LOAD
                                                   : VR_CPCA_PER_PASS,
                        .sums = copy >= 3 ? VR_SUMS_COMPUTE : VR_SUMS_VERTEX};
    if (vr_scene_create(&sd, &b->copy[copy - 1], &err) != VR_OK) {
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
        return 1;
    }
    for (int m = 0; m < n && b->nm < BENCH_MODES; m++) {
        int k = vv_mode_find(b->modes[m].name, strlen(b->modes[m].name), VV_MODE_BENCH_LOG);
        if (b->modes[m].mode != VR_MODE_VDSH_BUFFER || b->modes[m].from_copy || k < 0 ||
            (cpca_only && !cpca_stream(&info, b->modes[m].stream)))
            continue;
        snprintf(names[copy - 1][k], sizeof names[copy - 1][k], "%s-%s", vv_modes[k].json,
                 suffix[copy - 1]);
        bench_mode f = b->modes[m];
        f.name = names[copy - 1][k];
        f.from_copy = copy;
        b->modes[b->nm++] = f;
    }
    return 0;
}

/* Load a scene and choose the modes it is timed in. */
static int bench_open(const vv_options *o, const char *path, bench_scene *b)
{
    int shadow = o->shadow_size ? o->shadow_size : VR_DEFAULT_SHADOW_MAP_SIZE;
    b->path = path;
    if (vv_open_scene(o, path, &b->scene))
        return 1;
    for (int i = 0; vv_modes[i].name; i++) {
        const vv_mode *m = &vv_modes[i];
        /* On a log-distance scene both order-5 modes draw the same
         * per-vertex program: time it once, as vdsh5. */
        int same = m->mode == VR_MODE_VDSH5_POLY && vr_scene_supports(b->scene, VR_MODE_VDSH5) &&
                   vr_scene_interp(b->scene, VR_MODE_VDSH5) == VDSH_INTERP_DISTANCE;
        /* --bench-cube-sizes: the sized cubes replace cube and cube_pcf. */
        int sized = m->mode == VR_MODE_CUBE && o->bench_cube_count;
        if ((m->flags & VV_MODE_BENCH) && vv_mode_available(b->scene, m) && !same && !sized) {
            b->modes[b->nm] = bench_row(m, m->json);
            if (m->mode == VR_MODE_CUBE)
                b->modes[b->nm].cube_size = shadow;
            b->nm++;
        }
    }
    add_cube_sizes(o, b);
    add_buffer_modes(b);
    if (o->buffer_floats && add_copy_modes(b, 1))
        return 1;
    if (o->cpca_frame && add_copy_modes(b, 2))
        return 1;
    if (o->compute && (add_copy_modes(b, 3) || add_copy_modes(b, 4)))
        return 1;
    bench_filter(o, b);
    if (!b->nm) {
        fprintf(stderr, "vdsh-view: %s: no mode of --bench-modes %s in this file\n", path,
                o->bench_modes);
        return 1;
    }
    for (int ls = 0; ls < BENCH_SETS; ls++) {
        b->nl[ls] = vv_default_lights(b->scene, o, bench_light_sets[ls], b->lights[ls]);
        if (b->nl[ls] < bench_light_sets[ls]) {
            fprintf(stderr, "vdsh-view: %s: only %d light positions in free space, not %d\n", path,
                    b->nl[ls], bench_light_sets[ls]);
            return 1;
        }
    }
    return 0;
}

/* The scene mode m of bs draws: the scene, or one of its copies. */
static const vr_scene *mode_scene(const bench_scene *bs, int m)
{
    return bs->modes[m].from_copy ? bs->copy[bs->modes[m].from_copy - 1] : bs->scene;
}

/* Mode m of scene bs at light set ls: the draw's description (*d) and the
 * scene it draws (the float-coefficient copy for the buffer modes that
 * read floats). */
static const vr_scene *mode_desc(const vv_options *o, const bench_scene *bs, int ls, int m,
                                 vr_draw_desc *d)
{
    *d = vv_base_desc(o, bs->lights[ls], bs->nl[ls]);
    d->mode = bs->modes[m].mode;
    d->pcf = bs->modes[m].pcf;
    d->stream = bs->modes[m].stream;
    vv_scene_camera(bs->scene, o, &d->camera);
    return mode_scene(bs, m);
}

/* Time every mode of every scene, with 1 light, then 3, 16 and 64.
 * Warm-up first (two rounds, one for the long frames of 16 and 64
 * lights): compile every program and allocate every shadow map before
 * anything is timed. Then rounds that each time every (scene, mode) once,
 * starting at a different one each round, so that slow drifts of a shared
 * machine spread over all scenes and modes alike: a ratio between any two
 * of them compares frames of the same minutes. */
static int bench_time(const vv_options *o, bench_scene *b, int nb, vr_renderer **rs, int rounds)
{
    int total = 0;
    for (int i = 0; i < nb; i++)
        total += b[i].nm;
    for (int ls = 0; ls < BENCH_SETS; ls++)
        for (int round = ls < 2 ? -2 : -1; bench_set_on(o, ls) && round < bench_rounds(ls, rounds);
             round++)
            for (int k = 0; k < total; k++) {
                int j = (k + (round > 0 ? round : 0)) % total, i = 0;
                while (j >= b[i].nm)
                    j -= b[i++].nm;
                bench_scene *bs = &b[i];
                vr_renderer *r = rs[bs->modes[j].renderer];
                vr_draw_desc d;
                const vr_scene *drawn = mode_desc(o, bs, ls, j, &d);
                vr_error err;
                double proc0 = process_cpu_ms();
                if (vr_draw(r, drawn, &d, &err) != VR_OK) {
                    fprintf(stderr, "vdsh-view: %s: %s: %s\n", bs->path, bs->modes[j].name,
                            err.msg);
                    return 1;
                }
                vr_renderer_finish(r);
                double proc1 = process_cpu_ms();
                vr_timings t;
                vr_renderer_timings(r, &t);
                if (round >= 0) {
                    bs->proc[ls][j][round] = proc1 - proc0;
                    bs->cpu[ls][j][round] = t.cpu_ms;
                    bs->gpu[ls][j][round] = t.gpu_ms;
                    bs->shadow[ls][j][round] = t.shadow_total_ms;
                    bs->lighting[ls][j][round] = t.lighting_total_ms;
                }
            }
    return 0;
}

/* --bench-counts: one more frame of every (scene, mode, light set) with
 * the GL's counters around it (untimed). */
static int bench_count(const vv_options *o, bench_scene *b, int nb, vr_renderer **rs)
{
    for (int i = 0; i < nb; i++)
        for (int ls = 0; ls < BENCH_SETS; ls++)
            for (int m = 0; m < b[i].nm && bench_set_on(o, ls); m++) {
                bench_scene *bs = &b[i];
                vr_draw_desc d;
                const vr_scene *drawn = mode_desc(o, bs, ls, m, &d);
                vr_error err;
                if (vr_draw_counted(rs[bs->modes[m].renderer], drawn, &d, &bs->counts[ls][m],
                                    &err) != VR_OK) {
                    fprintf(stderr, "vdsh-view: %s: %s: %s\n", bs->path, bs->modes[m].name,
                            err.msg);
                    return 1;
                }
            }
    return 0;
}

/* One scene's JSON object (and a summary on stderr). */
static void bench_print(const vv_options *o, const bench_scene *b, int all_rounds, vt_json *j,
                        cJSON *list)
{
    vr_scene_info info;
    vr_scene_get_info(b->scene, &info);
    uint32_t method = 0;
    for (int k = 1; k <= VDSH_MAX_ORDER; k++)
        if (info.has_order[k])
            method = info.method[k];
    cJSON *so = vt_json_object(j, list, NULL);
    vt_json_string(j, so, "file", b->path);
    vt_json_u64(j, so, "vertices", info.vertex_count);
    vt_json_u64(j, so, "triangles", info.triangle_count);
    vt_json_string(j, so, "quantity", vdsh_quantity_name(info.quantity));
    vt_json_string(j, so, "method", vdsh_method_name(method));
    vt_json_u64(j, so, "gpu_bytes", info.gpu_bytes);
    vt_json_u64(j, so, "buffer_bytes", info.buffer_bytes);
    vt_json_i64(j, so, "variable_order", info.variable_order);
    vt_json_f64(j, so, "variable_mean_order", info.variable_mean_order);
    cJSON *results = vt_json_array(j, so, "results");
    for (int ls = 0; ls < BENCH_SETS; ls++)
        for (int m = 0; m < b->nm && bench_set_on(o, ls); m++) {
            int rounds = bench_rounds(ls, all_rounds);
            double sorted[BENCH_ROUNDS];
            memcpy(sorted, b->cpu[ls][m], (size_t)rounds * sizeof(double));
            qsort(sorted, (size_t)rounds, sizeof(double), cmp_double);
            int interp = vr_scene_interp(b->scene, b->modes[m].mode);
            cJSON *r = vt_json_object(j, results, NULL);
            vt_json_i64(j, r, "lights", b->nl[ls]);
            vt_json_string(j, r, "mode", b->modes[m].name);
            vt_json_string(j, r, "path",
                           interp >= 0 ? vdsh_interp_name((uint32_t)interp) : b->modes[m].name);
            vt_json_f64(j, r, "median_cpu_ms", sorted[rounds / 2]);
            /* Texture lookups per fragment and light, and the texels they
             * read, from the shaders (runtime/vr_glsl.c): the cube map one
             * nearest depth compare or with PCF four bilinear ones; order 5
             * on the paper's path four basis cube maps (bilinear); every
             * other mode none in the fragment stage. */
            int lookups = 0, texels = 0;
            if (b->modes[m].mode == VR_MODE_CUBE)
                lookups = b->modes[m].pcf ? 4 : 1, texels = b->modes[m].pcf ? 16 : 1;
            else if (b->modes[m].mode == VR_MODE_VDSH5 && interp >= 0 &&
                     interp != VDSH_INTERP_DISTANCE)
                lookups = 4, texels = 16;
            vt_json_i64(j, r, "texture_lookups_per_fragment_light", lookups);
            vt_json_i64(j, r, "texels_per_fragment_light", texels);
            if (b->modes[m].mode == VR_MODE_CUBE) {
                /* Depth cube maps, 32-bit float: one per light of a pass. */
                int per = b->nl[ls] < VR_MAX_LIGHTS_PER_PASS ? b->nl[ls] : VR_MAX_LIGHTS_PER_PASS;
                uint64_t face = (uint64_t)b->modes[m].cube_size * (uint64_t)b->modes[m].cube_size;
                vt_json_i64(j, r, "cube_size", b->modes[m].cube_size);
                vt_json_u64(j, r, "cube_bytes", (uint64_t)per * 6u * face * 4u);
            }
            if (b->modes[m].mode == VR_MODE_SDF) {
                /* The distance volume (R16); each trace step reads 8
                 * texels by texelFetch (shaders/vr_sdf.glsl), at most 64
                 * steps per fragment and light. */
                vt_json_u64(j, r, "sdf_bytes", info.sdf_bytes);
                vt_json_i64(j, r, "texels_per_sdf_step", 8);
            }
            if (o->bench_counts) {
                const vr_counts *c = &b->counts[ls][m];
                cJSON *co = vt_json_object(j, r, "counts");
                vt_json_bool(j, co, "pipeline_statistics", c->statistics);
                vt_json_u64(j, co, "samples_passed", c->samples_passed);
                vt_json_u64(j, co, "primitives_generated", c->primitives_generated);
                if (c->statistics) {
                    vt_json_u64(j, co, "vertices_submitted", c->vertices_submitted);
                    vt_json_u64(j, co, "vertex_shader_invocations", c->vertex_invocations);
                    vt_json_u64(j, co, "fragment_shader_invocations", c->fragment_invocations);
                    vt_json_u64(j, co, "clipping_input_primitives", c->clipping_primitives);
                }
            }
            if (b->modes[m].mode == VR_MODE_VDSH_BUFFER)
                vt_json_u64(j, r, "buffer_bytes",
                            vr_scene_buffer_bytes(mode_scene(b, m), b->modes[m].stream));
            json_series(j, r, "cpu_ms", b->cpu[ls][m], rounds);
            json_series(j, r, "process_cpu_ms", b->proc[ls][m], rounds);
            json_series(j, r, "gpu_ms", b->gpu[ls][m], rounds);
            json_series(j, r, "shadow_ms", b->shadow[ls][m], rounds);
            json_series(j, r, "lighting_ms", b->lighting[ls][m], rounds);
            if (!o->quiet)
                fprintf(stderr, "vdsh-view: %s, %d light%s, %-9s median %.1f ms\n", b->path,
                        b->nl[ls], b->nl[ls] == 1 ? "" : "s", b->modes[m].name, sorted[rounds / 2]);
        }
}

/* The results as one JSON document on stdout (vt_json.h), printed once
 * every scene has been timed. */
int vv_run_bench(const vv_options *o)
{
    int w = o->have_size ? o->width : VR_DEFAULT_WIDTH;
    int h = o->have_size ? o->height : VR_DEFAULT_HEIGHT;
    vr_context *ctx = NULL;
    vr_renderer *rs[9] = {NULL}, *r = NULL;
    if (vv_open_headless(o, w, h, 0, &ctx, &r) != 0)
        return 1;
    rs[0] = r;
    int rc = 0;
    for (int i = 0; i < o->bench_cube_count && !rc; i++) {
        vr_renderer_desc rd = {.width = w, .height = h, .shadow_map_size = o->bench_cube_sizes[i]};
        vr_error err;
        if (vr_renderer_create(&rd, &rs[1 + i], &err) != VR_OK) {
            fprintf(stderr, "vdsh-view: %s\n", err.msg);
            rc = 1;
        }
    }
    int rounds = o->frames ? (o->frames < BENCH_ROUNDS ? o->frames : BENCH_ROUNDS) : 7;
    vt_json j = {0};
    cJSON *root = vt_json_object(&j, NULL, NULL);
    vt_json_string(&j, root, "version", VDSH_VERSION_STRING);
    vt_json_string(&j, root, "renderer", vr_gl_renderer());
    vt_json_string(&j, root, "context", vr_context_description(ctx));
    vt_json_i64(&j, root, "width", w);
    vt_json_i64(&j, root, "height", h);
    vt_json_i64(&j, root, "shadow_size",
                o->shadow_size ? o->shadow_size : VR_DEFAULT_SHADOW_MAP_SIZE);
    vt_json_bool(&j, root, "mallopt", !o->no_mallopt);
    vt_json_i64(&j, root, "rounds", rounds);
    cJSON *list = vt_json_array(&j, root, "scenes");
    bench_scene *b = calloc((size_t)o->file_count, sizeof *b);
    if (!b)
        rc = 1;
    if (!b)
        fprintf(stderr, "vdsh-view: out of memory\n");
    for (int i = 0; i < o->file_count && !rc; i++)
        rc = bench_open(o, o->files[i], &b[i]);
    if (!rc)
        rc = bench_time(o, b, o->file_count, rs, rounds);
    if (!rc && o->bench_counts)
        rc = bench_count(o, b, o->file_count, rs);
    for (int i = 0; i < o->file_count && !rc; i++)
        bench_print(o, &b[i], rounds, &j, list);
    char msg[256];
    if (!rc && (o->json_path ? vt_json_write_file(&j, o->json_path, msg, sizeof msg)
                             : vt_json_write_stream(&j, stdout, "stdout", msg, sizeof msg)) != 0) {
        fprintf(stderr, "vdsh-view: --bench: %s\n", msg);
        rc = 1;
    }
    vt_json_free(&j);
    for (int i = 0; b && i < o->file_count; i++) {
        vr_scene_destroy(b[i].scene);
        for (int c = 0; c < 4; c++)
            vr_scene_destroy(b[i].copy[c]);
    }
    free(b);
    for (int i = 0; i < 9; i++)
        vr_renderer_destroy(rs[i]);
    vr_context_destroy(ctx);
    return rc;
}
