/*
 * mesh_parse.cpp - the strict OBJ/PLY/OFF/STL readers' shared part
 * (mesh_parse.h, mesh_read.h): numbers as the readers read them, the
 * arrays being built, the final checks and the C entry points. The
 * readers themselves, one pass over the file's bytes that checks
 * everything and fills the arrays, are mesh_obj.cpp, mesh_ply.cpp,
 * mesh_off.cpp and mesh_stl.cpp.
 *
 * Until issue 13 the baker read files with OpenMesh's readers behind a
 * strict pre-pass that modelled what those lenient readers would do with
 * the bytes, and refused the files they would have misread: an OBJ vertex
 * whose number does not parse was skipped by OpenMesh (every later index
 * then pointed one vertex off), "nan" or a truncated ascii PLY/OFF put its
 * stream into a failed state and the rest of the file read as zeros, a face
 * with fewer than three vertices vanished, an OFF header that claimed
 * 3.5e12 vertices looped for hours. The pre-pass now produces the arrays
 * itself, with OpenMesh 9's reading rules where they decide the result
 * (recorded bakes depend on them, byte for byte; each reader's file lists
 * its format's rules): numbers are read as std::istream reads them
 * (correctly rounded, the same floats as strtof), and must be whole tokens.
 *
 * One departure from OpenMesh: it fanned every polygon from its first
 * vertex, which puts part of a concave polygon's triangles outside it
 * (phantom occluders: Sponza's arches, fanned up to 3x their area). A
 * polygon whose fan reaches outside it is ear-clipped instead
 * (triangulate_polygon, builder::triangulate, after every reader); any
 * other, every convex polygon included, keeps the fan bit for bit.
 *
 * Normals given for a vertex more than once are averaged as mesh_parse.h
 * says; per face corner (OBJ) each corner keeps the last normal its line
 * gave its vertex.
 *
 * The readers count what the file must deliver (vertices, faces,
 * triangles) as the checks go and compare it with what they built; a
 * difference is refused, never a silently partial mesh.
 */
#include "mesh_read.h"
#include "vdsh_math.h"

#include <algorithm>
#include <array>
#include <cfloat>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <system_error>
#include <utility>
#include <vector>

