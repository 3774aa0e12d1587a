/*
 * test_triangulate.cpp - the ear clipping's time bound (bake/lib/mesh_read.h,
 * triangulate_polygon's budget of point-in-triangle tests; a file's readers
 * share builder::clip_budget). Past the bound a polygon falls back to the
 * fan from its first corner, the triangulation every reader made before ear
 * clipping: n - 2 triangles {0, i, i + 1}, valid (corners in range and
 * distinct) but, for a concave polygon, partly outside it (mesh.c counts
 * and warns). Checked:
 *
 *   budget  for every budget from 0 to what clipping needs, on an L and a
 *           comb (flat, and tilted out of every axis plane): short of it,
 *           false and exactly the fan, the triangles clipped before the
 *           budget ran out dropped and the caller's earlier triangles kept,
 *           the budget spent to 0; with it, true and triangles that tile
 *           the polygon in its winding; with the budget at 0, every later
 *           polygon is fanned at once
 *   file    an OBJ whose first polygon (a comb) needs more tests than a
 *           file's budget and whose second (an L) needs a handful: both
 *           fanned, every triangle's indices in range and distinct, each
 *           face's n - 2 triangles consecutive; the loaded mesh reports
 *           both as past the time bound, and a bowtie after them as not
 *           simple (two warnings), and the L alone in a file is clipped
 *
 *   test_triangulate
 */
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "mesh.h"
#include "mesh_read.h"

static int failures = 0;
#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            std::fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__);                              \
            std::fprintf(stderr, __VA_ARGS__);                                                     \
            std::fprintf(stderr, "\n");                                                            \
            failures++;                                                                            \
        }                                                                                          \
    } while (0)

/* A polygon: corners in order (counter-clockwise seen from +z before the
 * tilt), 3 floats each. */
struct polygon {
    std::vector<float> p;
    void add(double x, double y)
    {
        p.push_back((float)x);
        p.push_back((float)y);
        p.push_back(0.0f);
    }
    size_t n() const
    {
        return p.size() / 3;
    }
};

/* The L of area 3 listed from a corner that does not see all of it. */
static polygon ell()
{
    polygon L;
    const double c[6][2] = {{2, 1}, {1, 1}, {1, 2}, {0, 2}, {0, 0}, {2, 0}};
    for (auto &q : c)
        L.add(q[0], q[1]);
    return L;
}

/* A bowtie: 4 corners crossing themselves (no area). */
static polygon bowtie()
{
    polygon B;
    const double c[4][2] = {{10, 0}, {11, 1}, {11, 0}, {10, 1}};
    for (auto &q : c)
        B.add(q[0], q[1]);
    return B;
}

/* A comb of `teeth` teeth 1 wide and 2 high on a back 1 high, 4 * teeth
 * corners, from the back's corner (0, 0): its fan leaves it at every gap. */
static polygon comb(int teeth)
{
    polygon C;
    C.add(0, 0);
    C.add(2 * teeth - 1, 0);
    for (int i = teeth - 1; i >= 0; i--) {
        C.add(2 * i + 1, 3);
        C.add(2 * i, 3);
        if (i > 0) {
            C.add(2 * i, 1);
            C.add(2 * i - 1, 1);
        }
    }
    return C;
}

/* The polygon scaled by 25 and turned out of every axis plane: a rotation
 * by a 3-4-5 angle about x, then about y (flat but for float rounding). */
static polygon tilted(const polygon &in)
{
    polygon out = in;
    for (size_t c = 0; c < in.n(); c++) {
        const double x = 25.0 * in.p[3 * c], y = 25.0 * in.p[3 * c + 1], z = 25.0 * in.p[3 * c + 2];
        const double y1 = 0.8 * y - 0.6 * z, z1 = 0.6 * y + 0.8 * z;
        const double x2 = 0.8 * x + 0.6 * z1, z2 = -0.6 * x + 0.8 * z1;
        out.p[3 * c] = (float)x2;
        out.p[3 * c + 1] = (float)y1;
        out.p[3 * c + 2] = (float)z2;
    }
    return out;
}

