/*
 * vr_glsl.c - the shaders. One source per stage, specialised with
 * #defines for each program key (mode, comparison, quantity, output, PCF,
 * lights in the pass; and whether the per-draw constants travel as flat
 * varyings, below), so every variant is straight-line code and nothing
 * branches on a uniform per pixel.
 *
 * The VDSH part is written as three layers, so that a new stored quantity
 * or a new comparison touches one function each:
 *   sh_sum4 / sh_sum9 / sh_basis16   the SH basis, formats/vdsh_sh.c
 *   vdsh_distance(sum, max)          an SH sum -> a distance, per quantity,
 *                                    clamped to the bake's max distance
 *                                    (formats/vdsh_shadow.c
 *                                    vdsh_stream_distance)
 *   vdsh_compare(d_vis, d_light)     a distance pair -> visibility, per
 *                                    comparison (vdsh_shadow_compare)
 * and each path (vdsh_interp, chosen by vdsh_runtime_interp from the order
 * and the stored quantity) only decides where sums are computed and what
 * is interpolated:
 *   VDSH_VISIBILITY  linear quantities, orders 2, 3: the whole sum, the
 *                    distance and the comparison per vertex; the
 *                    visibility is interpolated;
 *   VDSH_SPLIT       linear quantities, order 5 (the paper's): bands 0-2
 *                    per vertex toward the vertex's light direction,
 *                    interpolated; bands 3-4 (16 coefficients,
 *                    interpolated) dotted in the fragment stage with the
 *                    basis cubemaps or with the polynomials;
 *   VDSH_DISTANCE    log-distance, every order: the whole sum (all
 *                    order^2 coefficients) and its distance per vertex,
 *                    one interpolated distance per light, compared in the
 *                    fragment stage with the fragment's own light distance
 *                    (exp cannot be split across the stages, and
 *                    interpolating log coefficients would be a geometric
 *                    mean of the vertices' distances).
 * VR_MODE_VDSH_BUFFER takes the distance path for any stream: its vertex
 * stage reads the coefficients from a buffer texture and sums them by a
 * recurrence for any order (vr_glsl_buffer.c, spliced in before main()
 * when BUFFER is 1; ORDER is then 0: no coefficient attributes).
 * The numbers these functions share with the C definition (the SH
 * constants, the ramp's slope and offset, the log-sum limit) are not
 * copied here: the C headers' macros are written into the source as they
 * stand. tests/test_runtime_glsl.c renders these against vdsh_shadow (per
 * vertex) and vdsh_shadow_interior (per fragment).
 *
 * Lights: the per-light code is a macro, LIGHT(I), expanded once per light
 * of the pass with a literal index, because GLSL 3.30 only lets sampler
 * arrays (the shadow cube maps) be indexed by constant expressions.
 *
 * Per-draw constants of the fragment stage (light positions, colours,
 * attenuations, the ambient term, the cube maps' planes, and on the split
 * path, the only one that reconstructs a distance there, the scene's max
 * distance) reach it as flat varyings that the vertex stage copies from
 * the uniforms (FLAT_LIGHTS), not as uniforms: Mesa's llvmpipe (22.x)
 * reads every uniform component in a fragment shader with a bounds-checked
 * gather, about 20 instructions per component for every 8 fragments,
 * again in every 4x4 block, where a flat input is one broadcast per block.
 * Read as uniforms, the 15 components of one light's Lambert term cost
 * about a third of the room's lighting pass on llvmpipe
 * (docs/BENCHMARKS.md). The values are the uniforms' own, bit for bit.
 * When the varyings would not fit in GL_MAX_VARYING_COMPONENTS (8 lights
 * need up to 106 of the 128 that llvmpipe and GPUs offer; GL 3.3 only
 * promises 60), or a driver does not link them, the fragment stage reads
 * the uniforms.
 */
#include "vr_internal.h"

#include "vdsh_sh.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A macro's value as a string literal: the constants below are the C
 * definitions' own macros (formats/vdsh_sh.h, formats/vdsh_shadow.h),
 * float literals that GLSL 3.30 reads as C does. */
#define VR_STR_(x) #x
#define VR_STR(x) VR_STR_(x)
#define VR_CONST(name, macro) "const float " name " = " VR_STR(macro) ";\n"

/* Shared by both stages: the SH basis (D3DX convention, the constants of
 * formats/vdsh_sh.h) and the two VDSH functions. */
