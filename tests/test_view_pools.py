#!/usr/bin/python3
"""scripts/view_pools at its smallest: validation room 3 at --max-edge 1,
64 x 48 frames, order 2, two pools of one camera and the default view.
A variant with no arguments (the default's bake again) differs by 0 in
every pool, with the interval [0, 0]; --method shadow's differences are
its pooled figures minus the default's, their mean and t interval over
the two pools those of the rows (the interval holds the mean); the JSON
has a row per pool, order, light count and variant. An unknown scene, no
variant, a variant named default, a --level outside (0, 1) and a --base
vdsh-bake refuses are errors naming the problem. --combine of that run
and one with --base '--seed 2' gives each run's mean over pools, their t
interval and the default's drift; a run of other pools is refused,
naming its file.

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


def run(args, js):
    r = subprocess.run(base + args + ["--json", js], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, text=True)
    if r.returncode:
        sys.exit("view_pools %s failed (%d): %s" % (args, r.returncode, r.stderr))
    with open(js) as f:
        return json.load(f)


tmpdir = tempfile.TemporaryDirectory()
tmp = tmpdir.name
variants = ["--scene", "val-room-3", "--variant", "same=", "--variant", "shadow=--method shadow"]
js = os.path.join(tmp, "out.json")
out = run(variants, js)
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
                   (["--scene", "val-room-3", "--variant", "a=", "--level", "1.5"], "--level"),
                   # --base reaches every bake: vdsh-bake's error, the command named.
                   (["--scene", "val-room-3", "--variant", "a=", "--base=--no-such-option"],
                    "--no-such-option")):
    r = subprocess.run(base + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode == 0 or word not in r.stderr:
        sys.exit("%s was not an error naming %s: %d %s" % (args, word, r.returncode, r.stderr))
# --combine: the run above with another of the bake's seed (--base): per
# run the mean over pools of each diff, their t interval over the two runs;
# the default's drift against the first run; runs of other pools refused.
js2, jsc = os.path.join(tmp, "seed2.json"), os.path.join(tmp, "comb.json")
out2 = run(variants + ["--base", "--seed 2"], js2)
if out2["base"] != "--seed 2":
    sys.exit("--base not recorded: %r" % out2["base"])
r = subprocess.run([sys.executable, script, "--combine", js, js2, "--json", jsc],
                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
if r.returncode:
    sys.exit("--combine failed (%d): %s" % (r.returncode, r.stderr))
with open(jsc) as f:
    comb = json.load(f)
if len(comb) != 2 * 2 * 3:
    sys.exit("--combine: expected 12 rows (2 variants x 2 light counts x 3), got %d" % len(comb))
for c in comb:
    per = []
    for o in (out, out2):
        xs = [p["diff"][c["metric"]] for p in o["pools"] if p["variant"] == c["variant"]
              and p["order"] == c["order"] and p["lights"] == c["lights"]]
        per.append(sum(xs) / len(xs))
    if any(math.isnan(x) for x in per):
        continue
    h = math.tan(math.pi * 0.475) * abs(per[0] - per[1]) / 2
    m = (per[0] + per[1]) / 2
    if not (all(math.isclose(x, y, abs_tol=1e-9) for x, y in zip(per, c["per_run"]))
            and math.isclose(c["mean"], m, abs_tol=1e-9)
            and math.isclose(c["low"], m - h, abs_tol=1e-6)
            and math.isclose(c["high"], m + h, abs_tol=1e-6)):
        sys.exit("--combine: row %s is not the runs' means %s and their t interval" % (c, per))
    if c["variant"] == "same" and c["per_run"] != [0, 0]:
        sys.exit("--combine: the default's bake again differs: %s" % c)
    d = [p["default"] for p in out2["pools"] if p["variant"] == c["variant"]
         and p["order"] == c["order"] and p["lights"] == c["lights"]]
    d0 = [p["default"] for p in out["pools"] if p["variant"] == c["variant"]
          and p["order"] == c["order"] and p["lights"] == c["lights"]]
    want = sum((100 * (x["rmse"] / y["rmse"] - 1) if c["metric"] == "rmse" else
                100 * (x[c["metric"]] - y[c["metric"]])) for x, y in zip(d, d0)) / len(d)
    if not math.isclose(c["default_drift"][0], want, abs_tol=1e-9):
        sys.exit("--combine: the default's drift %r is not %r" % (c["default_drift"], want))
js3 = os.path.join(tmp, "one.json")
run(["--scene", "val-room-3", "--variant", "a=", "--seeds", "2"], js3)
r = subprocess.run([sys.executable, script, "--combine", js, js3], stdout=subprocess.PIPE,
                   stderr=subprocess.PIPE, text=True)
if r.returncode == 0 or "one.json" not in r.stderr:
    sys.exit("--combine of other pools was not an error naming the file: %s" % r.stderr)
tmpdir.cleanup()
print("ok")
