/*
 * test_robust_corrupt.c - corruption sweep of real .vdsh files (issue 5):
 * a game runtime reads these files, so a damaged one must end in an
 * error, never a crash and never a silently different scene.
 *
 * Usage: test_robust_corrupt VDSH_BAKE VDSH_INFO WORK_DIR
 *
 * The files are baked by vdsh-bake itself (so every chunk a real bake
 * writes is there): a small scene of a floor and a box refined to max
 * edge 1 (orders 2,3,5, f16; and orders 1,4, f32, method full, with the
 * timings chunk; order 6 in cpca, 3 clusters of 7 vectors, 5-bit weights;
 * order 6 in cpca with a width per vector, --cpca 3,alloc:60, and the same
 * with s8 bases, --cpca 3,alloc:60,bases:8; shard 0 of 2
 * of that bake with --light-region grown, a part with its part, lpol and
 * lreg chunks, lpol 24 KB of light pool), and
 * builtin:room at max edge 0 (the room's 261 KB are
 * swept at a stride of 1/1009 of the file and with 1,000 two-byte changes;
 * a full sweep would take minutes). Then:
 *
 *   single-byte changes: every byte of each small file XOR 0xFF and XOR
 *                        0x01 (the lowest bit: a float that changes a
 *                        little, which only a CRC notices);
 *   two-byte changes:    a deterministic sample (4,000 per small file) of
 *                        pairs of positions and non-zero XOR values;
 *   truncations:         every prefix of each small file, empty included;
 *   extensions:          1..16 bytes appended;
 *   vdsh-info --verify:  a spread-out sample of the changed files must make
 *                        it exit 1 and name the file on stderr.
 *
 * Every changed file differs from a valid one in a byte that a CRC or the
 * file size covers, so every single change must be rejected by
 * vdsh_read_memory (and vdsh_scan_chunks must return without crashing).
 * Under ASan a read past the buffer fails the test too: each changed file
 * is read from a buffer of exactly its size.
 */
#include "test_util.h"
#include "vdsh.h"

#include <errno.h>
#include <fcntl.h>
#include <spawn.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

/* Runs argv with stdout to /dev/null and stderr to `err_path`; returns
 * the exit status, or -1 if it did not exit normally. */
static int run(char *const argv[], const char *err_path)
{
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 2, err_path ? err_path : "/dev/null",
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid;
    int rc = posix_spawn(&pid, argv[0], &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0) {
        fprintf(stderr, "cannot run %s: %s\n", argv[0], strerror(rc));
        return -1;
    }
    int status;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR)
            return -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static int write_all(const char *path, const uint8_t *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    int bad = fwrite(data, 1, size, f) != size;
    return fclose(f) != 0 || bad ? -1 : 0;
}

typedef struct counts {
    unsigned long tried, rejected;
} counts;

/* One changed file: it must be rejected, read from an exact-size copy. */
static void expect_rejected(const uint8_t *data, size_t size, counts *c, const char *what)
{
    uint8_t *exact = malloc(size ? size : 1);
    memcpy(exact, data, size);
    vdsh_file *f = NULL;
    vdsh_error err;
    vdsh_chunk_info info[16];
    uint32_t n;
    (void)vdsh_scan_chunks(exact, size, "corrupt", info, 16, &n, &err);
    vdsh_result r = vdsh_read_memory(exact, size, "corrupt", &f, &err);
    c->tried++;
    if (r != VDSH_OK) {
        c->rejected++;
        CHECK(strstr(err.msg, "corrupt") != NULL, "%s: message does not name the file: %s", what,
              err.msg);
    } else {
        CHECK(0, "%s: accepted", what);
        vdsh_free(f);
    }
    free(exact);
}

/* vdsh-info --verify on a changed file: exit 1, the file named on stderr. */
static void expect_info_rejects(const char *info, const char *dir, const uint8_t *data, size_t size,
                                counts *c, const char *what)
{
    char path[4096], err_path[4096];
    snprintf(path, sizeof path, "%s/changed.vdsh", dir);
    snprintf(err_path, sizeof err_path, "%s/info.err", dir);
    if (write_all(path, data, size) != 0) {
        CHECK(0, "cannot write %s", path);
        return;
    }
    char *argv[] = {(char *)info, "--verify", path, NULL};
    int rc = run(argv, err_path);
    size_t n;
    uint8_t *msg = test_read_file(err_path, &n);
    c->tried++;
    c->rejected += rc == 1;
    CHECK(rc == 1, "vdsh-info --verify on %s: exit %d, want 1", what, rc);
    CHECK(msg && strstr((char *)msg, "changed.vdsh") != NULL,
          "vdsh-info on %s: stderr does not name the file", what);
    free(msg);
}

