/*
 * test_frames.c - vdsh-frames and its core (bake/eval/frames.h), one part per
 * ctest:
 *
 *   score    the scores on hand-made frames: RMSE, PSNR, recall, false
 *            area, blotches (4-connectivity, the size threshold), pooling
 *   oracle   the truth scored as a method: ideal against ideal and hard
 *            against hard are exact (RMSE 0, recall 1, false area 0, no
 *            blotches), over views of the built-in room with real shadows
 *   box      a floor, a box floating above it and one light straight above,
 *            seen from straight above: the hard shadow's pixel count and
 *            the lit count match the areas from geometry; every primary
 *            hit lies on its ray (the barycentrics pick the right
 *            vertices); the truth is byte-identical for 1 and 2 threads
 *   views    vdsh-frames views on the built-in room: a valid file, the
 *            default view first, every eye and light in free space, every
 *            view's lights light and shadow a share of it, no surface
 *            nearer than 5% of the diagonal; the same file for the same
 *            seed (on 1 thread and on 2), another for another seed;
 *            --light-rule near: every light within 5% of the diagonal of
 *            a surface (uniform, the default: not every one)
 *   orders   orders above 5 and variable-order streams: a stream whose
 *            every vertex has order 7 scores and draws exactly as the
 *            fixed order-7 stream (c-vdsh-var = c-vdsh7); with orders 3
 *            and 7 mixed, a triangle of one order's vertices draws as that
 *            order's fixed stream
 *   errors   missing and invalid view sets, a frame of another size, a
 *            missing frame: exit 1 naming the file and no output; usage
 *            errors exit 2
 *
 *   test_frames score
 *   test_frames PART VDSH_BAKE VDSH_FRAMES WORK_DIR
 * Timing is printed by vdsh-frames truth, never asserted.
 */
#define _XOPEN_SOURCE 700 /* nftw */
#include <dirent.h>
#include <fcntl.h>
#include <ftw.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "eval.h"
#include "frames.h"
#include "test_run.h"
#include "test_util.h"
#include "vdsh.h"
#include "vdsh_shadow.h"
#include "vt_image.h"
#include "vt_json.h"
#include "vt_views.h"

static const char *work, *bake, *frames;
static char out_path[4096], err_path[4096];

/* Run argv (NULL-terminated) with stdout and stderr to files; exit code. */
static int run(char *const argv[])
{
    return test_run(argv, out_path, err_path);
}

static void show_stderr(void)
{
    char *e = (char *)test_read_file(err_path, NULL);
    fprintf(stderr, "stderr: %s\n", e ? e : "");
    free(e);
}

static char *path_in(const char *name)
{
    static char buf[16][4096];
    static int next;
    char *p = buf[next++ % 16];
    snprintf(p, 4096, "%s/%s", work, name);
    return p;
}

static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* ---- score: the scores on hand-made frames ---------------------------------------- */

static int part_score(void)
{
    /* A 100 x 100 frame (blotch threshold: more than 5 pixels). Left half
     * lit (hard 1), right half shadowed (hard 0); ideal 0 where shadowed,
     * except column 99 (ideal .75: shadowed but not "ideal < .5"). Row 0
     * is outside the mask. */
    enum { W = 100, H = 100, N = W * H };
    static float s[N], hard[N], ideal[N], mask[N];
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int i = y * W + x;
            hard[i] = x < 50 ? 1.0f : 0.0f;
            ideal[i] = x < 50 ? 1.0f : x == 99 ? 0.75f : 0.0f;
            mask[i] = y == 0 ? 0.0f : 1.0f;
            s[i] = ideal[i];
        }
    vb_frames_tally t = {0};
    vb_frames_scores r;
    vb_error err;
    CHECK(vb_frames_score_frame(s, hard, ideal, mask, W, H, &t, &err) == VB_OK, "score");
    vb_frames_scores_get(&t, &r);
    CHECK(t.counted == 9900 && t.pixels == N && t.frames == 1, "counted %llu",
          (unsigned long long)t.counted);
    CHECK(t.lit == 50 * 99 && t.shadowed == 49 * 99, "lit %llu shadowed %llu",
          (unsigned long long)t.lit, (unsigned long long)t.shadowed);
    CHECK(r.rmse_ideal == 0.0 && isinf(r.psnr_ideal) && r.recall == 1.0 && r.false_area == 0.0 &&
              r.blotches == 0,
          "ideal scored as itself: rmse %g recall %g false %g", r.rmse_ideal, r.recall,
          r.false_area);
    /* Against hard: only column 99 differs, by .75, on 99 rows. */
    double want = sqrt(99 * 0.75 * 0.75 / 9900.0);
    CHECK(fabs(r.rmse_hard - want) < 1e-12, "rmse vs hard %.15g, want %.15g", r.rmse_hard, want);
    CHECK(fabs(r.psnr_hard - 10.0 * log10(1.0 / (want * want))) < 1e-9, "psnr %g", r.psnr_hard);

    /* False shadows: a 2 x 3 region (6 px: a blotch), a 5 px plus-sign (not
     * one: 5 is not more than 5), two pixels touching only at a corner
     * (two regions of 1), an L of 7 pixels (one blotch), and a false pixel
     * in row 0 (outside the mask: not counted). Shadow recall: 10 of the
     * shadowed pixels drawn lit. */
    for (int i = 0; i < N; i++)
        s[i] = ideal[i];
    const int region[][2] = {{2, 2},   {3, 2},   {4, 2},   {2, 3},   {3, 3},   {4, 3}, /* 6 */
                             {10, 10}, {9, 10},  {11, 10}, {10, 9},  {10, 11},         /* 5 */
                             {20, 20}, {21, 21},                                       /* 1+1 */
                             {30, 30}, {30, 31}, {30, 32}, {30, 33}, {31, 33}, {32, 33},
                             {33, 33}, /* 7 */
                             {40, 0}};
    for (size_t k = 0; k < sizeof region / sizeof region[0]; k++)
        s[region[k][1] * W + region[k][0]] = 0.25f;
    for (int k = 0; k < 10; k++)
        s[(5 + k) * W + 60] = 0.5f; /* 0.5 is not < 0.5: drawn lit */
    vb_frames_tally t2 = {0};
    CHECK(vb_frames_score_frame(s, hard, ideal, mask, W, H, &t2, &err) == VB_OK, "score 2");
    vb_frames_scores_get(&t2, &r);
    CHECK(t2.false_shadow == 20, "false pixels %llu", (unsigned long long)t2.false_shadow);
    CHECK(fabs(r.false_area - 20.0 / 4950.0) < 1e-15, "false area %g", r.false_area);
    CHECK(r.blotches == 2 && t2.blotch_pixels == 13, "blotches %llu (%llu px), want 2 (13)",
          (unsigned long long)r.blotches, (unsigned long long)t2.blotch_pixels);
    CHECK(fabs(r.blotch_area - 13.0 / N) < 1e-15, "blotch area %g", r.blotch_area);
    CHECK(t2.recalled == t2.shadowed - 10, "recall count %llu of %llu",
          (unsigned long long)t2.recalled, (unsigned long long)t2.shadowed);

    /* Pooling adds counts: recall and false area are ratios of sums. */
    vb_frames_tally pool = {0};
    vb_frames_tally_add(&pool, &t);
    vb_frames_tally_add(&pool, &t2);
    vb_frames_scores_get(&pool, &r);
    CHECK(pool.frames == 2 && pool.counted == 2 * 9900, "pooled counts");
    CHECK(fabs(r.recall - (double)(2 * t.shadowed - 10) / (double)(2 * t.shadowed)) < 1e-15,
          "pooled recall %g", r.recall);
    CHECK(r.blotches == 2 && fabs(r.blotch_area - 13.0 / (2.0 * N)) < 1e-15, "pooled blotches");

    /* Nothing counted: NaN, not 0 or a division by zero. */
    for (int i = 0; i < N; i++)
        mask[i] = 0.0f;
    vb_frames_tally t3 = {0};
    vb_frames_score_frame(s, hard, ideal, mask, W, H, &t3, &err);
    vb_frames_scores_get(&t3, &r);
    CHECK(isnan(r.rmse_ideal) && isnan(r.psnr_hard) && isnan(r.recall) && isnan(r.false_area) &&
              r.blotches == 0,
          "an empty mask scores NaN");
    return test_report("frames_score");
}

