#!/usr/bin/env bash
# A bake's bytes do not depend on the CPU it runs on (brief: "whatever a
# bake decides must hold on any x86-64 CPU"). Two things differ between
# x86-64 CPUs besides Embree's kernels (tests/with_each_isa.sh):
#   - glibc's libm picks an FMA or an SSE2 code path for cos, sin, exp,
#     log, acos, atan2, log10 (double): their results differ in the last
#     bit for some arguments. GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX2,-FMA,-AVX
#     makes glibc choose the paths of a CPU without them;
#   - the bake's target_clones functions (bake/lib, formats/vdsh_sh.c) run
#     their AVX2 clone where the CPU has AVX2 and the baseline one
#     elsewhere. A sanitizer build has no clones (baseline code only): given
#     REF_BAKE, another build's vdsh-bake, its bytes are compared with it.
# Each case is baked natively and with glibc's baseline paths (or, given
# REF_BAKE, natively by both builds), one thread, and every output file
# compared byte for byte.
# On a CPU with FMA, LIBM_PROBE (a hash of libm results) must differ under
# the tunable: else glibc ignored it and the comparison would prove nothing.
# Usage: test_same_bytes_any_cpu.sh VDSH_BAKE LIBM_PROBE SCENES_DIR [REF_BAKE]
set -u
bake=$1 probe=$2 scenes=$3 ref=${4:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
baseline=glibc.cpu.hwcaps=-AVX2,-FMA,-AVX
export ASAN_OPTIONS=${ASAN_OPTIONS:-}${ASAN_OPTIONS:+:}detect_leaks=0

if [[ -z $ref ]] && grep -qw fma /proc/cpuinfo 2>/dev/null; then
  if [[ $("$probe") == "$(GLIBC_TUNABLES=$baseline "$probe")" ]]; then
    echo "FAIL: GLIBC_TUNABLES=$baseline did not change libm's results on this FMA CPU:" \
      "the baseline comparison would prove nothing" >&2
    exit 1
  fi
  echo "libm: the baseline paths give other bits than the native ones (as expected)"
fi

cases=(
  "builtin:room --max-edge 0.8 --rays 196"
  "builtin:room --max-edge 0.8 --rays 196 --method paper --cube-size 8"
  "builtin:room --max-edge 0.8 --rays 196 --method shadow --orders 2,5,12 --cube-size 0"
  "builtin:room:3 --max-edge 1 --rays 144 --adaptive-order 0.02 --cube-size 0"
  "builtin:room --max-edge 1 --adaptive 0.05 --rays 144 --cube-size 0"
  "builtin:room --max-edge 1 --rays auto --cube-size 0"
  "builtin:room --max-edge 1 --rays 100 --orders 12 --encoding cpca --cube-size 0"
  "builtin:room --max-edge 1 --rays 100 --orders 12 --encoding cpca --cpca margin:0.25,starts:2 --cube-size 0"
  "builtin:room --max-edge 1 --rays 100 --cube-size 0 --sdf 24"
)
if [[ -f $scenes/fandisk/fandisk.obj ]]; then
  cases+=("$scenes/fandisk/fandisk.obj --rays 100 --cube-size 0")
fi

fail=0
n=0
for c in "${cases[@]}"; do
  n=$((n + 1))
  read -r -a args <<<"$c"
  # With REF_BAKE (a sanitizer build, slow) only the clones are compared:
  # the libm paths are the plain build's test.
  if [[ -n $ref ]]; then runs=(native reference); else runs=(native baseline); fi
  for r in "${runs[@]}"; do
    mkdir -p "$tmp/$r"
    case $r in
      native) cmd=("$bake") ;;
      baseline) cmd=(env GLIBC_TUNABLES=$baseline "$bake") ;;
      reference) cmd=("$ref") ;;
    esac
    if ! "${cmd[@]}" "${args[@]}" --threads 1 -q -o "$tmp/$r/c$n.vdsh" >"$tmp/$r.log" 2>&1; then
      echo "FAIL: case $n ($r) did not bake: $c" >&2
      cat "$tmp/$r.log" >&2
      fail=1
    fi
  done
done
for r in baseline reference; do
  [[ -d $tmp/$r ]] || continue
  for f in "$tmp"/native/*; do
    g=$tmp/$r/$(basename "$f")
    if ! cmp -s "$f" "$g"; then
      echo "FAIL: $(basename "$f"): $r bytes differ from native ($(cmp "$f" "$g" 2>&1 | head -1))" >&2
      fail=1
    fi
  done
  [[ $(ls "$tmp/native" | wc -l) == "$(ls "$tmp/$r" | wc -l)" ]] ||
    { echo "FAIL: $r wrote other files than native" >&2; fail=1; }
done
echo "same_bytes_any_cpu: $n cases, $(ls "$tmp/native" | wc -l) files, compared with:" \
  "${ref:-glibc baseline paths}"
exit $fail
