/*
 * vr.h - the VDSH GL runtime (prefix vr_): load a baked .vdsh scene, upload
 * it, and draw it lit by point lights with precomputed visibility-distance
 * shadows (orders 2, 3, 5 from vertex attributes; any order, and streams
 * with an order per vertex, from buffer textures) or with the
 * cube-shadow-map baseline, into an
 * offscreen framebuffer that the caller reads back or blits.
 *
 * Does not: create a GL context or window (vr_context.h does, and only the
 * viewer uses both), bake anything, read anything but the .vdsh (the basis
 * cubemaps are computed, formats/vdsh_cube.h; the bake's OpenEXR copies
 * are for other engines), or write image files. Links formats/ and GL
 * only: neither bake/ nor OpenEXR, Embree or OpenMesh. Every function
 * here assumes the calling thread has a current GL 3.3 core (or later)
 * context, the same one for the whole life of an object.
 *
 * Usage (tests/test_runtime_glsl.c and runtime/vdsh_view_render.c are
 * compiled examples):
 *
 *     vr_error err;
 *     vr_scene *scene = NULL;
 *     vr_renderer *r = NULL;
 *     if (vr_scene_create(&(vr_scene_desc){.path = "room.vdsh"}, &scene, &err) ||
 *         vr_renderer_create(&(vr_renderer_desc){.width = 1024, .height = 768},
 *                            &r, &err)) {
 *         fprintf(stderr, "%s\n", err.msg);
 *         ...
 *     }
 *     vr_light light = {.position = {0, 3, 0}};
 *     vr_draw_desc d = {.mode = VR_MODE_VDSH3, .lights = &light, .light_count = 1};
 *     if (vr_draw(r, scene, &d, &err) != VR_OK) ...
 *     vr_read_pixels(r, rgba, rgba_size, &err);   (top row first)
 *     vr_renderer_destroy(r);
 *     vr_scene_destroy(scene);
 *
 * Descriptors: every *_desc struct (and vr_light, vr_camera) is read with
 * "zero means the documented default", so `{0}` plus the fields you care
 * about is always valid. Defaults are filled in one place per struct.
 *
 * Shadow modes (docs/DESIGN.md §1), for streams of a linear quantity
 * (distance, distance^2):
 *   VR_MODE_NONE        Lambert lighting only.
 *   VR_MODE_CUBE        baseline: one omnidirectional depth cube map per
 *                       light (shadow_map_size^2 per face), re-rendered on
 *                       every vr_draw; 1 nearest tap, or with pcf 4 taps of
 *                       bilinear (2x2) depth comparison.
 *   VR_MODE_VDSH2/3     order 2 / 3 (4 / 9 coefficients), the shadow term
 *                       evaluated per vertex and interpolated.
 *   VR_MODE_VDSH5       order 5 the paper's way: the first 9 coefficients in
 *                       the vertex stage, the last 16 interpolated and dotted
 *                       with the four basis cubemaps in the fragment stage
 *                       (half-float cube textures of the file's cube_size,
 *                       made at load, texel for texel the bake's files).
 *   VR_MODE_VDSH5_POLY  order 5 with the last 16 basis functions evaluated as
 *                       polynomials in the fragment stage (no cubemaps).
 *   VR_MODE_SDF         second baseline: distance-field soft shadows. The
 *                       scene's signed distance volume (vdsh-bake --sdf N,
 *                       a companion file) as a 3D texture, sphere-traced
 *                       from each fragment toward each light with
 *                       Quilez's soft-shadow estimate min(k h / t):
 *                       formats/vdsh_sdf.h's vdsh_sdf_shadow, the same in
 *                       C and GLSL.
 *   VR_MODE_VDSH_BUFFER any stored order (1..VDSH_MAX_ORDER), or a stream
 *                       with an order per vertex, chosen by
 *                       vr_draw_desc.stream: always the per-vertex distance
 *                       path below, whatever the quantity. Each vertex
 *                       reads its own record from a buffer texture (by
 *                       gl_VertexID; a variable-order stream's vertices
 *                       carry their order and record offset as integer
 *                       attributes), in the file's encoding and values,
 *                       reordered as the shader reads them (f32, f16 as
 *                       RGBA32F / RGBA16F texels, s8 as RGBA8I times a
 *                       step per coefficient index, s8s6 as R32UI words
 *                       unpacked in the shader: vdsh_stream_decode's
 *                       products; runtime/vr_buffer.c), and evaluates its
 *                       k^2 basis functions by the associated-Legendre
 *                       recurrence of formats/vdsh_sh.c (bands 0..k-1, the
 *                       same convention), each coefficient fetched once for
 *                       all lights of a pass. Streams of orders 2, 3, 5 are
 *                       buffered only with vr_scene_desc.buffers. A cpca
 *                       stream (vdsh-bake --encoding cpca, any order: never
 *                       on attributes) keeps its records as R32UI words and
 *                       its model in a second buffer texture, and each
 *                       vertex decodes its coefficients (mean + weights x
 *                       basis) in the vertex stage once per pass, four at
 *                       a time as the recurrence reads them
 *                       (docs/BENCHMARKS.md "Compressed high orders").
 * Log-distance streams (vdsh-bake --log) are drawn differently by every
 * VDSH mode: each vertex sums all its coefficients toward the light and
 * takes exp (its distance toward the light), the distances are
 * interpolated, and each fragment compares the result with its own light
 * distance; VR_MODE_VDSH5 and VR_MODE_VDSH5_POLY are then the same and need
 * no cubemaps. Which path a mode takes is vdsh_runtime_interp(order,
 * quantity) (vr_scene_interp; VR_MODE_VDSH_BUFFER: always the distance
 * path, which for log-distance streams is vdsh_runtime_interp's at every
 * order), and what each path computes inside a
 * triangle is vdsh_shadow_interior: the definitions vdsh-eval scores with.
 * The comparison (vdsh_compare from formats/vdsh_shadow.h: smooth ramp or
 * binary) and the stored quantity mean exactly what formats/vdsh_shadow.h
 * says, every reconstructed distance clamped to the file's max_distance;
 * tests/test_runtime_glsl.c checks the shaders against it, per vertex and
 * per fragment.
 *
 * Lights: any number. Up to max_lights_per_pass lights are summed in one
 * pass (a loop in the shaders); more lights take more passes, added with
 * additive blending. Each light's Lambert term is multiplied by its shadow.
 *
 * Errors: fallible functions return a vr_result (VR_OK = 0) and, when err
 * is not NULL, write a message that names the file (or the object) and the
 * problem, e.g. "room.vdsh: chunk 3 'COEF' at offset 1234: CRC mismatch".
 * Outputs are untouched on failure.
 * GL errors and shader compile/link logs end up in the message too.
 * Nothing is printed; there is no global error state.
 *
 * Ownership: vr_scene_create/vr_renderer_create return objects owned by
 * the caller and freed by vr_scene_destroy/vr_renderer_destroy, which
 * accept NULL. A scene owns its GL buffers and textures; a renderer owns
 * its framebuffer, programs, shadow maps and queries. Descriptors and the
 * arrays they point to are only borrowed for the duration of the call. A
 * scene may be drawn by several renderers of the same context.
 *
 * Threading: GL objects belong to the context; use each object from the
 * thread where its context is current. No shared state between objects.
 */