namespace vb_read
{

/* ====================================================================== */
/* Numbers                                                                */
/* ====================================================================== */

/* Where t's number starts after an optional '+' (which std::from_chars
 * does not take); NULL when nothing follows or a second sign does. */
static const char *after_plus(const token &t)
{
    const char *b = t.b;
    if (b < t.e && *b == '+') {
        b++;
        if (b < t.e && (*b == '-' || *b == '+'))
            return nullptr;
    }
    return b < t.e ? b : nullptr;
}

num_status parse_float(const token &t, float *out)
{
    if (has_nul(t))
        return NUM_NUL;
    const char *b = after_plus(t);
    if (!b)
        return NUM_BAD;
    float f = 0.0f;
    std::from_chars_result r = std::from_chars(b, t.e, f, std::chars_format::general);
    if (r.ec == std::errc::result_out_of_range) {
        /* Out of float range: overflow is an error; underflow (the result
         * rounds to zero) gives the signed zero strtof gives. */
        double d = 0.0;
        r = std::from_chars(b, t.e, d, std::chars_format::general);
        if (r.ec != std::errc() || r.ptr != t.e || std::fabs(d) > (double)FLT_MAX)
            return r.ec == std::errc::invalid_argument ? NUM_BAD : NUM_RANGE;
        f = (float)d;
    } else if (r.ec != std::errc() || r.ptr != t.e) {
        return NUM_BAD;
    }
    if (!std::isfinite(f))
        return NUM_NONFINITE;
    *out = f;
    return NUM_OK;
}

bool parse_int(const token &t, long long *out)
{
    const char *b = after_plus(t);
    if (!b)
        return false;
    long long v = 0;
    std::from_chars_result r = std::from_chars(b, t.e, v, 10);
    if (r.ec != std::errc() || r.ptr != t.e)
        return false;
    *out = v;
    return true;
}

bool stream_int(const char *b, const char *e, int *out)
{
    bool neg = false;
    if (b < e && (*b == '+' || *b == '-'))
        neg = *b++ == '-';
    if (b >= e || !is_digit(*b)) {
        *out = 0;
        return false;
    }
    unsigned long long mag = 0;
    for (; b < e && is_digit(*b); b++)
        if (mag <= (unsigned long long)INT_MAX + 1)
            mag = mag * 10 + (unsigned long long)(*b - '0');
    if (neg) {
        if (mag > (unsigned long long)INT_MAX + 1) {
            *out = INT_MIN;
            return false;
        }
        *out = (int)(-(long long)mag);
        return true;
    }
    if (mag > (unsigned long long)INT_MAX) {
        *out = INT_MAX;
        return false;
    }
    *out = (int)mag;
    return true;
}

const char *num_problem(num_status s)
{
    switch (s) {
    case NUM_OK: return "ok";
    case NUM_BAD: return "is not a number";
    case NUM_RANGE: return "is out of float range";
    case NUM_NONFINITE: return "is not finite";
    case NUM_NUL: return "contains a NUL byte (binary data in a text file?)";
    }
    return "is not a number";
}

/* ====================================================================== */
/* The arrays being built                                                 */
/* ====================================================================== */

void builder::set_normal(int64_t v, const float n[3])
{
    if (v < 0 || (uint64_t)v >= vertex_count() || !std::isfinite(n[0]) || !std::isfinite(n[1]) ||
        !std::isfinite(n[2]))
        return;
    if (per_corner)
        pending.push_back({v, {n[0], n[1], n[2]}});
    size_t nv = (size_t)vertex_count();
    if (normal_sums.size() < 3 * nv) {
        normal_sums.resize(3 * nv, 0.0f);
        has_normal.resize(nv, 0);
    }
    size_t i = (size_t)v;
    float *sum = &normal_sums[3 * i];
    if (has_normal[i] == 0) {
        has_normal[i] = 1;
        sum[0] = n[0], sum[1] = n[1], sum[2] = n[2];
        return;
    }
    if (has_normal[i] == 1) {
        if (sum[0] == n[0] && sum[1] == n[1] && sum[2] == n[2])
            return;
        vdsh_unit3f_keep(sum);
        has_normal[i] = 2;
    }
    float u[3] = {n[0], n[1], n[2]};
    vdsh_unit3f_keep(u);
    for (int k = 0; k < 3; k++)
        sum[k] += u[k];
}

void builder::finish(uint64_t dropped, vb_mesh_raw *out)
{
    vb_mesh_raw raw;
    memset(&raw, 0, sizeof raw);
    try {
        size_t nv = (size_t)vertex_count();
        raw.vertex_count = (uint32_t)nv;
        raw.triangle_count = (uint32_t)triangle_count();
        raw.positions = malloc_copy(positions);
        raw.indices = malloc_copy(indices);
        raw.faces = malloc_copy(tri_face);
        if (!has_normal.empty()) {
            normal_sums.resize(3 * nv, 0.0f);
            has_normal.resize(nv, 0);
            for (size_t i = 0; i < nv; i++)
                vdsh_unit3f_keep(&normal_sums[3 * i]);
            for (uint8_t &h : has_normal)
                h = h != 0;
            raw.normals = malloc_copy(normal_sums);
            raw.has_normal = malloc_copy(has_normal);
        }
        if (!corner_normals.empty()) {
            raw.corner_normals = malloc_copy(corner_normals);
            raw.corner_given = malloc_copy(corner_given);
        }
        raw.dropped_triangles = (uint32_t)std::min<uint64_t>(dropped, UINT32_MAX);
        if (!unclipped.empty()) {
            raw.unclipped_faces = malloc_copy(unclipped);
            raw.unclipped_count = (uint32_t)unclipped.size();
        }
    } catch (...) {
        vb_mesh_raw_free(&raw);
        throw;
    }
    *out = raw;
}

void builder::add_corner_normals(const int64_t *v, size_t n)
{
    if (pending.empty() && corner_normals.empty())
        return;
    size_t tris = indices.size() / 3, fan = n - 2;
    if (corner_normals.empty()) {
        corner_normals.assign(9 * (tris - fan), 0.0f);
        corner_given.assign(3 * (tris - fan), 0);
    }
    std::vector<const std::array<float, 3> *> given(n, nullptr);
    if (pending.size() <= 16) {
        for (size_t c = 0; c < n; c++)
            for (size_t p = pending.size(); p-- > 0;)
                if (pending[p].first == v[c]) {
                    given[c] = &pending[p].second;
                    break;
                }
    } else {
        std::vector<std::pair<int64_t, size_t>> last; /* vertex, latest pending entry */
        last.reserve(pending.size());
        for (size_t p = 0; p < pending.size(); p++)
            last.emplace_back(pending[p].first, p);
        std::stable_sort(last.begin(), last.end(),
                         [](const std::pair<int64_t, size_t> &a,
                            const std::pair<int64_t, size_t> &b) { return a.first < b.first; });
        for (size_t c = 0; c < n; c++) {
            auto it = std::upper_bound(last.begin(), last.end(), std::make_pair(v[c], SIZE_MAX));
            if (it != last.begin() && (it - 1)->first == v[c])
                given[c] = &pending[(it - 1)->second].second;
        }
    }
    for (size_t i = 1; i + 1 < n; i++) {
        const size_t corner[3] = {0, i, i + 1};
        for (size_t k = 0; k < 3; k++) {
            const std::array<float, 3> *g = given[corner[k]];
            corner_given.push_back(g != nullptr);
            for (int q = 0; q < 3; q++)
                corner_normals.push_back(g ? (*g)[(size_t)q] : 0.0f);
        }
    }
    pending.clear();
}

/* ====================================================================== */
/* Polygons: fan or ear clipping                                          */
/* ====================================================================== */

namespace
{

/* Twice the signed area of 2D triangle (a, b, c). */
inline double cross2(const double *a, const double *b, const double *c)
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* Twice the area of 3D triangle (a, b, c), float corners, in double. */
double area3(const float *a, const float *b, const float *c)
{
    double u[3], w[3];
    for (int d = 0; d < 3; d++)
        u[d] = (double)b[d] - a[d], w[d] = (double)c[d] - a[d];
    const double x = u[1] * w[2] - u[2] * w[1], y = u[2] * w[0] - u[0] * w[2],
                 z = u[0] * w[1] - u[1] * w[0];
    return std::sqrt(x * x + y * y + z * z);
}

} // namespace

bool triangulate_polygon(const float *positions, const int64_t *v, size_t n,
                         std::vector<uint32_t> &tris, uint64_t *budget, bool *timed_out)
{
    const size_t first = tris.size();
    auto fan = [&] {
        tris.resize(first);
        for (size_t i = 1; i + 1 < n; i++) {
            tris.push_back(0);
            tris.push_back((uint32_t)i);
            tris.push_back((uint32_t)(i + 1));
        }
        return false;
    };
    if (n < 4)
        return fan();
    auto pos = [&](size_t c) { return positions + 3 * (size_t)v[c]; };

    /* Newell normal (twice the vector area), corners relative to corner 0. */
    std::vector<double> q(3 * n);
    for (size_t c = 0; c < n; c++)
        for (int d = 0; d < 3; d++)
            q[3 * c + (size_t)d] = (double)pos(c)[d] - (double)pos(0)[d];
    double nrm[3] = {0.0, 0.0, 0.0};
    for (size_t c = 1; c + 1 < n; c++) {
        const double *a = &q[3 * c], *b = &q[3 * c + 3];
        nrm[0] += a[1] * b[2] - a[2] * b[1];
        nrm[1] += a[2] * b[0] - a[0] * b[2];
        nrm[2] += a[0] * b[1] - a[1] * b[0];
    }
    const double own = std::sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    if (!(own > 0.0) || !std::isfinite(own))
        return fan();

    /* Drop the dominant axis; (x, y) cyclic after it, so that the 2D
     * winding is the normal's sign along it, made positive. */
    int k = 0;
    for (int d = 1; d < 3; d++)
        if (std::fabs(nrm[d]) > std::fabs(nrm[k]))
            k = d;
    const int ax = (k + 1) % 3, ay = (k + 2) % 3;
    const double flip = nrm[k] < 0.0 ? -1.0 : 1.0;
    std::vector<double> p(2 * n);
    for (size_t c = 0; c < n; c++) {
        p[2 * c] = q[3 * c + (size_t)ax];
        p[2 * c + 1] = flip * q[3 * c + (size_t)ay];
    }
    auto pt = [&](size_t c) { return &p[2 * c]; };

    /* The fan, where none of its triangles is negative. The tolerance
     * (relative to the polygon's own projected area) only keeps rounding
     * in nearly collinear corners from sending a convex polygon on. */
    double total = 0.0, most_negative = 0.0;
    for (size_t i = 1; i + 1 < n; i++) {
        const double a = cross2(pt(0), pt(i), pt(i + 1));
        total += a;
        most_negative = std::min(most_negative, a);
    }
    if (!(total > 0.0) || most_negative >= -1e-9 * total)
        return fan();

    /* Ear clipping over a ring of the corners left. */
    std::vector<size_t> prev(n), next(n);
    for (size_t c = 0; c < n; c++) {
        prev[c] = (c + n - 1) % n;
        next[c] = (c + 1) % n;
    }
    size_t left = n, cur = 1, misses = 0;
    while (left > 3) {
        const size_t a = prev[cur], c = next[cur];
        const double *pa = pt(a), *pb = pt(cur), *pc = pt(c);
        bool ear = cross2(pa, pb, pc) > 0.0;
        for (size_t r = next[c]; ear && r != a; r = next[r]) {
            if (*budget == 0) {
                if (timed_out)
                    *timed_out = true;
                return fan();
            }
            (*budget)--;
            const double *pr = pt(r);
            /* A corner at one of the ear's own positions (a polygon that
             * touches itself there) does not block it. */
            if ((pr[0] == pa[0] && pr[1] == pa[1]) || (pr[0] == pb[0] && pr[1] == pb[1]) ||
                (pr[0] == pc[0] && pr[1] == pc[1]))
                continue;
            if (cross2(pa, pb, pr) >= 0.0 && cross2(pb, pc, pr) >= 0.0 && cross2(pc, pa, pr) >= 0.0)
                ear = false;
        }
        if (ear) {
            tris.push_back((uint32_t)a);
            tris.push_back((uint32_t)cur);
            tris.push_back((uint32_t)c);
            next[a] = c;
            prev[c] = a;
            left--;
            cur = c;
            misses = 0;
        } else {
            cur = next[cur];
            if (++misses >= left)
                return fan(); /* no ear: not a simple polygon */
        }
    }
    if (!(cross2(pt(prev[cur]), pt(cur), pt(next[cur])) >= 0.0))
        return fan();
    tris.push_back((uint32_t)prev[cur]);
    tris.push_back((uint32_t)cur);
    tris.push_back((uint32_t)next[cur]);

    /* Far from flat: the triangles' own area more than 1% over the
     * polygon's vector area (equal for a flat polygon). */
    double area = 0.0;
    for (size_t t = first; t < tris.size(); t += 3)
        area += area3(pos(tris[t]), pos(tris[t + 1]), pos(tris[t + 2]));
    if (!(area <= 1.01 * own))
        return fan();
    return true;
}

void builder::triangulate()
{
    std::vector<int64_t> poly;
    std::vector<uint32_t> tris;
    std::vector<float> normals;
    std::vector<uint8_t> given;
    const size_t nt = tri_face.size();
    const bool corners = !corner_normals.empty();
    for (size_t t = 0; t < nt;) {
        size_t e = t + 1;
        while (e < nt && tri_face[e] == tri_face[t])
            e++;
        const size_t n = e - t + 2;
        if (n >= 4) {
            /* The polygon's corners from its fan: {0,i,i+1} for i = 1..n-2. */
            auto fan_slot = [&](size_t c) {
                return c == 0 ? 3 * t : c + 1 < n ? 3 * (t + c - 1) + 1 : 3 * (t + n - 3) + 2;
            };
            poly.resize(n);
            for (size_t c = 0; c < n; c++)
                poly[c] = indices[fan_slot(c)];
            tris.clear();
            bool timed_out = false;
            const bool clipped = triangulate_polygon(positions.data(), poly.data(), n, tris,
                                                     &clip_budget, &timed_out);
            if (timed_out)
                unclipped.push_back(tri_face[t]);
            if (clipped) {
                if (corners) {
                    normals.resize(3 * n);
                    given.resize(n);
                    for (size_t c = 0; c < n; c++) {
                        const size_t s = fan_slot(c);
                        given[c] = corner_given[s];
                        for (int d = 0; d < 3; d++)
                            normals[3 * c + (size_t)d] = corner_normals[3 * s + (size_t)d];
                    }
                }
                for (size_t j = 0; j < tris.size(); j++) {
                    const size_t s = 3 * t + j, c = tris[j];
                    indices[s] = poly[c];
                    if (corners) {
                        corner_given[s] = given[c];
                        for (int d = 0; d < 3; d++)
                            corner_normals[3 * s + (size_t)d] = normals[3 * c + (size_t)d];
                    }
                }
            }
        }
        t = e;
    }
}

} // namespace vb_read

