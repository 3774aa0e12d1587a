#!/usr/bin/python3
"""vdsh-bake --up-axis: a mesh whose up axis is not +y (z-up: STL, most CAD
and 3ds Max exports) is turned into y-up before anything else, and the file
records it (HEAD load_flags bits 1..3) for the tools that rebuild the
scene from the sources:

- the unit cube on its 4 x 4 floor (tests/data/cube_floor.obj) written
  z-up (and -z, x, -x, -y up) and baked with --up-axis naming that axis
  gives the y-up bake's receivers (positions, triangles, normals) and
  coefficients; baked without it, it lies on its side (bounds 4 high);
- the recorded sources are the z-up file itself (name, size, SHA-256);
- vdsh-info says the axis (text and --json up_axis), and so does
  `python -m vdsh info`;
- vdsh-eval on the z-up bake rebuilds the occluders turned the same way:
  its figures are the y-up bake's, to the digit; vdsh-frames views runs;
- --up-axis y gives the bytes of no option (the default bake unchanged);
  a bad axis is refused (exit 2, naming --up-axis), nothing written.

Usage: test_up_axis.py VDSH_BAKE VDSH_INFO VDSH_EVAL VDSH_FRAMES SOURCE_DIR WORK_DIR
"""
import hashlib
import json
import os
import shutil
import subprocess
import sys

bake, info, ev, frames, src, work = sys.argv[1:7]
sys.path.insert(0, os.path.join(src, "python"))
import numpy as np  # noqa: E402
import vdsh  # noqa: E402

shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
fail = []
OBJ = os.path.join(src, "tests", "data", "cube_floor.obj")
BASE = ["--max-edge", "0.25", "--rays", "64", "--cube-size", "0", "-q"]
# y-up (X, Y, Z) as the file of each up axis writes it: the inverse of the
# turn vdsh-bake makes (bake/lib/mesh.c, turn_up)
WRITE = {"z": lambda X, Y, Z: (X, -Z, Y), "-z": lambda X, Y, Z: (X, Z, -Y),
         "x": lambda X, Y, Z: (Y, -X, Z), "-x": lambda X, Y, Z: (-Y, X, Z),
         "-y": lambda X, Y, Z: (X, -Y, -Z)}


def path(name):
    return os.path.join(work, name)


def run(cmd):
    return subprocess.run(cmd, capture_output=True, text=True, timeout=600)


def must(cmd):
    r = run(cmd)
    if r.returncode:
        sys.exit("%s: exit %d: %s" % (" ".join(cmd), r.returncode, r.stderr))
    return r


def write_turned(axis, out):
    with open(OBJ) as fh, open(out, "w") as o:
        for line in fh:
            if line.startswith("v "):
                X, Y, Z = (float(t) for t in line.split()[1:4])
                line = "v %r %r %r\n" % tuple(v + 0.0 for v in WRITE[axis](X, Y, Z))
            o.write(line)


shutil.copy(OBJ, path("yup.obj"))
must([bake, path("yup.obj")] + BASE + ["-o", path("y.vdsh")])
must([bake, path("yup.obj")] + BASE + ["--up-axis", "y", "-o", path("y2.vdsh")])
if open(path("y.vdsh"), "rb").read() != open(path("y2.vdsh"), "rb").read():
    fail.append("--up-axis y: not the bytes of no option")
ref = vdsh.read(path("y.vdsh"))

