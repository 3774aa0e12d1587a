/*
 * vdsh-view - look at a baked VDSH scene: interactively in a window, or
 * headless (--render one image, --grid the paper's comparison row,
 * --bench frame times of every shadow mode).
 *
 * The app layer: the only code that knows both the runtime (vr.h) and the
 * context (vr_context.h), plus GLFW input and PNG files.
 *
 * Exit status: 0 success, 1 error (a file, GL), 2 usage error.
 */
#include "vdsh_output.h"
#include "vr.h"
#include "vr_context.h"
#include "vt_cli.h"
#include "vt_image.h"
#include "vt_json.h"
#include "vt_views.h"

#ifdef VR_HAVE_GLFW
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#endif
#include <stb/stb_image_write.h>

#include <errno.h>
#include <getopt.h>
#include <malloc.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#ifndef VDSH_VERSION_STRING
#define VDSH_VERSION_STRING "0"
#endif

enum { MAX_LIGHTS = 64, MAX_FILES = 8 };

typedef struct options {
    const char *render_path, *grid_path;
    int bench;
    const char *files[MAX_FILES];
    int file_count;
    int have_camera;
    float camera[6];
    int fit;                   /* --fit: frame the bounds from outside */
    float fov;
    vr_light lights[MAX_LIGHTS];
    int light_count;
    int default_lights;        /* --lights N; 0: 1 (3 for --bench's second set) */
    int have_att;
    float att[3];
    int have_ambient;
    float ambient;
    vr_mode mode;
    int have_mode;
    vdsh_compare compare;
    int pcf;
    int shadow_size;
    int have_size;
    int width, height;
    int no_cubemaps;
    vr_egl_platform egl;
    int frames;
    int no_mallopt;
    int quiet;
    const char *screenshot;
    int no_overlay;
    const char *keys;
    const char *views_path;    /* --views: frames for a view set */
    const char *frames_arg;    /* --frames: a count, or with --views the folder */
    const char *frames_dir;
    int frame_modes[16];       /* --modes: indices into frame_modes[] */
    int frame_mode_count;
} options;

static const char usage_text[] =
    "Usage: vdsh-view [options] SCENE.vdsh              (a window)\n"
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
    "                        map | VDSH order 5 | 3 | 2, labelled, into one image;\n"
    "                        several SCENEs (e.g. the same scene baked two ways)\n"
    "                        give one row each\n"
    "      --bench           time every shadow mode with 1 and 3 lights on each\n"
    "                        SCENE, all in this process, each round timing\n"
    "                        every mode of every SCENE once (wall time and\n"
    "                        process CPU time per frame); JSON on stdout\n"
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
    "                        vdsh5poly, none (default: every one of the first\n"
    "                        six that the scene has)\n"
    "\n"
    "View (defaults come from the scene's bounds, y up: a room is seen from\n"
    "inside, an object framed from outside, lit from outside):\n"
    "      --camera EX,EY,EZ,TX,TY,TZ   eye and target point\n"
    "      --fit             frame the whole scene from outside, also a room\n"
    "      --fov DEG         vertical field of view (default 60)\n"
    "      --light X,Y,Z[,R,G,B]  a point light (repeatable)\n"
    "      --lights N        use N default lights, 1..4 (default 1)\n"
    "      --attenuation A0,A1,A2  for every light: 1/(A0 + A1 d + A2 d^2)\n"
    "                        (default 1, 0, 1/(0.3 * diagonal)^2)\n"
    "      --ambient V       ambient light (default 0.03)\n"
    "      --mode M          none, cube, vdsh2, vdsh3, vdsh5 (order 5, basis\n"
    "                        cubemaps) or vdsh5poly (order 5, polynomials);\n"
    "                        order n = n bands = n*n coefficients. Default:\n"
    "                        the runtime's, vdsh5 where the scene has it, else\n"
    "                        vdsh5poly, else the highest order it has.\n"
    "                        Scenes baked with --log are drawn per vertex in\n"
    "                        every VDSH mode (distances interpolated, no\n"
    "                        cubemaps; vdsh5 and vdsh5poly are then the same)\n"
    "      --compare C       smooth (the paper's ramp, default) or binary\n"
    "      --pcf             cube shadow maps with PCF (default: 1 tap)\n"
    "      --shadow-size N   cube shadow map face size (default 512)\n"
    "      --size WxH        image or window size (default 1024x768; with\n"
    "                        --grid the size of each panel, default 512x384)\n"
    "\n"
    "Files: only SCENE.vdsh is read (the basis cubemaps of mode vdsh5 are\n"
    "computed at load, the same as the .exr files vdsh-bake writes for other\n"
    "engines).\n"
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
    "  -q, --quiet           no summary on stderr\n"
    "  -h, --help            this text (the window's keys: press h in it)\n"
    "  -V, --version         version\n"
    "\n"
    "Exit status: 0 success, 1 error, 2 usage error.\n"
    "Example: vdsh-bake builtin:room --max-edge 0.2 -o room.vdsh\n"
    "         vdsh-view room.vdsh --grid room-grid.png\n";

static const char keys_text[] =
    "vdsh-view keys:\n"
    "  mouse left drag   orbit around the target     right drag   look around\n"
    "  wheel             closer / farther            W A S D Q E  fly (shift: faster)\n"
    "  1 2 3 4 5 6       mode: none, cube shadow map, VDSH order 2, 3, 5 (cubemaps),\n"
    "                    5 (polynomials)                M  next mode\n"
    "  C                 comparison smooth / binary   P  cube map PCF on / off\n"
    "  Tab               select the next light        N  new light at the target\n"
    "  arrows, PgUp/PgDn move the selected light      Backspace  remove it\n"
    "  Space             animate the lights           F  fire a short-lived light\n"
    "  R                 reset the view               X  save a screenshot (PNG)\n"
    "  O                 overlay on / off             H  this list\n"
    "  Esc               quit\n";

static int usage_error(const char *fmt, const char *arg)
{
    return vt_usage_error("vdsh-view", fmt, arg);
}

/* The modes frames are rendered in, by file name (--modes); the first
 * FRAME_DEFAULT_MODES are the default, where the scene has them. */
typedef struct frame_mode {
    const char *name;
    vr_mode mode;
    int pcf;
} frame_mode;

static const frame_mode frame_modes[] = {
    {"cube", VR_MODE_CUBE, 0},       {"cube-pcf", VR_MODE_CUBE, 1},
    {"vdsh2", VR_MODE_VDSH2, 0},     {"vdsh3", VR_MODE_VDSH3, 0},
    {"vdsh5", VR_MODE_VDSH5, 0},     {"vdsh5poly", VR_MODE_VDSH5_POLY, 0},
    {"none", VR_MODE_NONE, 0}};
enum { FRAME_MODES = 7, FRAME_DEFAULT_MODES = 6 };

/* "cube,vdsh5" into o->frame_modes (each once, in the order given);
 * 0, or -1 for an unknown or empty name. */
static int parse_modes(const char *list, options *o)
{
    o->frame_mode_count = 0;
    const char *p = list;
    for (;;) {
        size_t len = strcspn(p, ",");
        int found = -1;
        for (int i = 0; i < FRAME_MODES; i++)
            if (strlen(frame_modes[i].name) == len && !strncmp(p, frame_modes[i].name, len))
                found = i;
        if (found < 0)
            return -1;
        int seen = 0;
        for (int i = 0; i < o->frame_mode_count; i++)
            seen |= o->frame_modes[i] == found;
        if (!seen)
            o->frame_modes[o->frame_mode_count++] = found;
        if (!p[len])
            return 0;
        p += len + 1;
    }
}

