/*
 * vdsh_scene_view.h - a scene's default view, decided from its mesh alone:
 * is it a room to stand in or an object to look at, the camera for each,
 * and default point lights, each in free space (vdsh_light.h). One
 * definition, so that the GL viewer (runtime/, vr_scene_default_camera and
 * vr_scene_default_lights) and the bake side's tools (vdsh-frames, from the
 * .vdsh mesh) mean the same thing by "the default view".
 *
 * The scenes are y-up (the built-in room, OBJ convention). A room (or a
 * courtyard) is seen from inside: the eye a third of the way from the
 * middle to one end of the longest horizontal axis, at about a quarter of
 * the height, looking along that axis at the far half of the floor
 * (vdsh_view_room_camera). From there an object (a bunny, a teapot) would
 * be seen from inside its own bounding box, often from inside the mesh
 * itself. So the room's eye casts VDSH_VIEW_RAYS rays against the
 * triangles (vdsh_view_front_share): the scene is an interior when at
 * least VDSH_VIEW_INTERIOR_SHARE of them first meet the front of a
 * surface, the side its vertex normals face. Anything else is framed from
 * outside (vdsh_view_fit_camera); a flat object (every vertex on one
 * plane: a single triangle, a panel) from the side its normals face, the
 * fit view mirrored through its plane, lights too, where the fit
 * direction meets its back.
 *
 * Default lights: preferred positions from the bounds alone
 * (vdsh_view_preferred_lights: a room's spread through it, an object's
 * outside its bounding sphere, then pulled into the light region the bake
 * trained on, vdsh_light.h); each that is not in free space (inside a
 * pillar, on a wall) is moved to the nearest position that is, searched
 * deterministically (vdsh_view_compute says how).
 *
 * The rays are cast on the CPU against a uniform grid of the triangles
 * (vdsh_view_tracer): first hits exactly as testing every triangle would
 * find them (the same arithmetic; ties to the lower triangle index).
 *
 * Does not: read files, touch GL, or use threads.
 *
 * Usage (tests/test_scene_view.c is a compiled example):
 *
 *     vdsh_view v;
 *     vdsh_view_mesh m = {f->positions, f->normals, f->indices,
 *                         f->header.vertex_count, f->header.triangle_count};
 *     if (vdsh_view_compute(&m, &v, &err) != VDSH_OK) ...
 *     v.camera, v.lights[0 .. v.light_count - 1]
 *
 * Errors: vdsh_view_compute and vdsh_view_tracer_create return
 * VDSH_ERR_OUT_OF_MEMORY or VDSH_ERR_INVALID (a triangle index not below
 * vertex_count, a coordinate beyond +-VDSH_VIEW_MAX_COORD or a scene
 * smaller than VDSH_VIEW_MIN_EXTENT, where the float squares of the view's
 * distances overflow or underflow), message in err,
 * outputs untouched. The rest cannot fail.
 * Ownership: the mesh arrays are borrowed; a tracer borrows them for its
 * whole life (keep them until vdsh_view_tracer_destroy, which accepts
 * NULL). vdsh_view holds no pointers.
 * Threading: no shared state; a tracer may be used by several threads at
 * once (tracing only reads it).
 */
#ifndef VDSH_SCENE_VIEW_H
#define VDSH_SCENE_VIEW_H

#include <stdint.h>

#include "vdsh.h"
#include "vdsh_camera.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Rays from the room's eye, and the share of them that must meet the
 * front of a surface for the scene to count as an interior. Measured
 * (vdsh_view_front_share, default bakes): the built-in room 1.0, Sponza
 * 0.99, the Cornell boxes (one wall open) 0.64-0.70; a floor with a box
 * on it 0.48 (the floor below, the sky above), fandisk 0.40, the rocker
 * arm 0.36, Lost Empire 0.33 (a terrain open to the sky: framed from
 * outside, as an object), the teapot 0.27 (an eye beside the object
 * inside its bounds), the bunnies 0 (an eye inside the mesh sees the backs
 * of its faces). */
