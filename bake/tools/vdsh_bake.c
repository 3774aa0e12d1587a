/*
 * vdsh-bake - bake visibility-distance SH for a static scene.
 *
 * The story of a bake: load every mesh given (they form one scene of
 * occluders), refine a copy into the receivers, build the BVH, trace and
 * project, then write the basis cubemaps and, last, the .vdsh file - each
 * atomically, so an interrupted bake never leaves a partial file behind.
 * The cubemaps depend on the cube size only: a helper thread encodes them
 * in memory meanwhile.
 */
#include <errno.h>
#include <ctype.h>
#include <getopt.h>
#include <libgen.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "bake.h"
#include "job.h"
#include "mesh.h"
#include "method.h"
#include "scene.h"
#include "sdf.h"
#include "vdsh.h"
#include "vdsh_cpca.h"
#include "vdsh_output.h"
#include "vdsh_scene_view.h"
#include "vt_cli.h"
#include "vt_json.h"

typedef struct options {
    const char *output;
    const char *cubemap_dir;
    const char *report;
    const char *export_obj;
    const char *plan;      /* --plan: the adaptive receivers, as OBJ */
    const char *receivers; /* --receivers: a plan to bake */
    uint32_t rays;
    int adaptive_rays;   /* --rays auto */
    float ray_tolerance; /* --ray-tolerance; 0: the default */
    int have_ray_tolerance;
    int orders[VDSH_MAX_ORDER];
    int order_count;
    int orders_given;      /* --orders */
    float order_tolerance; /* --adaptive-order TOL; 0: none */
    int max_order;         /* --max-order N; 0: VB_DEFAULT_ORDER_CAP */
    vb_method method;
    vb_quantity quantity;
    float lambda;
    float log_offset;
    int have_log_offset;
    uint32_t decision_lights;    /* --decision-lights; 0: the default */
    int decision_near;           /* --decision-near as vb_bake_desc's; 0: the default */
    int decision_shell;          /* --decision-shell; 0: none */
    vdsh_light_box light_region; /* --light-region: rule 0 auto, grown, or the box */
    float false_rate;            /* --false-rate; 0: the default */
    vb_decision_params decision; /* --decision-params */
    int have_decision;
    int offset_cap; /* --offset-cap TOL[,KEEP[,MIN]] */
    float offset_cap_tol, offset_cap_keep;
    uint32_t offset_cap_min;
    float log_floor;
    vdsh_window window;
    vdsh_encoding encoding;
    vdsh_cpca_settings cpca; /* --cpca K,B,BITS (encoding cpca) */
    int have_cpca;
    float max_distance;
    float max_edge;
    int adaptive; /* --adaptive TOL */
    float adaptive_tol;
    float min_edge;         /* --min-edge; 0: max_edge / 8 */
    uint32_t max_receivers; /* --max-receivers; 0: none */
    uint32_t max_rounds;    /* --max-rounds; 0: none given (VB_ADAPTIVE_ROUNDS) */
    int weld;
    int up_axis; /* --up-axis: vb_load_desc.up_axis; 0: y */
    int crease;  /* --crease DEG; 0: off */
    uint64_t seed;
    uint32_t threads;
    int cube_size;
    int sdf; /* --sdf N: distance volume, N per longest side */
    int robust;
    int record_timings;
    int trace_only;
    int keep_normals;
    int quiet;
    uint32_t shard_index, shard_count; /* --shard I/N; count 0: the whole bake */
    const char *const *meshes;         /* the MESH arguments */
    int mesh_count;
} options;

/* --method's help, from the table: each row's name and help, indented,
 * then which rows trace only the upper half of the directions. */
static const char *methods_help(void)
{
    static char text[4096];
    int count = VB_METHOD_COUNT, at = 0;
    const vb_method_info *m = vb_method_get(0);
    for (int i = 0; i < count; i++) {
        at += snprintf(text + at, sizeof text - (size_t)at, "%26s%s%s: ", "",
                       vb_method_name(m[i].method), i == 0 ? " (default)" : "");
        for (const char *p = m[i].help; *p; p++) {
            at += snprintf(text + at, sizeof text - (size_t)at, "%c", *p);
            if (*p == '\n')
                at += snprintf(text + at, sizeof text - (size_t)at, "%26s", "");
        }
        at += snprintf(text + at, sizeof text - (size_t)at, "\n");
    }
    at += snprintf(text + at, sizeof text - (size_t)at, "%26sAll but", "");
    int sphere = 0;
    for (int i = 0; i < count; i++)
        if (!m[i].hemisphere && !m[i].horizon)
            at += snprintf(text + at, sizeof text - (size_t)at, "%s%s", sphere++ ? ", " : " ",
                           vb_method_name(m[i].method));
    snprintf(text + at, sizeof text - (size_t)at,
             " trace only the upper half\n%26sof the --rays directions\n", "");
    return text;
}

/* "shadow, lsq, mirror, paper or full": the table's names. */
static const char *method_names(void)
{
    static char text[512];
    int at = 0;
    for (int i = 0; i < VB_METHOD_COUNT; i++)
        at += snprintf(text + at, sizeof text - (size_t)at, "%s%s",
                       i == 0                     ? ""
                       : i + 1 == VB_METHOD_COUNT ? " or "
                                                  : ", ",
                       vb_method_name((vb_method)i));
    return text;
}

static void on_round(void *user, uint32_t round, uint32_t receivers, uint32_t candidates,
                     uint32_t split, double seconds)
{
    fprintf((FILE *)user,
            "vdsh-bake: adaptive round %u: %u of %u midpoints split, %u "
            "receivers (%.2f s)\n",
            round, split, candidates, receivers, seconds);
}

/* The default --cpca as --help and the --cpca usage message say it. */
static void cpca_default_text(char *buf, size_t size)
{
    snprintf(buf, size, "%u,alloc:%u,margin:%g,starts:%u%s", VDSH_CPCA_DEFAULT_CLUSTERS,
             VDSH_CPCA_DEFAULT_BUDGET, (double)VDSH_CPCA_DEFAULT_MARGIN, VDSH_CPCA_DEFAULT_STARTS,
             VDSH_CPCA_DEFAULT_BASES_S8 ? ",bases:8" : "");
}

