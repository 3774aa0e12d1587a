"""test_gltf_uri.py BAKE EXPORT WORKDIR - a glTF buffer URI names one file,
the same in vdsh-bake and vdsh-export --source (formats/vdsh_gltf_uri.h,
tinygltf's rule: '+' is a space, "%20" a space).

A quad whose buffer URI is "a%20b+c.bin": the file "a b c.bin" holds it,
and a decoy "a b+c.bin" (what a decoder keeping '+' reads) holds the quad
twice as large. The bake's receivers are the quad's (its --export-obj
within [0, 1]) and --source matches every one of its vertices. With
"a b c.bin" gone, both refuse, naming "a b c.bin", and write nothing. A
URI that decodes to a NUL byte ("a%00.bin", a file "a" beside it) is
refused by both, saying so (the baker read "a").
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


def quad_bin(scale):
    pos = struct.pack("<12f", *[scale * x for x in QUAD])
    return pos + struct.pack("<6H", 0, 1, 2, 0, 2, 3)


def gltf(uri):
    n = len(quad_bin(1))
    return {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                           "min": [0, 0, 0], "max": [1, 1, 0]},
                          {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}],
            "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                            {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
            "buffers": [{"uri": uri, "byteLength": n}]}


def write(name, data):
    with open(os.path.join(work, name), "wb") as fh:
        fh.write(data)


def run(cmd):
    return subprocess.run(cmd, capture_output=True, text=True)


def clean(*names):
    for n in names:
        p = os.path.join(work, n)
        if os.path.exists(p):
            os.remove(p)


src = os.path.join(work, "quad.gltf")
vd, obj, glb = (os.path.join(work, n) for n in ("quad.vdsh", "quad.obj", "quad.glb"))
write("quad.gltf", json.dumps(gltf("a%20b+c.bin")).encode())
write("a b c.bin", quad_bin(1))
write("a b+c.bin", quad_bin(2))
bake_args = ["-q", "--rays", "16", "--orders", "2", "--cube-size", "0"]

# Both read "a b c.bin".
clean("quad.vdsh", "quad.obj", "quad.glb")
p = run([bake, src, "--export-obj", obj])
if p.returncode != 0:
    fail.append("bake --export-obj: rc %d: %s" % (p.returncode, p.stderr.strip()))
else:
    vs = [[float(x) for x in ln.split()[1:4]] for ln in open(obj) if ln.startswith("v ")]
    if not vs or max(max(v) for v in vs) > 1.0:
        fail.append("bake read the decoy 'a b+c.bin': vertices up to %g" % max(max(v) for v in vs))
p = run([bake, src, "-o", vd] + bake_args)
if p.returncode != 0:
    fail.append("bake: rc %d: %s" % (p.returncode, p.stderr.strip()))
else:
    p = run([export, vd, "--source", src, "-o", glb, "-q"])
    if p.returncode != 0:
        fail.append("export --source: rc %d: %s" % (p.returncode, p.stderr.strip()))
    else:
        d = open(glb, "rb").read()
        g = json.loads(d[20:20 + struct.unpack_from("<I", d, 12)[0]])
        x = g["extensions"]["VDSH_visibility_distance"]
        if x["source_vertices_matched"] != 4 or x["source_vertices"] != 4:
            fail.append("export --source read another file than the bake: %s of %s vertices "
                        "matched, want 4" % (x["source_vertices_matched"], x["source_vertices"]))

# "a b c.bin" missing: both refuse, naming it (the decoy is still there).
clean("a b c.bin", "quad.glb", "never.vdsh")
never = os.path.join(work, "never.vdsh")
p = run([bake, src, "-o", never] + bake_args)
if p.returncode == 0 or "a b c.bin" not in p.stderr or os.path.exists(never):
    fail.append("bake, 'a b c.bin' missing: rc %d: %s" % (p.returncode, p.stderr.strip()))
if os.path.exists(vd):
    p = run([export, vd, "--source", src, "-o", glb])
    if p.returncode != 1 or "a b c.bin" not in p.stderr or os.path.exists(glb):
        fail.append("export --source, 'a b c.bin' missing: rc %d: %s" % (p.returncode, p.stderr.strip()))

# A URI decoding to a NUL byte: refused by both, saying so.
nul = os.path.join(work, "nul.gltf")
write("nul.gltf", json.dumps(gltf("a%00.bin")).encode())
write("a", quad_bin(1))
p = run([bake, nul, "-o", never] + bake_args)
if p.returncode == 0 or "NUL" not in p.stderr or "a%00.bin" not in p.stderr or os.path.exists(never):
    fail.append("bake, uri a%%00.bin: rc %d: %s" % (p.returncode, p.stderr.strip()))
if os.path.exists(vd):
    p = run([export, vd, "--source", nul, "-o", glb])
    if p.returncode != 1 or "NUL" not in p.stderr or "a%00.bin" not in p.stderr or os.path.exists(glb):
        fail.append("export --source, uri a%%00.bin: rc %d: %s" % (p.returncode, p.stderr.strip()))

for f in fail:
    print("FAIL:", f)
sys.exit(1 if fail else 0)
