/*
 * vr_view.c - a scene's default view: is it a room to stand in or an
 * object to look at, and the camera and lights for each.
 *
 * The scenes are y-up (the built-in room, OBJ convention). A room (or a
 * courtyard) is seen from inside: the eye a third of the way from the
 * middle to one end of the longest horizontal axis, at about a quarter of
 * the height, looking along that axis at the far half of the floor. From
 * there an object (a bunny, a teapot) would be seen from inside its own
 * bounding box, often from inside the mesh itself: nothing useful on
 * screen. So at load time (vr_view_interior) the room's eye casts rays in
 * 128 directions against the triangles: the scene is an interior when 60%
 * of them hit the front of a surface, the side its vertex normals face
 * (inside a room the walls face the eye; inside a closed object the eye
 * sees the backs of its faces; beside an open object most rays escape).
 * Anything else is framed from outside: the eye on a line from the centre
 * of the bounds, up and to the side, just far enough that every corner of
 * the bounds is in view. The rays are brute force, every triangle against
 * every direction, on one core: about 0.6 us per triangle (90 ms for the
 * 144,000 triangles of the closed bunny, 65 ms for Lost Empire's 225,000),
 * next to a load that reads and checks the whole file anyway.
 */
#include "vr_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Directions cast from the room's eye, and the share of them that must
 * see the front of a surface for the scene to count as an interior.
 * Measured (vr_view_front_share): the built-in room 1.0, Sponza 0.99,
 * Lost Empire 0.93, the Cornell boxes (one wall open) 0.64-0.70; a floor
 * with a box on it 0.48 (the floor below, the sky above), fandisk 0.40,
 * the rocker arm 0.36, the teapot 0.27 (an eye beside the object inside
 * its bounds), the bunnies and the sphere with a hole 0 (an eye inside the
 * mesh sees the backs of its faces). */
enum { VIEW_RAYS = 128 };
#define VR_VIEW_INTERIOR_SHARE 0.6f

/* The longest horizontal axis (x or z) and the other one. */
static void axes(const float lo[3], const float hi[3], int *ax, int *other)
{
    *ax = hi[0] - lo[0] >= hi[2] - lo[2] ? 0 : 2;
    *other = 2 - *ax;
}

void vr_view_room_camera(const float lo[3], const float hi[3], vr_camera *out)
{
    float c[3], e[3];
    for (int k = 0; k < 3; k++) {
        c[k] = 0.5f * (lo[k] + hi[k]);
        e[k] = hi[k] - lo[k];
    }
    int ax, other;
    axes(lo, hi, &ax, &other);
    vr_camera cam;
    memset(&cam, 0, sizeof cam);
    cam.eye[ax] = c[ax] + 0.36f * e[ax];
    cam.eye[other] = c[other] + 0.05f * e[other];
    cam.eye[1] = lo[1] + 0.28f * e[1];
    cam.target[ax] = c[ax] - 0.2f * e[ax];
    cam.target[other] = c[other];
    cam.target[1] = lo[1] + 0.13f * e[1];
    cam.up[1] = 1.0f;
    cam.fov_y = 60.0f;
    *out = cam;
}

/* Centre and radius of the bounding sphere of the bounds, and the unit
 * vectors of the frame the outside views are placed in: along the longest
 * horizontal axis, up, along the other. */
static float frame(const float lo[3], const float hi[3], float c[3], float u[3][3])
{
    float r2 = 0.0f;
    for (int k = 0; k < 3; k++) {
        c[k] = 0.5f * (lo[k] + hi[k]);
        r2 += 0.25f * (hi[k] - lo[k]) * (hi[k] - lo[k]);
    }
    int ax, other;
    axes(lo, hi, &ax, &other);
    memset(u, 0, 9 * sizeof(float));
    u[0][ax] = 1.0f;
    u[1][1] = 1.0f;
    u[2][other] = 1.0f;
    float r = sqrtf(r2);
    return r > 0.0f ? r : 1.0f;
}

/* c + s * (a u0 + b u1 + d u2) */
static void place(const float c[3], const float u[3][3], float s, float a, float b, float d,
                  float out[3])
{
    for (int k = 0; k < 3; k++)
        out[k] = c[k] + s * (a * u[0][k] + b * u[1][k] + d * u[2][k]);
}

