/*
 * mesh_ply.cpp - the strict PLY reader (mesh_parse.h, mesh_read.h), with
 * OpenMesh 9's reading rules where they decide the result: elements are
 * read in order up to and including "face"; x, y, z, nx, ny, nz as floats;
 * the face's vertex_indices list; binary data as OpenMesh's reader
 * consumed it. The elements after "face" are not used but walked, to find
 * a truncated file or trailing data.
 */
#include "mesh_read.h"

#include <algorithm>
#include <cfloat>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace vb_read
{

namespace
{

struct ply_type {
    const char *name;
    int size;
    bool is_float;
    bool is_signed;
};

/* In OpenMesh's order of preference (see ply_role). */
const ply_type ply_types[] = {
    {"float32", 4, true, true},  {"float64", 8, true, true},  {"float", 4, true, true},
    {"double", 8, true, true},   {"int8", 1, false, true},    {"uint8", 1, false, false},
    {"char", 1, false, true},    {"uchar", 1, false, false},  {"int32", 4, false, true},
    {"uint32", 4, false, false}, {"int", 4, false, true},     {"uint", 4, false, false},
    {"int16", 2, false, true},   {"uint16", 2, false, false}, {"short", 2, false, true},
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
enum ply_role {
    PLY_OTHER,
    PLY_X,
    PLY_Y,
    PLY_Z,
    PLY_NX,
    PLY_NY,
    PLY_NZ,
    PLY_TEX,
    PLY_COLOR,
    PLY_INDICES
};

struct ply_property {
    std::string name;
    const ply_type *type = nullptr;
    const ply_type *count_type = nullptr; /* lists only */
    const ply_type *read_type = nullptr;  /* OpenMesh's reading of "property TYPE NAME" */
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
    static const char *const colours[] = {"red",           "green",        "blue", "diffuse_red",
                                          "diffuse_green", "diffuse_blue", "alpha"};
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
vb_result ply_binary_read(const char *path, const std::vector<ply_element> &elems, size_t last,
                          int vertex_elem, int face_elem, bool has_normals, bool big,
                          const uint8_t *b, size_t left, builder &out, vb_error *err)
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
                        return vb_fail(err, VB_ERR_FORMAT,
                                       "%s: face %llu has %zu vertices as the binary data is "
                                       "read",
                                       path, (unsigned long long)n, polygon.size());
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
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: the binary data ends early as its properties' types are read "
                       "(x, y, z and normals of an integer type, colours of type double and "
                       "properties named after a type are read otherwise than declared)",
                       path);
    return VB_OK;
}

/* A binary integer of type t (1, 2 or 4 bytes) at q, with its sign. */
static long long binary_integer(const ply_type *t, const uint8_t *q, bool big)
{
    if (t->size == 1)
        return t->is_signed ? (long long)(int8_t)q[0] : (long long)q[0];
    if (t->size == 2) {
        uint16_t u = big ? (uint16_t)(q[0] << 8 | q[1]) : (uint16_t)(q[1] << 8 | q[0]);
        return t->is_signed ? (long long)(int16_t)u : (long long)u;
    }
    uint32_t u = load_u32(q, big);
    return t->is_signed ? (long long)(int32_t)u : (long long)u;
}

/* A binary list's size (p.count_type at b, moved past): the element's
 * n-th item, for messages; a truncated file or a negative size refused. */
static vb_result binary_list_size(const char *path, const ply_element &e, uint64_t n,
                                  const ply_property &p, bool big, const uint8_t *&b, size_t &left,
                                  uint64_t &items, vb_error *err)
{
    const size_t cs = (size_t)p.count_type->size;
    if (left < cs)
        return vb_fail(err, VB_ERR_FORMAT, "%s: truncated in %s %llu of %llu", path, e.name.c_str(),
                       (unsigned long long)n, (unsigned long long)e.count);
    if (cs == 1)
        items = b[0];
    else if (cs == 2)
        items = big ? (uint64_t)(b[0] << 8 | b[1]) : (uint64_t)(b[1] << 8 | b[0]);
    else {
        uint32_t u = load_u32(b, big);
        if (p.count_type->is_signed && (int32_t)u < 0)
            return vb_fail(err, VB_ERR_FORMAT, "%s: %s %llu: negative list size", path,
                           e.name.c_str(), (unsigned long long)n);
        items = u;
    }
    b += cs;
    left -= cs;
    return VB_OK;
}

/* The elements after "face", never used: walked by the layout the header
 * declares, since PLY's data holds every element declared, in order, and
 * only then is a truncated file or trailing data found. Ascii values must
 * be numbers of their property's kind (a whole number for an integer
 * type; the value itself is not used, so nan or 1e99 in a float property
 * pass) and list sizes whole numbers >= 0; binary values are not looked
 * at. The cursor (ascii) or b and left (binary) move past them. */
vb_result ply_walk_unused(const char *path, const std::vector<ply_element> &elems, size_t first,
                          int format, size_t size, cursor &c, const uint8_t *&b, size_t &left,
                          vb_error *err)
{
    const bool big = format == 2;
    token t;
    for (size_t i = first; i < elems.size(); i++) {
        const ply_element &e = elems[i];
        if (e.props.empty()) /* no data: nothing to walk, however many */
            continue;
        for (uint64_t n = 0; n < e.count; n++)
            for (const ply_property &p : e.props) {
                uint64_t items = 1;
                if (format != 0) {
                    if (p.count_type) {
                        vb_result r = binary_list_size(path, e, n, p, big, b, left, items, err);
                        if (r != VB_OK)
                            return r;
                    }
                    const size_t ts = (size_t)p.type->size;
                    if (items > left / ts)
                        return vb_fail(err, VB_ERR_FORMAT, "%s: truncated in %s %llu of %llu", path,
                                       e.name.c_str(), (unsigned long long)n,
                                       (unsigned long long)e.count);
                    b += items * ts;
                    left -= items * ts;
                    continue;
                }
                if (p.count_type) {
                    long long cnt = 0;
                    if (!c.next(&t))
                        return vb_fail(
                            err, VB_ERR_FORMAT, "%s: truncated: file ends in %s %llu of %llu", path,
                            e.name.c_str(), (unsigned long long)n, (unsigned long long)e.count);
                    if (has_nul(t))
                        return vb_fail(err, VB_ERR_FORMAT,
                                       "%s: line %lu: %s %llu: list size '%.*s' %s", path, c.line,
                                       e.name.c_str(), (unsigned long long)n, t.show_len(), t.b,
                                       num_problem(NUM_NUL));
                    if (!parse_int(t, &cnt) || cnt < 0 || (uint64_t)cnt > size)
                        return vb_fail(err, VB_ERR_FORMAT,
                                       "%s: line %lu: %s %llu: bad list size '%.*s'", path, c.line,
                                       e.name.c_str(), (unsigned long long)n, t.show_len(), t.b);
                    items = (uint64_t)cnt;
                }
                for (uint64_t q = 0; q < items; q++) {
                    if (!c.next(&t))
                        return vb_fail(
                            err, VB_ERR_FORMAT, "%s: truncated: file ends in %s %llu of %llu", path,
                            e.name.c_str(), (unsigned long long)n, (unsigned long long)e.count);
                    long long iv = 0;
                    float f = 0.0f;
                    if (p.type->is_float) {
                        num_status st = parse_float(t, &f);
                        if (st == NUM_BAD || st == NUM_NUL)
                            return vb_fail(err, VB_ERR_FORMAT,
                                           "%s: line %lu: %s %llu: %s '%.*s' %s", path, c.line,
                                           e.name.c_str(), (unsigned long long)n, p.name.c_str(),
                                           t.show_len(), t.b, num_problem(st));
                    } else if (!parse_int(t, &iv)) {
                        return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: %s %llu: %s '%.*s' %s",
                                       path, c.line, e.name.c_str(), (unsigned long long)n,
                                       p.name.c_str(), t.show_len(), t.b,
                                       int_problem(t, "is not an integer"));
                    }
                }
            }
    }
    return VB_OK;
}

/* read_ply's header, from the line after "ply" to end_header: the data's
 * format (0 ascii, 1 binary little endian, 2 binary big endian) and the
 * elements declared, with their properties. c is left at the data. */
vb_result read_ply_header(const char *path, cursor &c, int &format, std::vector<ply_element> &elems,
                          vb_error *err)
{
    token t;
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
                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: unknown PLY format '%.*s'", path,
                               line, args[0].show_len(), args[0].b);
            /* The version: PLY has one, 1.0 (written "1.0", also read as
             * "1" or "1."); another is a format this reader does not know. */
            float version = 0.0f;
            if (parse_float(args[1], &version) != NUM_OK || version != 1.0f)
                return vb_fail(err, VB_ERR_FORMAT,
                               "%s: line %lu: unknown PLY version '%.*s' (the only one is 1.0)",
                               path, line, args[1].show_len(), args[1].b);
        } else if (kw.is("element")) {
            long long n = 0;
            if (args.size() == 2 && has_nul(args[1]))
                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: element count '%.*s' %s", path,
                               line, args[1].show_len(), args[1].b, num_problem(NUM_NUL));
            if (args.size() != 2 || !parse_int(args[1], &n) || n < 0)
                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: bad element line", path, line);
            if ((uint64_t)n > max_count)
                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: element count %lld is too large",
                               path, line, n);
            ply_element e;
            e.name.assign(args[0].b, args[0].e);
            e.count = (uint64_t)n;
            elems.push_back(e);
        } else if (kw.is("property")) {
            if (elems.empty())
                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: property before any element",
                               path, line);
            ply_property p;
            if (!args.empty() && args[0].is("list")) {
                if (args.size() != 4)
                    return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: bad list property", path,
                                   line);
                p.count_type = find_ply_type(args[1]);
                p.type = find_ply_type(args[2]);
                p.name.assign(args[3].b, args[3].e);
                if (!p.count_type || !p.type)
                    return vb_fail(err, VB_ERR_FORMAT,
                                   "%s: line %lu: unknown type in list property", path, line);
                if (!(args[1].is("uint8") || args[1].is("uchar") || args[1].is("uint16") ||
                      args[1].is("int")))
                    return vb_fail(
                        err, VB_ERR_FORMAT,
                        "%s: line %lu: list count type '%.*s' is not supported (uint8, uchar, uint16, int)",
                        path, line, args[1].show_len(), args[1].b);
            } else {
                if (args.size() != 2)
                    return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: bad property line", path,
                                   line);
                /* "property float x" and "property x float" */
                int ti = find_ply_type(args[0]) ? 0 : 1;
                p.type = find_ply_type(args[ti]);
                if (!p.type)
                    return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: unknown property type", path,
                                   line);
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
    return VB_OK;
}

