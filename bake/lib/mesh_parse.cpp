/*
 * mesh_parse.cpp - strict OBJ/PLY/OFF/STL readers (mesh_parse.h): one pass
 * over the file's bytes that checks everything and fills the arrays.
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
 * (recorded bakes depend on them, byte for byte):
 *
 *  - numbers are read as std::istream reads them (correctly rounded, the
 *    same floats as strtof), and must be whole tokens;
 *  - OBJ: lines split at '\n' only, the first token is the keyword, a line
 *    whose first character after blanks is '#' is a comment; faces take
 *    each corner's index before the first '/', resolve negative indices
 *    against the "v" lines so far, give the corner's vertex the normal the
 *    corner names, drop repeated vertices (first occurrence kept) and
 *    fan-triangulate what is left (fewer than three: no face);
 *  - PLY: elements are read in order up to and including "face"; x, y, z,
 *    nx, ny, nz as floats; the face's vertex_indices list;
 *  - OFF: [ST][C][N]OFF [BINARY] headers (BINARY exactly one character
 *    after OFF), coordinates and normals, then faces;
 *  - STL: binary when the file is exactly 84 + 50 x (count at byte 80)
 *    bytes long, else ascii (every line containing "outer" starts a facet
 *    whose next three lines are "<word> x y z"); vertices with equal
 *    positions are merged (OpenMesh's comparison: components within
 *    FLT_MIN, through the same std::map, so the numbering is its
 *    numbering) and a triangle whose corners then repeat is dropped.
 *
 * Normals given for a vertex more than once are averaged as mesh_parse.h
 * says; per face corner (OBJ) each corner keeps the last normal its line
 * gave its vertex.
 *
 * The readers count what the file must deliver (vertices, faces,
 * triangles) as the checks go and compare it with what they built; a
 * difference is refused, never a silently partial mesh.
 */
#include "mesh_parse.h"

#include <algorithm>
#include <array>
#include <cfloat>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <new>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <strings.h>

namespace {

/* ====================================================================== */
/* Text scanning                                                          */
/* ====================================================================== */

/* Whitespace as std::istream's operator>> sees it in the "C" locale; '\n'
 * is handled separately so that lines can be counted. */
bool is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

bool is_digit(char c)
{
    return c >= '0' && c <= '9';
}

struct token {
    const char *b = nullptr;
    const char *e = nullptr;
    size_t size() const { return (size_t)(e - b); }
    bool is(const char *s) const
    {
        size_t n = strlen(s);
        return size() == n && memcmp(b, s, n) == 0;
    }
    /* For messages: at most 40 characters of the token. */
    int show_len() const { return (int)std::min<size_t>(size(), 40); }
};

/* A cursor over the file's bytes that counts lines (1-based). */
struct cursor {
    const char *p;
    const char *end;
    unsigned long line;

    cursor(const uint8_t *bytes, size_t size)
        : p((const char *)bytes), end((const char *)bytes + size), line(1) {}

    bool at_end() const { return p >= end; }

    /* Next whitespace-separated token, crossing lines (as operator>>). */
    bool next(token *t)
    {
        while (p < end && (is_blank(*p) || *p == '\n')) {
            if (*p == '\n')
                line++;
            p++;
        }
        if (p >= end)
            return false;
        t->b = p;
        while (p < end && !is_blank(*p) && *p != '\n')
            p++;
        t->e = p;
        return true;
    }

    /* Next token on the current line only; false at the end of the line. */
    bool next_on_line(token *t)
    {
        while (p < end && is_blank(*p))
            p++;
        if (p >= end || *p == '\n')
            return false;
        t->b = p;
        while (p < end && !is_blank(*p) && *p != '\n')
            p++;
        t->e = p;
        return true;
    }

    /* Skip the rest of the current line and its '\n' (std::getline). */
    void skip_line()
    {
        const char *nl = (const char *)memchr(p, '\n', (size_t)(end - p));
        if (nl) {
            p = nl + 1;
            line++;
        } else {
            p = end;
        }
    }
};

enum num_status { NUM_OK, NUM_BAD, NUM_RANGE, NUM_NONFINITE };

/* A whole token as a float, the way std::istream reads one (strtof): an
 * optional sign, decimal digits, optional exponent; underflow is fine
 * (the float strtof gives, down to a signed zero), overflow is an error.
 * "nan" and "inf" parse here (and are reported as such) although
 * std::istream refuses them. */
num_status parse_float(const token &t, float *out)
{
    const char *b = t.b;
    if (b < t.e && *b == '+') {
        b++;
        if (b < t.e && (*b == '-' || *b == '+'))
            return NUM_BAD;
    }
    if (b >= t.e)
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

/* A whole token as a decimal integer with an optional sign. */
bool parse_int(const token &t, long long *out)
{
    const char *b = t.b;
    if (b < t.e && *b == '+') {
        b++;
        if (b < t.e && (*b == '-' || *b == '+'))
            return false;
    }
    if (b >= t.e)
        return false;
    long long v = 0;
    std::from_chars_result r = std::from_chars(b, t.e, v, 10);
    if (r.ec != std::errc() || r.ptr != t.e)
        return false;
    *out = v;
    return true;
}

/* The leading integer of [b, e) as `std::istream >> int` reads it: an
 * optional sign and decimal digits, stopping at anything else ("2nd" is
 * 2). False, with *out 0, when there is no digit; false, with *out
 * INT_MAX or INT_MIN, when it does not fit an int. */
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
    }
    return "is not a number";
}

/* The largest counts accepted from a file: vertex indices are uint32_t,
 * and the readers this one replaces kept handles in an int. */
const uint64_t max_count = 0x7fffffffu;

/* ====================================================================== */
/* The arrays being built                                                 */
/* ====================================================================== */

class builder {
public:
    std::vector<float> positions;
    std::vector<float> normal_sums;    /* empty until the first normal */
    std::vector<uint8_t> has_normal;
    std::vector<int64_t> indices;      /* fan-triangulated */
    std::vector<uint32_t> tri_face;
    uint64_t polygons = 0;

    /* OBJ: normals per face corner. The face line gives normals to its
     * corners' vertices (set_normal, in the order of the corners) before
     * the face is added; those are kept in `pending` until add_face, which
     * gives each corner the last normal set for its vertex. (A line that
     * adds no face, with fewer than three distinct vertices, leaves its
     * normals pending for the next face; they matter only where that face
     * names the same vertex without a normal.) */
    bool per_corner = false;
    std::vector<std::pair<int64_t, std::array<float, 3>>> pending;
    std::vector<float> corner_normals; /* 9 per triangle, once one is given */
    std::vector<uint8_t> corner_given; /* 3 per triangle */

    uint64_t vertex_count() const { return positions.size() / 3; }
    uint64_t triangle_count() const { return indices.size() / 3; }

    void add_vertex(float x, float y, float z)
    {
        positions.push_back(x);
        positions.push_back(y);
        positions.push_back(z);
    }

    /* A polygon of n >= 3 vertices, fanned from its first. */
    void add_face(const int64_t *v, size_t n)
    {
        for (size_t i = 1; i + 1 < n; i++) {
            indices.push_back(v[0]);
            indices.push_back(v[i]);
            indices.push_back(v[i + 1]);
            tri_face.push_back((uint32_t)polygons);
        }
        if (per_corner)
            add_corner_normals(v, n);
        polygons++;
    }

    /* A vertex may be given several normals (an OBJ position used with
     * different "vn" in different faces): their unit average is used. One
     * normal (or the same one each time) is kept as it is when it is
     * already unit length, so that writing and reading back a mesh
     * reproduces its normals bit for bit. has_normal: 0 none, 1 one value
     * in normal_sums as given, 2 a sum of unit vectors. Non-finite normals
     * and vertices that do not exist are ignored. */
    void set_normal(int64_t v, const float n[3])
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
            unit(sum);
            has_normal[i] = 2;
        }
        float u[3] = {n[0], n[1], n[2]};
        unit(u);
        for (int k = 0; k < 3; k++)
            sum[k] += u[k];
    }

    /* n scaled to unit length, (0,0,0) if it has none; a vector already
     * unit to float precision is left alone. */
    static void unit(float *n)
    {
        double len = std::sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        if (std::fabs(len - 1.0) <= 4.0 * FLT_EPSILON)
            return;
        for (int k = 0; k < 3; k++)
            n[k] = len > 0.0 && std::isfinite(len) ? (float)(n[k] / len) : 0.0f;
    }

    /* Hand over malloc'ed arrays (mesh.c frees them with free()). */
    void finish(uint64_t dropped, vb_mesh_raw *out)
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
                    unit(&normal_sums[3 * i]);
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
        } catch (...) {
            vb_mesh_raw_free(&raw);
            throw;
        }
        *out = raw;
    }