#ifndef VR_H
#define VR_H

#include <stddef.h>
#include <stdint.h>

#include "vdsh.h"
#include "vdsh_shadow.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum vr_result {
    VR_OK = 0,
    VR_ERR_IO,      /* a file cannot be opened or read */
    VR_ERR_FORMAT,  /* a .vdsh file is corrupt or unsupported */
    VR_ERR_MISSING, /* a needed stream or the cubemaps are absent */
    VR_ERR_GL,      /* GL error, incomplete framebuffer, no context */
    VR_ERR_SHADER,  /* a shader failed to compile or link (log in msg) */
    VR_ERR_OUT_OF_MEMORY,
    VR_ERR_ARGUMENT /* a bad descriptor field or argument */
} vr_result;

/* A static string such as "missing stream or file"; never NULL. */
const char *vr_result_str(vr_result r);

typedef struct vr_error {
    char msg[1024];
} vr_error;

/* ------------------------------------------------------------------ */
/* Scene: the .vdsh geometry and coefficient streams on the GPU          */

typedef struct vr_scene vr_scene;

enum { VR_CPCA_PER_PASS = 0, VR_CPCA_PER_FRAME = 1, VR_CPCA_AT_LOAD = 2 };
enum { VR_SUMS_AUTO = 0, VR_SUMS_VERTEX = 1, VR_SUMS_COMPUTE = 2 };

