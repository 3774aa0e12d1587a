/* A scene's default view: vdsh_scene_view.h says what and why. */
#include "vdsh_scene_view.h"
#include "vdsh_failf.h"

#include "vdsh_light.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- cameras and preferred lights, from the bounds ------------------- */

void vdsh_view_bounds(const float *positions, uint32_t vertex_count, float lo[3], float hi[3])
{
    for (int k = 0; k < 3; k++) {
        lo[k] = INFINITY;
        hi[k] = -INFINITY;
    }
    for (uint32_t v = 0; v < vertex_count; v++)
        for (int k = 0; k < 3; k++) {
            float x = positions[3 * (size_t)v + (size_t)k];
            lo[k] = fminf(lo[k], x);
            hi[k] = fmaxf(hi[k], x);
        }
}

float vdsh_view_diagonal(const float lo[3], const float hi[3])
{
    float diag2 = 0.0f;
    for (int k = 0; k < 3; k++)
        diag2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    return sqrtf(diag2) > 0.0f ? sqrtf(diag2) : 1.0f;
}

/* The longest horizontal axis (x or z) and the other one. */
static void axes(const float lo[3], const float hi[3], int *ax, int *other)
{
    *ax = hi[0] - lo[0] >= hi[2] - lo[2] ? 0 : 2;
    *other = 2 - *ax;
}

void vdsh_view_room_camera(const float lo[3], const float hi[3], vdsh_camera *out)
{
    float c[3], e[3];
    for (int k = 0; k < 3; k++) {
        c[k] = 0.5f * (lo[k] + hi[k]);
        e[k] = hi[k] - lo[k];
    }
    int ax, other;
    axes(lo, hi, &ax, &other);
    vdsh_camera cam;
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

/* The fit camera's direction from the centre to the eye: from the side
 * of the room's eye, from above (unit). */
static void fit_direction(const float lo[3], const float hi[3], float w[3])
{
    float c[3], u[3][3];
    frame(lo, hi, c, u);
    place((float[3]){0, 0, 0}, u, 1.0f, 0.8f, 0.45f, 0.4f, w);
    float n = sqrtf(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    for (int k = 0; k < 3; k++)
        w[k] /= n;
}

/* The fit camera looking at the bounds' centre from direction w (unit,
 * not vertical). */
static void fit_along(const float lo[3], const float hi[3], const float w[3], vdsh_camera *out)
{
    float c[3], u[3][3];
    float r = frame(lo, hi, c, u);
    vdsh_camera cam;
    memset(&cam, 0, sizeof cam);
    cam.fov_y = 60.0f;
    cam.up[1] = 1.0f;
    memcpy(cam.target, c, sizeof cam.target);
    /* w points from the centre to the eye, s to the right of the image, v
     * up in it. */
    float s[3], v[3];
    s[0] = w[2], s[1] = 0.0f, s[2] = -w[0]; /* up x w */
    float n = sqrtf(s[0] * s[0] + s[2] * s[2]);
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

void vdsh_view_fit_camera(const float lo[3], const float hi[3], vdsh_camera *out)
{
    float w[3];
    fit_direction(lo, hi, w);
    fit_along(lo, hi, w, out);
}

int vdsh_view_preferred_lights(const float lo[3], const float hi[3], int interior, float (*out)[3],
                               int max)
{
    /* A room: in bounds fractions (x, y, z), light 0 a little off centre
     * at 40% of the height, the others toward the corners, so that props
     * between them cast shadows in different directions. */
    static const float at[VDSH_VIEW_MAX_LIGHTS][3] = {
        {0.42f, 0.4f, 0.45f}, {0.2f, 0.6f, 0.78f}, {0.78f, 0.3f, 0.22f}, {0.65f, 0.75f, 0.7f}};
    /* An object: outside its bounding sphere, in the outside camera's
     * frame (toward the eye, up, across): light 0 above and to the side of
     * the eye and a little to its left, so that the side in view is lit and
     * the object shades and shadows itself visibly. */
    static const float around[VDSH_VIEW_MAX_LIGHTS][3] = {
        {1.5f, 1.5f, -0.4f}, {-1.3f, 1.2f, 1.4f}, {0.5f, 2.1f, 1.5f}, {1.6f, 0.5f, 1.2f}};
    float c[3], u[3][3];
    float r = frame(lo, hi, c, u);
    int n = 0;
    for (; n < max && n < VDSH_VIEW_MAX_LIGHTS; n++) {
        if (interior)
            for (int k = 0; k < 3; k++)
                out[n][k] = lo[k] + at[n][k] * (hi[k] - lo[k]);
        else
            place(c, u, r, around[n][0], around[n][1], around[n][2], out[n]);
    }
    return n;
}

/* ---- rays against triangles ------------------------------------------ */

/* Moller-Trumbore of the ray (o, d) against triangle a, b, c: 1 with the
 * distance, barycentrics and determinant (< 0: the back of the face), or
 * 0. The arithmetic is written once, so that the grid and the plain loop
 * compute the same bits. */
static inline int intersect(const float o[3], const float d[3], const float *a, const float *b,
                            const float *c, float *dist, float *uu, float *vv, float *det_out)
{
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
    float p[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2],
                  d[0] * e2[1] - d[1] * e2[0]};
    float det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    if (det == 0.0f)
        return 0;
    float inv = 1.0f / det;
    float u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) * inv;
    if (!(u >= 0.0f && u <= 1.0f))
        return 0;
    float v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) * inv;
    if (!(v >= 0.0f && u + v <= 1.0f))
        return 0;
    *dist = qe2 * inv;
    *uu = u;
    *vv = v;
    *det_out = det;
    return 1;
}

/* How far outside its own bounding box (per axis) a hit on a triangle with
 * these bounds may lie: rounding, not more. A nearly degenerate triangle
 * (a sliver at a sphere's pole) can pass the barycentric tests for rays
 * nowhere near it, with a meaningless distance; such hits are refused.
 * The grid files each triangle in every cell within this of its box, so
 * that it and the plain loop accept the same hits. */
static inline float hit_slack(float lo, float hi, float extent)
{
    return 1e-3f * extent + 2e-6f * fmaxf(fabsf(lo), fabsf(hi));
}

static inline float tri_extent(const float *a, const float *b, const float *c)
{
    float e = 0.0f;
    for (int k = 0; k < 3; k++)
        e = fmaxf(e, fmaxf(a[k], fmaxf(b[k], c[k])) - fminf(a[k], fminf(b[k], c[k])));
    return e;
}

