/* View sets: vt_views.h says what and why. */
#include "vt_views.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vdsh_scene_view.h"
#include "vt_json.h"

/* A coordinate within +-VDSH_VIEW_MAX_COORD, the views' bound on a scene
 * (1e39 is a finite double but inf as the float the views hold, and an eye
 * at 3e38 overflows the ray arithmetic: Embree aborted on either). */
static int finite_number(const cJSON *x)
{
    return cJSON_IsNumber(x) && fabs(x->valuedouble) <= (double)VDSH_VIEW_MAX_COORD;
}

static int vec3(const cJSON *o, const char *key, float out[3], int optional)
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!a)
        return optional ? 0 : -1;
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != 3)
        return -1;
    for (int i = 0; i < 3; i++) {
        const cJSON *x = cJSON_GetArrayItem(a, i);
        if (!finite_number(x))
            return -1;
        out[i] = (float)x->valuedouble;
    }
    return 0;
}

static int good_name(const char *s)
{
    if (!s || !*s || strlen(s) >= 64)
        return 0;
    for (; *s; s++)
        if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || (*s >= '0' && *s <= '9') ||
              *s == '-' || *s == '_'))
            return 0;
    return 1;
}

#define FAIL(...)                                                                                  \
    do {                                                                                           \
        snprintf(msg, cap, __VA_ARGS__);                                                           \
        goto fail;                                                                                 \
    } while (0)

int vt_views_read(const char *path, vt_views *out, char *msg, size_t cap)
{
    vt_views v = {0};
    cJSON *root = vt_json_read_file(path, msg, cap);
    if (!root)
        return -1;
    const cJSON *w = cJSON_GetObjectItemCaseSensitive(root, "width");
    const cJSON *h = cJSON_GetObjectItemCaseSensitive(root, "height");
    const cJSON *views = cJSON_GetObjectItemCaseSensitive(root, "views");
    if (!cJSON_IsNumber(w) || !cJSON_IsNumber(h) || w->valuedouble < 1 || h->valuedouble < 1 ||
        w->valuedouble > 16384 || h->valuedouble > 16384 || w->valuedouble != (int)w->valuedouble ||
        h->valuedouble != (int)h->valuedouble)
        FAIL("%s: width and height must be whole numbers in 1..16384", path);
    if (!cJSON_IsArray(views) || cJSON_GetArraySize(views) < 1 ||
        cJSON_GetArraySize(views) > VT_VIEWS_MAX)
        FAIL("%s: 'views' must be an array of 1..%d views", path, VT_VIEWS_MAX);
    v.width = (int)w->valuedouble, v.height = (int)h->valuedouble;
    v.count = cJSON_GetArraySize(views);
    v.views = calloc((size_t)v.count, sizeof *v.views);
    if (!v.views)
        FAIL("%s: out of memory", path);
    for (int i = 0; i < v.count; i++) {
        const cJSON *o = cJSON_GetArrayItem(views, i);
        vt_view *x = v.views + i;
        const cJSON *name = cJSON_GetObjectItemCaseSensitive(o, "name");
        if (!cJSON_IsString(name) || !good_name(name->valuestring))
            FAIL("%s: view %d: 'name' must be 1..63 letters, digits, '-' or '_'", path, i);
        snprintf(x->name, sizeof x->name, "%s", name->valuestring);
        for (int j = 0; j < i; j++)
            if (!strcmp(v.views[j].name, x->name))
                FAIL("%s: view %d: name '%s' used twice", path, i, x->name);
        if (vec3(o, "eye", x->camera.eye, 0) || vec3(o, "target", x->camera.target, 0) ||
            vec3(o, "up", x->camera.up, 1))
            FAIL("%s: view '%s': 'eye', 'target' (and 'up') must be 3 finite numbers "
                 "within +-1e18",
                 path, x->name);
        if (!memcmp(x->camera.eye, x->camera.target, sizeof x->camera.eye))
            FAIL("%s: view '%s': eye and target are the same point", path, x->name);
        if (vdsh_camera_degenerate(&x->camera))
            FAIL("%s: view '%s': the eye looks along 'up' (straight above or below the "
                 "target with up +y): no image plane",
                 path, x->name);
        const cJSON *fov = cJSON_GetObjectItemCaseSensitive(o, "fov_y");
        if (fov && (!cJSON_IsNumber(fov) || !(fov->valuedouble > 0 && fov->valuedouble < 180)))
            FAIL("%s: view '%s': fov_y must be in (0, 180) degrees", path, x->name);
        x->camera.fov_y = fov ? (float)fov->valuedouble : 60.0f;
        const cJSON *sets = cJSON_GetObjectItemCaseSensitive(o, "light_sets");
        if (!cJSON_IsArray(sets) || cJSON_GetArraySize(sets) < 1 ||
            cJSON_GetArraySize(sets) > VT_VIEWS_MAX_SETS)
            FAIL("%s: view '%s': 'light_sets' must be an array of 1..%d sets", path, x->name,
                 VT_VIEWS_MAX_SETS);
        x->set_count = cJSON_GetArraySize(sets);
        for (int k = 0; k < x->set_count; k++) {
            const cJSON *set = cJSON_GetArrayItem(sets, k);
            if (!cJSON_IsArray(set) || cJSON_GetArraySize(set) < 1 ||
                cJSON_GetArraySize(set) > VT_VIEWS_MAX_LIGHTS)
                FAIL("%s: view '%s': light set %d must hold 1..%d lights", path, x->name, k,
                     VT_VIEWS_MAX_LIGHTS);
            x->light_count[k] = cJSON_GetArraySize(set);
            for (int l = 0; l < x->light_count[k]; l++) {
                const cJSON *p = cJSON_GetArrayItem(set, l);
                int bad = !cJSON_IsArray(p) || cJSON_GetArraySize(p) != 3;
                for (int a = 0; a < 3 && !bad; a++) {
                    const cJSON *c = cJSON_GetArrayItem(p, a);
                    bad = !finite_number(c);
                    if (!bad)
                        x->lights[k][l][a] = (float)c->valuedouble;
                }
                if (bad)
                    FAIL("%s: view '%s': light %d of set %d must be 3 finite numbers "
                         "within +-1e18",
                         path, x->name, l, k);
            }
        }
    }
    cJSON_Delete(root);
    *out = v;
    return 0;
fail:
    cJSON_Delete(root);
    vt_views_free(&v);
    return -1;
}

