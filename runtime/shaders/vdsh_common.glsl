/*
 * vdsh_common.glsl - the VDSH shadow functions, for both stages, for any
 * engine (README.md here: the interface). GLSL 3.30 core and GLSL ES 3.00
 * (WebGL2) alike: the includer writes the #version line (and in ES the
 * precision statements) and these #defines first:
 *   QUANTITY  the stream's stored quantity: 0 distance, 1 distance^2,
 *             2 log-distance (formats/VDSH.md)
 *   COMPARE   0 smooth (the default), 1 binary
 *
 * The numbers are formats/vdsh_sh.h's and formats/vdsh_shadow.h's macros
 * as they stand there (tests/test_runtime_shaders.c checks each against
 * the C header): the SH basis of the D3DX convention, the ramp, the
 * log-sum limit.
 *
 *   sh_sum4, sh_sum9      an SH sum of bands 0-1, 0-2 toward unit d
 *   sh_basis16            the basis functions 9..24 (bands 3-4)
 *   vdsh_sh_sum25(g, d)   the sum of orders up to 5 from seven groups of
 *                         four coefficients (the glTF attributes
 *                         _VDSH<o>_0.._6, unused ones 0)
 *   vdsh_distance(s, md)  an SH sum -> a distance, clamped to the bake's
 *                         max distance md
 *   vdsh_compare(dv, dl)  stored distance dv, light distance dl ->
 *                         visibility in [0, 1]
 *   vdsh_shadow(s, md, dl) the two above together: visibility of a light
 *                         at distance dl from the sum toward it
 */
const float C00 = 0.28209479177387814f;
const float C1 = 0.4886025119029199f;
const float C2A = 1.0925484305920792f;
const float C20 = 0.31539156525252005f;
const float C22 = 0.5462742152960396f;
const float C33 = 0.5900435899266435f;
const float C32 = 2.890611442640554f;
const float C31 = 0.4570457994644658f;
const float C30 = 0.3731763325901154f;
const float C32B = 1.445305721320277f;
const float C44 = 2.5033429417967046f;
const float C43 = 1.7701307697799304f;
const float C42 = 0.9461746957575601f;
const float C41 = 0.6690465435572892f;
const float C40 = 0.10578554691520431f;
const float C42B = 0.47308734787878004f;
const float C44B = 0.6258357354491761f;

/* sum of c_i Y_i(d), coefficients 0..3 (bands 0-1), unit d */
float sh_sum4(vec4 c0, vec3 d)
{
    return dot(c0, vec4(C00, -C1 * d.y, C1 * d.z, -C1 * d.x));
}

/* coefficients 0..8 (bands 0-2) */
float sh_sum9(vec4 c0, vec4 c1, float c8, vec3 d)
{
    float x = d.x, y = d.y, z = d.z;
    vec4 b = vec4(C2A * x * y, -C2A * y * z, C20 * (3.0 * z * z - 1.0),
                  -C2A * x * z);
    return sh_sum4(c0, d) + dot(c1, b) + c8 * (C22 * (x * x - y * y));
}

/* basis functions 9..24 (bands 3-4), four per vec4 like the cubemaps */
void sh_basis16(vec3 d, out vec4 b9, out vec4 b13, out vec4 b17, out vec4 b21)
{
    float x = d.x, y = d.y, z = d.z;
    float x2 = x * x, y2 = y * y, z2 = z * z;
    b9 = vec4(-C33 * y * (3.0 * x2 - y2), C32 * x * y * z,
              -C31 * y * (5.0 * z2 - 1.0), C30 * z * (5.0 * z2 - 3.0));
    b13 = vec4(-C31 * x * (5.0 * z2 - 1.0), C32B * z * (x2 - y2),
               -C33 * x * (x2 - 3.0 * y2), C44 * x * y * (x2 - y2));
    b17 = vec4(-C43 * y * z * (3.0 * x2 - y2), C42 * x * y * (7.0 * z2 - 1.0),
               -C41 * y * z * (7.0 * z2 - 3.0),
               C40 * (35.0 * z2 * z2 - 30.0 * z2 + 3.0));
    b21 = vec4(-C41 * x * z * (7.0 * z2 - 3.0), C42B * (x2 - y2) * (7.0 * z2 - 1.0),
               -C43 * x * z * (x2 - 3.0 * y2),
               C44B * (x2 * x2 - 6.0 * x2 * y2 + y2 * y2));
}

/* The distance a stream's SH sum stands for (vdsh_stream_distance):
 * never negative, ringing below zero counts as 0; never above the
 * bake's max distance md, which sums below a vertex's horizon can
 * run far past. */
float vdsh_distance(float sum, float md)
{
#if QUANTITY == 1
    float d = sum > 0.0 ? sqrt(sum) : 0.0;
#elif QUANTITY == 2
    float d = exp(min(sum, 80.0f)); /* stays finite */
#else
    float d = sum > 0.0 ? sum : 0.0;
#endif
    return d > md ? md : d;
}

/* Visibility of a light at distance dl when the stored distance toward
 * it is dv (vdsh_shadow_compare). A light at the receiver is visible. */
float vdsh_compare(float dv, float dl)
{
    if (!(dl > 0.0))
        return 1.0;
#if COMPARE == 1
    return dv >= dl ? 1.0 : 0.0;
#else
    if (isinf(dv) && dv > 0.0)
        return 1.0;
    /* ramp(x) = saturate((x - 1/3) * 1.5), written as in vdsh_ramp */
    return clamp(1.5f * (dv / dl) - 0.5f, 0.0, 1.0);
#endif
}

/* The visibility of a light at distance dl (receiver to light) whose
 * direction gives the stream's SH sum `sum` (times the stream's scale). */
float vdsh_shadow(float sum, float md, float dl)
{
    return vdsh_compare(vdsh_distance(sum, md), dl);
}

/* The SH sum of a stream of order <= 5 toward unit d from its
 * coefficients in groups of four (g[k] = coefficients 4k .. 4k+3, as the
 * glTF attributes _VDSH<o>_k hold them; groups past the order 0). The
 * terms are summed as the C runtime's order-5 vertex stage sums them. */
float vdsh_sh_sum25(vec4 g[7], vec3 d)
{
    vec4 b9, b13, b17, b21;
    sh_basis16(d, b9, b13, b17, b21);
    return sh_sum9(g[0], g[1], g[2].x, d) + dot(vec4(g[2].yzw, g[3].x), b9) +
           dot(vec4(g[3].yzw, g[4].x), b13) + dot(vec4(g[4].yzw, g[5].x), b17) +
           dot(vec4(g[5].yzw, g[6].x), b21);
}
