/*
 * test_runtime_frames.c - checks for vdsh-view --views VIEWS --frames DIR
 * (the runtime_view_frames test drives it) and the runtime's default view:
 *
 *   gl                 exit 77 when no headless GL context can be made
 *   names VIEWS DIR MODES
 *                      DIR holds exactly the frames of VIEWS in MODES
 *                      (comma-separated): NAME-sK-lJ-MODE.png 16-bit grey
 *                      and NAME-sK-shaded-MODE.png 8-bit RGBA, each of the
 *                      view set's size; nothing else (no temporaries)
 *   values VIEWS DIR VIEW SET LIGHT DARK LIT MODES
 *                      in frame VIEW-sSET-lLIGHT-MODE of every mode, the
 *                      scene point DARK (X,Y,Z: the light is hidden from
 *                      it) is low and LIT is 1: the median of s over a
 *                      few pixels around each (projected with the view's
 *                      vdsh_camera) <= 0.3 and >= 0.999
 *   empty VIEWS DIR SCENE VIEW MODES
 *                      in every frame of VIEW, each pixel whose primary
 *                      ray (and its neighbours') meets nothing in SCENE's
 *                      mesh is exactly 1; the view must have such pixels
 *                      and surfaces, not all of them 1
 *   facing VIEWS DIR VIEW SET LIGHT P MODES
 *                      prints s around P (a point whose surface faces away
 *                      from the light) in every mode; fails when a cube
 *                      mode is above 0.05 there (the light's own depth
 *                      map hides such a surface: s is the map's answer,
 *                      not 1 and not a Lambert term)
 *   lights SCENE       the runtime's default camera and four default
 *                      lights (vr_scene_default_camera / _lights) are
 *                      vdsh_view_compute's of the same file
 *                      (vdsh_view_file_mesh); its light pool
 *                      (vr_scene_pool_lights) holds 64 distinct
 *                      positions in free space (vdsh_view_free_space with
 *                      a tracer of the file's mesh), inside the bounds,
 *                      the first free candidates of vdsh_light_candidate
 *                      seed 1 in order; without a pool it is empty
 */
#include "test_runtime_util.h"

#include "vdsh_camera.h"
#include "vdsh_light.h"
#include "vdsh_scene_view.h"
#include "vt_image.h"
#include "vt_views.h"

#include <dirent.h>

static int parse3(const char *s, float v[3])
{
    char *end;
    for (int k = 0; k < 3; k++) {
        v[k] = strtof(s, &end);
        if (end == s || *end != (k < 2 ? ',' : '\0'))
            return -1;
        s = end + 1;
    }
    return 0;
}

/* Split "a,b,c" into at most 16 names (in buf). */
static int split_modes(const char *list, char *buf, size_t cap, char **out)
{
    snprintf(buf, cap, "%s", list);
    int n = 0;
    for (char *p = strtok(buf, ","); p && n < 16; p = strtok(NULL, ","))
        out[n++] = p;
    return n;
}

static const vt_view *find_view(const vt_views *vs, const char *name)
{
    for (int i = 0; i < vs->count; i++)
        if (!strcmp(vs->views[i].name, name))
            return &vs->views[i];
    fprintf(stderr, "no view '%s'\n", name);
    return NULL;
}

/* The PNG header: width, height, bit depth, colour type; -1 if absent. */
static int png_header(const char *path, int *w, int *h, int *depth, int *type)
{
    unsigned char b[26];
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    size_t n = fread(b, 1, sizeof b, f);
    fclose(f);
    if (n != sizeof b || memcmp(b, "\x89PNG\r\n\x1a\n", 8) || memcmp(b + 12, "IHDR", 4))
        return -1;
    *w = (b[16] << 24) | (b[17] << 16) | (b[18] << 8) | b[19];
    *h = (b[20] << 24) | (b[21] << 16) | (b[22] << 8) | b[23];
    *depth = b[24];
    *type = b[25];
    return 0;
}