/* Returns 0, or an exit status (help/version: -1 meaning exit 0). */
static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->mode = VR_MODE_DEFAULT; /* the runtime's, vr_scene_default_mode */
    o->egl = VR_EGL_AUTO;
    enum { O_RENDER = 256, O_GRID, O_BENCH, O_CAMERA, O_FIT, O_FOV, O_LIGHT, O_LIGHTS,
           O_ATT, O_AMBIENT, O_MODE, O_COMPARE, O_PCF, O_SHADOW_SIZE, O_SIZE,
           O_NO_CUBEMAPS, O_EGL, O_FRAMES, O_SCREENSHOT, O_NO_OVERLAY, O_KEYS,
           O_NO_MALLOPT, O_VIEWS, O_MODES };
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
        {"shadow-size", required_argument, 0, O_SHADOW_SIZE},
        {"size", required_argument, 0, O_SIZE},
        {"no-cubemaps", no_argument, 0, O_NO_CUBEMAPS},
        {"egl", required_argument, 0, O_EGL},
        {"frames", required_argument, 0, O_FRAMES},
        {"screenshot", required_argument, 0, O_SCREENSHOT},
        {"no-overlay", no_argument, 0, O_NO_OVERLAY},
        {"keys", required_argument, 0, O_KEYS},
        {"no-mallopt", no_argument, 0, O_NO_MALLOPT},
        {"views", required_argument, 0, O_VIEWS},
        {"modes", required_argument, 0, O_MODES},
        {"quiet", no_argument, 0, 'q'},
        {"help", no_argument, 0, 'h'},
        {"version", no_argument, 0, 'V'},
        {0, 0, 0, 0}};
    int c;
    while ((c = getopt_long(argc, argv, "qhV", longopts, NULL)) != -1) {
        const char *v = optarg;
        switch (c) {
        case 'h':
            fputs(usage_text, stdout);
            return -1;
        case 'V':
            printf("vdsh-view %s\n", VDSH_VERSION_STRING);
            return -1;
        case 'q': o->quiet = 1; break;
        case O_RENDER: o->render_path = v; break;
        case O_GRID: o->grid_path = v; break;
        case O_BENCH: o->bench = 1; break;
        case O_CAMERA:
            if (vt_parse_floats(v, o->camera, 6, 6) != 6)
                return usage_error("--camera: expected EX,EY,EZ,TX,TY,TZ, got '%s'", v);
            o->have_camera = 1;
            break;
        case O_FIT: o->fit = 1; break;
        case O_FOV:
            if (!vt_parse_float(v, &o->fov) || !(o->fov > 1.0f && o->fov < 179.0f))
                return usage_error("--fov: expected degrees in (1, 179), got '%s'", v);
            break;
        case O_LIGHT: {
            float f[6];
            int n = vt_parse_floats(v, f, 3, 6);
            if (n != 3 && n != 6)
                return usage_error("--light: expected X,Y,Z or X,Y,Z,R,G,B, got '%s'", v);
            if (o->light_count == MAX_LIGHTS)
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
            break;
        }
        case O_LIGHTS:
            if (!vt_parse_int(v, 1, 4, &o->default_lights))
                return usage_error("--lights: expected 1..4, got '%s'", v);
            break;
        case O_ATT:
            if (vt_parse_floats(v, o->att, 3, 3) != 3 || o->att[0] < 0 || o->att[1] < 0 ||
                o->att[2] < 0 || !(o->att[0] + o->att[1] + o->att[2] > 0))
                return usage_error("--attenuation: expected A0,A1,A2 >= 0, not all 0, got '%s'",
                                   v);
            o->have_att = 1;
            break;
        case O_AMBIENT:
            if (!vt_parse_float(v, &o->ambient) || o->ambient < 0)
                return usage_error("--ambient: expected a value >= 0, got '%s'", v);
            o->have_ambient = 1;
            break;
        case O_MODE:
            if (vr_mode_from_name(v, &o->mode))
                return usage_error("--mode: expected none, cube, vdsh2, vdsh3, vdsh5 or "
                                   "vdsh5poly, got '%s'", v);
            o->have_mode = 1;
            break;
        case O_COMPARE:
            if (!strcmp(v, "smooth"))
                o->compare = VDSH_COMPARE_SMOOTH;
            else if (!strcmp(v, "binary"))
                o->compare = VDSH_COMPARE_BINARY;
            else
                return usage_error("--compare: expected smooth or binary, got '%s'", v);
            break;
        case O_PCF: o->pcf = 1; break;
        case O_SHADOW_SIZE:
            if (!vt_parse_int(v, 1, 8192, &o->shadow_size))
                return usage_error("--shadow-size: expected 1..8192, got '%s'", v);
            break;
        case O_SIZE:
            if (!vt_parse_size(v, 1, 16384, &o->width, &o->height))
                return usage_error("--size: expected WxH (1..16384), got '%s'", v);
            o->have_size = 1;
            break;
        case O_NO_CUBEMAPS: o->no_cubemaps = 1; break;
        case O_EGL:
            if (!strcmp(v, "device"))
                o->egl = VR_EGL_DEVICE;
            else if (!strcmp(v, "surfaceless"))
                o->egl = VR_EGL_SURFACELESS;
            else
                return usage_error("--egl: expected device or surfaceless, got '%s'", v);
            break;
        case O_FRAMES: o->frames_arg = v; break;
        case O_VIEWS: o->views_path = v; break;
        case O_MODES:
            if (parse_modes(v, o))
                return usage_error("--modes: expected a comma-separated list of cube, cube-pcf, "
                                   "vdsh2, vdsh3, vdsh5, vdsh5poly and none, got '%s'", v);
            break;
        case O_SCREENSHOT: o->screenshot = v; break;
        case O_NO_OVERLAY: o->no_overlay = 1; break;
        case O_KEYS:
            for (const char *k = v; *k; k++)
                if (!strchr("abcdefghijklmnopqrstuvwxyz0123456789 <>", *k))
                    return usage_error("--keys: letters, digits, space, '<' and '>' only, "
                                       "got '%s'", v);
            o->keys = v;
            break;
        case O_NO_MALLOPT: o->no_mallopt = 1; break;
        default: /* getopt_long said what is wrong */
            fprintf(stderr, "Try 'vdsh-view --help'.\n");
            return VT_EXIT_USAGE;
        }
    }
    for (int i = optind; i < argc; i++) {
        if (o->file_count == MAX_FILES)
            return usage_error("too many scene files (%s)", argv[i]);
        o->files[o->file_count++] = argv[i];
    }
    if (o->file_count == 0)
        return usage_error("%s", "no scene file given");
    /* --frames: a folder with --views, else a count. */
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
    } else {
        if (o->frame_mode_count)
            return usage_error("%s", "--modes: only with --views");
        if (o->frames_arg && !vt_parse_int(o->frames_arg, 1, 1000000, &o->frames))
            return usage_error("--frames: expected a positive count, got '%s'", o->frames_arg);
    }
    if ((o->render_path != NULL) + (o->grid_path != NULL) + o->bench > 1)
        return usage_error("%s", "choose one of --render, --grid and --bench");
    if (o->file_count > 1 && !o->bench && !o->grid_path)
        return usage_error("one scene file at a time (several only with --grid and --bench), "
                           "got '%s'", o->files[1]);
    if (o->fit && o->have_camera)
        return usage_error("%s", "--fit and --camera both choose the view: give one");
    return 0;
}

/* ------------------------------------------------------------------ */
/* Scene defaults                                                       */

static float scene_diagonal(const vr_scene *s)
{
    vr_scene_info info;
    vr_scene_get_info(s, &info);
    float d2 = 0.0f;
    for (int k = 0; k < 3; k++)
        d2 += (info.bounds_max[k] - info.bounds_min[k]) * (info.bounds_max[k] - info.bounds_min[k]);
    return sqrtf(d2) > 0.0f ? sqrtf(d2) : 1.0f;
}

/* n default lights of the scene: positions from vr_scene_default_lights,
 * warm/cool colours, and a fall-off that halves the light at about 0.3 of
 * the scene's diagonal in a room, and at the middle of an object (its
 * lights stand outside it). */
static int default_lights(const vr_scene *s, const options *o, int n, vr_light *out)
{
    static const float colors[4][3] = {
        {1.0f, 0.92f, 0.8f}, {0.55f, 0.7f, 1.0f}, {1.0f, 0.62f, 0.4f}, {0.7f, 1.0f, 0.7f}};
    vr_scene_info info;
    vr_scene_get_info(s, &info);
    n = vr_scene_default_lights(s, out, n);
    float r = 0.3f * scene_diagonal(s);
    /* dimmer when there are several, so that their sum stays in range */
    float intensity = 1.6f / (1.0f + 0.6f * (float)(n - 1));
    for (int i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++)
            out[i].color[k] = intensity * colors[i][k];
        if (!info.interior) {
            r = 0.0f;
            for (int k = 0; k < 3; k++) {
                float d = out[i].position[k] - 0.5f * (info.bounds_min[k] + info.bounds_max[k]);
                r += d * d;
            }
            r = sqrtf(r) > 0.0f ? sqrtf(r) : 1.0f;
        }
        if (o->have_att)
            memcpy(out[i].attenuation, o->att, sizeof o->att);
        else {
            out[i].attenuation[0] = 1.0f;
            out[i].attenuation[2] = 1.0f / (r * r);
        }
    }
    return n;
}

