#!/usr/bin/env bash
# What the mesh loader drops, repairs or splits is said on vdsh-bake's
# stderr, one line per finding with its count and the file's name
# (vb_mesh_report_print); -q says nothing; vdsh-eval, which only rebuilds
# the occluders from the same files, repeats none of it.
# Usage: test_mesh_cli.sh VDSH_BAKE VDSH_EVAL
set -u
bake=$1
eval=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
has() { # has FILE TEXT: the file has a line containing TEXT
  if ! grep -qF -- "$2" "$1"; then
    echo "FAIL: stderr lacks '$2':" >&2; cat "$1" >&2; fail=1
  fi
}

# Vertices 1 and 2: zero normals on used vertices (repaired from the
# square's faces); 4 and 5 unused; 6 used only by a triangle repeating it;
# 7-9: zero normals on a zero-area triangle (nothing to repair from). Two
# triangles repeat an index.
cat >"$tmp/scan.ply" <<'PLY'
ply
format ascii 1.0
element vertex 10
property float x
property float y
property float z
property float nx
property float ny
property float nz
element face 5
property list uchar int vertex_indices
end_header
0 0 0 0 0 1
1 0 0 0 0 0
0 1 0 0 0 0
1 1 0 0 0 1
5 5 5 0 0 1
6 6 6 0 0 0
2 2 2 0 0 1
3 0 0 0 0 0
4 0 0 0 0 0
5 0 0 0 0 0
3 0 1 2
3 1 3 2
3 1 1 2
3 6 6 6
3 7 8 9
PLY

if ! "$bake" "$tmp/scan.ply" --export-obj "$tmp/scan.obj" 2>"$tmp/err"; then
  echo "FAIL: export of scan.ply failed:" >&2; cat "$tmp/err" >&2; fail=1
fi
has "$tmp/err" "vdsh-bake: $tmp/scan.ply: 2 triangles dropped (a repeated vertex index: no area)"
has "$tmp/err" "vdsh-bake: $tmp/scan.ply: 3 vertices removed (used by no remaining triangle)"
# the five zero normals on one line, saying what became of each of them
has "$tmp/err" "vdsh-bake: $tmp/scan.ply: 5 vertices have a zero normal in the file: 2 given their own triangles' normal, 3 left without a normal (0,0,0: their triangles have no area)"
n=$(grep -c "scan.ply: " "$tmp/err")
if [[ $n -ne 4 ]]; then  # the load line and three findings
  echo "FAIL: $n lines name scan.ply, want 4:" >&2; cat "$tmp/err" >&2; fail=1
fi
# the repaired normals are the square's, (0,0,1): vn lines 2 and 3
if [[ "$(sed -n '/^vn/p' "$tmp/scan.obj" | sed -n '2,3p' | tr '\n' ' ')" != "vn 0 0 1 vn 0 0 1 " ]]; then
  echo "FAIL: repaired normals:" >&2; grep '^vn' "$tmp/scan.obj" >&2; fail=1
fi

# Duplicate faces, as scans and merged exports have them: a copy with
# vertices of its own (same winding), a reversed copy on the same vertices,
# a copy with its corners rotated; all dropped and counted. A two-sided
# sheet (a reversed copy with its own vertices) keeps its back.
cat >"$tmp/dups.obj" <<'OBJ'
v 0 0 0
v 1 0 0
v 0 1 0
v 1 1 0
v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 5
v 1 0 5
v 0 1 5
v 0 0 5
v 1 0 5
v 0 1 5
f 1 2 3
f 2 4 3
f 5 6 7
f 3 2 1
f 3 1 2
f 8 9 10
f 11 13 12
OBJ
if ! "$bake" "$tmp/dups.obj" --export-obj "$tmp/dups.out.obj" 2>"$tmp/err"; then
  echo "FAIL: export of dups.obj failed:" >&2; cat "$tmp/err" >&2; fail=1
fi
has "$tmp/err" "vdsh-bake: $tmp/dups.obj: 10 vertices, 4 triangles"
has "$tmp/err" "vdsh-bake: $tmp/dups.obj: 3 duplicate triangles dropped (the same three positions as an earlier triangle, in any order)"
has "$tmp/err" "vdsh-bake: $tmp/dups.obj: 3 vertices removed (used by no remaining triangle)"
if [[ $(grep -c '^f ' "$tmp/dups.out.obj") -ne 4 ]]; then
  echo "FAIL: dups.obj: want 4 triangles written:" >&2; grep '^f ' "$tmp/dups.out.obj" >&2; fail=1
