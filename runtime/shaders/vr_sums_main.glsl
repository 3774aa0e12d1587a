/*
 * vr_sums_main.glsl - the main() of vr_sums.glsl's compute shader, after
 * vdsh_buffer.glsl.
 */
void main()
{
    /* rows of at most 65535 groups (vr_buffer.c's dispatch) */
    int id = int(gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x +
                 gl_GlobalInvocationID.x);
    int per = (u_lights + NUM_LIGHTS - 1) / NUM_LIGHTS;
    g_vertex = id / per;
    g_light = (id - g_vertex * per) * NUM_LIGHTS;
    /* a vertex no triangle of the frame's view uses (vr_cull.glsl) */
    if (g_vertex >= u_vertices || s_seen[g_vertex] != u_frame)
        return;
    float sum[NUM_LIGHTS];
    buffer_sums(sum);
    for (int i = 0; i < NUM_LIGHTS && g_light + i < u_lights; i++)
        s_sum[g_vertex * u_lights + g_light + i] = sum[i];
}