private:
    /* The corners of the polygon just fanned: its vertices' pending
     * normals, onto each of its triangles' corners. */
    void add_corner_normals(const int64_t *v, size_t n)
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
            std::vector<std::pair<int64_t, size_t>> last;   /* vertex, latest pending entry */
            last.reserve(pending.size());
            for (size_t p = 0; p < pending.size(); p++)
                last.emplace_back(pending[p].first, p);
            std::stable_sort(last.begin(), last.end(),
                             [](const std::pair<int64_t, size_t> &a, const std::pair<int64_t, size_t> &b) {
                                 return a.first < b.first;
                             });
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

    template <typename T>
    static T *malloc_copy(const std::vector<T> &v)
    {
        T *p = (T *)malloc(std::max<size_t>(v.size(), 1) * sizeof(T));
        if (!p)
            throw std::bad_alloc();
        if (!v.empty())
            memcpy(p, v.data(), v.size() * sizeof(T));
        return p;
    }
};

/* What the checks counted: the file must deliver exactly this. */
struct expectation {
    uint64_t vertices = 0;
    bool vertices_known = true;   /* STL: merged, count not known ahead */
    uint64_t faces = 0;           /* polygons with >= 3 vertices */
    uint64_t triangles = 0;       /* after fan triangulation */
    uint64_t dropped = 0;         /* OBJ: triangles of faces with < 3 distinct */
    std::string hint;             /* why the two might differ: the first line
                                     OpenMesh's reader read otherwise */
};

/* ---------------------------------------------------------------------- */
/* OBJ                                                                    */
/* ---------------------------------------------------------------------- */

/* One face line's corners as OpenMesh's OBJ reader reads them; appended
 * to `verts` (0-based vertex handles, possibly out of range) and `nsets`
 * (vertex, 1-based normal number: "give this vertex that normal"). Each
 * corner is split at '/' into components (vertex/texture/normal); an empty
 * component is skipped, a non-empty one is read with stream_int (a failed
 * read gives 0, except for the last component, which is then skipped). A
 * normal goes to the vertex read last on the line. Negative numbers count
 * back from the "v" (or "vn") lines so far. False if a normal comes before
 * any vertex (OpenMesh's behaviour is undefined there). */
bool obj_corner(const char *b, const char *e, int64_t lines_v, int64_t lines_vn, std::vector<int64_t> &verts,
                size_t face_first, std::vector<std::pair<int64_t, int64_t>> &nsets)
{
    int component = 0;
    const char *s = b;
    do {
        int value = 0;
        const char *slash = (const char *)memchr(s, '/', (size_t)(e - s));
        if (slash) {
            if (slash == s) {
                s = slash + 1;
                ++component;
                continue;
            }
            stream_int(s, slash, &value);
            s = slash + 1;
        } else {
            bool ok = stream_int(s, e, &value);
            s = e;
            if (!ok)
                continue;
        }
        if (component == 0) {
            int64_t v = value < 0 ? lines_v + value + 1 : value;
            verts.push_back(v - 1);
        } else if (component == 2) {
            if (verts.size() == face_first)
                return false;
            int64_t n = value < 0 ? lines_vn + value + 1 : value;
            nsets.emplace_back(verts.back(), n);
        }
        ++component;
    } while (s < e);
    return true;
}

/* Removes repeated vertices, keeping the first of each in order. */
void remove_repeated(std::vector<int64_t> &v)
{
    if (v.size() <= 64) {
        size_t n = 0;
        for (size_t i = 0; i < v.size(); i++) {
            bool seen = false;
            for (size_t j = 0; j < n && !seen; j++)
                seen = v[j] == v[i];
            if (!seen)
                v[n++] = v[i];
        }
        v.resize(n);
        return;
    }
    std::vector<std::pair<int64_t, size_t>> order(v.size());
    for (size_t i = 0; i < v.size(); i++)
        order[i] = {v[i], i};
    std::sort(order.begin(), order.end());
    std::vector<uint8_t> keep(v.size(), 0);
    for (size_t i = 0; i < order.size(); i++)
        keep[order[i].second] = i == 0 || order[i].first != order[i - 1].first;
    size_t n = 0;
    for (size_t i = 0; i < v.size(); i++)
        if (keep[i])
            v[n++] = v[i];
    v.resize(n);
}

/* Lines split at '\n' only; the first token is the keyword; '#' starts a
 * comment ("#" as the keyword, or any token of a face line from there on
 * for the checks below). "v" and "vn" need three whole numbers (finite,
 * in float range) before anything else; a face needs at least three
 * corners whose index (before the first '/') is a whole non-zero integer
 * in range; positive indices may point forward. Faces with fewer than
 * three distinct vertices add nothing (their triangles are counted as
 * dropped). Texture coordinates, materials and every other keyword are
 * ignored.
 *
 * Where OpenMesh's reader read a line otherwise than these checks, the
 * reading follows OpenMesh, and the file is refused when the counts then
 * differ (as the baker refused it before): a line whose first character
 * after spaces, TABs and CRs is a vertical tab or form feed is skipped (a
 * "v" line skipped that way always makes them differ), and the text after
 * '#' on a face line is read on as corners (a new vertex there makes them
 * differ; a repeated one may give its vertex a normal). */
