#!/usr/bin/env bash
# vdsh-frames truth writes its folder whole or not at all (a failed or
# killed run left the frames written so far in DIR, which a later score
# read as a whole truth): a run killed by SIGTERM part-way (the shim
# kill_at_rename.c, at the first c-vdsh2 frame) leaves no DIR and no
# temporary folder; into an earlier truth's DIR, it leaves that truth as
# it was; a run that fails (a folder where a frame goes) exits 1 naming
# it and moves nothing into DIR; a run that succeeds into an existing DIR
# replaces its frames; DIR a link to a folder works.
# Usage: test_truth_whole.sh SHIM.so VDSH_BAKE VDSH_FRAMES
set -u
shim=$1 bake=$2 frames=$3
. "$(dirname "$0")/lib.sh"
make_tmp
"$bake" builtin:room:3 --max-edge 1.5 --rays 16 --cube-size 8 -q -o "$tmp/scene.vdsh" || { echo "FAIL: bake" >&2; exit 1; }
"$frames" views "$tmp/scene.vdsh" -q --cameras 1 --size 32x24 -o "$tmp/v.json" || { echo "FAIL: views" >&2; exit 1; }
truth=("$frames" truth "$tmp/scene.vdsh" --views "$tmp/v.json" -q)
"${truth[@]}" -o "$tmp/full" || { echo "FAIL: truth" >&2; exit 1; }
ls "$tmp/full"/*-c-vdsh2.png >/dev/null 2>&1 || { echo "FAIL: no c-vdsh2 frames: $(ls "$tmp/full")" >&2; exit 1; }
[[ $(stat -c %a "$tmp/full") == $(mkdir "$tmp/m" && stat -c %a "$tmp/m") ]] ||
  { echo "FAIL: the truth folder's mode $(stat -c %a "$tmp/full"), not a new folder's" >&2; fail=1; }
leftovers() { find "$tmp" -name '*.tmp.*'; }
# Killed part-way into a new folder: no folder.
LD_PRELOAD=$shim VDSH_KILL_AT_RENAME=c-vdsh2 "${truth[@]}" -o "$tmp/killed" 2>"$tmp/err.txt"
rc=$?
[[ $rc -eq 143 ]] || { echo "FAIL: killed: exit $rc, want 143: $(head -c 300 "$tmp/err.txt")" >&2; fail=1; }
[[ -e $tmp/killed ]] && { echo "FAIL: killed: a partial truth left: $(ls "$tmp/killed")" >&2; fail=1; }
[[ -z $(leftovers) ]] || { echo "FAIL: killed: left $(leftovers)" >&2; fail=1; }
# Killed part-way into an earlier truth: that truth as it was.
cp -a "$tmp/full" "$tmp/again"
touch -d @1000000000 "$tmp/again"/*.png
before=$(cd "$tmp/again" && ls -l --time-style=+%s)
LD_PRELOAD=$shim VDSH_KILL_AT_RENAME=c-vdsh2 "${truth[@]}" -o "$tmp/again" 2>"$tmp/err.txt"
[[ $(cd "$tmp/again" && ls -l --time-style=+%s) == "$before" ]] ||
  { echo "FAIL: killed into an earlier truth: it changed" >&2; fail=1; }
[[ -z $(leftovers) ]] || { echo "FAIL: killed into an earlier truth: left $(leftovers)" >&2; fail=1; }
# A failure (a folder where a frame goes): exit 1 naming it, nothing moved in.
hard=$(cd "$tmp/full" && ls *-s0-l0-hard.png | head -n 1)
mkdir -p "$tmp/blocked/$hard"
expect_exit 1 "a folder where a frame goes" "${truth[@]}" -o "$tmp/blocked"
says "a folder where a frame goes" "$tmp/blocked/$hard: a folder of that name is there"
[[ $(ls "$tmp/blocked") == "$hard" ]] || { echo "FAIL: a failed run wrote into DIR: $(ls "$tmp/blocked")" >&2; fail=1; }
[[ -z $(leftovers) ]] || { echo "FAIL: a failed run left $(leftovers)" >&2; fail=1; }
# A run that succeeds into an existing folder (with a file of the user's),
# and through a link to a folder.
echo mine >"$tmp/again/notes.txt"
"${truth[@]}" -o "$tmp/again" || { echo "FAIL: truth into an existing folder" >&2; fail=1; }
for f in "$tmp/full"/*.png; do
  cmp -s "$f" "$tmp/again/${f##*/}" || { echo "FAIL: ${f##*/} not replaced" >&2; fail=1; }
done
[[ -e $tmp/again/notes.txt ]] || { echo "FAIL: the user's file removed" >&2; fail=1; }
ln -s again "$tmp/link"
"${truth[@]}" -o "$tmp/link/" || { echo "FAIL: truth into a link to a folder" >&2; fail=1; }
[[ -L $tmp/link && -e $tmp/again/$hard ]] || { echo "FAIL: the link replaced" >&2; fail=1; }
[[ -z $(leftovers) ]] || { echo "FAIL: left $(leftovers)" >&2; fail=1; }
exit $fail
