/*
 * vdsh-frames - what a viewer sees: ray-traced truth for frames, and the
 * image error of any frames against it (docs/DESIGN.md §3, "Image
 * error"). Three subcommands:
 *
 *   views  choose a view set for a scene (tools/vt_views.h): the viewer's
 *          default camera, then cameras in the scene's free space looking
 *          at surfaces that are lit and shadowed, each with a set of one
 *          light and a set of three (frames.h says how they are chosen)
 *   truth  trace every view, light set and light: hard, ideal, mask and
 *          the file's streams computed in C on the runtime's path, as
 *          16-bit frames NAME-sK-lJ-MODE.png, and shaded pictures
 *   score  score frames (GL frames of vdsh-view, or the C frames) against
 *          the truth: per frame, per light set, per scene
 *
 * The story of each is its cmd_ function: read, compute with the core
 * (bake/frames.h), write atomically, print.
 */
#include <dirent.h>
#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bake.h"
#include "eval.h"
#include "frames.h"
#include "parallel.h"
#include "scene.h"
#include "vdsh.h"
#include "vdsh_sdf.h"
#include "vdsh_shadow.h"
#include "vt_args.h"
#include "vt_cli.h"
#include "vt_image.h"
#include "vt_json.h"
#include "vt_views.h"

#define PROG "vdsh-frames"
#define MAX_MODES 32

static void usage(FILE *f)
{
    fprintf(f,
            "usage: vdsh-frames views SCENE.vdsh -o VIEWS.json [options]\n"
            "       vdsh-frames truth SCENE.vdsh --views VIEWS.json -o DIR [options]\n"
            "       vdsh-frames score SCENE.vdsh --views VIEWS.json --truth DIR --frames DIR2\n"
            "                         --modes LIST [--json OUT.json]\n"
            "What a viewer sees: ray-traced truth for frames, and image error against it.\n"
            "\n"
            "The scene is rebuilt as vdsh-eval does: the occluders from the sources\n"
            "recorded in SCENE.vdsh (looked up as recorded, then beside the file; each\n"
            "must have the SHA-256 the bake recorded), the receivers (what the GL\n"
            "draws) from the file's own positions and triangles.\n"
            "\n"
            "views: a view set (JSON, tools/vt_views.h) for the scene. View 'default'\n"
            "  is the camera vdsh-view opens the scene with; views v1..vN look from\n"
            "  eyes in the scene's free space (the rule for lights: formats/\n"
            "  vdsh_light.h) at a surface point they see, between 53 degrees below the\n"
            "  horizon and 12 above, and are kept when a 64-pixel-wide frame shows no\n"
            "  surface nearer than 5%% of the diagonal and each of its lights lights\n"
            "  at least 5%% of the frame's pixels and hard-shadows as many. Every view\n"
            "  gets light set 0 (one light) and set 1 (three), drawn from 128 lights\n"
            "  placed in free space (vdsh-eval's rule; --light-rule); the default view\n"
            "  takes the best it can get. Deterministic for a seed.\n"
            "  -o, --output FILE       the view set to write\n"
            "      --cameras N         views besides the default (default 6)\n"
            "      --seed N            seed of the eyes, directions and lights (default 1)\n"
            "      --size WxH          frame size recorded in the set (default 512x384)\n"
            "      --light-rule R      where the 128 lights go, all in free space (vdsh-eval's\n"
            "                          --light-rule; the eyes stay where they were):\n"
            "                          uniform (default), ceiling (the top fifth of the\n"
            "                          height, +y up), near (a surface within 5%% of the\n"
            "                          diagonal), path (a walk along x at 2/3 of the\n"
            "                          height), grown (the bounds grown by a quarter of\n"
            "                          their diagonal), around (grown by a diagonal,\n"
            "                          outside the bounds) or shell (grown by a quarter\n"
            "                          diagonal, outside the bounds); grown, around and\n"
            "                          shell not below an open floor (nor past any side a\n"
            "                          one-sided surface closes)\n"
            "      --light-region SPEC the light region of the eyes and of uniform,\n"
            "                          ceiling, near and path (vdsh-eval's): file\n"
            "                          (default: the bake's --light-region, recorded in\n"
            "                          the file, else auto), auto (the scene's rule),\n"
            "                          grown (vdsh-bake's) or a box\n"
            "                          XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX (truth and score\n"
            "                          take none: the view set holds the lights)\n"
            "\n"
            "truth: for every view, light set K and light J, frames DIR/NAME-sK-lJ-MODE.png\n"
            "  (16-bit grey, value round(v * 65535)), MODE:\n"
            "    hard     1 light visible, 0 blocked: the first hit toward the light\n"
            "             from the surface point (offset toward the camera) against the\n"
            "             occluders, d_T, against the light's distance d_L\n"
            "    ideal    ramp(d_T / d_L), ramp(x) = saturate((x - 1/3) * 1.5): the\n"
            "             exact distance through the runtime's comparison (--compare)\n"
            "    mask     1 where the pixel counts: a triangle is hit and its\n"
            "             interpolated normal faces the light (N . L > 0)\n"
            "    c-vdshN  the file's stream of order N (1..%d), computed in C exactly\n"
            "             on the runtime's path (formats/vdsh_shadow.h: vdsh_shadow_interior\n"
            "             with the triangle's vertices and barycentrics; log distance,\n"
            "             what method shadow bakes: each vertex's distance, interpolated)\n"
            "    c-vdsh-var  the file's variable-order stream (each vertex its own\n"
            "             order), on the per-vertex distance path\n"
            "    c-sdf    distance-field shadows when the scene has a distance volume\n"
            "             (SCENE.sdf beside it, vdsh-bake --sdf N; or --sdf FILE):\n"
            "             formats/vdsh_sdf.h's sphere trace, what vdsh-view's mode sdf\n"
            "             draws\n"
            "  Pixels that meet nothing hold 1 (mask 0). Primary rays go through pixel\n"
            "  centres (formats/vdsh_camera.h, the camera the runtime projects with)\n"
            "  and meet the receiver mesh; normals are interpolated as the GPU does.\n"
            "  Also DIR/NAME-sK-shaded-hard.png and -shaded-ideal.png: 8-bit RGBA\n"
            "  pictures of the set with the runtime's colour output: albedo 0.8 x\n"
            "  (ambient 0.03 + sum of 1.6 / (1 + 0.6 (n - 1)) x max(N . l, 0) /\n"
            "  (1 + d^2 / r^2) x shadow), r = 0.3 x the scene's diagonal, n lights.\n"
            "  Prints the time of each pass; a frame's truth is the primary pass plus\n"
            "  one light's shadow pass. DIR gets the whole truth or none of it: the\n"
            "  frames are written into DIR.tmp.XXXXXX beside it (removed on failure\n"
            "  or SIGINT/SIGTERM/SIGHUP; only a SIGKILL leaves it), then that folder\n"
            "  becomes DIR, or its frames replace their namesakes in DIR.\n"
            "      --views FILE        the view set\n"
            "  -o, --output DIR        where the frames go (created if missing)\n"
            "      --compare C         smooth (default, the paper's ramp) or binary,\n"
            "                          for ideal and the c-vdshN frames\n"
            "      --sdf FILE          the distance volume for c-sdf (default SCENE.sdf,\n"
            "                          when it exists)\n"
            "      --sdf-k K           c-sdf's softness (default 400, as vdsh-view's);\n"
            "                          an error when the scene has no volume\n"
            "\n"
            "score: reads the truth (hard, ideal, mask from --truth DIR) and the frames\n"
            "  of each mode in LIST (comma-separated: vdsh-view's modes cube, cube-pcf,\n"
            "  vdsh2, vdsh3, vdsh5, vdsh5poly, or c-vdshN, c-vdsh-var, or hard and ideal\n"
            "  themselves) from --frames DIR2, with the same names (greyscale PNG,\n"
            "  16-bit, or 8-bit read as sample / 255; colour or alpha is refused), and\n"
            "  scores each frame over its mask pixels; a light set pools its lights'\n"
            "  frames and the scene pools everything:\n"
            "    RMSE, PSNR   against ideal and against hard (PSNR peak 1; inf: equal)\n"
            "    recall       of the pixels with hard = 0 and ideal < .5, the share\n"
            "                 drawn at s < .5\n"
            "    false        false-shadow area: of the pixels with hard = 1, the share\n"
            "                 drawn at s < .5\n"
            "    blotches     4-connected regions of false shadow larger than 0.05%%\n"
            "                 of the frame's pixels: their count and area (share of\n"
            "                 the frames' pixels)\n"
            "  A missing frame or one of another size is an error naming the file.\n"
            "      --views FILE        the view set the frames were made for\n"
            "      --truth DIR         vdsh-frames truth's output\n"
            "      --frames DIR2       the frames to score (may be DIR itself)\n"
            "      --modes LIST        the modes to score\n"
            "      --json FILE         everything as JSON (each frame too: per_frame; -:\n"
            "                          on stdout, instead of the table)\n"
            "\n"
            "Common options:\n"
            "      --threads N         worker threads (default: all cores); the output\n"
            "                          does not depend on it\n"
            "  -q, --quiet             nothing on stderr but errors, and no table on\n"
            "                          stdout\n"
            "  -h, --help              this text\n"
            "  -V, --version           version\n"
            "\n"
            "Exit status: 0 success, 1 error, 2 usage error.\n"
            "Example: vdsh-bake builtin:room --max-edge 0.2 -o room.vdsh\n"
            "         vdsh-frames views room.vdsh -o room.views.json\n"
            "         vdsh-frames truth room.vdsh --views room.views.json -o frames\n"
            "         vdsh-frames score room.vdsh --views room.views.json --truth frames \\\n"
            "             --frames frames --modes c-vdsh2,c-vdsh3,c-vdsh5\n",
            VDSH_MAX_ORDER);
}

