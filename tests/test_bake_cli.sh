#!/usr/bin/env bash
# vdsh-bake end to end: determinism across thread counts and runs, the
# files it writes, exit codes, and no output left behind on failure.
# Usage: test_bake_cli.sh VDSH_BAKE VDSH_INFO [SCENES]
set -u
bake=$1
info=$2
scenes=${3:-}
. "$(dirname "$0")/lib.sh"
make_tmp

json() { # json FILE PYTHON_EXPRESSION_OF_d: true when it holds
  /usr/bin/python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); sys.exit(0 if eval(sys.argv[2]) else 1)' "$@"
}

quick=(builtin:room --max-edge 1.5 --rays 256 -q)

# Determinism: 1 thread, 2 threads and a repeat give byte-identical files.
expect_exit 0 "bake, 1 thread" "$bake" "${quick[@]}" --threads 1 -o "$tmp/a.vdsh"
expect_exit 0 "bake, 2 threads" "$bake" "${quick[@]}" --threads 2 -o "$tmp/b.vdsh"
expect_exit 0 "bake, repeat" "$bake" "${quick[@]}" --threads 2 -o "$tmp/c.vdsh"
check "1 and 2 threads give identical files" cmp -s "$tmp/a.vdsh" "$tmp/b.vdsh"
check "repeated bakes give identical files" cmp -s "$tmp/b.vdsh" "$tmp/c.vdsh"
for k in 09-12 13-16 17-20 21-24; do
  check "cubemap sh$k written beside the output" test -s "$tmp/a.sh$k.exr"
  check "cubemaps identical between bakes" cmp -s "$tmp/a.sh$k.exr" "$tmp/b.sh$k.exr"
done

# Adaptive receivers: identical for 1 and 2 threads, recorded in the file.
adaptive=(builtin:room --max-edge 1.5 --adaptive 0.08 --rays 256 -q)
expect_exit 0 "adaptive, 1 thread" "$bake" "${adaptive[@]}" --threads 1 -o "$tmp/ad1.vdsh"
expect_exit 0 "adaptive, 2 threads" "$bake" "${adaptive[@]}" --threads 2 -o "$tmp/ad2.vdsh" \
  --report "$tmp/ad2.json"
check "the report says what the refinement did" grep -q '"midpoints_baked"' "$tmp/ad2.json"
check "adaptive: 1 and 2 threads give identical files" cmp -s "$tmp/ad1.vdsh" "$tmp/ad2.vdsh"
expect_exit 0 "vdsh-info --verify accepts an adaptive bake" "$info" --verify "$tmp/ad1.vdsh"
"$info" "$tmp/ad1.vdsh" >"$tmp/adinfo.txt" 2>&1
check "info shows the adaptive tolerance" grep -q "adaptive     tolerance 0.08, min edge 0.1875" "$tmp/adinfo.txt"

# The round cap: --max-rounds N (default 8), in the report; stderr says when
# it stopped a refinement still splitting; no environment variable moves it.
check "report: the default round cap" json "$tmp/ad2.json" \
  "d['adaptive']['max_rounds'] == 8 and d['adaptive']['rounds'] <= 8"
expect_exit 0 "adaptive, done before the cap" "$bake" builtin:room --max-edge 1.5 --adaptive 0.08 \
  --min-edge 0.5 --rays 256 --cube-size 0 --max-rounds 2 -o "$tmp/nocap.vdsh" --report "$tmp/nocap.json"
check "no round-cap warning when the refinement finished" bash -c "! grep -q 'round cap' '$tmp/err.txt'"
check "report: finished before the cap" json "$tmp/nocap.json" \
  "d['adaptive']['max_rounds'] == 2 and d['adaptive']['rounds'] == 1 and d['adaptive']['rounds_reached'] is False and d['adaptive']['edges_pending'] == 0"
capped=(builtin:room --max-edge 1.5 --adaptive 0.08 --rays 256 --cube-size 0 --max-rounds 1)
expect_exit 0 "adaptive, --max-rounds 1" "$bake" "${capped[@]}" -o "$tmp/cap.vdsh" \
  --report "$tmp/cap.json"
check "stderr says the round cap stopped the refinement" \
  grep -q "adaptive refinement stopped at the round cap (1) while still splitting (.* edges split in the last round, [1-9][0-9]* edges not yet judged): raise --max-rounds" "$tmp/err.txt"