static void usage(FILE *f)
{
    char cpca_default[64];
    cpca_default_text(cpca_default, sizeof cpca_default);
    /* The default grid's side: the defaults are square grids. */
    const unsigned rays_side = (unsigned)lround(sqrt((double)VB_DEFAULT_RAYS));
    fprintf(f,
            "usage: vdsh-bake [options] MESH... -o OUT.vdsh\n"
            "Bake visibility-distance spherical harmonics for a static scene.\n"
            "\n"
            "MESH is an OBJ, PLY, OFF or STL file, a glTF 2.0 file (.gltf or .glb:\n"
            "its default scene's triangles), builtin:room (a procedural 19 x 6 x 19 m\n"
            "room) or builtin:room:N, N >= 1 (seeded variants: furnished rooms of\n"
            "varied size and shape). Several meshes form one scene: they occlude each\n"
            "other.\n"
            "Receivers are the mesh vertices (refined with --max-edge); rays are traced\n"
            "against the original triangles.\n"
            "\n"
            "Output:\n"
            "  -o, --output FILE       the .vdsh file to write (atomically)\n"
            "      --cubemap-dir DIR   where the SH basis cubemaps go (default: beside OUT)\n"
            "      --cube-size N       cubemap face size in texels (default %d; 0: none)\n"
            "      --sdf N             also bake the signed distance volume of the scene for\n"
            "                          vdsh-view --mode sdf: N samples along the bounds'\n"
            "                          longest side (%d..%d; 64 is a good start), written\n"
            "                          to OUT's companion file (room.vdsh: room.sdf)\n"
            "      --encoding E        coefficient encoding: s8s6 (default: bands 0-1 signed\n"
            "                          8-bit, bands 2+ 6-bit, a scale per coefficient\n"
            "                          index; 4, 8, 24 bytes per vertex at orders 2, 3, 5),\n"
            "                          s8 (all 8-bit: 4, 9, 25), f16 (8, 18, 50) or f32;\n"
            "                          compact ones within 0.1%% of f16: docs/ACCURACY.md;\n"
            "                          or cpca: clustered PCA of each order's coefficients\n"
            "                          (for orders 7..%d: order 12 in ~30-32 bytes per\n"
            "                          vertex; docs/ACCURACY.md \"Compressed high orders\");\n"
            "                          with --adaptive-order, its stream is written as a\n"
            "                          fixed cpca stream of order --max-order (zeros past\n"
            "                          each vertex's order)\n"
            "      --cpca K,B,BITS     cpca settings: clusters (1..256), basis vectors per\n"
            "                          cluster (capped at order^2), bits per weight (2..8);\n"
            "                          or auto[:BYTES]: per stream, of\n"
            "                          K = 4, 8, 16 at 4 bits with the largest B within\n"
            "                          BYTES per vertex (1..4096, default 32; the model\n"
            "                          included), the one with the least fit error\n"
            "                          (2-4x the encode time of one setting); or\n"
            "                          K,alloc:BYTES: K clusters, a width per basis vector\n"
            "                          (2..8 bits) within BYTES per vertex (1..4096, the\n"
            "                          model included; K is a most: a model over the\n"
            "                          budget halves it); each may end in ,light:A: the\n"
            "                          fit's metric weights each receiver's hemisphere by\n"
            "                          (1 - A) + A x the density of 2048 lights placed by\n"
            "                          the scene's light rule (A in 0..1, default %g for\n"
            "                          alloc and auto; 0, the uniform hemisphere, for\n"
            "                          K,B,BITS, where it lost on the validation meshes;\n"
            "                          docs/ACCURACY.md \"A light-density metric\");\n"
            "                          K,alloc:BYTES may also end in ,margin:S (each pool\n"
            "                          light weighted by 1 / (1 + (m / S)^2), m its\n"
            "                          decision margin) and ,starts:N (N k-means starts,\n"
            "                          the one whose decisions over the pool differ\n"
            "                          least kept, on up to --threads threads: N fits\n"
            "                          and one score of the pool) and ,bases:8 (the\n"
            "                          basis vectors stored in 8 bits, not f16: the bytes\n"
            "                          freed go to the weights; docs/ACCURACY.md \"Bases\n"
            "                          in 8 bits\"); a K,alloc:BYTES said has no margin,\n"
            "                          one start and f16 bases unless said.\n"
            "                          Default %s (order\n"
            "                          12 within 3%% of uncompressed on all 15\n"
            "                          validation bakes, mean +1.0%%; two starts 14,\n"
            "                          +1.1%%; f16 bases 13, +1.5%%; %u,alloc:%u alone 11,\n"
            "                          +2.0%%, at a third of the encode's CPU time:\n"
            "                          docs/ACCURACY.md \"A third start\"); options\n"
            "                          alone change the default's (starts:2,\n"
            "                          margin:0.5, bases:16; light:0 alone: the\n"
            "                          uniform metric, no margin, one start)\n"
            "      --shard I/N         bake shard I (0-based) of N only and write a part\n"
            "                          file; vdsh-merge joins the N parts into the file\n"
            "                          the whole bake writes, byte for byte\n"
            "      --report FILE       write timings and throughput as JSON\n"
            "      --record-timings    also store timings in the .vdsh (the file is then\n"
            "                          no longer byte-identical between runs)\n"
            "      --export-obj FILE   write the receiver mesh as OBJ (with -o beside the\n"
            "                          bake; without: the OBJ only, no bake)\n"
            "      --trace-only        benchmark: build the BVH and trace the same rays,\n"
            "                          nothing else; no file is written (with --report,\n"
            "                          the bare loop's time is the build + trace time)\n"
            "\n"
            "Bake:\n"
            "      --rays N            directions per receiver over the sphere, stratified\n"
            "                          and jittered (default %u = %u x %u); the fits\n"
            "                          of the upper hemisphere trace the N/2 above the\n"
            "                          horizon (vdsh-info's 'rays')\n"
            "      --rays auto         adaptive: nested stratified rounds (a power-of-two\n"
            "                          grid under %u, from 1/16 of it), each receiver\n"
            "                          stopping when a round changes its fit by less\n"
            "                          than --ray-tolerance in expected shadow error\n"
            "      --ray-tolerance T   with --rays auto (default %g; 0: every round)\n"
            "      --orders LIST       SH orders to store, order n = n bands = n*n\n"
            "                          coefficients (default 2,3,5, or none with\n"
            "                          --adaptive-order; each 1..%d: orders above 5 are\n"
            "                          drawn from buffers, for long shadows)\n"
            "      --adaptive-order TOL  one more stream, of variable order: each\n"
            "                          receiver gets the lowest candidate order (1, 2,\n"
            "                          3, 5, 7, 9, 12, up to --max-order) whose error is\n"
            "                          within TOL of the least of them; decision (the\n"
            "                          default): the decision loss of each order's lsq\n"
            "                          fit on the receiver's training lights, the chosen\n"
            "                          order then fitted to the decision, one offset\n"
            "                          calibrated for the stream; shadow: the expected\n"
            "                          shadow error on its own traced directions, under\n"
            "                          lights in the scene's free space\n"
            "      --max-order N       the adaptive order's cap (default %d)\n"
            "      --method M          the fit:\n"
            "%s"
            "      --quantity Q        what the SH store: auto (default): log for decision\n"
            "                          and shadow,\n"
            "                          distance for paper, and for the others per order\n"
            "                          the one with the lower expected shadow error on\n"
            "                          1024 sampled receivers; distance; log:\n"
            "                          ln(distance), reconstructed as exp of the SH sum\n"
            "                          (not with paper; the only one with decision and\n"
            "                          shadow)\n"
            "      --log               the same as --quantity log\n"
            "      --lambda X          lsq regularisation weight (default %g; decision\n"
            "                          and shadow use lsq's default)\n"
            "      --log-offset X      decision, shadow: added to the fitted ln d at every\n"
            "                          order (decision: calibrated per scene and order at\n"
            "                          bake time; shadow: per order 2/3/5 %.2f/%.2f/%.2f,\n"
            "                          chosen on validation scenes); recorded as the\n"
            "                          stream's method parameter\n"
            "      --false-rate R      decision: the share of lit (light, receiver) pairs\n"
            "                          the calibrated offset leaves in false shadow, on\n"
            "                          held-out lights (default %g)\n"
            "      --offset-cap TOL[,KEEP[,MIN]]\n"
            "                          decision: cap each receiver's log offset (raise it,\n"
            "                          never above 0) so that KEEP of its lit training\n"
            "                          pairs stay lit, less TOL ln units, where it has\n"
            "                          at least MIN lit pairs (default KEEP 1, MIN 1); a\n"
            "                          negative TOL keeps them lit by -TOL more; the\n"
            "                          calibration runs through the capped offsets.\n"
            "                          Fixed orders only (issue 25, docs/ACCURACY.md)\n"
            "      --decision-lights N decision: training lights per receiver, each\n"
            "                          traced (1..%d, default %d)\n"
            "      --decision-near K   decision: one in K of the training lights placed\n"
            "                          near a surface (in free space, a surface within\n"
            "                          5%% of the diagonal: vdsh-eval's --light-rule\n"
            "                          near), the rest and the calibration's lights\n"
            "                          uniform in free space (0: none; default %d)\n"
            "      --decision-shell K  decision: one in K of the training lights placed\n"
            "                          around an object (outside its bounds, inside them\n"
            "                          grown by a quarter diagonal: vdsh-eval's\n"
            "                          --light-rule shell); the calibration's stay in the\n"
            "                          light region (0: none, the default; objects only)\n"
            "      --light-region SPEC where your lights go: every light the bake places\n"
            "                          (the decision fit's training and calibration\n"
            "                          lights, the cpca metric's pool) goes there, in\n"
            "                          free space, and readers (vdsh-view, vdsh-eval,\n"
            "                          vdsh-frames) put their lights there too: auto (the\n"
            "                          scene's rule, default), grown (the bounds grown by a\n"
            "                          quarter of their diagonal on every side but one a\n"
            "                          one-sided surface closes, as below an open floor:\n"
            "                          lights around and above an object) or a box\n"
            "                          XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX in scene units\n"
            "      --decision-params TAU,LIT,RIDGE,RIDGE0,STEPS\n"
            "                          decision: the loss's temperature (ln units), the\n"
            "                          weight of lit pairs, the ridge per (l(l+1))^2 and\n"
            "                          on every coefficient toward the lsq fit, Newton\n"
            "                          steps (default 0.5,8,1e-5,1e-4,3)\n"
            "      --window W          per-band window on the coefficients: none (default),\n"
            "                          hann or lanczos (width: the order)\n"
            "      --log-floor D       log-distance: distances below D count as D\n"
            "                          (default: 1%% of the max distance)\n"
            "      --max-distance D    clamp distance; misses get it (default: the\n"
            "                          scene's bounding-box diagonal)\n"
            "      --max-edge L        refine receivers until no edge is longer than L\n"
            "                          (default 0: the mesh vertices as they are)\n"
            "      --adaptive TOL      adaptive receivers: from --max-edge, split an edge\n"
            "                          where the stream interpolated between its ends\n"
            "                          differs from its midpoint's bake by more than TOL\n"
            "                          plus the bake's noise floor (two bakes of a\n"
            "                          sample of its start receivers; none at TOL 0)\n"
            "                          in expected shadow error (lights in the scene's\n"
            "                          free space); a split vertex keeps that bake\n"
            "                          (docs/ACCURACY.md, \"Adaptive receivers\")\n"
            "      --min-edge L        with --adaptive: no edge is split below 2 L\n"
            "                          (default: --max-edge / 8)\n"
            "      --max-receivers N   with --adaptive: stop at N receivers, splitting\n"
            "                          the largest errors first\n"
            "      --max-rounds N      with --adaptive: at most N rounds of splits\n"
            "                          (default %d; stderr says when it stops one still\n"
            "                          splitting)\n"
            "      --plan FILE         write the receivers (refined, or with --adaptive\n"
            "                          as baked) for shards to read with --receivers:\n"
            "                          FILE.ply binary PLY (fast to read), else OBJ;\n"
            "                          exact floats. Without -o: the plan only\n"
            "      --receivers FILE    bake these receivers (a mesh file, e.g. a plan)\n"
            "                          as they are, instead of the scene's vertices\n"
            "      --weld              merge vertices with identical positions\n"
            "      --up-axis A         the meshes' up axis: y (default), z (most CAD\n"
            "                          and 3ds Max exports, STL), -z, x, -x or -y; the\n"
            "                          meshes are turned so that it points along +y\n"
            "                          (scenes are y-up) before anything else, and the\n"
            "                          file records it: vdsh-eval and vdsh-frames turn\n"
            "                          the sources the same way\n"
            "      --crease DEG        computed normals (a mesh without normals, or\n"
            "                          --weld): split vertices where faces meet at more\n"
            "                          than DEG degrees, each side its own normal\n"
            "                          (0..180, default %d; 0 or 180: off, smooth\n"
            "                          across every edge; 60 measures well, but is not\n"
            "                          the default: its bakes of Sponza differ between\n"
            "                          CPUs' kernel sets); file normals are kept\n"
            "      --keep-normals      keep normals that point into geometry (default:\n"
            "                          a receiver blocked at ~0 on its own side and open\n"
            "                          on the other gets its normal flipped)\n"
            "      --seed N            seed of every random sequence (default %u)\n"
            "      --no-robust         Embree's fast traversal instead of the robust one\n"
            "                          (default: robust; the fast one is 4-11%% quicker\n"
            "                          but lets grazing rays slip through creases, and\n"
            "                          which ones differs between CPUs' kernels)\n"
            "      --threads N         worker threads (default: all cores)\n"
            "\n"
            "  -q, --quiet             nothing on stderr but errors (no progress, summary,\n"
            "                          notes or warnings; progress: a line in place on a\n"
            "                          terminal, else a line every 5 s or 10%%, for logs)\n"
            "  -h, --help              this text\n"
            "  -V, --version           version\n"
            "\n"
            "Exit status: 0 success, 1 error, 2 usage error.\n"
            "Example: vdsh-bake builtin:room --max-edge 0.2 -o room.vdsh\n",
            VB_DEFAULT_CUBE_SIZE, VB_SDF_MIN_RESOLUTION, VB_SDF_MAX_RESOLUTION, VDSH_MAX_ORDER,
            (double)VDSH_CPCA_DEFAULT_LIGHT_MIX, cpca_default, VDSH_CPCA_DEFAULT_CLUSTERS,
            VDSH_CPCA_DEFAULT_BUDGET, VB_DEFAULT_RAYS, rays_side, rays_side, VB_DEFAULT_RAYS,
            (double)VB_DEFAULT_RAY_TOLERANCE, VDSH_MAX_ORDER, VB_DEFAULT_ORDER_CAP, methods_help(),
            (double)VB_DEFAULT_LAMBDA, (double)vb_shadow_log_offset(2),
            (double)vb_shadow_log_offset(3), (double)vb_shadow_log_offset(5),
            (double)VB_DEFAULT_FALSE_RATE, VB_DECISION_MAX_PAIRS, VB_DEFAULT_DECISION_LIGHTS,
            VB_DEFAULT_DECISION_NEAR, VB_ADAPTIVE_ROUNDS, VB_DEFAULT_CREASE, VB_DEFAULT_SEED);
}

static int bad_usage(const char *fmt, const char *arg)
{
    return vt_usage_error("vdsh-bake", fmt, arg);
}

/* ---- progress ------------------------------------------------------------ */

/* On a terminal one line rewritten in place; otherwise (a log, a pipe, a
 * Slurm shard's output) a line of its own every PROGRESS_SECONDS or each
 * 10% of the receivers, whichever comes first, and at the end. The ETA is
 * the rays still to trace at the rate they have been traced since this
 * loop's first report: never from the time before it (BVH build, origin
 * checks, the quantity choice), which made the first estimate 20x too
 * long. A new loop (adaptive rounds bake again) starts a new estimate. */
#define PROGRESS_SECONDS 5.0

typedef struct progress {
    int enabled;
    int terminal;  /* 1: \r in place; 0: a line each time */
    uint32_t rays; /* rays per receiver asked for (the cap with --rays auto) */
    double t0;     /* the bake's start */
    /* the current loop: its first report, and the last line printed */
    uint32_t total, last_done;
    double t_first, t_printed;
    uint32_t done_first;
    uint64_t traced_first;
    int decile_printed;
    int finished; /* this loop's 100% line is out */
} progress;

