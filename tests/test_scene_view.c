/*
 * test_scene_view.c - formats/vdsh_scene_view.h, the default view from a
 * mesh (no GL):
 *
 *   test_scene_view unit
 *     rays     the grid's first hits are the plain loop's, bit for bit
 *              (distance, barycentrics, triangle, side), on a room with a
 *              pillar, a sphere and a soup of large random triangles
 *     space    free space: the middle of a room is, and far above it (open
 *              sky); inside a pillar and near a wall are not
 *     room     a closed room is an interior seen by the room camera; a
 *              preferred light inside a pillar moves into free space
 *              nearby, the others stay where they were
 *     object   a sphere is framed from outside, lit from outside it
 *     object-on-floor  a cube on a floor quad: every default light in the
 *              light region the bake trains on (vdsh_light_region, here
 *              the bounds), free, within a diagonal of the bounds
 *     flat     a single triangle facing any way (and a flat quad): the
 *              default camera sees its front, all of it, within
 *              VDSH_VIEW_FLAT_ANGLE of its normal, every light there;
 *              a quad a thousandth of its diagonal off flat likewise
 *     none     a scene with no free space keeps the preferred lights and
 *              says they are not free
 *     two-rooms  an internal wall with a door, the camera in one room:
 *              every default light lights the frame (light 0 from the
 *              camera's room, lighting a quarter and shadowing some);
 *              the preferred light 0, behind the wall, does not
 *     blocked-eye  a block just in front of the room camera's eye: the
 *              eye rises over it, in free space, its frame open
 *     errors   an index out of range: VDSH_ERR_INVALID, output untouched
 *   test_scene_view room ROOM.vdsh
 *     the built-in room baked (a CTest fixture): the room camera; every
 *     default light in free space (probes cast by the plain loop), none
 *     inside or on a pillar, crate or the sphere (bake/lib/builtin.c places
 *     them); the two preferred positions that lie on and in pillars moved
 *     less than a metre, the other two kept
 */
#include "test_util.h"

#include "vdsh.h"
#include "vdsh_camera.h"
#include "vdsh_light.h"
#include "vdsh_scene_view.h"

#include <math.h>
#include <string.h>

/* ---- meshes ------------------------------------------------------------ */

enum { MAX_V = 8192, MAX_T = 8192 };

typedef struct mesh {
    float pos[MAX_V][3], nrm[MAX_V][3];
    uint32_t idx[MAX_T][3];
    uint32_t nv, nt;
} mesh;

static vdsh_view_mesh view_mesh(const mesh *m)
{
    vdsh_view_mesh v = {&m->pos[0][0], &m->nrm[0][0], &m->idx[0][0], m->nv, m->nt, NULL};
    return v;
}

/* Quad a b c d, counter-clockwise seen from the side its normal n faces. */
static void quad(mesh *m, const float a[3], const float b[3], const float c[3], const float d[3])
{
    const float *p[4] = {a, b, c, d};
    float e1[3], e2[3], n[3];
    for (int k = 0; k < 3; k++)
        e1[k] = b[k] - a[k], e2[k] = c[k] - a[k];
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    float l = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    uint32_t base = m->nv;
    for (int i = 0; i < 4; i++) {
        memcpy(m->pos[m->nv], p[i], sizeof m->pos[0]);
        for (int k = 0; k < 3; k++)
            m->nrm[m->nv][k] = n[k] / l;
        m->nv++;
    }
    uint32_t t0[3] = {base, base + 1, base + 2}, t1[3] = {base, base + 2, base + 3};
    memcpy(m->idx[m->nt++], t0, sizeof t0);
    memcpy(m->idx[m->nt++], t1, sizeof t1);
}

/* An axis-aligned box lo..hi, faces outward (a solid) or inward (a room). */
static void box(mesh *m, const float lo[3], const float hi[3], int inward)
{
    for (int a = 0; a < 3; a++)
        for (int side = 0; side < 2; side++) {
            int b = (a + 1) % 3, c = (a + 2) % 3;
            float q[4][3];
            /* corners around the face, counter-clockwise seen along +a */
            static const int uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
            for (int i = 0; i < 4; i++) {
                q[i][a] = side ? hi[a] : lo[a];
                q[i][b] = uv[i][0] ? hi[b] : lo[b];
                q[i][c] = uv[i][1] ? hi[c] : lo[c];
            }
            /* b x c = a: this order faces +a; flip for the -a face, and
             * again for a room */
            if ((side == 1) != (inward != 0))
                quad(m, q[0], q[1], q[2], q[3]);
            else
                quad(m, q[0], q[3], q[2], q[1]);
        }
}

/* A UV sphere, faces and normals outward. */
static void sphere(mesh *m, const float c[3], float r, int stacks, int slices)
{
    uint32_t base = m->nv;
    for (int i = 0; i <= stacks; i++)
        for (int j = 0; j <= slices; j++) {
            float t = 3.14159265f * (float)i / (float)stacks;
            float p = 6.2831853f * (float)j / (float)slices;
            float n[3] = {sinf(t) * cosf(p), cosf(t), sinf(t) * sinf(p)};
            for (int k = 0; k < 3; k++) {
                m->pos[m->nv][k] = c[k] + r * n[k];
                m->nrm[m->nv][k] = n[k];
            }
            m->nv++;
        }
    for (int i = 0; i < stacks; i++)
        for (int j = 0; j < slices; j++) {
            uint32_t a = base + (uint32_t)(i * (slices + 1) + j), b = a + 1;
            uint32_t d = a + (uint32_t)(slices + 1), e = d + 1;
            uint32_t t0[3] = {a, b, e}, t1[3] = {a, e, d};
            memcpy(m->idx[m->nt++], t0, sizeof t0);
            memcpy(m->idx[m->nt++], t1, sizeof t1);
        }
}

/* ---- free space by the plain loop -------------------------------------- */

/* vdsh_light.h's rule at this clearance, probes cast at every triangle
 * (no grid). */
static int free_all_at(const vdsh_view_mesh *m, const float p[3], float clearance)
{
    float dirs[VDSH_FREE_PROBES][3], t[VDSH_FREE_PROBES];
    int back[VDSH_FREE_PROBES];
    vdsh_free_probe_dirs(dirs);
    for (int i = 0; i < VDSH_FREE_PROBES; i++) {
        vdsh_view_hit h;
        int hit = vdsh_view_trace_all(m, p, dirs[i], 0.0f, &h);
        t[i] = hit ? h.t : INFINITY;
        back[i] = hit && h.back;
    }
    return vdsh_free_space(t, back, clearance);
}

static int free_all(const vdsh_view_mesh *m, const float p[3], float diagonal)
{
    return free_all_at(m, p, vdsh_free_clearance(diagonal));
}

static float dist3(const float a[3], const float b[3])
{
    float d = 0.0f;
    for (int k = 0; k < 3; k++)
        d += (a[k] - b[k]) * (a[k] - b[k]);
    return sqrtf(d);
}

static int same_camera(const vdsh_camera *a, const vdsh_camera *b)
{
    return !memcmp(a->eye, b->eye, sizeof a->eye) &&
           !memcmp(a->target, b->target, sizeof a->target) && !memcmp(a->up, b->up, sizeof a->up) &&
           a->fov_y == b->fov_y;
}

/* The share of camera c's check-frame pixels that see the mesh whose
 * surface faces light L (lit or shadowed: vdsh_view_light_shares). */
