/*
 * mesh_gltf.cpp - glTF 2.0 input (.gltf with its buffers, .glb) for the
 * baker, through tinygltf (Debian libtinygltf-dev): the JSON and the
 * containers are tinygltf's; every accessor is read and bounds-checked
 * here (tinygltf does not apply sparse accessors nor check strides).
 *
 * What is read: every mesh primitive reachable from the default scene (or
 * scene `scene` when >= 0), each node's matrix or TRS applied (normals by
 * the inverse transpose; a mirroring transform flips the winding), once per
 * instance of EXT_mesh_gpu_instancing (its TRS inside the node's), modes
 * TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN, indexed or not, float or
 * normalised integer POSITION/NORMAL, sparse accessors; primitives with
 * morph targets in their base pose (targets ignored), meshes of skinned
 * nodes in their bind pose (POSITION as stored, the node's transform
 * ignored as the spec says), both counted. What is skipped and counted
 * (vb_mesh_raw.gltf_*, printed by vb_mesh_report_print): POINTS and LINE*
 * primitives. Refused with the file and reason: unparsable JSON, buffers out of
 * range, an accessor of the wrong type, node cycles, no scene, extensions
 * the file requires (e.g. Draco compression) but those read_extension
 * lists; images are never decoded.
 *
 * External buffers (.gltf) resolve relative to `name`'s directory; a glTF
 * loaded from memory under a name without a directory resolves them in
 * the current directory.
 *
 * Errors: vb_result; no C++ exception leaves this file.
 * Threading: no shared state; concurrent calls are fine.
 */
#include <sys/stat.h>

#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <nettle/sha2.h>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "mesh_read.h"
#include "vdsh_gltf_component.h"
#include "vdsh_gltf_uri.h"
#include "vdsh_math.h"

namespace
{

/* Elements of one accessor, and vertices of the whole mesh: 2^24, the
 * refinement's limit (mesh.h). */
constexpr size_t max_vertices = (size_t)1 << 24;

struct reader {
    const char *name;
    const tinygltf::Model &m;
    vb_error *err;
};

/* Bytes [offset, offset + count * stride) of a buffer view, checked:
 * returns a pointer to the first element or NULL after vb_fail. */
const uint8_t *view_span(const reader &rd, int view, size_t offset, size_t count, size_t elem,
                         size_t stride, const char *what, vb_result *r)
{
    const tinygltf::Model &m = rd.m;
    if (view < 0 || (size_t)view >= m.bufferViews.size()) {
        *r = vb_fail(rd.err, VB_ERR_FORMAT, "%s: %s: buffer view %d does not exist", rd.name, what,
                     view);
        return nullptr;
    }
    const tinygltf::BufferView &bv = m.bufferViews[(size_t)view];
    if (bv.buffer < 0 || (size_t)bv.buffer >= m.buffers.size()) {
        *r = vb_fail(rd.err, VB_ERR_FORMAT,
                     "%s: %s: buffer view %d names buffer %d, which does not exist", rd.name, what,
                     view, bv.buffer);
        return nullptr;
    }
    const std::vector<unsigned char> &data = m.buffers[(size_t)bv.buffer].data;
    if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset) {
        *r = vb_fail(rd.err, VB_ERR_FORMAT,
                     "%s: %s: buffer view %d (offset %zu, length %zu) overruns its buffer "
                     "(%zu bytes)",
                     rd.name, what, view, bv.byteOffset, bv.byteLength, data.size());
        return nullptr;
    }
    if (bv.byteStride)
        stride = bv.byteStride;
    if (count && (stride < elem || stride > 252)) {
        if (!(bv.byteStride == 0 && stride == elem)) {
            *r = vb_fail(rd.err, VB_ERR_FORMAT, "%s: %s: byte stride %zu with %zu-byte elements",
                         rd.name, what, stride, elem);
            return nullptr;
        }
    }
    /* offset + (count - 1) * stride + elem <= byteLength, without overflow */
    if (count && (offset > bv.byteLength || (count - 1) > (bv.byteLength - offset) / stride ||
                  (count - 1) * stride + elem > bv.byteLength - offset)) {
        *r = vb_fail(rd.err, VB_ERR_FORMAT,
                     "%s: %s: %zu elements at offset %zu overrun buffer view %d (%zu bytes)",
                     rd.name, what, count, offset, view, bv.byteLength);
        return nullptr;
    }
    return data.data() + bv.byteOffset + offset;
}

