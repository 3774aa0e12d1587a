/* vr_depth.vert.glsl - the cube shadow maps' depth pass (VR_MODE_CUBE;
 * runtime/vr_glsl.c writes the #version line first). */
layout(location = 0) in vec3 a_position;
uniform mat4 u_view_proj;
void main()
{
    gl_Position = u_view_proj * vec4(a_position, 1.0);
}
