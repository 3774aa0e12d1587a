"""test_gltf_input.py VDSH_BAKE WORKDIR ASSIMP_MODELS [VDSH_EVAL VDSH_INFO] - glTF 2.0 input.

The hand-written fixtures (gltf_fixtures.py: lists, strips, fans, sparse
accessors, node matrices and TRS, a mirroring scale, points and lines
skipped, morph targets (base pose) and skins (bind pose) baked; refused
files) loaded as .gltf and .glb through
`vdsh-bake FILE --export-obj OUT`: the triangles written must be the
expected ones (positions, winding); refused files fail with a message
naming the file, never by a signal. Then Debian's assimp-testmodels glTF2
files: the valid ones load with their triangle counts (primitive modes
4-6, strips and fans, give the quad of mode 4), the malformed ones are
refused with the file named (a mesh whose primitives is not an array and
a scene without nodes with that reason, not "empty mesh (no faces)").
"""
import json
import os
import struct
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gltf_fixtures  # noqa: E402

bake, work, models = sys.argv[1], sys.argv[2], sys.argv[3]
evaluate, info = (sys.argv[4], sys.argv[5]) if len(sys.argv) > 5 else (None, None)
os.makedirs(work, exist_ok=True)
failures = []


def load(path):
    out = os.path.join(work, "out.obj")
    if os.path.exists(out):
        os.remove(out)
    p = subprocess.run([bake, path, "--export-obj", out], capture_output=True, text=True)
    if p.returncode < 0 or p.returncode >= 128:
        failures.append("%s: killed by a signal (%d)" % (path, p.returncode))
        return None, p
    if p.returncode != 0:
        return None, p
    vs, tris = [], []
    for line in open(out):
        f = line.split()
        if f and f[0] == "v":
            vs.append(tuple(float(x) for x in f[1:4]))
        elif f and f[0] == "f":
            tris.append(tuple(vs[int(c.split("/")[0]) - 1] for c in f[1:4]))
    return tris, p


def same(t, e):
    for r in range(3):
        rot = e[r:] + e[:r]
        if all(abs(a - b) < 1e-5 for p, q in zip(t, rot) for a, b in zip(p, q)):
            return True
    return False


def refused(path, p):
    if p.returncode in (0,) or p.returncode >= 128 or p.returncode < 0:
        failures.append("%s: expected a refusal, got rc %d" % (path, p.returncode))
    elif path not in p.stderr:
        failures.append("%s: the message does not name the file: %s" % (path, p.stderr.strip()))


for name, g, binary, expected in gltf_fixtures.fixtures():
    for ext, data in (("gltf", gltf_fixtures.as_gltf(g, binary)), ("glb", gltf_fixtures.as_glb(g, binary))):
        path = os.path.join(work, "%s.%s" % (name, ext))
        open(path, "wb").write(data)
        tris, p = load(path)
        if expected is None:
            refused(path, p)
            continue
        if tris is None:
            failures.append("%s: refused: %s" % (path, p.stderr.strip()))
            continue
        if len(tris) != len(expected) or not all(same(t, e) for t, e in zip(tris, expected)):
            failures.append("%s: triangles %s, expected %s" % (path, tris, expected))
        if name == "points_lines" and "2 glTF primitives of points or lines skipped" not in p.stderr:
            failures.append("%s: skipped primitives not reported: %s" % (path, p.stderr.strip()))
        if name == "morph" and "1 glTF primitive with morph targets baked in the base pose" not in p.stderr:
            failures.append("%s: ignored morph targets not reported: %s" % (path, p.stderr.strip()))
        if name == "skinned" and "1 glTF primitive of skinned nodes baked in the bind pose" not in p.stderr:
            failures.append("%s: bind pose not reported: %s" % (path, p.stderr.strip()))