/* Accessor `index` as count x ncomp doubles (sparse applied). `types`
 * lists the allowed TINYGLTF_TYPE_ (element shape). */
vb_result read_accessor(const reader &rd, int index, int want_type, bool integer_only,
                        const char *what, std::vector<double> &out, size_t *count_out)
{
    const tinygltf::Model &m = rd.m;
    if (index < 0 || (size_t)index >= m.accessors.size())
        return vb_fail(rd.err, VB_ERR_FORMAT, "%s: %s: accessor %d does not exist", rd.name, what,
                       index);
    const tinygltf::Accessor &a = m.accessors[(size_t)index];
    if (a.type != want_type)
        return vb_fail(rd.err, VB_ERR_FORMAT,
                       "%s: %s: accessor %d has the wrong type (%d, expected %d)", rd.name, what,
                       index, a.type, want_type);
    size_t cs = vdsh_gltf_component_size(a.componentType);
    if (cs == 0)
        return vb_fail(rd.err, VB_ERR_FORMAT,
                       "%s: %s: accessor %d has an unknown component type %d", rd.name, what, index,
                       a.componentType);
    if (integer_only && (a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT || a.normalized ||
                         a.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
                         a.componentType == TINYGLTF_COMPONENT_TYPE_SHORT))
        return vb_fail(rd.err, VB_ERR_FORMAT,
                       "%s: %s: accessor %d: indices must be unsigned integers", rd.name, what,
                       index);
    int nc = tinygltf::GetNumComponentsInType((uint32_t)a.type);
    if (nc <= 0)
        return vb_fail(rd.err, VB_ERR_FORMAT, "%s: %s: accessor %d: bad type", rd.name, what,
                       index);
    if (a.count > max_vertices)
        return vb_fail(rd.err, VB_ERR_FORMAT, "%s: %s: accessor %d: too many elements (%zu)",
                       rd.name, what, index, a.count);
    size_t elem = cs * (size_t)nc;
    vb_result r = VB_OK;
    /* Bytes first, memory after: a count the buffer cannot hold is refused
     * before anything is allocated for it. */
    const uint8_t *p = nullptr;
    if (a.bufferView >= 0 && a.count) {
        p = view_span(rd, a.bufferView, a.byteOffset, a.count, elem, elem, what, &r);
        if (!p)
            return r;
    }
    out.assign(a.count * (size_t)nc, 0.0);
    if (p) {
        size_t stride = m.bufferViews[(size_t)a.bufferView].byteStride;
        if (!stride)
            stride = elem;
        for (size_t i = 0; i < a.count; i++)
            for (int c = 0; c < nc; c++)
                out[i * (size_t)nc + (size_t)c] = vdsh_gltf_component(
                    p + i * stride + (size_t)c * cs, a.componentType, a.normalized);
    }
    if (a.sparse.isSparse) {
        if (a.sparse.count < 0 || (size_t)a.sparse.count > a.count)
            return vb_fail(rd.err, VB_ERR_FORMAT,
                           "%s: %s: accessor %d: sparse count %d out of range", rd.name, what,
                           index, a.sparse.count);
        size_t sc = (size_t)a.sparse.count;
        size_t ics = vdsh_gltf_component_size(a.sparse.indices.componentType);
        if (ics < 1 || a.sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT ||
            a.sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
            a.sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
            a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0)
            return vb_fail(rd.err, VB_ERR_FORMAT, "%s: %s: accessor %d: bad sparse indices",
                           rd.name, what, index);
        const uint8_t *pi = view_span(rd, a.sparse.indices.bufferView,
                                      (size_t)a.sparse.indices.byteOffset, sc, ics, ics, what, &r);
        if (!pi && sc)
            return r;
        const uint8_t *pv = view_span(rd, a.sparse.values.bufferView,
                                      (size_t)a.sparse.values.byteOffset, sc, elem, elem, what, &r);
        if (!pv && sc)
            return r;
        for (size_t k = 0; k < sc; k++) {
            double di = vdsh_gltf_component(pi + k * ics, a.sparse.indices.componentType, false);
            if (di >= (double)a.count)
                return vb_fail(rd.err, VB_ERR_FORMAT,
                               "%s: %s: accessor %d: sparse index %.0f out of range (%zu)", rd.name,
                               what, index, di, a.count);
            size_t i = (size_t)di;
            for (int c = 0; c < nc; c++)
                out[i * (size_t)nc + (size_t)c] = vdsh_gltf_component(
                    pv + k * elem + (size_t)c * cs, a.componentType, a.normalized);
        }
    }
    *count_out = a.count;
    return VB_OK;
}