/* Test triangle tri; keep it in *best when nearer (ties: lower index). */
static inline void test_triangle(const float *positions, const uint32_t *indices, uint32_t tri,
                                 const float o[3], const float d[3], float tmin,
                                 vdsh_view_hit *best)
{
    const uint32_t *ix = indices + 3 * (size_t)tri;
    const float *a = positions + 3 * (size_t)ix[0], *b = positions + 3 * (size_t)ix[1],
                *c = positions + 3 * (size_t)ix[2];
    float dist, u, v, det;
    if (!intersect(o, d, a, b, c, &dist, &u, &v, &det))
        return;
    if (!(dist >= tmin))
        return;
    if (!(dist < best->t || (dist == best->t && tri < best->triangle)))
        return;
    float ext = tri_extent(a, b, c);
    for (int k = 0; k < 3; k++) {
        float lo = fminf(a[k], fminf(b[k], c[k])), hi = fmaxf(a[k], fmaxf(b[k], c[k]));
        float p = o[k] + dist * d[k], slack = hit_slack(lo, hi, ext);
        if (!(p >= lo - slack && p <= hi + slack))
            return;
    }
    best->t = dist;
    best->u = u;
    best->v = v;
    best->triangle = tri;
    best->back = det < 0.0f;
}

int vdsh_view_trace_all(const vdsh_view_mesh *m, const float org[3], const float dir[3], float tmin,
                        vdsh_view_hit *hit)
{
    vdsh_view_hit best = {INFINITY, 0.0f, 0.0f, UINT32_MAX, 0};
    for (uint32_t t = 0; t < m->triangle_count; t++)
        test_triangle(m->positions, m->indices, t, org, dir, tmin, &best);
    if (best.triangle == UINT32_MAX)
        return 0;
    *hit = best;
    return 1;
}

/* The grid: n[0] x n[1] x n[2] cells of size cell over lo..; cell i holds
 * the triangles tris[start[i] .. start[i + 1] - 1], every triangle whose
 * bounding box (padded: tri_cells) overlaps it. */
struct vdsh_view_tracer {
    const float *positions;
    const uint32_t *indices;
    uint32_t triangle_count;
    float lo[3], hi[3], cell[3], inv_cell[3];
    int n[3];
    uint32_t *start;
    uint32_t *tris;
};

void vdsh_view_tracer_destroy(vdsh_view_tracer *t)
{
    if (!t)
        return;
    free(t->start);
    free(t->tris);
    free(t);
}

static int cell_of(const vdsh_view_tracer *g, int k, float x)
{
    float f = floorf((x - g->lo[k]) * g->inv_cell[k]);
    if (!(f >= 0.0f))
        return 0;
    return f >= (float)(g->n[k] - 1) ? g->n[k] - 1 : (int)f;
}

/* The cell range of triangle tri: its box widened by the slack a hit may
 * have (hit_slack) and a thousandth of a cell (the traversal's rounding). */
static void tri_cells(const vdsh_view_tracer *g, uint32_t tri, int c0[3], int c1[3])
{
    const uint32_t *ix = g->indices + 3 * (size_t)tri;
    const float *pa = g->positions + 3 * (size_t)ix[0], *pb = g->positions + 3 * (size_t)ix[1],
                *pc = g->positions + 3 * (size_t)ix[2];
    float ext = tri_extent(pa, pb, pc);
    for (int k = 0; k < 3; k++) {
        float lo = fminf(pa[k], fminf(pb[k], pc[k])), hi = fmaxf(pa[k], fmaxf(pb[k], pc[k]));
        float pad = 2.0f * hit_slack(lo, hi, ext) + 1e-3f * g->cell[k];
        c0[k] = cell_of(g, k, lo - pad);
        c1[k] = cell_of(g, k, hi + pad);
    }
}

/* References all triangles' cell ranges would need with cells of side h. */
static uint64_t grid_refs(vdsh_view_tracer *g)
{
    uint64_t refs = 0;
    for (uint32_t t = 0; t < g->triangle_count; t++) {
        int c0[3], c1[3];
        tri_cells(g, t, c0, c1);
        refs += (uint64_t)(c1[0] - c0[0] + 1) * (uint64_t)(c1[1] - c0[1] + 1) *
                (uint64_t)(c1[2] - c0[2] + 1);
    }
    return refs;
}

/* Each triangle into the cells its box overlaps, in triangle order:
 * without `fill`, counted in start[cell + 1]; with it, stored at
 * tris[fill[cell]++]. */
static void grid_pass(vdsh_view_tracer *g, uint32_t *fill)
{
    size_t nx = (size_t)g->n[0], nxy = nx * (size_t)g->n[1];
    for (uint32_t t = 0; t < g->triangle_count; t++) {
        int c0[3], c1[3];
        tri_cells(g, t, c0, c1);
        for (int z = c0[2]; z <= c1[2]; z++)
            for (int y = c0[1]; y <= c1[1]; y++)
                for (int x = c0[0]; x <= c1[0]; x++) {
                    size_t c = (size_t)z * nxy + (size_t)y * nx + (size_t)x;
                    if (fill)
                        g->tris[fill[c]++] = t;
                    else
                        g->start[c + 1]++;
                }
    }
}

static void grid_size(vdsh_view_tracer *g, const float ext[3], float h)
{
    for (int k = 0; k < 3; k++) {
        float n = ceilf(ext[k] / h);
        g->n[k] = n < 1.0f ? 1 : n > 512.0f ? 512 : (int)n;
        g->cell[k] = ext[k] / (float)g->n[k];
        g->inv_cell[k] = 1.0f / g->cell[k];
    }
}