static float key_facing(const vdsh_view_tracer *t, const vdsh_view_mesh *m, const vdsh_camera *c,
                        const float L[3], float diag)
{
    const int w = VDSH_VIEW_CHECK_W, h = VDSH_VIEW_CHECK_H;
    int hits = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float o[3], d[3];
            vdsh_view_hit hit;
            vdsh_camera_ray(c, w, h, x, y, o, d);
            hits += vdsh_view_trace(t, o, d, 0.0f, &hit);
        }
    float lit, sh;
    vdsh_view_light_shares(t, m, c, w, h, L, diag, &lit, &sh);
    return hits ? (lit + sh) * (float)(w * h) / (float)hits : 0.0f;
}

/* An object's default camera (vdsh_view_compute): the fit camera where
 * light 0 faces VDSH_VIEW_KEY_FACING of what it sees, else the fit camera
 * turned about the vertical by a multiple of 45 degrees, looking at the
 * same point, whose frame light 0 faces more. */
static void check_key_camera(const vdsh_view_mesh *m, const vdsh_view *v, const char *name)
{
    vdsh_view_tracer *t = NULL;
    vdsh_error err;
    CHECK(vdsh_view_tracer_create(m, &t, &err) == VDSH_OK, "%s: %s", name, err.msg);
    if (!t)
        return;
    const float diag = vdsh_view_diagonal(v->bounds_min, v->bounds_max);
    vdsh_camera fit;
    vdsh_view_fit_camera(v->bounds_min, v->bounds_max, &fit);
    const float f0 = key_facing(t, m, &fit, v->lights[0], diag);
    const float f1 = key_facing(t, m, &v->camera, v->lights[0], diag);
    printf("%s: light 0 faces %.1f%% of the fit camera's object pixels, %.1f%% of the view's\n",
           name, 100.0 * f0, 100.0 * f1);
    CHECK(same_camera(&v->fit, &v->camera), "%s: the fit camera (--fit) is not the view's", name);
    if (same_camera(&v->camera, &fit)) {
        CHECK(f0 >= VDSH_VIEW_KEY_FACING, "%s: light 0 faces %g of the view, not turned", name,
              (double)f0);
    } else {
        CHECK(!memcmp(v->camera.target, fit.target, sizeof fit.target) &&
                  v->camera.fov_y == fit.fov_y,
              "%s: the turned camera looks elsewhere", name);
        float a[2] = {fit.eye[0] - fit.target[0], fit.eye[2] - fit.target[2]};
        float b[2] = {v->camera.eye[0] - fit.target[0], v->camera.eye[2] - fit.target[2]};
        float ang =
            atan2f(a[0] * b[1] - a[1] * b[0], a[0] * b[0] + a[1] * b[1]) * 4.0f / 3.14159265f;
        CHECK(fabsf(ang - roundf(ang)) < 1e-3f, "%s: turned by %g x 45 degrees", name, (double)ang);
        CHECK(f0 < VDSH_VIEW_KEY_FACING && f1 > f0,
              "%s: turned with light 0 facing %g of the fit view, %g of the turned", name,
              (double)f0, (double)f1);
    }
    vdsh_view_tracer_destroy(t);
}

/* ---- unit tests --------------------------------------------------------- */

static mesh M;

/* Grid against plain loop on n random rays from in and around the box. */
static void rays_agree(const mesh *mm, const char *name, uint64_t seed, int n)
{
    vdsh_view_mesh m = view_mesh(mm);
    vdsh_view_tracer *t = NULL;
    vdsh_error err;
    CHECK(vdsh_view_tracer_create(&m, &t, &err) == VDSH_OK, "%s: %s", name, err.msg);
    if (!t)
        return;
    float lo[3], hi[3];
    vdsh_view_bounds(m.positions, m.vertex_count, lo, hi);
    int hits = 0, differ = 0, backs = 0;
    for (int i = 0; i < n; i++) {
        float o[3], d[3];
        for (int k = 0; k < 3; k++) {
            float e = hi[k] - lo[k];
            o[k] = lo[k] - 0.2f * e + 1.4f * e * (float)test_rand(&seed);
        }
        test_rand_dir(&seed, d);
        /* some rays along the axes and through vertices: ties and edges */
        if (i % 7 == 0)
            for (int k = 0; k < 3; k++)
                d[k] = k == i % 3 ? (i & 8 ? 1.0f : -1.0f) : 0.0f;
        if (i % 11 == 0) {
            const float *v = m.positions + 3 * (size_t)(i % (int)m.vertex_count);
            float l = dist3(v, o);
            for (int k = 0; k < 3; k++)
                d[k] = (v[k] - o[k]) / l;
        }
        float tmin = i % 3 == 0 ? 0.0f : (float)test_rand(&seed) * 0.1f;
        vdsh_view_hit a, b;
        memset(&a, 0, sizeof a);
        memset(&b, 0, sizeof b);
        int ha = vdsh_view_trace(t, o, d, tmin, &a), hb = vdsh_view_trace_all(&m, o, d, tmin, &b);
        hits += hb;
        backs += hb && b.back;
        if (ha != hb || memcmp(&a, &b, sizeof a)) {
            if (differ++ < 5)
                fprintf(stderr,
                        "%s: ray %d: grid %d (t %g, triangle %u), loop %d (t %g, "
                        "triangle %u)\n",
                        name, i, ha, (double)a.t, a.triangle, hb, (double)b.t, b.triangle);
        }
    }
    printf("rays: %s (%u triangles): %d rays, %d hits (%d from behind), %d differ\n", name,
           m.triangle_count, n, hits, backs, differ);
    CHECK(differ == 0, "%s: %d of %d rays hit differently through the grid", name, differ, n);
    CHECK(hits > n / 10 && hits < n, "%s: %d hits of %d rays: the test proves little", name, hits,
          n);
    vdsh_view_tracer_destroy(t);
}

/* The room of the unit tests: 20 x 6 x 20, a 0.4 m pillar, floor to
 * ceiling, around where preferred light 2 falls. */
static void unit_room(mesh *m, float pillar_lo[3], float pillar_hi[3])
{
    memset(m, 0, sizeof *m);
    const float lo[3] = {-10, 0, -10}, hi[3] = {10, 6, 10};
    box(m, lo, hi, 1);
    float pref[VDSH_VIEW_MAX_LIGHTS][3];
    vdsh_view_preferred_lights(lo, hi, 1, pref, VDSH_VIEW_MAX_LIGHTS);
    for (int k = 0; k < 3; k++) {
        pillar_lo[k] = k == 1 ? 0.0f : pref[2][k] - 0.15f;
        pillar_hi[k] = k == 1 ? 6.0f : pref[2][k] + 0.25f;
    }
    box(m, pillar_lo, pillar_hi, 0);
}

static void test_rays(void)
{
    float plo[3], phi[3];
    unit_room(&M, plo, phi);
    rays_agree(&M, "room with a pillar", 1, 4000);

    memset(&M, 0, sizeof M);
    sphere(&M, (float[3]){3, 1, -2}, 1.0f, 24, 32);
    rays_agree(&M, "sphere", 2, 4000);

    /* large random triangles: many cells each */
    memset(&M, 0, sizeof M);
    uint64_t s = 3;
    for (int i = 0; i < 600; i++) {
        float c[3], span = (float)(i % 10 == 0 ? 8.0 : 1.0);
        for (int k = 0; k < 3; k++)
            c[k] = 10.0f * (float)test_rand(&s);
        for (int v = 0; v < 3; v++) {
            for (int k = 0; k < 3; k++) {
                M.pos[M.nv][k] = c[k] + span * (float)(test_rand(&s) - 0.5);
                M.nrm[M.nv][k] = k == 1 ? 1.0f : 0.0f;
            }
            M.idx[M.nt][v] = M.nv++;
        }
        M.nt++;
    }
    rays_agree(&M, "soup", 4, 4000);
}

