/*
 * mesh_obj.cpp - the strict OBJ reader (mesh_parse.h, mesh_read.h), with
 * OpenMesh 9's reading rules where they decide the result: lines split at
 * '\n' only, the first token is the keyword, a line whose first character
 * after blanks is '#' is a comment; faces take each corner's index before
 * the first '/', resolve negative indices against the "v" lines so far,
 * give the corner's vertex the normal the corner names, drop repeated
 * vertices (first occurrence kept) and triangulate what is left (fewer
 * than three: no face). Each corner keeps the last normal its line gave
 * its vertex.
 */
#include "mesh_read.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace vb_read
{

namespace
{

/* One face line's corners as OpenMesh's OBJ reader reads them; appended
 * to `verts` (0-based vertex handles, possibly out of range) and `nsets`
 * (vertex, 1-based normal number: "give this vertex that normal"). Each
 * corner is split at '/' into components (vertex/texture/normal); an empty
 * component is skipped, a non-empty one is read with stream_int (a failed
 * read gives 0, except for the last component, which is then skipped). A
 * normal goes to the vertex read last on the line. Negative numbers count
 * back from the "v" (or "vn") lines so far. False if a normal comes before
 * any vertex (OpenMesh's behaviour is undefined there). */
bool obj_corner(const char *b, const char *e, int64_t lines_v, int64_t lines_vn,
                std::vector<int64_t> &verts, size_t face_first,
                std::vector<std::pair<int64_t, int64_t>> &nsets)
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

} // namespace

/* Lines split at '\n' only; the first token is the keyword; '#' starts a
 * comment ("#" as the keyword, or any token of a face line from there on
 * for the checks below). "v" and "vn" need three whole numbers (finite,
 * in float range) before anything else; a face needs at least three
 * corners whose index (before the first '/') is a whole non-zero integer
 * in range; positive indices may point forward. Faces with fewer than
 * three distinct vertices add nothing (their triangles are counted as
 * dropped). A corner's texture coordinate and normal indices, when
 * given, must be whole numbers naming a "vt" and a "vn" line (the same
 * rules); a corner has at most three '/' fields (v/vt/vn). The texture
 * coordinates themselves, materials and every other keyword are ignored.
 * A NUL byte in a number
 * or corner is refused as such.
 *
 * Where OpenMesh's reader read a line otherwise than these checks, the
 * reading follows OpenMesh, and the file is refused when the counts then
 * differ (as the baker refused it before): a line whose first character
 * after spaces, TABs and CRs is a vertical tab or form feed is skipped (a
 * "v" line skipped that way always makes them differ), and the text after
 * '#' on a face line is read on as corners (a new vertex there makes them
 * differ; a repeated one may give its vertex a normal). */
vb_result read_obj(const char *path, const uint8_t *bytes, size_t size, builder &out,
                   expectation *ex, vb_error *err)
{
    if (size >= 2 &&
        ((bytes[0] == 0xfe && bytes[1] == 0xff) || (bytes[0] == 0xff && bytes[1] == 0xfe)))
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: UTF-16 text is not supported (save as UTF-8 or ASCII)", path);
    /* A UTF-8 byte order mark is not part of the first line: read as its
     * keyword, it hid a first "v" line and shifted every index after it. */
    if (utf8_bom(bytes, size))
        bytes += 3, size -= 3;

    /* Positive indices may point forward, so count the "v" lines before
     * checking faces. */
    uint64_t total = 0, total_vt = 0, total_vn = 0;
    for (cursor c(bytes, size); !c.at_end(); c.skip_line()) {
        token kw;
        if (c.next_on_line(&kw) && kw.is("v"))
            total++;
        else if (kw.is("vt"))
            total_vt++;
        else if (kw.is("vn"))
            total_vn++;
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
    uint64_t nv = 0, nn = 0, nvt = 0; /* "v", "vn", "vt" lines so far */
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
                    return vb_fail(err, VB_ERR_FORMAT,
                                   "%s: line %lu: %s %llu has fewer than 3 numbers", path, c.line,
                                   what, (unsigned long long)number);
                num_status s = parse_float(t, &xyz[i]);
                if (s != NUM_OK)
                    return vb_fail(err, num_error(s), "%s: line %lu: %s %llu: coordinate '%.*s' %s",
                                   path, c.line, what, (unsigned long long)number, t.show_len(),
                                   t.b, num_problem(s));
            }
            if (is_v) {
                nv++;
                if (!skipped) {
                    out.add_vertex(xyz[0], xyz[1], xyz[2]);
                    read_v++;
                } else if (hint.empty()) {
                    hint = "line " + std::to_string(line_no) +
                           ": a vertex line starting with a vertical tab or "
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
                if (has_nul(t))
                    return vb_fail(err, VB_ERR_FORMAT,
                                   "%s: line %lu: face corner '%.*s' contains a NUL byte "
                                   "(binary data in a text file?)",
                                   path, c.line, t.show_len(), t.b);
                /* v, v/vt, v//vn or v/vt/vn: a fourth field would be
                 * read into the normal index ("'1/1' is not a number") */
                size_t fields = 1;
                for (const char *q = t.b; q < t.e; q++)
                    fields += *q == '/';
                if (fields > 3)
                    return vb_fail(err, VB_ERR_FORMAT,
                                   "%s: line %lu: face corner '%.*s' has too many '/' fields "
                                   "(%zu; at most 3: v/vt/vn)",
                                   path, c.line, t.show_len(), t.b, fields);
                const char *slash = (const char *)memchr(t.b, '/', t.size());
                token idx{t.b, slash ? slash : t.e};
                long long v = 0;
                if (!parse_int(idx, &v) || v == 0)
                    return vb_fail(err, VB_ERR_FORMAT,
                                   "%s: line %lu: face corner '%.*s' has no valid vertex index",
                                   path, c.line, t.show_len(), t.b);
                if (v < 0) {
                    if (v < -(long long)nv)
                        return vb_fail(
                            err, VB_ERR_INVALID,
                            "%s: line %lu: face index %lld out of range (%llu %s so far)", path,
                            c.line, v, (unsigned long long)nv,
                            vdsh_plural(nv, "vertex", "vertices"));
                    v = (long long)nv + v + 1;
                } else if ((unsigned long long)v > total) {
                    return vb_fail(err, VB_ERR_INVALID,
                                   "%s: line %lu: face index %lld out of range (%llu %s)", path,
                                   c.line, v, (unsigned long long)total,
                                   vdsh_plural(total, "vertex", "vertices"));
                }
                corners.push_back(v);
                /* The texture coordinate and the normal (v/VT/VN), when
                 * given: a whole number naming a "vt" (a "vn") line, as the
                 * vertex a "v"; positive ones may point forward. */
                const char *vt_end =
                    slash ? (const char *)memchr(slash + 1, '/', (size_t)(t.e - slash - 1))
                          : nullptr;
                const token sub[2] = {{slash ? slash + 1 : t.e, vt_end ? vt_end : t.e},
                                      {vt_end ? vt_end + 1 : t.e, t.e}};
                static const char *const sub_what[2] = {"texture coordinate", "normal"};
                static const char *const sub_kw[2] = {"vt", "vn"};
                const uint64_t so_far[2] = {nvt, nn}, all[2] = {total_vt, total_vn};
                for (int k = 0; k < 2; k++) {
                    long long i = 0;
                    if (!sub[k].size())
                        continue;
                    if (!parse_int(sub[k], &i))
                        return vb_fail(err, VB_ERR_FORMAT,
                                       "%s: line %lu: face corner '%.*s': %s index '%.*s' is not "
                                       "a number",
                                       path, c.line, t.show_len(), t.b, sub_what[k],
                                       sub[k].show_len(), sub[k].b);
                    if (i == 0 || (i < 0 && i < -(long long)so_far[k]) ||
                        (i > 0 && (unsigned long long)i > all[k]))
                        return vb_fail(err, VB_ERR_INVALID,
                                       "%s: line %lu: face corner '%.*s': %s index %lld out of "
                                       "range (\"%s\" lines%s: %llu)",
                                       path, c.line, t.show_len(), t.b, sub_what[k], i, sub_kw[k],
                                       i < 0 ? " so far" : "",
                                       (unsigned long long)(i < 0 ? so_far[k] : all[k]));
                }
            }
            if (corners.size() < 3)
                return vb_fail(err, VB_ERR_FORMAT,
                               "%s: line %lu: face has %zu %s (needs at least 3)", path, c.line,
                               corners.size(), vdsh_plural(corners.size(), "vertex", "vertices"));
            std::sort(corners.begin(), corners.end());
            size_t distinct =
                (size_t)(std::unique(corners.begin(), corners.end()) - corners.begin());
            if (distinct >= 3) {
                ex->faces++;
                ex->triangles += distinct - 2;
            } else {
                ex->dropped += corners.size() - 2;
            }

            /* The reading: every token of the line, '#' or not. */
            if (skipped) {
                if (distinct >= 3 && hint.empty())
                    hint = "line " + std::to_string(line_no) +
                           ": a face line starting with a vertical tab or "
                           "form feed is skipped";
            } else {
                size_t face_first = verts.size();
                cursor line_c = c;
                line_c.p = rest;
                while (line_c.next_on_line(&t))
                    if (!obj_corner(t.b, t.e, read_v, read_vn, verts, face_first, nsets))
                        return vb_fail(err, VB_ERR_FORMAT,
                                       "%s: line %lu: face corner '%.*s' gives a normal "
                                       "before any vertex",
                                       path, line_no, t.show_len(), t.b);
                faces.push_back(face_rec{verts.size(), nsets.size()});
                std::vector<int64_t> mine(verts.begin() + (ptrdiff_t)face_first, verts.end());
                remove_repeated(mine);
                if (((mine.size() >= 3) != (distinct >= 3) ||
                     (distinct >= 3 && mine.size() != distinct)) &&
                    hint.empty())
                    hint = "line " + std::to_string(line_no) +
                           ": the text after '#' reads as further face corners";
            }
        } else if (kw.is("vt"))
            nvt++; /* counted for the faces' checks; not used */
        /* "mtllib", "usemtl", groups, ...: not used */
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
            uint32_t k = (uint32_t)(nsets[i].second - 1); /* as OpenMesh: unsigned compare */
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

} // namespace vb_read
