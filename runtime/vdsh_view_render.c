/*
 * vdsh_view_render.c - vdsh-view --render (one image) and --grid (the
 * paper's comparison row and an adaptive-order column, one row per
 * scene), headless.
 */
#include "vdsh_sdf.h"
#include "vdsh_view.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int vv_run_render(const vv_options *o)
{
    int w = o->have_size ? o->width : VR_DEFAULT_WIDTH;
    int h = o->have_size ? o->height : VR_DEFAULT_HEIGHT;
    vv_session s;
    if (vv_session_open(o, VR_CONTEXT_HEADLESS, w, h, &s))
        return 1;
    vr_light lights[VV_MAX_LIGHTS];
    int n = vv_scene_lights(s.scene, o, o->default_lights ? o->default_lights : 1, lights);
    vr_draw_desc d = vv_base_desc(o, lights, n);
    vv_scene_camera(s.scene, o, &d.camera);
    vr_error err;
    int rc = 1;
    unsigned char *px = malloc((size_t)w * (size_t)h * 4);
    double t0 = vv_now_ms();
    if (!px)
        fprintf(stderr, "vdsh-view: out of memory\n");
    else if (vr_draw(s.r, s.scene, &d, &err) != VR_OK ||
             vr_read_pixels(s.r, px, (size_t)w * (size_t)h * 4, &err) != VR_OK)
        fprintf(stderr, "vdsh-view: %s: %s\n", o->files[0], err.msg);
    else {
        double ms = vv_now_ms() - t0;
        rc = vv_write_png(o->render_path, w, h, px);
        char label[160];
        vv_mode_label(s.scene, o->mode, o->stream, label, sizeof label);
        if (!rc && !o->quiet)
            fprintf(stderr,
                    "vdsh-view: wrote %s (%dx%d, mode %s: %s, %d light%s, %.0f ms, %s; "
                    "%s)\n",
                    o->render_path, w, h,
                    vr_mode_name(o->mode ? o->mode : vr_scene_default_mode(s.scene)), label, n,
                    n == 1 ? "" : "s", ms, vr_gl_renderer(), vr_context_description(s.ctx));
    }
    free(px);
    vv_session_close(&s);
    return rc;
}

/* What a scene's file holds, for a row label: "room.vdsh: paper bake,
 * distance" (the method of its highest fixed order, else of its stream
 * with an order per vertex). */
static void bake_label(const char *path, const vr_scene *s, char *out, size_t size)
{
    vr_scene_info info;
    vr_scene_get_info(s, &info);
    const char *slash = strrchr(path, '/');
    uint32_t method = info.variable_method;
    for (int k = 1; k <= VDSH_MAX_ORDER; k++)
        if (info.has_order[k] || info.has_buffer[k])
            method = info.method[k];
    snprintf(out, size, "%s: %s bake, %s", slash ? slash + 1 : path, vdsh_method_name(method),
             vdsh_quantity_name(info.quantity));
}

/* The grid's columns (vv_mode.grid): the paper's row (an order the file
 * holds only as a buffer, a cpca stream, drawn from it), then the file's
 * highest fixed stream of another order (1, 4, above 5: drawn from its
 * buffer), adaptive order (kept only when some scene has a stream with an
 * order per vertex), then distance-field shadows (kept only when some
 * scene has a volume); the buffer column is kept only when some scene
 * has such a stream. The summary line describes the first VDSH column
 * the file has (summary_mode). */
enum { GRID_MAX_COLS = 16, GRID_PAPER_COLS = 5, GRID_ORDER5_COL = 3, GRID_BUFFER_COL = 6 };

/* The number of columns: the highest vv_mode.grid. */
static int grid_columns(void)
{
    int n = 0;
    for (int i = 0; vv_modes[i].name; i++)
        n = vv_modes[i].grid > n ? vv_modes[i].grid : n;
    return n < GRID_MAX_COLS ? n : GRID_MAX_COLS;
}

/* The bufK mode (the order-K stream from its buffer); NULL if none. */
static const vv_mode *buf_mode(int k)
{
    for (int i = 0; vv_modes[i].name; i++)
        if (vv_modes[i].mode == VR_MODE_VDSH_BUFFER && vv_modes[i].stream == k)
            return &vv_modes[i];
    return NULL;
}

