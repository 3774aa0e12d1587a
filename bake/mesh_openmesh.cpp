/*
 * mesh_openmesh.cpp - the only code that includes OpenMesh: reading
 * OBJ/PLY/OFF/STL with OpenMesh's readers, and vb_mesh_refine on
 * OpenMesh's TriMesh. Everything here is reached through the C functions at
 * the end, each of which catches every C++ exception.
 *
 * Reading happens in three steps:
 *
 *  1. A strict pre-pass over the file's bytes (the ones mesh.c hashed).
 *     OpenMesh's readers are lenient in ways that lose or invent geometry
 *     without a word: an OBJ vertex whose number does not parse is skipped
 *     (every later index then points one vertex off), "nan" or a truncated
 *     ascii PLY/OFF puts the stream into a failed state and the rest of the
 *     file reads as zeros, a face with fewer than three vertices vanishes,
 *     an OFF header that claims 3.5e12 vertices loops for hours. The
 *     pre-pass models what each reader will do with the bytes and rejects
 *     those files with a message naming the file, the line and the problem.
 *     It also counts the vertices, faces and triangles OpenMesh must
 *     deliver.
 *
 *  2. OpenMesh reads the file into `collector`, a BaseImporter that only
 *     appends to arrays. OpenMesh's own ImporterT would build a half-edge
 *     mesh and must duplicate the vertices of every face that is not
 *     manifold (and silently drops faces that reference bad indices);
 *     occluders must keep every triangle of the file and receivers the
 *     file's vertex numbering, so no topology is built at this stage.
 *     OBJ: fed from memory with its `mtllib`, `usemtl` and `vt` lines
 *     commented out: materials and texture coordinates are not used; this
 *     keeps OpenMesh from opening whatever file `mtllib` names (a FIFO or
 *     /dev/zero would hang it) and from parsing numbers nobody needs (40%
 *     of Sponza's load time). PLY: fed from memory behind a plainly
 *     rewritten header (OpenMesh finds binary data at a fixed offset from
 *     the last header token, so a comment or a trailing space before
 *     end_header shifts every value it reads). STL: fed from memory. OFF:
 *     read from the path, because OpenMesh's OFF reader takes its options
 *     (binary, normals, colours) from the header only when it opens the
 *     file itself (its stream reader keeps the options of whatever file it
 *     saw last); the counts cross-check below catches a file that changed
 *     in between. Bytes loaded from memory go through a temporary copy.
 *
 *  3. The counts OpenMesh delivered are compared with the pre-pass's; any
 *     difference is an error rather than a silently partial mesh.
 *
 * OpenMesh's warnings go to its omerr/omlog/omout streams, which forward to
 * std::cerr/clog/cout (some readers also write to std::cerr directly).
 * While OpenMesh runs, those three standard streams are pointed at a
 * string; the first line is quoted when OpenMesh fails, nothing reaches the
 * baker's stderr. That redirection, OpenMesh's reader singletons and its
 * stream multiplexers are process-wide, so every OpenMesh call here runs
 * under one mutex.
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
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#pragma GCC diagnostic pop

#include <algorithm>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cerrno>
#include <cstring>
#include <iostream>
#include <mutex>
#include <new>
#include <queue>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include <strings.h>
#include <unistd.h>

namespace {

/* ====================================================================== */
/* OpenMesh session: one at a time, output captured                       */
/* ====================================================================== */

std::mutex &openmesh_mutex()
{
    static std::mutex m;
    return m;
}

/* A stream buffer that keeps the first few KiB written to it: OpenMesh can
 * print one warning per face, and only the first line is ever quoted. */
class capture_buf : public std::streambuf {
public:
    const std::string &text() const { return text_; }

protected:
    int_type overflow(int_type c) override
    {
        if (!traits_type::eq_int_type(c, traits_type::eof()) && text_.size() < cap)
            text_.push_back(traits_type::to_char_type(c));
        return traits_type::not_eof(c);
    }
    std::streamsize xsputn(const char *s, std::streamsize n) override
    {
        size_t room = text_.size() < cap ? cap - text_.size() : 0;
        text_.append(s, std::min(room, (size_t)n));
        return n;
    }

private:
    static constexpr size_t cap = 4096;
    std::string text_;
};

class openmesh_session {
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
         * is pending while it still lands in the capture. */
        ::omerr().flush();
        ::omlog().flush();
        ::omout().flush();
        std::cerr.rdbuf(err_);
        std::clog.rdbuf(log_);
        std::cout.rdbuf(out_);
    }
    openmesh_session(const openmesh_session &) = delete;
    openmesh_session &operator=(const openmesh_session &) = delete;

    /* First non-empty line OpenMesh printed, trimmed, for an error message. */
    std::string first_line()
    {
        ::omerr().flush();
        ::omlog().flush();
        const std::string &t = buf_.text();
        size_t i = 0;
        while (i < t.size()) {
            size_t j = t.find('\n', i);
            if (j == std::string::npos)
                j = t.size();
            size_t b = t.find_first_not_of(" \t\r", i);
            if (b != std::string::npos && b < j) {
                size_t e = t.find_last_not_of(" \t\r", j - 1);
                return t.substr(b, std::min<size_t>(e + 1 - b, 200));
            }
            i = j + 1;
        }
        return std::string();
    }

private:
    std::lock_guard<std::mutex> lock_;
    capture_buf buf_;
    std::streambuf *err_;
    std::streambuf *log_;
    std::streambuf *out_;
};

/* ====================================================================== */
/* Text scanning                                                          */
/* ====================================================================== */

/* Whitespace as std::istream's operator>> sees it in the "C" locale; '\n'
 * is handled separately so that lines can be counted. */
