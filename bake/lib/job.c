/* job.c - a whole bake as one straight line (job.h). */
#include "job.h"

#include <libgen.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "origins.h"
#include "vdsh_output.h"

int vb_job_cube_size(const vb_job_desc *d)
{
    /* The cubemaps serve orders 4 and 5 (functions 9..24; vdsh_cube.h).
     * No fixed order with an adaptive order: its stream alone, drawn from
     * buffers (bake.c resolve_orders), which the cubemaps do not serve
     * (they were written, and recorded in the header, for such a file). */
    uint32_t mask = d->bake.order_mask;
    if (mask == 0 && d->bake.order_tolerance > 0.0f)
        return 0;
    if (mask == 0)
        mask = 1u << (d->bake.max_order ? d->bake.max_order : VB_DEFAULT_ORDER); /* bake.h */
    if (!(mask & (1u << 4 | 1u << 5)) || d->cube_size < 0)
        return 0;
    return d->cube_size > 0 ? d->cube_size : VB_DEFAULT_CUBE_SIZE;
}

static void *encode_basis(void *arg)
{
    vb_job *j = arg;
    j->basis_result = vb_cubemap_basis_encode(j->basis_size, &j->basis, &j->basis_err);
    return NULL;
}

vb_result vb_job_load(vb_job *j, const vb_job_desc *d, vb_error *err)
{
    if (d->path_count < 1 || d->path_count > VDSH_MAX_SOURCES)
        return vb_fail(err, VB_ERR_ARGUMENT, "%u meshes: 1..%d make a scene", d->path_count,
                       VDSH_MAX_SOURCES);
    /* A name the .vdsh cannot record (SRCS: UTF-8) is refused before the
     * bake, not by the writer after it. */
    for (uint32_t i = 0; i < d->path_count && d->output; i++) {
        char why[200];
        if (!vdsh_source_name_ok(d->paths[i], why, sizeof why))
            return vb_fail(err, VB_ERR_ARGUMENT,
                           "%s: its name %s, which a .vdsh cannot record as its source: "
                           "rename the file",
                           d->paths[i], why);
    }
    j->t_start = vb_now();
    j->sources = calloc(d->path_count, sizeof *j->sources);
    if (!j->sources)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    /* The basis cubemaps meanwhile (deflate, most of it); a part has none. */
    int cube_size = vb_job_cube_size(d);
    j->basis_size = cube_size;
    j->basis_running = cube_size > 0 && d->output && !d->bake.trace_only && !d->shard_count &&
                       pthread_create(&j->basis_thread, NULL, encode_basis, j) == 0;
    vb_load_desc ld = {.weld = d->weld,
                       .up_axis = d->up_axis,
                       .crease = d->crease > 0 && d->crease < 180 ? d->crease : 0};
    for (uint32_t i = 0; i < d->path_count; i++) {
        const char *path = d->paths[i];
        vb_mesh m = {0};
        vb_source_info info;
        double t = vb_now();
        vb_result r = vb_mesh_load(path, &ld, &m, &info, err);
        if (r == VB_OK)
            r = vb_mesh_append(&j->occluders, &m, err);
        if (r != VB_OK) {
            vb_mesh_free(&m);
            return r;
        }
        j->sources[i].name = (char *)path;
        j->sources[i].size = info.size;
        memcpy(j->sources[i].sha256, info.sha256, 32);
        j->source_count = i + 1;
        j->creased |= info.report.crease_vertices > 0;
        if (d->on_mesh)
            d->on_mesh(d->user, path, &m, &info, vb_now() - t);
        vb_mesh_free(&m);
    }
    j->timings.load = vb_now() - j->t_start;
    /* A scene whose every triangle has no area (collinear corners, or one
     * point) casts and receives nothing: said here, naming the files,
     * rather than as a zero scene diagonal deep in the bake. */
    const vb_mesh *o = &j->occluders;
    int any_area = 0;
    for (uint32_t t = 0; t < o->triangle_count && !any_area; t++)
        any_area = vb_triangle_has_area(o->positions, o->indices + 3 * (size_t)t);
    if (!any_area)
        return vb_fail(err, VB_ERR_INVALID,
                       "%s%s: no triangle has any area (all %u are a line or a point): "
                       "nothing casts or receives a shadow",
                       d->paths[0], d->path_count > 1 ? " and the other meshes" : "",
                       o->triangle_count);
    /* Too large for single precision (coordinates near FLT_MAX): said here,
     * rather than as an infinite diagonal, or Embree's abort on rays of
     * infinite length, deep in the bake. */
    float lo[3], hi[3];
    vb_mesh_bounds(o, lo, hi);
    double diag2 = 0.0, far = 0.0;
    for (int k = 0; k < 3; k++) {
        const double e = (double)hi[k] - (double)lo[k];
        diag2 += e * e;
        far = fmax(far, fmax(fabs((double)lo[k]), fabs((double)hi[k])));
    }
    if (!(sqrt(diag2) <= VB_MAX_DIAGONAL))
        return vb_fail(err, VB_ERR_INVALID,
                       "%s%s: the scene is %.3g across (coordinates up to %.3g): more than the "
                       "bake takes, %g (its frame and distances are single precision); scale "
                       "it down",
                       d->paths[0], d->path_count > 1 ? " and the other meshes" : "", sqrt(diag2),
                       far, VB_MAX_DIAGONAL);
    return VB_OK;
}

