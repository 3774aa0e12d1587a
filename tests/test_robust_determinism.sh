#!/usr/bin/env bash
# Determinism on real scenes (issue 5, docs/DESIGN.md §2): the same inputs and
# options give byte-identical .vdsh files and cubemaps with 1 and 2 worker
# threads and across repeated runs. Scenes from ../shared/scenes, at
# reduced rays so the whole test takes seconds; each one goes through a
# different loader or path:
#   Cornell box (OBJ, TABs, negative indices; refined to 0.1 m)
#   Cornell box Mirror (non-manifold edges, duplicate faces; refined)
#   Newell teapot (open OBJ, parts not joined)
#   Stanford bunny res2 and res3 (ascii PLY, non-manifold; refined)
#   sphere with a hole (ascii STL, welded)
#   Sponza (the atrium, 60,848 vertices, 16 rays)
# Exit 77 (skip) when the scenes folder is absent; a scene that is missing
# from a present folder is a failure (the folder's README lists them).
# Usage: test_robust_determinism.sh VDSH_BAKE SCENES_DIR
set -u
bake=$1
scenes=$2
if [[ ! -d $scenes ]]; then
  echo "skipped: no scenes at $scenes"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0

# same NAME MESH [vdsh-bake options]: three bakes, all files identical.
same() {
  local name=$1 mesh=$scenes/$2
  shift 2
  if [[ ! -f $mesh ]]; then
    echo "FAIL: $name: $mesh missing" >&2; fail=1; return
  fi
  local run t0 t1
  t0=$(date +%s.%N)
  for run in "1 a" "2 b" "2 c"; do
    local threads=${run% *} tag=${run#* }
    if ! "$bake" "$mesh" "$@" --cube-size 8 --threads "$threads" -q -o "$tmp/$name-$tag.vdsh" 2>"$tmp/err"; then
      echo "FAIL: $name: bake with $threads threads failed: $(cat "$tmp/err")" >&2; fail=1; return
    fi
  done
  t1=$(date +%s.%N)
  local f ok=1
  for f in .vdsh .sh09-12.exr .sh13-16.exr .sh17-20.exr .sh21-24.exr; do
    if ! cmp -s "$tmp/$name-a$f" "$tmp/$name-b$f"; then
      echo "FAIL: $name: $f differs between 1 and 2 threads" >&2; fail=1; ok=0
    fi
    if ! cmp -s "$tmp/$name-b$f" "$tmp/$name-c$f"; then
      echo "FAIL: $name: $f differs between two runs" >&2; fail=1; ok=0
    fi
  done
  [[ $ok -eq 1 ]] && printf '%-16s identical (1 thread, 2 threads, repeat): %s bytes, %.1f s for 3 bakes\n' \
    "$name" "$(stat -c %s "$tmp/$name-a.vdsh")" "$(awk "BEGIN { print $t1 - $t0 }")"
  rm -f "$tmp/$name"-*
}

# The default method (decision) with 32 training lights where the rays are
# few: the same code at a fraction of the cost (the ISA run repeats all of
# it per kernel set, under the sanitizers too); Cornell once at its defaults.
few=(--decision-lights 32)
same cornell      cornell_box/CornellBox-Original.obj --max-edge 0.1 --rays 256 "${few[@]}"
same cornell-mirror cornell_box/CornellBox-Mirror.obj --max-edge 0.2 --rays 64 "${few[@]}"
same teapot       teapot_newell/teapot.obj --rays 64 "${few[@]}"
same bunny-res2   bunny_stanford/bun_zipper_res2.ply --rays 32 "${few[@]}"
same bunny-res3   bunny_stanford/bun_zipper_res3.ply --max-edge 0.004 --rays 64 --orders 2,3,5 --encoding f32 "${few[@]}"
same sphere-hole  sphere_with_hole/sphereWithHole.stl --weld --max-edge 0.3 --rays 256 --method full
same sponza       sponza_dabrovic/sponza.obj --rays 16 "${few[@]}"
same cornell-decision cornell_box/CornellBox-Original.obj --max-edge 0.1 --rays 256 --method decision
exit $fail