bool is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
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
 * optional sign, decimal digits, optional exponent; underflow is fine,
 * overflow is an error. "nan" and "inf" parse here (and are reported as
 * such) although std::istream refuses them. */
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
        /* Out of float range: overflow is an error, underflow rounds to a
         * tiny or zero float as strtof does. */
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

/* What the pre-pass expects OpenMesh to deliver. */
struct expectation {
    uint64_t vertices = 0;
    bool vertices_known = true;   /* STL: OpenMesh merges, count unknown */
    uint64_t faces = 0;           /* add_face calls with >= 3 vertices */
    uint64_t triangles = 0;       /* after fan triangulation */
    uint64_t dropped = 0;         /* OBJ: triangles of faces OpenMesh drops */
    bool stl_binary = false;
    std::vector<size_t> comment_out;   /* OBJ: offsets of mtllib/usemtl/vt */
    std::string ply_header;            /* PLY: the header rewritten plainly */
    size_t ply_body = 0;               /* PLY: where the data starts */
};

/* The largest counts accepted from a file: vertex indices are uint32_t
 * and OpenMesh's handles are int. */
const uint64_t max_count = 0x7fffffffu;

/* ---------------------------------------------------------------------- */
/* OBJ                                                                    */
/* ---------------------------------------------------------------------- */

/* Mirrors OpenMesh's OBJ reader: lines split at '\n' only, first token is
 * the keyword, '#' lines are comments; "v" needs three numbers (a vertex
 * whose numbers do not parse is skipped by OpenMesh, shifting every later
 * index), so does "vn" (the same for normal indices); "f" takes the part
 * before the first '/' of each corner, resolves negative indices against
 * the "v" lines so far, and drops repeated corners before adding the face
 * (fewer than three left: no face, which is fine: it had no area). An
 * inline '#' ends a line. Stricter than OpenMesh where it would guess: a
 * number must be the whole token, a face needs three corners. "vt",
 * "mtllib" and "usemtl" lines are only noted, to be commented out. */
vb_result scan_obj(const char *path, const uint8_t *bytes, size_t size,
                   expectation *ex, vb_error *err)
{
    if (size >= 2 && ((bytes[0] == 0xfe && bytes[1] == 0xff) ||
                      (bytes[0] == 0xff && bytes[1] == 0xfe)))
        return vb_fail(err, VB_ERR_FORMAT, "%s: UTF-16 text is not supported (save as UTF-8 or ASCII)", path);

    /* Positive indices may point forward (OpenMesh reads all vertices
     * first), so count the "v" lines before checking faces. */
    uint64_t total = 0;
    for (cursor c(bytes, size); !c.at_end(); c.skip_line()) {
        token kw;
        if (c.next_on_line(&kw) && kw.is("v"))
            total++;
    }

    cursor c(bytes, size);
    uint64_t nv = 0, nn = 0;
    std::vector<long long> corners;

    while (!c.at_end()) {
        token kw;
        if (!c.next_on_line(&kw) || kw.b[0] == '#') {
            c.skip_line();
            continue;
        }
        if (kw.is("v") || kw.is("vn")) {
            const char *what = kw.is("v") ? "vertex" : "normal";
            uint64_t number = kw.is("v") ? nv + 1 : nn + 1;
            for (int i = 0; i < 3; i++) {
                token t;
                if (!c.next_on_line(&t) || t.b[0] == '#')
                    return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: %s %llu has fewer than 3 numbers",
                                   path, c.line, what, (unsigned long long)number);
                float f;
                num_status s = parse_float(t, &f);
                if (s != NUM_OK)
                    return vb_fail(err, s == NUM_BAD ? VB_ERR_FORMAT : VB_ERR_INVALID,
                                   "%s: line %lu: %s %llu: coordinate '%.*s' %s", path, c.line, what,
                                   (unsigned long long)number, t.show_len(), t.b, num_problem(s));
            }
            if (kw.is("v"))
                nv++;
            else if (kw.is("vn"))
                nn++;
            if (nv > max_count)
                return vb_fail(err, VB_ERR_FORMAT, "%s: too many vertices", path);
        } else if (kw.is("f")) {
            corners.clear();
            token t;
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
        } else if (kw.is("mtllib") || kw.is("usemtl") || kw.is("vt")) {
            ex->comment_out.push_back((size_t)(kw.b - (const char *)bytes));
        }
        c.skip_line();
    }
    if (ex->triangles > max_count)
        return vb_fail(err, VB_ERR_FORMAT, "%s: too many triangles", path);
    ex->vertices = nv;
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

/* Exactly equal positions in OpenMesh's STL reader (its CmpVec with
 * eps = FLT_MIN): these are merged into one vertex. */
bool stl_same(const float *a, const float *b)
{
    for (int i = 0; i < 3; i++)
        if (!(std::fabs(a[i] - b[i]) <= FLT_MIN))
            return false;
    return true;
}

/* ---------------------------------------------------------------------- */
/* STL                                                                    */
/* ---------------------------------------------------------------------- */

/* OpenMesh decides binary vs ascii by size alone: binary when the file is
 * exactly 84 + 50 * (count at byte 80) bytes long. Ascii: every line that
 * contains "outer" starts a facet whose next three lines are read as
 * "<word> x y z" (so a solid named "outer..." is refused here). Both drop
 * a triangle whose corners share a position. Stricter than OpenMesh: an
 * ascii file must have an "endsolid" line after its last facet, or it may
 * have been cut between two facets. */
