"""test_eval_offsets.py BAKE EVAL WORKDIR - vdsh-eval --offsets: each
stream scored again with a log offset added, decoded to f32 in memory.

A copy with offset 0 is the stream itself: it must score exactly as the
stream (every metric of both kinds, vertices and interior points) and
report the stream's own bytes per vertex and encoding, for a fixed-order
s8s6 stream and for a variable-order (adaptive) stream, whose copy keeps
its orders (before the fix the adaptive copy was read as a dense stream:
about 70% false shadows and 514 bytes per vertex). A positive offset
lengthens every distance: its false-shadow rate must not rise and must
fall somewhere.
"""
import json
import os
import subprocess
import sys

bake, ev, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
fail = []
vd = os.path.join(work, "room.vdsh")
subprocess.run([bake, "builtin:room", "--max-edge", "0.6", "--rays", "128", "--orders", "3",
                "--adaptive-order", "0.02", "--max-order", "9", "-q", "--cube-size", "0", "-o", vd], check=True)
js = os.path.join(work, "room.json")
subprocess.run([ev, vd, "-q", "--points", "1500", "--interior", "1500", "--offsets", "0,0.4", "--json", js],
               check=True, stdout=subprocess.DEVNULL)
streams = json.load(open(js))["streams"]
if len(streams) != 6:
    fail.append("%d scored streams, not 2 x (1 + 2 offsets)" % len(streams))
KEYS = ("shadow_mae", "false_shadow", "light_leak", "binary_mae", "binary_false_shadow", "distance_rms")
for base in range(0, len(streams), 3):
    s, z, p = streams[base:base + 3]
    name = "order %d%s" % (s["order"], " (adaptive)" if s["variable_order"] else "")
    print("%s: %.1f B/vertex, %s; false %.4f / copy %.4f / +0.4 %.4f (vertices)"
          % (name, s["bytes_per_vertex"], s["encoding"], s["vertices"]["false_shadow"],
             z["vertices"]["false_shadow"], p["vertices"]["false_shadow"]))
    for k in ("bytes_per_vertex", "encoding", "variable_order", "order"):
        if z[k] != s[k] or p[k] != s[k]:
            fail.append("%s: the copies' %s %r / %r, the stream's %r" % (name, k, z[k], p[k], s[k]))
    if z["log_offset"] != 0 or abs(p["log_offset"] - 0.4) > 1e-6:
        fail.append("%s: offsets %r, %r" % (name, z["log_offset"], p["log_offset"]))
    for kind in ("vertices", "interior"):
        for k in KEYS:
            a, b = s[kind][k], z[kind][k]
            if not abs(a - b) <= 1e-6 * max(1.0, abs(a)):
                fail.append("%s %s: %s %g with offset 0, %g as stored" % (name, kind, k, b, a))
        if not p[kind]["false_shadow"] <= s[kind]["false_shadow"] + 1e-9:
            fail.append("%s %s: offset +0.4 raised the false shadows" % (name, kind))
    if not p["vertices"]["false_shadow"] + p["interior"]["false_shadow"] < \
            s["vertices"]["false_shadow"] + s["interior"]["false_shadow"]:
        fail.append("%s: offset +0.4 changed no false shadow (was the copy scored at all?)" % name)
if not any(s["variable_order"] for s in streams):
    fail.append("no adaptive stream was scored")
for f in fail:
    print("FAIL:", f)
sys.exit(1 if fail else 0)