fi

# Zero normals in the file on a fold (vertex 1: its triangles' normals
# cancel) and on a zero-area triangle: one line says what became of each.
cat >"$tmp/fold.obj" <<'OBJ'
v 0 0 0
v 1 0 0
v 0 1 0
v 0 -1 0
v -1 0 0
v 5 0 0
v 6 0 0
v 7 0 0
vn 0 0 0
vn 0 0 1
vn 0 0 0
vn 0 0 -1
vn 0 0 -1
vn 0 0 0
f 1//1 2//2 3//3
f 1//1 4//4 5//5
f 6//6 7//6 8//6
OBJ
if ! "$bake" "$tmp/fold.obj" --export-obj "$tmp/fold.out.obj" 2>"$tmp/err"; then
  echo "FAIL: export of fold.obj failed:" >&2; cat "$tmp/err" >&2; fail=1
fi
has "$tmp/err" "vdsh-bake: $tmp/fold.obj: 5 vertices have a zero normal in the file: 1 given their own triangles' normal, 1 their largest triangle's (their triangles' normals cancel: two-sided), 3 left without a normal (0,0,0: their triangles have no area)"
n=$(grep -c "fold.obj: " "$tmp/err")
if [[ $n -ne 2 ]]; then  # the load line and one finding
  echo "FAIL: $n lines name fold.obj, want 2:" >&2; cat "$tmp/err" >&2; fail=1
fi

# -q: nothing at all
if ! "$bake" "$tmp/scan.ply" --export-obj "$tmp/scan.obj" -q 2>"$tmp/err" || [[ -s $tmp/err ]]; then
  echo "FAIL: -q still printed:" >&2; cat "$tmp/err" >&2; fail=1
fi

# A crease: a floor and a wall sharing two positions, each corner naming
# its own normal: the two shared positions split, two vertices added.
cat >"$tmp/crease.obj" <<'OBJ'
v 0 0 0
v 1 0 0
v 1 0 1
v 0 0 1
v 0 1 0
v 1 1 0
vn 0 1 0
vn 0 0 1
f 4//1 3//1 2//1 1//1
f 1//2 2//2 6//2 5//2
OBJ
"$bake" "$tmp/crease.obj" --export-obj "$tmp/crease.out.obj" 2>"$tmp/err"
has "$tmp/err" "vdsh-bake: $tmp/crease.obj: 8 vertices, 4 triangles"
has "$tmp/err" "vdsh-bake: $tmp/crease.obj: 2 vertices split at creases"
has "$tmp/err" "2 vertices added (in the count above)"
sort -u <(grep '^vn' "$tmp/crease.out.obj") >"$tmp/vn"
if [[ "$(tr '\n' ' ' <"$tmp/vn")" != "vn 0 0 1 vn 0 1 0 " ]]; then
  echo "FAIL: crease normals are not the file's:" >&2; cat "$tmp/vn" >&2; fail=1
fi

# vdsh-eval rebuilds the occluders from the same file and says nothing
# about it (the bake did)
if "$bake" "$tmp/scan.ply" --rays 16 --cube-size 8 -q -o "$tmp/scan.vdsh" 2>"$tmp/err"; then
  "$eval" "$tmp/scan.vdsh" --interior 64 --directions 4 -q >"$tmp/out" 2>"$tmp/err"
  if grep -q "scan.ply: " "$tmp/err"; then
    echo "FAIL: vdsh-eval repeated the loader's findings:" >&2; cat "$tmp/err" >&2; fail=1
  fi
else
  echo "FAIL: bake of scan.ply failed:" >&2; cat "$tmp/err" >&2; fail=1
fi

# A mesh whose file name is not UTF-8 (a Latin-1 name) cannot be recorded
# in the .vdsh (VDSH.md: SRCS names are UTF-8): refused before the bake,
# naming the mesh, nothing written (it was refused after the whole bake,
# naming the output).
latin=$tmp/$'mod\xe8le.obj'
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$latin"
if "$bake" "$latin" --rays 16 --cube-size 0 -o "$tmp/latin.vdsh" 2>"$tmp/err"; then
  echo "FAIL: a mesh named in Latin-1 was baked into a .vdsh" >&2; fail=1