static const char common_glsl[] =
    VR_CONST("C00", VDSH_SH_C00)
    VR_CONST("C1", VDSH_SH_C1)
    VR_CONST("C2A", VDSH_SH_C2A)
    VR_CONST("C20", VDSH_SH_C20)
    VR_CONST("C22", VDSH_SH_C22)
    VR_CONST("C33", VDSH_SH_C33)
    VR_CONST("C32", VDSH_SH_C32)
    VR_CONST("C31", VDSH_SH_C31)
    VR_CONST("C30", VDSH_SH_C30)
    VR_CONST("C32B", VDSH_SH_C32B)
    VR_CONST("C44", VDSH_SH_C44)
    VR_CONST("C43", VDSH_SH_C43)
    VR_CONST("C42", VDSH_SH_C42)
    VR_CONST("C41", VDSH_SH_C41)
    VR_CONST("C40", VDSH_SH_C40)
    VR_CONST("C42B", VDSH_SH_C42B)
    VR_CONST("C44B", VDSH_SH_C44B)
    "\n"
    "/* sum of c_i Y_i(d), coefficients 0..3 (bands 0-1), unit d */\n"
    "float sh_sum4(vec4 c0, vec3 d)\n"
    "{\n"
    "    return dot(c0, vec4(C00, -C1 * d.y, C1 * d.z, -C1 * d.x));\n"
    "}\n"
    "\n"
    "/* coefficients 0..8 (bands 0-2) */\n"
    "float sh_sum9(vec4 c0, vec4 c1, float c8, vec3 d)\n"
    "{\n"
    "    float x = d.x, y = d.y, z = d.z;\n"
    "    vec4 b = vec4(C2A * x * y, -C2A * y * z, C20 * (3.0 * z * z - 1.0),\n"
    "                  -C2A * x * z);\n"
    "    return sh_sum4(c0, d) + dot(c1, b) + c8 * (C22 * (x * x - y * y));\n"
    "}\n"
    "\n"
    "/* basis functions 9..24 (bands 3-4), four per vec4 like the cubemaps */\n"
    "void sh_basis16(vec3 d, out vec4 b9, out vec4 b13, out vec4 b17, out vec4 b21)\n"
    "{\n"
    "    float x = d.x, y = d.y, z = d.z;\n"
    "    float x2 = x * x, y2 = y * y, z2 = z * z;\n"
    "    b9 = vec4(-C33 * y * (3.0 * x2 - y2), C32 * x * y * z,\n"
    "              -C31 * y * (5.0 * z2 - 1.0), C30 * z * (5.0 * z2 - 3.0));\n"
    "    b13 = vec4(-C31 * x * (5.0 * z2 - 1.0), C32B * z * (x2 - y2),\n"
    "               -C33 * x * (x2 - 3.0 * y2), C44 * x * y * (x2 - y2));\n"
    "    b17 = vec4(-C43 * y * z * (3.0 * x2 - y2), C42 * x * y * (7.0 * z2 - 1.0),\n"
    "               -C41 * y * z * (7.0 * z2 - 3.0),\n"
    "               C40 * (35.0 * z2 * z2 - 30.0 * z2 + 3.0));\n"
    "    b21 = vec4(-C41 * x * z * (7.0 * z2 - 3.0), C42B * (x2 - y2) * (7.0 * z2 - 1.0),\n"
    "               -C43 * x * z * (x2 - 3.0 * y2),\n"
    "               C44B * (x2 * x2 - 6.0 * x2 * y2 + y2 * y2));\n"
    "}\n"
    "\n"
    "/* The distance a stream's SH sum stands for (vdsh_stream_distance):\n"
    " * never negative, ringing below zero counts as 0; never above the\n"
    " * bake's max distance md, which sums below a vertex's horizon can\n"
    " * run far past. */\n"
    "float vdsh_distance(float sum, float md)\n"
    "{\n"
    "#if QUANTITY == 1\n"
    "    float d = sum > 0.0 ? sqrt(sum) : 0.0;\n"
    "#elif QUANTITY == 2\n"
    "    float d = exp(min(sum, " VR_STR(VDSH_LOG_SUM_MAX) ")); /* stays finite */\n"
    "#else\n"
    "    float d = sum > 0.0 ? sum : 0.0;\n"
    "#endif\n"
    "    return d > md ? md : d;\n"
    "}\n"
    "\n"
    "/* Visibility of a light at distance dl when the stored distance toward\n"
    " * it is dv (vdsh_shadow_compare). A light at the receiver is visible. */\n"
    "float vdsh_compare(float dv, float dl)\n"
    "{\n"
    "    if (!(dl > 0.0))\n"
    "        return 1.0;\n"
    "#if COMPARE == 1\n"
    "    return dv >= dl ? 1.0 : 0.0;\n"
    "#else\n"
    "    if (isinf(dv) && dv > 0.0)\n"
    "        return 1.0;\n"
    "    /* ramp(x) = saturate((x - 1/3) * 1.5), written as in vdsh_ramp */\n"
    "    return clamp(" VR_STR(VDSH_RAMP_SLOPE) " * (dv / dl) - " VR_STR(VDSH_RAMP_OFFSET)
    ", 0.0, 1.0);\n"
    "#endif\n"
    "}\n";

