#!/usr/bin/python3
"""scripts/order_curve's encoding axis (issue 29) at its smallest: a
validation room at --max-edge 0.6, 100 rays, orders 3 and 7, s8s6 and
cpca (4,12,4), C frames at 128 x 96. Checks:

- a row per (order, encoding), each with frame scores in (0, 1) and the
  table printing it with its encoding;
- bytes per vertex: s8s6's are its records (mean = largest); cpca's are
  its records (W words: the spec's rule) plus the model spread over the
  receivers, and the receiver count implied by the two cpca rows' model
  sizes (spec: 16 + round16(4KB) + round16(2Kn^2) + round16(2KBn^2)) is
  the same whole number: the model is counted, once per stream;
- the cpca rows are the cpca file's own frames (not s8s6's: the scores
  differ);
- the adaptive-order rows: s8s6's variable-order stream (records of
  orders 1..7, padded to words), cpca's a fixed cpca stream of the cap (order 7's records);
- an unknown encoding is an error naming it; so is a --scenes word that
  is no scene; a run that scores no scene fails; --frames on a scene
  without a listed view set scores frames of a view set made for it.

Usage: test_order_curve.py SCRIPTS_DIR BUILD_DIR
"""
import json
import math
import os
import subprocess
import sys
import tempfile

import testlib

scripts, build = sys.argv[1:3]
script = os.path.join(scripts, "order_curve")
fails = []
check = testlib.checker(fails)


def r16(n):
    return (n + 15) // 16 * 16


def cpca_words(b, bits):
    """Record words W of the spec: the cluster byte, then B fields that never
    straddle a word."""
    words, used = 1, 8
    for _ in range(b):
        if used + bits > 32:
            words, used = words + 1, 0
        used += bits
    return words


def model_bytes(n, k, b):
    return 16 + r16(4 * k * b) + r16(2 * k * n * n) + r16(2 * k * b * n * n)


r = subprocess.run([script, "--build", build, "--encodings", "s8s6,nosuch"],
                   capture_output=True, text=True)
check(r.returncode != 0 and "nosuch" in r.stderr and "|" not in r.stdout,
      "an unknown encoding: exit %d, stderr %r" % (r.returncode, r.stderr[-300:]))

# --scenes: a word that is no scene (no '=') is a usage error naming it
# (it was a Python traceback); a run whose meshes are all missing is an
# error (it printed an empty table and exited 0).
r = subprocess.run([script, "--build", build, "--scenes", "room3"], capture_output=True,
                   text=True)
check(r.returncode == 2 and "'room3'" in r.stderr and "Traceback" not in r.stderr and
      "|" not in r.stdout, "--scenes room3: exit %d, stderr %r" % (r.returncode, r.stderr[-300:]))
r = subprocess.run([script, "--build", build, "--scenes", "x=/nonexistent/x.obj:0.5"],
                   capture_output=True, text=True)
check(r.returncode not in (0, 2) and "no scene scored" in r.stderr and "|" not in r.stdout,
      "every mesh missing: exit %d, stderr %r" % (r.returncode, r.stderr[-300:]))
# --frames on a scene without docs/views/NAME.views.json: a view set made
# for it, and frame scores (--frames did nothing there).
with tempfile.TemporaryDirectory() as tmp:
    js = os.path.join(tmp, "tiny.json")
    r = subprocess.run([script, "--build", build, "--scenes", "tiny=builtin:room:3:1.5",
                        "--rays", "16", "--orders", "2", "--tolerances", "none", "--frames",
                        "--size", "32x24", "--points", "100", "--interior", "200", "--json", js],
                       capture_output=True, text=True)
    try:
        f = json.load(open(js))["tiny"][0]["frames"]
        check(f is not None and f["frames"] > 0 and 0.0 < f["rmse_ideal"] < 1.0,
              "--frames on an unlisted scene: frame scores %s" % f)
    except (OSError, ValueError, KeyError, IndexError) as e:
        check(False, "--frames on an unlisted scene: exit %d, %s %r"
              % (r.returncode, e, r.stderr[-500:]))

