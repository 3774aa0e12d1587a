"""scripts/score_bootstrap: the ratio of two vdsh-frames scores and its
bootstrap interval over views.

Made-up score files of four views (two with two light sets): the full
ratio is the pooled one (sqrt of summed squared error over summed
pixels), the interval holds it and is the same for the same seed; a file
against itself gives 0 and [0, 0]; a TEST with one view's error doubled
and the rest equal moves the ratio by the pooled amount; files of other
views, truth or masks, a file that is no score JSON, a missing file, a
scene row the views do not pool to, and two modes without --mode are
refused with the file named and a non-zero exit.

Usage: test_score_bootstrap.py SCRIPTS_DIR WORK_DIR
"""
import json
import math
import os
import subprocess
import sys

from testlib import load_script

scripts, work = sys.argv[1:3]
os.makedirs(work, exist_ok=True)
tool = os.path.join(scripts, "score_bootstrap")
sb = load_script(tool)
failed = 0


def check(ok, what):
    global failed
    if not ok:
        print("FAIL:", what, file=sys.stderr)
        failed = 1


# (view, set, counted, rmse_ideal)
SETS = [("a", 0, 1000, 0.30), ("a", 1, 500, 0.20), ("b", 0, 800, 0.10),
        ("c", 0, 1200, 0.40), ("c", 1, 300, 0.35), ("d", 0, 900, 0.25)]


def score(path, sets, truth="t", views="v.views.json", scene=None, modes=("c-vdsh12",)):
    se = sum(r * r * c for _, _, c, r in sets)
    n = sum(c for _, _, c, _ in sets)
    rm = math.sqrt(se / n) if scene is None else scene
    mo = [dict(mode=m, sets=[dict(view=v, set=k, counted=c, rmse_ideal=r, per_frame=[])
                             for v, k, c, r in sets],
               scene=dict(counted=n, rmse_ideal=rm)) for m in modes]
    with open(path, "w") as f:
        json.dump(dict(tool="vdsh-frames", command="score", truth=truth, views=views,
                       modes=mo), f)
    return path


def pooled(sets):
    return math.sqrt(sum(r * r * c for _, _, c, r in sets) / sum(c for _, _, c, _ in sets))


ref = score(os.path.join(work, "ref.json"), SETS)
worse = [(v, k, c, r * (2.0 if v == "b" else 1.05)) for v, k, c, r in SETS]
test = score(os.path.join(work, "test.json"), worse)

res = sb.bootstrap(ref, test, draws=1000, seed=1)
want = pooled(worse) / pooled(SETS) - 1
check(abs(res["ratio"] - want) < 1e-12, "ratio %r, pooled %r" % (res["ratio"], want))
check(res["views"] == 4, "views %r" % res["views"])
check(res["lo"] <= res["ratio"] <= res["hi"],
      "interval %r..%r holds %r" % (res["lo"], res["hi"], res["ratio"]))
check(res["lo"] >= 0.05 - 1e-12, "every view is at least 5%% worse: lo %r" % res["lo"])
check(res["hi"] > res["lo"], "views differ: a non-empty interval %r..%r" % (res["lo"], res["hi"]))
again = sb.bootstrap(ref, test, draws=1000, seed=1)
check(again == res, "the same seed, the same interval")
wide = sb.bootstrap(ref, test, draws=1000, seed=1, level=0.99)
check(wide["lo"] <= res["lo"] and wide["hi"] >= res["hi"], "99% holds 95%")

same = sb.bootstrap(ref, ref, draws=200, seed=3)
check(same["ratio"] == 0 and same["lo"] == 0 and same["hi"] == 0, "itself: %r" % same)

# the command line: one line with the ratio and interval, and --json
out = os.path.join(work, "res.json")
p = subprocess.run([sys.executable, tool, ref, test, "--json", out], capture_output=True, text=True)
check(p.returncode == 0, "command: rc %d %s" % (p.returncode, p.stderr))
check(("%+.2f%%" % (100 * want)) in p.stdout, "printed ratio: %r" % p.stdout)
check(json.load(open(out))["ratio"] == res["ratio"], "--json ratio")


def refused(args, needle, what):
    p = subprocess.run([sys.executable, tool] + args, capture_output=True, text=True)
    check(p.returncode != 0 and needle in p.stderr and "Traceback" not in p.stderr,
          "%s: rc %d, stderr %r" % (what, p.returncode, p.stderr))


other_views = score(os.path.join(work, "ov.json"), [(("e" if v == "d" else v), k, c, r)
                                                    for v, k, c, r in SETS])
refused([ref, other_views], "not the same views", "other views")
other_truth = score(os.path.join(work, "ot.json"), SETS, truth="t2")
refused([ref, other_truth], "other truth", "other truth")
other_mask = score(os.path.join(work, "om.json"), [(v, k, c + 1, r) for v, k, c, r in SETS])
refused([ref, other_mask], "other counted", "other masks")
bad_scene = score(os.path.join(work, "bs.json"), SETS, scene=0.5)
refused([ref, bad_scene], "bs.json", "scene row the views do not pool to")
two = score(os.path.join(work, "two.json"), SETS, modes=("c-vdsh12", "c-vdsh5"))
refused([two, two], "--mode", "two modes, none named")
p = subprocess.run([sys.executable, tool, two, two, "--mode", "c-vdsh5"], capture_output=True,
                   text=True)
check(p.returncode == 0, "two modes, --mode named: %s" % p.stderr)
junk = os.path.join(work, "junk.json")
open(junk, "w").write("{not json")
refused([ref, junk], "junk.json", "not JSON")
open(junk, "w").write('{"tool": "vdsh-frames", "command": "truth"}')
refused([ref, junk], "junk.json", "not a score")
refused([ref, os.path.join(work, "missing.json")], "missing.json", "missing file")
refused([ref, test, "--draws", "0"], "--draws", "no draws")

sys.exit(failed)
