/*
 * mesh_read.h - internal to the mesh readers (C++ only): what the four
 * strict readers share. mesh_parse.cpp holds the shared part and the
 * entry point vb_mesh_parse (mesh_parse.h says what is read and refused);
 * each reader has its own file: mesh_obj.cpp, mesh_ply.cpp, mesh_off.cpp,
 * mesh_stl.cpp. mesh_gltf.cpp uses the array copy and the exception guard.
 *
 * Here: a cursor over the bytes that counts lines and reads tokens as
 * std::istream does, numbers as OpenMesh 9's readers read them, the arrays
 * being built (builder: positions, normals averaged as mesh_parse.h says,
 * triangulated faces, OBJ corner normals), what the checks counted
 * (expectation, compared with what was built by vb_mesh_parse), and
 * little-endian/big-endian loads for the binary formats.
 *
 * Errors: the readers return vb_result after vb_fail; they may throw
 * std::bad_alloc, which no_throw turns into VB_ERR_OUT_OF_MEMORY at the C
 * entry points. Threading: no shared state.
 */
#ifndef VB_MESH_READ_H
#define VB_MESH_READ_H

#include "mesh_parse.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <utility>
#include <vector>

namespace vb_read
{

/* ====================================================================== */
/* Text scanning                                                          */
/* ====================================================================== */

/* Whitespace as std::istream's operator>> sees it in the "C" locale; '\n'
 * is handled separately so that lines can be counted. */
inline bool is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

inline bool is_digit(char c)
{
    return c >= '0' && c <= '9';
}

struct token {
    const char *b = nullptr;
    const char *e = nullptr;
    size_t size() const
    {
        return (size_t)(e - b);
    }
    bool is(const char *s) const
    {
        size_t n = strlen(s);
        return size() == n && memcmp(b, s, n) == 0;
    }
    /* For messages: at most 40 characters of the token. */
    int show_len() const
    {
        return (int)std::min<size_t>(size(), 40);
    }
};

/* A cursor over the file's bytes that counts lines (1-based). */
struct cursor {
    const char *p;
    const char *end;
    unsigned long line;

    cursor(const uint8_t *bytes, size_t size)
        : p((const char *)bytes), end((const char *)bytes + size), line(1)
    {
    }

    bool at_end() const
    {
        return p >= end;
    }

    /* Next whitespace-separated token, crossing lines (as operator>>). */
    bool next(token *t)
    {
        while (p < end && (is_blank(*p) || *p == '\n')) {
            if (*p == '\n')
                line++;
            p++;
        }
        return p < end && take(t);
    }

