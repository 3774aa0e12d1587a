"""test_mesh_not_vdsh.py SRC_DIR WORK PROGRAM... - a mesh handed to a
program that reads a .vdsh (vdsh-view model.obj) is named for what it is,
with the bake that makes a .vdsh of it, by one rule in every reader: the C
reader (formats/vdsh_read.c: vdsh-info, vdsh-info --verify, vdsh-eval,
vdsh-frames, vdsh-export, vdsh-merge, vdsh-view) and the Python one
(`python -m vdsh info`). Every format vdsh-bake reads: PLY and glb by their
first bytes, .obj, .off, .stl and .gltf by the name's extension in any case
(those four were "not a .vdsh file (wrong magic)"). Each program: exit 1 and
the same text after "NAME: ". A PROGRAM is a path whose base name says which
(vdsh-view is left out where it is not built).
"""
import os
import shutil
import subprocess
import sys

src, work = sys.argv[1:3]
programs = sys.argv[3:]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
fail = []

HINT = "; bake it first: vdsh-bake MODEL -o MODEL.vdsh"
meshes = (
    ("box.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "a Wavefront OBJ mesh"),
    ("3DSMaxExport.STL", b"solid 3DSMaxExport\n  facet normal 0 0 1\n", "an STL mesh"),
    ("box.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "an OFF mesh"),
    ("box.gltf", b'{"asset": {"version": "2.0"}}\n', "a glTF mesh"),
    ("box.ply", b"ply\nformat ascii 1.0\nend_header\n", "a PLY mesh"),
    ("box.glb", b"glTF\2\0\0\0" + bytes(24), "a binary glTF mesh (.glb, as vdsh-export writes)"),
)


def command(program, path):
    out = os.path.join(work, "out")
    base = os.path.basename(program)
    if base == "python":
        return [sys.executable, "-m", "vdsh", "info", path]
    if base.startswith("vdsh-info"):
        return [program, path]
    if base.startswith("vdsh-eval"):
        return [program, path]
    if base.startswith("vdsh-frames"):
        return [program, "views", path, "-o", out + ".json"]
    if base.startswith("vdsh-export"):
        return [program, path, "-o", out + ".glb"]
    if base.startswith("vdsh-merge"):
        return [program, path, path, "-o", out + ".vdsh"]
    if base.startswith("vdsh-view"):
        return [program, "--render", out + ".png", path]
    raise SystemExit("unknown program " + program)


env = dict(os.environ, PYTHONPATH=os.path.join(src, "python"), PYTHONDONTWRITEBYTECODE="1")
runs = [(p, command(p, "X")) for p in programs + ["python"]]
runs.append((programs[0] + " --verify", [programs[0], "--verify", "X"]))
for name, data, what in meshes:
    path = os.path.join(work, name)
    with open(path, "wb") as f:
        f.write(data)
    want = "%s: not a .vdsh file: %s%s\n" % (path, what, HINT)
    for label, cmd in runs:
        cmd = [path if a == "X" else a for a in cmd]
        r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=60)
        lines = [ln for ln in r.stderr.splitlines(True) if path in ln]
        if r.returncode != 1 or len(lines) != 1 or not lines[0].endswith(want):
            fail.append("%s on %s: exit %d, %r (want %r)" % (label, name, r.returncode,
                                                             r.stderr[-300:], want))
    for ext in (".json", ".glb", ".vdsh", ".png"):
        if os.path.exists(os.path.join(work, "out" + ext)):
            fail.append("out%s written" % ext)

for f in fail:
    print("FAIL:", f)
print("%d programs x %d meshes, %d failures" % (len(runs), len(meshes), len(fail)))
sys.exit(1 if fail else 0)
