/*
 * vr_glsl.c - the shaders: builds the programs from the files of
 * runtime/shaders/, compiled in at build time (shaders/README.md). One
 * source per stage, specialised with #defines for each program key
 * (mode, comparison, quantity, output, PCF, lights in the pass; and
 * whether the per-draw constants travel as flat varyings, below), so
 * every variant is straight-line code and nothing
 * branches on a uniform per pixel.
 *
 * The VDSH part is written as three layers, so that a new stored quantity
 * or a new comparison touches one function each:
 *   sh_sum4 / sh_sum9 / sh_basis16   the SH basis, formats/vdsh_sh.c
 *   vdsh_distance(sum, max)          an SH sum -> a distance, per quantity,
 *                                    clamped to the bake's max distance
 *                                    (formats/vdsh_shadow.c
 *                                    vdsh_stream_distance)
 *   vdsh_compare(d_vis, d_light)     a distance pair -> visibility, per
 *                                    comparison (vdsh_shadow_compare)
 * and each path (vdsh_interp, chosen by vdsh_runtime_interp from the order
 * and the stored quantity) only decides where sums are computed and what
 * is interpolated:
 *   VDSH_VISIBILITY  linear quantities, orders 2, 3: the whole sum, the
 *                    distance and the comparison per vertex; the
 *                    visibility is interpolated;
 *   VDSH_SPLIT       linear quantities, order 5 (the paper's): bands 0-2
 *                    per vertex toward the vertex's light direction,
 *                    interpolated; bands 3-4 (16 coefficients,
 *                    interpolated) dotted in the fragment stage with the
 *                    basis cubemaps or with the polynomials;
 *   VDSH_DISTANCE    log-distance, every order: the whole sum (all
 *                    order^2 coefficients) and its distance per vertex,
 *                    one interpolated distance per light, compared in the
 *                    fragment stage with the fragment's own light distance
 *                    (exp cannot be split across the stages, and
 *                    interpolating log coefficients would be a geometric
 *                    mean of the vertices' distances).
 * VR_MODE_VDSH_BUFFER takes the distance path for any stream: its vertex
 * stage reads the coefficients from a buffer texture and sums them by a
 * recurrence for any order (shaders/vdsh_buffer.glsl, spliced in before main()
 * when BUFFER is 1; ORDER is then 0: no coefficient attributes).
 * The numbers these functions share with the C definition (the SH
 * constants, the ramp's slope and offset, the log-sum limit) are the C
 * headers' macros as they stand, written into vdsh_common.glsl;
 * tests/test_runtime_shaders.c checks each against the header, and
 * tests/test_runtime_glsl.c renders these against vdsh_shadow (per
 * vertex) and vdsh_shadow_interior (per fragment).
 *
 * Lights: the per-light code is a macro, LIGHT(I), expanded once per light
 * of the pass with a literal index, because GLSL 3.30 only lets sampler
 * arrays (the shadow cube maps) be indexed by constant expressions.
 *
 * Per-draw constants of the fragment stage (light positions, colours,
 * attenuations, the ambient term, the cube maps' planes, and on the split
 * path, the only one that reconstructs a distance there, the scene's max
 * distance) reach it as flat varyings that the vertex stage copies from
 * the uniforms (FLAT_LIGHTS), not as uniforms: Mesa's llvmpipe (22.x)
 * reads every uniform component in a fragment shader with a bounds-checked
 * gather, about 20 instructions per component for every 8 fragments,
 * again in every 4x4 block, where a flat input is one broadcast per block.
 * Read as uniforms, the 15 components of one light's Lambert term cost
 * about a third of the room's lighting pass on llvmpipe
 * (docs/BENCHMARKS.md). The values are the uniforms' own, bit for bit.
 * When the varyings would not fit in GL_MAX_VARYING_COMPONENTS (8 lights
 * need up to 106 of the 128 that llvmpipe and GPUs offer; GL 3.3 only
 * promises 60), or a driver does not link them, the fragment stage reads
 * the uniforms.
 */