/* The lights of options (with --attenuation applied), else n defaults. */
static int scene_lights(const vr_scene *s, const options *o, int n, vr_light *out)
{
    if (o->light_count == 0)
        return default_lights(s, o, n, out);
    float r = 0.3f * scene_diagonal(s);
    for (int i = 0; i < o->light_count; i++) {
        out[i] = o->lights[i];
        if (o->have_att)
            memcpy(out[i].attenuation, o->att, sizeof o->att);
        else {
            out[i].attenuation[0] = 1.0f;
            out[i].attenuation[2] = 1.0f / (r * r);
        }
        if (!out[i].color[0] && !out[i].color[1] && !out[i].color[2])
            out[i].color[0] = out[i].color[1] = out[i].color[2] = 1.6f;
    }
    return o->light_count;
}

static void scene_camera(const vr_scene *s, const options *o, vr_camera *c)
{
    if (o->fit)
        vr_scene_fit_camera(s, c);
    else
        vr_scene_default_camera(s, c);
    if (o->have_camera) {
        memcpy(c->eye, o->camera, 3 * sizeof(float));
        memcpy(c->target, o->camera + 3, 3 * sizeof(float));
    }
    if (o->fov > 0.0f)
        c->fov_y = o->fov;
}

static vr_draw_desc base_desc(const options *o, const vr_light *lights, int n)
{
    vr_draw_desc d;
    memset(&d, 0, sizeof d);
    d.mode = o->mode;
    d.compare = o->compare;
    d.pcf = o->pcf;
    d.lights = lights;
    d.light_count = n;
    float amb = o->have_ambient ? o->ambient : 0.03f;
    d.ambient[0] = d.ambient[1] = d.ambient[2] = amb;
    return d;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

/* stb_image_write's output callback: into the atomic output (a failed
 * write is remembered; the commit reports it). */
static void png_put(void *user, void *data, int size)
{
    vdsh_output_put(user, data, (size_t)size);
}

static int write_png(const char *path, int w, int h, const unsigned char *rgba)
{
    /* Opaque PNGs: the framebuffer's alpha is whatever blending left. */
    size_t n = (size_t)w * (size_t)h;
    unsigned char *copy = malloc(n * 4);
    if (!copy) {
        fprintf(stderr, "vdsh-view: %s: out of memory\n", path);
        return 1;
    }
    for (size_t i = 0; i < n; i++) {
        memcpy(copy + 4 * i, rgba + 4 * i, 3);
        copy[4 * i + 3] = 255;
    }
    /* The file appears complete or not at all (formats/vdsh_output.h). */
    vdsh_output out;
    vdsh_error err;
    int rc = 1;
    if (vdsh_output_open(path, &out, &err) != VDSH_OK)
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
    else if (!stbi_write_png_to_func(png_put, &out, w, h, 4, copy, w * 4)) {
        fprintf(stderr, "vdsh-view: %s: cannot encode the PNG\n", path);
        vdsh_output_abort(&out);
    } else if (vdsh_output_commit(&out, &err) != VDSH_OK)
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
    else
        rc = 0;
    free(copy);
    return rc;
}

/* Everything a run needs: a context, the scene, a renderer. */
typedef struct session {
    vr_context *ctx;
    vr_scene *scene;
    vr_renderer *r;
} session;

static void session_close(session *s)
{
    vr_renderer_destroy(s->r);
    vr_scene_destroy(s->scene);
    vr_context_destroy(s->ctx);
    memset(s, 0, sizeof *s);
}

static int open_scene(const options *o, const char *path, vr_scene **out)
{
    vr_error err;
    vr_scene_desc sd = {.path = path, .skip_cubemaps = o->no_cubemaps};
    if (vr_scene_create(&sd, out, &err) != VR_OK) {
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
        return 1;
    }
    return 0;
}

static int session_open(const options *o, vr_context_kind kind, int w, int h, session *s)
{
    vr_error err;
    memset(s, 0, sizeof *s);
    vr_context_desc cd = {.kind = kind, .egl_platform = o->egl, .width = w, .height = h};
    if (vr_context_create(&cd, &s->ctx, &err) != VR_OK) {
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
        return 1;
    }
    if (open_scene(o, o->files[0], &s->scene)) {
        session_close(s);
        return 1;
    }
    vr_renderer_desc rd = {.width = w, .height = h, .shadow_map_size = o->shadow_size};
    if (vr_renderer_create(&rd, &s->r, &err) != VR_OK) {
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
        session_close(s);
        return 1;
    }
    return 0;
}

/* ------------------------------------------------------------------ */
/* --render and --grid                                                  */

static int run_render(const options *o)
{
    int w = o->have_size ? o->width : 1024, h = o->have_size ? o->height : 768;
    session s;
    if (session_open(o, VR_CONTEXT_HEADLESS, w, h, &s))
        return 1;
    vr_light lights[MAX_LIGHTS];
    int n = scene_lights(s.scene, o, o->default_lights ? o->default_lights : 1, lights);
    vr_draw_desc d = base_desc(o, lights, n);
    scene_camera(s.scene, o, &d.camera);
    vr_error err;
    int rc = 1;
    unsigned char *px = malloc((size_t)w * (size_t)h * 4);
    double t0 = now_ms();
    if (!px)
        fprintf(stderr, "vdsh-view: out of memory\n");
    else if (vr_draw(s.r, s.scene, &d, &err) != VR_OK ||
             vr_read_pixels(s.r, px, (size_t)w * (size_t)h * 4, &err) != VR_OK)
        fprintf(stderr, "vdsh-view: %s: %s\n", o->files[0], err.msg);
    else {
        double ms = now_ms() - t0;
        rc = write_png(o->render_path, w, h, px);
        if (!rc && !o->quiet)
            fprintf(stderr, "vdsh-view: wrote %s (%dx%d, mode %s: %s, %d light%s, %.0f ms, %s; "
                    "%s)\n", o->render_path, w, h,
                    vr_mode_name(o->mode ? o->mode : vr_scene_default_mode(s.scene)),
                    vr_scene_mode_label(s.scene, o->mode), n, n == 1 ? "" : "s", ms,
                    vr_gl_renderer(), vr_context_description(s.ctx));
    }
    free(px);
    session_close(&s);
    return rc;
}

/* What a scene's file holds, for a row label: "room.vdsh: paper bake,
 * distance" (the method of its highest order drawn). */
static void bake_label(const char *path, const vr_scene *s, char *out, size_t size)
{
    vr_scene_info info;
    vr_scene_get_info(s, &info);
    const char *slash = strrchr(path, '/');
    uint32_t method = 0;
    for (int k = 1; k <= 5; k++)
        if (info.has_order[k])
            method = info.method[k];
    snprintf(out, size, "%s: %s bake, %s", slash ? slash + 1 : path, vdsh_method_name(method),
             vdsh_quantity_name(info.quantity));
}

/* One row of the grid: the five panels of one scene into row (5 w wide). */
static int grid_row(const options *o, const char *path, vr_renderer *r, int w, int h,
                    unsigned char *px, unsigned char *row)
{
    vr_scene *scene = NULL;
    if (open_scene(o, path, &scene))
        return 1;
    vr_light lights[MAX_LIGHTS];
    int n = scene_lights(scene, o, o->default_lights ? o->default_lights : 1, lights);
    /* The paper's row. Order 5 the paper's way when the cubemaps are
     * there, else with the polynomials (the same image to f16 precision);
     * a log-distance scene draws both per vertex. */
    vr_mode modes[5] = {VR_MODE_NONE, VR_MODE_CUBE, VR_MODE_VDSH5, VR_MODE_VDSH3, VR_MODE_VDSH2};
    if (!vr_scene_supports(scene, VR_MODE_VDSH5))
        modes[2] = VR_MODE_VDSH5_POLY;
    size_t panel = (size_t)w * (size_t)h * 4;
    int rc = 0;
    for (int m = 0; m < 5 && !rc; m++) {
        vr_error err;
        vr_draw_desc d = base_desc(o, lights, n);
        d.mode = modes[m];
        scene_camera(scene, o, &d.camera);
        char label[320];
        int shadow = o->shadow_size ? o->shadow_size : 512;
        if (modes[m] == VR_MODE_CUBE)
            snprintf(label, sizeof label, "cube shadow map (%d^2 x 6, %s)", shadow,
                     o->pcf ? "PCF" : "1 tap");
        else if (modes[m] >= VR_MODE_VDSH2)
            snprintf(label, sizeof label, "%s%s", vr_scene_mode_label(scene, modes[m]),
                     o->compare == VDSH_COMPARE_BINARY ? ", binary" : "");
        else {
            char bake[256];
            bake_label(path, scene, bake, sizeof bake);
            snprintf(label, sizeof label, "%s\n%s", vr_mode_label(modes[m]), bake);
        }
        vr_result res = VR_OK;
        if (!vr_scene_supports(scene, modes[m])) {
            /* A file baked without this order: say so in the panel. */
            vr_draw_desc none = d;
            none.light_count = 0;
            none.mode = VR_MODE_NONE;
            snprintf(label + strlen(label), sizeof label - strlen(label), ": not in this file");
            res = vr_draw(r, scene, &none, &err);
        } else
            res = vr_draw(r, scene, &d, &err);
        if (res == VR_OK)
            res = vr_draw_text(r, 4, 4, w >= 400 ? 2.0f : 1.0f, NULL, label, &err);
        if (res == VR_OK)
            res = vr_read_pixels(r, px, panel, &err);
        if (res != VR_OK) {
            fprintf(stderr, "vdsh-view: %s: %s: %s\n", path, vr_mode_name(modes[m]), err.msg);
            rc = 1;
            break;
        }
        for (int y = 0; y < h; y++)
            memcpy(row + ((size_t)y * 5 * (size_t)w + (size_t)m * (size_t)w) * 4,
                   px + (size_t)y * (size_t)w * 4, (size_t)w * 4);
    }
    if (!rc && !o->quiet)
        fprintf(stderr, "vdsh-view: %s: none | cube | %s | vdsh3 | vdsh2 (%s), %d light%s\n",
                path, vr_mode_name(modes[2]), vr_scene_mode_label(scene, modes[2]), n,
                n == 1 ? "" : "s");
    vr_scene_destroy(scene);
    return rc;
}


/* A headless context (of w x h when `sized`, else the platform's default
 * surface) and a w x h renderer on it; 0, or 1 after printing why. */
static int open_headless(const options *o, int w, int h, int sized, vr_context **ctx,
                         vr_renderer **r)
{
    vr_error err;
    vr_context_desc cd = {.kind = VR_CONTEXT_HEADLESS, .egl_platform = o->egl,
                          .width = sized ? w : 0, .height = sized ? h : 0};
    if (vr_context_create(&cd, ctx, &err) != VR_OK) {
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
        return 1;
    }
    vr_renderer_desc rd = {.width = w, .height = h, .shadow_map_size = o->shadow_size};
    if (vr_renderer_create(&rd, r, &err) != VR_OK) {
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
        vr_context_destroy(*ctx);
        *ctx = NULL;
        return 1;
    }
    return 0;
}

static int run_grid(const options *o)
{
    int w = o->have_size ? o->width : 512, h = o->have_size ? o->height : 384;
    int rows = o->file_count;
    vr_context *ctx = NULL;
    vr_renderer *r = NULL;
    if (open_headless(o, w, h, 1, &ctx, &r) != 0)
        return 1;
    size_t panel = (size_t)w * (size_t)h * 4;
    unsigned char *px = malloc(panel), *img = calloc(5 * (size_t)rows, panel);
    int rc = 0;
    if (!px || !img) {
        fprintf(stderr, "vdsh-view: out of memory\n");
        rc = 1;
    }
    for (int i = 0; i < rows && !rc; i++)
        rc = grid_row(o, o->files[i], r, w, h, px, img + (size_t)i * 5 * panel);
    if (!rc) {
        /* A thin dark line between panels and between rows. */
        size_t stride = 5 * (size_t)w * 4;
        for (int y = 0; y < rows * h; y++)
            for (int m = 1; m < 5; m++)
                memset(img + (size_t)y * stride + (size_t)m * (size_t)w * 4, 40, 4);
        for (int i = 1; i < rows; i++)
            memset(img + (size_t)i * (size_t)h * stride, 40, stride);
        rc = write_png(o->grid_path, 5 * w, rows * h, img);
        if (!rc && !o->quiet)
            fprintf(stderr, "vdsh-view: wrote %s (%dx%d, %d row%s, %s)\n", o->grid_path, 5 * w,
                    rows * h, rows, rows == 1 ? "" : "s", vr_gl_renderer());
    }
    free(px);
    free(img);
    vr_renderer_destroy(r);
    vr_context_destroy(ctx);
    return rc;
}

/* ------------------------------------------------------------------ */
/* --views: frames of a view set, to be scored against ray-traced truth  */

/* The folder for the frames: made when missing (not its parents). */
static int frames_dir(const char *dir)
{
    struct stat st;
    if (stat(dir, &st) == 0) {
        if (S_ISDIR(st.st_mode))
            return 0;
        fprintf(stderr, "vdsh-view: %s: not a directory (--frames)\n", dir);
        return 1;
    }
    if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "vdsh-view: %s: cannot make the folder for the frames: %s\n", dir,
                strerror(errno));
        return 1;
    }
    return 0;
}