static const char vertex_glsl[] =
    "layout(location = 0) in vec3 a_position;\n"
    "layout(location = 1) in vec3 a_normal;\n"
    "#if ORDER >= 2\n"
    "layout(location = 2) in vec4 a_c0;   /* coefficients 0..3 */\n"
    "#endif\n"
    "#if ORDER >= 3 && PACKED\n"
    "/* s8s6: coefficients 4.. six bits each, five to a word: word w holds\n"
    " * 4 + 5w .. 8 + 5w in bits 0-5, 6-11, ..., 24-29 (two's complement) */\n"
    "layout(location = 3) in uvec4 a_w0;  /* words 0..3 (order 3: word 0 only) */\n"
    "#if ORDER >= 5\n"
    "layout(location = 4) in uint a_w4;   /* word 4 */\n"
    "#endif\n"
    "#elif ORDER >= 3\n"
    "layout(location = 3) in vec4 a_c1;   /* 4..7 */\n"
    "layout(location = 4) in float a_c8;  /* 8 */\n"
    "#endif\n"
    "#if ORDER >= 5 && !PACKED\n"
    "layout(location = 5) in vec4 a_c9;   /* 9..12, the first basis cubemap */\n"
    "layout(location = 6) in vec4 a_c13;\n"
    "layout(location = 7) in vec4 a_c17;\n"
    "layout(location = 8) in vec4 a_c21;\n"
    "#endif\n"
    "uniform mat4 u_view_proj;\n"
    "uniform float u_scale;   /* coefficient = stored value * u_scale */\n"
    "/* and times a factor per coefficient, as the attributes are grouped:\n"
    " * an s8 stream's steps (vdsh_s8_step), 1 for f16 and f32 (exact) */\n"
    "uniform vec4 u_coef_step[7];\n"
    "#define C0 (a_c0 * u_coef_step[0])\n"
    "#if PACKED\n"
    "/* field j (0..4) of a packed word, sign-extended: exact, as in C */\n"
    "float pk(uint w, int j)\n"
    "{\n"
    "    return float(int(w << uint(26 - 6 * j)) >> 26);\n"
    "}\n"
    "#define C1 (vec4(pk(a_w0.x, 0), pk(a_w0.x, 1), pk(a_w0.x, 2), pk(a_w0.x, 3)) * u_coef_step[1])\n"
    "#define C8 (pk(a_w0.x, 4) * u_coef_step[2].x)\n"
    "#define C9 (vec4(pk(a_w0.y, 0), pk(a_w0.y, 1), pk(a_w0.y, 2), pk(a_w0.y, 3)) * u_coef_step[3])\n"
    "#define C13 (vec4(pk(a_w0.y, 4), pk(a_w0.z, 0), pk(a_w0.z, 1), pk(a_w0.z, 2)) * u_coef_step[4])\n"
    "#define C17 (vec4(pk(a_w0.z, 3), pk(a_w0.z, 4), pk(a_w0.w, 0), pk(a_w0.w, 1)) * u_coef_step[5])\n"
    "#define C21 (vec4(pk(a_w0.w, 2), pk(a_w0.w, 3), pk(a_w0.w, 4), pk(a_w4, 0)) * u_coef_step[6])\n"
    "#else\n"
    "#define C1 (a_c1 * u_coef_step[1])\n"
    "#define C8 (a_c8 * u_coef_step[2].x)\n"
    "#define C9 (a_c9 * u_coef_step[3])\n"
    "#define C13 (a_c13 * u_coef_step[4])\n"
    "#define C17 (a_c17 * u_coef_step[5])\n"
    "#define C21 (a_c21 * u_coef_step[6])\n"
    "#endif\n"
    "uniform float u_max_distance; /* the clamp of every reconstructed distance */\n"
    "#if NUM_LIGHTS > 0\n"
    "uniform vec3 u_light_pos[NUM_LIGHTS];\n"
    "#endif\n"
    "#if FLAT_LIGHTS\n"
    "/* handed on to the fragment stage (see the top of vr_glsl.c) */\n"
    "uniform vec3 u_ambient;\n"
    "flat out vec3 f_ambient;\n"
    "#if NUM_LIGHTS > 0\n"
    "uniform vec3 u_light_color[NUM_LIGHTS];\n"
    "uniform vec3 u_light_att[NUM_LIGHTS];\n"
    "flat out vec3 f_light_pos[NUM_LIGHTS];\n"
    "flat out vec3 f_light_color[NUM_LIGHTS];\n"
    "flat out vec3 f_light_att[NUM_LIGHTS];\n"
    "#endif\n"
    "#if SHADOW_CUBE && NUM_LIGHTS > 0\n"
    "uniform vec2 u_shadow_nf[NUM_LIGHTS];\n"
    "uniform float u_shadow_texel;\n"
    "flat out vec2 f_shadow_nf[NUM_LIGHTS];\n"
    "flat out float f_shadow_texel;\n"
    "#endif\n"
    "#if VDSH_SPLIT\n"
    "flat out float f_max_distance;\n"
    "#endif\n"
    "#endif\n"
    "/* Later passes (more lights) test depth with GL_LEQUAL against the\n"
    " * first pass's depth: every program must compute the same position. */\n"
    "invariant gl_Position;\n"
    "out vec3 v_position;\n"
    "out vec3 v_normal;\n"
    "#if VDSH_VISIBILITY && NUM_LIGHTS > 0\n"
    "out float v_vis[NUM_LIGHTS];\n"
    "#endif\n"
    "#if VDSH_VISIBILITY && OUTPUT == 1\n"
    "out float v_dv;\n"
    "out float v_dl;\n"
    "#endif\n"
    "#if VDSH_DISTANCE && NUM_LIGHTS > 0\n"
    "out float v_dist[NUM_LIGHTS];\n"
    "#endif\n"
    "#if VDSH_SPLIT\n"
    "#if NUM_LIGHTS > 0\n"
    "out float v_sum9[NUM_LIGHTS];\n"
    "#endif\n"
    "out vec4 v_c9, v_c13, v_c17, v_c21;\n"
    "#endif\n"
    "\n";

/* The rest of the vertex stage (after the buffer path's code, which
 * uses the declarations above). */