vdsh_result vdsh_view_tracer_create(const vdsh_view_mesh *m, vdsh_view_tracer **out,
                                    vdsh_error *err)
{
    for (size_t i = 0; i < 3 * (size_t)m->triangle_count; i++)
        if (m->indices[i] >= m->vertex_count)
            return vdsh_failf(err, VDSH_ERR_INVALID,
                              "mesh: triangle %zu: vertex index %u not below the %u vert%s", i / 3,
                              m->indices[i], m->vertex_count, m->vertex_count == 1 ? "ex" : "ices");
    vdsh_view_tracer *g = calloc(1, sizeof *g);
    if (!g)
        return vdsh_failf(err, VDSH_ERR_OUT_OF_MEMORY, "mesh: out of memory (ray grid)");
    g->positions = m->positions;
    g->indices = m->indices;
    g->triangle_count = m->triangle_count;

    /* Bounds of the triangles' vertices, padded a little, no axis flat. */
    for (int k = 0; k < 3; k++)
        g->lo[k] = INFINITY, g->hi[k] = -INFINITY;
    for (size_t i = 0; i < 3 * (size_t)m->triangle_count; i++)
        for (int k = 0; k < 3; k++) {
            float x = m->positions[3 * (size_t)m->indices[i] + (size_t)k];
            g->lo[k] = fminf(g->lo[k], x);
            g->hi[k] = fmaxf(g->hi[k], x);
        }
    for (int k = 0; k < 3; k++)
        if (g->lo[k] < -VDSH_VIEW_MAX_COORD || g->hi[k] > VDSH_VIEW_MAX_COORD) {
            float far = fmaxf(-g->lo[k], g->hi[k]);
            vdsh_view_tracer_destroy(g);
            return vdsh_failf(err, VDSH_ERR_INVALID,
                              "mesh: a coordinate reaches %g, beyond the %g the view's float "
                              "arithmetic takes: scale the scene down",
                              (double)far, (double)VDSH_VIEW_MAX_COORD);
        }
    float longest = 0.0f;
    for (int k = 0; k < 3; k++)
        longest = fmaxf(longest, g->hi[k] - g->lo[k]);
    if (m->triangle_count && !(longest >= VDSH_VIEW_MIN_EXTENT)) {
        vdsh_view_tracer_destroy(g);
        return vdsh_failf(err, VDSH_ERR_INVALID,
                          "mesh: the scene is %g across, below the %g the view's float "
                          "arithmetic takes: scale the scene up",
                          (double)longest, (double)VDSH_VIEW_MIN_EXTENT);
    }
    for (int k = 0; k < 3; k++)
        if (!(g->lo[k] <= g->hi[k]))
            g->lo[k] = g->hi[k] = 0.0f;
    float ext[3], diag = vdsh_view_diagonal(g->lo, g->hi);
    for (int k = 0; k < 3; k++) {
        float pad = 1e-4f * diag;
        g->lo[k] -= pad;
        g->hi[k] += pad;
        ext[k] = fmaxf(g->hi[k] - g->lo[k], 1e-3f * diag);
        g->hi[k] = g->lo[k] + ext[k];
    }

    /* About two cells per triangle; coarser when big triangles would
     * need more than eight references each. */
    double target = 2.0 * (double)(m->triangle_count ? m->triangle_count : 1);
    float h = (float)cbrt((double)ext[0] * ext[1] * ext[2] / target);
    for (;;) {
        grid_size(g, ext, h);
        uint64_t refs = grid_refs(g);
        if (refs <= 8ull * m->triangle_count + 1024 ||
            (g->n[0] == 1 && g->n[1] == 1 && g->n[2] == 1)) {
            size_t cells = (size_t)g->n[0] * (size_t)g->n[1] * (size_t)g->n[2];
            g->start = calloc(cells + 1, sizeof *g->start);
            g->tris = malloc((size_t)(refs ? refs : 1) * sizeof *g->tris);
            if (!g->start || !g->tris) {
                vdsh_view_tracer_destroy(g);
                return vdsh_failf(err, VDSH_ERR_OUT_OF_MEMORY, "mesh: out of memory (ray grid)");
            }
            break;
        }
        h *= 1.5f;
    }

    /* Count, prefix sums, fill (in triangle order: each cell's list is
     * sorted, though nothing depends on it). */
    grid_pass(g, NULL);
    size_t cells = (size_t)g->n[0] * (size_t)g->n[1] * (size_t)g->n[2];
    for (size_t i = 0; i < cells; i++)
        g->start[i + 1] += g->start[i];
    uint32_t *fill = malloc(cells * sizeof *fill);
    if (!fill) {
        vdsh_view_tracer_destroy(g);
        return vdsh_failf(err, VDSH_ERR_OUT_OF_MEMORY, "mesh: out of memory (ray grid)");
    }
    memcpy(fill, g->start, cells * sizeof *fill);
    grid_pass(g, fill);
    free(fill);
    *out = g;
    return VDSH_OK;
}

int vdsh_view_trace(const vdsh_view_tracer *g, const float org[3], const float dir[3], float tmin,
                    vdsh_view_hit *hit)
{
    /* The ray's stretch inside the grid's box (slabs). */
    float t0 = tmin > 0.0f ? tmin : 0.0f, t1 = INFINITY;
    for (int k = 0; k < 3; k++) {
        if (dir[k] == 0.0f) {
            if (org[k] < g->lo[k] || org[k] > g->hi[k])
                return 0;
            continue;
        }
        float a = (g->lo[k] - org[k]) / dir[k], b = (g->hi[k] - org[k]) / dir[k];
        t0 = fmaxf(t0, fminf(a, b));
        t1 = fminf(t1, fmaxf(a, b));
    }
    if (!(t0 <= t1))
        return 0;

    /* Cell by cell (Amanatides-Woo), each boundary computed afresh from
     * the cell index so that no error accumulates. Stop once the nearest
     * hit so far lies before the current cell's far side. */
    int c[3], step[3];
    for (int k = 0; k < 3; k++) {
        c[k] = cell_of(g, k, org[k] + t0 * dir[k]);
        step[k] = dir[k] > 0.0f ? 1 : dir[k] < 0.0f ? -1 : 0;
    }
    size_t nx = (size_t)g->n[0], nxy = nx * (size_t)g->n[1];
    vdsh_view_hit best = {INFINITY, 0.0f, 0.0f, UINT32_MAX, 0};
    for (;;) {
        size_t cell = (size_t)c[2] * nxy + (size_t)c[1] * nx + (size_t)c[0];
        for (uint32_t i = g->start[cell]; i < g->start[cell + 1]; i++)
            test_triangle(g->positions, g->indices, g->tris[i], org, dir, tmin, &best);
        float next[3];
        int axis = 0;
        for (int k = 0; k < 3; k++) {
            next[k] =
                step[k] ? (g->lo[k] + (float)(c[k] + (step[k] > 0)) * g->cell[k] - org[k]) / dir[k]
                        : INFINITY;
            if (next[k] < next[axis])
                axis = k;
        }
        float exit = next[axis];
        if (best.t <= exit || exit > t1)
            break;
        c[axis] += step[axis];
        if (c[axis] < 0 || c[axis] >= g->n[axis])
            break;
    }
    if (best.triangle == UINT32_MAX)
        return 0;
    *hit = best;
    return 1;
}

/* ---- the interior test and free space -------------------------------- */

/* The free-space probes from p (vdsh_light.h): each one's first hit and
 * side, for vdsh_free_space at one clearance or several. */
typedef struct probes {
    float dist[VDSH_FREE_PROBES];
    int back[VDSH_FREE_PROBES];
} probes;

static void probe(const vdsh_view_tracer *t, const float p[3], probes *out)
{
    float dirs[VDSH_FREE_PROBES][3];
    vdsh_free_probe_dirs(dirs);
    for (int i = 0; i < VDSH_FREE_PROBES; i++) {
        vdsh_view_hit h;
        int hit = vdsh_view_trace(t, p, dirs[i], 0.0f, &h);
        out->dist[i] = hit ? h.t : INFINITY;
        out->back[i] = hit && h.back;
    }
}

/* vdsh_light.h's rule at this clearance. */
static int free_at(const vdsh_view_tracer *t, const float p[3], float clearance)
{
    probes pr;
    probe(t, p, &pr);
    return vdsh_free_space(pr.dist, pr.back, clearance);
}

int vdsh_view_free_space(const vdsh_view_tracer *t, const float p[3], float diagonal)
{
    return free_at(t, p, vdsh_free_clearance(diagonal));
}