vb_result scan_stl(const char *path, const uint8_t *bytes, size_t size,
                   expectation *ex, vb_error *err)
{
    ex->vertices_known = false;
    uint64_t declared = size >= 84 ? load_u32(bytes + 80, false) : 0;
    if (size >= 84 && 84 + 50 * declared == (uint64_t)size) {
        ex->stl_binary = true;
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
        }
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
                           "%s: line %lu: the solid's name contains 'outer', which OpenMesh's STL reader "
                           "takes for the start of a facet (rename the solid)", path, line_no);
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
     * facets: OpenMesh would read what is left without a word. */
    if (!ended) {
        if (facets == 0)
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: neither ascii STL (no facets and no 'endsolid': truncated?) nor binary STL "
                           "(%zu bytes, but 84 + 50 x %llu triangles = %llu)",
                           path, size, (unsigned long long)declared, (unsigned long long)(84 + 50 * declared));
        return vb_fail(err, VB_ERR_FORMAT, "%s: ascii STL ends without 'endsolid' after its last facet (truncated?)",
                       path);
    }
    return VB_OK;
}

/* ---------------------------------------------------------------------- */
/* OFF                                                                    */
/* ---------------------------------------------------------------------- */

/* Mirrors OpenMesh's OFF reader: header line [ST][C][N]OFF [BINARY]
 * ("4OFF"/"nOFF" unsupported; BINARY exactly one character after OFF);
 * counts nV nF nE as tokens; each vertex is
 * 3 numbers (+3 for a normal with N), then the rest of its line; each face
 * is a count and that many indices as tokens, then (only with C) the rest
 * of its line. Binary: little-endian uint32 counts, float32 coordinates,
 * uint32 face sizes and indices. */
vb_result scan_off(const char *path, const uint8_t *bytes, size_t size,
                   expectation *ex, vb_error *err)
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
    /* OpenMesh skips exactly one character after "OFF", whatever it is,
     * then looks for BINARY: "OFFxBINARY" is binary to it and "OFF  BINARY"
     * is not. Decide as it does, or the checks below check the wrong file. */
    p += 3;
    if (p < le)
        p++;
    if (le - p >= 6 && memcmp(p, "BINARY", 6) == 0)
        binary = true;
    c.skip_line();

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
        for (uint64_t i = 0; i < nv; i++) {
            for (int k = 0; k < 3; k++)
                if (!std::isfinite(load_f32(b + 4 * k, false)))
                    return vb_fail(err, VB_ERR_INVALID, "%s: vertex %llu has a non-finite coordinate",
                                   path, (unsigned long long)i);
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
            for (uint64_t k = 0; k < n; k++) {
                uint64_t idx = load_u32(b + 4 * k, false);
                if (idx >= nv)
                    return vb_fail(err, VB_ERR_INVALID, "%s: face %llu: vertex index %llu out of range (%llu vertices)",
                                   path, (unsigned long long)f, (unsigned long long)idx, (unsigned long long)nv);
            }
            b += 4 * n;
            left -= 4 * n;
            ex->faces++;
            ex->triangles += n - 2;
        }
        ex->vertices = nv;
        if (ex->triangles > max_count)
            return vb_fail(err, VB_ERR_FORMAT, "%s: too many triangles", path);
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
    uint64_t nv = (uint64_t)counts[0], nf = (uint64_t)counts[1];
    /* Every vertex needs at least "0 0 0\n" and every face "3 0 0 0\n": a
     * header promising more than the file holds is rejected before any
     * loop runs over its counts. */
    if (nv > max_count || nf > max_count || nv > size / 6 || nf > size / 8)
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: header declares %llu vertices and %llu faces, more than the file's %zu bytes can hold",
                       path, (unsigned long long)nv, (unsigned long long)nf, size);
    int per_vertex = normal ? 6 : 3;
    for (uint64_t i = 0; i < nv; i++) {
        for (int k = 0; k < per_vertex; k++) {
            token t;
            if (!c.next(&t))
                return vb_fail(err, VB_ERR_FORMAT, "%s: truncated: file ends in vertex %llu of %llu",
                               path, (unsigned long long)i, (unsigned long long)nv);
            float f;
            num_status s = parse_float(t, &f);
            if (s != NUM_OK)
                return vb_fail(err, s == NUM_BAD ? VB_ERR_FORMAT : VB_ERR_INVALID,
                               "%s: line %lu: vertex %llu: %s '%.*s' %s", path, c.line,
                               (unsigned long long)i, k < 3 ? "coordinate" : "normal component",
                               t.show_len(), t.b, num_problem(s));
        }
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
        if ((uint64_t)n > size)
            return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: face %llu claims %lld vertices",
                           path, c.line, (unsigned long long)f, n);
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
        }
        if (color)
            c.skip_line();
        ex->faces++;
        ex->triangles += (uint64_t)n - 2;
    }
    ex->vertices = nv;
    if (ex->triangles > max_count)
        return vb_fail(err, VB_ERR_FORMAT, "%s: too many triangles", path);
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

const ply_type ply_types[] = {
    {"char", 1, false, true},    {"uchar", 1, false, false},  {"short", 2, false, true},
    {"ushort", 2, false, false}, {"int", 4, false, true},     {"uint", 4, false, false},
    {"float", 4, true, true},    {"double", 8, true, true},   {"int8", 1, false, true},
    {"uint8", 1, false, false},  {"int16", 2, false, true},   {"uint16", 2, false, false},
    {"int32", 4, false, true},   {"uint32", 4, false, false}, {"float32", 4, true, true},
    {"float64", 8, true, true},
};

const ply_type *find_ply_type(const token &t)
{
    for (const ply_type &pt : ply_types)
        if (t.is(pt.name))
            return &pt;
    return nullptr;
}

struct ply_property {
    std::string name;
    const ply_type *type = nullptr;
    const ply_type *count_type = nullptr;   /* lists only */
};

struct ply_element {
    std::string name;
    uint64_t count = 0;
    std::vector<ply_property> props;
};