/* ---- scenes ------------------------------------------------------------------------------ */

/* A 4 x 4 floor at y = 0 (facing up) and a box [-.5, .5] x [.5, 1] x [-.5,
 * .5] floating above it, every face with its own vertices, wound to face
 * out. */
static void write_floor_box(const char *path)
{
    FILE *f = fopen(path, "w");
    int v = 0;
    fprintf(f, "v -2 0 -2\nv -2 0 2\nv 2 0 2\nv 2 0 -2\nf 1 2 3 4\n");
    v += 4;
    /* Box faces as (axis, side): four corners counter-clockwise seen from
     * outside. */
    const float lo[3] = {-0.5f, 0.5f, -0.5f}, hi[3] = {0.5f, 1.0f, 0.5f};
    for (int axis = 0; axis < 3; axis++)
        for (int side = 0; side < 2; side++) {
            int a = (axis + 1) % 3, b = (axis + 2) % 3;
            float c[4][3];
            const int ua[4] = {0, 1, 1, 0}, ub[4] = {0, 0, 1, 1};
            for (int k = 0; k < 4; k++) {
                c[k][axis] = side ? hi[axis] : lo[axis];
                c[k][a] = ua[k] ? hi[a] : lo[a];
                c[k][b] = ub[k] ? hi[b] : lo[b];
            }
            /* (a, b, axis) is right-handed: this order faces +axis. */
            for (int k = 0; k < 4; k++) {
                int j = side ? k : 3 - k;
                fprintf(f, "v %g %g %g\n", (double)c[j][0], (double)c[j][1], (double)c[j][2]);
            }
            fprintf(f, "f %d %d %d %d\n", v + 1, v + 2, v + 3, v + 4);
            v += 4;
        }
    fclose(f);
}

static int bake_to(char *const *sources, const char *out, const char *max_edge)
{
    char *argv[16];
    int n = 0;
    argv[n++] = (char *)bake;
    for (; *sources; sources++)
        argv[n++] = *sources;
    char *rest[] = {
        "--max-edge", (char *)max_edge, "--rays", "64", "--orders", "2,3", "--cube-size", "0", "-q",
        "-o",         (char *)out,      NULL};
    for (char **r = rest; *r; r++)
        argv[n++] = *r;
    argv[n] = NULL;
    int rc = run(argv);
    if (rc != 0)
        show_stderr();
    return rc;
}

/* The scene of a .vdsh in this process (occluders from `source`). */
typedef struct scene3 {
    vdsh_file *f;
    vb_scene *occ;
    vb_frames_scene *fs;
} scene3;

static int scene_load(const char *vdsh, const char *source, scene3 *s)
{
    vdsh_error ve;
    vb_error err;
    memset(s, 0, sizeof *s);
    if (vdsh_read(vdsh, &s->f, &ve) != VDSH_OK) {
        fprintf(stderr, "%s\n", ve.msg);
        return -1;
    }
    const char *paths[1] = {source};
    if (vb_eval_scene_create(s->f, paths, 1, NULL, &s->occ, &err) != VB_OK ||
        vb_frames_scene_create(s->f, s->occ, 0, &s->fs, &err) != VB_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return -1;
    }
    return 0;
}

static void scene_free(scene3 *s)
{
    vb_frames_scene_destroy(s->fs);
    vb_scene_destroy(s->occ);
    vdsh_free(s->f);
}

static float *frame(const char *dir, const char *view, int set, int light, const char *mode, int w,
                    int h)
{
    char p[4096], msg[4300];
    int fw = 0, fh = 0;
    float *v = NULL;
    vt_frame_path(p, sizeof p, dir, view, set, light, mode);
    if (vt_png16_read(p, &fw, &fh, &v, msg, sizeof msg) != 0) {
        fprintf(stderr, "%s\n", msg);
        return NULL;
    }
    if (fw != w || fh != h) {
        fprintf(stderr, "%s: %d x %d, want %d x %d\n", p, fw, fh, w, h);
        free(v);
        return NULL;
    }
    return v;
}