/* Which elements read_ply reads and where their values are: the
 * structure it can read (the rules above read_ply). */
struct ply_layout {
    /* the elements read: those before the face element's end */
    size_t last = 0;
    int vertex_elem = -1, face_elem = -1;
    /* the vertex element's x, y, z; the face's vertex_indices */
    int xyz[3] = {-1, -1, -1};
    int indices_prop = -1;
    bool has_normals = false;
};

vb_result ply_layout_of(const char *path, std::vector<ply_element> &elems, ply_layout &L,
                        vb_error *err)
{
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
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: a second vertex element (or one after the faces) is not supported",
                           path);
        }
    }
    if (vertex_elem < 0)
        return vb_fail(err, VB_ERR_INVALID, "%s: empty mesh (no vertex element)", path);
    /* OpenMesh's ascii reader read the first face element as many times as
     * the last "element face" line said. */
    if (std::count_if(elems.begin(), elems.end(),
                      [](const ply_element &e) { return e.name == "face"; }) > 1)
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
                            return vb_fail(err, VB_ERR_FORMAT,
                                           "%s: vertex property %s appears twice", path,
                                           p.name.c_str());
                        xyz[a] = (int)k;
                    }
                has_normals |= p.role == PLY_NX || p.role == PLY_NY || p.role == PLY_NZ;
            }
            if (!p.count_type)
                continue;
            if ((int)i == face_elem && (p.name == "vertex_indices" || p.name == "vertex_index") &&
                indices_prop < 0 && !p.type->is_float) {
                indices_prop = (int)k;
                continue;
            }
            return vb_fail(
                err, VB_ERR_FORMAT,
                "%s: list property '%s' of element '%s' is not supported (it would be misread)",
                path, p.name.c_str(), e.name.c_str());
        }
    }
    if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0)
        return vb_fail(err, VB_ERR_FORMAT, "%s: the vertex element lacks x, y or z", path);
    /* OpenMesh dropped the face properties declared before vertex_indices
     * from its list but not from the data, and misread every face. */
    if (indices_prop > 0)
        return vb_fail(
            err, VB_ERR_FORMAT,
            "%s: face property '%s' before vertex_indices is not supported (the faces would be "
            "misread)",
            path, elems[(size_t)face_elem].props[0].name.c_str());
    L.last = last;
    L.vertex_elem = vertex_elem;
    L.face_elem = face_elem;
    std::copy(xyz, xyz + 3, L.xyz);
    L.indices_prop = indices_prop;
    L.has_normals = has_normals;
    return VB_OK;
}