static const char vertex_main_glsl[] =
    "#if (VDSH_VISIBILITY || VDSH_DISTANCE) && !BUFFER\n"
    "/* The stream's whole SH sum toward unit direction d. */\n"
    "float vdsh_sh_sum(vec3 d)\n"
    "{\n"
    "#if ORDER == 2\n"
    "    return u_scale * sh_sum4(C0, d);\n"
    "#elif ORDER == 3\n"
    "    return u_scale * sh_sum9(C0, C1, C8, d);\n"
    "#else\n"
    "    vec4 b9, b13, b17, b21;\n"
    "    sh_basis16(d, b9, b13, b17, b21);\n"
    "    return u_scale * (sh_sum9(C0, C1, C8, d) + dot(C9, b9) + dot(C13, b13) +\n"
    "                      dot(C17, b17) + dot(C21, b21));\n"
    "#endif\n"
    "}\n"
    "#endif\n"
    "\n"
    "void main()\n"
    "{\n"
    "    v_position = a_position;\n"
    "    v_normal = a_normal;\n"
    "    gl_Position = u_view_proj * vec4(a_position, 1.0);\n"
    "#if FLAT_LIGHTS\n"
    "    f_ambient = u_ambient;\n"
    "#if NUM_LIGHTS > 0\n"
    "    for (int i = 0; i < NUM_LIGHTS; i++) {\n"
    "        f_light_pos[i] = u_light_pos[i];\n"
    "        f_light_color[i] = u_light_color[i];\n"
    "        f_light_att[i] = u_light_att[i];\n"
    "#if SHADOW_CUBE\n"
    "        f_shadow_nf[i] = u_shadow_nf[i];\n"
    "#endif\n"
    "    }\n"
    "#endif\n"
    "#if SHADOW_CUBE && NUM_LIGHTS > 0\n"
    "    f_shadow_texel = u_shadow_texel;\n"
    "#endif\n"
    "#if VDSH_SPLIT\n"
    "    f_max_distance = u_max_distance;\n"
    "#endif\n"
    "#endif\n"
    "#if VDSH_VISIBILITY && OUTPUT == 1\n"
    "    v_dv = -1.0;\n"
    "    v_dl = 0.0;\n"
    "#endif\n"
    "#if BUFFER && NUM_LIGHTS > 0\n"
    "    float b_sum[NUM_LIGHTS];\n"
    "    buffer_sums(b_sum);\n"
    "#endif\n"
    "#if (VDSH_VISIBILITY || VDSH_DISTANCE || VDSH_SPLIT) && NUM_LIGHTS > 0\n"
    "    for (int i = 0; i < NUM_LIGHTS; i++) {\n"
    "        vec3 lv = u_light_pos[i] - a_position;\n"
    "        float dl = length(lv);\n"
    "#if BUFFER\n"
    "        float dv = dl > 0.0 ? vdsh_distance(b_sum[i], u_max_distance) : 0.0;\n"
    "#elif VDSH_VISIBILITY || VDSH_DISTANCE\n"
    "        /* A light at the vertex has no direction: distance 0, not NaN,\n"
    "         * which would spread over every triangle around the vertex. */\n"
    "        float dv = dl > 0.0 ? vdsh_distance(vdsh_sh_sum(lv / dl), u_max_distance) : 0.0;\n"
    "#endif\n"
    "#if VDSH_VISIBILITY\n"
    "        v_vis[i] = vdsh_compare(dv, dl);\n"
    "#if OUTPUT == 1\n"
    "        if (i == 0) {\n"
    "            v_dv = dv;\n"
    "            v_dl = dl;\n"
    "        }\n"
    "#endif\n"
    "#elif VDSH_DISTANCE\n"
    "        v_dist[i] = dv;\n"
    "#else\n"
    "        /* As above, 0 for a light at the vertex; the fragment stage\n"
    "         * gives such a light visibility 1. */\n"
    "        v_sum9[i] = dl > 0.0 ? u_scale * sh_sum9(C0, C1, C8, lv / dl) : 0.0;\n"
    "#endif\n"
    "    }\n"
    "#endif\n"
    "#if VDSH_SPLIT\n"
    "    v_c9 = u_scale * C9;\n"
    "    v_c13 = u_scale * C13;\n"
    "    v_c17 = u_scale * C17;\n"
    "    v_c21 = u_scale * C21;\n"
    "#endif\n"
    "}\n";

