/*
 * vdsh-view - look at a baked VDSH scene: interactively in a window, or
 * headless (--render one image, --grid the paper's comparison row,
 * --bench frame times of every shadow mode, --views frames of a view set).
 *
 * This file is main and the command line; each mode is a file of its own
 * over a small core (vdsh_view.h lists them).
 *
 * Exit status: 0 success, 1 error (a file, GL), 2 usage error.
 */
#include "vdsh_camera.h"
#include "vdsh_view.h"
#include "vt_cli.h"

#include <getopt.h>
#include <malloc.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef VDSH_VERSION_STRING
#define VDSH_VERSION_STRING "0"
#endif

static const char usage_text[] =
    "usage: vdsh-view [options] SCENE.vdsh              (a window)\n"
    "       vdsh-view --render OUT.png [options] SCENE.vdsh\n"
    "       vdsh-view --grid OUT.png [options] SCENE.vdsh...\n"
    "       vdsh-view --bench [options] SCENE.vdsh...\n"
    "       vdsh-view --views VIEWS.json --frames DIR [options] SCENE.vdsh\n"
    "Look at a scene baked by vdsh-bake, lit by point lights with precomputed\n"
    "visibility-distance shadows (VDSH) or cube shadow maps.\n"
    "\n"
    "Output:\n"
    "      --render FILE     render one image headless (no display needed)\n"
    "      --grid FILE       render the comparison row: no shadows | cube shadow\n"
    "                        map | VDSH order 5 | 3 | 2, labelled, into one image\n"
    "                        (an order held only as a buffer, cpca, drawn from\n"
    "                        it: bufN), and | bufN when a SCENE has a fixed order\n"
    "                        other than 2, 3, 5 (its highest), | adaptive order\n"
    "                        when one has a stream with an order per vertex,\n"
    "                        | sdf when one has a distance volume (SCENE.sdf);\n"
    "                        several SCENEs (e.g. the same scene baked two\n"
    "                        ways) give one row each\n"
    "      --bench           time every shadow mode with 1, 3, 16 and 64 lights\n"
    "                        (fewer rounds for 16 and 64) on each SCENE (the\n"
    "                        buffer modes: buf5, each order above 5, adaptive),\n"
    "                        all in this process, each round timing\n"
    "                        every mode of every SCENE once (wall time and\n"
    "                        process CPU time per frame); JSON on stdout\n"
    "  -j, --json FILE       with --bench: the JSON to FILE instead (-: stdout)\n"
    "      --bench-lights L  with --bench: only these of 1,3,16,64 lights\n"
    "      --bench-cube-sizes LIST  with --bench: time the cube shadow map\n"
    "                        (1 tap and PCF) at each of these face sizes, as\n"
    "                        modes cubeN and cube_pcfN, instead of cube and\n"
    "                        cube_pcf at --shadow-size (e.g. 16,64,256)\n"
    "      --bench-modes LIST  with --bench: time only the modes of these\n"
    "                        names (comma-separated, as in the JSON)\n"
    "      --bench-counts    with --bench: per mode and light set, one more\n"
    "                        frame with GL queries around it (samples passed,\n"
    "                        primitives; vertex and fragment shader\n"
    "                        invocations where the context has pipeline\n"
    "                        statistics), as \"counts\" in the JSON\n"
    "      --buffer-floats   with --bench: time each buffer mode also from\n"
    "                        buffers of decoded f32 coefficients (MODE-f32)\n"
    "      --cpca-frame      decode a cpca stream once per frame into a scratch\n"
    "                        buffer (576 more GPU bytes per vertex at order\n"
    "                        12; GL 4.3) instead of in every pass of 8 lights;\n"
    "                        with --bench: time its buffer modes both ways\n"
    "                        (MODE-frame)\n"
    "      --compute         compute a buffer stream's sums once per frame in a\n"
    "                        compute shader, per vertex in view and light (a\n"
    "                        cpca stream decoded there, from its records;\n"
    "                        GL 4.3), instead of in the vertex stage of every\n"
    "                        pass; with --bench: time its buffer modes both\n"
    "                        ways (MODE-compute), and a cpca stream's also\n"
    "                        decoded at load (MODE-compute-load)\n"
    "      --vertex-sums     sum every buffer stream in the vertex stage of each\n"
    "                        pass (a cpca stream's too, decoded there), where\n"
    "                        by default a cpca stream's are summed in compute\n"
    "                        as with --compute when the GL has compute shaders\n"
    "      --cpca-load       decode a cpca stream to f32 once, at load, on the\n"
    "                        GPU (576 GPU bytes per vertex at order 12, the\n"
    "                        records freed; GL 4.3)\n"
    "      --views FILE      with --frames DIR: for every view, light set and\n"
    "                        light of the view set FILE (vdsh-frames writes\n"
    "                        one), the shadow of that one light alone as a\n"
    "                        16-bit grey PNG, DIR/NAME-sK-lJ-MODE.png (the\n"
    "                        shadow factor s: 0 shadowed .. 1 lit, no shading;\n"
    "                        1 where no surface is), and per view and set the\n"
    "                        shaded picture of all its lights together,\n"
    "                        DIR/NAME-sK-shaded-MODE.png; K and J count from 0.\n"
    "                        At the view set's size; time per frame on stderr\n"
    "      --modes LIST      with --views: modes to render, comma-separated:\n"
    "                        cube, cube-pcf (4 taps), vdsh2, vdsh3, vdsh5,\n"
    "                        vdsh5poly, none, bufN, adaptive (default: every\n"
    "                        one of the first six that the scene has)\n"
    "\n"
    "View (defaults come from the scene's bounds, y up: a room is seen from\n"
    "inside, an object framed from outside, lit in its light region):\n"
    "      --camera EX,EY,EZ,TX,TY,TZ   eye and target point\n"
    "      --fit             frame the whole scene from outside, also a room\n"
    "      --fov DEG         vertical field of view (default 60)\n"
    "      --light X,Y,Z[,R,G,B]  a point light (repeatable)\n"
    "      --lights N        use N default lights, 1..64 (default 1; beyond\n"
    "                        four, positions placed uniformly in free space)\n"
    "      --light-region SPEC  where the default lights (and those beyond four)\n"
    "                        go, as vdsh-eval's: file (default: the bake's\n"
    "                        --light-region, recorded in the file, else auto),\n"
    "                        auto (the scene's rule), grown (vdsh-bake's) or a\n"
    "                        box XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX\n"
    "      --attenuation A0,A1,A2  for every light: 1/(A0 + A1 d + A2 d^2)\n"
    "                        (default 1, 0, 1/(0.3 * diagonal)^2)\n"
    "      --ambient V       ambient light (default 0.03)\n"
    "      --mode M          none, cube, vdsh2, vdsh3, vdsh5 (order 5, basis\n"
    "                        cubemaps) or vdsh5poly (order 5, polynomials);\n"
    "                        order n = n bands = n*n coefficients. Default:\n"
    "                        the runtime's, vdsh5 where the scene has it, else\n"
    "                        vdsh5poly, else the highest of vdsh3 and vdsh2,\n"
    "                        else buffer.\n"
    "                        Scenes baked with --log are drawn per vertex in\n"
    "                        every VDSH mode (distances interpolated, no\n"
    "                        cubemaps; vdsh5 and vdsh5poly are then the same).\n"
    "                        From buffer textures, any order, always per\n"
    "                        vertex: bufN the stream of order N (1..16; orders\n"
    "                        above 5 and cpca streams, vdsh-bake --encoding\n"
    "                        cpca, only this way: cpca decoded per vertex in\n"
    "                        the vertex stage), adaptive the stream with\n"
    "                        an order per vertex (vdsh-bake's adaptive order),\n"
    "                        buffer the scene's default of these (adaptive if\n"
    "                        it has it, else its highest order)\n"
    "                        Distance-field shadows: sdf (the scene's signed\n"
    "                        distance volume, vdsh-bake --sdf N, sphere-traced\n"
    "                        toward each light per pixel)\n"
    "      --sdf-k K         mode sdf's softness: a light of radius diagonal / K\n"
    "                        (default 400; larger: harder shadows)\n"
    "      --compare C       smooth (the paper's ramp, default) or binary\n"
    "      --pcf             cube shadow maps with PCF (default: 1 tap)\n"
    "      --shadow-size N   cube shadow map face size (default 512)\n"
    "      --size WxH        image or window size (default 1024x768; with\n"
    "                        --grid the size of each panel, default 512x384)\n"
    "\n"
    "Files: SCENE.vdsh, and its distance volume SCENE.sdf when that file\n"
    "exists (the basis cubemaps of mode vdsh5 are computed at load, the same\n"
    "as the .exr files vdsh-bake writes for other engines).\n"
    "      --sdf FILE        the distance volume to read instead of SCENE.sdf\n"
    "      --no-cubemaps     do not make them (mode vdsh5 is then unavailable,\n"
    "                        except for --log scenes, which never need them)\n"
    "\n"
    "Other:\n"
    "      --egl P           headless EGL platform: device or surfaceless\n"
    "                        (default: device, else surfaceless)\n"
    "      --frames N        window: quit after N frames; --bench: timed\n"
    "                        rounds per mode (default 7); with --views the\n"
    "                        folder the frames go to (made if missing)\n"
    "      --screenshot FILE window: save what the window shows after the\n"
    "                        last frame (with --frames) as PNG\n"
    "      --no-overlay      window: start without the text overlay\n"
    "      --keys KEYS       window: press these keys, one per frame from the\n"
    "                        first (letters, digits, space; '>' is Tab, '<'\n"
    "                        Backspace): scripted demos and tests\n"
    "      --no-mallopt      keep glibc's default malloc trimming (by default\n"
    "                        the viewer raises M_TRIM_THRESHOLD and\n"
    "                        M_MMAP_THRESHOLD: see docs/BENCHMARKS.md)\n"
    "  -q, --quiet           nothing on stderr but errors (no summary or progress)\n"
    "  -h, --help            this text (the window's keys: press h in it)\n"
    "  -V, --version         version\n"
    "\n"
    "Exit status: 0 success, 1 error, 2 usage error.\n"
    "Example: vdsh-bake builtin:room --max-edge 0.2 -o room.vdsh\n"
    "         vdsh-view room.vdsh --grid room-grid.png\n";