/* Of a 9 x 7 grid of the camera's rays, how many travel farther than a
 * tenth of the diagonal before they meet a surface (or meet none). */
static int open_rays(const vdsh_view_tracer *t, const vdsh_camera *c, float diag)
{
    int open = 0;
    for (int y = 0; y < 7; y++)
        for (int x = 0; x < 9; x++) {
            float o[3], d[3];
            vdsh_camera_ray(c, 9, 7, x, y, o, d);
            vdsh_view_hit h;
            open += !vdsh_view_trace(t, o, d, 0.0f, &h) || h.t > 0.1f * diag;
        }
    return open;
}

int vdsh_view_room_camera_free(const vdsh_view_tracer *t, const float lo[3], const float hi[3],
                               vdsh_camera *out)
{
    vdsh_view_room_camera(lo, hi, out);
    float diag = vdsh_view_diagonal(lo, hi);
    /* The standard eye, then higher (over a block on the floor, the
     * Cornell box's), then across the room at the same heights; the
     * target stays. A moved eye first VDSH_VIEW_EYE_MARGIN clearances from
     * every surface (the first free one stood 0.25 units from a sphere of
     * the Cornell box, a third of the frame), then, where none is, one
     * clearance, as the standard eye. */
    static const float up[5] = {0.28f, 0.4f, 0.55f, 0.7f, 0.85f};
    static const float across[3] = {0.0f, -0.3f, 0.3f};
    int ax = hi[0] - lo[0] >= hi[2] - lo[2] ? 0 : 2, other = 2 - ax;
    float e1 = hi[1] - lo[1], eo = hi[other] - lo[other], co = 0.5f * (lo[other] + hi[other]);
    const float clearance = vdsh_free_clearance(diag);
    for (int pass = 0; pass < 2; pass++)
        for (int j = 0; j < 3; j++)
            for (int i = pass && !j; i < 5; i++) {
                int moved = i || j;
                vdsh_camera c = *out;
                c.eye[1] = lo[1] + up[i] * e1;
                c.eye[other] = co + (0.05f + across[j]) * eo;
                float need = moved && !pass ? VDSH_VIEW_EYE_MARGIN * clearance : clearance;
                if (free_at(t, c.eye, need) && open_rays(t, &c, diag) >= 48) {
                    *out = c;
                    return moved;
                }
            }
    return 0;
}

float vdsh_view_front_share(const vdsh_view_tracer *t, const vdsh_view_mesh *m, const float lo[3],
                            const float hi[3])
{
    vdsh_camera room;
    vdsh_view_room_camera_free(t, lo, hi, &room);
    /* Hits up to this close are the surface the eye stands on (a flat
     * scene) or rounding; they do not count. */
    float tmin = nextafterf(1e-5f * vdsh_view_diagonal(lo, hi), INFINITY);
    int front = 0;
    for (int i = 0; i < VDSH_VIEW_RAYS; i++) {
        /* A Fibonacci sphere: nearly uniform directions, the same every
         * time. */
        float z = 1.0f - (2.0f * (float)i + 1.0f) / (float)VDSH_VIEW_RAYS;
        float rho = sqrtf(fmaxf(0.0f, 1.0f - z * z)), ph = 2.39996323f * (float)i;
        float d[3] = {rho * cosf(ph), z, rho * sinf(ph)};
        vdsh_view_hit h;
        if (!vdsh_view_trace(t, room.eye, d, tmin, &h))
            continue;
        /* The interpolated vertex normal at the hit. */
        const uint32_t *tri = m->indices + 3 * (size_t)h.triangle;
        const float *na = m->normals + 3 * (size_t)tri[0], *nb = m->normals + 3 * (size_t)tri[1],
                    *nc = m->normals + 3 * (size_t)tri[2];
        float n[3];
        for (int k = 0; k < 3; k++)
            n[k] = (1.0f - h.u - h.v) * na[k] + h.u * nb[k] + h.v * nc[k];
        front += n[0] * d[0] + n[1] * d[1] + n[2] * d[2] < 0.0f;
    }
    return (float)front / (float)VDSH_VIEW_RAYS;
}

/* ---- what a light lights in the default frame ------------------------- */

/* The check frame's surface points: first hits, normals turned toward
 * the eye. */
typedef struct frame_pts {
    uint32_t n, pixels;
    float (*p)[3];
    float (*nrm)[3];
} frame_pts;

static int frame_points(const vdsh_view_tracer *t, const vdsh_view_mesh *m, const vdsh_camera *c,
                        int width, int height, frame_pts *out)
{
    size_t pixels = (size_t)width * (size_t)height;
    out->n = 0;
    out->pixels = (uint32_t)pixels;
    out->p = malloc(pixels * sizeof *out->p + 1);
    out->nrm = malloc(pixels * sizeof *out->nrm + 1);
    if (!out->p || !out->nrm) {
        free(out->p);
        free(out->nrm);
        out->p = out->nrm = NULL;
        return 0;
    }
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            float o[3], d[3];
            vdsh_view_hit h;
            vdsh_camera_ray(c, width, height, x, y, o, d);
            if (!vdsh_view_trace(t, o, d, 0.0f, &h))
                continue;
            const uint32_t *tri = m->indices + 3 * (size_t)h.triangle;
            const float *na = m->normals + 3 * (size_t)tri[0],
                        *nb = m->normals + 3 * (size_t)tri[1],
                        *nc = m->normals + 3 * (size_t)tri[2];
            float n[3], dot = 0.0f;
            for (int k = 0; k < 3; k++) {
                n[k] = (1.0f - h.u - h.v) * na[k] + h.u * nb[k] + h.v * nc[k];
                dot += n[k] * d[k];
            }
            float *p = out->p[out->n], *q = out->nrm[out->n];
            for (int k = 0; k < 3; k++) {
                p[k] = o[k] + h.t * d[k];
                q[k] = dot > 0.0f ? -n[k] : n[k];
            }
            out->n++;
        }
    return 1;
}

static void frame_free(frame_pts *f)
{
    free(f->p);
    free(f->nrm);
    f->p = f->nrm = NULL;
}

/* per_hit: shares of the pixels that see a surface (an object's, which
 * fills part of its frame), else of the whole frame (an interior's). */
static void shares_of(const vdsh_view_tracer *t, const frame_pts *f, const float L[3],
                      float diagonal, int per_hit, float *lit, float *shadowed)
{
    const float eps = 1e-4f * diagonal;
    uint32_t a = 0, b = 0;
    for (uint32_t i = 0; i < f->n; i++) {
        const float *p = f->p[i], *n = f->nrm[i];
        float d[3] = {L[0] - p[0], L[1] - p[1], L[2] - p[2]};
        if (n[0] * d[0] + n[1] * d[1] + n[2] * d[2] <= 0.0f)
            continue;
        float dist = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(dist > 2.0f * eps)) {
            a++;
            continue;
        }
        for (int k = 0; k < 3; k++)
            d[k] /= dist;
        vdsh_view_hit h;
        if (vdsh_view_trace(t, p, d, eps, &h) && h.t < dist - eps)
            b++;
        else
            a++;
    }
    const uint32_t of = per_hit ? f->n : f->pixels;
    *lit = of ? (float)a / (float)of : 0.0f;
    *shadowed = of ? (float)b / (float)of : 0.0f;
}