static int bad_usage(const char *fmt, const char *arg)
{
    return vt_usage_error(PROG, fmt, arg);
}

/* ---- what every subcommand shares -------------------------------------------------- */

/* The command line of every subcommand (parse_args, at the end). */
typedef struct options {
    int (*run)(const struct options *); /* the subcommand's */
    const char *path;                   /* SCENE.vdsh */
    unsigned threads;                   /* --threads; 0: every core */
    int quiet;
    const char *output;                /* -o: views' VIEWS.json, truth's DIR */
    vb_frames_views_desc views;        /* views: --cameras, --seed, --size, --light-rule */
    const char *views_path;            /* truth, score: --views */
    uint32_t compare;                  /* truth: --compare */
    const char *sdf;                   /* truth: --sdf */
    float sdf_k;                       /* truth: --sdf-k */
    int sdf_k_given;                   /* --sdf-k on the command line */
    vdsh_light_box light_region;       /* views: --light-region (vb_scene_use_light_box) */
    const char *truth, *frames, *json; /* score */
    char modes[MAX_MODES][64];         /* score: --modes */
    int mode_count;
} options;

/* The scene: the file, its occluders and the receiver scene. */
typedef struct loaded {
    vdsh_file *f;
    vb_scene *occ;
    vb_frames_scene *fs;
} loaded;

static void loaded_free(loaded *l)
{
    vb_frames_scene_destroy(l->fs);
    vb_scene_destroy(l->occ);
    vdsh_free(l->f);
    memset(l, 0, sizeof *l);
}

/* The scene of `path`; with `traced`, its occluders from the recorded
 * sources, which must not be `output` (the file the caller will write;
 * NULL: none): they are inputs too. */
static int load_scene(const char *path, unsigned threads, int traced, const char *output,
                      loaded *out)
{
    loaded l = {0};
    vb_error err;
    l.f = vt_read_whole(path);
    if (!l.f)
        return -1;
    if (!traced) {
        *out = l;
        return 0;
    }
    char **spath = calloc(l.f->source_count + 1, sizeof *spath);
    int rc = -1;
    if (!spath) {
        fprintf(stderr, PROG ": out of memory\n");
        goto done;
    }
    for (uint32_t i = 0; i < l.f->source_count; i++) {
        spath[i] = vb_eval_find_source(l.f->sources[i].name, path);
        if (!spath[i]) {
            fprintf(stderr,
                    PROG ": %s: cannot find source %u of %u, '%s' (looked as "
                         "recorded and beside the file)\n",
                    path, i + 1, l.f->source_count, l.f->sources[i].name);
            goto done;
        }
    }
    if (output &&
        vt_cli_check_outputs(&output, 1, (const char *const *)spath, (int)l.f->source_count) != 0)
        goto done;
    vb_eval_scene_desc sd = {.threads = threads};
    if (vb_eval_scene_create(l.f, (const char *const *)spath, l.f->source_count, &sd, &l.occ,
                             &err) != VB_OK ||
        vb_frames_scene_create(l.f, l.occ, threads, &l.fs, &err) != VB_OK) {
        fprintf(stderr, PROG ": %s: %s\n", path, err.msg);
        goto done;
    }
    rc = 0;
done:
    if (spath)
        for (uint32_t i = 0; i < l.f->source_count; i++)
            free(spath[i]);
    free(spath);
    if (rc)
        loaded_free(&l);
    else
        *out = l;
    return rc;
}

static int read_views(const char *path, vt_views *v)
{
    char msg[PATH_MAX + 256];
    if (vt_views_read(path, v, msg, sizeof msg) != 0) {
        fprintf(stderr, PROG ": %s\n", msg);
        return -1;
    }
    return 0;
}

/* ---- views ------------------------------------------------------------------------------ */

