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
 * The normalisations K_l^m (sqrt 2 folded in for m != 0) are computed in
 * double on the CPU as the C code does and written into the source as
 * float literals (vr_buffer_table).
 *
 * The loops run m outside and l inside, and each light's recurrence state
 * lives in small arrays, so that each coefficient is fetched (and for s8,
 * s8s6 unpacked) once per vertex, not once per light.
 */
#include "vr_internal.h"

#include <math.h>
#include <stdio.h>

const char vr_buffer_glsl[] =
    "#if BUFFER\n"
    "#if BUF_KIND == 2\n"
    "uniform isamplerBuffer u_coef;\n"
    "#elif BUF_KIND == 3\n"
    "uniform usamplerBuffer u_coef;\n"
    "#else\n"
    "uniform samplerBuffer u_coef;\n"
    "#endif\n"
    "#if BUF_KIND >= 2\n"
    "uniform samplerBuffer u_steps;   /* per coefficient index */\n"
    "#endif\n"
    "#if BUF_VARIABLE\n"
    "layout(location = 9) in uint a_record;  /* start, in 4-byte words */\n"
    "layout(location = 10) in uint a_order;  /* this vertex's order */\n"
    "#endif\n"
    "\n"
    "/* Coefficient i of the record starting at texel base. */\n"
    "float buf_coef(int base, int i)\n"
    "{\n"
    "#if BUF_KIND <= 1\n"
    "    return texelFetch(u_coef, base + i).r;\n"
    "#elif BUF_KIND == 2\n"
    "    return float(texelFetch(u_coef, base + i).r) * texelFetch(u_steps, i).r;\n"
    "#else\n"
    "    /* s8s6: bytes 0-3 of word 0 hold coefficients 0-3; word 1 + w\n"
    "     * holds 4 + 5w .. 8 + 5w, six bits each from bit 0 */\n"
    "    uint w;\n"
    "    int q;\n"
    "    if (i < 4) {\n"
    "        w = texelFetch(u_coef, base).r;\n"
    "        q = int(w << uint(24 - 8 * i)) >> 24;\n"
    "    } else {\n"
    "        int j = i - 4;\n"
    "        w = texelFetch(u_coef, base + 1 + j / 5).r;\n"
    "        q = int(w << uint(26 - 6 * (j - 5 * (j / 5)))) >> 26;\n"
    "    }\n"
    "    return float(q) * texelFetch(u_steps, i).r;\n"
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
    "    int base = int(a_record) * BUF_PER_WORD;\n"
    "#else\n"
    "    int k = BUF_ORDER;\n"
    "    int base = gl_VertexID * BUF_STRIDE;\n"
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
    "            float kk = SH_K[row / 2 + m];\n"
    "            float cp = kk * buf_coef(base, row + m);\n"
    "            float cn = m > 0 ? kk * buf_coef(base, row - m) : 0.0;\n"
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

int vr_buffer_table(int order, char *buf, size_t size)
{
    int nk = order * (order + 1) / 2;
    int n = snprintf(buf, size, "const float SH_K[%d] = float[%d](", nk, nk);
    for (int l = 0; l < order; l++)
        for (int m = 0; m <= l && n > 0 && (size_t)n < size; m++) {
            double kk = (2.0 * l + 1.0) / (4.0 * 3.14159265358979323846);
            for (int f = l - m + 1; f <= l + m; f++)
                kk /= f;
            float k = m == 0 ? (float)sqrt(kk) : (float)sqrt(2.0 * kk);
            n += snprintf(buf + n, size - (size_t)n, "%s%.9e", l || m ? ", " : "", (double)k);
        }
    if (n > 0 && (size_t)n < size)
        n += snprintf(buf + n, size - (size_t)n, ");\n");
    return n > 0 && (size_t)n < size ? 0 : -1;
}