    /* Next token on the current line only; false at the end of the line. */
    bool next_on_line(token *t)
    {
        while (p < end && is_blank(*p))
            p++;
        return p < end && *p != '\n' && take(t);
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

  private:
    /* The token starting at p (not a blank). */
    bool take(token *t)
    {
        t->b = p;
        while (p < end && !is_blank(*p) && *p != '\n')
            p++;
        t->e = p;
        return true;
    }
};

enum num_status { NUM_OK, NUM_BAD, NUM_RANGE, NUM_NONFINITE, NUM_NUL };

/* A whole token as a float, the way std::istream reads one (strtof): an
 * optional sign, decimal digits, optional exponent; underflow is fine
 * (the float strtof gives, down to a signed zero), overflow is an error.
 * "nan" and "inf" parse here (and are reported as such) although
 * std::istream refuses them. A NUL byte in the token is NUM_NUL (a
 * message showing the token would end at it). */
num_status parse_float(const token &t, float *out);

/* A whole token as a decimal integer with an optional sign. */
bool parse_int(const token &t, long long *out);

/* The leading integer of [b, e) as `std::istream >> int` reads it: an
 * optional sign and decimal digits, stopping at anything else ("2nd" is
 * 2). False, with *out 0, when there is no digit; false, with *out
 * INT_MAX or INT_MIN, when it does not fit an int. */
bool stream_int(const char *b, const char *e, int *out);

/* For messages: "is not a number", "is out of float range", ... */
const char *num_problem(num_status s);
/* Whether a token holds a NUL byte (binary data in a text file). A
 * message quoting the token stops at the NUL, so an integer field that
 * holds one is said as such (int_problem), as parse_float's NUM_NUL is. */
inline bool has_nul(const token &t)
{
    return memchr(t.b, '\0', t.size()) != nullptr;
}
/* For an integer token that did not parse (or was refused): the problem
 * for a message "... '%.*s' %s": num_problem(NUM_NUL) when the token
 * holds a NUL byte, else `otherwise` ("is not a number", ...). */
inline const char *int_problem(const token &t, const char *otherwise)
{
    return has_nul(t) ? num_problem(NUM_NUL) : otherwise;
}
/* The error code for a status other than NUM_OK: VB_ERR_FORMAT for text
 * that is no number, VB_ERR_INVALID for a number out of range. */
inline vb_result num_error(num_status s)
{
    return s == NUM_BAD || s == NUM_NUL ? VB_ERR_FORMAT : VB_ERR_INVALID;
}

/* The largest counts accepted from a file: vertex indices are uint32_t,
 * and the readers this one replaces kept handles in an int. */
const uint64_t max_count = 0x7fffffffu;

/* ====================================================================== */
/* Little binary helpers                                                  */
/* ====================================================================== */

/* Whether a text file starts with a UTF-8 byte order mark (EF BB BF). */
inline bool utf8_bom(const uint8_t *bytes, size_t size)
{
    return size >= 3 && bytes[0] == 0xef && bytes[1] == 0xbb && bytes[2] == 0xbf;
}

inline uint32_t load_u32(const uint8_t *p, bool big_endian)
{
    return big_endian ? (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3]
                      : (uint32_t)p[3] << 24 | (uint32_t)p[2] << 16 | (uint32_t)p[1] << 8 | p[0];
}

inline float load_f32(const uint8_t *p, bool big_endian)
{
    uint32_t u = load_u32(p, big_endian);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

inline double load_f64(const uint8_t *p, bool big_endian)
{
    uint64_t u = big_endian ? (uint64_t)load_u32(p, true) << 32 | load_u32(p + 4, true)
                            : (uint64_t)load_u32(p + 4, false) << 32 | load_u32(p, false);
    double d;
    memcpy(&d, &u, 8);
    return d;
}

/* ====================================================================== */
/* The arrays being built                                                 */
/* ====================================================================== */

/* v's elements in a malloc'ed array (at least one byte), for vb_mesh_raw,
 * which mesh.c frees with free(); throws std::bad_alloc. */
template <typename T> T *malloc_copy(const std::vector<T> &v)
{
    T *p = (T *)malloc(std::max<size_t>(v.size(), 1) * sizeof(T));
    if (!p)
        throw std::bad_alloc();
    if (!v.empty())
        memcpy(p, v.data(), v.size() * sizeof(T));
    return p;
}

class builder
{
  public:
    std::vector<float> positions;
    std::vector<float> normal_sums; /* empty until the first normal */
    std::vector<uint8_t> has_normal;
    std::vector<int64_t> indices; /* fanned; triangulate() re-cuts */
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

    uint64_t vertex_count() const
    {
        return positions.size() / 3;
    }
    uint64_t triangle_count() const
    {
        return indices.size() / 3;
    }

    void add_vertex(float x, float y, float z)
    {
        positions.push_back(x);
        positions.push_back(y);
        positions.push_back(z);
    }

    /* A polygon of n >= 3 vertices, fanned from its first (triangulate
     * later replaces the fans that reach outside their polygon). */
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
     * in normal_sums as given, 2 a sum of unit vectors (vdsh_unit3f_keep).
     * Non-finite normals and vertices that do not exist are ignored. */
    void set_normal(int64_t v, const float n[3]);

    /* Re-triangulate, once every position and index is known and checked
     * (vb_mesh_parse, before finish), each polygon of 4+ vertices whose
     * fan from its first vertex does not lie inside it: ear clipping
     * (triangulate_polygon), its corner normals following its corners.
     * Polygons whose fan does (every convex one) keep it exactly. */
    void triangulate();

    /* Hand over malloc'ed arrays (mesh.c frees them with free()). */
    void finish(uint64_t dropped, vb_mesh_raw *out);

    /* Point-in-triangle tests left to ear clipping in this file (a bound
     * on the time a file of huge concave polygons can take: past it, the
     * rest are fanned, deterministically). */
    uint64_t clip_budget = 200000000;
    /* The polygons (file numbers, ascending) fanned because clip_budget
     * ran out, not because they are not simple (for mesh.c's warnings). */
    std::vector<uint32_t> unclipped;

  private:
    /* The corners of the polygon just fanned: its vertices' pending
     * normals, onto each of its triangles' corners. */
    void add_corner_normals(const int64_t *v, size_t n);
};

/* The triangulation of polygon v[0..n-1] (n >= 4; indices into
 * `positions`, 3 floats each, all in range and finite) into n - 2
 * triangles, appended to `tris` as corner numbers 0..n-1 of the polygon,
 * 3 per triangle, in the polygon's winding. The one place the readers
 * triangulate polygons (builder::triangulate calls it for every reader).
 *
 * The polygon is projected onto the plane of its Newell normal (its
 * dominant axis dropped, so that the projection keeps its orientation).
 * When every fan triangle from corner 0 has no negative area there (all
 * convex polygons, and those corner 0 sees whole), the result is that fan,
 * exactly as the readers always fanned: {0,1,2}, {0,2,3}, ... Otherwise
 * the polygon is cut by ear clipping (from corner 1 on; the first ear
 * found is clipped, and the search goes on from the ear's next corner).
 * Falls back to the fan, returning false, for polygons with no area
 * (a zero Newell normal), without an ear (not simple), whose clipped
 * triangles cover more than 1% above the area the polygon encloses (the
 * Newell normal's length: far from flat; the fan's excess is what mesh.c
 * reports), or when *budget point-in-triangle tests run out (then, and
 * only then, *timed_out is set true when given). Returns true
 * when the result is not the fan. Deterministic: the same floats give
 * the same triangles on any machine (IEEE double, no library calls). */
bool triangulate_polygon(const float *positions, const int64_t *v, size_t n,
                         std::vector<uint32_t> &tris, uint64_t *budget, bool *timed_out = nullptr);

/* What the checks counted: the file must deliver exactly this. */
struct expectation {
    uint64_t vertices = 0;
    bool vertices_known = true; /* STL: merged, count not known ahead */
    uint64_t faces = 0;         /* polygons with >= 3 vertices */
    uint64_t triangles = 0;     /* n - 2 per polygon of n */
    uint64_t dropped = 0;       /* OBJ: triangles of faces with < 3 distinct */
    std::string hint;           /* why the two might differ: the first line
                                     OpenMesh's reader read otherwise */
};

/* ====================================================================== */
/* The readers, one file each                                             */
/* ====================================================================== */

/* Each reads the whole file `bytes` into `out`, counting in `ex` what the
 * file must deliver; `path` is for messages. */
vb_result read_obj(const char *path, const uint8_t *bytes, size_t size, builder &out,
                   expectation *ex, vb_error *err);
vb_result read_ply(const char *path, const uint8_t *bytes, size_t size, builder &out,
                   expectation *ex, vb_error *err);
vb_result read_off(const char *path, const uint8_t *bytes, size_t size, builder &out,
                   expectation *ex, vb_error *err);
vb_result read_stl(const char *path, const uint8_t *bytes, size_t size, builder &out,
                   expectation *ex, vb_error *err);

/* ====================================================================== */
/* C entry points: no exception passes these                              */
/* ====================================================================== */

/* read() (returning vb_result) with every C++ exception turned into a
 * vb_result and a message that names `name`. */
template <typename F> vb_result no_throw(const char *name, vb_error *err, F read)
{
    try {
        return read();
    } catch (const std::bad_alloc &) {
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "%s: out of memory while reading", name);
    } catch (const std::exception &e) {
        return vb_fail(err, VB_ERR_FORMAT, "%s: reading failed: %s", name, e.what());
    } catch (...) {
        return vb_fail(err, VB_ERR_FORMAT, "%s: reading failed with an unknown exception", name);
    }
}

} // namespace vb_read

#endif /* VB_MESH_READ_H */