static void test_space(void)
{
    float plo[3], phi[3];
    unit_room(&M, plo, phi);
    vdsh_view_mesh m = view_mesh(&M);
    vdsh_view_tracer *t = NULL;
    vdsh_error err;
    CHECK(vdsh_view_tracer_create(&m, &t, &err) == VDSH_OK, "%s", err.msg);
    if (!t)
        return;
    float diag = vdsh_view_diagonal((float[3]){-10, 0, -10}, (float[3]){10, 6, 10});
    float c = vdsh_free_clearance(diag);
    struct {
        float p[3];
        int free;
        const char *what;
    } cases[] = {
        {{0, 3, 0}, 1, "the middle of the room"},
        {{-9, 1, 9}, 1, "a corner, a metre from the walls"},
        {{0.5f * (plo[0] + phi[0]), 3, 0.5f * (plo[2] + phi[2])}, 0, "inside the pillar"},
        {{0, 3, 10.0f - 0.5f * c}, 0, "half the clearance from a wall"},
        {{0, 6.0f - 0.5f * c, 0}, 0, "half the clearance below the ceiling"},
        /* outside the closed room: the ceiling seen from behind */
        {{0, 30, 0}, 0, "far above the room"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        int g = vdsh_view_free_space(t, cases[i].p, diag), a = free_all(&m, cases[i].p, diag);
        CHECK(g == cases[i].free, "%s: free space %d, expected %d", cases[i].what, g,
              cases[i].free);
        CHECK(g == a, "%s: the grid says %d, the plain loop %d", cases[i].what, g, a);
    }
    vdsh_view_tracer_destroy(t);
}

static void test_room(void)
{
    float plo[3], phi[3];
    unit_room(&M, plo, phi);
    vdsh_view_mesh m = view_mesh(&M);
    vdsh_view v, v2;
    vdsh_error err;
    CHECK(vdsh_view_compute(&m, &v, &err) == VDSH_OK, "%s", err.msg);
    CHECK(vdsh_view_compute(&m, &v2, &err) == VDSH_OK, "%s", err.msg);
    CHECK(!memcmp(&v, &v2, sizeof v), "two computations of the same view differ");
    CHECK(v.front_share == 1.0f && v.interior, "a closed room: front share %g, interior %d",
          (double)v.front_share, v.interior);
    vdsh_camera room;
    vdsh_view_room_camera(v.bounds_min, v.bounds_max, &room);
    CHECK(same_camera(&v.camera, &room), "a room is not seen by the room camera");
    float diag = vdsh_view_diagonal(v.bounds_min, v.bounds_max);
    CHECK(v.light_count == VDSH_VIEW_MAX_LIGHTS, "%d lights", v.light_count);
    for (int i = 0; i < v.light_count; i++) {
        int was_free = free_all(&m, v.preferred[i], diag);
        CHECK(v.light_free[i] && free_all(&m, v.lights[i], diag),
              "light %d at (%g, %g, %g) is not in free space", i, v.lights[i][0], v.lights[i][1],
              v.lights[i][2]);
        if (i == 2) {
            CHECK(!was_free, "light 2's preferred position is free: the pillar misses it");
            /* Out of the pillar to a place VDSH_VIEW_LIGHT_MARGIN
             * clearances from every surface (not one clearance from the
             * pillar's face), within VDSH_VIEW_MARGIN_REACH of it. */
            const float cl = vdsh_free_clearance(diag);
            float moved = dist3(v.lights[i], v.preferred[i]);
            CHECK(moved > 0.0f && moved <= (VDSH_VIEW_MARGIN_REACH + 0.5f) * cl,
                  "light 2 moved %g from the pillar (clearance %g)", (double)moved, (double)cl);
            CHECK(free_all_at(&m, v.lights[i], VDSH_VIEW_LIGHT_MARGIN * cl),
                  "light 2 at (%g, %g, %g) is within %g clearances of a surface", v.lights[i][0],
                  v.lights[i][1], v.lights[i][2], (double)VDSH_VIEW_LIGHT_MARGIN);
            int in_pillar = 1;
            for (int k = 0; k < 3; k++)
                in_pillar &= v.lights[i][k] >= plo[k] && v.lights[i][k] <= phi[k];
            CHECK(!in_pillar, "light 2 is still in the pillar");
            printf("room: light 2 moved %.3f from (%g, %g, %g) to (%g, %g, %g)\n", (double)moved,
                   v.preferred[i][0], v.preferred[i][1], v.preferred[i][2], v.lights[i][0],
                   v.lights[i][1], v.lights[i][2]);
        } else {
            CHECK(was_free, "light %d's preferred position is not free", i);
            CHECK(!memcmp(v.lights[i], v.preferred[i], sizeof v.lights[i]),
                  "light %d moved from a free position", i);
        }
    }
}

static void test_object(void)
{
    memset(&M, 0, sizeof M);
    const float c[3] = {3, 1, -2};
    sphere(&M, c, 1.0f, 16, 24);
    vdsh_view_mesh m = view_mesh(&M);
    vdsh_view v;
    vdsh_error err;
    CHECK(vdsh_view_compute(&m, &v, &err) == VDSH_OK, "%s", err.msg);
    CHECK(!v.interior && v.front_share == 0.0f, "a sphere: interior %d, front share %g", v.interior,
          (double)v.front_share);
    /* light 0 in a corner of the bounds faces 32% of the sphere seen
     * from the fit direction: the camera turns toward it */
    check_key_camera(&m, &v, "sphere");
    float diag = vdsh_view_diagonal(v.bounds_min, v.bounds_max);
    for (int i = 0; i < v.light_count; i++) {
        float r = dist3(v.lights[i], c);
        CHECK(r > 1.0f + vdsh_free_clearance(diag), "light %d is %g from the centre", i, (double)r);
        CHECK(v.light_free[i] && free_all(&m, v.lights[i], diag), "light %d is not free", i);
        CHECK(!memcmp(v.lights[i], v.preferred[i], sizeof v.lights[i]), "light %d moved", i);
    }
}

typedef struct plain_ctx {
    const vdsh_view_mesh *m;
    float diag;
} plain_ctx;

static int plain_free(const void *ctx, const float p[3])
{
    const plain_ctx *c = ctx;
    return free_all(c->m, p, c->diag);
}

/* A room with a light region recorded (the file's lreg, vdsh-bake
 * --light-region): its default lights go there, as an object's do (they
 * stayed in the bounds, lights the bake trained on none of); a region
 * reaching outside the room (the bounds grown) keeps them inside it, free;
 * the frame rule's candidates come from the region too. */
static void test_room_region(void)
{
    float plo[3], phi[3];
    unit_room(&M, plo, phi);
    vdsh_view_mesh m = view_mesh(&M);
    vdsh_view plain, v;
    vdsh_error err;
    CHECK(vdsh_view_compute(&m, &plain, &err) == VDSH_OK, "%s", err.msg);
    /* the half of the room toward -x, below 4 m */
    static const float half[6] = {-9.5f, 0.5f, -9.5f, -1.0f, 4.0f, 9.5f};
    int outside = 0;
    for (int i = 0; i < plain.light_count; i++)
        outside += plain.lights[i][0] > half[3];
    CHECK(outside > 0, "no default light of the room outside the test's box: it proves nothing");
    m.light_region = half;
    CHECK(vdsh_view_compute(&m, &v, &err) == VDSH_OK, "%s", err.msg);
    const float diag = vdsh_view_diagonal(v.bounds_min, v.bounds_max);
    CHECK(v.interior && v.region_given, "room with a region: interior %d, region given %d",
          v.interior, v.region_given);
    CHECK(!memcmp(&v.camera, &plain.camera, sizeof v.camera), "the region moved the camera");
    for (int i = 0; i < v.light_count; i++) {
        int in = 1;
        for (int k = 0; k < 3; k++)
            in = in && v.lights[i][k] >= half[k] && v.lights[i][k] <= half[k + 3];
        CHECK(in && v.light_free[i] && free_all(&m, v.lights[i], diag),
              "room light %d (%g %g %g) outside the region given, or not free", i,
              (double)v.lights[i][0], (double)v.lights[i][1], (double)v.lights[i][2]);
    }
    /* the bounds grown by a quarter diagonal: outside the room is not
     * free, so every light stays inside it */
    const float g = 0.25f * diag;
    const float grown[6] = {-10 - g, -g, -10 - g, 10 + g, 6 + g, 10 + g};
    m.light_region = grown;
    CHECK(vdsh_view_compute(&m, &v, &err) == VDSH_OK, "%s", err.msg);
    for (int i = 0; i < v.light_count; i++) {
        int in = 1;
        for (int k = 0; k < 3; k++)
            in = in && v.lights[i][k] > v.bounds_min[k] && v.lights[i][k] < v.bounds_max[k];
        CHECK(in && v.light_free[i], "grown region: room light %d (%g %g %g) outside the room", i,
              (double)v.lights[i][0], (double)v.lights[i][1], (double)v.lights[i][2]);
    }
}

/* An object on a floor (a unit cube on a 4 x 4 quad, seen from outside):
 * its light region is its bounds (the box is mostly free), the one the
 * bake trains its fit on, and every default light lies in it, free, within
 * a diagonal (the default clamp) of every corner of the bounds. The
 * lights outside the bounding sphere that were the rule stood beyond the
 * region, up to 1.48 diagonals from the floor's far corner, and drew
 * false blotches on the open floor. */
static void test_object_on_floor(void)
{
    memset(&M, 0, sizeof M);
    quad(&M, (float[3]){-2, 0, -2}, (float[3]){-2, 0, 2}, (float[3]){2, 0, 2},
         (float[3]){2, 0, -2});
    box(&M, (float[3]){-0.5f, 0, -0.5f}, (float[3]){0.5f, 1, 0.5f}, 0);
    vdsh_view_mesh m = view_mesh(&M);
    vdsh_view v;
    vdsh_error err;
    CHECK(vdsh_view_compute(&m, &v, &err) == VDSH_OK, "%s", err.msg);
    CHECK(!v.interior, "a cube on a floor: an interior");
    const float diag = vdsh_free_diagonal(v.bounds_min, v.bounds_max);
    plain_ctx pc = {&m, diag};
    float lo[3], hi[3];
    int grown = vdsh_light_region(v.bounds_min, v.bounds_max, plain_free, &pc, lo, hi, NULL);
    CHECK(!grown && v.region_grown == grown, "a cube on a floor: region grown %d (plain %d)",
          v.region_grown, grown);
    CHECK(!memcmp(lo, v.region_min, sizeof lo) && !memcmp(hi, v.region_max, sizeof hi),
          "the view's light region is not vdsh_light_region's");
    for (int i = 0; i < v.light_count; i++) {
        const float *p = v.lights[i];
        int in = 1;
        for (int k = 0; k < 3; k++)
            in = in && p[k] >= lo[k] && p[k] <= hi[k];
        CHECK(in, "light %d (%g %g %g) outside the light region", i, (double)p[0], (double)p[1],
              (double)p[2]);
        CHECK(v.light_free[i] && free_all(&m, p, diag), "light %d is not free", i);
        for (int corner = 0; corner < 8; corner++) {
            float q[3];
            for (int k = 0; k < 3; k++)
                q[k] = (corner >> k) & 1 ? v.bounds_max[k] : v.bounds_min[k];
            CHECK(dist3(p, q) <= diag, "light %d is %g diagonals from corner %d", i,
                  (double)(dist3(p, q) / diag), corner);
        }
    }
}

/* A point seen by camera c: in front of it and within 30 degrees of its
 * axis up, down and to the sides (fov_y 60, an image at least square). */
static int in_view(const vdsh_camera *c, const float p[3])
{
    float s[3], u[3], f[3], d[3];
    vdsh_camera_basis(c, s, u, f);
    for (int k = 0; k < 3; k++)
        d[k] = p[k] - c->eye[k];
    float z = d[0] * f[0] + d[1] * f[1] + d[2] * f[2];
    float x = d[0] * s[0] + d[1] * s[1] + d[2] * s[2];
    float y = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
    float t = tanf(30.0f * 3.14159265f / 180.0f) * 1.0001f;
    return z > 0.0f && fabsf(x) <= t * z && fabsf(y) <= t * z;
}

static float side_of(const float p[3], const float o[3], const float n[3])
{
    return (p[0] - o[0]) * n[0] + (p[1] - o[1]) * n[1] + (p[2] - o[2]) * n[2];
}

/* A flat object, one triangle facing any way (axis-aligned both ways,
 * tilted both ways) or a quad whose second triangle is wound the other
 * way (its normals still say the front): the default camera sees the
 * side the normals face, the whole object in view, and every light on
 * that side. (The fit camera's fixed direction saw a triangle facing away
 * from it from behind.) */
static void test_flat(void)
{
    static const float dirs[][3] = {{0, 0, 1},  {0, 0, -1}, {1, 0, 0},    {-1, 0, 0},  {0, 1, 0},
                                    {0, -1, 0}, {1, 2, 3},  {-1, -2, -3}, {-3, 1, -2}, {3, -1, 2}};
    const float o[3] = {3, 1, -2};
    for (size_t i = 0; i < sizeof dirs / sizeof dirs[0] + 1; i++) {
        int is_quad = i == sizeof dirs / sizeof dirs[0];
        float n[3], t1[3], t2[3];
        memcpy(n, dirs[is_quad ? 1 : i], sizeof n);
        float l = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; k++)
            n[k] /= l;
        /* t1 across n, t2 = n x t1: a t1 t2 counter-clockwise seen from n */
        float a[3] = {fabsf(n[0]) < 0.9f ? 1.0f : 0.0f, fabsf(n[0]) < 0.9f ? 0.0f : 1.0f, 0};
        t1[0] = a[1] * n[2] - a[2] * n[1];
        t1[1] = a[2] * n[0] - a[0] * n[2];
        t1[2] = a[0] * n[1] - a[1] * n[0];
        l = sqrtf(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
        for (int k = 0; k < 3; k++)
            t1[k] /= l;
        t2[0] = n[1] * t1[2] - n[2] * t1[1];
        t2[1] = n[2] * t1[0] - n[0] * t1[2];
        t2[2] = n[0] * t1[1] - n[1] * t1[0];
        memset(&M, 0, sizeof M);
        float p[4][3];
        for (int k = 0; k < 3; k++) {
            p[0][k] = o[k];
            p[1][k] = o[k] + 2.0f * t1[k];
            p[2][k] = o[k] + 2.0f * t1[k] + t2[k];
            p[3][k] = o[k] + t2[k];
        }
        if (is_quad) {
            quad(&M, p[0], p[1], p[2], p[3]);
            uint32_t swap = M.idx[1][1];
            M.idx[1][1] = M.idx[1][2];
            M.idx[1][2] = swap;
        } else {
            static const int corner[3] = {0, 1, 3};
            for (int v = 0; v < 3; v++) {
                memcpy(M.pos[v], p[corner[v]], sizeof p[0]);
                memcpy(M.nrm[v], n, sizeof n);
                M.idx[0][v] = (uint32_t)v;
            }
            M.nv = 3, M.nt = 1;
        }
        vdsh_view_mesh m = view_mesh(&M);
        vdsh_view v;
        vdsh_error err;
        CHECK(vdsh_view_compute(&m, &v, &err) == VDSH_OK, "%s", err.msg);
        CHECK(!v.interior, "flat %zu: an interior", i);
        CHECK(side_of(v.camera.eye, o, n) > 0.0f,
              "flat %zu (normal %g %g %g): the camera sees the back (eye %g %g %g)", i,
              (double)n[0], (double)n[1], (double)n[2], (double)v.camera.eye[0],
              (double)v.camera.eye[1], (double)v.camera.eye[2]);
        CHECK(!vdsh_camera_degenerate(&v.camera), "flat %zu: a degenerate camera", i);
        {
            /* seen at most VDSH_VIEW_FLAT_ANGLE off its normal (was up to
             * 66 degrees: a panel facing across the longest axis) */
            float e[3], el = 0.0f;
            for (int k = 0; k < 3; k++)
                e[k] = v.camera.eye[k] - v.camera.target[k], el += e[k] * e[k];
            const float cang = side_of(e, (float[3]){0, 0, 0}, n) / sqrtf(el);
            CHECK(cang >= cosf(VDSH_VIEW_FLAT_ANGLE * 3.14159265f / 180.0f) - 1e-4f,
                  "flat %zu (normal %g %g %g): seen %g degrees off its normal", i, (double)n[0],
                  (double)n[1], (double)n[2], acos((double)cang) * 180.0 / 3.14159265358979);
        }
        CHECK(same_camera(&v.fit, &v.camera), "flat %zu: the fit camera (--fit) is not the view's",
              i);
        for (int k = 0; k < 4; k++)
            CHECK(k == 2 && !is_quad ? 1 : in_view(&v.camera, p[k]),
                  "flat %zu: corner %d out of view", i, k);
        /* every light, light 0 (vdsh-view's one) first, lights the front:
         * light 0 stood behind a triangle facing +-z (the frame black) */
        for (int k = 0; k < v.light_count; k++)
            CHECK(side_of(v.lights[k], o, n) > 0.0f,
                  "flat %zu (normal %g %g %g): light %d (%g %g %g) is behind the front", i,
                  (double)n[0], (double)n[1], (double)n[2], k, (double)v.lights[k][0],
                  (double)v.lights[k][1], (double)v.lights[k][2]);
    }
}

/* A quad whose fourth corner stands a thousandth of its diagonal off the
 * plane of the other three, tilted (OBJ/regr_3429812.obj of assimp's
 * models, 1 cm across): flat, seen from its front within
 * VDSH_VIEW_FLAT_ANGLE of its normal, every light on that side (it was
 * taken for a solid and framed edge-on, a line). */
static void test_nearly_flat(void)
{
    static const float p[4][3] = {{0.0498759f, 0.964456f, 0.0949991f},
                                  {0.042335f, 0.96222f, 0.0980526f},
                                  {0.0418548f, 0.961535f, 0.096869f},
                                  {0.049267f, 0.963762f, 0.0939126f}};
    float e1[3], e2[3], n[3];
    for (int k = 0; k < 3; k++)
        e1[k] = p[1][k] - p[0][k], e2[k] = p[2][k] - p[0][k];
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    float l = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int k = 0; k < 3; k++)
        n[k] /= l;
    memset(&M, 0, sizeof M);
    for (int v = 0; v < 4; v++) {
        memcpy(M.pos[v], p[v], sizeof p[0]);
        memcpy(M.nrm[v], n, sizeof n);
    }
    static const uint32_t idx[2][3] = {{0, 1, 2}, {0, 2, 3}};
    memcpy(M.idx, idx, sizeof idx);
    M.nv = 4, M.nt = 2;
    vdsh_view_mesh m = view_mesh(&M);
    vdsh_view v;
    vdsh_error err;
    CHECK(vdsh_view_compute(&m, &v, &err) == VDSH_OK, "%s", err.msg);
    float e[3], el = 0.0f;
    for (int k = 0; k < 3; k++)
        e[k] = v.camera.eye[k] - v.camera.target[k], el += e[k] * e[k];
    const float cang = side_of(e, (float[3]){0, 0, 0}, n) / sqrtf(el);
    CHECK(!v.interior && cang >= cosf(VDSH_VIEW_FLAT_ANGLE * 3.14159265f / 180.0f) - 1e-4f,
          "nearly flat quad: seen %g degrees off its normal", acos((double)cang) * 180.0 / 3.14159);
    for (int k = 0; k < v.light_count; k++)
        CHECK(side_of(v.lights[k], p[0], n) > 0.0f, "nearly flat quad: light %d behind it", k);
}

