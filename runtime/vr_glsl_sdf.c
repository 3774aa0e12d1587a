/*
 * vr_glsl_sdf.c - the fragment-stage GLSL of mode sdf: the sphere trace
 * of formats/vdsh_sdf.h (vdsh_sdf_sample, vdsh_sdf_shadow), operation for
 * operation, so vdsh-frames' C frames (c-sdf) and the GL frames agree
 * (tests/frames.cmake, frames_gl_vs_c). Trilinear filtering is done here
 * from 8 texelFetch taps in float, not by the texture unit (whose weights
 * have 8 fractional bits on many GPUs and on llvmpipe), for that reason.
 * Inserted between common_glsl and fragment_glsl (vr_glsl.c) when
 * SHADOW_SDF is 1.
 */
#include "vr_internal.h"

const char vr_sdf_glsl[] =
    "#if SHADOW_SDF\n"
    "uniform sampler3D u_sdf;      /* R16 unorm: (d / m + 1) / 2 */\n"
    "uniform vec3 u_sdf_origin;    /* sample (0,0,0) */\n"
    "uniform float u_sdf_cell;\n"
    "uniform float u_sdf_max;      /* m */\n"
    "uniform ivec3 u_sdf_dim;\n"
    "uniform float u_sdf_k;        /* softness: a light of radius u_sdf_max / k */\n"
    "\n"
    "float sdf_at(ivec3 c)\n"
    "{\n"
    "    return (texelFetch(u_sdf, c, 0).r * 2.0 - 1.0) * u_sdf_max;\n"
    "}\n"
    "\n"
    "/* vdsh_sdf_sample */\n"
    "float sdf_sample(vec3 p)\n"
    "{\n"
    "    vec3 hi = vec3(u_sdf_dim - 1);\n"
    "    vec3 g = clamp((p - u_sdf_origin) / u_sdf_cell, vec3(0.0), hi);\n"
    "    vec3 fl = min(floor(g), hi - 1.0);\n"
    "    ivec3 i = ivec3(fl);\n"
    "    vec3 f = g - fl;\n"
    "    float c0 = sdf_at(i), c1 = sdf_at(i + ivec3(1, 0, 0));\n"
    "    float c2 = sdf_at(i + ivec3(0, 1, 0)), c3 = sdf_at(i + ivec3(1, 1, 0));\n"
    "    float c4 = sdf_at(i + ivec3(0, 0, 1)), c5 = sdf_at(i + ivec3(1, 0, 1));\n"
    "    float c6 = sdf_at(i + ivec3(0, 1, 1)), c7 = sdf_at(i + ivec3(1, 1, 1));\n"
    "    float x00 = c0 + (c1 - c0) * f.x, x10 = c2 + (c3 - c2) * f.x;\n"
    "    float x01 = c4 + (c5 - c4) * f.x, x11 = c6 + (c7 - c6) * f.x;\n"
    "    float y0 = x00 + (x10 - x00) * f.y, y1 = x01 + (x11 - x01) * f.y;\n"
    "    return y0 + (y1 - y0) * f.z;\n"
    "}\n"
    "\n"
    "/* vdsh_sdf_shadow: p the surface point, n its unit normal. */\n"
    "float sdf_visibility(vec3 p, vec3 n, vec3 light)\n"
    "{\n"
    "    vec3 o = p + n * (1.5 * u_sdf_cell);\n"
    "    vec3 dir = light - o;\n"
    "    float tmax = length(dir);\n"
    "    if (!(tmax > 0.0))\n"
    "        return 1.0;\n"
    "    dir /= tmax;\n"
    "    float kk = u_sdf_k * tmax / u_sdf_max;\n"
    "    float res = 1.0, t = 0.5 * u_sdf_cell;\n"
    "    float min_step = u_sdf_cell * 0.125, hit = u_sdf_cell * (1.0 / 64.0);\n"
    "    for (int i = 0; i < 64 && t < tmax; i++) {\n"
    "        float h = sdf_sample(o + dir * t) - 0.35 * u_sdf_cell;\n"
    "        if (h < hit)\n"
    "            return 0.0;\n"
    "        res = min(res, kk * h / t);\n"
    "        t += max(h, min_step);\n"
    "    }\n"
    "    return max(res, 0.0);\n"
    "}\n"
    "#endif\n";

const size_t vr_sdf_glsl_size = sizeof vr_sdf_glsl;
