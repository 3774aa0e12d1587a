/*
 * test_runtime_shaders.c - the GLSL files of runtime/shaders/ as the
 * runtime has them (cmake/embed_glsl.cmake), without GL:
 *
 *   embed     every embedded string is its file, byte for byte (quotes,
 *             backslashes and line ends survive the C escaping);
 *   numbers   vdsh_common.glsl's constants are the C definition's: each SH
 *             constant, the ramp's slope and offset and the log-sum limit
 *             appear in the GLSL written exactly as formats/vdsh_sh.h and
 *             formats/vdsh_shadow.h define them, so a changed header fails
 *             here instead of drawing other shadows than vdsh-eval scores;
 *   interface the functions shaders/README.md documents for other engines
 *             are there with its signatures.
 * Usage: test_runtime_shaders SHADER_DIR
 */
#include "test_util.h"

#include "vdsh_sh.h"
#include "vdsh_shadow.h"
#include "vr_glsl_files.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define STR_(x) #x
#define STR(x) STR_(x)

static char *slurp(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *buf = NULL;
    long n = -1;
    if (fseek(f, 0, SEEK_END) == 0 && (n = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0) {
        buf = malloc((size_t)n + 1);
        if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
            free(buf);
            buf = NULL;
        }
    }
    fclose(f);
    if (buf) {
        buf[n] = 0;
        *size = (size_t)n;
    }
    return buf;
}

static void check_embed(const char *dir, const char *file, const char *text, size_t size)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, file);
    size_t n = 0;
    char *disk = slurp(path, &n);
    CHECK(disk != NULL, "cannot read %s", path);
    if (!disk)
        return;
    CHECK(size == n + 1 && memcmp(disk, text, n) == 0 && text[n] == 0,
          "%s: the embedded string (%zu bytes) is not the file (%zu bytes)", file, size - 1, n);
    free(disk);
}

static void check_has(const char *what, const char *text, const char *needle)
{
    CHECK(strstr(text, needle) != NULL, "%s lacks '%s'", what, needle);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_runtime_shaders SHADER_DIR\n");
        return 2;
    }
    const char *dir = argv[1];
    check_embed(dir, "vdsh_common.glsl", vr_glsl_common, vr_glsl_common_size);
    check_embed(dir, "vdsh_buffer.glsl", vr_buffer_glsl, vr_buffer_glsl_size);
    check_embed(dir, "vr_vertex.glsl", vr_glsl_vertex, vr_glsl_vertex_size);
    check_embed(dir, "vr_vertex_main.glsl", vr_glsl_vertex_main, vr_glsl_vertex_main_size);
    check_embed(dir, "vr_fragment.glsl", vr_glsl_fragment, vr_glsl_fragment_size);
    check_embed(dir, "vr_depth.vert.glsl", vr_glsl_depth_vs, vr_glsl_depth_vs_size);
    check_embed(dir, "vr_depth.frag.glsl", vr_glsl_depth_fs, vr_glsl_depth_fs_size);
    check_embed(dir, "vr_sdf.glsl", vr_sdf_glsl, vr_sdf_glsl_size);
    check_embed(dir, "vdsh_cpca_decode.glsl", vr_cpca_decode_glsl, vr_cpca_decode_glsl_size);
    check_embed(dir, "vr_sums.glsl", vr_sums_glsl, vr_sums_glsl_size);
    check_embed(dir, "vr_sums_main.glsl", vr_sums_main_glsl, vr_sums_main_glsl_size);
    check_embed(dir, "vr_cull.glsl", vr_cull_glsl, vr_cull_glsl_size);

    /* The C definition's numbers, as the headers write them. */
    static const char *const consts[][2] = {
        {"C00", STR(VDSH_SH_C00)},   {"C1", STR(VDSH_SH_C1)},     {"C2A", STR(VDSH_SH_C2A)},
        {"C20", STR(VDSH_SH_C20)},   {"C22", STR(VDSH_SH_C22)},   {"C33", STR(VDSH_SH_C33)},
        {"C32", STR(VDSH_SH_C32)},   {"C31", STR(VDSH_SH_C31)},   {"C30", STR(VDSH_SH_C30)},
        {"C32B", STR(VDSH_SH_C32B)}, {"C44", STR(VDSH_SH_C44)},   {"C43", STR(VDSH_SH_C43)},
        {"C42", STR(VDSH_SH_C42)},   {"C41", STR(VDSH_SH_C41)},   {"C40", STR(VDSH_SH_C40)},
        {"C42B", STR(VDSH_SH_C42B)}, {"C44B", STR(VDSH_SH_C44B)},
    };
    for (size_t i = 0; i < sizeof consts / sizeof consts[0]; i++) {
        char want[128];
        snprintf(want, sizeof want, "const float %s = %s;\n", consts[i][0], consts[i][1]);
        check_has("vdsh_common.glsl", vr_glsl_common, want);
    }
    check_has("vdsh_common.glsl", vr_glsl_common, "exp(min(sum, " STR(VDSH_LOG_SUM_MAX) "))");
    check_has("vdsh_common.glsl", vr_glsl_common,
              "clamp(" STR(VDSH_RAMP_SLOPE) " * (dv / dl) - " STR(VDSH_RAMP_OFFSET) ", 0.0, 1.0)");

    /* The documented interface (shaders/README.md). */
    check_has("vdsh_common.glsl", vr_glsl_common, "float vdsh_distance(float sum, float md)\n");
    check_has("vdsh_common.glsl", vr_glsl_common, "float vdsh_compare(float dv, float dl)\n");
    check_has("vdsh_common.glsl", vr_glsl_common,
              "float vdsh_shadow(float sum, float md, float dl)\n");
    check_has("vdsh_common.glsl", vr_glsl_common, "float vdsh_sh_sum25(vec4 g[7], vec3 d)\n");
    check_has("vdsh_buffer.glsl", vr_buffer_glsl, "void buffer_sums(out float sums[NUM_LIGHTS])\n");
    /* No #version line: the includer writes it (330 core or 300 es). */
    CHECK(strncmp(vr_glsl_common, "#version", 8) != 0 && !strstr(vr_glsl_common, "\n#version") &&
              strncmp(vr_buffer_glsl, "#version", 8) != 0 && !strstr(vr_buffer_glsl, "\n#version"),
          "a shared file holds a #version line");

    if (test_failures)
        fprintf(stderr, "%d checks failed\n", test_failures);
    else
        printf("runtime shaders: 11 files embedded as they are, the C constants, the interface\n");
    return test_failures ? 1 : 0;
}
