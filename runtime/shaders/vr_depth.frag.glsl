/* vr_depth.frag.glsl - the depth pass writes depth only. */
void main()
{
}
