/*
 * vr_sums_main.glsl - the main() of vr_sums.glsl's compute shader, after
 * vdsh_buffer.glsl.
 */
void main()
{
    /* rows of at most 65535 groups (vr_dispatch) */
    int id = int(gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x +
                 gl_GlobalInvocationID.x);
    g_vertex = id / u_lights;
    g_light = id - g_vertex * u_lights;
    if (g_vertex >= u_vertices)
        return;
    float sum[1];
    buffer_sums(sum);
    s_sum[id] = sum[0];
}