static void view_camera(const vt_view *v, vr_camera *c)
{
    memset(c, 0, sizeof *c);
    memcpy(c->eye, v->camera.eye, sizeof c->eye);
    memcpy(c->target, v->camera.target, sizeof c->target);
    memcpy(c->up, v->camera.up, sizeof c->up);
    c->fov_y = v->camera.fov_y;
}

/* One shadow-only frame: light alone, s of every pixel (1 where nothing
 * was drawn: VR_OUTPUT_SHADOW writes alpha 1, the clear colour 0). */
static vr_result shadow_frame(vr_renderer *r, const vr_scene *scene, const options *o,
                              const frame_mode *m, const vr_camera *cam, const float pos[3],
                              float *rgba, float *grey, size_t n, vr_error *err)
{
    vr_light light;
    memset(&light, 0, sizeof light);
    memcpy(light.position, pos, sizeof light.position);
    vr_draw_desc d;
    memset(&d, 0, sizeof d);
    d.mode = m->mode;
    d.pcf = m->pcf;
    d.compare = o->compare;
    d.lights = &light;
    d.light_count = 1;
    d.camera = *cam;
    d.output = VR_OUTPUT_SHADOW;
    vr_result res = vr_draw(r, scene, &d, err);
    if (res == VR_OK)
        res = vr_read_pixels(r, rgba, n * 4 * sizeof(float), err);
    if (res == VR_OK)
        for (size_t i = 0; i < n; i++)
            grey[i] = rgba[4 * i + 3] > 0.0f ? rgba[4 * i] : 1.0f;
    return res;
}

/* The shaded picture of a light set: the viewer's white lights (dimmer
 * when there are several), fall-off and ambient; opaque. */
static vr_result shaded_frame(vr_renderer *r, const vr_scene *scene, const options *o,
                              const frame_mode *m, const vr_camera *cam, const vt_view *v,
                              int set, unsigned char *px, size_t n, vr_error *err)
{
    vr_light lights[VT_VIEWS_MAX_LIGHTS];
    int nl = v->light_count[set];
    float fall = 0.3f * scene_diagonal(scene);
    float intensity = 1.6f / (1.0f + 0.6f * (float)(nl - 1));
    for (int i = 0; i < nl; i++) {
        memset(&lights[i], 0, sizeof lights[i]);
        memcpy(lights[i].position, v->lights[set][i], sizeof lights[i].position);
        lights[i].color[0] = lights[i].color[1] = lights[i].color[2] = intensity;
        if (o->have_att)
            memcpy(lights[i].attenuation, o->att, sizeof o->att);
        else {
            lights[i].attenuation[0] = 1.0f;
            lights[i].attenuation[2] = 1.0f / (fall * fall);
        }
    }
    vr_draw_desc d = base_desc(o, lights, nl);
    d.mode = m->mode;
    d.pcf = m->pcf;
    d.camera = *cam;
    vr_result res = vr_draw(r, scene, &d, err);
    if (res == VR_OK)
        res = vr_read_pixels(r, px, n * 4, err);
    if (res == VR_OK)
        for (size_t i = 0; i < n; i++)
            px[4 * i + 3] = 255;
    return res;
}

