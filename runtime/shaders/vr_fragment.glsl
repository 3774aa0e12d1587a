/*
 * vr_fragment.glsl - the C runtime's fragment stage (runtime/vr_glsl.c:
 * the #defines of each program, vdsh_common.glsl, then this).
 */
in vec3 v_position;
in vec3 v_normal;
#if VDSH_VISIBILITY && NUM_LIGHTS > 0
in float v_vis[NUM_LIGHTS];
#endif
#if VDSH_VISIBILITY && OUTPUT == 1
in float v_dv;
in float v_dl;
#endif
#if VDSH_DISTANCE && NUM_LIGHTS > 0
in float v_dist[NUM_LIGHTS];
#endif
#if VDSH_SPLIT
#if NUM_LIGHTS > 0
in float v_sum9[NUM_LIGHTS];
#endif
in vec4 v_c9, v_c13, v_c17, v_c21;
#endif
/* Per-draw constants: light colours and the ambient term are already
 * multiplied by the albedo; shadow planes are (near, far) of the
 * cube map's face projections, the texel size 2 / face size. */
#if FLAT_LIGHTS
flat in vec3 f_ambient;
#if NUM_LIGHTS > 0
flat in vec3 f_light_pos[NUM_LIGHTS];
flat in vec3 f_light_color[NUM_LIGHTS];
flat in vec3 f_light_att[NUM_LIGHTS];
#endif
#if SHADOW_CUBE && NUM_LIGHTS > 0
flat in vec2 f_shadow_nf[NUM_LIGHTS];
flat in float f_shadow_texel;
#endif
#if VDSH_SPLIT
flat in float f_max_distance;
#endif
#define AMBIENT f_ambient
#define LIGHT_POS(I) f_light_pos[I]
#define LIGHT_COLOR(I) f_light_color[I]
#define LIGHT_ATT(I) f_light_att[I]
#define SHADOW_NF(I) f_shadow_nf[I]
#define SHADOW_TEXEL f_shadow_texel
#define MAX_DISTANCE f_max_distance
#else
uniform vec3 u_ambient;
#if NUM_LIGHTS > 0
uniform vec3 u_light_pos[NUM_LIGHTS];
uniform vec3 u_light_color[NUM_LIGHTS];
uniform vec3 u_light_att[NUM_LIGHTS];
#endif
#if SHADOW_CUBE && NUM_LIGHTS > 0
uniform vec2 u_shadow_nf[NUM_LIGHTS];
uniform float u_shadow_texel;
#endif
#if VDSH_SPLIT
uniform float u_max_distance;
#endif
#define AMBIENT u_ambient
#define LIGHT_POS(I) u_light_pos[I]
#define LIGHT_COLOR(I) u_light_color[I]
#define LIGHT_ATT(I) u_light_att[I]
#define SHADOW_NF(I) u_shadow_nf[I]
#define SHADOW_TEXEL u_shadow_texel
#define MAX_DISTANCE u_max_distance
#endif
#if SHADOW_CUBE && NUM_LIGHTS > 0
uniform samplerCubeShadow u_shadow[NUM_LIGHTS];
#endif
#if VDSH_SPLIT && CUBEMAP_BASIS
uniform samplerCube u_basis[4];
#endif
out vec4 o_color;

#if VDSH_SPLIT
/* The SH sum of bands 3-4 toward unit direction d. */
float vdsh_sh_sum16(vec3 d)
{
#if CUBEMAP_BASIS
    return dot(v_c9, texture(u_basis[0], d)) + dot(v_c13, texture(u_basis[1], d)) +
           dot(v_c17, texture(u_basis[2], d)) + dot(v_c21, texture(u_basis[3], d));
#else
    vec4 b9, b13, b17, b21;
    sh_basis16(d, b9, b13, b17, b21);
    return dot(v_c9, b9) + dot(v_c13, b13) + dot(v_c17, b17) + dot(v_c21, b21);
#endif
}

/* sum9: bands 0-2 from the vertex stage; lv: receiver to light. */
float split_visibility(float sum9, vec3 lv, float dl, out float dv)
{
    dv = 0.0;
    if (!(dl > 0.0))
        return vdsh_compare(0.0, dl);
    dv = vdsh_distance(sum9 + vdsh_sh_sum16(lv / dl), MAX_DISTANCE);
    return vdsh_compare(dv, dl);
}
#endif