void vdsh_view_light_shares(const vdsh_view_tracer *t, const vdsh_view_mesh *m,
                            const vdsh_camera *c, int width, int height, const float light[3],
                            float diagonal, float *lit, float *shadowed)
{
    frame_pts f;
    *lit = *shadowed = 0.0f;
    if (width <= 0 || height <= 0 || !frame_points(t, m, c, width, height, &f))
        return;
    shares_of(t, &f, light, diagonal, 0, lit, shadowed);
    frame_free(&f);
}

/* ---- default lights in free space ------------------------------------ */

/* The 26 directions toward a cube's faces, edges and corners, unit. */
static int nudge_dirs(float out[26][3])
{
    int n = 0;
    for (int ones = 1; ones <= 3; ones++)
        for (int z = -1; z <= 1; z++)
            for (int y = -1; y <= 1; y++)
                for (int x = -1; x <= 1; x++) {
                    if (abs(x) + abs(y) + abs(z) != ones)
                        continue;
                    float l = sqrtf((float)ones);
                    out[n][0] = (float)x / l;
                    out[n][1] = (float)y / l;
                    out[n][2] = (float)z / l;
                    n++;
                }
    return n;
}

static int inside(const float p[3], const float lo[3], const float hi[3])
{
    return p[0] > lo[0] && p[0] < hi[0] && p[1] > lo[1] && p[1] < hi[1] && p[2] > lo[2] &&
           p[2] < hi[2];
}

typedef struct cand {
    float d2;
    uint32_t k;
} cand;

static int cmp_cand(const void *a, const void *b)
{
    const cand *x = a, *y = b;
    if (x->d2 != y->d2)
        return x->d2 < y->d2 ? -1 : 1;
    return (x->k > y->k) - (x->k < y->k);
}

enum { FALLBACK_CANDIDATES = 4096 };

/* A position in free space near p0, into out; 1, or 0 when none found.
 * p0 itself when it is free; else, inside lo..hi (an interior's bounds,
 * an object's light region), on rings of 26 directions around it,
 * the nearest position VDSH_VIEW_LIGHT_MARGIN clearances from every
 * surface within VDSH_VIEW_MARGIN_REACH clearances of p0, else the
 * nearest free one (a light moved just out of a solid lands one
 * clearance from its face: the hard case of every precomputed shadow,
 * which the default frame should not show). */
static int find_free(const vdsh_view_tracer *t, const float p0[3], const float lo[3],
                     const float hi[3], float diagonal, uint32_t *trials, float out[3])
{
    (*trials)++;
    if (vdsh_view_free_space(t, p0, diagonal)) {
        memcpy(out, p0, 3 * sizeof(float));
        return 1;
    }
    float dirs[26][3];
    int nd = nudge_dirs(dirs);
    const float clearance = vdsh_free_clearance(diagonal), h = 0.5f * clearance;
    const int rings = (int)ceilf(0.5f * diagonal / h);
    const int reach = (int)(VDSH_VIEW_MARGIN_REACH / 0.5f);
    /* The first pass's positions free at one clearance (1 no, 2 yes, 0
     * not probed), for the second: each position probed once. Without
     * memory for it, probed again. */
    uint8_t *seen = calloc((size_t)reach * (size_t)nd + 1, 1);
    for (int pass = 0; pass < 2; pass++) {
        const int last = pass ? rings : reach;
        for (int k = 1; k <= last; k++)
            for (int j = 0; j < nd; j++) {
                float p[3];
                for (int a = 0; a < 3; a++)
                    p[a] = p0[a] + (float)k * h * dirs[j][a];
                if (!inside(p, lo, hi))
                    continue;
                (*trials)++;
                uint8_t *at = seen && k <= reach ? &seen[(size_t)(k - 1) * nd + (size_t)j] : NULL;
                int ok;
                if (pass && at && *at) {
                    ok = *at == 2;
                } else {
                    probes pr;
                    probe(t, p, &pr);
                    ok = vdsh_free_space(pr.dist, pr.back,
                                         pass ? clearance : VDSH_VIEW_LIGHT_MARGIN * clearance);
                    if (!pass && at)
                        *at = (uint8_t)(1 + vdsh_free_space(pr.dist, pr.back, clearance));
                }
                if (ok) {
                    free(seen);
                    memcpy(out, p, sizeof p);
                    return 1;
                }
            }
    }
    free(seen);
    /* Nothing near: the seeded candidates in the bounds, nearest first. */
    cand *c = malloc(FALLBACK_CANDIDATES * sizeof *c);
    if (!c)
        return 0;
    for (uint32_t k = 0; k < FALLBACK_CANDIDATES; k++) {
        float p[3];
        vdsh_light_candidate(lo, hi, 1, k, p);
        c[k].d2 = 0.0f;
        for (int a = 0; a < 3; a++)
            c[k].d2 += (p[a] - p0[a]) * (p[a] - p0[a]);
        c[k].k = k;
    }
    qsort(c, FALLBACK_CANDIDATES, sizeof *c, cmp_cand);
    int found = 0;
    for (int i = 0; i < FALLBACK_CANDIDATES && !found; i++) {
        float p[3];
        vdsh_light_candidate(lo, hi, 1, c[i].k, p);
        (*trials)++;
        if (vdsh_view_free_space(t, p, diagonal)) {
            memcpy(out, p, sizeof p);
            found = 1;
        }
    }
    free(c);
    return found;
}

int vdsh_view_is_free(const void *ctx, const float p[3])
{
    const vdsh_view_free_ctx *c = ctx;
    return vdsh_view_free_space(c->t, p, c->diagonal);
}

/* An object's box for its lights (vdsh_view_compute): the light region
 * rlo..rhi, but along an axis where it is thinner than the clearance (no
 * room for a light) the bounds grown there by VDSH_REGION_GROW of the
 * diagonal, as around a closed object; a flat object's (flat: its
 * free-space probes pass through it and leave its region its bounds,
 * where a light can stand behind it) those grown bounds on every axis. */
static void light_box(const float rlo[3], const float rhi[3], const float lo[3], const float hi[3],
                      float diag, int flat, float blo[3], float bhi[3])
{
    const float g = VDSH_REGION_GROW * diag;
    for (int k = 0; k < 3; k++) {
        const int grow = flat || rhi[k] - rlo[k] < vdsh_free_clearance(diag);
        blo[k] = grow ? lo[k] - g : rlo[k];
        bhi[k] = grow ? hi[k] + g : rhi[k];
    }
}