#include "vr_internal.h"

#include "vdsh_sh.h"
#include "vr_glsl_files.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The two stages' shared code is vdsh_common.glsl, the rest the runtime's
 * own stage files (runtime/shaders/, compiled in by cmake/embed_glsl.cmake
 * as vr_glsl_files.h's strings); the program's #defines go first. */
/* ------------------------------------------------------------------ */

static void key_name(const vr_program_key *k, char *buf, size_t size)
{
    int interp = vr_mode_interp((vr_mode)k->mode, k->quantity);
    char buf_what[64] = "";
    if (k->mode == VR_MODE_VDSH_BUFFER)
        snprintf(buf_what, sizeof buf_what, ", order %u%s %s", k->buf_order,
                 k->buf_variable ? " (cap, variable)" : "",
                 vdsh_encoding_name(k->buf_kind <= VR_BUF_CPCA ? k->buf_kind : 0));
    snprintf(buf, size, "program %s%s%s, %s, %s, output %u, pcf %u, %u lights%s%s",
             vr_mode_name((vr_mode)k->mode), interp >= 0 ? " path " : "",
             interp >= 0 ? vdsh_interp_name((uint32_t)interp) : "",
             k->compare == VDSH_COMPARE_BINARY ? "binary" : "smooth",
             vdsh_quantity_name(k->quantity), k->output, k->pcf, k->lights,
             k->packed ? ", s8s6" : "", buf_what);
}

/* The varying components a program passes from the vertex to the
 * fragment stage, with or without the flat per-draw constants. */
static int varying_components(const vr_program_key *k, int flat)
{
    int interp = vr_mode_interp((vr_mode)k->mode, k->quantity), n = k->lights;
    int c = 6; /* position, normal */
    if (interp >= 0)
        c += n; /* a visibility, distance or band 0-2 sum per light */
    if (interp == VDSH_INTERP_SPLIT)
        c += 16;
    if (interp == VDSH_INTERP_VISIBILITY && k->output == VR_OUTPUT_SHADOW)
        c += 2;
    if (flat)
        c += 3 + 9 * n + (k->mode == VR_MODE_CUBE && n > 0 ? 2 * n + 1 : 0) +
             (interp == VDSH_INTERP_SPLIT);
    return c;
}

/* The #defines that specialise the sources for one key. The VDSH path
 * comes from formats/vdsh_shadow.h, the same function vdsh-eval scores
 * with, so the shaders draw what the evaluator measures. */
static void key_defines(const vr_program_key *k, int flat, char *buf, size_t size)
{
    int order = vr_mode_order((vr_mode)k->mode), cube = k->mode == VR_MODE_CUBE;
    int visibility = 0, split = 0, distance = 0, cubemap = 0;
    int buffer = k->mode == VR_MODE_VDSH_BUFFER;
    /* (vr_program_build has checked that the path is one of these.) */
    switch (vr_mode_interp((vr_mode)k->mode, k->quantity)) {
    case VDSH_INTERP_VISIBILITY: visibility = 1; break;
    case VDSH_INTERP_DISTANCE: distance = 1; break;
    case VDSH_INTERP_SPLIT:
        split = 1;
        cubemap = k->mode == VR_MODE_VDSH5;
        break;
    default: break;
    }
    int n = snprintf(buf, size,
                     "#version 330 core\n"
                     "#define ORDER %d\n#define VDSH_VISIBILITY %d\n#define VDSH_SPLIT %d\n"
                     "#define VDSH_DISTANCE %d\n"
                     "#define CUBEMAP_BASIS %d\n#define SHADOW_CUBE %d\n"
                     "#define QUANTITY %u\n#define COMPARE %u\n#define OUTPUT %u\n"
                     "#define PCF %u\n#define NUM_LIGHTS %u\n#define FLAT_LIGHTS %d\n"
                     "#define PACKED %d\n#define BUFFER %d\n#define BUF_ORDER %u\n"
                     "#define BUF_KIND %u\n#define BUF_VARIABLE %u\n#define BUF_STRIDE %d\n"
                     "#define SHADOW_SDF %d\n"
                     "#define BUF_CPCA_BASIS %u\n#define BUF_CPCA_BITS %u\n"
                     "#define BUF_CPCA_T %d\n#define BUF_SUMS %u\n"
                     "#define FOR_EACH_LIGHT",
                     order, visibility, split, distance, cubemap, cube, k->quantity, k->compare,
                     k->output, k->pcf, k->lights, flat, k->packed && order >= 3, buffer,
                     k->buf_order, k->buf_kind, k->buf_variable,
                     !buffer ? 0
                     : k->buf_kind == VR_BUF_CPCA
                         ? (int)k->cpca_words
                         : vr_buffer_stride(k->buf_order, (vr_buf_kind)k->buf_kind),
                     k->mode == VR_MODE_SDF, k->cpca_basis, k->cpca_bits,
                     vr_buffer_stride(k->buf_order, VR_BUF_F32), k->buf_sums);
    for (unsigned i = 0; i < k->lights && n > 0 && (size_t)n < size; i++)
        n += snprintf(buf + n, size - (size_t)n, " LIGHT(%u)", i);
    if (n > 0 && (size_t)n < size)
        snprintf(buf + n, size - (size_t)n, "\n");
}

/* 0 when a shader compiled (is_shader) or a program linked; else 1 with
 * its info log in log[] and the object deleted. */
static int failed(GLuint obj, int is_shader, char *log, GLsizei size)
{
    GLint ok = 0;
    if (is_shader)
        glGetShaderiv(obj, GL_COMPILE_STATUS, &ok);
    else
        glGetProgramiv(obj, GL_LINK_STATUS, &ok);
    if (ok)
        return 0;
    log[0] = '\0';
    if (is_shader) {
        glGetShaderInfoLog(obj, size, NULL, log);
        glDeleteShader(obj);
    } else {
        glGetProgramInfoLog(obj, size, NULL, log);
        glDeleteProgram(obj);
    }
    return 1;
}

static vr_result compile(const char *name, GLenum stage, const char *src, GLuint *out,
                         vr_error *err)
{
    GLuint sh = glCreateShader(stage);
    if (!sh)
        return vr_fail(err, VR_ERR_GL, "%s: glCreateShader failed", name);
    glShaderSource(sh, 1, &src, NULL);
    glCompileShader(sh);
    char log[768];
    if (failed(sh, 1, log, sizeof log))
        return vr_fail(err, VR_ERR_SHADER, "%s: %s shader: %s", name,
                       stage == GL_VERTEX_SHADER    ? "vertex"
                       : stage == GL_COMPUTE_SHADER ? "compute"
                                                    : "fragment",
                       log);
    *out = sh;
    return VR_OK;
}

/* Compile the n stages and link them into *out. */
static vr_result link_stages(const char *name, int n, const GLenum *stages, const char *const *srcs,
                             GLuint *out, vr_error *err)
{
    GLuint sh[2] = {0, 0};
    vr_result r = VR_OK;
    for (int i = 0; i < n && r == VR_OK; i++)
        r = compile(name, stages[i], srcs[i], &sh[i], err);
    if (r != VR_OK) {
        for (int i = 0; i < n; i++)
            if (sh[i])
                glDeleteShader(sh[i]);
        return r;
    }
    GLuint p = glCreateProgram();
    for (int i = 0; i < n; i++)
        glAttachShader(p, sh[i]);
    glLinkProgram(p);
    /* The program keeps what it needs; the shaders can go now. */
    for (int i = 0; i < n; i++)
        glDeleteShader(sh[i]);
    char log[768];
    if (failed(p, 0, log, sizeof log))
        return vr_fail(err, VR_ERR_SHADER, "%s: link: %s", name, log);
    *out = p;
    return VR_OK;
}

vr_result vr_link(const char *name, const char *vs, const char *fs, GLuint *out, vr_error *err)
{
    const GLenum stages[2] = {GL_VERTEX_SHADER, GL_FRAGMENT_SHADER};
    const char *srcs[2] = {vs, fs};
    return link_stages(name, 2, stages, srcs, out, err);
}

vr_result vr_link_compute(const char *name, const char *src, GLuint *out, vr_error *err)
{
    const GLenum stage = GL_COMPUTE_SHADER;
    return link_stages(name, 1, &stage, &src, out, err);
}

/* The buffer path's factor table as GLSL: "const float KS[n] = ...". */
char *vr_ks_table(const float *ks, int n)
{
    size_t size = 64 + 18 * (size_t)n;
    char *t = malloc(size);
    if (!t)
        return NULL;
    int len = snprintf(t, size, "const float KS[%d] = float[%d](", n, n);
    for (int i = 0; i < n && len > 0 && (size_t)len < size; i++)
        len += snprintf(t + len, size - (size_t)len, "%s%.9e", i ? ", " : "", (double)ks[i]);
    if (len > 0 && (size_t)len < size)
        snprintf(t + len, size - (size_t)len, ");\n");
    return t;
}

vr_result vr_program_build(const vr_program_key *key, const float *ks, const char *cpca_unpack,
                           vr_program *out, vr_error *err)
{
    char name[224], defines[1024];
    key_name(key, name, sizeof name);
    /* The shaders implement the paths vdsh_runtime_interp chooses; should
     * it ever choose another, say so rather than draw something else. */
    int interp = vr_mode_interp((vr_mode)key->mode, key->quantity);
    int order = vr_mode_order((vr_mode)key->mode);
    if (interp >= 0 && interp != VDSH_INTERP_VISIBILITY && interp != VDSH_INTERP_DISTANCE &&
        !(interp == VDSH_INTERP_SPLIT && order == 5))
        return vr_fail(err, VR_ERR_SHADER, "%s: the runtime has no shaders for this path", name);
    int buffer = key->mode == VR_MODE_VDSH_BUFFER;
    if (buffer && (key->buf_order < 1 || key->buf_order > VDSH_MAX_ORDER || !ks))
        return vr_fail(err, VR_ERR_SHADER, "%s: no buffer order", name);
    /* a cpca stream with a width per vector brings its unpacking */
    if (buffer && key->buf_kind == VR_BUF_CPCA && !key->cpca_bits && !cpca_unpack)
        return vr_fail(err, VR_ERR_SHADER, "%s: cpca widths without their unpacking", name);
    if (!buffer || key->buf_kind != VR_BUF_CPCA || key->cpca_bits)
        cpca_unpack = "";
    GLint max_varying = 0;
    glGetIntegerv(GL_MAX_VARYING_COMPONENTS, &max_varying);
    int flat = varying_components(key, 1) <= max_varying;

    /* The buffer path's code goes between the vertex stage's
     * declarations and its main(), unless the stage reads sums that a
     * compute shader made (BUF_SUMS, vr_buffer_sums). */
    int coefs = buffer && !key->buf_sums;
    char *table = coefs ? vr_ks_table(ks, key->buf_order * key->buf_order) : NULL;
    size_t vs_size = sizeof defines + vr_glsl_common_size + vr_glsl_vertex_size +
                     (table ? strlen(table) : 0) + strlen(cpca_unpack) + vr_buffer_glsl_size +
                     vr_glsl_vertex_main_size;
    size_t fs_size =
        sizeof defines + vr_glsl_common_size + vr_sdf_glsl_size + vr_glsl_fragment_size;
    char *vs = malloc(vs_size), *fs = malloc(fs_size);
    if (!vs || !fs || (coefs && !table)) {
        free(vs);
        free(fs);
        free(table);
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
    }
    /* A driver that packs varyings less tightly than the component count
     * assumes may still refuse the flat constants: then read uniforms. */
    GLuint prog = 0;
    vr_result r;
    for (;; flat = 0) {
        key_defines(key, flat, defines, sizeof defines);
        snprintf(vs, vs_size, "%s%s%s%s%s%s%s", defines, vr_glsl_common, vr_glsl_vertex,
                 coefs ? table : "", cpca_unpack, coefs ? vr_buffer_glsl : "", vr_glsl_vertex_main);
        snprintf(fs, fs_size, "%s%s%s%s", defines, vr_glsl_common,
                 key->mode == VR_MODE_SDF ? vr_sdf_glsl : "", vr_glsl_fragment);
        r = vr_link(name, vs, fs, &prog, err);
        if (r != VR_ERR_SHADER || !flat)
            break;
    }
    free(vs);
    free(fs);
    free(table);
    if (r != VR_OK)
        return r;

    vr_program p = {.key = *key, .prog = prog};
    p.u_view_proj = glGetUniformLocation(prog, "u_view_proj");
    p.u_scale = glGetUniformLocation(prog, "u_scale");
    p.u_coef_step = glGetUniformLocation(prog, "u_coef_step");
    p.u_max_distance = glGetUniformLocation(prog, "u_max_distance");
    p.u_light_pos = glGetUniformLocation(prog, "u_light_pos");
    p.u_light_color = glGetUniformLocation(prog, "u_light_color");
    p.u_light_att = glGetUniformLocation(prog, "u_light_att");
    p.u_ambient = glGetUniformLocation(prog, "u_ambient");
    p.u_shadow_nf = glGetUniformLocation(prog, "u_shadow_nf");
    p.u_shadow_texel = glGetUniformLocation(prog, "u_shadow_texel");
    p.u_sums_stride = glGetUniformLocation(prog, "u_sums_stride");
    p.u_sums_first = glGetUniformLocation(prog, "u_sums_first");

    /* Samplers never change unit: set them once. */
    glUseProgram(prog);
    GLint basis = glGetUniformLocation(prog, "u_basis");
    if (basis >= 0) {
        const GLint units[4] = {VR_UNIT_BASIS, VR_UNIT_BASIS + 1, VR_UNIT_BASIS + 2,
                                VR_UNIT_BASIS + 3};
        glUniform1iv(basis, 4, units);
    }
    GLint coef = glGetUniformLocation(prog, "u_coef");
    if (coef >= 0)
        glUniform1i(coef, VR_UNIT_COEF);
    GLint model = glGetUniformLocation(prog, "u_model");
    if (model >= 0)
        glUniform1i(model, VR_UNIT_MODEL);
    GLint sums = glGetUniformLocation(prog, "u_sums");
    if (sums >= 0)
        glUniform1i(sums, VR_UNIT_SUMS);
    GLint shadow = glGetUniformLocation(prog, "u_shadow");
    if (shadow >= 0) {
        GLint units[VR_MAX_LIGHTS_PER_PASS];
        for (int i = 0; i < VR_MAX_LIGHTS_PER_PASS; i++)
            units[i] = VR_UNIT_SHADOW + i;
        glUniform1iv(shadow, key->lights, units);
    }
    glUseProgram(0);
    r = vr_check_gl(err, name);
    if (r != VR_OK) {
        glDeleteProgram(prog);
        return r;
    }
    *out = p;
    return VR_OK;
}

vr_result vr_program_build_depth(GLuint *out, vr_error *err)
{
    static const char version[] = "#version 330 core\n";
    char vs[sizeof version + 512], fs[sizeof version + 256];
    if (vr_glsl_depth_vs_size > sizeof vs - sizeof version ||
        vr_glsl_depth_fs_size > sizeof fs - sizeof version)
        return vr_fail(err, VR_ERR_SHADER, "the depth program's source is too long");
    snprintf(vs, sizeof vs, "%s%s", version, vr_glsl_depth_vs);
    snprintf(fs, sizeof fs, "%s%s", version, vr_glsl_depth_fs);
    return vr_link("cube shadow map depth program", vs, fs, out, err);
}