/* Every file of folder a has a byte-identical twin in b; the count. */
static int same_folders(const char *a, const char *b)
{
    DIR *d = opendir(a);
    int n = 0, ok = d != NULL;
    struct dirent *e;
    while (d && (e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.')
            continue;
        char pa[4096], pb[4096];
        snprintf(pa, sizeof pa, "%s/%s", a, e->d_name);
        snprintf(pb, sizeof pb, "%s/%s", b, e->d_name);
        size_t na = 0, nb = 0;
        unsigned char *x = test_read_file(pa, &na), *y = test_read_file(pb, &nb);
        if (!x || !y || na != nb || memcmp(x, y, na) != 0) {
            fprintf(stderr, "%s and %s differ\n", pa, pb);
            ok = 0;
        }
        free(x);
        free(y);
        n++;
    }
    if (d)
        closedir(d);
    return ok ? n : -1;
}

/* ---- box: a shadow whose area geometry gives ---------------------------------------------- */

static int part_box(void)
{
    char *obj = path_in("floorbox.obj"), *vdsh = path_in("floorbox.vdsh");
    write_floor_box(obj);
    if (bake_to((char *[]){obj, NULL}, vdsh, "0.25") != 0) {
        CHECK(0, "bake");
        return test_report("frames_box");
    }
    /* Straight down from 8 above the floor, image up = -z; the light 3
     * above the floor, over the box's centre. */
    const int W = 320, H = 240;
    const double fov = 30.0, eye_h = 8.0, light_h = 3.0;
    char *views = path_in("floorbox.views.json");
    FILE *f = fopen(views, "w");
    fprintf(f,
            "{\"width\": %d, \"height\": %d, \"views\": [{\"name\": \"top\", "
            "\"eye\": [0, %g, 0], \"target\": [0, 0, 0], \"up\": [0, 0, -1], "
            "\"fov_y\": %g, \"light_sets\": [[[0, %g, 0]]]}]}\n",
            W, H, eye_h, fov, light_h);
    fclose(f);
    char *t1 = path_in("truth1"), *t2 = path_in("truth2");
    int rc1 = run((char *[]){(char *)frames, "truth", vdsh, "--views", views, "-o", t1, "--threads",
                             "1", NULL});
    CHECK(rc1 == 0, "truth, 1 thread: exit %d", rc1);
    CHECK(test_file_contains(out_path, "a frame's truth (320 x 240"),
          "the time per frame is printed");
    int rc2 = run((char *[]){(char *)frames, "truth", vdsh, "--views", views, "-o", t2, "--threads",
                             "2", NULL});
    CHECK(rc2 == 0, "truth, 2 threads: exit %d", rc2);
    if (rc1 || rc2) {
        show_stderr();
        return test_report("frames_box");
    }
    /* 3 truth frames, c-vdsh2 and c-vdsh3, two pictures. */
    int n = same_folders(t1, t2);
    CHECK(n == 7, "byte-identical across thread counts: %d files", n);

    /* The shadow: the box's top face projected from the light, a square
     * of half-side .5 * 3 / (3 - 1) = .75, less what the box hides from
     * the eye, a square of half-side .5 * 8 / (8 - 1). A floor seen
     * straight on maps area to pixels uniformly: (f / depth)^2 pixels per
     * unit area, f = (H / 2) / tan(fov / 2). */
    float *hard = frame(t1, "top", 0, 0, "hard", W, H);
    float *mask = frame(t1, "top", 0, 0, "mask", W, H);
    float *ideal = frame(t1, "top", 0, 0, "ideal", W, H);
    CHECK(hard && mask && ideal, "truth frames");
    if (hard && mask && ideal) {
        double fpx = (H / 2.0) / tan(0.5 * fov * M_PI / 180.0);
        double per_floor = (fpx / eye_h) * (fpx / eye_h);
        double per_top = (fpx / (eye_h - 1.0)) * (fpx / (eye_h - 1.0));
        double shadow = 1.5 * 1.5, hidden = pow(2 * 0.5 * eye_h / (eye_h - 1.0), 2);
        double want_dark = (shadow - hidden) * per_floor;
        double want_lit = (16.0 - shadow) * per_floor + 1.0 * per_top;
        long dark = 0, lit = 0, counted = 0, dark_ideal = 0;
        for (int i = 0; i < W * H; i++) {
            if (mask[i] < 0.5f)
                continue;
            counted++;
            dark += hard[i] < 0.5f;
            lit += hard[i] >= 0.5f;
            dark_ideal += ideal[i] < 0.5f;
        }
        printf("box: %ld hard-shadowed pixels (geometry: %.0f), %ld lit (%.0f)\n", dark, want_dark,
               lit, want_lit);
        CHECK(fabs(dark - want_dark) < 0.03 * want_dark, "shadow: %ld pixels, geometry %.1f", dark,
              want_dark);
        CHECK(fabs(lit - want_lit) < 0.01 * want_lit, "lit: %ld pixels, geometry %.1f", lit,
              want_lit);
        /* Every shadowed pixel is at d_T / d_L <= .5 / 3: ideal 0 there. */
        CHECK(dark_ideal == dark, "ideal < .5 exactly where hard: %ld of %ld", dark_ideal, dark);
        CHECK(counted == dark + lit, "mask");
    }
    free(hard);
    free(mask);
    free(ideal);

    /* In process: every primary hit lies on its ray, where the
     * barycentrics put it (the vertices they weigh are the hit
     * triangle's, in Embree's order). An oblique view, so that every
     * face in sight is at a slant. */
    scene3 s;
    if (scene_load(vdsh, obj, &s) == 0) {
        vdsh_camera cam = {.eye = {2.5f, 2.2f, 3.1f}, .target = {0.1f, 0.4f, -0.2f}};
        vb_frames_hits h = {0};
        vb_error err;
        CHECK(vb_frames_trace_primary(s.fs, &cam, 97, 61, 2, &h, &err) == VB_OK, "primary");
        long hits = 0, off = 0;
        for (int y = 0; y < h.height; y++)
            for (int x = 0; x < h.width; x++) {
                size_t i = (size_t)y * h.width + x;
                if (h.triangle[i] == UINT32_MAX)
                    continue;
                float o[3], d[3];
                vdsh_camera_ray(&cam, h.width, h.height, x, y, o, d);
                float e = 0.0f;
                for (int k = 0; k < 3; k++)
                    e = fmaxf(e, fabsf(o[k] + h.depth[i] * d[k] - h.position[3 * i + k]));
                hits++;
                off += e > 1e-4f;
            }
        CHECK(hits > 1000 && off == 0, "%ld of %ld hits off their rays", off, hits);
        vb_frames_hits_free(&h);
    } else {
        CHECK(0, "load the scene in process");
    }
    scene_free(&s);
    return test_report("frames_box");
}

/* ---- the built-in room: views and the oracle --------------------------------------------- */

/* vdsh-frames views of the room: 3 cameras, 160 x 120; rule NULL: no
 * --light-rule. */
static int room_views_rule(const char *vdsh, const char *views, const char *seed,
                           const char *threads, const char *rule)
{
    if (!exists(vdsh) && bake_to((char *[]){"builtin:room", NULL}, vdsh, "1") != 0)
        return -1;
    int rc = run((char *[]){(char *)frames, "views", (char *)vdsh, "-o", (char *)views, "--cameras",
                            "3", "--size", "160x120", "--seed", (char *)seed, "--threads",
                            (char *)threads, rule ? "--light-rule" : NULL, (char *)rule, NULL});
    if (rc != 0)
        show_stderr();
    return rc;
}

static int room_views(const char *vdsh, const char *views, const char *seed, const char *threads)
{
    return room_views_rule(vdsh, views, seed, threads, NULL);
}

static int same_file(const char *a, const char *b)
{
    size_t na = 0, nb = 0;
    unsigned char *x = test_read_file(a, &na), *y = test_read_file(b, &nb);
    int same = x && y && na == nb && memcmp(x, y, na) == 0;
    free(x);
    free(y);
    return same;
}

static int part_views(void)
{
    char *vdsh = path_in("room.vdsh"), *v1 = path_in("a.views.json"), *v2 = path_in("b.views.json"),
         *v3 = path_in("c.views.json");
    CHECK(room_views(vdsh, v1, "5", "2") == 0, "views, seed 5");
    CHECK(room_views(vdsh, v2, "5", "1") == 0, "views, seed 5 again, one thread");
    CHECK(room_views(vdsh, v3, "6", "2") == 0, "views, seed 6");
    size_t n1 = 0, n2 = 0, n3 = 0;
    unsigned char *a = test_read_file(v1, &n1), *b = test_read_file(v2, &n2),
                  *c = test_read_file(v3, &n3);
    CHECK(a && b && n1 == n2 && memcmp(a, b, n1) == 0,
          "the same seed gives the same file (on 1 thread and on 2)");
    CHECK(a && c && (n1 != n3 || memcmp(a, c, n1) != 0), "another seed gives another file");
    free(a);
    free(b);
    free(c);

    /* --light-rule: uniform is the default; near puts every light of
     * every view within 5% of the diagonal of a surface (the rule's own
     * measure, vb_scene_probe_nearest), which uniform's lights are not. */
    char *vu = path_in("uniform.views.json"), *vn = path_in("near.views.json");
    CHECK(room_views_rule(vdsh, vu, "5", "2", "uniform") == 0, "views, --light-rule uniform");
    CHECK(same_file(v1, vu), "--light-rule uniform gives the default's file");
    CHECK(room_views_rule(vdsh, vn, "5", "2", "near") == 0, "views, --light-rule near");
    CHECK(!same_file(v1, vn), "--light-rule near gives another file");

    vt_views V = {0}, N = {0};
    char msg[4300];
    CHECK(vt_views_read(v1, &V, msg, sizeof msg) == 0, "%s", msg);
    CHECK(vt_views_read(vn, &N, msg, sizeof msg) == 0, "%s", msg);
    scene3 s;
    if (V.count && N.count && scene_load(vdsh, "builtin:room", &s) == 0) {
        const float within = 0.05f * s.occ->diagonal;
        int far_uniform = 0;
        CHECK(N.count == V.count, "near: %d views", N.count);
        for (int i = 0; i < N.count && i < V.count; i++)
            for (int k = 0; k < N.views[i].set_count; k++)
                for (int l = 0; l < N.views[i].light_count[k]; l++) {
                    const float *p = N.views[i].lights[k][l];
                    float t = vb_scene_probe_nearest(s.occ, p);
                    CHECK(vb_scene_free_space(s.occ, p) && t < within,
                          "near: view %s, set %d, light %d: a surface %g away (%g is near)",
                          N.views[i].name, k, l, (double)t, (double)within);
                    far_uniform +=
                        !(vb_scene_probe_nearest(s.occ, V.views[i].lights[k][l]) < within);
                }
        CHECK(far_uniform > 0, "uniform: %d lights farther than 5%% of the diagonal", far_uniform);
        CHECK(V.count == 4 && V.width == 160 && V.height == 120, "4 views of 160 x 120");
        CHECK(strcmp(V.views[0].name, "default") == 0, "the default view first");
        /* The viewer's default camera for a room: from inside, along x. */
        const float *e = V.views[0].camera.eye;
        CHECK(fabsf(e[0] - 0.36f * 19.0f) < 1e-3f && fabsf(e[1] - 0.28f * 6.0f) < 1e-3f &&
                  fabsf(e[2] - 0.05f * 19.0f) < 1e-3f,
              "default eye (%g, %g, %g)", (double)e[0], (double)e[1], (double)e[2]);
        for (int i = 0; i < V.count; i++) {
            const vt_view *v = V.views + i;
            CHECK(v->set_count == 2 && v->light_count[0] == 1 && v->light_count[1] == 3,
                  "view %s: sets of 1 and 3 lights", v->name);
            if (i > 0)
                CHECK(vb_scene_free_space(s.occ, v->camera.eye), "view %s: eye in free space",
                      v->name);
            for (int k = 0; k < v->set_count; k++)
                for (int l = 0; l < v->light_count[k]; l++)
                    CHECK(vb_scene_free_space(s.occ, v->lights[k][l]),
                          "view %s: light %d of set %d in free space", v->name, l, k);
            if (i == 0)
                continue;
            /* No surface nearer than 5% of the diagonal (checked at 64 x
             * 48: a little less at full size), and each light lights and
             * shadows a share of the view (5% at 64 x 48). */
            vb_frames_hits h = {0};
            vb_error err;
            if (vb_frames_trace_primary(s.fs, &v->camera, V.width, V.height, 0, &h, &err)) {
                CHECK(0, "%s", err.msg);
                continue;
            }
            float near = INFINITY;
            for (int p = 0; p < V.width * V.height; p++)
                near = fminf(near, h.depth[p]);
            CHECK(near >= 0.04f * s.fs->diagonal, "view %s: a surface %g away", v->name,
                  (double)near);
            for (int k = 0; k < v->set_count; k++)
                for (int l = 0; l < v->light_count[k]; l++) {
                    vb_frames_light L = {0};
                    vb_frames_trace_light(s.fs, &h, v->lights[k][l], 0, 0, &L, &err);
                    int lit = 0, dark = 0;
                    for (int p = 0; p < V.width * V.height; p++)
                        if (L.mask[p] >= 0.5f) {
                            lit += L.hard[p] >= 0.5f;
                            dark += L.hard[p] < 0.5f;
                        }
                    double n = V.width * V.height;
                    CHECK(lit >= 0.03 * n && dark >= 0.03 * n,
                          "view %s, set %d, light %d: %.1f%% lit, %.1f%% shadowed", v->name, k, l,
                          100.0 * lit / n, 100.0 * dark / n);
                    vb_frames_light_free(&L);
                }
            vb_frames_hits_free(&h);
        }
        scene_free(&s);
    } else {
        CHECK(0, "read the views and the scene");
    }
    vt_views_free(&V);
    vt_views_free(&N);
    return test_report("frames_views");
}

static const cJSON *mode_scene(const cJSON *root, const char *mode)
{
    const cJSON *m;
    cJSON_ArrayForEach(m, cJSON_GetObjectItemCaseSensitive(root, "modes"))
    {
        const cJSON *name = cJSON_GetObjectItemCaseSensitive(m, "mode");
        if (cJSON_IsString(name) && strcmp(name->valuestring, mode) == 0)
            return cJSON_GetObjectItemCaseSensitive(m, "scene");
    }
    return NULL;
}

/* vdsh-frames truth of `vdsh` for the view set into `truth`, then its
 * score with the truth as the frames of `modes` into `json`: that JSON,
 * read back; NULL (and a failed check) when a step fails. */
static cJSON *truth_and_score(char *vdsh, char *views, char *truth, char *modes, char *json)
{
    int rc = run((char *[]){(char *)frames, "truth", vdsh, "--views", views, "-o", truth, NULL});
    CHECK(rc == 0, "truth: exit %d", rc);
    rc = run((char *[]){(char *)frames, "score", vdsh, "--views", views, "--truth", truth,
                        "--frames", truth, "--modes", modes, "--json", json, NULL});
    CHECK(rc == 0, "score: exit %d", rc);
    if (rc)
        show_stderr();
    char msg[4300];
    return rc == 0 ? vt_json_read_file(json, msg, sizeof msg) : NULL;
}

static int part_oracle(void)
{
    char *vdsh = path_in("room.vdsh"), *views = path_in("room.views.json"),
         *truth = path_in("truth"), *json = path_in("oracle.json");
    if (room_views(vdsh, views, "1", "2") != 0) {
        CHECK(0, "views");
        return test_report("frames_oracle");
    }
    cJSON *j = truth_and_score(vdsh, views, truth, "ideal,hard,c-vdsh3", json);
    const cJSON *id = mode_scene(j, "ideal"), *hd = mode_scene(j, "hard"),
                *c3 = mode_scene(j, "c-vdsh3");
    CHECK(id && hd && c3, "the JSON has every mode's scene");
    if (id && hd && c3) {
        /* 4 views x (1 + 3) lights; real shadows and lit pixels to count. */
        CHECK(vt_json_number(id, "frames") == 16, "frames %g", vt_json_number(id, "frames"));
        double shadowed = vt_json_number(id, "shadowed"), lit = vt_json_number(id, "lit");
        CHECK(shadowed > 1000 && lit > 1000, "shadowed %g, lit %g", shadowed, lit);
        CHECK(vt_json_number(id, "rmse_ideal") == 0.0 && vt_json_number(id, "recall") == 1.0 &&
                  vt_json_number(id, "false_area") == 0.0 && vt_json_number(id, "blotches") == 0.0,
              "ideal as a method: rmse %g recall %g false %g", vt_json_number(id, "rmse_ideal"),
              vt_json_number(id, "recall"), vt_json_number(id, "false_area"));
        /* PSNR of no error is +inf, written as null. */
        CHECK(cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(id, "psnr_ideal")), "psnr null");
        CHECK(vt_json_number(hd, "rmse_hard") == 0.0 && vt_json_number(hd, "recall") == 1.0 &&
                  vt_json_number(hd, "false_area") == 0.0 && vt_json_number(hd, "blotches") == 0.0,
              "hard as a method: rmse %g recall %g false %g", vt_json_number(hd, "rmse_hard"),
              vt_json_number(hd, "recall"), vt_json_number(hd, "false_area"));
        /* ideal differs from hard (lights near occluders ramp). */
        CHECK(vt_json_number(hd, "rmse_ideal") > 0.0, "hard vs ideal differ");
        /* The order-3 stream of a 64-ray bake is not the truth. */
        double r3 = vt_json_number(c3, "rmse_ideal");
        CHECK(r3 > 0.0 && r3 < 1.0, "c-vdsh3 rmse %g", r3);
    }
    cJSON_Delete(j);
    return test_report("frames_oracle");
}