static int run_views(const options *op)
{
    const char *path = op->path, *out = op->output;
    if (vt_cli_check_outputs(&out, 1, &path, 1) != 0)
        return 1;
    vb_frames_views_desc d = op->views;
    d.threads = op->threads;

    loaded L;
    if (load_scene(path, op->threads, 1, out, &L))
        return 1;
    vb_error rerr;
    vdsh_light_box region = op->light_region;
    if (vb_scene_use_light_box(L.occ, &region, "--light-region", &rerr) != VB_OK) {
        fprintf(stderr, PROG ": %s: %s\n", path, rerr.msg);
        loaded_free(&L);
        return 1;
    }
    int status = 1;
    vb_frames_view *fv = calloc(1 + (size_t)d.cameras, sizeof *fv);
    vt_views set = {.width = d.width, .height = d.height, .count = 1 + (int)d.cameras};
    set.views = calloc((size_t)set.count, sizeof *set.views);
    vb_frames_views_stats st;
    vb_error err;
    double t0 = vb_now();
    if (!fv || !set.views) {
        fprintf(stderr, PROG ": out of memory\n");
        goto done;
    }
    if (vb_frames_make_views(L.fs, &d, fv, &st, &err) != VB_OK) {
        fprintf(stderr, PROG ": %s: %s\n", path, err.msg);
        goto done;
    }
    for (int i = 0; i < set.count; i++) {
        vt_view *v = set.views + i;
        if (i == 0)
            snprintf(v->name, sizeof v->name, "default");
        else
            snprintf(v->name, sizeof v->name, "v%d", i);
        v->camera = fv[i].camera;
        v->set_count = VB_FRAMES_SETS;
        v->light_count[0] = 1;
        v->light_count[1] = 3;
        memcpy(v->lights[0][0], fv[i].lights[0], sizeof v->lights[0][0]);
        for (int j = 0; j < 3; j++)
            memcpy(v->lights[1][j], fv[i].lights[1 + j], sizeof v->lights[1][j]);
    }
    char msg[PATH_MAX + 256];
    if (vt_views_write(out, &set, msg, sizeof msg) != 0) {
        fprintf(stderr, PROG ": %s\n", msg);
        goto done;
    }
    if (!op->quiet) {
        printf(PROG " views: %s -> %s: %d view%s, %d x %d, seed %llu%s%s; %u candidate eye%s "
                    "(%u in free space), %.2f s\n",
               path, out, set.count, vdsh_s((unsigned)set.count), d.width, d.height,
               (unsigned long long)d.seed, d.light_rule ? ", lights by rule " : "",
               d.light_rule ? vb_light_rule_name((vb_light_rule)d.light_rule) : "", st.eyes_tried,
               vdsh_s(st.eyes_tried), st.eyes_free, vb_now() - t0);
        if (st.default_lights_ok < VB_FRAMES_VIEW_LIGHTS)
            printf("  note: only %u of the default view's 4 lights light and shadow %.0f%% "
                   "of it each; the best others fill in\n",
                   st.default_lights_ok, 100.0 * VB_FRAMES_MIN_SHARE);
        for (int i = 0; i < set.count; i++) {
            const vdsh_camera *cam = &fv[i].camera;
            printf("  %-8s eye (%.3g, %.3g, %.3g) target (%.3g, %.3g, %.3g); lit / shadowed "
                   "per light:",
                   set.views[i].name, (double)cam->eye[0], (double)cam->eye[1], (double)cam->eye[2],
                   (double)cam->target[0], (double)cam->target[1], (double)cam->target[2]);
            for (int j = 0; j < VB_FRAMES_VIEW_LIGHTS; j++)
                printf(" %.0f/%.0f%%", 100.0 * fv[i].lit[j], 100.0 * fv[i].shadowed[j]);
            printf("\n");
        }
    }
    status = 0;
done:
    free(fv);
    vt_views_free(&set);
    loaded_free(&L);
    return status;
}

/* ---- truth ----------------------------------------------------------------------------- */

/* The mode a stream's C frames are named by: c-vdshN for a fixed-order
 * stream of order N, c-vdsh-var for a variable-order stream. */
static void stream_mode(const vdsh_stream *st, char *name, size_t cap)
{
    if (st->flags & VDSH_STREAM_VARIABLE)
        snprintf(name, cap, "c-vdsh-var");
    else
        snprintf(name, cap, "c-vdsh%u", st->order);
}

/* The truth appears whole or not at all (a folder left by a failed or
 * killed run was read as a whole truth): it is written into a new folder
 * beside DIR, "DIR.tmp.XXXXXX" (beside the folder a link DIR leads to),
 * removed on any failure or SIGINT/SIGTERM/SIGHUP, then renamed to DIR when
 * DIR is not there or empty, else its frames moved into DIR, each replacing
 * its namesake (signals wait meanwhile). Only a SIGKILL can leave the
 * temporary folder behind, never a part of a truth in DIR. */
static int truth_begin(const char *dir, char *tmp, size_t cap)
{
    struct stat st;
    char real[PATH_MAX];
    const char *base = dir;
    if (stat(dir, &st) == 0) {
        if (!S_ISDIR(st.st_mode)) {
            fprintf(stderr, PROG ": %s: cannot create the folder: a file of that name is there\n",
                    dir);
            return -1;
        }
        if (!realpath(dir, real)) {
            fprintf(stderr, PROG ": %s: %s\n", dir, strerror(errno));
            return -1;
        }
        base = real;
    }
    size_t len = strlen(base);
    while (len > 1 && base[len - 1] == '/')
        len--;
    static const char suffix[] = ".tmp.XXXXXX";
    if (len + sizeof suffix > cap) {
        fprintf(stderr, PROG ": %s: path too long\n", dir);
        return -1;
    }
    memcpy(tmp, base, len);
    memcpy(tmp + len, suffix, sizeof suffix);
    if (!mkdtemp(tmp)) {
        fprintf(stderr, PROG ": %s: cannot create the folder %s: %s\n", dir, tmp, strerror(errno));
        return -1;
    }
    vt_cli_remove_dir_on_signal(tmp);
    mode_t mask = umask(0); /* mkdtemp makes it 0700: a new folder's mode */
    umask(mask);
    chmod(tmp, 0777 & ~mask);
    return 0;
}

/* Each of tmp's files to dir/NAME (pass 0: only checks that no NAME there
 * is a folder, so that no move fails half-way). */
