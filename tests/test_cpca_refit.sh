#!/usr/bin/env bash
# The cpca encoder's quantisation-aware refit (issue 29) on a real baked
# stream: an order-12 f32 bake of the builtin room, fitted by
# test_cpca_refit with the uniform metric or with a light pool (light mix
# 1, the default's metric), every check of test_cpca_refit.c.
# Usage: test_cpca_refit.sh VDSH_BAKE TEST_CPCA_REFIT LIGHT_POOL_TOOL uniform|lights
# (one metric per run, so that ctest runs the two side by side)
set -u
bake=$1 refit=$2 pooltool=$3 metric=$4
. "$(dirname "$0")/lib.sh"
make_tmp

expect_exit 0 "order-12 f32 bake" "$bake" builtin:room --max-edge 1.0 --rays 64 --cube-size 0 -q \
  --orders 12 --encoding f32 -o "$tmp/room.vdsh"
if [ "$metric" = uniform ]; then
  check "refit, uniform metric" "$refit" "$tmp/room.vdsh"
else
  expect_exit 0 "light pool" "$pooltool" builtin:room 256 bake:1 "$tmp/pool.f32"
  check "refit, light mix 1" "$refit" "$tmp/room.vdsh" "$tmp/pool.f32"
fi
exit $fail