static int usage_error(const char *fmt, const char *arg)
{
    return vt_usage_error("vdsh-view", fmt, arg);
}

/* Option opt's value v, one of a (*out 0) and b (*out 1): 0, or the
 * usage error. */
static int pick(const char *opt, const char *v, const char *a, const char *b, int *out)
{
    *out = !strcmp(v, b);
    if (*out || !strcmp(v, a))
        return 0;
    return vt_usage_error("vdsh-view", "%s: expected %s or %s, got '%s'", opt, a, b, v);
}

/* A buffer mode asks for its stream; orders 2, 3, 5 are buffered on request (1 and 4 always are). */
static void note_buffer(vv_options *o, const vv_mode *m)
{
    if (m->mode == VR_MODE_VDSH_BUFFER && m->stream >= 1 && m->stream <= 5)
        o->buffers = 1;
}

/* "cube,vdsh5" into o->frame_modes (each once, in the order given);
 * 0, or -1 for an unknown or empty name. */
static int parse_modes(const char *list, vv_options *o)
{
    o->frame_mode_count = 0;
    for (const char *p = list, *next; p; p = next) {
        size_t len = vt_list_item(p, &next);
        int found = vv_mode_find(p, len, VV_MODE_FRAMES);
        if (found < 0)
            return -1;
        int seen = 0;
        for (int i = 0; i < o->frame_mode_count; i++)
            seen |= o->frame_modes[i] == found;
        if (!seen) {
            o->frame_modes[o->frame_mode_count++] = found;
            note_buffer(o, &vv_modes[found]);
        }
    }
    return 0;
}

