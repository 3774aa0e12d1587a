/*
 * vr_internal.h - what the files of the runtime library share and nobody
 * else sees: the scene and renderer structs, the GLSL program builder, the
 * error helper and a little matrix arithmetic.
 */
#ifndef VR_INTERNAL_H
#define VR_INTERNAL_H

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include "vdsh_scene_view.h"
#include "vdsh_sdf.h"
#include "vdsh_plural.h"
#include "vr.h"

/* Format a message into err (if not NULL) and return r. */
#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
vr_result
vr_fail(vr_error *err, vr_result r, const char *fmt, ...);

/* Plurals in messages: formats/vdsh_plural.h (vdsh_s, vdsh_plural). */

/* VR_OK when glGetError reports nothing; else VR_ERR_GL naming `what`.
 * Drains every pending error so that the next check starts clean. */
vr_result vr_check_gl(vr_error *err, const char *what);
/* Whether the context is GL major.minor or later, or has every one of
 * the n extensions exts (what that version brings in core). */
int vr_gl_has(int major, int minor, const char *const *exts, int n);

/* The SH order a mode draws (2, 3, 5), 0 for modes none and cube. */
int vr_mode_order(vr_mode m);

/* The path (vdsh_interp) mode m draws a stream of `quantity` with:
 * vdsh_runtime_interp of its order; -1 for modes none and cube. */
int vr_mode_interp(vr_mode m, uint32_t quantity);

/* The GPU order of a scene's nt triangles over nv vertices (vr_order.c):
 * triangles reordered for the post-transform vertex cache, vertices
 * renumbered in the order they are first used. Writes out (3 nt indices,
 * in the new numbering) and remap (nv entries: remap[old] = new, a
 * permutation; vertices no triangle uses go last). VR_ERR_FORMAT when an
 * index is not below nv, VR_ERR_OUT_OF_MEMORY; `name` for messages;
 * outputs are undefined on failure. */
vr_result vr_order_triangles(const uint32_t *indices, uint32_t nt, uint32_t nv, uint32_t *out,
                             uint32_t *remap, const char *name, vr_error *err);

/* Attribute locations, the same in every program. Coefficient attribute
 * k covers coefficients first[k] .. first[k] + size[k] - 1 of the stream
 * (vr_coef_attribs): grouped so that bands 0-2 (0..8) and the four
 * cubemap groups (9..12, ..., 21..24) each map to whole attributes. */
enum { VR_ATTR_POSITION = 0, VR_ATTR_NORMAL = 1, VR_ATTR_COEF0 = 2, VR_COEF_ATTRIBS = 7 };
extern const int vr_coef_first[VR_COEF_ATTRIBS];
extern const int vr_coef_size[VR_COEF_ATTRIBS];
/* How many coefficient attributes an order uses (2: 1, 3: 3, 5: 7). */
int vr_coef_attrib_count(int order);

/* Texture units: the four basis cubemaps, then one shadow cube map per
 * light of a pass, then a buffer stream's records. */
enum {
    VR_UNIT_BASIS = 0,
    VR_UNIT_SHADOW = 4,
    VR_UNIT_COEF = VR_UNIT_SHADOW + VR_MAX_LIGHTS_PER_PASS,
    VR_UNIT_SDF = VR_UNIT_COEF + 1,
    VR_UNIT_MODEL = VR_UNIT_SDF + 1, /* a cpca buffer stream's model */
    VR_UNIT_SUMS = VR_UNIT_MODEL + 1 /* the frame's sums (VR_SUMS_COMPUTE) */
};

/* A buffer stream's vertex attributes (VR_MODE_VDSH_BUFFER, variable
 * order): the record's first texel, and the vertex's order. */
enum { VR_ATTR_RECORD = 9, VR_ATTR_ORDER = 10 };

/* What a buffer texture's texels are (vr_buffer.c). */
typedef enum vr_buf_kind {
    VR_BUF_F32 = 0,  /* RGBA32F: four coefficients per texel */
    VR_BUF_F16 = 1,  /* RGBA16F */
    VR_BUF_S8 = 2,   /* RGBA8I (times the steps in u_ks) */
    VR_BUF_S8S6 = 3, /* R32UI words: 4 bytes, then 6-bit fields */
    VR_BUF_CPCA = 4  /* R32UI words: a cpca record as stored (cluster
                                index, packed weights), decoded per vertex
                                from the model texture (vr_buffer.model) */
} vr_buf_kind;