/* Mirrors OpenMesh's PLY reader: elements are read in order up to and
 * including "face" (later ones are never read); "vertex" must come before
 * "face" and have x, y, z; the only list OpenMesh can step over correctly
 * is the face's vertex_indices (or vertex_index), any other list is read as
 * one value and shifts everything after it, so such files are refused;
 * list counts must be uint8/uchar/uint16/int; only one "face" element
 * (the ascii reader takes the count of the last one for the first) and
 * nothing before vertex_indices in it (dropped from the property list
 * but not from the data). Every value of the elements
 * read is checked (ascii: a number of the property's kind; both: sizes,
 * face indices in range, finite x, y, z), so a file OpenMesh would read
 * as garbage never reaches it. */
vb_result scan_ply(const char *path, const uint8_t *bytes, size_t size,
                   expectation *ex, vb_error *err)
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
                                   "%s: line %lu: list count type '%.*s' is not supported by OpenMesh (uint8, uchar, uint16, int)",
                                   path, line, args[1].show_len(), args[1].b);
            } else {
                if (args.size() != 2)
                    return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: bad property line", path, line);
                /* OpenMesh accepts "property float x" and "property x float" */
                int ti = find_ply_type(args[0]) ? 0 : 1;
                p.type = find_ply_type(args[ti]);
                if (!p.type)
                    return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: unknown property type", path, line);
                p.name.assign(args[1 - ti].b, args[1 - ti].e);
            }
            elems.back().props.push_back(p);
        }
        /* other keywords (obj_info, ...): ignored, as OpenMesh does */
        c.skip_line();
    }
    if (!ended)
        return vb_fail(err, VB_ERR_FORMAT, "%s: PLY header has no end_header (truncated?)", path);
    if (format < 0)
        return vb_fail(err, VB_ERR_FORMAT, "%s: PLY header has no format line", path);

    /* Which elements OpenMesh reads, and the structure it can handle. */
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
    /* OpenMesh's ascii reader reads the first face element as many times
     * as the last "element face" line says. */
    if (std::count_if(elems.begin(), elems.end(), [](const ply_element &e) { return e.name == "face"; }) > 1)
        return vb_fail(err, VB_ERR_FORMAT, "%s: a second face element is not supported", path);
    int xyz[3] = {-1, -1, -1};
    int indices_prop = -1;
    for (size_t i = 0; i < last; i++) {
        const ply_element &e = elems[i];
        for (size_t k = 0; k < e.props.size(); k++) {
            const ply_property &p = e.props[k];
            if ((int)i == vertex_elem && !p.count_type) {
                for (int a = 0; a < 3; a++)
                    if (p.name == std::string(1, (char)('x' + a))) {
                        if (xyz[a] >= 0)
                            return vb_fail(err, VB_ERR_FORMAT, "%s: vertex property %s appears twice", path, p.name.c_str());
                        xyz[a] = (int)k;
                    }
            }
            if (!p.count_type)
                continue;
            if ((int)i == face_elem && (p.name == "vertex_indices" || p.name == "vertex_index") && indices_prop < 0 &&
                !p.type->is_float) {
                indices_prop = (int)k;
                continue;
            }
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: list property '%s' of element '%s' is not supported (OpenMesh would misread the file)",
                           path, p.name.c_str(), e.name.c_str());
        }
    }
    if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0)
        return vb_fail(err, VB_ERR_FORMAT, "%s: the vertex element lacks x, y or z", path);
    /* OpenMesh drops the face properties declared before vertex_indices
     * from its list but not from the data, and misreads every face. */
    if (indices_prop > 0)
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: face property '%s' before vertex_indices is not supported (OpenMesh would misread the "
                       "faces)", path, elems[(size_t)face_elem].props[0].name.c_str());
    uint64_t nv = elems[(size_t)vertex_elem].count;

    /* OpenMesh finds binary data at a fixed distance after the last header
     * token before end_header, so a comment, blank line or trailing space
     * there makes it read everything shifted by a byte or more. It is fed
     * this plain rewrite of the header instead (same elements, properties
     * and order), followed by the file's data. */
    static const char *const format_names[3] = {"ascii", "binary_little_endian", "binary_big_endian"};
    std::string header = std::string("ply\nformat ") + format_names[format] + " 1.0\n";
    for (const ply_element &e : elems) {
        header += "element " + e.name + " " + std::to_string(e.count) + "\n";
        for (const ply_property &p : e.props) {
            if (p.count_type)
                header += std::string("property list ") + p.count_type->name + " " + p.type->name + " " + p.name + "\n";
            else
                header += std::string("property ") + p.type->name + " " + p.name + "\n";
        }
    }
    header += "end_header\n";
    ex->ply_header = header;
    ex->ply_body = (size_t)(c.p - (const char *)bytes);

    /* Walk the data of every element OpenMesh reads. */
    bool big = format == 2;
    const uint8_t *b = nullptr;
    size_t left = 0;
    if (format != 0) {
        b = (const uint8_t *)c.p;
        left = (size_t)(c.end - c.p);
    }
    for (size_t i = 0; i < last; i++) {
        const ply_element &e = elems[i];
        /* Items without properties hold no data: a count of billions of
         * them would only spin this walk (a fuzzer find). */
        if (e.props.empty() && e.count > 0)
            return vb_fail(err, VB_ERR_FORMAT, "%s: element '%s' has %llu items but no properties",
                           path, e.name.c_str(), (unsigned long long)e.count);
        for (uint64_t n = 0; n < e.count; n++) {
            for (size_t k = 0; k < e.props.size(); k++) {
                const ply_property &p = e.props[k];
                bool is_xyz = (int)i == vertex_elem && ((int)k == xyz[0] || (int)k == xyz[1] || (int)k == xyz[2]);
                bool is_indices = (int)i == face_elem && (int)k == indices_prop;
                uint64_t items = 1;
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
                    if (is_xyz) {
                        double v = 0.0;
                        if (ts == 4 && p.type->is_float) {
                            v = load_f32(b, big);
                        } else if (ts == 8 && p.type->is_float) {
                            uint64_t u = (uint64_t)load_u32(big ? b : b + 4, big) << 32 | load_u32(big ? b + 4 : b, big);
                            memcpy(&v, &u, 8);
                        }
                        if (!std::isfinite(v) || std::fabs(v) > (double)FLT_MAX)
                            return vb_fail(err, VB_ERR_INVALID, "%s: vertex %llu has a non-finite coordinate",
                                           path, (unsigned long long)n);
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
                        if (p.type->is_float) {
                            float f;
                            num_status s = parse_float(t, &f);
                            if (s != NUM_OK)
                                return vb_fail(err, s == NUM_BAD ? VB_ERR_FORMAT : VB_ERR_INVALID,
                                               "%s: line %lu: %s %llu: %s '%.*s' %s", path, c.line,
                                               e.name.c_str(), (unsigned long long)n, p.name.c_str(),
                                               t.show_len(), t.b, num_problem(s));
                        } else {
                            long long v = 0;
                            if (!parse_int(t, &v))
                                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: %s %llu: %s '%.*s' is not an integer",
                                               path, c.line, e.name.c_str(), (unsigned long long)n, p.name.c_str(),
                                               t.show_len(), t.b);
                            if (is_indices && (v < 0 || (uint64_t)v >= nv))
                                return vb_fail(err, VB_ERR_INVALID,
                                               "%s: line %lu: face %llu: vertex index %lld out of range (%llu vertices)",
                                               path, c.line, (unsigned long long)n, v, (unsigned long long)nv);
                        }
                    }
                }
                if (is_indices) {
                    ex->faces++;
                    ex->triangles += items - 2;
                }
            }
        }
    }
    ex->vertices = nv;
    if (ex->triangles > max_count)
        return vb_fail(err, VB_ERR_FORMAT, "%s: too many triangles", path);
    return VB_OK;
}

