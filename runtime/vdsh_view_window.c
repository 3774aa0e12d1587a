/*
 * vdsh_view_window.c - vdsh-view in a window (GLFW): orbit and fly the
 * camera, add, move and animate lights, switch modes, the text overlay,
 * screenshots; --keys scripts the keys for demos and tests. Without GLFW
 * at build time, a message saying so.
 */
#include "vdsh_view.h"

#ifdef VR_HAVE_GLFW
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef VR_HAVE_GLFW
static const char keys_text[] =
    "vdsh-view keys:\n"
    "  mouse left drag   orbit around the target     right drag   look around\n"
    "  wheel             closer / farther            W A S D Q E  fly (shift: faster)\n"
    "  1 2 3 4 5 6 7     mode: none, cube shadow map, VDSH order 2, 3, 5 (cubemaps),\n"
    "                    5 (polynomials), buffer (adaptive order, else the highest)\n"
    "                                                   M  next mode\n"
    "  C                 comparison smooth / binary   P  cube map PCF on / off\n"
    "  Tab               select the next light        N  new light at the target\n"
    "  arrows, PgUp/PgDn move the selected light      Backspace  remove it\n"
    "  Space             animate the lights           F  fire a short-lived light\n"
    "  R                 reset the view               X  save a screenshot (PNG)\n"
    "  O                 overlay on / off             H  this list\n"
    "  Esc               quit\n";

