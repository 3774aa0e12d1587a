/*
 * compute_probe FILE.vdsh [REPS]: the order-12 work of issue 29's frame
 * done in compute shaders (GL 4.3), timed and checked; measurement for
 * the runtime's next decomposition (docs/BENCHMARKS.md "On a GPU: NVIDIA
 * H200"), not a runtime path.
 * - sums: FILE's order-12 stream decoded in C (any encoding, cpca too),
 *   K_l^m folded into the coefficients, uploaded as f32 (shader storage);
 *   one invocation per (vertex, light) sums the 144 coefficients toward
 *   its light by vdsh_buffer.glsl's recurrence, for 1, 16 and 64 lights
 *   placed in the bounds. Checked against vdsh_sh_eval in C on every 97th
 *   vertex and all 16 lights: relative difference at most 1e-4.
 * - decode: a cpca-shaped decode of every vertex, one invocation per
 *   (vertex, texel of four coefficients): mean + sum_j w_j basis_j of its
 *   cluster, the model in shader storage (16 clusters, 48 vectors, 36
 *   texels; seeded weights and model, the clusters contiguous or
 *   scattered). Checked against the same sums in C on every 97th vertex.
 * Prints the renderer and, per step, the least wall time (dispatch to
 * glFinish) and GL_TIME_ELAPSED over REPS dispatches (default 20).
 * Exit 77 without GL 4.3 or its compute and storage-buffer extensions
 * (no display, or an older GL), 1 on a
 * read error or a check that fails, 2 on bad usage.
 */
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "vdsh.h"
#include "vdsh_sh.h"
#include "vr_context.h"

enum { ORDER = 12, N = ORDER * ORDER, MAX_LIGHTS = 64, K = 16, B = 48, T = N / 4 };

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Exit 1 with the log when the shader or program did not build. */
static void built(GLuint obj, int is_program)
{
    GLint ok = 0;
    char log[4096];
    (is_program ? glGetProgramiv
                : glGetShaderiv)(obj, is_program ? GL_LINK_STATUS : GL_COMPILE_STATUS, &ok);
    if (ok)
        return;
    (is_program ? glGetProgramInfoLog : glGetShaderInfoLog)(obj, sizeof log, NULL, log);
    fprintf(stderr, "compute_probe: %s: %s\n", is_program ? "link" : "compile", log);
    exit(1);
}

static GLuint program(const char *src)
{
    GLuint s = glCreateShader(GL_COMPUTE_SHADER), p = glCreateProgram();
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    built(s, 0);
    glAttachShader(p, s);
    glLinkProgram(p);
    built(p, 1);
    glDeleteShader(s);
    return p;
}

/* One invocation per (vertex, light): vdsh_buffer.glsl's recurrence for
 * one light, the K_l^m in the coefficients. */
static const char *SUMS_GLSL =
    "#version 430\n"
    "layout(local_size_x = 64) in;\n"
    "layout(std430, binding = 0) readonly buffer C { float coef[]; };\n"
    "layout(std430, binding = 1) readonly buffer P { float pos[]; };\n"
    "layout(std430, binding = 2) writeonly buffer S { float sums[]; };\n"
    "uniform int u_n;\n"
    "uniform int u_lights;\n"
    "uniform vec3 u_light[64];\n"
    "void main()\n"
    "{\n"
    "    int id = int(gl_GlobalInvocationID.x), v = id / u_lights, i = id - v * u_lights;\n"
    "    if (v >= u_n)\n"
    "        return;\n"
    "    vec3 lv = u_light[i] - vec3(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]);\n"
    "    float dl = length(lv);\n"
    "    vec3 d = dl > 0.0 ? lv / dl : vec3(0.0, 0.0, 1.0);\n"
    "    float cs = 1.0, sn = 0.0, pmm = 1.0, sum = 0.0;\n"
    "    int base = v * 144;\n"
    "    for (int m = 0; m < 12; m++) {\n"
    "        if (m > 0) {\n"
    "            float c = d.x * cs - d.y * sn;\n"
    "            sn = d.x * sn + d.y * cs;\n"
    "            cs = c;\n"
    "            pmm *= -float(2 * m - 1);\n"
    "        }\n"
    "        float p0 = 0.0, p1 = 0.0;\n"
    "        for (int l = m; l < 12; l++) {\n"
    "            int row = l * (l + 1);\n"
    "            float cp = coef[base + row + m], cn = m > 0 ? coef[base + row - m] : 0.0;\n"
    "            float a = float(2 * l - 1) / float(max(l - m, 1));\n"
    "            float b = float(l + m - 1) / float(max(l - m, 1));\n"
    "            float pl = l == m ? pmm : l == m + 1 ? d.z * float(2 * m + 1) * pmm\n"
    "                                                : a * d.z * p1 - b * p0;\n"
    "            p0 = p1;\n"
    "            p1 = pl;\n"
    "            sum += pl * (cp * cs + cn * sn);\n"
    "        }\n"
    "    }\n"
    "    sums[id] = sum;\n"
    "}\n";