typedef struct vr_scene_desc {
    /* The .vdsh file to load. Either path or file must be set. */
    const char *path;
    /* An already-read file to upload instead (borrowed for the call; path,
     * if also set, is then only used in messages). */
    const vdsh_file *file;
    /* Stream quantity to draw; 0: distance. A file with no stream of this
     * quantity draws the quantity of its first stream instead (a file
     * baked with --log has only log-distance streams); vr_scene_get_info
     * says which. Streams of other quantities are not uploaded. */
    vdsh_quantity quantity;
    /* 0 (default): when the drawn order-5 stream is of a linear quantity
     * and the file has a cube_size (the bake's choice of face size; 0:
     * none), the four basis cubemaps are made at that size. 1: do not
     * make them (VR_MODE_VDSH5 then fails with VR_ERR_MISSING;
     * VR_MODE_VDSH5_POLY needs no cubemaps). Log-distance streams never
     * get them: their path has no use for them. No file but the .vdsh is
     * read either way. */
    int skip_cubemaps;
    /* 0 (default): none. N (1..VR_MAX_POOL_LIGHTS): also place N light
     * positions uniformly in the scene's free space at load
     * (vr_scene_pool_lights), for drawing with many lights. Costs a grid
     * of the triangles and 14 rays per position tried. */
    int light_pool;
    /* Streams for VR_MODE_VDSH_BUFFER. 0 (default): those no attribute
     * path can draw go up as buffer textures (orders 1, 4 and above 5,
     * streams with an order per vertex, cpca streams); orders 2, 3 and 5
     * only as attributes. 1: orders
     * 2, 3 and 5 as buffers too (more GPU memory: both copies). */
    int buffers;
    /* 0 (default): buffers hold the file's encoding as stored. 1: decoded
     * f32 coefficients instead (vdsh_stream_decode; 2x the bytes of f16,
     * 4x s8; a cpca stream decoded at load), no unpacking in the shader:
     * for comparisons. */
    int buffer_floats;
    /* Where a cpca stream is decoded. VR_CPCA_PER_PASS (0, default):
     * where its sums are computed, from the records as stored (their
     * bytes and the model's only): in the vertex stage of every pass of up
     * to VR_MAX_LIGHTS_PER_PASS lights, or (VR_SUMS_COMPUTE) in the
     * compute sums, once per vertex for up to 16 of the frame's lights.
     * VR_CPCA_PER_FRAME: once per vr_draw, by a compute shader that writes
     * every vertex's f32 coefficients into a scratch buffer that the sums
     * then read (16 bytes per 4 coefficients per vertex more: 576 at order
     * 12). VR_CPCA_AT_LOAD: the same once, at load, the records and the
     * model then freed (576 bytes per vertex in all at order 12). Both
     * need compute shaders and shader storage buffers (GL 4.3, or
     * GL_ARB_compute_shader and GL_ARB_shader_storage_buffer_object), else
     * the load fails with VR_ERR_GL. docs/BENCHMARKS.md has each. */
    int cpca_decode;
    /* Where a buffer stream's SH sums (VR_MODE_VDSH_BUFFER, a stream of
     * one order) are computed. VR_SUMS_AUTO (0, default): a cpca stream's
     * as VR_SUMS_COMPUTE where the GL has compute shaders (faster at every
     * light count measured, the same bytes: docs/BENCHMARKS.md "A cpca
     * stream decoded in the compute sums"), every other stream's as
     * VR_SUMS_VERTEX. VR_SUMS_VERTEX: in the vertex
     * stage of every pass, toward the pass's lights. VR_SUMS_COMPUTE:
     * once per vr_draw in a compute shader, one invocation per vertex and
     * up to 8 lights, into a storage buffer of 4 bytes per vertex and
     * light of the frame that the passes read, one value per light, as
     * order 5's attributes are read; only the vertices of triangles in
     * view. A cpca stream is decoded as cpca_decode says (the default: in
     * the sums). The high orders' path on a GPU (docs/BENCHMARKS.md "Sums
     * in a compute shader"). Needs
     * compute shaders and storage buffers (GL 4.3, or
     * GL_ARB_compute_shader and GL_ARB_shader_storage_buffer_object), else
     * the load fails with VR_ERR_GL. A stream with an order per vertex
     * keeps the vertex stage's sums. */
    int sums;
    /* VR_MODE_SDF's signed distance volume (formats/vdsh_sdf.h), uploaded
     * as a 3D texture. NULL (default): the .vdsh's companion file
     * (vdsh_sdf_path: room.vdsh -> room.sdf) when desc->path is set and
     * that file exists, else none (VR_MODE_SDF then fails with
     * VR_ERR_MISSING, naming that file). A volume that cannot be read fails the load, as
     * does one named here that was baked beside a scene of other vertex
     * or triangle counts; such a companion (left by an earlier bake of
     * the same name) is skipped, and VR_MODE_SDF's VR_ERR_MISSING says
     * so. */
    const char *sdf_path;
    /* Where the default lights (vr_scene_default_lights) and the light
     * pool go (vdsh-view --light-region): VR_LIGHT_REGION_FILE (0,
     * default) the box the file's `lreg` chunk records (vdsh-bake
     * --light-region), else the scene's rule; VR_LIGHT_REGION_AUTO the
     * scene's rule, whatever the file says; VR_LIGHT_REGION_GROWN the
     * bounds grown as vdsh-bake --light-region grown grows them
     * (vdsh_light_grown_box); VR_LIGHT_REGION_BOX light_box (min x,y,z,
     * max x,y,z; each min below its max, else VR_ERR_ARGUMENT). */
    int light_region;
    float light_box[6];
} vr_scene_desc;