vb_result vb_job_refine(vb_job *j, const vb_job_desc *d, vb_error *err)
{
    double t = vb_now();
    vb_result r;
    if (d->receivers_path) {
        r = vb_mesh_load_plan(d->receivers_path, &j->receivers, err);
    } else {
        r = vb_mesh_refine(&j->occluders, d->max_edge, &j->receivers, err);
    }
    j->timings.refine = vb_now() - t;
    return r;
}

vb_result vb_job_check_shard(const vb_job *j, const vb_job_desc *d, vb_error *err)
{
    if (d->shard_count &&
        (d->shard_index >= d->shard_count || d->shard_count > j->receivers.vertex_count))
        return vb_fail(err, VB_ERR_ARGUMENT, "shard %u/%u: needs shard < count <= the %u receivers",
                       d->shard_index, d->shard_count, j->receivers.vertex_count);
    return VB_OK;
}

/* The encoding of the whole bake's streams (a part's are f32 whatever it is). */
static vdsh_encoding job_encoding(const vb_job_desc *d)
{
    return d->encoding_given ? d->encoding : VB_DEFAULT_ENCODING;
}

static vdsh_cpca_settings job_cpca_asked(const vb_job_desc *d)
{
    return d->cpca.clusters || d->cpca.budget ? d->cpca : vdsh_cpca_settings_default();
}

/* The light pool (bake.h, VB_POOL_SEED), placed once for the bake's
 * decision fit (all VB_DECISION_POOL lights, in every adaptive round) and
 * the cpca light-density metric (docs/ACCURACY.md "A light-density
 * metric": the first VB_CPCA_POOL, in scene units like the receivers'
 * positions, where a placement of that many alone finds room), whole bakes
 * and parts alike. A scene where the rule places no lights keeps the lsq
 * fits and the uniform metric: the same in every shard. */
static vb_result job_pool(vb_job *j, const vb_job_desc *d, vb_error *err)
{
    const int decision = vb_method_get(d->bake.method)->decision && !d->bake.trace_only;
    const int cpca = job_encoding(d) == VDSH_ENCODING_CPCA && !d->bake.trace_only &&
                     job_cpca_asked(d).light_mix > 0.0f;
    const uint32_t count = decision ? VB_DECISION_POOL : cpca ? VB_CPCA_POOL : 0;
    if (!count)
        return VB_OK;
    if (!(j->pool = malloc(count * sizeof *j->pool)))
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for the light pool");
    const double t = vb_now();
    vb_error perr;
    int first_ok;
    vb_result r = vb_scene_place_pool(j->scene, d->bake.seed ^ VB_POOL_SEED, count, j->pool,
                                      VB_CPCA_POOL, &first_ok, &perr);
    j->pool_count = r == VB_OK ? count : 0;
    j->cpca_lights = cpca && first_ok ? VB_CPCA_POOL : 0;
    j->pool_seconds = vb_now() - t;
    return VB_OK;
}