/* ====================================================================== */
/* The collector: OpenMesh's reader calls, as plain arrays                */
/* ====================================================================== */

using OpenMesh::EdgeHandle;
using OpenMesh::FaceHandle;
using OpenMesh::HalfedgeHandle;
using OpenMesh::Vec2f;
using OpenMesh::Vec3d;
using OpenMesh::Vec3f;
using OpenMesh::Vec3uc;
using OpenMesh::Vec4f;
using OpenMesh::Vec4uc;
using OpenMesh::VertexHandle;

class collector : public OpenMesh::IO::BaseImporter {
public:
    std::vector<float> positions;
    std::vector<float> normal_sums;    /* empty until the first normal */
    std::vector<uint8_t> has_normal;
    std::vector<int64_t> indices;      /* fan-triangulated */
    std::vector<uint32_t> tri_face;
    uint64_t polygons = 0;
    uint64_t short_faces = 0;

    /* OBJ: normals per face corner. OpenMesh's OBJ reader calls
     * set_normal(vertex, normal) for each corner of a face line that names
     * a normal, in order, then add_face with the face's vertices (repeated
     * ones removed); no other call tells where a face line begins. Those
     * calls are kept in `pending` until add_face, which gives each corner
     * the last normal set for its vertex. (A line OpenMesh drops, with
     * fewer than three distinct vertices, leaves its calls pending for the
     * next face; they matter only where that face names the same vertex
     * without a normal.) */
    bool per_corner = false;
    std::vector<std::pair<int, Vec3f>> pending;
    std::vector<float> corner_normals; /* 9 per triangle, once one is given */
    std::vector<uint8_t> corner_given; /* 3 per triangle */

    VertexHandle add_vertex(const Vec3f &p) override
    {
        positions.push_back(p[0]);
        positions.push_back(p[1]);
        positions.push_back(p[2]);
        return VertexHandle((int)(positions.size() / 3 - 1));
    }
    VertexHandle add_vertex(const Vec3d &p) override
    {
        return add_vertex(Vec3f((float)p[0], (float)p[1], (float)p[2]));
    }
    VertexHandle add_vertex() override { return add_vertex(Vec3f(0.0f, 0.0f, 0.0f)); }

    FaceHandle add_face(const VHandles &v) override
    {
        if (v.size() < 3) {
            short_faces++;
            return FaceHandle();
        }
        for (size_t i = 1; i + 1 < v.size(); i++) {
            indices.push_back(v[0].idx());
            indices.push_back(v[i].idx());
            indices.push_back(v[i + 1].idx());
            tri_face.push_back((uint32_t)polygons);
        }
        if (per_corner)
            add_corner_normals(v);
        return FaceHandle((int)polygons++);
    }

    /* The corners of the polygon just fanned: its vertices' pending
     * normals, onto each of its triangles' corners. */
    void add_corner_normals(const VHandles &v)
    {
        if (pending.empty() && corner_normals.empty())
            return;
        size_t tris = indices.size() / 3, fan = v.size() - 2;
        if (corner_normals.empty()) {
            corner_normals.assign(9 * (tris - fan), 0.0f);
            corner_given.assign(3 * (tris - fan), 0);
        }
        std::vector<const Vec3f *> given(v.size(), nullptr);
        if (pending.size() <= 16) {
            for (size_t c = 0; c < v.size(); c++)
                for (size_t p = pending.size(); p-- > 0;)
                    if (pending[p].first == v[c].idx()) {
                        given[c] = &pending[p].second;
                        break;
                    }
        } else {
            std::vector<std::pair<int, size_t>> last;   /* vertex, latest pending entry */
            last.reserve(pending.size());
            for (size_t p = 0; p < pending.size(); p++)
                last.emplace_back(pending[p].first, p);
            std::stable_sort(last.begin(), last.end(),
                             [](const std::pair<int, size_t> &a, const std::pair<int, size_t> &b) {
                                 return a.first < b.first;
                             });
            for (size_t c = 0; c < v.size(); c++) {
                auto it = std::upper_bound(last.begin(), last.end(), std::make_pair(v[c].idx(), SIZE_MAX));
                if (it != last.begin() && (it - 1)->first == v[c].idx())
                    given[c] = &pending[(it - 1)->second].second;
            }
        }
        for (size_t i = 1; i + 1 < v.size(); i++) {
            const size_t corner[3] = {0, i, i + 1};
            for (size_t k = 0; k < 3; k++) {
                const Vec3f *n = given[corner[k]];
                corner_given.push_back(n != nullptr);
                for (int q = 0; q < 3; q++)
                    corner_normals.push_back(n ? (*n)[q] : 0.0f);
            }
        }
        pending.clear();
    }