static void on_progress(void *user, uint32_t done, uint32_t total, uint64_t traced)
{
    progress *p = user;
    if (!p->enabled)
        return;
    double now = vb_now();
    if (p->t_first == 0.0 || total != p->total || done < p->last_done) {
        p->finished = 0;
        p->total = total;
        p->t_first = p->t_printed = now;
        p->done_first = done;
        p->traced_first = traced;
        p->decile_printed = total ? (int)(10.0 * done / total) : 10;
    }
    p->last_done = done;
    double frac = total ? (double)done / total : 1.0;
    int decile = (int)(10.0 * frac);
    int last = done == total;
    if (last && p->finished) /* the loop's closing report after one at 100% */
        return;
    p->finished = last;
    if (!p->terminal && !last && decile == p->decile_printed &&
        now - p->t_printed < PROGRESS_SECONDS)
        return;
    p->decile_printed = decile;
    p->t_printed = now;
    /* Rays left: the rays per receiver traced so far in this loop (the
     * nominal count before any finished), times the receivers left. */
    double dt = now - p->t_first;
    uint64_t rays_done = traced - p->traced_first;
    uint32_t recv_done = done - p->done_first;
    double per_receiver = recv_done > 0 ? (double)rays_done / recv_done : (double)p->rays;
    double rate = dt > 0.0 ? rays_done / dt : 0.0; /* rays per second */
    char eta[32] = "ETA -";
    if (last)
        snprintf(eta, sizeof eta, "%.1f s", now - p->t0);
    else if (rate > 0.0)
        snprintf(eta, sizeof eta, "ETA %.1f s", (total - done) * per_receiver / rate);
    double t = now - p->t0;
    fprintf(stderr, "%svdsh-bake: %5.1f%%  %u/%u receiver%s  %.1f Mrays/s  %s%s",
            p->terminal ? "\r" : "", 100.0 * frac, done, total, vdsh_s(total),
            rate > 0.0 ? rate * 1e-6 : (t > 0 ? traced / t * 1e-6 : 0.0), eta,
            p->terminal ? "   " : "\n");
    if (p->terminal && last)
        fputc('\n', stderr);
    fflush(stderr);
}

/* ---- interrupts ---------------------------------------------------------- */

/* SIGINT, SIGTERM and SIGHUP end a bake at once, removing the temporary
 * files of whatever it is writing (vt_cli_clean_exit_on_signals), except
 * while it writes its outputs (between vt_cli_defer_signals and
 * vt_cli_undefer_signals): then the signal waits until the last file is
 * in place, and the exit status still says the bake was interrupted.
 * SIGKILL cannot wait: each output is still replaced atomically, but its
 * temporary file stays, named "<output>.tmp...". */

/* The side outputs (--plan, --export-obj, --sdf): each staged beside its
 * target when made (vb_mesh_stage_obj, vdsh_sdf_stage) and renamed only
 * with the bake's other outputs, when everything has succeeded (with the
 * .vdsh file, before it: vb_job_write); a failed or interrupted bake
 * removes them, so it leaves none behind. Used with signals deferred. */
enum { SIDE_PLAN, SIDE_EXPORT, SIDE_SDF, SIDE_COUNT };
static vdsh_output side[SIDE_COUNT];
static char side_note[SIDE_COUNT][PATH_MAX + 160]; /* said once renamed */

/* ---- output -------------------------------------------------------------- */

/* The report: vt_json writes it atomically (formats/vdsh_output.h).
 * 0, or -1 with a message naming the file in msg. */
static void report_seconds(vt_json *j, cJSON *root, const vdsh_timings *t)
{
    cJSON *sec = vt_json_object(j, root, "seconds");
    vt_json_f64(j, sec, "load", t->load);
    vt_json_f64(j, sec, "refine", t->refine);
    vt_json_f64(j, sec, "build", t->build);
    vt_json_f64(j, sec, "trace", t->trace);
}

/* The report's "cpca": the settings the streams were fitted with, light
 * mix and pool included: a whole file does not record them (VDSH.md
 * "cpca streams"), a part's `part` and `lpol` chunks do. light_pool 0:
 * the uniform metric (a mix of 0, or no room for the pool). */
static void report_cpca(vt_json *j, cJSON *root, const options *o, const vb_job *job,
                        const vb_job_desc *jd)
{
    if (o->encoding != VDSH_ENCODING_CPCA) {
        vt_json_null(j, root, "cpca");
        return;
    }
    const vdsh_cpca_settings st = vb_job_cpca_settings(job, jd);
    cJSON *cp = vt_json_object(j, root, "cpca");
    vt_json_u64(j, cp, "clusters", st.clusters);
    vt_json_u64(j, cp, "basis", st.budget ? 0 : st.basis);
    vt_json_u64(j, cp, "bits", st.budget ? 0 : st.bits);
    vt_json_u64(j, cp, "budget", st.budget);
    vt_json_f32(j, cp, "light_mix", st.light_mix);
    vt_json_u64(j, cp, "light_pool", st.light_count);
    vt_json_f32(j, cp, "margin", st.margin);
    vt_json_u64(j, cp, "starts", st.starts);
}

/* The receivers' spacing before any bake (vb_mesh_spacing_of). */
static void report_spacing(vt_json *j, cJSON *root, const vb_mesh_spacing *sp)
{
    cJSON *spc = vt_json_object(j, root, "receiver_spacing");
    vt_json_f32(j, spc, "scene_diagonal", sp->diagonal);
    vt_json_f32(j, spc, "median_longest_edge", sp->median_edge);
    vt_json_f32(j, spc, "p90_longest_edge", sp->p90_edge);
    vt_json_f32(j, spc, "max_longest_edge", sp->max_edge);
    vt_json_f64(j, spc, "long_area_share", sp->long_area);
    vt_json_bool(j, spc, "far_apart", sp->far_apart);
}

/* The adaptive receivers' parameters and how their rounds ended. */
static void report_adaptive(vt_json *j, cJSON *root, const options *o, const vb_job *job)
{
    if (!o->adaptive) {
        vt_json_null(j, root, "adaptive");
        return;
    }
    cJSON *ad = vt_json_object(j, root, "adaptive");
    vt_json_f32(j, ad, "tolerance", o->adaptive_tol);
    vt_json_f32(j, ad, "min_edge", o->min_edge);
    vt_json_u64(j, ad, "max_receivers", o->max_receivers);
    vt_json_u64(j, ad, "start_receivers", job->adaptive.start_receivers);
    vt_json_u64(j, ad, "rounds", job->adaptive.rounds);
    vt_json_u64(j, ad, "midpoints_baked", job->adaptive.candidates);
    vt_json_bool(j, ad, "budget_reached", job->adaptive.budget_reached);
    vt_json_u64(j, ad, "max_rounds", job->adaptive.max_rounds);
    vt_json_bool(j, ad, "rounds_reached", job->adaptive.rounds_reached);
    vt_json_u64(j, ad, "edges_pending", job->adaptive.pending);
    vt_json_u64(j, ad, "uniform_receivers", job->adaptive.uniform_receivers);
    vt_json_bool(j, ad, "uniform_reached", job->adaptive.uniform_reached);
    vt_json_u64(j, ad, "noise_sample", job->adaptive.noise_sample);
    vt_json_f64(j, ad, "noise_floor", job->adaptive.noise_floor);
    vt_json_f64(j, ad, "threshold", job->adaptive.threshold);
}

/* The decision fit: its lights and pools, fits, calibration and the log
 * offsets per order. */
static void report_decision(vt_json *j, cJSON *root, const options *o, const vb_bake_output *b)
{
    if (b->method != VDSH_METHOD_DECISION) {
        vt_json_null(j, root, "decision");
        return;
    }
    cJSON *dec = vt_json_object(j, root, "decision");
    vt_json_u64(j, dec, "lights", b->decision_lights);
    vt_json_u64(j, dec, "near_pool_lights", b->decision_near_lights);
    vt_json_u64(j, dec, "shell_pool_lights", b->decision_shell_lights);
    vt_json_u64(j, dec, "fitted", b->decision_fitted);
    vt_json_u64(j, dec, "kept_lsq", b->decision_fallbacks);
    vt_json_f64(j, dec, "mean_pairs", b->decision_pairs);
    vt_json_u64(j, dec, "calibration_receivers", b->calibration_receivers);
    vt_json_f32(j, dec, "false_rate", b->false_rate);
    vt_json_u64(j, dec, "offset_cap_bound", b->cap_bound);
    vt_json_u64(j, dec, "lit_training_pairs", b->lit_training);
    vt_json_u64(j, dec, "lit_training_false", b->lit_training_false);
    if (b->decision_lights) {
        vt_json_string(j, dec, "light_region",
                       b->light_region_given   ? "given"
                       : b->light_region_grown ? "grown"
                                               : "bounds");
        vt_json_u64(j, dec, "light_region_probes", b->light_region_probes);
    }
    if (b->calibration_receivers)
        vt_json_u64(j, dec, "held_out_shadowed", b->calibration_shadowed);
    cJSON *off = vt_json_object(j, dec, "log_offsets");
    for (int i = 0; i < o->order_count; i++) {
        char key[8];
        snprintf(key, sizeof key, "%d", o->orders[i]);
        vt_json_f32(j, off, key, b->log_offset[o->orders[i]]);
    }
    if (b->variable_cap && b->variable_method == VDSH_METHOD_DECISION)
        vt_json_f32(j, off, "adaptive", b->variable_param);
}

/* The bake's rays: counts, receivers repaired, and the origins' probes. */
static void report_rays(vt_json *j, cJSON *root, const vb_bake_output *b)
{
    vt_json_u64(j, root, "rays_traced", b->rays_traced);
    vt_json_u64(j, root, "rays_missed", b->rays_missed);
    vt_json_u64(j, root, "degenerate_receivers", b->degenerate_receivers);
    vt_json_u64(j, root, "undefined_normals", b->undefined_normals);
    vt_json_u64(j, root, "moved_origins", b->moved_origins);
    vt_json_u64(j, root, "flipped_normals", b->flipped_normals);
    cJSON *org = vt_json_object(j, root, "origins");
    vt_json_u64(j, org, "probe_rays", b->origins.probe_rays);
    vt_json_u64(j, org, "repaired", b->origins.flagged);
    vt_json_u64(j, org, "moved", b->origins.moved);
    vt_json_u64(j, org, "coincident_faces", b->origins.ties);
    vt_json_u64(j, org, "skipped_zero_area", b->origins.skipped_zero_area);
}

/* The times of every step, the write's included, and the ray rates. */
static void report_times(vt_json *j, cJSON *root, const vb_job *job, double encode_seconds,
                         double write_seconds)
{
    const vb_bake_output *b = &job->bake;
    const vdsh_timings *t = &job->timings;
    report_seconds(j, root, t);
    cJSON *sec = cJSON_GetObjectItemCaseSensitive(root, "seconds");
    vt_json_f64(j, sec, "pool", job->pool_seconds);
    vt_json_f64(j, sec, "origins", b->origins.seconds);
    vt_json_f64(j, sec, "encode", encode_seconds); /* of write: the streams filled (cpca's fit) */
    vt_json_f64(j, sec, "write", write_seconds);
    vt_json_f64(j, sec, "total", t->total + write_seconds);
    vt_json_f64(j, root, "mrays_per_second_trace",
                t->trace > 0 ? b->rays_traced / t->trace * 1e-6 : 0.0);
    vt_json_f64(j, root, "mrays_per_second_total",
                t->total + write_seconds > 0 ? b->rays_traced / (t->total + write_seconds) * 1e-6
                                             : 0.0);
}

/* --sdf: the distance volume beside the output. */
static void report_sdf(vt_json *j, cJSON *root, const options *o, const vdsh_sdf *vol,
                       double sdf_seconds)
{
    if (!vol) {
        vt_json_null(j, root, "sdf");
        return;
    }
    cJSON *sdf = vt_json_object(j, root, "sdf");
    char sdf_path[PATH_MAX];
    if (vdsh_sdf_path(o->output, sdf_path, sizeof sdf_path) == 0)
        vt_json_string(j, sdf, "path", sdf_path);
    cJSON *dim = vt_json_array(j, sdf, "dims");
    for (int i = 0; i < 3; i++)
        vt_json_u64(j, dim, NULL, vol->dim[i]);
    vt_json_f64(j, sdf, "spacing", vol->cell);
    vt_json_f64(j, sdf, "seconds", sdf_seconds);
    vt_json_u64(j, sdf, "bytes", vdsh_sdf_file_size(vol));
}