vb_result read_obj(const char *path, const uint8_t *bytes, size_t size, builder &out, expectation *ex,
                   vb_error *err)
{
    if (size >= 2 && ((bytes[0] == 0xfe && bytes[1] == 0xff) || (bytes[0] == 0xff && bytes[1] == 0xfe)))
        return vb_fail(err, VB_ERR_FORMAT, "%s: UTF-16 text is not supported (save as UTF-8 or ASCII)", path);

    /* Positive indices may point forward, so count the "v" lines before
     * checking faces. */
    uint64_t total = 0;
    for (cursor c(bytes, size); !c.at_end(); c.skip_line()) {
        token kw;
        if (c.next_on_line(&kw) && kw.is("v"))
            total++;
    }

    /* Faces are built after all normals are known (a face may name a
     * normal defined further down): their corners go to `verts` and
     * `nsets`, one entry per face in `faces`. */
    struct face_rec {
        size_t verts_end, nsets_end;
    };
    std::vector<face_rec> faces;
    std::vector<int64_t> verts;
    std::vector<std::pair<int64_t, int64_t>> nsets;
    std::vector<float> normals;
    out.positions.reserve(3 * (size_t)std::min<uint64_t>(total, 1u << 24));

    cursor c(bytes, size);
    uint64_t nv = 0, nn = 0;          /* "v", "vn" lines so far */
    int64_t read_v = 0, read_vn = 0;  /* of those, the lines not skipped */
    std::vector<long long> corners;
    std::string &hint = ex->hint;
    while (!c.at_end()) {
        const char *line = c.p;
        token kw;
        if (!c.next_on_line(&kw) || kw.b[0] == '#') {
            c.skip_line();
            continue;
        }
        /* OpenMesh skipped a line that starts with a vertical tab or form
         * feed after spaces, TABs and CRs. */
        const char *first = line;
        while (first < kw.b && (*first == ' ' || *first == '\t' || *first == '\r'))
            first++;
        const bool skipped = first < kw.b;
        unsigned long line_no = c.line;
        if (kw.is("v") || kw.is("vn")) {
            const bool is_v = kw.is("v");
            const char *what = is_v ? "vertex" : "normal";
            uint64_t number = is_v ? nv + 1 : nn + 1;
            float xyz[3];
            for (int i = 0; i < 3; i++) {
                token t;
                if (!c.next_on_line(&t) || t.b[0] == '#')
                    return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: %s %llu has fewer than 3 numbers",
                                   path, c.line, what, (unsigned long long)number);
                num_status s = parse_float(t, &xyz[i]);
                if (s != NUM_OK)
                    return vb_fail(err, s == NUM_BAD ? VB_ERR_FORMAT : VB_ERR_INVALID,
                                   "%s: line %lu: %s %llu: coordinate '%.*s' %s", path, c.line, what,
                                   (unsigned long long)number, t.show_len(), t.b, num_problem(s));
            }
            if (is_v) {
                nv++;
                if (!skipped) {
                    out.add_vertex(xyz[0], xyz[1], xyz[2]);
                    read_v++;
                } else if (hint.empty()) {
                    hint = "line " + std::to_string(line_no) + ": a vertex line starting with a vertical tab or "
                           "form feed is skipped";
                }
            } else {
                nn++;
                if (!skipped) {
                    normals.insert(normals.end(), xyz, xyz + 3);
                    read_vn++;
                }
            }
            if (nv > max_count)
                return vb_fail(err, VB_ERR_FORMAT, "%s: too many vertices", path);
        } else if (kw.is("f")) {
            /* The checks: corners up to the first '#'. */
            corners.clear();
            token t;
            const char *rest = c.p;
            while (c.next_on_line(&t) && t.b[0] != '#') {
                const char *slash = (const char *)memchr(t.b, '/', t.size());
                token idx{t.b, slash ? slash : t.e};
                long long v = 0;
                if (!parse_int(idx, &v) || v == 0)
                    return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: face corner '%.*s' has no valid vertex index",
                                   path, c.line, t.show_len(), t.b);
                if (v < 0) {
                    if (v < -(long long)nv)
                        return vb_fail(err, VB_ERR_INVALID,
                                       "%s: line %lu: face index %lld out of range (%llu vertices so far)",
                                       path, c.line, v, (unsigned long long)nv);
                    v = (long long)nv + v + 1;
                } else if ((unsigned long long)v > total) {
                    return vb_fail(err, VB_ERR_INVALID, "%s: line %lu: face index %lld out of range (%llu vertices)",
                                   path, c.line, v, (unsigned long long)total);
                }
                corners.push_back(v);
            }
            if (corners.size() < 3)
                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: face has %zu vertices (needs at least 3)",
                               path, c.line, corners.size());
            std::sort(corners.begin(), corners.end());
            size_t distinct = (size_t)(std::unique(corners.begin(), corners.end()) - corners.begin());
            if (distinct >= 3) {
                ex->faces++;
                ex->triangles += distinct - 2;
            } else {
                ex->dropped += corners.size() - 2;
            }

            /* The reading: every token of the line, '#' or not. */
            if (skipped) {
                if (distinct >= 3 && hint.empty())
                    hint = "line " + std::to_string(line_no) + ": a face line starting with a vertical tab or "
                           "form feed is skipped";
            } else {
                size_t face_first = verts.size();
                cursor line_c = c;
                line_c.p = rest;
                while (line_c.next_on_line(&t))
                    if (!obj_corner(t.b, t.e, read_v, read_vn, verts, face_first, nsets))
                        return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: face corner '%.*s' gives a normal "
                                                           "before any vertex", path, line_no, t.show_len(), t.b);
                faces.push_back(face_rec{verts.size(), nsets.size()});
                std::vector<int64_t> mine(verts.begin() + (ptrdiff_t)face_first, verts.end());
                remove_repeated(mine);
                if (((mine.size() >= 3) != (distinct >= 3) || (distinct >= 3 && mine.size() != distinct)) &&
                    hint.empty())
                    hint = "line " + std::to_string(line_no) + ": the text after '#' reads as further face corners";
            }
        }
        /* "vt", "mtllib", "usemtl", groups, ...: not used */
        c.skip_line();
    }
    if (ex->triangles > max_count)
        return vb_fail(err, VB_ERR_FORMAT, "%s: too many triangles", path);
    ex->vertices = nv;

    /* The faces, now that every normal is known: each line's normals,
     * then its polygon without repeated vertices. */
    out.per_corner = true;
    out.indices.reserve(3 * (size_t)std::min<uint64_t>(ex->triangles, 1u << 24));
    out.tri_face.reserve((size_t)std::min<uint64_t>(ex->triangles, 1u << 24));
    size_t vb = 0, nb = 0;
    std::vector<int64_t> polygon;
    for (const face_rec &f : faces) {
        for (size_t i = nb; i < f.nsets_end; i++) {
            uint32_t k = (uint32_t)(nsets[i].second - 1);   /* as OpenMesh: unsigned compare */
            if (!normals.empty() && k < normals.size() / 3)
                out.set_normal(nsets[i].first, &normals[3 * (size_t)k]);
        }
        polygon.assign(verts.begin() + (ptrdiff_t)vb, verts.begin() + (ptrdiff_t)f.verts_end);
        remove_repeated(polygon);
        if (polygon.size() >= 3)
            out.add_face(polygon.data(), polygon.size());
        vb = f.verts_end;
        nb = f.nsets_end;
    }
    return VB_OK;
}

/* ---------------------------------------------------------------------- */
/* Little binary helpers                                                  */
/* ---------------------------------------------------------------------- */

uint32_t load_u32(const uint8_t *p, bool big_endian)
{
    return big_endian ? (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3]
                      : (uint32_t)p[3] << 24 | (uint32_t)p[2] << 16 | (uint32_t)p[1] << 8 | p[0];
}