/* The most lights one invocation of the compute sums takes. */
enum { VR_SUMS_MAX_GROUP = 16 };

/* A stream drawn from buffer textures (VR_MODE_VDSH_BUFFER). */
typedef struct vr_buffer {
    int order;          /* fixed: its order; variable: the cap; 0: none */
    int variable;       /* 1: an order per vertex */
    vdsh_method method; /* how it was baked */
    vr_buf_kind kind;
    vdsh_encoding encoding;       /* the file's */
    float scale;                  /* multiplies the sums (f32, f16), else 1 */
    int stride;                   /* fixed: texels per vertex */
    GLuint buf, tex;              /* the records, in the GPU vertex order */
    float *ks;                    /* per coefficient index, K_l^m x step: a
                                constant table of the program (vr_glsl.c) */
    uint64_t ks_hash;             /* of ks and the order (the program key) */
    GLuint vbo_record, vbo_order; /* variable: per vertex, u32 and u8 */
    GLuint vao;
    size_t bytes;     /* all of the above */
    float mean_order; /* variable: over the vertices */
    /* VR_BUF_CPCA: the model as an RGBA32F buffer texture (vr_buffer.c),
     * basis vectors per cluster and bits per weight */
    GLuint model_buf, model_tex;
    int cpca_basis, cpca_bits;
    /* cpca_bits 0 (a width per basis vector, VDSH.md "cpca streams"): the
     * unpacking written out, "#define BUF_CPCA_UNPACK(f) ...\n"
     * (vr_buffer_cpca_unpack), malloc'd and in ks_hash; else NULL */
    char *cpca_unpack;
    /* VR_CPCA_PER_FRAME or VR_CPCA_AT_LOAD (vr_scene_desc.cpca_decode):
     * the scratch (scratch_tex 0: decoded where the sums are), f32
     * records of stride scratch_stride texels that the sums or the light
     * passes read as VR_BUF_F32 (vr_render.c), and the decode program
     * that writes it (a compute shader, shaders/vdsh_cpca_decode.glsl)
     * once per frame. VR_CPCA_AT_LOAD decodes once, at load, and then
     * deletes the program, the records and the model (decode_prog, buf,
     * tex, model_* 0; release_decoded) */
    GLuint decode_prog, scratch_buf, scratch_tex;
    int scratch_stride;
    /* VR_SUMS_COMPUTE (vr_scene_desc.sums; summed set): the sums
     * programs (shaders/vr_sums.glsl) by lights per invocation, each
     * built when first needed (0: not yet), reading the records (a cpca
     * stream's decoded as they are read: "in the sums") or the scratch;
     * sums_group: the lights per invocation, or 0: the frame's lights, up
     * to VR_SUMS_MAX_GROUP (a cpca stream decoded in the sums, whose
     * decode a group shares) */
    int summed;
    GLuint sums_prog[VR_SUMS_MAX_GROUP + 1];
    GLint sums_u_lights[VR_SUMS_MAX_GROUP + 1], sums_u_frame[VR_SUMS_MAX_GROUP + 1];
    int sums_group;
} vr_buffer;

/* Upload stream st (its quantity drawn) as a buffer stream of s, in the
 * GPU vertex order (remap[file vertex] = GPU vertex); floats: decoded f32.
 * VR_ERR_FORMAT, VR_ERR_OUT_OF_MEMORY, VR_ERR_GL naming `name`. */
vr_result vr_buffer_upload(vr_scene *s, const vdsh_stream *st, const uint32_t *remap, int floats,
                           int cpca_decode, int sums, const char *name, vr_error *err);
/* Whether this GL has compute shaders and shader storage buffers (GL
 * 4.3, or the ARB extensions of both). */
int vr_has_compute(void);
/* A cpca stream decoded: b's records into its scratch (a compute
 * dispatch), before the frame's light passes, or at load before any sums. */
void vr_buffer_decode(const vr_scene *s, const vr_buffer *b);
/* VR_SUMS_COMPUTE: the SH sums of b toward each of the n lights whose
 * positions storage buffer `lights` holds (n vec4, xyz; w unused), per
 * vertex and light, into sums (vertex-major: vertex v's at v * n), of the
 * vertices whose u32 in `seen` is `frame` (vr_cull). */