static int write_report(const char *path, const options *o, const vb_job_desc *jd,
                        const vb_job *job, const vb_mesh_spacing *sp, const vdsh_sdf *vol,
                        double sdf_seconds, double encode_seconds, double write_seconds, char *msg,
                        size_t cap)
{
    const vdsh_file *f = &job->file;
    const vb_bake_output *b = &job->bake;
    vt_json j = {0};
    cJSON *root = vt_json_object(&j, NULL, NULL);
    vt_json_string(&j, root, "output", o->output);
    cJSON *src = vt_json_array(&j, root, "sources");
    for (uint32_t i = 0; i < f->source_count; i++)
        vt_json_string(&j, src, NULL, f->sources[i].name);
    vt_json_u64(&j, root, "receivers", f->header.vertex_count);
    vt_json_u64(&j, root, "receiver_triangles", f->header.triangle_count);
    vt_json_u64(&j, root, "occluder_triangles", f->header.occluder_triangle_count);
    vt_json_u64(&j, root, "rays_per_receiver", b->rays);
    vt_json_bool(&j, root, "adaptive_rays", o->adaptive_rays);
    if (o->adaptive_rays)
        vt_json_f64(&j, root, "ray_tolerance", b->ray_tolerance);
    vt_json_f64(&j, root, "mean_rays_traced",
                b->vertex_count ? (double)b->rays_traced / b->vertex_count : 0.0);
    vt_json_string(&j, root, "method", vb_method_name(o->method));
    cJSON *orders = vt_json_array(&j, root, "orders");
    for (int i = 0; i < o->order_count; i++)
        vt_json_u64(&j, orders, NULL, (uint64_t)o->orders[i]);
    vt_json_string(&j, root, "encoding", vdsh_encoding_name(o->encoding));
    report_cpca(&j, root, o, job, jd);
    vt_json_f32(&j, root, "max_distance", b->max_distance);
    vt_json_f32(&j, root, "max_edge", o->max_edge);
    report_spacing(&j, root, sp);
    /* The receivers as baked: their worst triangle (vb_mesh_worst_aspect:
     * 1 equilateral, 1.73 right isosceles). */
    vt_json_f64(&j, root, "worst_aspect", vb_mesh_worst_aspect(&job->receivers, NULL));
    report_adaptive(&j, root, o, job);
    report_decision(&j, root, o, b);
    vt_json_u64(&j, root, "seed", o->seed);
    vt_json_u64(&j, root, "threads", b->threads);
    vt_json_bool(&j, root, "robust", o->robust);
    report_rays(&j, root, b);
    report_times(&j, root, job, encode_seconds, write_seconds);
    vt_json_u64(&j, root, "coefficient_bytes_per_vertex", job->coefficient_bytes);
    vt_json_i64(&j, root, "file_bytes", (long long)job->file_bytes);
    report_sdf(&j, root, o, vol, sdf_seconds);
    int r = vt_json_write_file(&j, path, msg, cap);
    vt_json_free(&j);
    return r;
}

/* The bare loop's record: what the benchmark compares the bake against. */
static int write_bare_report(const char *path, const vb_bake_output *b, const vdsh_timings *t,
                             char *msg, size_t cap)
{
    vt_json j = {0};
    cJSON *root = vt_json_object(&j, NULL, NULL);
    vt_json_bool(&j, root, "trace_only", 1);
    vt_json_u64(&j, root, "receivers", b->vertex_count);
    vt_json_u64(&j, root, "rays_per_receiver", b->rays);
    vt_json_u64(&j, root, "threads", b->threads);
    vt_json_u64(&j, root, "rays_traced", b->rays_traced);
    report_seconds(&j, root, t);
    vt_json_f64(&j, cJSON_GetObjectItemCaseSensitive(root, "seconds"), "bare", t->build + t->trace);
    int r = vt_json_write_file(&j, path, msg, cap);
    vt_json_free(&j);
    return r;
}

/* One mesh loaded (vb_job_desc.on_mesh): what it holds, and what the
 * reader repaired or refused. */
static void on_mesh(void *user, const char *path, const vb_mesh *m, const vb_source_info *info,
                    double seconds)
{
    FILE *log = user;
    fprintf(log, "vdsh-bake: %s: %u %s, %u triangle%s (%.2f s)\n", path, m->vertex_count,
            vdsh_plural(m->vertex_count, "vertex", "vertices"), m->triangle_count,
            vdsh_s(m->triangle_count), seconds);
    vb_mesh_report_print(log, "vdsh-bake", path, &info->report);
}

/* ---- main ---------------------------------------------------------------- */

/* Stage the receivers as a plan for shards (--plan; side[SIDE_PLAN]):
 * binary PLY when the name ends in .ply, else OBJ; exact floats either
 * way. Nonzero on error (said on stderr). */
static int write_plan(const vb_mesh *m, const char *path)
{
    vb_error err;
    size_t n = strlen(path);
    vdsh_output *out = &side[SIDE_PLAN];
    vt_cli_defer_signals();
    vb_result r = n > 4 && strcasecmp(path + n - 4, ".ply") == 0
                      ? vb_mesh_stage_ply(m, path, out, &err)
                      : vb_mesh_stage_obj(m, path, out, &err);
    vt_cli_undefer_signals();
    if (r != VB_OK) {
        fprintf(stderr, "vdsh-bake: %s\n", err.msg);
        return 1;
    }
    snprintf(side_note[SIDE_PLAN], sizeof side_note[SIDE_PLAN],
             "wrote the plan %s (%u receiver%s, %u triangle%s)", path, m->vertex_count,
             vdsh_s(m->vertex_count), m->triangle_count, vdsh_s(m->triangle_count));
    return 0;
}

/* Say the side outputs that are now in place (their notes, once). */
static void say_sides(FILE *log)
{
    for (int k = 0; k < SIDE_COUNT; k++) {
        if (log && side_note[k][0] && !side[k].path)
            fprintf(log, "vdsh-bake: %s\n", side_note[k]);
        if (!side[k].path)
            side_note[k][0] = '\0';
    }
}

/* Rename the staged side outputs into place (the bake succeeded without
 * a .vdsh file to write them with). Nonzero on error (said). Under
 * deferred signals. */
static int commit_sides(FILE *log)
{
    int bad = 0;
    for (int k = 0; k < SIDE_COUNT; k++) {
        vdsh_error verr;
        if (side[k].path && vdsh_output_commit(&side[k], &verr) != VDSH_OK) {
            fprintf(stderr, "vdsh-bake: %s\n", verr.msg);
            bad = 1;
        }
    }
    say_sides(log);
    return bad;
}

/* Every file the bake will write (vt_cli_check_outputs): the .vdsh file
 * and its basis cubemaps, the report, the plan and the OBJ export. */
static int check_outputs(const options *o, const vb_job_desc *jd, const char *const *meshes,
                         int nmesh)
{
    char cube[VB_CUBEMAP_BASIS_FILES][PATH_MAX];
    const char *outs[4 + VB_CUBEMAP_BASIS_FILES] = {jd->output, o->report, o->plan, o->export_obj};
    int n = 4;
    vb_error err;
    {
        const char *files[] = {jd->output, o->plan, o->export_obj};
        const char *opts[] = {"-o", "--plan", "--export-obj"};
        int rc = vt_cli_no_stdout(files, opts, 3);
        if (rc)
            return rc;
    }
    if (jd->output && !jd->shard_count && vb_job_cube_size(jd) > 0 &&
        vb_output_has_cubemaps(jd->output, jd->cubemap_dir))
        for (int k = 0; k < VB_CUBEMAP_BASIS_FILES; k++) {
            if (vb_output_cubemap_path(jd->output, jd->cubemap_dir, k, cube[k], sizeof cube[k],
                                       &err) != VB_OK) {
                fprintf(stderr, "vdsh-bake: %s\n", err.msg);
                return 1;
            }
            outs[n++] = cube[k];
        }
    const char *ins[VDSH_MAX_SOURCES + 1];
    int nin = 0;
    for (int i = 0; i < nmesh && i < VDSH_MAX_SOURCES; i++)
        ins[nin++] = meshes[i];
    ins[nin++] = o->receivers;
    /* The checks make and remove a temporary beside each output: an
     * interrupt waits for them as for the writes. */
    vt_cli_defer_signals();
    int bad = vt_cli_check_outputs(outs, n, ins, nin);
    vt_cli_undefer_signals();
    return bad;
}

/* ---- the command line ---------------------------------------------------- */

/* The long options' codes (getopt_long), and what reading one answers:
 * taken, not this reader's, or the usage status (said). */
enum {
    O_RAYS = 256,
    O_ORDERS,
    O_METHOD,
    O_ENCODING,
    O_MAXDIST,
    O_MAXEDGE,
    O_WELD,
    O_UP_AXIS,
    O_CREASE,
    O_SEED,
    O_THREADS,
    O_CUBESIZE,
    O_CUBEDIR,
    O_ROBUST,
    O_NO_ROBUST,
    O_REPORT,
    O_TIMINGS,
    O_EXPORT,
    O_TRACE_ONLY,
    O_LOG,
    O_LAMBDA,
    O_LOG_OFFSET,
    O_LOG_FLOOR,
    O_KEEP_NORMALS,
    O_WINDOW,
    O_QUANTITY,
    O_RAY_TOL,
    O_SHARD,
    O_ADAPTIVE,
    O_MIN_EDGE,
    O_MAX_RECEIVERS,
    O_MAX_ROUNDS,
    O_PLAN,
    O_RECEIVERS,
    O_ADAPTIVE_ORDER,
    O_MAX_ORDER,
    O_DEC_LIGHTS,
    O_DEC_NEAR,
    O_DEC_SHELL,
    O_LIGHT_REGION,
    O_FALSE_RATE,
    O_OFFSET_CAP,
    O_DEC_PARAMS,
    O_SDF,
    O_CPCA
};
enum { OPT_NOT_MINE = -1, OPT_TAKEN = 1 };

/* The names --encoding takes: formats' encoding table (vdsh_encodings), in
 * its order. */
static const vt_choice *encodings(void)
{
    static vt_choice c[VDSH_ENCODING_LAST + 2];
    size_t n = 0;
    const vdsh_encoding_info *e = vdsh_encodings(&n);
    for (size_t i = 0; i < n && i <= VDSH_ENCODING_LAST; i++)
        c[i] = (vt_choice){e[i].name, (int)e[i].encoding};
    return c;
}

/* The names --quantity and --window take. */
static const vt_choice quantities[] = {{"auto", VB_QUANTITY_AUTO},
                                       {"distance", VB_QUANTITY_DISTANCE},
                                       {"log", VB_QUANTITY_LOG},
                                       {NULL, 0}};
static const vt_choice windows[] = {{"none", VDSH_WINDOW_NONE},
                                    {"hann", VDSH_WINDOW_HANN},
                                    {"lanczos", VDSH_WINDOW_LANCZOS},
                                    {NULL, 0}};