/* A sphere scaled by s: the view of a scene at any scale the view's float
 * arithmetic takes, a clear error beyond it (a scene 1e19 across crashed
 * the ray grid; 1e-20 across gave a light with infinite attenuation). */
static void test_scale(void)
{
    const struct {
        float s;
        const char *want; /* NULL: computed */
    } cases[] = {{1e-14f, NULL},
                 {1e17f, NULL},
                 {1e-17f, "scale the scene up"},
                 {1e-30f, "scale the scene up"},
                 {1e19f, "scale the scene down"},
                 {1e30f, "scale the scene down"}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        memset(&M, 0, sizeof M);
        const float c[3] = {3 * cases[i].s, cases[i].s, -2 * cases[i].s};
        sphere(&M, c, cases[i].s, 8, 12);
        vdsh_view_mesh m = view_mesh(&M);
        vdsh_view v;
        vdsh_error err = {0};
        vdsh_result r = vdsh_view_compute(&m, &v, &err);
        if (!cases[i].want) {
            CHECK(r == VDSH_OK, "a sphere of radius %g: %s", (double)cases[i].s, err.msg);
            if (r == VDSH_OK) {
                CHECK(!v.interior && !vdsh_camera_degenerate(&v.camera),
                      "a sphere of radius %g: interior %d, a degenerate camera", (double)cases[i].s,
                      v.interior);
                for (int k = 0; k < v.light_count; k++)
                    CHECK(isfinite(v.lights[k][0]) && isfinite(v.lights[k][1]) &&
                              isfinite(v.lights[k][2]),
                          "a sphere of radius %g: light %d not finite", (double)cases[i].s, k);
            }
        } else {
            CHECK(r == VDSH_ERR_INVALID && strstr(err.msg, cases[i].want),
                  "a sphere of radius %g: result %d, '%s' (want '%s')", (double)cases[i].s, (int)r,
                  err.msg, cases[i].want);
        }
    }
}

