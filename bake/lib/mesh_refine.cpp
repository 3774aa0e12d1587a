/*
 * mesh_refine.cpp - vb_mesh_refine (mesh.h) on OpenMesh's TriMesh: the only
 * code that includes OpenMesh. Reached through the C function at the end,
 * which catches every C++ exception.
 *
 * OpenMesh earns its place here: refinement needs a half-edge structure
 * (the edges around a vertex, the faces on an edge, splitting an edge and
 * both its triangles), and its refusal of non-manifold faces is what tells
 * which triangles get private vertices. Reading files does not use it
 * (mesh_parse.cpp, mesh_obj/ply/off/stl.cpp).
 *
 * OpenMesh prints warnings (a refused face: "complex edge") to its
 * omerr/omlog/omout streams, which forward to std::cerr/clog/cout. While
 * OpenMesh runs, those three standard streams are pointed at a string, so
 * nothing reaches the baker's stderr. That redirection and OpenMesh's stream
 * multiplexers are process-wide, so every refinement runs under one mutex.
 */
#include "mesh.h"

/* OpenMesh's VectorT has a deliberately uninitialised default constructor,
 * which GCC reports (inlined into std::vector, in the standard headers)
 * when optimising. The pragma covers the headers only; the region must
 * include the first inclusion of the standard library headers for GCC to
 * apply it there. */
#pragma GCC diagnostic push
#ifndef __clang__ /* clang has no such warning, and warns about the name */
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#pragma GCC diagnostic pop

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <mutex>
#include <new>
#include <queue>
#include <string>
#include <vector>

#include "vdsh_math.h"

namespace
{

/* ====================================================================== */
/* OpenMesh session: one at a time, output discarded                      */
/* ====================================================================== */

std::mutex &openmesh_mutex()
{
    static std::mutex m;
    return m;
}

/* A stream buffer that drops what is written to it: OpenMesh can print one
 * warning per refused face, and nothing of it is used. */
class discard_buf : public std::streambuf
{
  protected:
    int_type overflow(int_type c) override
    {
        return traits_type::not_eof(c);
    }
    std::streamsize xsputn(const char *, std::streamsize n) override
    {
        return n;
    }
};

class openmesh_session
{
  public:
    openmesh_session() : lock_(openmesh_mutex())
    {
        err_ = std::cerr.rdbuf(&buf_);
        log_ = std::clog.rdbuf(&buf_);
        out_ = std::cout.rdbuf(&buf_);
    }
    ~openmesh_session()
    {
        /* OpenMesh's multiplexers hold text until a newline: push out what
         * is pending while it still lands in the discard. */
        ::omerr().flush();
        ::omlog().flush();
        ::omout().flush();
        std::cerr.rdbuf(err_);
        std::clog.rdbuf(log_);
        std::cout.rdbuf(out_);
    }
    openmesh_session(const openmesh_session &) = delete;
    openmesh_session &operator=(const openmesh_session &) = delete;

