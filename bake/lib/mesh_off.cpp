/*
 * mesh_off.cpp - the strict OFF reader (mesh_parse.h, mesh_read.h), with
 * OpenMesh 9's reading rules where they decide the result: [ST][C][N]OFF
 * [BINARY] headers (BINARY exactly one character after OFF), coordinates
 * and normals, then faces.
 */
#include "mesh_read.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace vb_read
{

/* Header line [ST][C][N]OFF [BINARY] ("4OFF"/"nOFF" unsupported; BINARY
 * exactly one character after OFF, as OpenMesh's reader decided); counts
 * nV nF nE as tokens (on the OFF line itself when it holds just them); each vertex is 3 numbers (+3 for a normal with N),
 * then the rest of its line (colours, texture coordinates: not used); each
 * face is a count and that many indices as tokens, then (only with C) the
 * rest of its line. Binary: little-endian uint32 counts, float32
 * coordinates, uint32 face sizes and indices, no colours. */
vb_result read_off(const char *path, const uint8_t *bytes, size_t size, builder &out,
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
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: 4OFF/nOFF (vertex dimension other than 3) is not supported", path);
    if (utf8_bom(bytes, size))
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: starts with a UTF-8 byte order mark: save it without one (the "
                       "first line must be [ST][C][N]OFF)",
                       path);
    if (le - p < 3 || memcmp(p, "OFF", 3) != 0)
        return vb_fail(err, VB_ERR_FORMAT, "%s: not an OFF file (first line must be [ST][C][N]OFF)",
                       path);
    /* Exactly one character after "OFF", whatever it is, then BINARY:
     * "OFFxBINARY" is binary and "OFF  BINARY" is not (OpenMesh's rule,
     * kept: files were baked by it). */
    p += 3;
    const char *after_off = p; /* the counts, when the OFF line has them */
    if (p < le)
        p++;
    if (le - p >= 6 && memcmp(p, "BINARY", 6) == 0)
        binary = true;
    c.skip_line();

    std::vector<int64_t> polygon;
    if (binary) {
        if (tex || color)
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: binary OFF with colours or texture coordinates is not supported",
                           path);
        const uint8_t *b = (const uint8_t *)c.p;
        size_t left = (size_t)(c.end - c.p);
        if (left < 12)
            return vb_fail(err, VB_ERR_FORMAT, "%s: truncated binary OFF header", path);
        uint64_t nv = load_u32(b, false), nf = load_u32(b + 4, false);
        b += 12;
        left -= 12;
        size_t vsize = normal ? 24 : 12;
        if (nv > max_count || nf > max_count || nv > left / vsize)
            return vb_fail(
                err, VB_ERR_FORMAT,
                "%s: header declares %llu vertices, more than the file's %zu bytes can hold", path,
                (unsigned long long)nv, size);
        out.positions.reserve(3 * (size_t)nv);
        for (uint64_t i = 0; i < nv; i++) {
            float v[3];
            for (int k = 0; k < 3; k++) {
                v[k] = load_f32(b + 4 * k, false);
                if (!std::isfinite(v[k]))
                    return vb_fail(err, VB_ERR_INVALID,
                                   "%s: vertex %llu has a non-finite coordinate", path,
                                   (unsigned long long)i);
            }
            out.add_vertex(v[0], v[1], v[2]);
            if (normal) {
                const float n[3] = {load_f32(b + 12, false), load_f32(b + 16, false),
                                    load_f32(b + 20, false)};
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
                return vb_fail(
                    err, VB_ERR_FORMAT,
                    "%s: truncated: face %llu has %llu vertices past the end of the file", path,
                    (unsigned long long)f, (unsigned long long)n);
            if (n < 3)
                return vb_fail(err, VB_ERR_FORMAT,
                               "%s: face %llu has %llu vertices (needs at least 3)", path,
                               (unsigned long long)f, (unsigned long long)n);
            polygon.clear();
            for (uint64_t k = 0; k < n; k++) {
                uint64_t idx = load_u32(b + 4 * k, false);
                if (idx >= nv)
                    return vb_fail(err, VB_ERR_INVALID,
                                   "%s: face %llu: vertex index %llu out of range (%llu %s)", path,
                                   (unsigned long long)f, (unsigned long long)idx,
                                   (unsigned long long)nv, vdsh_plural(nv, "vertex", "vertices"));
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

    /* ascii. The counts on the OFF line itself when it holds exactly three
     * ("OFF 8 6 0", ModelNet40's "OFF8 6 0"; OpenMesh took the first
     * vertex for them), else on the lines after it. */
    long long counts[3];
    int on_line = 0;
    for (const char *q = after_off; on_line >= 0;) {
        while (q < le && (*q == ' ' || *q == '\t' || *q == '\r'))
            q++;
        if (q == le)
            break;
        token t{q, q};
        while (q < le && *q != ' ' && *q != '\t' && *q != '\r')
            q++;
        t.e = q;
        if (on_line == 3 || !parse_int(t, &counts[on_line]) || counts[on_line] < 0)
            on_line = -1;
        else
            on_line++;
    }
    for (int i = on_line == 3 ? 3 : 0; i < 3; i++) {
        token t;
        bool got = c.next(&t);
        if (got && has_nul(t))
            return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: count '%.*s' %s", path, c.line,
                           t.show_len(), t.b, num_problem(NUM_NUL));
        if (!got || !parse_int(t, &counts[i]) || counts[i] < 0)
            return vb_fail(
                err, VB_ERR_FORMAT,
                "%s: line %lu: expected three counts (vertices faces edges) after the OFF line",
                path, c.line);
    }
    /* The edge count is not used, but OpenMesh read it as an unsigned
     * int: a larger one failed its stream and every later number read as
     * garbage. */
    if (counts[2] > (long long)UINT32_MAX)
        return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: edge count %lld is too large", path,
                       c.line, counts[2]);
    uint64_t nv = (uint64_t)counts[0], nf = (uint64_t)counts[1];
    /* Every vertex needs at least "0 0 0\n" and every face "3 0 0 0\n": a
     * header promising more than the file holds is rejected before any
     * loop runs over its counts. */
    if (nv > max_count || nf > max_count || nv > size / 6 || nf > size / 8)
        return vb_fail(
            err, VB_ERR_FORMAT,
            "%s: header declares %llu vertices and %llu faces, more than the file's %zu bytes can hold",
            path, (unsigned long long)nv, (unsigned long long)nf, size);
    int per_vertex = normal ? 6 : 3;
    out.positions.reserve(3 * (size_t)nv);
    for (uint64_t i = 0; i < nv; i++) {
        float v[6];
        for (int k = 0; k < per_vertex; k++) {
            token t;
            if (!c.next(&t))
                return vb_fail(err, VB_ERR_FORMAT,
                               "%s: truncated: file ends in vertex %llu of %llu", path,
                               (unsigned long long)i, (unsigned long long)nv);
            num_status s = parse_float(t, &v[k]);
            if (s != NUM_OK)
                return vb_fail(err, num_error(s), "%s: line %lu: vertex %llu: %s '%.*s' %s", path,
                               c.line, (unsigned long long)i,
                               k < 3 ? "coordinate" : "normal component", t.show_len(), t.b,
                               num_problem(s));
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
            return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: face %llu: vertex count '%.*s' %s",
                           path, c.line, (unsigned long long)f, t.show_len(), t.b,
                           int_problem(t, "is not a number"));
        if (n < 3)
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: line %lu: face %llu has %lld vertices (needs at least 3)", path,
                           c.line, (unsigned long long)f, n);
        if ((uint64_t)n > size || (uint64_t)n > max_count)
            return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: face %llu claims %lld vertices", path,
                           c.line, (unsigned long long)f, n);
        polygon.clear();
        for (long long k = 0; k < n; k++) {
            long long idx = 0;
            if (!c.next(&t))
                return vb_fail(err, VB_ERR_FORMAT, "%s: truncated: file ends in face %llu", path,
                               (unsigned long long)f);
            if (!parse_int(t, &idx))
                return vb_fail(err, VB_ERR_FORMAT,
                               "%s: line %lu: face %llu: vertex index '%.*s' %s", path, c.line,
                               (unsigned long long)f, t.show_len(), t.b,
                               int_problem(t, "is not a number"));
            if (idx < 0 || (uint64_t)idx >= nv)
                return vb_fail(err, VB_ERR_INVALID,
                               "%s: line %lu: face %llu: vertex index %lld out of range (%llu %s)",
                               path, c.line, (unsigned long long)f, idx, (unsigned long long)nv,
                               vdsh_plural(nv, "vertex", "vertices"));
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

} // namespace vb_read
