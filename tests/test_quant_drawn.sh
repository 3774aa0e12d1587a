#!/usr/bin/env bash
# The s8, s8s6 scales are over the drawn receivers only: a receiver whose
# triangles all have no area is drawn nowhere, and its coefficients
# (extreme: it keeps the standard origin, buried, since issue 26) must not
# coarsen every receiver's steps. Two bakes of one room (a box on its
# floor), the second with three zero-area triangles added at positions no
# other receiver has: facing down through the floor, inside the box,
# facing out through a wall. Their s8s6 scales (vdsh-info --json) must be
# the room's alone; each scale of the second is the largest |coefficient|
# over its drawn receivers (its f32 bake), and the buried ones do exceed
# some scale (so the test can fail): the clamp distance is set far beyond
# the room (1000, the log floor kept at 0.01), so the two facing out into
# the void see ln 1000 everywhere, more than any receiver in the closed
# room sees. Then the same with shards: 1 and 3
# parts merged are the whole s8s6 bake byte for byte (the merge finds the
# drawn receivers from POSN and TRIS), and the room's s8 and s8s6 bakes,
# which have no such receivers, merge byte for byte too.
# Usage: test_quant_drawn.sh VDSH_BAKE VDSH_MERGE VDSH_INFO PYTHON_SOURCE_DIR
set -u
bake=$1
merge=$2
info=$3
pysrc=$4
. "$(dirname "$0")/lib.sh"
make_tmp
run() { # run DESCRIPTION COMMAND...: must exit 0
  local what=$1; shift
  "$@" 2>"$tmp/err.txt" || { echo "FAIL: $what" >&2; cat "$tmp/err.txt" >&2; exit 1; }
}

# the room, and the room with three zero-area triangles
room_box_pair <<'OBJ'
v 1 0 1
v 1.5 0 1.5
v 2 0 2
v 4.25 0.5 4.5
v 4.5 0.5 4.5
v 4.75 0.5 4.5
v 10 1 2
v 10 2 2
v 10 3 2
f 17//2 18//2 19//2
f 20//1 21//1 22//1
f 23//3 24//3 25//3
OBJ

opts=(--rays 64 --cube-size 0 --threads 2 --orders 2,3,5 --max-distance 1000 --log-floor 0.01 -q)
for m in a b; do
  run "bake $m s8s6" "$bake" "$tmp/$m.obj" "${opts[@]}" --encoding s8s6 -o "$tmp/$m.vdsh"
  run "info $m" "$info" --json - "$tmp/$m.vdsh" >"$tmp/$m.json"
done
run "bake b f32" "$bake" "$tmp/b.obj" "${opts[@]}" --encoding f32 -o "$tmp/b32.vdsh"

# The scales of a and b, and of b from its f32 rows: per order, the largest
# |c| per index over every receiver, and over the drawn ones (a triangle
# with nonzero cross product touches it: all but the 9 added).
check "s8s6 scales: the room's alone; over b's drawn receivers; below b's all" \
  env PYTHONPATH="$pysrc" /usr/bin/python3 - "$tmp" <<'PY'
import json, sys
import numpy as np
import vdsh
t = sys.argv[1]
def scales(p):
    return {s["order"]: s["coef_scales"] for s in json.load(open(p))["streams"]}
a, b = scales(t + "/a.json"), scales(t + "/b.json")
ok = True
if a != b:
    print("  room alone:", a, "\n  with the undrawn receivers:", b, file=sys.stderr)
    ok = False
f = vdsh.read(t + "/b32.vdsh")
p = f.positions.astype(np.float64)
tri = f.triangles.astype(np.int64)
n = np.cross(p[tri[:, 1]] - p[tri[:, 0]], p[tri[:, 2]] - p[tri[:, 0]])
area = np.linalg.norm(n, axis=1) > 0
drawn = np.zeros(len(p), bool)
drawn[tri[area].ravel()] = True
if (~drawn).sum() != 9:
    print("  undrawn receivers: %d, want the 9 added" % (~drawn).sum(), file=sys.stderr)
    ok = False
exceeds = False
for s in f.streams:
    c = np.abs(vdsh.coefficients(s))
    want = c[drawn].max(axis=0).astype(np.float32)
    if not np.array_equal(np.float32(b[s["order"]]), want):
        print("  order %d: scales %s, drawn receivers' largest |c| %s"
              % (s["order"], b[s["order"]], want), file=sys.stderr)
        ok = False
    exceeds |= bool((c[~drawn].max(axis=0) > c[drawn].max(axis=0)).any())
if not exceeds:
    print("  no undrawn receiver exceeds a drawn one's |c|: the test cannot fail", file=sys.stderr)
    ok = False
sys.exit(0 if ok else 1)
PY

# Shards: the merge derives the drawn receivers from the merged POSN and
# TRIS, as the whole bake from its receivers.
for n in 1 3; do
  d=$tmp/n$n; mkdir -p "$d"
  for ((i = 0; i < n; i++)); do
    run "b shard $i/$n" "$bake" "$tmp/b.obj" "${opts[@]}" --encoding s8s6 --shard "$i/$n" \
      -o "$d/part-$i.vdsh"
  done
  run "merge b $n" "$merge" -q "$d"/part-*.vdsh -o "$d/b.vdsh"
  check "b, $n shards: merged s8s6 identical to the whole bake" cmp "$d/b.vdsh" "$tmp/b.vdsh"
done
# The room alone (no undrawn receivers): s8 as well.
run "bake a s8" "$bake" "$tmp/a.obj" "${opts[@]}" --encoding s8 -o "$tmp/a8.vdsh"
d=$tmp/a3; mkdir -p "$d"
for i in 0 1 2; do
  run "a s8 shard $i/3" "$bake" "$tmp/a.obj" "${opts[@]}" --encoding s8 --shard "$i/3" \
    -o "$d/part-$i.vdsh"
done
run "merge a s8" "$merge" -q "$d"/part-*.vdsh -o "$d/a8.vdsh"
check "a, 3 shards: merged s8 identical to the whole bake" cmp "$d/a8.vdsh" "$tmp/a8.vdsh"
exit $fail