  private:
    std::lock_guard<std::mutex> lock_;
    discard_buf buf_;
    std::streambuf *err_;
    std::streambuf *log_;
    std::streambuf *out_;
};

/* ====================================================================== */
/* Refinement                                                             */
/* ====================================================================== */

typedef OpenMesh::TriMesh_ArrayKernelT<> om_mesh;

/* More output vertices than this is almost surely a wrong max_edge (units:
 * 0.2 on a scene modelled in millimetres), and costs gigabytes. */
const uint64_t refine_max_vertices = 1u << 24;

struct edge_entry {
    double len2;
    int edge;
};

/* std::priority_queue pops the "largest": longest edge first, and among
 * equal lengths the lowest edge index, so the order is deterministic. */
struct edge_order {
    bool operator()(const edge_entry &a, const edge_entry &b) const
    {
        if (a.len2 != b.len2)
            return a.len2 < b.len2;
        return a.edge > b.edge;
    }
};

double dist2(const om_mesh::Point &a, const om_mesh::Point &b)
{
    double dx = (double)a[0] - b[0], dy = (double)a[1] - b[1], dz = (double)a[2] - b[2];
    return dx * dx + dy * dy + dz * dz;
}

double edge_len2(const om_mesh &m, om_mesh::EdgeHandle e)
{
    om_mesh::HalfedgeHandle h = m.halfedge_handle(e, 0);
    return dist2(m.point(m.from_vertex_handle(h)), m.point(m.to_vertex_handle(h)));
}

/* The cross product (b - a) x (c - a), in double. */
void cross3(const om_mesh::Point &a, const om_mesh::Point &b, const om_mesh::Point &c, double x[3])
{
    double u[3], v[3];
    for (int k = 0; k < 3; k++) {
        u[k] = (double)b[k] - a[k];
        v[k] = (double)c[k] - a[k];
    }
    x[0] = u[1] * v[2] - u[2] * v[1];
    x[1] = u[2] * v[0] - u[0] * v[2];
    x[2] = u[0] * v[1] - u[1] * v[0];
}

/* Flips mend slivers only: an edge whose two triangles both have an aspect
 * of at most this is left as it is. Longest-edge bisection of a
 * well-shaped triangle stays well shaped (its right-isosceles halves are
 * 1.73), and the meshes already refined that way (the rooms: worst 4.0 at
 * 0.2) keep their receivers. */
const double sliver_aspect = 4.5;

/* Two faces are one plane when their normals differ by less than ~0.08
 * degrees: flipping the edge between them moves no surface (beyond float
 * rounding) and changes only which receivers interpolate where. */
const double flat_cos = 1.0 - 1e-6;

/* Whether flipping e makes its two triangles better shaped: both faces in
 * one plane, and the angles opposite e sum to more than pi (e is not
 * locally Delaunay; the flip then always gives a convex quad's other
 * diagonal, whose opposite angles sum to less than pi: no flip back).
 *
 * Only sums, products, divisions and square roots (correctly rounded in
 * IEEE double, no libm call whose rounding may depend on the CPU), so the
 * decision is the same on any x86-64 CPU. With alpha, beta the angles at
 * c0 and c1 (cos = d / l, sin = s / l: d the dot product, s the norm of
 * the cross product of the sides, l the product of their lengths),
 * sin(alpha + beta) = (s0 d1 + d0 s1) / (l0 l1), and since both angles
 * are in (0, pi), alpha + beta > pi + 1e-9 is sin(alpha + beta) <
 * -sin(1e-9): s0 d1 + d0 s1 < -1e-9 l0 l1 (the margin keeps rounding from
 * flipping a quad whose corners lie on one circle back and forth).
 *
 * The cheap tests come first: most edges of a refinement are between
 * well-shaped triangles, and OpenMesh's is_flip_ok (a walk around a
 * vertex) is needed only for an edge that would be flipped. */
bool should_flip(const om_mesh &m, om_mesh::EdgeHandle e)
{
    if (m.is_boundary(e))
        return false;
    om_mesh::HalfedgeHandle h0 = m.halfedge_handle(e, 0), h1 = m.halfedge_handle(e, 1);
    const om_mesh::Point a = m.point(m.from_vertex_handle(h0)), b = m.point(m.to_vertex_handle(h0));
    const om_mesh::Point c0 = m.point(m.to_vertex_handle(m.next_halfedge_handle(h0)));
    const om_mesh::Point c1 = m.point(m.to_vertex_handle(m.next_halfedge_handle(h1)));
    /* Face h0 is (a, b, c0), face h1 is (b, a, c1): their normals. */
    double x0[3], x1[3];
    cross3(a, b, c0, x0);
    cross3(b, a, c1, x1);
    double s0 = std::sqrt(vdsh_dot3d(x0, x0)), s1 = std::sqrt(vdsh_dot3d(x1, x1));
    if (!(s0 > 0.0) || !(s1 > 0.0) || vdsh_dot3d(x0, x1) < flat_cos * (s0 * s1))
        return false; /* a crease, or a face without area */
    /* Aspect (sqrt(3) L^2 / (4 A), A = s / 2) of both: well shaped already,
     * bisection keeps them so. */
    double ab2 = dist2(a, b);
    double l0 = std::max(ab2, std::max(dist2(b, c0), dist2(c0, a)));
    double l1 = std::max(ab2, std::max(dist2(a, c1), dist2(c1, b)));
    double k = std::sqrt(3.0) / 2.0;
    if (k * l0 / s0 <= sliver_aspect && k * l1 / s1 <= sliver_aspect)
        return false;
    /* The angles at c0 and c1, between their sides to a and b. */
    double ca2 = dist2(c0, a), cb2 = dist2(c0, b), da2 = dist2(c1, a), db2 = dist2(c1, b);
    double d0 = 0.0, d1 = 0.0;
    for (int i = 0; i < 3; i++) {
        d0 += ((double)a[i] - c0[i]) * ((double)b[i] - c0[i]);
        d1 += ((double)a[i] - c1[i]) * ((double)b[i] - c1[i]);
    }
    /* |(a - c) x (b - c)| is twice the area: s0 and s1 again. */
    double len0 = std::sqrt(ca2 * cb2), len1 = std::sqrt(da2 * db2);
    if (!(s0 * d1 + d0 * s1 < -1e-9 * (len0 * len1)))
        return false;
    return m.is_flip_ok(e);
}

/* Lawson's flips from the edges on `stack` (and those they expose) until
 * every flat edge is locally Delaunay; each flipped edge that is longer
 * than limit2 goes on `queue` (its new length). `budget` bounds the flips
 * (planar flips end by themselves; the bound keeps faces that are flat
 * only within the tolerance from cycling). */
template <class Queue>
void legalize(om_mesh &m, std::vector<int> &stack, double limit2, Queue &queue, uint64_t &budget)
{
    while (!stack.empty()) {
        om_mesh::EdgeHandle e(stack.back());
        stack.pop_back();
        if (budget == 0 || !should_flip(m, e))
            continue;
        budget--;
        m.flip(e);
        double l2 = edge_len2(m, e);
        if (l2 > limit2)
            queue.push(edge_entry{l2, e.idx()});
        for (int s = 0; s < 2; s++) {
            om_mesh::HalfedgeHandle h = m.halfedge_handle(e, s);
            stack.push_back(m.edge_handle(m.next_halfedge_handle(h)).idx());
            stack.push_back(m.edge_handle(m.prev_halfedge_handle(h)).idx());
        }
    }
}

/* uint64 key -> uint32 value, open addressing: std::unordered_map's node
 * per entry cost more than the whole refinement on large meshes. */
class pair_table
{
  public:
    explicit pair_table(size_t n)
    {
        size_t cap = 16;
        while (cap < 2 * n)
            cap *= 2;
        keys_.assign(n ? cap : 0, empty);
        vals_.resize(n ? cap : 0);
        mask_ = cap - 1;
    }
    /* The value stored for `key`, or `value` after storing it. */
    uint32_t find_or_insert(uint64_t key, uint32_t value)
    {
        uint64_t h = key * 0x9e3779b97f4a7c15ull;
        size_t i = (size_t)(h ^ (h >> 29)) & mask_;
        while (keys_[i] != empty) {
            if (keys_[i] == key)
                return vals_[i];
            i = (i + 1) & mask_;
        }
        keys_[i] = key;
        vals_[i] = value;
        return value;
    }