vb_result vb_job_bake(vb_job *j, const vb_job_desc *d, vb_error *err)
{
    vb_result sr = vb_job_check_shard(j, d, err);
    if (sr != VB_OK)
        return sr;
    double t = vb_now();
    vb_scene_desc sd = {
        .robust = !d->fast_traversal, .threads = d->bake.threads, .corner_lift = j->creased};
    vb_result r = vb_scene_create(&j->occluders, &sd, &j->scene, err);
    if (r != VB_OK)
        return r;
    j->timings.build = vb_now() - t;
    if (d->light_region.rule) {
        j->light_region = d->light_region;
        if ((r = vb_scene_use_light_box(j->scene, &j->light_region, "--light-region", err)) !=
            VB_OK)
            return r;
    }
    vb_bake_desc bd = d->bake;
    if (d->shard_count) {
        vb_shard_range(j->receivers.vertex_count, d->shard_index, d->shard_count, &bd.range_begin,
                       &bd.range_end);
    }
    bd.receivers = &j->receivers;
    bd.scene = j->scene;
    if ((r = job_pool(j, d, err)) != VB_OK)
        return r;
    if (j->pool && vb_method_get(bd.method)->decision) {
        bd.pool = &j->pool[0][0];
        bd.pool_count = j->pool_count;
    }
    if (d->adaptive) {
        if (d->shard_count)
            return vb_fail(err, VB_ERR_ARGUMENT,
                           "adaptive receivers cannot be sharded yet (the refinement bakes "
                           "as it decides): bake them in one process");
        vb_mesh fine = {0};
        r = vb_bake_adaptive(&bd, &j->receivers, &d->adapt, &fine, &j->bake, &j->adaptive, err);
        if (r != VB_OK)
            return r;
        vb_mesh_free(&j->receivers);
        j->receivers = fine;
    } else if ((r = vb_bake_run(&bd, &j->bake, err)) != VB_OK) {
        return r;
    }
    if (d->shard_count && j->bake.normals) {
        /* The part's normals (VDSH.md "Parts"): the range's as oriented, the
         * others as loaded; the bake returned the range's rows only. */
        memcpy(j->receivers.normals + 3 * (size_t)bd.range_begin, j->bake.normals,
               (size_t)(bd.range_end - bd.range_begin) * 3 * sizeof *j->bake.normals);
        free(j->bake.normals);
        j->bake.normals = NULL;
    }
    j->timings.trace = j->bake.seconds;
    j->timings.threads = j->bake.threads;
    j->timings.total = vb_now() - j->t_start;
    return VB_OK;
}

/* job.h. The encoder's settings: what was asked for, with the job's pool and
 * receivers when the light mix is > 0 (job_pool placed it). */
vdsh_cpca_settings vb_job_cpca_settings(const vb_job *j, const vb_job_desc *d)
{
    vdsh_cpca_settings st = job_cpca_asked(d);
    st.threads = d->bake.threads; /* the starts' (0: every online core, as the bake's) */
    if (st.light_mix > 0.0f && j->cpca_lights) {
        st.light_count = j->cpca_lights;
        st.lights = &j->pool[0][0];
        st.positions = j->receivers.positions;
    }
    return st;
}

/* Stream s cpca-encoded from f32 (rows of every receiver) by the global
 * step, with the file's normals: the encoder's block replaces
 * j->stream_data[s] (f32's data, when it is there, is freed); on failure
 * the stream keeps f32's header without data. */
static vb_result job_cpca_encode(vb_job *j, const vb_job_desc *d, uint32_t s, vdsh_stream f32,
                                 const char *what, vb_error *err)
{
    vdsh_cpca_settings st = vb_job_cpca_settings(j, d);
    vdsh_error e;
    void *storage = NULL;
    const float *nrm = j->bake.normals ? j->bake.normals : j->receivers.normals;
    vdsh_result er = vdsh_cpca_encode_stream(&f32, j->receivers.vertex_count, nrm, &st,
                                             &j->streams[s], &storage, NULL, &e);
    free(j->stream_data[s]);
    j->stream_data[s] = storage;
    if (er != VDSH_OK) {
        j->streams[s] = f32; /* its block is freed: nothing of it stays */
        j->streams[s].data = NULL;
        return vb_fail(err, er == VDSH_ERR_OUT_OF_MEMORY ? VB_ERR_OUT_OF_MEMORY : VB_ERR_INVALID,
                       "%s stream: %s", what, e.msg);
    }
    return VB_OK;
}

/* --encoding cpca with --adaptive-order: the variable-order stream (f32, in
 * j->streams[s]) becomes a fixed stream of its cap's order whose rows are
 * each vertex's coefficients with zeros past its own order, cpca-encoded
 * by the global step, as vdsh-merge does with the joined parts' rows
 * (formats/VDSH.md, "cpca streams": the cpca layout has no order table). */
