#!/usr/bin/env bash
# scripts/bake-parallel with real GNU parallel: 5 shards on local job slots
# merge to the whole bake's file byte for byte, into an output whose name
# has a space, a quote, a dollar sign (issue 26) and braces; a rerun with a part
# already there bakes only the others. The usage text is the header comment
# only (issue 26: it ended with the script's `set -euo pipefail`). Installs
# Debian's parallel when root and it is missing; skips (77) when it cannot
# be had. Each shard's progress is in the output. OUT in a missing folder
# is refused before any shard runs, and so is a parallel that is not GNU's.
# --sshlogin hosts need no bash (a POSIX sh runs the shards).
# --report R.json among the bake's arguments: each shard writes R.part-I.json;
# a rerun with fewer shards removes the extra shards' reports and refuses
# their parts.
# Usage: test_shard_parallel.sh VDSH_BAKE VDSH_MERGE SCRIPTS_DIR
set -u
bake=$1 merge=$2 scripts=$3
. "$(dirname "$0")/lib.sh"
# The usage text (needs no parallel).
check_recipe_usage bake-parallel
if ! command -v parallel >/dev/null; then
  if [[ $(id -u) -eq 0 ]]; then
    apt-get install -y --no-install-recommends parallel >/dev/null 2>&1 || true
  fi
  command -v parallel >/dev/null || { [[ $fail -eq 0 ]] || exit 1; echo "SKIP: no GNU parallel"; exit 77; }
fi
make_tmp
tiny=(builtin:room --max-edge 1.5 --rays 32 --cube-size 8)
# Without GNU parallel on PATH: said, exit 1, nothing baked (was bash's
# "parallel: command not found", 127).
mkdir -p "$tmp/bin"
for t in bash dirname rm; do ln -s "$(command -v $t)" "$tmp/bin/$t"; done
msg=$(PATH=$tmp/bin VDSH_BAKE=$bake VDSH_MERGE=$merge "$tmp/bin/bash" "$scripts/bake-parallel" 2 "$tmp/nopar.vdsh" -- "${tiny[@]}" 2>&1)
rc=$?
[[ $rc -eq 1 && $msg == *"no GNU parallel"* ]] || { echo "FAIL: without parallel: exit $rc: $msg" >&2; fail=1; }
ls "$tmp"/nopar* >/dev/null 2>&1 && { echo "FAIL: without parallel: files written" >&2; fail=1; }
# vdsh-bake's own output or shard among its arguments: refused, exit 2,
# nothing baked (a user's -o was silently overridden by the script's).
for a in "-o $tmp/y.vdsh" "--output=$tmp/y.vdsh" "--shard 1/2" "--out $tmp/y.vdsh" "--outp=$tmp/y.vdsh" "--sha 1/2" "--sh=1/2"; do
  msg=$(VDSH_BAKE=$bake VDSH_MERGE=$merge "$scripts/bake-parallel" 2 "$tmp/x.vdsh" -- "${tiny[@]}" $a 2>&1)
  rc=$?
  [[ $rc -eq 2 && $msg == *"among vdsh-bake's arguments"* ]] || { echo "FAIL: '$a': exit $rc: $msg" >&2; fail=1; }
done
ls "$tmp"/[xy].* "$tmp"/x.part-* >/dev/null 2>&1 && { echo "FAIL: -o among the arguments: files written" >&2; fail=1; }
# moreutils' parallel (same name, other options) first on PATH: said, exit 1
# (the run failed with that program's usage line).
mkdir -p "$tmp/mu"
printf '#!/bin/sh\necho "parallel [OPTIONS] command -- arguments" >&2\nexit 1\n' >"$tmp/mu/parallel"
chmod +x "$tmp/mu/parallel"
msg=$(PATH=$tmp/mu:$PATH VDSH_BAKE=$bake VDSH_MERGE=$merge "$scripts/bake-parallel" 2 "$tmp/mu.vdsh" -- "${tiny[@]}" 2>&1)
rc=$?
[[ $rc -eq 1 && $msg == *"is not GNU parallel"* ]] || { echo "FAIL: moreutils' parallel: exit $rc: $msg" >&2; fail=1; }
# OUT in a folder that does not exist: said before any shard runs, exit 1.
msg=$(VDSH_BAKE=$bake VDSH_MERGE=$merge "$scripts/bake-parallel" 2 "$tmp/nodir/x.vdsh" -- "${tiny[@]}" 2>&1)
rc=$?
[[ $rc -eq 1 && $msg == *"no folder '$tmp/nodir'"* && $msg != *vdsh-bake* ]] ||
  { echo "FAIL: OUT in a missing folder: exit $rc: $msg" >&2; fail=1; }