# External images are never read (the baker does not use them): a .gltf
# naming a 256 MiB image file (sparse) beside its external buffer loads
# with a peak RSS far below the image's size (tinygltf read every image
# file into memory before the no-op image loader saw it: ~800 MB peak).
name, g, binary, expected = gltf_fixtures.fixtures()[0]
d = os.path.join(work, "bigimage")
os.makedirs(d, exist_ok=True)
gi = json.loads(json.dumps(g))
gi["buffers"][0]["uri"] = "quad.bin"
gi["images"] = [{"uri": "big%20texture.png"}]
gi["textures"] = [{"source": 0}]
gi["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
gi["meshes"][0]["primitives"][0]["material"] = 0
open(os.path.join(d, "quad.bin"), "wb").write(binary)
with open(os.path.join(d, "big texture.png"), "wb") as f:
    f.truncate(256 << 20)
path = os.path.join(d, "bigimage.gltf")
open(path, "w").write(json.dumps(gi))
out = os.path.join(work, "out.obj")
proc = subprocess.Popen([bake, path, "--export-obj", out], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
_, status, usage = os.wait4(proc.pid, 0)
proc.returncode = os.waitstatus_to_exitcode(status)
err = proc.stderr.read().decode()
if proc.returncode != 0:
    failures.append("%s: rc %d: %s" % (path, proc.returncode, err.strip()))
elif usage.ru_maxrss > 128 * 1024:
    failures.append("%s: peak RSS %d KiB: the 256 MiB image file was read" % (path, usage.ru_maxrss))
else:
    tris, p = load(path)
    if tris is None or len(tris) != len(expected) or not all(same(t, e) for t, e in zip(tris, expected)):
        failures.append("%s: triangles %s, expected %s" % (path, tris, expected))
os.remove(os.path.join(d, "big texture.png"))

# A .gltf source's recorded SHA-256 and size cover its external buffers
# (formats/VDSH.md, SRCS: the file's bytes, then each external buffer's):
# vdsh-eval refuses the source once its .bin changed, even when the counts
# are the same (the hash was the .gltf's alone: a moved vertex passed).
if evaluate:
    import hashlib
    d = os.path.join(work, "hashbin")
    os.makedirs(d, exist_ok=True)
    gi = json.loads(json.dumps(g))
    gi["buffers"][0]["uri"] = "quad.bin"
    path, vd = os.path.join(d, "quad.gltf"), os.path.join(d, "quad.vdsh")
    text = json.dumps(gi).encode()
    open(path, "wb").write(text)
    open(os.path.join(d, "quad.bin"), "wb").write(binary)
    p = subprocess.run([bake, path, "-o", vd, "-q", "--rays", "16", "--orders", "2", "--cube-size", "0"],
                       capture_output=True, text=True)
    if p.returncode != 0:
        failures.append("%s: bake rc %d: %s" % (path, p.returncode, p.stderr.strip()))
    else:
        q = subprocess.run([info, "--json", "-", vd], capture_output=True, text=True)
        srcs = json.loads(q.stdout)["sources"] if q.returncode == 0 else []
        want = hashlib.sha256(text + bytes(binary)).hexdigest()
        if len(srcs) != 1 or srcs[0]["sha256"] != want or srcs[0]["size"] != len(text) + len(binary):
            failures.append("%s: recorded %s, want size %d, sha256 %s (JSON then .bin)"
                            % (vd, srcs, len(text) + len(binary), want))
        ev = [evaluate, vd, path, "-q", "--points", "4", "--interior", "0", "--lights", "2",
              "--directions", "2", "--threads", "1"]
        p = subprocess.run(ev, capture_output=True, text=True)
        if p.returncode != 0:
            failures.append("%s: vdsh-eval of the unchanged source: rc %d: %s" % (vd, p.returncode, p.stderr.strip()))
        moved = bytearray(binary)
        moved[0:4] = struct.pack("<f", 0.5)  # vertex 0's x: same counts, same bounds
        open(os.path.join(d, "quad.bin"), "wb").write(moved)
        p = subprocess.run(ev, capture_output=True, text=True)
        if p.returncode == 0 or "is not the mesh the bake used" not in p.stderr:
            failures.append("%s: vdsh-eval with a changed .bin: rc %d: %s" % (vd, p.returncode, p.stderr.strip()))

# The container is known by its bytes, not the name: a .glb named .gltf
# and a .gltf named .glb load (was a JSON parse error, "Invalid magic"),
# as vdsh-export --source reads them.
name, g, binary, expected = gltf_fixtures.fixtures()[0]
for ext, data in (("gltf", gltf_fixtures.as_glb(g, binary)), ("glb", gltf_fixtures.as_gltf(g, binary))):
    path = os.path.join(work, "swapped.%s" % ext)
    open(path, "wb").write(data)
    tris, p = load(path)
    if tris is None or len(tris) != len(expected):
        failures.append("%s: %s" % (path, p.stderr.strip()))

# A node chain deeper than the reader goes (1000) is refused as such, not
# as "a cycle in the node tree" (it has none).
name, g, binary, expected = gltf_fixtures.fixtures()[0]
g = json.loads(json.dumps(g))
g["nodes"] = [{"children": [i + 1]} for i in range(1100)] + [{"mesh": 0}]
path = os.path.join(work, "deep.glb")
open(path, "wb").write(gltf_fixtures.as_glb(g, binary))
tris, p = load(path)
refused(path, p)
if "cycle" in p.stderr or "deeper" not in p.stderr:
    failures.append("%s: %s" % (path, p.stderr.strip()))

# External buffers are read beside the .gltf only, and only regular files:
# a buffer missing there is refused even when the current directory has
# one of that name (tinygltf looked there too and loaded it), a FIFO is
# refused at once (it waited for a writer forever), a directory as such
# (was "out of memory while reading").
name, g, binary, expected = gltf_fixtures.fixtures()[0]
ext_dir = os.path.join(work, "external")
os.makedirs(os.path.join(ext_dir, "models"), exist_ok=True)
g = json.loads(json.dumps(g))
for case, what in (("elsewhere", "File not found"), ("fifo", "not a regular file"), ("dir", "not a regular file")):
    g["buffers"][0]["uri"] = case + ".bin"
    path = os.path.join(ext_dir, "models", case + ".gltf")
    open(path, "w").write(json.dumps(g))
    target = os.path.join(ext_dir, "models", case + ".bin")
    if case == "elsewhere":
        open(os.path.join(ext_dir, case + ".bin"), "wb").write(bytes(binary))
    elif case == "fifo" and not os.path.exists(target):
        os.mkfifo(target)
    elif case == "dir":
        os.makedirs(target, exist_ok=True)
    try:
        p = subprocess.run([bake, os.path.join("models", case + ".gltf"), "--export-obj", "out.obj"], cwd=ext_dir,
                           capture_output=True, text=True, timeout=30)
        if p.returncode == 0 or what not in p.stderr:
            failures.append("%s: rc %d, %s (want '%s')" % (path, p.returncode, p.stderr.strip(), what))
    except subprocess.TimeoutExpired:
        failures.append("%s: still running after 30 s" % path)

# A file that requires an extension tinygltf refuses before its own list
# can be checked (vdsh-export --compress: EXT_meshopt_compression's fallback
# buffer has no data): the extension is named, not "Invalid byteLength".
import json  # noqa: E402
import struct  # noqa: E402
meshopt = {"asset": {"version": "2.0"}, "extensionsUsed": ["EXT_meshopt_compression"],
           "extensionsRequired": ["EXT_meshopt_compression"],
           "buffers": [{"byteLength": 64, "extensions": {"EXT_meshopt_compression": {"fallback": True}}}],
           "scenes": [{"nodes": []}], "scene": 0}
js = json.dumps(meshopt).encode()
js += b" " * (-len(js) % 4)
path = os.path.join(work, "meshopt-fallback.glb")
open(path, "wb").write(struct.pack("<III", 0x46546C67, 2, 20 + len(js)) + struct.pack("<II", len(js), 0x4E4F534A) + js)
tris, p = load(path)
refused(path, p)
if "requires the extension EXT_meshopt_compression" not in p.stderr:
    failures.append("%s: the required extension not named: %s" % (path, p.stderr.strip()))

# A triangle list whose count is not a multiple of 3 (invalid glTF; as
# assimp, the baker drops the last 1 or 2): said on stderr, not silently
# (indexed: 7 indices; not indexed: 4 vertices). One finding per list.
b = gltf_fixtures.Builder()
pos = b.acc(gltf_fixtures.QUAD)
ind = b.acc([0, 1, 2, 0, 2, 3, 1], gltf_fixtures.USHORT, "SCALAR")
g = b.gltf([{"primitives": [{"attributes": {"POSITION": pos}, "indices": ind}]},
            {"primitives": [{"attributes": {"POSITION": pos}}]}],
           [{"mesh": 0}, {"mesh": 1, "translation": [0, 0, 5]}], [0, 1])
for ext, data in (("gltf", gltf_fixtures.as_gltf(g, b.bin)), ("glb", gltf_fixtures.as_glb(g, b.bin))):
    path = os.path.join(work, "ragged.%s" % ext)
    open(path, "wb").write(data)
    tris, p = load(path)
    if tris is None or len(tris) != 3:
        failures.append("%s: expected 3 triangles, got %s (%s)" % (path, None if tris is None else len(tris),
                                                                 p.stderr.strip()))
    elif "2 glTF triangle lists with a count not a multiple of 3" not in p.stderr:
        failures.append("%s: the ignored indices not said: %s" % (path, p.stderr.strip()))

g2 = os.path.join(models, "glTF2")
if os.path.isdir(g2):
    gen = os.path.join(g2, "glTF-Asset-Generator", "Mesh_PrimitiveMode")
    good = {os.path.join(gen, "Mesh_PrimitiveMode_%02d.gltf" % i): 2 for i in (4, 5, 6, 11, 12, 13, 14, 15)}
    good[os.path.join(g2, "BoxTextured-glTF-Binary", "BoxTextured.glb")] = 12
    good[os.path.join(g2, "BoxTextured-glTF-Embedded", "BoxTextured.gltf")] = 12
    good[os.path.join(g2, "BoxTextured-glTF", "BoxTextured.gltf")] = 12
    good[os.path.join(g2, "cameras", "Cameras.gltf")] = 2
    # requires KHR_technique_webgl, which only affects materials (was refused)
    good[os.path.join(g2, "BoxTextured-glTF-techniqueWebGL", "BoxTextured.gltf")] = 12
    # morph targets: the base pose; skinned: the bind pose (were skipped,
    # then refused as empty)
    good[os.path.join(g2, "glTF-Sample-Models", "AnimatedMorphCube-glTF", "AnimatedMorphCube.gltf")] = 12
    good[os.path.join(g2, "simple_skin", "simple_skin.gltf")] = 8
    # two triangle lists of 35 (invalid): 11 triangles each, said on stderr
    good[os.path.join(g2, "IncorrectVertexArrays", "Cube.gltf")] = 46
    quad = None
    for path, n in sorted(good.items()):
        tris, p = load(path)
        if tris is None or len(tris) != n:
            failures.append("%s: expected %d triangles, got %s (%s)" % (path, n, None if tris is None else len(tris),
                                                                      p.stderr.strip()))
        elif "Mesh_PrimitiveMode" in path:
            area = sum(abs((t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1]))
                       for t in tris) / 2
            quad = quad if quad is not None else area
            if abs(area - quad) > 1e-5 or area <= 0:
                failures.append("%s: area %g, mode 4's %g" % (path, area, quad))
    bad = ["IndexOutOfRange/IndexOutOfRange.gltf", "IndexOutOfRange/AllIndicesOutOfRange.gltf",
           "MissingBin/BoxTextured.gltf", "RecursiveNodes/RecursiveNodes.gltf", "TestNoRootNode/NoScene.gltf",
           "BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb", "draco/2CylinderEngine.gltf",
           "glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_00.gltf"]
    for rel in bad:
        path = os.path.join(g2, rel)
        tris, p = load(path)
        refused(path, p)
    # No triangles, and the JSON says why (the bake said only "empty mesh
    # (no faces)"): a mesh whose primitives is not an array, a scene
    # without nodes.
    for rel, why in [("wrongTypes/badArray.gltf", '"primitives" is missing or not an array'),
                     ("TestNoRootNode/SceneWithoutNodes.gltf", "scene 0 has no nodes")]:
        path = os.path.join(g2, rel)
        tris, p = load(path)
        refused(path, p)
        if why not in p.stderr:
            failures.append("%s: the reason (%s) not given: %s" % (path, why, p.stderr.strip()))
    # glTF 1.0 (assimp-testmodels' glTF folder): refused as such, not as
    # "no scene" or "Invalid glTF binary".
    g1 = os.path.join(models, "glTF")
    for rel in ["BoxTextured-glTF/BoxTextured.gltf", "BoxTextured-glTF-Binary/BoxTextured.glb",
                "CesiumMilkTruck/CesiumMilkTruck.gltf"]:
        path = os.path.join(g1, rel)
        if os.path.exists(path):
            tris, p = load(path)
            refused(path, p)
            if "glTF 1.0" not in p.stderr:
                failures.append("%s: not said to be glTF 1.0: %s" % (path, p.stderr.strip()))
else:
    print("no %s: assimp-testmodels part skipped" % g2)

for f in failures:
    print("FAIL:", f)
sys.exit(1 if failures else 0)