float load_f32(const uint8_t *p, bool big_endian)
{
    uint32_t u = load_u32(p, big_endian);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

double load_f64(const uint8_t *p, bool big_endian)
{
    uint64_t u = big_endian ? (uint64_t)load_u32(p, true) << 32 | load_u32(p + 4, true)
                            : (uint64_t)load_u32(p + 4, false) << 32 | load_u32(p, false);
    double d;
    memcpy(&d, &u, 8);
    return d;
}

/* ---------------------------------------------------------------------- */
/* STL                                                                    */
/* ---------------------------------------------------------------------- */

/* Equal positions as OpenMesh's STL reader compares them (its CmpVec with
 * eps = FLT_MIN): components within FLT_MIN are equal. Not a strict weak
 * order for tiny values (0 ~ FLT_MIN/2 ~ FLT_MIN), so the vertices are
 * merged through a std::map with this comparison, in the same order of
 * calls: the same tree, the same merges. */
struct stl_less {
    bool operator()(const std::array<float, 3> &a, const std::array<float, 3> &b) const
    {
        const float eps = FLT_MIN;
        float d0 = a[0] - b[0], d1 = a[1] - b[1];
        if (std::fabs(d0) <= eps) {
            if (std::fabs(d1) <= eps)
                return a[2] < b[2] - eps;
            return a[1] < b[1] - eps;
        }
        return a[0] < b[0] - eps;
    }
};

bool stl_same(const float *a, const float *b)
{
    for (int i = 0; i < 3; i++)
        if (!(std::fabs(a[i] - b[i]) <= FLT_MIN))
            return false;
    return true;
}

struct stl_merger {
    std::map<std::array<float, 3>, int64_t, stl_less> seen;

    /* One triangle: its corners merged with earlier ones, then added
     * unless two of them are the same vertex. */
    void facet(const float *v, builder &out)
    {
        int64_t h[3];
        for (int i = 0; i < 3; i++) {
            std::array<float, 3> p = {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
            auto it = seen.find(p);
            if (it == seen.end()) {
                h[i] = (int64_t)out.vertex_count();
                out.add_vertex(p[0], p[1], p[2]);
                seen[p] = h[i];
            } else {
                h[i] = it->second;
            }
        }
        if (h[0] != h[1] && h[0] != h[2] && h[1] != h[2])
            out.add_face(h, 3);
    }
};

/* Binary when the file is exactly 84 + 50 * (count at byte 80) bytes
 * long. Ascii: every line that contains "outer" starts a facet whose next
 * three lines are read as "<word> x y z" (so a solid named "outer..." is
 * refused here). Stricter than a lenient reader: an ascii file must have
 * an "endsolid" line after its last facet, or it may have been cut between
 * two facets. */
vb_result read_stl(const char *path, const uint8_t *bytes, size_t size, builder &out, expectation *ex,
                   vb_error *err)
{
    ex->vertices_known = false;
    stl_merger merge;
    uint64_t declared = size >= 84 ? load_u32(bytes + 80, false) : 0;
    if (size >= 84 && 84 + 50 * declared == (uint64_t)size) {
        if (declared > max_count)
            return vb_fail(err, VB_ERR_FORMAT, "%s: too many triangles", path);
        for (uint64_t t = 0; t < declared; t++) {
            const uint8_t *rec = bytes + 84 + 50 * t;
            float v[9];
            for (int i = 0; i < 9; i++) {
                v[i] = load_f32(rec + 12 + 4 * i, false);
                if (!std::isfinite(v[i]))
                    return vb_fail(err, VB_ERR_INVALID,
                                   "%s: triangle %llu: vertex %d has a non-finite coordinate",
                                   path, (unsigned long long)t, i / 3);
            }
            if (!stl_same(v, v + 3) && !stl_same(v, v + 6) && !stl_same(v + 3, v + 6)) {
                ex->faces++;
                ex->triangles++;
            }
            merge.facet(v, out);
        }
        if (out.polygons != ex->faces)
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: coordinates that differ by less than FLT_MIN (%g) make it ambiguous which "
                           "corners are the same vertex (%llu or %llu triangles)", path, (double)FLT_MIN,
                           (unsigned long long)out.polygons, (unsigned long long)ex->faces);
        return VB_OK;
    }

    cursor c(bytes, size);
    uint64_t facets = 0;
    bool ended = false; /* an "endsolid" after the last facet */
    while (!c.at_end()) {
        const char *nl = (const char *)memchr(c.p, '\n', (size_t)(c.end - c.p));
        const char *le = nl ? nl : c.end;
        std::string line(c.p, le);
        unsigned long line_no = c.line;
        c.skip_line();
        size_t first = line.find_first_not_of(" \t\r\v\f");
        const char *word = first == std::string::npos ? "" : line.c_str() + first;
        bool name_line = strncasecmp(word, "solid", 5) == 0 || strncasecmp(word, "endsolid", 8) == 0;
        if (line.find("outer") == std::string::npos && line.find("OUTER") == std::string::npos) {
            if (strncasecmp(word, "endsolid", 8) == 0)
                ended = true;
            continue;
        }
        if (name_line)
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: line %lu: the solid's name contains 'outer', which STL readers take for the "
                           "start of a facet (rename the solid)", path, line_no);
        ended = false;
        float v[9];
        for (int i = 0; i < 3; i++) {
            if (c.at_end())
                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: file ends inside a facet (truncated?)",
                               path, line_no);
            token t;
            if (!c.next_on_line(&t))
                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: expected 'vertex x y z'", path, c.line);
            for (int k = 0; k < 3; k++) {
                if (!c.next_on_line(&t))
                    return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: expected 'vertex x y z'", path, c.line);
                num_status s = parse_float(t, &v[3 * i + k]);
                if (s != NUM_OK)
                    return vb_fail(err, s == NUM_BAD ? VB_ERR_FORMAT : VB_ERR_INVALID,
                                   "%s: line %lu: vertex coordinate '%.*s' %s", path, c.line,
                                   t.show_len(), t.b, num_problem(s));
            }
            c.skip_line();
        }
        facets++;
        if (facets > max_count)
            return vb_fail(err, VB_ERR_FORMAT, "%s: too many triangles", path);
        if (!stl_same(v, v + 3) && !stl_same(v, v + 6) && !stl_same(v + 3, v + 6)) {
            ex->faces++;
            ex->triangles++;
        }
        merge.facet(v, out);
    }
    if (facets == 0) {
        size_t i = 0;
        while (i < size && (is_blank((char)bytes[i]) || bytes[i] == '\n'))
            i++;
        if (size - i < 5 || memcmp(bytes + i, "solid", 5) != 0)
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: neither ascii STL (no 'solid' header, no facets) nor binary STL "
                           "(%zu bytes, but 84 + 50 x %llu triangles = %llu)",
                           path, size, (unsigned long long)declared,
                           (unsigned long long)(84 + 50 * declared));
    }
    /* Without its closing line a text STL may have lost any number of
     * facets. */
    if (!ended) {
        if (facets == 0)
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: neither ascii STL (no facets and no 'endsolid': truncated?) nor binary STL "
                           "(%zu bytes, but 84 + 50 x %llu triangles = %llu)",
                           path, size, (unsigned long long)declared, (unsigned long long)(84 + 50 * declared));
        return vb_fail(err, VB_ERR_FORMAT, "%s: ascii STL ends without 'endsolid' after its last facet (truncated?)",
                       path);
    }
    /* Tiny coordinates (within FLT_MIN of each other but not equal) can
     * make the merging disagree with the count above. */
    if (out.polygons != ex->faces)
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: coordinates that differ by less than FLT_MIN (%g) make it ambiguous which corners "
                       "are the same vertex (%llu or %llu triangles)", path, (double)FLT_MIN,
                       (unsigned long long)out.polygons, (unsigned long long)ex->faces);
    return VB_OK;
}

/* ---------------------------------------------------------------------- */
/* OFF                                                                    */
/* ---------------------------------------------------------------------- */

/* Header line [ST][C][N]OFF [BINARY] ("4OFF"/"nOFF" unsupported; BINARY
 * exactly one character after OFF, as OpenMesh's reader decided); counts
 * nV nF nE as tokens; each vertex is 3 numbers (+3 for a normal with N),
 * then the rest of its line (colours, texture coordinates: not used); each
 * face is a count and that many indices as tokens, then (only with C) the
 * rest of its line. Binary: little-endian uint32 counts, float32
 * coordinates, uint32 face sizes and indices, no colours. */
