#include "vdsh_shadow.h"

#include <math.h>

#include "vdsh.h"
#include "vdsh_sh.h"

float vdsh_ramp(float x)
{
    /* (x - 1/3) * 1.5 written so that x = 1/3 and x = 1 give exactly 0
     * and 1 in float (the shaders use the same form). */
    float s = 1.5f * x - 0.5f;
    return s > 0.0f ? (s < 1.0f ? s : 1.0f) : 0.0f; /* NaN fails both: 0 */
}

float vdsh_stream_distance(uint32_t order, uint32_t quantity, const float *c,
                           const float d[3])
{
    float sum = vdsh_sh_reconstruct((int)order, c, d);
    switch (quantity) {
    case VDSH_QUANTITY_DISTANCE2:
        return sum > 0.0f ? sqrtf(sum) : 0.0f;
    case VDSH_QUANTITY_LOG_DISTANCE:
        return expf(sum);
    default:
        return sum > 0.0f ? sum : 0.0f;
    }
}

float vdsh_shadow_compare(float d_vis, float d_light, uint32_t compare)
{
    if (!(d_light > 0.0f)) /* at the receiver (or NaN): unshadowed */
        return d_light == 0.0f ? 1.0f : 0.0f;
    if (compare == VDSH_COMPARE_BINARY)
        return d_vis >= d_light ? 1.0f : 0.0f;
    if (isinf(d_vis) && d_vis > 0.0f)
        return 1.0f;
    return vdsh_ramp(d_vis / d_light);
}

float vdsh_shadow(uint32_t order, uint32_t quantity, const float *c,
                  const float p[3], const float l[3], uint32_t compare)
{
    float v[3] = {l[0] - p[0], l[1] - p[1], l[2] - p[2]};
    float dl = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(dl > 0.0f))
        return vdsh_shadow_compare(0.0f, dl, compare);
    for (int i = 0; i < 3; i++)
        v[i] /= dl;
    return vdsh_shadow_compare(vdsh_stream_distance(order, quantity, c, v), dl, compare);
}
