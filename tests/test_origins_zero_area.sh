#!/usr/bin/env bash
# Origin repair skips receivers whose triangles all have no area (issue
# 26): they are drawn nowhere, so they keep the standard origin and get
# no probe rays, and nothing else about the repair changes. Two bakes of
# one room (a box resting on its floor, so that some receivers are
# repaired), the second with three zero-area triangles added (file
# normals, corners collinear: along the floor-wall edge, under the box's
# bottom edge, on open floor), at positions no other receiver has.
# Usage: test_origins_zero_area.sh VDSH_BAKE
set -u
bake=$1
. "$(dirname "$0")/lib.sh"
make_tmp
json() { # json PYTHON_EXPRESSION_OF_a_AND_b (the two reports): true when it holds
  /usr/bin/python3 -c 'import json, sys
a = json.load(open(sys.argv[1]))["origins"]; b = json.load(open(sys.argv[2]))["origins"]
ok = eval(sys.argv[3])
if not ok: print("  without:", a, "\n  with:   ", b, file=sys.stderr)
sys.exit(0 if ok else 1)' "$tmp/a.json" "$tmp/b.json" "$1"
}

# the room, and the room with three zero-area triangles
room_box_pair <<'OBJ'
v 0 0 2
v 0 0 5
v 0 0 8
v 4 0 4.25
v 4 0 4.5
v 4 0 4.75
v 2 0 2
v 2.5 0 2.5
v 3 0 3
f 17//1 18//1 19//1
f 20//2 21//2 22//2
f 23//1 24//1 25//1
OBJ

opts=(--rays 16 --cube-size 0 --threads 2)
"$bake" "$tmp/a.obj" "${opts[@]}" -o "$tmp/a.vdsh" --report "$tmp/a.json" 2>"$tmp/a.err" ||
  { echo "FAIL: bake without the zero-area triangles" >&2; cat "$tmp/a.err" >&2; exit 1; }
"$bake" "$tmp/b.obj" "${opts[@]}" -o "$tmp/b.vdsh" --report "$tmp/b.json" 2>"$tmp/b.err" ||
  { echo "FAIL: bake with the zero-area triangles" >&2; cat "$tmp/b.err" >&2; exit 1; }

check "the room alone has repaired receivers (the box's bottom) and none skipped" \
  json "a['repaired'] > 0 and a.get('skipped_zero_area') == 0"
check "the 9 receivers on zero-area triangles only are counted as skipped" \
  json "b.get('skipped_zero_area') == 9"
check "they get no probe rays: the same probe rays as the room alone" \
  json "b['probe_rays'] == a['probe_rays']"
check "the other receivers' repair is unchanged" \
  json "(b['repaired'], b['moved'], b['coincident_faces']) == (a['repaired'], a['moved'], a['coincident_faces'])"
check "stderr says so once" \
  test "$(grep -c 'receivers on zero-area triangles only (drawn nowhere): origins not probed' "$tmp/b.err")" = 1
check "no such line without them" bash -c "! grep -q 'zero-area triangles only' '$tmp/a.err'"
exit $fail