vb_result read_off(const char *path, const uint8_t *bytes, size_t size, builder &out, expectation *ex,
                   vb_error *err)
{
    cursor c(bytes, size);
    const char *p = c.p;
    const char *le = (const char *)memchr(p, '\n', size);
    if (!le)
        le = c.end;
    bool tex = false, color = false, normal = false, binary = false;
    if (le - p >= 2 && p[0] == 'S' && p[1] == 'T') {
        tex = true;
        p += 2;
    }
    if (p < le && *p == 'C') {
        color = true;
        p++;
    }
    if (p < le && *p == 'N') {
        normal = true;
        p++;
    }
    if (p < le && (*p == '4' || *p == 'n'))
        return vb_fail(err, VB_ERR_FORMAT, "%s: 4OFF/nOFF (vertex dimension other than 3) is not supported", path);
    if (le - p < 3 || memcmp(p, "OFF", 3) != 0)
        return vb_fail(err, VB_ERR_FORMAT, "%s: not an OFF file (first line must be [ST][C][N]OFF)", path);
    /* Exactly one character after "OFF", whatever it is, then BINARY:
     * "OFFxBINARY" is binary and "OFF  BINARY" is not (OpenMesh's rule,
     * kept: files were baked by it). */
    p += 3;
    if (p < le)
        p++;
    if (le - p >= 6 && memcmp(p, "BINARY", 6) == 0)
        binary = true;
    c.skip_line();

    std::vector<int64_t> polygon;
    if (binary) {
        if (tex || color)
            return vb_fail(err, VB_ERR_FORMAT, "%s: binary OFF with colours or texture coordinates is not supported", path);
        const uint8_t *b = (const uint8_t *)c.p;
        size_t left = (size_t)(c.end - c.p);
        if (left < 12)
            return vb_fail(err, VB_ERR_FORMAT, "%s: truncated binary OFF header", path);
        uint64_t nv = load_u32(b, false), nf = load_u32(b + 4, false);
        b += 12;
        left -= 12;
        size_t vsize = normal ? 24 : 12;
        if (nv > max_count || nf > max_count || nv > left / vsize)
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: header declares %llu vertices, more than the file's %zu bytes can hold",
                           path, (unsigned long long)nv, size);
        out.positions.reserve(3 * (size_t)nv);
        for (uint64_t i = 0; i < nv; i++) {
            float v[3];
            for (int k = 0; k < 3; k++) {
                v[k] = load_f32(b + 4 * k, false);
                if (!std::isfinite(v[k]))
                    return vb_fail(err, VB_ERR_INVALID, "%s: vertex %llu has a non-finite coordinate",
                                   path, (unsigned long long)i);
            }
            out.add_vertex(v[0], v[1], v[2]);
            if (normal) {
                const float n[3] = {load_f32(b + 12, false), load_f32(b + 16, false), load_f32(b + 20, false)};
                out.set_normal((int64_t)i, n);
            }
            b += vsize;
            left -= vsize;
        }
        for (uint64_t f = 0; f < nf; f++) {
            if (left < 4)
                return vb_fail(err, VB_ERR_FORMAT, "%s: truncated: face %llu of %llu is missing",
                               path, (unsigned long long)f, (unsigned long long)nf);
            uint64_t n = load_u32(b, false);
            b += 4;
            left -= 4;
            if (n > left / 4)
                return vb_fail(err, VB_ERR_FORMAT, "%s: truncated: face %llu has %llu vertices past the end of the file",
                               path, (unsigned long long)f, (unsigned long long)n);
            if (n < 3)
                return vb_fail(err, VB_ERR_FORMAT, "%s: face %llu has %llu vertices (needs at least 3)",
                               path, (unsigned long long)f, (unsigned long long)n);
            polygon.clear();
            for (uint64_t k = 0; k < n; k++) {
                uint64_t idx = load_u32(b + 4 * k, false);
                if (idx >= nv)
                    return vb_fail(err, VB_ERR_INVALID, "%s: face %llu: vertex index %llu out of range (%llu vertices)",
                                   path, (unsigned long long)f, (unsigned long long)idx, (unsigned long long)nv);
                polygon.push_back((int64_t)idx);
            }
            b += 4 * n;
            left -= 4 * n;
            ex->faces++;
            ex->triangles += n - 2;
            if (ex->triangles > max_count)
                return vb_fail(err, VB_ERR_FORMAT, "%s: too many triangles", path);
            out.add_face(polygon.data(), polygon.size());
        }
        ex->vertices = nv;
        return VB_OK;
    }

    /* ascii */
    long long counts[3];
    for (int i = 0; i < 3; i++) {
        token t;
        if (!c.next(&t) || !parse_int(t, &counts[i]) || counts[i] < 0)
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: line %lu: expected three counts (vertices faces edges) after the OFF line",
                           path, c.line);
    }
    /* The edge count is not used, but OpenMesh read it as an unsigned
     * int: a larger one failed its stream and every later number read as
     * garbage. */
    if (counts[2] > (long long)UINT32_MAX)
        return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: edge count %lld is too large", path, c.line, counts[2]);
    uint64_t nv = (uint64_t)counts[0], nf = (uint64_t)counts[1];
    /* Every vertex needs at least "0 0 0\n" and every face "3 0 0 0\n": a
     * header promising more than the file holds is rejected before any
     * loop runs over its counts. */
    if (nv > max_count || nf > max_count || nv > size / 6 || nf > size / 8)
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: header declares %llu vertices and %llu faces, more than the file's %zu bytes can hold",
                       path, (unsigned long long)nv, (unsigned long long)nf, size);
    int per_vertex = normal ? 6 : 3;
    out.positions.reserve(3 * (size_t)nv);
    for (uint64_t i = 0; i < nv; i++) {
        float v[6];
        for (int k = 0; k < per_vertex; k++) {
            token t;
            if (!c.next(&t))
                return vb_fail(err, VB_ERR_FORMAT, "%s: truncated: file ends in vertex %llu of %llu",
                               path, (unsigned long long)i, (unsigned long long)nv);
            num_status s = parse_float(t, &v[k]);
            if (s != NUM_OK)
                return vb_fail(err, s == NUM_BAD ? VB_ERR_FORMAT : VB_ERR_INVALID,
                               "%s: line %lu: vertex %llu: %s '%.*s' %s", path, c.line,
                               (unsigned long long)i, k < 3 ? "coordinate" : "normal component",
                               t.show_len(), t.b, num_problem(s));
        }
        out.add_vertex(v[0], v[1], v[2]);
        if (normal)
            out.set_normal((int64_t)i, v + 3);
        c.skip_line();
    }
    for (uint64_t f = 0; f < nf; f++) {
        token t;
        long long n = 0;
        if (!c.next(&t))
            return vb_fail(err, VB_ERR_FORMAT, "%s: truncated: file ends before face %llu of %llu",
                           path, (unsigned long long)f, (unsigned long long)nf);
        if (!parse_int(t, &n) || n < 0)
            return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: face %llu: vertex count '%.*s' is not a number",
                           path, c.line, (unsigned long long)f, t.show_len(), t.b);
        if (n < 3)
            return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: face %llu has %lld vertices (needs at least 3)",
                           path, c.line, (unsigned long long)f, n);
        if ((uint64_t)n > size || (uint64_t)n > max_count)
            return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: face %llu claims %lld vertices",
                           path, c.line, (unsigned long long)f, n);
        polygon.clear();
        for (long long k = 0; k < n; k++) {
            long long idx = 0;
            if (!c.next(&t))
                return vb_fail(err, VB_ERR_FORMAT, "%s: truncated: file ends in face %llu", path, (unsigned long long)f);
            if (!parse_int(t, &idx))
                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: face %llu: vertex index '%.*s' is not a number",
                               path, c.line, (unsigned long long)f, t.show_len(), t.b);
            if (idx < 0 || (uint64_t)idx >= nv)
                return vb_fail(err, VB_ERR_INVALID, "%s: line %lu: face %llu: vertex index %lld out of range (%llu vertices)",
                               path, c.line, (unsigned long long)f, idx, (unsigned long long)nv);
            polygon.push_back((int64_t)idx);
        }
        if (color)
            c.skip_line();
        ex->faces++;
        ex->triangles += (uint64_t)n - 2;
        if (ex->triangles > max_count)
            return vb_fail(err, VB_ERR_FORMAT, "%s: too many triangles", path);
        out.add_face(polygon.data(), polygon.size());
    }
    ex->vertices = nv;
    return VB_OK;
}

/* ---------------------------------------------------------------------- */
/* PLY                                                                    */
/* ---------------------------------------------------------------------- */

struct ply_type {
    const char *name;
    int size;
    bool is_float;
    bool is_signed;
};

/* In OpenMesh's order of preference (see ply_role). */
const ply_type ply_types[] = {
    {"float32", 4, true, true},  {"float64", 8, true, true},   {"float", 4, true, true},
    {"double", 8, true, true},   {"int8", 1, false, true},     {"uint8", 1, false, false},
    {"char", 1, false, true},    {"uchar", 1, false, false},   {"int32", 4, false, true},
    {"uint32", 4, false, false}, {"int", 4, false, true},      {"uint", 4, false, false},
    {"int16", 2, false, true},   {"uint16", 2, false, false},  {"short", 2, false, true},
    {"ushort", 2, false, false},
};

const ply_type *find_ply_type(const token &t)
{
    for (const ply_type &pt : ply_types)
        if (t.is(pt.name))
            return &pt;
    return nullptr;
}

const ply_type *find_ply_type(const std::string &s)
{
    for (const ply_type &pt : ply_types)
        if (s == pt.name)
            return &pt;
    return nullptr;
}

/* What a property is read as (OpenMesh's PLY reader decided by the
 * element's and the property's names). */
enum ply_role { PLY_OTHER, PLY_X, PLY_Y, PLY_Z, PLY_NX, PLY_NY, PLY_NZ, PLY_TEX, PLY_COLOR, PLY_INDICES };

struct ply_property {
    std::string name;
    const ply_type *type = nullptr;
    const ply_type *count_type = nullptr;   /* lists only */
    const ply_type *read_type = nullptr;    /* OpenMesh's reading of "property TYPE NAME" */
    ply_role role = PLY_OTHER;
};

struct ply_element {
    std::string name;
    uint64_t count = 0;
    std::vector<ply_property> props;
};

/* OpenMesh's PLY reader, for the properties of `e`: its roles (by name, in
 * elements named "vertex" and "face" only) and the type it reads: of
 * "property TYPE NAME" where NAME is itself a type name, whichever of the
 * two comes first in ply_types. */
void ply_roles(ply_element &e)
{
    static const char *const colours[] = {"red", "green", "blue", "diffuse_red", "diffuse_green", "diffuse_blue",
                                          "alpha"};
    for (ply_property &p : e.props) {
        p.read_type = p.type;
        if (!p.count_type) {
            const ply_type *other = find_ply_type(p.name);
            if (other && other < p.type)
                p.read_type = other;
        }
        const std::string &n = p.name;
        if (e.name == "vertex" && !p.count_type) {
            if (n == "x")
                p.role = PLY_X;
            else if (n == "y")
                p.role = PLY_Y;
            else if (n == "z")
                p.role = PLY_Z;
            else if (n == "nx")
                p.role = PLY_NX;
            else if (n == "ny")
                p.role = PLY_NY;
            else if (n == "nz")
                p.role = PLY_NZ;
            else if (n == "u" || n == "s" || n == "v" || n == "t")
                p.role = PLY_TEX;
            else
                for (const char *col : colours)
                    if (n == col)
                        p.role = PLY_COLOR;
        } else if (e.name == "face") {
            if (p.count_type && (n == "vertex_indices" || n == "vertex_index"))
                p.role = PLY_INDICES;
            else if (!p.count_type && (n == "red" || n == "green" || n == "blue" || n == "alpha"))
                p.role = PLY_COLOR;
        }
    }
}