  private:
    static constexpr uint64_t empty = ~(uint64_t)0; /* min < max: never a key */
    std::vector<uint64_t> keys_;
    std::vector<uint32_t> vals_;
    size_t mask_ = 0;
};

/* The half-edge mesh of `in`: its vertices, then private copies of the
 * vertices of each triangle the half-edge structure refuses (as OpenMesh's
 * ImporterT); copy_of maps them back, kept counts the faces added. */
vb_result build_mesh(const vb_mesh *in, om_mesh &m, std::vector<uint32_t> &copy_of, uint64_t &kept,
                     vb_error *err)
{
    const uint32_t n = in->vertex_count;
    for (uint32_t i = 0; i < n; i++) {
        const float *p = in->positions + 3 * (size_t)i;
        m.add_vertex(om_mesh::Point(p[0], p[1], p[2]));
    }
    kept = 0;
    for (uint64_t t = 0; t < in->triangle_count; t++) {
        const uint32_t *tri = in->indices + 3 * t;
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
            continue;
        om_mesh::VertexHandle v0((int)tri[0]), v1((int)tri[1]), v2((int)tri[2]);
        om_mesh::FaceHandle fh = m.add_face(v0, v1, v2);
        if (!fh.is_valid()) {
            om_mesh::VertexHandle c[3];
            for (int k = 0; k < 3; k++) {
                /* A copy, not m.point()'s reference: add_vertex may
                 * reallocate the array that reference points into. */
                const om_mesh::Point p = m.point(om_mesh::VertexHandle((int)tri[k]));
                c[k] = m.add_vertex(p);
                copy_of.push_back(tri[k]);
            }
            fh = m.add_face(c[0], c[1], c[2]);
            if (!fh.is_valid())
                return vb_fail(err, VB_ERR_INVALID,
                               "refine: OpenMesh refused triangle %llu even with its own vertices",
                               (unsigned long long)t);
        }
        kept++;
    }

    return VB_OK;
}

/* The output mesh of m, built from `in` (n vertices, copies copy_of) with
 * new vertices from `parents` (two per vertex added after the copies). */
vb_result emit_mesh(const vb_mesh *in, const om_mesh &m, const std::vector<uint32_t> &copy_of,
                    const std::vector<uint32_t> &parents, vb_mesh *out, vb_error *err)
{
    const uint32_t n = in->vertex_count;
    const uint64_t first_new = (uint64_t)n + copy_of.size();
    /* Output numbering: originals keep theirs, copies map back, and new
     * vertices follow in creation order. An original edge that a copied
     * triangle shares has been split once per copy: those midpoints sit at
     * the same place (same float arithmetic on the same ends) and must
     * become one vertex, or the shared edge would not be conforming. (The
     * same happens inside coincident triangles, where OpenMesh makes two
     * edges between the same two vertices.) So a new vertex is known by its
     * parents' output numbers and made only once. */
    const size_t total = m.n_vertices();
    std::vector<uint32_t> out_of(total);
    for (uint32_t i = 0; i < n; i++)
        out_of[i] = i;
    for (size_t i = 0; i < copy_of.size(); i++)
        out_of[n + i] = copy_of[i];
    pair_table merged(total - (size_t)first_new);
    std::vector<float> pos(3 * (size_t)n), nrm(3 * (size_t)n, 0.0f);
    pos.reserve(3 * (total - (size_t)first_new + n));
    nrm.reserve(pos.capacity());
    memcpy(pos.data(), in->positions, 3 * (size_t)n * sizeof(float));
    if (in->normals)
        memcpy(nrm.data(), in->normals, 3 * (size_t)n * sizeof(float));
    uint32_t next = n;
    for (size_t v = (size_t)first_new; v < total; v++) {
        size_t k = v - (size_t)first_new;
        uint32_t pa = out_of[parents[2 * k]], pb = out_of[parents[2 * k + 1]];
        uint64_t key = (uint64_t)std::min(pa, pb) << 32 | std::max(pa, pb);
        uint32_t id = merged.find_or_insert(key, next);
        if (id != next) {
            out_of[v] = id;
            continue;
        }
        out_of[v] = next++;
        const om_mesh::Point &p = m.point(om_mesh::VertexHandle((int)v));
        pos.push_back(p[0]);
        pos.push_back(p[1]);
        pos.push_back(p[2]);
        float nn[3];
        for (int q = 0; q < 3; q++)
            nn[q] = nrm[3 * (size_t)pa + (size_t)q] + nrm[3 * (size_t)pb + (size_t)q];
        vdsh_normalize3f_in_double(nn);
        nrm.insert(nrm.end(), nn, nn + 3);
    }
    std::vector<uint32_t> idx;
    idx.reserve(3 * m.n_faces());
    for (om_mesh::FaceHandle f : m.faces())
        for (om_mesh::VertexHandle fv : m.fv_range(f))
            idx.push_back(out_of[(size_t)fv.idx()]);

    vb_mesh res;
    memset(&res, 0, sizeof res);
    res.vertex_count = next;
    res.triangle_count = (uint32_t)(idx.size() / 3);
    res.positions = (float *)malloc(std::max<size_t>(pos.size(), 1) * sizeof(float));
    res.normals = (float *)malloc(std::max<size_t>(nrm.size(), 1) * sizeof(float));
    res.indices = (uint32_t *)malloc(std::max<size_t>(idx.size(), 1) * sizeof(uint32_t));
    if (!res.positions || !res.normals || !res.indices) {
        vb_mesh_free(&res);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "refine: out of memory");
    }
    if (!pos.empty())
        memcpy(res.positions, pos.data(), pos.size() * sizeof(float));
    if (!nrm.empty())
        memcpy(res.normals, nrm.data(), nrm.size() * sizeof(float));
    if (!idx.empty())
        memcpy(res.indices, idx.data(), idx.size() * sizeof(uint32_t));
    *out = res;
    return VB_OK;
}