/* ---- orders: orders above 5 and a variable-order stream ------------------------------------- */

/* A copy of file f with one more stream: the variable-order stream (f32,
 * scale 1) whose vertex v has order orders[v] and the coefficients of f's
 * fixed stream of that order, to `out`. 0 on success. */
static int write_variable(const vdsh_file *f, const uint8_t *orders, uint32_t cap, const char *out)
{
    const uint32_t rows = vdsh_file_stream_vertices(f), nc = cap * cap;
    float *src = calloc((size_t)rows * nc, sizeof *src);
    uint32_t *offsets = malloc((rows + 1) * sizeof *offsets);
    vdsh_stream *streams = calloc(f->stream_count + 1, sizeof *streams);
    float scales[VDSH_MAX_COEFFS], c[VDSH_MAX_COEFFS];
    void *data = NULL;
    int rc = -1;
    if (!src || !offsets || !streams)
        goto done;
    const vdsh_stream *base = NULL;
    for (uint32_t v = 0; v < rows; v++) {
        const vdsh_stream *st = vdsh_find_stream(f, orders[v], VDSH_QUANTITY_LOG_DISTANCE);
        if (!st) {
            fprintf(stderr, "%s: no log-distance stream of order %u\n", out, orders[v]);
            goto done;
        }
        base = base ? base : st;
        vdsh_stream_decode(st, v, c);
        memcpy(src + (size_t)v * nc, c, (size_t)orders[v] * orders[v] * sizeof *c);
    }
    vdsh_stream_offsets(orders, rows, VDSH_ENCODING_F32, offsets);
    data = malloc(4 * (size_t)offsets[rows] + 4);
    if (!data || vdsh_encode_variable(VDSH_ENCODING_F32, src, nc, orders, rows, cap, 1.0f, offsets,
                                      scales, data) != VDSH_OK)
        goto done;
    memcpy(streams, f->streams, f->stream_count * sizeof *streams);
    vdsh_stream *vs = &streams[f->stream_count];
    *vs = *base;
    vs->order = cap;
    vs->encoding = VDSH_ENCODING_F32;
    vs->scale = 1.0f;
    vs->data = data;
    vs->coef_scales = NULL;
    vs->flags = VDSH_STREAM_VARIABLE;
    vs->orders = orders;
    vs->offsets = offsets;
    /* What the file will hold decodes to the fixed streams' values. */
    float d[VDSH_MAX_COEFFS];
    int same = 1;
    for (uint32_t v = 0; v < rows; v++) {
        vdsh_stream_decode(vs, v, d);
        same &= memcmp(d, src + (size_t)v * nc, nc * sizeof *d) == 0;
    }
    CHECK(same, "the variable stream decodes to the fixed streams' coefficients");
    vdsh_file g = *f;
    g.streams = streams;
    g.stream_count = f->stream_count + 1;
    vdsh_error ve;
    rc = vdsh_write(out, &g, &ve) == VDSH_OK ? 0 : -1;
    if (rc)
        fprintf(stderr, "%s: %s\n", out, ve.msg);
done:
    free(src);
    free(offsets);
    free(streams);
    free(data);
    return rc;
}