static const char fragment_glsl[] =
    "in vec3 v_position;\n"
    "in vec3 v_normal;\n"
    "#if VDSH_VISIBILITY && NUM_LIGHTS > 0\n"
    "in float v_vis[NUM_LIGHTS];\n"
    "#endif\n"
    "#if VDSH_VISIBILITY && OUTPUT == 1\n"
    "in float v_dv;\n"
    "in float v_dl;\n"
    "#endif\n"
    "#if VDSH_DISTANCE && NUM_LIGHTS > 0\n"
    "in float v_dist[NUM_LIGHTS];\n"
    "#endif\n"
    "#if VDSH_SPLIT\n"
    "#if NUM_LIGHTS > 0\n"
    "in float v_sum9[NUM_LIGHTS];\n"
    "#endif\n"
    "in vec4 v_c9, v_c13, v_c17, v_c21;\n"
    "#endif\n"
    "/* Per-draw constants: light colours and the ambient term are already\n"
    " * multiplied by the albedo; shadow planes are (near, far) of the\n"
    " * cube map's face projections, the texel size 2 / face size. */\n"
    "#if FLAT_LIGHTS\n"
    "flat in vec3 f_ambient;\n"
    "#if NUM_LIGHTS > 0\n"
    "flat in vec3 f_light_pos[NUM_LIGHTS];\n"
    "flat in vec3 f_light_color[NUM_LIGHTS];\n"
    "flat in vec3 f_light_att[NUM_LIGHTS];\n"
    "#endif\n"
    "#if SHADOW_CUBE && NUM_LIGHTS > 0\n"
    "flat in vec2 f_shadow_nf[NUM_LIGHTS];\n"
    "flat in float f_shadow_texel;\n"
    "#endif\n"
    "#if VDSH_SPLIT\n"
    "flat in float f_max_distance;\n"
    "#endif\n"
    "#define AMBIENT f_ambient\n"
    "#define LIGHT_POS(I) f_light_pos[I]\n"
    "#define LIGHT_COLOR(I) f_light_color[I]\n"
    "#define LIGHT_ATT(I) f_light_att[I]\n"
    "#define SHADOW_NF(I) f_shadow_nf[I]\n"
    "#define SHADOW_TEXEL f_shadow_texel\n"
    "#define MAX_DISTANCE f_max_distance\n"
    "#else\n"
    "uniform vec3 u_ambient;\n"
    "#if NUM_LIGHTS > 0\n"
    "uniform vec3 u_light_pos[NUM_LIGHTS];\n"
    "uniform vec3 u_light_color[NUM_LIGHTS];\n"
    "uniform vec3 u_light_att[NUM_LIGHTS];\n"
    "#endif\n"
    "#if SHADOW_CUBE && NUM_LIGHTS > 0\n"
    "uniform vec2 u_shadow_nf[NUM_LIGHTS];\n"
    "uniform float u_shadow_texel;\n"
    "#endif\n"
    "#if VDSH_SPLIT\n"
    "uniform float u_max_distance;\n"
    "#endif\n"
    "#define AMBIENT u_ambient\n"
    "#define LIGHT_POS(I) u_light_pos[I]\n"
    "#define LIGHT_COLOR(I) u_light_color[I]\n"
    "#define LIGHT_ATT(I) u_light_att[I]\n"
    "#define SHADOW_NF(I) u_shadow_nf[I]\n"
    "#define SHADOW_TEXEL u_shadow_texel\n"
    "#define MAX_DISTANCE u_max_distance\n"
    "#endif\n"
    "#if SHADOW_CUBE && NUM_LIGHTS > 0\n"
    "uniform samplerCubeShadow u_shadow[NUM_LIGHTS];\n"
    "#endif\n"
    "#if VDSH_SPLIT && CUBEMAP_BASIS\n"
    "uniform samplerCube u_basis[4];\n"
    "#endif\n"
    "out vec4 o_color;\n"
    "\n"
    "#if VDSH_SPLIT\n"
    "/* The SH sum of bands 3-4 toward unit direction d. */\n"
    "float vdsh_sh_sum16(vec3 d)\n"
    "{\n"
    "#if CUBEMAP_BASIS\n"
    "    return dot(v_c9, texture(u_basis[0], d)) + dot(v_c13, texture(u_basis[1], d)) +\n"
    "           dot(v_c17, texture(u_basis[2], d)) + dot(v_c21, texture(u_basis[3], d));\n"
    "#else\n"
    "    vec4 b9, b13, b17, b21;\n"
    "    sh_basis16(d, b9, b13, b17, b21);\n"
    "    return dot(v_c9, b9) + dot(v_c13, b13) + dot(v_c17, b17) + dot(v_c21, b21);\n"
    "#endif\n"
    "}\n"
    "\n"
    "/* sum9: bands 0-2 from the vertex stage; lv: receiver to light. */\n"
    "float split_visibility(float sum9, vec3 lv, float dl, out float dv)\n"
    "{\n"
    "    dv = 0.0;\n"
    "    if (!(dl > 0.0))\n"
    "        return vdsh_compare(0.0, dl);\n"
    "    dv = vdsh_distance(sum9 + vdsh_sh_sum16(lv / dl), MAX_DISTANCE);\n"
    "    return vdsh_compare(dv, dl);\n"
    "}\n"
    "#endif\n"
    "\n"
    "#if VDSH_DISTANCE\n"
    "/* dist: the vertices' distances toward the light, interpolated;\n"
    " * compared with this fragment's own light distance dl. */\n"
    "float distance_visibility(float dist, float dl, out float dv)\n"
    "{\n"
    "    dv = dist;\n"
    "    return vdsh_compare(dist, dl);\n"
    "}\n"
    "#endif\n"
    "\n"
    "#if SHADOW_CUBE && NUM_LIGHTS > 0\n"
    "/* Baseline: depth cube map of the light, compared at the receiver's\n"
    " * depth in the face it falls in (major axis). The receiver is first\n"
    " * pushed off its surface along the normal by 1.5 shadow texels at its\n"
    " * distance (normal-offset bias: removes acne at grazing angles without\n"
    " * the detached shadows of a large depth bias). */\n"
    "float cube_visibility(samplerCubeShadow map, vec2 nf, vec3 lv, float dl, vec3 n)\n"
    "{\n"
    "    if (!(dl > 0.0))\n"
    "        return 1.0;   /* at the receiver, as vdsh_compare */\n"
    "    vec3 v = -lv;\n"
    "    float ma = max(max(abs(v.x), abs(v.y)), abs(v.z));\n"
    "    v += n * (1.5 * SHADOW_TEXEL * ma);\n"
    "    ma = max(max(abs(v.x), abs(v.y)), abs(v.z));\n"
    "    float z = (nf.y + nf.x) / (nf.y - nf.x) - 2.0 * nf.y * nf.x / ((nf.y - nf.x) * ma);\n"
    "    float ref = 0.5 * z + 0.5;\n"
    "#if PCF\n"
    "    /* four bilinear (2x2) taps a texel apart around v */\n"
    "    vec3 a = abs(v.y) < 0.9 * length(v) ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);\n"
    "    vec3 t1 = normalize(cross(v, a)) * (0.5 * SHADOW_TEXEL * ma);\n"
    "    vec3 t2 = normalize(cross(v, t1)) * (0.5 * SHADOW_TEXEL * ma);\n"
    "    return 0.25 * (texture(map, vec4(v + t1 + t2, ref)) + texture(map, vec4(v + t1 - t2, ref)) +\n"
    "                   texture(map, vec4(v - t1 + t2, ref)) + texture(map, vec4(v - t1 - t2, ref)));\n"
    "#else\n"
    "    return texture(map, vec4(v, ref));\n"
    "#endif\n"
    "}\n"
    "#endif\n"
    "\n"
    "#if NUM_LIGHTS > 0\n"
    "/* Lambert with distance attenuation, before the shadow. */\n"
    "vec3 light_term(vec3 color, vec3 att3, vec3 lv, float dl, vec3 n)\n"
    "{\n"
    "    float ndl = dl > 0.0 ? max(dot(n, lv) / dl, 0.0) : 1.0;\n"
    "    float att = 1.0 / dot(att3, vec3(1.0, dl, dl * dl));\n"
    "    return color * (ndl * att);\n"
    "}\n"
    "#endif\n"
    "\n"
    "/* Per mode: the visibility of light I; may set dv (debug output). */\n"
    "#if VDSH_VISIBILITY\n"
    "#define VISIBILITY(I) v_vis[I]\n"
    "#elif VDSH_DISTANCE\n"
    "#define VISIBILITY(I) distance_visibility(v_dist[I], dl, dv)\n"
    "#elif VDSH_SPLIT\n"
    "#define VISIBILITY(I) split_visibility(v_sum9[I], lv, dl, dv)\n"
    "#elif SHADOW_SDF\n"
    "#define VISIBILITY(I) sdf_visibility(v_position, n, LIGHT_POS(I))\n"
    "#elif SHADOW_CUBE\n"
    "#define VISIBILITY(I) cube_visibility(u_shadow[I], SHADOW_NF(I), lv, dl, n)\n"
    "#else\n"
    "#define VISIBILITY(I) 1.0\n"
    "#endif\n"
    "#define LIGHT(I) { vec3 lv = LIGHT_POS(I) - v_position; float dl = length(lv); float dv = -1.0; float s = VISIBILITY(I); acc += s * light_term(LIGHT_COLOR(I), LIGHT_ATT(I), lv, dl, n); if (I == 0) { s0 = s; dv0 = dv; dl0 = dl; } }\n"
    "\n"
    "void main()\n"
    "{\n"
    "    vec3 n = normalize(v_normal);\n"
    "    vec3 acc = vec3(0.0);\n"
    "    float s0 = 1.0, dv0 = -1.0, dl0 = 0.0;\n"
    "    FOR_EACH_LIGHT\n"
    "#if VDSH_VISIBILITY && OUTPUT == 1\n"
    "    /* the values the vertex stage compared */\n"
    "    dv0 = v_dv;\n"
    "    dl0 = v_dl;\n"
    "#endif\n"
    "#if OUTPUT == 1\n"
    "    o_color = vec4(s0, dv0, dl0, 1.0);\n"
    "#elif OUTPUT == 2\n"
    "    o_color = vec4(v_position, 1.0);\n"
    "#else\n"
    "    o_color = vec4(AMBIENT + acc, 1.0);\n"
    "#endif\n"
    "}\n";

