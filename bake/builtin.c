/*
 * builtin.c - the procedural "paper room" (builtin:room): a closed room of
 * 19 x 6 x 19 m like the scene of Pranckevicius (ShaderX3, 2004), with
 * three boxes (one stacked on another, one turned about y), three
 * floor-to-ceiling pillars and a sphere.
 *
 * Built like a game level: every face has its own vertices (hard edges,
 * nothing welded across faces or objects); only the sphere is smooth, its
 * triangles sharing vertices. Faces are coarse; the receiver density comes
 * from vb_mesh_refine: at a maximum edge of 0.2 m this room gives 58,007
 * receivers (the paper's had 54,500).
 * Faces nobody can see are left out: box bottoms resting on the floor or
 * on another box, pillar ends in the floor and ceiling. Their vertices
 * would lie inside other surfaces and bake to zero distance.
 *
 * Why the faces are lattices rather than two-triangle quads: the shell
 * holds over 90% of the receivers, and how many vertices longest-edge
 * bisection produces depends on the shape and size of the starting
 * triangles. A quad cut along its diagonal refines into right isosceles
 * triangles: 50 or (one level off) 90 vertices per m^2 at 0.2 m, which
 * would give the bare shell 100,000 receivers. Near-equilateral triangles
 * whose edges sit just under 0.2 * 2^k m refine to about 46. The lattice
 * sizes below are chosen that way (floor and ceiling edges 3.17/3.14 m,
 * walls 0.79/0.78 m, pillar sides 1.2/0.72 m), which keeps the room at the
 * paper's receiver count with this layout.
 *
 * Coordinates: metres, y up, floor at y = 0, ceiling at y = 6, walls at
 * x, z = +-9.5. All faces are wound counter-clockwise seen from the side
 * their normal points to (into the room for the room's shell).
 * Deterministic: plain arithmetic on constants, no data files.
 */
#include "mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define ROOM_HALF 9.5f
#define ROOM_HEIGHT 6.0f

/* Lattices (columns x rows, see add_panel). Walls run their columns along
 * the wall. */
#define FLOOR_COLS 6
#define FLOOR_ROWS 7
#define WALL_COLS 24
#define WALL_ROWS 9
#define PILLAR_COLS 5    /* along the pillar's height */
#define PILLAR_ROWS 1

/* Icosahedron subdivided twice: 320 triangles. */
#define SPHERE_LEVELS 2

/* Room for the whole of builtin:room (it has 1,518 vertices and 2,428
 * triangles; test_mesh checks the counts). The builder's arrays grow. */
enum {
    MAX_VERTICES = 4096,
    MAX_TRIANGLES = 4096,
    MAX_LATTICE = 64,
    SPHERE_MAX_VERTICES = 162,
    SPHERE_MAX_TRIANGLES = 320
};

typedef struct room_builder {
    vb_mesh *m;
    uint32_t vertex_cap, triangle_cap;  /* of m's arrays; they grow as needed */
    int failed;                         /* out of memory: stop adding */
    /* The variants' turned objects: a vertex p is placed at
     * (tx + c p.x + s p.z, p.y, tz - s p.x + c p.z). Off for builtin:room. */
    int turned;
    float c, s, tx, tz;
} room_builder;

static int grow(void **array, uint32_t *cap, size_t item)
{
    uint32_t want = *cap ? 2 * *cap : 1024;
    void *p = want > *cap ? realloc(*array, (size_t)want * item) : NULL;
    if (!p)
        return 0;
    *array = p;
    *cap = want;
    return 1;
}

static uint32_t add_vertex(room_builder *b, const float p[3])
{
    vb_mesh *m = b->m;
    if (m->vertex_count == b->vertex_cap) {
        void *a = m->positions;
        uint32_t cap = b->vertex_cap;
        if (b->failed || cap > UINT32_MAX / 2 || !grow(&a, &cap, 3 * sizeof(float))) {
            b->failed = 1;
            return 0;
        }
        m->positions = a;
        b->vertex_cap = cap;
    }
    float *q = m->positions + 3 * (size_t)m->vertex_count;
    memcpy(q, p, 3 * sizeof(float));
    if (b->turned) {
        q[0] = b->tx + b->c * p[0] + b->s * p[2];
        q[2] = b->tz - b->s * p[0] + b->c * p[2];
    }
    return m->vertex_count++;
}

