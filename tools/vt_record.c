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
    const vdsh_stats *s = &f->stats;
    const struct {
        const char *key;
        uint64_t v;
    } count[] = {{"rays_traced", s->rays_traced},
                 {"rays_missed", s->rays_missed},
                 {"degenerate_receivers", s->degenerate_receivers},
                 {"undefined_normals", s->undefined_normals},
                 {"moved_origins", s->moved_origins},
                 {"flipped_normals", s->flipped_normals}};
    const size_t n = all ? sizeof count / sizeof count[0] : 4;
    cJSON *st = vt_json_object(j, parent, "stats");
    for (size_t i = 0; i < n; i++)
        vt_json_u64(j, st, count[i].key, count[i].v);
}

void vt_record_timings(vt_json *j, cJSON *parent, const vdsh_file *f)
{
    if (!f->has_timings) {
        vt_json_null(j, parent, "timings");
        return;
    }
    const vdsh_timings *t = &f->timings;
    const struct {
        const char *key;
        double v;
    } seconds[] = {{"load", t->load},
                   {"refine", t->refine},
                   {"build", t->build},
                   {"trace", t->trace},
                   {"total", t->total}};
    cJSON *tm = vt_json_object(j, parent, "timings");
    for (size_t i = 0; i < sizeof seconds / sizeof seconds[0]; i++)
        vt_json_f64(j, tm, seconds[i].key, seconds[i].v);
    vt_json_u64(j, tm, "threads", t->threads);
}