static void sweep(const char *name, const uint8_t *orig, size_t size, size_t stride, int pair_count,
                  const char *info, const char *dir)
{
    /* The original itself must read. */
    vdsh_file *f = NULL;
    vdsh_error err;
    CHECK(vdsh_read_memory(orig, size, name, &f, &err) == VDSH_OK, "%s: %s", name, err.msg);
    vdsh_free(f);

    uint8_t *buf = malloc(size + 16);
    memcpy(buf, orig, size);
    counts single = {0}, pairs = {0}, cut = {0}, longer = {0}, tool = {0};
    char what[128];
    static const uint8_t masks[2] = {0xFF, 0x01};
    size_t tool_every = size / stride / 12 + 1;

    for (size_t i = 0; i < size; i += stride)
        for (int m = 0; m < 2; m++) {
            buf[i] ^= masks[m];
            snprintf(what, sizeof what, "%s byte %zu ^ 0x%02x", name, i, masks[m]);
            expect_rejected(buf, size, &single, what);
            if (m == 0 && (i / stride) % tool_every == 0)
                expect_info_rejects(info, dir, buf, size, &tool, what);
            buf[i] ^= masks[m];
        }

    uint64_t s = 0x9e3779b97f4a7c15ull ^ size;
    for (int k = 0; k < pair_count; k++) {
        size_t i = (size_t)(test_rand(&s) * (double)size),
               j = (size_t)(test_rand(&s) * (double)size);
        uint8_t a = (uint8_t)(1 + test_rand(&s) * 255), b = (uint8_t)(1 + test_rand(&s) * 255);
        if (i == j)
            continue;
        buf[i] ^= a;
        buf[j] ^= b;
        snprintf(what, sizeof what, "%s bytes %zu ^ 0x%02x, %zu ^ 0x%02x", name, i, a, j, b);
        expect_rejected(buf, size, &pairs, what);
        if (k % (pair_count / 5) == 0)
            expect_info_rejects(info, dir, buf, size, &tool, what);
        buf[i] ^= a;
        buf[j] ^= b;
    }

    for (size_t n = 0; n < size; n += stride) {
        snprintf(what, sizeof what, "%s truncated to %zu bytes", name, n);
        expect_rejected(buf, n, &cut, what);
    }
    snprintf(what, sizeof what, "%s truncated by one byte", name);
    expect_info_rejects(info, dir, buf, size - 1, &tool, what);

    for (size_t extra = 1; extra <= 16; extra++) {
        memset(buf + size, extra == 16 ? 0 : (int)extra, extra);
        snprintf(what, sizeof what, "%s with %zu bytes appended", name, extra);
        expect_rejected(buf, size + extra, &longer, what);
    }
    free(buf);

    printf("%s (%zu bytes%s): single-byte changes %lu/%lu rejected, two-byte changes %lu/%lu, "
           "truncations %lu/%lu, extensions %lu/%lu, vdsh-info --verify exit 1: %lu/%lu\n",
           name, size, stride > 1 ? ", sampled" : "", single.rejected, single.tried, pairs.rejected,
           pairs.tried, cut.rejected, cut.tried, longer.rejected, longer.tried, tool.rejected,
           tool.tried);
}