#define VDSH_VIEW_RAYS 128
#define VDSH_VIEW_INTERIOR_SHARE 0.6f
#define VDSH_VIEW_MAX_LIGHTS 4
/* A default light whose preferred place is not free moves to the nearest
 * place this many clearances (vdsh_free_clearance) from every surface,
 * within VDSH_VIEW_MARGIN_REACH clearances; else to the nearest free one. */
#define VDSH_VIEW_LIGHT_MARGIN 8.0f
#define VDSH_VIEW_MARGIN_REACH 16.0f
/* The frame rule for an interior's default lights (vdsh-frames' view-set
 * rule, bake/eval/frames.h): each lights at least this share of a
 * VDSH_VIEW_CHECK_W x VDSH_VIEW_CHECK_H frame of the default camera and
 * shadows as many; when the preferred lights do not, up to
 * VDSH_VIEW_LIGHT_POOL seeded candidates are tried: first those
 * VDSH_VIEW_LIGHT_MARGIN clearances from every surface (the margin of a
 * moved light), then, while too few light the frame, the others in free
 * space. */
#define VDSH_VIEW_MIN_SHARE 0.05f
/* An object's camera turns about the vertical until its light 0 faces at
 * least this share of the pixels that see the object, or as much as a
 * turn allows (vdsh_view_compute). */
#define VDSH_VIEW_KEY_FACING 0.5f
#define VDSH_VIEW_CHECK_W 64
#define VDSH_VIEW_CHECK_H 48
#define VDSH_VIEW_LIGHT_POOL 64

typedef struct vdsh_view_mesh {
    const float *positions;  /* vertex_count x 3 */
    const float *normals;    /* vertex_count x 3: the front side */
    const uint32_t *indices; /* triangle_count x 3 */
    uint32_t vertex_count;
    uint32_t triangle_count;
    /* NULL, or where the bake's lights went (the file's `lreg` chunk,
     * vdsh-bake --light-region): min x,y,z, max x,y,z. The default
     * lights go there instead of the rule's region: an object's, and an
     * interior's (its preferred lights pulled into it, the frame rule's
     * candidates drawn in it; they stayed in its bounds, where the bake
     * trained on none of them when the region was elsewhere). */
    const float *light_region;
} vdsh_view_mesh;

typedef struct vdsh_view {
    float bounds_min[3]; /* of all vertices (vdsh_view_bounds) */
    float bounds_max[3];
    float front_share;                     /* vdsh_view_front_share, 0..1 */
    int interior;                          /* front_share >= VDSH_VIEW_INTERIOR_SHARE */
    vdsh_camera camera;                    /* the default camera: room or fit */
    int light_count;                       /* VDSH_VIEW_MAX_LIGHTS */
    float lights[VDSH_VIEW_MAX_LIGHTS][3]; /* default light positions */
    /* before any move into free space (a light the frame rule took from
     * the seeded candidates: that candidate; an object's: already pulled
     * into its light region) */
    float preferred[VDSH_VIEW_MAX_LIGHTS][3];
    /* 1: lights[i] is in free space (moved there when preferred[i] was
     * not); 0: no position searched was (a scene without free space), and
     * lights[i] is preferred[i]. */
    int light_free[VDSH_VIEW_MAX_LIGHTS];
    uint32_t light_trials; /* positions tested for free space */
    /* An object's light region, the one the bake trained on
     * (vdsh_light_region of the bounds with vdsh_view_free_space: the
     * bounds, or the bounds grown around a closed object), and whether it
     * is grown; its lights lie in it (vdsh_view_compute: but a flat
     * one's, and along an axis thinner than the clearance). An
     * interior's: its bounds, not grown (not probed; its lights stay in
     * its bounds, which its region holds), or the region given. */
    float region_min[3];
    float region_max[3];
    int region_grown;
    int region_given; /* 1: the mesh's light_region, as given */
    /* An interior's lights in the check frame (vdsh_view_light_shares):
     * shares of its pixels lit and shadowed; 0 for an object's. */
    float light_lit[VDSH_VIEW_MAX_LIGHTS];
    float light_shadowed[VDSH_VIEW_MAX_LIGHTS];
    uint32_t pool_tried; /* seeded candidate tests of the frame rule (both passes) */
    /* The fit camera, whatever the scene (vdsh-view --fit): a flat
     * object's seen from its front, as vdsh_view_compute says; an
     * object's default camera. */
    vdsh_camera fit;
} vdsh_view;