/* p pulled into lo..hi, VDSH_VIEW_REGION_INSET of the extent inside each
 * face: per axis, or with c (the box's centre: a flat object's) along the
 * line to c, so that it stays on its side of any plane through c. */
static void into_region(float p[3], const float lo[3], const float hi[3], const float *c)
{
    float s = 1.0f;
    for (int k = 0; k < 3; k++) {
        const float in = VDSH_VIEW_REGION_INSET * (hi[k] - lo[k]);
        if (!c) {
            p[k] = fminf(fmaxf(p[k], lo[k] + in), hi[k] - in);
            continue;
        }
        const float d = p[k] - c[k], room = d > 0.0f ? hi[k] - in - c[k] : c[k] - (lo[k] + in);
        if (fabsf(d) > room)
            s = fminf(s, room / fabsf(d));
    }
    for (int k = 0; c && k < 3; k++)
        p[k] = c[k] + s * (p[k] - c[k]);
}

/* The frame rule (vdsh_view_compute): an interior's lights, found in
 * free space near the preferred positions, replaced where they do not
 * light what the camera sees. */
typedef struct scored {
    float p[3];
    float lit, sh;
    int free, pref; /* pref: the preferred light's index, or -1 */
} scored;

/* A light lights the frame when it lights its share of it, and more
 * than it shadows (a light behind a wall, seen through a door, shadows
 * most of the frame). 0: a preferred light that lights the frame (kept:
 * the room's own lights, shadows or not); 1: a seeded one that lights it
 * and shadows the share; 2: one that lights it; 3: the rest. */
static int tier(const scored *c)
{
    int lights = c->lit >= VDSH_VIEW_MIN_SHARE && c->lit >= c->sh;
    if (c->pref >= 0)
        return lights ? 0 : 3;
    return lights && c->sh >= VDSH_VIEW_MIN_SHARE ? 1 : lights ? 2 : 3;
}

/* Candidate c as out's light k (its preferred position v's, or its own). */
static void take_light(vdsh_view *out, int k, const scored *c, const vdsh_view *v)
{
    memcpy(out->lights[k], c->p, sizeof c->p);
    out->light_free[k] = c->free;
    out->light_lit[k] = c->lit, out->light_shadowed[k] = c->sh;
    memcpy(out->preferred[k], c->pref >= 0 ? v->preferred[c->pref] : c->p,
           sizeof out->preferred[k]);
}

static vdsh_result choose_lights(const vdsh_view_tracer *t, const vdsh_view_mesh *m, vdsh_view *v,
                                 float diag)
{
    frame_pts f;
    if (!frame_points(t, m, &v->camera, VDSH_VIEW_CHECK_W, VDSH_VIEW_CHECK_H, &f))
        return VDSH_ERR_OUT_OF_MEMORY;
    scored c[VDSH_VIEW_MAX_LIGHTS + VDSH_VIEW_LIGHT_POOL];
    int n = 0, good = 0;
    for (int i = 0; i < v->light_count; i++, n++) {
        memcpy(c[n].p, v->lights[i], sizeof c[n].p);
        c[n].free = v->light_free[i], c[n].pref = i;
        shares_of(t, &f, c[n].p, diag, 0, &c[n].lit, &c[n].sh);
        good += tier(&c[n]) == 0;
    }
    /* Too few light the frame: seeded candidates, until enough do; first
     * those VDSH_VIEW_LIGHT_MARGIN clearances from every surface, as
     * find_free moves a light (one clearance from a wall is the hard case
     * of every precomputed shadow, which the default frame should not
     * show), then the others in free space. */
    const float clearance = vdsh_free_clearance(diag);
    const float margin = VDSH_VIEW_LIGHT_MARGIN * clearance;
    uint8_t room[VDSH_VIEW_LIGHT_POOL]; /* the first pass's: 2 at the margin, 1 free, 0 not */
    for (int pass = 0; pass < 2; pass++)
        for (uint32_t k = 0; good < v->light_count && k < VDSH_VIEW_LIGHT_POOL; k++) {
            float p[3];
            vdsh_light_candidate(v->region_min, v->region_max, 2, k, p);
            v->pool_tried++;
            if (!pass) { /* the second runs only once the first tried all */
                probes pr;
                probe(t, p, &pr);
                room[k] = vdsh_free_space(pr.dist, pr.back, margin)      ? 2
                          : vdsh_free_space(pr.dist, pr.back, clearance) ? 1
                                                                         : 0;
            }
            if (room[k] != 2 - pass)
                continue;
            memcpy(c[n].p, p, sizeof p);
            c[n].free = 1, c[n].pref = -1;
            shares_of(t, &f, p, diag, 0, &c[n].lit, &c[n].sh);
            good += tier(&c[n]) == 1;
            n++;
        }
    frame_free(&f);
    /* Tiers in candidate order; the last by the share lit (a stable
     * selection: ties keep the earlier). */
    uint8_t taken[VDSH_VIEW_MAX_LIGHTS + VDSH_VIEW_LIGHT_POOL] = {0};
    vdsh_view out = *v;
    int k = 0;
    for (int tr = 0; tr < 3; tr++)
        for (int i = 0; i < n && k < v->light_count; i++)
            if (!taken[i] && tier(&c[i]) == tr) {
                taken[i] = 1;
                take_light(&out, k++, &c[i], v);
            }
    for (; k < v->light_count; k++) {
        int best = -1;
        for (int i = 0; i < n; i++)
            if (!taken[i] && (best < 0 || c[i].lit > c[best].lit))
                best = i;
        taken[best] = 1;
        take_light(&out, k, &c[best], v);
    }
    *v = out;
    return VDSH_OK;
}

/* An object's lights pulled into a light region of its bounds (not
 * grown: bounds that hold free space) can stand behind its end faces:
 * the 2CylinderEngine's light 0, clamped per axis to the bounds' far
 * corner, stood inside its end cap, on the side away from the eye, and
 * lit 7% of what the camera sees of it and shadowed 27%. A light that
 * lights less than VDSH_VIEW_MIN_SHARE of the pixels that see the object,
 * or less than it shadows, tries its preferred position raw[i] pulled
 * into the bounds grown as around a closed object (light_box, every axis)
 * instead, and takes it when that one lights the frame so; the others are
 * left as they were. */
