#!/usr/bin/env bash
# vdsh-bake --encoding cpca --cpca auto[:BYTES] (issue 29): the encoder
# picks K, B and bits per stream within a byte budget. Whatever it picks
# is one global step like any cpca fit, so 1 and 2 threads, and 3 shards
# merged, give the same bytes; every stream's bytes per vertex (records
# plus the model, vdsh-info --json) stay within the budget (a tight 12,
# which leaves a small mesh's order 5 a part of its basis, and the
# default 32); a part names the budget; bad budgets are usage
# errors, a budget no setting fits is refused naming it with nothing
# written, and the merge refuses parts of auto and fixed settings mixed.
# Usage: test_cpca_auto.sh VDSH_BAKE VDSH_MERGE VDSH_INFO SOURCE_DIR
set -u
bake=$1 merge=$2 info=$3 src=$4
. "$(dirname "$0")/lib.sh"
make_tmp
# within FILE BUDGET: every stream is cpca and within BUDGET bytes per vertex
within() {
  "$info" --json - "$1" | /usr/bin/python3 -c '
import json, sys
budget = float(sys.argv[1])
streams = json.load(sys.stdin)["streams"]
assert streams, "no streams"
for s in streams:
    c = s["cpca"]
    print("order %d: %d,%d,%d, %.2f bytes per vertex (budget %g)" % (
        s["order"], c["clusters"], c["basis"], c["bits"], c["mean_bytes_per_vertex"], budget))
    assert c["mean_bytes_per_vertex"] <= budget, s
' "$2"
}

tiny=(builtin:room --max-edge 1.0 --rays 64 --cube-size 0 -q --orders 5)
cp=(--encoding cpca --cpca auto:12)
d=$tmp/12; mkdir -p "$d"
expect_exit 0 "auto:12, 1 thread" "$bake" "${tiny[@]}" "${cp[@]}" --threads 1 -o "$d/w1.vdsh"
expect_exit 0 "auto:12, 2 threads" "$bake" "${tiny[@]}" "${cp[@]}" --threads 2 -o "$d/w2.vdsh"
check "auto:12: 1 and 2 threads identical" cmp "$d/w1.vdsh" "$d/w2.vdsh"
check "auto:12: within 12 bytes per vertex" within "$d/w1.vdsh" 12
for i in 0 1 2; do
  expect_exit 0 "auto:12 shard $i/3" "$bake" "${tiny[@]}" "${cp[@]}" --shard "$i/3" -o "$d/p$i.vdsh"
done
expect_exit 0 "auto:12 merge" "$merge" -q "$d"/p*.vdsh -o "$d/m.vdsh"
check "auto:12: 3 shards merged identical to the whole bake" cmp "$d/m.vdsh" "$d/w1.vdsh"
expect_exit 0 "vdsh-info on an auto part" "$info" "$d/p1.vdsh"
says_any "vdsh-info shows the part's budget" "cpca auto:12,light:"
check "the Python reader reads an auto part" /usr/bin/python3 -c '
import sys
sys.path.insert(0, sys.argv[1])
import vdsh
p = vdsh.read(sys.argv[2]).part
assert (p["cpca_clusters"], p["cpca_basis"], p["cpca_bits"]) == (0, 12, 0), p
' "$src/python" "$d/p1.vdsh"
expect_exit 0 "vdsh-info on the auto file" "$info" "$d/w1.vdsh"
says_any "vdsh-info shows what auto chose" "basis vectors of 4-bit weights"
expect_exit 0 "auto (32)" "$bake" "${tiny[@]}" --encoding cpca --cpca auto -o "$tmp/a32.vdsh"
check "auto: within 32 bytes per vertex" within "$tmp/a32.vdsh" 32
check "auto and auto:12 differ" bash -c "! cmp -s '$tmp/a32.vdsh' '$d/w1.vdsh'"
expect_exit 0 "an auto (32) part" "$bake" "${tiny[@]}" --encoding cpca --cpca auto --shard 2/3 \
  -o "$tmp/a32-2.vdsh"

out=$tmp/none.vdsh
for bad in auto:0 auto:x auto: auto:4097 auto:-3 autox; do
  expect_exit 2 "--cpca $bad" "$bake" "${tiny[@]}" --encoding cpca --cpca "$bad" -o "$out"
  says_any "--cpca $bad" "or auto or auto:BYTES"
done
expect_exit 1 "a budget nothing fits" "$bake" "${tiny[@]}" --encoding cpca --cpca auto:1 -o "$out"
says_any "auto:1 refused" "auto budget 1 byte per vertex too small"
expect_exit 1 "merge refuses parts of two budgets" "$merge" -q "$d/p0.vdsh" "$d/p1.vdsh" \
  "$tmp/a32-2.vdsh" -o "$out"
says_any "merge of two budgets" "another --cpca"
expect_exit 0 "a fixed part" "$bake" "${tiny[@]}" --encoding cpca --cpca 4,20,4 --shard 2/3 \
  -o "$tmp/fixed-2.vdsh"
expect_exit 1 "merge refuses auto and fixed parts" "$merge" -q "$d/p0.vdsh" "$d/p1.vdsh" \
  "$tmp/fixed-2.vdsh" -o "$out"
says_any "merge of auto and fixed" "another --cpca"
check "nothing written after refusals" test ! -e "$out"
exit $fail
