"""test_gltf_source_match.py BAKE EXPORT WORKDIR - vdsh-export --source with a
glTF other than the one the bake recorded (formats/VDSH.md SRCS: size and
SHA-256, the external buffers included).

A quad baked from a.glb: --source a.glb exports, every vertex matched,
nothing said. moved.glb (the same quad, one vertex moved: same size, same
vertex count) was exported with a warning that blamed the bake
("unreferenced, or dropped by the bake") and zero attributes on that
vertex, exit 0: now refused, exit 1, naming the file and the bake's record,
nothing written; --allow-mismatch exports it with a warning. other.glb
(another quad of 4 vertices: no vertex at a receiver) is refused as before.
named.glb (the same geometry, a material added: the file differs) exports
with a note, as formats/GLTF.md allows. A .gltf whose external buffer
q.bin is changed (its JSON the same) is refused: the buffer is in the
record.
"""
import json
import os
import struct
import subprocess
import sys

bake, export, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
fail = []
QUAD = [0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0]


def quad_bin(pos):
    return struct.pack("<12f", *pos) + struct.pack("<6H", 0, 1, 2, 0, 2, 3)


def quad_json(uri=None, material=False):
    buf = {"byteLength": 60}
    if uri:
        buf["uri"] = uri
    extra = {"materials": [{"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 1]}}]} \
        if material else {}
    return dict(extra, **{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                           "min": [0, 0, 0], "max": [1, 1, 0.5]},
                          {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}],
            "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                            {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
            "buffers": [buf]})


def glb(path, pos, material=False):
    j = json.dumps(quad_json(material=material)).encode()
    j += b" " * (-len(j) % 4)
    b = quad_bin(pos)
    b += b"\0" * (-len(b) % 4)
    total = 12 + 8 + len(j) + 8 + len(b)
    with open(path, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, total) + struct.pack("<II", len(j), 0x4E4F534A) + j +
                struct.pack("<II", len(b), 0x004E4942) + b)


def run(args):
    return subprocess.run(args, capture_output=True, text=True)


a, moved, other = (os.path.join(work, n + ".glb") for n in ("a", "moved", "other"))
glb(a, QUAD)
glb(moved, QUAD[:11] + [0.5])
glb(other, [x + 3 for x in QUAD])
named = os.path.join(work, "named.glb")
glb(named, QUAD, material=True)
vd = os.path.join(work, "a.vdsh")
p = run([bake, a, "-o", vd, "-q", "--rays", "16", "--orders", "2", "--cube-size", "0"])
if p.returncode != 0:
    print("FAIL: bake a.glb: rc %d, %s" % (p.returncode, p.stderr.strip()))
    sys.exit(1)


def out_of(name):
    o = os.path.join(work, "out-" + name + ".glb")
    if os.path.exists(o):
        os.remove(o)
    return o


o = out_of("a")
p = run([export, vd, "--source", a, "-o", o, "-q"])
if p.returncode != 0 or not os.path.exists(o) or p.stderr:
    fail.append("--source a.glb (the bake's): rc %d, %s" % (p.returncode, p.stderr.strip()))
for src in (moved, other):
    o = out_of(os.path.basename(src)[:-4])
    p = run([export, vd, "--source", src, "-o", o, "-q"])
    # moved.glb names the bake's record (a.glb); other.glb the bake
    want = ["not the file", "a.glb"] if src == moved else ["not the glTF it was baked from", "a.vdsh"]
    if (p.returncode != 1 or any(w not in p.stderr for w in want) or os.path.basename(src) not in p.stderr
            or os.path.exists(o)):
        fail.append("--source %s (not the bake's): rc %d, %s, output %s" %
                    (os.path.basename(src), p.returncode, p.stderr.strip(), os.path.exists(o)))
# the note and the warning are said without -q; -q says nothing but errors
# (as every program's -q: vdsh-export's kept its notes and warnings)
for quiet in ([], ["-q"]):
    o = out_of("named")
    p = run([export, vd, "--source", named, "-o", o] + quiet)
    if p.returncode != 0 or ("note" in p.stderr) == bool(quiet) or not os.path.exists(o):
        fail.append("--source named.glb (a material added) %s: rc %d, %r" %
                    (quiet, p.returncode, p.stderr.strip()))
    o = out_of("moved-allowed")
    p = run([export, vd, "--source", moved, "--allow-mismatch", "-o", o] + quiet)
    if p.returncode != 0 or ("warning" in p.stderr) == bool(quiet) or not os.path.exists(o) or \
            (quiet and p.stderr):
        fail.append("--source moved.glb --allow-mismatch %s: rc %d, %r" %
                    (quiet, p.returncode, p.stderr.strip()))

# A .gltf with an external buffer: the buffer's bytes are part of the record.
g, qbin = os.path.join(work, "q.gltf"), os.path.join(work, "q.bin")
json.dump(quad_json("q.bin"), open(g, "w"))
open(qbin, "wb").write(quad_bin(QUAD))
vg = os.path.join(work, "q.vdsh")
p = run([bake, g, "-o", vg, "-q", "--rays", "16", "--orders", "2", "--cube-size", "0"])
o = out_of("q")
p2 = run([export, vg, "--source", g, "-o", o, "-q"])
if p.returncode != 0 or p2.returncode != 0 or not os.path.exists(o):
    fail.append("q.gltf: bake rc %d, export rc %d: %s %s" % (p.returncode, p2.returncode, p.stderr.strip(),
                                                          p2.stderr.strip()))
open(qbin, "wb").write(quad_bin(QUAD[:11] + [0.5]))
o = out_of("q-changed")
p = run([export, vg, "--source", g, "-o", o, "-q"])
if p.returncode != 1 or "not the file" not in p.stderr or os.path.exists(o):
    fail.append("q.gltf with q.bin changed: rc %d, %s" % (p.returncode, p.stderr.strip()))

for f in fail:
    print("FAIL:", f)
sys.exit(1 if fail else 0)
