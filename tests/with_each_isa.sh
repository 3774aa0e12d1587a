#!/usr/bin/env bash
# with_each_isa.sh VDSH_BAKE CMD [ARGS...]: run CMD once for every Embree
# kernel set (ISA) this CPU supports - sse4.2, avx, avx2, avx512 - with
# VDSH_EMBREE_CONFIG=isa=X, which vdsh-bake and the bake library append to
# Embree's device configuration. Before each run it checks, with Embree's
# verbose report of a tiny bake, that the device really runs that ISA's
# kernels and nothing wider. Fails if any run fails; prints which ran.
# A bake must be right on every x86-64 CPU: a suite that passes only with
# the widest kernels of the machine it was written on proves nothing.
set -u
bake=$1
shift
flags=$(grep -m1 '^flags' /proc/cpuinfo 2>/dev/null || true)
has() { [[ " $flags " == *" $1 "* ]]; }
isas=()
has sse4_2 && isas+=(sse4.2)
has avx && isas+=(avx)
has avx2 && has fma && has bmi2 && isas+=(avx2)
has avx512f && has avx512dq && has avx512cd && has avx512bw && has avx512vl && isas+=(avx512)
if ((${#isas[@]} == 0)); then
  echo "with_each_isa: no x86-64 ISA found in /proc/cpuinfo: running once, natively"
  exec "$@"
fi
top() { # the widest target in Embree's "Config" report
  case $1 in sse4.2) echo "SSE4.2" ;; avx) echo "AVX" ;; avx2) echo "AVX2" ;; avx512) echo "AVX512" ;; esac
}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
for isa in "${isas[@]}"; do
  VDSH_EMBREE_CONFIG="isa=$isa,verbose=1" "$bake" builtin:room --rays 4 --cube-size 4 \
    -o "$tmp/probe.vdsh" >"$tmp/verbose" 2>&1
  # Config's "Targets :" line lists the kernels in use; the next one
  # wider than asked must not be among them.
  targets=$(awk '/^  Config/{c=1} c && /Targets/{print; exit}' "$tmp/verbose")
  want=$(top "$isa")
  if [[ " $targets " != *" $want "* ]] ||
     { [[ $isa != avx512 ]] && [[ " $targets " == *" AVX512 "* ]]; } ||
     { [[ $isa == sse4.2 ]] && [[ " $targets " == *" AVX "* ]]; }; then
    echo "FAIL: isa=$isa: Embree reports targets '$targets'" >&2
    fail=1
    continue
  fi
  echo "== isa=$isa (Embree targets:${targets#*:})"
  if ! VDSH_EMBREE_CONFIG="isa=$isa" "$@"; then
    echo "FAIL: isa=$isa: $*" >&2
    fail=1
  fi
done
echo "with_each_isa: ran under ${isas[*]}"
exit $fail
