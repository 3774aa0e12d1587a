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
 *
 * Seeded variants (builtin:room:N, N = 1 .. 2^32 - 1): a validation set of
 * furnished interiors, each a closed room built the same way (hard-edged
 * faces with their own vertices, lattice-tiled large faces, hidden faces
 * left out), its layout drawn from a splitmix64 stream seeded with N:
 *   - the room: 8-25 m each way, 2.5-8 m high (not square as a rule), its
 *     size redrawn until the shell's area is 300-850 m^2; a rectangle, an
 *     L (one corner cut away) or a rectangle split by an interior wall
 *     6-30 cm thick with a doorway; then turned or mirrored into one of the
 *     rectangle's eight orientations;
 *   - against the walls (about one try per 3 m of wall): shelves (2 cm
 *     boards between 2 cm uprights, with blocks of books), cabinets and
 *     crates pushed into corners (with something standing on them), a
 *     sofa-like block (seat, back, arms), desks with a chair, pilasters;
 *   - standing free: tables on four thin legs with chairs around them,
 *     round tables on a pedestal, stacks of turned crates, balls, barrels,
 *     a thin (2-4 cm) screen, a door frame, square or round pillars, and
 *     lamps hanging from the ceiling on a 1.2 cm cord (a 2 cm sheet or a
 *     drum);
 *   - smooth: spheres (the icosphere above) and cylinders (16 sides of
 *     shared vertices; flat caps with their own); everything else hard.
 * Objects keep 10 cm from each other and free-standing ones 25 cm from
 * the walls (planned as boxes), except where they are meant to touch:
 * standing on the floor or on each other, pressed against a wall, a leg
 * under a table top. The faces that touch are left out, whole: an object
 * on another lies within its top, one against a wall within that wall. At
 * 0.2 m, N = 1 .. 8 give 36,000-68,000 receivers (test_mesh checks
 * 20,000-80,000 and, with rays, that each is closed and every face looks
 * into free space). Positions come from whole centimetres and exact
 * constants (no cosf or sinf; this file is built without FMA
 * contraction), so N gives the same bytes on any machine and compiler.
 */
#include "icosphere.h"
#include "mesh.h"
#include "vdsh_det.h"

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
#define PILLAR_COLS 5 /* along the pillar's height */
#define PILLAR_ROWS 1

/* Icosahedron subdivided twice: 320 triangles. */
#define SPHERE_LEVELS 2

/* Room for the whole of builtin:room (it has 1,518 vertices and 2,428
 * triangles; test_mesh checks the counts). The variants' arrays grow. */
enum { MAX_VERTICES = 4096, MAX_TRIANGLES = 4096, MAX_LATTICE = 64 };

typedef struct room_builder {
    vb_mesh *m;
    uint32_t vertex_cap, triangle_cap; /* of m's arrays; they grow as needed */
    int failed;                        /* out of memory: stop adding */
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
    int an, au, av; /* axes of the normal, the width, the height */
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
 * an offset lattice of nc columns and nr rows: lattice lines alternate
 * between nc + 1 and nc + 2 points (the odd ones offset by half a column,
 * plus the two border points), and each strip between two lines is zipped
 * into triangles. Inside the triangles are isosceles, near-equilateral
 * when H / nr ~ 0.87 W / nc; at the left and right borders they are halves
 * of those. */
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
static void add_quad(room_builder *b, const float *a, const float *c1, const float *c2,
                     const float *d)
{
    uint32_t i0 = add_vertex(b, a), i1 = add_vertex(b, c1), i2 = add_vertex(b, c2),
             i3 = add_vertex(b, d);
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
    add_panel(b, c000, pz, px, side, side, FLOOR_COLS, FLOOR_ROWS); /* floor: +y */
    add_panel(b, c0y0, px, pz, side, side, FLOOR_COLS, FLOOR_ROWS); /* ceiling: -y */
    add_panel(b, c000, px, py, side, y, WALL_COLS, WALL_ROWS);      /* z = -h: +z */
    add_panel(b, c101, nx, py, side, y, WALL_COLS, WALL_ROWS);      /* z = +h: -z */
    add_panel(b, c100, pz, py, side, y, WALL_COLS, WALL_ROWS);      /* x = +h: -x */
    add_panel(b, c001, nz, py, side, y, WALL_COLS, WALL_ROWS);      /* x = -h: +x */
}

enum { FACE_BOTTOM = 1, FACE_TOP = 2, AS_PILLAR = 4 };

/* An outward-facing box: footprint sx by sz centred on (cx, cz), turned by
 * `angle` radians about y, from y0 to y0 + sy. `flags`: FACE_BOTTOM /
 * FACE_TOP leave that face out; AS_PILLAR tiles the sides as tall
 * lattices instead of quads. */
static void add_box(room_builder *b, float cx, float cz, float y0, float sx, float sy, float sz,
                    float angle, int flags)
{
    float c = (float)vdsh_det_cos(angle), s = (float)vdsh_det_sin(angle);
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
        add_quad(b, p[1], p[5], p[7], p[3]); /* +x */
        add_quad(b, p[0], p[2], p[6], p[4]); /* -x */
        add_quad(b, p[2], p[3], p[7], p[6]); /* +z */
        add_quad(b, p[1], p[0], p[4], p[5]); /* -z */
    }
    if (!(flags & FACE_TOP))
        add_quad(b, p[4], p[6], p[7], p[5]);
    if (!(flags & FACE_BOTTOM))
        add_quad(b, p[0], p[1], p[3], p[2]);
}

/* The sphere of radius r with its lowest vertex on y = y0: smooth, its
 * triangles sharing vertices, so the computed normals are radial. */
