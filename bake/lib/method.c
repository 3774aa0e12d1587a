/* method.c - the table of fit methods (method.h). One row per method. */
#include "method.h"

#include <string.h>

#define Q_DIST VB_QUANTITY_BIT(VDSH_QUANTITY_DISTANCE)
#define Q_LOG VB_QUANTITY_BIT(VDSH_QUANTITY_LOG_DISTANCE)

/* Method shadow's default log offsets, per order: how much longer than the
 * least-squares fit of ln d the stored distances are (a factor e^offset),
 * trading drawn shadows for fewer false ones. Chosen on the validation
 * scenes by frames (docs/ACCURACY.md, "Choosing the default: the log
 * offsets" and "Orders beyond 5: log offsets"; orders 11, 13 and 15 lie
 * between their measured neighbours). */
static const float shadow_offsets[] = {0.0f, 1.6f, 1.6f,  1.1f, 0.9f, 0.8f, 0.7f, 0.6f, 0.6f,
                                       0.5f, 0.5f, 0.45f, 0.4f, 0.4f, 0.4f, 0.4f, 0.4f};
_Static_assert(sizeof shadow_offsets / sizeof shadow_offsets[0] == VDSH_ORDER_SLOTS,
               "one log offset per order");

static const float zero_offsets[VDSH_ORDER_SLOTS] = {0};

static const vb_method_info methods[VB_METHOD_COUNT] = {
    [VB_METHOD_SHADOW] = {.method = VB_METHOD_SHADOW,
                          .stored = VDSH_METHOD_SHADOW,
                          .hemisphere = 1,
                          .fit = VB_FIT_LSQ,
                          .regularised = 1,
                          .lambda_fixed = 1,
                          .param = VB_PARAM_LOG_OFFSET,
                          .quantities = Q_LOG,
                          .refused = {[VDSH_QUANTITY_DISTANCE] =
                                          "--method shadow fits the log distance: use "
                                          "--quantity log or auto, or --method lsq for "
                                          "the distance"},
                          .default_log_offset = shadow_offsets,
                          .help = "lsq of the log distance, the stored\n"
                                  "distances then e^offset times the fit's\n"
                                  "(--log-offset; fewer false shadows where a light\n"
                                  "sits just past a silhouette)"},
    [VB_METHOD_LSQ] = {.method = VB_METHOD_LSQ,
                       .stored = VDSH_METHOD_LSQ,
                       .hemisphere = 1,
                       .fit = VB_FIT_LSQ,
                       .regularised = 1,
                       .param = VB_PARAM_LAMBDA,
                       .quantities = Q_DIST | Q_LOG,
                       .help = "regularised least squares to the upper\nhemisphere"},
    [VB_METHOD_MIRROR] = {.method = VB_METHOD_MIRROR,
                          .stored = VDSH_METHOD_MIRROR,
                          .hemisphere = 1,
                          .fit = VB_FIT_MIRROR,
                          .quantities = Q_DIST | Q_LOG,
                          .help = "the upper hemisphere, mirrored below"},
    [VB_METHOD_PAPER] =
        {.method = VB_METHOD_PAPER,
         .stored = VDSH_METHOD_PAPER,
         .horizon = 1,
         .fit = VB_FIT_IDENTITY,
         .quantities = Q_DIST,
         .refused = {[VDSH_QUANTITY_LOG_DISTANCE] =
                         "log-distance needs --method mirror, lsq or full: the paper's zero fill "
                         "below the horizon has no meaning for ln(distance)"},
         .help = "the paper's fit, directions below the\n"
                 "horizon count as distance 0"},
    [VB_METHOD_DECISION] = {.method = VB_METHOD_DECISION,
                            .stored = VDSH_METHOD_DECISION,
                            .hemisphere = 1,
                            .fit = VB_FIT_LSQ,
                            .regularised = 1,
                            .lambda_fixed = 1,
                            .param = VB_PARAM_LOG_OFFSET,
                            .quantities = Q_LOG,
                            .refused = {[VDSH_QUANTITY_DISTANCE] =
                                            "--method decision fits the log distance: use "
                                            "--quantity log or auto"},
                            .default_log_offset = zero_offsets,
                            .decision = 1,
                            .help = "the log distance fitted to the shadow\n"
                                    "decision under lights in the scene's free\n"
                                    "space (traced), its log offset calibrated\n"
                                    "per scene and order at bake time"},
    [VB_METHOD_FULL] = {.method = VB_METHOD_FULL,
                        .stored = VDSH_METHOD_FULL,
                        .fit = VB_FIT_IDENTITY,
                        .quantities = Q_DIST | Q_LOG,
                        .help = "the whole sphere, no horizon"},
};

const vb_method_info *vb_method_get(vb_method method)
{
    return (unsigned)method < VB_METHOD_COUNT ? &methods[method] : NULL;
}

const vb_method_info *vb_method_stored(uint32_t stored)
{
    for (int i = 0; i < VB_METHOD_COUNT; i++)
        if ((uint32_t)methods[i].stored == stored)
            return &methods[i];
    return NULL;
}

const vb_method_info *vb_method_by_name(const char *name)
{
    for (int i = 0; i < VB_METHOD_COUNT; i++)
        if (strcmp(vdsh_method_name(methods[i].stored), name) == 0)
            return &methods[i];
    return NULL;
}

const char *vb_method_name(vb_method method)
{
    const vb_method_info *m = vb_method_get(method);
    return m ? vdsh_method_name(m->stored) : "?";
}

vdsh_quantity vb_quantity_stored(vb_quantity q)
{
    return q == VB_QUANTITY_LOG ? VDSH_QUANTITY_LOG_DISTANCE : VDSH_QUANTITY_DISTANCE;
}
