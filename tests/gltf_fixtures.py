"""gltf_fixtures.py - small glTF 2.0 files written by hand for the glTF
input tests (test_gltf_input.py) and the fuzz seeds (run as a script:
`gltf_fixtures.py DIR_GLTF DIR_GLB` writes the seed corpora
tests/corpus/mesh_gltf and mesh_glb).

Each fixture is (name, gltf dict with its one buffer as a data: URI or as
the GLB BIN chunk, expected): expected is the list of triangles the baker
must load (each three (x, y, z) corners, world space, in winding order),
or None for a file that must be refused.
"""
import base64
import json
import struct
import sys

FLOAT, USHORT, UBYTE, UINT = 5126, 5123, 5121, 5125


class Builder:
    def __init__(self):
        self.bin = bytearray()
        self.views = []
        self.accessors = []

    def view(self, data):
        while len(self.bin) % 4:
            self.bin.append(0)
        self.views.append({"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)})
        self.bin += data
        return len(self.views) - 1

    def acc(self, values, ctype=FLOAT, kind="VEC3", sparse=None, no_view=False):
        n = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[kind]
        fmt = {FLOAT: "f", USHORT: "H", UBYTE: "B", UINT: "I"}[ctype]
        a = {"componentType": ctype, "count": len(values) // n, "type": kind}
        if not no_view:
            a["bufferView"] = self.view(struct.pack("<%d%s" % (len(values), fmt), *values))
        if kind == "VEC3" and ctype == FLOAT:
            full = list(values) if not no_view else [0.0] * (a["count"] * 3)
            if sparse:
                for i, v in sparse:
                    full[3 * i:3 * i + 3] = v
            a["min"] = [min(full[k::3]) for k in range(3)]
            a["max"] = [max(full[k::3]) for k in range(3)]
        if sparse:
            idx = [i for i, _ in sparse]
            val = [x for _, v in sparse for x in v]
            a["sparse"] = {"count": len(sparse),
                           "indices": {"bufferView": self.view(struct.pack("<%dH" % len(idx), *idx)),
                                       "componentType": USHORT},
                           "values": {"bufferView": self.view(struct.pack("<%df" % len(val), *val))}}
        self.accessors.append(a)
        return len(self.accessors) - 1

    def gltf(self, meshes, nodes, scene_nodes, extra=None):
        g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": scene_nodes}],
             "nodes": nodes, "meshes": meshes, "accessors": self.accessors,
             "bufferViews": self.views, "buffers": [{"byteLength": len(self.bin)}]}
        if extra:
            g.update(extra)
        return g


QUAD = [0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0]


def v(p, i):
    return tuple(p[3 * i:3 * i + 3])


def fixtures():
    out = []
    # Indexed triangle list, ushort indices.
    b = Builder()
    pos = b.acc(QUAD)
    ind = b.acc([0, 1, 2, 0, 2, 3], USHORT, "SCALAR")
    g = b.gltf([{"primitives": [{"attributes": {"POSITION": pos}, "indices": ind}]}], [{"mesh": 0}], [0])
    out.append(("list", g, b.bin, [(v(QUAD, 0), v(QUAD, 1), v(QUAD, 2)), (v(QUAD, 0), v(QUAD, 2), v(QUAD, 3))]))
    # Strip (0 1 3 2 draws the quad) and fan, non-indexed.
    b = Builder()
    sp = [0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0]
    pos = b.acc(sp)
    g = b.gltf([{"primitives": [{"attributes": {"POSITION": pos}, "mode": 5}]}], [{"mesh": 0}], [0])
    out.append(("strip", g, b.bin, [(v(sp, 0), v(sp, 1), v(sp, 2)), (v(sp, 2), v(sp, 1), v(sp, 3))]))
    b = Builder()
    pos = b.acc(QUAD)
    g = b.gltf([{"primitives": [{"attributes": {"POSITION": pos}, "mode": 6}]}], [{"mesh": 0}], [0])
    out.append(("fan", g, b.bin, [(v(QUAD, 0), v(QUAD, 1), v(QUAD, 2)), (v(QUAD, 0), v(QUAD, 2), v(QUAD, 3))]))
    # Sparse accessor: vertex 2 of the quad moved to (2, 3, 0); node with
    # translation and scale under a parent with a matrix (translate x+10).
    b = Builder()
    pos = b.acc(QUAD, sparse=[(2, (2.0, 3.0, 0.0))])
    ind = b.acc([0, 1, 2], UBYTE, "SCALAR")
    g = b.gltf([{"primitives": [{"attributes": {"POSITION": pos}, "indices": ind}]}],
               [{"children": [1], "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 10, 0, 0, 1]},
                {"mesh": 0, "translation": [0, 0, 5], "scale": [2, 2, 2]}], [0])
    out.append(("sparse_nodes", g, b.bin, [((10, 0, 5), (12, 0, 5), (14, 6, 5))]))
    # Mirroring scale: the winding flips so the face keeps its side.
    b = Builder()
    pos = b.acc(QUAD[:9])
    g = b.gltf([{"primitives": [{"attributes": {"POSITION": pos}}]}], [{"mesh": 0, "scale": [-1, 1, 1]}], [0])
    out.append(("mirror", g, b.bin, [((0, 0, 0), (-1, 1, 0), (-1, 0, 0))]))
    # Sparse accessor without a buffer view (zeros, then the sparse values).
    b = Builder()
    pos = b.acc([0.0] * 9, no_view=True, sparse=[(1, (1.0, 0.0, 0.0)), (2, (0.0, 1.0, 0.0))])
    g = b.gltf([{"primitives": [{"attributes": {"POSITION": pos}}]}], [{"mesh": 0}], [0])
    out.append(("sparse_zero", g, b.bin, [((0, 0, 0), (1, 0, 0), (0, 1, 0))]))
    # Points and lines beside a triangle: skipped, the triangle kept.
    b = Builder()
    pos = b.acc(QUAD[:9])
    g = b.gltf([{"primitives": [{"attributes": {"POSITION": pos}, "mode": 0},
                                {"attributes": {"POSITION": pos}, "mode": 1},
                                {"attributes": {"POSITION": pos}, "mode": 4}]}], [{"mesh": 0}], [0])
    out.append(("points_lines", g, b.bin, [(v(QUAD, 0), v(QUAD, 1), v(QUAD, 2))]))
    # Extensions that leave the triangles as they are, required: read.
    # KHR_mesh_quantization (gltfpack's default): integer positions, not
    # normalised, scaled by the node; texture and material extensions.
    b = Builder()
    pos = b.acc([0, 0, 0, 2, 0, 0, 0, 2, 0], USHORT)
    g = b.gltf([{"primitives": [{"attributes": {"POSITION": pos}}]}], [{"mesh": 0, "scale": [0.5, 0.5, 0.5]}], [0],
               {"extensionsUsed": ["KHR_mesh_quantization", "KHR_texture_transform", "KHR_materials_emissive_strength",
                                   "KHR_technique_webgl"],
                "extensionsRequired": ["KHR_mesh_quantization", "KHR_texture_transform",
                                       "KHR_materials_emissive_strength", "KHR_technique_webgl"]})
    out.append(("quantized", g, b.bin, [((0, 0, 0), (1, 0, 0), (0, 1, 0))]))
    # EXT_mesh_gpu_instancing (used, not required): every instance baked,
    # each instance's TRS inside the node's transform.
    b = Builder()
    pos = b.acc(QUAD[:9])
    tr = b.acc([0, 0, 0, 5, 0, 0])
    sc = b.acc([1, 1, 1, 2, 2, 2])
    g = b.gltf([{"primitives": [{"attributes": {"POSITION": pos}}]}],
               [{"mesh": 0, "translation": [0, 0, 1],
                 "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": tr, "SCALE": sc}}}}], [0],
               {"extensionsUsed": ["EXT_mesh_gpu_instancing"]})
    out.append(("instanced", g, b.bin, [((0, 0, 1), (1, 0, 1), (1, 1, 1)), ((5, 0, 1), (7, 0, 1), (7, 2, 1))]))
    # Morph targets: the base pose (the primitive's own POSITION) is baked,
    # the target (which would move vertex 2) ignored; the node's transform
    # applies as for any mesh.
    b = Builder()
    pos = b.acc(QUAD[:9])
    tgt = b.acc([0, 0, 0, 0, 0, 0, 0, 0, 4])
    g = b.gltf([{"primitives": [{"attributes": {"POSITION": pos}, "targets": [{"POSITION": tgt}]}],
                "weights": [1.0]}], [{"mesh": 0, "translation": [0, 0, 3]}], [0])
    out.append(("morph", g, b.bin, [((0, 0, 3), (1, 0, 3), (1, 1, 3))]))
    # Skinned node: the bind pose, POSITION as stored; the skinned node's
    # own translation is ignored (glTF spec), the joint node draws nothing.
    b = Builder()
    pos = b.acc(QUAD[:9])
    joints = b.acc([0, 0, 0, 0] * 3, USHORT, "VEC4")
    weights = b.acc([1.0, 0, 0, 0] * 3, FLOAT, "VEC4")
    g = b.gltf([{"primitives": [{"attributes": {"POSITION": pos, "JOINTS_0": joints, "WEIGHTS_0": weights}}]}],
               [{"mesh": 0, "skin": 0, "translation": [0, 0, 7]}, {"translation": [0, 0, 0]}], [0, 1],
               {"skins": [{"joints": [1]}]})
    out.append(("skinned", g, b.bin, [(v(QUAD, 0), v(QUAD, 1), v(QUAD, 2))]))
    # Refused: index out of range, stride/overrun, cycle, only points.
    b = Builder()
    pos = b.acc(QUAD[:9])
    ind = b.acc([0, 1, 7], USHORT, "SCALAR")
    g = b.gltf([{"primitives": [{"attributes": {"POSITION": pos}, "indices": ind}]}], [{"mesh": 0}], [0])
    out.append(("bad_index", g, b.bin, None))
    b = Builder()
    pos = b.acc(QUAD[:9])
    b.accessors[pos]["count"] = 1000
    g = b.gltf([{"primitives": [{"attributes": {"POSITION": pos}}]}], [{"mesh": 0}], [0])
    out.append(("bad_overrun", g, b.bin, None))
    b = Builder()
    pos = b.acc(QUAD[:9])
    g = b.gltf([{"primitives": [{"attributes": {"POSITION": pos}}]}], [{"mesh": 0, "children": [1]},
                                                                       {"children": [0]}], [0])
    out.append(("bad_cycle", g, b.bin, None))
    b = Builder()
    pos = b.acc(QUAD[:9])
    g = b.gltf([{"primitives": [{"attributes": {"POSITION": pos}, "mode": 0}]}], [{"mesh": 0}], [0])
    out.append(("bad_only_points", g, b.bin, None))
    return out


