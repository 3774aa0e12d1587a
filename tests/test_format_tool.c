/*
 * test_format_tool.c - helpers for the vdsh-info tests in formats.cmake.
 *
 *   test_format_tool make DIR
 *       write the fixtures: good.vdsh (two sources, order 5 f16, order 3
 *       f32, stat and time chunks), corrupt.vdsh (one payload byte changed),
 *       truncated.vdsh (cut in a chunk), text.vdsh (not a .vdsh at all),
 *       volume.sdf and scene.glb (the first bytes of a distance volume and
 *       of a binary glTF: files the tools write, not .vdsh files)
 *   test_format_tool clean DIR
 *       remove what `make` wrote
 *   test_format_tool expect CODE [--out TEXT]... [--err TEXT]... -- PROG ARG...
 *       run PROG, fail unless it exits with CODE and its stdout / stderr
 *       contain every TEXT given
 *
 * CTest's WILL_FAIL only knows "non-zero"; the tool's contract is 1 for a
 * bad file and 2 for bad usage, so the exit code is checked exactly here.
 */
#include "vdsh.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

enum { V = 40, T = 60 };

static int write_fixtures(const char *dir)
{
    static float pos[3 * V], nrm[3 * V];
    static uint32_t idx[3 * T];
    static uint16_t c5[V * 25];
    static float c3[V * 9];
    vdsh_source src[2];
    vdsh_stream st[2];
    vdsh_file f;
    vdsh_error err;
    char path[4096];

    memset(&f, 0, sizeof f);
    memset(src, 0, sizeof src);
    memset(st, 0, sizeof st);
    for (int v = 0; v < V; v++) {
        double a = 0.3 * v;
        pos[3 * v + 0] = (float)cos(a) * 2.0f;
        pos[3 * v + 1] = (float)(v % 7) * 0.5f;
        pos[3 * v + 2] = (float)sin(a) * 2.0f;
        nrm[3 * v + 0] = (float)-cos(a);
        nrm[3 * v + 1] = 0.0f;
        nrm[3 * v + 2] = (float)-sin(a);
        for (int i = 0; i < 25; i++)
            c5[25 * v + i] =
                vdsh_f16_from_f32(i == 0 ? 0.5f + 0.01f * (float)v : 0.001f * (float)(i - v));
        for (int i = 0; i < 9; i++)
            c3[9 * v + i] = i == 0 ? 7.5f + 0.1f * (float)v : 0.01f * (float)i;
    }
    for (int t = 0; t < 3 * T; t++)
        idx[t] = (uint32_t)((t * 7 + t / 3) % V);

    f.header.vertex_count = V;
    f.header.triangle_count = T;
    f.header.rays = 2500;
    f.header.sampling = VDSH_SAMPLING_SPHERE;
    f.header.seed = 1;
    f.header.max_distance = 15.0f;
    f.header.max_edge = 0.2f;
    f.header.offset_rule = VDSH_OFFSET_WB_AVG;
    f.header.load_flags = VDSH_LOAD_WELD;
    f.header.cube_size = 64;
    f.header.occluder_vertex_count = 8;
    f.header.occluder_triangle_count = 12;
    f.header.trace_flags = VDSH_TRACE_ROBUST;
    for (int k = 0; k < 3; k++) {
        f.header.bounds_min[k] = -2.0f;
        f.header.bounds_max[k] = 3.5f;
    }
    f.positions = pos;
    f.normals = nrm;
    f.indices = idx;
    src[0].name = "builtin:room";
    src[0].size = 1234;
    src[1].name = "scenes/\"quoted\"\\caf\xc3\xa9.obj"; /* JSON escaping */
    src[1].size = 99;
    for (int k = 0; k < 32; k++) {
        src[0].sha256[k] = (uint8_t)(0xa0 + k);
        src[1].sha256[k] = (uint8_t)k;
    }
    f.source_count = 2;
    f.sources = src;
    st[0] = (vdsh_stream){.order = 5,
                          .encoding = VDSH_ENCODING_F16,
                          .method = VDSH_METHOD_PAPER,
                          .quantity = VDSH_QUANTITY_DISTANCE,
                          .window = VDSH_WINDOW_HANN,
                          .window_param = 2.5f,
                          .scale = 15.0f,
                          .data = c5};
    st[1] = (vdsh_stream){.order = 3,
                          .encoding = VDSH_ENCODING_F32,
                          .method = VDSH_METHOD_FULL,
                          .quantity = VDSH_QUANTITY_LOG_DISTANCE,
                          .scale = 1.0f,
                          .quantity_param = 0.25f,
                          .data = c3};
    f.stream_count = 2;
    f.streams = st;
    f.has_stats = 1;
    f.stats.rays_traced = 100000;
    f.stats.rays_missed = 2500;
    f.stats.degenerate_receivers = 1;
    f.stats.undefined_normals = 0;
    f.has_timings = 1;
    f.timings = (vdsh_timings){0.5, 0.25, 0.125, 10.0, 11.0, 2};

    mkdir(dir, 0777);
    snprintf(path, sizeof path, "%s/good.vdsh", dir);
    if (vdsh_write(path, &f, &err) != VDSH_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }

    void *mem = NULL;
    size_t n = 0;
    if (vdsh_write_memory(&f, &mem, &n, &err) != VDSH_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    uint8_t *b = mem;
    struct {
        const char *name;
        size_t size;
    } out[3] = {{"corrupt.vdsh", n}, {"truncated.vdsh", n - 100}, {"text.vdsh", 0}};
    static const char text[] = "solid cube\n  facet normal 0 0 1\n";
    for (int i = 0; i < 3; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, out[i].name);
        FILE *fp = fopen(path, "wb");
        if (!fp) {
            perror(path);
            free(mem);
            return 1;
        }
        if (i == 0)
            b[n - 200] ^= 0x40; /* inside the last stream's data */
        if (i < 2)
            fwrite(b, 1, out[i].size, fp);
        else
            fputs(text, fp);
        fclose(fp);
    }
    free(mem);
    /* The distance volume's magic begins with "VDSH" (was called a .vdsh
     * damaged in a text-mode transfer). */
    static const struct {
        const char *name;
        char bytes[16];
    } other[2] = {{"volume.sdf", "VDSHSDF\0\1\0\0\0\23\0\0"},
                  {"scene.glb", "glTF\2\0\0\0\100\0\0"}};
    for (int i = 0; i < 2; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, other[i].name);
        FILE *fp = fopen(path, "wb");
        if (!fp) {
            perror(path);
            return 1;
        }
        uint8_t zeros[64] = {0};
        fwrite(other[i].bytes, 1, 12, fp);
        fwrite(zeros, 1, sizeof zeros, fp);
        fclose(fp);
    }
    return 0;
}