vb_result refine(const vb_mesh *in, float max_edge, vb_mesh *out, vb_error *err)
{
    const uint32_t n = in->vertex_count;
    const double limit2 = (double)max_edge * (double)max_edge;

    /* Input checks: the mesh may come from anywhere, not only a loader. */
    if (n > refine_max_vertices)
        return vb_fail(err, VB_ERR_ARGUMENT,
                       "refine: the mesh has %u vertices; refinement handles at most %llu", n,
                       (unsigned long long)refine_max_vertices);
    for (uint64_t i = 0; i < 3 * (uint64_t)n; i++)
        if (!std::isfinite(in->positions[i]))
            return vb_fail(err, VB_ERR_INVALID, "refine: vertex %llu has a non-finite coordinate",
                           (unsigned long long)(i / 3));
    double area = 0.0;
    for (uint64_t t = 0; t < in->triangle_count; t++) {
        const uint32_t *tri = in->indices + 3 * t;
        for (int k = 0; k < 3; k++)
            if (tri[k] >= n)
                return vb_fail(err, VB_ERR_INVALID,
                               "refine: triangle %llu: index %u out of range (%u vertices)",
                               (unsigned long long)t, tri[k], n);
        const float *a = in->positions + 3 * (size_t)tri[0];
        const float *b = in->positions + 3 * (size_t)tri[1];
        const float *c = in->positions + 3 * (size_t)tri[2];
        double u[3], v[3];
        for (int k = 0; k < 3; k++) {
            u[k] = (double)b[k] - a[k];
            v[k] = (double)c[k] - a[k];
        }
        double cx = u[1] * v[2] - u[2] * v[1], cy = u[2] * v[0] - u[0] * v[2],
               cz = u[0] * v[1] - u[1] * v[0];
        area += 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
    }
    /* No triangle with all edges <= max_edge is larger than the equilateral
     * one: a lower bound on the faces needed, checked before any work. */
    double min_faces = area / (std::sqrt(3.0) / 4.0 * limit2);
    if (min_faces > 2.0 * (double)refine_max_vertices)
        return vb_fail(
            err, VB_ERR_ARGUMENT,
            "refine: max_edge %g is too small for this mesh (surface area %g needs over %.3g triangles; "
            "the limit is %llu vertices)",
            (double)max_edge, area, min_faces, (unsigned long long)refine_max_vertices);

    om_mesh m;
    /* Longest-edge bisection ends with about 1.3 - 2.3 vertices per
     * max_edge^2 of area: reserve for the upper end. */
    size_t est_v =
        (size_t)std::min<double>((double)n + 2.5 * area / limit2, (double)refine_max_vertices);
    m.reserve(est_v, est_v * 3, est_v * 2);

    vb_result r = VB_OK;
    std::vector<uint32_t> copy_of;
    uint64_t kept = 0;
    if ((r = build_mesh(in, m, copy_of, kept, err)) != VB_OK)
        return r;

    /* Longest edge first. Each entry's length is checked again when it is
     * taken: an entry whose edge has changed since it was queued (the
     * change queued it again) or that is short enough is skipped, never
     * split. OpenMesh's LongestEdgeT splits whatever it pops on the queued
     * length alone. (Here, as there, every edge is queued once per length,
     * so in practice entries do not go stale: on the meshes measured both
     * split the same edges. The check makes it a guarantee.) */
    std::priority_queue<edge_entry, std::vector<edge_entry>, edge_order> queue;
    for (om_mesh::EdgeHandle e : m.edges()) {
        double l2 = edge_len2(m, e);
        if (l2 > limit2)
            queue.push(edge_entry{l2, e.idx()});
    }
    /* Within each plane the triangulation is kept Delaunay (Lawson's flips
     * of flat edges, first over the input, then around every new vertex):
     * bisection alone keeps an input sliver's small angle (halving it at
     * worst), so a floor of long thin triangles refined to 0.2 gave 11.8
     * receivers per area / max_edge^2 and aspect ratios of 35 where the
     * flips give ~1.5 and ~2. Nothing is flipped when no edge is too long:
     * such a mesh comes back unchanged. */
    std::vector<int> stack;
    uint64_t flip_budget = 64 * ((uint64_t)m.n_edges() + (uint64_t)(2.5 * area / limit2) + 16);
    if (!queue.empty()) {
        for (int i = (int)m.n_edges() - 1; i >= 0; i--)
            stack.push_back(i);
        legalize(m, stack, limit2, queue, flip_budget);
    }
    std::vector<uint32_t> parents; /* two per new vertex: the split edge's ends */
    uint64_t faces_added = 0;
    while (!queue.empty()) {
        edge_entry top = queue.top();
        queue.pop();
        om_mesh::EdgeHandle e(top.edge);
        double l2 = edge_len2(m, e);
        if (l2 != top.len2 || l2 <= limit2)
            continue;
        if (m.n_vertices() - copy_of.size() >= refine_max_vertices)
            return vb_fail(err, VB_ERR_ARGUMENT,
                           "refine: max_edge %g would need more than %llu vertices",
                           (double)max_edge, (unsigned long long)refine_max_vertices);
        om_mesh::HalfedgeHandle h = m.halfedge_handle(e, 0);
        om_mesh::VertexHandle a = m.from_vertex_handle(h), b = m.to_vertex_handle(h);
        const om_mesh::Point pa = m.point(a), pb = m.point(b);
        om_mesh::Point mid((pa[0] + pb[0]) * 0.5f, (pa[1] + pb[1]) * 0.5f, (pa[2] + pb[2]) * 0.5f);
        /* Far from the origin with a tiny max_edge, float midpoints stop
         * halving edges (one lands on an end, the other keeps the whole
         * length) and refinement would never end. Each half must be clearly
         * shorter (at most 90% of the edge; exactly 50% when the spacing of
         * floats is small against the edge). */
        if (!(dist2(pa, mid) <= 0.81 * l2 && dist2(mid, pb) <= 0.81 * l2))
            return vb_fail(err, VB_ERR_ARGUMENT,
                           "refine: max_edge %g is below float precision at (%g, %g, %g)",
                           (double)max_edge, (double)pa[0], (double)pa[1], (double)pa[2]);
        faces_added += m.is_boundary(e) ? 1 : 2;
        om_mesh::VertexHandle vm = m.add_vertex(mid);
        parents.push_back((uint32_t)a.idx());
        parents.push_back((uint32_t)b.idx());
        m.split(e, vm);
        for (om_mesh::HalfedgeHandle oh : m.voh_range(vm)) /* the new vertex's link */
            if (!m.is_boundary(oh))
                stack.push_back(m.edge_handle(m.next_halfedge_handle(oh)).idx());
        legalize(m, stack, limit2, queue, flip_budget);
        for (om_mesh::EdgeHandle ve : m.ve_range(vm)) {
            double nl2 = edge_len2(m, ve);
            if (nl2 > limit2)
                queue.push(edge_entry{nl2, ve.idx()});
        }
    }
    if (m.n_faces() != kept + faces_added)
        return vb_fail(err, VB_ERR_INVALID, "refine: internal error: %zu faces, expected %llu",
                       (size_t)m.n_faces(), (unsigned long long)(kept + faces_added));

    return emit_mesh(in, m, copy_of, parents, out, err);
}