/* One invocation per (vertex, texel): mean + sum_j w_j basis_j. */
static const char *DECODE_GLSL =
    "#version 430\n"
    "layout(local_size_x = 64) in;\n"
    "layout(std430, binding = 0) readonly buffer W { float wts[]; };\n"
    "layout(std430, binding = 1) readonly buffer M { vec4 model[]; };\n"
    "layout(std430, binding = 2) readonly buffer L { int cl[]; };\n"
    "layout(std430, binding = 3) writeonly buffer O { vec4 outc[]; };\n"
    "uniform int u_n;\n"
    "void main()\n"
    "{\n"
    "    int id = int(gl_GlobalInvocationID.x), v = id / 36, t = id - v * 36;\n"
    "    if (v >= u_n)\n"
    "        return;\n"
    "    int m = (cl[v] * 36 + t) * 49;\n"
    "    vec4 a = model[m];\n"
    "    for (int j = 0; j < 48; j++)\n"
    "        a += wts[v * 48 + j] * model[m + 1 + j];\n"
    "    outc[id] = a;\n"
    "}\n";

/* The least wall and GPU time of reps dispatches of groups x 64. */
static void time_dispatch(GLuint prog, GLuint groups, int reps, const char *what)
{
    GLuint q;
    glGenQueries(1, &q);
    glUseProgram(prog);
    glDispatchCompute(groups, 1, 1); /* warm-up */
    glFinish();
    double wall = INFINITY, gpu = INFINITY;
    for (int r = 0; r < reps; r++) {
        double t0 = now();
        glBeginQuery(GL_TIME_ELAPSED, q);
        glDispatchCompute(groups, 1, 1);
        glEndQuery(GL_TIME_ELAPSED);
        glFinish();
        double t1 = now();
        GLuint64 ns = 0;
        glGetQueryObjectui64v(q, GL_QUERY_RESULT, &ns);
        wall = fmin(wall, t1 - t0);
        gpu = fmin(gpu, 1e-9 * (double)ns);
    }
    glDeleteQueries(1, &q);
    printf("%-48s wall %8.3f ms  gpu %8.3f ms\n", what, 1e3 * wall, 1e3 * gpu);
}

static GLuint storage(GLuint binding, size_t bytes, const void *data)
{
    GLuint b;
    glGenBuffers(1, &b);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, b);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)bytes, data,
                 data ? GL_STATIC_DRAW : GL_DYNAMIC_COPY);
    return b;
}

static void read_back(GLuint b, size_t bytes, void *out)
{
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, b);
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)bytes, out);
}

/* K_l^|m| (times sqrt 2 for m != 0) per coefficient index l(l+1)+m. */
static void normalisations(double ks[N])
{
    for (int l = 0; l < ORDER; l++)
        for (int m = -l; m <= l; m++) {
            int am = abs(m);
            double ratio = 1.0; /* (l - |m|)! / (l + |m|)! */
            for (int q = l - am + 1; q <= l + am; q++)
                ratio /= q;
            ks[l * (l + 1) + m] =
                sqrt((2 * l + 1) / (4.0 * 3.14159265358979323846) * ratio) * (m ? sqrt(2.0) : 1.0);
        }
}

