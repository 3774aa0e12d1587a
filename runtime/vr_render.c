/*
 * vr_render.c - the renderer: offscreen framebuffer, program cache, cube
 * shadow maps, the light passes and the timer queries.
 *
 * A frame (vr_draw):
 *   1. clear the framebuffer;
 *   2. for each group of up to max_lights_per_pass lights:
 *        VR_MODE_CUBE: render a depth cube map per light of the group
 *          (6 faces, the whole scene each, every frame: the baseline's
 *          real cost), timed as the group's shadow pass;
 *        draw the scene once with the group's program, timed as its
 *          lighting pass; the first group writes depth, later groups add
 *          with GL_ONE/GL_ONE blending where depth is equal.
 * The debug outputs (shadow terms, positions) draw the first group only.
 */
#include "vdsh_camera.h"
#include "vr_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { FRAMES_IN_FLIGHT = 4, MAX_PROGRAMS = 96 };

/* Timer queries of one frame. */
typedef struct frame_slot {
    uint64_t frame; /* 0: slot unused */
    int pending;    /* queries issued, results not collected */
    int count, cap;
    GLuint *queries;
    uint8_t *kind; /* 0 shadow, 1 lighting */
    uint8_t *group;
    int groups;
    double cpu_start; /* seconds, CLOCK_MONOTONIC */
} frame_slot;

struct vr_renderer {
    int width, height;
    vr_color_format color_format;
    int shadow_size;
    int per_pass;
    GLuint fbo, color, depth;
    /* Cube shadow maps: one depth cube per light slot of a pass. */
    GLuint shadow_fbo, depth_prog;
    GLint depth_u_view_proj;
    GLuint shadow_tex[VR_MAX_LIGHTS_PER_PASS];
    GLuint sampler_nearest, sampler_linear;
    vr_program programs[MAX_PROGRAMS];
    int program_count;
    int timers; /* GL_TIME_ELAPSED available */
    frame_slot slots[FRAMES_IN_FLIGHT];
    uint64_t frame;
    vr_timings last;
    vr_text_state text;
    /* VR_SUMS_COMPUTE: the frame's light positions and sums (a storage
     * buffer read by the passes as an R32F buffer texture), grown to the
     * largest frame drawn */
    GLuint sums_lights, sums_buf, sums_tex;
    size_t sums_cap;      /* floats */
    float (*sums_pos)[4]; /* the lights' positions, as uploaded */
    int sums_pos_cap;     /* lights */
    /* which vertices the frame's view uses (vr_cull): the program, a u32
     * per vertex (seen_cap of them) and the frame's mark, never 0 */
    vr_cull_prog cull;
    GLuint seen_buf;
    uint32_t seen_cap, seen_frame;
};

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ------------------------------------------------------------------ */
/* Framebuffer                                                          */

static void delete_targets(vr_renderer *r)
{
    glDeleteFramebuffers(1, &r->fbo);
    glDeleteTextures(1, &r->color);
    glDeleteRenderbuffers(1, &r->depth);
    r->fbo = r->color = r->depth = 0;
}

static const char *fbo_status_name(GLenum s)
{
    switch (s) {
    case GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT: return "incomplete attachment";
    case GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT: return "missing attachment";
    case GL_FRAMEBUFFER_UNSUPPORTED: return "unsupported format combination";
    default: return "incomplete";
    }
}

static vr_result make_targets(vr_renderer *r, int w, int h, vr_error *err)
{
    GLuint fbo = 0, color = 0, depth = 0;
    glGenTextures(1, &color);
    glBindTexture(GL_TEXTURE_2D, color);
    if (r->color_format == VR_COLOR_RGBA32F)
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, w, h, 0, GL_RGBA, GL_FLOAT, NULL);
    else
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenRenderbuffers(1, &depth);
    glBindRenderbuffer(GL_RENDERBUFFER, depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, w, h);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    GLenum st = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    vr_result res = vr_check_gl(err, "framebuffer");
    if (res == VR_OK && st != GL_FRAMEBUFFER_COMPLETE)
        res = vr_fail(err, VR_ERR_GL, "framebuffer %dx%d: %s (0x%04x)", w, h, fbo_status_name(st),
                      (unsigned)st);
    if (res != VR_OK) {
        glDeleteFramebuffers(1, &fbo);
        glDeleteTextures(1, &color);
        glDeleteRenderbuffers(1, &depth);
        return res;
    }
    delete_targets(r);
    r->fbo = fbo;
    r->color = color;
    r->depth = depth;
    r->width = w;
    r->height = h;
    return VR_OK;
}

static vr_result check_size(int w, int h, vr_error *err)
{
    GLint max = 0;
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max);
    if (w < 1 || h < 1 || w > max || h > max)
        return vr_fail(err, VR_ERR_ARGUMENT, "framebuffer size %dx%d not in 1..%d", w, h, (int)max);
    return VR_OK;
}