static void test_none(void)
{
    /* A solid cube (faces outward by winding) whose normals say "room":
     * the interior test sees fronts, every point inside sees backs. */
    memset(&M, 0, sizeof M);
    box(&M, (float[3]){-5, 0, -5}, (float[3]){5, 3, 5}, 0);
    for (uint32_t i = 0; i < M.nv; i++)
        for (int k = 0; k < 3; k++)
            M.nrm[i][k] = -M.nrm[i][k];
    vdsh_view_mesh m = view_mesh(&M);
    vdsh_view v;
    vdsh_error err;
    CHECK(vdsh_view_compute(&m, &v, &err) == VDSH_OK, "%s", err.msg);
    CHECK(v.interior, "the inverted cube should pass as a room");
    for (int i = 0; i < v.light_count; i++) {
        CHECK(!v.light_free[i], "light %d found free space inside a solid", i);
        CHECK(!memcmp(v.lights[i], v.preferred[i], sizeof v.lights[i]),
              "light %d without free space moved", i);
    }
    printf("none: %u positions tried\n", v.light_trials);
}

/* The share of a w x h frame of camera c lit and shadowed by a light at
 * L, every ray cast at every triangle (vdsh_view_light_shares' rule). */
static void shares_all(const vdsh_view_mesh *m, const vdsh_camera *c, int w, int h,
                       const float L[3], float diag, float *lit, float *shadowed)
{
    int a = 0, b = 0;
    float eps = 1e-4f * diag;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float o[3], d[3], n[3], p[3], l[3];
            vdsh_view_hit hit;
            vdsh_camera_ray(c, w, h, x, y, o, d);
            if (!vdsh_view_trace_all(m, o, d, 0.0f, &hit))
                continue;
            const uint32_t *t = m->indices + 3 * (size_t)hit.triangle;
            float dot = 0.0f, facing = 0.0f, dist = 0.0f;
            for (int k = 0; k < 3; k++) {
                n[k] = (1.0f - hit.u - hit.v) * m->normals[3 * t[0] + k] +
                       hit.u * m->normals[3 * t[1] + k] + hit.v * m->normals[3 * t[2] + k];
                dot += n[k] * d[k];
                p[k] = o[k] + hit.t * d[k];
                l[k] = L[k] - p[k];
                dist += l[k] * l[k];
            }
            for (int k = 0; k < 3; k++)
                facing += (dot > 0.0f ? -n[k] : n[k]) * l[k];
            if (facing <= 0.0f)
                continue;
            dist = sqrtf(dist);
            for (int k = 0; k < 3; k++)
                l[k] /= dist;
            vdsh_view_hit sh;
            if (vdsh_view_trace_all(m, p, l, eps, &sh) && sh.t < dist - eps)
                b++;
            else
                a++;
        }
    *lit = (float)a / (float)(w * h);
    *shadowed = (float)b / (float)(w * h);
}