namespace
{

using namespace vb_read;

vb_result parse(const char *name, vb_mesh_format format, const uint8_t *bytes, size_t size,
                vb_mesh_raw *out, vb_error *err)
{
    builder b;
    expectation ex;
    vb_result r = VB_OK;
    switch (format) {
    case VB_MESH_OBJ: r = read_obj(name, bytes, size, b, &ex, err); break;
    case VB_MESH_PLY: r = read_ply(name, bytes, size, b, &ex, err); break;
    case VB_MESH_OFF: r = read_off(name, bytes, size, b, &ex, err); break;
    case VB_MESH_STL: r = read_stl(name, bytes, size, b, &ex, err); break;
    default: return vb_fail(err, VB_ERR_ARGUMENT, "%s: unknown mesh format", name);
    }
    if (r != VB_OK)
        return r;
    /* What was built is what the checks counted, or the file is refused. */
    if ((ex.vertices_known && b.vertex_count() != ex.vertices) || b.polygons != ex.faces ||
        b.triangle_count() != ex.triangles) {
        if (!ex.hint.empty())
            return vb_fail(
                err, VB_ERR_FORMAT,
                "%s: %s by other readers: the file reads as %llu vertices, %llu faces, %llu triangles "
                "or as %llu, %llu, %llu (refused)",
                name, ex.hint.c_str(), (unsigned long long)b.vertex_count(),
                (unsigned long long)b.polygons, (unsigned long long)b.triangle_count(),
                (unsigned long long)ex.vertices, (unsigned long long)ex.faces,
                (unsigned long long)ex.triangles);
        return vb_fail(
            err, VB_ERR_FORMAT,
            "%s: read %llu vertices, %llu faces, %llu triangles, but the file has %llu, %llu, %llu; "
            "refusing a partial mesh",
            name, (unsigned long long)b.vertex_count(), (unsigned long long)b.polygons,
            (unsigned long long)b.triangle_count(), (unsigned long long)ex.vertices,
            (unsigned long long)ex.faces, (unsigned long long)ex.triangles);
    }
    if (b.vertex_count() > max_count)
        return vb_fail(err, VB_ERR_FORMAT, "%s: too many vertices", name);
    /* Only what the checks could not see (a binary PLY read as OpenMesh
     * read it, an OBJ comment read as corners) can fail here. Element
     * numbers as the format counts them. */
    const unsigned long long base = format == VB_MESH_OBJ ? 1 : 0;
    const uint64_t nv = b.vertex_count();
    for (uint64_t i = 0; i < nv; i++) {
        const float *p = &b.positions[3 * (size_t)i];
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
            return vb_fail(err, VB_ERR_INVALID,
                           "%s: vertex %llu has a non-finite coordinate (%g, %g, %g)", name,
                           (unsigned long long)i + base, (double)p[0], (double)p[1], (double)p[2]);
    }
    for (size_t j = 0; j < b.indices.size(); j++) {
        int64_t v = b.indices[j];
        if (v < 0 || (uint64_t)v >= nv)
            return vb_fail(
                err, VB_ERR_INVALID, "%s: face %llu: vertex index %lld out of range (%u %s)", name,
                (unsigned long long)b.tri_face[j / 3] + base, (long long)v + (long long)base,
                (unsigned)nv, vdsh_plural(nv, "vertex", "vertices"));
    }
    b.triangulate();
    b.finish(ex.dropped, out);
    return VB_OK;
}

} // namespace

