#!/usr/bin/env bash
# No fused multiply-add instruction in the project's programs (docs/DESIGN.md,
# "Across CPUs, decision by decision"): a plain float expression must round
# the same on every x86-64 CPU, so the build contracts nothing
# (-ffp-contract=off, CMakeLists.txt) and no target_clones or -march brings
# FMA in. Without the flag a -march=native build had 162 (C++: glTF node
# transforms, refinement), and its glTF bakes other bytes. Embree's own
# kernels (a shared library) are not looked at. Skips (77) without objdump.
# Usage: test_no_fma.sh PROGRAM...
set -u
command -v objdump >/dev/null 2>&1 || { echo "no objdump: skipped"; exit 77; }
fail=0
for p in "$@"; do
  n=$(objdump -d --no-show-raw-insn "$p" | grep -cE '\svfn?m(add|sub)[0-9a-z]*\s')
  if [[ $n != 0 ]]; then
    echo "FAIL: $p has $n FMA instructions:" >&2
    objdump -d --no-show-raw-insn -C "$p" |
      awk '/>:$/ { fn = $0 } /[[:space:]]vfn?m(add|sub)[0-9a-z]*[[:space:]]/ { c[fn]++ } END { for (f in c) print "  " c[f], f }' |
      sort -rn | head -5 | cut -c1-160 >&2
    fail=1
  fi
done
((fail)) || echo "no FMA instruction in $#" programs
exit $fail