static vdsh_result object_lights(const vdsh_view_tracer *t, const vdsh_view_mesh *m, vdsh_view *v,
                                 float diag, float region_diag, int flat, const float *c,
                                 const float (*raw)[3])
{
    frame_pts f;
    if (!frame_points(t, m, &v->camera, VDSH_VIEW_CHECK_W, VDSH_VIEW_CHECK_H, &f))
        return VDSH_ERR_OUT_OF_MEMORY;
    float glo[3], ghi[3];
    light_box(v->region_min, v->region_max, v->bounds_min, v->bounds_max, region_diag, 1, glo, ghi);
    for (int i = 0; i < v->light_count; i++) {
        scored a = {{0}, 0, 0, 0, i};
        shares_of(t, &f, v->lights[i], diag, 1, &a.lit, &a.sh);
        if (tier(&a) == 0)
            continue;
        scored b = {{0}, 0, 0, 0, i};
        float q[3];
        memcpy(q, raw[i], sizeof q);
        into_region(q, glo, ghi, flat ? c : NULL);
        b.free = find_free(t, q, glo, ghi, diag, &v->light_trials, b.p);
        if (!b.free)
            memcpy(b.p, q, sizeof q);
        shares_of(t, &f, b.p, diag, 1, &b.lit, &b.sh);
        if (tier(&b) != 0)
            continue;
        memcpy(v->lights[i], b.p, sizeof b.p);
        memcpy(v->preferred[i], q, sizeof q);
        v->light_free[i] = b.free;
    }
    frame_free(&f);
    return VDSH_OK;
}

/* An object's light 0 (vdsh-view's one light) stays in the light region
 * the bake trained on, and there it can face little of what the fit
 * camera sees: the fandisk's region is its bounds, thin across the face in
 * view, and the light found free behind it faced 23% of the object's
 * pixels (the default frame dark but a notch); Wuson's 7% (black). When
 * light 0 faces less than VDSH_VIEW_KEY_FACING of the pixels that see the
 * object (lit or shadowed: N . (L - p) > 0), the camera is fitted along w
 * turned about the vertical by 45, -45, 90, -90, 135, -135 and 180
 * degrees in turn, and the first turn whose frame light 0 faces so is
 * kept (the nearest to the fixed direction); when none does, the one it
 * faces most (the first on a tie; none when no turn beats w). The lights
 * stay; object_lights, where it runs, checks them in the camera kept. Returns
 * VDSH_ERR_OUT_OF_MEMORY or VDSH_OK. */
static vdsh_result face_key_light(const vdsh_view_tracer *t, const vdsh_view_mesh *m, vdsh_view *v,
                                  float diag, const float w[3])
{
#define H_ 0.70710678f /* cos and sin of the turns: 0, 45, -45, 90, -90, 135, -135, 180 */
    static const float cs[8][2] = {{1, 0},  {H_, H_},  {H_, -H_},  {0, 1},
                                   {0, -1}, {-H_, H_}, {-H_, -H_}, {-1, 0}};
#undef H_
    float best = -1.0f;
    vdsh_camera keep = v->camera;
    for (int turn = 0; turn < 8; turn++) {
        const float ca = cs[turn][0], sa = cs[turn][1];
        const float wt[3] = {w[0] * ca - w[2] * sa, w[1], w[0] * sa + w[2] * ca};
        vdsh_camera cam = v->camera;
        if (turn)
            fit_along(v->bounds_min, v->bounds_max, wt, &cam);
        frame_pts f;
        if (!frame_points(t, m, &cam, VDSH_VIEW_CHECK_W, VDSH_VIEW_CHECK_H, &f))
            return VDSH_ERR_OUT_OF_MEMORY;
        float lit, sh;
        shares_of(t, &f, v->lights[0], diag, 1, &lit, &sh);
        frame_free(&f);
        if (lit + sh >= VDSH_VIEW_KEY_FACING) {
            keep = cam;
            break;
        }
        if (lit + sh > best)
            best = lit + sh, keep = cam;
    }
    v->camera = v->fit = keep;
    return VDSH_OK;
}

/* Whether every vertex lies on one plane (a single triangle, a quad, a
 * flat panel), within VDSH_VIEW_FLAT_SHARE of the diagonal; then *n is its unit
 * normal toward the front: the side the vertex normals face on the whole
 * (the winding normals where those cancel). 0 also when no triangle has
 * an area or the sides cancel. */
static int flat_front(const vdsh_view_mesh *m, float diag, float n[3])
{
    /* the plane of the triangle of largest area */
    double best = 0.0, pn[3] = {0, 0, 0};
    const float *p0 = NULL;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const float *a = m->positions + 3 * (size_t)m->indices[3 * (size_t)t];
        const float *b = m->positions + 3 * (size_t)m->indices[3 * (size_t)t + 1];
        const float *c = m->positions + 3 * (size_t)m->indices[3 * (size_t)t + 2];
        double e1[3], e2[3], x[3];
        for (int k = 0; k < 3; k++)
            e1[k] = (double)b[k] - a[k], e2[k] = (double)c[k] - a[k];
        x[0] = e1[1] * e2[2] - e1[2] * e2[1];
        x[1] = e1[2] * e2[0] - e1[0] * e2[2];
        x[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double l = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        if (l > best) {
            best = l;
            for (int k = 0; k < 3; k++)
                pn[k] = x[k] / l;
            p0 = a;
        }
    }
    if (!p0)
        return 0;
    double side = 0.0, wind = 0.0;
    for (uint32_t i = 0; i < m->vertex_count; i++) {
        const float *q = m->positions + 3 * (size_t)i;
        double d = 0.0;
        for (int k = 0; k < 3; k++)
            d += ((double)q[k] - p0[k]) * pn[k];
        if (fabs(d) > VDSH_VIEW_FLAT_SHARE * diag)
            return 0;
        if (m->normals)
            for (int k = 0; k < 3; k++)
                side += (double)m->normals[3 * (size_t)i + (size_t)k] * pn[k];
    }
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const float *a = m->positions + 3 * (size_t)m->indices[3 * (size_t)t];
        const float *b = m->positions + 3 * (size_t)m->indices[3 * (size_t)t + 1];
        const float *c = m->positions + 3 * (size_t)m->indices[3 * (size_t)t + 2];
        double e1[3], e2[3];
        for (int k = 0; k < 3; k++)
            e1[k] = (double)b[k] - a[k], e2[k] = (double)c[k] - a[k];
        wind += (e1[1] * e2[2] - e1[2] * e2[1]) * pn[0] + (e1[2] * e2[0] - e1[0] * e2[2]) * pn[1] +
                (e1[0] * e2[1] - e1[1] * e2[0]) * pn[2];
    }
    double sign = side != 0.0 ? side : wind;
    if (sign == 0.0)
        return 0;
    for (int k = 0; k < 3; k++)
        n[k] = (float)(sign > 0.0 ? pn[k] : -pn[k]);
    return 1;
}

/* x mirrored through the plane through c with unit normal n. */
static void mirror(float x[3], const float c[3], const float n[3])
{
    float d = 0.0f;
    for (int k = 0; k < 3; k++)
        d += (x[k] - c[k]) * n[k];
    for (int k = 0; k < 3; k++)
        x[k] -= 2.0f * d * n[k];
}