/* Twice the vector area of triangle (a, b, c) of the polygon's corners. */
static void cross(const polygon &P, uint32_t a, uint32_t b, uint32_t c, double x[3])
{
    double u[3], w[3];
    for (int d = 0; d < 3; d++) {
        u[d] = (double)P.p[3 * b + d] - P.p[3 * a + d];
        w[d] = (double)P.p[3 * c + d] - P.p[3 * a + d];
    }
    x[0] = u[1] * w[2] - u[2] * w[1];
    x[1] = u[2] * w[0] - u[0] * w[2];
    x[2] = u[0] * w[1] - u[1] * w[0];
}

/* Whether tris[from..] is exactly the fan of n corners. */
static bool is_fan(const std::vector<uint32_t> &t, size_t from, size_t n)
{
    if (t.size() != from + 3 * (n - 2))
        return false;
    for (size_t i = 1; i + 1 < n; i++) {
        const uint32_t *q = &t[from + 3 * (i - 1)];
        if (q[0] != 0 || q[1] != i || q[2] != i + 1)
            return false;
    }
    return true;
}

/* Whether tris[from..] are n - 2 triangles of distinct corners < n. */
static bool valid(const std::vector<uint32_t> &t, size_t from, size_t n)
{
    if (t.size() != from + 3 * (n - 2))
        return false;
    for (size_t s = from; s < t.size(); s += 3)
        if (t[s] >= n || t[s + 1] >= n || t[s + 2] >= n || t[s] == t[s + 1] ||
            t[s + 1] == t[s + 2] || t[s] == t[s + 2])
            return false;
    return true;
}

/* Whether tris[from..] tile the polygon in its winding: every triangle's
 * vector area along the polygon's, and their areas summing to its own
 * (for a flat polygon, only a tiling does both). */
static bool tiles(const polygon &P, const std::vector<uint32_t> &t, size_t from)
{
    double own[3] = {0, 0, 0}, sum = 0.0;
    for (size_t c = 1; c + 1 < P.n(); c++) {
        double x[3];
        cross(P, 0, (uint32_t)c, (uint32_t)(c + 1), x);
        for (int d = 0; d < 3; d++)
            own[d] += x[d];
    }
    const double len = std::sqrt(own[0] * own[0] + own[1] * own[1] + own[2] * own[2]);
    for (size_t s = from; s < t.size(); s += 3) {
        double x[3];
        cross(P, t[s], t[s + 1], t[s + 2], x);
        if (!(x[0] * own[0] + x[1] * own[1] + x[2] * own[2] > 0.0))
            return false;
        sum += std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    }
    return std::fabs(sum - len) <= 1e-9 * len;
}