static int run_frames(const options *o)
{
    char msg[1024];
    vt_views vs;
    memset(&vs, 0, sizeof vs);
    if (vt_views_read(o->views_path, &vs, msg, sizeof msg) != 0) {
        fprintf(stderr, "vdsh-view: %s\n", msg);
        return 1;
    }
    if (frames_dir(o->frames_dir)) {
        vt_views_free(&vs);
        return 1;
    }
    int w = vs.width, h = vs.height;
    size_t n = (size_t)w * (size_t)h;
    session s;
    vr_renderer *rf = NULL;
    vr_error err;
    if (session_open(o, VR_CONTEXT_HEADLESS, w, h, &s)) {
        vt_views_free(&vs);
        return 1;
    }
    int rc = 0;
    vr_renderer_desc rd = {.width = w, .height = h, .color_format = VR_COLOR_RGBA32F,
                           .shadow_map_size = o->shadow_size};
    if (vr_renderer_create(&rd, &rf, &err) != VR_OK) {
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
        rc = 1;
    }

    /* The modes: those asked for (each must be in the scene), else every
     * shadow mode the scene has. */
    int modes[FRAME_MODES], nm = 0;
    if (!rc && o->frame_mode_count) {
        for (int i = 0; i < o->frame_mode_count && !rc; i++) {
            const frame_mode *m = &frame_modes[o->frame_modes[i]];
            if (!vr_scene_supports(s.scene, m->mode)) {
                fprintf(stderr, "vdsh-view: %s: mode %s is not available in this file%s\n",
                        o->files[0], m->name,
                        m->mode == VR_MODE_VDSH5 ? " (order 5 with its basis cubemaps)" : "");
                rc = 1;
            }
            modes[nm++] = o->frame_modes[i];
        }
    } else if (!rc) {
        for (int i = 0; i < FRAME_DEFAULT_MODES; i++)
            if (vr_scene_supports(s.scene, frame_modes[i].mode))
                modes[nm++] = i;
    }

    float *rgba = malloc(n * 4 * sizeof(float)), *grey = malloc(n * sizeof(float));
    unsigned char *px = malloc(n * 4);
    if (!rc && (!rgba || !grey || !px)) {
        fprintf(stderr, "vdsh-view: out of memory (%dx%d frames)\n", w, h);
        rc = 1;
    }
    int total = 0, done = 0;
    for (int v = 0; v < vs.count; v++)
        for (int k = 0; k < vs.views[v].set_count; k++)
            total += vs.views[v].light_count[k];
    total *= nm;
    if (!rc && !o->quiet)
        fprintf(stderr, "vdsh-view: %s: %d view%s of %s, %d shadow frames of %dx%d in %d "
                "mode%s, into %s (%s)\n", o->files[0], vs.count, vs.count == 1 ? "" : "s",
                o->views_path, total, w, h, nm, nm == 1 ? "" : "s", o->frames_dir,
                vr_gl_renderer());

    /* Mode by mode (one program, its shadow maps re-rendered per frame);
     * the time of a frame is its draw and read-back, without the PNG. */
    for (int mi = 0; mi < nm && !rc; mi++) {
        const frame_mode *m = &frame_modes[modes[mi]];
        double mode_ms = 0.0, first_ms = 0.0, png_ms = 0.0;
        int mode_frames = 0;
        for (int v = 0; v < vs.count && !rc; v++) {
            const vt_view *view = &vs.views[v];
            vr_camera cam;
            view_camera(view, &cam);
            for (int k = 0; k < view->set_count && !rc; k++) {
                char path[4096];
                for (int j = 0; j < view->light_count[k] && !rc; j++) {
                    if (vt_frame_path(path, sizeof path, o->frames_dir, view->name, k, j,
                                      m->name)) {
                        fprintf(stderr, "vdsh-view: %s: frame path too long\n", o->frames_dir);
                        rc = 1;
                        break;
                    }
                    double t0 = now_ms();
                    if (shadow_frame(rf, s.scene, o, m, &cam, view->lights[k][j], rgba, grey, n,
                                     &err) != VR_OK) {
                        fprintf(stderr, "vdsh-view: %s: %s: %s\n", o->files[0], path, err.msg);
                        rc = 1;
                        break;
                    }
                    double ms = now_ms() - t0;
                    if (mode_frames++ == 0)
                        first_ms = ms;
                    else
                        mode_ms += ms;
                    done++;
                    double t1 = now_ms();
                    if (vt_png16_write(path, w, h, grey, msg, sizeof msg) != 0) {
                        fprintf(stderr, "vdsh-view: %s\n", msg);
                        rc = 1;
                        break;
                    }
                    double wms = now_ms() - t1;
                    png_ms += wms;
                    if (!o->quiet)
                        fprintf(stderr, "vdsh-view: [%d/%d] %s  %.1f ms (PNG %.1f ms)\n", done,
                                total, path, ms, wms);
                }
                if (rc)
                    break;
                if (vt_shaded_path(path, sizeof path, o->frames_dir, view->name, k, m->name)) {
                    fprintf(stderr, "vdsh-view: %s: frame path too long\n", o->frames_dir);
                    rc = 1;
                } else if (shaded_frame(s.r, s.scene, o, m, &cam, view, k, px, n, &err) !=
                           VR_OK) {
                    fprintf(stderr, "vdsh-view: %s: %s: %s\n", o->files[0], path, err.msg);
                    rc = 1;
                } else if (vt_png_rgba_write(path, w, h, px, msg, sizeof msg) != 0) {
                    fprintf(stderr, "vdsh-view: %s\n", msg);
                    rc = 1;
                }
            }
        }
        /* The first frame of a mode compiles its program. */
        if (!rc && !o->quiet && mode_frames > 1)
            fprintf(stderr, "vdsh-view: mode %s: %d frames of %dx%d, %.1f ms per frame after "
                    "the first (%.1f ms: compiling), draw and read-back; PNG %.1f ms per "
                    "frame\n", m->name, mode_frames, w, h, mode_ms / (mode_frames - 1), first_ms,
                    png_ms / mode_frames);
        else if (!rc && !o->quiet && mode_frames == 1)
            fprintf(stderr, "vdsh-view: mode %s: 1 frame of %dx%d, %.1f ms (with compiling)\n",
                    m->name, w, h, first_ms);
    }
    free(rgba);
    free(grey);
    free(px);
    vr_renderer_destroy(rf);
    session_close(&s);
    vt_views_free(&vs);
    return rc;
}

/* ------------------------------------------------------------------ */
/* --bench                                                              */

typedef struct bench_mode {
    vr_mode mode;
    int pcf;
    const char *name;
} bench_mode;

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void json_series(vt_json *j, cJSON *o, const char *key, const double *v, int n)
{
    cJSON *a = vt_json_array(j, o, key);
    for (int i = 0; i < n; i++)
        vt_json_f64(j, a, NULL, v[i]);
}

enum { BENCH_MODES = 7, BENCH_ROUNDS = 64 };

/* CPU time of the whole process (every thread: llvmpipe's rasterizer
 * threads render in this process), milliseconds. */
static double process_cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

/* One scene of a benchmark: what it times and the results. */
typedef struct bench_scene {
    const char *path;
    vr_scene *scene;
    bench_mode modes[BENCH_MODES];
    int nm;
    vr_light lights[2][4];
    int nl[2];
    /* [light set][mode][round] */
    double cpu[2][BENCH_MODES][BENCH_ROUNDS], gpu[2][BENCH_MODES][BENCH_ROUNDS];
    double shadow[2][BENCH_MODES][BENCH_ROUNDS], lighting[2][BENCH_MODES][BENCH_ROUNDS];
    double proc[2][BENCH_MODES][BENCH_ROUNDS];
} bench_scene;

/* Load a scene and choose the modes it is timed in. */
static int bench_open(const options *o, const char *path, bench_scene *b)
{
    static const bench_mode all[BENCH_MODES] = {
        {VR_MODE_NONE, 0, "none"},   {VR_MODE_CUBE, 0, "cube"},
        {VR_MODE_CUBE, 1, "cube_pcf"}, {VR_MODE_VDSH2, 0, "vdsh2"},
        {VR_MODE_VDSH3, 0, "vdsh3"}, {VR_MODE_VDSH5, 0, "vdsh5"},
        {VR_MODE_VDSH5_POLY, 0, "vdsh5poly"}};
    static const int light_sets[2] = {1, 3};
    b->path = path;
    if (open_scene(o, path, &b->scene))
        return 1;
    for (int i = 0; i < BENCH_MODES; i++) {
        /* On a log-distance scene both order-5 modes draw the same
         * per-vertex program: time it once, as vdsh5. */
        int same = all[i].mode == VR_MODE_VDSH5_POLY &&
                   vr_scene_supports(b->scene, VR_MODE_VDSH5) &&
                   vr_scene_interp(b->scene, VR_MODE_VDSH5) == VDSH_INTERP_DISTANCE;
        if (vr_scene_supports(b->scene, all[i].mode) && !same)
            b->modes[b->nm++] = all[i];
    }
    for (int ls = 0; ls < 2; ls++)
        b->nl[ls] = default_lights(b->scene, o, light_sets[ls], b->lights[ls]);
    return 0;
}

