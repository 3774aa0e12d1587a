/*
 * mesh_stl.cpp - the strict STL reader (mesh_parse.h, mesh_read.h), with
 * OpenMesh 9's reading rules where they decide the result: binary when the
 * file is exactly 84 + 50 x (count at byte 80) bytes long, else ascii
 * (every line containing "outer" starts a facet whose next three lines are
 * "<word> x y z"); vertices with equal positions are merged (OpenMesh's
 * comparison: components within FLT_MIN, through the same std::map, so the
 * numbering is its numbering) and a triangle whose corners then repeat is
 * dropped.
 */
#include "mesh_read.h"

#include <array>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>

#include <strings.h>

namespace vb_read
{

namespace
{

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

/* Tiny coordinates (within FLT_MIN of each other but not equal) can
 * make the merging disagree with the count of triangles whose corners
 * differ: refused. */
vb_result merged_as_counted(const char *path, const builder &out, const expectation *ex,
                            vb_error *err)
{
    if (out.polygons != ex->faces)
        return vb_fail(
            err, VB_ERR_FORMAT,
            "%s: coordinates that differ by less than FLT_MIN (%g) make it ambiguous which corners "
            "are the same vertex (%llu or %llu triangles)",
            path, (double)FLT_MIN, (unsigned long long)out.polygons, (unsigned long long)ex->faces);
    return VB_OK;
}

} // namespace

/* Binary when the file is exactly 84 + 50 * (count at byte 80) bytes
 * long. Ascii: every line that contains "outer" starts a facet whose next
 * three lines are read as "<word> x y z" (so a solid named "outer..." is
 * refused here). Stricter than a lenient reader: an ascii file must have
 * an "endsolid" line after its last facet, or it may have been cut between
 * two facets. */
vb_result read_stl(const char *path, const uint8_t *bytes, size_t size, builder &out,
                   expectation *ex, vb_error *err)
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
                                   "%s: triangle %llu: vertex %d has a non-finite coordinate", path,
                                   (unsigned long long)t, i / 3);
            }
            if (!stl_same(v, v + 3) && !stl_same(v, v + 6) && !stl_same(v + 3, v + 6)) {
                ex->faces++;
                ex->triangles++;
            }
            merge.facet(v, out);
        }
        return merged_as_counted(path, out, ex, err);
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
        bool name_line =
            strncasecmp(word, "solid", 5) == 0 || strncasecmp(word, "endsolid", 8) == 0;
        if (line.find("outer") == std::string::npos && line.find("OUTER") == std::string::npos) {
            if (strncasecmp(word, "endsolid", 8) == 0)
                ended = true;
            continue;
        }
        if (name_line)
            return vb_fail(
                err, VB_ERR_FORMAT,
                "%s: line %lu: the solid's name contains 'outer', which STL readers take for the "
                "start of a facet (rename the solid)",
                path, line_no);
        ended = false;
        float v[9];
        for (int i = 0; i < 3; i++) {
            if (c.at_end())
                return vb_fail(err, VB_ERR_FORMAT,
                               "%s: line %lu: file ends inside a facet (truncated?)", path,
                               line_no);
            token t;
            if (!c.next_on_line(&t))
                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: expected 'vertex x y z'", path,
                               c.line);
            for (int k = 0; k < 3; k++) {
                if (!c.next_on_line(&t))
                    return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: expected 'vertex x y z'",
                                   path, c.line);
                num_status s = parse_float(t, &v[3 * i + k]);
                if (s != NUM_OK)
                    return vb_fail(err, num_error(s), "%s: line %lu: vertex coordinate '%.*s' %s",
                                   path, c.line, t.show_len(), t.b, num_problem(s));
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
            return vb_fail(
                err, VB_ERR_FORMAT,
                "%s: neither ascii STL (no facets and no 'endsolid': truncated?) nor binary STL "
                "(%zu bytes, but 84 + 50 x %llu triangles = %llu)",
                path, size, (unsigned long long)declared, (unsigned long long)(84 + 50 * declared));
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: ascii STL ends without 'endsolid' after its last facet (truncated?)",
                       path);
    }
    return merged_as_counted(path, out, ex, err);
}

} // namespace vb_read