vr_result vr_buffer_sums(const vr_scene *s, vr_buffer *b, GLuint lights, GLuint sums, int n,
                         GLuint seen, uint32_t frame, vr_error *err);
/* The cull program (shaders/vr_cull.glsl) and its uniforms' locations. */
typedef struct vr_cull_prog {
    GLuint prog;
    GLint u_view_proj, u_triangles, u_frame;
} vr_cull_prog;
/* Build the cull program into *c. VR_ERR_SHADER, VR_ERR_OUT_OF_MEMORY. */
vr_result vr_cull_make(vr_cull_prog *c, vr_error *err);
/* Set seen[v] = frame for every vertex v of s that a triangle the view
 * vp (column-major, as the passes') does not clip away wholly uses;
 * seen: a storage buffer of a u32 per vertex. */
void vr_cull(const vr_scene *s, const vr_cull_prog *c, GLuint seen, const float vp[16],
             uint32_t frame);
void vr_buffer_destroy(vr_buffer *b);
/* The positions and normals (and indices) of s into the bound VAO. */
void vr_scene_base_attribs(const vr_scene *s);

struct vr_scene {
    uint32_t vertex_count, triangle_count;
    float bounds_min[3], bounds_max[3];
    vdsh_quantity quantity;
    float max_distance; /* the file's: clamps reconstructed distances */
    GLuint vbo_position, vbo_normal, ibo;
    /* Per order 1..VDSH_MAX_ORDER: the stream's buffer and a VAO with positions,
     * normals and its coefficients; vao[0] has positions and normals only. */
    GLuint vbo_stream[VDSH_ORDER_SLOTS];
    GLuint vao[VDSH_ORDER_SLOTS];
    vdsh_encoding encoding[VDSH_ORDER_SLOTS];
    vdsh_method method[VDSH_ORDER_SLOTS];
    float scale[VDSH_ORDER_SLOTS];
    /* Per order: a factor per coefficient, laid out as the attributes
     * (attribute k's component j at 4k + j): s8 streams' steps, else 1. */
    float coef_step[VDSH_ORDER_SLOTS][4 * VR_COEF_ATTRIBS];
    GLuint basis[4]; /* cube textures, functions 9+4k..12+4k */
    int cube_size;
    size_t gpu_bytes;
    vdsh_view view;                    /* the default view, decided at load */
    float pool[VR_MAX_POOL_LIGHTS][3]; /* vr_scene_pool_lights */
    int pool_count;
    vr_buffer buffer[VDSH_ORDER_SLOTS]; /* fixed orders, by order */
    vr_buffer variable;                 /* an order per vertex */
    GLuint sdf_tex;                     /* mode sdf: the distance volume (0: none) */
    vdsh_sdf sdf;                       /* its header (samples NULL) */
    size_t sdf_bytes;
    /* Why mode sdf has no volume, for its message: the companion volume
     * found beside the .vdsh but baked beside another bake (left by an
     * earlier vdsh-bake --sdf of the same name), not loaded; or the
     * companion's name, this scene's own, when there is none ("": the
     * scene has no path, or a volume was loaded). */
    char sdf_why[4608];
};

/* Mode sdf (vr_sdf.c): load desc->sdf_path, or the .vdsh's companion when
 * it exists, into s; a scene without either is fine (no volume). */
vr_result vr_sdf_load(vr_scene *s, const vr_scene_desc *desc, uint32_t vertex_count,
                      uint32_t triangle_count, vr_error *err);
/* Bind the volume and set the trace's uniforms of a bound program. */
void vr_sdf_bind(const vr_scene *s, GLuint prog, float k);

/* The buffer stream vr_draw_desc.stream names (vr_scene_buffer_stream),
 * or NULL. */
const vr_buffer *vr_scene_buffer(const vr_scene *s, int stream);

/* Place desc->light_pool lights in free space (vr_view.c). */
vr_result vr_scene_place_pool(vr_scene *s, const vdsh_view_mesh *m, int count, const char *name,
                              vr_error *err);

/* Which program: everything that changes the shader source. Compared
 * with memcmp: make it with memset(0) first (padding included). */