static void add_triangle(room_builder *b, uint32_t i0, uint32_t i1, uint32_t i2)
{
    vb_mesh *m = b->m;
    if (m->triangle_count == b->triangle_cap) {
        void *a = m->indices;
        uint32_t cap = b->triangle_cap;
        if (b->failed || cap > UINT32_MAX / 2 || !grow(&a, &cap, 3 * sizeof(uint32_t)))
            b->failed = 1;
        else {
            m->indices = a;
            b->triangle_cap = cap;
        }
    }
    if (b->failed)
        return;
    uint32_t *t = m->indices + 3 * (size_t)m->triangle_count++;
    t[0] = i0;
    t[1] = i1;
    t[2] = i2;
}

/* Where a lattice point (x along the panel's width, t along its height)
 * lies: o + x u + t v for builtin:room's panels; for the variants'
 * axis-aligned rectangles, each coordinate separately, with the borders
 * (x = 0 or W, t = 0 or H) exactly the rectangle's given edges, so that
 * faces meant to meet (a cabinet's side and the wall behind it, a shelf
 * board and its upright) meet without a rounding gap. */
typedef struct panel_frame {
    const float *o, *u, *v;
    int exact;
    int an, au, av;          /* axes of the normal, the width, the height */
    float plane, u0, u1, v0, v1;
} panel_frame;

static void panel_point(const panel_frame *f, float W, float H, float x, float t, float p[3])
{
    if (!f->exact) {
        for (int k = 0; k < 3; k++)
            p[k] = f->o[k] + x * f->u[k] + t * f->v[k];
        return;
    }
    p[f->an] = f->plane;
    p[f->au] = x == 0.0f ? f->u0 : x == W ? f->u1 : f->u0 < f->u1 ? f->u0 + x : f->u0 - x;
    p[f->av] = t == 0.0f ? f->v0 : t == H ? f->v1 : f->v0 + t;
}

/* A W x H rectangle placed by f (at o, spanned by unit vectors u along W
 * and v along H, facing u x v; or the exact axis-aligned form), tiled with
 * an offset lattice of nc columns and nr rows: lattice lines alternate between nc + 1 and nc + 2 points (the
 * odd ones offset by half a column, plus the two border points), and each
 * strip between two lines is zipped into triangles. Inside the triangles
 * are isosceles, near-equilateral when H / nr ~ 0.87 W / nc; at the left
 * and right borders they are halves of those. */
static void add_lattice(room_builder *b, const panel_frame *f, float W, float H, int nc, int nr)
{
    float xs[2][MAX_LATTICE + 2];
    uint32_t start[2] = {0, 0};
    int count[2] = {0, 0};
    float w = W / (float)nc, h = H / (float)nr;
    for (int j = 0; j <= nr; j++) {
        int cur = j & 1, prev = 1 - cur;
        float t = j == nr ? H : (float)j * h;
        int n = 0;
        if (cur == 0) {
            for (int i = 0; i <= nc; i++)
                xs[cur][n++] = i == nc ? W : (float)i * w;
        } else {
            xs[cur][n++] = 0.0f;
            for (int i = 0; i < nc; i++)
                xs[cur][n++] = ((float)i + 0.5f) * w;
            xs[cur][n++] = W;
        }
        start[cur] = b->m->vertex_count;
        count[cur] = n;
        for (int i = 0; i < n; i++) {
            float p[3];
            panel_point(f, W, H, xs[cur][i], t, p);
            add_vertex(b, p);
        }
        if (j == 0)
            continue;
        /* Zip line j - 1 (a) to line j (b): always advance on the side
         * whose next point comes first along u. */
        int ia = 0, ib = 0;
        while (ia < count[prev] - 1 || ib < count[cur] - 1) {
            int advance_a;
            if (ia == count[prev] - 1)
                advance_a = 0;
            else if (ib == count[cur] - 1)
                advance_a = 1;
            else
                advance_a = xs[prev][ia + 1] <= xs[cur][ib + 1];
            uint32_t a0 = start[prev] + (uint32_t)ia, b0 = start[cur] + (uint32_t)ib;
            if (advance_a) {
                add_triangle(b, a0, a0 + 1, b0);
                ia++;
            } else {
                add_triangle(b, a0, b0 + 1, b0);
                ib++;
            }
        }
    }
}

