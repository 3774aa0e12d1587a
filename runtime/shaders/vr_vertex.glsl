/*
 * vr_vertex.glsl - the C runtime's vertex stage, its declarations
 * (runtime/vr_glsl.c: the #defines of each program, after which come
 * vdsh_common.glsl, this, the buffer path's KS table and vdsh_buffer.glsl
 * when BUFFER is 1, then vr_vertex_main.glsl). An example of the
 * interface of README.md, not part of it.
 */
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
#if ORDER >= 2
layout(location = 2) in vec4 a_c0;   /* coefficients 0..3 */
#endif
#if ORDER >= 3 && PACKED
/* s8s6: coefficients 4.. six bits each, five to a word: word w holds
 * 4 + 5w .. 8 + 5w in bits 0-5, 6-11, ..., 24-29 (two's complement) */
layout(location = 3) in uvec4 a_w0;  /* words 0..3 (order 3: word 0 only) */
#if ORDER >= 5
layout(location = 4) in uint a_w4;   /* word 4 */
#endif
#elif ORDER >= 3
layout(location = 3) in vec4 a_c1;   /* 4..7 */
layout(location = 4) in float a_c8;  /* 8 */
#endif
#if ORDER >= 5 && !PACKED
layout(location = 5) in vec4 a_c9;   /* 9..12, the first basis cubemap */
layout(location = 6) in vec4 a_c13;
layout(location = 7) in vec4 a_c17;
layout(location = 8) in vec4 a_c21;
#endif
uniform mat4 u_view_proj;
uniform float u_scale;   /* coefficient = stored value * u_scale */
/* and times a factor per coefficient, as the attributes are grouped:
 * an s8 stream's steps (vdsh_s8_step), 1 for f16 and f32 (exact) */
uniform vec4 u_coef_step[7];
#define C0 (a_c0 * u_coef_step[0])
#if PACKED
/* field j (0..4) of a packed word, sign-extended: exact, as in C */
float pk(uint w, int j)
{
    return float(int(w << uint(26 - 6 * j)) >> 26);
}
#define C1 (vec4(pk(a_w0.x, 0), pk(a_w0.x, 1), pk(a_w0.x, 2), pk(a_w0.x, 3)) * u_coef_step[1])
#define C8 (pk(a_w0.x, 4) * u_coef_step[2].x)
#define C9 (vec4(pk(a_w0.y, 0), pk(a_w0.y, 1), pk(a_w0.y, 2), pk(a_w0.y, 3)) * u_coef_step[3])
#define C13 (vec4(pk(a_w0.y, 4), pk(a_w0.z, 0), pk(a_w0.z, 1), pk(a_w0.z, 2)) * u_coef_step[4])
#define C17 (vec4(pk(a_w0.z, 3), pk(a_w0.z, 4), pk(a_w0.w, 0), pk(a_w0.w, 1)) * u_coef_step[5])
#define C21 (vec4(pk(a_w0.w, 2), pk(a_w0.w, 3), pk(a_w0.w, 4), pk(a_w4, 0)) * u_coef_step[6])
#else
#define C1 (a_c1 * u_coef_step[1])
#define C8 (a_c8 * u_coef_step[2].x)
#define C9 (a_c9 * u_coef_step[3])
#define C13 (a_c13 * u_coef_step[4])
#define C17 (a_c17 * u_coef_step[5])
#define C21 (a_c21 * u_coef_step[6])
#endif
uniform float u_max_distance; /* the clamp of every reconstructed distance */
#if NUM_LIGHTS > 0
uniform vec3 u_light_pos[NUM_LIGHTS];
#endif
#if BUF_SUMS && NUM_LIGHTS > 0
/* The frame's SH sums from a compute shader (vr_sums.glsl): vertex v's
 * toward the frame's light j at v * u_sums_stride + j; this pass's first
 * light is the frame's u_sums_first. */
uniform samplerBuffer u_sums;
uniform int u_sums_stride, u_sums_first;
#endif
#if FLAT_LIGHTS
/* handed on to the fragment stage (see the top of vr_glsl.c) */
uniform vec3 u_ambient;
flat out vec3 f_ambient;
#if NUM_LIGHTS > 0
uniform vec3 u_light_color[NUM_LIGHTS];
uniform vec3 u_light_att[NUM_LIGHTS];
flat out vec3 f_light_pos[NUM_LIGHTS];
flat out vec3 f_light_color[NUM_LIGHTS];
flat out vec3 f_light_att[NUM_LIGHTS];
#endif
#if SHADOW_CUBE && NUM_LIGHTS > 0
uniform vec2 u_shadow_nf[NUM_LIGHTS];
uniform float u_shadow_texel;
flat out vec2 f_shadow_nf[NUM_LIGHTS];
flat out float f_shadow_texel;
#endif
#if VDSH_SPLIT
flat out float f_max_distance;
#endif
#endif
/* Later passes (more lights) test depth with GL_LEQUAL against the
 * first pass's depth: every program must compute the same position. */
invariant gl_Position;
out vec3 v_position;
out vec3 v_normal;
#if VDSH_VISIBILITY && NUM_LIGHTS > 0
out float v_vis[NUM_LIGHTS];
#endif
#if VDSH_VISIBILITY && OUTPUT == 1
out float v_dv;
out float v_dl;
#endif
#if VDSH_DISTANCE && NUM_LIGHTS > 0
out float v_dist[NUM_LIGHTS];
#endif
#if VDSH_SPLIT
#if NUM_LIGHTS > 0
out float v_sum9[NUM_LIGHTS];
#endif
out vec4 v_c9, v_c13, v_c17, v_c21;
#endif

