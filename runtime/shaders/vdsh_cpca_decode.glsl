/*
 * vdsh_cpca_decode.glsl - a cpca stream's decode once per frame
 * (vr_scene_desc.cpca_decode = VR_CPCA_PER_FRAME, vr_buffer.c): a vertex
 * stage drawn as points with the rasteriser off, one invocation per
 * vertex, that writes each vertex's coefficients as f32 texels (the
 * buffer path's BUF_KIND 0 record: BUF_CPCA_T texels, four coefficients
 * each, in vr_buffer_sequence's order) into a shader storage buffer, the
 * scratch that every light pass of the frame then reads as an RGBA32F
 * buffer texture. It follows vdsh_buffer.glsl (included before it, BUF_KIND
 * 4, NUM_LIGHTS 0): buf_begin unpacks the weight levels, and each texel is
 * mean + sum_j level_j * texel_j in the same order of operations as
 * buf_next, so the passes sum the same coefficients the per-pass decode
 * does. BUF_CPCA_DOT(m), where the includer defines it (vr_buffer.c
 * does), is that sum written out with constant weight indices: half the
 * decode's time on llvmpipe, which keeps a loop's weights in memory.
 */
layout(std430) writeonly buffer vr_decoded { vec4 d_out[]; };

void main()
{
    buf_begin(gl_VertexID * BUF_STRIDE);
    for (int t = 0; t < BUF_CPCA_T; t++) {
        int m = (b_texel + t) * (BUF_CPCA_BASIS + 1);
#ifdef BUF_CPCA_DOT
        vec4 a = BUF_CPCA_DOT(m);
#else
        vec4 a = BUF_MODEL(m);
        for (int j = 0; j < BUF_CPCA_BASIS; j++)
            a += b_wt[j] * BUF_MODEL(m + 1 + j);
#endif
        d_out[gl_VertexID * BUF_CPCA_T + t] = a;
    }
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
}
