"""test_gltf_source_views.py BAKE EXPORT WORKDIR - vdsh-export --source and
a source's buffer views that do not fit their buffer.

A glTF whose one triangle reads valid bytes, with a second buffer view no
primitive uses that reaches past its buffer's end (Debian
assimp-testmodels' IncorrectVertexArrays/Cube.gltf has three): the bake
never reads that view and succeeds; --source copied it, and once the
source's buffers and the VDSH attributes were one BIN buffer the view
fitted and read the VDSH coefficients as its data. The export must
refuse, exit 1, name the file and the view, and write nothing; the same
glTF without that view exports (exit 0).
"""
import base64
import json
import os
import struct
import subprocess
import sys

bake, export, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
fail = []

# One triangle and its three positions (36 bytes), little-endian floats.
data = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
views = [{"buffer": 0, "byteOffset": 0, "byteLength": 36}]
gltf = {
    "asset": {"version": "2.0"},
    "scene": 0,
    "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 4}]}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [1, 1, 0]}],
    "bufferViews": views,
    "buffers": [{"byteLength": 36,
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
}


def write(name, g):
    path = os.path.join(work, name)
    with open(path, "w") as f:
        json.dump(g, f)
    return path


good = write("good.gltf", gltf)
views.append({"buffer": 0, "byteOffset": 24, "byteLength": 48})  # 24..72 of 36 bytes
bad = write("bad.gltf", gltf)

for name, src, want in (("good", good, 0), ("bad", bad, 1)):
    vd, out = os.path.join(work, name + ".vdsh"), os.path.join(work, name + ".glb")
    for p in (vd, out):
        if os.path.exists(p):
            os.unlink(p)
    r = subprocess.run([bake, src, "--rays", "16", "--orders", "2", "--cube-size", "0", "-q",
                        "-o", vd], capture_output=True, text=True)
    if r.returncode != 0:
        fail.append("bake %s: exit %d, %s" % (src, r.returncode, r.stderr.strip()))
        continue
    r = subprocess.run([export, vd, "--source", src, "-q", "-o", out], capture_output=True,
                       text=True)
    if r.returncode != want:
        fail.append("export --source %s: exit %d (want %d), %s" % (src, r.returncode, want,
                                                                   r.stderr.strip()))
    if want == 0 and not os.path.exists(out):
        fail.append("export --source %s: no output" % src)
    if want == 1:
        if os.path.exists(out):
            fail.append("export --source %s: wrote %s" % (src, out))
        if src not in r.stderr or "bufferView 1" not in r.stderr or "does not fit" not in r.stderr:
            fail.append("export --source %s: the message does not name the file and the view: %r"
                        % (src, r.stderr))
    print("%s: exit %d %s" % (name, r.returncode, r.stderr.strip()))

for f in fail:
    print("FAIL:", f)
sys.exit(1 if fail else 0)