/* vdsh-view's options beyond -q, -h, -V and -j. */
enum {
    O_RENDER = 256,
    O_GRID,
    O_BENCH,
    O_CAMERA,
    O_FIT,
    O_FOV,
    O_LIGHT,
    O_LIGHTS,
    O_ATT,
    O_AMBIENT,
    O_MODE,
    O_COMPARE,
    O_PCF,
    O_SHADOW_SIZE,
    O_SIZE,
    O_NO_CUBEMAPS,
    O_EGL,
    O_FRAMES,
    O_SCREENSHOT,
    O_NO_OVERLAY,
    O_KEYS,
    O_NO_MALLOPT,
    O_VIEWS,
    O_MODES,
    O_BUFFER_FLOATS,
    O_CPCA_FRAME,
    O_COMPUTE,
    O_CPCA_LOAD,
    O_VERTEX_SUMS,
    O_BENCH_LIGHTS,
    O_BENCH_CUBE_SIZES,
    O_BENCH_MODES,
    O_BENCH_COUNTS,
    O_SDF,
    O_SDF_K,
    O_LIGHT_REGION
};

static const struct option longopts[] = {
    {"render", required_argument, 0, O_RENDER},
    {"grid", required_argument, 0, O_GRID},
    {"bench", no_argument, 0, O_BENCH},
    {"camera", required_argument, 0, O_CAMERA},
    {"fit", no_argument, 0, O_FIT},
    {"fov", required_argument, 0, O_FOV},
    {"light", required_argument, 0, O_LIGHT},
    {"lights", required_argument, 0, O_LIGHTS},
    {"attenuation", required_argument, 0, O_ATT},
    {"ambient", required_argument, 0, O_AMBIENT},
    {"mode", required_argument, 0, O_MODE},
    {"compare", required_argument, 0, O_COMPARE},
    {"pcf", no_argument, 0, O_PCF},
    {"sdf", required_argument, 0, O_SDF},
    {"sdf-k", required_argument, 0, O_SDF_K},
    {"json", required_argument, 0, 'j'},
    {"shadow-size", required_argument, 0, O_SHADOW_SIZE},
    {"size", required_argument, 0, O_SIZE},
    {"no-cubemaps", no_argument, 0, O_NO_CUBEMAPS},
    {"egl", required_argument, 0, O_EGL},
    {"frames", required_argument, 0, O_FRAMES},
    {"screenshot", required_argument, 0, O_SCREENSHOT},
    {"no-overlay", no_argument, 0, O_NO_OVERLAY},
    {"keys", required_argument, 0, O_KEYS},
    {"no-mallopt", no_argument, 0, O_NO_MALLOPT},
    {"buffer-floats", no_argument, 0, O_BUFFER_FLOATS},
    {"cpca-frame", no_argument, 0, O_CPCA_FRAME},
    {"compute", no_argument, 0, O_COMPUTE},
    {"cpca-load", no_argument, 0, O_CPCA_LOAD},
    {"vertex-sums", no_argument, 0, O_VERTEX_SUMS},
    {"bench-lights", required_argument, 0, O_BENCH_LIGHTS},
    {"bench-cube-sizes", required_argument, 0, O_BENCH_CUBE_SIZES},
    {"bench-modes", required_argument, 0, O_BENCH_MODES},
    {"bench-counts", no_argument, 0, O_BENCH_COUNTS},
    {"light-region", required_argument, 0, O_LIGHT_REGION},
    {"views", required_argument, 0, O_VIEWS},
    {"modes", required_argument, 0, O_MODES},
    {"quiet", no_argument, 0, 'q'},
    VT_CLI_LONGOPTS_END};