enum { VR_LIGHT_REGION_FILE = 0, VR_LIGHT_REGION_AUTO, VR_LIGHT_REGION_GROWN, VR_LIGHT_REGION_BOX };

/* Load (when desc->path is set and desc->file is not), validate, upload
 * positions, normals, indices, every stream of the chosen quantity (orders
 * 1-5: f16 streams as GL_HALF_FLOAT attributes, f32 as GL_FLOAT, no
 * conversion; the rest as buffer textures, see desc->buffers) and
 * make the basis cubemaps (vdsh_cube_basis_face_gl_f16). Triangles and
 * vertices are uploaded in an order chosen for the vertex cache (the same
 * triangles, reordered; vertices renumbered), not the file's. On failure
 * *out is untouched and nothing stays allocated. Errors: VR_ERR_IO /
 * VR_ERR_FORMAT from the .vdsh reader (and VR_ERR_FORMAT for an index out
 * of range or a max_distance that is not finite and > 0 in a desc->file,
 * or a cube_size above GL_MAX_CUBE_MAP_TEXTURE_SIZE),
 * VR_ERR_OUT_OF_MEMORY, VR_ERR_GL (also for a buffer stream larger than
 * GL_MAX_TEXTURE_BUFFER_SIZE texels). */
vr_result vr_scene_create(const vr_scene_desc *desc, vr_scene **out, vr_error *err);

/* NULL is fine. */
void vr_scene_destroy(vr_scene *s);

