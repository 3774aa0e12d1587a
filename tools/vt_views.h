/*
 * vt_views.h - a view set: the cameras and lights every method of a scene
 * is scored on, in frames (vdsh-frames makes one and traces its truth,
 * vdsh-view renders it). A JSON file, written once and kept, so that every
 * bake of the scene is judged on the same frames:
 *
 *   {"width": 512, "height": 384,
 *    "views": [{"name": "default",
 *               "eye": [x, y, z], "target": [x, y, z], "up": [0, 1, 0],
 *               "fov_y": 60,
 *               "light_sets": [[[x, y, z]],
 *                              [[x, y, z], [x, y, z], [x, y, z]]]}, ...]}
 *
 * The camera is formats/vdsh_camera.h's. Light set k of a view holds the
 * lights of one frame (scene units); frames are scored one light at a
 * time (shadow-only images) and a set's scores pooled.
 *
 * Frame files in a folder: NAME-sK-lJ-MODE.png, 16-bit grey (vt_image.h),
 * for view NAME, light set K, light J of the set (K and J count from 0),
 * and MODE one of the runtime's mode names ("cube", "vdsh5", ...; "cube-pcf"
 * for the cube map with PCF) or the truth's ("hard", "ideal", and
 * "c-vdshN": the stream of order N computed in C on the runtime's path).
 * Beside them NAME-sK-shaded-MODE.png, 8-bit RGBA: the set's lights
 * together, shaded, for looking at.
 *
 * Errors: 0, or -1 with a message naming the file and the field in msg.
 * Ownership: vt_views_free frees what vt_views_read allocated (and
 * accepts a zeroed set). Threading: no shared state.
 */
#ifndef VT_VIEWS_H
#define VT_VIEWS_H

#include <stddef.h>

#include "vdsh_camera.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VT_VIEWS_MAX_SETS 4
#define VT_VIEWS_MAX_LIGHTS 8
#define VT_VIEWS_MAX 256

typedef struct vt_view {
    char name[64]; /* letters, digits, '-', '_' */
    vdsh_camera camera;
    int set_count;
    int light_count[VT_VIEWS_MAX_SETS];
    float lights[VT_VIEWS_MAX_SETS][VT_VIEWS_MAX_LIGHTS][3];
} vt_view;

typedef struct vt_views {
    int width, height;
    int count;
    vt_view *views; /* count entries */
} vt_views;

int vt_views_read(const char *path, vt_views *out, char *msg, size_t cap);
int vt_views_write(const char *path, const vt_views *v, char *msg, size_t cap);
void vt_views_free(vt_views *v);

/* DIR/NAME-sK-lJ-MODE.png into out (cap bytes); -1 if it does not fit. */
int vt_frame_path(char *out, size_t cap, const char *dir, const char *view, int set, int light,
                  const char *mode);

/* DIR/NAME-sK-shaded-MODE.png: the shaded picture of light set K (all its
 * lights together, 8-bit RGBA) for looking at; -1 if it does not fit. */
int vt_shaded_path(char *out, size_t cap, const char *dir, const char *view, int set,
                   const char *mode);

#ifdef __cplusplus
}
#endif

#endif /* VT_VIEWS_H */