/* --camera EX,EY,EZ,TX,TY,TZ: 0, or the usage error. */
static int parse_camera(const char *v, vv_options *o)
{
    if (vt_parse_floats(v, o->camera, 6, 6) != 6)
        return usage_error("--camera: expected EX,EY,EZ,TX,TY,TZ, got '%s'", v);
    vdsh_camera cam = {{o->camera[0], o->camera[1], o->camera[2]},
                       {o->camera[3], o->camera[4], o->camera[5]},
                       {0.0f, 0.0f, 0.0f},
                       0.0f};
    if (vdsh_camera_degenerate(&cam))
        return usage_error("--camera: the eye is at the target or straight above or "
                           "below it (up is +y: move it aside a little), got '%s'",
                           v);
    o->have_camera = 1;
    return 0;
}

/* --light X,Y,Z or X,Y,Z,R,G,B, one more light: 0, or the usage error. */
static int parse_light(const char *v, vv_options *o)
{
    float f[6];
    int n = vt_parse_floats(v, f, 3, 6);
    if (n != 3 && n != 6)
        return usage_error("--light: expected X,Y,Z or X,Y,Z,R,G,B, got '%s'", v);
    if (n == 6 && !(f[3] >= 0.0f && f[4] >= 0.0f && f[5] >= 0.0f))
        return usage_error("--light: the colour R,G,B must be >= 0, got '%s'", v);
    if (o->light_count == VV_MAX_LIGHTS)
        return usage_error("--light: at most 64 lights (%s)", v);
    vr_light *l = &o->lights[o->light_count++];
    memset(l, 0, sizeof *l);
    memcpy(l->position, f, sizeof l->position);
    if (n == 6) {
        memcpy(l->color, f + 3, sizeof l->color);
        /* all-zero means white in vr_light: keep a black light black */
        if (!f[3] && !f[4] && !f[5])
            l->color[0] = 1e-30f;
    }
    return 0;
}