else
  has "$tmp/err" "$latin: its name is not valid UTF-8"
  if grep -q "tracing" "$tmp/err" || [[ -e $tmp/latin.vdsh ]]; then
    echo "FAIL: the Latin-1 name was refused after the bake:" >&2; cat "$tmp/err" >&2; fail=1
  fi
fi
"$bake" "$latin" --export-obj "$tmp/latin-out.obj" -q 2>"$tmp/err" ||
  { echo "FAIL: --export-obj refused a Latin-1 name:" >&2; cat "$tmp/err" >&2; fail=1; }

# A concave polygon face (an L of 6 vertices, area 3, listed from a corner
# that does not see all of it) is ear-clipped: no warning, and the
# exported triangles cover the L's 3 units (its fan from the first vertex
# covered 4, part of it outside the face; Sponza has 190 flat concave
# faces, assimp's concave_polygon.obj one at 13.5x). The same L with its
# inner corner raised 3 units (far from flat) and a polygon that crosses
# itself are still fanned, and said on stderr with the ratio. A convex quad
# and a slightly warped one are not.
printf 'v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 3 4 5 6 1 2\n' >"$tmp/ell.obj"
"$bake" "$tmp/ell.obj" --export-obj "$tmp/ell-out.obj" 2>"$tmp/err" ||
  { echo "FAIL: ell.obj refused:" >&2; cat "$tmp/err" >&2; fail=1; }
if grep -q "warning" "$tmp/err"; then
  echo "FAIL: the flat concave L still warned about:" >&2; cat "$tmp/err" >&2; fail=1
fi
# The exported triangles' area, from the file written (v and f lines).
area=$(awk '$1 == "v" { n++; x[n] = $2; y[n] = $3; z[n] = $4 }
  $1 == "f" { split($2, a, "/"); split($3, b, "/"); split($4, c, "/")
    ux = x[b[1]] - x[a[1]]; uy = y[b[1]] - y[a[1]]; uz = z[b[1]] - z[a[1]]
    vx = x[c[1]] - x[a[1]]; vy = y[c[1]] - y[a[1]]; vz = z[c[1]] - z[a[1]]
    cx = uy * vz - uz * vy; cy = uz * vx - ux * vz; cz = ux * vy - uy * vx
    s += 0.5 * sqrt(cx * cx + cy * cy + cz * cz) }
  END { printf "%.6f", s }' "$tmp/ell-out.obj")
[[ $area == 3.000000 ]] ||
  { echo "FAIL: ell.obj exported with area $area, not the L's 3" >&2; fail=1; }
printf 'v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 3\nv 1 2 0\nv 0 2 0\nf 3 4 5 6 1 2\n' >"$tmp/bent.obj"
printf 'v 0 0 0\nv 3 0 0\nv 3 2 0\nv 1 -1 0\nv 1 2 0\nv 0 2 0\nf 1 2 3 4 5 6\n' >"$tmp/cross.obj"
for f in bent cross; do
  "$bake" "$tmp/$f.obj" --export-obj "$tmp/$f-out.obj" 2>"$tmp/err" ||
    { echo "FAIL: $f.obj refused:" >&2; cat "$tmp/err" >&2; fail=1; }
  has "$tmp/err" "$f.obj: warning: 1 polygon of 4 or more vertices not simple (or far from flat), so not ear-clipped: fanned from the first vertex, the triangles cover "
done
printf 'v 0 0 0\nv 2 0 0\nv 2 1 0.01\nv 0 1 0\nv 3 0 0\nv 4 0 0\nv 4 1 0\nv 3 1 0\nf 1 2 3 4\nf 5 6 7 8\n' >"$tmp/quads.obj"
"$bake" "$tmp/quads.obj" --export-obj "$tmp/quads-out.obj" 2>"$tmp/err" ||
  { echo "FAIL: quads.obj refused:" >&2; cat "$tmp/err" >&2; fail=1; }
if grep -q "warning" "$tmp/err"; then
  echo "FAIL: convex quads warned about:" >&2; cat "$tmp/err" >&2; fail=1
fi

[[ $fail -eq 0 ]] && echo "mesh report cli: all checks passed"
exit $fail