vr_result vr_renderer_create(const vr_renderer_desc *desc, vr_renderer **out, vr_error *err)
{
    vr_renderer_desc d = desc ? *desc : (vr_renderer_desc){0};
    /* Defaults, in one place. */
    if (!d.width && !d.height) {
        d.width = VR_DEFAULT_WIDTH;
        d.height = VR_DEFAULT_HEIGHT;
    }
    if (!d.shadow_map_size)
        d.shadow_map_size = VR_DEFAULT_SHADOW_MAP_SIZE;
    if (!d.max_lights_per_pass)
        d.max_lights_per_pass = VR_MAX_LIGHTS_PER_PASS;
    if (!out)
        return vr_fail(err, VR_ERR_ARGUMENT, "vr_renderer_create: NULL output");
    if (!glGetString(GL_VERSION))
        return vr_fail(err, VR_ERR_GL, "vr_renderer_create: no current GL context");
    if ((unsigned)d.color_format > VR_COLOR_RGBA32F)
        return vr_fail(err, VR_ERR_ARGUMENT, "unknown colour format %u", (unsigned)d.color_format);
    if (d.max_lights_per_pass < 1 || d.max_lights_per_pass > VR_MAX_LIGHTS_PER_PASS)
        return vr_fail(err, VR_ERR_ARGUMENT, "max_lights_per_pass %d not in 1..%d",
                       d.max_lights_per_pass, VR_MAX_LIGHTS_PER_PASS);
    GLint max_cube = 0;
    glGetIntegerv(GL_MAX_CUBE_MAP_TEXTURE_SIZE, &max_cube);
    if (d.shadow_map_size < 1 || d.shadow_map_size > max_cube)
        return vr_fail(err, VR_ERR_ARGUMENT, "shadow map size %d not in 1..%d", d.shadow_map_size,
                       (int)max_cube);
    vr_result res = check_size(d.width, d.height, err);
    if (res != VR_OK)
        return res;

    vr_renderer *r = calloc(1, sizeof *r);
    if (!r)
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "renderer: out of memory");
    r->color_format = d.color_format;
    r->shadow_size = d.shadow_map_size;
    r->per_pass = d.max_lights_per_pass;
    res = make_targets(r, d.width, d.height, err);
    if (res == VR_OK)
        res = vr_program_build_depth(&r->depth_prog, err);
    if (res == VR_OK) {
        r->depth_u_view_proj = glGetUniformLocation(r->depth_prog, "u_view_proj");
        glGenFramebuffers(1, &r->shadow_fbo);
        glBindFramebuffer(GL_FRAMEBUFFER, r->shadow_fbo);
        glDrawBuffer(GL_NONE);
        glReadBuffer(GL_NONE);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        /* Depth comparison in the sampler: one tap is one compare
         * (nearest); PCF taps are 2x2 bilinear compares (linear). */
        glGenSamplers(1, &r->sampler_nearest);
        glGenSamplers(1, &r->sampler_linear);
        const GLuint smp[2] = {r->sampler_nearest, r->sampler_linear};
        for (int i = 0; i < 2; i++) {
            GLint filter = i ? GL_LINEAR : GL_NEAREST;
            glSamplerParameteri(smp[i], GL_TEXTURE_MIN_FILTER, filter);
            glSamplerParameteri(smp[i], GL_TEXTURE_MAG_FILTER, filter);
            glSamplerParameteri(smp[i], GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
            glSamplerParameteri(smp[i], GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
            glSamplerParameteri(smp[i], GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
            glSamplerParameteri(smp[i], GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
            glSamplerParameteri(smp[i], GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
        }
        GLint bits = 0;
        glGetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &bits);
        r->timers = bits > 0;
        res = vr_check_gl(err, "renderer");
    }
    if (res != VR_OK) {
        vr_renderer_destroy(r);
        return res;
    }
    *out = r;
    return VR_OK;
}

void vr_renderer_destroy(vr_renderer *r)
{
    if (!r)
        return;
    delete_targets(r);
    glDeleteFramebuffers(1, &r->shadow_fbo);
    glDeleteTextures(VR_MAX_LIGHTS_PER_PASS, r->shadow_tex);
    glDeleteSamplers(1, &r->sampler_nearest);
    glDeleteSamplers(1, &r->sampler_linear);
    if (r->depth_prog)
        glDeleteProgram(r->depth_prog);
    for (int i = 0; i < r->program_count; i++)
        glDeleteProgram(r->programs[i].prog);
    for (int i = 0; i < FRAMES_IN_FLIGHT; i++) {
        frame_slot *s = &r->slots[i];
        if (s->cap)
            glDeleteQueries(s->cap, s->queries);
        free(s->queries);
        free(s->kind);
        free(s->group);
    }
    vr_text_destroy(&r->text);
    GLuint bufs[3] = {r->sums_lights, r->sums_buf, r->seen_buf};
    glDeleteBuffers(3, bufs);
    if (r->cull.prog)
        glDeleteProgram(r->cull.prog);
    glDeleteTextures(1, &r->sums_tex);
    free(r->sums_pos);
    free(r);
}

vr_result vr_renderer_resize(vr_renderer *r, int width, int height, vr_error *err)
{
    if (width == r->width && height == r->height)
        return VR_OK;
    vr_result res = check_size(width, height, err);
    return res != VR_OK ? res : make_targets(r, width, height, err);
}

void vr_renderer_size(const vr_renderer *r, int *width, int *height)
{
    *width = r->width;
    *height = r->height;
}

/* ------------------------------------------------------------------ */
/* Timer queries                                                        */

/* Move a finished frame's results into r->last. With wait = 0 only when
 * they are available (never stalls); returns 1 when collected. */
static int collect(vr_renderer *r, frame_slot *s, int wait)
{
    if (!s->pending)
        return 0;
    if (s->count > 0 && !wait) {
        GLint ready = 0;
        glGetQueryObjectiv(s->queries[s->count - 1], GL_QUERY_RESULT_AVAILABLE, &ready);
        if (!ready)
            return 0;
    }
    vr_timings t;
    memset(&t, 0, sizeof t);
    t.frame = s->frame;
    t.groups = s->groups;
    for (int i = 0; i < s->count; i++) {
        GLuint64 ns = 0;
        glGetQueryObjectui64v(s->queries[i], GL_QUERY_RESULT, &ns);
        double ms = 1e-6 * (double)ns;
        int g = s->group[i];
        if (s->kind[i] == 0) {
            t.shadow_ms[g] += ms;
            t.shadow_total_ms += ms;
        } else {
            t.lighting_ms[g] += ms;
            t.lighting_total_ms += ms;
        }
    }
    t.gpu_ms = t.shadow_total_ms + t.lighting_total_ms;
    s->pending = 0;
    if (t.frame >= r->last.frame)
        r->last = t;
    return 1;
}

/* Begin timing `kind` of group g in the current frame's slot. Returns 0
 * when nothing was begun (no timers or out of memory). */
static int timer_begin(vr_renderer *r, frame_slot *s, int kind, int g)
{
    if (!r->timers)
        return 0;
    if (s->count == s->cap) {
        int cap = s->cap ? 2 * s->cap : 8;
        GLuint *q = realloc(s->queries, (size_t)cap * sizeof *q);
        if (q)
            s->queries = q;
        uint8_t *k = q ? realloc(s->kind, (size_t)cap) : NULL;
        if (k)
            s->kind = k;
        uint8_t *gr = k ? realloc(s->group, (size_t)cap) : NULL;
        if (!gr)
            return 0;
        s->group = gr;
        glGenQueries(cap - s->cap, s->queries + s->cap);
        s->cap = cap;
    }
    s->kind[s->count] = (uint8_t)kind;
    s->group[s->count] = (uint8_t)(g < VR_TIMING_MAX_GROUPS ? g : VR_TIMING_MAX_GROUPS - 1);
    glBeginQuery(GL_TIME_ELAPSED, s->queries[s->count++]);
    return 1;
}

static void timer_end(int begun)
{
    if (begun)
        glEndQuery(GL_TIME_ELAPSED);
}

void vr_renderer_finish(vr_renderer *r)
{
    glFinish();
    double end = now_seconds();
    frame_slot *cur = NULL;
    for (int i = 0; i < FRAMES_IN_FLIGHT; i++) {
        frame_slot *s = &r->slots[i];
        if (s->frame == r->frame && r->frame)
            cur = s;
        collect(r, s, 1);
    }
    if (cur && r->last.frame == cur->frame)
        r->last.cpu_ms = 1e3 * (end - cur->cpu_start);
}

void vr_renderer_timings(vr_renderer *r, vr_timings *out)
{
    for (int i = 0; i < FRAMES_IN_FLIGHT; i++)
        collect(r, &r->slots[i], 0);
    *out = r->last;
}

/* ------------------------------------------------------------------ */
/* Programs                                                             */

static vr_result get_program(vr_renderer *r, const vr_program_key *k, const float *ks,
                             const char *cpca_unpack, const vr_program **out, vr_error *err)
{
    for (int i = 0; i < r->program_count; i++)
        if (memcmp(&r->programs[i].key, k, sizeof *k) == 0) {
            *out = &r->programs[i];
            return VR_OK;
        }
    /* A full cache drops everything: it only fills when cycling through
     * every combination, and rebuilding is cheap next to that. */
    if (r->program_count == MAX_PROGRAMS) {
        for (int i = 0; i < r->program_count; i++)
            glDeleteProgram(r->programs[i].prog);
        r->program_count = 0;
    }
    vr_result res = vr_program_build(k, ks, cpca_unpack, &r->programs[r->program_count], err);
    if (res != VR_OK)
        return res;
    *out = &r->programs[r->program_count++];
    return VR_OK;
}

/* ------------------------------------------------------------------ */
/* Cube shadow maps                                                     */

static vr_result ensure_shadow_tex(vr_renderer *r, int slot, vr_error *err)
{
    if (r->shadow_tex[slot])
        return VR_OK;
    GLuint t = 0;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_CUBE_MAP, t);
    for (int f = 0; f < 6; f++)
        glTexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f, 0, GL_DEPTH_COMPONENT32F,
                     r->shadow_size, r->shadow_size, 0, GL_DEPTH_COMPONENT, GL_FLOAT, NULL);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAX_LEVEL, 0);
    glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
    vr_result res = vr_check_gl(err, "shadow cube map");
    if (res == VR_OK) {
        glBindFramebuffer(GL_FRAMEBUFFER, r->shadow_fbo);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_CUBE_MAP_POSITIVE_X,
                               t, 0);
        GLenum st = glCheckFramebufferStatus(GL_FRAMEBUFFER);
        if (st != GL_FRAMEBUFFER_COMPLETE)
            res = vr_fail(err, VR_ERR_GL, "shadow framebuffer: %s (0x%04x)", fbo_status_name(st),
                          (unsigned)st);
    }
    if (res != VR_OK) {
        glDeleteTextures(1, &t);
        return res;
    }
    r->shadow_tex[slot] = t;
    return VR_OK;
}