/* Whether the scene has the grid mode m: the buffer column's own entry
 * ("buffer", stream 0: any stream) stands for none. */
static int grid_has(const vr_scene *s, const vv_mode *m)
{
    return !(m->mode == VR_MODE_VDSH_BUFFER && m->stream == 0) && vv_mode_available(s, m);
}

/* The mode of column c (1..) for this scene: the first of its rows the
 * scene has; else, in a VDSH order column, that order's buffer (a cpca
 * stream); in the buffer column, the highest fixed order that neither
 * the paper's columns (2, 3, 5) draw; else the last row. Order 5 the
 * paper's way when the cubemaps are there, else with the polynomials (the
 * same image to f16 precision); a log-distance scene draws both per
 * vertex. */
static const vv_mode *grid_mode(const vr_scene *s, int c)
{
    const vv_mode *last = NULL;
    for (int i = 0; vv_modes[i].name; i++)
        if (vv_modes[i].grid == c) {
            if (grid_has(s, &vv_modes[i]))
                return &vv_modes[i];
            last = &vv_modes[i];
        }
    if (!last)
        return NULL;
    int order = last->mode == VR_MODE_VDSH2                                       ? 2
                : last->mode == VR_MODE_VDSH3                                     ? 3
                : last->mode == VR_MODE_VDSH5 || last->mode == VR_MODE_VDSH5_POLY ? 5
                                                                                  : 0;
    const vv_mode *b = order ? buf_mode(order) : NULL;
    if (b && grid_has(s, b))
        return b;
    for (int k = VDSH_MAX_ORDER; c == GRID_BUFFER_COL && k >= 1; k--)
        if (k != 2 && k != 3 && k != 5 && (b = buf_mode(k)) && grid_has(s, b))
            return b;
    return last;
}

/* The mode the grid's summary line describes: the first of the VDSH
 * columns (orders 5, 3, 2, the buffer column) the file has; else its
 * adaptive stream's, with that stream's method, as bake_label names it. */
static void summary_mode(const vr_scene *s, char *out, size_t size)
{
    for (int c = GRID_ORDER5_COL; c <= GRID_BUFFER_COL; c++) {
        const vv_mode *m = grid_mode(s, c);
        if (grid_has(s, m)) {
            vv_mode_label(s, m->mode, m->stream, out, size);
            return;
        }
    }
    vr_scene_info info;
    vr_scene_get_info(s, &info);
    char label[160];
    vv_mode_label(s, VR_MODE_VDSH_BUFFER, VR_STREAM_VARIABLE, label, sizeof label);
    if (info.variable_order)
        snprintf(out, size, "%s, %s", label, vdsh_method_name(info.variable_method));
    else
        snprintf(out, size, "no VDSH stream");
}

/* One row of the grid: the panels of one scene into row (cols panels w
 * wide); have[c]: 1 when the scene has column c's mode. */
