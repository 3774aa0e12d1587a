/*
 * vr_sums.glsl - the C runtime's sums in a compute shader
 * (vr_scene_desc.sums = VR_SUMS_COMPUTE, runtime/vr_buffer.c): one
 * invocation per vertex and group of NUM_LIGHTS lights of the frame (a
 * cpca stream read from its records: the frame's lights, up to 16; else
 * 8 on llvmpipe, 1 elsewhere: vr_buffer.c sums_group; the last group's
 * missing lights repeat the frame's last) computes the
 * stream's SH sums toward them with vdsh_buffer.glsl's buffer_sums, and
 * stores light j's at vertex * u_lights + j; the
 * light passes' vertex stage then reads one value per light
 * (vr_vertex_main.glsl, BUF_SUMS) where it would have summed the record.
 * This part goes before vdsh_buffer.glsl (the vertex, receiver and light
 * it reads are these), vr_sums_main.glsl after it. The record is read as
 * stored (a cpca stream's decoded as it is read, BUF_KIND 4), or a cpca
 * stream's decoded scratch (BUF_KIND 0, vdsh_cpca_decode.glsl). A group
 * of lights per invocation fetches (and unpacks, and decodes) each
 * coefficient once for the group, as the vertex stage
 * does (docs/BENCHMARKS.md "Sums in a compute shader"). Vertices that
 * no triangle in view uses are skipped (vr_cull.glsl marks the others).
 */
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer vr_positions { float s_position[]; };
layout(std430, binding = 1) readonly buffer vr_lights { vec4 s_light[]; };
layout(std430, binding = 2) writeonly buffer vr_sums { float s_sum[]; };
layout(std430, binding = 3) readonly buffer vr_seen { uint s_seen[]; };
uniform int u_vertices;   /* vertices of the scene */
uniform int u_lights;     /* lights of the frame */
uniform float u_scale;    /* as the vertex stage's */
uniform uint u_frame;     /* the vertices to sum: s_seen[v] == u_frame */
int g_vertex, g_light;    /* this invocation's */
#define BUF_VERTEX g_vertex
#define BUF_RECEIVER \
    vec3(s_position[3 * g_vertex], s_position[3 * g_vertex + 1], s_position[3 * g_vertex + 2])
#define BUF_LIGHT(i) s_light[min(g_light + (i), u_lights - 1)].xyz