/* Options that take a number or a name, each checked on its own. */
static int read_value(int c, const char *arg, options *o)
{
    double t = 0.0;
    int ok = 1, v = 0;
    switch (c) {
    case O_RAYS:
        o->adaptive_rays = strcmp(arg, "auto") == 0;
        o->rays = VB_DEFAULT_RAYS;
        if (!o->adaptive_rays)
            ok = vt_opt_u32("--rays", "auto or a whole number", arg, 1, 1u << 20, &o->rays);
        break;
    case O_RAY_TOL:
        ok = vt_opt_tolerance("--ray-tolerance", "a number", arg, 1, &t);
        o->ray_tolerance = t == 0.0 ? -1.0f : (float)t;
        o->have_ray_tolerance = 1;
        break;
    case O_ORDERS: {
        int want[VDSH_ORDER_SLOTS];
        if (!(ok = vt_opt_orders("--orders", "2,3,5", arg, VDSH_MAX_ORDER, want)))
            break;
        o->order_count = 0;
        for (int k = 1; k <= VDSH_MAX_ORDER; k++)
            if (want[k])
                o->orders[o->order_count++] = k;
        o->orders_given = 1;
        break;
    }
    case O_ADAPTIVE_ORDER:
        ok = vt_opt_tolerance("--adaptive-order", NULL, arg, 0, &t);
        o->order_tolerance = (float)t;
        break;
    case O_MAX_ORDER:
        ok = vt_opt_int("--max-order", "an order", arg, 1, VDSH_MAX_ORDER, &o->max_order);
        break;
    case O_MAXDIST: ok = vt_opt_positive("--max-distance", arg, &o->max_distance); break;
    case O_MAXEDGE: ok = vt_opt_nonnegative("--max-edge", arg, &o->max_edge); break;
    case O_ADAPTIVE:
        ok = vt_opt_tolerance("--adaptive", NULL, arg, 1, &t);
        o->adaptive = 1;
        o->adaptive_tol = (float)t;
        break;
    case O_MIN_EDGE: ok = vt_opt_positive("--min-edge", arg, &o->min_edge); break;
    case O_MAX_RECEIVERS:
        ok = vt_opt_u32("--max-receivers", NULL, arg, 1, VDSH_MAX_VERTICES, &o->max_receivers);
        break;
    case O_MAX_ROUNDS: ok = vt_opt_u32("--max-rounds", NULL, arg, 1, 1000, &o->max_rounds); break;
    case O_SEED: ok = vt_opt_u64("--seed", NULL, arg, 0, UINT64_MAX, &o->seed); break;
    case O_THREADS: ok = vt_opt_u32("--threads", NULL, arg, 1, 256, &o->threads); break;
    case O_CREASE: ok = vt_opt_int("--crease", NULL, arg, 0, 180, &o->crease); break;
    case O_CUBESIZE: ok = vt_opt_int("--cube-size", NULL, arg, 0, 4096, &o->cube_size); break;
    case O_SDF:
        ok = vt_opt_int("--sdf", NULL, arg, VB_SDF_MIN_RESOLUTION, VB_SDF_MAX_RESOLUTION, &o->sdf);
        break;
    case O_LAMBDA: ok = vt_opt_positive("--lambda", arg, &o->lambda); break;
    case O_LOG_FLOOR: ok = vt_opt_positive("--log-floor", arg, &o->log_floor); break;
    case O_DEC_LIGHTS:
        ok =
            vt_opt_u32("--decision-lights", "", arg, 1, VB_DECISION_MAX_PAIRS, &o->decision_lights);
        break;
    case O_DEC_NEAR:
        ok = vt_opt_int("--decision-near", "", arg, 0, (int)VB_DECISION_POOL, &o->decision_near);
        o->decision_near = o->decision_near ? o->decision_near : -1; /* 0: none */
        break;
    case O_DEC_SHELL:
        ok = vt_opt_int("--decision-shell", "", arg, 0, (int)VB_DECISION_POOL, &o->decision_shell);
        break;
    case O_LIGHT_REGION:
        ok = vt_opt_light_region("--light-region", arg, 0, &o->light_region);
        break;
    case O_ENCODING:
        ok = vt_opt_choice("--encoding", arg, encodings(), &v);
        o->encoding = (vdsh_encoding)v;
        break;
    case O_QUANTITY:
        ok = vt_opt_choice("--quantity", arg, quantities, &v);
        o->quantity = (vb_quantity)v;
        break;
    case O_WINDOW:
        ok = vt_opt_choice("--window", arg, windows, &v);
        o->window = (vdsh_window)v;
        break;
    default: return OPT_NOT_MINE;
    }
    return ok ? OPT_TAKEN : VT_EXIT_USAGE;
}

/* Options that name a choice or take a tuple. */
static int read_choice(int c, const char *arg, options *o)
{
    switch (c) {
    case O_METHOD: {
        const vb_method_info *m = vb_method_by_name(arg);
        if (!m) {
            char fmt[640];
            snprintf(fmt, sizeof fmt, "--method takes %s, not '%%s'", method_names());
            return bad_usage(fmt, arg);
        }
        o->method = m->method;
        break;
    }
    case O_CPCA: {
        vdsh_error e;
        if (vdsh_cpca_parse(arg, &o->cpca, &e) != VDSH_OK) {
            char msg[sizeof e.msg + 512], deflt[64];
            cpca_default_text(deflt, sizeof deflt);
            snprintf(
                msg, sizeof msg,
                "--cpca takes K,B,BITS: clusters 1..256, basis vectors 1..256, bits 2..8, "
                "or auto or auto:BYTES, or K,alloc:BYTES (a width per basis vector), bytes "
                "per vertex 1..4096 (default %s), each "
                "optionally ending in ,light:A (the light mix A in 0..1), and K,alloc:BYTES in "
                ",margin:S (S > 0), ,starts:N (1..%d) and ,bases:8|16, or those options alone: "
                "%s",
                deflt, VDSH_CPCA_MAX_STARTS, e.msg);
            return bad_usage("%s", msg);
        }
        o->have_cpca = 1;
        break;
    }
    case O_LOG_OFFSET:
        if (!vt_parse_float(arg, &o->log_offset) || fabsf(o->log_offset) > 5.0f)
            return bad_usage("--log-offset takes a number in -5..5, not '%s'", arg);
        o->have_log_offset = 1;
        break;
    case O_FALSE_RATE:
        if (!vt_parse_float(arg, &o->false_rate) || !(o->false_rate > 0.0f) ||
            !(o->false_rate < 0.5f))
            return bad_usage("--false-rate takes a number in (0, 0.5), not '%s'", arg);
        break;
    case O_OFFSET_CAP: {
        float v[3] = {0.0f, 1.0f, 1.0f};
        int n = vt_parse_floats(arg, v, 1, 3);
        float tol = v[0], keep = v[1];
        unsigned min = v[2] >= 1.0f && v[2] <= (float)VB_DECISION_MAX_PAIRS && v[2] == floorf(v[2])
                           ? (unsigned)v[2]
                           : 0u;
        if (!n || !(fabsf(tol) <= 5.0f) || !(keep > 0.0f && keep <= 1.0f) || min < 1)
            return bad_usage("--offset-cap takes TOL[,KEEP[,MIN]]: a tolerance in -5..5 ln "
                             "units, the share of lit training pairs kept lit in (0, 1], the "
                             "least lit pairs 1..1024, not '%s'",
                             arg);
        o->offset_cap = 1;
        o->offset_cap_tol = tol;
        o->offset_cap_keep = keep;
        o->offset_cap_min = min;
        break;
    }
    case O_DEC_PARAMS: {
        vb_decision_params *p = &o->decision;
        vb_decision_defaults(p);
        float v[5] = {0.0f, 0.0f, 0.0f, 0.0f, -1.0f};
        int ok = vt_parse_floats(arg, v, 5, 5) == 5 && v[4] == floorf(v[4]);
        p->tau = v[0], p->lit_weight = v[1], p->ridge = v[2], p->ridge0 = v[3];
        p->steps = ok && v[4] >= 0.0f && v[4] <= 64.0f ? (int)v[4] : -1;
        if (!(p->tau > 0.0f) || !(p->lit_weight > 0.0f) || !(p->ridge >= 0.0f) ||
            !(p->ridge0 > 0.0f) || p->steps < 0 || p->steps > 64)
            return bad_usage("--decision-params takes TAU,LIT_WEIGHT,RIDGE,RIDGE0,STEPS "
                             "(positive; ridge >= 0; steps 0..64), not '%s'",
                             arg);
        o->have_decision = 1;
        break;
    }
    case O_SHARD: {
        unsigned si, sn;
        int used = 0;
        if (sscanf(arg, "%u/%u%n", &si, &sn, &used) != 2 || arg[used] || sn < 1 || sn > 1u << 20 ||
            si >= sn || !isdigit((unsigned char)arg[0]))
            return bad_usage("--shard takes I/N with 0 <= I < N <= 1048576, such as 3/8, "
                             "not '%s'",
                             arg);
        o->shard_index = si, o->shard_count = sn;
        break;
    }
    default: return OPT_NOT_MINE;
    }
    return OPT_TAKEN;
}

/* The options taken together: what one allows of another. VT_CLI_RUN or
 * VT_EXIT_USAGE (said). Sets what follows from them (min_edge, the orders
 * with --adaptive-order alone). */
static int check_options(options *o)
{
    if (o->have_cpca && o->encoding != VDSH_ENCODING_CPCA)
        return bad_usage("--cpca %s needs --encoding cpca", "K,B,BITS");
    if (o->encoding == VDSH_ENCODING_CPCA && o->order_tolerance > 0.0f && o->orders_given) {
        /* cpca writes the adaptive-order stream as a fixed stream of its cap */
        int cap = o->max_order ? o->max_order : VB_DEFAULT_ORDER_CAP;
        for (int s = 0; s < o->order_count; s++)
            if (o->orders[s] == cap) {
                char n[8];
                snprintf(n, sizeof n, "%d", cap);
                return bad_usage("--encoding cpca writes --adaptive-order's stream as a "
                                 "fixed stream of its --max-order, %s: --orders cannot "
                                 "hold that order too",
                                 n);
            }
    }
    if (o->have_ray_tolerance && !o->adaptive_rays)
        return bad_usage("%s needs --rays auto", "--ray-tolerance");
    if ((o->min_edge > 0.0f || o->max_receivers || o->max_rounds) && !o->adaptive)
        return bad_usage("%s need --adaptive TOL", "--min-edge, --max-receivers and --max-rounds");
    if (o->adaptive && !(o->max_edge > 0.0f))
        return bad_usage("%s", "--adaptive needs --max-edge L: the uniform refinement it "
                               "starts from (the coarsest receivers)");
    if (o->adaptive && o->min_edge == 0.0f)
        o->min_edge = o->max_edge / 8.0f;
    if (o->adaptive && o->shard_count)
        return bad_usage("%s", "--adaptive cannot be combined with --shard: the refinement "
                               "bakes as it decides. Plan it once (--adaptive ... --plan "
                               "plan.obj), then shard the plan (--receivers plan.obj --shard I/N)");
    if (o->sdf && (o->shard_count || !o->output || o->trace_only))
        return bad_usage("%s", "--sdf writes beside the output file: it needs -o OUT.vdsh, "
                               "and neither --shard nor --trace-only");
    if (o->sdf && vdsh_output_is_stream(o->output))
        return bad_usage("--sdf writes OUT's companion file beside it: not with -o %s, "
                         "a device or pipe",
                         o->output);
    if (o->plan && o->receivers)
        return bad_usage("%s", "--plan writes the receivers --receivers reads: not both");
    if (o->receivers && (o->adaptive || o->max_edge > 0.0f || o->weld))
        return bad_usage("%s", "--receivers takes the receivers as they are: not with "
                               "--adaptive, --max-edge or --weld");
    if (o->crease >= 180)
        o->crease = 0; /* 180: no crease is sharper */
    if (o->mesh_count < 1)
        return bad_usage("%s", "no mesh given");
    if (o->mesh_count > VDSH_MAX_SOURCES)
        return bad_usage("%s", "too many meshes (at most 64)");
    /* The same mesh twice (by name, or the same file by device and inode)
     * would bake its triangles twice, each over the other. */
    for (int i = 1; i < o->mesh_count; i++)
        for (int j = 0; j < i; j++) {
            const int named_twice = strcmp(o->meshes[i], o->meshes[j]) == 0;
            if (!named_twice && !vt_cli_same_file(o->meshes[j], o->meshes[i]))
                continue;
            char msg[2 * PATH_MAX + 128];
            if (named_twice)
                snprintf(msg, sizeof msg, "%s given twice", o->meshes[i]);
            else
                snprintf(msg, sizeof msg, "%s and %s are the same file", o->meshes[j],
                         o->meshes[i]);
            size_t len = strlen(msg);
            snprintf(msg + len, sizeof msg - len,
                     ": its triangles would be baked twice, each copy over the other");
            return bad_usage("%s", msg);
        }
    /* What the method's row allows. */
    const vb_method_info *mi = vb_method_get(o->method);
    vdsh_quantity stored = vb_quantity_stored(o->quantity);
    if (o->quantity != VB_QUANTITY_AUTO && !(mi->quantities & VB_QUANTITY_BIT(stored)))
        return bad_usage("%s", mi->refused[stored]);
    if (o->have_log_offset && mi->param != VB_PARAM_LOG_OFFSET)
        return bad_usage("%s", "--log-offset is methods decision's and shadow's");
    if ((o->false_rate != 0.0f || o->decision_lights || o->decision_near || o->decision_shell ||
         o->have_decision || o->offset_cap) &&
        !mi->decision)
        return bad_usage("%s",
                         "--false-rate, --decision-lights, --decision-near, --decision-shell, "
                         "--decision-params and --offset-cap are method decision's");
    if (o->lambda != 0.0f && mi->lambda_fixed)
        return bad_usage("--lambda is lsq's: method %s uses lsq's default (its method "
                         "parameter is the log offset)",
                         vb_method_name(o->method));
    if (!o->output && !o->export_obj && !o->trace_only && !o->plan)
        return bad_usage("%s", "no output: give -o OUT.vdsh (or --export-obj FILE)");
    if (o->max_order && !(o->order_tolerance > 0.0f))
        return bad_usage("%s", "--max-order is the cap of --adaptive-order TOL");
    if (o->order_tolerance > 0.0f &&
        !(mi->quantities & VB_QUANTITY_BIT(VDSH_QUANTITY_LOG_DISTANCE)))
        return bad_usage("--adaptive-order fits the log distance: method %s does not (use "
                         "decision, the default, or shadow)",
                         vb_method_name(o->method));
    if (o->order_tolerance > 0.0f && !o->orders_given)
        o->order_count = 0; /* the variable-order stream alone */
    if (o->offset_cap && o->order_count == 0)
        return bad_usage("%s", "--offset-cap caps the fixed orders' offsets: this bake writes "
                               "the adaptive order's stream alone (add --orders)");

    return VT_CLI_RUN;
}