"$bake" "${tiny[@]}" -q -o "$tmp/whole.vdsh" || { echo "FAIL: whole bake" >&2; exit 1; }
export VDSH_BAKE=$bake VDSH_MERGE=$merge
name="$tmp/it's a \$cene {} {1}" # '{}' and '{1}': parallel's replacement strings (they became the shard)
if ! "$scripts/bake-parallel" 5 "$name.vdsh" -j 2 -- "${tiny[@]}" 2>"$tmp/err.txt"; then
  echo "FAIL: bake-parallel:" >&2; cat "$tmp/err.txt" >&2; fail=1
fi
cmp "$name.vdsh" "$tmp/whole.vdsh" || { echo "FAIL: parallel merge differs" >&2; fail=1; }
# The shards' progress stays in the output (the recipe no longer passes -q).
[[ $(grep -c '^vdsh-bake: 100.0%' "$tmp/err.txt") -ge 5 ]] ||
  { echo "FAIL: 5 shards' progress expected:" >&2; cat "$tmp/err.txt" >&2; fail=1; }
for k in 09-12 13-16 17-20 21-24; do
  cmp "$name.sh$k.exr" "$tmp/whole.sh$k.exr" || { echo "FAIL: cubemap $k" >&2; fail=1; }
done
ls "$name".part-* >/dev/null 2>&1 && { echo "FAIL: parts left behind" >&2; fail=1; }
# A rerun after a failure: part 2 is there, the other four are baked (a
# wrapper logs the shards it runs), and the merge is the whole bake's.
"$bake" "${tiny[@]}" -q --shard 2/5 -o "$tmp/again.part-2.vdsh" || { echo "FAIL: shard 2/5" >&2; fail=1; }
printf '#!/bin/sh\nfor a in "$@"; do case $a in */5) echo "$a" >> %q;; esac; done\nexec %q "$@"\n' \
  "$tmp/shards.log" "$bake" > "$tmp/logging-bake"
chmod +x "$tmp/logging-bake"
VDSH_BAKE=$tmp/logging-bake "$scripts/bake-parallel" 5 "$tmp/again.vdsh" -j 2 -- "${tiny[@]}" 2>"$tmp/err.txt" ||
  { echo "FAIL: bake-parallel rerun:" >&2; cat "$tmp/err.txt" >&2; fail=1; }