/* vb_mesh_split_edges: one level of chosen splits. */
vb_result split_edges(const vb_mesh *in, const uint32_t *pairs, uint32_t count, vb_mesh *out,
                      vb_error *err)
{
    const uint32_t n = in->vertex_count;
    for (uint64_t t = 0; t < 3 * (uint64_t)in->triangle_count; t++)
        if (in->indices[t] >= n)
            return vb_fail(err, VB_ERR_INVALID,
                           "split: triangle %llu: index %u out of range (%u vertices)",
                           (unsigned long long)(t / 3), in->indices[t], n);
    om_mesh m;
    m.reserve((size_t)n + count, 3 * ((size_t)in->triangle_count + 2 * (size_t)count),
              (size_t)in->triangle_count + 2 * (size_t)count);
    std::vector<uint32_t> copy_of;
    uint64_t kept = 0;
    vb_result r = build_mesh(in, m, copy_of, kept, err);
    if (r != VB_OK)
        return r;
    /* Every half-edge structure edge by its ends' input numbers (a shared
     * edge of copied triangles, or of coincident ones, is several). */
    auto number = [&](om_mesh::VertexHandle v) {
        size_t i = (size_t)v.idx();
        return i < n ? (uint32_t)i : copy_of[i - n];
    };
    auto key_of = [](uint32_t a, uint32_t b) {
        return (uint64_t)std::min(a, b) << 32 | std::max(a, b);
    };
    std::vector<std::pair<uint64_t, int>> edges;
    edges.reserve(m.n_edges());
    for (om_mesh::EdgeHandle e : m.edges()) {
        om_mesh::HalfedgeHandle h = m.halfedge_handle(e, 0);
        edges.emplace_back(key_of(number(m.from_vertex_handle(h)), number(m.to_vertex_handle(h))),
                           e.idx());
    }
    std::sort(edges.begin(), edges.end());
    std::vector<uint32_t> parents;
    uint64_t faces_added = 0;
    for (uint32_t i = 0; i < count; i++) {
        uint32_t a = pairs[2 * i], b = pairs[2 * i + 1];
        uint64_t key = key_of(a, b);
        auto it = std::lower_bound(edges.begin(), edges.end(), std::make_pair(key, -1));
        if (a == b || it == edges.end() || it->first != key)
            return vb_fail(err, VB_ERR_ARGUMENT,
                           "split: pair %u (%u, %u) is not an edge of the mesh", i, a, b);
        if (i > 0 && key == key_of(pairs[2 * i - 2], pairs[2 * i - 1]))
            return vb_fail(err, VB_ERR_ARGUMENT, "split: edge (%u, %u) listed twice", a, b);
        for (; it != edges.end() && it->first == key; ++it) {
            om_mesh::EdgeHandle e(it->second);
            om_mesh::HalfedgeHandle h = m.halfedge_handle(e, 0);
            om_mesh::VertexHandle va = m.from_vertex_handle(h), vb = m.to_vertex_handle(h);
            const om_mesh::Point pa = m.point(va), pb = m.point(vb);
            om_mesh::Point mid((pa[0] + pb[0]) * 0.5f, (pa[1] + pb[1]) * 0.5f,
                               (pa[2] + pb[2]) * 0.5f);
            faces_added += m.is_boundary(e) ? 1 : 2;
            om_mesh::VertexHandle vm = m.add_vertex(mid);
            parents.push_back((uint32_t)va.idx());
            parents.push_back((uint32_t)vb.idx());
            m.split(e, vm);
        }
    }
    if (m.n_faces() != kept + faces_added)
        return vb_fail(err, VB_ERR_INVALID, "split: internal error: %zu faces, expected %llu",
                       (size_t)m.n_faces(), (unsigned long long)(kept + faces_added));
    r = emit_mesh(in, m, copy_of, parents, out, err);
    if (r == VB_OK && out->vertex_count != n + count) { /* an edge listed twice, out of order */
        vb_mesh_free(out);
        return vb_fail(err, VB_ERR_ARGUMENT,
                       "split: %u edges gave %u new vertices (an edge listed twice?)", count,
                       out->vertex_count - n);
    }
    return r;
}

