/*
 * test_runtime_shaders_standalone.c - the shader files as another engine
 * uses them (runtime/shaders/README.md): read from the folder given (the
 * source tree's, or an installed share/vdsh/shaders), not the strings the
 * runtime embeds, and compiled as GLSL 3.30 with the includer's #defines
 * and declarations the README lists, nothing of the C runtime's:
 *
 *   - the order-5 vertex stage of the README (vdsh_common.glsl, the glb's
 *     seven attribute groups, vdsh_sh_sum25 and vdsh_distance), linked
 *     with a fragment stage that calls vdsh_compare;
 *   - the buffer path (vdsh_buffer.glsl), a record per vertex
 *     (BUF_VARIABLE 1) and a record every BUF_STRIDE texels
 *     (BUF_VARIABLE 0, the README's second recipe);
 *   - a buffer path that leaves out BUF_STRIDE, or BUF_KIND, fails with a
 *     message naming what is missing (it failed at the first line that
 *     used it: "`BUF_STRIDE' undeclared ... no matching function for call
 *     to `buf_begin(error)'", and the README did not list BUF_STRIDE).
 *
 * Usage: test_runtime_shaders_standalone SHADER_DIR. Exit 77 without EGL.
 */
#include "test_runtime_util.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

static char *slurp(const char *dir, const char *name)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *fp = fopen(path, "rb");
    CHECK(fp, "%s: cannot open", path);
    if (!fp)
        exit(1);
    fseek(fp, 0, SEEK_END);
    long n = ftell(fp);
    rewind(fp);
    char *s = calloc((size_t)n + 1, 1);
    CHECK(s && fread(s, 1, (size_t)n, fp) == (size_t)n, "%s: cannot read", path);
    fclose(fp);
    return s;
}

/* Compile the parts as one shader; its info log in `log`. */
static GLuint compile(GLenum kind, const char *const *parts, int n, char *log, size_t size)
{
    GLuint s = glCreateShader(kind);
    glShaderSource(s, n, parts, NULL);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    log[0] = 0;
    glGetShaderInfoLog(s, (GLsizei)size, NULL, log);
    if (!ok) {
        glDeleteShader(s);
        return 0;
    }
    return s;
}

static const char head5[] = "#version 330 core\n#define QUANTITY 2\n#define COMPARE 0\n";
static const char vs5[] =
    "#define N 2\n"
    "in vec3 position;\n"
    "in vec4 vdsh0, vdsh1, vdsh2, vdsh3, vdsh4, vdsh5, vdsh6;\n"
    "uniform float u_scale, u_max_distance;\n"
    "uniform vec3 u_light_pos[N];\n"
    "out float v_dist[N];\n"
    "out vec3 v_p;\n"
    "void main() {\n"
    "    vec4 g[7] = vec4[7](vdsh0, vdsh1, vdsh2, vdsh3, vdsh4, vdsh5, vdsh6);\n"
    "    for (int i = 0; i < N; i++) {\n"
    "        vec3 lv = u_light_pos[i] - position;\n"
    "        float dl = length(lv);\n"
    "        v_dist[i] = dl > 0.0 ? vdsh_distance(u_scale * vdsh_sh_sum25(g, lv / dl), "
    "u_max_distance) : 0.0;\n"
    "    }\n"
    "    v_p = position;\n"
    "    gl_Position = vec4(position, 1.0);\n"
    "}\n";
static const char fs5[] = "#define N 2\n"
                          "in float v_dist[N];\n"
                          "in vec3 v_p;\n"
                          "uniform vec3 u_light_pos[N];\n"
                          "out vec4 o_color;\n"
                          "void main() {\n"
                          "    float s = 0.0;\n"
                          "    for (int i = 0; i < N; i++)\n"
                          "        s += vdsh_compare(v_dist[i], length(u_light_pos[i] - v_p));\n"
                          "    o_color = vec4(s / float(N));\n"
                          "}\n";

