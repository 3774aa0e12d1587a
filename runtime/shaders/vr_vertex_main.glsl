/*
 * vr_vertex_main.glsl - the C runtime's vertex stage, its main()
 * (runtime/vr_glsl.c; after vr_vertex.glsl and the buffer path's code).
 */
#if (VDSH_VISIBILITY || VDSH_DISTANCE) && !BUFFER
/* The stream's whole SH sum toward unit direction d. */
float vdsh_sh_sum(vec3 d)
{
#if ORDER == 2
    return u_scale * sh_sum4(C0, d);
#elif ORDER == 3
    return u_scale * sh_sum9(C0, C1, C8, d);
#else
    vec4 b9, b13, b17, b21;
    sh_basis16(d, b9, b13, b17, b21);
    return u_scale * (sh_sum9(C0, C1, C8, d) + dot(C9, b9) + dot(C13, b13) +
                      dot(C17, b17) + dot(C21, b21));
#endif
}
#endif

void main()
{
    v_position = a_position;
    v_normal = a_normal;
    gl_Position = u_view_proj * vec4(a_position, 1.0);
#if FLAT_LIGHTS
    f_ambient = u_ambient;
#if NUM_LIGHTS > 0
    for (int i = 0; i < NUM_LIGHTS; i++) {
        f_light_pos[i] = u_light_pos[i];
        f_light_color[i] = u_light_color[i];
        f_light_att[i] = u_light_att[i];
#if SHADOW_CUBE
        f_shadow_nf[i] = u_shadow_nf[i];
#endif
    }
#endif
#if SHADOW_CUBE && NUM_LIGHTS > 0
    f_shadow_texel = u_shadow_texel;
#endif
#if VDSH_SPLIT
    f_max_distance = u_max_distance;
#endif
#endif
#if VDSH_VISIBILITY && OUTPUT == 1
    v_dv = -1.0;
    v_dl = 0.0;
#endif
#if BUFFER && NUM_LIGHTS > 0
    float b_sum[NUM_LIGHTS];
#if BUF_SUMS
    for (int i = 0; i < NUM_LIGHTS; i++)
        b_sum[i] = texelFetch(u_sums, gl_VertexID * u_sums_stride + u_sums_first + i).r;
#else
    buffer_sums(b_sum);
#endif
#endif
#if (VDSH_VISIBILITY || VDSH_DISTANCE || VDSH_SPLIT) && NUM_LIGHTS > 0
    for (int i = 0; i < NUM_LIGHTS; i++) {
        vec3 lv = u_light_pos[i] - a_position;
        float dl = length(lv);
#if BUFFER
        float dv = dl > 0.0 ? vdsh_distance(b_sum[i], u_max_distance) : 0.0;
#elif VDSH_VISIBILITY || VDSH_DISTANCE
        /* A light at the vertex has no direction: distance 0, not NaN,
         * which would spread over every triangle around the vertex. */
        float dv = dl > 0.0 ? vdsh_distance(vdsh_sh_sum(lv / dl), u_max_distance) : 0.0;
#endif
#if VDSH_VISIBILITY
        v_vis[i] = vdsh_compare(dv, dl);
#if OUTPUT == 1
        if (i == 0) {
            v_dv = dv;
            v_dl = dl;
        }
#endif
#elif VDSH_DISTANCE
        v_dist[i] = dv;
#else
        /* As above, 0 for a light at the vertex; the fragment stage
         * gives such a light visibility 1. */
        v_sum9[i] = dl > 0.0 ? u_scale * sh_sum9(C0, C1, C8, lv / dl) : 0.0;
#endif
    }
#endif
#if VDSH_SPLIT
    v_c9 = u_scale * C9;
    v_c13 = u_scale * C13;
    v_c17 = u_scale * C17;
    v_c21 = u_scale * C21;
#endif
}