check "report: the round cap stopped it" json "$tmp/cap.json" \
  "d['adaptive']['max_rounds'] == 1 and d['adaptive']['rounds'] == 1 and d['adaptive']['rounds_reached'] is True and d['adaptive']['edges_pending'] > 0"
"$info" --json - "$tmp/cap.vdsh" >"$tmp/cap.info.json" 2>/dev/null
check "the file records the round cap" json "$tmp/cap.info.json" \
  "d['adaptive']['max_rounds'] == 1 and d['adaptive']['rounds'] == 1"
expect_exit 0 "adaptive, default cap, VDSH_ROUNDS=1 set" env VDSH_ROUNDS=1 "$bake" "${adaptive[@]}" \
  --threads 2 -o "$tmp/ad3.vdsh"
check "VDSH_ROUNDS no longer changes the bake" cmp -s "$tmp/ad2.vdsh" "$tmp/ad3.vdsh"
expect_exit 2 "--max-rounds 0" "$bake" builtin:room --max-edge 1 --adaptive 0.1 --max-rounds 0 -o "$tmp/x.vdsh"
expect_exit 2 "--max-rounds 2x" "$bake" builtin:room --max-edge 1 --adaptive 0.1 --max-rounds 2x -o "$tmp/x.vdsh"
expect_exit 2 "--max-rounds without --adaptive" "$bake" builtin:room --max-edge 1 --max-rounds 3 -o "$tmp/x.vdsh"
check "--help lists --max-rounds" bash -c "'$bake' --help | grep -q -- '--max-rounds N'"

# The file verifies and says what it is.
expect_exit 0 "vdsh-info --verify accepts the bake" "$info" --verify "$tmp/a.vdsh"
"$info" "$tmp/a.vdsh" >"$tmp/info.txt" 2>&1
check "info names the source" grep -q "builtin:room" "$tmp/info.txt"
check "info lists order 5" grep -q "order 5 (25 coefficients)" "$tmp/info.txt"

# Options land in the file; timings only when asked.
expect_exit 0 "bake f32 orders 2,3 full" "$bake" "${quick[@]}" --orders 3,2 --encoding f32 \
  --method full --seed 9 -o "$tmp/d.vdsh" --report "$tmp/d.json"
"$info" --json - "$tmp/d.vdsh" >"$tmp/d.info.json"
check "f32 recorded" json "$tmp/d.info.json" "{s['encoding'] for s in d['streams']} == {'f32'}"
check "method full recorded" json "$tmp/d.info.json" "{s['method'] for s in d['streams']} == {'full'}"
check "orders 2, 3 and no order 5 stream" json "$tmp/d.info.json" "sorted(s['order'] for s in d['streams']) == [2, 3]"
check "seed recorded" json "$tmp/d.info.json" "d['bake']['seed'] == 9"
check "no cubemaps without order 4+" test ! -e "$tmp/d.sh09-12.exr"
check "report written" json "$tmp/d.json" "d['rays_traced'] > 0 and d['orders'] == [2, 3] and d['seed'] == 9 and d['sdf'] is None"
check "report: the origins' repair is its own phase" json "$tmp/d.json" \
  "d['origins']['probe_rays'] >= 32 * d['receivers'] and d['seconds']['origins'] >= 0 and d['robust'] is True"
expect_exit 0 "bake with timings" "$bake" "${quick[@]}" --record-timings -o "$tmp/e.vdsh"
"$info" --json - "$tmp/e.vdsh" >"$tmp/e.info.json"
check "timings stored when asked" json "$tmp/e.info.json" "d['timings']['total'] > 0"
check "no timings otherwise" json "$tmp/d.info.json" "d['timings'] is None"
check "--cubemap-dir" bash -c "mkdir -p '$tmp/cubes' && '$bake' ${quick[*]} --cubemap-dir '$tmp/cubes' -o '$tmp/f.vdsh' && test -s '$tmp/cubes/f.sh21-24.exr' && test ! -e '$tmp/f.sh21-24.exr'"

