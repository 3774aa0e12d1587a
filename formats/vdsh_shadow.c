#include "vdsh_shadow.h"

#include <math.h>
#include <string.h>

#include "vdsh.h"
#include "vdsh_sh.h"

float vdsh_ramp(float x)
{
    /* (x - 1/3) * 1.5 written so that x = 1/3 and x = 1 give exactly 0
     * and 1 in float (the shaders use the same form and constants). */
    float s = VDSH_RAMP_SLOPE * x - VDSH_RAMP_OFFSET;
    return s > 0.0f ? (s < 1.0f ? s : 1.0f) : 0.0f; /* NaN fails both: 0 */
}

/* The quantity's distance from an SH sum, clamped to [0, max_distance]
 * (the top of vdsh_shadow.h). A NaN max_distance clamps nothing. */
static float from_sum(uint32_t quantity, float max_distance, float sum)
{
    float d;
    switch (quantity) {
    case VDSH_QUANTITY_DISTANCE2: d = sum > 0.0f ? sqrtf(sum) : 0.0f; break;
    case VDSH_QUANTITY_LOG_DISTANCE:
        d = expf(sum < VDSH_LOG_SUM_MAX ? sum : VDSH_LOG_SUM_MAX);
        break;
    default: d = sum > 0.0f ? sum : 0.0f; break;
    }
    return d > max_distance ? max_distance : d;
}

float vdsh_stream_distance(uint32_t order, uint32_t quantity, float max_distance, const float *c,
                           const float d[3])
{
    return from_sum(quantity, max_distance, vdsh_sh_reconstruct((int)order, c, d));
}

/* The comparisons, for d_light > 0 (vdsh_shadow_compare handles the
 * rest): one row each, by vdsh_compare value. */
static float compare_smooth(float d_vis, float d_light)
{
    if (isinf(d_vis) && d_vis > 0.0f)
        return 1.0f;
    return vdsh_ramp(d_vis / d_light);
}

static float compare_binary(float d_vis, float d_light)
{
    return d_vis >= d_light ? 1.0f : 0.0f;
}

static const struct {
    const char *name;
    float (*fn)(float d_vis, float d_light);
} compares[VDSH_COMPARE_COUNT] = {
    [VDSH_COMPARE_SMOOTH] = {"smooth", compare_smooth},
    [VDSH_COMPARE_BINARY] = {"binary", compare_binary},
};

const char *vdsh_compare_name(uint32_t compare)
{
    return compare < VDSH_COMPARE_COUNT ? compares[compare].name : "?";
}

vdsh_compare vdsh_compare_by_name(const char *name)
{
    for (int i = 0; i < VDSH_COMPARE_COUNT; i++)
        if (strcmp(compares[i].name, name) == 0)
            return (vdsh_compare)i;
    return VDSH_COMPARE_COUNT;
}

float vdsh_shadow_compare(float d_vis, float d_light, uint32_t compare)
{
    if (!(d_light > 0.0f)) /* at the receiver (or NaN): unshadowed */
        return d_light == 0.0f ? 1.0f : 0.0f;
    /* An unknown value compares smoothly, as before the table. */
    return compares[compare < VDSH_COMPARE_COUNT ? compare : VDSH_COMPARE_SMOOTH].fn(d_vis,
                                                                                     d_light);
}

float vdsh_shadow(uint32_t order, uint32_t quantity, float max_distance, const float *c,
                  const float p[3], const float l[3], uint32_t compare)
{
    float v[3] = {l[0] - p[0], l[1] - p[1], l[2] - p[2]};
    float dl = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(dl > 0.0f))
        return vdsh_shadow_compare(0.0f, dl, compare);
    for (int i = 0; i < 3; i++)
        v[i] /= dl;
    return vdsh_shadow_compare(vdsh_stream_distance(order, quantity, max_distance, c, v), dl,
                               compare);
}

const char *vdsh_interp_name(uint32_t interp)
{
    static const char *const n[] = {"coefficients", "distance", "visibility", "split"};
    return interp < 4 ? n[interp] : "?";
}

uint32_t vdsh_runtime_interp(uint32_t order, uint32_t quantity)
{
    if (quantity == VDSH_QUANTITY_LOG_DISTANCE)
        return VDSH_INTERP_DISTANCE;
    return order <= 3 ? VDSH_INTERP_VISIBILITY : VDSH_INTERP_SPLIT;
}