static int truth_move(const char *dir, const char *tmp, int pass)
{
    DIR *d = opendir(tmp);
    if (!d) {
        fprintf(stderr, PROG ": %s: %s\n", tmp, strerror(errno));
        return -1;
    }
    int rc = 0;
    struct dirent *e;
    while (rc == 0 && (e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        char from[PATH_MAX], to[PATH_MAX];
        struct stat st;
        int a = snprintf(from, sizeof from, "%s/%s", tmp, e->d_name);
        int b = snprintf(to, sizeof to, "%s/%s", dir, e->d_name);
        if (a < 0 || b < 0 || (size_t)a >= sizeof from || (size_t)b >= sizeof to) {
            fprintf(stderr, PROG ": %s: path too long\n", dir);
            rc = -1;
        } else if (pass == 0 && lstat(to, &st) == 0 && S_ISDIR(st.st_mode)) {
            fprintf(stderr, PROG ": %s: a folder of that name is there: no frame written\n", to);
            rc = -1;
        } else if (pass == 1 && rename(from, to) != 0) {
            fprintf(stderr, PROG ": %s: %s\n", to, strerror(errno));
            rc = -1;
        }
    }
    closedir(d);
    return rc;
}

static int truth_commit(const char *dir, const char *tmp)
{
    int rc = 0;
    vt_cli_defer_signals();
    if (rename(tmp, dir) != 0) {
        if (errno != ENOTEMPTY && errno != EEXIST && errno != ENOTDIR) {
            fprintf(stderr, PROG ": %s: cannot rename %s to it: %s\n", dir, tmp, strerror(errno));
            rc = -1;
        } else if (truth_move(dir, tmp, 0) || truth_move(dir, tmp, 1)) {
            rc = -1;
        } else {
            rmdir(tmp);
        }
    }
    if (rc == 0)
        vt_cli_remove_dir_on_signal(NULL);
    vt_cli_undefer_signals();
    return rc;
}

/* The frames of one light, written on the workers: PNG encoding is most
 * of the truth's time. Each item keeps its own message; the first failure
 * in item order is reported, whatever the scheduling. */
typedef struct frame_item {
    char mode[32];
    const float *values;
    int failed;
    char msg[PATH_MAX + 256];
} frame_item;

typedef struct frame_batch {
    const char *dir, *view;
    int set, light, w, h;
    frame_item *items;
} frame_batch;

static void write_items(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    (void)worker;
    frame_batch *b = ctx;
    for (uint32_t i = begin; i < end; i++) {
        frame_item *it = b->items + i;
        char path[PATH_MAX];
        if (vt_frame_path(path, sizeof path, b->dir, b->view, b->set, b->light, it->mode)) {
            snprintf(it->msg, sizeof it->msg, "%s: path too long", b->dir);
            it->failed = 1;
        } else if (vt_png16_write(path, b->w, b->h, it->values, it->msg, sizeof it->msg)) {
            it->failed = 1;
        }
    }
}

static int write_frames(const frame_batch *b, uint32_t count, unsigned threads)
{
    if (!vb_parallel_for(threads, count, 1, write_items, (void *)b, NULL, NULL)) {
        fprintf(stderr, PROG ": cannot start worker threads\n");
        return -1;
    }
    for (uint32_t i = 0; i < count; i++)
        if (b->items[i].failed) {
            fprintf(stderr, PROG ": %s\n", b->items[i].msg);
            return -1;
        }
    return 0;
}

/* c-sdf: the runtime's mode sdf in C, per pixel (1 where nothing is hit). */
typedef struct sdf_pass {
    const vdsh_sdf *v;
    const vb_frames_hits *hits;
    const float *light;
    float k;
    float *out;
} sdf_pass;

static void sdf_block(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    (void)worker;
    const sdf_pass *P = ctx;
    for (uint32_t i = begin; i < end; i++)
        P->out[i] = P->hits->triangle[i] == UINT32_MAX
                        ? 1.0f
                        : vdsh_sdf_shadow(P->v, P->hits->position + 3 * (size_t)i,
                                          P->hits->normal + 3 * (size_t)i, P->light, P->k);
}

/* The distance volume of c-sdf: --sdf, else the companion file when it
 * exists (*have: one was read and fits the scene). Returns 0, 1 on an
 * error (the message printed) or 2 for --sdf-k with no volume. */
static int open_volume(const options *op, const vdsh_file *f, vdsh_sdf *vol, int *have)
{
    const char *path = op->path, *sdf_arg = op->sdf;
    char sp[PATH_MAX];
    struct stat sst;
    const char *p = sdf_arg;
    *have = 0;
    if (!p && vdsh_sdf_path(path, sp, sizeof sp) == 0 && stat(sp, &sst) == 0)
        p = sp;
    if (p) {
        vdsh_error ve;
        if (vdsh_sdf_read(p, vol, &ve) != VDSH_OK) {
            fprintf(stderr, PROG ": %s\n", ve.msg);
            return 1;
        }
        *have = 1;
        /* The runtime's rule (vr.h, sdf_path): a volume baked beside
         * other vertex or triangle counts is refused when named, and
         * skipped when it is the companion (left by an earlier bake of
         * the same name), so c-sdf is what vdsh-view's mode sdf draws. */
        if (vdsh_sdf_other_scene(vol, f->header.vertex_count, f->header.triangle_count)) {
            if (sdf_arg || !op->quiet) /* the companion skipped: a note */
                fprintf(stderr,
                        PROG ": %s%s was baked beside another bake (%u vertices and %u "
                             "triangles, not %u and %u)%s\n",
                        p, sdf_arg ? "" : " beside it", vol->vertex_count, vol->triangle_count,
                        f->header.vertex_count, f->header.triangle_count,
                        sdf_arg ? ": bake it again (vdsh-bake --sdf N)"
                                : ": skipped, no c-sdf frames (bake again with vdsh-bake --sdf N)");
            vdsh_sdf_free(vol);
            *have = 0;
            if (sdf_arg)
                return 1;
        }
    }
    if (!*have && op->sdf_k_given) { /* it made no c-sdf frame, exit 0 */
        fprintf(stderr,
                PROG ": --sdf-k: %s has no distance volume (no %s; bake one with "
                     "vdsh-bake --sdf N, or give --sdf FILE)\n",
                path, vdsh_sdf_path(path, sp, sizeof sp) == 0 ? sp : "SCENE.sdf");
        return 2;
    }
    return 0;
}

/* The streams drawn (use[s]): one c-vdshN per order, the first
 * fixed-order stream of each, and one c-vdsh-var, the first
 * variable-order stream (slot 0 of seen); a note for each other. */
static void choose_streams(const options *op, const vdsh_file *f, int use[VDSH_MAX_STREAMS])
{
    int seen[VDSH_ORDER_SLOTS] = {0};
    for (uint32_t s = 0; s < f->stream_count; s++) {
        const vdsh_stream *st = &f->streams[s];
        uint32_t o = st->flags & VDSH_STREAM_VARIABLE ? 0 : st->order;
        if (o <= VDSH_MAX_ORDER && !seen[o] &&
            (o || vdsh_runtime_interp(st->order, st->quantity) == VDSH_INTERP_DISTANCE)) {
            use[s] = 1;
            seen[o] = 1;
        } else if (!op->quiet) {
            char name[32];
            stream_mode(st, name, sizeof name);
            fprintf(stderr, PROG ": %s: stream %u (%s): %s\n", op->path, s, name,
                    seen[o] ? "a mode of that name is drawn already: only the first is"
                            : "a variable-order stream is drawn only per vertex distance "
                              "(log distance): skipped");
        }
    }
}

/* What the truth of every view shares. */
typedef struct truth_run {
    const options *op;
    const vt_views *V;
    const loaded *L;
    /* The output folder, and the one the frames go to until the commit. */
    const char *dir;
    char tmp_dir[PATH_MAX];
    int w, h;
    size_t n;
    /* Per stream: drawn as a c-vdsh frame (choose_streams). */
    int use[VDSH_MAX_STREAMS];
    /* The distance volume of c-sdf, when have_sdf (open_volume). */
    vdsh_sdf vol;
    int have_sdf;
    /* Scratch: a view's primary hits, its set's lights, a light's C
     * frames (stream s at s * n, c-sdf at (stream_count + 1) * n), the
     * frames to write and a shaded picture. */
    vb_frames_hits hits;
    vb_frames_light lights[VT_VIEWS_MAX_LIGHTS];
    float *streams;
    frame_item *items;
    uint8_t *rgba;
    /* For the summary: seconds of each pass, and frames made. */
    double t_primary, t_shadow, t_streams, t_write;
    int light_frames, stream_frames;
} truth_run;

/* One view's times, for its line. */
typedef struct view_times {
    double primary, shadow, streams;
    int lights;
} view_times;

/* Light j of set k of view v: its shadow pass, then its frames written:
 * hard, ideal and mask, each stream drawn, and c-sdf. */
static int truth_light(truth_run *T, const vt_view *v, int k, int j, view_times *vt)
{
    const options *op = T->op;
    const vdsh_file *f = T->L->f;
    const float *L0 = v->lights[k][j];
    vb_frames_light *lt = &T->lights[j];
    vb_error err;
    double t = vb_now();
    if (vb_frames_trace_light(T->L->fs, &T->hits, L0, op->compare, op->threads, lt, &err) !=
        VB_OK) {
        fprintf(stderr, PROG ": view '%s': %s\n", v->name, err.msg);
        return -1;
    }
    vt->shadow += vb_now() - t;
    T->light_frames++;
    vt->lights++;
    frame_item *items = T->items;
    frame_batch fb = {.dir = T->tmp_dir,
                      .view = v->name,
                      .set = k,
                      .light = j,
                      .w = T->w,
                      .h = T->h,
                      .items = items};
    uint32_t count = 0;
    const char *truth_modes[3] = {"hard", "ideal", "mask"};
    const float *truth_values[3] = {lt->hard, lt->ideal, lt->mask};
    for (int m = 0; m < 3; m++, count++) {
        memset(&items[count], 0, sizeof items[count]);
        snprintf(items[count].mode, sizeof items[count].mode, "%s", truth_modes[m]);
        items[count].values = truth_values[m];
    }
    for (uint32_t s = 0; s < f->stream_count; s++) {
        if (!T->use[s])
            continue;
        float *out = T->streams + (size_t)s * T->n;
        t = vb_now();
        if (vb_frames_eval_stream(T->L->fs, &T->hits, s, L0, op->compare, op->threads, out, &err) !=
            VB_OK) {
            fprintf(stderr, PROG ": %s: %s\n", op->path, err.msg);
            return -1;
        }
        vt->streams += vb_now() - t;
        T->stream_frames++;
        memset(&items[count], 0, sizeof items[count]);
        stream_mode(&f->streams[s], items[count].mode, sizeof items[count].mode);
        items[count++].values = out;
    }
    if (T->have_sdf) {
        float *out = T->streams + (size_t)(f->stream_count + 1) * T->n;
        t = vb_now();
        sdf_pass sp = {.v = &T->vol, .hits = &T->hits, .light = L0, .k = op->sdf_k, .out = out};
        if (!vb_parallel_for(op->threads, (uint32_t)T->n, 1024, sdf_block, &sp, NULL, NULL)) {
            fprintf(stderr, PROG ": cannot start worker threads\n");
            return -1;
        }
        vt->streams += vb_now() - t;
        T->stream_frames++;
        memset(&items[count], 0, sizeof items[count]);
        snprintf(items[count].mode, sizeof items[count].mode, "c-sdf");
        items[count++].values = out;
    }
    t = vb_now();
    if (write_frames(&fb, count, op->threads))
        return -1;
    T->t_write += vb_now() - t;
    return 0;
}

/* The pictures of set k: shaded with its lights' hard and ideal shadows. */
static int truth_shaded(truth_run *T, const vt_view *v, int k, const float *const *vis_hard,
                        const float *const *vis_ideal)
{
    vb_frames_shading sh;
    vb_frames_shading_default(T->L->fs, v->light_count[k], &sh);
    for (int pass = 0; pass < 2; pass++) {
        char p[PATH_MAX], msg[PATH_MAX + 256];
        int len = snprintf(p, sizeof p, "%s/%s-s%d-shaded-%s.png", T->tmp_dir, v->name, k,
                           pass ? "ideal" : "hard");
        if (len < 0 || (size_t)len >= sizeof p) {
            fprintf(stderr, PROG ": %s: path too long\n", T->dir);
            return -1;
        }
        vb_frames_shade(&T->hits, (const float(*)[3])v->lights[k], v->light_count[k],
                        pass ? vis_ideal : vis_hard, &sh, T->rgba);
        if (vt_png_rgba_write(p, T->w, T->h, T->rgba, msg, sizeof msg) != 0) {
            fprintf(stderr, PROG ": %s\n", msg);
            return -1;
        }
    }
    return 0;
}

/* View vi: its primary pass, then every light of every set, and the
 * set's pictures; a line with its times. */
static int truth_view(truth_run *T, int vi)
{
    const options *op = T->op;
    const vt_view *v = T->V->views + vi;
    view_times vt = {0};
    vb_error err;
    double t = vb_now();
    if (vb_frames_trace_primary(T->L->fs, &v->camera, T->w, T->h, op->threads, &T->hits, &err) !=
        VB_OK) {
        fprintf(stderr, PROG ": %s: view '%s': %s\n", op->views_path, v->name, err.msg);
        return -1;
    }
    vt.primary = vb_now() - t;
    T->t_primary += vt.primary;
    for (int k = 0; k < v->set_count; k++) {
        const float *vis_hard[VT_VIEWS_MAX_LIGHTS], *vis_ideal[VT_VIEWS_MAX_LIGHTS];
        for (int j = 0; j < v->light_count[k]; j++) {
            if (truth_light(T, v, k, j, &vt))
                return -1;
            vis_hard[j] = T->lights[j].hard;
            vis_ideal[j] = T->lights[j].ideal;
        }
        if (truth_shaded(T, v, k, vis_hard, vis_ideal))
            return -1;
        for (int j = 0; j < v->light_count[k]; j++)
            vb_frames_light_free(&T->lights[j]);
    }
    vb_frames_hits_free(&T->hits);
    T->t_shadow += vt.shadow;
    T->t_streams += vt.streams;
    if (!op->quiet)
        printf("  %-10s primary %6.1f ms; %d light%s: shadow %6.1f ms per light, C streams "
               "%6.1f ms per light\n",
               v->name, 1e3 * vt.primary, vt.lights, vdsh_s((unsigned)vt.lights),
               1e3 * vt.shadow / (vt.lights ? vt.lights : 1),
               1e3 * vt.streams / (vt.lights ? vt.lights : 1));
    return 0;
}

/* The summary: a frame's truth, the C streams, the frames written. */
static void print_truth_times(const truth_run *T, double t0)
{
    const options *op = T->op;
    double per_view = T->t_primary / T->V->count;
    double per_light = T->light_frames ? T->t_shadow / T->light_frames : 0.0;
    printf("  a frame's truth (%d x %d, primary + shadow ray per pixel): %.1f ms "
           "(primary %.1f + shadow %.1f) on %u thread%s\n",
           T->w, T->h, 1e3 * (per_view + per_light), 1e3 * per_view, 1e3 * per_light,
           vb_parallel_threads(op->threads), vdsh_s(vb_parallel_threads(op->threads)));
    printf("  C streams: %.1f ms per stream per frame; %d + %d frames written (%.2f s) in "
           "%.2f s in all\n",
           T->stream_frames ? 1e3 * T->t_streams / T->stream_frames : 0.0, 3 * T->light_frames,
           T->stream_frames, T->t_write, vb_now() - t0);
}

static int run_truth(const options *op)
{
    const char *dir = op->output;
    const char *opt = "-o";
    int rc = vt_cli_no_stdout(&dir, &opt, 1);
    if (rc)
        return rc;
    vt_views V = {0};
    if (read_views(op->views_path, &V))
        return 1;
    loaded L;
    if (load_scene(op->path, op->threads, 1, NULL, &L)) {
        vt_views_free(&V);
        return 1;
    }
    truth_run T = {.op = op, .V = &V, .L = &L, .dir = dir, .w = V.width, .h = V.height};
    rc = open_volume(op, L.f, &T.vol, &T.have_sdf);
    if (rc) {
        vdsh_sdf_free(&T.vol);
        loaded_free(&L);
        vt_views_free(&V);
        return rc;
    }
    int status = 1, have_tmp = 0;
    const vdsh_file *f = L.f;
    T.n = (size_t)T.w * (size_t)T.h;
    T.streams = malloc(((size_t)f->stream_count + 2) * T.n * sizeof *T.streams);
    T.items = calloc(4 + (size_t)f->stream_count, sizeof *T.items);
    T.rgba = malloc(4 * T.n);
    choose_streams(op, f, T.use);
    if (!T.streams || !T.items || !T.rgba) {
        fprintf(stderr, PROG ": out of memory for %d x %d frames\n", T.w, T.h);
        goto done;
    }
    if (truth_begin(dir, T.tmp_dir, sizeof T.tmp_dir))
        goto done;
    have_tmp = 1;

    double t0 = vb_now();
    if (!op->quiet)
        printf(PROG " truth: %s, %d view%s from %s, %d x %d, %s comparison -> %s\n", op->path,
               V.count, vdsh_s((unsigned)V.count), op->views_path, T.w, T.h,
               vdsh_compare_name(op->compare), dir);
    for (int vi = 0; vi < V.count; vi++)
        if (truth_view(&T, vi))
            goto done;
    if (truth_commit(dir, T.tmp_dir))
        goto done;
    have_tmp = 0;
    if (!op->quiet)
        print_truth_times(&T, t0);
    status = 0;
done:
    if (have_tmp) { /* a failure: none of the truth */
        vt_cli_remove_dir(T.tmp_dir);
        vt_cli_remove_dir_on_signal(NULL);
    }
    for (int j = 0; j < VT_VIEWS_MAX_LIGHTS; j++)
        vb_frames_light_free(&T.lights[j]);
    vb_frames_hits_free(&T.hits);
    free(T.streams);
    free(T.items);
    free(T.rgba);
    vdsh_sdf_free(&T.vol);
    loaded_free(&L);
    vt_views_free(&V);
    return status;
}

/* ---- score ------------------------------------------------------------------------------- */

static int good_mode(const char *s, size_t n)
{
    if (n == 0 || n > 48)
        return 0;
    for (size_t i = 0; i < n; i++)
        if (!((s[i] >= 'a' && s[i] <= 'z') || (s[i] >= 'A' && s[i] <= 'Z') ||
              (s[i] >= '0' && s[i] <= '9') || s[i] == '-' || s[i] == '_'))
            return 0;
    return 1;
}

/* name,name,... into modes; the count, or 0 if not such a list. */
static int parse_modes(const char *s, char modes[MAX_MODES][64])
{
    int n = 0;
    for (const char *p = s, *next; p; p = next) {
        size_t len = vt_list_item(p, &next);
        if (!good_mode(p, len) || n == MAX_MODES)
            return 0;
        memcpy(modes[n], p, len);
        modes[n][len] = '\0';
        for (int i = 0; i < n; i++)
            if (strcmp(modes[i], modes[n]) == 0)
                return 0;
        n++;
    }
    return n;
}

/* A frame of the view set's size, or -1 with the file named. */
static int read_frame(const char *dir, const vt_views *V, const char *views_path, const char *view,
                      int set, int light, const char *mode, float **out, char *path, size_t cap)
{
    char msg[PATH_MAX + 256];
    int w, h;
    if (vt_frame_path(path, cap, dir, view, set, light, mode) != 0) {
        fprintf(stderr, PROG ": %s: path too long\n", dir);
        return -1;
    }
    struct stat st;
    if (stat(path, &st) != 0) {
        fprintf(stderr, PROG ": %s: missing frame (view '%s', set %d, light %d, mode %s): %s\n",
                path, view, set, light, mode, strerror(errno));
        return -1;
    }
    if (vt_png16_read(path, &w, &h, out, msg, sizeof msg) != 0) {
        fprintf(stderr, PROG ": %s\n", msg);
        return -1;
    }
    if (w != V->width || h != V->height) {
        fprintf(stderr, PROG ": %s: %d x %d pixels, but the view set %s is %d x %d\n", path, w, h,
                views_path, V->width, V->height);
        free(*out);
        *out = NULL;
        return -1;
    }
    return 0;
}

static void json_scores(vt_json *j, cJSON *o, const vb_frames_tally *t)
{
    vb_frames_scores s;
    vb_frames_scores_get(t, &s);
    vt_json_u64(j, o, "frames", t->frames);
    vt_json_u64(j, o, "pixels", t->pixels);
    vt_json_u64(j, o, "counted", t->counted);
    vt_json_f64(j, o, "rmse_ideal", s.rmse_ideal);
    vt_json_f64(j, o, "psnr_ideal", s.psnr_ideal);
    vt_json_f64(j, o, "rmse_hard", s.rmse_hard);
    vt_json_f64(j, o, "psnr_hard", s.psnr_hard);
    vt_json_f64(j, o, "recall", s.recall);
    vt_json_u64(j, o, "shadowed", t->shadowed);
    vt_json_f64(j, o, "false_area", s.false_area);
    vt_json_u64(j, o, "lit", t->lit);
    vt_json_u64(j, o, "blotches", s.blotches);
    vt_json_f64(j, o, "blotch_area", s.blotch_area);
}

static void print_row(const char *view, const char *set, int lights, const vb_frames_tally *t)
{
    vb_frames_scores s;
    vb_frames_scores_get(t, &s);
    printf("  %-10s %-3s %6d %9llu  %8.4f %6.2f  %8.4f %6.2f  %7.4f %7.4f  %4llu %7.3f%%\n", view,
           set, lights, (unsigned long long)t->counted, s.rmse_ideal, s.psnr_ideal, s.rmse_hard,
           s.psnr_hard, s.recall, s.false_area, (unsigned long long)s.blotches,
           100.0 * s.blotch_area);
}

/* The frames of a view set: one per (view, set, light). */
static size_t frame_count_of(const vt_views *V)
{
    size_t n = 0;
    for (int vi = 0; vi < V->count; vi++)
        for (int k = 0; k < V->views[vi].set_count; k++)
            n += (size_t)V->views[vi].light_count[k];
    return n;
}

/* Every frame of every mode scored against the truth: tally[m *
 * frame_count + fi] for mode m and frame fi, frames in view, set and
 * light order. Returns 0, or -1 with the message printed. */
static int score_frames(const options *op, const vt_views *V, size_t frame_count,
                        vb_frames_tally *tally)
{
    const char *views_path = op->views_path;
    float *hard = NULL, *ideal = NULL, *mask = NULL, *s = NULL;
    vb_error err;
    char p[PATH_MAX];
    int rc = -1;
    size_t fi = 0;
    for (int vi = 0; vi < V->count; vi++) {
        const vt_view *v = V->views + vi;
        for (int k = 0; k < v->set_count; k++)
            for (int l = 0; l < v->light_count[k]; l++, fi++) {
                if (read_frame(op->truth, V, views_path, v->name, k, l, "hard", &hard, p,
                               sizeof p) ||
                    read_frame(op->truth, V, views_path, v->name, k, l, "ideal", &ideal, p,
                               sizeof p) ||
                    read_frame(op->truth, V, views_path, v->name, k, l, "mask", &mask, p, sizeof p))
                    goto done;
                for (int m = 0; m < op->mode_count; m++) {
                    if (read_frame(op->frames, V, views_path, v->name, k, l, op->modes[m], &s, p,
                                   sizeof p))
                        goto done;
                    if (vb_frames_score_frame(s, hard, ideal, mask, V->width, V->height,
                                              &tally[(size_t)m * frame_count + fi],
                                              &err) != VB_OK) {
                        fprintf(stderr, PROG ": %s: %s\n", p, err.msg);
                        goto done;
                    }
                    free(s);
                    s = NULL;
                }
                free(hard);
                free(ideal);
                free(mask);
                hard = ideal = mask = NULL;
            }
    }
    rc = 0;
done:
    free(hard);
    free(ideal);
    free(mask);
    free(s);
    return rc;
}

/* Mode m's scores (T: its frames' tallies): per frame and set in the
 * JSON (under jm), per set and for the scene in the table. */
static void report_mode(const options *op, const vt_views *V, int m, const vb_frames_tally *T,
                        vt_json *j, cJSON *jm)
{
    const char *mode = op->modes[m];
    vb_frames_tally scene = {0};
    char p[PATH_MAX];
    cJSON *mo = vt_json_object(j, jm, NULL);
    vt_json_string(j, mo, "mode", mode);
    cJSON *sets = vt_json_array(j, mo, "sets");
    if (!op->quiet)
        printf("\n  mode %s\n  %-10s %-3s %6s %9s  %8s %6s  %8s %6s  %7s %7s  %s\n", mode, "view",
               "set", "lights", "counted", "RMSE/id", "PSNR", "RMSE/hd", "PSNR", "recall", "false",
               "blotches");
    size_t fi = 0;
    for (int vi = 0; vi < V->count; vi++) {
        const vt_view *v = V->views + vi;
        for (int k = 0; k < v->set_count; k++) {
            vb_frames_tally set = {0};
            cJSON *so = vt_json_object(j, sets, NULL);
            vt_json_string(j, so, "view", v->name);
            vt_json_i64(j, so, "set", k);
            /* each frame's scores; "frames" (json_scores) is their count */
            cJSON *fr = vt_json_array(j, so, "per_frame");
            for (int l = 0; l < v->light_count[k]; l++, fi++) {
                vb_frames_tally_add(&set, &T[fi]);
                cJSON *o = vt_json_object(j, fr, NULL);
                vt_json_i64(j, o, "light", l);
                vt_frame_path(p, sizeof p, op->frames, v->name, k, l, mode);
                vt_json_string(j, o, "file", p);
                json_scores(j, o, &T[fi]);
            }
            json_scores(j, so, &set);
            vb_frames_tally_add(&scene, &set);
            if (!op->quiet) {
                char sk[16];
                snprintf(sk, sizeof sk, "%d", k);
                print_row(v->name, sk, v->light_count[k], &set);
            }
        }
    }
    json_scores(j, vt_json_object(j, mo, "scene"), &scene);
    if (!op->quiet)
        print_row("scene", "", (int)scene.frames, &scene);
}

static int run_score(const options *op)
{
    const char *path = op->path, *views_path = op->views_path, *truth = op->truth;
    const char *frames = op->frames, *json = op->json;
    {
        const char *ins[] = {path, views_path};
        if (vt_cli_check_outputs(&json, 1, ins, 2) != 0)
            return 1;
    }

    vt_views V = {0};
    if (read_views(views_path, &V))
        return 1;
    loaded L = {0};
    if (load_scene(path, op->threads, 0, NULL, &L)) {
        vt_views_free(&V);
        return 1;
    }
    int status = 1;
    /* Tallies: per mode, per (view, set, light) frame; sets and the scene
     * are sums of those, in order. */
    const size_t frame_count = frame_count_of(&V);
    vb_frames_tally *tally = calloc((size_t)op->mode_count * frame_count, sizeof *tally);
    vt_json j = {0};
    if (!tally) {
        fprintf(stderr, PROG ": out of memory\n");
        goto done;
    }
    if (score_frames(op, &V, frame_count, tally))
        goto done;

    /* Report: the table, then the JSON. */
    cJSON *root = vt_json_object(&j, NULL, NULL);
    vt_json_string(&j, root, "tool", PROG);
    vt_json_string(&j, root, "command", "score");
    vt_json_string(&j, root, "version", VDSH_VERSION_STRING);
    vt_json_string(&j, root, "scene", path);
    vt_json_string(&j, root, "views", views_path);
    vt_json_string(&j, root, "truth", truth);
    vt_json_string(&j, root, "frames", frames);
    vt_json_u64(&j, root, "width", (uint64_t)V.width);
    vt_json_u64(&j, root, "height", (uint64_t)V.height);
    vt_json_f64(&j, root, "blotch_threshold", VB_FRAMES_BLOTCH);
    cJSON *jm = vt_json_array(&j, root, "modes");
    if (!op->quiet)
        printf(PROG " score: %s, %d view%s from %s, %d x %d; truth %s, frames %s\n", path, V.count,
               vdsh_s((unsigned)V.count), views_path, V.width, V.height, truth, frames);
    for (int m = 0; m < op->mode_count; m++)
        report_mode(op, &V, m, tally + (size_t)m * frame_count, &j, jm);
    if (!op->quiet)
        printf("\n  (over mask pixels; recall: of hard = 0 and ideal < .5, drawn < .5; false: "
               "of hard = 1, drawn < .5;\n   blotches: false-shadow regions above %.2f%% of a "
               "frame, count and area; scene row: lights = frames)\n",
               100.0 * VB_FRAMES_BLOTCH);
    char msg[PATH_MAX + 256];
    if (json && vt_json_write_file(&j, json, msg, sizeof msg) != 0) {
        fprintf(stderr, PROG ": %s\n", msg);
        goto done;
    }
    status = 0;
done:
    vt_json_free(&j);
    free(tally);
    loaded_free(&L);
    vt_views_free(&V);
    return status;
}

/* ---- the command line ---------------------------------------------------------------------- */

enum {
    O_THREADS = 256,
    O_CAMERAS,
    O_SEED,
    O_LIGHT_RULE,
    O_LIGHT_REGION,
    O_SIZE,
    O_VIEWS,
    O_COMPARE,
    O_TRUTH,
    O_FRAMES,
    O_MODES,
    O_JSON,
    O_SDF,
    O_SDF_K
};

#define COMMON_OPTIONS                                                                             \
    {"threads", required_argument, 0, O_THREADS}, {"quiet", no_argument, 0, 'q'},                  \
        {"help", no_argument, 0, 'h'},                                                             \
    {                                                                                              \
        "version", no_argument, 0, 'V'                                                             \
    }

static const struct option views_options[] = {
    {"output", required_argument, 0, 'o'},
    {"cameras", required_argument, 0, O_CAMERAS},
    {"seed", required_argument, 0, O_SEED},
    {"size", required_argument, 0, O_SIZE},
    {"light-rule", required_argument, 0, O_LIGHT_RULE},
    {"light-region", required_argument, 0, O_LIGHT_REGION},
    COMMON_OPTIONS,
    {0, 0, 0, 0}};
static const struct option truth_options[] = {{"output", required_argument, 0, 'o'},
                                              {"views", required_argument, 0, O_VIEWS},
                                              {"compare", required_argument, 0, O_COMPARE},
                                              {"sdf", required_argument, 0, O_SDF},
                                              {"sdf-k", required_argument, 0, O_SDF_K},
                                              COMMON_OPTIONS,
                                              {0, 0, 0, 0}};
static const struct option score_options[] = {{"views", required_argument, 0, O_VIEWS},
                                              {"truth", required_argument, 0, O_TRUTH},
                                              {"frames", required_argument, 0, O_FRAMES},
                                              {"modes", required_argument, 0, O_MODES},
                                              {"json", required_argument, 0, O_JSON},
                                              COMMON_OPTIONS,
                                              {0, 0, 0, 0}};

/* The subcommands: name, getopt's name for messages, options, run. */
static const struct command {
    const char *name, *prog;
    const char *shortopts;
    const struct option *longopts;
    int (*run)(const options *);
} commands[] = {
    {"views", PROG " views", "o:qhV", views_options, run_views},
    {"truth", PROG " truth", "o:qhV", truth_options, run_truth},
    {"score", PROG " score", "qhV", score_options, run_score},
};

/* A subcommand's option: 1, or 0 after the usage error. */
static int take_option(int c, options *o)
{
    uint64_t u;
    switch (c) {
    case 'o': return vt_opt_once("-o", optarg, &o->output);
    case O_VIEWS: return vt_opt_once("--views", optarg, &o->views_path);
    case O_SDF: return vt_opt_once("--sdf", optarg, &o->sdf);
    case O_TRUTH: return vt_opt_once("--truth", optarg, &o->truth);
    case O_FRAMES: return vt_opt_once("--frames", optarg, &o->frames);
    case O_JSON: return vt_opt_once("--json", optarg, &o->json);
    case 'q': o->quiet = 1; return 1;
    case O_THREADS: return vt_opt_u32("--threads", NULL, optarg, 1, 256, &o->threads);
    case O_CAMERAS:
        if (!vt_parse_u64(optarg, 1, VT_VIEWS_MAX - 1, &u))
            return !bad_usage("--cameras takes a whole number 1..255, not '%s'", optarg);
        o->views.cameras = (uint32_t)u;
        return 1;
    case O_SEED:
        if (!vt_parse_u64(optarg, 1, UINT64_MAX, &o->views.seed))
            return !bad_usage("--seed takes a whole number >= 1, not '%s'", optarg);
        return 1;
    case O_LIGHT_RULE:
        if ((o->views.light_rule = vb_light_rule_by_name(optarg)) >= 0)
            return 1;
        return !bad_usage("--light-rule takes uniform, ceiling, near, path, grown, around or "
                          "shell, not '%s'",
                          optarg);
    case O_LIGHT_REGION: return vt_opt_light_region("--light-region", optarg, 1, &o->light_region);
    case O_SIZE:
        if (!vt_parse_size(optarg, 16, 16384, &o->views.width, &o->views.height))
            return !bad_usage("--size takes WxH, each 16..16384, not '%s'", optarg);
        return 1;
    case O_SDF_K:
        if (!vt_parse_float(optarg, &o->sdf_k) || !(o->sdf_k > 0.0f && o->sdf_k <= 1000.0f))
            return !bad_usage("--sdf-k takes a number > 0 and <= 1000, not '%s'", optarg);
        o->sdf_k_given = 1;
        return 1;
    case O_COMPARE:
        o->compare = vdsh_compare_by_name(optarg);
        if (o->compare == VDSH_COMPARE_COUNT)
            return !bad_usage("--compare takes smooth or binary, not '%s'", optarg);
        return 1;
    case O_MODES:
        o->mode_count = parse_modes(optarg, o->modes);
        if (!o->mode_count)
            return !bad_usage("--modes takes distinct names of letters, digits, '-' and "
                              "'_' separated by commas (at most 32), not '%s'",
                              optarg);
        return 1;
    }
    return 0;
}

/* What a subcommand cannot do without: the usage error for the first
 * missing, or 0. */
static int missing(const options *o, const char *cmd)
{
    const struct {
        const char *cmd;
        int given;
        const char *what;
    } need[] = {{"views", o->output != NULL, "views: no output given (-o VIEWS.json)"},
                {"truth", o->views_path != NULL, "truth: no view set given (--views VIEWS.json)"},
                {"truth", o->output != NULL, "truth: no output folder given (-o DIR)"},
                {"score", o->views_path != NULL, "score: no view set given (--views VIEWS.json)"},
                {"score", o->truth != NULL, "score: no truth folder given (--truth DIR)"},
                {"score", o->frames != NULL, "score: no folder of frames given (--frames DIR2)"},
                {"score", o->mode_count != 0, "score: no modes given (--modes LIST)"}};
    for (size_t i = 0; i < sizeof need / sizeof need[0]; i++)
        if (strcmp(need[i].cmd, cmd) == 0 && !need[i].given)
            return bad_usage("%s", need[i].what);
    return 0;
}

/* -1 with *o ready to run (o->run), else the exit status (help, version,
 * a usage error: said). Each subcommand parses its own options; getopt's
 * messages name it. */
static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->views = (vb_frames_views_desc){.cameras = 6, .seed = 1, .width = 512, .height = 384};
    o->compare = VDSH_COMPARE_SMOOTH;
    o->sdf_k = VDSH_SDF_DEFAULT_K;
    o->light_region.rule = VT_LIGHT_REGION_FILE;
    if (argc < 2)
        return bad_usage("%s", "no subcommand given (views, truth or score)");
    const char *name = argv[1];
    if (strcmp(name, "-h") == 0 || strcmp(name, "--help") == 0) {
        usage(stdout);
        return 0;
    }
    if (strcmp(name, "-V") == 0 || strcmp(name, "--version") == 0)
        return vt_cli_version("Embree " RTC_VERSION_STRING);
    const struct command *cmd = NULL;
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (strcmp(name, commands[i].name) == 0)
            cmd = &commands[i];
    if (!cmd)
        return bad_usage("unknown subcommand '%s' (views, truth or score)", name);
    argv[1] = (char *)cmd->prog;
    argc--, argv++;
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, cmd->shortopts, cmd->longopts, NULL)) != -1) {
        if (c == 'h') {
            usage(stdout);
            return 0;
        }
        if (c == 'V')
            return vt_cli_version("Embree " RTC_VERSION_STRING);
        if (c == '?' || c == ':')
            return vt_cli_try_help();
        if (!take_option(c, o))
            return VT_EXIT_USAGE;
    }
    o->path = vt_arg_vdsh(argc, argv, optind, cmd->name, 0);
    if (!o->path)
        return VT_EXIT_USAGE;
    if (missing(o, cmd->name))
        return VT_EXIT_USAGE;
    if (o->json && strcmp(o->json, "-") == 0)
        o->quiet = 1; /* stdout is the JSON's: no table */
    o->run = cmd->run;
    return -1;
}

int main(int argc, char **argv)
{
    vt_cli_begin(PROG, argv);
    vt_cli_clean_exit_on_signals(); /* no temporary file left by a signal */
    options o;
    int status = parse_args(argc, argv, &o);
    return status >= 0 ? status : o.run(&o);
}