# Receivers far apart against the scene (no --max-edge, --adaptive or
# --receivers): a warning with figures and a --max-edge to try; none when
# the receivers were chosen or are dense; the figures in the report.
awk 'BEGIN { n = 40; s = 10 / n
  for (j = 0; j <= n; j++) for (i = 0; i <= n; i++) printf "v %g 0 %g\n", i * s, j * s
  for (j = 0; j < n; j++) for (i = 0; i < n; i++) {
    a = j * (n + 1) + i + 1; b = a + 1; c = a + n + 1; d = c + 1
    printf "f %d %d %d\nf %d %d %d\n", a, c, b, b, c, d } }' >"$tmp/grid.obj"
printf 'v 0 0 0\nv 10 0 0\nv 10 0 10\nv 0 0 10\nv 4 0 4\nv 4.5 0 4\nv 4 0.5 4\nf 1 4 3 2\nf 5 6 7\n' \
  >"$tmp/coarse.obj"
far="receivers far apart"
expect_exit 0 "coarse floor at its vertices" "$bake" "$tmp/coarse.obj" --rays 16 --cube-size 0 \
  -o "$tmp/coarse.vdsh" --report "$tmp/coarse.json"
check "warning: receivers far apart, with figures and a --max-edge" grep -q \
  "warning: $far: 100% of the surface is in triangles whose longest edge exceeds 5% of the scene's diagonal (14.15; longest edges: median 14.1, 90th percentile 14.1, area-weighted).*--max-edge 0.14 (1% of the diagonal)" \
  "$tmp/err.txt"
check "report: the receivers' spacing" json "$tmp/coarse.json" \
  "d['receiver_spacing']['far_apart'] is True and d['receiver_spacing']['long_area_share'] > 0.99 and abs(d['receiver_spacing']['scene_diagonal'] - 200.25 ** 0.5) < 0.001"
expect_exit 0 "coarse floor with --max-edge" "$bake" "$tmp/coarse.obj" --rays 16 --cube-size 0 \
  --max-edge 0.5 -o "$tmp/coarse2.vdsh" --report "$tmp/coarse2.json"
check "no warning with --max-edge" bash -c "! grep -q '$far' '$tmp/err.txt'"
check "report: refined receivers are close" json "$tmp/coarse2.json" \
  "d['receiver_spacing']['far_apart'] is False and d['receiver_spacing']['max_longest_edge'] <= 0.5"
expect_exit 0 "dense grid at its vertices" "$bake" "$tmp/grid.obj" --rays 16 --cube-size 0 -o "$tmp/grid.vdsh"
check "no warning for a dense mesh" bash -c "! grep -q '$far' '$tmp/err.txt'"
expect_exit 0 "builtin:room at --max-edge 0.2" "$bake" builtin:room --max-edge 0.2 --rays 16 \
  --orders 2 --method lsq --cube-size 0 -o "$tmp/room02.vdsh"
check "no warning for the room at --max-edge 0.2" bash -c "! grep -q '$far' '$tmp/err.txt'"
expect_exit 0 "builtin:room at its vertices, plan only" "$bake" builtin:room --plan "$tmp/roomplan.ply"
check "the room at its vertices warns" grep -q "warning: $far: 60% of the surface" "$tmp/err.txt"
expect_exit 0 "export only" "$bake" builtin:room --export-obj "$tmp/roomx.obj"
check "no warning when nothing is baked" bash -c "! grep -q '$far' '$tmp/err.txt'"
sponza=$scenes/sponza_dabrovic/sponza.obj
if [[ -n $scenes && -f $sponza ]]; then
  expect_exit 0 "Sponza at its vertices" "$bake" "$sponza" --rays 16 --orders 2 --method lsq \
    --cube-size 0 -o "$tmp/sponza.vdsh"
  check "Sponza at its vertices warns, suggesting --max-edge 0.42" grep -q \
    "warning: $far: 84% of the surface.*--max-edge 0.42 (1% of the diagonal)" "$tmp/err.txt"
else
  echo "no Sponza at '$sponza': its spacing warning not checked"
fi

# Export the built-in scene as OBJ and bake it back: same occluders.
expect_exit 0 "export OBJ" "$bake" builtin:room -q --export-obj "$tmp/room.obj"
check "OBJ has faces" grep -q "^f " "$tmp/room.obj"

# A seeded variant of the room bakes and exports by name; unknown names
# list the known ones.
expect_exit 0 "bake builtin:room:7" "$bake" builtin:room:7 --max-edge 1.5 --rays 64 --cube-size 0 -q \
  -o "$tmp/v7.vdsh"
