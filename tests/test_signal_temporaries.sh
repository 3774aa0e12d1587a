#!/usr/bin/env bash
# A program that ends on SIGTERM (or SIGINT, SIGHUP) while it writes leaves
# no temporary file ("<output>.tmp.<pid>.<n>") behind: vdsh-merge (a
# 60 MB merge left its whole .vdsh temporary), vdsh-frames truth (a frame's),
# vdsh-eval (--json and --per-vertex), vdsh-export and vdsh-info --json.
# Deterministic: an LD_PRELOAD shim (kill_at_rename.c) sends SIGTERM at the
# first rename of a chosen output, when its temporary (and others') is
# written and not yet renamed. Each program must still end by the signal
# (exit 143); whatever it renamed is whole.
# vdsh-view --render too, when it can render (GL).
# Usage: test_signal_temporaries.sh SHIM.so VDSH_BAKE VDSH_MERGE VDSH_FRAMES VDSH_EVAL VDSH_EXPORT VDSH_INFO [VDSH_VIEW]
set -u
shim=$1 bake=$2 merge=$3 frames=$4 evaluate=$5 export=$6 info=$7 view=${8:-}
. "$(dirname "$0")/lib.sh"
make_tmp
d=$tmp/o
mkdir -p "$d"
tiny=(builtin:room:3 --max-edge 1.5 --rays 16 --cube-size 8 -q)
for i in 0 1; do
  "$bake" "${tiny[@]}" --shard $i/2 -o "$tmp/part-$i.vdsh" || { echo "FAIL: shard $i" >&2; exit 1; }
done
"$bake" "${tiny[@]}" -o "$tmp/scene.vdsh" || { echo "FAIL: bake" >&2; exit 1; }
"$frames" views "$tmp/scene.vdsh" -q --cameras 1 --size 32x24 -o "$tmp/v.json" || { echo "FAIL: views" >&2; exit 1; }

killed() { # killed WHAT AT COMMAND...: SIGTERM at the first rename to AT
  local what=$1 at=$2
  shift 2
  rm -rf "$d"; mkdir -p "$d"
  LD_PRELOAD=$shim VDSH_KILL_AT_RENAME=$at "$@" >/dev/null 2>"$tmp/err.txt"
  local rc=$?
  [[ $rc -eq 143 ]] || { echo "FAIL: $what: exit $rc, want 143 (SIGTERM); $(head -c 300 "$tmp/err.txt")" >&2; fail=1; }
  local left
  left=$(find "$d" -name '*.tmp.*')
  [[ -z $left ]] || { echo "FAIL: $what: temporary files left: $left" >&2; fail=1; }
}
killed "vdsh-merge" m.sh09 "$merge" -q "$tmp/part-0.vdsh" "$tmp/part-1.vdsh" -o "$d/m.vdsh"
# ... and its outputs change together: the signal at the first cubemap's
# rename waits for the rest (it left new cubemaps beside no .vdsh).
n=$(ls "$d"/m.vdsh "$d"/m.sh*.exr 2>/dev/null | wc -l)
[[ $n -eq 5 ]] || { echo "FAIL: vdsh-merge: $n of its 5 outputs written: $(ls "$d")" >&2; fail=1; }
killed "vdsh-frames truth" c-vdsh2 "$frames" truth "$tmp/scene.vdsh" --views "$tmp/v.json" -o "$d/f" -q
killed "vdsh-eval" e.json "$evaluate" "$tmp/scene.vdsh" -q --points 50 --interior 50 --json "$d/e.json" \
  --per-vertex "$d/e.pv"
n=$(ls "$d"/e.json "$d"/e.pv 2>/dev/null | wc -l)
[[ $n -eq 2 ]] || { echo "FAIL: vdsh-eval: $n of its 2 outputs (--json, --per-vertex) written: $(ls "$d")" >&2; fail=1; }
killed "vdsh-export" x.glb "$export" -q "$tmp/scene.vdsh" -o "$d/x.glb"
killed "vdsh-info --json" i.json "$info" --json "$d/i.json" "$tmp/scene.vdsh"
# The signal with no time for the signal thread before the program
# returns from main (a loaded machine): still the signal's exit status.
for i in 1 2 3 4 5; do
  VDSH_KILL_ONE_CPU=1 VDSH_KILL_SLEEP_US=0 killed "vdsh-export, no wait ($i)" x.glb "$export" -q "$tmp/scene.vdsh" -o "$d/x.glb"
  VDSH_KILL_ONE_CPU=1 VDSH_KILL_SLEEP_US=0 killed "vdsh-info --json, no wait ($i)" i.json "$info" --json "$d/i.json" "$tmp/scene.vdsh"
done
if [[ -n $view ]] && "$view" "$tmp/scene.vdsh" --render "$tmp/probe.png" --size 64x48 -q >/dev/null 2>&1; then
  killed "vdsh-view --render" r.png "$view" "$tmp/scene.vdsh" --render "$d/r.png" --size 64x48 -q
else
  echo "vdsh-view: not checked (no GL render)"
fi
[[ $fail -eq 0 ]] && echo "no temporary file left by SIGTERM"
exit $fail