/* max_edge <= 0: a plain copy (also of meshes with repeated indices). */
vb_result copy_mesh(const vb_mesh *in, vb_mesh *out, vb_error *err)
{
    vb_mesh res;
    memset(&res, 0, sizeof res);
    size_t nv = 3 * (size_t)in->vertex_count, ni = 3 * (size_t)in->triangle_count;
    res.positions = (float *)malloc(std::max<size_t>(nv, 1) * sizeof(float));
    res.normals = (float *)calloc(std::max<size_t>(nv, 1), sizeof(float));
    res.indices = (uint32_t *)malloc(std::max<size_t>(ni, 1) * sizeof(uint32_t));
    if (!res.positions || !res.normals || !res.indices) {
        vb_mesh_free(&res);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "refine: out of memory");
    }
    res.vertex_count = in->vertex_count;
    res.triangle_count = in->triangle_count;
    if (nv) {
        memcpy(res.positions, in->positions, nv * sizeof(float));
        if (in->normals)
            memcpy(res.normals, in->normals, nv * sizeof(float));
    }
    if (ni)
        memcpy(res.indices, in->indices, ni * sizeof(uint32_t));
    *out = res;
    return VB_OK;
}

} // namespace

/* ====================================================================== */
/* C entry points: no exception passes these                              */
/* ====================================================================== */