void vr_view_fit_camera(const float lo[3], const float hi[3], vr_camera *out)
{
    float c[3], u[3][3];
    float r = frame(lo, hi, c, u);
    vr_camera cam;
    memset(&cam, 0, sizeof cam);
    cam.fov_y = 60.0f;
    cam.up[1] = 1.0f;
    memcpy(cam.target, c, sizeof cam.target);
    /* Seen from the side of the room's eye, from above: w points from the
     * centre to the eye, s to the right of the image, v up in it. */
    float w[3], s[3], v[3];
    place((float[3]){0, 0, 0}, u, 1.0f, 0.8f, 0.45f, 0.4f, w);
    float n = sqrtf(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    for (int k = 0; k < 3; k++)
        w[k] /= n;
    s[0] = w[2], s[1] = 0.0f, s[2] = -w[0]; /* up x w */
    n = sqrtf(s[0] * s[0] + s[2] * s[2]);
    s[0] /= n, s[2] /= n;
    v[0] = w[1] * s[2] - w[2] * s[1];
    v[1] = w[2] * s[0] - w[0] * s[2];
    v[2] = w[0] * s[1] - w[1] * s[0];
    /* The distance at which every corner of the bounds is inside the
     * field of view, vertically and (for an image at least as wide as it
     * is tall) horizontally, with a 5% margin: a corner at depth d along
     * w and offset o across needs o / (D - d) <= tan(fov / 2). */
    float t = tanf(0.5f * cam.fov_y * 3.14159265358979f / 180.0f), dist = 0.0f;
    for (int corner = 0; corner < 8; corner++) {
        float p[3], d = 0.0f, a = 0.0f, b = 0.0f;
        for (int k = 0; k < 3; k++) {
            p[k] = ((corner >> k) & 1 ? hi[k] : lo[k]) - c[k];
            d += p[k] * w[k];
            a += p[k] * s[k];
            b += p[k] * v[k];
        }
        dist = fmaxf(dist, d + fmaxf(fabsf(a), fabsf(b)) / t);
    }
    dist = 1.05f * (dist > 0.0f ? dist : r);
    for (int k = 0; k < 3; k++)
        cam.eye[k] = c[k] + dist * w[k];
    *out = cam;
}

int vr_view_lights(const float lo[3], const float hi[3], int interior, vr_light *out, int max)
{
    /* A room: in bounds fractions (x, y, z), light 0 a little off centre
     * at 40% of the height, the others toward the corners, so that props
     * between them cast shadows in different directions. */
    static const float at[4][3] = {
        {0.42f, 0.4f, 0.45f}, {0.2f, 0.6f, 0.78f}, {0.78f, 0.3f, 0.22f}, {0.65f, 0.75f, 0.7f}};
    /* An object: outside its bounding sphere, in the outside camera's
     * frame (toward the eye, up, across): light 0 above and to the side of
     * the eye and a little to its left, so that the side in view is lit and
 * the object shades and shadows itself visibly. */
    static const float around[4][3] = {
        {1.5f, 1.5f, -0.4f}, {-1.3f, 1.2f, 1.4f}, {0.5f, 2.1f, 1.5f}, {1.6f, 0.5f, 1.2f}};
    float c[3], u[3][3];
    float r = frame(lo, hi, c, u);
    int n = 0;
    for (; n < max && n < 4; n++) {
        memset(&out[n], 0, sizeof out[n]);
        if (interior)
            for (int k = 0; k < 3; k++)
                out[n].position[k] = lo[k] + at[n][k] * (hi[k] - lo[k]);
        else
            place(c, u, r, around[n][0], around[n][1], around[n][2], out[n].position);
    }
    return n;
}

/* The interpolated vertex normal of triangle t at barycentrics (u, v). */
static void normal_at(const float *normals, const uint32_t *tri, float u, float v, float n[3])
{
    const float *a = normals + 3 * (size_t)tri[0], *b = normals + 3 * (size_t)tri[1],
                *c = normals + 3 * (size_t)tri[2];
    for (int k = 0; k < 3; k++)
        n[k] = (1.0f - u - v) * a[k] + u * b[k] + v * c[k];
}

float vr_view_front_share(const float *positions, const float *normals,
                          const uint32_t *indices, uint32_t triangle_count, const float lo[3],
                          const float hi[3])
{
    vr_camera room;
    vr_view_room_camera(lo, hi, &room);
    const float *o = room.eye;
    float diag2 = 0.0f;
    for (int k = 0; k < 3; k++)
        diag2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    /* Hits closer than this are the surface the eye stands on (a flat
     * scene) or rounding; they do not count. */
    float tmin = 1e-5f * sqrtf(diag2);

    /* A Fibonacci sphere: nearly uniform directions, the same every time. */
    float dir[VIEW_RAYS][3], best[VIEW_RAYS];
    uint32_t hit[VIEW_RAYS];
    float hu[VIEW_RAYS], hv[VIEW_RAYS];
    for (int i = 0; i < VIEW_RAYS; i++) {
        float z = 1.0f - (2.0f * (float)i + 1.0f) / (float)VIEW_RAYS;
        float rho = sqrtf(fmaxf(0.0f, 1.0f - z * z)), ph = 2.39996323f * (float)i;
        dir[i][0] = rho * cosf(ph);
        dir[i][1] = z;
        dir[i][2] = rho * sinf(ph);
        best[i] = INFINITY;
        hit[i] = UINT32_MAX;
    }

    /* Moller-Trumbore, triangles outer: what depends on the triangle and
     * the eye only (edges, the eye relative to a vertex, q) once each. */
    for (uint32_t t = 0; t < triangle_count; t++) {
        const uint32_t *tri = indices + 3 * (size_t)t;
        const float *a = positions + 3 * (size_t)tri[0], *b = positions + 3 * (size_t)tri[1],
                    *c = positions + 3 * (size_t)tri[2];
        float e1[3], e2[3], s[3], q[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = b[k] - a[k];
            e2[k] = c[k] - a[k];
            s[k] = o[k] - a[k];
        }
        q[0] = s[1] * e1[2] - s[2] * e1[1];
        q[1] = s[2] * e1[0] - s[0] * e1[2];
        q[2] = s[0] * e1[1] - s[1] * e1[0];
        float qe2 = q[0] * e2[0] + q[1] * e2[1] + q[2] * e2[2];
        for (int i = 0; i < VIEW_RAYS; i++) {
            const float *d = dir[i];
            float p[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2],
                          d[0] * e2[1] - d[1] * e2[0]};
            float det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
            if (det == 0.0f)
                continue;
            float inv = 1.0f / det;
            float u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) * inv;
            if (!(u >= 0.0f && u <= 1.0f))
                continue;
            float v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) * inv;
            if (!(v >= 0.0f && u + v <= 1.0f))
                continue;
            float dist = qe2 * inv;
            if (dist > tmin && dist < best[i]) {
                best[i] = dist;
                hit[i] = t;
                hu[i] = u;
                hv[i] = v;
            }
        }
    }

    int front = 0;
    for (int i = 0; i < VIEW_RAYS; i++) {
        if (hit[i] == UINT32_MAX)
            continue;
        float n[3];
        normal_at(normals, indices + 3 * (size_t)hit[i], hu[i], hv[i], n);
        front += n[0] * dir[i][0] + n[1] * dir[i][1] + n[2] * dir[i][2] < 0.0f;
    }
    return (float)front / (float)VIEW_RAYS;
}

int vr_view_interior(const float *positions, const float *normals, const uint32_t *indices,
                     uint32_t triangle_count, const float lo[3], const float hi[3])
{
    return vr_view_front_share(positions, normals, indices, triangle_count, lo, hi) >=
           VR_VIEW_INTERIOR_SHARE;
}

/* ---- the public side (vr.h) ------------------------------------------- */

void vr_scene_default_camera(const vr_scene *s, vr_camera *out)
{
    if (s->interior)
        vr_view_room_camera(s->bounds_min, s->bounds_max, out);
    else
        vr_view_fit_camera(s->bounds_min, s->bounds_max, out);
}

void vr_scene_fit_camera(const vr_scene *s, vr_camera *out)
{
    vr_view_fit_camera(s->bounds_min, s->bounds_max, out);
}

int vr_scene_default_lights(const vr_scene *s, vr_light *out, int max)
{
    return vr_view_lights(s->bounds_min, s->bounds_max, s->interior, out, max);
}