def as_gltf(g, binary):
    g = json.loads(json.dumps(g))
    g["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(binary).decode()
    return json.dumps(g).encode()


def as_glb(g, binary):
    j = json.dumps(g).encode()
    j += b" " * (-len(j) % 4)
    binary = bytes(binary) + b"\0" * (-len(binary) % 4)
    body = struct.pack("<II", len(j), 0x4E4F534A) + j + struct.pack("<II", len(binary), 0x004E4942) + binary
    return struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body


if __name__ == "__main__":
    import os
    for d in sys.argv[1:3]:
        os.makedirs(d, exist_ok=True)
    for name, g, binary, _ in fixtures():
        open(os.path.join(sys.argv[1], name + ".gltf"), "wb").write(as_gltf(g, binary))
        glb = as_glb(g, binary)
        open(os.path.join(sys.argv[2], name + ".glb"), "wb").write(glb)
    # Truncated GLB (cut in the BIN chunk) and a JSON cut mid-way.
    name, g, binary, _ = fixtures()[0]
    glb = as_glb(g, binary)
    open(os.path.join(sys.argv[2], "truncated.glb"), "wb").write(glb[:len(glb) - 10])
    txt = as_gltf(g, binary)
    open(os.path.join(sys.argv[1], "truncated.gltf"), "wb").write(txt[:len(txt) // 2])