    void set_point(VertexHandle vh, const Vec3f &p) override
    {
        if (valid(vh))
            for (int k = 0; k < 3; k++)
                positions[3 * (size_t)vh.idx() + (size_t)k] = p[k];
    }

    /* A vertex may be given several normals (an OBJ position used with
     * different "vn" in different faces): their unit average is used. One
     * normal (or the same one each time) is kept as it is when it is
     * already unit length, so that writing and reading back a mesh
     * reproduces its normals bit for bit. has_normal: 0 none, 1 one value
     * in normal_sums as given, 2 a sum of unit vectors. */
    void set_normal(VertexHandle vh, const Vec3f &n) override
    {
        if (!valid(vh) || !std::isfinite(n[0]) || !std::isfinite(n[1]) || !std::isfinite(n[2]))
            return;
        if (per_corner)
            pending.emplace_back(vh.idx(), n);
        size_t nv = positions.size() / 3;
        if (normal_sums.size() < 3 * nv) {
            normal_sums.resize(3 * nv, 0.0f);
            has_normal.resize(nv, 0);
        }
        size_t i = (size_t)vh.idx();
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
    void set_normal(VertexHandle vh, const Vec3d &n) override
    {
        set_normal(vh, Vec3f((float)n[0], (float)n[1], (float)n[2]));
    }

    void reserve(unsigned int nv, unsigned int, unsigned int nf) override
    {
        /* counts come from the file: trust them only up to a point */
        positions.reserve(3 * (size_t)std::min(nv, 1u << 24));
        indices.reserve(3 * (size_t)std::min(nf, 1u << 24));
    }

    size_t n_vertices() const override { return positions.size() / 3; }
    size_t n_faces() const override { return (size_t)polygons; }
    size_t n_edges() const override { return 0; }

    /* Everything else OpenMesh may hand over is not needed. */
    HalfedgeHandle add_edge(VertexHandle, VertexHandle) override { return HalfedgeHandle(); }
    FaceHandle add_face(HalfedgeHandle) override { return FaceHandle(); }
    void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec2f> &) override {}
    void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec3f> &) override {}
    void set_face_texindex(FaceHandle, int) override {}
    void set_halfedge(VertexHandle, HalfedgeHandle) override {}
    void set_color(VertexHandle, const Vec3uc &) override {}
    void set_color(VertexHandle, const Vec4uc &) override {}
    void set_color(VertexHandle, const Vec3f &) override {}
    void set_color(VertexHandle, const Vec4f &) override {}
    void set_texcoord(VertexHandle, const Vec2f &) override {}
    void set_texcoord(VertexHandle, const Vec3f &) override {}
    void set_status(VertexHandle, const OpenMesh::Attributes::StatusInfo &) override {}
    void set_next(HalfedgeHandle, HalfedgeHandle) override {}
    void set_face(HalfedgeHandle, FaceHandle) override {}
    void request_face_texcoords2D() override {}
    void set_texcoord(HalfedgeHandle, const Vec2f &) override {}
    void set_texcoord(HalfedgeHandle, const Vec3f &) override {}
    void set_status(HalfedgeHandle, const OpenMesh::Attributes::StatusInfo &) override {}
    void set_color(EdgeHandle, const Vec3uc &) override {}
    void set_color(EdgeHandle, const Vec4uc &) override {}
    void set_color(EdgeHandle, const Vec3f &) override {}
    void set_color(EdgeHandle, const Vec4f &) override {}
    void set_status(EdgeHandle, const OpenMesh::Attributes::StatusInfo &) override {}
    void set_normal(FaceHandle, const Vec3f &) override {}
    void set_normal(FaceHandle, const Vec3d &) override {}
    void set_color(FaceHandle, const Vec3uc &) override {}
    void set_color(FaceHandle, const Vec4uc &) override {}
    void set_color(FaceHandle, const Vec3f &) override {}
    void set_color(FaceHandle, const Vec4f &) override {}
    void set_status(FaceHandle, const OpenMesh::Attributes::StatusInfo &) override {}
    void add_texture_information(int, std::string) override {}

private:
    bool valid(VertexHandle vh) const
    {
        return vh.idx() >= 0 && (size_t)vh.idx() < positions.size() / 3;
    }
};

template <typename T>
T *malloc_copy(const std::vector<T> &v)
{
    T *p = (T *)malloc(std::max<size_t>(v.size(), 1) * sizeof(T));
    if (!p)
        throw std::bad_alloc();
    if (!v.empty())
        memcpy(p, v.data(), v.size() * sizeof(T));
    return p;
}

/* OFF from memory: a private copy of the bytes in a file named *.off
 * (OpenMesh picks its reader by the extension), removed when this goes. */
class temp_off_file {
public:
    temp_off_file() = default;
    ~temp_off_file()
    {
        if (!path_.empty())
            unlink(path_.c_str());
    }
    temp_off_file(const temp_off_file &) = delete;
    temp_off_file &operator=(const temp_off_file &) = delete;