typedef std::array<double, 16> mat4; /* column-major, as glTF */

mat4 mul(const mat4 &a, const mat4 &b)
{
    mat4 c;
    vdsh_mat4d_mul(a.data(), b.data(), c.data());
    return c;
}

mat4 node_matrix(const tinygltf::Node &n)
{
    mat4 m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    if (n.matrix.size() == 16) {
        for (size_t i = 0; i < 16; i++)
            m[i] = n.matrix[i];
        return m;
    }
    vdsh_mat4d_trs(n.translation.size() == 3 ? n.translation.data() : nullptr,
                   n.rotation.size() == 4 ? n.rotation.data() : nullptr,
                   n.scale.size() == 3 ? n.scale.data() : nullptr, m.data());
    return m;
}

struct out_mesh {
    std::vector<float> pos, nrm;
    std::vector<uint8_t> has_n;
    std::vector<int64_t> idx;
    uint32_t skipped_modes = 0, skipped_morph = 0, skipped_skin = 0, ragged = 0;
};

vb_result add_primitive(const reader &rd, const tinygltf::Primitive &p, const mat4 &w, out_mesh &o)
{
    auto it = p.attributes.find("POSITION");
    if (it == p.attributes.end())
        return vb_fail(rd.err, VB_ERR_FORMAT, "%s: a triangle primitive has no POSITION", rd.name);
    std::vector<double> pos, nrm, ind;
    size_t nv = 0, nn = 0, ni = 0;
    vb_result r = read_accessor(rd, it->second, TINYGLTF_TYPE_VEC3, false, "POSITION", pos, &nv);
    if (r != VB_OK)
        return r;
    auto itn = p.attributes.find("NORMAL");
    if (itn != p.attributes.end()) {
        r = read_accessor(rd, itn->second, TINYGLTF_TYPE_VEC3, false, "NORMAL", nrm, &nn);
        if (r != VB_OK)
            return r;
        if (nn != nv)
            return vb_fail(rd.err, VB_ERR_FORMAT, "%s: NORMAL has %zu elements, POSITION %zu",
                           rd.name, nn, nv);
    }
    if (p.indices >= 0) {
        r = read_accessor(rd, p.indices, TINYGLTF_TYPE_SCALAR, true, "indices", ind, &ni);
        if (r != VB_OK)
            return r;
    } else {
        ni = nv;
        ind.resize(nv);
        for (size_t i = 0; i < nv; i++)
            ind[i] = (double)i;
    }
    for (size_t i = 0; i < ni; i++)
        if (ind[i] >= (double)nv)
            return vb_fail(rd.err, VB_ERR_INVALID, "%s: index %.0f out of range (%zu %s)", rd.name,
                           ind[i], nv, vdsh_plural(nv, "vertex", "vertices"));
    if (o.pos.size() / 3 + nv > max_vertices)
        return vb_fail(rd.err, VB_ERR_FORMAT, "%s: too many vertices", rd.name);
    /* Normal matrix: inverse transpose of the upper 3x3 (cofactors). */
    const double a = w[0], b = w[4], c = w[8], d = w[1], e = w[5], f = w[9], g = w[2], h = w[6],
                 k = w[10];
    const double det = a * (e * k - f * h) - b * (d * k - f * g) + c * (d * h - e * g);
    const double cof[9] = {e * k - f * h,    -(d * k - f * g), d * h - e * g,
                           -(b * k - c * h), a * k - c * g,    -(a * h - b * g),
                           b * f - c * e,    -(a * f - c * d), a * e - b * d};
    const int64_t base = (int64_t)(o.pos.size() / 3);
    for (size_t i = 0; i < nv; i++) {
        const double *q = &pos[3 * i];
        for (int r3 = 0; r3 < 3; r3++)
            o.pos.push_back((float)(w[(size_t)r3] * q[0] + w[(size_t)(4 + r3)] * q[1] +
                                    w[(size_t)(8 + r3)] * q[2] + w[(size_t)(12 + r3)]));
        if (!nrm.empty()) {
            const double *n = &nrm[3 * i];
            double t[3];
            for (int r3 = 0; r3 < 3; r3++)
                t[r3] = cof[3 * r3] * n[0] + cof[3 * r3 + 1] * n[1] + cof[3 * r3 + 2] * n[2];
            float u[3];
            vdsh_unit3d_to_f(t, u);
            o.nrm.insert(o.nrm.end(), {u[0], u[1], u[2]});
            o.has_n.push_back(1);
        } else {
            o.nrm.insert(o.nrm.end(), {0.0f, 0.0f, 0.0f});
            o.has_n.push_back(0);
        }
    }
    const bool flip = det < 0;
    auto tri = [&](size_t i0, size_t i1, size_t i2) {
        int64_t v0 = base + (int64_t)ind[i0], v1 = base + (int64_t)ind[i1],
                v2 = base + (int64_t)ind[i2];
        if (flip)
            std::swap(v1, v2);
        o.idx.insert(o.idx.end(), {v0, v1, v2});
    };
    if (p.mode == TINYGLTF_MODE_TRIANGLES || p.mode == -1) {
        if (ni % 3) /* invalid glTF; other readers drop the rest too: said */
            o.ragged++;
        for (size_t i = 0; i + 2 < ni; i += 3)
            tri(i, i + 1, i + 2);
    } else if (p.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        for (size_t i = 0; i + 2 < ni; i++)
            if (i % 2 == 0)
                tri(i, i + 1, i + 2);
            else
                tri(i + 1, i, i + 2);
    } else { /* fan */
        for (size_t i = 1; i + 1 < ni; i++)
            tri(0, i, i + 1);
    }
    return VB_OK;
}