/* Time every mode of every scene, with 1 light and then 3. Warm-up
 * first: compile every program and allocate every shadow map before
 * anything is timed. Then rounds that each time every (scene, mode) once,
 * starting at a different one each round, so that slow drifts of a shared
 * machine spread over all scenes and modes alike: a ratio between any two
 * of them compares frames of the same minutes. */
static int bench_time(const options *o, bench_scene *b, int nb, vr_renderer *r, int rounds)
{
    int total = 0;
    for (int i = 0; i < nb; i++)
        total += b[i].nm;
    for (int ls = 0; ls < 2; ls++)
        for (int round = -2; round < rounds; round++)
            for (int k = 0; k < total; k++) {
                int j = (k + (round > 0 ? round : 0)) % total, i = 0;
                while (j >= b[i].nm)
                    j -= b[i++].nm;
                bench_scene *bs = &b[i];
                vr_draw_desc d = base_desc(o, bs->lights[ls], bs->nl[ls]);
                d.mode = bs->modes[j].mode;
                d.pcf = bs->modes[j].pcf;
                scene_camera(bs->scene, o, &d.camera);
                vr_error err;
                double proc0 = process_cpu_ms();
                if (vr_draw(r, bs->scene, &d, &err) != VR_OK) {
                    fprintf(stderr, "vdsh-view: %s: %s: %s\n", bs->path, bs->modes[j].name,
                            err.msg);
                    return 1;
                }
                vr_renderer_finish(r);
                double proc1 = process_cpu_ms();
                vr_timings t;
                vr_renderer_timings(r, &t);
                if (round >= 0) {
                    bs->proc[ls][j][round] = proc1 - proc0;
                    bs->cpu[ls][j][round] = t.cpu_ms;
                    bs->gpu[ls][j][round] = t.gpu_ms;
                    bs->shadow[ls][j][round] = t.shadow_total_ms;
                    bs->lighting[ls][j][round] = t.lighting_total_ms;
                }
            }
    return 0;
}

/* One scene's JSON object (and a summary on stderr). */
static void bench_print(const options *o, const bench_scene *b, int rounds, vt_json *j,
                        cJSON *list)
{
    vr_scene_info info;
    vr_scene_get_info(b->scene, &info);
    uint32_t method = 0;
    for (int k = 1; k <= 5; k++)
        if (info.has_order[k])
            method = info.method[k];
    cJSON *so = vt_json_object(j, list, NULL);
    vt_json_string(j, so, "file", b->path);
    vt_json_u64(j, so, "vertices", info.vertex_count);
    vt_json_u64(j, so, "triangles", info.triangle_count);
    vt_json_string(j, so, "quantity", vdsh_quantity_name(info.quantity));
    vt_json_string(j, so, "method", vdsh_method_name(method));
    cJSON *results = vt_json_array(j, so, "results");
    for (int ls = 0; ls < 2; ls++)
        for (int m = 0; m < b->nm; m++) {
            double sorted[BENCH_ROUNDS];
            memcpy(sorted, b->cpu[ls][m], (size_t)rounds * sizeof(double));
            qsort(sorted, (size_t)rounds, sizeof(double), cmp_double);
            int interp = vr_scene_interp(b->scene, b->modes[m].mode);
            cJSON *r = vt_json_object(j, results, NULL);
            vt_json_i64(j, r, "lights", b->nl[ls]);
            vt_json_string(j, r, "mode", b->modes[m].name);
            vt_json_string(j, r, "path", interp >= 0 ? vdsh_interp_name((uint32_t)interp)
                                                     : b->modes[m].name);
            vt_json_f64(j, r, "median_cpu_ms", sorted[rounds / 2]);
            json_series(j, r, "cpu_ms", b->cpu[ls][m], rounds);
            json_series(j, r, "process_cpu_ms", b->proc[ls][m], rounds);
            json_series(j, r, "gpu_ms", b->gpu[ls][m], rounds);
            json_series(j, r, "shadow_ms", b->shadow[ls][m], rounds);
            json_series(j, r, "lighting_ms", b->lighting[ls][m], rounds);
            if (!o->quiet)
                fprintf(stderr, "vdsh-view: %s, %d light%s, %-9s median %.1f ms\n", b->path,
                        b->nl[ls], b->nl[ls] == 1 ? "" : "s", b->modes[m].name,
                        sorted[rounds / 2]);
        }
}

/* The results as one JSON document on stdout (vt_json.h), printed once
 * every scene has been timed. */
static int run_bench(const options *o)
{
    int w = o->have_size ? o->width : 1024, h = o->have_size ? o->height : 768;
    vr_context *ctx = NULL;
    vr_renderer *r = NULL;
    if (open_headless(o, w, h, 0, &ctx, &r) != 0)
        return 1;
    int rounds = o->frames ? (o->frames < BENCH_ROUNDS ? o->frames : BENCH_ROUNDS) : 7;
    vt_json j = {0};
    cJSON *root = vt_json_object(&j, NULL, NULL);
    vt_json_string(&j, root, "version", VDSH_VERSION_STRING);
    vt_json_string(&j, root, "renderer", vr_gl_renderer());
    vt_json_string(&j, root, "context", vr_context_description(ctx));
    vt_json_i64(&j, root, "width", w);
    vt_json_i64(&j, root, "height", h);
    vt_json_i64(&j, root, "shadow_size", o->shadow_size ? o->shadow_size : 512);
    vt_json_bool(&j, root, "mallopt", !o->no_mallopt);
    vt_json_i64(&j, root, "rounds", rounds);
    cJSON *list = vt_json_array(&j, root, "scenes");
    bench_scene *b = calloc((size_t)o->file_count, sizeof *b);
    int rc = b ? 0 : 1;
    if (!b)
        fprintf(stderr, "vdsh-view: out of memory\n");
    for (int i = 0; i < o->file_count && !rc; i++)
        rc = bench_open(o, o->files[i], &b[i]);
    if (!rc)
        rc = bench_time(o, b, o->file_count, r, rounds);
    for (int i = 0; i < o->file_count && !rc; i++)
        bench_print(o, &b[i], rounds, &j, list);
    char msg[256];
    if (!rc && vt_json_write_stream(&j, stdout, "stdout", msg, sizeof msg) != 0) {
        fprintf(stderr, "vdsh-view: --bench: %s\n", msg);
        rc = 1;
    }
    vt_json_free(&j);
    for (int i = 0; b && i < o->file_count; i++)
        vr_scene_destroy(b[i].scene);
    free(b);
    vr_renderer_destroy(r);
    vr_context_destroy(ctx);
    return rc;
}

/* ------------------------------------------------------------------ */
/* The window                                                           */

#ifdef VR_HAVE_GLFW
typedef struct app {
    const options *o;
    session s;
    vr_light base[MAX_LIGHTS];   /* user lights before animation */
    int n;
    int selected;
    float target[3], yaw, pitch, dist, diag;
    vr_camera home;
    int animate;
    double anim_t;
    int fired;                   /* a short-lived light is alive */
    float fired_pos[3], fired_vel[3];
    double fired_age;
    vr_mode mode;
    vdsh_compare compare;
    int pcf, overlay;
    double mx, my;
    int drag;                    /* 1 left (orbit), 2 right (look) */
    int shots;
    char status[256];
} app;

static const double FIRE_LIFE = 2.0;

static void forward(const app *a, float f[3])
{
    f[0] = cosf(a->pitch) * cosf(a->yaw);
    f[1] = sinf(a->pitch);
    f[2] = cosf(a->pitch) * sinf(a->yaw);
}

static void set_view(app *a, const vr_camera *c)
{
    float f[3] = {c->target[0] - c->eye[0], c->target[1] - c->eye[1], c->target[2] - c->eye[2]};
    a->dist = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    if (!(a->dist > 0.0f))
        a->dist = 1.0f;
    memcpy(a->target, c->target, sizeof a->target);
    a->yaw = atan2f(f[2], f[0]);
    a->pitch = asinf(f[1] / a->dist);
}

static void eye_of(const app *a, float eye[3])
{
    float f[3];
    forward(a, f);
    for (int k = 0; k < 3; k++)
        eye[k] = a->target[k] - a->dist * f[k];
}