/* Binary properties OpenMesh's reader read otherwise than declared
 * (ply_binary_read): what it read must be what the file says (out, as
 * read_ply read it from the data at c), or the file is refused. */
vb_result ply_check_as_read(const char *path, const std::vector<ply_element> &elems,
                            const ply_layout &L, int format, const cursor &c, const builder &out,
                            vb_error *err)
{
    const size_t last = L.last;
    const int vertex_elem = L.vertex_elem, face_elem = L.face_elem;
    const bool has_normals = L.has_normals, big = format == 2;
    const ply_property *odd = nullptr;
    const ply_element *odd_elem = nullptr;
    for (size_t i = 0; i < last && format != 0 && !odd; i++)
        for (const ply_property &p : elems[i].props)
            if (!p.count_type &&
                ply_read_size(p, (int)i == vertex_elem, (int)i == face_elem) != p.type->size) {
                odd = &p;
                odd_elem = &elems[i];
                break;
            }
    if (odd) {
        builder as_read;
        vb_error why;
        if (ply_binary_read(path, elems, last, vertex_elem, face_elem, has_normals, big,
                            (const uint8_t *)c.p, (size_t)(c.end - c.p), as_read, &why) != VB_OK ||
            as_read.positions != out.positions || as_read.normal_sums != out.normal_sums ||
            as_read.has_normal != out.has_normal || as_read.indices != out.indices)
            return vb_fail(
                err, VB_ERR_FORMAT,
                "%s: binary property '%s' of type %s in element '%s' is not supported (x, y, z, "
                "normals and texture coordinates must be float or double, colours float or an integer "
                "type, and a property must not be named after another type)",
                path, odd->name.c_str(), odd->type->name, odd_elem->name.c_str());
    }
    return VB_OK;
}

} // namespace