/* Two rooms, 20 x 4 x 8, split at x = 12 by a wall 0.4 thick with a door
 * (z 0.4..1.4, 2.2 high), a crate in the camera's room (x > 12: the room
 * camera stands at 36% of the length past the middle). The preferred
 * light 0 (42% of the length) is in the other room, in free space, and
 * lights what the camera sees through the door only: the first picture
 * was the wall and a dark floor. Every default light must light the frame,
 * light 0 from the camera's room, and shadow part of it (the crate). */
static void test_two_rooms(void)
{
    memset(&M, 0, sizeof M);
    box(&M, (float[3]){0, 0, 0}, (float[3]){20, 4, 8}, 1);
    box(&M, (float[3]){11.8f, 0, 0}, (float[3]){12.2f, 4, 0.4f}, 0);
    box(&M, (float[3]){11.8f, 0, 1.4f}, (float[3]){12.2f, 4, 8}, 0);
    box(&M, (float[3]){11.8f, 2.2f, 0.4f}, (float[3]){12.2f, 4, 1.4f}, 0);
    box(&M, (float[3]){14, 0, 2}, (float[3]){15, 1, 3}, 0);
    vdsh_view_mesh m = view_mesh(&M);
    vdsh_view v;
    vdsh_error err;
    CHECK(vdsh_view_compute(&m, &v, &err) == VDSH_OK, "%s", err.msg);
    CHECK(v.interior, "two rooms: not an interior (front share %g)", (double)v.front_share);
    CHECK(v.camera.eye[0] > 12.2f, "the camera is not in the second room (x %g)",
          (double)v.camera.eye[0]);
    float diag = vdsh_view_diagonal(v.bounds_min, v.bounds_max);
    /* the case: the preferred light 0 is free, behind the wall */
    float pref[VDSH_VIEW_MAX_LIGHTS][3], lit, sh;
    vdsh_view_preferred_lights(v.bounds_min, v.bounds_max, 1, pref, VDSH_VIEW_MAX_LIGHTS);
    shares_all(&m, &v.camera, 32, 24, pref[0], diag, &lit, &sh);
    printf("two rooms: preferred light 0 (%g, %g, %g) lights %.1f%%, shadows %.1f%%\n", pref[0][0],
           pref[0][1], pref[0][2], 100.0 * lit, 100.0 * sh);
    CHECK(pref[0][0] < 11.8f && free_all(&m, pref[0], diag) && lit < sh,
          "the test has lost its case: preferred light 0 at x %g, lights %g", (double)pref[0][0],
          (double)lit);
    for (int i = 0; i < v.light_count; i++) {
        shares_all(&m, &v.camera, 32, 24, v.lights[i], diag, &lit, &sh);
        printf("two rooms: light %d (%g, %g, %g) lights %.1f%%, shadows %.1f%% (check frame "
               "%.1f%%, %.1f%%)\n",
               i, v.lights[i][0], v.lights[i][1], v.lights[i][2], 100.0 * lit, 100.0 * sh,
               100.0 * v.light_lit[i], 100.0 * v.light_shadowed[i]);
        CHECK(v.light_free[i] && free_all(&m, v.lights[i], diag), "light %d is not free", i);
        CHECK(lit >= VDSH_VIEW_MIN_SHARE && lit >= sh && v.light_lit[i] >= VDSH_VIEW_MIN_SHARE,
              "light %d lights %g of the frame and shadows %g", i, (double)lit, (double)sh);
    }
    CHECK(v.lights[0][0] > 12.2f, "light 0 is not in the camera's room (x %g)",
          (double)v.lights[0][0]);
    shares_all(&m, &v.camera, 32, 24, v.lights[0], diag, &lit, &sh);
    CHECK(lit >= 0.25f && sh > 0.0f, "light 0 lights %g and shadows %g of the frame", (double)lit,
          (double)sh);
}

/* A block on the floor just in front of the room camera's eye (the
 * Cornell box's short block): the eye is in free space, but most of its
 * frame is the block's face. The eye moves up until the frame is open. */
static void test_blocked_eye(void)
{
    memset(&M, 0, sizeof M);
    const float lo[3] = {-1, 0, -1}, hi[3] = {1, 2, 1};
    box(&M, lo, hi, 1);
    vdsh_camera room;
    vdsh_view_room_camera(lo, hi, &room);
    /* Along z (the camera looks toward -z), the block's face 0.1 in front
     * of the eye, as wide as the room's middle, 0.6 high. */
    const float blo[3] = {-0.6f, 0.0f, room.eye[2] - 0.5f},
                bhi[3] = {0.6f, 0.6f, room.eye[2] - 0.1f};
    box(&M, blo, bhi, 0);
    vdsh_view_mesh m = view_mesh(&M);
    vdsh_view v;
    vdsh_error err;
    CHECK(vdsh_view_compute(&m, &v, &err) == VDSH_OK, "%s", err.msg);
    CHECK(v.interior, "the blocked room is not an interior (front share %g)",
          (double)v.front_share);
    float diag = vdsh_view_diagonal(v.bounds_min, v.bounds_max);
    CHECK(free_all(&m, room.eye, diag), "the test is wrong: the standard eye is not free");
    CHECK(v.camera.eye[1] > bhi[1], "the eye at height %g, not above the block (%g)",
          (double)v.camera.eye[1], (double)bhi[1]);
    CHECK(free_all(&m, v.camera.eye, diag), "the moved eye is not in free space");
    /* Its frame: most rays travel a tenth of the diagonal (by the plain
     * loop); the standard eye's do not. */
    int open_std = 0, open_new = 0;
    for (int y = 0; y < 7; y++)
        for (int x = 0; x < 9; x++) {
            float o[3], d[3];
            vdsh_view_hit h;
            vdsh_camera_ray(&room, 9, 7, x, y, o, d);
            open_std += !vdsh_view_trace_all(&m, o, d, 0.0f, &h) || h.t > 0.1f * diag;
            vdsh_camera_ray(&v.camera, 9, 7, x, y, o, d);
            open_new += !vdsh_view_trace_all(&m, o, d, 0.0f, &h) || h.t > 0.1f * diag;
        }
    CHECK(open_std < 48, "the test is wrong: the standard eye sees %d of 63 open", open_std);
    CHECK(open_new >= 48, "the moved eye sees %d of 63 rays open", open_new);
    printf("blocked eye: moved to height %.2f, open rays %d -> %d of 63\n", (double)v.camera.eye[1],
           open_std, open_new);
}

