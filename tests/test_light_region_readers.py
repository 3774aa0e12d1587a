#!/usr/bin/python3
"""The readers' --light-region (vdsh-frames views, vdsh-view), as
vdsh-eval's: file (the default: the bake's, its `lreg` chunk), auto, grown
or a box; one parser (tools/vt_cli.h, vt_opt_light_region) and, on the
bake side, one rule (bake/lib/scene.h, vb_scene_apply_light_region). On a
unit cube on a 4 x 4 floor (tests/data/cube_floor.obj) baked with
--light-region grown:

- vdsh-frames views: the eyes and lights of views v1.. in the file's
  region by default (some above the cube), in the bounds with auto, in a
  box given; bad SPECs exit 2 naming --light-region; truth and score take
  no --light-region (the view set holds the lights): exit 2;
- vdsh-view (skipped without GL): --light-region file is the default's
  bytes, and so are grown (the viewer's grown box, its probes against the
  drawn mesh, is the one the bake recorded) and the recorded box given as
  a box; auto draws other lights; bad SPECs exit 2 naming it.

Usage: test_light_region_readers.py VDSH_BAKE VDSH_FRAMES VDSH_VIEW SOURCE_DIR WORK_DIR
"""
import json
import os
import subprocess
import sys

bake, frames, view, src, work = sys.argv[1:6]
sys.path.insert(0, os.path.join(src, "python"))
import vdsh  # noqa: E402

os.makedirs(work, exist_ok=True)
OBJ = os.path.join(src, "tests", "data", "cube_floor.obj")
fail = []


def path(name):
    return os.path.join(work, name)


def run(args):
    return subprocess.run(args, capture_output=True, text=True)


def must(r, what):
    if r.returncode:
        sys.exit("%s failed (exit %d): %s" % (what, r.returncode, r.stderr))
    return r


grown = path("grown.vdsh")
must(run([bake, OBJ, "--max-edge", "0.25", "--rays", "16", "--cube-size", "0", "-q",
          "--light-region", "grown", "-o", grown]), "grown bake")
f = vdsh.read(grown)
lo, hi = f.header["bounds_min"], f.header["bounds_max"]
lr = f.light_region
BOX = [-1.5, 0.2, -1.5, 1.5, 2.5, 1.5]


def inside(p, a, b):
    return all(a[k] - 1e-4 <= p[k] <= b[k] + 1e-4 for k in range(3))


# 1. vdsh-frames views
def views(extra):
    out = path("v.json")
    must(run([frames, "views", grown, "-o", out, "--cameras", "4", "--size", "64x48", "-q"] +
             extra), "views %s" % extra)
    with open(out) as fh:
        vs = json.load(fh)["views"][1:]  # v1..: their eyes and lights by the region
    return [v["eye"] for v in vs] + [li[:3] for v in vs for s in v["light_sets"] for li in s]


for extra, a, b in (([], lr["min"], lr["max"]), (["--light-region", "file"], lr["min"], lr["max"]),
                    (["--light-region", "grown"], lr["min"], lr["max"]),
                    (["--light-region", "auto"], lo, hi),
                    (["--light-region", ",".join(map(str, BOX))], BOX[:3], BOX[3:])):
    ps = views(extra)
    out_of = [p for p in ps if not inside(p, a, b)]
    if out_of:
        fail.append("views %s: %d of %d eyes and lights outside %r..%r, e.g. %r" %
                    (extra, len(out_of), len(ps), a, b, out_of[0]))
    if not extra and not any(p[1] > hi[1] for p in ps):
        fail.append("views: none above the cube in the grown region")
for spec in ("up", "0,0,0,0,1,1", "1,2,3"):
    r = run([frames, "views", grown, "-o", path("bad.json"), "--light-region", spec])
    if r.returncode != 2 or "--light-region" not in r.stderr:
        fail.append("views --light-region %r: exit %d, %r" % (spec, r.returncode, r.stderr))
for sub in (["truth", grown, "--views", path("v.json"), "-o", path("t")],
            ["score", grown, "--views", path("v.json"), "--truth", path("t"), "--frames",
             path("t"), "--modes", "c-vdsh2"]):
    r = run([frames] + sub + ["--light-region", "auto"])
    if r.returncode != 2:
        fail.append("%s --light-region: exit %d (the view set holds the lights)" %
                    (sub[0], r.returncode))

# 2. vdsh-view: the lights by the image they draw
def render(name, extra):
    out = path(name + ".png")
    r = run([view, "-q", "--render", out, "--size", "96x72", "--lights", "4", grown] + extra)
    return r, out


r, base = render("file-default", [])
if r.returncode:
    print("vdsh-view cannot render here (exit %d): its part skipped: %s" %
          (r.returncode, r.stderr.strip()[:200]))
else:
    data = open(base, "rb").read()
    box = ",".join("%.9g" % v for v in lr["min"] + lr["max"])
    for name, extra, same in (("file", ["--light-region", "file"], True),
                              ("grown", ["--light-region", "grown"], True),
                              ("box", ["--light-region", box], True),
                              ("auto", ["--light-region", "auto"], False)):
        r, out = render(name, extra)
        if r.returncode or (open(out, "rb").read() == data) != same:
            fail.append("vdsh-view %s: exit %d, %s the default's image (want %s): %s" %
                        (extra, r.returncode, "same as" if not same else "not",
                         "the same" if same else "another", r.stderr.strip()[:200]))
    for spec in ("up", "0,0,0,0,1,1"):
        r = run([view, "-q", "--render", path("bad.png"), "--light-region", spec, grown])
        if r.returncode != 2 or "--light-region" not in r.stderr:
            fail.append("vdsh-view --light-region %r: exit %d, %r" % (spec, r.returncode,
                                                                     r.stderr))

if fail:
    sys.exit("FAIL:\n  " + "\n  ".join(fail))
print("ok")
