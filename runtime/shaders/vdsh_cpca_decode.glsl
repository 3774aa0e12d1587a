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
 * does.
 */
layout(std430) writeonly buffer vr_decoded { vec4 d_out[]; };
#if BUF_CPCA_UBO
/* One cluster's model, the vertices drawn grouped by cluster (a draw per
 * cluster, this block bound to that cluster's range): the same texels as
 * u_model's, at indices the same for every vertex of the draw. */
layout(std140) uniform vr_model { vec4 u_m[BUF_CPCA_T * (BUF_CPCA_BASIS + 1)]; };
#define DEC_MODEL(k) u_m[k]
#else
#define DEC_MODEL(k) BUF_MODEL(b_texel * (BUF_CPCA_BASIS + 1) + (k))
#endif

void main()
{
#ifdef DEC_UNROLLED
    /* the includer's (vr_buffer.c): the loops below written out for the
     * draw's texels u_t0 .. u_t0 + chunk - 1, every u_m index u_t0 *
     * (BUF_CPCA_BASIS + 1) plus a constant */
    dec_unrolled(gl_VertexID);
#else
    buf_begin(gl_VertexID * BUF_STRIDE);
    for (int t = 0; t < BUF_CPCA_T; t++) {
        int m = t * (BUF_CPCA_BASIS + 1);
        vec4 a = DEC_MODEL(m);
        for (int j = 0; j < BUF_CPCA_BASIS; j++)
            a += b_wt[j] * DEC_MODEL(m + 1 + j);
        d_out[gl_VertexID * BUF_CPCA_T + t] = a;
    }
#endif
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
}