/* Everything above from the mesh: bounds, the interior test, the default
 * camera, the default lights. A flat object (all vertices within
 * VDSH_VIEW_FLAT_SHARE of the diagonal of the plane of its largest
 * triangle) whose
 * front (the side the summed vertex normals face; the winding's where
 * they cancel) faces away from the fit camera's direction w: the fit
 * camera (fit; an object's camera) is fitted along w mirrored through the plane (along the plane's normal
 * where that is within about 6 degrees of vertical), and the preferred
 * lights are mirrored through the plane through the bounds' centre. A flat
 * object's camera direction more than VDSH_VIEW_FLAT_ANGLE from its
 * normal is then turned toward the normal to that angle, its azimuth
 * about the normal kept (a panel facing across the longest horizontal
 * axis was seen 66 degrees off its normal, a tilted quad edge-on). Then
 * every preferred light of a flat object (facing either way) that lies
 * behind that plane is mirrored through it, and one nearer the plane than
 * a quarter of the diagonal moved along its normal to that distance: all
 * its lights light the front the camera sees (light 0 stood behind a
 * panel facing across the longest horizontal axis, and the default frame
 * was black). An
 * object's preferred lights are then pulled into the light region
 * (region_min..region_max; along an axis where it is thinner than the
 * clearance the bounds grown by VDSH_REGION_GROW of the diagonal there)
 * per axis, VDSH_VIEW_REGION_INSET of its extent inside each face; a flat
 * object's (whose region, its bounds, has room behind it) into its bounds
 * grown so on every axis, along the line to the centre (so each stays on
 * its side of the plane): the bake's decision fit and its calibration saw
 * lights there only, and a light beyond 1.5 clamp distances (the
 * diagonal) shadows every receiver (docs/DESIGN.md, "Lights beyond the
 * clamp"; the lights outside the bounding sphere that were the rule drew
 * false blotches on an object's floor). An interior's are pulled so into
 * the region given (vdsh_view_mesh.light_region), when there is one. A
 * preferred light position in free space is kept. Otherwise the candidates p + k h d are tried, rings k = 1, 2, ...
 * of step h = half the clearance (vdsh_free_clearance of the bounds'
 * diagonal), up to half the diagonal, d each of the 26 directions toward
 * a cube's faces, edges and corners in a fixed order; an interior's
 * candidates must lie inside its bounds (the region given, if any), an
 * object's inside its light region. The first in free space is the
 * light. If none is, the first 4096 candidates of vdsh_light_candidate
 * (seed 1) are tried, nearest first.
 * Then an object's camera (not a flat one's) turns toward light 0: when
 * light 0 faces less than VDSH_VIEW_KEY_FACING of the check frame's pixels
 * that see the object, the fit camera along the fit direction turned
 * about the vertical by 45, -45, 90, -90, 135, -135, 180 degrees, the
 * first whose frame light 0 faces so, else the one it faces most (fit is
 * that camera too).
 * Then an interior's lights must light what the camera sees (a room
 * behind an internal wall is free space too): each light so found is
 * scored in the check frame (vdsh_view_light_shares) and kept when it
 * lights it: at least VDSH_VIEW_MIN_SHARE of it, and more than it
 * shadows (a light behind a wall seen through a door shadows most). When fewer are kept, the candidates
 * of vdsh_light_candidate (seed 2) in the bounds (the region given, if
 * any) that are in free space
 * are scored, up to VDSH_VIEW_LIGHT_POOL of them or until enough light
 * and shadow that share each; the lights are, in this order: the kept
 * ones, the candidates that light the frame and shadow the share, those
 * that light it, then the rest by the share they light (ties: the earlier). Where
 * every preferred light lights the frame, nothing changes. An object's
 * lights, where its light region is its bounds (not given, not grown),
 * must light what the camera sees of it likewise: a light that lights
 * less than VDSH_VIEW_MIN_SHARE of the check frame's pixels that see the
 * object, or less than it shadows (pulled into the bounds, it can stand
 * behind the object's end faces: the 2CylinderEngine's light 0, inside
 * its end cap), tries its preferred position pulled into the bounds
 * grown by VDSH_REGION_GROW of the diagonal on every axis instead, found
 * free as above, and takes it when that one lights the object so; the
 * lights that light it stay (the default views of the teapot, bunny,
 * fandisk, rocker arm and a cube on a floor: light 0 as it was).
 * Deterministic: the same mesh gives the same view on every machine. */