static const char depth_vs[] =
    "#version 330 core\n"
    "layout(location = 0) in vec3 a_position;\n"
    "uniform mat4 u_view_proj;\n"
    "void main()\n"
    "{\n"
    "    gl_Position = u_view_proj * vec4(a_position, 1.0);\n"
    "}\n";

static const char depth_fs[] =
    "#version 330 core\n"
    "void main()\n"
    "{\n"
    "}\n";

/* ------------------------------------------------------------------ */

static void key_name(const vr_program_key *k, char *buf, size_t size)
{
    int interp = vr_mode_interp((vr_mode)k->mode, k->quantity);
    static const char *const kinds[4] = {"f32", "f16", "s8", "s8s6"};
    char buf_what[64] = "";
    if (k->mode == VR_MODE_VDSH_BUFFER)
        snprintf(buf_what, sizeof buf_what, ", order %u%s %s", k->buf_order,
                 k->buf_variable ? " (cap, variable)" : "", kinds[k->buf_kind & 3]);
    snprintf(buf, size, "program %s%s%s, %s, %s, output %u, pcf %u, %u lights%s%s",
             vr_mode_name((vr_mode)k->mode), interp >= 0 ? " path " : "",
             interp >= 0 ? vdsh_interp_name((uint32_t)interp) : "",
             k->compare == VDSH_COMPARE_BINARY ? "binary" : "smooth",
             vdsh_quantity_name(k->quantity), k->output, k->pcf, k->lights,
             k->packed ? ", s8s6" : "", buf_what);
}

