/*
 * vt_record.c - a .vdsh's record of its bake as JSON (vt_record.h).
 */
#include "vt_record.h"

void vt_record_params(vt_json *j, cJSON *bake, const vdsh_header *h)
{
    vt_json_u64(j, bake, "rays", h->rays);
    vt_json_string(j, bake, "sampling", vdsh_sampling_name(h->sampling));
    vt_json_u64(j, bake, "seed", h->seed);
    vt_json_f32(j, bake, "max_distance", h->max_distance);
    vt_json_f32(j, bake, "max_edge", h->max_edge);
    vt_json_string(j, bake, "offset_rule", vdsh_offset_rule_name(h->offset_rule));
}

void vt_record_stats(vt_json *j, cJSON *parent, const vdsh_file *f, int all)
{
    if (!f->has_stats) {
        vt_json_null(j, parent, "stats");
        return;
    }
    cJSON *st = vt_json_object(j, parent, "stats");
    vt_json_u64(j, st, "rays_traced", f->stats.rays_traced);
    vt_json_u64(j, st, "rays_missed", f->stats.rays_missed);
    vt_json_u64(j, st, "degenerate_receivers", f->stats.degenerate_receivers);
    vt_json_u64(j, st, "undefined_normals", f->stats.undefined_normals);
    if (all) {
        vt_json_u64(j, st, "moved_origins", f->stats.moved_origins);
        vt_json_u64(j, st, "flipped_normals", f->stats.flipped_normals);
    }
}

void vt_record_timings(vt_json *j, cJSON *parent, const vdsh_file *f)
{
    if (!f->has_timings) {
        vt_json_null(j, parent, "timings");
        return;
    }
    const vdsh_timings *t = &f->timings;
    cJSON *tm = vt_json_object(j, parent, "timings");
    vt_json_f64(j, tm, "load", t->load);
    vt_json_f64(j, tm, "refine", t->refine);
    vt_json_f64(j, tm, "build", t->build);
    vt_json_f64(j, tm, "trace", t->trace);
    vt_json_f64(j, tm, "total", t->total);
    vt_json_u64(j, tm, "threads", t->threads);
}