/* Bytes OpenMesh's binary reader consumed for scalar property p (see
 * ply_binary_read). */
int ply_read_size(const ply_property &p, bool in_vertex, bool in_face)
{
    const ply_type *t = p.read_type;
    if (in_vertex && p.role >= PLY_X && p.role <= PLY_TEX)
        return t->is_float ? t->size : 0;
    if ((in_vertex || in_face) && p.role == PLY_COLOR)
        return t->is_float && t->size == 8 ? 0 : t->size;
    return t->size;
}

/* Binary data as OpenMesh's reader read it, into `out`: the layout the
 * header declares, except that it read x, y, z, normals and texture
 * coordinates only of type float or double (others as 0, consuming no
 * bytes), colours only of type float or an integer type (double: 0, no
 * bytes), and a property named after another type ("property uint16
 * int") as the type of those two that comes first in ply_types. Where that
 * differs from the declared layout the rest is read shifted, as it was;
 * the counts, ranges and values are then checked like any others (usually
 * the file is refused; where the shifts cancel it reads as it always did).
 * Reading past the end refuses the file. */
vb_result ply_binary_read(const char *path, const std::vector<ply_element> &elems, size_t last, int vertex_elem,
                          int face_elem, bool has_normals, bool big, const uint8_t *b, size_t left, builder &out,
                          vb_error *err)
{
    bool past_end = false;
    auto take = [&](size_t n) -> const uint8_t * {
        if (n > left) {
            past_end = true;
            left = 0;
            return nullptr;
        }
        const uint8_t *at = b;
        b += n;
        left -= n;
        return at;
    };
    /* An integer of type t (as OpenMesh's readInteger into unsigned int). */
    auto integer = [&](const ply_type *t) -> uint32_t {
        const uint8_t *q = take((size_t)t->size);
        if (!q)
            return 0;
        if (t->size == 1)
            return t->is_signed ? (uint32_t)(int32_t)(int8_t)q[0] : q[0];
        if (t->size == 2) {
            uint16_t u = big ? (uint16_t)(q[0] << 8 | q[1]) : (uint16_t)(q[1] << 8 | q[0]);
            return t->is_signed ? (uint32_t)(int32_t)(int16_t)u : u;
        }
        return load_u32(q, big);
    };
    std::vector<int64_t> polygon;
    for (size_t i = 0; i < last && !past_end; i++) {
        const ply_element &e = elems[i];
        const bool is_vertex = (int)i == vertex_elem, is_face = (int)i == face_elem;
        for (uint64_t n = 0; n < e.count && !past_end; n++) {
            float v[3] = {0.0f, 0.0f, 0.0f}, nrm[3] = {0.0f, 0.0f, 0.0f};
            for (const ply_property &p : e.props) {
                const ply_type *t = p.read_type;
                const bool real = t->is_float;
                if (p.role == PLY_INDICES) {
                    uint32_t count = integer(p.count_type);
                    polygon.clear();
                    for (uint32_t q = 0; q < count && !past_end; q++)
                        polygon.push_back((int64_t)(int32_t)integer(t));
                    if (past_end)
                        break;
                    if (polygon.size() < 3)
                        return vb_fail(err, VB_ERR_FORMAT, "%s: face %llu has %zu vertices as the binary data is "
                                                           "read", path, (unsigned long long)n, polygon.size());
                    out.add_face(polygon.data(), polygon.size());
                } else if (is_vertex && p.role >= PLY_X && p.role <= PLY_TEX) {
                    float f = 0.0f;
                    if (real && t->size == 4) {
                        const uint8_t *q = take(4);
                        f = q ? load_f32(q, big) : 0.0f;
                    } else if (real) {
                        const uint8_t *q = take(8);
                        f = q ? (float)load_f64(q, big) : 0.0f;
                    }
                    if (p.role <= PLY_Z)
                        v[p.role - PLY_X] = f;
                    else if (p.role <= PLY_NZ)
                        nrm[p.role - PLY_NX] = f;
                } else {
                    take((size_t)ply_read_size(p, is_vertex, is_face));
                }
                if (past_end)
                    break;
            }
            if (is_vertex && !past_end) {
                out.add_vertex(v[0], v[1], v[2]);
                if (has_normals)
                    out.set_normal((int64_t)n, nrm);
            }
        }
    }
    if (past_end)
        return vb_fail(err, VB_ERR_FORMAT, "%s: the binary data ends early as its properties' types are read "
                                           "(x, y, z and normals of an integer type, colours of type double and "
                                           "properties named after a type are read otherwise than declared)", path);
    return VB_OK;
}

/* Elements are read in order up to and including "face" (later ones are
 * never read); "vertex" must come before "face" and have x, y, z; the
 * only list property is the face's vertex_indices (or vertex_index), with
 * a uint8/uchar/uint16/int count and integer entries; one "face" element
 * and nothing before vertex_indices in it. Every value of the elements
 * read is checked (ascii: a whole number of the property's kind; both:
 * sizes, face indices in range, finite x, y, z) before it is used.
 *
 * Refused because OpenMesh's reader read them otherwise than declared
 * (the baker refused such files before, or read garbage from them): binary
 * x, y, z, normals or texture coordinates of an integer type (read as 0,
 * consuming nothing), binary colours of type double (the same) and binary
 * properties named after another type of another size ("property double
 * float32"), unless what OpenMesh read (ply_binary_read) is still what the
 * file declares; ascii colours that are not whole numbers of int range
 * unless their type is float (read as integers: the rest failed or shifted
 * into the next value), unless nothing used follows (the last face). */