static int clean_fixtures(const char *dir)
{
    static const char *const names[] = {"good.vdsh", "corrupt.vdsh", "truncated.vdsh",
                                        "text.vdsh", "volume.sdf",   "scene.glb"};
    char path[4096];
    for (int i = 0; i < 6; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        unlink(path);
    }
    rmdir(dir);
    return 0;
}

static char *slurp_fd(int fd)
{
    size_t cap = 4096, n = 0;
    char *s = malloc(cap);
    lseek(fd, 0, SEEK_SET);
    for (;;) {
        ssize_t k = read(fd, s + n, cap - n - 1);
        if (k <= 0)
            break;
        n += (size_t)k;
        if (cap - n - 1 == 0)
            s = realloc(s, cap *= 2);
    }
    s[n] = 0;
    return s;
}

static int expect(int argc, char **argv)
{
    /* argv: CODE [--out TEXT | --err TEXT]... -- PROG ARG... */
    int want = atoi(argv[0]);
    int i = 1;
    while (i < argc && strcmp(argv[i], "--") != 0)
        i += 2;
    if (i >= argc - 1) {
        fprintf(stderr, "expect: missing -- PROG\n");
        return 2;
    }
    char out_name[] = "/tmp/vdsh_tool_out_XXXXXX";
    char err_name[] = "/tmp/vdsh_tool_err_XXXXXX";
    int out_fd = mkstemp(out_name), err_fd = mkstemp(err_name);
    if (out_fd < 0 || err_fd < 0) {
        perror("mkstemp");
        return 2;
    }
    unlink(out_name);
    unlink(err_name);

    pid_t pid = fork();
    if (pid == 0) {
        dup2(out_fd, 1);
        dup2(err_fd, 2);
        execv(argv[i + 1], &argv[i + 1]);
        perror(argv[i + 1]);
        _exit(127);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    char *out = slurp_fd(out_fd), *err = slurp_fd(err_fd);
    int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
    int ok = WIFEXITED(status) && code == want;
    for (int k = 1; k < i; k += 2) {
        const char *hay = !strcmp(argv[k], "--out") ? out : err;
        if (!strstr(hay, argv[k + 1])) {
            fprintf(stderr, "expected %s to contain \"%s\"\n", argv[k] + 2, argv[k + 1]);
            ok = 0;
        }
    }
    printf("--- exit %d (want %d); stdout:\n%s--- stderr:\n%s", code, want, out, err);
    free(out);
    free(err);
    return ok ? 0 : 1;
}

int main(int argc, char **argv)
{
    if (argc >= 3 && !strcmp(argv[1], "make"))
        return write_fixtures(argv[2]);
    if (argc >= 3 && !strcmp(argv[1], "clean"))
        return clean_fixtures(argv[2]);
    if (argc >= 5 && !strcmp(argv[1], "expect"))
        return expect(argc - 2, argv + 2);
    fprintf(stderr,
            "usage: %s make DIR | clean DIR | expect CODE "
            "[--out TEXT] [--err TEXT] -- PROG ARG...\n",
            argv[0]);
    return 2;
}