typedef struct vr_scene_info {
    uint32_t vertex_count;
    uint32_t triangle_count;
    float bounds_min[3]; /* of the receiver vertices */
    float bounds_max[3];
    int has_order[VDSH_ORDER_SLOTS];          /* has_order[n]: a stream of order n */
    vdsh_encoding encoding[VDSH_ORDER_SLOTS]; /* its encoding */
    vdsh_method method[VDSH_ORDER_SLOTS];     /* how it was baked (has_order or has_buffer) */
    float scale[VDSH_ORDER_SLOTS];            /* its stream scale */
    int has_cubemaps;                         /* basis cubemaps made */
    int cube_size;                            /* their face size, or 0 */
    vdsh_quantity quantity;                   /* the quantity drawn */
    /* the file's: no reconstructed distance exceeds it (vdsh_shadow.h) */
    float max_distance;
    size_t gpu_bytes; /* buffers and textures uploaded */
    /* 1: a room, seen from inside by default; 0: an object, framed from
     * outside (see vr_scene_default_camera) */
    int interior;
    /* VR_MODE_VDSH_BUFFER's streams: has_buffer[n], a fixed stream of
     * order n; variable_order, the cap of the stream with an order per
     * vertex (0: none), variable_mean_order its vertices' mean order and
     * variable_method how it was baked;
     * buffer_bytes, their share of gpu_bytes; buffer_encoding[n], the
     * file's encoding of the fixed stream of order n (cpca: decoded per
     * pass, or once per frame where buffer_per_frame[n]). */
    int has_buffer[VDSH_ORDER_SLOTS];
    vdsh_encoding buffer_encoding[VDSH_ORDER_SLOTS];
    int buffer_per_frame[VDSH_ORDER_SLOTS];
    /* 1: the fixed stream of order n is summed in a compute shader
     * (vr_scene_desc.sums) */
    int buffer_compute[VDSH_ORDER_SLOTS];
    int variable_order;
    float variable_mean_order;
    vdsh_method variable_method;
    size_t buffer_bytes;
    int has_sdf;         /* a distance volume: VR_MODE_SDF */
    uint32_t sdf_dim[3]; /* its samples per axis */
    size_t sdf_bytes;    /* its share of gpu_bytes */
} vr_scene_info;

void vr_scene_get_info(const vr_scene *s, vr_scene_info *out);

/* ------------------------------------------------------------------ */
/* Renderer: framebuffer, programs, shadow maps, timers                  */

typedef struct vr_renderer vr_renderer;

enum { VR_MAX_LIGHTS_PER_PASS = 8 };

/* The defaults of zero sizes, here and in vr_context_desc; the viewer's
 * too (it names them, it does not repeat them). */
enum { VR_DEFAULT_WIDTH = 1024, VR_DEFAULT_HEIGHT = 768, VR_DEFAULT_SHADOW_MAP_SIZE = 512 };

typedef enum vr_color_format {
    VR_COLOR_RGBA8 = 0,  /* default: an image to look at */
    VR_COLOR_RGBA32F = 1 /* exact values for tests and debug outputs */
} vr_color_format;

typedef struct vr_renderer_desc {
    int width, height;            /* 0: VR_DEFAULT_WIDTH x _HEIGHT, 1024 x 768 */
    vr_color_format color_format; /* 0: RGBA8 */
    /* cube shadow map face size; 0: VR_DEFAULT_SHADOW_MAP_SIZE, 512 */
    int shadow_map_size;
    int max_lights_per_pass; /* 1..VR_MAX_LIGHTS_PER_PASS; 0: 8 */
} vr_renderer_desc;

/* Create the offscreen framebuffer (colour texture + 32-bit float depth)
 * and the timer queries. Programs are compiled when first needed. */
vr_result vr_renderer_create(const vr_renderer_desc *desc, vr_renderer **out, vr_error *err);

/* NULL and half-built renderers are fine. */
void vr_renderer_destroy(vr_renderer *r);

/* Resize the framebuffer (contents undefined afterwards). On failure the
 * old size stays. */
vr_result vr_renderer_resize(vr_renderer *r, int width, int height, vr_error *err);

void vr_renderer_size(const vr_renderer *r, int *width, int *height);

/* "llvmpipe (LLVM 15.0.6, 256 bits)" etc.: GL_RENDERER of the current
 * context; never NULL. */
const char *vr_gl_renderer(void);

/* ------------------------------------------------------------------ */
/* Drawing                                                               */

typedef enum vr_mode {
    VR_MODE_DEFAULT = 0, /* vr_scene_default_mode: every tool's default */
    VR_MODE_NONE,
    VR_MODE_CUBE,
    VR_MODE_VDSH2,
    VR_MODE_VDSH3,
    VR_MODE_VDSH5,
    VR_MODE_VDSH5_POLY,
    VR_MODE_VDSH_BUFFER,
    VR_MODE_SDF, /* distance-field shadows (vr_scene_desc.sdf_path) */
    VR_MODE_COUNT_
} vr_mode;

/* vr_draw_desc.stream for VR_MODE_VDSH_BUFFER: the stream with an order
 * per vertex (1..VDSH_MAX_ORDER: the fixed stream of that order). */
enum { VR_STREAM_VARIABLE = -1 };