/* Elements are read in order up to and including "face" (later ones are
 * never read); "vertex" must come before "face" and have x, y, z; the
 * only list property is the face's vertex_indices (or vertex_index), with
 * a uint8/uchar/uint16/int count and integer entries; one "face" element
 * and nothing before vertex_indices in it. Version 1.0 only (the only one there
 * is). The elements after "face" are walked by their declared layout
 * (ply_walk_unused): a file that ends in them is truncated, and data after
 * the last element of all is refused. Every value of the elements
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
/* Item n of element e as read_ply walks it: its face's indices go to
 * *polygon; nv: the vertices, for the indices' range. */
struct ply_item {
    const char *path;
    const ply_element *e;
    uint64_t n, nv;
    bool is_face;
    std::vector<int64_t> *polygon;
};

/* Binary: property p of item `it` at b (left bytes, moved past it): its
 * value into *into (a coordinate or normal; is_xyz: a coordinate, which
 * must be finite), or (is_indices) the face's vertex indices; items: its
 * values (a list's size, else 1). */
static vb_result binary_property(const ply_item &it, const ply_property &p, bool big, bool is_xyz,
                                 bool is_indices, float *into, const uint8_t *&b, size_t &left,
                                 uint64_t &items, vb_error *err)
{
    const char *path = it.path;
    const ply_element &e = *it.e;
    const uint64_t n = it.n, nv = it.nv;
    if (p.count_type) {
        vb_result r = binary_list_size(path, e, n, p, big, b, left, items, err);
        if (r != VB_OK)
            return r;
        const uint64_t cnt = items;
        if (is_indices && cnt < 3)
            return vb_fail(err, VB_ERR_FORMAT, "%s: face %llu has %llu %s (needs at least 3)", path,
                           (unsigned long long)n, (unsigned long long)cnt,
                           vdsh_plural(cnt, "vertex", "vertices"));
    }
    int ts = p.type->size;
    if (items > left / (size_t)ts)
        return vb_fail(err, VB_ERR_FORMAT, "%s: truncated in %s %llu of %llu", path, e.name.c_str(),
                       (unsigned long long)n, (unsigned long long)e.count);
    if (into) {
        double d = !p.type->is_float ? (double)binary_integer(p.type, b, big)
                   : ts == 4         ? (double)load_f32(b, big)
                                     : load_f64(b, big);
        if (is_xyz && (!std::isfinite(d) || std::fabs(d) > (double)FLT_MAX))
            return vb_fail(err, VB_ERR_INVALID, "%s: vertex %llu has a non-finite coordinate", path,
                           (unsigned long long)n);
        *into = ts == 4 && p.type->is_float ? load_f32(b, big) : (float)d;
    }
    if (is_indices) {
        for (uint64_t q = 0; q < items; q++) {
            long long idx = binary_integer(p.type, b + q * (size_t)ts, big);
            if (idx < 0 || (uint64_t)idx >= nv)
                return vb_fail(err, VB_ERR_INVALID,
                               "%s: face %llu: vertex index %lld out of range (%llu %s)", path,
                               (unsigned long long)n, idx, (unsigned long long)nv,
                               vdsh_plural(nv, "vertex", "vertices"));
            it.polygon->push_back(idx);
        }
    }
    b += items * (size_t)ts;
    left -= items * (size_t)ts;
    return VB_OK;
}