/* The command line into *o: VT_CLI_RUN, or the exit status (0 after --help
 * or --version; VT_EXIT_USAGE after saying what is wrong). */
static int parse_args(int argc, char **argv, options *o)
{
    *o = (options){0};
    o->rays = VB_DEFAULT_RAYS;
    o->orders[0] = 2, o->orders[1] = 3, o->orders[2] = 5, o->order_count = 3;
    /* method and quantity: 0 is the default (decision, auto) */
    o->encoding = VB_DEFAULT_ENCODING;
    o->seed = VB_DEFAULT_SEED;
    o->robust = 1;
    o->cube_size = VB_DEFAULT_CUBE_SIZE;
    o->crease = VB_DEFAULT_CREASE;

    static const struct option longopts[] = {
        {"output", required_argument, 0, 'o'},
        {"rays", required_argument, 0, O_RAYS},
        {"ray-tolerance", required_argument, 0, O_RAY_TOL},
        {"orders", required_argument, 0, O_ORDERS},
        {"adaptive-order", required_argument, 0, O_ADAPTIVE_ORDER},
        {"max-order", required_argument, 0, O_MAX_ORDER},
        {"method", required_argument, 0, O_METHOD},
        {"encoding", required_argument, 0, O_ENCODING},
        {"cpca", required_argument, 0, O_CPCA},
        {"max-distance", required_argument, 0, O_MAXDIST},
        {"max-edge", required_argument, 0, O_MAXEDGE},
        {"weld", no_argument, 0, O_WELD},
        {"up-axis", required_argument, 0, O_UP_AXIS},
        {"crease", required_argument, 0, O_CREASE},
        {"seed", required_argument, 0, O_SEED},
        {"threads", required_argument, 0, O_THREADS},
        {"cube-size", required_argument, 0, O_CUBESIZE},
        {"sdf", required_argument, 0, O_SDF},
        {"cubemap-dir", required_argument, 0, O_CUBEDIR},
        {"robust", no_argument, 0, O_ROBUST},
        {"no-robust", no_argument, 0, O_NO_ROBUST},
        {"report", required_argument, 0, O_REPORT},
        {"record-timings", no_argument, 0, O_TIMINGS},
        {"export-obj", required_argument, 0, O_EXPORT},
        {"trace-only", no_argument, 0, O_TRACE_ONLY},
        {"log", no_argument, 0, O_LOG},
        {"quantity", required_argument, 0, O_QUANTITY},
        {"lambda", required_argument, 0, O_LAMBDA},
        {"log-offset", required_argument, 0, O_LOG_OFFSET},
        {"decision-lights", required_argument, 0, O_DEC_LIGHTS},
        {"decision-near", required_argument, 0, O_DEC_NEAR},
        {"decision-shell", required_argument, 0, O_DEC_SHELL},
        {"light-region", required_argument, 0, O_LIGHT_REGION},
        {"false-rate", required_argument, 0, O_FALSE_RATE},
        {"offset-cap", required_argument, 0, O_OFFSET_CAP},
        {"decision-params", required_argument, 0, O_DEC_PARAMS},
        {"log-floor", required_argument, 0, O_LOG_FLOOR},
        {"keep-normals", no_argument, 0, O_KEEP_NORMALS},
        {"window", required_argument, 0, O_WINDOW},
        {"shard", required_argument, 0, O_SHARD},
        {"adaptive", required_argument, 0, O_ADAPTIVE},
        {"plan", required_argument, 0, O_PLAN},
        {"receivers", required_argument, 0, O_RECEIVERS},
        {"min-edge", required_argument, 0, O_MIN_EDGE},
        {"max-receivers", required_argument, 0, O_MAX_RECEIVERS},
        {"max-rounds", required_argument, 0, O_MAX_ROUNDS},
        {"quiet", no_argument, 0, 'q'},
        VT_CLI_LONGOPTS_END};
    int c;
    while ((c = getopt_long(argc, argv, "o:qhV", longopts, NULL)) != -1) {
        int r = read_value(c, optarg, o);
        if (r == OPT_NOT_MINE)
            r = read_choice(c, optarg, o);
        if (r == VT_EXIT_USAGE)
            return r;
        if (r == OPT_TAKEN)
            continue;
        switch (c) {
        case 'o':
            if (!vt_opt_once("-o", optarg, &o->output))
                return VT_EXIT_USAGE;
            break;
        case O_WELD: o->weld = 1; break;
        case O_UP_AXIS:
            for (o->up_axis = 0; o->up_axis < VDSH_UP_AXES; o->up_axis++)
                if (strcmp(optarg, vdsh_up_axis_name((uint32_t)o->up_axis)) == 0)
                    break;
            if (o->up_axis == VDSH_UP_AXES)
                return bad_usage("--up-axis takes y, z, -z, x, -x or -y, not '%s'", optarg);
            break;
        case O_CUBEDIR:
            if (!vt_opt_once("--cubemap-dir", optarg, &o->cubemap_dir))
                return VT_EXIT_USAGE;
            break;
        case O_ROBUST: o->robust = 1; break;
        case O_NO_ROBUST: o->robust = 0; break;
        case O_REPORT:
            if (!vt_opt_once("--report", optarg, &o->report))
                return VT_EXIT_USAGE;
            break;
        case O_TIMINGS: o->record_timings = 1; break;
        case O_EXPORT:
            if (!vt_opt_once("--export-obj", optarg, &o->export_obj))
                return VT_EXIT_USAGE;
            break;
        case O_PLAN:
            if (!vt_opt_once("--plan", optarg, &o->plan))
                return VT_EXIT_USAGE;
            break;
        case O_RECEIVERS:
            if (!vt_opt_once("--receivers", optarg, &o->receivers))
                return VT_EXIT_USAGE;
            break;
        case O_TRACE_ONLY: o->trace_only = 1; break;
        case O_LOG: o->quantity = VB_QUANTITY_LOG; break;
        case O_KEEP_NORMALS: o->keep_normals = 1; break;
        case 'q': o->quiet = 1; break;
        default: return vt_cli_common_option(c, usage, "Embree " RTC_VERSION_STRING);
        }
    }
    o->meshes = (const char *const *)argv + optind;
    o->mesh_count = argc - optind;
    return check_options(o);
}

/* The distance volume (--sdf) of the occluders, for the file at `path`
 * beside the output. 0, or 1 after saying why. */
static int bake_sdf(const options *o, const vb_job *job, char *path, size_t cap, vdsh_sdf *vol,
                    double *seconds)
{
    vb_error err;
    double ts = vb_now();
    if (vdsh_sdf_path(o->output, path, cap) != 0) {
        fprintf(stderr, "vdsh-bake: %s: path too long for its distance volume\n", o->output);
        return 1;
    }
    if (vb_sdf_bake(job->scene, &job->occluders, o->sdf, o->threads, vol, &err) != VB_OK) {
        fprintf(stderr, "vdsh-bake: %s: %s\n", path, err.msg);
        return 1;
    }
    vol->vertex_count = job->file.header.vertex_count;
    vol->triangle_count = job->file.header.triangle_count;
    *seconds = vb_now() - ts;
    return 0;
}

/* What was written: the file, its orders and encoding, the cubemaps. */
static void say_written(FILE *log, const options *o, const vb_job *job, const vb_job_desc *jd,
                        double write_seconds)
{
    const vb_bake_output *bo = &job->bake;
    int cube_size = o->shard_count ? 0 : vb_job_cube_size(jd); /* a part has none */
    fprintf(log,
            "vdsh-bake: wrote %s (%.2f MB, %.1f bytes of coefficients per "
            "vertex for orders",
            o->output, job->file_bytes / 1e6, job->coefficient_bytes + job->variable_bytes);
    for (int s = 0; s < o->order_count; s++)
        fprintf(log, "%s%d", s ? "," : " ", o->orders[s]);
    if (bo->variable_cap)
        fprintf(log, "%sadaptive 1..%d", o->order_count ? "," : " ", bo->variable_cap);
    if (o->shard_count) /* a part keeps f32 coefficients: vdsh-merge encodes them */
        fprintf(log, ", f32 in a part: %s once merged)", vdsh_encoding_name(o->encoding));
    else
        fprintf(log, ", %s)", vdsh_encoding_name(o->encoding));
    if (cube_size > 0 && vb_output_has_cubemaps(o->output, o->cubemap_dir))
        fprintf(log, " and 4 basis cubemaps %dx%d in %s", cube_size, cube_size,
                o->cubemap_dir ? o->cubemap_dir : "the output's directory");
    else if (cube_size > 0) /* not beside /dev/null or /dev/stdout */
        fprintf(log,
                ", without its basis cubemaps: %s is a device or pipe "
                "(--cubemap-dir DIR writes them)",
                o->output);
    fprintf(log, "\nvdsh-bake: done in %.2f s\n", job->timings.total + write_seconds);
}

/* ---- the bake ----------------------------------------------------------- */

/* The bake the options ask for, its messages and its files; the exit
 * status (0 done, 1 failed: said on stderr). */
/* The bake, described once: vb_job (job.h) runs it as a straight line.
 * offsets (VDSH_ORDER_SLOTS) and pr are the caller's, borrowed by it. */