static int check_names(const char *views, const char *dir, const char *modes)
{
    vt_views vs;
    char msg[512], buf[256], *mode[16];
    if (vt_views_read(views, &vs, msg, sizeof msg)) {
        fprintf(stderr, "%s\n", msg);
        return 1;
    }
    int nm = split_modes(modes, buf, sizeof buf, mode), expected = 0;
    for (int m = 0; m < nm; m++)
        for (int v = 0; v < vs.count; v++)
            for (int k = 0; k < vs.views[v].set_count; k++)
                for (int j = -1; j < vs.views[v].light_count[k]; j++) {
                    char path[1024];
                    int w, h, depth, type;
                    if (j < 0)
                        vt_shaded_path(path, sizeof path, dir, vs.views[v].name, k, mode[m]);
                    else
                        vt_frame_path(path, sizeof path, dir, vs.views[v].name, k, j, mode[m]);
                    expected++;
                    int ok = png_header(path, &w, &h, &depth, &type) == 0;
                    CHECK(ok, "%s: missing or not a PNG", path);
                    if (!ok)
                        continue;
                    CHECK(w == vs.width && h == vs.height, "%s: %dx%d, not %dx%d", path, w, h,
                          vs.width, vs.height);
                    /* grey is colour type 0, RGBA 6 */
                    if (j < 0)
                        CHECK(depth == 8 && type == 6, "%s: depth %d type %d, not 8-bit RGBA", path,
                              depth, type);
                    else
                        CHECK(depth == 16 && type == 0, "%s: depth %d type %d, not 16-bit grey",
                              path, depth, type);
                }
    int found = 0;
    DIR *d = opendir(dir);
    CHECK(d != NULL, "%s: cannot list", dir);
    for (struct dirent *e; d && (e = readdir(d));)
        if (e->d_name[0] != '.') {
            found++;
            CHECK(strstr(e->d_name, ".png") && !strstr(e->d_name, ".tmp"), "%s: unexpected file %s",
                  dir, e->d_name);
        }
    if (d)
        closedir(d);
    CHECK(found == expected, "%s: %d files, expected %d", dir, found, expected);
    printf("%s: %d frames and pictures, names and sizes as expected\n", dir, expected);
    vt_views_free(&vs);
    return test_report("names");
}

