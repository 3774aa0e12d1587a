#!/usr/bin/env bash
# tests/test_format_check.sh SRC WORK: scripts/format_check itself. In a
# tree without git (its find fallback) it passes a formatted file, fails
# (exit 1) on a misformatted one and names it, and skips build folders.
set -u
src=$1 work=$2
rm -rf "$work" && mkdir -p "$work/lib" "$work/build"
cp "$src/.clang-format" "$work/"
fail=0
printf 'int f(int x)\n{\n    return x + 1;\n}\n' >"$work/lib/good.c"
printf 'int  g ( int x ){return x;}\n' >"$work/build/generated.c"
out=$(bash "$src/scripts/format_check" "$work" 2>&1); rc=$?
[ $rc -eq 0 ] || { echo "FAIL: formatted tree (build/ skipped): exit $rc: $out"; fail=1; }
printf 'int  g ( int x ){return x;}\n' >"$work/lib/bad.c"
out=$(bash "$src/scripts/format_check" "$work" 2>&1); rc=$?
[ $rc -eq 1 ] || { echo "FAIL: misformatted file: exit $rc, not 1: $out"; fail=1; }
grep -q 'lib/bad.c' <<<"$out" || { echo "FAIL: misformatted file not named: $out"; fail=1; }
grep -q 'good.c\|generated.c' <<<"$out" && { echo "FAIL: a formatted or build file named: $out"; fail=1; }
[ $fail -eq 0 ] && echo "format_check: passes a formatted tree, names a misformatted file"
exit $fail