static vb_result cpca_variable(vb_job *j, const vb_job_desc *d, uint32_t s, vb_error *err)
{
    const uint32_t V = j->receivers.vertex_count;
    vdsh_stream var = j->streams[s];
    const size_t nc = (size_t)var.order * var.order;
    float *rows = malloc((size_t)V * nc * sizeof *rows + 1);
    if (!rows)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for the adaptive-order rows");
    for (uint32_t v = 0; v < V; v++)
        vdsh_stream_decode(&var, v, rows + v * nc); /* zeros past the vertex's order */
    vdsh_stream f32 = var;
    f32.flags = 0;
    f32.orders = NULL;
    f32.offsets = NULL;
    f32.coef_scales = NULL;
    f32.data = rows;
    vb_result r = job_cpca_encode(j, d, s, f32, "adaptive-order", err);
    free(rows);
    return r;
}

vb_result vb_bake_fill_file(vb_job *j, const vb_job_desc *d, vb_error *err)
{
    const vb_bake_output *b = &j->bake;
    uint32_t count = 0;
    j->coefficient_bytes = 0;
    if (!d->shard_count) {
        /* The quantised scales are over the drawn receivers (vdsh-merge
         * derives the same mask from the merged file's POSN and TRIS). */
        free(j->drawn);
        if (!(j->drawn = malloc((size_t)j->receivers.vertex_count + 1)))
            return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for %u receivers",
                           j->receivers.vertex_count);
        vb_drawn_receivers(j->receivers.positions, j->receivers.vertex_count, j->receivers.indices,
                           j->receivers.triangle_count, j->drawn);
        j->bake.drawn = j->drawn;
    }
    for (int o = 1; o <= VDSH_MAX_ORDER; o++) {
        if (!b->coeffs[o])
            continue;
        if (count == VDSH_MAX_STREAMS - (b->variable_orders != NULL))
            return vb_fail(err, VB_ERR_ARGUMENT, "more than %d streams", VDSH_MAX_STREAMS);
        /* The stream takes the bake's coefficients (an f32 part's) or a
         * copy of them, and the bake's are freed now: peak memory holds at
         * most one order's two copies, not every order's. */
        int cpca = !d->shard_count && job_encoding(d) == VDSH_ENCODING_CPCA;
        vb_result r = vb_bake_stream_take(
            &j->bake, o, d->shard_count || cpca ? VDSH_ENCODING_F32 : job_encoding(d),
            &j->streams[count], &j->stream_data[count], err);
        if (r != VB_OK)
            return r;
        if (cpca) { /* as vdsh-merge over the joined parts */
            char what[32];
            snprintf(what, sizeof what, "order %d", o);
            if ((r = job_cpca_encode(j, d, count, j->streams[count], what, err)) != VB_OK)
                return r;
        }
        j->coefficient_bytes += vdsh_stream_bytes_per_vertex(&j->streams[count]);
        count++;
    }
    if (b->variable_orders) { /* adaptive order: its average bytes per vertex */
        int cpca = !d->shard_count && job_encoding(d) == VDSH_ENCODING_CPCA;
        vb_result r =
            vb_bake_variable_stream(b, d->shard_count || cpca ? VDSH_ENCODING_F32 : job_encoding(d),
                                    &j->streams[count], &j->stream_data[count], err);
        if (r != VB_OK)
            return r;
        uint32_t rows = b->range_end ? b->range_end - b->range_begin : b->vertex_count;
        if (cpca && (r = cpca_variable(j, d, count, err)) != VB_OK)
            return r;
        j->variable_bytes = cpca ? vdsh_stream_size_of(&j->streams[count], rows).mean_bytes
                                 : (double)vdsh_stream_data_bytes(&j->streams[count], rows) / rows;
        count++;
        free(j->bake.variable_coeffs);
        j->bake.variable_coeffs = NULL;
    }
    vdsh_file f = {0};
    vdsh_header *h = &f.header;
    h->vertex_count = j->receivers.vertex_count;
    h->triangle_count = j->receivers.triangle_count;
    h->rays = b->rays;
    h->sampling = b->hemisphere ? VDSH_SAMPLING_HEMISPHERE : VDSH_SAMPLING_SPHERE;
    h->seed = d->bake.seed;
    h->max_distance = b->max_distance;
    h->max_edge = d->max_edge;
    h->offset_rule = VDSH_OFFSET_WB_AVG;
    if (d->adaptive) {
        f.has_adaptive = 1;
        f.adaptive = (vdsh_adaptive){.tolerance = d->adapt.tolerance,
                                     .min_edge = d->adapt.min_edge,
                                     .max_receivers = d->adapt.max_receivers,
                                     .lights = j->adaptive.lights,
                                     .max_rounds = j->adaptive.max_rounds,
                                     .start_receivers = j->adaptive.start_receivers,
                                     .rounds = j->adaptive.rounds,
                                     .candidates = j->adaptive.candidates};
    }
    if (d->light_region.rule) {
        f.has_light_box = 1;
        f.light_box = j->light_region;
    }
    h->load_flags = (d->weld ? VDSH_LOAD_WELD : 0) | (uint32_t)d->up_axis << VDSH_LOAD_UP_SHIFT |
                    (j->creased ? (uint32_t)d->crease << VDSH_LOAD_CREASE_SHIFT : 0);
    h->cube_size = (uint32_t)vb_job_cube_size(d);
    h->occluder_vertex_count = j->occluders.vertex_count;
    h->occluder_triangle_count = j->occluders.triangle_count;
    h->trace_flags = d->fast_traversal ? 0 : VDSH_TRACE_ROBUST;
    memcpy(h->bounds_min, j->scene->bounds_min, sizeof h->bounds_min);
    memcpy(h->bounds_max, j->scene->bounds_max, sizeof h->bounds_max);
    f.source_count = j->source_count;
    f.sources = j->sources;
    f.positions = j->receivers.positions;
    f.normals = b->normals ? b->normals : j->receivers.normals;
    f.indices = j->receivers.indices;
    f.stream_count = count;
    f.streams = j->streams;
    f.has_stats = 1;
    f.stats = (vdsh_stats){.rays_traced = b->rays_traced,
                           .rays_missed = b->rays_missed,
                           .degenerate_receivers = b->degenerate_receivers,
                           .undefined_normals = b->undefined_normals,
                           .moved_origins = b->moved_origins,
                           .flipped_normals = b->flipped_normals};
    f.has_timings = d->record_timings;
    f.timings = j->timings;
    if (d->shard_count) {
        f.has_part = 1;
        f.part = (vdsh_part){
            .index = d->shard_index, .count = d->shard_count, .encoding = job_encoding(d)};
        if (job_encoding(d) == VDSH_ENCODING_CPCA) { /* the pool for the merge */
            vdsh_cpca_settings st = vb_job_cpca_settings(j, d);
            vdsh_cpca_part_record(&st, &f);
        }
        vb_shard_range(h->vertex_count, d->shard_index, d->shard_count, &f.part.range_begin,
                       &f.part.range_end);
    }
    j->file = f;
    return VB_OK;
}