/* The world matrices a node's mesh is drawn with: `w`, or with
 * EXT_mesh_gpu_instancing (used or required) w times each instance's TRS
 * (TRANSLATION, ROTATION, SCALE accessors of one count). */
vb_result instances(const reader &rd, int node, const tinygltf::Node &n, const mat4 &w,
                    std::vector<mat4> &ws)
{
    auto ext = n.extensions.find("EXT_mesh_gpu_instancing");
    if (ext == n.extensions.end()) {
        ws.assign(1, w);
        return VB_OK;
    }
    const tinygltf::Value &at = ext->second.Get("attributes");
    static const char *const names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
    std::vector<double> v[3];
    size_t count = 0, got[3] = {0, 0, 0};
    bool any = false;
    for (int k = 0; k < 3; k++) {
        if (!at.IsObject() || !at.Has(names[k]))
            continue;
        const tinygltf::Value &a = at.Get(names[k]);
        vb_result r = read_accessor(rd, a.IsNumber() ? a.GetNumberAsInt() : -1,
                                    k == 1 ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3, false,
                                    names[k], v[k], &got[k]);
        if (r != VB_OK)
            return r;
        if (any && got[k] != count)
            return vb_fail(rd.err, VB_ERR_FORMAT,
                           "%s: node %d: EXT_mesh_gpu_instancing attributes of different counts",
                           rd.name, node);
        count = got[k];
        any = true;
    }
    if (!any)
        return vb_fail(rd.err, VB_ERR_FORMAT,
                       "%s: node %d: EXT_mesh_gpu_instancing without TRANSLATION, ROTATION or "
                       "SCALE",
                       rd.name, node);
    ws.resize(count);
    for (size_t i = 0; i < count; i++) {
        mat4 t;
        vdsh_mat4d_trs(got[0] ? &v[0][3 * i] : nullptr, got[1] ? &v[1][4 * i] : nullptr,
                       got[2] ? &v[2][3 * i] : nullptr, t.data());
        ws[i] = mul(w, t);
        for (double x : ws[i])
            if (!std::isfinite(x))
                return vb_fail(rd.err, VB_ERR_INVALID,
                               "%s: node %d: instance %zu: non-finite "
                               "transform",
                               rd.name, node, i);
    }
    return VB_OK;
}