    vb_result create(const char *name, const uint8_t *bytes, size_t size, vb_error *err)
    {
        const char *dir = getenv("TMPDIR");
        std::string templ = std::string(dir && dir[0] ? dir : "/tmp") + "/vdsh-mesh-XXXXXX.off";
        int fd = mkstemps(&templ[0], 4);
        if (fd < 0)
            return vb_fail(err, VB_ERR_IO, "%s: cannot create a temporary file for OpenMesh's OFF reader (%s): %s",
                           name, templ.c_str(), strerror(errno));
        path_ = templ;
        size_t done = 0;
        while (done < size) {
            ssize_t n = write(fd, bytes + done, size - done);
            if (n < 0 && errno == EINTR)
                continue;
            if (n <= 0) {
                int e = n < 0 ? errno : EIO;
                close(fd);
                return vb_fail(err, VB_ERR_IO, "%s: cannot write a temporary file for OpenMesh's OFF reader (%s): %s",
                               name, path_.c_str(), strerror(e));
            }
            done += (size_t)n;
        }
        if (close(fd) != 0)
            return vb_fail(err, VB_ERR_IO, "%s: cannot write a temporary file for OpenMesh's OFF reader (%s): %s",
                           name, path_.c_str(), strerror(errno));
        return VB_OK;
    }
    const std::string &path() const { return path_; }

private:
    std::string path_;
};

vb_result read_openmesh(const char *path, const char *file, vb_mesh_format format, const uint8_t *bytes,
                        size_t size, vb_mesh_raw *out, vb_error *err)
{
    expectation ex;
    vb_result r = VB_OK;
    switch (format) {
    case VB_MESH_OBJ: r = scan_obj(path, bytes, size, &ex, err); break;
    case VB_MESH_PLY: r = scan_ply(path, bytes, size, &ex, err); break;
    case VB_MESH_OFF: r = scan_off(path, bytes, size, &ex, err); break;
    case VB_MESH_STL: r = scan_stl(path, bytes, size, &ex, err); break;
    default: return vb_fail(err, VB_ERR_ARGUMENT, "%s: unknown mesh format", path);
    }
    if (r != VB_OK)
        return r;

    temp_off_file off_copy;
    if (format == VB_MESH_OFF && !file) {
        r = off_copy.create(path, bytes, size, err);
        if (r != VB_OK)
            return r;
        file = off_copy.path().c_str();
    }

    collector col;
    col.per_corner = format == VB_MESH_OBJ;
    bool ok = false;
    std::string said;
    {
        openmesh_session session;
        OpenMesh::IO::Options opt = OpenMesh::IO::Options::VertexNormal;
        OpenMesh::IO::_IOManager_ &io = OpenMesh::IO::IOManager();
        if (format == VB_MESH_OFF) {
            ok = io.read(std::string(file), col, opt);
        } else {
            std::string text;
            if (format == VB_MESH_PLY) {
                text = ex.ply_header;
                text.append((const char *)bytes + ex.ply_body, size - ex.ply_body);
            } else {
                text.assign((const char *)bytes, size);
            }
            for (size_t at : ex.comment_out)
                text[at] = '#';
            std::istringstream in(std::move(text), std::ios::in | std::ios::binary);
            const char *ext = format == VB_MESH_OBJ ? "obj" : format == VB_MESH_PLY ? "ply" : "stl";
            if (format == VB_MESH_STL && ex.stl_binary)
                opt += OpenMesh::IO::Options::Binary;
            ok = io.read(in, std::string(ext), col, opt);
        }
        said = session.first_line();
    }
    if (!ok)
        return vb_fail(err, VB_ERR_FORMAT, "%s: OpenMesh could not read the file%s%s", path,
                       said.empty() ? "" : ": ", said.c_str());

    uint64_t nv = col.positions.size() / 3;
    if ((ex.vertices_known && nv != ex.vertices) || col.polygons != ex.faces ||
        col.indices.size() / 3 != ex.triangles || col.short_faces != 0)
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: OpenMesh read %llu vertices, %llu faces, %llu triangles, but the file has "
                       "%llu, %llu, %llu; refusing a partial mesh%s%s",
                       path, (unsigned long long)nv, (unsigned long long)col.polygons,
                       (unsigned long long)(col.indices.size() / 3),
                       (unsigned long long)ex.vertices, (unsigned long long)ex.faces,
                       (unsigned long long)ex.triangles, said.empty() ? "" : " (OpenMesh: ",
                       said.empty() ? "" : (said + ")").c_str());
    if (nv > max_count)
        return vb_fail(err, VB_ERR_FORMAT, "%s: too many vertices", path);
    if (!col.corner_normals.empty() && col.corner_normals.size() != 9 * (col.indices.size() / 3))
        return vb_fail(err, VB_ERR_FORMAT, "%s: internal error: %zu corner normals for %zu triangles", path,
                       col.corner_normals.size() / 3, col.indices.size() / 3);

    /* Hand over malloc'ed arrays (mesh.c frees them with free()). */
    vb_mesh_raw raw;
    memset(&raw, 0, sizeof raw);
    try {
        raw.vertex_count = (uint32_t)nv;
        raw.triangle_count = (uint32_t)(col.indices.size() / 3);
        raw.positions = malloc_copy(col.positions);
        raw.indices = malloc_copy(col.indices);
        raw.faces = malloc_copy(col.tri_face);
        if (!col.has_normal.empty()) {
            col.normal_sums.resize(3 * nv, 0.0f);
            col.has_normal.resize(nv, 0);
            for (size_t i = 0; i < nv; i++)
                collector::unit(&col.normal_sums[3 * i]);
            for (uint8_t &h : col.has_normal)
                h = h != 0;
            raw.normals = malloc_copy(col.normal_sums);
            raw.has_normal = malloc_copy(col.has_normal);
        }
        if (!col.corner_normals.empty()) {
            raw.corner_normals = malloc_copy(col.corner_normals);
            raw.corner_given = malloc_copy(col.corner_given);
        }
        raw.dropped_triangles = (uint32_t)std::min<uint64_t>(ex.dropped, UINT32_MAX);
    } catch (...) {
        vb_mesh_raw_free(&raw);
        throw;
    }
    *out = raw;
    return VB_OK;
}

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