/* Sums toward 1, 16 and 64 lights; 0 when the check fails. */
static int probe_sums(const vdsh_file *f, const float *c, int reps)
{
    const uint32_t n = f->header.vertex_count;
    double ks[N];
    normalisations(ks);
    float *cg = malloc((size_t)n * N * sizeof *cg), *gs = malloc((size_t)n * 16 * sizeof *gs);
    if (!cg || !gs) {
        fprintf(stderr, "compute_probe: out of memory\n");
        exit(1);
    }
    for (size_t x = 0; x < (size_t)n * N; x++)
        cg[x] = (float)(c[x] * ks[x % N]);
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t v = 0; v < n; v++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fminf(lo[k], f->positions[3 * v + k]);
            hi[k] = fmaxf(hi[k], f->positions[3 * v + k]);
        }
    float lights[MAX_LIGHTS * 3]; /* spread over the middle 60% of the bounds */
    for (int i = 0; i < MAX_LIGHTS; i++)
        for (int k = 0; k < 3; k++)
            lights[3 * i + k] =
                lo[k] + (hi[k] - lo[k]) * (0.2f + 0.6f * (float)((i * 7 + k * 13) % 17) / 16.0f);
    GLuint bc = storage(0, (size_t)n * N * sizeof *cg, cg);
    GLuint bp = storage(1, (size_t)n * 3 * sizeof(float), f->positions);
    GLuint bs = storage(2, (size_t)n * MAX_LIGHTS * sizeof(float), NULL);
    GLuint prog = program(SUMS_GLSL);
    glUseProgram(prog);
    glUniform3fv(glGetUniformLocation(prog, "u_light"), MAX_LIGHTS, lights);
    glUniform1i(glGetUniformLocation(prog, "u_n"), (GLint)n);
    const int counts[3] = {1, 16, 64};
    for (int a = 0; a < 3; a++) {
        char what[64];
        snprintf(what, sizeof what, "sums of order 12 per (vertex, light), %d light%s", counts[a],
                 counts[a] > 1 ? "s" : "");
        glUseProgram(prog);
        glUniform1i(glGetUniformLocation(prog, "u_lights"), counts[a]);
        time_dispatch(prog, (GLuint)(((size_t)n * (size_t)counts[a] + 63) / 64), reps, what);
    }
    glUniform1i(glGetUniformLocation(prog, "u_lights"), 16);
    glDispatchCompute((GLuint)(((size_t)n * 16 + 63) / 64), 1, 1);
    read_back(bs, (size_t)n * 16 * sizeof *gs, gs);
    double worst = 0.0;
    for (uint32_t v = 0; v < n; v += 97)
        for (int i = 0; i < 16; i++) {
            float d[3], y[N];
            double r = 0.0, s = 0.0;
            for (int k = 0; k < 3; k++) {
                d[k] = lights[3 * i + k] - f->positions[3 * v + k];
                r += (double)d[k] * d[k];
            }
            r = sqrt(r);
            for (int k = 0; k < 3; k++)
                d[k] = (float)(d[k] / r);
            vdsh_sh_eval(ORDER, d, y);
            for (int q = 0; q < N; q++)
                s += (double)y[q] * c[(size_t)v * N + q];
            worst = fmax(worst, fabs(s - gs[(size_t)v * 16 + i]) / (1.0 + fabs(s)));
        }
    printf("sums against vdsh_sh_eval (every 97th vertex, 16 lights): worst relative %.2e\n",
           worst);
    glDeleteProgram(prog);
    GLuint bufs[3] = {bc, bp, bs};
    glDeleteBuffers(3, bufs);
    free(cg);
    free(gs);
    return worst <= 1e-4;
}

/* The cpca-shaped decode, clusters contiguous then scattered; 0 when
 * the check fails. */