ran=$(sort "$tmp/shards.log" 2>/dev/null | tr '\n' ' ')
[[ $ran == "0/5 1/5 3/5 4/5 " ]] || { echo "FAIL: the rerun baked shards '$ran', not 0 1 3 4" >&2; fail=1; }
cmp "$tmp/again.vdsh" "$tmp/whole.vdsh" || { echo "FAIL: rerun merge differs" >&2; fail=1; }
# --sshlogin with hosts that have no bash, only a POSIX sh (dash) and what
# GNU parallel needs there (perl, rm): an ssh of our own (PARALLEL_SSH)
# runs the host's command line with sh and a PATH of those only (the shard
# ran as "bash -c ...": "bash: not found").
mkdir -p "$tmp/nobash"
for t in perl sh rm; do ln -s "$(command -v $t)" "$tmp/nobash/$t"; done
cat >"$tmp/fakessh" <<SSH
#!/bin/sh
while [ \$# -gt 0 ]; do case \$1 in -o|-l|-p) shift 2;; --) shift; break;; -*) shift;; *) shift; [ "\${1:-}" = -- ] && shift; break;; esac; done
SHELL=/bin/sh PATH=$tmp/nobash exec /bin/sh -c "\$*"
SSH
chmod +x "$tmp/fakessh"
PARALLEL_SSH=$tmp/fakessh "$scripts/bake-parallel" 3 "$tmp/ssh it's.vdsh" --sshlogin 2/nobashhost -- "${tiny[@]}" 2>"$tmp/err.txt" ||
  { echo "FAIL: bake-parallel --sshlogin to a host without bash:" >&2; tail -5 "$tmp/err.txt" >&2; fail=1; }
cmp -s "$tmp/ssh it's.vdsh" "$tmp/whole.vdsh" || { echo "FAIL: --sshlogin without bash: merge differs" >&2; fail=1; }
# A failing shard fails the run and writes no merged file.
if "$scripts/bake-parallel" 3 "$tmp/bad.vdsh" -- "${tiny[@]}" --rays 0 2>/dev/null; then
  echo "FAIL: a failing shard did not fail the run" >&2; fail=1
fi
[[ -e $tmp/bad.vdsh ]] && { echo "FAIL: merged despite a failed shard" >&2; fail=1; }
# --report among vdsh-bake's arguments: each shard writes its own report,
# named like its part (every shard wrote the same file, the last one won).
for form in "--report $tmp/rep.json" "--report=$tmp/rep.json" "--repo $tmp/rep.json"; do
  rm -f "$tmp"/rep*.json "$tmp/rep.vdsh"
  "$scripts/bake-parallel" 3 "$tmp/rep.vdsh" -j 2 -- "${tiny[@]}" $form 2>/dev/null ||
    { echo "FAIL: bake-parallel with '$form'" >&2; fail=1; }
  cmp -s "$tmp/rep.vdsh" "$tmp/whole.vdsh" || { echo "FAIL: '$form': merge differs" >&2; fail=1; }
  [[ -e $tmp/rep.json ]] && { echo "FAIL: '$form': every shard wrote rep.json" >&2; fail=1; }
  for i in 0 1 2; do
    grep -q '"seconds"' "$tmp/rep.part-$i.json" 2>/dev/null ||
      { echo "FAIL: '$form': no report rep.part-$i.json for shard $i" >&2; fail=1; }
  done
done
# A rerun with fewer shards: the reports of the earlier run's extra shards
# are removed (rep.part-3.json and -4 stayed beside the new 0-2), and a
# part of it with an index the rerun does not have is refused, naming it.
rm -f "$tmp"/rep*.json "$tmp/rep.vdsh"
"$scripts/bake-parallel" 5 "$tmp/rep.vdsh" -j 2 -- "${tiny[@]}" --report "$tmp/rep.json" 2>/dev/null ||
  { echo "FAIL: bake-parallel 5 shards with --report" >&2; fail=1; }
[[ -e $tmp/rep.part-4.json ]] || { echo "FAIL: 5 shards wrote no rep.part-4.json" >&2; fail=1; }
"$scripts/bake-parallel" 3 "$tmp/rep.vdsh" -j 2 -- "${tiny[@]}" --report "$tmp/rep.json" 2>"$tmp/err.txt" ||
  { echo "FAIL: bake-parallel 3 shards after 5:" >&2; cat "$tmp/err.txt" >&2; fail=1; }
cmp -s "$tmp/rep.vdsh" "$tmp/whole.vdsh" || { echo "FAIL: 3 shards after 5: merge differs" >&2; fail=1; }
for i in 3 4; do
  [[ -e $tmp/rep.part-$i.json ]] && { echo "FAIL: the stale report rep.part-$i.json kept" >&2; fail=1; }
done
grep -q "removed '$tmp/rep.part-4.json'" "$tmp/err.txt" || { echo "FAIL: the removal not said:" >&2; cat "$tmp/err.txt" >&2; fail=1; }
for i in 0 1 2; do
  grep -q '"seconds"' "$tmp/rep.part-$i.json" 2>/dev/null || { echo "FAIL: 3 shards after 5: no rep.part-$i.json" >&2; fail=1; }
done
"$bake" "${tiny[@]}" -q --shard 4/5 -o "$tmp/stale.part-4.vdsh" || { echo "FAIL: shard 4/5" >&2; fail=1; }
printf '#!/bin/sh\necho ran >> %q\nexec %q "$@"\n' "$tmp/stale.log" "$bake" > "$tmp/stale-bake"
chmod +x "$tmp/stale-bake"
msg=$(VDSH_BAKE=$tmp/stale-bake "$scripts/bake-parallel" 3 "$tmp/stale.vdsh" -- "${tiny[@]}" 2>&1)
rc=$?
[[ $rc -eq 1 && $msg == *"'$tmp/stale.part-4.vdsh' is a part of a bake with more than 3 shards"* ]] ||
  { echo "FAIL: a part of a run with more shards: exit $rc: $msg" >&2; fail=1; }
[[ -e $tmp/stale.log || -e $tmp/stale.vdsh ]] && { echo "FAIL: a part of a run with more shards: shards baked" >&2; fail=1; }
msg=$("$scripts/bake-parallel" 2 "$tmp/rep2.vdsh" -- "${tiny[@]}" --report 2>&1)
rc=$?
[[ $rc -eq 2 && $msg == *"without a FILE"* ]] || { echo "FAIL: --report without FILE: exit $rc: $msg" >&2; fail=1; }
exit $fail