/* Pixel of scene point p in a w x h frame of camera c; -1 if behind. */
static int project(const vdsh_camera *c, int w, int h, const float p[3], int *x, int *y)
{
    float view[16], proj[16], e[4], q[4];
    vdsh_camera_view(c, view);
    vdsh_camera_projection(c, (float)w / (float)h, 0.01f, 1000.0f, proj);
    for (int r = 0; r < 4; r++)
        e[r] = view[r] * p[0] + view[4 + r] * p[1] + view[8 + r] * p[2] + view[12 + r];
    for (int r = 0; r < 4; r++)
        q[r] = proj[r] * e[0] + proj[4 + r] * e[1] + proj[8 + r] * e[2] + proj[12 + r] * e[3];
    if (!(q[3] > 0.0f))
        return -1;
    *x = (int)floorf(0.5f * (q[0] / q[3] + 1.0f) * (float)w);
    *y = (int)floorf(0.5f * (1.0f - q[1] / q[3]) * (float)h);
    return 0;
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* Min, max and median of the (2r + 1)^2 values around (x, y) (r <= 7). */
static void window(const float *v, int w, int h, int x, int y, int r, float *lo, float *hi,
                   float *median)
{
    float vals[225];
    int n = 0;
    for (int j = y - r; j <= y + r; j++)
        for (int i = x - r; i <= x + r; i++)
            if (i >= 0 && j >= 0 && i < w && j < h && n < 225)
                vals[n++] = v[(size_t)j * (size_t)w + (size_t)i];
    qsort(vals, (size_t)n, sizeof vals[0], cmp_float);
    *lo = n ? vals[0] : NAN;
    *hi = n ? vals[n - 1] : NAN;
    *median = n ? vals[n / 2] : NAN;
}

static float *read_frame(const char *dir, const vt_view *v, int set, int light, const char *mode,
                         int w, int h, char *path, size_t cap)
{
    char msg[512];
    int fw, fh;
    float *px = NULL;
    vt_frame_path(path, cap, dir, v->name, set, light, mode);
    if (vt_png16_read(path, &fw, &fh, &px, msg, sizeof msg)) {
        fprintf(stderr, "%s\n", msg);
        test_failures++;
        return NULL;
    }
    if (fw != w || fh != h) {
        fprintf(stderr, "%s: %dx%d, not %dx%d\n", path, fw, fh, w, h);
        test_failures++;
        free(px);
        return NULL;
    }
    return px;
}

static int check_values(char **argv)
{
    vt_views vs;
    char msg[512], buf[256], *mode[16];
    float dark[3], lit[3];
    int set = atoi(argv[5]), light = atoi(argv[6]);
    if (parse3(argv[7], dark) || parse3(argv[8], lit)) {
        fprintf(stderr, "values: bad point\n");
        return 2;
    }
    if (vt_views_read(argv[2], &vs, msg, sizeof msg)) {
        fprintf(stderr, "%s\n", msg);
        return 1;
    }
    const vt_view *v = find_view(&vs, argv[4]);
    int w = vs.width, h = vs.height, nm = split_modes(argv[9], buf, sizeof buf, mode);
    int r = h / 60 > 1 ? h / 60 : 1;
    for (int m = 0; v && m < nm; m++) {
        char path[1024];
        float *px = read_frame(argv[3], v, set, light, mode[m], w, h, path, sizeof path);
        if (!px)
            continue;
        const float *pts[2] = {dark, lit};
        for (int k = 0; k < 2; k++) {
            int x, y;
            if (project(&v->camera, w, h, pts[k], &x, &y) || x < r || y < r || x >= w - r ||
                y >= h - r) {
                CHECK(0, "%s point (%g, %g, %g) is not in view %s", k ? "lit" : "dark", pts[k][0],
                      pts[k][1], pts[k][2], v->name);
                continue;
            }
            float lo, hi, med;
            window(px, w, h, x, y, r, &lo, &hi, &med);
            printf("%s: %s point at pixel (%d, %d): s %.4f .. %.4f, median %.4f\n", path,
                   k ? "lit" : "shadowed", x, y, lo, hi, med);
            if (k == 0)
                CHECK(med <= 0.3f, "%s: the shadowed point is not low (median %.4f)", path, med);
            else
                CHECK(med >= 0.999f, "%s: the lit point is not 1 (median %.4f)", path, med);
        }
        free(px);
    }
    vt_views_free(&vs);
    return test_report("values");
}

static int check_empty(char **argv)
{
    vt_views vs;
    char msg[512], buf[256], *mode[16];
    if (vt_views_read(argv[2], &vs, msg, sizeof msg)) {
        fprintf(stderr, "%s\n", msg);
        return 1;
    }
    const vt_view *v = find_view(&vs, argv[5]);
    vdsh_file *f = NULL;
    vdsh_error err;
    if (!v || vdsh_read(argv[4], &f, &err)) {
        fprintf(stderr, "%s\n", v ? err.msg : "no such view");
        vt_views_free(&vs);
        return 1;
    }
    int w = vs.width, h = vs.height, nm = split_modes(argv[6], buf, sizeof buf, mode);

    /* The pixels whose primary ray meets nothing in the mesh, away from
     * its silhouette (every ray of the 3 x 3 block around misses). */
    float region[6];
    vdsh_view_mesh mesh;
    vdsh_view_file_mesh(f, region, &mesh);
    vdsh_view_tracer *tr = NULL;
    CHECK(vdsh_view_tracer_create(&mesh, &tr, &err) == VDSH_OK, "%s", err.msg);
    unsigned char *miss = calloc((size_t)w * (size_t)h, 1),
                  *empty = calloc((size_t)w * (size_t)h, 1);
    size_t empties = 0;
    for (int y = 0; tr && y < h; y++)
        for (int x = 0; x < w; x++) {
            float o[3], d[3];
            vdsh_view_hit hit;
            vdsh_camera_ray(&v->camera, w, h, x, y, o, d);
            miss[(size_t)y * (size_t)w + (size_t)x] = !vdsh_view_trace(tr, o, d, 0.0f, &hit);
        }
    for (int y = 1; y < h - 1; y++)
        for (int x = 1; x < w - 1; x++) {
            int all = 1;
            for (int j = -1; j <= 1; j++)
                for (int i = -1; i <= 1; i++)
                    all &= miss[(size_t)(y + j) * (size_t)w + (size_t)(x + i)];
            empty[(size_t)y * (size_t)w + (size_t)x] = (unsigned char)all;
            empties += (size_t)all;
        }
    size_t hits = 0;
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
        hits += !miss[i];
    CHECK(empties > 0 && hits > 0,
          "view %s: %zu of %d pixels without a surface, %zu with one: choose a view with both",
          v->name, empties, w * h, hits);
    for (int m = 0; m < nm; m++)
        for (int k = 0; k < v->set_count; k++)
            for (int j = 0; j < v->light_count[k]; j++) {
                char path[1024];
                float *px = read_frame(argv[3], v, k, j, mode[m], w, h, path, sizeof path);
                if (!px)
                    continue;
                size_t bad = 0, surface_ones = 0, surfaces = 0;
                for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
                    if (empty[i])
                        bad += px[i] != 1.0f;
                    else if (!miss[i]) {
                        surfaces++;
                        surface_ones += px[i] == 1.0f;
                    }
                }
                printf("%s: %zu pixels without a surface, %zu of them not 1; %zu of %zu "
                       "surface pixels are 1\n",
                       path, empties, bad, surface_ones, surfaces);
                CHECK(bad == 0, "%s: %zu of %zu pixels without a surface are not 1", path, bad,
                      empties);
                /* the control: not a frame of all ones */
                CHECK(surface_ones < surfaces, "%s: every surface pixel is 1", path);
                free(px);
            }
    free(miss);
    free(empty);
    vdsh_view_tracer_destroy(tr);
    vdsh_free(f);
    vt_views_free(&vs);
    return test_report("empty");
}