/* --mode NAME: 0, or the usage error. */
static int parse_mode(const char *v, vv_options *o)
{
    int i = vv_mode_find(v, strlen(v), VV_MODE_OPTION);
    if (i < 0)
        return usage_error("--mode: expected none, cube, vdsh2, vdsh3, vdsh5, "
                           "vdsh5poly, buffer, bufN (N = 1..16) or adaptive, "
                           "got '%s'",
                           v);
    o->mode = vv_modes[i].mode;
    if (vv_modes[i].stream) /* the others keep a stream given before */
        o->stream = vv_modes[i].stream;
    note_buffer(o, &vv_modes[i]);
    o->have_mode = 1;
    return 0;
}

/* --keys: letters, digits, space, '<' and '>': 0, or the usage error. */
static int parse_keys(const char *v, vv_options *o)
{
    for (const char *k = v; *k; k++)
        if (!strchr("abcdefghijklmnopqrstuvwxyz0123456789 <>", *k))
            return usage_error("--keys: letters, digits, space, '<' and '>' only, "
                               "got '%s'",
                               v);
    o->keys = v;
    return 0;
}

/* --bench-lights: some of 1,3,16,64 as bits 1, 2, 4, 8 of o->bench_sets:
 * 0, or the usage error. */
static int parse_bench_lights(const char *v, vv_options *o)
{
    float n[4];
    int k = vt_parse_floats(v, n, 1, 4);
    o->bench_sets = 0;
    for (int i = 0; i < k; i++)
        o->bench_sets |= n[i] == 1 ? 1 : n[i] == 3 ? 2 : n[i] == 16 ? 4 : n[i] == 64 ? 8 : 16;
    if (k < 1 || o->bench_sets >= 16)
        return usage_error("--bench-lights: expected some of 1,3,16,64, got '%s'", v);
    return 0;
}

/* --bench-cube-sizes: 1 to 8 face sizes: 0, or the usage error. */
static int parse_bench_cube_sizes(const char *v, vv_options *o)
{
    float n[8];
    int k = vt_parse_floats(v, n, 1, 8);
    o->bench_cube_count = k > 0 ? k : 0;
    for (int i = 0; i < k; i++) {
        if (!(n[i] >= 1 && n[i] <= 8192 && n[i] == (float)(int)n[i]))
            k = 0;
        else
            o->bench_cube_sizes[i] = (int)n[i];
    }
    if (k < 1)
        return usage_error("--bench-cube-sizes: expected 1 to 8 face sizes of 1..8192, "
                           "got '%s'",
                           v);
    return 0;
}

/* --light-region: vt_opt_light_region's rule as the runtime's: 0, or the
 * usage error (vt_opt_light_region said what is wrong). */