"$info" "$tmp/v7.vdsh" >"$tmp/v7.txt" 2>&1
check "info names the variant" grep -q "builtin:room:7" "$tmp/v7.txt"
expect_exit 0 "export builtin:room:7" "$bake" builtin:room:7 --max-edge 0.5 -q --export-obj "$tmp/v7.obj"
check "variant OBJ has faces" grep -q "^f " "$tmp/v7.obj"
expect_exit 1 "unknown built-in" "$bake" builtin:hall -q -o "$tmp/y.vdsh"
check "unknown built-in lists the known ones" grep -q "known: builtin:room, builtin:room:N" "$tmp/err.txt"
expect_exit 1 "variant 0" "$bake" builtin:room:0 -q -o "$tmp/y.vdsh"

# Usage errors exit 2 and write nothing.
expect_exit 2 "no mesh" "$bake" -o "$tmp/x.vdsh"
expect_exit 2 "no output" "$bake" builtin:room
expect_exit 2 "bad order" "$bake" builtin:room --orders 2,17 -o "$tmp/x.vdsh"
expect_exit 2 "bad rays" "$bake" builtin:room --rays 0 -o "$tmp/x.vdsh"
expect_exit 2 "bad method" "$bake" builtin:room --method magic -o "$tmp/x.vdsh"
expect_exit 2 "--log-offset with lsq" "$bake" builtin:room --method lsq --log-offset 0.2 -o "$tmp/x.vdsh"
expect_exit 2 "--log-offset out of range" "$bake" builtin:room --log-offset 7 -o "$tmp/x.vdsh"
expect_exit 2 "--lambda with shadow" "$bake" builtin:room --lambda 1e-3 -o "$tmp/x.vdsh"
expect_exit 2 "unknown option" "$bake" builtin:room --frobnicate -o "$tmp/x.vdsh"
expect_exit 2 "--offset-cap with shadow" "$bake" builtin:room --method shadow --offset-cap 0 -o "$tmp/x.vdsh"
expect_exit 2 "--offset-cap share out of range" "$bake" builtin:room --offset-cap 0,1.5 -o "$tmp/x.vdsh"
expect_exit 2 "--offset-cap not a number" "$bake" builtin:room --offset-cap x -o "$tmp/x.vdsh"
expect_exit 2 "--offset-cap without fixed orders" "$bake" builtin:room --adaptive-order 0.05 --offset-cap 0 -o "$tmp/x.vdsh"
expect_exit 2 "--offset-cap trailing comma" "$bake" builtin:room --offset-cap 0, -o "$tmp/x.vdsh"
expect_exit 2 "--offset-cap trailing text" "$bake" builtin:room --offset-cap 0,1,4x -o "$tmp/x.vdsh"
expect_exit 2 "--offset-cap fractional MIN" "$bake" builtin:room --offset-cap 0,1,2.5 -o "$tmp/x.vdsh"
expect_exit 2 "--decision-params trailing text" "$bake" builtin:room --decision-params 0.5,8,0.1,1,12x -o "$tmp/x.vdsh"
expect_exit 2 "--decision-params fractional steps" "$bake" builtin:room --decision-params 0.5,8,0.1,1,1.5 -o "$tmp/x.vdsh"
expect_exit 2 "--adaptive without --max-edge" "$bake" builtin:room --adaptive 0.1 -o "$tmp/x.vdsh"
expect_exit 2 "--adaptive with a negative tolerance" "$bake" builtin:room --max-edge 1 --adaptive -1 -o "$tmp/x.vdsh"
expect_exit 2 "--min-edge without --adaptive" "$bake" builtin:room --max-edge 1 --min-edge 0.1 -o "$tmp/x.vdsh"
expect_exit 2 "--max-receivers without --adaptive" "$bake" builtin:room --max-edge 1 --max-receivers 9 -o "$tmp/x.vdsh"
expect_exit 2 "--adaptive with --shard" "$bake" builtin:room --max-edge 1 --adaptive 0.1 --shard 0/2 -o "$tmp/x.vdsh"
expect_exit 2 "the same mesh twice" "$bake" builtin:room builtin:room -o "$tmp/x.vdsh"
check "the same mesh twice is named" grep -q "builtin:room given twice" "$tmp/err.txt"
ln -sf room.obj "$tmp/room-link.obj"
expect_exit 2 "one file under two names" "$bake" "$tmp/room.obj" "$tmp/room-link.obj" -o "$tmp/x.vdsh"
check "one file under two names is named" grep -q "are the same file" "$tmp/err.txt"
expect_exit 1 "--max-receivers below the start mesh" "$bake" builtin:room --max-edge 1 --adaptive 0.1 --max-receivers 9 -o "$tmp/x.vdsh"
check "no output after usage errors" test ! -e "$tmp/x.vdsh"
expect_exit 0 "--help" "$bake" --help
check "--help shows usage" grep -q "usage: vdsh-bake" "$tmp/out.txt"
check "--help lists --offset-cap" grep -q -- "--offset-cap TOL" "$tmp/out.txt"
expect_exit 0 "--version" "$bake" --version