static int check_facing(char **argv)
{
    vt_views vs;
    char msg[512], buf[256], *mode[16];
    float p[3];
    int set = atoi(argv[5]), light = atoi(argv[6]);
    if (parse3(argv[7], p)) {
        fprintf(stderr, "facing: bad point\n");
        return 2;
    }
    if (vt_views_read(argv[2], &vs, msg, sizeof msg)) {
        fprintf(stderr, "%s\n", msg);
        return 1;
    }
    const vt_view *v = find_view(&vs, argv[4]);
    int w = vs.width, h = vs.height, nm = split_modes(argv[8], buf, sizeof buf, mode);
    int r = h / 60 > 1 ? h / 60 : 1;
    for (int m = 0; v && m < nm; m++) {
        char path[1024];
        float *px = read_frame(argv[3], v, set, light, mode[m], w, h, path, sizeof path);
        int x, y;
        if (!px)
            continue;
        if (project(&v->camera, w, h, p, &x, &y) || x < r || y < r || x >= w - r || y >= h - r) {
            CHECK(0, "point (%g, %g, %g) is not in view %s", p[0], p[1], p[2], v->name);
        } else {
            float lo, hi, med;
            window(px, w, h, x, y, r, &lo, &hi, &med);
            printf("%s: facing away from the light at pixel (%d, %d): s %.4f .. %.4f, "
                   "median %.4f\n",
                   path, x, y, lo, hi, med);
            if (!strncmp(mode[m], "cube", 4))
                CHECK(hi <= 0.05f,
                      "%s: the cube map does not hide a surface facing away "
                      "(s up to %.4f)",
                      path, hi);
        }
        free(px);
    }
    vt_views_free(&vs);
    return test_report("facing");
}

/* The light pool: 64 free positions, the sequence's first free ones. */
static void check_pool(const char *path, const vdsh_file *f, const vr_scene *plain)
{
    vr_light none[1];
    CHECK(vr_scene_pool_lights(plain, none, 1) == 0, "a scene loaded without a pool has one");
    vr_error err;
    vr_scene *s = NULL;
    if (vr_scene_create(&(vr_scene_desc){.path = path, .light_pool = VR_MAX_POOL_LIGHTS}, &s,
                        &err) != VR_OK) {
        CHECK(0, "%s", err.msg);
        return;
    }
    float region[6];
    vdsh_view_mesh m;
    vdsh_view_file_mesh(f, region, &m);
    vdsh_view_tracer *t = NULL;
    vdsh_error verr;
    CHECK(vdsh_view_tracer_create(&m, &t, &verr) == VDSH_OK, "%s", verr.msg);
    vr_scene_info info;
    vr_scene_get_info(s, &info);
    const float diag = vdsh_view_diagonal(info.bounds_min, info.bounds_max);
    vr_light l[VR_MAX_POOL_LIGHTS];
    int n = vr_scene_pool_lights(s, l, VR_MAX_POOL_LIGHTS);
    CHECK(n == VR_MAX_POOL_LIGHTS, "%d pool lights, not %d", n, VR_MAX_POOL_LIGHTS);
    uint32_t k = 0;
    for (int i = 0; i < n && t; i++) {
        CHECK(vdsh_view_free_space(t, l[i].position, diag), "pool light %d not in free space", i);
        for (int a = 0; a < 3; a++)
            CHECK(l[i].position[a] >= info.bounds_min[a] && l[i].position[a] <= info.bounds_max[a],
                  "pool light %d outside the bounds", i);
        float p[3];
        do
            vdsh_light_candidate(info.bounds_min, info.bounds_max, 1, k++, p);
        while (!vdsh_view_free_space(t, p, diag) && k < 100000);
        CHECK(!memcmp(p, l[i].position, sizeof p), "pool light %d is not free candidate %u", i,
              k - 1);
        for (int j = 0; j < i; j++)
            CHECK(memcmp(l[i].position, l[j].position, sizeof p), "pool lights %d and %d equal", i,
                  j);
    }
    printf("light pool: %d positions in free space, %u candidates tried\n", n, k);
    vdsh_view_tracer_destroy(t);
    vr_scene_destroy(s);
}