vdsh_result vdsh_view_compute(const vdsh_view_mesh *m, vdsh_view *out, vdsh_error *err)
{
    vdsh_view_tracer *t = NULL;
    vdsh_result r = vdsh_view_tracer_create(m, &t, err);
    if (r != VDSH_OK)
        return r;
    vdsh_view v;
    memset(&v, 0, sizeof v);
    vdsh_view_bounds(m->positions, m->vertex_count, v.bounds_min, v.bounds_max);
    const float *lo = v.bounds_min, *hi = v.bounds_max;
    v.front_share = vdsh_view_front_share(t, m, lo, hi);
    v.interior = v.front_share >= VDSH_VIEW_INTERIOR_SHARE;
    const float diag = vdsh_view_diagonal(lo, hi);
    /* A flat object's fit camera on its back side (a triangle facing away
     * from the fixed direction): the view mirrored through the plane, eye
     * and lights alike, so that it sees the front lit as the fit view
     * would. Nearly vertical once mirrored: the eye along the normal. */
    float fn[3] = {0, 0, 0}, w[3], c[3];
    int flip = 0;
    fit_direction(lo, hi, w);
    const int flat = flat_front(m, diag, fn);
    if (flat && w[0] * fn[0] + w[1] * fn[1] + w[2] * fn[2] < 0.0f) {
        flip = 1;
        mirror(w, (float[3]){0, 0, 0}, fn);
        if (w[0] * w[0] + w[2] * w[2] < 0.01f)
            memcpy(w, fn, sizeof w);
    }
    /* ... and at most VDSH_VIEW_FLAT_ANGLE from its normal: the fixed
     * direction saw a panel facing across the longest horizontal axis 66
     * degrees off its normal, and a tilted quad nearly edge-on (a line);
     * turned toward the normal in the plane of the two, its azimuth kept. */
    const float cw = w[0] * fn[0] + w[1] * fn[1] + w[2] * fn[2];
    const float cmax = cosf(VDSH_VIEW_FLAT_ANGLE * 3.14159265358979f / 180.0f);
    if (flat && cw < cmax) {
        float tn[3], tl = 0.0f;
        for (int k = 0; k < 3; k++)
            tn[k] = w[k] - cw * fn[k], tl += tn[k] * tn[k];
        tl = sqrtf(tl);
        const float smax = sqrtf(1.0f - cmax * cmax);
        for (int k = 0; k < 3; k++)
            w[k] = cmax * fn[k] + smax * tn[k] / tl;
        if (w[0] * w[0] + w[2] * w[2] < 0.01f)
            memcpy(w, fn, sizeof w);
    }
    fit_along(lo, hi, w, &v.fit);
    if (!v.interior)
        v.camera = v.fit;
    else
        vdsh_view_room_camera_free(t, lo, hi, &v.camera);
    flip = flip && !v.interior;
    v.light_count =
        vdsh_view_preferred_lights(lo, hi, v.interior, v.preferred, VDSH_VIEW_MAX_LIGHTS);
    for (int k = 0; k < 3; k++)
        c[k] = 0.5f * (lo[k] + hi[k]);
    for (int i = 0; flip && i < v.light_count; i++)
        mirror(v.preferred[i], c, fn);
    /* A flat object's lights on its front, the side the camera sees, and
     * a quarter of the diagonal off its plane at least: the places around
     * the bounds put light 0 (vdsh-view's one light) behind a panel facing
     * across the longest horizontal axis (a triangle in z = 0 facing +z:
     * the default frame black), mirrored or not, and a tilted one's light
     * so near the plane that the search for free space (find_free) took
     * one behind it. */
    for (int i = 0; flat && !v.interior && i < v.light_count; i++) {
        float d = 0.0f;
        for (int k = 0; k < 3; k++)
            d += (v.preferred[i][k] - c[k]) * fn[k];
        if (d < 0.0f)
            mirror(v.preferred[i], c, fn), d = -d;
        const float off = 0.25f * diag;
        for (int k = 0; d < off && k < 3; k++)
            v.preferred[i][k] += (off - d) * fn[k];
    }
    /* The light region as the bake computes it (the bake's diagonal, so
     * the same clearance): an object's lights inside it, where the bake's
     * fit was made for them. */
    vdsh_view_free_ctx rc = {t, vdsh_free_diagonal(lo, hi)};
    memcpy(v.region_min, lo, sizeof v.region_min);
    memcpy(v.region_max, hi, sizeof v.region_max);
    v.region_given = m->light_region != NULL;
    if (v.region_given) { /* the user's (the file's lreg): as given, a room's too */
        memcpy(v.region_min, m->light_region, sizeof v.region_min);
        memcpy(v.region_max, m->light_region + 3, sizeof v.region_max);
        v.region_grown = 1;
    } else if (!v.interior) /* a room's lights stay in its bounds: no probes spent */
        v.region_grown =
            vdsh_light_region(lo, hi, vdsh_view_is_free, &rc, v.region_min, v.region_max, NULL);
    float blo[3], bhi[3];
    light_box(v.region_min, v.region_max, lo, hi, rc.diagonal, flat && !v.region_given, blo, bhi);
    /* a room's lights in its bounds, or in the region given (the frame
     * rule's seeded candidates too: choose_lights) */
    const float *slo = v.interior ? v.region_min : blo, *shi = v.interior ? v.region_max : bhi;
    float raw[VDSH_VIEW_MAX_LIGHTS][3];
    memcpy(raw, v.preferred, sizeof raw);
    for (int i = 0; (!v.interior || v.region_given) && i < v.light_count; i++)
        into_region(v.preferred[i], slo, shi, flat && !v.interior ? c : NULL);
    for (int i = 0; i < v.light_count; i++) {
        v.light_free[i] =
            find_free(t, v.preferred[i], slo, shi, diag, &v.light_trials, v.lights[i]);
        if (!v.light_free[i])
            memcpy(v.lights[i], v.preferred[i], sizeof v.lights[i]);
    }
    if ((v.interior && choose_lights(t, m, &v, diag) != VDSH_OK) ||
        (!v.interior && !flat && v.light_count && face_key_light(t, m, &v, diag, w) != VDSH_OK) ||
        (!v.interior && !v.region_given && !v.region_grown &&
         object_lights(t, m, &v, diag, rc.diagonal, flat, c, (const float(*)[3])raw) != VDSH_OK)) {
        vdsh_view_tracer_destroy(t);
        return vdsh_failf(err, VDSH_ERR_OUT_OF_MEMORY, "out of memory for the default lights");
    }
    vdsh_view_tracer_destroy(t);
    *out = v;
    return VDSH_OK;
}

void vdsh_view_file_mesh(const vdsh_file *f, float region[6], vdsh_view_mesh *out)
{
    memcpy(region, f->light_box.min, 3 * sizeof *region);
    memcpy(region + 3, f->light_box.max, 3 * sizeof *region);
    *out = (vdsh_view_mesh){f->positions,
                            f->normals,
                            f->indices,
                            f->header.vertex_count,
                            f->header.triangle_count,
                            f->has_light_box ? region : NULL};
}