/* "none", "cube", "vdsh2", "vdsh3", "vdsh5", "vdsh5poly", "buffer", "sdf" (the
 * viewer's --mode names); "?" for others. vr_mode_from_name returns 0 on success
 * and leaves *out untouched on an unknown name. */
const char *vr_mode_name(vr_mode m);
int vr_mode_from_name(const char *name, vr_mode *out);
/* A label for pictures: "VDSH order 5 (25 coeff., cubemaps)" etc. */
const char *vr_mode_label(vr_mode m);
/* The mode VR_MODE_DEFAULT draws for a scene, the one definition of the
 * default that vdsh-view (no --mode) uses too: order 5 the paper's way
 * (VR_MODE_VDSH5) where the scene supports it, else order 5 with the
 * polynomials, else the highest of orders 3 and 2 the file has, else
 * VR_MODE_VDSH_BUFFER when it has a buffer stream (a bake of orders 1, 4,
 * above 5 or of adaptive order only; vr_draw_desc.stream 0 then draws its
 * default). A scene with none of these streams gets VR_MODE_VDSH5, which
 * vr_draw refuses with VR_ERR_MISSING naming the stream. Never
 * VR_MODE_DEFAULT. */
vr_mode vr_scene_default_mode(const vr_scene *s);
/* 1 when the scene has what the mode needs (stream, cubemaps; for
 * VR_MODE_VDSH_BUFFER any buffer stream). Here and below VR_MODE_DEFAULT
 * stands for vr_scene_default_mode(s). */
int vr_scene_supports(const vr_scene *s, vr_mode m);
/* The stream VR_MODE_VDSH_BUFFER draws for vr_draw_desc.stream: 0 means
 * the scene's default, its stream with an order per vertex if it has one,
 * else its highest buffered order; returns that (VR_STREAM_VARIABLE or an
 * order), or 0 when the scene has no such stream. */
int vr_scene_buffer_stream(const vr_scene *s, int stream);
/* GPU bytes of that stream's buffers (records, and for a stream with an
 * order per vertex its 5 bytes of attributes per vertex); 0 without it. */
size_t vr_scene_buffer_bytes(const vr_scene *s, int stream);
/* The path (vdsh_interp) a VDSH mode draws this scene's stream with:
 * vdsh_runtime_interp(order, quantity drawn); -1 for modes none and cube. */
int vr_scene_interp(const vr_scene *s, vr_mode m);
/* vr_mode_label, saying what is drawn for this scene: for log-distance
 * streams "VDSH order 5 (25 coeff., log, per-vertex)" etc. */
const char *vr_scene_mode_label(const vr_scene *s, vr_mode m);

typedef struct vr_light {
    float position[3];
    float color[3];       /* linear RGB; all zero: white (1, 1, 1) */
    float attenuation[3]; /* 1 / (a0 + a1 d + a2 d^2); all zero: (1, 0, 0) */
} vr_light;

typedef struct vr_camera {
    float eye[3];
    /* eye == target (e.g. both zero): the scene's default view
     * (vr_scene_default_camera) */
    float target[3];
    float up[3];        /* zero: (0, 1, 0) */
    float fov_y;        /* degrees; 0: 60 */
    float znear, zfar;  /* 0: from the scene bounds */
    float ortho_height; /* > 0: orthographic, this many units tall */
} vr_camera;

typedef enum vr_output {
    VR_OUTPUT_COLOR = 0, /* albedo * (ambient + sum lambert * shadow) */
    /* light 0: (s, d_V, d_L, 1): s the shadow factor alone (0 shadowed .. 1
     * lit; no Lambert term, no attenuation, also where the surface faces
     * away from the light: whatever the mode's test gives there, the cube
     * map's depth test or the SH distance below the horizon), and the
     * distances compared (on the visibility path, the vertices' values
     * interpolated, as vdsh_shadow_interior's d_vis); d_V is -1 in modes
     * none and cube. Alpha 1 where a surface was drawn: the clear colour's
     * alpha elsewhere */
    VR_OUTPUT_SHADOW = 1,
    VR_OUTPUT_POSITION = 2 /* (world x, y, z, 1) */
} vr_output;

