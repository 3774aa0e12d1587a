#!/usr/bin/env bash
# Sharded bakes: vdsh-bake --shard I/N parts joined by vdsh-merge give the
# whole bake's file (and basis cubemaps) byte for byte for 1, 2, 7 and 64
# shards, f16, f32, s8 and s8s6; vdsh-merge refuses parts that do not belong together
# (other inputs, other options, a whole file, missing, duplicate shards)
# naming the part, and writes nothing then; a shard killed mid-bake leaves
# no part, and rerunning it alone completes the set. A part holds its own
# range's coefficients only (VDSH.md "Parts"): vdsh-info reads it as a part,
# its COEF chunks are the range's size, and vdsh-eval refuses it.
# Usage: test_shard.sh VDSH_BAKE VDSH_MERGE VDSH_INFO VDSH_EVAL
set -u
bake=$1
merge=$2
info=$3
evaluate=$4
. "$(dirname "$0")/lib.sh"
make_tmp

tiny=(builtin:room --max-edge 1.5 --rays 32 --cube-size 8 -q)
expect_exit 0 "whole bake" "$bake" "${tiny[@]}" -o "$tmp/whole.vdsh"
expect_exit 0 "whole bake f32" "$bake" "${tiny[@]}" --encoding f32 -o "$tmp/whole32.vdsh"
# a part's summary says its coefficients are f32 (152 bytes per vertex at
# orders 2,3,5) and what the merge makes of them (it said s8s6 beside 152)
loud=("${tiny[@]:0:${#tiny[@]}-1}")
expect_exit 0 "shard 0/2, not quiet" "$bake" "${loud[@]}" --shard 0/2 -o "$tmp/loud-part.vdsh"
says "a part's summary" "152.0 bytes of coefficients per vertex for orders 2,3,5, f32 in a part: s8s6 once merged)"
rm -f "$tmp/loud-part.vdsh"

for n in 1 2 7 64; do
  d=$tmp/n$n; mkdir -p "$d"
  for ((i = 0; i < n; i++)); do
    expect_exit 0 "shard $i/$n" "$bake" "${tiny[@]}" --threads 1 --shard "$i/$n" -o "$d/part-$i.vdsh"
  done
  # in reverse order: the merge sorts by shard
  expect_exit 0 "merge $n" "$merge" -q $(ls -r "$d"/part-*.vdsh) -o "$d/scene.vdsh"
  check "$n shards: merged file identical to the whole bake" cmp "$d/scene.vdsh" "$tmp/whole.vdsh"
  for k in 09-12 13-16 17-20 21-24; do
    check "$n shards: basis cubemap $k identical" cmp "$d/scene.sh$k.exr" "$tmp/whole.sh$k.exr"
  done
done
d=$tmp/f32; mkdir -p "$d"
for i in 0 1 2; do
  expect_exit 0 "f32 shard $i/3" "$bake" "${tiny[@]}" --encoding f32 --shard "$i/3" -o "$d/p$i.vdsh"
done
expect_exit 0 "merge f32" "$merge" -q "$d"/p*.vdsh -o "$d/scene.vdsh"
check "3 f32 shards: identical to the whole f32 bake" cmp "$d/scene.vdsh" "$tmp/whole32.vdsh"
# s8, s8s6: the merge quantises with the whole bake's rule
# (vdsh_encode_quantised: per-index scales over all receivers), so 1, 3 and
# 7 shards give its bytes.
for enc in s8 s8s6; do
  expect_exit 0 "whole bake $enc" "$bake" "${tiny[@]}" --encoding $enc -o "$tmp/whole-$enc.vdsh"
  for n in 1 3 7; do
    d=$tmp/$enc-$n; mkdir -p "$d"
    for ((i = 0; i < n; i++)); do
      expect_exit 0 "$enc shard $i/$n" "$bake" "${tiny[@]}" --encoding $enc --shard "$i/$n" -o "$d/p$i.vdsh"
    done
    expect_exit 0 "merge $enc $n" "$merge" -q "$d"/p*.vdsh -o "$d/scene.vdsh"
    check "$n $enc shards: identical to the whole $enc bake" cmp "$d/scene.vdsh" "$tmp/whole-$enc.vdsh"
  done
done
# Adaptive order (a variable-order stream beside order 3), every encoding:
# parts hold f32 rows of their own orders; the merge encodes as the bake.
for enc in f16 s8s6 f32; do
  ao=(builtin:room --max-edge 1.5 --rays 64 --cube-size 8 -q --adaptive-order 0.02
      --max-order 9 --orders 3 --encoding $enc)
  expect_exit 0 "whole adaptive-order bake $enc" "$bake" "${ao[@]}" -o "$tmp/ao-$enc.vdsh"
  for n in 1 2 7; do
    d=$tmp/ao-$enc-$n; mkdir -p "$d"
    for ((i = 0; i < n; i++)); do
      expect_exit 0 "adaptive order $enc shard $i/$n" "$bake" "${ao[@]}" --shard "$i/$n" \
        -o "$d/p$i.vdsh"
    done
    expect_exit 0 "merge adaptive order $enc $n" "$merge" -q "$d"/p*.vdsh -o "$d/scene.vdsh"
    check "$n adaptive-order $enc shards: identical to the whole bake" cmp "$d/scene.vdsh" \
      "$tmp/ao-$enc.vdsh"
  done