vb_result visit(const reader &rd, int node, const mat4 &parent, std::vector<uint8_t> &on_path,
                int depth, out_mesh &o)
{
    const tinygltf::Model &m = rd.m;
    if (node < 0 || (size_t)node >= m.nodes.size())
        return vb_fail(rd.err, VB_ERR_FORMAT, "%s: node %d does not exist", rd.name, node);
    if (on_path[(size_t)node])
        return vb_fail(rd.err, VB_ERR_FORMAT,
                       "%s: node %d is its own ancestor (a cycle in the node tree)", rd.name, node);
    if (depth > 1000)
        return vb_fail(rd.err, VB_ERR_FORMAT,
                       "%s: node %d: the node tree is deeper than 1000 levels, which the reader "
                       "does not go",
                       rd.name, node);
    on_path[(size_t)node] = 1;
    const tinygltf::Node &n = m.nodes[(size_t)node];
    mat4 w = mul(parent, node_matrix(n));
    for (double v : w)
        if (!std::isfinite(v))
            return vb_fail(rd.err, VB_ERR_INVALID, "%s: node %d: non-finite transform", rd.name,
                           node);
    if (n.mesh >= 0) {
        if ((size_t)n.mesh >= m.meshes.size())
            return vb_fail(rd.err, VB_ERR_FORMAT, "%s: node %d: mesh %d does not exist", rd.name,
                           node, n.mesh);
        std::vector<mat4> ws;
        vb_result r = instances(rd, node, n, w, ws);
        if (r != VB_OK)
            return r;
        /* A skinned node's mesh in its bind pose: the glTF spec ignores
         * the node's own transform (the joints place the mesh), and at
         * the bind pose every joint's world matrix times its inverse bind
         * matrix is the identity, so POSITION is already in scene
         * coordinates. */
        const mat4 id{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        if (n.skin >= 0)
            ws.assign(1, id);
        for (const tinygltf::Primitive &p : m.meshes[(size_t)n.mesh].primitives) {
            if (p.mode != -1 && p.mode != TINYGLTF_MODE_TRIANGLES &&
                p.mode != TINYGLTF_MODE_TRIANGLE_STRIP && p.mode != TINYGLTF_MODE_TRIANGLE_FAN) {
                o.skipped_modes++;
                continue;
            }
            /* morph targets ignored: the base pose (the primitive's own
             * POSITION and NORMAL) is baked */
            if (!p.targets.empty())
                o.skipped_morph++;
            if (n.skin >= 0)
                o.skipped_skin++;
            for (const mat4 &wi : ws) {
                r = add_primitive(rd, p, wi, o);
                if (r != VB_OK)
                    return r;
            }
        }
    }
    for (int c : n.children) {
        vb_result r = visit(rd, c, w, on_path, depth + 1, o);
        if (r != VB_OK)
            return r;
    }
    on_path[(size_t)node] = 0;
    return VB_OK;
}

/* External files (buffers): beside the glTF only (tinygltf also looked
 * in the current directory, and read a same-named file there), regular
 * files only (vb_mesh_read_file: a FIFO would block). `dir` is the base
 * directory tinygltf joins URIs to. */
struct files {
    std::string dir;
    /* the external images' paths, as tinygltf forms them: said not to
     * exist, so that tinygltf keeps the URI and reads nothing (the baker
     * never uses images; a no-op image loader alone still had every
     * image file read into memory first) */
    std::vector<std::string> images;
    /* a path held a NUL byte (a URI's "%00"): refused, not read as the
     * file its bytes before the NUL name */
    bool nul;
};

bool file_exists(const std::string &path, void *user)
{
    files *fs = (files *)user;
    const std::string &dir = fs->dir;
    const std::string base = !dir.empty() && dir.back() == '/' ? dir : dir + "/";
    for (const std::string &im : fs->images)
        if (path == im)
            return false;
    if (path.find('\0') != std::string::npos) {
        fs->nul = true;
        return false;
    }
    struct stat st;
    return path.compare(0, base.size(), base) == 0 && stat(path.c_str(), &st) == 0;
}

/* The file name a URI names, as tinygltf decodes it before joining it to
 * the base directory (formats/vdsh_gltf_uri.h, which vdsh-export --source
 * uses too); any NUL byte kept, as in tinygltf's path. */
std::string url_decode(const std::string &u)
{
    std::vector<char> r(u.size() + 1);
    return std::string(r.data(), vdsh_gltf_uri_decode(u.data(), u.size(), r.data()));
}

bool read_whole_file(std::vector<unsigned char> *out, std::string *err, const std::string &path,
                     void *)
{
    uint8_t *bytes = nullptr;
    size_t size = 0;
    vb_error e;
    memset(&e, 0, sizeof e);
    if (vb_mesh_read_file(path.c_str(), &bytes, &size, &e) != VB_OK) {
        if (err)
            *err = e.msg;
        return false;
    }
    out->assign(bytes, bytes + size);
    free(bytes);
    return true;
}

bool no_images(tinygltf::Image *, const int, std::string *, std::string *, int, int,
               const unsigned char *, int, void *)
{
    return true;
}

/* A required extension the baker reads: KHR_mesh_quantization (integer
 * positions and normals, which read_accessor reads; the dequantisation is
 * the node's transform), EXT_mesh_gpu_instancing (instances()), and
 * extensions of textures and materials alone (the triangles are the
 * same; KHR_technique_webgl, shaders for materials, among them). */
bool read_extension(const std::string &x)
{
    static const char *const names[] = {"KHR_mesh_quantization", "EXT_mesh_gpu_instancing",
                                        "KHR_texture_transform", "KHR_texture_basisu",
                                        "EXT_texture_webp",      "EXT_texture_avif",
                                        "KHR_technique_webgl"};
    for (const char *n : names)
        if (x == n)
            return true;
    return x.rfind("KHR_materials_", 0) == 0;
}

/* The first extension the file requires, read from its JSON alone (empty
 * when none, or when the JSON does not parse): tinygltf refuses some such
 * files before its own list can be checked (EXT_meshopt_compression's
 * fallback buffer has no data: "Invalid byteLength"), and the extension is
 * then the reason to give. */
nlohmann::json file_json(int binary, const uint8_t *bytes, size_t size)
{
    const char *j = (const char *)bytes;
    size_t n = size;
    if (binary) {
        uint32_t len = 0;
        if (size < 20)
            return nlohmann::json();
        memcpy(&len, bytes + 12, 4);
        if (len > size - 20)
            return nlohmann::json();
        j = (const char *)bytes + 20;
        n = len;
    }
    return nlohmann::json::parse(j, j + n, nullptr, false);
}

/* The first buffer URI that decodes to a NUL byte ("%00"; empty when
 * none): tinygltf would read the file named by the bytes before it. */
std::string nul_buffer_uri(int binary, const uint8_t *bytes, size_t size)
{
    nlohmann::json doc = file_json(binary, bytes, size);
    auto it = doc.is_object() ? doc.find("buffers") : doc.end();
    if (it == doc.end() || !it->is_array())
        return std::string();
    for (const auto &x : *it)
        if (x.is_object() && x.contains("uri") && x["uri"].is_string()) {
            std::string u = x["uri"].get<std::string>();
            if (u.rfind("data:", 0) != 0 && url_decode(u).find('\0') != std::string::npos)
                return u;
        }
    return std::string();
}

/* Whether the file is glTF 1.0 (tinygltf then says "no scene", "Invalid
 * glTF binary" or that "asset" is missing): a binary of container version
 * 1, an asset.version 1.x, or objects where 2.0 has arrays (1.0's
 * dictionaries of accessors, meshes, nodes). */
bool gltf_1(int binary, const uint8_t *bytes, size_t size)
{
    uint32_t v = 0;
    if (binary && size >= 8)
        memcpy(&v, bytes + 4, 4);
    if (v == 1)
        return true;
    nlohmann::json doc = file_json(binary, bytes, size);
    if (!doc.is_object())
        return false;
    auto a = doc.find("asset");
    if (a != doc.end() && a->is_object()) {
        auto ver = a->find("version");
        if (ver != a->end() && ver->is_string() && ver->get<std::string>().rfind("1", 0) == 0)
            return true;
    }
    for (const char *k : {"accessors", "meshes", "nodes"}) {
        auto it = doc.find(k);
        if (it != doc.end() && it->is_object())
            return true;
    }
    return false;
}

std::string required_extension(int binary, const uint8_t *bytes, size_t size)
{
    nlohmann::json doc = file_json(binary, bytes, size);
    if (!doc.is_object())
        return std::string();
    auto it = doc.find("extensionsRequired");
    if (it == doc.end() || !it->is_array())
        return std::string();
    for (const auto &x : *it)
        if (x.is_string() && !read_extension(x.get<std::string>()))
            return x.get<std::string>();
    return std::string();
}

/* Why scene s gave no triangle, where the JSON says (empty when it does
 * not): tinygltf takes a mesh whose "primitives" is not an array for a
 * mesh without primitives, and a scene without nodes for an empty one,
 * and the bake then said only "empty mesh (no faces)". */
std::string no_triangles_reason(int binary, const uint8_t *bytes, size_t size, int s)
{
    nlohmann::json doc = file_json(binary, bytes, size);
    if (!doc.is_object())
        return std::string();
    auto meshes = doc.find("meshes");
    if (meshes != doc.end() && meshes->is_array())
        for (size_t i = 0; i < meshes->size(); i++) {
            const nlohmann::json &m = (*meshes)[i];
            if (m.is_object() && (!m.contains("primitives") || !m["primitives"].is_array()))
                return "mesh " + std::to_string(i) +
                       ": \"primitives\" is missing or not an array (not valid glTF 2.0)";
        }
    auto scenes = doc.find("scenes");
    if (scenes != doc.end() && scenes->is_array() && (size_t)s < scenes->size()) {
        const nlohmann::json &sc = (*scenes)[(size_t)s];
        if (sc.is_object() &&
            (!sc.contains("nodes") || !sc["nodes"].is_array() || sc["nodes"].empty()))
            return "scene " + std::to_string(s) + " has no nodes: nothing to bake";
    }
    return std::string();
}

/* The paths tinygltf would read the file's external images from (the
 * base directory joined to each decoded URI, as its LoadExternalFile
 * does), leaving out any a buffer also names. Only when the JSON has an
 * "images" member at all (the JSON is parsed a second time then). */
void external_images(int binary, const uint8_t *bytes, size_t size, const std::string &dir,
                     std::vector<std::string> &out)
{
    static const char key[] = "\"images\"";
    if (!memmem(bytes, size, key, sizeof key - 1))
        return;
    nlohmann::json doc = file_json(binary, bytes, size);
    if (!doc.is_object())
        return;
    auto uris = [&](const char *k) {
        std::vector<std::string> u;
        auto it = doc.find(k);
        if (it != doc.end() && it->is_array())
            for (const auto &x : *it)
                if (x.is_object() && x.contains("uri") && x["uri"].is_string())
                    u.push_back(url_decode(x["uri"].get<std::string>()));
        return u;
    };
    std::vector<std::string> bufs = uris("buffers");
    for (const std::string &u : uris("images")) {
        if (u.rfind("data:", 0) == 0 || u.empty())
            continue;
        bool buffer = false;
        for (const std::string &b : bufs)
            buffer = buffer || b == u;
        if (!buffer)
            out.push_back(dir.back() == '/' ? dir + u : dir + "/" + u);
    }
}

vb_result parse(const char *name, int binary, int scene, const uint8_t *bytes, size_t size,
                vb_mesh_raw *out, vb_error *err)
{
    /* The container by its bytes, as vdsh-export --source reads it: a .glb
     * named .gltf, or the other way round, is still the file it is. */
    binary = size >= 4 && memcmp(bytes, "glTF", 4) == 0;
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(no_images, nullptr);
    tinygltf::Model model;
    std::string e, w;
    std::string path(name);
    size_t slash = path.rfind('/');
    std::string dir = slash == std::string::npos ? std::string(".")
                      : slash == 0               ? std::string("/")
                                                 : path.substr(0, slash);
    files fs_dir{dir, {}, false};
    external_images(binary, bytes, size, dir, fs_dir.images);
    loader.SetFsCallbacks({&file_exists, &tinygltf::ExpandFilePath, &read_whole_file,
                           &tinygltf::WriteWholeFile, &fs_dir});
    if (size > 0xffffffffu)
        return vb_fail(err, VB_ERR_FORMAT, "%s: file too large", name);
    bool ok = binary ? loader.LoadBinaryFromMemory(&model, &e, &w, bytes, (unsigned)size, dir)
                     : loader.LoadASCIIFromString(&model, &e, &w, (const char *)bytes,
                                                  (unsigned)size, dir);
    if ((!ok || model.asset.version.rfind("1", 0) == 0) && gltf_1(binary, bytes, size))
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: a glTF 1.0 file: only glTF 2.0 is read (convert it, e.g. with "
                       "Khronos' gltf-pipeline)",
                       name);
    if (!ok) {
        std::string u = fs_dir.nul ? nul_buffer_uri(binary, bytes, size) : std::string();
        if (!u.empty())
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: buffer uri \"%s\" decodes to a NUL byte, which no file name holds",
                           name, u.c_str());
        std::string x = required_extension(binary, bytes, size);
        if (!x.empty())
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: requires the extension %s, which the baker does not read", name,
                           x.c_str());
        while (!e.empty() && (e.back() == '\n' || e.back() == ' '))
            e.pop_back();
        for (char &ch : e)
            if (ch == '\n')
                ch = ';';
        return vb_fail(err, VB_ERR_FORMAT, "%s: not a readable glTF 2.0 file: %s", name,
                       e.empty() ? "(no reason given)" : e.c_str());
    }
    for (const std::string &x : model.extensionsRequired)
        if (!read_extension(x))
            return vb_fail(err, VB_ERR_FORMAT,
                           "%s: requires the extension %s, which the baker does not read", name,
                           x.c_str());
    if (model.scenes.empty())
        return vb_fail(err, VB_ERR_FORMAT, "%s: no scene", name);
    int s = scene >= 0 ? scene : (model.defaultScene >= 0 ? model.defaultScene : 0);
    if ((size_t)s >= model.scenes.size())
        return vb_fail(err, VB_ERR_ARGUMENT, "%s: scene %d does not exist (%zu scenes)", name, s,
                       model.scenes.size());
    reader rd{name, model, err};
    out_mesh o;
    std::vector<uint8_t> on_path(model.nodes.size(), 0);
    const mat4 id{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    for (int n : model.scenes[(size_t)s].nodes) {
        vb_result r = visit(rd, n, id, on_path, 0, o);
        if (r != VB_OK)
            return r;
    }
    for (float v : o.pos)
        if (!std::isfinite(v))
            return vb_fail(err, VB_ERR_INVALID, "%s: a vertex has a non-finite coordinate", name);
    if (o.idx.empty() && !o.skipped_modes) {
        std::string why = no_triangles_reason(binary, bytes, size, s);
        if (!why.empty())
            return vb_fail(err, VB_ERR_INVALID, "%s: empty mesh: %s", name, why.c_str());
    }
    if (o.idx.empty() && o.skipped_modes)
        return vb_fail(err, VB_ERR_INVALID,
                       "%s: empty mesh: no triangles left after skipping %u point/line "
                       "primitives",
                       name, o.skipped_modes);
    vb_mesh_raw raw;
    memset(&raw, 0, sizeof raw);
    raw.vertex_count = (uint32_t)(o.pos.size() / 3);
    raw.triangle_count = (uint32_t)(o.idx.size() / 3);
    raw.gltf_skipped_modes = o.skipped_modes;
    raw.gltf_skipped_morph = o.skipped_morph;
    raw.gltf_skipped_skin = o.skipped_skin;
    raw.gltf_ragged = o.ragged;
    /* The source's hash covers its external buffers too (formats/VDSH.md,
     * SRCS): the file's bytes, then each external buffer's, in order. */
    bool external = false;
    for (const tinygltf::Buffer &b : model.buffers)
        external = external || (!b.uri.empty() && b.uri.rfind("data:", 0) != 0);
    if (external) {
        struct sha256_ctx c;
        sha256_init(&c);
        sha256_update(&c, size, bytes);
        uint64_t total = size;
        for (const tinygltf::Buffer &b : model.buffers)
            if (!b.uri.empty() && b.uri.rfind("data:", 0) != 0) {
                sha256_update(&c, b.data.size(), b.data.data());
                total += b.data.size();
            }
        sha256_digest(&c, SHA256_DIGEST_SIZE, raw.gltf_sha256);
        raw.gltf_size = total;
        raw.gltf_hashed = 1;
    }
    try {
        raw.positions = vb_read::malloc_copy(o.pos);
        raw.indices = vb_read::malloc_copy(o.idx);
        std::vector<uint32_t> faces(raw.triangle_count);
        for (uint32_t t = 0; t < raw.triangle_count; t++)
            faces[t] = t;
        raw.faces = vb_read::malloc_copy(faces);
        bool any = false;
        for (uint8_t h : o.has_n)
            any = any || h;
        if (any) {
            raw.normals = vb_read::malloc_copy(o.nrm);
            raw.has_normal = vb_read::malloc_copy(o.has_n);
        }
    } catch (...) {
        vb_mesh_raw_free(&raw);
        throw;
    }
    *out = raw;
    return VB_OK;
}

} // namespace

extern "C" vb_result vb_mesh_parse_gltf(const char *name, int binary, int scene,
                                        const uint8_t *bytes, size_t size, vb_mesh_raw *out,
                                        vb_error *err)
{
    if (!name || (!bytes && size) || !out)
        return vb_fail(err, VB_ERR_ARGUMENT, "vb_mesh_parse_gltf: NULL argument");
    static const uint8_t nothing = 0;
    const uint8_t *b = bytes ? bytes : &nothing;
    return vb_read::no_throw(name, err,
                             [&] { return parse(name, binary, scene, b, size, out, err); });
}