static void print_status(app *a, const char *what)
{
    snprintf(a->status, sizeof a->status, "%s", what);
    if (!a->o->quiet)
        printf("%s\n", what);
}

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods)
{
    (void)scancode;
    (void)mods;
    app *a = glfwGetWindowUserPointer(w);
    if (action != GLFW_PRESS)
        return;
    char msg[200];
    static const vr_mode by_digit[6] = {VR_MODE_NONE, VR_MODE_CUBE, VR_MODE_VDSH2,
                                        VR_MODE_VDSH3, VR_MODE_VDSH5, VR_MODE_VDSH5_POLY};
    if (key >= GLFW_KEY_1 && key <= GLFW_KEY_6) {
        vr_mode m = by_digit[key - GLFW_KEY_1];
        if (!vr_scene_supports(a->s.scene, m)) {
            snprintf(msg, sizeof msg, "mode %s: not available in this file", vr_mode_name(m));
            print_status(a, msg);
            return;
        }
        a->mode = m;
        snprintf(msg, sizeof msg, "mode: %s", vr_scene_mode_label(a->s.scene, m));
        print_status(a, msg);
        return;
    }
    switch (key) {
    case GLFW_KEY_ESCAPE:
        glfwSetWindowShouldClose(w, GLFW_TRUE);
        break;
    case GLFW_KEY_M:
        for (int i = 1; i <= 6; i++) {
            vr_mode m = by_digit[(a->mode - VR_MODE_NONE + i) % 6];
            if (vr_scene_supports(a->s.scene, m)) {
                a->mode = m;
                break;
            }
        }
        snprintf(msg, sizeof msg, "mode: %s", vr_scene_mode_label(a->s.scene, a->mode));
        print_status(a, msg);
        break;
    case GLFW_KEY_C:
        a->compare = a->compare == VDSH_COMPARE_SMOOTH ? VDSH_COMPARE_BINARY : VDSH_COMPARE_SMOOTH;
        print_status(a, a->compare == VDSH_COMPARE_SMOOTH ? "comparison: smooth (paper ramp)"
                                                          : "comparison: binary");
        break;
    case GLFW_KEY_P:
        a->pcf = !a->pcf;
        print_status(a, a->pcf ? "cube shadow map: PCF" : "cube shadow map: 1 tap");
        break;
    case GLFW_KEY_TAB:
        if (a->n == 0) {
            print_status(a, "no lights (N adds one)");
            break;
        }
        a->selected = (a->selected + 1) % a->n;
        snprintf(msg, sizeof msg, "light %d of %d selected", a->selected + 1, a->n);
        print_status(a, msg);
        break;
    case GLFW_KEY_N:
        if (a->n < MAX_LIGHTS - 1) {
            vr_light *l = &a->base[a->n];
            *l = a->base[a->n > 0 ? a->n - 1 : 0];
            memcpy(l->position, a->target, sizeof l->position);
            l->position[1] += 0.05f * a->diag;
            if (a->n == 0) {
                l->color[0] = l->color[1] = l->color[2] = 1.6f;
                l->attenuation[0] = 1.0f;
                l->attenuation[2] = 1.0f / (0.09f * a->diag * a->diag);
            }
            a->selected = a->n++;
            snprintf(msg, sizeof msg, "light %d added at the target", a->n);
            print_status(a, msg);
        }
        break;
    case GLFW_KEY_BACKSPACE:
    case GLFW_KEY_DELETE:
        if (a->n > 0) {
            memmove(&a->base[a->selected], &a->base[a->selected + 1],
                    (size_t)(a->n - a->selected - 1) * sizeof a->base[0]);
            a->n--;
            if (a->selected >= a->n)
                a->selected = a->n > 0 ? a->n - 1 : 0;
            print_status(a, "light removed");
        }
        break;
    case GLFW_KEY_SPACE:
        a->animate = !a->animate;
        print_status(a, a->animate ? "lights animated" : "lights still");
        break;
    case GLFW_KEY_F: {
        float f[3];
        forward(a, f);
        eye_of(a, a->fired_pos);
        for (int k = 0; k < 3; k++)
            a->fired_vel[k] = 0.35f * a->diag * f[k];
        a->fired = 1;
        a->fired_age = 0.0;
        print_status(a, "fired a light");
        break;
    }
    case GLFW_KEY_R:
        set_view(a, &a->home);
        print_status(a, "view reset");
        break;
    case GLFW_KEY_O:
        a->overlay = !a->overlay;
        break;
    case GLFW_KEY_H:
        fputs(keys_text, stdout);
        a->overlay = 2;
        break;
    case GLFW_KEY_X: {
        int fw, fh;
        vr_renderer_size(a->s.r, &fw, &fh);
        unsigned char *px = malloc((size_t)fw * (size_t)fh * 4);
        vr_error err;
        char path[64];
        snprintf(path, sizeof path, "vdsh-view-%03d.png", a->shots++);
        if (px && vr_read_pixels(a->s.r, px, (size_t)fw * (size_t)fh * 4, &err) == VR_OK &&
            write_png(path, fw, fh, px) == 0) {
            snprintf(msg, sizeof msg, "saved %s", path);
            print_status(a, msg);
        }
        free(px);
        break;
    }
    default:
        break;
    }
}

static void on_mouse_button(GLFWwindow *w, int button, int action, int mods)
{
    (void)mods;
    app *a = glfwGetWindowUserPointer(w);
    if (action == GLFW_PRESS) {
        a->drag = button == GLFW_MOUSE_BUTTON_LEFT ? 1 : button == GLFW_MOUSE_BUTTON_RIGHT ? 2 : 0;
        glfwGetCursorPos(w, &a->mx, &a->my);
    } else {
        a->drag = 0;
    }
}

static void on_cursor(GLFWwindow *w, double x, double y)
{
    app *a = glfwGetWindowUserPointer(w);
    if (!a->drag)
        return;
    float dx = (float)(x - a->mx), dy = (float)(y - a->my);
    a->mx = x;
    a->my = y;
    float eye[3];
    eye_of(a, eye);
    a->yaw += 0.005f * dx;
    a->pitch -= 0.005f * dy;
    if (a->pitch > 1.5f)
        a->pitch = 1.5f;
    if (a->pitch < -1.5f)
        a->pitch = -1.5f;
    if (a->drag == 2) {
        /* look around: the eye stays, the target moves */
        float f[3];
        forward(a, f);
        for (int k = 0; k < 3; k++)
            a->target[k] = eye[k] + a->dist * f[k];
    }
}

static void on_scroll(GLFWwindow *w, double xoff, double yoff)
{
    (void)xoff;
    app *a = glfwGetWindowUserPointer(w);
    a->dist *= powf(0.9f, (float)yoff);
    if (a->dist < 0.01f * a->diag)
        a->dist = 0.01f * a->diag;
}

/* Held keys: fly the camera, move the selected light. */
static void update(app *a, GLFWwindow *w, float dt)
{
    float f[3], right[3], speed = 0.25f * a->diag * dt;
    forward(a, f);
    float hl = sqrtf(f[0] * f[0] + f[2] * f[2]);
    float fh[3] = {hl > 0 ? f[0] / hl : 1.0f, 0.0f, hl > 0 ? f[2] / hl : 0.0f};
    right[0] = -fh[2];
    right[1] = 0.0f;
    right[2] = fh[0];
    if (glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS)
        speed *= 4.0f;
    float move[3] = {0, 0, 0};
    for (int k = 0; k < 3; k++) {
        if (glfwGetKey(w, GLFW_KEY_W) == GLFW_PRESS)
            move[k] += f[k];
        if (glfwGetKey(w, GLFW_KEY_S) == GLFW_PRESS)
            move[k] -= f[k];
        if (glfwGetKey(w, GLFW_KEY_D) == GLFW_PRESS)
            move[k] += right[k];
        if (glfwGetKey(w, GLFW_KEY_A) == GLFW_PRESS)
            move[k] -= right[k];
    }
    if (glfwGetKey(w, GLFW_KEY_E) == GLFW_PRESS)
        move[1] += 1.0f;
    if (glfwGetKey(w, GLFW_KEY_Q) == GLFW_PRESS)
        move[1] -= 1.0f;
    for (int k = 0; k < 3; k++)
        a->target[k] += speed * move[k];

    if (a->n > 0) {
        float lm[3] = {0, 0, 0}, ls = 0.15f * a->diag * dt;
        for (int k = 0; k < 3; k++) {
            if (glfwGetKey(w, GLFW_KEY_UP) == GLFW_PRESS)
                lm[k] += fh[k];
            if (glfwGetKey(w, GLFW_KEY_DOWN) == GLFW_PRESS)
                lm[k] -= fh[k];
            if (glfwGetKey(w, GLFW_KEY_RIGHT) == GLFW_PRESS)
                lm[k] += right[k];
            if (glfwGetKey(w, GLFW_KEY_LEFT) == GLFW_PRESS)
                lm[k] -= right[k];
        }
        if (glfwGetKey(w, GLFW_KEY_PAGE_UP) == GLFW_PRESS)
            lm[1] += 1.0f;
        if (glfwGetKey(w, GLFW_KEY_PAGE_DOWN) == GLFW_PRESS)
            lm[1] -= 1.0f;
        for (int k = 0; k < 3; k++)
            a->base[a->selected].position[k] += ls * lm[k];
    }
    if (a->animate)
        a->anim_t += dt;
    if (a->fired) {
        a->fired_age += dt;
        for (int k = 0; k < 3; k++)
            a->fired_pos[k] += dt * a->fired_vel[k];
        if (a->fired_age > FIRE_LIFE)
            a->fired = 0;
    }
}