static int parse_light_region(const char *v, vv_options *o)
{
    /* vt_opt_light_region's auto, grown, box, file */
    static const int to_vr[4] = {VR_LIGHT_REGION_AUTO, VR_LIGHT_REGION_GROWN, VR_LIGHT_REGION_BOX,
                                 VR_LIGHT_REGION_FILE};
    vdsh_light_box b;
    if (!vt_opt_light_region("--light-region", v, 1, &b))
        return VT_EXIT_USAGE;
    o->light_region = to_vr[b.rule];
    memcpy(o->light_box, b.min, sizeof b.min);
    memcpy(o->light_box + 3, b.max, sizeof b.max);
    return 0;
}

/* getopt_long's option c with value v into o: 0, or an exit status
 * (help/version: -1 meaning exit 0). */
static int parse_option(int c, const char *v, vv_options *o)
{
    int which, rc;
    switch (c) {
    case 'h': fputs(usage_text, stdout); return -1;
    case 'V': vt_cli_version(NULL); return -1;
    case 'q': o->quiet = 1; return 0;
    case O_RENDER: return vt_opt_once("--render", v, &o->render_path) ? 0 : VT_EXIT_USAGE;
    case O_GRID: return vt_opt_once("--grid", v, &o->grid_path) ? 0 : VT_EXIT_USAGE;
    case O_BENCH: o->bench = 1; return 0;
    case O_CAMERA: return parse_camera(v, o);
    case O_FIT: o->fit = 1; return 0;
    case O_FOV:
        if (!vt_parse_float(v, &o->fov) || !(o->fov > 1.0f && o->fov < 179.0f))
            return usage_error("--fov: expected degrees in (1, 179), got '%s'", v);
        return 0;
    case O_LIGHT: return parse_light(v, o);
    case O_LIGHTS:
        if (!vt_parse_int(v, 1, VV_MAX_LIGHTS, &o->default_lights))
            return usage_error("--lights: expected 1..64, got '%s'", v);
        return 0;
    case O_ATT:
        if (vt_parse_floats(v, o->att, 3, 3) != 3 || o->att[0] < 0 || o->att[1] < 0 ||
            o->att[2] < 0 || !(o->att[0] + o->att[1] + o->att[2] > 0))
            return usage_error("--attenuation: expected A0,A1,A2 >= 0, not all 0, got '%s'", v);
        o->have_att = 1;
        return 0;
    case O_AMBIENT:
        if (!vt_parse_float(v, &o->ambient) || o->ambient < 0)
            return usage_error("--ambient: expected a value >= 0, got '%s'", v);
        o->have_ambient = 1;
        return 0;
    case O_MODE: return parse_mode(v, o);
    case O_COMPARE:
        if ((rc = pick("--compare", v, "smooth", "binary", &which)) != 0)
            return rc;
        o->compare = which ? VDSH_COMPARE_BINARY : VDSH_COMPARE_SMOOTH;
        return 0;
    case O_PCF: o->pcf = 1; return 0;
    case O_SDF: return vt_opt_once("--sdf", v, &o->sdf_path) ? 0 : VT_EXIT_USAGE;
    case O_SDF_K:
        if (!vt_parse_float(v, &o->sdf_k) || !(o->sdf_k > 0.0f && o->sdf_k <= 1000.0f))
            return usage_error("--sdf-k: expected a number > 0 and <= 1000, got '%s'", v);
        return 0;
    case O_SHADOW_SIZE:
        if (!vt_parse_int(v, 1, 8192, &o->shadow_size))
            return usage_error("--shadow-size: expected 1..8192, got '%s'", v);
        return 0;
    case O_SIZE:
        if (!vt_parse_size(v, 1, 16384, &o->width, &o->height))
            return usage_error("--size: expected WxH (1..16384), got '%s'", v);
        o->have_size = 1;
        return 0;
    case O_NO_CUBEMAPS: o->no_cubemaps = 1; return 0;
    case O_EGL:
        if ((rc = pick("--egl", v, "device", "surfaceless", &which)) != 0)
            return rc;
        o->egl = which ? VR_EGL_SURFACELESS : VR_EGL_DEVICE;
        return 0;
    case O_FRAMES: return vt_opt_once("--frames", v, &o->frames_arg) ? 0 : VT_EXIT_USAGE;
    case O_VIEWS: return vt_opt_once("--views", v, &o->views_path) ? 0 : VT_EXIT_USAGE;
    case O_MODES:
        if (parse_modes(v, o))
            return usage_error("--modes: expected a comma-separated list of cube, cube-pcf, "
                               "vdsh2, vdsh3, vdsh5, vdsh5poly, none, bufN (N = 1..16) "
                               "and adaptive, got '%s'",
                               v);
        return 0;
    case O_SCREENSHOT: return vt_opt_once("--screenshot", v, &o->screenshot) ? 0 : VT_EXIT_USAGE;
    case O_NO_OVERLAY: o->no_overlay = 1; return 0;
    case O_KEYS: return parse_keys(v, o);
    case O_NO_MALLOPT: o->no_mallopt = 1; return 0;
    case O_BUFFER_FLOATS: o->buffer_floats = 1; return 0;
    case O_CPCA_FRAME: o->cpca_frame = 1; return 0;
    case O_COMPUTE: o->compute = 1; return 0;
    case O_CPCA_LOAD: o->cpca_load = 1; return 0;
    case O_VERTEX_SUMS: o->vertex_sums = 1; return 0;
    case O_BENCH_LIGHTS: return parse_bench_lights(v, o);
    case O_BENCH_CUBE_SIZES: return parse_bench_cube_sizes(v, o);
    case O_BENCH_MODES:
        if (!*v)
            return usage_error("%s", "--bench-modes: expected mode names");
        o->bench_modes = v;
        return 0;
    case O_BENCH_COUNTS: o->bench_counts = 1; return 0;
    case O_LIGHT_REGION: return parse_light_region(v, o);
    case 'j': return vt_opt_once("--json", v, &o->json_path) ? 0 : 2;
    default: /* getopt_long said what is wrong */ vt_cli_try_help(); return VT_EXIT_USAGE;
    }
}

