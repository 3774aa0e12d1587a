#!/usr/bin/env bash
# scripts/bake-parallel with real GNU parallel: 5 shards on local job slots
# merge to the whole bake's file byte for byte; a rerun with one part
# removed bakes only that one; each shard's progress is in the output.
# Installs Debian's parallel when root and it is missing; skips (77) when
# it cannot be had.
# Usage: test_shard_parallel.sh VDSH_BAKE VDSH_MERGE SCRIPTS_DIR
set -u
bake=$1 merge=$2 scripts=$3
if ! command -v parallel >/dev/null; then
  if [[ $(id -u) -eq 0 ]]; then
    apt-get install -y --no-install-recommends parallel >/dev/null 2>&1 || true
  fi
  command -v parallel >/dev/null || { echo "SKIP: no GNU parallel"; exit 77; }
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
tiny=(builtin:room --max-edge 1.5 --rays 32 --cube-size 8)
"$bake" "${tiny[@]}" -q -o "$tmp/whole.vdsh" || { echo "FAIL: whole bake" >&2; exit 1; }
export VDSH_BAKE=$bake VDSH_MERGE=$merge
if ! "$scripts/bake-parallel" 5 "$tmp/scene.vdsh" -j 2 -- "${tiny[@]}" 2>"$tmp/err.txt"; then
  echo "FAIL: bake-parallel:" >&2; cat "$tmp/err.txt" >&2; fail=1
fi
cmp "$tmp/scene.vdsh" "$tmp/whole.vdsh" || { echo "FAIL: parallel merge differs" >&2; fail=1; }
# The shards' progress stays in the output (the recipe no longer passes -q).
[[ $(grep -c '^vdsh-bake: 100.0%' "$tmp/err.txt") -ge 5 ]] ||
  { echo "FAIL: 5 shards' progress expected:" >&2; cat "$tmp/err.txt" >&2; fail=1; }
for k in 09-12 13-16 17-20 21-24; do
  cmp "$tmp/scene.sh$k.exr" "$tmp/whole.sh$k.exr" || { echo "FAIL: cubemap $k" >&2; fail=1; }
done
ls "$tmp"/scene.part-* >/dev/null 2>&1 && { echo "FAIL: parts left behind" >&2; fail=1; }
# A failing shard fails the run and writes no merged file.
if "$scripts/bake-parallel" 3 "$tmp/bad.vdsh" -- "${tiny[@]}" --rays 0 2>/dev/null; then
  echo "FAIL: a failing shard did not fail the run" >&2; fail=1
fi
[[ -e $tmp/bad.vdsh ]] && { echo "FAIL: merged despite a failed shard" >&2; fail=1; }
exit $fail
