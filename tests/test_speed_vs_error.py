#!/usr/bin/python3
"""scripts/speed_vs_error at its smallest (the room, --quick, 16 rays, one
order, f16, 200 evaluation points): --resume reuses an evaluation only
when the same arguments made it (a rerun with --orders 3 reused the order-2
evaluations and reported order 2, exit 0), and a run with no scene to sweep
(its meshes missing) fails and leaves --doc's section as it was (it wrote
an empty table there, exit 0); --rays and --orders that are not whole
numbers are usage errors (they were tracebacks).

Usage: test_speed_vs_error.py SCRIPTS_DIR BUILD_DIR
"""
import csv
import os
import shutil
import subprocess
import sys
import tempfile

import testlib

scripts, build = sys.argv[1:3]
script = os.path.join(scripts, "speed_vs_error")
fails = []
check = testlib.checker(fails)


def sweep(out, orders, *extra):
    return subprocess.run([script, "--build", build, "--quick", "--scenes", "room", "--rays",
                           "16", "--orders", orders, "--encodings", "f16", "--eval-args",
                           "--points 200 --interior 200", "--out", out, *extra],
                          capture_output=True, text=True)


def orders_in(out):
    with open(os.path.join(out, "sweep.csv")) as f:
        return sorted({r["order"] for r in csv.DictReader(f)})


with tempfile.TemporaryDirectory() as tmp:
    out = os.path.join(tmp, "sweep")
    r = sweep(out, "2")
    check(r.returncode == 0 and orders_in(out) == ["2"],
          "first sweep: exit %d %r" % (r.returncode, r.stderr[-500:]))
    r = sweep(out, "3", "--resume")
    got = orders_in(out) if r.returncode == 0 else None
    check(got == ["3"], "--orders 3 --resume after --orders 2: orders %s in sweep.csv (exit %d)"
          % (got, r.returncode))
    r = sweep(out, "3", "--resume")
    check(r.returncode == 0 and "not reused" not in r.stdout and orders_in(out) == ["3"],
          "the same arguments again: reused (%r)" % r.stdout[-300:])

    # --rays and --orders that are not whole numbers: usage errors naming
    # the option (a ValueError traceback).
    for opt, val in (("--rays", "64,abc"), ("--orders", "2,,3"), ("--orders", "0")):
        r = subprocess.run([script, "--build", build, opt, val, "--out", os.path.join(tmp, "bad")],
                           capture_output=True, text=True)
        check(r.returncode == 2 and opt in r.stderr and "Traceback" not in r.stderr,
              "%s %s: exit %d, %r" % (opt, val, r.returncode, r.stderr[-300:]))

    # No scene: a copy of the script finds no ../shared/scenes beside it.
    tree = os.path.join(tmp, "tree", "scripts")
    os.makedirs(tree)
    shutil.copy(script, tree)
    doc = os.path.join(tmp, "doc.md")
    text = "# doc\n<!-- sweep:begin -->\nthe measured table\n<!-- sweep:end -->\n"
    with open(doc, "w") as f:
        f.write(text)
    r = subprocess.run([os.path.join(tree, "speed_vs_error"), "--build", build, "--quick",
                        "--scenes", "cornell", "--out", os.path.join(tmp, "none"), "--doc", doc],
                       capture_output=True, text=True)
    check(r.returncode != 0 and "no scene" in r.stderr,
          "no scene to sweep: exit %d, %r" % (r.returncode, r.stderr[-300:]))
    check(open(doc).read() == text, "no scene to sweep: --doc changed: %r" % open(doc).read())
sys.exit(1 if fails else 0)