/* Near and far planes of a light's face projections: far reaches the
 * farthest corner of the scene; near is a fixed fraction of it (32-bit
 * float depth keeps about far/near * 2^-24 relative precision at far).
 * Both relative to the scene, so a scene 1e-11 across keeps its shadows
 * (an absolute margin of 1e-6 put it inside the near plane). */
static void shadow_planes(const vr_scene *s, const float l[3], float nf[2])
{
    float far2 = 0.0f;
    for (int c = 0; c < 8; c++) {
        float d2 = 0.0f;
        for (int k = 0; k < 3; k++) {
            float x = ((c >> k) & 1) ? s->bounds_max[k] : s->bounds_min[k];
            d2 += (x - l[k]) * (x - l[k]);
        }
        far2 = fmaxf(far2, d2);
    }
    float far = 1.01f * sqrtf(far2);
    if (!(far > 0.0f))
        far = 1.0f; /* the light at the only point of the scene */
    nf[0] = far * 1e-3f;
    nf[1] = far;
}

/* GL cube-map face f seen from `eye`: the look-at directions and up
 * vectors that make a 90-degree render land in GL's face orientation
 * (OpenGL 4.6 table 8.19; the face images have t = -y on the side faces);
 * a 90-degree formats/vdsh_camera.h camera, as the eye's view is one. */