typedef struct app {
    const vv_options *o;
    vv_session s;
    vr_light base[VV_MAX_LIGHTS]; /* user lights before animation */
    int n;
    int selected;
    float target[3], yaw, pitch, dist, diag;
    vr_camera home;
    int animate;
    double anim_t;
    int fired; /* a short-lived light is alive */
    float fired_pos[3], fired_vel[3];
    double fired_age;
    vr_mode mode;
    int stream; /* VR_MODE_VDSH_BUFFER's */
    vdsh_compare compare;
    int pcf, overlay;
    double mx, my;
    int drag; /* 1 left (orbit), 2 right (look) */
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
    /* The modes with a digit key (vv_mode.key), in the order M steps
     * through them. */
    const vv_mode *keyed[10];
    int nk = 0, at = 0;
    for (int i = 0; vv_modes[i].name && nk < 10; i++)
        if (vv_modes[i].key) {
            if (vv_modes[i].mode == a->mode)
                at = nk;
            keyed[nk++] = &vv_modes[i];
        }
    for (int i = 0; i < nk; i++)
        if (key == GLFW_KEY_0 + (keyed[i]->key - '0')) {
            vr_mode m = keyed[i]->mode;
            if (!vr_scene_supports(a->s.scene, m)) {
                snprintf(msg, sizeof msg, "mode %s: not available in this file", vr_mode_name(m));
                print_status(a, msg);
                return;
            }
            a->mode = m;
            char label[160];
            vv_mode_label(a->s.scene, m, a->stream, label, sizeof label);
            snprintf(msg, sizeof msg, "mode: %s", label);
            print_status(a, msg);
            return;
        }
    switch (key) {
    case GLFW_KEY_ESCAPE: glfwSetWindowShouldClose(w, GLFW_TRUE); break;
    case GLFW_KEY_M:
        /* the next the scene has (after the first when this one has no key) */
        for (int i = 1; i <= nk; i++) {
            vr_mode m = keyed[(at + i) % nk]->mode;
            if (vr_scene_supports(a->s.scene, m)) {
                a->mode = m;
                break;
            }
        }
        char label[160];
        vv_mode_label(a->s.scene, a->mode, a->stream, label, sizeof label);
        snprintf(msg, sizeof msg, "mode: %s", label);
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
        if (a->n < VV_MAX_LIGHTS - 1) {
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
    case GLFW_KEY_O: a->overlay = !a->overlay; break;
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
            vv_write_png(path, fw, fh, px) == 0) {
            snprintf(msg, sizeof msg, "saved %s", path);
            print_status(a, msg);
        }
        free(px);
        break;
    }
    default: break;
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

/* Where the held keys point: keys[0]/[1] along +/-fwd, [2]/[3] along
 * +/-right, [4]/[5] up/down. */
static void held_move(GLFWwindow *w, const int keys[6], const float fwd[3], const float right[3],
                      float out[3])
{
    int held[6];
    for (int i = 0; i < 6; i++)
        held[i] = glfwGetKey(w, keys[i]) == GLFW_PRESS;
    for (int k = 0; k < 3; k++) {
        out[k] = 0.0f;
        if (held[0])
            out[k] += fwd[k];
        if (held[1])
            out[k] -= fwd[k];
        if (held[2])
            out[k] += right[k];
        if (held[3])
            out[k] -= right[k];
    }
    if (held[4])
        out[1] += 1.0f;
    if (held[5])
        out[1] -= 1.0f;
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
    static const int fly[6] = {GLFW_KEY_W, GLFW_KEY_S, GLFW_KEY_D,
                               GLFW_KEY_A, GLFW_KEY_E, GLFW_KEY_Q};
    float move[3];
    held_move(w, fly, f, right, move);
    for (int k = 0; k < 3; k++)
        a->target[k] += speed * move[k];

    if (a->n > 0) {
        static const int keys[6] = {GLFW_KEY_UP,   GLFW_KEY_DOWN,    GLFW_KEY_RIGHT,
                                    GLFW_KEY_LEFT, GLFW_KEY_PAGE_UP, GLFW_KEY_PAGE_DOWN};
        float lm[3], ls = 0.15f * a->diag * dt;
        held_move(w, keys, fh, right, lm);
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
    if (a->fired && n < VV_MAX_LIGHTS) {
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

int vv_run_window(const vv_options *o)
{
    int w = o->have_size ? o->width : VR_DEFAULT_WIDTH;
    int h = o->have_size ? o->height : VR_DEFAULT_HEIGHT;
    app a;
    memset(&a, 0, sizeof a);
    a.o = o;
    if (vv_session_open(o, VR_CONTEXT_WINDOW, w, h, &a.s)) {
        fprintf(stderr, "vdsh-view: (use --render or --grid without a display)\n");
        return 1;
    }
    GLFWwindow *win = vr_context_window(a.s.ctx);
    glfwSetWindowUserPointer(win, &a);
    glfwSetKeyCallback(win, on_key);
    glfwSetMouseButtonCallback(win, on_mouse_button);
    glfwSetCursorPosCallback(win, on_cursor);
    glfwSetScrollCallback(win, on_scroll);

    a.diag = vv_scene_diagonal(a.s.scene);
    a.n = vv_scene_lights(a.s.scene, o, o->default_lights ? o->default_lights : 1, a.base);
    vv_scene_camera(a.s.scene, o, &a.home);
    set_view(&a, &a.home);
    a.mode = o->mode;
    a.stream = o->stream;
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
    double last = vv_now_ms(), fps_t0 = last, frame_ms = 0.0;
    int fps_frames = 0;
    while (!glfwWindowShouldClose(win)) {
        glfwPollEvents();
        if (frames < keys_len) {
            char k = o->keys[frames];
            int key = k == ' '               ? GLFW_KEY_SPACE
                      : k == '>'             ? GLFW_KEY_TAB
                      : k == '<'             ? GLFW_KEY_BACKSPACE
                      : k >= '0' && k <= '9' ? GLFW_KEY_0 + (k - '0')
                                             : GLFW_KEY_A + (k - 'a');
            on_key(win, key, 0, GLFW_PRESS, 0);
        }
        double t = vv_now_ms();
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
        vr_light lights[VV_MAX_LIGHTS];
        int n = frame_lights(&a, lights);
        vr_draw_desc d = vv_base_desc(o, lights, n);
        d.mode = a.mode;
        d.stream = a.stream;
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
            char text[1024], label[160];
            vv_mode_label(a.s.scene, a.mode, a.stream, label, sizeof label);
            int len = snprintf(text, sizeof text,
                               "%s, %s\n%d light%s (selected %d)%s\n"
                               "frame %.1f ms (%.1f fps)\n"
                               "GPU: shadow maps %.1f ms, lighting %.1f ms\n%s",
                               label,
                               a.mode == VR_MODE_CUBE             ? (a.pcf ? "PCF" : "1 tap")
                               : a.compare == VDSH_COMPARE_SMOOTH ? "smooth"
                                                                  : "binary",
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
            } else if (vv_write_png(o->screenshot, fw, fh, px)) {
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
    vv_session_close(&a.s);
    return rc;
}
#else
int vv_run_window(const vv_options *o)
{
    (void)o;
    fprintf(stderr, "vdsh-view: built without GLFW: no window (use --render or --grid)\n");
    return 1;
}
#endif