static int grid_row(const vv_options *o, const char *path, vr_renderer *r, int w, int h, int cols,
                    unsigned char *px, unsigned char *row, int *have)
{
    vr_scene *scene = NULL;
    if (vv_open_scene(o, path, &scene))
        return 1;
    vr_light lights[VV_MAX_LIGHTS];
    int n = vv_scene_lights(scene, o, o->default_lights ? o->default_lights : 1, lights);
    size_t panel = (size_t)w * (size_t)h * 4;
    int rc = 0;
    char names[256] = "", bake[256];
    bake_label(path, scene, bake, sizeof bake);
    for (int m = 0; m < cols && !rc; m++) {
        const vv_mode *e = grid_mode(scene, m + 1);
        vr_error err;
        vr_draw_desc d = vv_base_desc(o, lights, n);
        d.mode = e->mode;
        d.stream = e->stream;
        vv_scene_camera(scene, o, &d.camera);
        char label[320];
        int shadow = o->shadow_size ? o->shadow_size : VR_DEFAULT_SHADOW_MAP_SIZE;
        have[m] = grid_has(scene, e);
        if (m < GRID_PAPER_COLS || have[m])
            snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", m ? " | " : "",
                     e->name);
        if (e->mode == VR_MODE_CUBE)
            snprintf(label, sizeof label, "cube shadow map (%d^2 x 6, %s)", shadow,
                     o->pcf ? "PCF" : "1 tap");
        else if (e->mode == VR_MODE_VDSH_BUFFER && !have[m])
            snprintf(label, sizeof label, "%s",
                     e->stream == VR_STREAM_VARIABLE ? "VDSH adaptive order"
                                                     : "VDSH order 1, 4 or above 5");
        else if (e->mode == VR_MODE_SDF)
            snprintf(label, sizeof label, "%s, k %g", vr_mode_label(VR_MODE_SDF),
                     (double)(o->sdf_k > 0.0f ? o->sdf_k : VDSH_SDF_DEFAULT_K));
        else if (e->mode >= VR_MODE_VDSH2) {
            vv_mode_label(scene, e->mode, e->stream, label, sizeof label);
            snprintf(label + strlen(label), sizeof label - strlen(label), "%s",
                     o->compare == VDSH_COMPARE_BINARY ? ", binary" : "");
        } else {
            snprintf(label, sizeof label, "%s\n%s", vr_mode_label(e->mode), bake);
        }
        vr_result res = VR_OK;
        if (!have[m]) {
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
            fprintf(stderr, "vdsh-view: %s: %s: %s\n", path, vr_mode_name(e->mode), err.msg);
            rc = 1;
            break;
        }
        for (int y = 0; y < h; y++)
            memcpy(row + ((size_t)y * (size_t)cols * (size_t)w + (size_t)m * (size_t)w) * 4,
                   px + (size_t)y * (size_t)w * 4, (size_t)w * 4);
    }
    if (!rc && !o->quiet) {
        char mode[256];
        summary_mode(scene, mode, sizeof mode);
        fprintf(stderr, "vdsh-view: %s: %s (%s), %d light%s\n", bake, names, mode, n,
                n == 1 ? "" : "s");
    }
    vr_scene_destroy(scene);
    return rc;
}

int vv_run_grid(const vv_options *o)
{
    int w = o->have_size ? o->width : 512, h = o->have_size ? o->height : 384;
    int rows = o->file_count;
    vr_context *ctx = NULL;
    vr_renderer *r = NULL;
    if (vv_open_headless(o, w, h, 1, &ctx, &r) != 0)
        return 1;
    size_t panel = (size_t)w * (size_t)h * 4;
    int all = grid_columns();
    unsigned char *px = malloc(panel), *img = calloc((size_t)all * (size_t)rows, panel);
    int rc = 0, cols = 0, keep[GRID_MAX_COLS] = {0};
    for (int m = 0; m < GRID_PAPER_COLS; m++)
        keep[m] = 1;
    if (!px || !img) {
        fprintf(stderr, "vdsh-view: out of memory\n");
        rc = 1;
    }
    for (int i = 0; i < rows && !rc; i++) {
        int have[GRID_MAX_COLS] = {0};
        rc =
            grid_row(o, o->files[i], r, w, h, all, px, img + (size_t)i * (size_t)all * panel, have);
        for (int m = GRID_PAPER_COLS; m < all; m++)
            keep[m] |= have[m];
    }
    for (int m = 0; m < all; m++)
        cols += keep[m];
    if (!rc) {
        /* Keep the kept panels of each row, in order (in place: the
         * rows only shrink), with a thin dark line between panels and
         * rows. */
        size_t wide = (size_t)all * (size_t)w * 4, stride = (size_t)cols * (size_t)w * 4;
        size_t pw = (size_t)w * 4;
        for (int y = 0; y < rows * h; y++)
            for (int m = 0, c = 0; m < all; m++)
                if (keep[m])
                    memmove(img + (size_t)y * stride + (size_t)c++ * pw,
                            img + (size_t)y * wide + (size_t)m * pw, pw);
        for (int y = 0; y < rows * h; y++)
            for (int m = 1; m < cols; m++)
                memset(img + (size_t)y * stride + (size_t)m * (size_t)w * 4, 40, 4);
        for (int i = 1; i < rows; i++)
            memset(img + (size_t)i * (size_t)h * stride, 40, stride);
        rc = vv_write_png(o->grid_path, cols * w, rows * h, img);
        if (!rc && !o->quiet)
            fprintf(stderr, "vdsh-view: wrote %s (%dx%d, %d row%s, %s)\n", o->grid_path, cols * w,
                    rows * h, rows, rows == 1 ? "" : "s", vr_gl_renderer());
    }
    free(px);
    free(img);
    vr_renderer_destroy(r);
    vr_context_destroy(ctx);
    return rc;
}