static vb_job_desc job_desc(const options *o, FILE *log, progress *pr, float *offsets)
{
    uint32_t order_mask = 0;
    for (int s = 0; s < o->order_count; s++)
        order_mask |= 1u << o->orders[s];
    for (int k = 0; k <= VDSH_MAX_ORDER; k++)
        offsets[k] = o->log_offset;
    return (vb_job_desc){
        .paths = o->meshes,
        .path_count = (uint32_t)o->mesh_count,
        .output = o->trace_only ? NULL : o->output,
        .cubemap_dir = o->cubemap_dir,
        .weld = o->weld,
        .up_axis = o->up_axis,
        .crease = o->crease,
        .max_edge = o->max_edge,
        .fast_traversal = !o->robust,
        .light_region = o->light_region,
        .adaptive = o->adaptive,
        .receivers_path = o->receivers,
        .adapt = {.tolerance = o->adaptive_tol,
                  .min_edge = o->min_edge,
                  .max_receivers = o->max_receivers,
                  .max_rounds = o->max_rounds ? o->max_rounds : VB_ADAPTIVE_ROUNDS,
                  .on_round = log ? on_round : NULL,
                  .user = log},
        .bake = {.rays = o->rays,
                 .adaptive_rays = o->adaptive_rays,
                 .ray_tolerance = o->ray_tolerance,
                 .seed = o->seed,
                 .max_distance = o->max_distance,
                 .method = o->method,
                 .quantity = o->quantity,
                 .lambda = o->lambda,
                 .log_floor = o->log_floor,
                 .log_offsets = o->have_log_offset ? offsets : NULL,
                 .decision = o->have_decision ? &o->decision : NULL,
                 .decision_lights = o->decision_lights,
                 .decision_near = o->decision_near,
                 .decision_shell = o->decision_shell,
                 .false_rate = o->false_rate,
                 .offset_cap = o->offset_cap,
                 .offset_cap_tol = o->offset_cap_tol,
                 .offset_cap_keep = o->offset_cap_keep,
                 .offset_cap_min = o->offset_cap_min,
                 .window = o->window,
                 .order_mask = order_mask,
                 .threads = o->threads,
                 .order_tolerance = o->order_tolerance,
                 .variable_cap = o->max_order,
                 .keep_normals = o->keep_normals,
                 .trace_only = o->trace_only,
                 .progress = on_progress,
                 .progress_user = pr},
        .encoding_given = 1,
        .encoding = o->encoding,
        .cpca = o->cpca,
        .cube_size = o->cube_size > 0 ? o->cube_size : -1,
        .record_timings = o->record_timings,
        .shard_index = o->shard_index,
        .shard_count = o->shard_count,
        .on_mesh = log ? on_mesh : NULL,
        .user = log,
    };
}

/* What the receivers are, and a warning when they are far apart against
 * the scene; *spacing gets their spacing when a message or the report
 * needs it. */
static void say_receivers(FILE *log, const options *o, const vb_job *job, vb_mesh_spacing *spacing)
{
    const vb_mesh *rec = &job->receivers;
    if (log && o->max_edge > 0.0f)
        fprintf(log,
                "vdsh-bake: receivers refined to max edge %g: %u %s, "
                "%u triangle%s, worst aspect ratio %.1f (%.2f s)\n",
                (double)o->max_edge, rec->vertex_count,
                vdsh_plural(rec->vertex_count, "vertex", "vertices"), rec->triangle_count,
                vdsh_s(rec->triangle_count), vb_mesh_worst_aspect(rec, NULL), job->timings.refine);
    /* Receivers far apart against the scene draw false shadows inside their
     * triangles: say so when nothing chose them (no --max-edge, --adaptive
     * or --receivers) and a bake or plan follows. */
    const int chosen = o->max_edge > 0.0f || o->adaptive || o->receivers;
    if ((log && !chosen && (o->output || o->plan)) || o->report) {
        float lo[3], hi[3];
        vb_mesh_bounds(&job->occluders, lo, hi);
        vb_mesh_spacing_of(rec, vdsh_view_diagonal(lo, hi), spacing);
    }
    if (log && !chosen && (o->output || o->plan) && spacing->far_apart)
        fprintf(log,
                "vdsh-bake: warning: receivers far apart: %.0f%% of the surface is in "
                "triangles whose longest edge exceeds %.0f%% of the scene's diagonal (%.4g; "
                "longest edges: median %.3g, 90th percentile %.3g, area-weighted). The "
                "shadows are interpolated between receivers, so these triangles draw false "
                "shadows inside them: refine, e.g. --max-edge %g (1%% of the diagonal), "
                "or --adaptive from a coarser --max-edge\n",
                100.0 * spacing->long_area, 100.0 * VB_SPACING_WARN_EDGE, (double)spacing->diagonal,
                (double)spacing->median_edge, (double)spacing->p90_edge,
                (double)spacing->suggest_edge);
    /* The bake takes any scale (a normalised frame); the views do not. */
    if (log && (o->output || o->plan) && rec->vertex_count) {
        float lo[3], hi[3], far = 0.0f, across = 0.0f;
        vb_mesh_bounds(rec, lo, hi);
        for (int k = 0; k < 3; k++) {
            far = fmaxf(far, fmaxf(fabsf(lo[k]), fabsf(hi[k])));
            across = fmaxf(across, hi[k] - lo[k]);
        }
        if (far > VDSH_VIEW_MAX_COORD || !(across >= VDSH_VIEW_MIN_EXTENT))
            fprintf(log,
                    "vdsh-bake: warning: the scene is %g across with coordinates up to %g: "
                    "vdsh-view, vdsh-frames views and vdsh-export refuse scenes beyond %g or "
                    "under %g across (float views); scale the scene %s to view the bake\n",
                    (double)across, (double)far, (double)VDSH_VIEW_MAX_COORD,
                    (double)VDSH_VIEW_MIN_EXTENT, far > VDSH_VIEW_MAX_COORD ? "down" : "up");
    }
}

/* The adaptive receivers: how many from how many, and whether the round
 * cap stopped them while still splitting. */
static void say_adaptive_receivers(FILE *log, const options *o, const vb_job *job)
{
    fprintf(log,
            "vdsh-bake: adaptive receivers: %u from %u in %u round%s (%u midpoint%s "
            "baked, tolerance %g + noise floor %.3g from %u receiver%s baked twice, min "
            "edge %g%s)\n",
            job->receivers.vertex_count, job->adaptive.start_receivers, job->adaptive.rounds,
            vdsh_s(job->adaptive.rounds), job->adaptive.candidates,
            vdsh_s(job->adaptive.candidates), (double)o->adaptive_tol, job->adaptive.noise_floor,
            job->adaptive.noise_sample, vdsh_s(job->adaptive.noise_sample), (double)o->min_edge,
            job->adaptive.budget_reached    ? ", the budget stopped it"
            : job->adaptive.uniform_reached ? ", stopped at the uniform bake's count at 2 x "
                                              "the min edge"
                                            : "");
    if (job->adaptive.rounds_reached)
        fprintf(log,
                "vdsh-bake: warning: adaptive refinement stopped at the round cap (%u) "
                "while still splitting (%u edge%s split in the last round, %u edge%s not "
                "yet judged): raise --max-rounds\n",
                job->adaptive.max_rounds, job->adaptive.last_split,
                vdsh_s(job->adaptive.last_split), job->adaptive.pending,
                vdsh_s(job->adaptive.pending));
}

/* The adaptive order's receivers per order. */
static void say_adaptive_order(FILE *log, const vb_bake_output *bo)
{
    uint32_t hist[VDSH_ORDER_SLOTS] = {0};
    uint32_t rows = bo->range_end - bo->range_begin;
    double coeffs = 0.0;
    for (uint32_t v = 0; v < rows; v++) {
        hist[bo->variable_orders[v]]++;
        coeffs += (double)bo->variable_orders[v] * bo->variable_orders[v];
    }
    fprintf(log,
            "vdsh-bake: adaptive order (tolerance %g, cap %d): %.1f coefficients per "
            "receiver on average; receivers per order:",
            (double)bo->order_tolerance, bo->variable_cap, rows ? coeffs / rows : 0.0);
    for (int k = 1; k <= bo->variable_cap; k++)
        if (hist[k])
            fprintf(log, " %d: %u (%.1f%%)", k, hist[k], 100.0 * hist[k] / rows);
    fputc('\n', log);
}

/* The ray origins' check: probe rays, receivers repaired and moved,
 * those on zero-area triangles only. */
static void say_origins(FILE *log, const vb_bake_output *bo)
{
    fprintf(log,
            "vdsh-bake: ray origins checked in %.2f s: %llu probe ray%s (%.1f%% of the "
            "traced rays), %u receiver%s repaired, %u moved\n",
            bo->origins.seconds, (unsigned long long)bo->origins.probe_rays,
            vdsh_s(bo->origins.probe_rays),
            bo->rays_traced ? 100.0 * bo->origins.probe_rays / bo->rays_traced : 0.0,
            bo->origins.flagged, vdsh_s(bo->origins.flagged), bo->origins.moved);
    if (bo->origins.skipped_zero_area)
        fprintf(log,
                "vdsh-bake: %u receiver%s on zero-area triangles only (drawn nowhere): "
                "origin%s not probed\n",
                bo->origins.skipped_zero_area, vdsh_s(bo->origins.skipped_zero_area),
                vdsh_s(bo->origins.skipped_zero_area));
}

/* --light-region: where, and whether in reach. */
static void say_light_region(FILE *log, const vb_job *job)
{
    const vdsh_light_box *b = &job->light_region;
    const float *lo = job->scene->bounds_min, *hi = job->scene->bounds_max;
    double far = 0.0; /* the farthest light from the farthest occluder corner */
    for (int a = 0; a < 3; a++) {
        const double d = fmax(fabs((double)b->max[a] - lo[a]), fabs((double)hi[a] - b->min[a]));
        far += d * d;
    }
    far = sqrt(far);
    fprintf(log, "vdsh-bake: lights in %s %g %g %g .. %g %g %g\n",
            b->rule == VDSH_LIGHT_REGION_GROWN ? "the bounds grown:" : "the box", (double)b->min[0],
            (double)b->min[1], (double)b->min[2], (double)b->max[0], (double)b->max[1],
            (double)b->max[2]);
    if (far > 1.5 * (double)job->bake.max_distance)
        fprintf(log,
                "vdsh-bake: warning: lights in this region may stand up to %g from a "
                "receiver, beyond 1.5 x the max distance %g, where every stream reads "
                "shadow: give --max-distance %g or more (docs/DESIGN.md, \"Lights beyond "
                "the clamp\")\n",
                far, (double)job->bake.max_distance, far / 1.5);
}

/* The decision fit: receivers fitted, the calibrated log offsets and the
 * offset cap's effect. */
static void say_decision(FILE *log, const options *o, const vb_bake_output *bo)
{
    if (!bo->decision_lights)
        fprintf(log, "vdsh-bake: warning: no free space for lights in this scene: every "
                     "receiver keeps its least-squares fit\n");
    else
        fprintf(log,
                "vdsh-bake: decision fit: %u receiver%s fitted on %.0f traced lights "
                "each on average, %u with fewer than 16 lights above %s horizon "
                "kept the least-squares fit\n",
                bo->decision_fitted, vdsh_s(bo->decision_fitted), bo->decision_pairs,
                bo->decision_fallbacks, vdsh_plural(bo->decision_fallbacks, "its", "their"));
    if (bo->calibration_receivers) {
        fprintf(log,
                "vdsh-bake: log offsets calibrated on %u receiver%s for %.1f%% false "
                "shadow on held-out lights:",
                bo->calibration_receivers, vdsh_s(bo->calibration_receivers),
                100.0 * bo->false_rate);
        for (int s = 0; s < o->order_count; s++)
            fprintf(log, "%s order %d %+.3f", s ? "," : "", o->orders[s],
                    (double)bo->log_offset[o->orders[s]]);
        if (bo->variable_cap && bo->variable_method == VDSH_METHOD_DECISION)
            fprintf(log, "%s adaptive order %+.3f", o->order_count ? "," : "",
                    (double)bo->variable_param);
        fputc('\n', log);
    }
    if (o->offset_cap)
        fprintf(
            log,
            "vdsh-bake: offset cap raised %llu (receiver, order) offsets; the offset turns %llu of "
            "%llu lit training pairs false (margin below %g; calibration sample not counted)\n",
            (unsigned long long)bo->cap_bound, (unsigned long long)bo->lit_training_false,
            (unsigned long long)bo->lit_training, (double)o->offset_cap_tol);
}