K, B, BITS = 4, 12, 4
with tempfile.TemporaryDirectory() as tmp:
    js = os.path.join(tmp, "curve.json")
    r = subprocess.run([script, "--build", build, "--scenes", "val-room-3=builtin:room:3:0.6",
                        "--rays", "100", "--orders", "3,7", "--encodings", "s8s6,cpca",
                        "--cpca", "%d,%d,%d" % (K, B, BITS), "--tolerances", "0.05",
                        "--cap", "7", "--frames", "--size", "128x96", "--points", "300",
                        "--interior", "1000", "--json", js],
                       capture_output=True, text=True)
    check(r.returncode == 0, "order_curve exit %d: %s" % (r.returncode, r.stderr[-2000:]))
    if r.returncode == 0:
        with open(js) as f:
            rows = json.load(f)["val-room-3"]
        by = {(x["label"], x["encoding"], x["tolerance"]): x for x in rows}
        keys = sorted(by, key=str)
        want = [("3", "s8s6", None), ("7", "s8s6", None), ("3", "cpca", None),
                ("7", "cpca", None), ("a7", "s8s6", 0.05), ("a7", "cpca", 0.05)]
        check(sorted(want, key=str) == keys, "rows %s, want %s" % (keys, want))
        x = by.get(("a7", "s8s6", 0.05))
        # the largest record is one of orders 1, 2, 3, 5, 7's (4-byte words)
        check(x and x["max_bytes"] in (4, 8, 24, 40) and 0 < x["bytes"] <= x["max_bytes"],
              "adaptive s8s6: %r" % ((x and (x["bytes"], x["max_bytes"])),))
        for key in want:
            x = by.get(key)
            if not x:
                continue
            f = x.get("frames")
            check(f is not None and all(0.0 < f[m] < 1.0 for m in ("rmse_ideal", "recall")) and
                  0.0 <= f["false_area"] < 1.0, "%s: frame scores %s" % (key, f))
            row = "| val-room-3 | %s | %s |" % (key[0], key[1])
            check(row in r.stdout, "the table has no row %r" % row)
        for o, want_b in (("3", 8), ("7", 40)):  # s8s6: 4 + 4 ceil((n^2 - 4) / 5)
            x = by.get((o, "s8s6", None))
            check(x and x["bytes"] == want_b and x["max_bytes"] == want_b,
                  "s8s6 order %s: %s bytes per vertex, want %d" % (o, x and x["bytes"], want_b))
        implied = []
        for o, key in ((3, ("3", "cpca", None)), (7, ("7", "cpca", None)),
                       (7, ("a7", "cpca", 0.05))):
            x = by.get(key)
            if not x:
                continue
            b = min(B, o * o)
            rec = 4 * cpca_words(b, BITS)
            check(x["max_bytes"] == rec, "cpca %s: records %s bytes, want %d"
                  % (key, x["max_bytes"], rec))
            extra = x["bytes"] - rec
            check(extra > 0, "cpca %s: the model is not counted (%s)" % (key, x["bytes"]))
            if extra > 0:
                implied.append(model_bytes(o, K, b) / extra)
        check(len(implied) == 3 and all(abs(v - round(v)) < 0.01 for v in implied) and
              len({round(v) for v in implied}) == 1 and implied[0] > 100,
              "receivers implied by the cpca rows' model bytes: %s" % implied)
        a, c = by.get(("7", "s8s6", None)), by.get(("7", "cpca", None))
        check(a and c and a.get("frames") and c.get("frames") and
              a["frames"]["rmse_ideal"] != c["frames"]["rmse_ideal"] and
              math.isfinite(c["recall"]),
              "cpca order 7's frames are its own (s8s6 %s, cpca %s)"
              % (a and a.get("frames"), c and c.get("frames")))

sys.exit(1 if fails else 0)