static int check_lights(const char *path)
{
    vr_context *ctx = rt_context_or_skip("lights");
    vr_error err;
    vr_scene *s = NULL;
    vdsh_file *f = NULL;
    vdsh_error verr;
    vdsh_view v;
    int ok = vr_scene_create(&(vr_scene_desc){.path = path}, &s, &err) == VR_OK;
    CHECK(ok, "%s", err.msg);
    CHECK(vdsh_read(path, &f, &verr) == VDSH_OK, "%s", verr.msg);
    if (ok && f) {
        float region[6];
        vdsh_view_mesh m;
        vdsh_view_file_mesh(f, region, &m);
        CHECK(vdsh_view_compute(&m, &v, &verr) == VDSH_OK, "%s", verr.msg);
        vr_camera c;
        vr_scene_default_camera(s, &c);
        CHECK(!memcmp(c.eye, v.camera.eye, sizeof c.eye) &&
                  !memcmp(c.target, v.camera.target, sizeof c.target) &&
                  !memcmp(c.up, v.camera.up, sizeof c.up) && c.fov_y == v.camera.fov_y,
              "the runtime's default camera is not vdsh_view_compute's");
        vr_light l[VDSH_VIEW_MAX_LIGHTS];
        int n = vr_scene_default_lights(s, l, VDSH_VIEW_MAX_LIGHTS);
        CHECK(n == v.light_count, "%d default lights, not %d", n, v.light_count);
        for (int i = 0; i < n && i < v.light_count; i++) {
            CHECK(!memcmp(l[i].position, v.lights[i], sizeof v.lights[i]),
                  "light %d: (%g, %g, %g), not (%g, %g, %g)", i, l[i].position[0], l[i].position[1],
                  l[i].position[2], v.lights[i][0], v.lights[i][1], v.lights[i][2]);
            printf("default light %d: (%g, %g, %g)%s\n", i, l[i].position[0], l[i].position[1],
                   l[i].position[2],
                   memcmp(v.lights[i], v.preferred[i], sizeof v.lights[i])
                       ? " (moved into free space)"
                       : "");
        }
    }
    if (ok && f)
        check_pool(path, f, s);
    vdsh_free(f);
    vr_scene_destroy(s);
    vr_context_destroy(ctx);
    return test_report("lights");
}

int main(int argc, char **argv)
{
    if (argc == 2 && !strcmp(argv[1], "gl")) {
        vr_context_destroy(rt_context_or_skip("gl"));
        return 0;
    }
    if (argc == 5 && !strcmp(argv[1], "names"))
        return check_names(argv[2], argv[3], argv[4]);
    if (argc == 10 && !strcmp(argv[1], "values"))
        return check_values(argv);
    if (argc == 7 && !strcmp(argv[1], "empty"))
        return check_empty(argv);
    if (argc == 9 && !strcmp(argv[1], "facing"))
        return check_facing(argv);
    if (argc == 3 && !strcmp(argv[1], "lights"))
        return check_lights(argv[2]);
    fprintf(stderr, "usage: test_runtime_frames gl | names VIEWS DIR MODES |\n"
                    "       values VIEWS DIR VIEW SET LIGHT DARK LIT MODES |\n"
                    "       empty VIEWS DIR SCENE VIEW MODES |\n"
                    "       facing VIEWS DIR VIEW SET LIGHT P MODES | lights SCENE\n");
    return 2;
}