# Data errors exit 1, name the file, and leave no output (nor temp files).
: >"$tmp/empty.obj"
printf 'v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n' >"$tmp/nan.obj"
for bad in "$tmp/missing.obj" "$tmp/empty.obj" "$tmp/nan.obj" "$tmp/file.xyz"; do
  expect_exit 1 "bad input $(basename "$bad")" "$bake" "$bad" -q -o "$tmp/y.vdsh"
  check "message names $(basename "$bad")" grep -q "$(basename "$bad")" "$tmp/err.txt"
done
check "no output after data errors" test ! -e "$tmp/y.vdsh"
expect_exit 1 "unwritable output" "$bake" "${quick[@]}" -o "$tmp/no/such/dir/z.vdsh"
check "no temporary files left" bash -c "! ls '$tmp' | grep -q tmp"

# A failed bake never touches an existing output.
cp "$tmp/a.vdsh" "$tmp/keep.vdsh"
expect_exit 1 "bad input over an existing file" "$bake" "$tmp/empty.obj" -q -o "$tmp/keep.vdsh"
check "existing output untouched" cmp -s "$tmp/a.vdsh" "$tmp/keep.vdsh"

# An explicit log offset (the default method, decision: instead of its
# calibration): recorded per stream as its method parameter.
expect_exit 0 "bake --log-offset" "$bake" "${quick[@]}" --log-offset 0.25 -o "$tmp/off.vdsh"
"$info" --json - "$tmp/off.vdsh" >"$tmp/off.json"
check "log offset recorded" json "$tmp/off.json" \
  "all(s['method'] == 'decision' and abs(s['method_param'] - 0.25) < 1e-7 for s in d['streams'])"

# --rays auto: byte-identical across thread counts, the cap and tolerance in
# the report, fewer rays than the cap; --ray-tolerance only with it.
auto=(builtin:room --max-edge 1.5 --rays auto --cube-size 0 -q)
expect_exit 0 "adaptive rays, 1 thread" "$bake" "${auto[@]}" --threads 1 -o "$tmp/ar1.vdsh" \
  --report "$tmp/ar1.json"
expect_exit 0 "adaptive rays, 2 threads" "$bake" "${auto[@]}" --threads 2 -o "$tmp/ar2.vdsh"
check "adaptive rays: 1 and 2 threads give identical files" cmp -s "$tmp/ar1.vdsh" "$tmp/ar2.vdsh"
check "adaptive rays reported" json "$tmp/ar1.json" \
  "d['adaptive_rays'] is True and d['rays_per_receiver'] == 1024 and abs(d['ray_tolerance'] - 0.06) < 1e-6 and 128 <= d['mean_rays_traced'] < 1024"
expect_exit 0 "adaptive rays, tolerance 0" "$bake" "${auto[@]}" --ray-tolerance 0 -o "$tmp/ar0.vdsh" \
  --report "$tmp/ar0.json"
check "tolerance 0 traces every round" json "$tmp/ar0.json" "d['mean_rays_traced'] == 1024"
expect_exit 0 "adaptive rays, tolerance inf" "$bake" "${auto[@]}" --ray-tolerance inf \
  -o "$tmp/ari.vdsh" --report "$tmp/ari.json"
check "tolerance inf stops at the first check" json "$tmp/ari.json" "d['mean_rays_traced'] == 128"
expect_exit 2 "--ray-tolerance without --rays auto" "$bake" builtin:room --ray-tolerance 0.1 \
  -o "$tmp/x.vdsh"