vb_result read_ply(const char *path, const uint8_t *bytes, size_t size, builder &out, expectation *ex,
                   vb_error *err)
{
    cursor c(bytes, size);
    token t;
    if (!c.next_on_line(&t) || !(t.is("ply") || t.is("PLY")) || c.next_on_line(&t))
        return vb_fail(err, VB_ERR_FORMAT, "%s: not a PLY file (first line must be 'ply')", path);
    c.skip_line();

    int format = -1; /* 0 ascii, 1 binary little endian, 2 binary big endian */
    std::vector<ply_element> elems;
    bool ended = false;
    while (!c.at_end()) {
        token kw;
        if (!c.next_on_line(&kw)) {
            c.skip_line();
            continue;
        }
        if (kw.is("end_header")) {
            /* ascii data follows the end_header token; binary data the
             * end of its line */
            ended = true;
            if (format != 0)
                c.skip_line();
            break;
        }
        unsigned long line = c.line;
        std::vector<token> args;
        while (c.next_on_line(&t))
            args.push_back(t);
        if (kw.is("comment")) {
            c.skip_line();
            continue;
        }
        if (kw.is("format")) {
            if (args.size() < 2)
                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: bad format line", path, line);
            if (args[0].is("ascii"))
                format = 0;
            else if (args[0].is("binary_little_endian"))
                format = 1;
            else if (args[0].is("binary_big_endian"))
                format = 2;
            else
                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: unknown PLY format '%.*s'",
                               path, line, args[0].show_len(), args[0].b);
        } else if (kw.is("element")) {
            long long n = 0;
            if (args.size() != 2 || !parse_int(args[1], &n) || n < 0)
                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: bad element line", path, line);
            if ((uint64_t)n > max_count)
                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: element count %lld is too large", path, line, n);
            ply_element e;
            e.name.assign(args[0].b, args[0].e);
            e.count = (uint64_t)n;
            elems.push_back(e);
        } else if (kw.is("property")) {
            if (elems.empty())
                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: property before any element", path, line);
            ply_property p;
            if (!args.empty() && args[0].is("list")) {
                if (args.size() != 4)
                    return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: bad list property", path, line);
                p.count_type = find_ply_type(args[1]);
                p.type = find_ply_type(args[2]);
                p.name.assign(args[3].b, args[3].e);
                if (!p.count_type || !p.type)
                    return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: unknown type in list property", path, line);
                if (!(args[1].is("uint8") || args[1].is("uchar") || args[1].is("uint16") || args[1].is("int")))
                    return vb_fail(err, VB_ERR_FORMAT,
                                   "%s: line %lu: list count type '%.*s' is not supported (uint8, uchar, uint16, int)",
                                   path, line, args[1].show_len(), args[1].b);
            } else {
                if (args.size() != 2)
                    return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: bad property line", path, line);
                /* "property float x" and "property x float" */
                int ti = find_ply_type(args[0]) ? 0 : 1;
                p.type = find_ply_type(args[ti]);
                if (!p.type)
                    return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: unknown property type", path, line);
                p.name.assign(args[1 - ti].b, args[1 - ti].e);
            }
            elems.back().props.push_back(p);
        }
        /* other keywords (obj_info, ...): ignored */
        c.skip_line();
    }
    if (!ended)
        return vb_fail(err, VB_ERR_FORMAT, "%s: PLY header has no end_header (truncated?)", path);
    if (format < 0)
        return vb_fail(err, VB_ERR_FORMAT, "%s: PLY header has no format line", path);

    /* Which elements are read, and the structure that can be read. */
    size_t last = elems.size();
    int vertex_elem = -1, face_elem = -1;
    for (size_t i = 0; i < elems.size(); i++) {
        if (elems[i].name == "vertex" && vertex_elem < 0 && face_elem < 0) {
            vertex_elem = (int)i;
        } else if (elems[i].name == "face") {
            face_elem = (int)i;
            last = i + 1;
            break;
        } else if (elems[i].name == "vertex") {
            return vb_fail(err, VB_ERR_FORMAT, "%s: a second vertex element (or one after the faces) is not supported", path);
        }
    }
    if (vertex_elem < 0)
        return vb_fail(err, VB_ERR_INVALID, "%s: empty mesh (no vertex element)", path);
    /* OpenMesh's ascii reader read the first face element as many times as
     * the last "element face" line said. */
    if (std::count_if(elems.begin(), elems.end(), [](const ply_element &e) { return e.name == "face"; }) > 1)
        return vb_fail(err, VB_ERR_FORMAT, "%s: a second face element is not supported", path);
    int xyz[3] = {-1, -1, -1};
    int indices_prop = -1;
    bool has_normals = false;
    for (size_t i = 0; i < last; i++) {
        ply_element &e = elems[i];
        ply_roles(e);
        for (size_t k = 0; k < e.props.size(); k++) {
            const ply_property &p = e.props[k];
            if ((int)i == vertex_elem && !p.count_type) {
                for (int a = 0; a < 3; a++)
                    if (p.name == std::string(1, (char)('x' + a))) {
                        if (xyz[a] >= 0)
                            return vb_fail(err, VB_ERR_FORMAT, "%s: vertex property %s appears twice", path, p.name.c_str());
                        xyz[a] = (int)k;
                    }
                has_normals |= p.role == PLY_NX || p.role == PLY_NY || p.role == PLY_NZ;
            }
            if (!p.count_type)
                continue;
            if ((int)i == face_elem && (p.name == "vertex_indices" || p.name == "vertex_index") && indices_prop < 0 &&
                !p.type->is_float) {
                indices_prop = (int)k;
                continue;
            }
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: list property '%s' of element '%s' is not supported (it would be misread)",
                           path, p.name.c_str(), e.name.c_str());
        }
    }
    if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0)
        return vb_fail(err, VB_ERR_FORMAT, "%s: the vertex element lacks x, y or z", path);
    /* OpenMesh dropped the face properties declared before vertex_indices
     * from its list but not from the data, and misread every face. */
    if (indices_prop > 0)
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: face property '%s' before vertex_indices is not supported (the faces would be "
                       "misread)", path, elems[(size_t)face_elem].props[0].name.c_str());
    /* ascii: a value OpenMesh's reader would have read otherwise than the
     * checks below is refused once they have passed (before, the file
     * failed after them, or was read as garbage). */
    vb_error differs;
    differs.msg[0] = 0;
    uint64_t nv = elems[(size_t)vertex_elem].count;

    /* Walk the data of every element read. */
    bool big = format == 2;
    const uint8_t *b = nullptr;
    size_t left = 0;
    if (format != 0) {
        b = (const uint8_t *)c.p;
        left = (size_t)(c.end - c.p);
    }
    std::vector<int64_t> polygon;
    for (size_t i = 0; i < last; i++) {
        const ply_element &e = elems[i];
        const bool is_vertex = (int)i == vertex_elem, is_face = (int)i == face_elem;
        /* Items without properties hold no data: a count of billions of
         * them would only spin this walk (a fuzzer find). */
        if (e.props.empty() && e.count > 0)
            return vb_fail(err, VB_ERR_FORMAT, "%s: element '%s' has %llu items but no properties",
                           path, e.name.c_str(), (unsigned long long)e.count);
        if (is_vertex)
            out.positions.reserve(3 * (size_t)std::min<uint64_t>(e.count, 1u << 24));
        for (uint64_t n = 0; n < e.count; n++) {
            float v[3] = {0.0f, 0.0f, 0.0f}, nrm[3] = {0.0f, 0.0f, 0.0f};
            for (size_t k = 0; k < e.props.size(); k++) {
                const ply_property &p = e.props[k];
                bool is_xyz = is_vertex && ((int)k == xyz[0] || (int)k == xyz[1] || (int)k == xyz[2]);
                bool is_indices = is_face && (int)k == indices_prop;
                /* the value of a coordinate or normal, once read */
                float *into = nullptr;
                if (is_vertex && p.role >= PLY_X && p.role <= PLY_NZ)
                    into = p.role <= PLY_Z ? &v[p.role - PLY_X] : &nrm[p.role - PLY_NX];
                uint64_t items = 1;
                if (is_indices)
                    polygon.clear();
                if (format != 0) {
                    if (p.count_type) {
                        int cs = p.count_type->size;
                        if (left < (size_t)cs)
                            return vb_fail(err, VB_ERR_FORMAT, "%s: truncated in %s %llu of %llu",
                                           path, e.name.c_str(), (unsigned long long)n, (unsigned long long)e.count);
                        uint64_t cnt = 0;
                        if (cs == 1)
                            cnt = b[0];
                        else if (cs == 2)
                            cnt = big ? (uint64_t)(b[0] << 8 | b[1]) : (uint64_t)(b[1] << 8 | b[0]);
                        else {
                            uint32_t u = load_u32(b, big);
                            if (p.count_type->is_signed && (int32_t)u < 0)
                                return vb_fail(err, VB_ERR_FORMAT, "%s: %s %llu: negative list size",
                                               path, e.name.c_str(), (unsigned long long)n);
                            cnt = u;
                        }
                        b += cs;
                        left -= (size_t)cs;
                        items = cnt;
                        if (is_indices && cnt < 3)
                            return vb_fail(err, VB_ERR_FORMAT, "%s: face %llu has %llu vertices (needs at least 3)",
                                           path, (unsigned long long)n, (unsigned long long)cnt);
                    }
                    int ts = p.type->size;
                    if (items > left / (size_t)ts)
                        return vb_fail(err, VB_ERR_FORMAT, "%s: truncated in %s %llu of %llu",
                                       path, e.name.c_str(), (unsigned long long)n, (unsigned long long)e.count);
                    if (into) {
                        double d = 0.0;
                        if (p.type->is_float)
                            d = ts == 4 ? (double)load_f32(b, big) : load_f64(b, big);
                        else if (ts == 1)
                            d = p.type->is_signed ? (double)(int8_t)b[0] : (double)b[0];
                        else if (ts == 2) {
                            uint16_t u = big ? (uint16_t)(b[0] << 8 | b[1]) : (uint16_t)(b[1] << 8 | b[0]);
                            d = p.type->is_signed ? (double)(int16_t)u : (double)u;
                        } else {
                            uint32_t u = load_u32(b, big);
                            d = p.type->is_signed ? (double)(int32_t)u : (double)u;
                        }
                        if (is_xyz && (!std::isfinite(d) || std::fabs(d) > (double)FLT_MAX))
                            return vb_fail(err, VB_ERR_INVALID, "%s: vertex %llu has a non-finite coordinate",
                                           path, (unsigned long long)n);
                        *into = ts == 4 && p.type->is_float ? load_f32(b, big) : (float)d;
                    }
                    if (is_indices) {
                        for (uint64_t q = 0; q < items; q++) {
                            const uint8_t *ip = b + q * (size_t)ts;
                            long long idx = 0;
                            if (ts == 1)
                                idx = p.type->is_signed ? (long long)(int8_t)ip[0] : (long long)ip[0];
                            else if (ts == 2) {
                                uint16_t u = big ? (uint16_t)(ip[0] << 8 | ip[1]) : (uint16_t)(ip[1] << 8 | ip[0]);
                                idx = p.type->is_signed ? (long long)(int16_t)u : (long long)u;
                            } else {
                                uint32_t u = load_u32(ip, big);
                                idx = p.type->is_signed ? (long long)(int32_t)u : (long long)u;
                            }
                            if (idx < 0 || (uint64_t)idx >= nv)
                                return vb_fail(err, VB_ERR_INVALID, "%s: face %llu: vertex index %lld out of range (%llu vertices)",
                                               path, (unsigned long long)n, idx, (unsigned long long)nv);
                            polygon.push_back(idx);
                        }
                    }
                    b += items * (size_t)ts;
                    left -= items * (size_t)ts;
                } else {
                    if (p.count_type) {
                        long long cnt = 0;
                        if (!c.next(&t))
                            return vb_fail(err, VB_ERR_FORMAT, "%s: truncated: file ends in %s %llu of %llu",
                                           path, e.name.c_str(), (unsigned long long)n, (unsigned long long)e.count);
                        if (!parse_int(t, &cnt) || cnt < 0 || (uint64_t)cnt > size)
                            return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: %s %llu: bad list size '%.*s'",
                                           path, c.line, e.name.c_str(), (unsigned long long)n, t.show_len(), t.b);
                        if (is_indices && cnt < 3)
                            return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: face %llu has %lld vertices (needs at least 3)",
                                           path, c.line, (unsigned long long)n, cnt);
                        items = (uint64_t)cnt;
                    }
                    for (uint64_t q = 0; q < items; q++) {
                        if (!c.next(&t))
                            return vb_fail(err, VB_ERR_FORMAT, "%s: truncated: file ends in %s %llu of %llu",
                                           path, e.name.c_str(), (unsigned long long)n, (unsigned long long)e.count);
                        long long iv = 0;
                        float f = 0.0f;
                        if (p.type->is_float) {
                            num_status s = parse_float(t, &f);
                            if (s != NUM_OK)
                                return vb_fail(err, s == NUM_BAD ? VB_ERR_FORMAT : VB_ERR_INVALID,
                                               "%s: line %lu: %s %llu: %s '%.*s' %s", path, c.line,
                                               e.name.c_str(), (unsigned long long)n, p.name.c_str(),
                                               t.show_len(), t.b, num_problem(s));
                        } else {
                            if (!parse_int(t, &iv))
                                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: %s %llu: %s '%.*s' is not an integer",
                                               path, c.line, e.name.c_str(), (unsigned long long)n, p.name.c_str(),
                                               t.show_len(), t.b);
                            if (is_indices && (iv < 0 || (uint64_t)iv >= nv))
                                return vb_fail(err, VB_ERR_INVALID,
                                               "%s: line %lu: face %llu: vertex index %lld out of range (%llu vertices)",
                                               path, c.line, (unsigned long long)n, iv, (unsigned long long)nv);
                        }
                        /* Colours not of type float were read as an int:
                         * anything else would shift (or stop) the rest,
                         * unless nothing used is read after it (in the
                         * last face, after its vertex_indices). */
                        long long cv = 0;
                        bool last_read = is_face && n + 1 == e.count;
                        if (p.role == PLY_COLOR && !(p.read_type->is_float && p.read_type->size == 4) &&
                            !last_read && !differs.msg[0] && (!parse_int(t, &cv) || cv < INT_MIN || cv > INT_MAX))
                            vb_fail(&differs, VB_ERR_FORMAT,
                                    "%s: line %lu: %s %llu: %s '%.*s': a colour of type %s must be a whole number "
                                    "of int range", path, c.line, e.name.c_str(), (unsigned long long)n,
                                    p.name.c_str(), t.show_len(), t.b, p.type->name);
                        if (into) {
                            if (!p.type->is_float)
                                parse_float(t, &f);   /* an integer, checked above */
                            *into = f;
                        }
                        if (is_indices)
                            polygon.push_back(iv);
                    }
                }
                if (is_indices) {
                    ex->faces++;
                    ex->triangles += items - 2;
                    if (ex->triangles > max_count)
                        return vb_fail(err, VB_ERR_FORMAT, "%s: too many triangles", path);
                    out.add_face(polygon.data(), polygon.size());
                }
            }
            if (is_vertex) {
                out.add_vertex(v[0], v[1], v[2]);
                if (has_normals)
                    out.set_normal((int64_t)n, nrm);
            }
        }
    }
    ex->vertices = nv;
    if (differs.msg[0]) {
        if (err)
            *err = differs;
        return VB_ERR_FORMAT;
    }
    /* Binary properties OpenMesh's reader read otherwise than declared
     * (ply_binary_read): what it read must be what the file says, or the
     * file is refused. */
    const ply_property *odd = nullptr;
    const ply_element *odd_elem = nullptr;
    for (size_t i = 0; i < last && format != 0 && !odd; i++)
        for (const ply_property &p : elems[i].props)
            if (!p.count_type && ply_read_size(p, (int)i == vertex_elem, (int)i == face_elem) != p.type->size) {
                odd = &p;
                odd_elem = &elems[i];
                break;
            }
    if (odd) {
        builder as_read;
        vb_error why;
        if (ply_binary_read(path, elems, last, vertex_elem, face_elem, has_normals, big, (const uint8_t *)c.p,
                            (size_t)(c.end - c.p), as_read, &why) != VB_OK ||
            as_read.positions != out.positions || as_read.normal_sums != out.normal_sums ||
            as_read.has_normal != out.has_normal || as_read.indices != out.indices)
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: binary property '%s' of type %s in element '%s' is not supported (x, y, z, "
                           "normals and texture coordinates must be float or double, colours float or an integer "
                           "type, and a property must not be named after another type)",
                           path, odd->name.c_str(), odd->type->name, odd_elem->name.c_str());
    }
    return VB_OK;
}