/* ====================================================================== */
/* C entry points: no exception passes these                              */
/* ====================================================================== */

extern "C" vb_result vb_mesh_parse(const char *name, vb_mesh_format format, const uint8_t *bytes,
                                   size_t size, vb_mesh_raw *out, vb_error *err)
{
    if (!name || (!bytes && size) || !out)
        return vb_fail(err, VB_ERR_ARGUMENT, "vb_mesh_parse: NULL argument");
    static const uint8_t nothing = 0;
    const uint8_t *b = bytes ? bytes : &nothing;
    /* A value outside the enum is refused here, as an int: it is never
     * loaded as a vb_mesh_format (UBSan's enum check reports such a load
     * through the lambda's reference). */
    const int fmt = format;
    if (fmt < VB_MESH_OBJ || fmt > VB_MESH_GLB)
        return vb_fail(err, VB_ERR_ARGUMENT, "%s: unknown mesh format", name);
    const vb_mesh_format f = static_cast<vb_mesh_format>(fmt);
    return vb_read::no_throw(name, err, [&] { return parse(name, f, b, size, out, err); });
}

extern "C" void vb_mesh_raw_free(vb_mesh_raw *raw)
{
    if (!raw)
        return;
    free(raw->positions);
    free(raw->normals);
    free(raw->has_normal);
    free(raw->corner_normals);
    free(raw->corner_given);
    free(raw->indices);
    free(raw->faces);
    free(raw->unclipped_faces);
    memset(raw, 0, sizeof *raw);
}
