#!/usr/bin/python3
"""Where the lights go (vdsh-bake --light-region SPEC; issue 25, docs/
ACCURACY.md "Where your lights go"), on a unit cube on a 4 x 4 floor
(tests/data/cube_floor.obj: its bounds are as high as the cube):

- bad SPECs are refused naming --light-region (exit 2, no file); a box
  with no free space (inside the cube) is refused (exit 1, no file);
- `auto` is the default: the same bytes as no option, and no `lreg`;
- `grown` and a box are recorded in an `lreg` chunk that the C reader
  (vdsh-info, text and --json) and the Python reader give back: grown
  is the bounds grown by a quarter of their diagonal, a box as given;
- a box beyond 1.5 x the clamp from the bounds is baked with a warning
  naming --max-distance (grown never is);
- the same bytes on 1 and 2 threads; two shards merged are the whole
  bake's bytes; parts with other regions are refused by vdsh-merge;
- a damaged lreg (rule 3, min >= max, reserved byte) is refused by the C
  and Python readers;
- vdsh-eval's uniform lights go where the file says (in the grown box,
  some above the cube), `--light-region auto` puts them back in the
  bounds;
- per sample, under lights around the object (--light-rule grown), the
  grown-region bake's interior false shadows at orders 3 and 5 are below
  the default bake's.

Usage: test_light_region.py VDSH_BAKE VDSH_EVAL VDSH_MERGE VDSH_INFO SOURCE_DIR WORK_DIR
"""
import json
import os
import struct
import subprocess
import sys

bake, ev, merge, info, src, work = sys.argv[1:7]
sys.path.insert(0, os.path.join(src, "python"))
import vdsh  # noqa: E402
from testlib import chunks, fix_crc  # noqa: E402

os.makedirs(work, exist_ok=True)
OBJ = os.path.join(src, "tests", "data", "cube_floor.obj")
BASE = [OBJ, "--max-edge", "0.1", "--rays", "64", "--cube-size", "0", "-q"]
fail = []


def path(name):
    return os.path.join(work, name)


def run_bake(out, extra):
    if os.path.exists(path(out)):
        os.unlink(path(out))
    return subprocess.run([bake] + BASE + extra + ["-o", path(out)], capture_output=True,
                          text=True)


def must(r, what):
    if r.returncode:
        sys.exit("%s failed (exit %d): %s" % (what, r.returncode, r.stderr))
    return r


def blob(name):
    with open(path(name), "rb") as f:
        return f.read()


# 1. Bad values: exit 2, the message names the option, no file.
for spec in ("up", "", "1,2,3", "0,0,0,1,1", "0,0,0,1,1,1,1", "0,0,0,0,1,1", "0,2,0,1,1,1",
             "nan,0,0,1,1,1", "0,0,0,1,1,inf", "0,0,0,1e39,1,1", "x,0,0,1,1,1"):
    r = run_bake("bad.vdsh", ["--light-region", spec])
    if r.returncode != 2 or "--light-region" not in r.stderr or os.path.exists(path("bad.vdsh")):
        fail.append("--light-region %r: exit %d, stderr %r" % (spec, r.returncode, r.stderr))
# a box inside the closed cube: no free space there
r = run_bake("bad.vdsh", ["--light-region", "-0.3,0.2,-0.3,0.3,0.8,0.3"])
if r.returncode != 1 or "--light-region" not in r.stderr or "free space" not in r.stderr or \
        os.path.exists(path("bad.vdsh")):
    fail.append("a box inside the cube: exit %d, stderr %r" % (r.returncode, r.stderr))

# 2. auto is the default, byte for byte, and writes no lreg.
must(run_bake("default.vdsh", []), "default bake")
must(run_bake("auto.vdsh", ["--light-region", "auto"]), "auto bake")
if blob("default.vdsh") != blob("auto.vdsh"):
    fail.append("--light-region auto is not the default's bytes")
if any(c[1] == b"lreg" for c in chunks(blob("default.vdsh"))):
    fail.append("a default bake writes lreg")
if vdsh.read(path("default.vdsh")).light_region is not None:
    fail.append("the Python reader finds a light region in a default bake")

