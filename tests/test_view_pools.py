#!/usr/bin/python3
"""scripts/view_pools at its smallest: validation room 3 at --max-edge 1,
64 x 48 frames, order 2, two pools of one camera and the default view.
A variant with no arguments (the default's bake again) differs by 0 in
every pool, with the interval [0, 0]; --method shadow's differences are
its pooled figures minus the default's, their mean and t interval over
the two pools those of the rows (the interval holds the mean); the JSON
has a row per pool, order, light count and variant. An unknown scene, no
variant, a variant named default and a --level outside (0, 1) are errors
naming the problem.

Usage: test_view_pools.py SCRIPTS_DIR BUILD_DIR"""
import json
import math
import os
import subprocess
import sys
import tempfile

script, build = sys.argv[1] + "/view_pools", sys.argv[2]
base = [sys.executable, script, "--build", build, "--max-edge", "1", "--size", "64x48",
        "--orders", "2", "--cameras", "1", "--seeds", "2,3"]
with tempfile.TemporaryDirectory() as tmp:
    js = os.path.join(tmp, "out.json")
    r = subprocess.run(base + ["--scene", "val-room-3", "--variant", "same=",
                               "--variant", "shadow=--method shadow", "--json", js],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode:
        sys.exit("view_pools failed (%d): %s" % (r.returncode, r.stderr))
    with open(js) as f:
        out = json.load(f)
pools, ivs = out["pools"], out["intervals"]
if len(pools) != 2 * 2 * 2 or len(ivs) != 2 * 2:
    sys.exit("expected 8 pool rows and 4 intervals, got %d, %d" % (len(pools), len(ivs)))
if sorted({p["seed"] for p in pools}) != [2, 3] or any(p["views"] != 2 for p in pools):
    sys.exit("pools are not seeds 2, 3 of 2 views: %s" % pools)
for p in pools:
    d, v, ref = p["diff"], p["value"], p["default"]
    if p["variant"] == "same":
        if any(d[k] != 0 for k in d) or v != ref:
            sys.exit("the default's bake again differs from the default: %s" % p)
        continue
    want = dict(rmse=100 * (v["rmse"] / ref["rmse"] - 1),
                recall=100 * (v["recall"] - ref["recall"]),
                false=100 * (v["false"] - ref["false"]))
    for k in want:
        if not math.isclose(d[k], want[k], rel_tol=1e-9, abs_tol=1e-12) and \
                not (math.isnan(d[k]) and math.isnan(want[k])):
            sys.exit("%s: diff %r is not variant minus default %r" % (k, d[k], want[k]))
    if not 0 < ref["rmse"] < 1 or not 0 < v["rmse"] < 1:
        sys.exit("RMSE out of range: %s" % p)
for iv in ivs:
    rows = [p["diff"] for p in pools if p["variant"] == iv["variant"] and
            p["order"] == iv["order"] and p["lights"] == iv["lights"]]
    for k in ("rmse", "recall", "false"):
        xs, c = [x[k] for x in rows], iv[k]
        if any(math.isnan(x) for x in xs):
            continue
        m = sum(xs) / 2
        # Two pools: t with 1 degree of freedom, the Cauchy quantile.
        h = math.tan(math.pi * 0.475) * abs(xs[0] - xs[1]) / 2
        if iv["variant"] == "same" and (c["mean"], c["low"], c["high"]) != (0, 0, 0):
            sys.exit("same: interval is not [0, 0]: %s" % iv)
        if not (math.isclose(c["mean"], m, abs_tol=1e-9)
                and math.isclose(c["low"], m - h, abs_tol=1e-6)
                and math.isclose(c["high"], m + h, abs_tol=1e-6)
                and c["low"] <= c["mean"] <= c["high"]):
            sys.exit("%s %s: interval %s is not the t interval of %s" % (iv["variant"], k, c, xs))
for args, word in ((["--scene", "no-such-scene", "--variant", "a=--rays 64"], "no-such-scene"),
                   (["--scene", "val-room-3"], "--variant"),
                   (["--scene", "val-room-3", "--variant", "default=--rays 64"], "default"),
                   (["--scene", "val-room-3", "--variant", "a=", "--level", "1.5"], "--level")):
    r = subprocess.run(base + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode == 0 or word not in r.stderr:
        sys.exit("%s was not an error naming %s: %d %s" % (args, word, r.returncode, r.stderr))
print("ok")
