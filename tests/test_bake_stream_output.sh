#!/usr/bin/env bash
# -o naming a device or pipe (/dev/null, /dev/stdout, a FIFO): the .vdsh is
# written in place, byte for byte the regular file's, and the basis
# cubemaps, which go beside OUT, are left out (said on stderr) unless
# --cubemap-dir names a folder: `vdsh-bake m.obj -o /dev/null` wrote
# /dev/null.sh09-12.exr ... into /dev. --sdf (OUT's companion file) with
# such an OUT is a usage error; vdsh-merge does as vdsh-bake.
# Usage: test_bake_stream_output.sh VDSH_BAKE VDSH_MERGE
set -u
bake=$1 merge=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
no() { echo "FAIL: $*" >&2; fail=1; }
# a floor and a box on it
cp "$(dirname "$0")/data/cube_floor.obj" "$tmp/m.obj"
opts=(--rays 64 -q)
cd "$tmp" || exit 1
"$bake" m.obj "${opts[@]}" -o ref.vdsh || { echo "FAIL: the regular bake" >&2; exit 1; }
[ -f ref.sh09-12.exr ] || no "a regular bake wrote no cubemaps beside its file"
# /dev/stdout, redirected to a file
# 0 when /dev/NAME.shXX-YY.exr were written (removed then: root can write /dev)
leak() {
  local k found=1
  for k in 09-12 13-16 17-20 21-24; do
    [ -e "/dev/$1.sh$k.exr" ] && { rm -f "/dev/$1.sh$k.exr"; found=0; }
  done
  return $found
}
"$bake" m.obj "${opts[@]}" -o /dev/stdout > so.vdsh; rc=$?
[ $rc -eq 0 ] || no "-o /dev/stdout: exit $rc"
cmp -s so.vdsh ref.vdsh || no "-o /dev/stdout: not the regular file's bytes"
leak stdout && no "-o /dev/stdout wrote cubemaps into /dev"
# /dev/null
"$bake" m.obj --rays 64 -o /dev/null 2> err; rc=$?
[ $rc -eq 0 ] || no "-o /dev/null: exit $rc: $(cat err)"
leak null && no "-o /dev/null wrote cubemaps into /dev"
grep -q "without its basis cubemaps" err || no "-o /dev/null: not said that the cubemaps were left out: $(tail -2 err)"
# a FIFO: the bytes come through it, nothing beside it
mkfifo pipe.vdsh
cat pipe.vdsh > got.vdsh & reader=$!
"$bake" m.obj "${opts[@]}" -o pipe.vdsh; rc=$?
wait $reader
[ $rc -eq 0 ] || no "-o FIFO: exit $rc"
cmp -s got.vdsh ref.vdsh || no "-o FIFO: not the regular file's bytes"
ls pipe.sh*.exr > /dev/null 2>&1 && no "-o FIFO wrote cubemaps beside the FIFO"
# --cubemap-dir still writes them
mkdir cubes
cat pipe.vdsh > /dev/null & reader=$!
"$bake" m.obj "${opts[@]}" -o pipe.vdsh --cubemap-dir cubes; rc=$?
wait $reader
[ $rc -eq 0 ] && cmp -s cubes/pipe.sh09-12.exr ref.sh09-12.exr ||
  no "-o FIFO --cubemap-dir: exit $rc, cubemaps $(ls cubes)"
# --sdf beside a device: refused before any work
"$bake" m.obj "${opts[@]}" --sdf 8 -o /dev/null 2> err; rc=$?
[ $rc -eq 2 ] && grep -q -- "--sdf" err || no "--sdf -o /dev/null: exit $rc, want 2: $(cat err)"
[ -e /dev/null.sdf ] && { rm -f /dev/null.sdf; no "--sdf -o /dev/null wrote /dev/null.sdf"; }
# vdsh-merge
for i in 0 1; do "$bake" m.obj "${opts[@]}" --shard $i/2 -o part-$i.vdsh || no "shard $i"; done
"$merge" part-0.vdsh part-1.vdsh -o /dev/null 2> err; rc=$?
[ $rc -eq 0 ] || no "vdsh-merge -o /dev/null: exit $rc: $(cat err)"
leak null && no "vdsh-merge -o /dev/null wrote cubemaps into /dev"
"$merge" part-0.vdsh part-1.vdsh -q -o /dev/stdout > merged.vdsh; rc=$?
[ $rc -eq 0 ] && cmp -s merged.vdsh ref.vdsh || no "vdsh-merge -o /dev/stdout: exit $rc or not the whole bake's bytes"
leak stdout && no "vdsh-merge -o /dev/stdout wrote cubemaps into /dev"
[ $fail -eq 0 ] && echo "device and pipe outputs: written in place, no cubemaps beside them"
exit $fail
