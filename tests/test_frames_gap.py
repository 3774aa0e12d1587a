#!/usr/bin/python3
"""scripts/frames_gap at its smallest: validation room 3 at --max-edge 1,
64 x 48 frames, order 2, with a `shadow` variant. The paper's rows are
1.00 against themselves, shadow's recall 1.00 against itself; every row's
split of the squared error adds up to 100% (the script itself checks the
split against vdsh-frames score's RMSE); an unknown scene is an error
naming it; a validation mesh runs by its view set's name (val-spider at
64 x 48, where assimp's spider is installed); --against 2 with order 3
gives the paper's rows at order 2 (1.00) and the default's at 3, over the
paper's order-2 RMSE; an order outside 1..16 is an error.

Usage: test_frames_gap.py SCRIPTS_DIR BUILD_DIR"""
import os
import subprocess
import sys

script, build = sys.argv[1] + "/frames_gap", sys.argv[2]
sys.path.insert(0, sys.argv[1])
import vdsh_scenes  # noqa: E402
r = subprocess.run([sys.executable, script, "--build", build, "--scenes", "val-room-3",
                    "--max-edge", "1", "--size", "64x48", "--orders", "2",
                    "--variant", "shadow=--method shadow"],
                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
if r.returncode:
    sys.exit("frames_gap failed (%d): %s" % (r.returncode, r.stderr))
rows = [l.split("|")[1:-1] for l in r.stdout.splitlines() if l.startswith("| val-room-3")]
if len(rows) != 6:
    sys.exit("expected 6 rows (paper, default, shadow x 1, 3 lights), got:\n" + r.stdout)
for row in rows:
    c = [x.strip() for x in row]
    parts = [float(x.rstrip("%")) for x in c[9].split(",")]
    if abs(sum(parts) - 100) > 1.5:
        sys.exit("split does not add up to 100%%: %s" % c)
    if c[1] == "paper" and (c[5] != "1.00" or c[8] != "1.00"):
        sys.exit("paper against itself is not 1.00: %s" % c)
    if c[1] == "shadow" and c[10] != ("-" if c[6] == "0.0%" else "1.00"):
        sys.exit("shadow's recall against itself is not 1.00: %s" % c)
    if c[1] == "default" and c[10] != "-" and float(c[10]) <= 0:
        sys.exit("recall over shadow's out of range: %s" % c)
    if not 0 < float(c[4]) < 1:
        sys.exit("RMSE out of range: %s" % c)
# --against: the paper baked at order 2 alone (its rows at order 2, 1.00),
# the default at order 3, its ratio over the paper's order-2 RMSE.
r = subprocess.run([sys.executable, script, "--build", build, "--scenes", "val-room-3",
                    "--max-edge", "1", "--size", "64x48", "--orders", "3", "--against", "2"],
                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
if r.returncode:
    sys.exit("frames_gap --against failed (%d): %s" % (r.returncode, r.stderr))
rows = [[x.strip() for x in l.split("|")[1:-1]] for l in r.stdout.splitlines()
        if l.startswith("| val-room-3")]
if [(c[1], c[2], c[3]) for c in rows] != [("paper", "2", "1"), ("paper", "2", "3"),
                                          ("default", "3", "1"), ("default", "3", "3")]:
    sys.exit("--against 2: expected the paper at order 2, the default at 3:\n" + r.stdout)
if "/ paper's order 2" not in r.stdout:
    sys.exit("--against 2: the header does not name the paper's order:\n" + r.stdout)
for paper, c in zip(rows[:2], rows[2:]):
    if paper[5] != "1.00" or paper[8] != "1.00":
        sys.exit("--against: paper against itself is not 1.00: %s" % paper)
    ratio = float(c[4]) / float(paper[4])
    if abs(ratio - float(c[5])) > 0.01 + 0.0006 / float(paper[4]) * ratio:
        sys.exit("--against: %s / %s is not %s" % (c[4], paper[4], c[5]))
for bad in ("0", "17"):
    r = subprocess.run([sys.executable, script, "--build", build, "--scenes", "val-room-3",
                        "--against", bad], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       text=True)
    if r.returncode == 0 or "--against" not in r.stderr:
        sys.exit("--against %s was not an error naming it: %s" % (bad, r.stderr))
r = subprocess.run([sys.executable, script, "--build", build, "--scenes", "no-such-scene"],
                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
if r.returncode == 0 or "no-such-scene" not in r.stderr:
    sys.exit("an unknown scene was not an error naming it: %d %s" % (r.returncode, r.stderr))
# A validation mesh by its view set's name (val-spider: assimp's spider at
# its own vertices, the smallest), where the mesh is installed.
if os.path.exists(vdsh_scenes.by_name(vdsh_scenes.MESHES)["spider"][0]):
    r = subprocess.run([sys.executable, script, "--build", build, "--scenes", "val-spider",
                        "--size", "64x48", "--orders", "2"],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    rows = [l.split("|")[1:-1] for l in r.stdout.splitlines() if l.startswith("| val-spider")]
    if r.returncode or len(rows) != 4:
        sys.exit("val-spider: expected 4 rows (%d): %s %s" % (r.returncode, r.stdout, r.stderr))
    for row in rows:
        c = [x.strip() for x in row]
        if c[1] == "paper" and c[5] != "1.00":
            sys.exit("val-spider: paper against itself is not 1.00: %s" % c)
        if c[10] != "-":
            sys.exit("val-spider: a recall over shadow's without a shadow variant: %s" % c)
print("ok")
