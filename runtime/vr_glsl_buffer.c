/*
 * vr_glsl_buffer.c - the vertex-stage code of VR_MODE_VDSH_BUFFER
 * (vr.h): a vertex's coefficients from a buffer texture, its SH sum toward
 * every light of the pass by the associated-Legendre recurrence, for any
 * order. vr_glsl.c puts it between the vertex stage's declarations and
 * its main(), which turns the sums into distances on the distance path
 * like every other mode (vdsh_distance, interpolated, compared per
 * fragment).
 *
 * The recurrence is formats/vdsh_sh.c's eval_high_bands, step for step
 * (the same convention as the closed forms of bands 0-4: Condon-Shortley
 * phase, sin for m < 0, index l(l+1)+m): for each m, (x + iy)^m and
 * P_m^m = -(2m - 1) P_{m-1}^{m-1}, then P_l^m from the two before it, the
 * (1 - z^2)^(m/2) factor carried by (x + iy)^m. It runs over every band
 * here, where the C evaluation uses its closed forms below band 5: the
 * two agree to float rounding (tests/test_runtime_buffer.c measures it).
 * The normalisations K_l^m (sqrt 2 folded in for m != 0), times an s8 or
 * s8s6 stream's steps, come as a constant table per coefficient index,
 * written into the source (KS, vr_buffer.c and vr_glsl.c: a program per
 * table). Read from a uniform array instead, the lookups cost as much as
 * the texel fetches on llvmpipe (its bounds-checked gathers; about 17 ms
 * a frame of the paper-sized room at order 12), from the constant table
 * about 4.
 *
 * The loops run m outside and l inside, and each light's recurrence state
 * lives in small arrays, so that each coefficient is fetched (and for s8,
 * s8s6 unpacked) once per vertex, not once per light; the record holds
 * the coefficients in that very order (vr_buffer_sequence), so it is read
 * front to back, a texel (four coefficients, or an s8s6 word's five) at a
 * time (buf_next).
 */
#include "vr_internal.h"