static void face_view_proj(int f, const float eye[3], const float nf[2], float out[16])
{
    static const float dir[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                    {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
    static const float up[6][3] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1},
                                   {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
    /* The target a step away at the eye's own scale: eye + 1 is the eye
     * itself in float beyond 2^24 (no view, no shadows). */
    const float k = 1.0f + fmaxf(fabsf(eye[0]), fmaxf(fabsf(eye[1]), fabsf(eye[2])));
    vdsh_camera c = {{eye[0], eye[1], eye[2]},
                     {eye[0] + k * dir[f][0], eye[1] + k * dir[f][1], eye[2] + k * dir[f][2]},
                     {up[f][0], up[f][1], up[f][2]},
                     90.0f};
    float view[16], proj[16];
    vdsh_camera_view(&c, view);
    vdsh_camera_projection(&c, 1.0f, nf[0], nf[1], proj);
    vr_mat4_mul(out, proj, view);
}

static vr_result render_shadow_maps(vr_renderer *r, const vr_scene *s, const vr_light *lights,
                                    int n, float nf[][2], vr_error *err)
{
    for (int i = 0; i < n; i++) {
        vr_result res = ensure_shadow_tex(r, i, err);
        if (res != VR_OK)
            return res;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, r->shadow_fbo);
    glViewport(0, 0, r->shadow_size, r->shadow_size);
    glUseProgram(r->depth_prog);
    glBindVertexArray(s->vao[0]);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    /* Slope-scaled offset for surfaces at grazing angles to the light;
     * the normal offset in the shader does the rest. */
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.5f, 2.0f);
    for (int i = 0; i < n; i++) {
        shadow_planes(s, lights[i].position, nf[i]);
        for (int f = 0; f < 6; f++) {
            float vp[16];
            face_view_proj(f, lights[i].position, nf[i], vp);
            glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT,
                                   GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f, r->shadow_tex[i], 0);
            glClear(GL_DEPTH_BUFFER_BIT);
            glUniformMatrix4fv(r->depth_u_view_proj, 1, GL_FALSE, vp);
            glDrawElements(GL_TRIANGLES, (GLsizei)(3 * s->triangle_count), GL_UNSIGNED_INT, NULL);
        }
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
    return VR_OK;
}

/* ------------------------------------------------------------------ */
/* Drawing                                                              */

static int finite3(const float v[3])
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

/* The camera with its defaults filled in, as one view-projection matrix. */
static void camera_matrix(const vr_renderer *r, const vr_scene *s, const vr_camera *in,
                          float vp[16])
{
    vr_camera c = *in;
    if (c.eye[0] == c.target[0] && c.eye[1] == c.target[1] && c.eye[2] == c.target[2]) {
        vr_camera def;
        vr_scene_default_camera(s, &def);
        memcpy(c.eye, def.eye, sizeof c.eye);
        memcpy(c.target, def.target, sizeof c.target);
        if (!c.up[0] && !c.up[1] && !c.up[2])
            memcpy(c.up, def.up, sizeof c.up);
    }
    if (!c.up[0] && !c.up[1] && !c.up[2])
        c.up[1] = 1.0f;
    if (!(c.fov_y > 0.0f))
        c.fov_y = 60.0f;
    float far2 = 0.0f;
    for (int k = 0; k < 8; k++) {
        float d2 = 0.0f;
        for (int a = 0; a < 3; a++) {
            float x = ((k >> a) & 1) ? s->bounds_max[a] : s->bounds_min[a];
            d2 += (x - c.eye[a]) * (x - c.eye[a]);
        }
        far2 = fmaxf(far2, d2);
    }
    /* the margin 1e-6 (scene units), or a thousandth of the distance in a
     * scene too small for it (1e-11 units across: every surface nearer
     * than far / 4000 was clipped, a black frame) */
    float far = 1.05f * sqrtf(far2) + fminf(1e-6f, 1e-3f * sqrtf(far2));
    if (!(far > 0.0f))
        far = 1e-6f;
    float aspect = (float)r->width / (float)r->height;
    /* The view and the perspective are formats/vdsh_camera.h's: the same
     * camera a ray-traced frame of this view uses (vdsh-frames). */
    vdsh_camera vc;
    memcpy(vc.eye, c.eye, sizeof vc.eye);
    memcpy(vc.target, c.target, sizeof vc.target);
    memcpy(vc.up, c.up, sizeof vc.up);
    vc.fov_y = c.fov_y;
    float view[16], proj[16];
    vdsh_camera_view(&vc, view);
    if (c.ortho_height > 0.0f) {
        float zn = c.znear != 0.0f ? c.znear : -far, zf = c.zfar != 0.0f ? c.zfar : far;
        vr_mat4_ortho(proj, 0.5f * c.ortho_height * aspect, 0.5f * c.ortho_height, zn, zf);
    } else {
        float zf = c.zfar > 0.0f ? c.zfar : far;
        float zn = c.znear > 0.0f ? c.znear : zf / 4000.0f;
        vdsh_camera_projection(&vc, aspect, zn, zf, proj);
    }
    vr_mat4_mul(vp, proj, view);
}

/* The descriptor's defaults, in one place. */
static void draw_defaults(const vr_scene *s, vr_draw_desc *d)
{
    if (d->mode == VR_MODE_DEFAULT)
        d->mode = vr_scene_default_mode(s);
    if (!d->albedo[0] && !d->albedo[1] && !d->albedo[2])
        d->albedo[0] = d->albedo[1] = d->albedo[2] = 0.8f;
    if (d->sdf_k == 0.0f)
        d->sdf_k = VDSH_SDF_DEFAULT_K;
}

/* The descriptor's values, its defaults filled in. */
static vr_result check_draw_desc(const vr_draw_desc *d, vr_error *err)
{
    if ((unsigned)d->mode >= VR_MODE_COUNT_)
        return vr_fail(err, VR_ERR_ARGUMENT, "vr_draw: unknown mode %u", (unsigned)d->mode);
    if ((unsigned)d->compare > VDSH_COMPARE_BINARY)
        return vr_fail(err, VR_ERR_ARGUMENT, "vr_draw: unknown comparison %u",
                       (unsigned)d->compare);
    if ((unsigned)d->output > VR_OUTPUT_POSITION)
        return vr_fail(err, VR_ERR_ARGUMENT, "vr_draw: unknown output %u", (unsigned)d->output);
    if (!(d->sdf_k > 0.0f && d->sdf_k < 1e6f))
        return vr_fail(err, VR_ERR_ARGUMENT, "vr_draw: sdf_k %g is not a number > 0",
                       (double)d->sdf_k);
    if (d->light_count < 0 || (d->light_count > 0 && !d->lights))
        return vr_fail(err, VR_ERR_ARGUMENT, "vr_draw: %d light%s but no array", d->light_count,
                       vdsh_plural((unsigned long long)d->light_count, "", "s"));
    for (int i = 0; i < d->light_count; i++)
        if (!finite3(d->lights[i].position) || !finite3(d->lights[i].color) ||
            !finite3(d->lights[i].attenuation))
            return vr_fail(err, VR_ERR_ARGUMENT, "vr_draw: light %d is not finite", i);
    return VR_OK;
}

/* Whether the scene has what d->mode draws, with a message that says what
 * is missing and how to get it; for mode buffer, *buf: the stream drawn. */
static vr_result check_mode(const vr_scene *s, const vr_draw_desc *d, const vr_buffer **buf,
                            vr_error *err)
{
    vr_mode mode = d->mode;
    *buf = NULL;
    if (mode == VR_MODE_VDSH_BUFFER) {
        *buf = vr_scene_buffer(s, d->stream);
        if (!*buf && d->stream == VR_STREAM_VARIABLE)
            return vr_fail(err, VR_ERR_MISSING,
                           "mode buffer: the scene has no %s stream with "
                           "an order per vertex",
                           vdsh_quantity_name(s->quantity));
        if (!*buf && d->stream == 0)
            return vr_fail(err, VR_ERR_MISSING,
                           "mode buffer: the scene has no %s stream in a "
                           "buffer (orders 1, 4, above 5, an order per vertex; 2, 3, 5 with "
                           "vr_scene_desc.buffers)",
                           vdsh_quantity_name(s->quantity));
        if (!*buf)
            return vr_fail(err, VR_ERR_MISSING,
                           "mode buffer: the scene has no order-%d %s stream in a buffer%s",
                           d->stream, vdsh_quantity_name(s->quantity),
                           d->stream >= 1 && d->stream <= 5 && s->vbo_stream[d->stream]
                               ? " (orders 2, 3, 5 are buffered with vr_scene_desc.buffers)"
                               : "");
    } else if (!vr_scene_supports(s, mode)) {
        if (mode == VR_MODE_SDF && s->sdf_why[0])
            return vr_fail(err, VR_ERR_MISSING, "mode sdf needs the scene's distance volume: %s",
                           s->sdf_why);
        if (mode == VR_MODE_SDF)
            return vr_fail(err, VR_ERR_MISSING,
                           "mode sdf needs the scene's distance volume: "
                           "none was loaded (bake it with vdsh-bake --sdf N, which writes "
                           "SCENE.sdf beside SCENE.vdsh)");
        if (mode == VR_MODE_VDSH5 && s->vbo_stream[5])
            return vr_fail(err, VR_ERR_MISSING,
                           "mode %s needs the basis cubemaps, which this scene has not "
                           "(its file's cube_size is 0, or they were skipped; vdsh5poly "
                           "needs none)",
                           vr_mode_name(mode));
        return vr_fail(err, VR_ERR_MISSING, "mode %s: the scene has no order-%d %s stream",
                       vr_mode_name(mode), vr_mode_order(mode), vdsh_quantity_name(s->quantity));
    }
    return VR_OK;
}

/* The timing slot of a new frame, its finished predecessors' timings
 * collected first. */
static frame_slot *begin_frame(vr_renderer *r)
{
    uint64_t frame = ++r->frame;
    frame_slot *slot = &r->slots[frame % FRAMES_IN_FLIGHT];
    for (int i = 0; i < FRAMES_IN_FLIGHT; i++)
        collect(r, &r->slots[i], 0);
    collect(r, slot, 1);
    slot->frame = frame;
    slot->count = 0;
    slot->pending = 1;
    slot->cpu_start = now_seconds();
    return slot;
}

/* The frame's target cleared, and the state every pass starts from. */
static void clear_target(const vr_renderer *r, const vr_draw_desc *d)
{
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    glViewport(0, 0, r->width, r->height);
    glDepthMask(GL_TRUE);
    glClearColor(d->clear_color[0], d->clear_color[1], d->clear_color[2], d->clear_color[3]);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
}

/* What every pass of one frame shares. */
typedef struct draw_frame {
    vr_renderer *r;
    const vr_scene *s;
    const vr_draw_desc *d;
    /* The stream's order in the attribute modes (0: none). */
    int order;
    /* Mode buffer: the stream drawn, whether it was decoded into its
     * f32 scratch this frame (a cpca stream: vr_buffer_decode), and
     * whether its sums were computed (VR_SUMS_COMPUTE: frame_sums). */
    const vr_buffer *buf;
    int scratch, summed;
    float vp[16];
    frame_slot *slot;
} draw_frame;

/* The program of a pass of n lights: everything that changes its source. */
static void program_key(const draw_frame *F, int n, vr_program_key *key)
{
    const vr_draw_desc *d = F->d;
    const vr_buffer *buf = F->buf;
    memset(key, 0, sizeof *key);
    key->mode = (uint8_t)d->mode;
    key->compare = (uint8_t)d->compare;
    key->quantity = (uint8_t)F->s->quantity;
    key->output = (uint8_t)d->output;
    key->pcf = (uint8_t)(d->pcf && d->mode == VR_MODE_CUBE);
    key->lights = (uint8_t)n;
    key->packed = F->order && F->s->encoding[F->order] == VDSH_ENCODING_S8S6;
    if (buf) {
        key->buf_order = (uint8_t)buf->order;
        key->buf_kind = (uint8_t)(F->scratch ? VR_BUF_F32 : buf->kind);
        key->buf_variable = (uint8_t)buf->variable;
        key->ks_hash = buf->ks_hash;
        key->cpca_basis = (uint16_t)(F->scratch ? 0 : buf->cpca_basis);
        key->cpca_bits = (uint8_t)(F->scratch ? 0 : buf->cpca_bits);
        key->cpca_words = (uint8_t)(F->scratch || buf->kind != VR_BUF_CPCA ? 0 : buf->stride);
        if (F->summed) { /* no record read: one program for every stream */
            key->buf_kind = VR_BUF_F32;
            key->ks_hash = 0;
            key->buf_sums = 1;
        }
    }
}

/* Depth and blending of pass g: the first writes depth, the others add
 * their lights onto it where the depth is equal. */
static void pass_state(const vr_renderer *r, int g)
{
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    glViewport(0, 0, r->width, r->height);
    glEnable(GL_DEPTH_TEST);
    if (g == 0) {
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        glDisable(GL_BLEND);
    } else {
        glDepthFunc(GL_LEQUAL);
        glDepthMask(GL_FALSE);
        glEnable(GL_BLEND);
        glBlendFunc(GL_ONE, GL_ONE);
    }
}

/* The uniforms of pass g: camera, the stream's scale and steps, the
 * ambient term (first pass only) and the group's n lights. */
static void set_uniforms(const draw_frame *F, const vr_program *p, int g, const vr_light *group,
                         int n)
{
    const vr_scene *s = F->s;
    const vr_draw_desc *d = F->d;
    int order = F->order;
    glUseProgram(p->prog);
    glUniformMatrix4fv(p->u_view_proj, 1, GL_FALSE, F->vp);
    glUniform1f(p->u_scale, F->buf ? F->buf->scale : order ? s->scale[order] : 1.0f);
    if (order)
        glUniform4fv(p->u_coef_step, VR_COEF_ATTRIBS, s->coef_step[order]);
    glUniform1f(p->u_max_distance, s->max_distance);
    /* The albedo multiplies the ambient term and the light colours
     * here, once, rather than every fragment. */
    float ambient[3];
    for (int k = 0; k < 3; k++)
        ambient[k] = g == 0 ? d->albedo[k] * d->ambient[k] : 0.0f;
    glUniform3fv(p->u_ambient, 1, ambient);
    if (n > 0) {
        float pos[VR_MAX_LIGHTS_PER_PASS][3], col[VR_MAX_LIGHTS_PER_PASS][3];
        float att[VR_MAX_LIGHTS_PER_PASS][3];
        for (int i = 0; i < n; i++) {
            const vr_light *L = &group[i];
            memcpy(pos[i], L->position, sizeof pos[i]);
            int black = !L->color[0] && !L->color[1] && !L->color[2];
            for (int k = 0; k < 3; k++)
                col[i][k] = d->albedo[k] * (black ? 1.0f : L->color[k]);
            int none = !L->attenuation[0] && !L->attenuation[1] && !L->attenuation[2];
            for (int k = 0; k < 3; k++)
                att[i][k] = none ? (k == 0 ? 1.0f : 0.0f) : L->attenuation[k];
        }
        glUniform3fv(p->u_light_pos, n, &pos[0][0]);
        glUniform3fv(p->u_light_color, n, &col[0][0]);
        glUniform3fv(p->u_light_att, n, &att[0][0]);
        if (F->summed) {
            glUniform1i(p->u_sums_stride, d->light_count);
            glUniform1i(p->u_sums_first, g * F->r->per_pass);
        }
    }
}

/* The textures the mode reads: the group's shadow maps (nf: their near
 * and far planes), the basis cubemaps, the distance volume or the
 * buffer stream; unit 0 active after. */
static void bind_textures(const draw_frame *F, const vr_program *p, const vr_program_key *key,
                          int n, const float nf[][2])
{
    const vr_renderer *r = F->r;
    const vr_scene *s = F->s;
    const vr_buffer *buf = F->buf;
    vr_mode mode = F->d->mode;
    if (mode == VR_MODE_CUBE && n > 0) {
        glUniform2fv(p->u_shadow_nf, n, &nf[0][0]);
        glUniform1f(p->u_shadow_texel, 2.0f / (float)r->shadow_size);
        for (int i = 0; i < n; i++) {
            glActiveTexture(GL_TEXTURE0 + VR_UNIT_SHADOW + (GLenum)i);
            glBindTexture(GL_TEXTURE_CUBE_MAP, r->shadow_tex[i]);
            glBindSampler(VR_UNIT_SHADOW + (GLuint)i,
                          key->pcf ? r->sampler_linear : r->sampler_nearest);
        }
    }
    if (mode == VR_MODE_VDSH5 && vr_mode_interp(mode, s->quantity) == VDSH_INTERP_SPLIT) {
        for (int k = 0; k < 4; k++) {
            glActiveTexture(GL_TEXTURE0 + VR_UNIT_BASIS + (GLenum)k);
            glBindTexture(GL_TEXTURE_CUBE_MAP, s->basis[k]);
        }
    }
    if (mode == VR_MODE_SDF)
        vr_sdf_bind(s, p->prog, F->d->sdf_k);
    if (F->summed) {
        glActiveTexture(GL_TEXTURE0 + VR_UNIT_SUMS);
        glBindTexture(GL_TEXTURE_BUFFER, r->sums_tex);
    } else if (buf) {
        glActiveTexture(GL_TEXTURE0 + VR_UNIT_COEF);
        glBindTexture(GL_TEXTURE_BUFFER, F->scratch ? buf->scratch_tex : buf->tex);
        if (buf->model_tex && !F->scratch) {
            glActiveTexture(GL_TEXTURE0 + VR_UNIT_MODEL);
            glBindTexture(GL_TEXTURE_BUFFER, buf->model_tex);
        }
    }
    glActiveTexture(GL_TEXTURE0);
}

/* Pass g: lights g * per .. of the frame's, their shadow maps first in
 * mode cube, then the scene drawn with them. */
static vr_result draw_pass(const draw_frame *F, int g, vr_error *err)
{
    vr_renderer *r = F->r;
    const vr_scene *s = F->s;
    const vr_draw_desc *d = F->d;
    int per = r->per_pass;
    const vr_light *group = d->lights ? d->lights + g * per : NULL;
    int n = d->light_count - g * per;
    if (n > per)
        n = per;
    if (n < 0)
        n = 0;

    float nf[VR_MAX_LIGHTS_PER_PASS][2];
    if (d->mode == VR_MODE_CUBE && n > 0) {
        int t = timer_begin(r, F->slot, 0, g);
        vr_result res = render_shadow_maps(r, s, group, n, nf, err);
        timer_end(t);
        if (res != VR_OK)
            return res;
    }

    vr_program_key key;
    program_key(F, n, &key);
    const vr_buffer *buf = F->buf;
    const vr_program *p = NULL;
    vr_result res = get_program(
        r, &key, buf ? buf->ks : NULL,
        buf && !F->scratch && !F->summed && buf->kind == VR_BUF_CPCA ? buf->cpca_unpack : NULL, &p,
        err);
    if (res != VR_OK)
        return res;

    int t = timer_begin(r, F->slot, 1, g);
    pass_state(r, g);
    set_uniforms(F, p, g, group, n);
    bind_textures(F, p, &key, n, (const float(*)[2])nf);
    glBindVertexArray(buf ? buf->vao : s->vao[F->order]);
    if (d->points)
        glDrawArrays(GL_POINTS, 0, (GLsizei)s->vertex_count);
    else
        glDrawElements(GL_TRIANGLES, (GLsizei)(3 * s->triangle_count), GL_UNSIGNED_INT, NULL);
    timer_end(t);
    return VR_OK;
}

/* VR_SUMS_COMPUTE: mark the vertices view vp uses (vr_cull) in the
 * renderer's seen buffer, grown to the scene (zeros) as needed; *frame:
 * the mark. */
static vr_result frame_cull(vr_renderer *r, const vr_scene *s, const float vp[16], uint32_t *frame,
                            vr_error *err)
{
    if (!r->cull.prog) {
        vr_result res = vr_cull_make(&r->cull, err);
        if (res != VR_OK)
            return res;
    }
    /* grown, or the mark about to wrap to 0: every mark zero again */
    if (s->vertex_count > r->seen_cap || r->seen_frame == UINT32_MAX) {
        uint32_t n = s->vertex_count > r->seen_cap ? s->vertex_count : r->seen_cap;
        uint32_t *zero = calloc(n, sizeof *zero);
        if (!zero)
            return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "vr_draw: out of memory");
        if (!r->seen_buf)
            glGenBuffers(1, &r->seen_buf);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, r->seen_buf);
        glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)((size_t)n * sizeof *zero), zero,
                     GL_DYNAMIC_COPY);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
        free(zero);
        vr_result res = vr_check_gl(err, "vr_draw: the sums' cull storage");
        if (res != VR_OK)
            return res;
        r->seen_cap = n;
        r->seen_frame = 0;
    }
    *frame = ++r->seen_frame;
    vr_cull(s, &r->cull, r->seen_buf, vp, *frame);
    return VR_OK;
}