# 3. grown and a box: recorded, read back by both readers.
must(run_bake("grown.vdsh", ["--light-region", "grown", "--threads", "1"]), "grown bake")
must(run_bake("grown2.vdsh", ["--light-region", "grown", "--threads", "2"]), "grown bake, 2")
if blob("grown.vdsh") != blob("grown2.vdsh"):
    fail.append("--light-region grown: 1 and 2 threads differ")
if blob("grown.vdsh") == blob("default.vdsh"):
    fail.append("--light-region grown changed nothing")
f = vdsh.read(path("grown.vdsh"))
lo, hi = f.header["bounds_min"], f.header["bounds_max"]
g = 0.25 * sum((b - a) ** 2 for a, b in zip(lo, hi)) ** 0.5
lr = f.light_region
# grown on every side but the floor's: below the open floor (one-sided,
# spanning the bounds) lights light nothing (vdsh_light_grown_box)
want_lo = [lo[0] - g, lo[1], lo[2] - g]
if not lr or lr["rule"] != "grown" or \
        any(abs(lr["min"][k] - want_lo[k]) > 1e-5 or abs(lr["max"][k] - (hi[k] + g)) > 1e-5
            for k in range(3)):
    fail.append("grown: the Python reader's light region %r (bounds %r..%r)" % (lr, lo, hi))
r = must(subprocess.run([info, path("grown.vdsh")], capture_output=True, text=True), "info")
if "region grown" not in r.stdout:
    fail.append("vdsh-info does not show the grown region: %r" % r.stdout)
must(subprocess.run([info, path("grown.vdsh"), "--json", path("grown.info.json")],
                    capture_output=True, text=True), "info --json")
with open(path("grown.info.json")) as fh:
    jr = json.load(fh).get("light_region")
f32 = lambda xs: [struct.unpack("<f", struct.pack("<f", x))[0] for x in xs]  # noqa: E731
if not jr or jr["rule"] != "grown" or f32(jr["min"]) != lr["min"] or f32(jr["max"]) != lr["max"]:
    fail.append("vdsh-info --json's light_region %r, the Python reader's %r" % (jr, lr))
BOX = "-1.5,0,-1.5,1.5,2.5,1.5"
must(run_bake("box.vdsh", ["--light-region", BOX]), "box bake")
lr = vdsh.read(path("box.vdsh")).light_region
if not lr or lr["rule"] != "box" or lr["min"] != [-1.5, 0, -1.5] or lr["max"] != [1.5, 2.5, 1.5]:
    fail.append("box: the Python reader's light region %r" % lr)

# a box out of the clamp's reach is baked, with a warning naming
# --max-distance; grown never is (at most 1.43 diagonals from the bounds)
for spec, warned in (("5,5,5,6,6,6", True), ("grown", False)):
    r = subprocess.run([bake] + [a for a in BASE if a != "-q"] +
                       ["--light-region", spec, "-o", path("far.vdsh")], capture_output=True,
                       text=True)
    said = "warning" in r.stderr and "--max-distance" in r.stderr
    if r.returncode or said != warned:
        fail.append("--light-region %s: exit %d, warned %s: %r" % (spec, r.returncode, said,
                                                                  r.stderr))

# 4. Shards: merged, the whole bake's bytes; other regions refused.
for i in (0, 1):
    must(run_bake("s%d.vdsh" % i, ["--light-region", "grown", "--shard", "%d/2" % i]),
         "shard %d" % i)
must(subprocess.run([merge, "-q", path("s0.vdsh"), path("s1.vdsh"), "-o", path("merged.vdsh")],
                    capture_output=True, text=True), "merge")
if blob("merged.vdsh") != blob("grown.vdsh"):
    fail.append("two grown shards merged are not the whole grown bake's bytes")
must(run_bake("a1.vdsh", ["--shard", "1/2"]), "auto shard 1")
r = subprocess.run([merge, "-q", path("s0.vdsh"), path("a1.vdsh"), "-o", path("mix.vdsh")],
                   capture_output=True, text=True)
