/*
 * test_eval_cli.c - vdsh-eval end to end: bake a small closed box written
 * here as OBJ, evaluate it, and check exit codes, messages, the JSON and
 * the per-vertex file; then change the mesh and check that the evaluator
 * names the source that no longer matches.
 *
 *   test_eval_cli VDSH_BAKE VDSH_EVAL WORK_DIR
 */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "test_run.h"
#include "test_util.h"
#include "vt_json.h"

static const char *work;
static char out_path[4096], err_path[4096];

/* Run argv (NULL-terminated) with stdout and stderr to files; exit code. */
static int run(char *const argv[])
{
    return test_run(argv, out_path, err_path);
}

static char *path_in(const char *name)
{
    static char buf[8][4096];
    static int next;
    char *p = buf[next++ % 8];
    snprintf(p, 4096, "%s/%s", work, name);
    return p;
}

/* A closed box [0,2] x [0,1] x [0,2], faces wound to face inwards. */
static void write_box(const char *path, const char *extra)
{
    FILE *f = fopen(path, "w");
    for (int i = 0; i < 8; i++)
        fprintf(f, "v %d %d %d\n", (i & 1) ? 2 : 0, (i & 2) ? 1 : 0, (i & 4) ? 2 : 0);
    static const int q[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                                {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
    for (int k = 0; k < 6; k++) {
        /* Orient each quad so its normal points to the centre (1, .5, 1). */
        float p[4][3];
        for (int j = 0; j < 4; j++)
            for (int c = 0; c < 3; c++)
                p[j][c] = (float)((q[k][j] >> c) & 1) * (c == 1 ? 1.0f : 2.0f);
        float e1[3], e2[3], n[3], mid[3] = {0, 0, 0};
        for (int c = 0; c < 3; c++) {
            e1[c] = p[1][c] - p[0][c], e2[c] = p[2][c] - p[0][c];
            for (int j = 0; j < 4; j++)
                mid[c] += p[j][c] / 4;
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        float to_c[3] = {1 - mid[0], 0.5f - mid[1], 1 - mid[2]};
        int in = n[0] * to_c[0] + n[1] * to_c[1] + n[2] * to_c[2] > 0;
        if (in)
            fprintf(f, "f %d %d %d %d\n", q[k][0] + 1, q[k][1] + 1, q[k][2] + 1, q[k][3] + 1);
        else
            fprintf(f, "f %d %d %d %d\n", q[k][3] + 1, q[k][2] + 1, q[k][1] + 1, q[k][0] + 1);
    }
    if (extra)
        fputs(extra, f);
    fclose(f);
}

static uint32_t u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: test_eval_cli VDSH_BAKE VDSH_EVAL WORK_DIR\n");
        return 2;
    }
    char *bake = argv[1], *ev = argv[2];
    work = argv[3];
    mkdir(work, 0755);
    snprintf(out_path, sizeof out_path, "%s/stdout.txt", work);
    snprintf(err_path, sizeof err_path, "%s/stderr.txt", work);

    /* Usage. */
    CHECK(run((char *[]){ev, "--help", NULL}) == 0, "--help");
    CHECK(test_file_contains(out_path, "--per-vertex") && test_file_contains(out_path, "VDSHPVE1"),
          "--help documents the per-vertex layout");
    CHECK(run((char *[]){ev, "--version", NULL}) == 0 && test_file_contains(out_path, "vdsh-eval "),
          "--version");
    CHECK(run((char *[]){ev, NULL}) == 2 && test_file_contains(err_path, "no .vdsh file"),
          "no file");
    CHECK(run((char *[]){ev, "--no-such-option", "x.vdsh", NULL}) == 2, "bad option");
    CHECK(run((char *[]){ev, "--points", "0", "x.vdsh", NULL}) == 2, "--points 0");
    CHECK(run((char *[]){ev, "--orders", "2,17", "x.vdsh", NULL}) == 2, "--orders 2,17");
    /* Options that would do nothing are usage errors (they were accepted and
     * ignored): --interp with no interior points, --offsets with --oracle. */
    CHECK(run((char *[]){ev, "--interior", "0", "--interp", "distance", "x.vdsh", NULL}) == 2 &&
              test_file_contains(err_path, "--interior 0"),
          "--interp with --interior 0 refused");
    CHECK(run((char *[]){ev, "--oracle", "--offsets", "0.2", "x.vdsh", NULL}) == 2 &&
              test_file_contains(err_path, "--oracle"),
          "--offsets with --oracle refused");
    char *missing = path_in("no-such.vdsh");
    CHECK(run((char *[]){ev, missing, NULL}) == 1 && test_file_contains(err_path, "no-such.vdsh"),
          "a missing file is named");

    /* Bake a box. */
    char *obj = path_in("box.obj"), *vdsh = path_in("box.vdsh"), *rep = path_in("box.bake.json");
    write_box(obj, NULL);
    int rc = run((char *[]){bake, obj, "--max-edge", "0.5", "--rays", "256", "--method", "paper",
                            "--orders", "2,3,5", "--record-timings", "--cube-size", "0", "-q",
                            "--report", rep, "-o", vdsh, NULL});
    CHECK(rc == 0, "bake: exit %d", rc);
    if (rc != 0) {
        char *e = (char *)test_read_file(err_path, NULL);
        fprintf(stderr, "%s\n", e ? e : "");
        free(e);
        return test_report("test_eval_cli");
    }

    /* Evaluate: table, JSON, per-vertex file. */
    char *json = path_in("box.eval.json"), *pv = path_in("box.pv");
    rc = run((char *[]){ev, vdsh, "--json", json, "--per-vertex", pv, "--interior", "1000",
                        "--threads", "2", NULL});
    CHECK(rc == 0, "eval: exit %d", rc);
    CHECK(test_file_contains(out_path, "SHA-256 verified") &&
              test_file_contains(out_path, "interior") &&
              test_file_contains(out_path, "(time chunk)") && test_file_contains(out_path, "paper"),
          "table");
    CHECK(test_file_contains(out_path, " 0.0000% escaped"), "the truth escapes a closed box");
    CHECK(test_file_contains(out_path, "SH sum range <= 0 (read as distance 0)"),
          "the ringing line (it said 'rang')");
    /* The JSON parses (the project's reader, vt_json.h) and holds the
     * streams. */
    {
        char msg[512];
        cJSON *j = vt_json_read_file(json, msg, sizeof msg);
        const cJSON *streams = cJSON_GetObjectItemCaseSensitive(j, "streams");
        CHECK(j && cJSON_GetArraySize(streams) == 3, "JSON: %s", j ? "streams" : msg);
        CHECK(vt_json_number(cJSON_GetArrayItem(streams, 2), "bytes_per_vertex") == 24.0,
              "JSON: order 5 in the default encoding (s8s6) is 24 bytes per vertex");
        /* The table's scene-light pair counts: whole below 10,000 (88 pairs
         * were printed as "8.8e-05M"), else k or M. */
        const cJSON *sl =
            cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(streams, 0), "scene_lights");
        const char *kinds[] = {"vertices", "interior"};
        for (int k = 0; k < 2; k++) {
            double pairs = vt_json_number(cJSON_GetObjectItemCaseSensitive(sl, kinds[k]), "pairs");
            char want[64];
            if (pairs < 10000)
                snprintf(want, sizeof want, "| %7.0f |", pairs);
            else {
                double v = pairs < 1e6 ? pairs / 1e3 : pairs / 1e6; /* three figures */
                snprintf(want, sizeof want, "| %6.*f%c |",
                         v < 9.995   ? 2
                         : v < 99.95 ? 1
                                     : 0,
                         v, pairs < 1e6 ? 'k' : 'M');
            }
            CHECK(pairs > 0 && test_file_contains(out_path, want),
                  "the table shows %s's %.0f scene-light pairs as '%s'", kinds[k], pairs, want);
        }
        cJSON_Delete(j);
    }
    size_t size = 0;
    unsigned char *b = test_read_file(pv, &size);
    CHECK(b && size >= 64, "per-vertex file");
    if (b && size >= 64) {
        uint32_t V = u32(b + 12), K = u32(b + 16), F = u32(b + 20), off = u32(b + 24);
        CHECK(memcmp(b, "VDSHPVE1", 8) == 0 && u32(b + 8) == 1, "magic, version");
        CHECK(K == 3 && F == 2 + 5 * K && off == 64 + 16 * K, "K %u F %u offset %u", K, F, off);
        CHECK(u32(b + 64) == 2 && u32(b + 64 + 16) == 3 && u32(b + 64 + 32) == 5, "orders");
        CHECK(size == off + (size_t)V * F * 4, "size %zu for %u vertices", size, V);
        if (size == off + (size_t)V * F * 4) {
            int finite = 1;
            for (uint32_t v = 0; v < V; v++) {
                float x[32];
                memcpy(x, b + off + (size_t)v * F * 4, F * 4);
                for (uint32_t i = 0; i < F; i++)
                    if (i != 2 + 2 && i != 2 + 3 && i != 7 + 2 && i != 7 + 3 && i != 12 + 2 &&
                        i != 12 + 3)
                        finite &= isfinite(x[i]) && x[i] >= 0;
            }
            CHECK(finite, "every vertex evaluated (no --points), values >= 0");
        }
    }
    free(b);

    /* The oracle scores exactly zero. */
    rc = run((char *[]){ev, vdsh, "--oracle", "--interior", "200", "--json", json, NULL});
    {
        char msg[512];
        cJSON *j = rc == 0 ? vt_json_read_file(json, msg, sizeof msg) : NULL;
        const cJSON *st;
        int streams = 0, zero = 1;
        cJSON_ArrayForEach(st, cJSON_GetObjectItemCaseSensitive(j, "streams"))
        {
            streams++;
            zero &= vt_json_number(cJSON_GetObjectItemCaseSensitive(st, "vertices"),
                                   "shadow_mae") == 0.0 &&
                    vt_json_number(cJSON_GetObjectItemCaseSensitive(st, "interior"),
                                   "shadow_mae") == 0.0;
        }
        CHECK(rc == 0 && streams == 3 && zero, "oracle: every shadow MAE exactly 0");
        cJSON_Delete(j);
    }
    /* The curve: every stream again with each offset added to ln D (the
     * paper's distance streams: times e^offset). Shorter distances
     * (offset -0.5) draw more shadows: recall and false shadows rise; the
     * zero offset reproduces the stream itself. */
    char *room = path_in("room.vdsh");
    rc = run((char *[]){bake, "builtin:room", "--max-edge", "1", "--rays", "256", "--method",
                        "paper", "--cube-size", "0", "-q", "-o", room, NULL});
    CHECK(rc == 0, "bake the room: exit %d", rc);
    rc = run((char *[]){ev, room, "--orders", "5", "--offsets", "-0.5,0,0.5", "--lights", "16",
                        "--interior", "2000", "--points", "2000", "--json", json, NULL});
    {
        char msg[512];
        cJSON *j = rc == 0 ? vt_json_read_file(json, msg, sizeof msg) : NULL;
        double rec[4], fa[4], mae[4], off[4];
        int n = 0;
        const cJSON *st;
        cJSON_ArrayForEach(st, cJSON_GetObjectItemCaseSensitive(j, "streams"))
        {
            if (n < 4) {
                const cJSON *sl = cJSON_GetObjectItemCaseSensitive(
                    cJSON_GetObjectItemCaseSensitive(st, "scene_lights"), "interior");
                rec[n] = vt_json_number(sl, "recall");
                fa[n] = vt_json_number(sl, "false_shadow");
                mae[n] = vt_json_number(sl, "shadow_mae");
                off[n] = vt_json_number(st, "log_offset");
            }
            n++;
        }
        CHECK(rc == 0 && n == 4 &&
                  vt_json_number(cJSON_GetObjectItemCaseSensitive(j, "eval"), "scene_lights") == 16,
              "--offsets: %d streams (rc %d)", n, rc);
        if (n == 4) {
            CHECK(off[0] == 0 && off[1] == -0.5 && off[2] == 0 && off[3] == 0.5,
                  "offsets %g %g %g %g", off[0], off[1], off[2], off[3]);
            CHECK(rec[1] >= rec[0] && rec[0] >= rec[3] && fa[1] >= fa[0] && fa[0] >= fa[3] &&
                      rec[1] > rec[3] && fa[1] > fa[3],
                  "recall %g %g %g and false shadows %g %g %g must fall with the offset", rec[1],
                  rec[0], rec[3], fa[1], fa[0], fa[3]);
            CHECK(fabs(mae[2] - mae[0]) < 1e-6 && rec[2] == rec[0],
                  "offset 0 (f32 copy) scores as the stream: MAE %.9g %.9g, recall %g %g", mae[2],
                  mae[0], rec[2], rec[0]);
        }
        cJSON_Delete(j);
    }
    CHECK(run((char *[]){ev, vdsh, "--offsets", "9", NULL}) == 2 &&
              test_file_contains(err_path, "--offsets"),
          "--offsets 9 refused");
    CHECK(run((char *[]){ev, vdsh, "--offsets", "0.1,0.2,0.3,0.4,0.5", NULL}) == 2 &&
              test_file_contains(err_path, "streams"),
          "too many offset streams refused");
    CHECK(run((char *[]){ev, vdsh, "--lights", "0", NULL}) == 2, "--lights 0 refused");

    /* Bake time from the bake's report. */
    rc = run((char *[]){ev, vdsh, "--bake-report", rep, "--interior", "0", "--orders", "5", NULL});
    CHECK(rc == 0 && test_file_contains(out_path, "(bake report)") &&
              !test_file_contains(out_path, "order 2 "),
          "--bake-report, --orders");
    /* A report of another bake: refused, naming it (its time was given as
     * this file's, exit 0). */
    char other[4096]; /* not path_in: its 8 buffers are in use */
    snprintf(other, sizeof other, "%s/other.bake.json", work);
    FILE *of = fopen(other, "w");
    fprintf(of, "{\"sources\": [\"other.obj\"], \"receivers\": 3, \"seconds\": {\"total\": 7}}\n");
    fclose(of);
    rc = run((char *[]){ev, vdsh, "--bake-report", other, "--interior", "0", NULL});
    CHECK(rc == 1 && test_file_contains(err_path, "the report of another bake"),
          "--bake-report of another bake refused: exit %d", rc);

    /* The mesh changes: named; --allow-mismatch goes on with a warning; the
     * original content under another name is accepted. */
    char *moved = path_in("moved.obj");
    rename(obj, moved);
    rc = run((char *[]){ev, vdsh, NULL});
    CHECK(rc == 1 && test_file_contains(err_path, "cannot find source 1 of 1") &&
              test_file_contains(err_path, "box.obj"),
          "a missing source is named (exit %d)", rc);
    rc = run((char *[]){ev, vdsh, moved, "--interior", "100", NULL});
    CHECK(rc == 0, "the source under another name: exit %d", rc);
    write_box(obj, "# changed\n");
    rc = run((char *[]){ev, vdsh, NULL});
    CHECK(rc == 1 && test_file_contains(err_path, "source 1 of 1") &&
              test_file_contains(err_path, "box.obj") && test_file_contains(err_path, "SHA-256"),
          "a changed source is named (exit %d)", rc);
    rc = run((char *[]){ev, vdsh, "--allow-mismatch", "--interior", "100", NULL});
    CHECK(rc == 0 && test_file_contains(err_path, "warning"), "--allow-mismatch (exit %d)", rc);
    /* -q: nothing on stderr but errors, in every program (the warning was
     * said under -q too) */
    rc = run((char *[]){ev, vdsh, "--allow-mismatch", "--interior", "100", "-q", NULL});
    CHECK(rc == 0 && !test_file_contains(err_path, "warning"), "--allow-mismatch -q (exit %d)", rc);
    rc = run((char *[]){ev, vdsh, moved, moved, NULL});
    CHECK(rc == 2 && test_file_contains(err_path, "2 mesh(es) given"), "two meshes for one source");

    /* A file that is not a .vdsh. */
    rc = run((char *[]){ev, obj, NULL});
    CHECK(rc == 1 && test_file_contains(err_path, "box.obj"), "not a .vdsh: exit %d", rc);
    return test_report("test_eval_cli");
}