done
expect_exit 1 "s8 and f16 parts refused together" "$merge" -q "$tmp"/s8-3/p0.vdsh "$tmp"/s8-3/p1.vdsh "$tmp"/f32/p2.vdsh -o "$tmp/mixed.vdsh"
says "mixed encodings" "another --encoding"

# A part's streams are its range's rows: with 7 parts of f16 orders 2, 3, 5
# (parts are f32: 38 floats per receiver), part 3's COEF payloads are
# 48-byte headers plus 152 bytes per receiver of its range.
p=$tmp/n7
"$info" --json - "$p/part-3.vdsh" >"$tmp/info.json" 2>"$tmp/err.txt"
check "vdsh-info reads a part" /usr/bin/python3 - "$tmp/info.json" "$p/part-3.vdsh" <<'PY'
import json, struct, sys
d = json.load(open(sys.argv[1]))
pt = d.get("part")
assert pt and pt["index"] == 3 and pt["count"] == 7, pt
V = d["vertex_count"]
assert (pt["range_begin"], pt["range_end"]) == (V * 3 // 7, V * 4 // 7), (pt, V)
data, off, coef = open(sys.argv[2], "rb").read(), 32, []
while off < len(data):
    cid, size = data[off:off + 4], struct.unpack_from("<Q", data, off + 8)[0]
    if cid == b"COEF":
        coef.append(size)
    off += 16 + (size + 15) // 16 * 16
rows = pt["range_end"] - pt["range_begin"]
want = sorted(48 + 4 * o * o * rows for o in (2, 3, 5))
assert sorted(coef) == want, (coef, want)
PY
expect_exit 1 "vdsh-eval refuses a part" "$evaluate" "$p/part-3.vdsh"
says "vdsh-eval on a part" "a part of a sharded bake (shard 3 of 7)"

# Refusals, each naming the part; nothing written.
p=$tmp/n7
out=$tmp/refused.vdsh
expect_exit 0 "foreign shard" "$bake" builtin:room:2 --max-edge 1.5 --rays 32 --cube-size 8 -q --shard 3/7 -o "$tmp/foreign-3.vdsh"
expect_exit 1 "foreign part refused" "$merge" -q "$p"/part-{0,1,2,4,5,6}.vdsh "$tmp/foreign-3.vdsh" -o "$out"
says "foreign part" "$tmp/foreign-3.vdsh: does not belong with $p/part-0.vdsh: other inputs"
expect_exit 0 "other options" "$bake" "${tiny[@]}" --seed 9 --shard 3/7 -o "$tmp/seed-3.vdsh"
expect_exit 1 "other options refused" "$merge" -q "$p"/part-{0,1,2,4,5,6}.vdsh "$tmp/seed-3.vdsh" -o "$out"
says "other options" "$tmp/seed-3.vdsh: does not belong with $p/part-0.vdsh: other options"
expect_exit 1 "missing shards refused" "$merge" -q "$p"/part-{0,2,3,5,6}.vdsh -o "$out"
says "missing shards" "2 of 7 shards missing: 1 4"
expect_exit 1 "duplicate shard refused" "$merge" -q "$p"/part-{0,1,2,3,4,5,6,3}.vdsh -o "$out"
says "duplicate shard" "shard 3 of 7 again"
expect_exit 1 "a whole file is not a part" "$merge" -q "$p"/part-0.vdsh "$tmp/whole.vdsh" -o "$out"
says "whole file" "$tmp/whole.vdsh: not a part"
expect_exit 1 "mixed shard counts refused" "$merge" -q "$tmp"/n2/part-0.vdsh "$p"/part-1.vdsh -o "$out"
says "mixed counts" "$p/part-1.vdsh: does not belong with $tmp/n2/part-0.vdsh"
check "no output after refusals" test ! -e "$out"
# vdsh-merge spills f16/s8/s8s6 parts' rows beside the output, unlinked as
# soon as made: no merge, refused or not, leaves one.
check "no spill file left by any merge" test -z "$(find "$tmp" -name '*.spill-*')"
expect_exit 2 "--shard 7/7 is a usage error" "$bake" "${tiny[@]}" --shard 7/7 -o "$out"
expect_exit 2 "--shard x is a usage error" "$bake" "${tiny[@]}" --shard 1/x -o "$out"
expect_exit 1 "more shards than receivers" "$bake" builtin:room --rays 8 -q --shard 0/1000000 -o "$out"
check "no output after bad shards" test ! -e "$out"
# ... also where the run stops before the bake (--export-obj: bake-slurm's
# check before it submits; --plan): it exited 0 and wrote them.
expect_exit 1 "more shards than receivers, --export-obj" "$bake" builtin:room --max-edge 1.5 -q \
  --shard 0/1000000 --export-obj "$tmp/shard-check.obj"
says "more shards than receivers, --export-obj" "needs shard < count <= the"
check "no --export-obj after bad shards" test ! -e "$tmp/shard-check.obj"
expect_exit 1 "more shards than receivers, --plan" "$bake" builtin:room --max-edge 1.5 -q \
  --shard 0/1000000 --plan "$tmp/shard-check.ply"
check "no --plan after bad shards" test ! -e "$tmp/shard-check.ply"

# A shard killed mid-bake leaves no part; rerunning it alone completes the set.
k=$tmp/killed; mkdir -p "$k"
cp "$p"/part-*.vdsh "$k"/ && rm "$k/part-5.vdsh"
"$bake" builtin:room --max-edge 0.1 --rays 4096 -q --shard 5/7 -o "$k/part-5.vdsh" &
pid=$!
sleep 1
kill -9 "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
check "a killed shard leaves no part" test ! -e "$k/part-5.vdsh"
expect_exit 1 "merge names the killed shard" "$merge" -q "$k"/part-*.vdsh -o "$k/scene.vdsh"
says "killed shard" "1 of 7 shards missing: 5"
expect_exit 0 "rerun shard 5" "$bake" "${tiny[@]}" --shard 5/7 -o "$k/part-5.vdsh"
expect_exit 0 "merge after rerun" "$merge" -q "$k"/part-*.vdsh -o "$k/scene.vdsh"
check "rerun set identical to the whole bake" cmp "$k/scene.vdsh" "$tmp/whole.vdsh"

# Adaptive receivers: planned once (--adaptive ... --plan), the plan baked
# whole and in 1, 2 and 7 shards (--receivers): byte for byte.
expect_exit 0 "adaptive plan" "$bake" builtin:room --max-edge 1.5 --adaptive 0.05 --rays 256 -q \
  --plan "$tmp/plan.obj"
check "the plan is written, no .vdsh beside it" test -s "$tmp/plan.obj"
planned=(builtin:room --receivers "$tmp/plan.obj" --rays 32 --cube-size 8 -q)
expect_exit 0 "whole bake of the plan" "$bake" "${planned[@]}" -o "$tmp/plan-whole.vdsh"
for n in 1 2 7; do
  d=$tmp/plan$n; mkdir -p "$d"
  for ((i = 0; i < n; i++)); do
    expect_exit 0 "plan shard $i/$n" "$bake" "${planned[@]}" --shard "$i/$n" -o "$d/part-$i.vdsh"
  done
  expect_exit 0 "merge plan $n" "$merge" -q "$d"/part-*.vdsh -o "$d/scene.vdsh"
  check "plan, $n shards: identical to the whole bake of the plan" cmp "$d/scene.vdsh" "$tmp/plan-whole.vdsh"
done
# A uniform plan in binary PLY (--plan FILE.ply, no bake): read back bit
# for bit, so its bake is the OBJ plan's bake of the same receivers.
expect_exit 0 "uniform plan, PLY" "$bake" builtin:room --max-edge 1.5 -q --plan "$tmp/uplan.ply"
expect_exit 0 "uniform plan, OBJ" "$bake" builtin:room --max-edge 1.5 -q --plan "$tmp/uplan.obj"
expect_exit 0 "bake of the PLY plan" "$bake" builtin:room --receivers "$tmp/uplan.ply" --rays 32 --cube-size 8 -q -o "$tmp/up.vdsh"
expect_exit 0 "bake of the OBJ plan" "$bake" builtin:room --receivers "$tmp/uplan.obj" --rays 32 --cube-size 8 -q -o "$tmp/uo.vdsh"
check "PLY and OBJ plans give the same bake" cmp "$tmp/up.vdsh" "$tmp/uo.vdsh"
d=$tmp/uplan3; mkdir -p "$d"
for i in 0 1 2; do
  expect_exit 0 "PLY plan shard $i/3" "$bake" builtin:room --receivers "$tmp/uplan.ply" --rays 32 --cube-size 8 -q --shard "$i/3" -o "$d/p$i.vdsh"
done
expect_exit 0 "merge PLY plan" "$merge" -q "$d"/p*.vdsh -o "$d/scene.vdsh"
check "PLY plan, 3 shards: identical to its whole bake" cmp "$d/scene.vdsh" "$tmp/up.vdsh"
expect_exit 2 "--adaptive with --shard is refused" "$bake" builtin:room --max-edge 1.5 --adaptive 0.05 \
  --shard 0/2 -o "$out"
says "--adaptive with --shard" "shard the plan"
expect_exit 2 "--plan with --receivers" "$bake" builtin:room --receivers "$tmp/plan.obj" --plan "$tmp/x.obj"
expect_exit 2 "--receivers with --max-edge" "$bake" builtin:room --receivers "$tmp/plan.obj" --max-edge 1 -o "$out"
expect_exit 1 "--receivers of a missing file" "$bake" builtin:room --receivers "$tmp/none.obj" -o "$out"
says "--receivers of a missing file" "none.obj"
says "--receivers of a missing file: what failed" "reading the receivers (--receivers)"
check "no output after refusals" test ! -e "$out"

exit $fail