typedef struct vr_draw_desc {
    vr_mode mode;           /* 0: vr_scene_default_mode of the scene */
    vdsh_compare compare;   /* 0: smooth (the paper's ramp) */
    int pcf;                /* VR_MODE_CUBE: 0 one nearest tap, 1 PCF */
    const vr_light *lights; /* light_count entries, borrowed */
    int light_count;        /* 0: no lights (ambient only) */
    vr_camera camera;
    float ambient[3];     /* added before the albedo multiply; zero: none */
    float albedo[3];      /* all zero: 0.8 grey */
    float clear_color[4]; /* zero: black, alpha 0 */
    vr_output output;     /* 0: colour */
    /* 1: draw the vertices as 1-pixel points, not triangles (a test aid:
     * each pixel then holds one vertex's unclipped, uninterpolated value) */
    int points;
    /* VR_MODE_VDSH_BUFFER: the stream drawn, vr_scene_buffer_stream's
     * argument (0: the scene's default); ignored by other modes */
    int stream;
    /* VR_MODE_SDF: the softness k of vdsh_sdf_shadow; 0: VDSH_SDF_DEFAULT_K */
    float sdf_k;
} vr_draw_desc;

/* Draw one frame into the renderer's framebuffer: for each group of up to
 * max_lights_per_pass lights, render their cube shadow maps (VR_MODE_CUBE)
 * and one lighting pass. Errors: VR_ERR_MISSING when the scene lacks the
 * mode's stream (VR_MODE_VDSH_BUFFER: the stream asked for) or cubemaps, VR_ERR_ARGUMENT for bad fields, VR_ERR_SHADER
 * / VR_ERR_GL. On failure the framebuffer contents are undefined. */
vr_result vr_draw(vr_renderer *r, const vr_scene *s, const vr_draw_desc *d, vr_error *err);

/* The default camera for a scene (y up). An interior (a room, a
 * courtyard: vr_scene_info.interior) is seen from inside its bounds near
 * one end, along the longest horizontal axis, a little above the floor.
 * Anything else (an object, a terrain) is framed from outside, as
 * vr_scene_fit_camera. A scene is an interior when, from that inside eye,
 * at least 60% of 128 directions meet the front of a surface (the side its
 * vertex normals face), decided once at load. The decision, the cameras
 * and the default lights are formats/vdsh_scene_view.h's: the bake side's
 * tools compute the same view from the same .vdsh mesh. */
void vr_scene_default_camera(const vr_scene *s, vr_camera *out);

/* The whole scene in view from outside, whatever the scene: the eye up and
 * to the side of the bounds' centre, looking at it, just far enough that
 * every corner of the bounds is within a 60-degree field of view (fov_y
 * 60) vertically and horizontally (an image at least as wide as it is
 * tall shows all of it; a wider fov too). A flat object (one triangle,
 * a panel) is seen from the side its normals face: the view mirrored
 * through its plane (vdsh_view.fit, formats/vdsh_scene_view.h). */
void vr_scene_fit_camera(const vr_scene *s, vr_camera *out);

/* Up to max (at most 4) default light positions; returns how many were
 * written. An interior's are spread through its bounds (light 0 roughly in
 * the middle, a little above the floor), pulled into the box the file's
 * `lreg` chunk records when it has one; an object's in the light region
 * the bake trained on (vdsh_light_region, or the box the file's `lreg`
 * chunk records: vdsh-bake --light-region), light 0 toward the top of it
 * and to the side of the default eye.
 * Each is in free space (formats/vdsh_light.h: not inside a solid, not on
 * a surface), moved at load when its place is not: to the nearest place
 * VDSH_VIEW_LIGHT_MARGIN clearances from every surface, else the nearest
 * free one (vdsh_view_compute, formats/vdsh_scene_view.h, says how). Colours and attenuations are left
 * to the caller. */
int vr_scene_default_lights(const vr_scene *s, vr_light *out, int max);

enum { VR_MAX_POOL_LIGHTS = 64 };

/* Up to max of the light positions placed at load (vr_scene_desc
 * light_pool); returns how many were written (0 without a pool). They are
 * "placed uniformly in free space" as formats/vdsh_light.h defines it:
 * the candidates of vdsh_light_candidate (seed 1) in the light region
 * (the file's `lreg` box when it has one, else vdsh_light_region: the
 * bounds, or the bounds grown around a closed
 * or nearly closed object) that pass vdsh_view_free_space against the drawn mesh, in
 * sequence order (vdsh_light_place, the bake side's placement: at most
 * vdsh_light_tries candidates, 1000 per position in the bounds); deterministic. Colours and attenuations are
 * left zero. */
