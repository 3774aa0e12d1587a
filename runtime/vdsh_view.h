/*
 * vdsh_view.h - what the files of vdsh-view share (prefix vv_): its
 * options, its render modes, the scene defaults it draws with
 * (lights, camera, the base draw descriptor), the session (a context, the
 * scene, a renderer) and PNG output. One mode of the program per file,
 * over this small core:
 *   vdsh_view.c          main and the command line
 *   vdsh_view_core.c     the functions below
 *   vdsh_view_render.c   --render and --grid: headless images
 *   vdsh_view_frames.c   --views --frames: frames of a view set
 *   vdsh_view_bench.c    --bench: frame times of every mode, JSON
 *   vdsh_view_window.c   the window (GLFW): keys, mouse, overlay
 * The app layer: the only code that knows both the runtime (vr.h) and the
 * context (vr_context.h), plus GLFW input and PNG files.
 *
 * Errors: functions returning int give 0, or 1 after printing why on
 * stderr ("vdsh-view: ..."); the vv_run_* functions return the exit
 * status. Ownership: a session owns its context, scene and renderer
 * (vv_session_close frees them, also half-opened). One thread.
 */
#ifndef VDSH_VIEW_H
#define VDSH_VIEW_H

#include "vr.h"
#include "vr_context.h"

enum { VV_MAX_LIGHTS = 64, VV_MAX_FILES = 8, VV_MAX_MODES = 32 };

typedef struct vv_options {
    const char *render_path, *grid_path;
    int bench;
    const char *files[VV_MAX_FILES];
    int file_count;
    int have_camera;
    float camera[6];
    int fit; /* --fit: frame the bounds from outside */
    float fov;
    vr_light lights[VV_MAX_LIGHTS];
    int light_count;
    int default_lights; /* --lights N; 0: 1 (3 for --bench's second set) */
    int have_att;
    float att[3];
    int have_ambient;
    float ambient;
    vr_mode mode;
    int stream; /* VR_MODE_VDSH_BUFFER: vr_draw_desc.stream */
    int have_mode;
    vdsh_compare compare;
    int pcf;
    const char *sdf_path; /* --sdf FILE: mode sdf's volume (NULL: SCENE.sdf) */
    float sdf_k;          /* --sdf-k; 0: the runtime's default */
    int shadow_size;
    int have_size;
    int width, height;
    int no_cubemaps;
    vr_egl_platform egl;
    int frames;
    int no_mallopt;
    int buffer_floats; /* --bench: also time buffers of decoded f32 */
    int cpca_frame;    /* cpca decoded once per frame (--cpca-frame) */
    int compute;       /* sums in a compute shader (--compute) */
    int cpca_load;     /* cpca decoded once at load (--cpca-load) */
    int vertex_sums;   /* every buffer stream summed per pass (--vertex-sums) */
    /* --bench-lights: bit i, light set i of 1, 3, 16, 64; 0: all */
    int bench_sets;
    /* --bench-cube-sizes: cube and cube_pcf timed at each face size (cubeN,
     * cube_pcfN) */
    int bench_cube_sizes[8];
    int bench_cube_count;
    const char *bench_modes; /* --bench-modes: only these names; NULL: all */
    int bench_counts;        /* --bench-counts: GL counts of each mode */
    const char *json_path;   /* --json FILE: --bench's JSON ("-", NULL: stdout) */
    int quiet;
    int light_region;   /* --light-region: vr_scene_desc.light_region (0: the file's) */
    float light_box[6]; /* its box */
    const char *screenshot;
    int no_overlay;
    const char *keys;
    const char *views_path; /* --views: frames for a view set */
    const char *frames_arg; /* --frames: a count, or with --views the folder */
    const char *frames_dir;
    int frame_modes[VV_MAX_MODES]; /* --modes: indices into vv_modes[] */
    int frame_mode_count;
    /* load orders 2, 3, 5 as buffers too (a bufN mode of such an order, or
     * --bench) */
    int buffers;
} vv_options;