/* VR_SUMS_COMPUTE: the frame's sums toward all its lights
 * (vr_buffer_sums) at the vertices view vp uses (frame_cull), into the
 * renderer's storage, grown as needed. */
static vr_result frame_sums(vr_renderer *r, const vr_scene *s, vr_buffer *b, const vr_draw_desc *d,
                            const float vp[16], vr_error *err)
{
    size_t need = (size_t)s->vertex_count * (size_t)d->light_count;
    if (need > r->sums_cap) {
        GLint max_texels = 0;
        glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_texels);
        if (need > (size_t)max_texels)
            return vr_fail(err, VR_ERR_GL,
                           "vr_draw: sums of %u vertices toward %d lights: %zu texels, above "
                           "this GL's GL_MAX_TEXTURE_BUFFER_SIZE (%d); draw fewer lights",
                           s->vertex_count, d->light_count, need, (int)max_texels);
        if (!r->sums_buf) {
            glGenBuffers(1, &r->sums_lights);
            glGenBuffers(1, &r->sums_buf);
            glGenTextures(1, &r->sums_tex);
        }
        glBindBuffer(GL_TEXTURE_BUFFER, r->sums_buf);
        glBufferData(GL_TEXTURE_BUFFER, (GLsizeiptr)(need * sizeof(float)), NULL, GL_DYNAMIC_COPY);
        glBindTexture(GL_TEXTURE_BUFFER, r->sums_tex);
        glTexBuffer(GL_TEXTURE_BUFFER, GL_R32F, r->sums_buf);
        glBindTexture(GL_TEXTURE_BUFFER, 0);
        glBindBuffer(GL_TEXTURE_BUFFER, 0);
        vr_result res = vr_check_gl(err, "vr_draw: the sums' storage");
        if (res != VR_OK)
            return res;
        r->sums_cap = need;
    }
    /* the positions: the storage and its copy grown, then rewritten */
    int n = d->light_count;
    size_t pos_bytes = (size_t)n * sizeof *r->sums_pos;
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, r->sums_lights);
    if (n > r->sums_pos_cap) {
        float(*pos)[4] = realloc(r->sums_pos, pos_bytes);
        if (!pos) {
            glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
            return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "vr_draw: out of memory");
        }
        r->sums_pos = pos;
        r->sums_pos_cap = n;
        glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)pos_bytes, NULL, GL_DYNAMIC_DRAW);
    }
    for (int i = 0; i < n; i++) {
        memcpy(r->sums_pos[i], d->lights[i].position, sizeof d->lights[i].position);
        r->sums_pos[i][3] = 1.0f;
    }
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)pos_bytes, r->sums_pos);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
    uint32_t frame = 0;
    vr_result res = frame_cull(r, s, vp, &frame, err);
    if (res == VR_OK)
        res = vr_buffer_sums(s, b, r->sums_lights, r->sums_buf, n, r->seen_buf, frame, err);
    return res;
}