/* File stem and directory of OUT: "dir/room.vdsh" -> "dir", "room". */
static void split_output(const char *out, char *dir, char *stem, size_t cap)
{
    char a[PATH_MAX], b[PATH_MAX];
    snprintf(a, sizeof a, "%s", out);
    snprintf(b, sizeof b, "%s", out);
    snprintf(dir, cap, "%s", dirname(a));
    snprintf(stem, cap, "%s", basename(b));
    size_t n = strlen(stem);
    if (n > 5 && strcmp(stem + n - 5, ".vdsh") == 0)
        stem[n - 5] = '\0';
}

vb_result vb_output_cubemap_path(const char *output, const char *cubemap_dir, int k, char *buf,
                                 size_t cap, vb_error *err)
{
    char dir[PATH_MAX], stem[PATH_MAX];
    if (!output)
        return vb_fail(err, VB_ERR_ARGUMENT, "no output file");
    split_output(output, dir, stem, sizeof dir);
    return vb_cubemap_basis_path(cubemap_dir ? cubemap_dir : dir, stem, k, buf, cap, err);
}

int vb_output_has_cubemaps(const char *output, const char *cubemap_dir)
{
    return cubemap_dir != NULL || (output && !vdsh_output_is_stream(output));
}

vb_result vb_write_outputs(const vdsh_file *f, const char *output, const char *cubemap_dir,
                           const vb_cubemap_basis *b, vdsh_output *also, int also_count,
                           uint64_t *bytes, vb_error *err)
{
    if (!output)
        return vb_fail(err, VB_ERR_ARGUMENT, "no output file");
    if (!vb_output_has_cubemaps(output, cubemap_dir))
        b = NULL; /* not beside /dev/null or /dev/stdout */
    char dir[PATH_MAX], stem[PATH_MAX];
    split_output(output, dir, stem, sizeof dir);
    vdsh_output cubes[VB_CUBEMAP_BASIS_FILES], file = {.fd = -1};
    for (int k = 0; k < VB_CUBEMAP_BASIS_FILES; k++)
        cubes[k] = (vdsh_output){.fd = -1};
    /* 1. The .vdsh file, encoded in memory, then staged beside its target. */
    void *data = NULL;
    size_t size = 0;
    vdsh_error verr;
    vb_result r = VB_OK;
    if (vdsh_write_memory(f, &data, &size, &verr) != VDSH_OK) {
        const char *why = strncmp(verr.msg, "memory: ", 8) == 0 ? verr.msg + 8 : verr.msg;
        return vb_fail(err, VB_ERR_IO, "%s: %s", output, why);
    }
    if (vdsh_output_open(output, &file, &verr) != VDSH_OK) {
        r = vb_fail(err, VB_ERR_IO, "%s", verr.msg);
    } else {
        vdsh_output_put(&file, data, size);
        if (vdsh_output_finish(&file, &verr) != VDSH_OK)
            r = vb_fail(err, VB_ERR_IO, "%s", verr.msg);
    }
    free(data);
    /* 2. The cubemaps, staged too. */
    if (r == VB_OK && b)
        r = vb_cubemap_basis_stage(b, cubemap_dir ? cubemap_dir : dir, stem, cubes, err);
    /* 3. All complete: rename, the caller's staged files, then the
     * cubemaps, then the .vdsh file last. */
    int renamed = 0, renamed_also = 0;
    for (int k = 0; r == VB_OK && k < also_count; k++) {
        if (!also[k].path) /* none staged there */
            continue;
        if (vdsh_output_commit(&also[k], &verr) != VDSH_OK)
            r = vb_fail(err, VB_ERR_IO, "%s", verr.msg);
        else
            renamed_also++;
    }
    for (int k = 0; r == VB_OK && b && k < VB_CUBEMAP_BASIS_FILES; k++) {
        if (vdsh_output_commit(&cubes[k], &verr) != VDSH_OK)
            r = vb_fail(err, VB_ERR_IO, "%s", verr.msg);
        else
            renamed++;
    }
    if (r == VB_OK && vdsh_output_commit(&file, &verr) != VDSH_OK)
        r = vb_fail(err, VB_ERR_IO, "%s", verr.msg);
    if (r != VB_OK && renamed_also > 0)
        vb_append(err, " (%d side files were already replaced)", renamed_also);
    if (r != VB_OK && renamed > 0)
        vb_append(err, " (%d basis cubemaps were already replaced)", renamed);
    for (int k = 0; k < VB_CUBEMAP_BASIS_FILES; k++)
        vdsh_output_abort(&cubes[k]);
    vdsh_output_abort(&file);
    if (r == VB_OK && bytes)
        *bytes = size;
    return r;
}

