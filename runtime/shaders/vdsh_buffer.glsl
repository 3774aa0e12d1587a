/*
 * vdsh_buffer.glsl - the vertex-stage code of the buffer path
 * (VR_MODE_VDSH_BUFFER, vr.h; the web page's and vdsh_three.js's orders
 * other than 2, 3, 5 and the adaptive order): a vertex's coefficients from
 * a texture, its SH sum toward every light of the pass by the
 * associated-Legendre recurrence, for any order. The C runtime puts it
 * between its vertex stage's declarations and its main() (vr_glsl.c),
 * which turns the sums into distances on the distance path like every
 * other mode (vdsh_distance, interpolated, compared per fragment).
 *
 * Defines it reads (README.md here): BUFFER (1, else nothing is
 * declared), NUM_LIGHTS, BUF_ORDER, BUF_KIND (0 f32, 1 f16: float texels;
 * 2 s8: int texels; 3 s8s6: uint words), BUF_VARIABLE (1: attributes
 * a_record, a_order per vertex; 0: record gl_VertexID * BUF_STRIDE of
 * order BUF_ORDER), BUF_TEXTURE_2D (1: a 2D texture BUF_TEX_WIDTH texels
 * wide, for GLSL ES; 0: a buffer texture), a table
 * const float KS[BUF_ORDER * BUF_ORDER] (the K_l^m, times an s8 stream's
 * steps) written before it, and BUF_VERTEX, BUF_RECEIVER, BUF_LIGHT(i),
 * BUF_SCALE (default gl_VertexID, a_position, u_light_pos[i], u_scale;
 * the C runtime's compute shaders, vr_sums.glsl, set their own).
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
 *
 * BUF_KIND 4 (cpca, formats/VDSH.md "cpca streams"): the record is the
 * file's, BUF_STRIDE words (u_coef, uint): cluster c in bits 0-7 of word
 * 0, then BUF_CPCA_BASIS weight levels of BUF_CPCA_BITS bits each, a
 * field that does not fit in what is left of a word starting the next
 * (BUF_CPCA_BITS 0: a width per vector, each field's word and shifts
 * written out by the includer as BUF_CPCA_UNPACK(first), vr_buffer.c).
 * buf_begin unpacks the levels once; buf_next decodes four coefficients
 * (a texel of the f32 record) at a time from the model u_model (f32
 * texels: for cluster c and record texel t, BUF_CPCA_BASIS + 1 texels
 * from (c * BUF_CPCA_T + t) * (BUF_CPCA_BASIS + 1): the mean, then each
 * basis vector times its step) as mean + sum_j level_j * texel_j. So a
 * vertex decodes once for all the lights of its pass; decoding per light
 * instead (its sum as mean.Y + sum_j w_j (basis_j.Y)) fetches the same
 * model texels once per light (docs/BENCHMARKS.md "cpca"). Per pass the
 * decode is most of the frame on llvmpipe: (B + 1) * T model texels per
 * vertex (1980 at order 12, 8,54,4), each a bounds-checked gather, in
 * every pass of 8 lights, and indexed triangles shade a vertex 1.19
 * times a pass (GL_VERTEX_SHADER_INVOCATIONS over the vertex count, the
 * built-in room at --max-edge 0.2). The C runtime can instead decode once
 * per frame (vr_scene_desc.cpca_decode, vdsh_cpca_decode.glsl, which
 * includes this file for buf_begin and BUF_MODEL): a draw of points
 * writes every vertex's f32 record into a scratch, and the passes read
 * it as BUF_KIND 0, at 576 more GPU bytes per vertex at order 12 and half
 * the frame at 16 lights (docs/BENCHMARKS.md "Decoding once per frame").
 */
#if BUFFER
/* What the includer must define (README.md here): a shader that leaves
 * one out fails here, naming it, not at the first line that uses it (no
 * quotes in the messages: GLSL ES has no such characters). */