typedef struct vr_program_key {
    uint64_t ks_hash;     /* VR_MODE_VDSH_BUFFER: of its factor table (vr_buffer.ks) */
    uint8_t mode;         /* vr_mode, resolved (never DEFAULT) */
    uint8_t compare;      /* vdsh_compare */
    uint8_t quantity;     /* vdsh_quantity */
    uint8_t output;       /* vr_output */
    uint8_t pcf;          /* 0 or 1 */
    uint8_t lights;       /* lights in this pass, 0..VR_MAX_LIGHTS_PER_PASS */
    uint8_t packed;       /* 1: the stream is s8s6 (bands 2+ in packed words) */
    uint8_t buf_order;    /* VR_MODE_VDSH_BUFFER: order (variable: the cap) */
    uint8_t buf_kind;     /* vr_buf_kind */
    uint8_t buf_variable; /* 1: an order per vertex */
    uint8_t cpca_bits;    /* VR_BUF_CPCA: bits per weight, 0: a width per
                             vector (vr_buffer.cpca_unpack, in ks_hash) */
    uint8_t cpca_words;   /* VR_BUF_CPCA: u32 words per record */
    uint16_t cpca_basis;  /* VR_BUF_CPCA: basis vectors per cluster */
    uint8_t buf_sums;     /* 1: the vertex stage reads sums a compute
                             shader made (VR_SUMS_COMPUTE), no record */
} vr_program_key;

/* Texels of a record of this order and kind. */
int vr_buffer_stride(int order, vr_buf_kind kind);
/* The coefficient indices of an order in the order the shader consumes
 * them (m = 0..order-1, l = m..order-1, index l(l+1)+m then l(l+1)-m);
 * returns order^2. */
int vr_buffer_sequence(int order, int *out);

/* The buffer path's vertex-stage GLSL (shaders/vdsh_buffer.glsl). */
extern const char vr_buffer_glsl[];
extern const size_t vr_buffer_glsl_size;

typedef struct vr_program {
    vr_program_key key;
    GLuint prog;
    GLint u_view_proj, u_scale, u_coef_step, u_max_distance, u_light_pos, u_light_color,
        u_light_att;
    GLint u_ambient, u_shadow_nf, u_shadow_texel;
    GLint u_sums_stride, u_sums_first; /* buf_sums */
} vr_program;

/* Compile and link the lighting program for `key` (ks: the buffer
 * stream's factor table, buf_order^2 entries; NULL for other modes;
 * cpca_unpack: a cpca stream's with a width per vector, vr_buffer's, else
 * NULL). On failure returns VR_ERR_SHADER with the info log (and the key)
 * in err; *out untouched. */
vr_result vr_program_build(const vr_program_key *key, const float *ks, const char *cpca_unpack,
                           vr_program *out, vr_error *err);

/* The depth-only program that renders cube shadow map faces
 * (uniform u_view_proj). */
vr_result vr_program_build_depth(GLuint *out, vr_error *err);

/* Compile and link vertex + fragment source; `name` for messages. */
vr_result vr_link(const char *name, const char *vs, const char *fs, GLuint *out, vr_error *err);
/* The same for one compute shader. */
vr_result vr_link_compute(const char *name, const char *src, GLuint *out, vr_error *err);
/* The buffer path's factor table as GLSL, "const float KS[n] = ...;\n";
 * malloc'd, NULL when out of memory. */
char *vr_ks_table(const float *ks, int n);

/* Column-major 4x4 matrices. */
void vr_mat4_mul(float out[16], const float a[16], const float b[16]);
void vr_mat4_ortho(float out[16], float half_w, float half_h, float znear, float zfar);

/* Text (vr_text.c): lazily created GL objects owned by the renderer. */
typedef struct vr_text_state {
    GLuint prog, vao, vbo;
    GLint u_viewport, u_color;
    size_t vbo_size;
} vr_text_state;
void vr_text_destroy(vr_text_state *t);
/* Draw text into framebuffer fbo of size w x h (vr_draw_text). */
vr_result vr_text_draw_impl(vr_text_state *t, GLuint fbo, int w, int h, int x, int y, float scale,
                            const float color[4], const char *text, vr_error *err);

#endif /* VR_INTERNAL_H */