static void add_panel(room_builder *b, const float o[3], const float u[3], const float v[3],
                      float W, float H, int nc, int nr)
{
    panel_frame f = {.o = o, .u = u, .v = v};
    add_lattice(b, &f, W, H, nc, nr);
}

/* A planar quad a, b, c, d (counter-clockwise seen from the front) with
 * its own four vertices. */
static void add_quad(room_builder *b, const float *a, const float *c1, const float *c2, const float *d)
{
    uint32_t i0 = add_vertex(b, a), i1 = add_vertex(b, c1), i2 = add_vertex(b, c2), i3 = add_vertex(b, d);
    add_triangle(b, i0, i1, i2);
    add_triangle(b, i0, i2, i3);
}

/* The room's shell, every face turned inwards. */
static void add_shell(room_builder *b)
{
    const float h = ROOM_HALF, y = ROOM_HEIGHT, side = 2.0f * ROOM_HALF;
    const float px[3] = {1, 0, 0}, nx[3] = {-1, 0, 0}, py[3] = {0, 1, 0};
    const float pz[3] = {0, 0, 1}, nz[3] = {0, 0, -1};
    const float c000[3] = {-h, 0, -h}, c0y0[3] = {-h, y, -h};
    const float c100[3] = {h, 0, -h}, c001[3] = {-h, 0, h}, c101[3] = {h, 0, h};
    add_panel(b, c000, pz, px, side, side, FLOOR_COLS, FLOOR_ROWS);   /* floor: +y */
    add_panel(b, c0y0, px, pz, side, side, FLOOR_COLS, FLOOR_ROWS);   /* ceiling: -y */
    add_panel(b, c000, px, py, side, y, WALL_COLS, WALL_ROWS);        /* z = -h: +z */
    add_panel(b, c101, nx, py, side, y, WALL_COLS, WALL_ROWS);        /* z = +h: -z */
    add_panel(b, c100, pz, py, side, y, WALL_COLS, WALL_ROWS);        /* x = +h: -x */
    add_panel(b, c001, nz, py, side, y, WALL_COLS, WALL_ROWS);        /* x = -h: +x */
}

enum { FACE_BOTTOM = 1, FACE_TOP = 2, AS_PILLAR = 4 };

/* An outward-facing box: footprint sx by sz centred on (cx, cz), turned by
 * `angle` radians about y, from y0 to y0 + sy. `flags`: FACE_BOTTOM /
 * FACE_TOP leave that face out; AS_PILLAR tiles the sides as tall
 * lattices instead of quads. */
