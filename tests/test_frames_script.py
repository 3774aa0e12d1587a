#!/usr/bin/python3
"""scripts/frames' scenes (issue 26): an unknown scene name is an error
(exit non-zero, naming it; it printed empty tables and exited 0), and a
scene may be the path of a mesh file (baked, its view set made by
vdsh-frames views, scored: a table row of its name and a --json document
that parses strictly), also when its file is named like a listed scene
(room.obj: its own view set, not docs/views/room's). Skips (77) when vdsh-view cannot render (no GL).

Usage: test_frames_script.py SCRIPTS_DIR BUILD_DIR WORK_DIR
"""
import json
import os
import shutil
import subprocess
import sys

import testlib

scripts, build, work = sys.argv[1:4]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
frames = os.path.join(scripts, "frames")
fails = []
check = testlib.checker(fails)


def no_duplicates(pairs):
    keys = [k for k, _ in pairs]
    if len(set(keys)) != len(keys):
        raise ValueError("duplicate keys in %s" % keys)
    return dict(pairs)


r = subprocess.run([frames, "--build", build, "--scenes", "room,nosuch"], capture_output=True,
                   text=True)
check(r.returncode != 0 and "unknown scene 'nosuch'" in r.stderr and "|" not in r.stdout,
      "an unknown scene: exit %d, stderr %r, stdout %r" % (r.returncode, r.stderr, r.stdout[:200]))

# A floor and a box: a mesh no list holds.
mesh = os.path.join(work, "floorbox.obj")
with open(mesh, "w") as f:
    f.write("v -4 0 -4\nv 4 0 -4\nv 4 0 4\nv -4 0 4\n"
            "v -1 0 -1\nv 1 0 -1\nv 1 2 -1\nv -1 2 -1\nv -1 0 1\nv 1 0 1\nv 1 2 1\nv -1 2 1\n"
            "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 9 11 10\nf 9 12 11\nf 5 8 12\nf 5 12 9\n"
            "f 6 10 11\nf 6 11 7\nf 8 7 11\nf 8 11 12\n")
probe = subprocess.run([os.path.join(build, "bake", "vdsh-bake"), mesh, "-q", "-o",
                        os.path.join(work, "probe.vdsh")], capture_output=True)
gl = probe.returncode == 0 and subprocess.run(
    [os.path.join(build, "runtime", "vdsh-view"), "--render", os.path.join(work, "probe.png"),
     "--size", "64x48", os.path.join(work, "probe.vdsh")], capture_output=True).returncode == 0
if gl:
    js = os.path.join(work, "floorbox.json")
    r = subprocess.run([frames, "--build", build, "--scenes", mesh, "--max-edge", "1",
                        "--cameras", "1", "--size", "128x96", "--json", js],
                       capture_output=True, text=True)
    check(r.returncode == 0 and "| floorbox |" in r.stdout,
          "a mesh path as the scene: exit %d, %r %r" % (r.returncode, r.stdout[:300], r.stderr))
    try:
        d = json.load(open(js), object_pairs_hook=no_duplicates)
        check(d["floorbox"]["default"]["vdsh5"]["0"]["frames"] > 0, "its scores in --json")
    except (OSError, ValueError, KeyError) as e:
        check(False, "--json: %s" % e)
    # The same mesh in a file named like a listed scene (room.obj): its own
    # view set, made with --cameras and --size, not docs/views/room's (which
    # it took, with --cameras and --size ignored, scoring the built-in room's
    # cameras on another mesh).
    os.makedirs(os.path.join(work, "named"), exist_ok=True)
    room = os.path.join(work, "named", "room.obj")
    shutil.copyfile(mesh, room)
    js2 = os.path.join(work, "named.json")
    r = subprocess.run([frames, "--build", build, "--scenes", room, "--max-edge", "1",
                        "--cameras", "1", "--size", "128x96", "--json", js2],
                       capture_output=True, text=True)
    try:
        d2 = json.load(open(js2), object_pairs_hook=no_duplicates)
        for k in ("0", "1"):
            got, want = (x["default"]["vdsh5"][k]["frames"] for x in (d2["room"], d["floorbox"]))
            check(got == want, "room.obj, light set %s: %d frames scored, %d for the same mesh "
                  "as floorbox.obj (a listed scene's view set?)" % (k, got, want))
    except (OSError, ValueError, KeyError, NameError) as e:
        check(False, "room.obj: exit %d, %s %r" % (r.returncode, e, r.stderr[-300:]))
if fails:
    sys.exit(1)
print("ok" if gl else "skipped the mesh path: no GL")
sys.exit(0 if gl else 77)