static void budget_sweep(const char *name, const polygon &P)
{
    const size_t n = P.n();
    std::vector<int64_t> v(n);
    for (size_t c = 0; c < n; c++)
        v[c] = (int64_t)c;
    /* What clipping needs: the tests one unbounded run makes. */
    std::vector<uint32_t> tris = {7, 7, 7};
    uint64_t b = UINT64_MAX;
    const bool clipped = vb_read::triangulate_polygon(P.p.data(), v.data(), n, tris, &b);
    const uint64_t need = UINT64_MAX - b;
    CHECK(clipped && need > 0 && valid(tris, 3, n) && tiles(P, tris, 3),
          "%s: clipped unbounded (%llu tests), tiling it", name, (unsigned long long)need);
    int short_ok = 0;
    for (uint64_t budget = 0; budget <= need; budget++) {
        tris.assign({7, 8, 9});
        b = budget;
        const bool r = vb_read::triangulate_polygon(P.p.data(), v.data(), n, tris, &b);
        const bool earlier = tris[0] == 7 && tris[1] == 8 && tris[2] == 9;
        if (budget < need) {
            const bool ok = !r && b == 0 && earlier && is_fan(tris, 3, n) && valid(tris, 3, n);
            CHECK(ok, "%s: budget %llu of %llu: %s, %zu corners left, budget left %llu", name,
                  (unsigned long long)budget, (unsigned long long)need,
                  r ? "clipped" : "not the fan or earlier triangles lost", tris.size(),
                  (unsigned long long)b);
            short_ok += ok;
        } else {
            CHECK(r && b == 0 && earlier && valid(tris, 3, n) && tiles(P, tris, 3),
                  "%s: the whole budget (%llu) clips it", name, (unsigned long long)need);
        }
    }
    std::printf("%s: %zu corners, %llu tests to clip; every shorter budget fanned: %s\n", name, n,
                (unsigned long long)need, (uint64_t)short_ok == need ? "yes" : "no");
    /* Spent: later polygons fanned at once, the budget left at 0. */
    tris.clear();
    b = 0;
    CHECK(!vb_read::triangulate_polygon(P.p.data(), v.data(), n, tris, &b) && b == 0 &&
              is_fan(tris, 0, n),
          "%s: no budget left: the fan", name);
}

/* An OBJ of the polygons, one face each, in order. */
static std::string obj_of(const std::vector<polygon> &polys)
{
    std::string s;
    char line[128];
    for (const polygon &P : polys)
        for (size_t c = 0; c < P.n(); c++) {
            std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", (double)P.p[3 * c],
                          (double)P.p[3 * c + 1], (double)P.p[3 * c + 2]);
            s += line;
        }
    size_t base = 1;
    for (const polygon &P : polys) {
        s += "f";
        for (size_t c = 0; c < P.n(); c++) {
            std::snprintf(line, sizeof line, " %zu", base + c);
            s += line;
        }
        s += "\n";
        base += P.n();
    }
    return s;
}