/* ASCII: property p of item `it` from c (size: the file's bytes, a bound
 * on a list's size), as binary_property; a colour OpenMesh would read
 * otherwise than these checks is said in *differs (the first only). */
static vb_result ascii_property(const ply_item &it, const ply_property &p, cursor &c, size_t size,
                                bool is_indices, float *into, vb_error *differs, uint64_t &items,
                                vb_error *err)
{
    const char *path = it.path;
    const ply_element &e = *it.e;
    const uint64_t n = it.n, nv = it.nv;
    token t;
    if (p.count_type) {
        long long cnt = 0;
        if (!c.next(&t))
            return vb_fail(err, VB_ERR_FORMAT, "%s: truncated: file ends in %s %llu of %llu", path,
                           e.name.c_str(), (unsigned long long)n, (unsigned long long)e.count);
        if (has_nul(t))
            return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: %s %llu: list size '%.*s' %s", path,
                           c.line, e.name.c_str(), (unsigned long long)n, t.show_len(), t.b,
                           num_problem(NUM_NUL));
        if (!parse_int(t, &cnt) || cnt < 0 || (uint64_t)cnt > size)
            return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: %s %llu: bad list size '%.*s'", path,
                           c.line, e.name.c_str(), (unsigned long long)n, t.show_len(), t.b);
        if (is_indices && cnt < 3)
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: line %lu: face %llu has %lld vertices (needs at least 3)", path,
                           c.line, (unsigned long long)n, cnt);
        items = (uint64_t)cnt;
    }
    for (uint64_t q = 0; q < items; q++) {
        if (!c.next(&t))
            return vb_fail(err, VB_ERR_FORMAT, "%s: truncated: file ends in %s %llu of %llu", path,
                           e.name.c_str(), (unsigned long long)n, (unsigned long long)e.count);
        long long iv = 0;
        float f = 0.0f;
        if (p.type->is_float) {
            num_status s = parse_float(t, &f);
            if (s != NUM_OK)
                return vb_fail(err, num_error(s), "%s: line %lu: %s %llu: %s '%.*s' %s", path,
                               c.line, e.name.c_str(), (unsigned long long)n, p.name.c_str(),
                               t.show_len(), t.b, num_problem(s));
        } else {
            if (!parse_int(t, &iv))
                return vb_fail(err, VB_ERR_FORMAT, "%s: line %lu: %s %llu: %s '%.*s' %s", path,
                               c.line, e.name.c_str(), (unsigned long long)n, p.name.c_str(),
                               t.show_len(), t.b, int_problem(t, "is not an integer"));
            if (is_indices && (iv < 0 || (uint64_t)iv >= nv))
                return vb_fail(err, VB_ERR_INVALID,
                               "%s: line %lu: face %llu: vertex index %lld out of range (%llu %s)",
                               path, c.line, (unsigned long long)n, iv, (unsigned long long)nv,
                               vdsh_plural(nv, "vertex", "vertices"));
        }
        /* Colours not of type float were read as an int: anything else
         * would shift (or stop) the rest, unless nothing used is read
         * after it (in the last face, after its vertex_indices). */
        long long cv = 0;
        bool last_read = it.is_face && n + 1 == e.count;
        if (p.role == PLY_COLOR && !(p.read_type->is_float && p.read_type->size == 4) &&
            !last_read && !differs->msg[0] && (!parse_int(t, &cv) || cv < INT_MIN || cv > INT_MAX))
            vb_fail(differs, VB_ERR_FORMAT,
                    "%s: line %lu: %s %llu: %s '%.*s': a colour of type %s must be a whole number "
                    "of int range",
                    path, c.line, e.name.c_str(), (unsigned long long)n, p.name.c_str(),
                    t.show_len(), t.b, p.type->name);
        if (into) {
            if (!p.type->is_float)
                parse_float(t, &f); /* an integer, checked above */
            *into = f;
        }
        if (is_indices)
            it.polygon->push_back(iv);
    }
    return VB_OK;
}