expect_exit 2 "negative --ray-tolerance" "$bake" builtin:room --rays auto --ray-tolerance -1 \
  -o "$tmp/x.vdsh"
check "no output after refused tolerances" test ! -e "$tmp/x.vdsh"

# Adaptive order: one variable-order stream alone (no --orders), 1 and 2
# threads identical, its histogram in vdsh-info; with --orders, beside them.
ao=(builtin:room --max-edge 1.5 --rays 256 --adaptive-order 0.02 --max-order 9 -q)
expect_exit 0 "adaptive order, 1 thread" "$bake" "${ao[@]}" --threads 1 -o "$tmp/ao1.vdsh"
expect_exit 0 "adaptive order, 2 threads" "$bake" "${ao[@]}" --threads 2 -o "$tmp/ao2.vdsh"
check "adaptive order: 1 and 2 threads identical" cmp -s "$tmp/ao1.vdsh" "$tmp/ao2.vdsh"
# Its stream is drawn from buffers: no basis cubemaps written or recorded
# (they were, for a file with no order 4 or 5 stream).
check "adaptive order alone: no cubemaps" test ! -e "$tmp/ao1.sh09-12.exr" -a ! -e "$tmp/ao1.sh21-24.exr"
"$info" --json - "$tmp/ao1.vdsh" >"$tmp/ao1.json" 2>/dev/null
check "adaptive order: one variable stream up to 9" json "$tmp/ao1.json" \
  "d['bake']['cube_size'] == 0 and len(d['streams']) == 1 and d['streams'][0]['variable_order'] and d['streams'][0]['order'] == 9 and sum(d['streams'][0]['vertices_per_order']) == d['vertex_count'] and 4 <= d['streams'][0]['mean_bytes_per_vertex'] <= d['streams'][0]['max_bytes_per_vertex']"
expect_exit 0 "adaptive order with --orders" "$bake" "${ao[@]}" --orders 2,3 -o "$tmp/ao3.vdsh"
"$info" --json - "$tmp/ao3.vdsh" >"$tmp/ao3.json" 2>/dev/null
check "adaptive order beside orders 2 and 3" json "$tmp/ao3.json" \
  "[s['order'] for s in d['streams']] == [2, 3, 9] and [s['variable_order'] for s in d['streams']] == [False, False, True]"
expect_exit 2 "--max-order without --adaptive-order" "$bake" builtin:room --max-order 9 \
  -o "$tmp/y.vdsh"
expect_exit 2 "--adaptive-order 0" "$bake" builtin:room --adaptive-order 0 -o "$tmp/y.vdsh"
expect_exit 2 "--max-order 17" "$bake" builtin:room --adaptive-order 0.1 --max-order 17 \
  -o "$tmp/y.vdsh"
expect_exit 2 "adaptive order with paper" "$bake" builtin:room --adaptive-order 0.1 \
  --method paper -o "$tmp/y.vdsh"
check "no output after refused adaptive orders" test ! -e "$tmp/y.vdsh"

# Plurals in the progress and summary lines: one triangle, one thread, one
# degenerate receiver are said in the singular ("1 triangles" before).
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$tmp/one.obj"
"$bake" "$tmp/one.obj" --rays 16 --threads 1 -o "$tmp/one.vdsh" 2>"$tmp/one.txt"
check "one triangle: said in the singular" grep -q "one.obj: 3 vertices, 1 triangle (" "$tmp/one.txt"
check "one thread: said in the singular" grep -q "on 1 thread)" "$tmp/one.txt"
check "no '1 <plural>' in the bake's lines" \
  bash -c '! grep -E "(^|[^0-9.])1 (triangles|threads|receivers|rays|vertices|ray origins)\b" "$1"' _ "$tmp/one.txt"
# vdsh-info's listing the same ("1 triangles", "(1 coefficients)" before;
# scripts/pareto reads both forms)
"$bake" "$tmp/one.obj" --rays 16 --threads 1 --orders 1 --record-timings --cube-size 0 -q \
  -o "$tmp/one1.vdsh"
"$info" "$tmp/one1.vdsh" >"$tmp/one1.info.txt"
check "info: one triangle, receivers and occluders" \
  bash -c '[ "$(grep -cE "^  (receivers|occluders)    3 vertices, 1 triangle$" "$1")" = 2 ]' _ "$tmp/one1.info.txt"