vb_result vb_job_write(vb_job *j, const vb_job_desc *d, vdsh_output *also, int also_count,
                       vb_error *err)
{
    if (!d->output)
        return vb_fail(err, VB_ERR_ARGUMENT, "no output file");
    int cube_size = d->shard_count ? 0 : vb_job_cube_size(d); /* parts: the merge's */
    if (cube_size > 0) {
        if (j->basis_running)
            pthread_join(j->basis_thread, NULL);
        else /* no helper thread could start */
            j->basis_result = vb_cubemap_basis_encode(cube_size, &j->basis, &j->basis_err);
        j->basis_running = 0;
        if (j->basis_result != VB_OK) {
            *err = j->basis_err;
            return j->basis_result;
        }
    }
    return vb_write_outputs(&j->file, d->output, d->cubemap_dir, cube_size > 0 ? &j->basis : NULL,
                            also, also_count, &j->file_bytes, err);
}

void vb_shard_range(uint32_t v, uint32_t i, uint32_t n, uint32_t *begin, uint32_t *end)
{
    *begin = (uint32_t)((uint64_t)v * i / n);
    *end = (uint32_t)((uint64_t)v * (i + 1) / n);
}

void vb_job_free(vb_job *j)
{
    if (!j)
        return;
    if (j->basis_running)
        pthread_join(j->basis_thread, NULL);
    vb_cubemap_basis_free(&j->basis);
    free(j->pool);
    for (int s = 0; s < VDSH_MAX_STREAMS; s++)
        free(j->stream_data[s]);
    vb_bake_output_free(&j->bake);
    free(j->drawn);
    vb_scene_destroy(j->scene);
    vb_mesh_free(&j->receivers);
    vb_mesh_free(&j->occluders);
    free(j->sources);
    memset(j, 0, sizeof *j);
}