/* The varying components a program passes from the vertex to the
 * fragment stage, with or without the flat per-draw constants. */
static int varying_components(const vr_program_key *k, int flat)
{
    int interp = vr_mode_interp((vr_mode)k->mode, k->quantity), n = k->lights;
    int c = 6;   /* position, normal */
    if (interp >= 0)
        c += n;  /* a visibility, distance or band 0-2 sum per light */
    if (interp == VDSH_INTERP_SPLIT)
        c += 16;
    if (interp == VDSH_INTERP_VISIBILITY && k->output == VR_OUTPUT_SHADOW)
        c += 2;
    if (flat)
        c += 3 + 9 * n + (k->mode == VR_MODE_CUBE && n > 0 ? 2 * n + 1 : 0) +
             (interp == VDSH_INTERP_SPLIT);
    return c;
}

/* The #defines that specialise the sources for one key. The VDSH path
 * comes from formats/vdsh_shadow.h, the same function vdsh-eval scores
 * with, so the shaders draw what the evaluator measures. */
static void key_defines(const vr_program_key *k, int flat, char *buf, size_t size)
{
    int order = vr_mode_order((vr_mode)k->mode), cube = k->mode == VR_MODE_CUBE;
    int visibility = 0, split = 0, distance = 0, cubemap = 0;
    int buffer = k->mode == VR_MODE_VDSH_BUFFER;
    /* (vr_program_build has checked that the path is one of these.) */
    switch (vr_mode_interp((vr_mode)k->mode, k->quantity)) {
    case VDSH_INTERP_VISIBILITY: visibility = 1; break;
    case VDSH_INTERP_DISTANCE: distance = 1; break;
    case VDSH_INTERP_SPLIT:
        split = 1;
        cubemap = k->mode == VR_MODE_VDSH5;
        break;
    default: break;
    }
    int n = snprintf(buf, size,
                     "#version 330 core\n"
                     "#define ORDER %d\n#define VDSH_VISIBILITY %d\n#define VDSH_SPLIT %d\n"
                     "#define VDSH_DISTANCE %d\n"
                     "#define CUBEMAP_BASIS %d\n#define SHADOW_CUBE %d\n"
                     "#define QUANTITY %u\n#define COMPARE %u\n#define OUTPUT %u\n"
                     "#define PCF %u\n#define NUM_LIGHTS %u\n#define FLAT_LIGHTS %d\n"
                     "#define PACKED %d\n#define BUFFER %d\n#define BUF_ORDER %u\n"
                     "#define BUF_KIND %u\n#define BUF_VARIABLE %u\n#define BUF_STRIDE %d\n"
                     "#define SHADOW_SDF %d\n"
                     "#define FOR_EACH_LIGHT",
                     order, visibility, split, distance, cubemap, cube, k->quantity, k->compare,
                     k->output, k->pcf, k->lights, flat, k->packed && order >= 3, buffer,
                     k->buf_order, k->buf_kind, k->buf_variable,
                     buffer ? vr_buffer_stride(k->buf_order, (vr_buf_kind)k->buf_kind) : 0,
                     k->mode == VR_MODE_SDF);
    for (unsigned i = 0; i < k->lights && n > 0 && (size_t)n < size; i++)
        n += snprintf(buf + n, size - (size_t)n, " LIGHT(%u)", i);
    if (n > 0 && (size_t)n < size)
        snprintf(buf + n, size - (size_t)n, "\n");
}

static vr_result compile(const char *name, GLenum stage, const char *src,
                         GLuint *out, vr_error *err)
{
    GLuint sh = glCreateShader(stage);
    if (!sh)
        return vr_fail(err, VR_ERR_GL, "%s: glCreateShader failed", name);
    glShaderSource(sh, 1, &src, NULL);
    glCompileShader(sh);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[768] = "";
        glGetShaderInfoLog(sh, sizeof log, NULL, log);
        glDeleteShader(sh);
        return vr_fail(err, VR_ERR_SHADER, "%s: %s shader: %s", name,
                       stage == GL_VERTEX_SHADER ? "vertex" : "fragment", log);
    }
    *out = sh;
    return VR_OK;
}

vr_result vr_link(const char *name, const char *vs, const char *fs,
                  GLuint *out, vr_error *err)
{
    GLuint v = 0, f = 0;
    vr_result r = compile(name, GL_VERTEX_SHADER, vs, &v, err);
    if (r == VR_OK)
        r = compile(name, GL_FRAGMENT_SHADER, fs, &f, err);
    if (r != VR_OK) {
        if (v)
            glDeleteShader(v);
        return r;
    }
    GLuint p = glCreateProgram();
    glAttachShader(p, v);
    glAttachShader(p, f);
    glLinkProgram(p);
    /* The program keeps what it needs; the shaders can go now. */
    glDeleteShader(v);
    glDeleteShader(f);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[768] = "";
        glGetProgramInfoLog(p, sizeof log, NULL, log);
        glDeleteProgram(p);
        return vr_fail(err, VR_ERR_SHADER, "%s: link: %s", name, log);
    }
    *out = p;
    return VR_OK;
}

