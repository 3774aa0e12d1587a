/*
 * Refinement to a maximum edge on a mesh of long thin triangles
 * (vb_mesh_refine, mesh.h): a 20 x 20 m floor made of strips 0.5 m wide
 * and 20 m long (each strip two slivers of aspect ~35), with four thin
 * pillars (0.15 m boxes, 3 m tall), refined to 0.2 m:
 *   - no edge longer than 0.2 and no area lost;
 *   - receivers within 3.5x area / edge^2 (well-shaped triangles from
 *     longest-edge bisection give 1.2 - 2.3x; slivers kept as slivers give
 *     a vertex every 0.2 m along every strip: ~12x here);
 *   - worst aspect ratio (vb_mesh_worst_aspect) below 8, on the floor
 *     (flat: what flips can mend) and overall (the pillars' faces are
 *     narrower than the edge: their pieces are 0.15 x 0.2 at worst).
 * Before the flips (issue 26) the floor gave 11.8x and aspect 34.7.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mesh.h"
#include "test_scenes.h"
#include "test_util.h"

#define EDGE 0.2f

/* The strip floor: vertices every `w` along z = 0 and z = size, y = 0. */
static void make_strips(vb_mesh *m, float size, float w)
{
    uint32_t n = (uint32_t)lrintf(size / w) + 1;
    test_mesh_alloc(m, 2 * n, 2 * (n - 1));
    for (uint32_t i = 0; i < n; i++) {
        float x = (float)i * w;
        float *p = m->positions + 3 * (size_t)i, *q = m->positions + 3 * (size_t)(n + i);
        p[0] = q[0] = x;
        p[2] = 0.0f;
        q[2] = size;
        m->normals[3 * i + 1] = m->normals[3 * (n + i) + 1] = 1.0f;
    }
    for (uint32_t i = 0; i + 1 < n; i++) {
        uint32_t t[6] = {i, n + i, i + 1, i + 1, n + i, n + i + 1};
        memcpy(m->indices + 6 * (size_t)i, t, sizeof t);
    }
}

static double longest_edge(const vb_mesh *m)
{
    double best = 0.0;
    for (uint32_t t = 0; t < m->triangle_count; t++)
        for (int e = 0; e < 3; e++) {
            const float *a = m->positions + 3 * (size_t)m->indices[3 * t + e];
            const float *b = m->positions + 3 * (size_t)m->indices[3 * t + (e + 1) % 3];
            double d = sqrt(((double)a[0] - b[0]) * ((double)a[0] - b[0]) +
                            ((double)a[1] - b[1]) * ((double)a[1] - b[1]) +
                            ((double)a[2] - b[2]) * ((double)a[2] - b[2]));
            if (d > best)
                best = d;
        }
    return best;
}

static void check_refined(const char *what, const vb_mesh *in, double max_ratio, double max_aspect)
{
    vb_mesh out = {0};
    vb_error err;
    CHECK(vb_mesh_refine(in, EDGE, &out, &err) == VB_OK, "%s: refine: %s", what, err.msg);
    double a0 = test_mesh_area(in), a1 = test_mesh_area(&out);
    double ratio = out.vertex_count / (a1 / ((double)EDGE * EDGE));
    uint32_t worst_t = 0;
    double aspect = vb_mesh_worst_aspect(&out, &worst_t);
    printf("%s: %u vertices, %u triangles, %.2fx area / edge^2, worst aspect %.2f (in: %.1f)\n",
           what, out.vertex_count, out.triangle_count, ratio, aspect,
           vb_mesh_worst_aspect(in, NULL));
    CHECK(fabs(a1 - a0) < 1e-4 * a0, "%s: area %g, was %g", what, a1, a0);
    CHECK(longest_edge(&out) <= EDGE * (1.0 + 1e-6), "%s: an edge of %g", what, longest_edge(&out));
    CHECK(ratio <= max_ratio, "%s: %u receivers, %.2fx area / edge^2 (at most %.1fx)", what,
          out.vertex_count, ratio, max_ratio);
    CHECK(aspect < max_aspect, "%s: worst aspect ratio %.1f (triangle %u; below %.0f)", what,
          aspect, worst_t, max_aspect);
    /* Deterministic: the same mesh again. */
    vb_mesh again = {0};
    CHECK(vb_mesh_refine(in, EDGE, &again, &err) == VB_OK, "%s: refine again", what);
    CHECK(again.vertex_count == out.vertex_count && again.triangle_count == out.triangle_count &&
              !memcmp(again.indices, out.indices, 3 * (size_t)out.triangle_count * 4) &&
              !memcmp(again.positions, out.positions, 3 * (size_t)out.vertex_count * 4),
          "%s: not deterministic", what);
    vb_mesh_free(&again);
    vb_mesh_free(&out);
}

int main(void)
{
    vb_error err;
    vb_mesh floor_ = {0};
    make_strips(&floor_, 20.0f, 0.5f);
    CHECK(vb_mesh_worst_aspect(&floor_, NULL) > 30.0, "the floor's strips are not slivers");
    check_refined("strip floor", &floor_, 3.5, 8.0);

    /* The floor with pillars: the interior of the issue (long thin
     * triangles, pillars), 4 pillars at (+-5, +-5). */
    vb_mesh scene = {0};
    make_strips(&scene, 20.0f, 0.5f);
    for (int k = 0; k < 4; k++) {
        vb_mesh box = {0};
        test_make_box(&box, 0.075f, 3.0f, 0.075f);
        for (uint32_t v = 0; v < box.vertex_count; v++) {
            box.positions[3 * v] += (k & 1) ? 15.0f : 5.0f;
            box.positions[3 * v + 2] += (k & 2) ? 15.0f : 5.0f;
        }
        vb_mesh_compute_normals(&box);
        CHECK(vb_mesh_append(&scene, &box, &err) == VB_OK, "append: %s", err.msg);
        test_mesh_free(&box);
    }
    check_refined("floor and pillars", &scene, 3.5, 8.0);

    /* The measure itself: equilateral 1, right isosceles sqrt(3). */
    vb_mesh tri = {0};
    test_mesh_alloc(&tri, 3, 1);
    const float eq[9] = {0, 0, 0, 1, 0, 0, 0.5f, 0.8660254f, 0};
    memcpy(tri.positions, eq, sizeof eq);
    tri.indices[0] = 0, tri.indices[1] = 1, tri.indices[2] = 2;
    CHECK(fabs(vb_mesh_worst_aspect(&tri, NULL) - 1.0) < 1e-5, "equilateral: %g",
          vb_mesh_worst_aspect(&tri, NULL));
    tri.positions[6] = 0.0f, tri.positions[7] = 1.0f;
    CHECK(fabs(vb_mesh_worst_aspect(&tri, NULL) - sqrt(3.0)) < 1e-5, "right isosceles: %g",
          vb_mesh_worst_aspect(&tri, NULL));
    test_mesh_free(&tri);
    test_mesh_free(&scene);
    test_mesh_free(&floor_);
    return test_report("test_refine_shape");
}