if r.returncode == 0 or "a1.vdsh" not in r.stderr or "--light-region" not in r.stderr or \
        os.path.exists(path("mix.vdsh")):
    fail.append("parts with other regions: exit %d, stderr %r" % (r.returncode, r.stderr))


# 5. A damaged lreg: refused by both readers.
def refused(name, data, words):
    with open(path(name), "wb") as fh:
        fh.write(data)
    r = subprocess.run([info, path(name)], capture_output=True, text=True)
    if r.returncode == 0 or not all(w in r.stderr for w in words):
        fail.append("%s: vdsh-info exit %d, stderr %r" % (name, r.returncode, r.stderr))
    try:
        vdsh.read(path(name))
        fail.append("%s: the Python reader accepts it" % name)
    except vdsh.VdshError as e:
        if "lreg" not in str(e):
            fail.append("%s: the Python reader says %r" % (name, str(e)))


d = blob("grown.vdsh")
off, _, size = next(c for c in chunks(d) if c[1] == b"lreg")
for name, at, fmt, value in (("rule3", 0, "<I", 3), ("minmax", 4, "<f", 1e9),
                             ("reserved", 28, "<I", 1)):
    bad = bytearray(d)
    struct.pack_into(fmt, bad, off + 16 + at, value)
    fix_crc(bad, off, size)
    refused("lreg-%s.vdsh" % name, bad, ["lreg"])


# 6. vdsh-eval: uniform lights where the file says, or in the bounds.
def evaluate(name, extra):
    out = path(name + ".json")
    must(subprocess.run([ev, path(name), "-q", "--json", out, "--points", "3000", "--interior",
                         "3000", "--seed", "202"] + extra, capture_output=True, text=True),
         "eval %s %s" % (name, extra))
    with open(out) as fh:
        return json.load(fh)


j = evaluate("grown.vdsh", [])
ps = j["eval"]["scene_light_positions"]
if j["eval"].get("scene_light_region") != "given" or \
        any(not all(want_lo[k] - 1e-5 <= p[k] <= hi[k] + g + 1e-5 for k in range(3)) for p in ps) \
        or not any(p[1] > hi[1] for p in ps):
    fail.append("eval of the grown bake: lights %r, region %r" %
                (ps[:4], j["eval"].get("scene_light_region")))
# none below the open floor (one in six stood there: they lit nothing),
# under vdsh-eval's own --light-region grown and its --light-rule grown too,
# and the rules outside the bounds, around and shell (their lights below
# the floor were 13 and 5 of 32 here: the floor closes that side)
for extra in (["--light-region", "grown"], ["--light-rule", "grown"],
              ["--light-rule", "around"], ["--light-rule", "shell"]):
    below = [p for p in evaluate("grown.vdsh", extra)["eval"]["scene_light_positions"]
             if p[1] < lo[1]]
    if below:
        fail.append("eval %s: %d lights below the open floor, e.g. %r" % (extra, len(below),
                                                                        below[0]))
j = evaluate("grown.vdsh", ["--light-region", "auto"])
ps = j["eval"]["scene_light_positions"]
if "scene_light_region" in j["eval"] or \
        any(not all(lo[k] <= p[k] <= hi[k] for k in range(3)) for p in ps):
    fail.append("eval --light-region auto: lights outside the bounds %r" % ps[:4])
r = subprocess.run([ev, path("grown.vdsh"), "-q", "--light-region", "0,0,0,0,1,1"],
                   capture_output=True, text=True)
if r.returncode != 2 or "--light-region" not in r.stderr:
    fail.append("vdsh-eval --light-region with x 0..0: exit %d, %r" % (r.returncode, r.stderr))

# 7. Under lights around the object, the grown region's false shadows fall.
false = {}
for name in ("default.vdsh", "grown.vdsh"):
    js = evaluate(name, ["--light-rule", "grown"])
    false[name] = {s["order"]: s["scene_lights"]["interior"]["false_shadow"]
                   for s in js["streams"]}
for o in (3, 5):
    if not false["grown.vdsh"][o] < false["default.vdsh"][o]:
        fail.append("order %d: grown lights' false shadows %s" % (o, false))

if fail:
    sys.exit("FAIL:\n  " + "\n  ".join(fail))
print("ok", false)