check "info: order 1 has 1 coefficient" grep -q "order 1 (1 coefficient)," "$tmp/one1.info.txt"
check "info: 1 thread" grep -q ", 1 thread$" "$tmp/one1.info.txt"
check "no '1 <plural>' in vdsh-info's listing" \
  bash -c '! grep -E "(^|[^0-9.])1 (triangles|vertices|coefficients|threads|bytes|clusters|basis vectors|lights|receivers|rounds|midpoints)\b" "$1"' _ "$tmp/one1.info.txt"
"$bake" builtin:room --max-edge 1.5 --rays 64 --threads 1 -o "$tmp/room1.vdsh" 2>"$tmp/room1.txt"
check "the room's one degenerate receiver and repair: singular" \
  bash -c '! grep -E "(^|[^0-9.])1 (receivers|ray origins|degenerate receivers|threads)\b" "$1"' _ "$tmp/room1.txt"

# Near training lights (--decision-near K, default 2): the report counts
# them, 0 turns them off (the uniform pool: another file), both bakes are
# the same on 1 and 2 threads, and only method decision takes the option.
near=(builtin:room --max-edge 1.5 --rays 64 --cube-size 0 -q)
expect_exit 0 "near: default, 1 thread" "$bake" "${near[@]}" --threads 1 -o "$tmp/n1.vdsh" \
  --report "$tmp/n1.json"
expect_exit 0 "near: default, 2 threads" "$bake" "${near[@]}" --threads 2 -o "$tmp/n2.vdsh"
expect_exit 0 "near: none" "$bake" "${near[@]}" --decision-near 0 --threads 2 -o "$tmp/n0.vdsh" \
  --report "$tmp/n0.json"
expect_exit 0 "near: none, 1 thread" "$bake" "${near[@]}" --decision-near 0 --threads 1 \
  -o "$tmp/n01.vdsh"
check "near: 1 and 2 threads give identical files" cmp -s "$tmp/n1.vdsh" "$tmp/n2.vdsh"
check "near: none, 1 and 2 threads give identical files" cmp -s "$tmp/n0.vdsh" "$tmp/n01.vdsh"
check "near: the default places near training lights" \
  json "$tmp/n1.json" 'd["decision"]["near_pool_lights"] > 0'
check "near: --decision-near 0 places none" \
  json "$tmp/n0.json" 'd["decision"]["near_pool_lights"] == 0'
check "near: the training lights change the fit" bash -c '! cmp -s "$1" "$2"' _ "$tmp/n1.vdsh" \
  "$tmp/n0.vdsh"
expect_exit 2 "near: only method decision" "$bake" "${near[@]}" --method shadow --decision-near 2 \
  -o "$tmp/nx.vdsh"
check "near: the refusal names the option" grep -q -- "--decision-near" "$tmp/err.txt"
expect_exit 2 "near: not negative" "$bake" "${near[@]}" --decision-near -1 -o "$tmp/nx.vdsh"
check "near: nothing written on a refusal" test ! -e "$tmp/nx.vdsh"

# Shell training lights (--decision-shell K, default none): on an object
# (a unit cube on a 4 x 4 floor) the report counts them, the bake is the
# same on 1 and 2 threads and differs from the default's; the default
# places none; only method decision takes the option.
cp "$(dirname "$0")/data/cube_floor.obj" "$tmp/cube_floor.obj"
shell=("$tmp/cube_floor.obj" --max-edge 0.25 --rays 64 --cube-size 0 -q)
expect_exit 0 "shell: 4, 1 thread" "$bake" "${shell[@]}" --decision-shell 4 --threads 1 \
  -o "$tmp/s1.vdsh" --report "$tmp/s1.json"
expect_exit 0 "shell: 4, 2 threads" "$bake" "${shell[@]}" --decision-shell 4 --threads 2 \
  -o "$tmp/s2.vdsh"
expect_exit 0 "shell: default" "$bake" "${shell[@]}" --threads 2 -o "$tmp/s0.vdsh" \
  --report "$tmp/s0.json"
check "shell: 1 and 2 threads give identical files" cmp -s "$tmp/s1.vdsh" "$tmp/s2.vdsh"
check "shell: a quarter of the pool placed in the shell" \
  json "$tmp/s1.json" 'd["decision"]["shell_pool_lights"] == 1024'