/* --quantity auto: each order's choice and the errors it was made on. */
static void say_quantity_choice(FILE *log, const options *o, const vb_bake_output *bo)
{
    fprintf(log,
            "vdsh-bake: quantity chosen on %u sampled receiver%s (expected shadow "
            "error, distance / log):",
            bo->auto_receivers, vdsh_s(bo->auto_receivers));
    for (int s = 0; s < o->order_count; s++) {
        int k = o->orders[s];
        fprintf(log, "%s order %d %s (%.4f / %.4f)", s ? "," : "", k,
                bo->quantity[k] == VDSH_QUANTITY_LOG_DISTANCE ? "log" : "distance",
                bo->auto_error[k][0], bo->auto_error[k][1]);
    }
    fputc('\n', log);
}

/* What the bake did: rounds, fits, rays, repairs and warnings. */
static void say_bake(FILE *log, const options *o, const vb_job *job)
{
    const vb_bake_output *bo = &job->bake;
    const vb_mesh *rec = &job->receivers;
    if (!log)
        return;
    if (o->adaptive)
        say_adaptive_receivers(log, o, job);
    if (bo->flipped_normals)
        fprintf(log,
                "vdsh-bake: %u receiver normal%s pointed into geometry and %s "
                "flipped (--keep-normals keeps them)\n",
                bo->flipped_normals, vdsh_s(bo->flipped_normals),
                vdsh_plural(bo->flipped_normals, "was", "were"));
    fprintf(log,
            "vdsh-bake: traced %.1f M rays in %.2f s (%.1f Mrays/s on %u "
            "thread%s), %.2f%% missed, %u ray origin%s moved off other geometry, "
            "%u degenerate receiver%s (max distance %g)\n",
            bo->rays_traced * 1e-6, bo->seconds,
            bo->seconds > 0 ? bo->rays_traced / bo->seconds * 1e-6 : 0.0, bo->threads,
            vdsh_s(bo->threads), bo->rays_traced ? 100.0 * bo->rays_missed / bo->rays_traced : 0.0,
            bo->moved_origins, vdsh_s(bo->moved_origins), bo->degenerate_receivers,
            vdsh_s(bo->degenerate_receivers), (double)bo->max_distance);
    if (bo->variable_orders)
        say_adaptive_order(log, bo);
    if (o->adaptive_rays)
        fprintf(log,
                "vdsh-bake: adaptive rays: %.1f traced per receiver on average "
                "(cap %u, tolerance %g)\n",
                bo->vertex_count ? (double)bo->rays_traced / bo->vertex_count : 0.0, bo->rays,
                (double)bo->ray_tolerance);
    if (job->pool)
        fprintf(log, "vdsh-bake: light pool placed in %.2f s: %u light%s%s\n", job->pool_seconds,
                job->pool_count, vdsh_s(job->pool_count),
                job->pool_count ? "" : " (no room in free space: none used)");
    say_origins(log, bo);
    if (job->light_region.rule)
        say_light_region(log, job);
    if (bo->method == VDSH_METHOD_DECISION)
        say_decision(log, o, bo);
    if (bo->auto_receivers > 0)
        say_quantity_choice(log, o, bo);
    if (bo->degenerate_receivers > 0)
        fprintf(log,
                "vdsh-bake: warning: %u receiver%s (%.2f%%) %s distance ~0 in almost "
                "every direction above %s horizon: receivers inside or flush "
                "against other geometry, or inverted normals\n",
                bo->degenerate_receivers, vdsh_s(bo->degenerate_receivers),
                100.0 * bo->degenerate_receivers / rec->vertex_count,
                vdsh_plural(bo->degenerate_receivers, "sees", "see"),
                vdsh_plural(bo->degenerate_receivers, "its", "their"));
}

static int run(const options *o)
{
    FILE *log = o->quiet ? NULL : stderr;
    progress pr = {.enabled = log != NULL, .terminal = isatty(STDERR_FILENO), .rays = o->rays};
    float offsets[VDSH_ORDER_SLOTS];
    const vb_job_desc jd = job_desc(o, log, &pr, offsets);
    int status = 1;
    int writing = 0; /* signals deferred: outputs are being written */
    vb_mesh_spacing spacing = {0};
    vb_error err;
    vb_job job = {0};

    /* 0. Every output writable and none of them an input, before any work. */
    int bad = check_outputs(o, &jd, o->meshes, o->mesh_count);
    if (bad)
        return bad;

    /* 1. Load every mesh into one occluder scene. */
    if (vb_job_load(&job, &jd, &err) != VB_OK) {
        fprintf(stderr, "vdsh-bake: %s\n", err.msg);
        goto out;
    }

    /* 2. Receivers: the scene's vertices, refined if asked. */
    if (vb_job_refine(&job, &jd, &err) != VB_OK) {
        fprintf(stderr, "vdsh-bake: %s: %s\n",
                o->receivers ? "reading the receivers (--receivers)" : "refining receivers",
                err.msg);
        goto out;
    }
    const vb_mesh *rec = &job.receivers;
    say_receivers(log, o, &job, &spacing);
    /* The shard against the receivers before any output: --export-obj
     * (bake-slurm's check before it submits) and --plan exit before the
     * bake, where a shard count above the receivers was found. */
    if (vb_job_check_shard(&job, &jd, &err) != VB_OK) {
        fprintf(stderr, "vdsh-bake: %s\n", err.msg);
        goto out;
    }
    if (o->plan && !o->adaptive) { /* uniform: the refined receivers, before any bake */
        if (write_plan(rec, o->plan) != 0)
            goto out;
        if (!o->output && !o->export_obj && !o->trace_only) {
            status = 0;
            goto out;
        }
    }
    if (o->export_obj) {
        vt_cli_defer_signals();
        vb_result written = vb_mesh_stage_obj(rec, o->export_obj, &side[SIDE_EXPORT], &err);
        vt_cli_undefer_signals();
        if (written != VB_OK) {
            fprintf(stderr, "vdsh-bake: %s\n", err.msg);
            goto out;
        }
        snprintf(side_note[SIDE_EXPORT], sizeof side_note[SIDE_EXPORT], "wrote %s", o->export_obj);
        if (!o->output && !o->trace_only) {
            status = 0;
            goto out;
        }
    }

    /* 3. The occluders' BVH, then orient, trace and project. */
    if (log)
        fprintf(log,
                "vdsh-bake: tracing %u ray%s x %u receiver%s against %u triangle%s "
                "(method %s)\n",
                o->rays, vdsh_s(o->rays), rec->vertex_count, vdsh_s(rec->vertex_count),
                job.occluders.triangle_count, vdsh_s(job.occluders.triangle_count),
                vb_method_name(o->method));
    pr.t0 = vb_now();
    if (vb_job_bake(&job, &jd, &err) != VB_OK) {
        fprintf(stderr, "vdsh-bake: %s\n", err.msg);
        goto out;
    }
    const vb_bake_output *bo = &job.bake;
    if (o->plan && o->adaptive) { /* the receivers as baked (oriented normals) */
        vb_mesh planned = job.receivers;
        if (bo->normals)
            planned.normals = bo->normals;
        if (write_plan(&planned, o->plan) != 0)
            goto out;
        if (!o->output) {
            status = 0;
            goto out;
        }
    }
    say_bake(log, o, &job);
    char msg[PATH_MAX + 256];
    if (o->trace_only) {
        vt_cli_defer_signals();
        writing = 1;
        if (o->report && write_bare_report(o->report, bo, &job.timings, msg, sizeof msg) != 0) {
            fprintf(stderr, "vdsh-bake: %s (the report)\n", msg);
            goto out;
        }
        status = 0;
        goto out;
    }

    /* 4. The file: streams, header and all, filled by the core (cpca's
     * global step, most of a high order's bake, said before and after). */
    const int say_cpca = log && o->encoding == VDSH_ENCODING_CPCA && !o->shard_count;
    if (say_cpca) {
        const vdsh_cpca_settings st = vb_job_cpca_settings(&job, &jd);
        char text[192];
        vdsh_cpca_settings_text(&st, text, sizeof text);
        const int no_pool = st.light_mix > 0.0f && !st.light_count;
        fprintf(log, "vdsh-bake: cpca: fitting %s over %u receiver%s%s\n", text,
                job.receivers.vertex_count, vdsh_s(job.receivers.vertex_count),
                no_pool         ? " (no light pool in this scene: the uniform metric, one start)"
                : st.starts > 1 ? " (each start a fit, then the pool's decisions pick one)"
                                : "");
    }
    double t = vb_now();
    if (vb_bake_fill_file(&job, &jd, &err) != VB_OK) {
        fprintf(stderr, "vdsh-bake: %s\n", err.msg);
        goto out;
    }
    const double encode_seconds = vb_now() - t;
    if (say_cpca)
        fprintf(log, "vdsh-bake: cpca: fitted in %.1f s\n", encode_seconds);

    /* 5. The distance volume, if asked: baked and written beside the
     * output before it, so the .vdsh is still the last file to appear. */
    char sdf_path[PATH_MAX];
    vdsh_sdf vol = {0};
    double sdf_seconds = 0.0;
    if (o->sdf && bake_sdf(o, &job, sdf_path, sizeof sdf_path, &vol, &sdf_seconds) != 0)
        goto out;

    /* 6. Write: the distance volume staged, then the side outputs, the
     * basis cubemaps and the .vdsh file, last, renamed together. */
    vt_cli_defer_signals();
    writing = 1;
    if (o->sdf) {
        vdsh_error verr;
        vdsh_result vr = vdsh_sdf_stage(sdf_path, &vol, &side[SIDE_SDF], &verr);
        vdsh_sdf_free(&vol);
        if (vr != VDSH_OK) {
            fprintf(stderr, "vdsh-bake: %s\n", verr.msg);
            goto out;
        }
        snprintf(side_note[SIDE_SDF], sizeof side_note[SIDE_SDF],
                 "distance volume %u x %u x %u (spacing %g) baked in %.2f s, wrote %s (%.2f MB)",
                 vol.dim[0], vol.dim[1], vol.dim[2], (double)vol.cell, sdf_seconds, sdf_path,
                 vdsh_sdf_file_size(&vol) / 1e6);
    }
    if (vb_job_write(&job, &jd, side, SIDE_COUNT, &err) != VB_OK) {
        fprintf(stderr, "vdsh-bake: %s\n", err.msg);
        goto out;
    }
    say_sides(log);
    double write_seconds = vb_now() - t;
    if (log)
        say_written(log, o, &job, &jd, write_seconds);
    if (o->report &&
        write_report(o->report, o, &jd, &job, &spacing, o->sdf ? &vol : NULL, sdf_seconds,
                     encode_seconds, write_seconds, msg, sizeof msg) != 0) {
        fprintf(stderr, "vdsh-bake: %s (the report)\n", msg);
        goto out;
    }
    status = 0;

out:
    /* The side outputs: renamed into place when the bake succeeded
     * (without -o; with it vb_job_write did), else removed. */
    if (!writing)
        vt_cli_defer_signals();
    if (status == 0 && commit_sides(log) != 0)
        status = 1;
    for (int k = 0; k < SIDE_COUNT; k++)
        vdsh_output_abort(&side[k]);
    vt_cli_undefer_signals(); /* an interrupt that came meanwhile ends it here */
    vb_job_free(&job);
    return status;
}

int main(int argc, char **argv)
{
    vt_cli_begin("vdsh-bake", argv);
    vt_cli_clean_exit_on_signals(); /* first: before any thread starts */
    options o;
    int status = parse_args(argc, argv, &o);
    return status == VT_CLI_RUN ? run(&o) : status;
}