/* c-vdsh-var of a stream whose every vertex has order 7 scores exactly as
 * c-vdsh7 and draws the same frames; with orders 3 and 7 mixed, a
 * triangle of order-3 vertices draws as c-vdsh3 and one of order-7
 * vertices as c-vdsh7 (each vertex takes its own order). */
static int part_orders(void)
{
    char *fixed = path_in("room37.vdsh"), *all7 = path_in("room-all7.vdsh"),
         *mixed = path_in("room-mixed.vdsh"), *views = path_in("room.views.json"),
         *truth = path_in("truth"), *json = path_in("orders.json");
    int rc = run((char *[]){(char *)bake, "builtin:room", "--max-edge", "1", "--rays", "64",
                            "--orders", "3,7", "--cube-size", "0", "-q", "-o", fixed, NULL});
    CHECK(rc == 0, "bake orders 3,7: exit %d", rc);
    if (rc) {
        show_stderr();
        return test_report("frames_orders");
    }
    vdsh_file *f = NULL;
    vdsh_error ve;
    CHECK(vdsh_read(fixed, &f, &ve) == VDSH_OK, "%s", ve.msg);
    if (!f)
        return test_report("frames_orders");
    const uint32_t rows = vdsh_file_stream_vertices(f);
    uint8_t *o7 = malloc(rows), *o37 = malloc(rows);
    float mid = 0.0f;
    for (uint32_t v = 0; v < rows; v++)
        mid += f->positions[3 * v] / (float)rows;
    for (uint32_t v = 0; v < rows; v++) {
        o7[v] = 7;
        o37[v] = f->positions[3 * v] < mid ? 3 : 7;
    }
    CHECK(write_variable(f, o7, 7, all7) == 0, "write %s", all7);
    CHECK(write_variable(f, o37, 7, mixed) == 0, "write %s", mixed);
    CHECK(room_views(all7, views, "1", "2") == 0, "views");

    /* All order 7: the same scores and frames as the fixed stream. */
    cJSON *j = truth_and_score(all7, views, truth, "c-vdsh3,c-vdsh7,c-vdsh-var", json);
    char msg[4300];
    const cJSON *c3 = mode_scene(j, "c-vdsh3"), *c7 = mode_scene(j, "c-vdsh7"),
                *cv = mode_scene(j, "c-vdsh-var");
    CHECK(c3 && c7 && cv, "the JSON has every mode's scene");
    if (c3 && c7 && cv) {
        const char *keys[] = {"rmse_ideal", "rmse_hard", "recall",   "false_area",
                              "shadowed",   "lit",       "blotches", "blotch_area"};
        for (size_t k = 0; k < sizeof keys / sizeof *keys; k++)
            CHECK(vt_json_number(c7, keys[k]) == vt_json_number(cv, keys[k]) ||
                      (isnan(vt_json_number(c7, keys[k])) && isnan(vt_json_number(cv, keys[k]))),
                  "%s: c-vdsh7 %g, c-vdsh-var %g", keys[k], vt_json_number(c7, keys[k]),
                  vt_json_number(cv, keys[k]));
        double r7 = vt_json_number(c7, "rmse_ideal"), r3 = vt_json_number(c3, "rmse_ideal");
        CHECK(r7 > 0.0 && r7 < 1.0 && r3 > 0.0 && r3 != r7, "rmse c-vdsh3 %g c-vdsh7 %g", r3, r7);
    }
    cJSON_Delete(j);
    vt_views V = {0};
    CHECK(vt_views_read(views, &V, msg, sizeof msg) == 0, "%s", msg);
    int frames_same = V.count > 0;
    for (int vi = 0; vi < V.count; vi++) {
        float *a = frame(truth, V.views[vi].name, 0, 0, "c-vdsh7", V.width, V.height);
        float *b = frame(truth, V.views[vi].name, 0, 0, "c-vdsh-var", V.width, V.height);
        frames_same &= a && b && memcmp(a, b, sizeof *a * V.width * V.height) == 0;
        free(a);
        free(b);
    }
    CHECK(frames_same, "c-vdsh-var's frames are c-vdsh7's");

    /* Mixed orders, in this process: per triangle, its vertices' order. */
    scene3 S;
    if (V.count > 0 && scene_load(mixed, "builtin:room", &S) == 0) {
        const size_t n = (size_t)V.width * V.height;
        float *s3 = malloc(n * sizeof *s3), *s7 = malloc(n * sizeof *s7),
              *sv = malloc(n * sizeof *sv);
        uint32_t i3 = UINT32_MAX, i7 = UINT32_MAX, iv = UINT32_MAX;
        for (uint32_t s = 0; s < S.f->stream_count; s++) {
            const vdsh_stream *st = &S.f->streams[s];
            if (st->flags & VDSH_STREAM_VARIABLE)
                iv = s;
            else if (st->order == 3)
                i3 = s;
            else if (st->order == 7)
                i7 = s;
        }
        vb_frames_hits h = {0};
        vb_error err;
        uint64_t pure3 = 0, pure7 = 0, bad = 0;
        for (int vi = 0; vi < V.count && iv != UINT32_MAX; vi++) {
            const float *L = V.views[vi].lights[0][0];
            if (vb_frames_trace_primary(S.fs, &V.views[vi].camera, V.width, V.height, 0, &h,
                                        &err) != VB_OK ||
                vb_frames_eval_stream(S.fs, &h, i3, L, VDSH_COMPARE_SMOOTH, 0, s3, &err) ||
                vb_frames_eval_stream(S.fs, &h, i7, L, VDSH_COMPARE_SMOOTH, 0, s7, &err) ||
                vb_frames_eval_stream(S.fs, &h, iv, L, VDSH_COMPARE_SMOOTH, 0, sv, &err)) {
                CHECK(0, "%s", err.msg);
                break;
            }
            for (size_t i = 0; i < n; i++) {
                if (h.triangle[i] == UINT32_MAX)
                    continue;
                const uint32_t *ix = S.f->indices + 3 * (size_t)h.triangle[i];
                int k3 = o37[ix[0]] == 3 && o37[ix[1]] == 3 && o37[ix[2]] == 3;
                int k7 = o37[ix[0]] == 7 && o37[ix[1]] == 7 && o37[ix[2]] == 7;
                pure3 += k3;
                pure7 += k7;
                bad += (k3 && sv[i] != s3[i]) || (k7 && sv[i] != s7[i]);
            }
            vb_frames_hits_free(&h);
        }
        CHECK(iv != UINT32_MAX && i3 != UINT32_MAX && i7 != UINT32_MAX, "streams found");
        CHECK(pure3 > 100 && pure7 > 100 && bad == 0,
              "mixed orders: %llu order-3 pixels, %llu order-7, %llu not their order's",
              (unsigned long long)pure3, (unsigned long long)pure7, (unsigned long long)bad);
        free(s3);
        free(s7);
        free(sv);
        scene_free(&S);
    } else {
        CHECK(0, "load %s", mixed);
    }
    vt_views_free(&V);
    free(o7);
    free(o37);
    vdsh_free(f);
    return test_report("frames_orders");
}