vb_result parse(const char *name, vb_mesh_format format, const uint8_t *bytes, size_t size, vb_mesh_raw *out,
                vb_error *err)
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
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: %s by other readers: the file reads as %llu vertices, %llu faces, %llu triangles "
                           "or as %llu, %llu, %llu (refused)", name, ex.hint.c_str(),
                           (unsigned long long)b.vertex_count(), (unsigned long long)b.polygons,
                           (unsigned long long)b.triangle_count(), (unsigned long long)ex.vertices,
                           (unsigned long long)ex.faces, (unsigned long long)ex.triangles);
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: read %llu vertices, %llu faces, %llu triangles, but the file has %llu, %llu, %llu; "
                       "refusing a partial mesh", name, (unsigned long long)b.vertex_count(),
                       (unsigned long long)b.polygons, (unsigned long long)b.triangle_count(),
                       (unsigned long long)ex.vertices, (unsigned long long)ex.faces,
                       (unsigned long long)ex.triangles);
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
            return vb_fail(err, VB_ERR_INVALID, "%s: vertex %llu has a non-finite coordinate (%g, %g, %g)", name,
                           (unsigned long long)i + base, (double)p[0], (double)p[1], (double)p[2]);
    }
    for (size_t j = 0; j < b.indices.size(); j++) {
        int64_t v = b.indices[j];
        if (v < 0 || (uint64_t)v >= nv)
            return vb_fail(err, VB_ERR_INVALID, "%s: face %llu: vertex index %lld out of range (%u vertices)", name,
                           (unsigned long long)b.tri_face[j / 3] + base, (long long)v + (long long)base,
                           (unsigned)nv);
    }
    b.finish(ex.dropped, out);
    return VB_OK;
}

} // namespace

/* ====================================================================== */
/* C entry points: no exception passes these                              */
/* ====================================================================== */

extern "C" vb_result vb_mesh_parse(const char *name, vb_mesh_format format, const uint8_t *bytes, size_t size,
                                   vb_mesh_raw *out, vb_error *err)
{
    if (!name || (!bytes && size) || !out)
        return vb_fail(err, VB_ERR_ARGUMENT, "vb_mesh_parse: NULL argument");
    static const uint8_t nothing = 0;
    try {
        return parse(name, format, bytes ? bytes : &nothing, size, out, err);
    } catch (const std::bad_alloc &) {
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "%s: out of memory while reading", name);
    } catch (const std::exception &e) {
        return vb_fail(err, VB_ERR_FORMAT, "%s: reading failed: %s", name, e.what());
    } catch (...) {
        return vb_fail(err, VB_ERR_FORMAT, "%s: reading failed with an unknown exception", name);
    }
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
    memset(raw, 0, sizeof *raw);
}
