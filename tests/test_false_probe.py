#!/usr/bin/python3
"""scripts/false_probe at its smallest: on scripts/frames_gap --keep's run
of validation room 3 at --max-edge 1, 64 x 48 frames, order 2, with a
`shadow` variant, the first frame of the default with false-shadow pixels
is probed: its numpy path must redraw every one of them in false shadow
(the C frame's runtime path, recomputed), the false pixels split by false
vertices must add up to the frame's count, and the per-view table must
list the three variants. A missing run is an error naming the file.

Usage: test_false_probe.py SCRIPTS_DIR BUILD_DIR WORK_DIR"""
import json
import os
import re
import shutil
import subprocess
import sys

scripts, build, work = sys.argv[1:4]
shutil.rmtree(work, ignore_errors=True)
r = subprocess.run([sys.executable, scripts + "/frames_gap", "--build", build, "--scenes",
                    "val-room-3", "--max-edge", "1", "--size", "64x48", "--orders", "2",
                    "--variant", "shadow=--method shadow", "--keep", work],
                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
if r.returncode:
    sys.exit("frames_gap failed (%d): %s" % (r.returncode, r.stderr))
with open(os.path.join(work, "val-room-3-default", "score.json")) as f:
    sets = [s for m in json.load(f)["modes"] if m["mode"] == "c-vdsh2" for s in m["sets"]]
frame = None
for s in sets:
    for pf in s["per_frame"]:
        if pf["false_area"] > 0:
            frame = (s["view"], s["set"], pf["light"])
            break
    if frame:
        break
if not frame:
    sys.exit("no frame of the default with false shadow to probe: %s" % sets)
r = subprocess.run([sys.executable, scripts + "/false_probe", work, "--scene", "val-room-3",
                    "--view", frame[0], "--set", str(frame[1]), "--light", str(frame[2]),
                    "--order", "2"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
if r.returncode:
    sys.exit("false_probe failed (%d): %s" % (r.returncode, r.stderr))
out = r.stdout
n = int(re.search(r"(\d+) drawn in false shadow \(", out).group(1))
m = re.search(r"recomputed at those pixels: (\d+) of (\d+)", out)
if not m or n == 0 or int(m.group(1)) != n or int(m.group(2)) != n:
    sys.exit("the runtime path, recomputed, does not redraw the %d false pixels:\n%s" % (n, out))
split = re.search(r"false vertices in their triangle \(0..3\): \[([\d, ]+)\]", out)
if not split or sum(int(x) for x in split.group(1).split(",")) != n:
    sys.exit("the split by false vertices does not add up to %d:\n%s" % (n, out))
for v in ("val-room-3-default", "val-room-3-paper", "val-room-3-shadow"):
    if not re.search("^%s " % v, out, re.M):
        sys.exit("per-view table lacks %s:\n%s" % (v, out))
r = subprocess.run([sys.executable, scripts + "/false_probe", work + "/none", "--scene",
                    "val-room-3", "--view", "v1"],
                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
if r.returncode == 0 or "none/val-room-3-default/s.vdsh" not in r.stderr:
    sys.exit("a missing run was not an error naming it: %d %s" % (r.returncode, r.stderr))
print("ok")