static void put3(vt_json *j, cJSON *parent, const char *key, const float v[3])
{
    cJSON *a = vt_json_array(j, parent, key);
    for (int i = 0; i < 3; i++)
        vt_json_f32(j, a, NULL, v[i]);
}

int vt_views_write(const char *path, const vt_views *v, char *msg, size_t cap)
{
    vt_json j = {0};
    cJSON *root = vt_json_object(&j, NULL, NULL);
    vt_json_u64(&j, root, "width", (uint64_t)v->width);
    vt_json_u64(&j, root, "height", (uint64_t)v->height);
    cJSON *views = vt_json_array(&j, root, "views");
    for (int i = 0; i < v->count; i++) {
        const vt_view *x = v->views + i;
        cJSON *o = vt_json_object(&j, views, NULL);
        vt_json_string(&j, o, "name", x->name);
        put3(&j, o, "eye", x->camera.eye);
        put3(&j, o, "target", x->camera.target);
        float up[3] = {x->camera.up[0], x->camera.up[1], x->camera.up[2]};
        if (!up[0] && !up[1] && !up[2])
            up[1] = 1.0f;
        put3(&j, o, "up", up);
        vt_json_f32(&j, o, "fov_y", vdsh_camera_fov(&x->camera));
        cJSON *sets = vt_json_array(&j, o, "light_sets");
        for (int k = 0; k < x->set_count; k++) {
            cJSON *set = vt_json_array(&j, sets, NULL);
            for (int l = 0; l < x->light_count[k]; l++)
                put3(&j, set, NULL, x->lights[k][l]);
        }
    }
    int r = vt_json_write_file(&j, path, msg, cap);
    vt_json_free(&j);
    return r;
}

void vt_views_free(vt_views *v)
{
    if (!v)
        return;
    free(v->views);
    memset(v, 0, sizeof *v);
}

int vt_frame_path(char *out, size_t cap, const char *dir, const char *view, int set, int light,
                  const char *mode)
{
    int n = snprintf(out, cap, "%s/%s-s%d-l%d-%s.png", dir, view, set, light, mode);
    return n < 0 || (size_t)n >= cap ? -1 : 0;
}

int vt_shaded_path(char *out, size_t cap, const char *dir, const char *view, int set,
                   const char *mode)
{
    int n = snprintf(out, cap, "%s/%s-s%d-shaded-%s.png", dir, view, set, mode);
    return n < 0 || (size_t)n >= cap ? -1 : 0;
}