/* Unit direction and distance from a to b; 0 distance for a == b. */
static float toward(const float a[3], const float b[3], float d[3])
{
    float v[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    float len = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int i = 0; i < 3; i++)
        d[i] = len > 0.0f ? v[i] / len : 0.0f;
    return len;
}

float vdsh_shadow_interior(uint32_t order, uint32_t quantity, float max_distance, uint32_t interp,
                           const float *const c[3], const float *const pv[3], const float b[3],
                           const float l[3], uint32_t compare, float *d_vis)
{
    const int n = (int)(order * order);
    float p[3], w[3];
    for (int i = 0; i < 3; i++)
        p[i] = b[0] * pv[0][i] + b[1] * pv[1][i] + b[2] * pv[2][i];
    const float dl = toward(p, l, w);

    if (interp == VDSH_INTERP_COEFFICIENTS || interp > VDSH_INTERP_SPLIT ||
        (interp == VDSH_INTERP_SPLIT && order < 4)) {
        float ci[VDSH_MAX_COEFFS];
        for (int i = 0; i < n; i++)
            ci[i] = b[0] * c[0][i] + b[1] * c[1][i] + b[2] * c[2][i];
        float d = dl > 0.0f ? vdsh_stream_distance(order, quantity, max_distance, ci, w) : 0.0f;
        if (d_vis)
            *d_vis = d;
        return vdsh_shadow_compare(d, dl, compare);
    }
    if (interp == VDSH_INTERP_SPLIT) {
        /* Bands 0-2 toward the light from each vertex, interpolated;
         * bands 3-4 at p from interpolated coefficients. */
        float sum9 = 0.0f, y[VDSH_MAX_COEFFS], ci[VDSH_MAX_COEFFS];
        for (int k = 0; k < 3; k++) {
            float dk[3];
            if (!(toward(pv[k], l, dk) > 0.0f))
                continue; /* the runtime stores 0 for a light at the vertex */
            vdsh_sh_eval(3, dk, y);
            float s = 0.0f;
            for (int i = 0; i < 9; i++)
                s += c[k][i] * y[i];
            sum9 += b[k] * s;
        }
        vdsh_sh_eval((int)order, w, y);
        float sum16 = 0.0f;
        for (int i = 9; i < n; i++) {
            ci[i] = b[0] * c[0][i] + b[1] * c[1][i] + b[2] * c[2][i];
            sum16 += ci[i] * y[i];
        }
        float d = dl > 0.0f ? from_sum(quantity, max_distance, sum9 + sum16) : 0.0f;
        if (d_vis)
            *d_vis = d;
        return vdsh_shadow_compare(d, dl, compare);
    }
    /* DISTANCE and VISIBILITY: each vertex toward the light. */
    float dv[3];
    for (int k = 0; k < 3; k++)
        dv[k] = vdsh_vertex_distance(order, quantity, max_distance, c[k], pv[k], l);
    if (interp == VDSH_INTERP_DISTANCE)
        return vdsh_shadow_interior_distance(dv, pv, b, l, compare, d_vis);
    float d = 0.0f, s = 0.0f;
    for (int k = 0; k < 3; k++) {
        float dk[3];
        float dlk = toward(pv[k], l, dk);
        d += b[k] * dv[k];
        s += b[k] * vdsh_shadow_compare(dv[k], dlk, compare);
    }
    if (d_vis)
        *d_vis = d;
    return s;
}

float vdsh_vertex_distance(uint32_t order, uint32_t quantity, float max_distance, const float *c,
                           const float pv[3], const float l[3])
{
    float dk[3];
    float dlk = toward(pv, l, dk);
    return dlk > 0.0f ? vdsh_stream_distance(order, quantity, max_distance, c, dk) : 0.0f;
}

float vdsh_shadow_interior_distance(const float dv[3], const float *const pv[3], const float b[3],
                                    const float l[3], uint32_t compare, float *d_vis)
{
    float p[3], w[3];
    for (int i = 0; i < 3; i++)
        p[i] = b[0] * pv[0][i] + b[1] * pv[1][i] + b[2] * pv[2][i];
    const float dl = toward(p, l, w);
    float d = 0.0f;
    for (int k = 0; k < 3; k++)
        d += b[k] * dv[k];
    if (d_vis)
        *d_vis = d;
    return vdsh_shadow_compare(d, dl, compare);
}