#if VDSH_DISTANCE
/* dist: the vertices' distances toward the light, interpolated;
 * compared with this fragment's own light distance dl. */
float distance_visibility(float dist, float dl, out float dv)
{
    dv = dist;
    return vdsh_compare(dist, dl);
}
#endif

#if SHADOW_CUBE && NUM_LIGHTS > 0
/* Baseline: depth cube map of the light, compared at the receiver's
 * depth in the face it falls in (major axis). The receiver is first
 * pushed off its surface along the normal by 1.5 shadow texels at its
 * distance (normal-offset bias: removes acne at grazing angles without
 * the detached shadows of a large depth bias). */
float cube_visibility(samplerCubeShadow map, vec2 nf, vec3 lv, float dl, vec3 n)
{
    if (!(dl > 0.0))
        return 1.0;   /* at the receiver, as vdsh_compare */
    vec3 v = -lv;
    float ma = max(max(abs(v.x), abs(v.y)), abs(v.z));
    v += n * (1.5 * SHADOW_TEXEL * ma);
    ma = max(max(abs(v.x), abs(v.y)), abs(v.z));
    float z = (nf.y + nf.x) / (nf.y - nf.x) - 2.0 * nf.y * nf.x / ((nf.y - nf.x) * ma);
    float ref = 0.5 * z + 0.5;
#if PCF
    /* four bilinear (2x2) taps a texel apart around v */
    vec3 a = abs(v.y) < 0.9 * length(v) ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 t1 = normalize(cross(v, a)) * (0.5 * SHADOW_TEXEL * ma);
    vec3 t2 = normalize(cross(v, t1)) * (0.5 * SHADOW_TEXEL * ma);
    return 0.25 * (texture(map, vec4(v + t1 + t2, ref)) + texture(map, vec4(v + t1 - t2, ref)) +
                   texture(map, vec4(v - t1 + t2, ref)) + texture(map, vec4(v - t1 - t2, ref)));
#else
    return texture(map, vec4(v, ref));
#endif
}
#endif

#if NUM_LIGHTS > 0
/* Lambert with distance attenuation, before the shadow. */
vec3 light_term(vec3 color, vec3 att3, vec3 lv, float dl, vec3 n)
{
    float ndl = dl > 0.0 ? max(dot(n, lv) / dl, 0.0) : 1.0;
    float att = 1.0 / dot(att3, vec3(1.0, dl, dl * dl));
    return color * (ndl * att);
}
#endif

/* Per mode: the visibility of light I; may set dv (debug output). */
#if VDSH_VISIBILITY
#define VISIBILITY(I) v_vis[I]
#elif VDSH_DISTANCE
#define VISIBILITY(I) distance_visibility(v_dist[I], dl, dv)
#elif VDSH_SPLIT
#define VISIBILITY(I) split_visibility(v_sum9[I], lv, dl, dv)
#elif SHADOW_SDF
#define VISIBILITY(I) sdf_visibility(v_position, n, LIGHT_POS(I))
#elif SHADOW_CUBE
#define VISIBILITY(I) cube_visibility(u_shadow[I], SHADOW_NF(I), lv, dl, n)
#else
#define VISIBILITY(I) 1.0
#endif
#define LIGHT(I) { vec3 lv = LIGHT_POS(I) - v_position; float dl = length(lv); float dv = -1.0; float s = VISIBILITY(I); acc += s * light_term(LIGHT_COLOR(I), LIGHT_ATT(I), lv, dl, n); if (I == 0) { s0 = s; dv0 = dv; dl0 = dl; } }

void main()
{
    vec3 n = normalize(v_normal);
    vec3 acc = vec3(0.0);
    float s0 = 1.0, dv0 = -1.0, dl0 = 0.0;
    FOR_EACH_LIGHT
#if VDSH_VISIBILITY && OUTPUT == 1
    /* the values the vertex stage compared */
    dv0 = v_dv;
    dl0 = v_dl;
#endif
#if OUTPUT == 1
    o_color = vec4(s0, dv0, dl0, 1.0);
#elif OUTPUT == 2
    o_color = vec4(v_position, 1.0);
#else
    o_color = vec4(AMBIENT + acc, 1.0);
#endif
}