/* Leave the state as the next user expects it. */
static void restore_state(const vr_renderer *r)
{
    for (int i = 0; i < r->per_pass; i++)
        glBindSampler(VR_UNIT_SHADOW + (GLuint)i, 0);
    glBindVertexArray(0);
    glUseProgram(0);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    glDisable(GL_BLEND);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

vr_result vr_draw(vr_renderer *r, const vr_scene *s, const vr_draw_desc *desc, vr_error *err)
{
    if (!r || !s || !desc)
        return vr_fail(err, VR_ERR_ARGUMENT, "vr_draw: NULL renderer, scene or descriptor");
    vr_draw_desc d = *desc;
    draw_defaults(s, &d);
    draw_frame F = {.r = r, .s = s, .d = &d};
    vr_result res = check_draw_desc(&d, err);
    if (res == VR_OK)
        res = check_mode(s, &d, &F.buf, err);
    if (res != VR_OK)
        return res;
    F.order = vr_mode_order(d.mode);
    F.slot = begin_frame(r);
    camera_matrix(r, s, &d.camera, F.vp);

    int per = r->per_pass;
    int groups = d.light_count > 0 ? (d.light_count + per - 1) / per : 1;
    if (d.output != VR_OUTPUT_COLOR)
        groups = 1;
    F.slot->groups = groups;
    clear_target(r, &d);

    /* A cpca stream decoded into its scratch, which the sums or the
     * passes read as f32 records: once per frame (vr_buffer_decode), or
     * once at load (VR_CPCA_AT_LOAD, vr_buffer_upload). */
    F.scratch = F.buf && F.buf->scratch_tex;
    /* Sums in a compute shader: once for all the frame's lights. */
    F.summed = F.buf && F.buf->summed && d.light_count > 0;
    /* both counted as the first group's lighting in the timings */
    int t = F.scratch || F.summed ? timer_begin(r, F.slot, 1, 0) : 0;
    if (F.scratch && F.buf->decode_prog)
        vr_buffer_decode(s, F.buf);
    if (F.summed)
        /* the sums programs are built as the frames need them: a cache
         * in the scene's buffer, not a change to what it draws */
        res = frame_sums(r, s, (vr_buffer *)F.buf, &d, F.vp, err);
    timer_end(t);

    for (int g = 0; g < groups && res == VR_OK; g++)
        res = draw_pass(&F, g, err);
    restore_state(r);
    if (res == VR_OK)
        res = vr_check_gl(err, "vr_draw");
    return res;
}

/* Whether the context has the pipeline statistics queries: GL 4.6, or
 * ARB_pipeline_statistics_query. */
static int has_pipeline_statistics(void)
{
    static const char *const ext[1] = {"GL_ARB_pipeline_statistics_query"};
    return vr_gl_has(4, 6, ext, 1);
}

vr_result vr_draw_counted(vr_renderer *r, const vr_scene *s, const vr_draw_desc *d, vr_counts *out,
                          vr_error *err)
{
    static const GLenum targets[6] = {GL_SAMPLES_PASSED,
                                      GL_PRIMITIVES_GENERATED,
                                      GL_VERTICES_SUBMITTED,
                                      GL_VERTEX_SHADER_INVOCATIONS,
                                      GL_FRAGMENT_SHADER_INVOCATIONS,
                                      GL_CLIPPING_INPUT_PRIMITIVES};
    if (!r || !s || !d || !out)
        return vr_fail(err, VR_ERR_ARGUMENT, "vr_draw_counted: NULL argument");
    memset(out, 0, sizeof *out);
    out->statistics = has_pipeline_statistics();
    int n = out->statistics ? 6 : 2;
    GLuint q[6] = {0};
    glGenQueries(n, q);
    for (int i = 0; i < n; i++)
        glBeginQuery(targets[i], q[i]);
    vr_result res = vr_draw(r, s, d, err);
    for (int i = 0; i < n; i++)
        glEndQuery(targets[i]);
    glFinish();
    uint64_t v[6] = {0};
    for (int i = 0; i < n; i++)
        glGetQueryObjectui64v(q[i], GL_QUERY_RESULT, &v[i]);
    glDeleteQueries(n, q);
    out->samples_passed = v[0];
    out->primitives_generated = v[1];
    out->vertices_submitted = v[2];
    out->vertex_invocations = v[3];
    out->fragment_invocations = v[4];
    out->clipping_primitives = v[5];
    if (res == VR_OK)
        res = vr_check_gl(err, "vr_draw_counted");
    return res;
}

/* ------------------------------------------------------------------ */
/* Results                                                              */

/* Read a w x h area of framebuffer fbo, top row first. */
static vr_result read_framebuffer(GLuint fbo, GLenum buffer, int w, int h, int floats, void *dst,
                                  size_t size, vr_error *err)
{
    size_t px = floats ? 16 : 4;
    size_t row = (size_t)w * px, need = row * (size_t)h;
    if (!dst || w < 1 || h < 1 || size < need)
        return vr_fail(err, VR_ERR_ARGUMENT, "read pixels: buffer of %zu bytes, need %zu", size,
                       need);
    unsigned char *tmp = malloc(row);
    if (!tmp)
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "read pixels: out of memory");
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glReadBuffer(buffer);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, w, h, GL_RGBA, floats ? GL_FLOAT : GL_UNSIGNED_BYTE, dst);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    /* GL's first row is the bottom one; images start at the top. */
    unsigned char *p = dst;
    for (int y = 0; y < h / 2; y++) {
        unsigned char *a = p + (size_t)y * row, *b = p + (size_t)(h - 1 - y) * row;
        memcpy(tmp, a, row);
        memcpy(a, b, row);
        memcpy(b, tmp, row);
    }
    free(tmp);
    return vr_check_gl(err, "read pixels");
}