/* The buffer recipe: the README's #defines, less those `drop` names. */
static void buffer_head(char *out, size_t size, int variable, const char *drop)
{
    static const char *const lines[] = {
        "#define QUANTITY 2\n",   "#define COMPARE 0\n",   "#define BUFFER 1\n",
        "#define NUM_LIGHTS 2\n", "#define BUF_ORDER 3\n", "#define BUF_KIND 0\n",
        NULL /* BUF_VARIABLE */,  NULL /* BUF_STRIDE */,
    };
    size_t n = (size_t)snprintf(out, size, "#version 330 core\n");
    for (size_t i = 0; i < sizeof lines / sizeof lines[0]; i++) {
        char line[64];
        if (i == 6)
            snprintf(line, sizeof line, "#define BUF_VARIABLE %d\n", variable);
        else if (i == 7)
            snprintf(line, sizeof line, "%s", variable ? "" : "#define BUF_STRIDE 3\n");
        else
            snprintf(line, sizeof line, "%s", lines[i]);
        if (drop && strstr(line, drop))
            continue;
        n += (size_t)snprintf(out + n, size - n, "%s", line);
    }
    snprintf(out + n, size - n,
             "in vec3 a_position;\n"
             "uniform vec3 u_light_pos[2];\n"
             "uniform float u_scale, u_max_distance;\n"
             "const float KS[9] = float[9](1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0);\n");
}

static const char vs_buffer[] = "out float v_dist[NUM_LIGHTS];\n"
                                "void main() {\n"
                                "    float sums[NUM_LIGHTS];\n"
                                "    buffer_sums(sums);\n"
                                "    for (int i = 0; i < NUM_LIGHTS; i++)\n"
                                "        v_dist[i] = vdsh_distance(sums[i], u_max_distance);\n"
                                "    gl_Position = vec4(a_position, 1.0);\n"
                                "}\n";

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_runtime_shaders_standalone SHADER_DIR\n");
        return 2;
    }
    vr_context *ctx = rt_context_or_skip("test_runtime_shaders_standalone");
    char *common = slurp(argv[1], "vdsh_common.glsl");
    char *buffer = slurp(argv[1], "vdsh_buffer.glsl");
    char log[8192];

    /* The order-5 recipe, both stages, linked. */
    const char *v[] = {head5, common, vs5};
    const char *f[] = {head5, common, fs5};
    GLuint vs = compile(GL_VERTEX_SHADER, v, 3, log, sizeof log);
    CHECK(vs, "order-5 vertex recipe does not compile:\n%s", log);
    GLuint fs = compile(GL_FRAGMENT_SHADER, f, 3, log, sizeof log);
    CHECK(fs, "fragment recipe (vdsh_compare) does not compile:\n%s", log);
    if (vs && fs) {
        GLuint p = glCreateProgram();
        glAttachShader(p, vs);
        glAttachShader(p, fs);
        glLinkProgram(p);
        GLint ok = 0;
        glGetProgramiv(p, GL_LINK_STATUS, &ok);
        glGetProgramInfoLog(p, sizeof log, NULL, log);
        CHECK(ok, "order-5 recipe does not link:\n%s", log);
        glDeleteProgram(p);
        printf("order-5 recipe (vdsh_common.glsl): compiles and links\n");
    }

    /* The buffer path, both record layouts. */
    char head[1024];
    for (int variable = 1; variable >= 0; variable--) {
        buffer_head(head, sizeof head, variable, NULL);
        const char *b[] = {head, common, buffer, vs_buffer};
        GLuint s = compile(GL_VERTEX_SHADER, b, 4, log, sizeof log);
        CHECK(s, "buffer recipe, BUF_VARIABLE %d, does not compile:\n%s", variable, log);
        printf("buffer recipe, BUF_VARIABLE %d: %s\n", variable, s ? "compiles" : "FAILS");
        if (s)
            glDeleteShader(s);
    }

    /* Left out: the message names what is missing. */
    static const struct {
        int variable;
        const char *drop, *needle;
    } missing[] = {{0, "BUF_STRIDE", "BUF_STRIDE"}, {1, "BUF_KIND", "BUF_KIND"}};
    for (size_t i = 0; i < sizeof missing / sizeof missing[0]; i++) {
        buffer_head(head, sizeof head, missing[i].variable, missing[i].drop);
        const char *b[] = {head, common, buffer, vs_buffer};
        GLuint s = compile(GL_VERTEX_SHADER, b, 4, log, sizeof log);
        CHECK(!s, "buffer recipe without %s compiles", missing[i].drop);
        CHECK(strstr(log, "vdsh_buffer.glsl") && strstr(log, missing[i].needle),
              "buffer recipe without %s: the log does not name it:\n%s", missing[i].drop, log);
        printf("buffer recipe without %s: %s", missing[i].drop, log);
        if (s)
            glDeleteShader(s);
    }
    if (vs)
        glDeleteShader(vs);
    if (fs)
        glDeleteShader(fs);
    free(common);
    free(buffer);
    vr_context_destroy(ctx);
    return test_failures ? 1 : 0;
}
