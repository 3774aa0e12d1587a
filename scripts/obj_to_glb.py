#!/usr/bin/python3
"""obj_to_glb.py IN.obj OUT.glb - the OBJ that vdsh-bake --export-obj writes
(v, vn, f v//vn triangles, one normal per vertex) as a .glb with the same
vertices, normals and triangles (for scripts/bench_gltf_load)."""
import json
import struct
import sys

import numpy as np

if len(sys.argv) == 2 and sys.argv[1] in ("-h", "--help"):
    print(__doc__)
    sys.exit(0)
if len(sys.argv) != 3 or any(a.startswith("-") for a in sys.argv[1:]):
    print("usage: scripts/obj_to_glb.py IN.obj OUT.glb", file=sys.stderr)
    sys.exit(2)

v, n, f = [], [], []
for line in open(sys.argv[1]):
    p = line.split()
    if not p:
        continue
    if p[0] == "v":
        v.append([float(x) for x in p[1:4]])
    elif p[0] == "vn":
        n.append([float(x) for x in p[1:4]])
    elif p[0] == "f":
        f.append([int(c.split("/")[0]) - 1 for c in p[1:4]])
v = np.array(v, np.float32)
n = np.array(n, np.float32) if len(n) == len(v) else None
f = np.array(f, np.uint32)
blobs = [v.tobytes()] + ([n.tobytes()] if n is not None else []) + [f.tobytes()]
views, off = [], 0
for b in blobs:
    views.append({"buffer": 0, "byteOffset": off, "byteLength": len(b)})
    off += len(b)
acc = [{"bufferView": 0, "componentType": 5126, "count": len(v), "type": "VEC3",
        "min": v.min(0).tolist(), "max": v.max(0).tolist()}]
attrs = {"POSITION": 0}
if n is not None:
    acc.append({"bufferView": 1, "componentType": 5126, "count": len(v), "type": "VEC3"})
    attrs["NORMAL"] = 1
acc.append({"bufferView": len(views) - 1, "componentType": 5125, "count": f.size, "type": "SCALAR"})
g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
     "meshes": [{"primitives": [{"attributes": attrs, "indices": len(acc) - 1}]}], "accessors": acc,
     "bufferViews": views, "buffers": [{"byteLength": off}]}
j = json.dumps(g).encode()
j += b" " * (-len(j) % 4)
binary = b"".join(blobs)
binary += b"\0" * (-len(binary) % 4)
body = struct.pack("<II", len(j), 0x4E4F534A) + j + struct.pack("<II", len(binary), 0x004E4942) + binary
open(sys.argv[2], "wb").write(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)