#if !defined(NUM_LIGHTS) || !defined(BUF_ORDER) || !defined(BUF_KIND) || !defined(BUF_VARIABLE)
#error vdsh_buffer.glsl: define NUM_LIGHTS, BUF_ORDER, BUF_KIND and BUF_VARIABLE before it
#elif BUF_VARIABLE == 0 && !defined(BUF_STRIDE)
#error vdsh_buffer.glsl: BUF_VARIABLE 0 needs BUF_STRIDE, the texels (words for BUF_KIND 3 and 4) of one vertex record
#endif
#ifndef BUF_TEXTURE_2D
#define BUF_TEXTURE_2D 0
#endif
#if BUF_TEXTURE_2D
/* WebGL2 (no buffer textures): the same texels, row by row, in a 2D
 * texture BUF_TEX_WIDTH texels wide */
#if BUF_KIND == 2
uniform highp isampler2D u_coef;
#elif BUF_KIND == 3 || BUF_KIND == 4
uniform highp usampler2D u_coef;
#else
uniform highp sampler2D u_coef;
#endif
#define BUF_FETCH(t) texelFetch(u_coef, ivec2((t) % BUF_TEX_WIDTH, (t) / BUF_TEX_WIDTH), 0)
#if BUF_KIND == 4
uniform highp sampler2D u_model;
#define BUF_MODEL(t) texelFetch(u_model, ivec2((t) % BUF_TEX_WIDTH, (t) / BUF_TEX_WIDTH), 0)
#endif
#else
#if BUF_KIND == 2
uniform isamplerBuffer u_coef;
#elif BUF_KIND == 3 || BUF_KIND == 4
uniform usamplerBuffer u_coef;
#else
uniform samplerBuffer u_coef;
#endif
#define BUF_FETCH(t) texelFetch(u_coef, t)
#if BUF_KIND == 4
uniform samplerBuffer u_model;
#define BUF_MODEL(t) texelFetch(u_model, t)
#endif
#endif
/* What buffer_sums reads, unless the includer says otherwise: the
 * vertex (a fixed order's record), the receiver's position, light i's
 * position (the bake's frame) and the stream's scale. */
#ifndef BUF_VERTEX
#define BUF_VERTEX gl_VertexID
#endif
#ifndef BUF_RECEIVER
#define BUF_RECEIVER a_position
#endif
#ifndef BUF_LIGHT
#define BUF_LIGHT(i) u_light_pos[i]
#endif
#ifndef BUF_SCALE
#define BUF_SCALE u_scale
#endif
#if BUF_VARIABLE
layout(location = 9) in uint a_record;  /* the record's first texel */
layout(location = 10) in uint a_order;  /* this vertex's order */
#endif

/* A reader of one record, front to back. */
int b_texel;
#if BUF_KIND == 3
uint b_w0, b_w;   /* s8s6: word 0 (coefficients 0-3), the current word */
int b_field;
#else
vec4 b_cache;
int b_j;
#endif
#if BUF_KIND == 4
float b_wt[BUF_CPCA_BASIS];   /* the weight levels */
#endif

void buf_begin(int first)
{
#if BUF_KIND == 3
    b_w0 = BUF_FETCH(first).r;
    b_texel = first + 1;
    b_field = 5;
#elif BUF_KIND == 4
    uint w = BUF_FETCH(first).r;
    int word = first, shift = 8;
    b_texel = int(w & 255u) * BUF_CPCA_T;
    b_j = 4;
#if BUF_CPCA_BITS == 0
    /* a width per vector: the fields' places written out (vr_buffer.c) */
    BUF_CPCA_UNPACK(first)
#else
    for (int j = 0; j < BUF_CPCA_BASIS; j++) {
        if (shift + BUF_CPCA_BITS > 32) {
            word++;
            w = BUF_FETCH(word).r;
            shift = 0;
        }
        b_wt[j] = float(int(w << uint(32 - shift - BUF_CPCA_BITS)) >> (32 - BUF_CPCA_BITS));
        shift += BUF_CPCA_BITS;
    }
#endif
#else
    b_texel = first;
    b_j = 4;
#endif
}

