/*
 * vr_cull.glsl - which vertices a frame can show, for the sums in a
 * compute shader (vr_sums.glsl; runtime/vr_buffer.c vr_cull): one
 * invocation per triangle marks its three vertices seen this frame
 * (s_seen[v] = u_frame) unless all three lie beyond one plane of the view
 * frustum, where the rasteriser clips the whole triangle away. The sums
 * then skip every vertex no kept triangle uses: its value would be read
 * only by triangles that draw nothing. The test is in clip space before
 * the division (exact for points behind the eye too), against a frustum
 * grown by 1/1000 so that a triangle the rasteriser keeps by rounding is
 * kept here. Triangles marking a shared vertex write the same value.
 */
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer vr_positions { float s_position[]; };
layout(std430, binding = 1) readonly buffer vr_indices { uint s_index[]; };
layout(std430, binding = 2) writeonly buffer vr_seen { uint s_seen[]; };
uniform mat4 u_view_proj;
uniform int u_triangles;
uniform uint u_frame;

vec4 clip_of(uint v)
{
    return u_view_proj *
           vec4(s_position[3u * v], s_position[3u * v + 1u], s_position[3u * v + 2u], 1.0);
}

void main()
{
    /* rows of at most 65535 groups (vr_buffer.c's dispatch) */
    int t = int(gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x +
                gl_GlobalInvocationID.x);
    if (t >= u_triangles)
        return;
    uint i0 = s_index[3 * t], i1 = s_index[3 * t + 1], i2 = s_index[3 * t + 2];
    vec4 a = clip_of(i0), b = clip_of(i1), c = clip_of(i2);
    vec3 w = 1.001 * vec3(a.w, b.w, c.w);
    vec3 x = vec3(a.x, b.x, c.x), y = vec3(a.y, b.y, c.y), z = vec3(a.z, b.z, c.z);
    if (all(lessThan(x, -w)) || all(greaterThan(x, w)) || all(lessThan(y, -w)) ||
        all(greaterThan(y, w)) || all(lessThan(z, -w)) || all(greaterThan(z, w)))
        return;
    s_seen[i0] = u_frame;
    s_seen[i1] = u_frame;
    s_seen[i2] = u_frame;
}
