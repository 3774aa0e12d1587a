/*
 * vdsh_view_frames.c - vdsh-view --views VIEWS.json --frames DIR: per view,
 * light set and light the shadow factor of that light alone as a 16-bit
 * grey PNG, per set the shaded picture, in every mode asked for; frames
 * to score against ray-traced truth (vdsh-frames score).
 */
#include "vdsh_view.h"

#include "vt_image.h"
#include "vt_views.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

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

/* A draw of mode m from cam: vv_base_desc with m's mode, stream and PCF. */
static vr_draw_desc frame_desc(const vv_options *o, const vv_mode *m, const vr_camera *cam,
                               const vr_light *lights, int n)
{
    vr_draw_desc d = vv_base_desc(o, lights, n);
    d.mode = m->mode;
    d.stream = m->stream;
    d.pcf = m->pcf;
    d.camera = *cam;
    return d;
}

/* One shadow-only frame: light alone, s of every pixel (1 where nothing
 * was drawn: VR_OUTPUT_SHADOW writes alpha 1, the clear colour 0). */
static vr_result shadow_frame(vr_renderer *r, const vr_scene *scene, const vv_options *o,
                              const vv_mode *m, const vr_camera *cam, const float pos[3],
                              float *rgba, float *grey, size_t n, vr_error *err)
{
    vr_light light;
    memset(&light, 0, sizeof light);
    memcpy(light.position, pos, sizeof light.position);
    vr_draw_desc d = frame_desc(o, m, cam, &light, 1);
    d.output = VR_OUTPUT_SHADOW; /* no ambient term, no shading */
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
static vr_result shaded_frame(vr_renderer *r, const vr_scene *scene, const vv_options *o,
                              const vv_mode *m, const vr_camera *cam, const vt_view *v, int set,
                              unsigned char *px, size_t n, vr_error *err)
{
    vr_light lights[VT_VIEWS_MAX_LIGHTS];
    int nl = v->light_count[set];
    float fall = 0.3f * vv_scene_diagonal(scene);
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
    vr_draw_desc d = frame_desc(o, m, cam, lights, nl);
    vr_result res = vr_draw(r, scene, &d, err);
    if (res == VR_OK)
        res = vr_read_pixels(r, px, n * 4, err);
    if (res == VR_OK)
        for (size_t i = 0; i < n; i++)
            px[4 * i + 3] = 255;
    return res;
}

/* The modes: those asked for (each must be in the scene), else every
 * shadow mode the scene has. Returns 0, or 1 with the message printed. */
static int choose_modes(const vv_options *o, const vr_scene *scene, int modes[VV_MAX_MODES],
                        int *nm)
{
    int rc = 0;
    *nm = 0;
    if (o->frame_mode_count) {
        for (int i = 0; i < o->frame_mode_count && !rc; i++) {
            const vv_mode *m = &vv_modes[o->frame_modes[i]];
            if (!vv_mode_available(scene, m)) {
                fprintf(stderr, "vdsh-view: %s: mode %s is not available in this file%s\n",
                        o->files[0], m->name,
                        m->mode == VR_MODE_VDSH5 ? " (order 5 with its basis cubemaps)" : "");
                rc = 1;
            }
            modes[(*nm)++] = o->frame_modes[i];
        }
    } else {
        for (int i = 0; vv_modes[i].name; i++)
            if ((vv_modes[i].flags & VV_MODE_FRAMES_DEFAULT) &&
                vv_mode_available(scene, &vv_modes[i]))
                modes[(*nm)++] = i;
    }
    return rc;
}

/* What every frame of the run shares. */
typedef struct frames_run {
    const vv_options *o;
    const vt_views *vs;
    const vv_session *s;
    /* The shadow frames' target (RGBA32F); shaded pictures use s->r. */
    vr_renderer *rf;
    int w, h;
    size_t n;
    /* A shadow frame read back and its grey values; a shaded picture. */
    float *rgba, *grey;
    unsigned char *px;
    /* Frames in all and written so far, for the progress lines. */
    int total, done;
} frames_run;

/* One mode's times: the first frame's (it compiles the program), the
 * others' draw and read-back, and the PNGs'. */
typedef struct mode_times {
    double first_ms, mode_ms, png_ms;
    int frames;
} mode_times;

/* The shadow frame of light j of set k, written as a 16-bit grey PNG. */
static int write_shadow_frame(frames_run *F, const vv_mode *m, const vt_view *view,
                              const vr_camera *cam, int k, int j, mode_times *t)
{
    const vv_options *o = F->o;
    char path[4096], msg[1024];
    vr_error err;
    if (vt_frame_path(path, sizeof path, o->frames_dir, view->name, k, j, m->name)) {
        fprintf(stderr, "vdsh-view: %s: frame path too long\n", o->frames_dir);
        return 1;
    }
    double t0 = vv_now_ms();
    if (shadow_frame(F->rf, F->s->scene, o, m, cam, view->lights[k][j], F->rgba, F->grey, F->n,
                     &err) != VR_OK) {
        fprintf(stderr, "vdsh-view: %s: %s: %s\n", o->files[0], path, err.msg);
        return 1;
    }
    double ms = vv_now_ms() - t0;
    if (t->frames++ == 0)
        t->first_ms = ms;
    else
        t->mode_ms += ms;
    F->done++;
    double t1 = vv_now_ms();
    if (vt_png16_write(path, F->w, F->h, F->grey, msg, sizeof msg) != 0) {
        fprintf(stderr, "vdsh-view: %s\n", msg);
        return 1;
    }
    double wms = vv_now_ms() - t1;
    t->png_ms += wms;
    if (!o->quiet)
        fprintf(stderr, "vdsh-view: [%d/%d] %s  %.1f ms (PNG %.1f ms)\n", F->done, F->total, path,
                ms, wms);
    return 0;
}

/* The shaded picture of set k, written as an RGBA PNG. */
static int write_shaded_frame(frames_run *F, const vv_mode *m, const vt_view *view,
                              const vr_camera *cam, int k)
{
    const vv_options *o = F->o;
    char path[4096], msg[1024];
    vr_error err;
    if (vt_shaded_path(path, sizeof path, o->frames_dir, view->name, k, m->name)) {
        fprintf(stderr, "vdsh-view: %s: frame path too long\n", o->frames_dir);
        return 1;
    }
    if (shaded_frame(F->s->r, F->s->scene, o, m, cam, view, k, F->px, F->n, &err) != VR_OK) {
        fprintf(stderr, "vdsh-view: %s: %s: %s\n", o->files[0], path, err.msg);
        return 1;
    }
    if (vt_png_rgba_write(path, F->w, F->h, F->px, msg, sizeof msg) != 0) {
        fprintf(stderr, "vdsh-view: %s\n", msg);
        return 1;
    }
    return 0;
}

/* Every frame of mode m (one program, its shadow maps re-rendered per
 * frame), then a line with its times: a frame's is its draw and
 * read-back, without the PNG. */
static int render_mode(frames_run *F, const vv_mode *m)
{
    const vv_options *o = F->o;
    mode_times t = {0};
    for (int v = 0; v < F->vs->count; v++) {
        const vt_view *view = &F->vs->views[v];
        vr_camera cam;
        view_camera(view, &cam);
        for (int k = 0; k < view->set_count; k++) {
            for (int j = 0; j < view->light_count[k]; j++)
                if (write_shadow_frame(F, m, view, &cam, k, j, &t))
                    return 1;
            if (write_shaded_frame(F, m, view, &cam, k))
                return 1;
        }
    }
    /* The first frame of a mode compiles its program. */
    if (!o->quiet && t.frames > 1)
        fprintf(stderr,
                "vdsh-view: mode %s: %d frames of %dx%d, %.1f ms per frame after "
                "the first (%.1f ms: compiling), draw and read-back; PNG %.1f ms per "
                "frame\n",
                m->name, t.frames, F->w, F->h, t.mode_ms / (t.frames - 1), t.first_ms,
                t.png_ms / t.frames);
    else if (!o->quiet && t.frames == 1)
        fprintf(stderr, "vdsh-view: mode %s: 1 frame of %dx%d, %.1f ms (with compiling)\n", m->name,
                F->w, F->h, t.first_ms);
    return 0;
}

int vv_run_frames(const vv_options *o)
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
    vv_session s;
    vr_renderer *rf = NULL;
    vr_error err;
    if (vv_session_open(o, VR_CONTEXT_HEADLESS, w, h, &s)) {
        vt_views_free(&vs);
        return 1;
    }
    int rc = 0;
    vr_renderer_desc rd = {.width = w,
                           .height = h,
                           .color_format = VR_COLOR_RGBA32F,
                           .shadow_map_size = o->shadow_size};
    if (vr_renderer_create(&rd, &rf, &err) != VR_OK) {
        fprintf(stderr, "vdsh-view: %s\n", err.msg);
        rc = 1;
    }
    int modes[VV_MAX_MODES], nm = 0;
    if (!rc)
        rc = choose_modes(o, s.scene, modes, &nm);

    frames_run F = {.o = o, .vs = &vs, .s = &s, .rf = rf, .w = w, .h = h, .n = n};
    F.rgba = malloc(n * 4 * sizeof(float));
    F.grey = malloc(n * sizeof(float));
    F.px = malloc(n * 4);
    if (!rc && (!F.rgba || !F.grey || !F.px)) {
        fprintf(stderr, "vdsh-view: out of memory (%dx%d frames)\n", w, h);
        rc = 1;
    }
    for (int v = 0; v < vs.count; v++)
        for (int k = 0; k < vs.views[v].set_count; k++)
            F.total += vs.views[v].light_count[k];
    F.total *= nm;
    if (!rc && !o->quiet)
        fprintf(stderr,
                "vdsh-view: %s: %d view%s of %s, %d shadow frames of %dx%d in %d "
                "mode%s, into %s (%s)\n",
                o->files[0], vs.count, vs.count == 1 ? "" : "s", o->views_path, F.total, w, h, nm,
                nm == 1 ? "" : "s", o->frames_dir, vr_gl_renderer());
    for (int mi = 0; mi < nm && !rc; mi++)
        rc = render_mode(&F, &vv_modes[modes[mi]]);
    free(F.rgba);
    free(F.grey);
    free(F.px);
    vr_renderer_destroy(rf);
    vv_session_close(&s);
    vt_views_free(&vs);
    return rc;
}
