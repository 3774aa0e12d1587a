#!/usr/bin/python3
"""scripts/mottling at its smallest: validation room 3 at --max-edge 1,
64 x 48 C frames, order 3, 400 rays. The first variant's noise is 0
against itself; a second bake with the same arguments gives the same row
(the bake is deterministic) with noise 0; every lit-pixel figure is in
its range; --png writes the strip; a test scene is refused by name.

Usage: test_mottling.py SCRIPTS_DIR BUILD_DIR OUT_DIR"""
import os
import shutil
import subprocess
import sys

script, build, out = sys.argv[1] + "/mottling", sys.argv[2], sys.argv[3]
shutil.rmtree(out, ignore_errors=True)
r = subprocess.run([sys.executable, script, "--build", build, "--scenes", "val-room-3",
                    "--max-edge", "1", "--size", "64x48", "--order", "3",
                    "--variant", "a=--rays 400", "--variant", "b=--rays 400",
                    "--variant", "s=--rays 400 --method shadow", "--png", out],
                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
if r.returncode:
    sys.exit("mottling failed (%d): %s" % (r.returncode, r.stderr))
rows = {}
for line in r.stdout.splitlines():
    if line.startswith("| val-room-3"):
        c = [x.strip() for x in line.split("|")[1:-1]]
        rows[c[1]] = c
if sorted(rows) != ["a", "b", "s"]:
    sys.exit("expected rows a, b, s, got:\n" + r.stdout)
# Columns: scene, variant, bake s, RMSE, recall, false area, blotches,
# deficit, dark, false (lit), rough, grad, noise.
if float(rows["a"][12]) != 0 or float(rows["b"][12]) != 0:
    sys.exit("a bake against itself or its twin is not noise 0: %s %s" % (rows["a"], rows["b"]))
if rows["a"][3:] != rows["b"][3:]:
    sys.exit("two bakes with the same arguments differ: %s %s" % (rows["a"], rows["b"]))
for c in rows.values():
    if not (0 < float(c[3]) < 1 and 0 <= float(c[7]) <= 1 and 0 <= float(c[10]) < 1
            and 0 <= float(c[11]) < 1):
        sys.exit("a figure out of range: %s" % c)
    if float(c[9].rstrip("%")) > float(c[8].rstrip("%")):
        sys.exit("more lit pixels below 0.5 than below 0.9: %s" % c)
if not os.path.getsize(os.path.join(out, "mottling-val-room-3.png")):
    sys.exit("no strip written")
r = subprocess.run([sys.executable, script, "--build", build, "--scenes", "room",
                    "--variant", "a="], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
if r.returncode == 0 or "'room'" not in r.stderr:
    sys.exit("a test scene was not refused by name: %d %s" % (r.returncode, r.stderr))
print("ok")