/* The lights of this frame: the user's (circling when animated) and the
 * fired one, fading out. */
static int frame_lights(const app *a, vr_light *out)
{
    int n = 0;
    for (int i = 0; i < a->n; i++) {
        out[n] = a->base[i];
        if (a->animate) {
            float ph = (float)a->anim_t * 0.8f + 2.1f * (float)i, r = 0.08f * a->diag;
            out[n].position[0] += r * cosf(ph);
            out[n].position[2] += r * sinf(ph);
        }
        n++;
    }
    if (a->fired && n < MAX_LIGHTS) {
        vr_light *l = &out[n++];
        memset(l, 0, sizeof *l);
        memcpy(l->position, a->fired_pos, sizeof l->position);
        float fade = 1.0f - (float)(a->fired_age / FIRE_LIFE);
        l->color[0] = 2.0f * fade + 1e-6f;
        l->color[1] = 1.1f * fade;
        l->color[2] = 0.4f * fade;
        l->attenuation[0] = 1.0f;
        l->attenuation[2] = 1.0f / (0.01f * a->diag * a->diag);
    }
    return n;
}

static int run_window(const options *o)
{
    int w = o->have_size ? o->width : 1024, h = o->have_size ? o->height : 768;
    app a;
    memset(&a, 0, sizeof a);
    a.o = o;
    if (session_open(o, VR_CONTEXT_WINDOW, w, h, &a.s)) {
        fprintf(stderr, "vdsh-view: (use --render or --grid without a display)\n");
        return 1;
    }
    GLFWwindow *win = vr_context_window(a.s.ctx);
    glfwSetWindowUserPointer(win, &a);
    glfwSetKeyCallback(win, on_key);
    glfwSetMouseButtonCallback(win, on_mouse_button);
    glfwSetCursorPosCallback(win, on_cursor);
    glfwSetScrollCallback(win, on_scroll);

    a.diag = scene_diagonal(a.s.scene);
    a.n = scene_lights(a.s.scene, o, o->default_lights ? o->default_lights : 1, a.base);
    scene_camera(a.s.scene, o, &a.home);
    set_view(&a, &a.home);
    a.mode = o->mode;
    if (a.mode == VR_MODE_DEFAULT || !vr_scene_supports(a.s.scene, a.mode))
        a.mode = vr_scene_default_mode(a.s.scene);
    a.compare = o->compare;
    a.pcf = o->pcf;
    a.overlay = !o->no_overlay;
    if (!o->quiet) {
        printf("vdsh-view: %s on %s (%s)\n", o->files[0], vr_gl_renderer(),
               vr_context_description(a.s.ctx));
        fputs(keys_text, stdout);
    }

    int rc = 0;
    long frames = 0, keys_len = o->keys ? (long)strlen(o->keys) : 0;
    double last = now_ms(), fps_t0 = last, frame_ms = 0.0;
    int fps_frames = 0;
    while (!glfwWindowShouldClose(win)) {
        glfwPollEvents();
        if (frames < keys_len) {
            char k = o->keys[frames];
            int key = k == ' ' ? GLFW_KEY_SPACE : k == '>' ? GLFW_KEY_TAB
                    : k == '<' ? GLFW_KEY_BACKSPACE
                    : k >= '0' && k <= '9' ? GLFW_KEY_0 + (k - '0') : GLFW_KEY_A + (k - 'a');
            on_key(win, key, 0, GLFW_PRESS, 0);
        }
        double t = now_ms();
        float dt = (float)((t - last) * 1e-3);
        last = t;
        update(&a, win, dt);

        int fw = 0, fh = 0;
        glfwGetFramebufferSize(win, &fw, &fh);
        vr_error err;
        if (fw > 0 && fh > 0 && vr_renderer_resize(a.s.r, fw, fh, &err) != VR_OK) {
            fprintf(stderr, "vdsh-view: %s\n", err.msg);
            rc = 1;
            break;
        }
        vr_light lights[MAX_LIGHTS];
        int n = frame_lights(&a, lights);
        vr_draw_desc d = base_desc(o, lights, n);
        d.mode = a.mode;
        d.compare = a.compare;
        d.pcf = a.pcf;
        memcpy(d.camera.target, a.target, sizeof a.target);
        eye_of(&a, d.camera.eye);
        d.camera.fov_y = a.home.fov_y;
        if (vr_draw(a.s.r, a.s.scene, &d, &err) != VR_OK) {
            fprintf(stderr, "vdsh-view: %s\n", err.msg);
            rc = 1;
            break;
        }
        if (a.overlay) {
            vr_timings tm;
            vr_renderer_timings(a.s.r, &tm);
            char text[1024];
            int len = snprintf(text, sizeof text,
                               "%s, %s\n%d light%s (selected %d)%s\n"
                               "frame %.1f ms (%.1f fps)\n"
                               "GPU: shadow maps %.1f ms, lighting %.1f ms\n%s",
                               vr_scene_mode_label(a.s.scene, a.mode),
                               a.mode == VR_MODE_CUBE ? (a.pcf ? "PCF" : "1 tap")
                               : a.compare == VDSH_COMPARE_SMOOTH ? "smooth" : "binary",
                               n, n == 1 ? "" : "s", a.n ? a.selected + 1 : 0,
                               a.animate ? ", animated" : "", frame_ms,
                               frame_ms > 0 ? 1e3 / frame_ms : 0.0, tm.shadow_total_ms,
                               tm.lighting_total_ms, a.status[0] ? a.status : "h: keys");
            (void)len;
            vr_draw_text(a.s.r, 8, 8, fw >= 700 ? 2.0f : 1.0f, NULL, text, &err);
            /* the key list in the small font, along the bottom (13 lines
             * of stb_easy_font's 12-pixel line height) */
            if (a.overlay == 2)
                vr_draw_text(a.s.r, 8, fh - 13 * 12 - 16, 1.0f, NULL, keys_text, &err);
        }
        vr_renderer_blit(a.s.r, 0, fw, fh);
        if (o->screenshot && o->frames && frames + 1 >= o->frames) {
            /* what the window shows, read back from it */
            size_t size = (size_t)fw * (size_t)fh * 4;
            unsigned char *px = malloc(size);
            if (!px || vr_read_window(fw, fh, px, size, &err) != VR_OK) {
                fprintf(stderr, "vdsh-view: %s: %s\n", o->screenshot,
                        px ? err.msg : "out of memory");
                rc = 1;
            } else if (write_png(o->screenshot, fw, fh, px)) {
                rc = 1;
            }
            free(px);
        }
        vr_context_swap(a.s.ctx);
        frames++;
        fps_frames++;
        if (t - fps_t0 > 500.0) {
            frame_ms = (t - fps_t0) / fps_frames;
            fps_t0 = t;
            fps_frames = 0;
        }
        if (o->frames && frames >= o->frames)
            break;
    }
    if (!o->quiet)
        fprintf(stderr, "vdsh-view: %ld frames in a window (%s, %s)\n", frames,
                vr_context_description(a.s.ctx), vr_gl_renderer());
    session_close(&a.s);
    return rc;
}
#else
static int run_window(const options *o)
{
    (void)o;
    fprintf(stderr, "vdsh-view: built without GLFW: no window (use --render or --grid)\n");
    return 1;
}
#endif

int main(int argc, char **argv)
{
    options o;
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
    if (o.bench)
        return run_bench(&o);
    if (o.render_path)
        return run_render(&o);
    if (o.grid_path)
        return run_grid(&o);
    if (o.views_path)
        return run_frames(&o);
    return run_window(&o);
}