/* ---- errors ---------------------------------------------------------------------------------- */

static int part_errors(void)
{
    char *fr = (char *)frames;
    CHECK(run((char *[]){fr, "--help", NULL}) == 0 && test_file_contains(out_path, "c-vdshN") &&
              test_file_contains(out_path, "blotches") && test_file_contains(out_path, "--compare"),
          "--help documents the frames and the scores");
    CHECK(run((char *[]){fr, "--version", NULL}) == 0 &&
              test_file_contains(out_path, "vdsh-frames "),
          "--version");
    CHECK(run((char *[]){fr, NULL}) == 2 && test_file_contains(err_path, "no subcommand"), "none");
    CHECK(run((char *[]){fr, "paint", NULL}) == 2 && test_file_contains(err_path, "'paint'"),
          "unknown");
    CHECK(run((char *[]){fr, "views", "x.vdsh", NULL}) == 2 && test_file_contains(err_path, "-o"),
          "views without -o");
    CHECK(run((char *[]){fr, "views", "x.vdsh", "-o", "v.json", "--cameras", "0", NULL}) == 2 &&
              test_file_contains(err_path, "--cameras"),
          "--cameras 0");
    CHECK(run((char *[]){fr, "views", "x.vdsh", "-o", "v.json", "--size", "160x", NULL}) == 2 &&
              test_file_contains(err_path, "--size"),
          "--size 160x");
    CHECK(run((char *[]){fr, "truth", "x.vdsh", "--views", "v", "-o", "d", "--threads", "0",
                         NULL}) == 2 &&
              test_file_contains(err_path, "--threads"),
          "--threads 0");
    CHECK(run((char *[]){fr, "truth", "x.vdsh", "--views", "v", "-o", "d", "--compare", "soft",
                         NULL}) == 2,
          "--compare soft");
    CHECK(run((char *[]){fr, "truth", "x.vdsh", "y.vdsh", "--views", "v", "-o", "d", NULL}) == 2,
          "two scenes");
    CHECK(run((char *[]){fr, "score", "x.vdsh", "--views", "v", "--truth", "t", "--frames", "f",
                         "--modes", "vdsh5,,cube", NULL}) == 2 &&
              test_file_contains(err_path, "--modes"),
          "an empty mode");
    CHECK(run((char *[]){fr, "score", "x.vdsh", "--views", "v", "--truth", "t", "--frames", "f",
                         NULL}) == 2,
          "no modes");
    CHECK(run((char *[]){fr, "views", "x.vdsh", "-o", "v.json", "--light-rule", "nearby", NULL}) ==
                  2 &&
              test_file_contains(err_path, "--light-rule") &&
              test_file_contains(err_path, "nearby"),
          "views --light-rule nearby");
    CHECK(run((char *[]){fr, "views", "x.vdsh", "-o", "v.json", "--bogus", NULL}) == 2,
          "an unknown option");

    char *obj = path_in("floorbox.obj"), *vdsh = path_in("floorbox.vdsh");
    write_floor_box(obj);
    if (bake_to((char *[]){obj, NULL}, vdsh, "0.5") != 0) {
        CHECK(0, "bake");
        return test_report("frames_errors");
    }
    /* A lone quad casts no shadow: no view is found, and the message
     * says a seed would not help (it advised one). */
    char *qobj = path_in("quad.obj"), *qvdsh = path_in("quad.vdsh");
    FILE *qf = fopen(qobj, "w");
    fprintf(qf, "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 2 3\nf 1 3 4\n");
    fclose(qf);
    CHECK(bake_to((char *[]){qobj, NULL}, qvdsh, "0.2") == 0 &&
              run((char *[]){fr, "views", qvdsh, "-o", path_in("q.json"), "--cameras", "2",
                             NULL}) == 1 &&
              test_file_contains(err_path, "found 0 of 2") &&
              test_file_contains(err_path, "no seed changes") &&
              !test_file_contains(err_path, "try another seed"),
          "a scene with no shadow: no seed advised");

    char *missing = path_in("no-such.vdsh"), *nov = path_in("no-such.views.json"),
         *bad = path_in("bad.views.json"), *views = path_in("ok.views.json"),
         *truth = path_in("truth"), *json = path_in("score.json");
    CHECK(run((char *[]){fr, "views", missing, "-o", path_in("v.json"), NULL}) == 1 &&
              test_file_contains(err_path, "no-such.vdsh"),
          "a missing scene is named");
    CHECK(run((char *[]){fr, "truth", vdsh, "--views", nov, "-o", truth, NULL}) == 1 &&
              test_file_contains(err_path, "no-such.views.json") && !exists(truth),
          "a missing view set is named, nothing written");
    FILE *f = fopen(bad, "w");
    fprintf(f, "{\"width\": 64, \"height\": 48, \"views\": [{\"name\": \"a b\"}]}\n");
    fclose(f);
    CHECK(run((char *[]){fr, "truth", vdsh, "--views", bad, "-o", truth, NULL}) == 1 &&
              test_file_contains(err_path, "bad.views.json") &&
              test_file_contains(err_path, "name"),
          "an invalid view set is named with its field");
    f = fopen(views, "w");
    fprintf(f,
            "{\"width\": 64, \"height\": 48, \"views\": [{\"name\": \"a\", \"eye\": [0, 3, 3], "
            "\"target\": [0, 0, 0], \"light_sets\": [[[0, 3, 0]], [[1, 2, 0], [-1, 2, 0]]]}]}\n");
    fclose(f);
    int rc = run((char *[]){fr, "truth", vdsh, "--views", views, "-o", truth, NULL});
    CHECK(rc == 0, "truth: exit %d", rc);
    if (rc)
        show_stderr();
    /* The truth is there and scores; then break it one way at a time. */
    CHECK(run((char *[]){fr, "score", vdsh, "--views", views, "--truth", truth, "--frames", truth,
                         "--modes", "c-vdsh2", "--json", json, NULL}) == 0 &&
              exists(json),
          "score");
    unlink(json);
    CHECK(run((char *[]){fr, "score", vdsh, "--views", views, "--truth", truth, "--frames", truth,
                         "--modes", "c-vdsh2,vdsh5", "--json", json, NULL}) == 1 &&
              test_file_contains(err_path, "a-s0-l0-vdsh5.png") &&
              test_file_contains(err_path, "missing") && !exists(json),
          "a missing frame is named, no JSON written");
    char other[4096];
    vt_frame_path(other, sizeof other, truth, "a", 1, 1, "c-vdsh3");
    float small[32 * 24] = {0};
    char msg[4300];
    CHECK(vt_png16_write(other, 32, 24, small, msg, sizeof msg) == 0, "%s", msg);
    CHECK(run((char *[]){fr, "score", vdsh, "--views", views, "--truth", truth, "--frames", truth,
                         "--modes", "c-vdsh3", "--json", json, NULL}) == 1 &&
              test_file_contains(err_path, "a-s1-l1-c-vdsh3.png") &&
              test_file_contains(err_path, "32 x 24") && !exists(json),
          "a frame of another size is named");
    /* An RGBA picture where a frame should be: refused, not read as grey
     * (its alpha composited onto black, its samples decoded as sRGB). */
    {
        static uint8_t rgba[64 * 48 * 4];
        memset(rgba, 200, sizeof rgba);
        CHECK(vt_png_rgba_write(other, 64, 48, rgba, msg, sizeof msg) == 0, "%s", msg);
        CHECK(run((char *[]){fr, "score", vdsh, "--views", views, "--truth", truth, "--frames",
                             truth, "--modes", "c-vdsh3", "--json", json, NULL}) == 1 &&
                  test_file_contains(err_path, "a-s1-l1-c-vdsh3.png: an RGBA PNG, not a frame") &&
                  !exists(json),
              "an RGBA frame is refused, named");
    }
    char mask[4096];
    vt_frame_path(mask, sizeof mask, truth, "a", 0, 0, "mask");
    f = fopen(mask, "w");
    fputs("not a PNG", f);
    fclose(f);
    CHECK(run((char *[]){fr, "score", vdsh, "--views", views, "--truth", truth, "--frames", truth,
                         "--modes", "c-vdsh2", NULL}) == 1 &&
              test_file_contains(err_path, "a-s0-l0-mask.png"),
          "a broken truth frame is named");
    /* A file where the output folder should be. */
    CHECK(run((char *[]){fr, "truth", vdsh, "--views", views, "-o", obj, NULL}) == 1 &&
              test_file_contains(err_path, "floorbox.obj"),
          "an output folder that is a file");
    return test_report("frames_errors");
}

static int remove_one(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st, (void)flag, (void)ftw;
    return remove(path);
}

int main(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "score") == 0)
        return part_score();
    if (argc != 5) {
        fprintf(stderr, "usage: test_frames score | PART VDSH_BAKE VDSH_FRAMES WORK_DIR\n");
        return 2;
    }
    bake = argv[2];
    frames = argv[3];
    work = argv[4];
    /* A fresh folder: nothing left from an earlier run can pass a check. */
    nftw(work, remove_one, 16, FTW_DEPTH | FTW_PHYS);
    mkdir(work, 0755);
    snprintf(out_path, sizeof out_path, "%s/stdout.txt", work);
    snprintf(err_path, sizeof err_path, "%s/stderr.txt", work);
    if (strcmp(argv[1], "oracle") == 0)
        return part_oracle();
    if (strcmp(argv[1], "box") == 0)
        return part_box();
    if (strcmp(argv[1], "orders") == 0)
        return part_orders();
    if (strcmp(argv[1], "views") == 0)
        return part_views();
    if (strcmp(argv[1], "errors") == 0)
        return part_errors();
    fprintf(stderr, "unknown part '%s'\n", argv[1]);
    return 2;
}