static void add_sphere(room_builder *b, float cx, float y0, float cz, float r)
{
    float pos[VB_ICOSPHERE_VERTICES(SPHERE_LEVELS)][3];
    uint32_t tri[VB_ICOSPHERE_TRIANGLES(SPHERE_LEVELS)][3];
    uint32_t nv = 0, nt = 0;
    vb_icosphere(SPHERE_LEVELS, pos, &nv, tri, &nt);
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

/* ====================================================================== */
/* Seeded variants: builtin:room:N                                        */
/* ====================================================================== */

/* splitmix64 (Steele, Lea and Flood 2014): every layout decision is drawn
 * from it, in a fixed order, as whole centimetres or small integers, so
 * the same N gives the same bytes everywhere (no libc rand, no libm; the
 * arithmetic on the draws is plain IEEE float, compiled without FMA
 * contraction). A statement draws at most once per function argument list
 * or operator (their evaluation order is unspecified in C); several draws
 * go to separate declarators, which are sequenced. */
typedef struct room_rng {
    uint64_t s;
} room_rng;

static uint64_t rng_next(room_rng *r)
{
    uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* lo..hi inclusive */
static int rng_int(room_rng *r, int lo, int hi)
{
    uint64_t draw = rng_next(r);
    return hi <= lo ? lo : lo + (int)(draw % (uint64_t)(hi - lo + 1));
}

/* lo..hi centimetres, in metres */
static float rng_cm(room_rng *r, int lo, int hi)
{
    return (float)rng_int(r, lo, hi) / 100.0f;
}

static int rng_percent(room_rng *r, int percent)
{
    return rng_int(r, 0, 99) < percent;
}

/* Turns about y for crates, as constants (not cosf/sinf, whose
 * last bit is the C library's choice): 0, 15, 30, 45, 60 and 75 degrees. */
static const float TURN_COS[6] = {1.0f, 0.96592583f, 0.86602540f, 0.70710678f, 0.5f, 0.25881905f};
static const float TURN_SIN[6] = {0.0f, 0.25881905f, 0.5f, 0.70710678f, 0.86602540f, 0.96592583f};

/* ---- Faces and solids ------------------------------------------------ */

/* The lattice for a W x H face (columns along W): 0 for a plain quad,
 * else columns and rows. Longest-edge bisection refines a lattice most
 * economically when both the triangles' bases and their sides sit just
 * under 0.2 * 2^k m (see the header; measured: 46-50 vertices per m^2 at
 * 0.2 m against 55-90 for lattices off that mark), so among a few column
 * counts for each k the one whose shorter edge comes closest to its step
 * wins, a coarser k when it is within 3%. Small faces stay quads. */
static int choose_lattice(float W, float H, int *nc, int *nr)
{
    if (W < 0.6f || H < 0.6f || W * H < 1.2f)
        return 0;
    float best = 0.0f;
    for (int k = 4; k >= 1; k--) {
        float step = 0.2f * (float)(1 << k), edge = 0.99f * step;
        float first = ceilf(W / edge);
        for (int extra = 0; extra < 3; extra++) {
            float cols = first + (float)extra, w = W / cols;
            float rows = ceilf(H / sqrtf(edge * edge - 0.25f * w * w)), h = H / rows;
            if (cols > (float)MAX_LATTICE || rows > (float)MAX_LATTICE)
                continue;
            float side = sqrtf(0.25f * w * w + h * h);
            float score = (w < side ? w : side) / step;
            if (score > best + 0.03f) {
                best = score;
                *nc = (int)cols;
                *nr = (int)rows;
            }
        }
    }
    return best > 0.0f;
}

/* The axis-aligned rectangle lo..hi (its extent along `an` ignored) in the
 * plane p[an] = plane, facing +an (sign > 0) or -an. Its width runs
 * horizontally (along z for the floor and ceiling) and its height along y
 * (along x for the floor and ceiling). */
static void add_rect(room_builder *b, int an, int sign, float plane, const float lo[3],
                     const float hi[3])
{
    panel_frame f = {.exact = 1, .an = an, .plane = plane};
    int flip;
    if (an == 1) {
        /* width along z: +z for the floor (z x x = +y), -z for a ceiling */
        f.au = 2;
        f.av = 0;
        flip = sign < 0;
    } else {
        /* height along y, width along y x n: -z for +x, +z for -x, +x for
         * +z, -x for -z */
        f.au = 2 - an;
        f.av = 1;
        flip = an == 0 ? sign > 0 : sign < 0;
    }
    f.u0 = flip ? hi[f.au] : lo[f.au];
    f.u1 = flip ? lo[f.au] : hi[f.au];
    f.v0 = lo[f.av];
    f.v1 = hi[f.av];
    float W = hi[f.au] - lo[f.au], H = hi[f.av] - lo[f.av];
    int nc = 1, nr = 1;
    if (choose_lattice(W, H, &nc, &nr)) {
        add_lattice(b, &f, W, H, nc, nr);
        return;
    }
    float c[4][3];
    panel_point(&f, W, H, 0.0f, 0.0f, c[0]);
    panel_point(&f, W, H, W, 0.0f, c[1]);
    panel_point(&f, W, H, W, H, c[2]);
    panel_point(&f, W, H, 0.0f, H, c[3]);
    add_quad(b, c[0], c[1], c[2], c[3]);
}

/* Faces of a block to leave out: those resting on or pressed against
 * something (bit 2 * axis for the - side, bit 2 * axis + 1 for +). */
enum {
    OMIT_XN = 1,
    OMIT_XP = 2,
    OMIT_YN = 4,
    OMIT_YP = 8,
    OMIT_ZN = 16,
    OMIT_ZP = 32,
    OMIT_BOTTOM = OMIT_YN,
    OMIT_TOP = OMIT_YP
};

/* The outward-facing axis-aligned block lo..hi (in the builder's frame). */
static void add_block(room_builder *b, const float lo[3], const float hi[3], int omit)
{
    for (int a = 0; a < 3; a++) {
        if (!(omit & (1 << (2 * a))))
            add_rect(b, a, -1, lo[a], lo, hi);
        if (!(omit & (2 << (2 * a))))
            add_rect(b, a, 1, hi[a], lo, hi);
    }
}

/* 16 directions around y, k * 22.5 degrees, from exact constants. */
#define CYLINDER_SEGMENTS 16
static void cylinder_dir(int k, float *c, float *s)
{
    static const float q[5] = {1.0f, 0.92387953f, 0.70710678f, 0.38268343f, 0.0f};
    k &= 15;
    int quadrant = k / 4, j = k % 4;
    float a = q[j], e = q[4 - j];
    float cs[4][2] = {{a, e}, {-e, a}, {-a, -e}, {e, -a}};
    *c = cs[quadrant][0];
    *s = cs[quadrant][1];
}

/* A cylinder about the vertical line (cx, cz), radius r, from y0 to y1:
 * its side smooth (rings of shared vertices), its caps flat with their own
 * vertices (hard edges). OMIT_BOTTOM / OMIT_TOP leave a cap out. */
static void add_cylinder(room_builder *b, float cx, float cz, float y0, float y1, float r, int omit)
{
    const int n = CYLINDER_SEGMENTS;
    int rows = (int)ceilf((y1 - y0) / 0.6f);
    if (rows < 1)
        rows = 1;
    float ring[CYLINDER_SEGMENTS][2];
    for (int k = 0; k < n; k++) {
        float c, s;
        cylinder_dir(k, &c, &s);
        ring[k][0] = cx + r * c;
        ring[k][1] = cz + r * s;
    }
    uint32_t first = b->m->vertex_count;
    for (int j = 0; j <= rows; j++) {
        float y = j == rows ? y1 : y0 + (y1 - y0) * (float)j / (float)rows;
        for (int k = 0; k < n; k++) {
            float p[3] = {ring[k][0], y, ring[k][1]};
            add_vertex(b, p);
        }
    }
    for (int j = 0; j < rows; j++)
        for (int k = 0; k < n; k++) {
            uint32_t a = first + (uint32_t)(j * n + k), e = first + (uint32_t)(j * n + (k + 1) % n);
            uint32_t d = a + (uint32_t)n, c = e + (uint32_t)n;
            /* (d - a) x (c - a) ~ up x tangent: outwards */
            add_triangle(b, a, d, c);
            add_triangle(b, a, c, e);
        }
    for (int cap = 0; cap < 2; cap++) {
        if (omit & (cap ? OMIT_TOP : OMIT_BOTTOM))
            continue;
        float y = cap ? y1 : y0;
        float centre[3] = {cx, y, cz};
        uint32_t mid = add_vertex(b, centre), rim = b->m->vertex_count;
        for (int k = 0; k < n; k++) {
            float p[3] = {ring[k][0], y, ring[k][1]};
            add_vertex(b, p);
        }
        for (int k = 0; k < n; k++) {
            uint32_t a = rim + (uint32_t)k, e = rim + (uint32_t)((k + 1) % n);
            if (cap)
                add_triangle(b, mid, e, a);
            else
                add_triangle(b, mid, a, e);
        }
    }
}

static void turn(room_builder *b, float c, float s, float tx, float tz)
{
    b->turned = 1;
    b->c = c;
    b->s = s;
    b->tx = tx;
    b->tz = tz;
}

static void unturn(room_builder *b)
{
    b->turned = 0;
}

/* ---- The plan: free floor, walls, what is taken ----------------------- */

enum { MAX_TAKEN = 512, MAX_WALLS = 12 };

/* Clearances: between separate objects, and of free-standing ones from
 * the walls (closer than a ray origin's "near" distance they would read as
 * pressed together). */
#define GAP 0.1f
#define WALL_GAP 0.25f

typedef struct room_aabb {
    float lo[3], hi[3];
} room_aabb;

/* A stretch of wall objects can stand against: the plane x = at (axis 0)
 * or z = at (axis 2), the room on its + side (in = 1) or - side, from e0
 * to e1 along the other horizontal axis; corner0/1: another wall meets it
 * at that end (an object pushed there touches both). */
typedef struct room_wall {
    int axis, in;
    float at, e0, e1;
    int corner0, corner1;
} room_wall;

typedef struct room_plan {
    room_builder *b;
    room_rng rng;
    float hx, hz, height; /* half width (x), half depth (z), height */
    room_aabb free[2];    /* the floor: an object lies within one */
    int free_count;
    room_wall walls[MAX_WALLS];
    int wall_count;
    room_aabb taken[MAX_TAKEN]; /* what is placed (and the doorway) */
    int taken_count;
} room_plan;

static room_aabb aabb(float x0, float y0, float z0, float x1, float y1, float z1)
{
    room_aabb a = {{x0, y0, z0}, {x1, y1, z1}};
    return a;
}

/* Inside the room, `wall_gap` from its walls, and `gap` from everything
 * placed so far. */
static int fits(const room_plan *p, const room_aabb *a, float gap, float wall_gap)
{
    if (p->taken_count == MAX_TAKEN || a->lo[1] < 0.0f || a->hi[1] > p->height)
        return 0;
    int inside = 0;
    for (int i = 0; i < p->free_count && !inside; i++) {
        const room_aabb *f = &p->free[i];
        inside = a->lo[0] >= f->lo[0] + wall_gap && a->hi[0] <= f->hi[0] - wall_gap &&
                 a->lo[2] >= f->lo[2] + wall_gap && a->hi[2] <= f->hi[2] - wall_gap;
    }
    if (!inside)
        return 0;
    for (int i = 0; i < p->taken_count; i++) {
        const room_aabb *t = &p->taken[i];
        int apart = 0;
        for (int k = 0; k < 3; k++)
            apart |= a->lo[k] >= t->hi[k] + gap || t->lo[k] >= a->hi[k] + gap;
        if (!apart)
            return 0;
    }
    return 1;
}

static void take(room_plan *p, const room_aabb *a)
{
    if (p->taken_count < MAX_TAKEN)
        p->taken[p->taken_count++] = *a;
}

/* Faces of an object against a wall, in the wall's terms. */
enum { W_BACK = 1, W_FRONT = 2, W_START = 4, W_END = 8, W_BOTTOM = 16, W_TOP = 32 };

/* The box s0..s1 along wall w, d0..d1 out from it, y0..y1, as world
 * bounds; *omit (may be NULL) gets the wall-terms faces `w_omit` as
 * block faces. d = 0 gives exactly the wall's plane. */
static room_aabb wall_box(const room_wall *w, float s0, float s1, float d0, float d1, float y0,
                          float y1, int w_omit, int *omit)
{
    room_aabb r;
    int a = w->axis, o = 2 - a;
    float p0 = w->at + (float)w->in * d0, p1 = w->at + (float)w->in * d1;
    r.lo[a] = w->in > 0 ? p0 : p1;
    r.hi[a] = w->in > 0 ? p1 : p0;
    r.lo[o] = s0;
    r.hi[o] = s1;
    r.lo[1] = y0;
    r.hi[1] = y1;
    if (omit) {
        int back = w->in > 0 ? 1 << (2 * a) : 2 << (2 * a),
            front = w->in > 0 ? 2 << (2 * a) : 1 << (2 * a);
        *omit = ((w_omit & W_BACK) ? back : 0) | ((w_omit & W_FRONT) ? front : 0) |
                ((w_omit & W_START) ? 1 << (2 * o) : 0) | ((w_omit & W_END) ? 2 << (2 * o) : 0) |
                ((w_omit & W_BOTTOM) ? OMIT_BOTTOM : 0) | ((w_omit & W_TOP) ? OMIT_TOP : 0);
    }
    return r;
}

static void add_wall_block(room_plan *p, const room_wall *w, float s0, float s1, float d0, float d1,
                           float y0, float y1, int w_omit)
{
    int omit = 0;
    room_aabb a = wall_box(w, s0, s1, d0, d1, y0, y1, w_omit, &omit);
    add_block(p->b, a.lo, a.hi, omit);
}

/* A free stretch len long, dep deep and hgt high against some wall: the
 * wall, where it starts (s0) and W_START / W_END where it is pushed into
 * a corner. Returns 0 when nothing was found. */
static int find_wall_spot(room_plan *p, float len, float dep, float hgt, const room_wall **wall,
                          float *s0, int *corner)
{
    for (int attempt = 0; attempt < 40; attempt++) {
        const room_wall *w = &p->walls[rng_int(&p->rng, 0, p->wall_count - 1)];
        if (w->e1 - w->e0 < len + 0.02f)
            continue;
        int where = rng_int(&p->rng, 0, 3);
        float a, e;
        int c = 0;
        if (where == 0 && w->corner0) {
            a = w->e0;
            e = a + len;
            c = W_START;
        } else if (where == 1 && w->corner1) {
            e = w->e1;
            a = e - len;
            c = W_END;
        } else {
            /* off the corner by more than a ray origin's near distance */
            int slack = (int)((w->e1 - w->e0 - len - 2.0f * WALL_GAP) * 100.0f);
            if (slack < 0)
                continue;
            a = w->e0 + WALL_GAP + (float)rng_int(&p->rng, 0, slack) / 100.0f;
            e = a + len;
            if (e > w->e1 - WALL_GAP)
                continue;
        }
        room_aabb box = wall_box(w, a, e, 0.0f, dep, 0.0f, hgt, 0, NULL);
        if (!fits(p, &box, GAP, 0.0f))
            continue;
        *wall = w;
        *s0 = a;
        *corner = c;
        return 1;
    }
    return 0;
}

/* A free spot for a free-standing footprint sx by sz, y0..y1: its centre.
 * Positions are whole centimetres. */
static int find_floor_spot(room_plan *p, float sx, float sz, float y0, float y1, float *cx,
                           float *cz)
{
    for (int attempt = 0; attempt < 40; attempt++) {
        const room_aabb *f = &p->free[rng_int(&p->rng, 0, p->free_count - 1)];
        float span_x = f->hi[0] - f->lo[0] - 2.0f * WALL_GAP - sx,
              span_z = f->hi[2] - f->lo[2] - 2.0f * WALL_GAP - sz;
        if (span_x <= 0.0f || span_z <= 0.0f)
            continue;
        float x = f->lo[0] + WALL_GAP + 0.5f * sx +
                  (float)rng_int(&p->rng, 0, (int)(span_x * 100.0f)) / 100.0f;
        float z = f->lo[2] + WALL_GAP + 0.5f * sz +
                  (float)rng_int(&p->rng, 0, (int)(span_z * 100.0f)) / 100.0f;
        room_aabb box = aabb(x - 0.5f * sx, y0, z - 0.5f * sz, x + 0.5f * sx, y1, z + 0.5f * sz);
        if (!fits(p, &box, GAP, WALL_GAP))
            continue;
        *cx = x;
        *cz = z;
        return 1;
    }
    return 0;
}

/* ---- The shell --------------------------------------------------------- */

static void add_wall(room_plan *p, int axis, int in, float at, float e0, float e1, int corner0,
                     int corner1)
{
    room_wall w = {axis, in, at, e0, e1, corner0, corner1};
    p->walls[p->wall_count++] = w;
    /* the wall's face, from the floor to the ceiling, facing the room */
    float lo[3], hi[3];
    int o = 2 - axis;
    lo[axis] = hi[axis] = at;
    lo[o] = e0;
    hi[o] = e1;
    lo[1] = 0.0f;
    hi[1] = p->height;
    add_rect(p->b, axis, in, at, lo, hi);
}

static void add_floor_and_ceiling(room_plan *p, float x0, float z0, float x1, float z1, int ceiling)
{
    float lo[3] = {x0, 0.0f, z0}, hi[3] = {x1, 0.0f, z1};
    add_rect(p->b, 1, 1, 0.0f, lo, hi);
    if (ceiling) {
        lo[1] = hi[1] = p->height;
        add_rect(p->b, 1, -1, p->height, lo, hi);
    }
}

/* A rectangle, an L (the +x +z corner cut away) or a rectangle split by an
 * interior wall (along x, at z = zw .. zw + t) with one doorway. */
enum { SHAPE_RECT, SHAPE_L, SHAPE_SPLIT };

static void add_room_shell(room_plan *p, int shape)
{
    const float hx = p->hx, hz = p->hz, H = p->height;
    room_rng *r = &p->rng;
    if (shape == SHAPE_L) {
        float xc = hx - rng_cm(r, (int)(70.0f * hx), (int)(120.0f * hx));
        float zc = hz - rng_cm(r, (int)(70.0f * hz), (int)(120.0f * hz));
        add_floor_and_ceiling(p, -hx, -hz, hx, zc, 1);
        add_floor_and_ceiling(p, -hx, zc, xc, hz, 1);
        add_wall(p, 0, 1, -hx, -hz, hz, 1, 1);
        add_wall(p, 2, 1, -hz, -hx, hx, 1, 1);
        add_wall(p, 0, -1, hx, -hz, zc, 1, 1);
        add_wall(p, 2, -1, zc, xc, hx, 0, 1);
        add_wall(p, 0, -1, xc, zc, hz, 0, 1);
        add_wall(p, 2, -1, hz, -hx, xc, 1, 1);
        p->free[0] = aabb(-hx, 0.0f, -hz, hx, H, zc);
        p->free[1] = aabb(-hx, 0.0f, -hz, xc, H, hz);
        p->free_count = 2;
        return;
    }
    if (shape == SHAPE_RECT) {
        add_floor_and_ceiling(p, -hx, -hz, hx, hz, 1);
        add_wall(p, 0, 1, -hx, -hz, hz, 1, 1);
        add_wall(p, 0, -1, hx, -hz, hz, 1, 1);
        add_wall(p, 2, 1, -hz, -hx, hx, 1, 1);
        add_wall(p, 2, -1, hz, -hx, hx, 1, 1);
        p->free[0] = aabb(-hx, 0.0f, -hz, hx, H, hz);
        p->free_count = 1;
        return;
    }
    /* The interior wall: t thick (6 cm, a thin partition, to 30 cm), with
     * a doorway d0..d1 up to dh. Floor, ceiling and outer walls stop at
     * it, so none of their faces is buried inside it. */
    float t = rng_cm(r, 6, 30);
    float zw = -hz + rng_cm(r, 300, (int)(200.0f * hz) - 300 - (int)(t * 100.0f));
    float door = rng_cm(r, 90, 180), dh = rng_cm(r, 200, H > 2.7f ? 240 : (int)(H * 100.0f) - 30);
    float d0 = -hx + rng_cm(r, 60, (int)(200.0f * hx) - 60 - (int)(door * 100.0f)), d1 = d0 + door;
    float zb = zw + t;
    add_floor_and_ceiling(p, -hx, -hz, hx, zw, 1);
    add_floor_and_ceiling(p, -hx, zb, hx, hz, 1);
    add_floor_and_ceiling(p, d0, zw, d1, zb, 0); /* the threshold */
    add_wall(p, 0, 1, -hx, -hz, zw, 1, 1);
    add_wall(p, 0, 1, -hx, zb, hz, 1, 1);
    add_wall(p, 0, -1, hx, -hz, zw, 1, 1);
    add_wall(p, 0, -1, hx, zb, hz, 1, 1);
    add_wall(p, 2, 1, -hz, -hx, hx, 1, 1);
    add_wall(p, 2, -1, hz, -hx, hx, 1, 1);
    /* its two sides, each as the stretches either side of the doorway
     * plus the piece above it */
    for (int side = 0; side < 2; side++) {
        float at = side ? zb : zw;
        int in = side ? 1 : -1;
        room_wall left = {2, in, at, -hx, d0, 1, 0}, right = {2, in, at, d1, hx, 0, 1};
        p->walls[p->wall_count++] = left;
        p->walls[p->wall_count++] = right;
        float lo[3] = {-hx, 0.0f, at}, hi[3] = {d0, H, at};
        add_rect(p->b, 2, in, at, lo, hi);
        lo[0] = d1;
        hi[0] = hx;
        add_rect(p->b, 2, in, at, lo, hi);
        lo[0] = d0;
        hi[0] = d1;
        lo[1] = dh;
        add_rect(p->b, 2, in, at, lo, hi);
    }
    /* the doorway's jambs and head */
    float lo[3] = {d0, 0.0f, zw}, hi[3] = {d0, dh, zb};
    add_rect(p->b, 0, 1, d0, lo, hi);
    lo[0] = hi[0] = d1;
    add_rect(p->b, 0, -1, d1, lo, hi);
    lo[0] = d0;
    lo[1] = hi[1] = dh;
    add_rect(p->b, 1, -1, dh, lo, hi);
    p->free[0] = aabb(-hx, 0.0f, -hz, hx, H, zw);
    p->free[1] = aabb(-hx, 0.0f, zb, hx, H, hz);
    p->free_count = 2;
    /* keep the way through the door clear */
    room_aabb way = aabb(d0 - 0.2f, 0.0f, zw - 1.0f, d1 + 0.2f, H, zb + 1.0f);
    take(p, &way);
}

/* ---- Furniture --------------------------------------------------------- */

/* A crate (cube of side a, turned by TURN index k, mirrored when `neg`)
 * with its bottom at y0, centred on (cx, cz); `omit` as add_block. */
static void add_crate(room_plan *p, float cx, float cz, float y0, float a, int k, int neg, int omit)
{
    turn(p->b, TURN_COS[k], neg ? -TURN_SIN[k] : TURN_SIN[k], cx, cz);
    float lo[3] = {-0.5f * a, y0, -0.5f * a}, hi[3] = {0.5f * a, y0 + a, 0.5f * a};
    add_block(p->b, lo, hi, omit);
    unturn(p->b);
}

/* Something small standing on the top lo..hi of a support, placed at y =
 * hi[1]: a box (bottom left out), a barrel-like cylinder (likewise) or a
 * ball touching it in one point. Returns its height (0: nothing fitted). */
static float add_on_top(room_plan *p, const float lo[3], const float hi[3], float max_h)
{
    room_rng *r = &p->rng;
    float sx = hi[0] - lo[0], sz = hi[2] - lo[2], y = hi[1];
    float room = sx < sz ? sx : sz;
    if (room < 0.25f || max_h < 0.15f)
        return 0.0f;
    int kind = rng_int(r, 0, 2);
    float size = rng_cm(r, 12, (int)(room * 70.0f));
    if (size > max_h)
        size = max_h;
    if (size < 0.1f)
        return 0.0f;
    /* centred within the top with a margin of 10% of the room left */
    float ox = (sx - size) * 0.5f, oz = (sz - size) * 0.5f;
    float cx = lo[0] + 0.5f * size + (float)rng_int(r, 0, (int)(ox * 100.0f)) / 100.0f;
    float cz = lo[2] + 0.5f * size + (float)rng_int(r, 0, (int)(oz * 100.0f)) / 100.0f;
    room_aabb box =
        aabb(cx - 0.5f * size, y, cz - 0.5f * size, cx + 0.5f * size, y + size, cz + 0.5f * size);
    if (box.lo[0] < lo[0] || box.hi[0] > hi[0] || box.lo[2] < lo[2] || box.hi[2] > hi[2])
        return 0.0f;
    if (kind == 0) {
        float blo[3] = {box.lo[0], y, box.lo[2]}, bhi[3] = {box.hi[0], y + size, box.hi[2]};
        add_block(p->b, blo, bhi, OMIT_BOTTOM);
    } else if (kind == 1) {
        add_cylinder(p->b, cx, cz, y, y + size, 0.4f * size, OMIT_BOTTOM);
    } else {
        add_sphere(p->b, cx, y, cz, 0.5f * size);
    }
    return size;
}

/* Shelves against a wall: two 2 cm uprights, 2 cm boards between them
 * (their backs and ends pressed against the wall and the uprights), and
 * blocks of books on the boards. */
static int add_shelves(room_plan *p)
{
    room_rng *r = &p->rng;
    float len = rng_cm(r, 80, 220), dep = rng_cm(r, 25, 45);
    float hgt = rng_cm(r, 120, p->height > 2.6f ? 240 : (int)(p->height * 100.0f) - 30);
    const room_wall *w;
    float s0;
    int corner;
    /* Not in a corner: a 2 cm upright open on two sides would be closed
     * by the walls' fronts, and the bake would read the end of a board
     * pressed against it as a normal pointing into a solid. */
    if (!find_wall_spot(p, len, dep, hgt, &w, &s0, &corner) || corner)
        return 0;
    const float t = 0.02f;
    float s1 = s0 + len, a = s0 + t, e = s1 - t;
    add_wall_block(p, w, s0, a, 0.0f, dep, 0.0f, hgt, W_BACK | W_BOTTOM);
    add_wall_block(p, w, e, s1, 0.0f, dep, 0.0f, hgt, W_BACK | W_BOTTOM);
    int boards = rng_int(r, 3, 6);
    float first = rng_cm(r, 6, 15), spacing = (hgt - t - first) / (float)(boards - 1);
    for (int i = 0; i < boards; i++) {
        float y0 = i == boards - 1 ? hgt - t : first + spacing * (float)i,
              y1 = i == boards - 1 ? hgt : y0 + t;
        add_wall_block(p, w, a, e, 0.0f, dep, y0, y1, W_BACK | W_START | W_END);
        if (i == boards - 1 || spacing < 0.2f)
            continue;
        /* books: blocks 6-30 cm wide with gaps of at least 6 cm, against
         * the wall or standing off it */
        float s = a + rng_cm(r, 6, 20);
        while (s < e - 0.12f) {
            float wide = rng_cm(r, 6, 30),
                  tall = rng_cm(r, 12, (int)((spacing - t - 0.06f) * 100.0f));
            if (s + wide > e - 0.06f || tall < 0.12f)
                break;
            float d0 = rng_percent(r, 60) ? 0.0f : rng_cm(r, 6, 8);
            float d1 = d0 + rng_cm(r, 12, (int)((dep - d0) * 100.0f));
            if (rng_percent(r, 75))
                add_wall_block(p, w, s, s + wide, d0, d1, y1, y1 + tall,
                               W_BOTTOM | (d0 == 0.0f ? W_BACK : 0));
            s += wide + rng_cm(r, 6, 40);
        }
    }
    room_aabb box = wall_box(w, s0, s1, 0.0f, dep, 0.0f, hgt, 0, NULL);
    take(p, &box);
    return 1;
}

/* A cabinet: a thick block against a wall (in a corner sometimes), with
 * something standing on it. */
static int add_cabinet(room_plan *p)
{
    room_rng *r = &p->rng;
    float len = rng_cm(r, 60, 220), dep = rng_cm(r, 40, 70);
    float hgt = rng_cm(r, 70, p->height > 2.6f ? 220 : (int)(p->height * 100.0f) - 40);
    const room_wall *w;
    float s0;
    int corner;
    if (!find_wall_spot(p, len, dep, hgt, &w, &s0, &corner))
        return 0;
    add_wall_block(p, w, s0, s0 + len, 0.0f, dep, 0.0f, hgt, W_BACK | W_BOTTOM | corner);
    room_aabb box = wall_box(w, s0, s0 + len, 0.0f, dep, 0.0f, hgt, 0, NULL);
    float above = p->height - hgt - 0.3f;
    if (hgt < 1.6f && above > 0.2f && rng_percent(r, 70))
        box.hi[1] += add_on_top(p, box.lo, box.hi, above < 0.6f ? above : 0.6f);
    take(p, &box);
    return 1;
}

/* A sofa-like block against a wall: the seat, the back on it along the
 * wall and an arm on it at each end. */
static int add_sofa(room_plan *p)
{
    room_rng *r = &p->rng;
    float len = rng_cm(r, 150, 280), dep = rng_cm(r, 80, 105);
    float seat = rng_cm(r, 38, 46), back = rng_cm(r, 78, 95), arm = rng_cm(r, 55, 68);
    float back_d = rng_cm(r, 15, 25), arm_w = rng_cm(r, 12, 25);
    const room_wall *w;
    float s0;
    int corner;
    if (!find_wall_spot(p, len, dep, back, &w, &s0, &corner))
        return 0;
    float s1 = s0 + len;
    add_wall_block(p, w, s0, s1, 0.0f, dep, 0.0f, seat, W_BACK | W_BOTTOM | corner);
    add_wall_block(p, w, s0, s1, 0.0f, back_d, seat, back, W_BACK | W_BOTTOM | corner);
    add_wall_block(p, w, s0, s0 + arm_w, back_d, dep, seat, arm,
                   W_BACK | W_BOTTOM | (corner & W_START));
    add_wall_block(p, w, s1 - arm_w, s1, back_d, dep, seat, arm,
                   W_BACK | W_BOTTOM | (corner & W_END));
    room_aabb box = wall_box(w, s0, s1, 0.0f, dep, 0.0f, back, 0, NULL);
    take(p, &box);
    return 1;
}

/* A table: a top t thick at height h over four legs (long thin shadows),
 * footprint lo..hi in the builder's frame. */
static void add_table_at(room_builder *b, float x0, float z0, float x1, float z1, float h, float t,
                         float leg, float inset)
{
    float top_lo[3] = {x0, h - t, z0}, top_hi[3] = {x1, h, z1};
    add_block(b, top_lo, top_hi, 0);
    for (int i = 0; i < 4; i++) {
        float lx = (i & 1) ? x1 - inset - leg : x0 + inset,
              lz = (i & 2) ? z1 - inset - leg : z0 + inset;
        float lo[3] = {lx, 0.0f, lz}, hi[3] = {lx + leg, h - t, lz + leg};
        add_block(b, lo, hi, OMIT_BOTTOM | OMIT_TOP);
    }
}

/* A chair facing (fx, fz) (a unit axis direction), its seat centred on
 * (cx, cz): four legs, the seat, a thin back standing on the seat. Its
 * footprint is w (across) by d (deep). */
static void add_chair_at(room_builder *b, float cx, float cz, float fx, float fz, float w, float d,
                         float seat, float back)
{
    /* local +z is the chair's front: turned so that it maps to (fx, fz) */
    turn(b, fz, fx, cx, cz);
    float x0 = -0.5f * w, x1 = 0.5f * w, z0 = -0.5f * d, z1 = 0.5f * d;
    const float t = 0.04f, leg = 0.035f;
    for (int i = 0; i < 4; i++) {
        float lx = (i & 1) ? x1 - leg - 0.01f : x0 + 0.01f,
              lz = (i & 2) ? z1 - leg - 0.01f : z0 + 0.01f;
        float lo[3] = {lx, 0.0f, lz}, hi[3] = {lx + leg, seat - t, lz + leg};
        add_block(b, lo, hi, OMIT_BOTTOM | OMIT_TOP);
    }
    float s_lo[3] = {x0, seat - t, z0}, s_hi[3] = {x1, seat, z1};
    add_block(b, s_lo, s_hi, 0);
    float b_lo[3] = {x0, seat, z0}, b_hi[3] = {x1, back, z0 + 0.03f};
    add_block(b, b_lo, b_hi, OMIT_BOTTOM);
    unturn(b);
}

static void chair_dims(room_rng *r, float *w, float *d, float *seat, float *back)
{
    *w = rng_cm(r, 40, 50);
    *d = rng_cm(r, 40, 48);
    *seat = rng_cm(r, 43, 48);
    *back = *seat + rng_cm(r, 35, 50);
}

/* Try a chair at (cx, cz) facing (fx, fz); returns whether it fitted. */
static int try_chair(room_plan *p, float cx, float cz, float fx, float fz)
{
    float w, d, seat, back;
    chair_dims(&p->rng, &w, &d, &seat, &back);
    float ex = fx != 0.0f ? d : w, ez = fx != 0.0f ? w : d;
    room_aabb box =
        aabb(cx - 0.5f * ex, 0.0f, cz - 0.5f * ez, cx + 0.5f * ex, back, cz + 0.5f * ez);
    if (!fits(p, &box, 0.05f, 0.1f))
        return 0;
    add_chair_at(p->b, cx, cz, fx, fz, w, d, seat, back);
    take(p, &box);
    return 1;
}

/* A desk against a wall with a chair in front of it, facing the wall. */
static int add_desk(room_plan *p)
{
    room_rng *r = &p->rng;
    float len = rng_cm(r, 100, 180), dep = rng_cm(r, 60, 80), h = rng_cm(r, 72, 76);
    float gap = rng_cm(r, 3, 8);
    const room_wall *w;
    float s0;
    int corner;
    if (!find_wall_spot(p, len, gap + dep, h, &w, &s0, &corner))
        return 0;
    room_aabb box = wall_box(w, s0, s0 + len, gap, gap + dep, 0.0f, h, 0, NULL);
    if (corner) {
        /* a desk keeps off the side wall too */
        int o = 2 - w->axis;
        if (corner & W_START)
            box.lo[o] += gap;
        else
            box.hi[o] -= gap;
    }
    float top = rng_cm(r, 3, 5), leg = rng_cm(r, 4, 6), inset = rng_cm(r, 2, 6);
    add_table_at(p->b, box.lo[0], box.lo[2], box.hi[0], box.hi[2], h, top, leg, inset);
    room_aabb all = wall_box(w, s0, s0 + len, 0.0f, gap + dep, 0.0f, h, 0, NULL);
    if (rng_percent(r, 60))
        all.hi[1] += add_on_top(p, box.lo, (float[3]){box.hi[0], h, box.hi[2]}, 0.5f);
    take(p, &all);
    /* the chair: half under the desk's front edge would bury it; in
     * front, facing the wall */
    float out = gap + dep + rng_cm(r, 12, 35) + 0.25f;
    float s = s0 + 0.5f * len, fx = w->axis == 0 ? (float)-w->in : 0.0f,
          fz = w->axis == 2 ? (float)-w->in : 0.0f;
    float cx = w->axis == 0 ? w->at + (float)w->in * out : s,
          cz = w->axis == 2 ? w->at + (float)w->in * out : s;
    try_chair(p, cx, cz, fx, fz);
    return 1;
}

/* A pilaster: a square column pressed against a wall, floor to ceiling. */
static int add_pilaster(room_plan *p)
{
    room_rng *r = &p->rng;
    float len = rng_cm(r, 30, 70), dep = rng_cm(r, 20, 50);
    const room_wall *w;
    float s0;
    int corner;
    if (!find_wall_spot(p, len, dep, p->height, &w, &s0, &corner) || corner)
        return 0;
    add_wall_block(p, w, s0, s0 + len, 0.0f, dep, 0.0f, p->height, W_BACK | W_BOTTOM | W_TOP);
    room_aabb box = wall_box(w, s0, s0 + len, 0.0f, dep, 0.0f, p->height, 0, NULL);
    take(p, &box);
    return 1;
}

/* Crates in a corner: one pushed into it, perhaps a smaller one on it. */
static int add_corner_crates(room_plan *p)
{
    room_rng *r = &p->rng;
    float a = rng_cm(r, 50, 130);
    const room_wall *w;
    float s0;
    int corner;
    if (!find_wall_spot(p, a, a, a, &w, &s0, &corner) || !corner)
        return 0;
    room_aabb box = wall_box(w, s0, s0 + a, 0.0f, a, 0.0f, a, 0, NULL);
    add_wall_block(p, w, s0, s0 + a, 0.0f, a, 0.0f, a, W_BACK | W_BOTTOM | corner);
    if (rng_percent(r, 60) && a + 0.6f < p->height - 0.3f) {
        /* the one on top stays within the lower one's top */
        float b = rng_cm(r, 30, (int)(a * 75.0f));
        int k = rng_int(r, 0, 5);
        float half = 0.5f * b * (TURN_COS[k] + TURN_SIN[k]);
        if (half <= 0.5f * a - 0.01f) {
            float cx = 0.5f * (box.lo[0] + box.hi[0]), cz = 0.5f * (box.lo[2] + box.hi[2]);
            float shift = (0.5f * a - half) * 0.5f;
            cx += rng_percent(r, 50) ? shift : -shift;
            add_crate(p, cx, cz, a, b, k, rng_percent(r, 50), OMIT_BOTTOM);
            box.hi[1] += b;
        }
    }
    take(p, &box);
    return 1;
}

/* A table with chairs around it (they face it) and perhaps a lamp hanging
 * over it and things on it. Axis-aligned. */
static int add_dining(room_plan *p)
{
    room_rng *r = &p->rng;
    float sx = rng_cm(r, 110, 240), sz = rng_cm(r, 70, 110), h = rng_cm(r, 72, 78);
    if (rng_percent(r, 50)) {
        float tmp = sx;
        sx = sz;
        sz = tmp;
    }
    float cx, cz;
    /* room for chairs on every side */
    if (!find_floor_spot(p, sx + 1.4f, sz + 1.4f, 0.0f, 1.1f, &cx, &cz))
        return 0;
    float x0 = cx - 0.5f * sx, x1 = cx + 0.5f * sx, z0 = cz - 0.5f * sz, z1 = cz + 0.5f * sz;
    float t = rng_cm(r, 3, 6);
    float leg = rng_cm(r, 4, 9), inset = rng_cm(r, 3, 12);
    add_table_at(p->b, x0, z0, x1, z1, h, t, leg, inset);
    room_aabb box = aabb(x0, 0.0f, z0, x1, h, z1);
    if (rng_percent(r, 60)) {
        float lo[3] = {x0, 0.0f, z0}, hi[3] = {x1, h, z1};
        box.hi[1] += add_on_top(p, lo, hi, 0.45f);
    }
    take(p, &box);
    /* chairs: pulled out 8-30 cm from the edges */
    int along_x = (int)(sx / 0.65f), along_z = (int)(sz / 0.65f);
    for (int side = 0; side < 4; side++) {
        int n = side < 2 ? along_x : along_z;
        for (int i = 0; i < n; i++) {
            if (!rng_percent(r, 70))
                continue;
            float off = rng_cm(r, 8, 30) + 0.25f;
            float pos = (float)(2 * i + 1) / (float)(2 * n);
            float px, pz, fx = 0.0f, fz = 0.0f;
            if (side < 2) {
                px = x0 + pos * sx;
                pz = side == 0 ? z0 - off : z1 + off;
                fz = side == 0 ? 1.0f : -1.0f;
            } else {
                pz = z0 + pos * sz;
                px = side == 2 ? x0 - off : x1 + off;
                fx = side == 2 ? 1.0f : -1.0f;
            }
            try_chair(p, px, pz, fx, fz);
        }
    }
    return 1;
}

/* A round table: a smooth disc on a pedestal. */
static int add_round_table(room_plan *p)
{
    room_rng *r = &p->rng;
    float rad = rng_cm(r, 35, 65), h = rng_cm(r, 55, 76), t = rng_cm(r, 3, 5),
          leg = rng_cm(r, 4, 8);
    float cx, cz;
    if (!find_floor_spot(p, 2.0f * rad, 2.0f * rad, 0.0f, h, &cx, &cz))
        return 0;
    add_cylinder(p->b, cx, cz, h - t, h, rad, 0);
    add_cylinder(p->b, cx, cz, 0.0f, h - t, leg, OMIT_BOTTOM | OMIT_TOP);
    room_aabb box = aabb(cx - rad, 0.0f, cz - rad, cx + rad, h, cz + rad);
    if (rng_percent(r, 50)) {
        /* within a square inside the 16-gon (its corners at 0.92 r) */
        float e = 0.65f * rad, lo[3] = {cx - e, 0.0f, cz - e}, hi[3] = {cx + e, h, cz + e};
        box.hi[1] += add_on_top(p, lo, hi, 0.4f);
    }
    take(p, &box);
    return 1;
}

/* A stack of one to three crates, each turned its own way and resting
 * wholly on the one below. */
static int add_crate_stack(room_plan *p)
{
    room_rng *r = &p->rng;
    float a = rng_cm(r, 40, 160);
    int k = rng_int(r, 0, 5), neg = rng_percent(r, 50);
    float half = 0.5f * a * (TURN_COS[k] + TURN_SIN[k]);
    float cx, cz;
    if (a > p->height - 0.5f || !find_floor_spot(p, 2.0f * half, 2.0f * half, 0.0f, a, &cx, &cz))
        return 0;
    add_crate(p, cx, cz, 0.0f, a, k, neg, OMIT_BOTTOM);
    room_aabb box = aabb(cx - half, 0.0f, cz - half, cx + half, a, cz + half);
    float y = a, below = a;
    for (int level = 0; level < 2 && rng_percent(r, 55); level++) {
        float b = rng_cm(r, 25, (int)(below * 80.0f));
        int kb = rng_int(r, 0, 5);
        /* the upper square's corners stay inside the lower's inscribed
         * circle: turned any way, it rests wholly on the lower one */
        if (b * 0.7072f > 0.5f * below || y + b > p->height - 0.4f)
            break;
        add_crate(p, cx, cz, y, b, kb, rng_percent(r, 50), OMIT_BOTTOM);
        y += b;
        below = b;
    }
    box.hi[1] = y;
    take(p, &box);
    return 1;
}

static int add_ball(room_plan *p)
{
    room_rng *r = &p->rng;
    float rad = rng_cm(r, 15, 80);
    float cx, cz;
    if (!find_floor_spot(p, 2.0f * rad, 2.0f * rad, 0.0f, 2.0f * rad, &cx, &cz))
        return 0;
    add_sphere(p->b, cx, 0.0f, cz, rad);
    room_aabb box = aabb(cx - rad, 0.0f, cz - rad, cx + rad, 2.0f * rad, cz + rad);
    take(p, &box);
    return 1;
}

static int add_barrel(room_plan *p)
{
    room_rng *r = &p->rng;
    float rad = rng_cm(r, 20, 45), h = rng_cm(r, 50, 120);
    float cx, cz;
    if (!find_floor_spot(p, 2.0f * rad, 2.0f * rad, 0.0f, h, &cx, &cz))
        return 0;
    add_cylinder(p->b, cx, cz, 0.0f, h, rad, OMIT_BOTTOM);
    room_aabb box = aabb(cx - rad, 0.0f, cz - rad, cx + rad, h, cz + rad);
    take(p, &box);
    return 1;
}

/* A free-standing screen: a thin (2-4 cm) partition on the floor. */
static int add_screen(room_plan *p)
{
    room_rng *r = &p->rng;
    float len = rng_cm(r, 120, 350), t = rng_cm(r, 2, 4);
    float h = rng_cm(r, 120, p->height > 2.5f ? 220 : (int)(p->height * 100.0f) - 30);
    int along_x = rng_percent(r, 50);
    float sx = along_x ? len : t, sz = along_x ? t : len;
    float cx, cz;
    if (!find_floor_spot(p, sx, sz, 0.0f, h, &cx, &cz))
        return 0;
    float lo[3] = {cx - 0.5f * sx, 0.0f, cz - 0.5f * sz},
          hi[3] = {cx + 0.5f * sx, h, cz + 0.5f * sz};
    add_block(p->b, lo, hi, OMIT_BOTTOM);
    room_aabb box = aabb(lo[0], 0.0f, lo[2], hi[0], h, hi[2]);
    take(p, &box);
    return 1;
}

/* A free-standing door frame: two posts and a beam resting on them. */
static int add_door_frame(room_plan *p)
{
    room_rng *r = &p->rng;
    float post = rng_cm(r, 8, 14), open = rng_cm(r, 80, 140), beam = rng_cm(r, 10, 20);
    float h = rng_cm(r, 200, 230);
    if (h + beam > p->height - 0.2f)
        h = p->height - 0.2f - beam;
    int along_x = rng_percent(r, 50);
    float len = open + 2.0f * post;
    float sx = along_x ? len : post, sz = along_x ? post : len;
    float cx, cz;
    /* room to walk through it */
    if (!find_floor_spot(p, along_x ? sx : 1.6f, along_x ? 1.6f : sz, 0.0f, h + beam, &cx, &cz))
        return 0;
    float x0 = cx - 0.5f * sx, z0 = cz - 0.5f * sz, x1 = cx + 0.5f * sx, z1 = cz + 0.5f * sz;
    for (int i = 0; i < 2; i++) {
        float lo[3] = {x0, 0.0f, z0}, hi[3] = {x1, h, z1};
        if (along_x) {
            lo[0] = i ? x1 - post : x0;
            hi[0] = i ? x1 : x0 + post;
        } else {
            lo[2] = i ? z1 - post : z0;
            hi[2] = i ? z1 : z0 + post;
        }
        add_block(p->b, lo, hi, OMIT_BOTTOM | OMIT_TOP);
    }
    float lo[3] = {x0, h, z0}, hi[3] = {x1, h + beam, z1};
    add_block(p->b, lo, hi, 0);
    room_aabb box = aabb(along_x ? x0 : cx - 0.8f, 0.0f, along_x ? cz - 0.8f : z0,
                         along_x ? x1 : cx + 0.8f, h + beam, along_x ? cz + 0.8f : z1);
    take(p, &box);
    return 1;
}

/* A lamp hanging from the ceiling on a 1.2 cm cord: a thin square shade
 * (a 2 cm sheet) or a smooth drum. */
static int add_lamp(room_plan *p)
{
    room_rng *r = &p->rng;
    int drum = rng_percent(r, 40);
    float size = drum ? rng_cm(r, 30, 70) : rng_cm(r, 50, 140),
          t = drum ? rng_cm(r, 20, 40) : 0.02f;
    float low = p->height - 2.3f < 2.05f ? 2.05f : p->height - 2.3f;
    if (low + t > p->height - 0.3f)
        return 0;
    float y0 = low + (float)rng_int(r, 0, (int)((p->height - 0.3f - t - low) * 100.0f)) / 100.0f;
    float cx, cz;
    if (!find_floor_spot(p, size, size, y0, p->height, &cx, &cz))
        return 0;
    float y1 = y0 + t;
    if (drum) {
        add_cylinder(p->b, cx, cz, y0, y1, 0.5f * size, 0);
    } else {
        float lo[3] = {cx - 0.5f * size, y0, cz - 0.5f * size},
              hi[3] = {cx + 0.5f * size, y1, cz + 0.5f * size};
        add_block(p->b, lo, hi, 0);
    }
    float c_lo[3] = {cx - 0.006f, y1, cz - 0.006f}, c_hi[3] = {cx + 0.006f, p->height, cz + 0.006f};
    add_block(p->b, c_lo, c_hi, OMIT_BOTTOM | OMIT_TOP);
    room_aabb box =
        aabb(cx - 0.5f * size, y0, cz - 0.5f * size, cx + 0.5f * size, p->height, cz + 0.5f * size);
    take(p, &box);
    return 1;
}

/* A free-standing pillar, floor to ceiling: square (hard edges) or round
 * (smooth). */
static int add_pillar(room_plan *p)
{
    room_rng *r = &p->rng;
    int round = rng_percent(r, 50);
    float a = round ? rng_cm(r, 30, 80) : rng_cm(r, 30, 70);
    float cx, cz;
    if (!find_floor_spot(p, a + 0.6f, a + 0.6f, 0.0f, p->height, &cx, &cz))
        return 0;
    if (round) {
        add_cylinder(p->b, cx, cz, 0.0f, p->height, 0.5f * a, OMIT_BOTTOM | OMIT_TOP);
    } else {
        float lo[3] = {cx - 0.5f * a, 0.0f, cz - 0.5f * a},
              hi[3] = {cx + 0.5f * a, p->height, cz + 0.5f * a};
        add_block(p->b, lo, hi, OMIT_BOTTOM | OMIT_TOP);
    }
    room_aabb box =
        aabb(cx - 0.5f * a, 0.0f, cz - 0.5f * a, cx + 0.5f * a, p->height, cz + 0.5f * a);
    take(p, &box);
    return 1;
}

/* Hanging lamps go over tables, so they are placed before them; pillars
 * and wall furniture first, free-standing things in what is left. */
static void furnish(room_plan *p)
{
    room_rng *r = &p->rng;
    float area = 4.0f * p->hx * p->hz;
    int pillars = area > 150.0f ? rng_int(r, 0, 4) : rng_int(r, 0, 2);
    for (int i = 0; i < pillars; i++)
        add_pillar(p);
    int (*const against_wall[])(room_plan *) = {add_shelves, add_shelves,       add_cabinet,
                                                add_cabinet, add_sofa,          add_desk,
                                                add_desk,    add_corner_crates, add_pilaster};
    const int kinds = (int)(sizeof against_wall / sizeof against_wall[0]);
    /* roughly one item per 3 m of wall */
    int items = (int)(4.0f * (p->hx + p->hz) / 3.0f);
    for (int i = 0; i < items; i++)
        against_wall[rng_int(r, 0, kinds - 1)](p);
    int lamps = rng_int(r, 1, 3);
    for (int i = 0; i < lamps; i++)
        add_lamp(p);
    int (*const standing[])(room_plan *) = {add_dining,      add_dining,      add_round_table,
                                            add_crate_stack, add_crate_stack, add_ball,
                                            add_barrel,      add_screen,      add_door_frame};
    const int free_kinds = (int)(sizeof standing / sizeof standing[0]);
    /* most kinds once (where they fit), then more at random */
    for (int i = 0; i < free_kinds; i++)
        if (rng_percent(r, 65))
            standing[i](p);
    int more = (int)(area / 60.0f);
    for (int i = 0; i < more; i++)
        standing[rng_int(r, 0, free_kinds - 1)](p);
}

vb_result vb_builtin_room_variant(uint32_t n, vb_mesh *out, vb_error *err)
{
    if (!out)
        return vb_fail(err, VB_ERR_ARGUMENT, "builtin:room:%u: NULL output", n);
    if (n == 0)
        return vb_fail(err, VB_ERR_ARGUMENT, "builtin:room:0: variants are numbered from 1");
    vb_mesh m = {0};
    room_builder b = {.m = &m};
    room_plan p = {.b = &b, .rng = {0x5EEDC0DEull ^ ((uint64_t)n << 32) ^ n}};

    /* The size: 8-25 m each way, 2.5-8 m high, redrawn until the shell's
     * area keeps the receivers at 0.2 m in the validation range (about
     * 46 per m^2 of shell, plus the furniture). */
    float W = 12.0f, D = 10.0f, H = 4.0f;
    for (int attempt = 0; attempt < 1000; attempt++) {
        float w = rng_cm(&p.rng, 800, 2500), d = rng_cm(&p.rng, 800, 2500),
              h = rng_cm(&p.rng, 250, 800);
        float shell = 2.0f * w * d + 2.0f * h * (w + d);
        if (shell >= 300.0f && shell <= 850.0f) {
            W = w, D = d, H = h;
            break;
        }
    }
    p.hx = 0.5f * W;
    p.hz = 0.5f * D;
    p.height = H;
    int shape = rng_int(&p.rng, 0, 9);
    shape = shape < 4 ? SHAPE_RECT : shape < 7 ? SHAPE_L : SHAPE_SPLIT;
    if (shape == SHAPE_SPLIT && D < 8.0f)
        shape = SHAPE_RECT;
    add_room_shell(&p, shape);
    furnish(&p);

    /* One of the rectangle's eight symmetries, exact (swaps and sign
     * changes); a mirror image reverses every triangle's winding. Adding
     * +0 turns any -0 into +0: one bit pattern for zero (the ray-origin
     * offset works on the bits, and -0 is INT_MIN there). */
    int sym = rng_int(&p.rng, 0, 7);
    for (uint32_t i = 0; i < m.vertex_count && !b.failed; i++) {
        float *q = m.positions + 3 * (size_t)i;
        if (sym & 1) {
            float t = q[0];
            q[0] = q[2];
            q[2] = t;
        }
        if (sym & 2)
            q[0] = -q[0];
        if (sym & 4)
            q[2] = -q[2];
        for (int k = 0; k < 3; k++)
            q[k] += 0.0f;
    }
    if (((sym ^ (sym >> 1) ^ (sym >> 2)) & 1) && !b.failed)
        for (uint32_t t = 0; t < m.triangle_count; t++) {
            uint32_t *tri = m.indices + 3 * (size_t)t, k = tri[1];
            tri[1] = tri[2];
            tri[2] = k;
        }
    if (!b.failed)
        vb_mesh_compute_normals(&m);
    if (b.failed || !m.normals) {
        vb_mesh_free(&m);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "builtin:room:%u: out of memory", n);
    }
    *out = m;
    return VB_OK;
}

vb_result vb_builtin_load(const char *name, vb_mesh *out, vb_error *err)
{
    if (!name || !out)
        return vb_fail(err, VB_ERR_ARGUMENT, "builtin: NULL name or output");
    if (strcmp(name, "builtin:room") == 0)
        return vb_builtin_room(out, err);
    if (strncmp(name, "builtin:room:", 13) == 0) {
        const char *d = name + 13;
        uint64_t n = 0;
        size_t len = strlen(d);
        int ok = len > 0 && len <= 10 && d[0] != '0';
        for (size_t i = 0; ok && i < len; i++) {
            ok = d[i] >= '0' && d[i] <= '9';
            n = 10 * n + (uint64_t)(d[i] - '0');
        }
        if (!ok || n > UINT32_MAX)
            return vb_fail(
                err, VB_ERR_ARGUMENT,
                "%s: unknown built-in scene: N in builtin:room:N is a whole number from 1 to "
                "4294967295, without leading zeros",
                name);
        return vb_builtin_room_variant((uint32_t)n, out, err);
    }
    return vb_fail(
        err, VB_ERR_ARGUMENT,
        "%s: unknown built-in scene (known: builtin:room, builtin:room:N for N = 1 .. 4294967295)",
        name);
}