vdsh_result vdsh_view_compute(const vdsh_view_mesh *m, vdsh_view *out, vdsh_error *err);

/* The mesh of a file, as vdsh-view, vdsh-export and vdsh-frames give it to
 * vdsh_view_compute: *out borrows f's arrays, and its light_region is
 * region, filled with f's `lreg` box, when f has one (else NULL); f and
 * region must outlive *out. */
void vdsh_view_file_mesh(const vdsh_file *f, float region[6], vdsh_view_mesh *out);

/* The bounding box of positions (vertex_count x 3), fminf / fmaxf per
 * axis; with no vertices lo = +INFINITY, hi = -INFINITY. */
void vdsh_view_bounds(const float *positions, uint32_t vertex_count, float lo[3], float hi[3]);

/* The bounds' diagonal in float (1 when it is 0): the view's scale for
 * its ray offsets, open rays and free-space clearance, and vdsh-view's
 * for its lights' fall-off. Not vdsh_free_diagonal, the bake's, summed in
 * double: the two can differ in the last bit, and the default view has
 * been computed with this one; only the light region (vdsh_view_compute)
 * uses the bake's. */
float vdsh_view_diagonal(const float lo[3], const float hi[3]);

/* The cameras (fov_y 60, up +y), from the bounds only. Fit: the eye up and
 * to the side of the bounds' centre, looking at it, just far enough that
 * every corner of the bounds is within the field of view vertically and
 * (for an image at least as wide as it is tall) horizontally. */
void vdsh_view_room_camera(const float lo[3], const float hi[3], vdsh_camera *out);
void vdsh_view_fit_camera(const float lo[3], const float hi[3], vdsh_camera *out);

/* A flat object: every vertex within this share of the diagonal of the
 * plane of its largest triangle (the clearance, vdsh_free_clearance: a
 * millionth took a quad whose fourth corner stood a thousandth off the
 * plane for a solid, framed edge-on). Its camera is at most
 * VDSH_VIEW_FLAT_ANGLE degrees from its normal (vdsh_view_compute). */
#define VDSH_VIEW_FLAT_SHARE 0.01f
#define VDSH_VIEW_FLAT_ANGLE 45.0f

/* The share of the light region's extent an object's preferred light is
 * kept inside each of its faces (vdsh_view_compute). */
#define VDSH_VIEW_REGION_INSET 0.05f

/* Up to max (at most VDSH_VIEW_MAX_LIGHTS) preferred light positions from
 * the bounds only; returns how many. Not checked for free space. */
int vdsh_view_preferred_lights(const float lo[3], const float hi[3], int interior, float (*out)[3],
                               int max);

/* ---- rays against the mesh ------------------------------------------ */

typedef struct vdsh_view_tracer vdsh_view_tracer;

typedef struct vdsh_view_hit {
    float t;    /* distance along the unit direction */
    float u, v; /* barycentrics of vertices 1 and 2 */
    uint32_t triangle;
    /* the ray met the face from behind: its winding normal (v1 - v0) x (v2 -
     * v0) points along the ray */
    int back;
} vdsh_view_hit;