static void file_past_the_bound()
{
    /* A comb clips in about n^2 / 2 tests: one of n^2 / 2 = 1.1 x a
     * file's budget runs it out partway. */
    const double budget = (double)vb_read::builder().clip_budget;
    const int teeth = (int)std::ceil(std::sqrt(2.2 * budget) / 4.0);
    const std::vector<polygon> polys = {comb(teeth), ell()};
    const std::string text = obj_of(polys);
    vb_mesh_raw raw;
    vb_error err;
    vb_result r = vb_mesh_parse("comb.obj", VB_MESH_OBJ, (const uint8_t *)text.data(), text.size(),
                                &raw, &err);
    CHECK(r == VB_OK, "comb.obj: %s", r == VB_OK ? "" : err.msg);
    if (r != VB_OK)
        return;
    const size_t n0 = polys[0].n(), n1 = polys[1].n();
    CHECK(raw.triangle_count == n0 - 2 + n1 - 2, "comb.obj: %u triangles, want %zu",
          raw.triangle_count, n0 - 2 + n1 - 2);
    bool in_range = true, fans = raw.triangle_count == n0 - 2 + n1 - 2;
    for (uint32_t t = 0; t < raw.triangle_count; t++) {
        const int64_t *q = raw.indices + 3 * (size_t)t;
        for (int k = 0; k < 3; k++)
            in_range = in_range && q[k] >= 0 && q[k] < (int64_t)raw.vertex_count;
        in_range = in_range && q[0] != q[1] && q[1] != q[2] && q[0] != q[2];
        /* Face 0's triangles first, then face 1's: each its fan. */
        const bool first = t < n0 - 2;
        const int64_t base = first ? 0 : (int64_t)n0, i = first ? t + 1 : t - (int64_t)(n0 - 2) + 1;
        fans = fans && raw.faces[t] == (first ? 0u : 1u) && q[0] == base && q[1] == base + i &&
               q[2] == base + i + 1;
    }
    CHECK(in_range, "comb.obj: a triangle's corners out of range or repeated");
    CHECK(fans,
          "comb.obj: the comb (%zu corners, past the budget of %.0f tests) and the L "
          "after it are not both their fans",
          n0, budget);
    vb_mesh_raw_free(&raw);
    std::printf("comb.obj: a comb of %zu corners past the budget (%.0f tests) and an L: both "
                "fanned, %zu valid triangles\n",
                n0, budget, n0 - 2 + n1 - 2);

    /* Loaded: both fanned polygons counted as past the time bound, apart
     * from a bowtie after them (crossing itself: not simple, fanned
     * without a try), mesh.c's two warnings (it lumped them in one). */
    const std::string with_bowtie = obj_of({polys[0], polys[1], bowtie()});
    vb_mesh m;
    vb_source_info info;
    std::memset(&m, 0, sizeof m);
    std::memset(&info, 0, sizeof info);
    r = vb_mesh_load_memory(with_bowtie.data(), with_bowtie.size(), "comb.obj", nullptr, &m, &info,
                            &err);
    CHECK(r == VB_OK && info.report.unclipped_polygons == 2 && info.report.nonconvex_polygons == 1,
          "comb.obj loaded: %s, %u polygons past the time bound (want 2), %u not simple (want 1)",
          r == VB_OK ? "" : err.msg, r == VB_OK ? info.report.unclipped_polygons : 0u,
          r == VB_OK ? info.report.nonconvex_polygons : 0u);
    if (r == VB_OK)
        vb_mesh_free(&m);

    /* The L alone is clipped: it was the budget, not the L. */
    const std::string alone = obj_of({ell()});
    r = vb_mesh_parse("ell.obj", VB_MESH_OBJ, (const uint8_t *)alone.data(), alone.size(), &raw,
                      &err);
    bool fan = r == VB_OK && raw.triangle_count == 4;
    for (uint32_t t = 0; fan && t < raw.triangle_count; t++)
        fan = raw.indices[3 * t] == 0 && raw.indices[3 * t + 1] == t + 1 &&
              raw.indices[3 * t + 2] == t + 2;
    CHECK(r == VB_OK && raw.triangle_count == 4 && !fan, "ell.obj alone: %s",
          r == VB_OK ? "fanned, not clipped" : err.msg);
    if (r == VB_OK)
        vb_mesh_raw_free(&raw);
}

/* A bowtie encloses no area, so the warning cannot give the fans' area as
 * a multiple of it (it printed "infx"). */
static void bowtie_warning()
{
    const std::string text = obj_of({bowtie()});
    vb_mesh m;
    vb_source_info info;
    vb_error err;
    std::memset(&m, 0, sizeof m);
    std::memset(&info, 0, sizeof info);
    vb_result r =
        vb_mesh_load_memory(text.data(), text.size(), "bowtie.obj", nullptr, &m, &info, &err);
    if (r != VB_OK) {
        CHECK(false, "bowtie.obj: %s", err.msg);
        return;
    }
    vb_mesh_free(&m);
    char *buf = nullptr;
    size_t size = 0;
    FILE *fp = open_memstream(&buf, &size);
    vb_mesh_report_print(fp, "test", "bowtie.obj", &info.report);
    std::fclose(fp);
    const std::string said(buf ? buf : "");
    std::free(buf);
    CHECK(info.report.nonconvex_polygons == 1 && said.find("encloses none") != std::string::npos &&
              said.find("inf") == std::string::npos && said.find("nan") == std::string::npos,
          "bowtie.obj: %u not simple (want 1), warning: %s", info.report.nonconvex_polygons,
          said.c_str());
}

int main()
{
    budget_sweep("L", ell());
    budget_sweep("comb of 16 teeth", comb(16));
    budget_sweep("comb of 16 teeth, tilted", tilted(comb(16)));
    file_past_the_bound();
    bowtie_warning();
    if (failures)
        std::fprintf(stderr, "test_triangulate: %d failure%s\n", failures,
                     failures == 1 ? "" : "s");
    return failures ? 1 : 0;
}