int vr_scene_pool_lights(const vr_scene *s, vr_light *out, int max);

/* Draw text (ASCII, stb_easy_font's 7-pixel font scaled by `scale`) on top
 * of the framebuffer at pixel (x, y) from the top-left, on a dark box.
 * color NULL: white. Lines break at '\n'. */
vr_result vr_draw_text(vr_renderer *r, int x, int y, float scale, const float color[4],
                       const char *text, vr_error *err);

/* Read the framebuffer, top row first: RGBA8 gives width*height*4 bytes,
 * RGBA32F width*height*4 floats. size is the byte size of dst; too small
 * gives VR_ERR_ARGUMENT and dst untouched. */
vr_result vr_read_pixels(vr_renderer *r, void *dst, size_t size, vr_error *err);

/* Copy the framebuffer to framebuffer `dst` (0: the window), scaled to
 * dst_width x dst_height. */
void vr_renderer_blit(vr_renderer *r, unsigned dst, int dst_width, int dst_height);

/* Read width x height RGBA8 pixels of the window's back buffer
 * (framebuffer 0), top row first: what the next swap will show. */
vr_result vr_read_window(int width, int height, void *dst, size_t size, vr_error *err);

/* ------------------------------------------------------------------ */
/* Timings                                                               */

enum { VR_TIMING_MAX_GROUPS = 8 };

typedef struct vr_timings {
    uint64_t frame; /* 1 for the first vr_draw; 0: none available */
    int groups;     /* light groups (passes) drawn */
    /* GPU time (GL_TIME_ELAPSED), milliseconds. Per group g: the cube
     * shadow maps of its lights and its lighting pass (groups beyond the
     * last slot add into the last); group 0's lighting also holds the
     * frame's decode and sums in compute shaders (vr_scene_desc). */
    double shadow_ms[VR_TIMING_MAX_GROUPS];
    double lighting_ms[VR_TIMING_MAX_GROUPS];
    double shadow_total_ms, lighting_total_ms;
    double gpu_ms; /* sum of the above */
    /* CPU wall time from the start of vr_draw to the end of
     * vr_renderer_finish (glFinish); 0 if the frame was not finished. */
    double cpu_ms;
} vr_timings;

/* glFinish, then collect every pending timer result. Afterwards
 * vr_renderer_timings returns this frame's complete timings. */
void vr_renderer_finish(vr_renderer *r);

/* The most recent frame whose timer results are available (queries are
 * kept in a ring of a few frames, so without vr_renderer_finish this lags
 * a frame or two behind and never stalls). out->frame is 0 when none. */
void vr_renderer_timings(vr_renderer *r, vr_timings *out);

/* The work of one frame as the GL counts it, for figures that carry from a
 * software rasteriser to a GPU: every pass of the frame (cube shadow-map
 * faces and lighting passes) summed. GL_SAMPLES_PASSED and
 * GL_PRIMITIVES_GENERATED always; the pipeline statistics (GL 4.6 or
 * ARB_pipeline_statistics_query) where the context has them
 * (`statistics` 1), else those fields are 0. */
typedef struct vr_counts {
    int statistics;                /* the pipeline statistics below are valid */
    uint64_t samples_passed;       /* samples passing the depth test */
    uint64_t primitives_generated; /* primitives out of the vertex stage */
    uint64_t vertices_submitted;   /* vertices read by the draws */
    uint64_t vertex_invocations;   /* vertex shader runs (after reuse) */
    uint64_t fragment_invocations; /* fragment shader runs (depth-only too) */
    uint64_t clipping_primitives;  /* primitives reaching clipping */
} vr_counts;

/* vr_draw with the queries of vr_counts around it, then glFinish; the
 * counts of this frame in *out. Slower than vr_draw (a stall): not for
 * timed frames. Errors as vr_draw. */
vr_result vr_draw_counted(vr_renderer *r, const vr_scene *s, const vr_draw_desc *d, vr_counts *out,
                          vr_error *err);

#ifdef __cplusplus
}
#endif

#endif /* VR_H */