/* --views: the folder for the frames in --frames, and none of the
 * options it gives itself; else --frames is a count and --modes is not
 * given. 0, or the usage error. */
static int check_views(vv_options *o)
{
    if (o->views_path) {
        if (!o->frames_arg || !*o->frames_arg)
            return usage_error("%s", "--views: give the folder for the frames with --frames DIR");
        o->frames_dir = o->frames_arg;
        if (o->render_path || o->grid_path || o->bench)
            return usage_error("%s", "--views makes frames: not with --render, --grid or --bench");
        if (o->have_camera || o->fit || o->fov > 0.0f || o->light_count || o->default_lights ||
            o->have_size)
            return usage_error("%s", "--views gives the cameras, lights and size: not with "
                                     "--camera, --fit, --fov, --light, --lights or --size");
        if (o->have_mode || o->pcf)
            return usage_error("%s", "--views renders the modes of --modes (cube-pcf: the cube "
                                     "map with PCF): not with --mode or --pcf");
        return 0;
    }
    if (o->frame_mode_count)
        return usage_error("%s", "--modes: only with --views");
    if ((o->buffer_floats || o->bench_sets || o->bench_cube_count || o->bench_modes ||
         o->bench_counts || o->json_path) &&
        !o->bench)
        return usage_error("%s", "--buffer-floats, --bench-lights, --bench-cube-sizes, "
                                 "--bench-modes, --bench-counts, --json: only with --bench");
    if (o->cpca_load && o->cpca_frame)
        return usage_error("%s", "--cpca-load and --cpca-frame: decode once at load or once "
                                 "per frame, not both");
    if (o->vertex_sums && o->compute)
        return usage_error("%s", "--vertex-sums and --compute: the sums in one place, not both");
    if (o->vertex_sums && o->bench)
        return usage_error("%s", "--vertex-sums: not with --bench (its buffer modes are the "
                                 "vertex stage's; --compute adds MODE-compute)");
    if (o->cpca_load && o->bench)
        return usage_error("%s", "--cpca-load: not with --bench (--compute times "
                                 "MODE-compute-load)");
    if (o->frames_arg && !vt_parse_int(o->frames_arg, 1, 1000000, &o->frames))
        return usage_error("--frames: expected a positive count, got '%s'", o->frames_arg);
    return 0;
}