const char vr_buffer_glsl[] =
    "#if BUFFER\n"
    "#if BUF_KIND == 2\n"
    "uniform isamplerBuffer u_coef;\n"
    "#elif BUF_KIND == 3\n"
    "uniform usamplerBuffer u_coef;\n"
    "#else\n"
    "uniform samplerBuffer u_coef;\n"
    "#endif\n"

    "#if BUF_VARIABLE\n"
    "layout(location = 9) in uint a_record;  /* the record's first texel */\n"
    "layout(location = 10) in uint a_order;  /* this vertex's order */\n"
    "#endif\n"
    "\n"
    "/* A reader of one record, front to back. */\n"
    "int b_texel;\n"
    "#if BUF_KIND == 3\n"
    "uint b_w0, b_w;   /* s8s6: word 0 (coefficients 0-3), the current word */\n"
    "int b_field;\n"
    "#else\n"
    "vec4 b_cache;\n"
    "int b_j;\n"
    "#endif\n"
    "\n"
    "void buf_begin(int first)\n"
    "{\n"
    "#if BUF_KIND == 3\n"
    "    b_w0 = texelFetch(u_coef, first).r;\n"
    "    b_texel = first + 1;\n"
    "    b_field = 5;\n"
    "#else\n"
    "    b_texel = first;\n"
    "    b_j = 4;\n"
    "#endif\n"
    "}\n"
    "\n"
    "/* The next coefficient, whose index is i, times KS[i]: K_l^m (and an\n"
    " * s8, s8s6 stream's step), a constant table (vr_glsl.c). */\n"
    "float buf_next(int i)\n"
    "{\n"
    "    float ks = KS[i];\n"
    "#if BUF_KIND == 3\n"
    "    if (i < 4)\n"
    "        return ks * float(int(b_w0 << uint(24 - 8 * i)) >> 24);\n"
    "    if (b_field == 5) {\n"
    "        b_w = texelFetch(u_coef, b_texel).r;\n"
    "        b_texel++;\n"
    "        b_field = 0;\n"
    "    }\n"
    "    int q = int(b_w << uint(26 - 6 * b_field)) >> 26;\n"
    "    b_field++;\n"
    "    return ks * float(q);\n"
    "#else\n"
    "    if (b_j == 4) {\n"
    "        b_cache = vec4(texelFetch(u_coef, b_texel));\n"
    "        b_texel++;\n"
    "        b_j = 0;\n"
    "    }\n"
    "    float c = b_cache[b_j];\n"
    "    b_j++;\n"
    "    return ks * c;\n"
    "#endif\n"
    "}\n"
    "\n"
    "#if NUM_LIGHTS > 0\n"
    "/* sums[i]: the stream's SH sum toward light i (any direction for a\n"
    " * light at the vertex: main() ignores it there). */\n"
    "void buffer_sums(out float sums[NUM_LIGHTS])\n"
    "{\n"
    "#if BUF_VARIABLE\n"
    "    int k = int(a_order);\n"
    "    buf_begin(int(a_record));\n"
    "#else\n"
    "    int k = BUF_ORDER;\n"
    "    buf_begin(gl_VertexID * BUF_STRIDE);\n"
    "#endif\n"
    "    vec3 d[NUM_LIGHTS];\n"
    "    float cs[NUM_LIGHTS], sn[NUM_LIGHTS], pmm[NUM_LIGHTS], p0[NUM_LIGHTS], p1[NUM_LIGHTS];\n"
    "    for (int i = 0; i < NUM_LIGHTS; i++) {\n"
    "        vec3 lv = u_light_pos[i] - a_position;\n"
    "        float dl = length(lv);\n"
    "        d[i] = dl > 0.0 ? lv / dl : vec3(0.0, 0.0, 1.0);\n"
    "        cs[i] = 1.0;\n"
    "        sn[i] = 0.0;\n"
    "        pmm[i] = 1.0;\n"
    "        p0[i] = 0.0;\n"
    "        p1[i] = 0.0;\n"
    "        sums[i] = 0.0;\n"
    "    }\n"
    "    for (int m = 0; m < k; m++) {\n"
    "        if (m > 0)   /* (x + iy)^m, and P_m^m = -(2m - 1) P_{m-1}^{m-1} */\n"
    "            for (int i = 0; i < NUM_LIGHTS; i++) {\n"
    "                float c = d[i].x * cs[i] - d[i].y * sn[i];\n"
    "                sn[i] = d[i].x * sn[i] + d[i].y * cs[i];\n"
    "                cs[i] = c;\n"
    "                pmm[i] *= -float(2 * m - 1);\n"
    "            }\n"
    "        for (int l = m; l < k; l++) {\n"
    "            int row = l * (l + 1);\n"
    "            float cp = buf_next(row + m);\n"
    "            float cn = m > 0 ? buf_next(row - m) : 0.0;\n"
    "            float a = float(2 * l - 1) / float(max(l - m, 1));\n"
    "            float b = float(l + m - 1) / float(max(l - m, 1));\n"
    "            for (int i = 0; i < NUM_LIGHTS; i++) {\n"
    "                /* P_l^m from P_{l-1}^m (p1) and P_{l-2}^m (p0) */\n"
    "                float pl = l == m ? pmm[i]\n"
    "                         : l == m + 1 ? d[i].z * float(2 * m + 1) * pmm[i]\n"
    "                         : a * d[i].z * p1[i] - b * p0[i];\n"
    "                p0[i] = p1[i];\n"
    "                p1[i] = pl;\n"
    "                sums[i] += pl * (cp * cs[i] + cn * sn[i]);\n"
    "            }\n"
    "        }\n"
    "    }\n"
    "    for (int i = 0; i < NUM_LIGHTS; i++)\n"
    "        sums[i] *= u_scale;\n"
    "}\n"
    "#endif\n"
    "#endif\n";

const size_t vr_buffer_glsl_size = sizeof vr_buffer_glsl;
