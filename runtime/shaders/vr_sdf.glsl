/*
 * vr_sdf.glsl - the fragment-stage GLSL of mode sdf: the sphere trace
 * of formats/vdsh_sdf.h (vdsh_sdf_sample, vdsh_sdf_shadow), operation for
 * operation, so vdsh-frames' C frames (c-sdf) and the GL frames agree
 * (tests/frames.cmake, frames_gl_vs_c). Trilinear filtering is done here
 * from 8 texelFetch taps in float, not by the texture unit (whose weights
 * have 8 fractional bits on many GPUs and on llvmpipe), for that reason.
 * Inserted between vdsh_common.glsl and vr_fragment.glsl (vr_glsl.c)
 * in mode sdf, where SHADOW_SDF is 1.
 */
#if SHADOW_SDF
uniform sampler3D u_sdf;      /* R16 unorm: (d / m + 1) / 2 */
uniform vec3 u_sdf_origin;    /* sample (0,0,0) */
uniform float u_sdf_cell;
uniform float u_sdf_max;      /* m */
uniform ivec3 u_sdf_dim;
uniform float u_sdf_k;        /* softness: a light of radius u_sdf_max / k */

float sdf_at(ivec3 c)
{
    return (texelFetch(u_sdf, c, 0).r * 2.0 - 1.0) * u_sdf_max;
}

/* vdsh_sdf_sample */
float sdf_sample(vec3 p)
{
    vec3 hi = vec3(u_sdf_dim - 1);
    vec3 g = clamp((p - u_sdf_origin) / u_sdf_cell, vec3(0.0), hi);
    vec3 fl = min(floor(g), hi - 1.0);
    ivec3 i = ivec3(fl);
    vec3 f = g - fl;
    float c0 = sdf_at(i), c1 = sdf_at(i + ivec3(1, 0, 0));
    float c2 = sdf_at(i + ivec3(0, 1, 0)), c3 = sdf_at(i + ivec3(1, 1, 0));
    float c4 = sdf_at(i + ivec3(0, 0, 1)), c5 = sdf_at(i + ivec3(1, 0, 1));
    float c6 = sdf_at(i + ivec3(0, 1, 1)), c7 = sdf_at(i + ivec3(1, 1, 1));
    float x00 = c0 + (c1 - c0) * f.x, x10 = c2 + (c3 - c2) * f.x;
    float x01 = c4 + (c5 - c4) * f.x, x11 = c6 + (c7 - c6) * f.x;
    float y0 = x00 + (x10 - x00) * f.y, y1 = x01 + (x11 - x01) * f.y;
    return y0 + (y1 - y0) * f.z;
}

/* vdsh_sdf_shadow: p the surface point, n its unit normal. */
float sdf_visibility(vec3 p, vec3 n, vec3 light)
{
    vec3 o = p + n * (1.5 * u_sdf_cell);
    vec3 dir = light - o;
    float tmax = length(dir);
    if (!(tmax > 0.0))
        return 1.0;
    dir /= tmax;
    float kk = u_sdf_k * tmax / u_sdf_max;
    float res = 1.0, t = 0.5 * u_sdf_cell;
    float min_step = u_sdf_cell * 0.125, hit = u_sdf_cell * (1.0 / 64.0);
    for (int i = 0; i < 64 && t < tmax; i++) {
        float h = sdf_sample(o + dir * t) - 0.35 * u_sdf_cell;
        if (h < hit)
            return 0.0;
        res = min(res, kk * h / t);
        t += max(h, min_step);
    }
    return max(res, 0.0);
}
#endif