/* A room twice as long as test_blocked_eye's (its end wall beyond the
 * margin) and a post the standard eye stands in, its top 0.15 below the
 * first higher eye (0.4 of the height): that eye is free (one clearance)
 * and open, but within VDSH_VIEW_EYE_MARGIN clearances of the post (as the
 * Cornell box's stood 0.25 units from a sphere). The eye moves on to a
 * place the margin from every surface. */
static void test_eye_margin(void)
{
    memset(&M, 0, sizeof M);
    const float lo[3] = {-2, 0, -1}, hi[3] = {2, 2, 1};
    box(&M, lo, hi, 1);
    vdsh_camera room;
    vdsh_view_room_camera(lo, hi, &room);
    const float *e = room.eye, up = lo[1] + 0.4f * (hi[1] - lo[1]);
    box(&M, (float[3]){e[0] - 0.1f, 0.0f, e[2] - 0.1f},
        (float[3]){e[0] + 0.1f, up - 0.15f, e[2] + 0.1f}, 0);
    vdsh_view_mesh m = view_mesh(&M);
    vdsh_view v;
    vdsh_error err;
    CHECK(vdsh_view_compute(&m, &v, &err) == VDSH_OK, "%s", err.msg);
    CHECK(v.interior, "the room is not an interior (front share %g)", (double)v.front_share);
    const float clear = vdsh_free_clearance(vdsh_free_diagonal(v.bounds_min, v.bounds_max));
    const float first[3] = {e[0], up, e[2]};
    CHECK(free_all_at(&m, first, clear) && !free_all_at(&m, first, VDSH_VIEW_EYE_MARGIN * clear),
          "the test is wrong: the first higher eye is not free within the margin");
    CHECK(v.camera.eye[1] > up, "the eye at height %g, not above %g", (double)v.camera.eye[1],
          (double)up);
    CHECK(free_all_at(&m, v.camera.eye, VDSH_VIEW_EYE_MARGIN * clear),
          "the moved eye (%g %g %g) is within %g clearances of a surface", (double)v.camera.eye[0],
          (double)v.camera.eye[1], (double)v.camera.eye[2], (double)VDSH_VIEW_EYE_MARGIN);
    printf("eye margin: moved to height %.2f\n", (double)v.camera.eye[1]);
}

static void test_errors(void)
{
    memset(&M, 0, sizeof M);
    box(&M, (float[3]){0, 0, 0}, (float[3]){1, 1, 1}, 0);
    M.idx[3][1] = M.nv;
    vdsh_view_mesh m = view_mesh(&M);
    vdsh_view v;
    memset(&v, 0x5a, sizeof v);
    vdsh_view before = v;
    vdsh_error err = {{0}};
    CHECK(vdsh_view_compute(&m, &v, &err) == VDSH_ERR_INVALID, "an index out of range passed");
    CHECK(strstr(err.msg, "triangle 3") != NULL, "message: %s", err.msg);
    CHECK(!memcmp(&v, &before, sizeof v), "the output was written on failure");
}

/* ---- the built-in room -------------------------------------------------- */

/* bake/lib/builtin.c: pillars 0.4 m square, floor to ceiling; the crates (the
 * third turned 30 degrees about y); the sphere. */
static int in_solid(const float p[3], float margin, char *what, size_t cap)
{
    const float pillars[3][2] = {{-5.5f, 5.5f}, {5.5f, 5.5f}, {5.5f, -5.5f}};
    for (int i = 0; i < 3; i++)
        if (fabsf(p[0] - pillars[i][0]) <= 0.2f + margin &&
            fabsf(p[2] - pillars[i][1]) <= 0.2f + margin) {
            snprintf(what, cap, "the pillar at (%g, %g)", pillars[i][0], pillars[i][1]);
            return 1;
        }
    /* centre x, z, bottom, size, turn */
    const float boxes[3][5] = {{-4.0f, -3.0f, 0.0f, 1.58f, 0.0f},
                               {-4.2f, -3.15f, 1.58f, 0.79f, 0.0f},
                               {4.0f, 3.5f, 0.0f, 1.12f, 30.0f}};
    for (int i = 0; i < 3; i++) {
        float a = boxes[i][4] * 3.14159265f / 180.0f, dx = p[0] - boxes[i][0],
              dz = p[2] - boxes[i][1];
        float u = cosf(a) * dx + sinf(a) * dz, w = -sinf(a) * dx + cosf(a) * dz;
        float h = 0.5f * boxes[i][3] + margin;
        if (fabsf(u) <= h && fabsf(w) <= h && p[1] >= boxes[i][2] - margin &&
            p[1] <= boxes[i][2] + boxes[i][3] + margin) {
            snprintf(what, cap, "crate %d", i);
            return 1;
        }
    }
    if (dist3(p, (float[3]){-1.0f, 0.6f, 2.0f}) <= 0.6f + margin) {
        snprintf(what, cap, "the sphere");
        return 1;
    }
    return 0;
}