extern "C" vb_result vb_mesh_refine(const vb_mesh *in, float max_edge, vb_mesh *out, vb_error *err)
{
    if (!in || !out)
        return vb_fail(err, VB_ERR_ARGUMENT, "vb_mesh_refine: NULL argument");
    if (std::isnan(max_edge))
        return vb_fail(err, VB_ERR_ARGUMENT, "refine: max_edge is NaN");
    if ((in->vertex_count && !in->positions) || (in->triangle_count && !in->indices))
        return vb_fail(err, VB_ERR_ARGUMENT, "refine: mesh has counts but no arrays");
    try {
        if (max_edge <= 0.0f || std::isinf(max_edge))
            return copy_mesh(in, out, err);
        openmesh_session session;
        return refine(in, max_edge, out, err);
    } catch (const std::bad_alloc &) {
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "refine: out of memory");
    } catch (const std::exception &e) {
        return vb_fail(err, VB_ERR_INVALID, "refine: OpenMesh failed: %s", e.what());
    } catch (...) {
        return vb_fail(err, VB_ERR_INVALID, "refine: OpenMesh failed with an unknown exception");
    }
}

extern "C" vb_result vb_mesh_split_edges(const vb_mesh *in, const uint32_t *pairs, uint32_t count,
                                         vb_mesh *out, vb_error *err)
{
    if (!in || !out || (count && !pairs))
        return vb_fail(err, VB_ERR_ARGUMENT, "vb_mesh_split_edges: NULL argument");
    if ((in->vertex_count && (!in->positions || !in->normals)) ||
        (in->triangle_count && !in->indices))
        return vb_fail(err, VB_ERR_ARGUMENT, "split: mesh has counts but no arrays");
    if ((uint64_t)in->vertex_count + count > refine_max_vertices)
        return vb_fail(err, VB_ERR_ARGUMENT, "split: more than %llu vertices",
                       (unsigned long long)refine_max_vertices);
    try {
        openmesh_session session;
        return split_edges(in, pairs, count, out, err);
    } catch (const std::bad_alloc &) {
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "split: out of memory");
    } catch (const std::exception &e) {
        return vb_fail(err, VB_ERR_INVALID, "split: OpenMesh failed: %s", e.what());
    } catch (...) {
        return vb_fail(err, VB_ERR_INVALID, "split: OpenMesh failed with an unknown exception");
    }
}

