/*
 * vdsh_cpca_decode.glsl - a cpca stream's decode on the GPU, once per
 * frame (vr_scene_desc.cpca_decode = VR_CPCA_PER_FRAME) or once at load
 * (VR_CPCA_AT_LOAD; vr_buffer.c): a compute shader, one invocation per
 * (vertex, texel of four coefficients), that writes each vertex's
 * coefficients as f32 texels (the buffer path's BUF_KIND 0 record: BUF_CPCA_T texels in
 * vr_buffer_sequence's order) into a shader storage buffer, the scratch
 * that the light passes or the sums then read. It follows
 * vdsh_buffer.glsl (included before it, BUF_KIND 4, NUM_LIGHTS 0):
 * buf_begin unpacks the weight levels, and the texel is
 * mean + sum_j level_j * texel_j in the same order of operations as
 * buf_next, so every path sums the same coefficients the per-pass decode
 * does. BUF_CPCA_DOT(m), where the includer defines it (vr_buffer.c
 * does), is that sum written out with constant weight indices: half the
 * decode's time on llvmpipe, which keeps a loop's weights in memory.
 * One invocation per texel rather than per vertex keeps a GPU's lanes
 * busy (36 times the invocations at order 12); each unpacks its vertex's
 * levels, a few words, against the 49 model texels it reads.
 */
layout(local_size_x = 64) in;
layout(std430, binding = 0) writeonly buffer vr_decoded { vec4 d_out[]; };
uniform int u_vertices;

void main()
{
    /* rows of at most 65535 groups (vr_buffer.c's dispatch) */
    int id = int(gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x +
                 gl_GlobalInvocationID.x);
    int v = id / BUF_CPCA_T;
    if (v >= u_vertices)
        return;
    buf_begin(v * BUF_STRIDE);
    int m = (b_texel + id - v * BUF_CPCA_T) * (BUF_CPCA_BASIS + 1);
#ifdef BUF_CPCA_DOT
    vec4 a = BUF_CPCA_DOT(m);
#else
    vec4 a = BUF_MODEL(m);
    for (int j = 0; j < BUF_CPCA_BASIS; j++)
        a += b_wt[j] * BUF_MODEL(m + 1 + j);
#endif
    d_out[id] = a;
}