vr_result vr_read_pixels(vr_renderer *r, void *dst, size_t size, vr_error *err)
{
    return read_framebuffer(r->fbo, GL_COLOR_ATTACHMENT0, r->width, r->height,
                            r->color_format == VR_COLOR_RGBA32F, dst, size, err);
}

vr_result vr_read_window(int width, int height, void *dst, size_t size, vr_error *err)
{
    return read_framebuffer(0, GL_BACK, width, height, 0, dst, size, err);
}

void vr_renderer_blit(vr_renderer *r, unsigned dst, int dst_width, int dst_height)
{
    glBindFramebuffer(GL_READ_FRAMEBUFFER, r->fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, dst);
    int same = dst_width == r->width && dst_height == r->height;
    glBlitFramebuffer(0, 0, r->width, r->height, 0, 0, dst_width, dst_height, GL_COLOR_BUFFER_BIT,
                      same ? GL_NEAREST : GL_LINEAR);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

vr_result vr_draw_text(vr_renderer *r, int x, int y, float scale, const float color[4],
                       const char *text, vr_error *err)
{
    if (!r || !text)
        return vr_fail(err, VR_ERR_ARGUMENT, "vr_draw_text: NULL argument");
    return vr_text_draw_impl(&r->text, r->fbo, r->width, r->height, x, y, scale, color, text, err);
}