check "shell: the default places none" json "$tmp/s0.json" 'd["decision"]["shell_pool_lights"] == 0'
check "shell: the training lights change the fit" bash -c '! cmp -s "$1" "$2"' _ "$tmp/s1.vdsh" \
  "$tmp/s0.vdsh"
expect_exit 2 "shell: only method decision" "$bake" "${shell[@]}" --method shadow \
  --decision-shell 2 -o "$tmp/sx.vdsh"
check "shell: the refusal names the option" grep -q -- "--decision-shell" "$tmp/err.txt"
expect_exit 2 "shell: not negative" "$bake" "${shell[@]}" --decision-shell -1 -o "$tmp/sx.vdsh"

# No room in the shell: a closed cube room, faces inward, has free space
# inside (its pool is placed) but none around it (every point in the
# shell sees the back of a wall): an error that says so, exit 1, nothing
# written; without --decision-shell the room bakes.
cp "$(dirname "$0")/data/cube_room.obj" "$tmp/cube_room.obj"
room=("$tmp/cube_room.obj" --max-edge 1 --rays 16 --cube-size 0 -q)
expect_exit 1 "shell: no room around a closed room" "$bake" "${room[@]}" --decision-shell 4 \
  -o "$tmp/sr.vdsh" --report "$tmp/sr.json"
check "shell: the error names the shell" grep -q "decision shell.*no room for 1024 lights" \
  "$tmp/err.txt"
check "shell: the error says why" grep -q "closed room" "$tmp/err.txt"
check "shell: no file written on no room" test ! -e "$tmp/sr.vdsh"
check "shell: no report written on no room" test ! -e "$tmp/sr.json"
expect_exit 0 "shell: the same room without the shell bakes" "$bake" "${room[@]}" -o "$tmp/sr0.vdsh"

# --crease 60 (the default is off): a cube without normals splits into 24 vertices
# (face normals) and the file records the angle, which vdsh-info shows;
# --crease 0 keeps the 8 smooth corners and records nothing, as does a
# mesh the angle splits nowhere (a corner tetrahedron's face normals meet
# at 90 and 125.3 degrees: split at 60, not at 130): its file is the
# --crease 0 one byte for byte.
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n' >"$tmp/crease_cube.obj"
cube=("$tmp/crease_cube.obj" --rays 16 --cube-size 0 -q)
expect_exit 0 "crease: --crease 60" "$bake" "${cube[@]}" --crease 60 -o "$tmp/c60.vdsh"
expect_exit 0 "crease: --crease 0" "$bake" "${cube[@]}" --crease 0 -o "$tmp/c0.vdsh"
expect_exit 0 "crease: default bake of a cube" "$bake" "${cube[@]}" -o "$tmp/cdef.vdsh"
check "crease: off by default" cmp -s "$tmp/c0.vdsh" "$tmp/cdef.vdsh"
"$info" --json - "$tmp/c60.vdsh" >"$tmp/c60.json" 2>/dev/null
"$info" --json - "$tmp/c0.vdsh" >"$tmp/c0.json" 2>/dev/null
check "crease: 24 receivers at 60" json "$tmp/c60.json" "d['vertex_count'] == 24 and d['bake']['occluder_vertex_count'] == 24 and d['bake']['crease'] == 60"
check "crease: 8 receivers and no crease recorded at 0" json "$tmp/c0.json" "d['vertex_count'] == 8 and 'crease' not in d['bake']"
expect_exit 0 "crease: --crease 180" "$bake" "${cube[@]}" --crease 180 -o "$tmp/c180.vdsh"
check "crease: 180 is off" cmp -s "$tmp/c0.vdsh" "$tmp/c180.vdsh"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n' >"$tmp/tet.obj"
expect_exit 0 "crease: tetrahedron at 130" "$bake" "$tmp/tet.obj" --rays 16 --cube-size 0 -q --crease 130 -o "$tmp/t130.vdsh"
expect_exit 0 "crease: tetrahedron off" "$bake" "$tmp/tet.obj" --rays 16 --cube-size 0 -q --crease 0 -o "$tmp/t0.vdsh"
check "crease: an angle that splits nothing is not recorded" cmp -s "$tmp/t0.vdsh" "$tmp/t130.vdsh"
expect_exit 2 "crease: out of range" "$bake" "${cube[@]}" --crease 181 -o "$tmp/cbad.vdsh"

exit $fail