static void add_box(room_builder *b, float cx, float cz, float y0, float sx, float sy, float sz,
                    float angle, int flags)
{
    float c = cosf(angle), s = sinf(angle);
    float p[8][3];
    /* corner i: bit 0 = +x, bit 1 = +z, bit 2 = top (box axes) */
    for (int i = 0; i < 8; i++) {
        float lx = (i & 1) ? 0.5f * sx : -0.5f * sx;
        float lz = (i & 2) ? 0.5f * sz : -0.5f * sz;
        p[i][0] = cx + c * lx + s * lz;
        p[i][1] = (i & 4) ? y0 + sy : y0;
        p[i][2] = cz - s * lx + c * lz;
    }
    if (flags & AS_PILLAR) {
        /* side i runs from corner a to corner b, counter-clockwise seen from
         * above, so (b - a) x up faces outwards */
        static const int ring[5] = {0, 1, 3, 2, 0};
        const float up[3] = {0, 1, 0};
        for (int i = 0; i < 4; i++) {
            const float *a = p[ring[i]], *e = p[ring[i + 1]];
            float d[3] = {e[0] - a[0], e[1] - a[1], e[2] - a[2]};
            float len = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (int k = 0; k < 3; k++)
                d[k] /= len;
            add_panel(b, a, up, d, sy, len, PILLAR_COLS, PILLAR_ROWS);
        }
    } else {
        add_quad(b, p[1], p[5], p[7], p[3]);   /* +x */
        add_quad(b, p[0], p[2], p[6], p[4]);   /* -x */
        add_quad(b, p[2], p[3], p[7], p[6]);   /* +z */
        add_quad(b, p[1], p[0], p[4], p[5]);   /* -z */
    }
    if (!(flags & FACE_TOP))
        add_quad(b, p[4], p[6], p[7], p[5]);
    if (!(flags & FACE_BOTTOM))
        add_quad(b, p[0], p[1], p[3], p[2]);
}

/* A unit icosphere: the icosahedron, each triangle split into four with
 * midpoints pushed onto the sphere, SPHERE_LEVELS times. Midpoints are
 * shared between the two triangles of an edge (found by a linear search:
 * a few hundred edges), so the facets meet exactly. */