/* uint64 key -> uint32 value, open addressing: std::unordered_map's node
 * per entry cost more than the whole refinement on large meshes. */
class pair_table {
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
    static constexpr uint64_t empty = ~(uint64_t)0;   /* min < max: never a key */
    std::vector<uint64_t> keys_;
    std::vector<uint32_t> vals_;
    size_t mask_ = 0;
};

void normalize3(float *n)
{
    double len = std::sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
    for (int k = 0; k < 3; k++)
        n[k] = len > 0.0 && std::isfinite(len) ? (float)(n[k] / len) : 0.0f;
}

vb_result refine(const vb_mesh *in, float max_edge, vb_mesh *out, vb_error *err)
{
    const uint32_t n = in->vertex_count;
    const double limit2 = (double)max_edge * (double)max_edge;

    /* Input checks: the mesh may come from anywhere, not only a loader. */
    if (n > refine_max_vertices)
        return vb_fail(err, VB_ERR_ARGUMENT, "refine: the mesh has %u vertices; refinement handles at most %llu", n,
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
                return vb_fail(err, VB_ERR_INVALID, "refine: triangle %llu: index %u out of range (%u vertices)",
                               (unsigned long long)t, tri[k], n);
        const float *a = in->positions + 3 * (size_t)tri[0];
        const float *b = in->positions + 3 * (size_t)tri[1];
        const float *c = in->positions + 3 * (size_t)tri[2];
        double u[3], v[3];
        for (int k = 0; k < 3; k++) {
            u[k] = (double)b[k] - a[k];
            v[k] = (double)c[k] - a[k];
        }
        double cx = u[1] * v[2] - u[2] * v[1], cy = u[2] * v[0] - u[0] * v[2], cz = u[0] * v[1] - u[1] * v[0];
        area += 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
    }
    /* No triangle with all edges <= max_edge is larger than the equilateral
     * one: a lower bound on the faces needed, checked before any work. */
    double min_faces = area / (std::sqrt(3.0) / 4.0 * limit2);
    if (min_faces > 2.0 * (double)refine_max_vertices)
        return vb_fail(err, VB_ERR_ARGUMENT,
                       "refine: max_edge %g is too small for this mesh (surface area %g needs over %.3g triangles; "
                       "the limit is %llu vertices)",
                       (double)max_edge, area, min_faces, (unsigned long long)refine_max_vertices);

    om_mesh m;
    /* Longest-edge bisection ends with about 1.3 - 2.3 vertices per
     * max_edge^2 of area: reserve for the upper end. */
    size_t est_v = (size_t)std::min<double>((double)n + 2.5 * area / limit2, (double)refine_max_vertices);
    m.reserve(est_v, est_v * 3, est_v * 2);

    /* Build. A triangle the half-edge structure refuses gets private copies
     * of its vertices (as OpenMesh's ImporterT); `copy_of` maps them back. */
    for (uint32_t i = 0; i < n; i++) {
        const float *p = in->positions + 3 * (size_t)i;
        m.add_vertex(om_mesh::Point(p[0], p[1], p[2]));
    }
    std::vector<uint32_t> copy_of;
    uint64_t kept = 0;
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
                return vb_fail(err, VB_ERR_INVALID, "refine: OpenMesh refused triangle %llu even with its own vertices",
                               (unsigned long long)t);
        }
        kept++;
    }
    const uint64_t first_new = (uint64_t)n + copy_of.size();

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
    std::vector<uint32_t> parents;   /* two per new vertex: the split edge's ends */
    uint64_t faces_added = 0;
    while (!queue.empty()) {
        edge_entry top = queue.top();
        queue.pop();
        om_mesh::EdgeHandle e(top.edge);
        double l2 = edge_len2(m, e);
        if (l2 != top.len2 || l2 <= limit2)
            continue;
        if (m.n_vertices() - copy_of.size() >= refine_max_vertices)
            return vb_fail(err, VB_ERR_ARGUMENT, "refine: max_edge %g would need more than %llu vertices",
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
        for (om_mesh::EdgeHandle ve : m.ve_range(vm)) {
            double nl2 = edge_len2(m, ve);
            if (nl2 > limit2)
                queue.push(edge_entry{nl2, ve.idx()});
        }
    }
    if (m.n_faces() != kept + faces_added)
        return vb_fail(err, VB_ERR_INVALID, "refine: internal error: %zu faces, expected %llu",
                       (size_t)m.n_faces(), (unsigned long long)(kept + faces_added));

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
        normalize3(nn);
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

extern "C" vb_result vb_mesh_read_openmesh(const char *path, const char *file, vb_mesh_format format,
                                           const uint8_t *bytes, size_t size,
                                           vb_mesh_raw *out, vb_error *err)
{
    if (!path || !bytes || !out)
        return vb_fail(err, VB_ERR_ARGUMENT, "vb_mesh_read_openmesh: NULL argument");
    try {
        return read_openmesh(path, file, format, bytes, size, out, err);
    } catch (const std::bad_alloc &) {
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "%s: out of memory while reading", path);
    } catch (const std::exception &e) {
        return vb_fail(err, VB_ERR_FORMAT, "%s: OpenMesh failed: %s", path, e.what());
    } catch (...) {
        return vb_fail(err, VB_ERR_FORMAT, "%s: OpenMesh failed with an unknown exception", path);
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

extern "C" vb_result vb_mesh_refine(const vb_mesh *in, float max_edge, vb_mesh *out,
                                    vb_error *err)
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