vb_result read_ply(const char *path, const uint8_t *bytes, size_t size, builder &out,
                   expectation *ex, vb_error *err)
{
    cursor c(bytes, size);
    token t;
    if (utf8_bom(bytes, size))
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: starts with a UTF-8 byte order mark: save it without one (the "
                       "first line must be 'ply')",
                       path);
    if (!c.next_on_line(&t) || !(t.is("ply") || t.is("PLY")) || c.next_on_line(&t))
        return vb_fail(err, VB_ERR_FORMAT, "%s: not a PLY file (first line must be 'ply')", path);
    c.skip_line();

    int format = -1; /* 0 ascii, 1 binary little endian, 2 binary big endian */
    std::vector<ply_element> elems;
    ply_layout L;
    vb_result head = read_ply_header(path, c, format, elems, err);
    if (head != VB_OK)
        return head;
    vb_result lay = ply_layout_of(path, elems, L, err);
    if (lay != VB_OK)
        return lay;
    const size_t last = L.last;
    const int vertex_elem = L.vertex_elem, face_elem = L.face_elem;
    const int *xyz = L.xyz;
    const int indices_prop = L.indices_prop;
    const bool has_normals = L.has_normals;
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
            const ply_item it = {path, &e, n, nv, is_face, &polygon};
            for (size_t k = 0; k < e.props.size(); k++) {
                const ply_property &p = e.props[k];
                bool is_xyz =
                    is_vertex && ((int)k == xyz[0] || (int)k == xyz[1] || (int)k == xyz[2]);
                bool is_indices = is_face && (int)k == indices_prop;
                /* the value of a coordinate or normal, once read */
                float *into = nullptr;
                if (is_vertex && p.role >= PLY_X && p.role <= PLY_NZ)
                    into = p.role <= PLY_Z ? &v[p.role - PLY_X] : &nrm[p.role - PLY_NX];
                uint64_t items = 1;
                if (is_indices)
                    polygon.clear();
                vb_result r =
                    format != 0
                        ? binary_property(it, p, big, is_xyz, is_indices, into, b, left, items, err)
                        : ascii_property(it, p, c, size, is_indices, into, &differs, items, err);
                if (r != VB_OK)
                    return r;
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
    /* The elements after "face": there, whole, and nothing after them. */
    vb_result walked = ply_walk_unused(path, elems, last, format, size, c, b, left, err);
    if (walked != VB_OK)
        return walked;
    /* Nothing follows the last element: trailing data is a wrong element
     * count, or two files in one. */
    if (format != 0 && left > 0)
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: %zu byte%s of data after the last element ('%s'): a wrong element "
                       "count?",
                       path, left, vdsh_s(left), elems.back().name.c_str());
    if (format == 0 && c.next(&t))
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: line %lu: data after the last element ('%s'): '%.*s' (a wrong "
                       "element count?)",
                       path, c.line, elems.back().name.c_str(), t.show_len(), t.b);
    ex->vertices = nv;
    if (differs.msg[0]) {
        if (err)
            *err = differs;
        return VB_ERR_FORMAT;
    }
    return ply_check_as_read(path, elems, L, format, c, out, err);
}

} // namespace vb_read