extern "C" double vb_mesh_worst_aspect(const vb_mesh *m, uint32_t *worst)
{
    double best = 0.0;
    uint32_t at = 0;
    for (uint32_t t = 0; m && t < m->triangle_count; t++) {
        const uint32_t *tri = m->indices + 3 * (size_t)t;
        if (tri[0] >= m->vertex_count || tri[1] >= m->vertex_count || tri[2] >= m->vertex_count)
            continue;
        double p[3][3], l2max = 0.0;
        for (int k = 0; k < 3; k++)
            for (int c = 0; c < 3; c++)
                p[k][c] = m->positions[3 * (size_t)tri[k] + (size_t)c];
        for (int k = 0; k < 3; k++) {
            double d2 = 0.0;
            for (int c = 0; c < 3; c++)
                d2 += (p[(k + 1) % 3][c] - p[k][c]) * (p[(k + 1) % 3][c] - p[k][c]);
            l2max = std::max(l2max, d2);
        }
        double u[3], v[3];
        for (int c = 0; c < 3; c++) {
            u[c] = p[1][c] - p[0][c];
            v[c] = p[2][c] - p[0][c];
        }
        double cx = u[1] * v[2] - u[2] * v[1], cy = u[2] * v[0] - u[0] * v[2],
               cz = u[0] * v[1] - u[1] * v[0];
        double area = 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
        if (!(l2max > 0.0) || !(area > 0.0))
            continue; /* no shape: counted by the bake as degenerate */
        double a = std::sqrt(3.0) * l2max / (4.0 * area);
        if (a > best)
            best = a, at = t;
    }
    if (worst)
        *worst = at;
    return best;
}
