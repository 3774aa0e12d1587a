#!/usr/bin/env bash
# The README's scripts take --help (exit 0, their usage on stdout, nothing
# run) and refuse an unknown option (exit 2, the option named, nothing
# run): `scripts/demo --help` ran the demo with an output folder named
# --help, `scripts/test -R x` the whole suite. Each script runs from a copy
# in a scratch tree, so that one that ignored the option would find no
# sources there instead of building or testing this checkout.
# Usage: test_scripts_help.sh SOURCE_DIR
set -u
src=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/scripts"
fail=0
for s in demo test setup format_check bake-parallel bake-slurm shard_args.sh; do
  cp "$src/scripts/$s" "$tmp/scripts/$s"
done
for s in demo test setup format_check bake-parallel bake-slurm; do
  out=$(cd "$tmp" && timeout 30 bash "scripts/$s" --help 2>"$tmp/err"); rc=$?
  if [[ $rc -ne 0 || $out != *"scripts/$s"* || -s $tmp/err ]]; then
    echo "FAIL: scripts/$s --help: exit $rc, want 0 and its usage; stdout: ${out:0:200}; stderr: $(head -c 300 "$tmp/err")" >&2
    fail=1
  fi
done
for s in demo test setup format_check; do
  out=$(cd "$tmp" && timeout 30 bash "scripts/$s" --bogus 2>"$tmp/err"); rc=$?
  if [[ $rc -ne 2 ]] || ! grep -q -- "--bogus" "$tmp/err"; then
    echo "FAIL: scripts/$s --bogus: exit $rc, want 2 naming the option; stderr: $(head -c 300 "$tmp/err")" >&2
    fail=1
  fi
done
# The measuring and helper scripts: --help exits 0 with the usage on
# stdout, an unknown option exits 2 (npm_gltf_tools --help ran
# `mkdir --help` and npm with a folder named --help; bench_gltf_load
# --help baked with an argument '--help'; obj_to_glb.py gave a traceback;
# bench_shard, fuzz and reference_set --help exited 2, bench_gltf_libs 1
# without libassimp-dev). Python ones through /usr/bin/python3 (Debian's,
# as their #! says).
for s in bench_gltf_libs bench_gltf_load bench_shard fuzz gpu_bundle npm_gltf_tools obj_to_glb.py plot_shard_rss \
         reference_set; do
  cp "$src/scripts/$s" "$tmp/scripts/$s"
  case $s in *.py | plot_shard_rss) run=(/usr/bin/python3) ;; *) run=(bash) ;; esac
  out=$(cd "$tmp" && timeout 30 "${run[@]}" "scripts/$s" --help 2>"$tmp/err"); rc=$?
  if [[ $rc -ne 0 || -z $out || -s $tmp/err ]]; then
    echo "FAIL: scripts/$s --help: exit $rc, want 0 and its usage on stdout; stdout: ${out:0:200}; stderr: $(head -c 300 "$tmp/err")" >&2
    fail=1
  fi
  out=$(cd "$tmp" && timeout 30 "${run[@]}" "scripts/$s" --bogus 2>"$tmp/err"); rc=$?
  if [[ $rc -ne 2 ]] || grep -q Traceback "$tmp/err"; then
    echo "FAIL: scripts/$s --bogus: exit $rc, want 2; stderr: $(head -c 300 "$tmp/err")" >&2
    fail=1
  fi
done
# A measurement's name then --help prints the usage and measures
# nothing (bench_shard rss --help ran rss).
out=$(cd "$tmp" && BUILD=$tmp/none timeout 30 bash scripts/bench_shard rss --help 2>"$tmp/err"); rc=$?
if [[ $rc -ne 0 || $out != *"scripts/bench_shard rss"* || -s $tmp/err ]]; then
  echo "FAIL: scripts/bench_shard rss --help: exit $rc, want 0 and the usage; stderr: $(head -c 300 "$tmp/err")" >&2
  fail=1
fi
rm -f "$tmp/err"
leftover=$(cd "$tmp" && ls -A | grep -v '^scripts$' | grep -v '^err$')
[[ -z $leftover ]] || { echo "FAIL: the scripts left files: $leftover" >&2; fail=1; }
[[ $fail -eq 0 ]] && echo "scripts: --help and unknown options handled"
exit $fail