static int probe_decode(uint32_t n, int reps)
{
    const size_t model_floats = (size_t)K * T * (B + 1) * 4;
    float *w = malloc((size_t)n * B * sizeof *w), *model = malloc(model_floats * sizeof *model);
    float *out = malloc((size_t)n * T * 4 * sizeof *out);
    int *cl = malloc((size_t)n * sizeof *cl);
    if (!w || !model || !out || !cl) {
        fprintf(stderr, "compute_probe: out of memory\n");
        exit(1);
    }
    for (size_t x = 0; x < (size_t)n * B; x++)
        w[x] = (float)((x * 2654435761u) % 1000u) / 1000.0f - 0.5f;
    for (size_t x = 0; x < model_floats; x++)
        model[x] = (float)((x * 40503u) % 997u) / 997.0f;
    GLuint bw = storage(0, (size_t)n * B * sizeof *w, w);
    GLuint bm = storage(1, model_floats * sizeof *model, model);
    GLuint bo = storage(3, (size_t)n * T * 4 * sizeof *out, NULL);
    GLuint prog = program(DECODE_GLSL), bl = 0;
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_n"), (GLint)n);
    double worst = 0.0;
    for (int scattered = 0; scattered < 2; scattered++) {
        for (uint32_t v = 0; v < n; v++)
            cl[v] = scattered ? (int)((v * 2654435761u) >> 28) : (int)((uint64_t)v * K / n);
        if (bl)
            glDeleteBuffers(1, &bl);
        bl = storage(2, (size_t)n * sizeof *cl, cl);
        time_dispatch(prog, (GLuint)(((size_t)n * T + 63) / 64), reps,
                      scattered ? "cpca decode per (vertex, texel), clusters scattered"
                                : "cpca decode per (vertex, texel), clusters contiguous");
        read_back(bo, (size_t)n * T * 4 * sizeof *out, out);
        for (uint32_t v = 0; v < n; v += 97)
            for (int t = 0; t < T; t++)
                for (int k = 0; k < 4; k++) {
                    const float *m = model + ((size_t)(cl[v] * T + t) * (B + 1)) * 4 + k;
                    double s = m[0];
                    for (int j = 0; j < B; j++)
                        s += (double)w[(size_t)v * B + j] * m[4 * (j + 1)];
                    worst =
                        fmax(worst, fabs(s - out[((size_t)v * T + t) * 4 + k]) / (1.0 + fabs(s)));
                }
    }
    printf("decode against C (every 97th vertex): worst relative %.2e\n", worst);
    glDeleteProgram(prog);
    GLuint bufs[4] = {bw, bm, bo, bl};
    glDeleteBuffers(4, bufs);
    free(w);
    free(model);
    free(out);
    free(cl);
    return worst <= 1e-4;
}

/* Whether the context names extension e (NVIDIA's 3.3 core context has
 * compute shaders as extensions). */
static int has_extension(const char *e)
{
    GLint n = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &n);
    for (GLint i = 0; i < n; i++)
        if (!strcmp((const char *)glGetStringi(GL_EXTENSIONS, (GLuint)i), e))
            return 1;
    return 0;
}

int main(int argc, char **argv)
{
    int reps = argc == 3 ? atoi(argv[2]) : 20;
    if (argc < 2 || argc > 3 || reps < 1 || reps > 10000) {
        fprintf(stderr, "usage: compute_probe FILE.vdsh [REPS 1..10000]\n");
        return 2;
    }
    vdsh_file *f = NULL;
    vdsh_error err;
    if (vdsh_read(argv[1], &f, &err) != VDSH_OK) {
        fprintf(stderr, "compute_probe: %s\n", err.msg);
        return 1;
    }
    const vdsh_stream *st = NULL;
    for (uint32_t k = 0; k < f->stream_count; k++)
        if (f->streams[k].order == ORDER && !f->streams[k].orders)
            st = &f->streams[k];
    if (!st) {
        fprintf(stderr, "compute_probe: %s: no fixed order-12 stream\n", argv[1]);
        vdsh_free(f);
        return 1;
    }
    vr_context *ctx = NULL;
    vr_context_desc cd;
    vr_error verr;
    memset(&cd, 0, sizeof cd);
    if (vr_context_create(&cd, &ctx, &verr) != VR_OK) {
        printf("compute_probe: no GL context (%s): skipped\n", verr.msg);
        vdsh_free(f);
        return 77;
    }
    GLint major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    printf("%s, GL %d.%d, %s\n", (const char *)glGetString(GL_RENDERER), major, minor,
           vr_context_description(ctx));
    if ((major < 4 || (major == 4 && minor < 3)) &&
        !(has_extension("GL_ARB_compute_shader") &&
          has_extension("GL_ARB_shader_storage_buffer_object"))) {
        printf("compute_probe: compute shaders need GL 4.3: skipped\n");
        vr_context_destroy(ctx);
        vdsh_free(f);
        return 77;
    }
    const uint32_t n = f->header.vertex_count;
    float *c = malloc((size_t)n * N * sizeof *c);
    if (!c) {
        fprintf(stderr, "compute_probe: out of memory\n");
        return 1;
    }
    for (uint32_t v = 0; v < n; v++)
        vdsh_stream_decode(st, v, c + (size_t)v * N);
    printf("%s: %u vertices\n", argv[1], n);
    int ok = probe_sums(f, c, reps);
    ok = probe_decode(n, reps) && ok;
    vr_context_destroy(ctx);
    free(c);
    vdsh_free(f);
    return ok ? 0 : 1;
}