for axis in WRITE:
    obj = path("up%s.obj" % axis)
    write_turned(axis, obj)
    out = path("up%s.vdsh" % axis)
    must([bake, obj] + BASE + ["--up-axis", axis, "-o", out])
    f = vdsh.read(out)
    h, hr = f.header, ref.header
    if not (np.array_equal(f.positions, ref.positions) and
            np.array_equal(f.triangles, ref.triangles) and
            np.abs(f.normals - ref.normals).max() <= 1e-6):
        fail.append("%s up: other receivers than the y-up bake's" % axis)
    if h["bounds_min"] != hr["bounds_min"] or h["bounds_max"] != hr["bounds_max"]:
        fail.append("%s up: bounds %r..%r, want %r..%r" % (axis, h["bounds_min"], h["bounds_max"],
                                                           hr["bounds_min"], hr["bounds_max"]))
    for s, t in zip(f.streams, ref.streams):
        if np.abs(vdsh.coefficients(s) - vdsh.coefficients(t)).max() > 1e-4:
            fail.append("%s up: order %d coefficients differ" % (axis, s["order"]))
    data = open(obj, "rb").read()
    srcs = f.sources
    if len(srcs) != 1 or srcs[0]["name"] != obj or srcs[0]["size"] != len(data) or \
            srcs[0]["sha256"] != hashlib.sha256(data).hexdigest():
        fail.append("%s up: sources %r are not the file" % (axis, srcs))
    want = (h["load_flags"] >> 1) & 7 == vdsh.UP_AXES.index(axis)
    r = run([info, out])
    if not want or "up axis %s (" % axis not in r.stdout:
        fail.append("%s up: load_flags %d, vdsh-info %r" % (axis, h["load_flags"], r.stdout[:600]))

# without the option it lies on its side: 4 high, not 1
must([bake, path("up-z.obj")] + BASE + ["-o", path("side.vdsh")])
side = vdsh.read(path("side.vdsh")).header
if side["bounds_max"][1] - side["bounds_min"][1] != 4.0:
    fail.append("z-up baked as it is: bounds %r..%r" % (side["bounds_min"], side["bounds_max"]))

j = json.loads(must([info, "--json", "-", path("upz.vdsh")]).stdout)
jy = json.loads(must([info, "--json", "-", path("y.vdsh")]).stdout)
env = dict(os.environ, PYTHONPATH=os.path.join(src, "python"), PYTHONDONTWRITEBYTECODE="1")
jp = json.loads(subprocess.run([sys.executable, "-m", "vdsh", "info", "--json", "-",
                                path("upz.vdsh")], capture_output=True, text=True, env=env).stdout
                or "{}")
if j["bake"].get("up_axis") != "z" or jy["bake"].get("up_axis") != "y" or \
        jp.get("bake", {}).get("up_axis") != "z":
    fail.append("up_axis in vdsh-info --json %r / %r, python %r" % (
        j["bake"].get("up_axis"), jy["bake"].get("up_axis"), jp.get("bake", {}).get("up_axis")))

# vdsh-eval rebuilds the occluders turned: the y-up bake's figures
EVAL = ["-q", "--points", "1500", "--interior", "1500", "--seed", "7"]
figs = []
for name in ("y.vdsh", "upz.vdsh"):
    must([ev, path(name)] + EVAL + ["--json", path(name + ".json")])
    e = json.load(open(path(name + ".json")))
    if e["bake"].get("up_axis") != ("y" if name == "y.vdsh" else "z"):
        fail.append("vdsh-eval --json %s: up_axis %r" % (name, e["bake"].get("up_axis")))
    figs.append([(s["order"], s["scene_lights"]["interior"]["shadow_mae"],
                  s["scene_lights"]["interior"]["false_shadow"]) for s in e["streams"]] +
                [e["eval"]["scene_light_positions"]])
if figs[0] != figs[1]:
    fail.append("vdsh-eval of the z-up bake: %r, the y-up one's %r" % (figs[1][:3], figs[0][:3]))
r = run([frames, "views", path("upz.vdsh"), "-o", path("views.json"), "--cameras", "2", "-q"])
if r.returncode or not os.path.exists(path("views.json")):
    fail.append("vdsh-frames views on the z-up bake: exit %d, %r" % (r.returncode, r.stderr[-400:]))

r = run([bake, path("yup.obj")] + BASE + ["--up-axis", "up", "-o", path("bad.vdsh")])
if r.returncode != 2 or "--up-axis" not in r.stderr or os.path.exists(path("bad.vdsh")):
    fail.append("--up-axis up: exit %d, %r" % (r.returncode, r.stderr))

for f in fail:
    print("FAIL:", f)
print("%d failures" % len(fail))
sys.exit(1 if fail else 0)