/* The next coefficient, whose index is i, times KS[i]: K_l^m (and an
 * s8, s8s6 stream's step), a constant table (vr_glsl.c). */
float buf_next(int i)
{
    float ks = KS[i];
#if BUF_KIND == 3
    if (i < 4)
        return ks * float(int(b_w0 << uint(24 - 8 * i)) >> 24);
    if (b_field == 5) {
        b_w = BUF_FETCH(b_texel).r;
        b_texel++;
        b_field = 0;
    }
    int q = int(b_w << uint(26 - 6 * b_field)) >> 26;
    b_field++;
    return ks * float(q);
#else
    if (b_j == 4) {
#if BUF_KIND == 4
        int t = b_texel * (BUF_CPCA_BASIS + 1);
        vec4 a = BUF_MODEL(t);
        for (int j = 0; j < BUF_CPCA_BASIS; j++)
            a += b_wt[j] * BUF_MODEL(t + 1 + j);
        b_cache = a;
#else
        b_cache = vec4(BUF_FETCH(b_texel));
#endif
        b_texel++;
        b_j = 0;
    }
    float c = b_cache[b_j];
    b_j++;
    return ks * c;
#endif
}

#if NUM_LIGHTS > 0
/* sums[i]: the stream's SH sum toward light i (any direction for a
 * light at the vertex: main() ignores it there). */
void buffer_sums(out float sums[NUM_LIGHTS])
{
#if BUF_VARIABLE
    int k = int(a_order);
    buf_begin(int(a_record));
#else
    int k = BUF_ORDER;
    buf_begin(BUF_VERTEX * BUF_STRIDE);
#endif
    vec3 d[NUM_LIGHTS];
    float cs[NUM_LIGHTS], sn[NUM_LIGHTS], pmm[NUM_LIGHTS], p0[NUM_LIGHTS], p1[NUM_LIGHTS];
    for (int i = 0; i < NUM_LIGHTS; i++) {
        vec3 lv = BUF_LIGHT(i) - BUF_RECEIVER;
        float dl = length(lv);
        d[i] = dl > 0.0 ? lv / dl : vec3(0.0, 0.0, 1.0);
        cs[i] = 1.0;
        sn[i] = 0.0;
        pmm[i] = 1.0;
        p0[i] = 0.0;
        p1[i] = 0.0;
        sums[i] = 0.0;
    }
    for (int m = 0; m < k; m++) {
        if (m > 0)   /* (x + iy)^m, and P_m^m = -(2m - 1) P_{m-1}^{m-1} */
            for (int i = 0; i < NUM_LIGHTS; i++) {
                float c = d[i].x * cs[i] - d[i].y * sn[i];
                sn[i] = d[i].x * sn[i] + d[i].y * cs[i];
                cs[i] = c;
                pmm[i] *= -float(2 * m - 1);
            }
        for (int l = m; l < k; l++) {
            int row = l * (l + 1);
            float cp = buf_next(row + m);
            float cn = m > 0 ? buf_next(row - m) : 0.0;
            float a = float(2 * l - 1) / float(max(l - m, 1));
            float b = float(l + m - 1) / float(max(l - m, 1));
            for (int i = 0; i < NUM_LIGHTS; i++) {
                /* P_l^m from P_{l-1}^m (p1) and P_{l-2}^m (p0) */
                float pl = l == m ? pmm[i]
                         : l == m + 1 ? d[i].z * float(2 * m + 1) * pmm[i]
                         : a * d[i].z * p1[i] - b * p0[i];
                p0[i] = p1[i];
                p1[i] = pl;
                sums[i] += pl * (cp * cs[i] + cn * sn[i]);
            }
        }
    }
    for (int i = 0; i < NUM_LIGHTS; i++)
        sums[i] *= BUF_SCALE;
}
#endif
#endif