/* The largest |coordinate| the view's float arithmetic takes (extents
 * and their squares stay finite below it), and the least extent along the
 * scene's longest axis (squares of its distances stay normal floats). */
#define VDSH_VIEW_MAX_COORD 1e18f
#define VDSH_VIEW_MIN_EXTENT 1e-15f

/* A uniform grid of the mesh's triangles (about two cells per triangle). */
vdsh_result vdsh_view_tracer_create(const vdsh_view_mesh *m, vdsh_view_tracer **out,
                                    vdsh_error *err);
void vdsh_view_tracer_destroy(vdsh_view_tracer *t);

/* The nearest hit with t >= tmin along org + t dir (Moller-Trumbore,
 * edges and vertices included): 1 and *hit, or 0 (nothing; *hit
 * untouched). Equal t: the lower triangle index. */
int vdsh_view_trace(const vdsh_view_tracer *t, const float org[3], const float dir[3], float tmin,
                    vdsh_view_hit *hit);

/* vdsh_view_trace for every triangle in index order, no grid: the
 * reference the grid is tested against (and the cost it saves). */
int vdsh_view_trace_all(const vdsh_view_mesh *m, const float org[3], const float dir[3], float tmin,
                        vdsh_view_hit *hit);

/* The room camera, its eye moved when it is not in free space or stands
 * against a surface (fewer than 48 of a 9 x 7 grid of its rays travel a
 * tenth of the diagonal: in front of the Cornell box's short block) to the
 * first position of a fixed list that is open and VDSH_VIEW_EYE_MARGIN
 * clearances (a tenth of the diagonal) from every surface by the
 * free-space probes (vdsh_light.h), else the first that is open and free:
 * higher (0.4, 0.55, 0.7, 0.85 of the height), then across the room (0.3
 * of its width to either side); the target stays. Returns 1 when the eye
 * moved (0: the eye of vdsh_view_room_camera, also when no position of the
 * list is). */
#define VDSH_VIEW_EYE_MARGIN 10.0f
int vdsh_view_room_camera_free(const vdsh_view_tracer *t, const float lo[3], const float hi[3],
                               vdsh_camera *out);

/* The share of VDSH_VIEW_RAYS directions (a Fibonacci sphere) from the
 * room camera's eye (vdsh_view_room_camera_free) whose first hit farther
 * than 1e-5 of the diagonal is
 * the front of a surface (the interpolated vertex normal against the
 * ray), 0..1. */
float vdsh_view_front_share(const vdsh_view_tracer *t, const vdsh_view_mesh *m, const float lo[3],
                            const float hi[3]);

/* vdsh_free_space (vdsh_light.h) at p, its probes cast against the mesh,
 * clearance from `diagonal`; back faces by winding. */
int vdsh_view_free_space(const vdsh_view_tracer *t, const float p[3], float diagonal);

/* vdsh_view_free_space as a vdsh_free_fn (vdsh_light.h), for
 * vdsh_light_region and vdsh_light_place: ctx a vdsh_view_free_ctx. */
typedef struct vdsh_view_free_ctx {
    const vdsh_view_tracer *t;
    float diagonal;
} vdsh_view_free_ctx;
int vdsh_view_is_free(const void *ctx, const float p[3]);

/* The shares of a width x height frame of camera c whose pixels a point
 * light at `light` lights and shadows: a pixel's first hit, its
 * interpolated normal turned toward the eye, faces the light (N . (L - p)
 * > 0); it is shadowed when a surface lies between it and the light
 * (farther than 1e-4 of `diagonal` from both), lit otherwise. Pixels that
 * see nothing or face away count as neither. */
void vdsh_view_light_shares(const vdsh_view_tracer *t, const vdsh_view_mesh *m,
                            const vdsh_camera *c, int width, int height, const float light[3],
                            float diagonal, float *lit, float *shadowed);

#ifdef __cplusplus
}
#endif

#endif /* VDSH_SCENE_VIEW_H */