/* A floor and a box on it: small, but with the occlusion a real scene has. */
static const char scene_obj[] = "v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\n"
                                "v -0.5 0 -0.5\nv 0.5 0 -0.5\nv 0.5 0 0.5\nv -0.5 0 0.5\n"
                                "v -0.5 1 -0.5\nv 0.5 1 -0.5\nv 0.5 1 0.5\nv -0.5 1 0.5\n"
                                "f 1 4 3 2\n"
                                "f 9 12 11 10\nf 5 6 10 9\nf 6 7 11 10\nf 7 8 12 11\nf 8 5 9 12\n";

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: test_robust_corrupt VDSH_BAKE VDSH_INFO WORK_DIR\n");
        return 2;
    }
    const char *bake = argv[1], *info = argv[2], *dir = argv[3];
    char obj[4096], a[4096], b[4096], c[4096], room[4096], var[4096], cp[4096], cw[4096], c8[4096],
        pt[4096], err_path[4096];
    mkdir(dir, 0755);
    snprintf(obj, sizeof obj, "%s/scene.obj", dir);
    snprintf(a, sizeof a, "%s/scene-f16.vdsh", dir);
    snprintf(b, sizeof b, "%s/scene-f32.vdsh", dir);
    snprintf(c, sizeof c, "%s/scene-s8s6.vdsh", dir);
    snprintf(room, sizeof room, "%s/room.vdsh", dir);
    snprintf(var, sizeof var, "%s/scene-var.vdsh", dir);
    snprintf(cp, sizeof cp, "%s/scene-cpca.vdsh", dir);
    snprintf(cw, sizeof cw, "%s/scene-cpca-widths.vdsh", dir);
    snprintf(c8, sizeof c8, "%s/scene-cpca-s8.vdsh", dir);
    snprintf(pt, sizeof pt, "%s/scene-cpca-part.vdsh", dir);
    snprintf(err_path, sizeof err_path, "%s/bake.err", dir);
    if (write_all(obj, (const uint8_t *)scene_obj, sizeof scene_obj - 1) != 0) {
        fprintf(stderr, "cannot write %s\n", obj);
        return 1;
    }
    char *bake_a[] = {(char *)bake, obj,          "--max-edge", "1",  "--rays", "64", "--cube-size",
                      "0",          "--encoding", "f16",        "-q", "-o",     a,    NULL};
    /* the default encoding: scale tables and packed words */
    char *bake_c[] = {(char *)bake,  obj, "--max-edge", "1",  "--rays", "64",
                      "--cube-size", "0", "-q",         "-o", c,        NULL};
    char *bake_b[] = {(char *)bake,
                      obj,
                      "--max-edge",
                      "1",
                      "--rays",
                      "64",
                      "--orders",
                      "1,4",
                      "--encoding",
                      "f32",
                      "--method",
                      "full",
                      "--record-timings",
                      "--cube-size",
                      "0",
                      "-q",
                      "-o",
                      b,
                      NULL};
    char *bake_room[] = {(char *)bake, "builtin:room", "--rays", "16", "--cube-size",
                         "0",          "-q",           "-o",     room, NULL};
    /* an adaptive order: the order table and records of every size */
    char *bake_var[] = {
        (char *)bake,       obj,    "--max-edge",  "1", "--rays", "64", "--cube-size", "0",
        "--adaptive-order", "0.01", "--max-order", "7", "-q",     "-o", var,           NULL};
    /* cpca (issue 29): a model (scales, means, bases) and packed records */
    char *bake_cp[] = {(char *)bake,  obj,     "--max-edge", "1",  "--rays",     "64",
                       "--cube-size", "0",     "--orders",   "6",  "--encoding", "cpca",
                       "--cpca",      "3,7,5", "-q",         "-o", cp,           NULL};
    /* a width per basis vector: the widths table and mixed fields */
    char *bake_cw[] = {(char *)bake,  obj,          "--max-edge", "1",  "--rays",     "64",
                       "--cube-size", "0",          "--orders",   "6",  "--encoding", "cpca",
                       "--cpca",      "3,alloc:60", "-q",         "-o", cw,           NULL};
    /* s8 bases (--cpca ...,bases:8: the bits word's flag, a byte per value) */
    char *bake_c8[] = {(char *)bake,
                       obj,
                       "--max-edge",
                       "1",
                       "--rays",
                       "64",
                       "--cube-size",
                       "0",
                       "--orders",
                       "6",
                       "--encoding",
                       "cpca",
                       "--cpca",
                       "3,alloc:60,bases:8",
                       "-q",
                       "-o",
                       c8,
                       NULL};
    /* a part of a sharded cpca bake: the part chunk, lpol (the light
     * pool of the byte-budget settings' light-density metric) and lreg
     * (--light-region grown: the pool placed around the scene) */
    char *bake_pt[] = {(char *)bake,  obj,          "--max-edge", "1",   "--rays",         "64",
                       "--cube-size", "0",          "--orders",   "6",   "--encoding",     "cpca",
                       "--cpca",      "3,alloc:60", "--shard",    "0/2", "--light-region", "grown",
                       "-q",          "-o",         pt,           NULL};
    int ok = run(bake_a, err_path) == 0 && run(bake_b, err_path) == 0 &&
             run(bake_c, err_path) == 0 && run(bake_room, err_path) == 0 &&
             run(bake_var, err_path) == 0 && run(bake_cp, err_path) == 0 &&
             run(bake_cw, err_path) == 0 && run(bake_c8, err_path) == 0 &&
             run(bake_pt, err_path) == 0;
    CHECK(ok, "vdsh-bake failed (see %s)", err_path);
    if (!ok)
        return test_report("robust_corrupt");

    const char *names[9] = {
        "scene-f16.vdsh",      "scene-f32.vdsh",  "scene-s8s6.vdsh",        "room.vdsh",
        "scene-var.vdsh",      "scene-cpca.vdsh", "scene-cpca-widths.vdsh", "scene-cpca-s8.vdsh",
        "scene-cpca-part.vdsh"};
    const char *paths[9] = {a, b, c, room, var, cp, cw, c8, pt};
    for (int k = 0; k < 9; k++) {
        size_t size;
        uint8_t *data = test_read_file(paths[k], &size);
        CHECK(data && size > 64, "cannot read %s", paths[k]);
        if (!data)
            continue;
        if (paths[k] == pt) { /* the sweep covers both chunks of a part */
            vdsh_chunk_info chunks[32];
            uint32_t count = 0;
            vdsh_error err;
            int part = 0, lpol = 0, lreg = 0;
            if (vdsh_scan_chunks(data, size, pt, chunks, 32, &count, &err) == VDSH_OK)
                for (uint32_t i = 0; i < count; i++) {
                    part |= strcmp(chunks[i].id, "part") == 0;
                    lpol |= strcmp(chunks[i].id, "lpol") == 0;
                    lreg |= strcmp(chunks[i].id, "lreg") == 0;
                }
            CHECK(part && lpol && lreg, "%s: no part (%d), lpol (%d) or lreg chunk (%d)", pt, part,
                  lpol, lreg);
        }
        /* The small files: every byte; the room: about 1,000 positions. */
        int large = size > 65536;
        sweep(names[k], data, size, large ? size / 1009 : 1, large ? 1000 : 4000, info, dir);
        free(data);
    }
    return test_report("robust_corrupt");
}