static int test_builtin_room(const char *path)
{
    vdsh_file *f = NULL;
    vdsh_error err;
    if (vdsh_read(path, &f, &err) != VDSH_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    float region[6];
    vdsh_view_mesh m;
    vdsh_view_file_mesh(f, region, &m);
    vdsh_view v;
    CHECK(vdsh_view_compute(&m, &v, &err) == VDSH_OK, "%s", err.msg);
    CHECK(v.interior, "%s: not an interior (front share %g)", path, (double)v.front_share);
    /* the room camera as it was written before it moved to formats/: a
     * third of the way along x, 28% up, looking at the far half */
    const float *lo = v.bounds_min, *hi = v.bounds_max;
    vdsh_camera c = {{0.5f * (lo[0] + hi[0]) + 0.36f * (hi[0] - lo[0]),
                      lo[1] + 0.28f * (hi[1] - lo[1]),
                      0.5f * (lo[2] + hi[2]) + 0.05f * (hi[2] - lo[2])},
                     {0.5f * (lo[0] + hi[0]) - 0.2f * (hi[0] - lo[0]),
                      lo[1] + 0.13f * (hi[1] - lo[1]), 0.5f * (lo[2] + hi[2])},
                     {0, 1, 0},
                     60.0f};
    CHECK(same_camera(&v.camera, &c), "%s: the default camera is not the room camera", path);
    float diag = vdsh_view_diagonal(lo, hi), clear = vdsh_free_clearance(diag);
    for (int i = 0; i < v.light_count; i++) {
        char what[64];
        int pref_free = free_all(&m, v.preferred[i], diag);
        float moved = dist3(v.lights[i], v.preferred[i]);
        printf("light %d: preferred (%g, %g, %g)%s, now (%g, %g, %g), moved %.3f\n", i,
               v.preferred[i][0], v.preferred[i][1], v.preferred[i][2],
               pref_free ? " free" : " not free", v.lights[i][0], v.lights[i][1], v.lights[i][2],
               (double)moved);
        CHECK(v.light_free[i] && free_all(&m, v.lights[i], diag), "light %d is not in free space",
              i);
        CHECK(!in_solid(v.lights[i], 0.0f, what, sizeof what), "light %d is inside %s", i, what);
        /* the axis probes keep it clear of the faces it is in front of:
         * no closer than the clearance to a pillar's or crate's sides */
        CHECK(!in_solid(v.lights[i], 0.5f * clear, what, sizeof what),
              "light %d is within half the clearance (%g) of %s", i, (double)(0.5f * clear), what);
        if (i == 1 || i == 2) {
            CHECK(!pref_free,
                  "light %d's preferred position is in free space: the test has "
                  "lost its pillar",
                  i);
            CHECK(in_solid(v.preferred[i], 0.01f, what, sizeof what),
                  "light %d's preferred position is not at a pillar", i);
            /* out of the pillar to a place VDSH_VIEW_LIGHT_MARGIN
             * clearances from every surface, within the reach */
            CHECK(moved > 0.0f && moved <= (VDSH_VIEW_MARGIN_REACH + 0.5f) * clear,
                  "light %d moved %g", i, (double)moved);
            CHECK(free_all_at(&m, v.lights[i], VDSH_VIEW_LIGHT_MARGIN * clear),
                  "light %d is within %g clearances of a surface", i,
                  (double)VDSH_VIEW_LIGHT_MARGIN);
        } else {
            CHECK(pref_free && moved == 0.0f, "light %d: free %d, moved %g", i, pref_free,
                  (double)moved);
        }
    }
    vdsh_free(f);
    return test_report("scene_view room");
}

/* The two rooms 6 high, the crate at x 17: the preferred lights 0 and 1
 * do not light the frame, and the frame rule takes two seeded
 * candidates. Those VDSH_VIEW_LIGHT_MARGIN clearances from every surface
 * come first, as a moved light keeps the margin (both were taken 1-3
 * clearances from a wall or the floor, the hard case of every precomputed
 * shadow, where candidates at the margin also light the frame). */
static void test_seeded_margin(void)
{
    memset(&M, 0, sizeof M);
    box(&M, (float[3]){0, 0, 0}, (float[3]){20, 6, 8}, 1);
    box(&M, (float[3]){11.8f, 0, 0}, (float[3]){12.2f, 6, 0.4f}, 0);
    box(&M, (float[3]){11.8f, 0, 1.4f}, (float[3]){12.2f, 6, 8}, 0);
    box(&M, (float[3]){11.8f, 2.2f, 0.4f}, (float[3]){12.2f, 6, 1.4f}, 0);
    box(&M, (float[3]){17, 0, 2}, (float[3]){18, 1, 3}, 0);
    vdsh_view_mesh m = view_mesh(&M);
    vdsh_view v;
    vdsh_error err;
    CHECK(vdsh_view_compute(&m, &v, &err) == VDSH_OK, "%s", err.msg);
    const float margin = VDSH_VIEW_LIGHT_MARGIN *
                         vdsh_free_clearance(vdsh_view_diagonal(v.bounds_min, v.bounds_max));
    float pref[VDSH_VIEW_MAX_LIGHTS][3];
    vdsh_view_preferred_lights(v.bounds_min, v.bounds_max, 1, pref, VDSH_VIEW_MAX_LIGHTS);
    int seeded = 0;
    for (int i = 0; i < v.light_count; i++) {
        int own = 0; /* a seeded light's preferred place is its own */
        for (int q = 0; q < VDSH_VIEW_MAX_LIGHTS; q++)
            own |= !memcmp(v.preferred[i], pref[q], sizeof pref[q]);
        if (own)
            continue;
        seeded++;
        printf("seeded margin: light %d (%g, %g, %g) lights %.1f%%\n", i, v.lights[i][0],
               v.lights[i][1], v.lights[i][2], 100.0 * v.light_lit[i]);
        CHECK(free_all_at(&m, v.lights[i], margin) && v.light_lit[i] >= VDSH_VIEW_MIN_SHARE,
              "seeded light %d (%g, %g, %g) nearer than %g clearances to a surface, or lights "
              "%g of the frame",
              i, (double)v.lights[i][0], (double)v.lights[i][1], (double)v.lights[i][2],
              (double)VDSH_VIEW_LIGHT_MARGIN, (double)v.light_lit[i]);
    }
    CHECK(seeded == 2, "the test has lost its case: %d seeded lights, not 2", seeded);
}

/* An object whose bounds hold free space (its light region its bounds, not
 * grown): every default light lights what the camera sees of it, at least
 * as much as it shadows. The 2CylinderEngine's light 0, pulled into its
 * bounds, stood inside its end cap on the side away from the eye (lit 0.9%
 * of the frame, shadowed 3.5%): its default view was mostly dark. */
static int test_object_lights(const char *path)
{
    vdsh_file *f = NULL;
    vdsh_error err;
    if (vdsh_read(path, &f, &err) != VDSH_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    float region[6];
    vdsh_view_mesh m;
    vdsh_view_file_mesh(f, region, &m);
    vdsh_view v;
    CHECK(vdsh_view_compute(&m, &v, &err) == VDSH_OK, "%s", err.msg);
    CHECK(!v.interior && !v.region_grown,
          "%s: interior %d, region grown %d (want an object whose "
          "region is its bounds)",
          path, v.interior, v.region_grown);
    check_key_camera(&m, &v, path);
    vdsh_view_tracer *t = NULL;
    CHECK(vdsh_view_tracer_create(&m, &t, &err) == VDSH_OK, "%s", err.msg);
    const float diag = vdsh_view_diagonal(v.bounds_min, v.bounds_max);
    for (int i = 0; t && i < v.light_count; i++) {
        float lit, sh;
        vdsh_view_light_shares(t, &m, &v.camera, VDSH_VIEW_CHECK_W, VDSH_VIEW_CHECK_H, v.lights[i],
                               diag, &lit, &sh);
        printf("light %d at (%g, %g, %g): lit %.1f%%, shadowed %.1f%% of the frame\n", i,
               (double)v.lights[i][0], (double)v.lights[i][1], (double)v.lights[i][2], 100.0 * lit,
               100.0 * sh);
        CHECK(lit > 0.0f && lit >= sh, "%s: light %d lights %g of the frame, shadows %g", path, i,
              (double)lit, (double)sh);
    }
    vdsh_view_tracer_destroy(t);
    vdsh_free(f);
    return test_report("scene_view object lights");
}

int main(int argc, char **argv)
{
    if (argc == 3 && !strcmp(argv[1], "room"))
        return test_builtin_room(argv[2]);
    if (argc == 3 && !strcmp(argv[1], "object-lights"))
        return test_object_lights(argv[2]);
    if (argc != 2 || strcmp(argv[1], "unit")) {
        fprintf(stderr, "usage: test_scene_view unit | room ROOM.vdsh\n");
        return 2;
    }
    test_rays();
    test_space();
    test_room();
    test_room_region();
    test_object();
    test_object_on_floor();
    test_flat();
    test_nearly_flat();
    test_scale();
    test_none();
    test_two_rooms();
    test_seeded_margin();
    test_blocked_eye();
    test_eye_margin();
    test_errors();
    return test_report("scene_view");
}