/* One way to run, one scene file unless --grid or --bench, one view
 * choice: 0, or the usage error. */
static int check_run(const vv_options *o)
{
    if ((o->render_path != NULL) + (o->grid_path != NULL) + o->bench > 1)
        return usage_error("%s", "choose one of --render, --grid and --bench");
    if ((o->screenshot || o->keys || o->no_overlay) &&
        (o->render_path || o->grid_path || o->bench || o->views_path))
        return usage_error("%s", "--screenshot, --keys and --no-overlay are the window's: not "
                                 "with --render, --grid, --bench or --views");
    if (o->file_count > 1 && !o->bench && !o->grid_path)
        return usage_error("one scene file at a time (several only with --grid and --bench), "
                           "got '%s'",
                           o->files[1]);
    if (o->fit && o->have_camera)
        return usage_error("%s", "--fit and --camera both choose the view: give one");
    return 0;
}

/* The images it writes: never a scene file, and writable now; the same
 * for --json's file ("-": stdout, not checked). 0, or an exit status. */
static int check_outputs(const vv_options *o)
{
    const char *outs[] = {o->render_path, o->grid_path, o->screenshot,
                          o->json_path && strcmp(o->json_path, "-") ? o->json_path : NULL};
    const char *opts[] = {"--render", "--grid", "--screenshot", "--json"};
    int rc = vt_cli_no_stdout(outs, opts, 3);
    if (rc)
        return rc;
    if (vt_cli_check_outputs(outs, 4, (const char *const *)o->files, o->file_count) != 0)
        return 1;
    return 0;
}

/* Returns 0, or an exit status (help/version: -1 meaning exit 0). */
static int parse_args(int argc, char **argv, vv_options *o)
{
    memset(o, 0, sizeof *o);
    o->mode = VR_MODE_DEFAULT; /* the runtime's, vr_scene_default_mode */
    o->egl = VR_EGL_AUTO;
    int c, rc;
    while ((c = getopt_long(argc, argv, "qhVj:", longopts, NULL)) != -1)
        if ((rc = parse_option(c, optarg, o)) != 0)
            return rc;
    for (int i = optind; i < argc; i++) {
        if (o->file_count == VV_MAX_FILES)
            return usage_error("too many scene files (%s)", argv[i]);
        o->files[o->file_count++] = argv[i];
    }
    if (o->file_count == 0)
        return usage_error("%s", "no scene file given");
    if ((rc = check_views(o)) != 0 || (rc = check_run(o)) != 0)
        return rc;
    return check_outputs(o);
}

int main(int argc, char **argv)
{
    vt_cli_begin("vdsh-view", argv);
    vt_cli_clean_exit_on_signals(); /* no temporary file left by a signal */
    vv_options o;
    int rc = parse_args(argc, argv, &o);
    if (rc)
        return rc < 0 ? 0 : rc;
    /* llvmpipe allocates and frees large blocks every frame; glibc's
     * defaults (a 128 KiB trim threshold, mmap for large blocks) can hand
     * that memory back to the kernel each time and fault it in again on
     * the next frame. Keeping it costs some resident memory. Measured in
     * docs/BENCHMARKS.md (scripts/bench_runtime): on the 2-core llvmpipe
     * machine it cuts the page faults and the kernel time several-fold and
     * makes frames a few percent faster, most where a frame is short
     * next to the memory llvmpipe bins for it (one light, VDSH modes);
     * --no-mallopt turns it off. */
    if (!o.no_mallopt) {
        mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
        mallopt(M_TRIM_THRESHOLD, 512 * 1024 * 1024);
    }
    if (o.bench) {
        o.buffers = 1; /* the buffer path at order 5 beside the attribute path */
        return vv_run_bench(&o);
    }
    if (o.render_path)
        return vv_run_render(&o);
    if (o.grid_path)
        return vv_run_grid(&o);
    if (o.views_path)
        return vv_run_frames(&o);
    return vv_run_window(&o);
}