static void icosphere(float pos[][3], uint32_t *nv, uint32_t tri[][3], uint32_t *nt)
{
    const float t = 1.6180339887f;
    static const float base[12][3] = {
        {-1, 1.6180339887f, 0}, {1, 1.6180339887f, 0}, {-1, -1.6180339887f, 0}, {1, -1.6180339887f, 0},
        {0, -1, 1.6180339887f}, {0, 1, 1.6180339887f}, {0, -1, -1.6180339887f}, {0, 1, -1.6180339887f},
        {1.6180339887f, 0, -1}, {1.6180339887f, 0, 1}, {-1.6180339887f, 0, -1}, {-1.6180339887f, 0, 1}};
    static const uint32_t faces[20][3] = {
        {0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
        {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    float len = sqrtf(1.0f + t * t);
    for (int i = 0; i < 12; i++)
        for (int k = 0; k < 3; k++)
            pos[i][k] = base[i][k] / len;
    *nv = 12;
    memcpy(tri, faces, sizeof faces);
    *nt = 20;
    for (int level = 0; level < SPHERE_LEVELS; level++) {
        uint32_t edge_a[SPHERE_MAX_TRIANGLES * 3 / 2], edge_b[SPHERE_MAX_TRIANGLES * 3 / 2];
        uint32_t edge_mid[SPHERE_MAX_TRIANGLES * 3 / 2];
        uint32_t next[SPHERE_MAX_TRIANGLES][3];
        uint32_t ne = 0, nn = 0;
        for (uint32_t f = 0; f < *nt; f++) {
            uint32_t mid[3];
            for (int e = 0; e < 3; e++) {
                uint32_t a = tri[f][e], c = tri[f][(e + 1) % 3];
                uint32_t lo = a < c ? a : c, hi = a < c ? c : a, found = UINT32_MAX;
                for (uint32_t q = 0; q < ne; q++)
                    if (edge_a[q] == lo && edge_b[q] == hi)
                        found = edge_mid[q];
                if (found == UINT32_MAX) {
                    float m[3], l = 0.0f;
                    for (int k = 0; k < 3; k++) {
                        m[k] = 0.5f * (pos[a][k] + pos[c][k]);
                        l += m[k] * m[k];
                    }
                    l = sqrtf(l);
                    for (int k = 0; k < 3; k++)
                        pos[*nv][k] = m[k] / l;
                    found = (*nv)++;
                    edge_a[ne] = lo;
                    edge_b[ne] = hi;
                    edge_mid[ne++] = found;
                }
                mid[e] = found;
            }
            const uint32_t split[4][3] = {{tri[f][0], mid[0], mid[2]}, {tri[f][1], mid[1], mid[0]},
                                          {tri[f][2], mid[2], mid[1]}, {mid[0], mid[1], mid[2]}};
            memcpy(next[nn], split, sizeof split);
            nn += 4;
        }
        memcpy(tri, next, nn * sizeof next[0]);
        *nt = nn;
    }
}

/* The sphere of radius r with its lowest vertex on y = y0: smooth, its
 * triangles sharing vertices, so the computed normals are radial. */
static void add_sphere(room_builder *b, float cx, float y0, float cz, float r)
{
    float pos[SPHERE_MAX_VERTICES][3];
    uint32_t tri[SPHERE_MAX_TRIANGLES][3];
    uint32_t nv = 0, nt = 0;
    icosphere(pos, &nv, tri, &nt);
    float lowest = 0.0f;
    for (uint32_t i = 0; i < nv; i++)
        if (pos[i][1] < lowest)
            lowest = pos[i][1];
    uint32_t first = 0;
    for (uint32_t i = 0; i < nv; i++) {
        float p[3] = {cx + r * pos[i][0], y0 + r * (pos[i][1] - lowest), cz + r * pos[i][2]};
        uint32_t v = add_vertex(b, p);
        if (i == 0)
            first = v;
    }
    for (uint32_t f = 0; f < nt; f++)
        add_triangle(b, first + tri[f][0], first + tri[f][1], first + tri[f][2]);
}

vb_result vb_builtin_room(vb_mesh *out, vb_error *err)
{
    if (!out)
        return vb_fail(err, VB_ERR_ARGUMENT, "builtin:room: NULL output");
    vb_mesh m = {0};
    m.positions = malloc(3 * MAX_VERTICES * sizeof(float));
    m.normals = malloc(3 * MAX_VERTICES * sizeof(float));
    m.indices = malloc(3 * MAX_TRIANGLES * sizeof(uint32_t));
    if (!m.positions || !m.normals || !m.indices) {
        vb_mesh_free(&m);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "builtin:room: out of memory");
    }
    room_builder b = {.m = &m, .vertex_cap = MAX_VERTICES, .triangle_cap = MAX_TRIANGLES};
    const float deg = 3.14159265358979f / 180.0f;

    add_shell(&b);

    /* Crates: a 1.58 m one with a 0.79 m one stacked on it, off centre,
     * and a 1.12 m one turned 30 degrees about y. (Square faces whose
     * diagonal sits just under 0.2 * sqrt(2)^k m refine economically as
     * two-triangle quads: 2.23, 1.12 and 1.58 m here.) */
    add_box(&b, -4.0f, -3.0f, 0.0f, 1.58f, 1.58f, 1.58f, 0.0f, FACE_BOTTOM);
    add_box(&b, -4.2f, -3.15f, 1.58f, 0.79f, 0.79f, 0.79f, 0.0f, FACE_BOTTOM);
    add_box(&b, 4.0f, 3.5f, 0.0f, 1.12f, 1.12f, 1.12f, 30.0f * deg, FACE_BOTTOM);

    /* Three pillars, 0.4 m square, floor to ceiling. */
    const float at[3][2] = {{-5.5f, 5.5f}, {5.5f, 5.5f}, {5.5f, -5.5f}};
    for (int i = 0; i < 3; i++)
        add_box(&b, at[i][0], at[i][1], 0.0f, 0.4f, ROOM_HEIGHT, 0.4f, 0.0f,
                FACE_BOTTOM | FACE_TOP | AS_PILLAR);

    /* A sphere of radius 0.6 m resting on the floor (its facets are about
     * 0.2 m already). */
    add_sphere(&b, -1.0f, 0.0f, 2.0f, 0.6f);

    /* the normals were allocated for MAX_VERTICES: the layout fits */
    if (b.failed || m.vertex_count > MAX_VERTICES) {
        vb_mesh_free(&m);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "builtin:room: out of memory");
    }
    vb_mesh_compute_normals(&m);
    *out = m;
    return VB_OK;
}