/* The viewer's render modes: the one list that --mode, --modes, the frame
 * file names, --bench (its modes and JSON keys), the --grid columns and
 * the window's digit keys all read (vdsh_view_core.c). A new render mode
 * is a row there plus its own code (vr.h and the runtime's mode table in
 * vr_util.c, vr_scene_supports, its shaders); the help texts
 * (vdsh_view.c, the window's key list) say it in words.
 *
 * Two spellings: `name` is the command line's and the frame files'
 * (cube-pcf), `json` the --bench JSON's and --bench-modes' (cube_pcf);
 * they differ for that mode only, and both stay: outputs and the scripts
 * that read them use each. The buffer modes: "bufN" (N = 1..16: the
 * fixed stream of order N from its buffer, VR_MODE_VDSH_BUFFER; only
 * orders up to VDSH_MAX_ORDER can exist), "adaptive" (the stream with an
 * order per vertex) and "buffer" (the scene's default of those). */
typedef struct vv_mode {
    const char *name; /* --mode, --modes, frame file names */
    const char *json; /* --bench's JSON and --bench-modes */
    vr_mode mode;
    int pcf;
    int stream;     /* VR_MODE_VDSH_BUFFER: vr_draw_desc.stream */
    unsigned flags; /* VV_MODE_* below */
    /* --grid: its column, 1..; 0 none. Several rows in a column: the first the
     * scene has, else the last */
    int grid;
    char key; /* the window: its digit key, 0 none */
} vv_mode;

enum {
    VV_MODE_OPTION = 1,         /* --mode takes it */
    VV_MODE_FRAMES = 2,         /* --modes takes it */
    VV_MODE_FRAMES_DEFAULT = 4, /* --views without --modes, where the scene has it */
    VV_MODE_BENCH = 8,          /* --bench, where the scene has it */
    VV_MODE_BENCH_LOG = 16      /* --bench on a log-distance scene, where it has it */
};

/* The rows, ended by one whose name is NULL; at most VV_MAX_MODES. */
extern const vv_mode vv_modes[];
/* Index of the mode called `name` (its first len characters) that has
 * `flag` (0: any), or -1. */
int vv_mode_find(const char *name, size_t len, unsigned flag);
/* 1 when the scene can draw mode m (its stream, its cubemaps). */
int vv_mode_available(const vr_scene *s, const vv_mode *m);
/* A label for m in this scene: vr_scene_mode_label, or for a buffer
 * mode its order (cap and mean order of an adaptive stream). */
void vv_mode_label(const vr_scene *s, vr_mode mode, int stream, char *out, size_t size);

/* The scene's bounds' diagonal, the default view's (vdsh_view_diagonal). */
float vv_scene_diagonal(const vr_scene *s);
/* n default lights of the scene: positions from vr_scene_default_lights,
 * the viewer's colours and fall-off (or --attenuation). */
int vv_default_lights(const vr_scene *s, const vv_options *o, int n, vr_light *out);
/* The lights of the options (with --attenuation applied), else n
 * defaults. */
int vv_scene_lights(const vr_scene *s, const vv_options *o, int n, vr_light *out);
/* The scene's default (or --fit) camera, with --camera and --fov. */
void vv_scene_camera(const vr_scene *s, const vv_options *o, vr_camera *c);
/* A draw of these lights with the options' mode, comparison, PCF and
 * ambient term; the camera is left zero. */
vr_draw_desc vv_base_desc(const vv_options *o, const vr_light *lights, int n);
/* CLOCK_MONOTONIC in milliseconds. */
double vv_now_ms(void);
/* An opaque RGBA8 PNG, written atomically (formats/vdsh_output.h). */
int vv_write_png(const char *path, int w, int h, const unsigned char *rgba);

/* Everything a run needs: a context, the scene, a renderer. */
typedef struct vv_session {
    vr_context *ctx;
    vr_scene *scene;
    vr_renderer *r;
} vv_session;

/* Load a scene file (with --no-cubemaps). */
int vv_open_scene(const vv_options *o, const char *path, vr_scene **out);
/* A context of `kind` (w x h for a window), the first scene file and a
 * w x h renderer. */
int vv_session_open(const vv_options *o, vr_context_kind kind, int w, int h, vv_session *s);
/* NULL members are fine. */
void vv_session_close(vv_session *s);
/* A headless context (of w x h when `sized`, else the platform's default
 * surface) and a w x h renderer on it; 0, or 1 after printing why. */
int vv_open_headless(const vv_options *o, int w, int h, int sized, vr_context **ctx,
                     vr_renderer **r);

/* The modes: the exit status of the program. */
int vv_run_render(const vv_options *o);
int vv_run_grid(const vv_options *o);
int vv_run_frames(const vv_options *o);
int vv_run_bench(const vv_options *o);
int vv_run_window(const vv_options *o);

#endif /* VDSH_VIEW_H */
