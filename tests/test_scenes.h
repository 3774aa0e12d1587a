/*
 * test_scenes.h - small scenes built in code for the bake tests, so the
 * default suite needs no files. Every builder fills a zeroed vb_mesh that
 * the caller frees with test_mesh_free().
 */
#ifndef VDSH_TEST_SCENES_H
#define VDSH_TEST_SCENES_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mesh.h"

static inline void test_mesh_alloc(vb_mesh *m, uint32_t nv, uint32_t nt)
{
    m->vertex_count = nv;
    m->triangle_count = nt;
    m->positions = calloc(3 * (size_t)nv + 1, sizeof(float));
    m->normals = calloc(3 * (size_t)nv + 1, sizeof(float));
    m->indices = calloc(3 * (size_t)nt + 1, sizeof(uint32_t));
}

static inline void test_mesh_free(vb_mesh *m)
{
    free(m->positions);
    free(m->normals);
    free(m->indices);
    memset(m, 0, sizeof *m);
}

/* Closed box [-a,a] x [0,h] x [-b,b] as 8 shared vertices and 12
 * triangles (normals +y: only the occluders matter). */
static inline void test_make_box(vb_mesh *m, float a, float h, float b)
{
    test_mesh_alloc(m, 8, 12);
    for (int i = 0; i < 8; i++) {
        m->positions[3 * i + 0] = (i & 1) ? a : -a;
        m->positions[3 * i + 1] = (i & 2) ? h : 0.0f;
        m->positions[3 * i + 2] = (i & 4) ? b : -b;
        m->normals[3 * i + 1] = 1.0f;
    }
    static const uint32_t q[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                                     {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
    for (int f = 0; f < 6; f++) {
        uint32_t t[6] = {q[f][0], q[f][1], q[f][2], q[f][0], q[f][2], q[f][3]};
        memcpy(m->indices + 6 * f, t, sizeof t);
    }
}

/* Receivers that are bare points with normals (no triangles). */
static inline void test_make_points(vb_mesh *m, int n, const float *p, const float *nrm)
{
    test_mesh_alloc(m, (uint32_t)n, 0);
    memcpy(m->positions, p, 3 * (size_t)n * sizeof(float));
    memcpy(m->normals, nrm, 3 * (size_t)n * sizeof(float));
}

/* Append one quad c0..c3 (counter-clockwise seen from the side `n` points
 * to) with its own four vertices: unwelded, like a game level's faces. */
static inline void test_add_quad(vb_mesh *m, const float c[4][3], const float n[3])
{
    uint32_t v0 = m->vertex_count, t0 = m->triangle_count;
    m->positions = realloc(m->positions, 3 * (size_t)(v0 + 4) * sizeof(float));
    m->normals = realloc(m->normals, 3 * (size_t)(v0 + 4) * sizeof(float));
    m->indices = realloc(m->indices, 3 * (size_t)(t0 + 2) * sizeof(uint32_t));
    for (int k = 0; k < 4; k++) {
        memcpy(m->positions + 3 * (v0 + k), c[k], 3 * sizeof(float));
        memcpy(m->normals + 3 * (v0 + k), n, 3 * sizeof(float));
    }
    uint32_t t[6] = {v0, v0 + 1, v0 + 2, v0, v0 + 2, v0 + 3};
    memcpy(m->indices + 3 * t0, t, sizeof t);
    m->vertex_count += 4;
    m->triangle_count += 2;
}

/* Closed room [-a,a] x [0,h] x [-b,b], six unwelded inward-facing quads. */
static inline void test_make_room(vb_mesh *m, float a, float h, float b)
{
    const float fl[4][3] = {{-a, 0, -b}, {-a, 0, b}, {a, 0, b}, {a, 0, -b}};
    const float ce[4][3] = {{-a, h, -b}, {a, h, -b}, {a, h, b}, {-a, h, b}};
    const float wx0[4][3] = {{-a, 0, -b}, {-a, h, -b}, {-a, h, b}, {-a, 0, b}};
    const float wx1[4][3] = {{a, 0, -b}, {a, 0, b}, {a, h, b}, {a, h, -b}};
    const float wz0[4][3] = {{-a, 0, -b}, {a, 0, -b}, {a, h, -b}, {-a, h, -b}};
    const float wz1[4][3] = {{-a, 0, b}, {-a, h, b}, {a, h, b}, {a, 0, b}};
    const float up[3] = {0, 1, 0}, down[3] = {0, -1, 0}, px[3] = {1, 0, 0}, nx[3] = {-1, 0, 0},
                pz[3] = {0, 0, 1}, nz[3] = {0, 0, -1};
    test_add_quad(m, fl, up);
    test_add_quad(m, ce, down);
    test_add_quad(m, wx0, px);
    test_add_quad(m, wx1, nx);
    test_add_quad(m, wz0, pz);
    test_add_quad(m, wz1, nz);
}

/* The area of triangle t of m, in double. */
static inline double test_triangle_area(const vb_mesh *m, uint32_t t)
{
    const float *p0 = m->positions + 3 * (size_t)m->indices[3 * t];
    const float *p1 = m->positions + 3 * (size_t)m->indices[3 * t + 1];
    const float *p2 = m->positions + 3 * (size_t)m->indices[3 * t + 2];
    double u[3], v[3];
    for (int k = 0; k < 3; k++) {
        u[k] = (double)p1[k] - p0[k];
        v[k] = (double)p2[k] - p0[k];
    }
    double c[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    return 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

/* The total area of m's triangles. */
static inline double test_mesh_area(const vb_mesh *m)
{
    double a = 0.0;
    for (uint32_t t = 0; t < m->triangle_count; t++)
        a += test_triangle_area(m, t);
    return a;
}

#endif