/* The buffer path's factor table as GLSL: "const float KS[n] = ...". */
static char *ks_table(const float *ks, int n)
{
    size_t size = 64 + 18 * (size_t)n;
    char *t = malloc(size);
    if (!t)
        return NULL;
    int len = snprintf(t, size, "const float KS[%d] = float[%d](", n, n);
    for (int i = 0; i < n && len > 0 && (size_t)len < size; i++)
        len += snprintf(t + len, size - (size_t)len, "%s%.9e", i ? ", " : "", (double)ks[i]);
    if (len > 0 && (size_t)len < size)
        snprintf(t + len, size - (size_t)len, ");\n");
    return t;
}

vr_result vr_program_build(const vr_program_key *key, const float *ks, vr_program *out,
                           vr_error *err)
{
    char name[224], defines[1024];
    key_name(key, name, sizeof name);
    /* The shaders implement the paths vdsh_runtime_interp chooses; should
     * it ever choose another, say so rather than draw something else. */
    int interp = vr_mode_interp((vr_mode)key->mode, key->quantity);
    int order = vr_mode_order((vr_mode)key->mode);
    if (interp >= 0 && interp != VDSH_INTERP_VISIBILITY && interp != VDSH_INTERP_DISTANCE &&
        !(interp == VDSH_INTERP_SPLIT && order == 5))
        return vr_fail(err, VR_ERR_SHADER, "%s: the runtime has no shaders for this path", name);
    int buffer = key->mode == VR_MODE_VDSH_BUFFER;
    if (buffer && (key->buf_order < 1 || key->buf_order > VDSH_MAX_ORDER || !ks))
        return vr_fail(err, VR_ERR_SHADER, "%s: no buffer order", name);
    GLint max_varying = 0;
    glGetIntegerv(GL_MAX_VARYING_COMPONENTS, &max_varying);
    int flat = varying_components(key, 1) <= max_varying;

    /* The buffer path's code goes between the vertex stage's
     * declarations and its main(). */
    char *table = buffer ? ks_table(ks, key->buf_order * key->buf_order) : NULL;
    size_t vs_size = sizeof defines + sizeof common_glsl + sizeof vertex_glsl +
                     (table ? strlen(table) : 0) + vr_buffer_glsl_size + sizeof vertex_main_glsl;
    size_t fs_size = sizeof defines + sizeof common_glsl + vr_sdf_glsl_size + sizeof fragment_glsl;
    char *vs = malloc(vs_size), *fs = malloc(fs_size);
    if (!vs || !fs || (buffer && !table)) {
        free(vs);
        free(fs);
        free(table);
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
    }
    /* A driver that packs varyings less tightly than the component count
     * assumes may still refuse the flat constants: then read uniforms. */
    GLuint prog = 0;
    vr_result r;
    for (;; flat = 0) {
        key_defines(key, flat, defines, sizeof defines);
        snprintf(vs, vs_size, "%s%s%s%s%s%s", defines, common_glsl, vertex_glsl,
                 buffer ? table : "", buffer ? vr_buffer_glsl : "", vertex_main_glsl);
        snprintf(fs, fs_size, "%s%s%s%s", defines, common_glsl,
                 key->mode == VR_MODE_SDF ? vr_sdf_glsl : "", fragment_glsl);
        r = vr_link(name, vs, fs, &prog, err);
        if (r != VR_ERR_SHADER || !flat)
            break;
    }
    free(vs);
    free(fs);
    free(table);
    if (r != VR_OK)
        return r;

    vr_program p = {.key = *key, .prog = prog};
    p.u_view_proj = glGetUniformLocation(prog, "u_view_proj");
    p.u_scale = glGetUniformLocation(prog, "u_scale");
    p.u_coef_step = glGetUniformLocation(prog, "u_coef_step");
    p.u_max_distance = glGetUniformLocation(prog, "u_max_distance");
    p.u_light_pos = glGetUniformLocation(prog, "u_light_pos");
    p.u_light_color = glGetUniformLocation(prog, "u_light_color");
    p.u_light_att = glGetUniformLocation(prog, "u_light_att");
    p.u_ambient = glGetUniformLocation(prog, "u_ambient");
    p.u_shadow_nf = glGetUniformLocation(prog, "u_shadow_nf");
    p.u_shadow_texel = glGetUniformLocation(prog, "u_shadow_texel");

    /* Samplers never change unit: set them once. */
    glUseProgram(prog);
    GLint basis = glGetUniformLocation(prog, "u_basis");
    if (basis >= 0) {
        const GLint units[4] = {VR_UNIT_BASIS, VR_UNIT_BASIS + 1, VR_UNIT_BASIS + 2,
                                VR_UNIT_BASIS + 3};
        glUniform1iv(basis, 4, units);
    }
    GLint coef = glGetUniformLocation(prog, "u_coef");
    if (coef >= 0)
        glUniform1i(coef, VR_UNIT_COEF);
    GLint shadow = glGetUniformLocation(prog, "u_shadow");
    if (shadow >= 0) {
        GLint units[VR_MAX_LIGHTS_PER_PASS];
        for (int i = 0; i < VR_MAX_LIGHTS_PER_PASS; i++)
            units[i] = VR_UNIT_SHADOW + i;
        glUniform1iv(shadow, key->lights, units);
    }
    glUseProgram(0);
    r = vr_check_gl(err, name);
    if (r != VR_OK) {
        glDeleteProgram(prog);
        return r;
    }
    *out = p;
    return VR_OK;
}

vr_result vr_program_build_depth(GLuint *out, vr_error *err)
{
    return vr_link("cube shadow map depth program", depth_vs, depth_fs, out, err);
}
