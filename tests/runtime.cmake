# Tests of runtime/ (issue 4): the GL runtime library and vdsh-view.
# Every test name starts with "runtime". GL tests make a headless EGL
# context (Mesa llvmpipe works) and exit 77 ("skipped") when none can be
# made. Run with: ctest -R runtime
#
# Sanitizer builds: see pin_libraries in runtime/vr_context.c for why
# LeakSanitizer stays quiet about Mesa; no suppressions are needed.

set(_rt_dir ${CMAKE_CURRENT_BINARY_DIR}/runtime_tmp)
file(MAKE_DIRECTORY ${_rt_dir})

function(_runtime_test name)
  add_executable(${name} ${CMAKE_CURRENT_LIST_DIR}/${name}.c)
  target_include_directories(${name} PRIVATE ${CMAKE_CURRENT_LIST_DIR})
  target_link_libraries(${name} PRIVATE vr vr_context vdsh_format m)
endfunction()

function(_runtime_props name)
  set_tests_properties(${name} PROPERTIES SKIP_RETURN_CODE 77 ${ARGN})
endfunction()

# The upload order of a scene (vertex cache), no GL needed.
_runtime_test(test_runtime_order)
add_test(NAME runtime_order_permutes_and_cuts_cache_misses COMMAND test_runtime_order)

# The basis cubemaps the runtime makes against its old upload of the bake's
# .exr files, texel for texel (the one runtime test that links the EXR
# reader).
_runtime_test(test_runtime_basis)
target_link_libraries(test_runtime_basis PRIVATE vb_cubemap)
add_test(NAME runtime_basis_cubemaps_match_exr_upload COMMAND test_runtime_basis ${_rt_dir}/basis)
_runtime_props(runtime_basis_cubemaps_match_exr_upload)

# GLSL against the C SH and shadow evaluation (and cubemap orientation).
_runtime_test(test_runtime_glsl)
add_test(NAME runtime_glsl_matches_c_evaluation COMMAND test_runtime_glsl ${_rt_dir}/glsl)
_runtime_props(runtime_glsl_matches_c_evaluation)

# runtime/shaders/*.glsl embedded byte for byte, with the C definition's
# constants and the documented interface (no GL).
_runtime_test(test_runtime_shaders)
target_include_directories(test_runtime_shaders PRIVATE ${PROJECT_BINARY_DIR}/runtime)
add_test(NAME runtime_shaders_embedded_byte_for_byte COMMAND test_runtime_shaders ${PROJECT_SOURCE_DIR}/runtime/shaders)

# The shader files as another engine includes them (shaders/README.md's
# recipes, compiled and linked from the files with only the #defines it
# lists), and a buffer path missing a #define fails naming it.
_runtime_test(test_runtime_shaders_standalone)
add_test(NAME runtime_shaders_standalone
         COMMAND test_runtime_shaders_standalone ${PROJECT_SOURCE_DIR}/runtime/shaders)
_runtime_props(runtime_shaders_standalone)

# A small bake of the built-in room for the tests below (0.2 s).
add_test(NAME runtime_fixture_room
         COMMAND vdsh-bake builtin:room --max-edge 0.5 --rays 400 --method paper -q
                 -o ${_rt_dir}/room/room.vdsh)
set_tests_properties(runtime_fixture_room PROPERTIES FIXTURES_SETUP runtime_room)
file(MAKE_DIRECTORY ${_rt_dir}/room)
# The same room baked with --method lsq --log, without cubemaps (0.3 s).
add_test(NAME runtime_fixture_room_log
         COMMAND vdsh-bake builtin:room --max-edge 0.5 --rays 400 --method lsq --log
                 --cube-size 0 -q -o ${_rt_dir}/room_log/room_log.vdsh)
set_tests_properties(runtime_fixture_room_log PROPERTIES FIXTURES_SETUP runtime_room)
file(MAKE_DIRECTORY ${_rt_dir}/room_log)

# Rendering sanity: closed sphere, light behind a wall, modes, passes.
_runtime_test(test_runtime_render)
target_link_libraries(test_runtime_render PRIVATE vb_icosphere)
add_test(NAME runtime_render_shadows_where_expected
         COMMAND test_runtime_render ${_rt_dir}/room/room.vdsh ${_rt_dir}/render)
_runtime_props(runtime_render_shadows_where_expected FIXTURES_REQUIRED runtime_room)

# Log-distance streams on large triangles: a 20 x 20 floor of two
# triangles and a box hovering over one corner, baked with --method lsq
# --log and no cubemaps (0.1 s); drawn on the distance path.
add_test(NAME runtime_fixture_floor COMMAND sh -c [=[
set -e
mkdir -p "$2"
cat > "$2/floor.obj" <<EOF
# a 20 x 20 floor of two triangles, a box hovering over its corner (-10, 0, -10)
v -10 0 -10
v 10 0 -10
v 10 0 10
v -10 0 10
f 1 4 3
f 1 3 2
v -10.5 0.15 -10.5
v -9 0.15 -10.5
v -9 0.15 -9
v -10.5 0.15 -9
v -10.5 0.6 -10.5
v -9 0.6 -10.5
v -9 0.6 -9
v -10.5 0.6 -9
f 5 6 7
f 5 7 8
f 9 12 11
f 9 11 10
f 5 9 10
f 5 10 6
f 6 10 11
f 6 11 7
f 7 11 12
f 7 12 8
f 8 12 9
f 8 9 5
EOF
"$1" "$2/floor.obj" --method lsq --log --cube-size 0 -q -o "$2/floor.vdsh"
]=] sh $<TARGET_FILE:vdsh-bake> ${_rt_dir}/floor)
set_tests_properties(runtime_fixture_floor PROPERTIES FIXTURES_SETUP runtime_floor)

# VR_MODE_VDSH_BUFFER: per vertex against the C evaluation at every order
# the format holds, and against the attribute path on the room.
_runtime_test(test_runtime_buffer)
add_test(NAME runtime_buffer_vertex COMMAND test_runtime_buffer vertex -)
_runtime_props(runtime_buffer_vertex)
foreach(part frames errors)
  add_test(NAME runtime_buffer_${part}
           COMMAND test_runtime_buffer ${part} ${_rt_dir}/room_log/room_log.vdsh)
  _runtime_props(runtime_buffer_${part} FIXTURES_REQUIRED runtime_room)
endforeach()

_runtime_test(test_runtime_log)
add_test(NAME runtime_log_distance_path_no_smear COMMAND test_runtime_log ${_rt_dir}/floor/floor.vdsh)
_runtime_props(runtime_log_distance_path_no_smear FIXTURES_REQUIRED runtime_floor)

# Bad input: missing, corrupted and truncated files, a cube_size no GL
# holds; no file but the .vdsh needed.
_runtime_test(test_runtime_errors)
add_test(NAME runtime_bad_input_clear_errors COMMAND test_runtime_errors ${_rt_dir}/errors)
_runtime_props(runtime_bad_input_clear_errors)

# vdsh-view on the command line. PNG checks use test_runtime_png (stb).
add_executable(test_runtime_png ${CMAKE_CURRENT_LIST_DIR}/test_runtime_png.c)
target_include_directories(test_runtime_png PRIVATE ${VDSH_STB_INCLUDE})
target_link_libraries(test_runtime_png PRIVATE ${VDSH_STB_LIB} m)

set(_view $<TARGET_FILE:vdsh-view>)
set(_png $<TARGET_FILE:test_runtime_png>)
set(_room ${_rt_dir}/room/room.vdsh)
set(_room_log ${_rt_dir}/room_log/room_log.vdsh)

add_test(NAME runtime_view_help COMMAND sh -c [=[
set -e
"$1" --help | grep -q "^usage: vdsh-view"
"$1" --help | grep -q "order n = n bands = n\*n coefficients"
"$1" --version | grep -q "^vdsh-view "
]=] sh ${_view})

# Usage errors exit 2 and say what is wrong.
add_test(NAME runtime_view_usage COMMAND sh -c [=[
v=$1; room=$2; fail=0
expect2() {
  out=$("$v" "$@" 2>&1); rc=$?
  if [ $rc -ne 2 ]; then echo "exit $rc, not 2: $*"; fail=1; fi
  echo "$out" | head -1
}
expect2
expect2 --bogus "$room"
expect2 --mode vdsh4 "$room"
expect2 --compare fuzzy "$room"
expect2 --size 100 "$room"
expect2 --light 1,2 "$room"
expect2 --camera 1,2,3 "$room"
expect2 --render a.png --grid b.png "$room"
expect2 --render a.png "$room" "$room"
expect2 --frames 0 "$room"
expect2 --fit --camera 1,2,3,4,5,6 "$room"
expect2 --bench --bench-cube-sizes 16,0 "$room"
expect2 --bench --bench-cube-sizes 16.5 "$room"
expect2 --bench --bench-cube-sizes 1,2,3,4,5,6,7,8,9 "$room"
expect2 --bench-counts "$room"
expect2 --bench-modes none "$room"
expect2 --bench --bench-modes "" "$room"
# a cpca stream decoded at load and per frame, or at load in --bench
expect2 --render a.png --cpca-load --cpca-frame "$room"
expect2 --bench --cpca-load "$room"
# the window's options where no window opens (they were ignored, exit 0)
expect2 --render a.png --keys abc "$room"
expect2 --grid a.png --screenshot b.png "$room"
expect2 --bench --no-overlay "$room"
# --json is --bench's; given twice, a usage error
expect2 --json a.json "$room"
expect2 --bench --json a.json --json b.json "$room"
exit $fail
]=] sh ${_view} ${_room})

# vdsh-view --bench --json FILE (README: every program writes its JSON
# with --json FILE, '-' stdout; --bench wrote only to stdout): the JSON in
# FILE, nothing on stdout; --json - is stdout; a scene file as FILE is
# refused (exit 1) and left as it was.
add_test(NAME runtime_view_bench_json COMMAND sh -c [=[
v=$1; room=$2; d=$3
rm -rf "$d"; mkdir -p "$d"
b() { "$v" --bench --bench-lights 1 --bench-modes vdsh3 --frames 1 --size 32x24 -q "$@"; }
b --json "$d/b.json" "$room" > "$d/stdout"; rc=$?
[ $rc -eq 77 ] && exit 77
[ $rc -eq 0 ] && [ ! -s "$d/stdout" ] && grep -q '"scenes"' "$d/b.json" ||
  { echo "FAIL: --json FILE: exit $rc, stdout $(wc -c < "$d/stdout") bytes"; exit 1; }
b --json - "$room" > "$d/stdout2" && grep -q '"scenes"' "$d/stdout2" || { echo "FAIL: --json -"; exit 1; }
cp "$room" "$d/copy.vdsh"
b --json "$d/copy.vdsh" "$d/copy.vdsh" 2> "$d/err"; rc=$?
[ $rc -eq 1 ] && cmp -s "$room" "$d/copy.vdsh" || { echo "FAIL: --json over the scene: exit $rc"; cat "$d/err"; exit 1; }
echo ok
]=] sh ${_view} ${_room} ${_rt_dir}/view_bench_json)

# Data errors exit 1 and name the file; nothing crashes.
add_test(NAME runtime_view_errors COMMAND sh -c [=[
v=$1; room=$2; d=$3; fail=0
rm -rf "$d"; mkdir -p "$d"
expect1() {
  needle=$1; shift
  out=$("$v" "$@" 2>&1); rc=$?
  echo "$out" | head -2
  if [ $rc -ne 1 ]; then echo "exit $rc, not 1: $*"; fail=1; fi
  echo "$out" | grep -q -- "$needle" || { echo "message does not name $needle"; fail=1; }
}
expect1 nothere.vdsh --render "$d/x.png" "$d/nothere.vdsh"
head -c 1000 "$room" > "$d/cut.vdsh"
expect1 cut.vdsh --render "$d/x.png" "$d/cut.vdsh"
# The .vdsh alone, without the .exr files the bake wrote beside it:
# vdsh5 draws the same bytes (the runtime makes the basis cubemaps).
cp "$room" "$d/alone.vdsh"
"$v" -q --render "$d/alone.png" --size 64x48 --mode vdsh5 "$d/alone.vdsh" || { echo "vdsh5 of the .vdsh alone failed"; fail=1; }
"$v" -q --render "$d/beside.png" --size 64x48 --mode vdsh5 "$room" || fail=1
cmp "$d/alone.png" "$d/beside.png" || { echo "the .vdsh alone renders differently"; fail=1; }
expect1 "x/y/z.png" --render "$d/x/y/z.png" "$room"
# mode sdf without a volume names the file it looked for, this scene's own
# (it cited a sample room.sdf)
expect1 "no $d/alone.sdf" --render "$d/x.png" --mode sdf "$d/alone.vdsh"
"$v" -q --render "$d/ok.png" --size 64x48 --no-cubemaps --mode vdsh5poly "$d/alone.vdsh" || { echo "--no-cubemaps failed"; fail=1; }
# a log-distance bake needs no cubemaps in any mode
"$v" -q --render "$d/log.png" --size 64x48 --mode vdsh5 "$4" || { echo "log-distance vdsh5 failed"; fail=1; }
# the buffer path: an order the file lacks is named; one it has draws
expect1 "no order-7" --render "$d/x.png" --mode buf7 "$room"
expect1 "order per vertex" --render "$d/x.png" --mode adaptive "$room"
"$v" -q --render "$d/buf3.png" --size 64x48 --mode buf3 "$4" || { echo "buf3 failed"; fail=1; }
exit $fail
]=] sh ${_view} ${_room} ${_rt_dir}/view_errors ${_room_log})

# Scale: a scene 1e-11 units across draws the same bytes as at unit size
# (it drew black: every surface was nearer than the near plane); one too
# small or too large for the view's float arithmetic (1e-16, 1e20 across)
# is refused, exit 1, naming the file and what to do (1e20 crashed).
if(TARGET vdsh-bake)
  add_test(NAME runtime_view_scale COMMAND sh -c [=[
v=$1; bake=$2; d=$3; png=$4; fail=0
rm -rf "$d"; mkdir -p "$d"
for s in 1 1e-11 1e10 1e17 1e-16 1e20; do
  awk -v s=$s 'BEGIN {
    split("0 0 0 4 0 0 4 0 4 0 0 4 1 1 1 3 1 1 3 1 3 1 1 3", c, " ")
    for (i = 0; i < 8; i++) printf "v %.9g %.9g %.9g\n", c[3*i+1]*s, c[3*i+2]*s, c[3*i+3]*s
    print "f 1 3 2"; print "f 1 4 3"; print "f 5 6 7"; print "f 5 7 8"; print "f 5 7 6"; print "f 5 8 7"
  }' > "$d/s$s.obj"
  "$bake" "$d/s$s.obj" --rays 16 --cube-size 0 -q -o "$d/s$s.vdsh" || { echo "bake at scale $s failed"; fail=1; }
done
# The bake takes every scale but says which ones the views refuse.
for c in "1e20 down" "1e-16 up" "1 none"; do
  s=${c%% *}; want=${c#* }
  out=$("$bake" "$d/s$s.obj" --rays 16 --cube-size 0 -o "$d/w.vdsh" 2>&1)
  case $want:$out in
    none:*"warning: the scene"*) echo "scale $s: a warning the views do not need"; fail=1 ;;
    none:*) ;;
    *:*"warning: the scene"*"scale the scene $want"*) ;;
    *) echo "scale $s: no warning to scale the scene $want: $out"; fail=1 ;;
  esac
done
"$v" -q --render "$d/s1.png" --size 64x48 --mode none "$d/s1.vdsh" || fail=1
"$v" -q --render "$d/s1e-11.png" --size 64x48 --mode none "$d/s1e-11.vdsh" || fail=1
# the same picture (to 2/255: the sanitizer build rounds a few pixels otherwise)
"$png" same "$d/s1.png" "$d/s1e-11.png" 2 || { echo "a scene 1e-11 across draws differently"; fail=1; }
# Cube shadow maps at any scale the view takes: the same image, and not
# the unshadowed one (their near plane had an absolute margin of 1e-6, and
# the faces' targets eye + 1, which is the eye in float beyond 2^24). The
# light above the raised quad, scaled with the scene: the default lights
# lie in the light region, here the bounds, below the quad, where it
# shadows nothing.
for s in 1 1e-11 1e10 1e17; do
  l=$(awk -v s=$s 'BEGIN { printf "%.9g,%.9g,%.9g", 2 * s, 3 * s, 2 * s }')
  "$v" -q --render "$d/c$s.png" --size 64x48 --mode cube --light "$l" "$d/s$s.vdsh" || fail=1
done
"$v" -q --render "$d/n1.png" --size 64x48 --mode none --light 2,3,2 "$d/s1.vdsh" || fail=1
! "$png" same "$d/c1.png" "$d/n1.png" 2 2>/dev/null || { echo "cube maps draw no shadow at unit size"; fail=1; }
for s in 1e-11 1e10 1e17; do
  "$png" same "$d/c1.png" "$d/c$s.png" 2 || { echo "cube maps at scale $s draw differently"; fail=1; }
done
for c in "1e-16 scale the scene up" "1e20 scale the scene down"; do
  s=${c%% *}; want=${c#* }
  out=$("$v" -q --render "$d/x.png" --size 64x48 "$d/s$s.vdsh" 2>&1); rc=$?
  echo "$out"
  [ $rc -eq 1 ] || { echo "scale $s: exit $rc, not 1"; fail=1; }
  case $out in *"s$s.vdsh"*"$want"*) ;; *) echo "scale $s: message does not say '$want'"; fail=1 ;; esac
done
[ ! -e "$d/x.png" ] || { echo "a refused scene left an image"; fail=1; }
exit $fail
]=] sh ${_view} $<TARGET_FILE:vdsh-bake> ${_rt_dir}/view_scale ${_png})
  _runtime_props(runtime_view_scale)
  # --fit on a flat object (one triangle) facing away from the fit
  # direction: seen from its front, as the default view sees it (the
  # default camera of an object is the fit camera; --fit framed the
  # triangle's back from the bounds alone).
  add_test(NAME runtime_view_fit_flat COMMAND sh -c [=[
v=$1; bake=$2; d=$3; fail=0
rm -rf "$d"; mkdir -p "$d"
for c in "away 1 2 3" "toward 1 3 2"; do
  set -- $c
  printf 'v 0 0 0\nv 1 0 0\nv 0 0 1\nf %s %s %s\n' $2 $3 $4 > "$d/$1.obj"
  "$bake" "$d/$1.obj" --rays 16 --cube-size 0 -q -o "$d/$1.vdsh" || exit 1
  "$v" -q --render "$d/$1-default.png" --size 64x48 --mode none "$d/$1.vdsh" || exit 1
  "$v" -q --render "$d/$1-fit.png" --size 64x48 --mode none --fit "$d/$1.vdsh" || exit 1
  cmp -s "$d/$1-default.png" "$d/$1-fit.png" || { echo "triangle facing $1: --fit draws another view than the default"; fail=1; }
done
exit $fail
]=] sh ${_view} $<TARGET_FILE:vdsh-bake> ${_rt_dir}/view_fit_flat)
  _runtime_props(runtime_view_fit_flat)
endif()

# Headless images: one render per mode and the comparison row.
add_test(NAME runtime_view_render COMMAND sh -c [=[
set -e
v=$1; png=$2; room=$3; d=$4
rm -rf "$d"; mkdir -p "$d"
for m in none cube vdsh2 vdsh3 vdsh5 vdsh5poly; do
  "$v" -q --render "$d/$m.png" --size 160x120 --mode $m "$room"
  "$png" info "$d/$m.png" 160 120
done
# No --mode: the runtime's default (vr_scene_default_mode), byte for byte:
# order 5 with cubemaps, and without them the polynomials.
"$v" -q --render "$d/default.png" --size 160x120 "$room"
cmp "$d/default.png" "$d/vdsh5.png"
"$v" -q --render "$d/default-nocube.png" --size 160x120 --no-cubemaps "$room"
cmp "$d/default-nocube.png" "$d/vdsh5poly.png"
# Shadows where the room's geometry (bake/lib/builtin.c) puts them. The light
# at (-4, 3.5, 1) is in front of the 1.58 m crate (x in [-4.79, -3.21], z
# in [-3.79, -2.21]); the floor point (-4, 0, -4.2), 0.41 m behind the
# crate, sees it through the crate; (-4, 0, 1.5) sees it 3.5 m away
# across empty room. Seen from (0, 5.5, -6.5), every shadow mode, on the
# paper bake and on the log-distance bake (drawn per vertex), must darken
# the first point and leave the second lit, against mode none; and none
# against itself must fail the darkening check (the control).
cam=0,5.5,-6.5,-4,0,-2; light=-4,3.5,1,0.8,0.8,0.8; dark=-4,0,-4.2; lit=-4,0,1.5
for s in room log; do
  f=$room; [ $s = log ] && f=$5
  for m in none cube vdsh2 vdsh3 vdsh5 vdsh5poly; do
    "$v" -q --render "$d/$s-$m.png" --size 160x120 --mode $m --camera $cam --fov 60 \
         --light $light "$f"
    [ $m = none ] || "$png" shadow "$d/$s-$m.png" "$d/$s-none.png" $cam 60 $dark $lit
  done
done
if "$png" shadow "$d/room-none.png" "$d/room-none.png" $cam 60 $dark $lit 2> "$d/control.log"
then
  echo "control: mode none passes the shadow check"; exit 1
fi
cat "$d/control.log"
grep -q "not darkened" "$d/control.log"
"$v" -q --render "$d/opts.png" --size 120x90 --mode cube --pcf --shadow-size 128 \
     --camera 5,3,5,0,0.5,0 --light 0,2,0,1,0.5,0.2 --light -3,4,2 --ambient 0.1 \
     --attenuation 1,0.1,0 --fov 75 --egl surfaceless "$room"
"$png" info "$d/opts.png" 120 90
"$v" -q --render "$d/binary.png" --size 120x90 --compare binary --lights 3 "$room"
"$png" info "$d/binary.png" 120 90
"$v" --grid "$d/grid.png" --size 128x96 "$room"
"$png" info "$d/grid.png" 640 96
# log-distance: every mode, and a grid of two rows that says what it draws
for m in vdsh2 vdsh3 vdsh5 vdsh5poly; do
  "$v" -q --render "$d/log-$m.png" --size 160x120 --mode $m "$5"
  "$png" info "$d/log-$m.png" 160 120
done
"$v" --grid "$d/grid2.png" --size 128x96 "$room" "$5" 2> "$d/grid2.log"
cat "$d/grid2.log"
"$png" info "$d/grid2.png" 640 192
grep -q "VDSH order 5 (25 coeff., cubemaps)" "$d/grid2.log"
grep -q "VDSH order 5 (25 coeff., log, per-vertex)" "$d/grid2.log"
grep -q "2 rows" "$d/grid2.log"
]=] sh ${_view} ${_png} ${_room} ${_rt_dir}/view_render ${_room_log})

# The default view: an object (a ball baked here) is framed from outside
# and lit from outside - it covers part of the image, not none and not all
# of it (the room's inside eye would stand inside the ball); the room is
# still seen from inside (it fills the image); --fit frames any scene from
# outside. And a PNG that cannot be written whole leaves the old file and
# no temporary.
add_test(NAME runtime_view_frame COMMAND sh -c [=[
set -e
v=$1; bake=$2; png=$3; room=$4; d=$5
rm -rf "$d"; mkdir -p "$d"
# A UV sphere of radius 1 at (3, 1, -2), 12 stacks x 16 slices, wound
# counter-clockwise seen from outside.
awk 'BEGIN {
  S = 12; L = 16; pi = 3.14159265358979
  print "v 3 2 -2"
  for (i = 1; i < S; i++) for (j = 0; j < L; j++) {
    t = pi * i / S; p = 2 * pi * j / L
    printf "v %.6f %.6f %.6f\n", 3 + sin(t) * cos(p), 1 + cos(t), -2 + sin(t) * sin(p)
  }
  print "v 3 0 -2"
  for (j = 0; j < L; j++) { a = 2 + j; b = 2 + (j + 1) % L; print "f 1", b, a }
  for (i = 0; i < S - 2; i++) for (j = 0; j < L; j++) {
    a = 2 + i * L + j; b = 2 + i * L + (j + 1) % L; c = a + L; e = b + L
    print "f", a, b, e; print "f", a, e, c
  }
  n = 2 + (S - 1) * L
  for (j = 0; j < L; j++) { a = 2 + (S - 2) * L + j; b = 2 + (S - 2) * L + (j + 1) % L; print "f", n, a, b }
}' > "$d/ball.obj"
"$bake" "$d/ball.obj" --rays 64 --method lsq --cube-size 0 -q -o "$d/ball.vdsh"
"$v" -q --render "$d/ball.png" --size 160x120 --mode vdsh3 "$d/ball.vdsh"
"$png" coverage "$d/ball.png" 0.05 0.9
"$v" -q --render "$d/room.png" --size 160x120 --mode vdsh3 "$room"
"$png" coverage "$d/room.png" 0.97 1
"$v" -q --render "$d/room-fit.png" --size 160x120 --mode vdsh3 --fit "$room"
"$png" coverage "$d/room-fit.png" 0.05 0.9
# a write that fails (a 1 KiB file size limit): the old file stays
echo old > "$d/keep.png"
if (ulimit -f 1; trap '' XFSZ; exec "$v" -q --render "$d/keep.png" --size 160x120 "$room") 2> "$d/err.txt"; then
  echo "a PNG past the size limit was written"; exit 1
fi
cat "$d/err.txt"
grep -q "keep.png" "$d/err.txt"
test "$(cat "$d/keep.png")" = old
if ls "$d" | grep -q '\.tmp'; then echo "temporary left: $(ls "$d")"; exit 1; fi
]=] sh ${_view} $<TARGET_FILE:vdsh-bake> ${_png} ${_room} ${_rt_dir}/view_frame)

# The benchmark mode: every mode, 1, 3, 16 and 64 lights (fewer rounds for
# 16 and 64), two scenes, one process;
# its JSON parses (a scene path with quotes and backslashes too).
find_package(Python3 COMPONENTS Interpreter QUIET)
if(Python3_Interpreter_FOUND)
  add_test(NAME runtime_view_bench COMMAND ${Python3_EXECUTABLE} -c [=[
import json, os, shutil, subprocess, sys
view, room, room_log, d = sys.argv[1:5]
shutil.rmtree(d, ignore_errors=True)
os.makedirs(d)
odd = os.path.join(os.fsencode(d), b'q"x\\r\t\xffoom.vdsh')
shutil.copy(room_log, odd)
out = subprocess.run([view, '--bench', '--frames', '6', '--size', '96x72', '--shadow-size', '64',
                      '-q', room, room, odd], check=True, capture_output=True).stdout
print(out[:400])
b = json.loads(out.decode('utf-8'))
assert b['renderer'] and b['rounds'] == 6 and b['width'] == 96, b
shown = os.path.join(d, 'q"x\\r\t\ufffdoom.vdsh')
assert [s['file'] for s in b['scenes']] == [room, room, shown], [s['file'] for s in b['scenes']]
modes = {r['mode'] for s in b['scenes'] for r in s['results']}
assert modes == {'none', 'cube', 'cube_pcf', 'vdsh2', 'vdsh3', 'vdsh5', 'vdsh5poly', 'buf5'}, modes
assert {r['lights'] for r in b['scenes'][0]['results']} == {1, 3, 16, 64}
rounds = {r['lights']: len(r['cpu_ms']) for r in b['scenes'][0]['results']}
assert rounds == {1: 6, 3: 6, 16: 3, 64: 3}, rounds
r0 = b['scenes'][0]['results'][0]
assert len(r0['process_cpu_ms']) == 6 and len(r0['cpu_ms']) == 6
# the log-distance scene: its VDSH modes on the distance path
log = b['scenes'][2]
assert log['quantity'] == 'log-distance' and log['method'] == 'lsq', log
paths = {(r['mode'], r['path']) for r in log['results']}
assert ('vdsh5', 'distance') in paths, paths
# the buffer path at order 5 beside it, on log-distance scenes only
assert ('buf5', 'distance') in paths, paths
assert 'buf5' not in {r['mode'] for r in b['scenes'][0]['results']}
assert ('vdsh5', 'split') in {(r['mode'], r['path']) for r in b['scenes'][0]['results']}
print('ok')
]=] ${_view} ${_room} ${_room_log} ${_rt_dir}/view_bench)
endif()

# The window: under a display server (Xvfb), the image the window shows
# is the headless one.
add_test(NAME runtime_view_window COMMAND sh -c [=[
command -v xvfb-run >/dev/null 2>&1 || { echo "xvfb-run not found: skipped"; exit 77; }
set -e
v=$1; png=$2; room=$3; d=$4
rm -rf "$d"; mkdir -p "$d"
xvfb-run -a -s "-screen 0 640x480x24" "$v" -q --frames 3 --size 200x150 --no-overlay \
    --screenshot "$d/window.png" "$room"
"$v" -q --render "$d/headless.png" --size 200x150 "$room"
"$png" info "$d/window.png" 200 150
"$png" same "$d/window.png" "$d/headless.png" 2
# Every key once (modes, comparison, PCF, lights added, selected, removed,
# animated, fired, screenshot, help, reset), then a few frames more.
cd "$d"
xvfb-run -a -s "-screen 0 640x480x24" "$v" --frames 40 --size 160x120 \
    --keys "2p1345c6mmn>> f<hoxr2n" "$room" > keys.log
grep -q "mode: cube shadow map" keys.log
grep -q "fired a light" keys.log
grep -q "light removed" keys.log
grep -q "saved vdsh-view-000.png" keys.log
"$png" info vdsh-view-000.png 160 120
]=] sh ${_view} ${_png} ${_room} ${_rt_dir}/view_window)

# The default lights of the built-in room (baked above) in free space: none
# in or on a pillar, crate or the sphere (test_scene_view, no GL).
add_test(NAME runtime_default_lights COMMAND test_scene_view room ${_rt_dir}/room/room.vdsh)
set_tests_properties(runtime_default_lights PROPERTIES FIXTURES_REQUIRED runtime_room)

# Frames of a view set (vdsh-view --views --frames): names, sizes and
# formats; the crate's shadow low and a lit floor point 1 in every shadow
# mode, also at a grazing angle (the frames are the shadow factor, no
# Lambert term); pixels with no surface 1; a surface facing away from the
# light hidden by the cube map; a subset of modes on the log-distance bake;
# errors. The runtime's default view is vdsh_view_compute's.
add_executable(test_runtime_frames ${CMAKE_CURRENT_LIST_DIR}/test_runtime_frames.c)
target_include_directories(test_runtime_frames PRIVATE ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(test_runtime_frames PRIVATE vr vr_context vb_cubemap vdsh_format vt_tools m)

add_test(NAME runtime_view_frames COMMAND sh -c [=[
v=$1; t=$2; room=$3; log=$4; d=$5
"$t" gl || exit $?
set -e
rm -rf "$d"; mkdir -p "$d"
cat > "$d/views.json" <<EOF
{"width": 160, "height": 120,
 "views": [{"name": "crate", "eye": [0, 5.5, -6.5], "target": [-4, 0, -2], "up": [0, 1, 0],
            "fov_y": 60, "light_sets": [[[-4, 3.5, 1]], [[-4, 3.5, 1], [3, 4, 0]]]},
           {"name": "outside", "eye": [26, 16, 22], "target": [0, 3, 0], "fov_y": 40,
            "light_sets": [[[0, 3, 0]]]}]}
EOF
all=cube,cube-pcf,vdsh2,vdsh3,vdsh5,vdsh5poly
"$v" --views "$d/views.json" --frames "$d/room" "$room" 2> "$d/room.log"
cat "$d/room.log"
grep -q "\[24/24\] $d/room/outside-s0-l0-vdsh5poly.png" "$d/room.log"
grep -q "mode cube-pcf: 4 frames of 160x120" "$d/room.log"
"$t" names "$d/views.json" "$d/room" $all
test -f "$d/room/crate-s1-l1-cube-pcf.png"
test -f "$d/room/crate-s1-shaded-cube-pcf.png"
# the light at (-4, 3.5, 1) is in front of the 1.58 m crate; the floor at
# (-4, 0, -4) is just behind it, (-4, 0, 1.5) below the light and (0, 0, -3)
# lit at 58 degrees from the normal (Lambert 0.53)
"$t" values "$d/views.json" "$d/room" crate 0 0 -4,0,-4 -4,0,1.5 $all
"$t" values "$d/views.json" "$d/room" crate 1 0 -4,0,-4 0,0,-3 $all
"$t" empty "$d/views.json" "$d/room" "$room" outside $all
# the crate's side toward the camera faces away from the light
"$t" facing "$d/views.json" "$d/room" crate 0 0 -4,0.79,-3.79 $all
# a log-distance bake (no cubemaps), some modes
"$v" -q --views "$d/views.json" --frames "$d/log" --modes vdsh5,cube-pcf,vdsh3,vdsh5 "$log"
"$t" names "$d/views.json" "$d/log" vdsh5,cube-pcf,vdsh3
"$t" values "$d/views.json" "$d/log" crate 0 0 -4,0,-4 -4,0,1.5 vdsh5,cube-pcf,vdsh3
# errors: exit 1 naming the file or the mode, exit 2 for usage
expect() {
  code=$1; needle=$2; shift 2
  rc=0; "$v" "$@" > "$d/err.txt" 2>&1 || rc=$?
  cat "$d/err.txt"
  [ $rc -eq $code ] || { echo "exit $rc, not $code: $*"; exit 1; }
  grep -q -- "$needle" "$d/err.txt" || { echo "message does not say $needle"; exit 1; }
}
cp "$room" "$d/alone.vdsh"
expect 1 "mode vdsh5 is not available" --views "$d/views.json" --frames "$d/x" --no-cubemaps --modes vdsh5 "$d/alone.vdsh"
echo '{"width": 16}' > "$d/bad.json"
expect 1 "bad.json" --views "$d/bad.json" --frames "$d/x" "$room"
expect 1 "nothere.json" --views "$d/nothere.json" --frames "$d/x" "$room"
expect 1 "not a directory" --views "$d/views.json" --frames "$d/views.json" "$room"
expect 2 "--frames DIR" --views "$d/views.json" "$room"
expect 2 "--modes" --views "$d/views.json" --frames "$d/x" --modes vdsh4 "$room"
expect 2 "--modes" --modes vdsh5 --render "$d/x.png" "$room"
expect 2 "not with" --views "$d/views.json" --frames "$d/x" --size 64x48 "$room"
expect 2 "not with" --views "$d/views.json" --frames "$d/x" --bench "$room"
expect 2 "not with --mode or --pcf" --views "$d/views.json" --frames "$d/x" --pcf "$room"
expect 2 "positive count" --frames "$d/x" "$room"
"$t" lights "$room"
]=] sh ${_view} $<TARGET_FILE:test_runtime_frames> ${_room} ${_room_log} ${_rt_dir}/view_frames)

# The buffer modes on the command line: a file with orders 7, 9, 12 and an
# order per vertex (test_runtime_buffer derive); the grid gains its
# buffer column (| buf12) and adaptive-order column (7 panels) and says
# so; --help names the modes; a file of adaptive order alone draws its buffer and its grid row and
# summary line name its method; files of fixed orders without order 5
# name their method and their first order in the summary line; an order
# other than 2, 3, 5 gets the buffer column (| bufN), a cpca order 5 the
# order-5 column.
add_test(NAME runtime_view_buffer COMMAND sh -c [=[
set -e
v=$1; png=$2; derive=$3; log=$4; d=$5
rm -rf "$d"; mkdir -p "$d"
"$derive" derive "$log" "$d/high.vdsh"
for m in buf7 buf12 adaptive buffer; do
  "$v" -q --render "$d/$m.png" --size 96x72 --mode $m --lights 3 "$d/high.vdsh"
  "$png" info "$d/$m.png" 96 72
done
"$v" --render "$d/a.png" --size 96x72 --mode adaptive "$d/high.vdsh" 2> "$d/render.log"
cat "$d/render.log"
grep -q "VDSH adaptive order (up to 11, mean 6.0" "$d/render.log"
"$v" --grid "$d/grid.png" --size 96x72 "$d/high.vdsh" "$log" 2> "$d/grid.log"
cat "$d/grid.log"
"$png" info "$d/grid.png" 672 144
grep -q "| buf12 | adaptive" "$d/grid.log"
"$v" --grid "$d/grid5.png" --size 96x72 "$log" 2> /dev/null
"$png" info "$d/grid5.png" 480 72
"$v" --help | grep -q "bufN the stream of order N"
"$v" --help | grep -q "adaptive-order column\|| adaptive order"
"$v" --help | grep -q "| bufN when a SCENE has a fixed order"
# A bake of adaptive order alone: the default mode is the buffer's
"$6" builtin:room --max-edge 1.0 --rays 256 --adaptive-order 0.05 --max-order 9 -q \
  -o "$d/adaptive.vdsh"
"$v" --render "$d/default.png" --size 96x72 "$d/adaptive.vdsh" 2> "$d/default.log"
cat "$d/default.log"
grep -q "mode buffer: VDSH adaptive order (up to 9" "$d/default.log"
# its grid row names the adaptive stream's method (it had no fixed order
# and was labelled a paper bake)
"$v" --grid "$d/agrid.png" --size 96x72 "$d/adaptive.vdsh" 2> "$d/agrid.log"
cat "$d/agrid.log"
grep -q "adaptive.vdsh: decision bake" "$d/agrid.log"
# and its summary line describes that stream and its method, not the
# order-5 column (not in this file)
grep -q "| adaptive (VDSH adaptive order (up to 9, mean [0-9.]*; per-vertex), decision)" \
  "$d/agrid.log"
if grep -q "VDSH order 5" "$d/agrid.log"; then exit 1; fi
# A file of fixed orders without 5: order 3 alone, whose summary names
# order 3; order 7 alone (drawn from a buffer), whose row names its
# method (shadow; it was labelled a paper bake) and summary order 7
"$6" builtin:room --max-edge 1.0 --rays 256 --orders 3 -q -o "$d/o3.vdsh"
"$v" --grid "$d/o3grid.png" --size 96x72 "$d/o3.vdsh" 2> "$d/o3grid.log"
cat "$d/o3grid.log"
grep -q "vdsh2 (VDSH order 3 (9 coeff" "$d/o3grid.log"
"$6" builtin:room --max-edge 1.0 --rays 256 --orders 7 --method shadow -q -o "$d/o7.vdsh"
"$v" --grid "$d/o7grid.png" --size 96x72 "$d/o7.vdsh" 2> "$d/o7grid.log"
cat "$d/o7grid.log"
grep -q "o7.vdsh: shadow bake" "$d/o7grid.log"
# drawn in a column of its own, the summary line describing that column
# (before: no panel drew order 7)
grep -q "vdsh2 | buf7 (VDSH order 7 (49 coeff" "$d/o7grid.log"
"$png" info "$d/o7grid.png" 576 72
# cpca order 5 alone (a buffer): drawn in the order-5 column, not "not in
# this file" beside a summary that names order 5
"$6" builtin:room --max-edge 1.0 --rays 256 --orders 5 --encoding cpca --cpca auto -q \
  -o "$d/c5.vdsh"
"$v" --grid "$d/c5grid.png" --size 96x72 "$d/c5.vdsh" 2> "$d/c5grid.log"
cat "$d/c5grid.log"
grep -q "none | cube | buf5 | vdsh3 | vdsh2 (VDSH order 5 (25 coeff" "$d/c5grid.log"
"$png" info "$d/c5grid.png" 480 72
]=] sh ${_view} ${_png} $<TARGET_FILE:test_runtime_buffer> ${_room_log} ${_rt_dir}/view_buffer
       $<TARGET_FILE:vdsh-bake>)

# A cpca stream decoded once per frame (--cpca-frame, issue 29): at 16
# lights (two passes of 8, both reading the scratch) the frame is the one
# decoded in every pass, and with 3 lights it is not (the control: the
# comparison can fail); a file without a cpca stream draws as before; a
# stream with a width per basis vector draws the same both ways.
if(TARGET vdsh-bake)
add_test(NAME runtime_view_cpca_frame COMMAND sh -c [=[
v=$1; png=$2; bake=$3; log=$4; d=$5
rm -rf "$d"; mkdir -p "$d"
set -e
"$bake" builtin:room --max-edge 1.0 --rays 256 --cube-size 0 --orders 12 --encoding cpca \
  --cpca 8,54,4 -q -o "$d/c.vdsh"
set +e
"$v" -q --vertex-sums --render "$d/pass.png" --size 96x72 --mode buf12 --lights 16 "$d/c.vdsh"
rc=$?
[ $rc -eq 77 ] && exit 77
[ $rc -eq 0 ] || exit 1
if ! "$v" -q --vertex-sums --render "$d/frame.png" --size 96x72 --mode buf12 --lights 16 --cpca-frame \
    "$d/c.vdsh" 2> "$d/frame.err"; then
  cat "$d/frame.err"
  grep -q "shader storage" "$d/frame.err" && exit 77
  exit 1
fi
set -e
"$v" -q --vertex-sums --render "$d/frame3.png" --size 96x72 --mode buf12 --lights 3 --cpca-frame "$d/c.vdsh"
"$png" info "$d/pass.png" 96 72
"$png" same "$d/pass.png" "$d/frame.png" 2
if "$png" same "$d/pass.png" "$d/frame3.png" 2; then echo "control: 3 and 16 lights the same"; exit 1; fi
"$v" -q --vertex-sums --render "$d/log.png" --size 96x72 --mode vdsh5 --cpca-frame "$log"
"$png" info "$d/log.png" 96 72
# A width per basis vector (--cpca K,alloc:BYTES, bits 0): the same, and
# its frame is not the uniform stream's (the control)
"$bake" builtin:room --max-edge 1.0 --rays 256 --cube-size 0 --orders 12 --encoding cpca \
  --cpca 8,alloc:32 -q -o "$d/w.vdsh"
"$v" -q --vertex-sums --render "$d/wpass.png" --size 96x72 --mode buf12 --lights 16 "$d/w.vdsh"
"$v" -q --vertex-sums --render "$d/wframe.png" --size 96x72 --mode buf12 --lights 16 --cpca-frame "$d/w.vdsh"
"$png" info "$d/wpass.png" 96 72
"$png" same "$d/wpass.png" "$d/wframe.png" 2
if "$png" same "$d/wpass.png" "$d/pass.png" 0; then echo "control: widths as uniform"; exit 1; fi
]=] sh ${_view} ${_png} $<TARGET_FILE:vdsh-bake> ${_room_log} ${_rt_dir}/view_cpca_frame)
_runtime_props(runtime_view_cpca_frame FIXTURES_REQUIRED runtime_room)
endif()

# Sums in a compute shader (--compute, vr_scene_desc.sums, issue 29): the
# order-12 cpca stream (decoded in the sums, per vertex for up to 16
# lights; or at load, --cpca-load) and an s8s6 one (summed from its
# records) draw the frame the vertex stage draws, at 16 lights (two
# passes reading the frame's sums at their offsets) and 64 (eight), with
# the default lights per invocation (16 for the cpca stream, 8 for s8s6 on
# llvmpipe), 3 and 1 (VR_SUMS_GROUP); 3 lights is the control. Skips (77)
# where the GL has no compute shaders, which vdsh-view reports as a
# failed load.
if(TARGET vdsh-bake)
add_test(NAME runtime_view_compute COMMAND sh -c [=[
v=$1; png=$2; bake=$3; d=$4
rm -rf "$d"; mkdir -p "$d"
set -e
"$bake" builtin:room --max-edge 1.0 --rays 256 --cube-size 0 --orders 12 --encoding cpca \
  -q -o "$d/c.vdsh"
"$bake" builtin:room --max-edge 1.0 --rays 256 --cube-size 0 --orders 5,12 -q -o "$d/s.vdsh"
set +e
"$v" -q --vertex-sums --render "$d/c16.png" --size 96x72 --mode buf12 --lights 16 "$d/c.vdsh"
rc=$?
[ $rc -eq 77 ] && exit 77
[ $rc -eq 0 ] || exit 1
if ! "$v" -q --render "$d/c16x.png" --size 96x72 --mode buf12 --lights 16 --compute \
    "$d/c.vdsh" 2> "$d/compute.err"; then
  cat "$d/compute.err"
  grep -q "compute shaders" "$d/compute.err" && exit 77
  exit 1
fi
set -e
for f in c s; do
  for n in 3 16 64; do
    [ -f "$d/$f$n.png" ] || "$v" -q --vertex-sums --render "$d/$f$n.png" --size 96x72 --mode buf12 --lights $n "$d/$f.vdsh"
    [ -f "$d/$f${n}x.png" ] || "$v" -q --render "$d/$f${n}x.png" --size 96x72 --mode buf12 \
      --lights $n --compute "$d/$f.vdsh"
    "$png" info "$d/$f${n}x.png" 96 72
    "$png" same "$d/$f$n.png" "$d/$f${n}x.png" 2
  done
  # one light per invocation (GPUs' default) and 3 (a last group short of
  # lights) where llvmpipe takes 8
  for g in 1 3; do
    VR_SUMS_GROUP=$g "$v" -q --render "$d/${f}g$g.png" --size 96x72 --mode buf12 --lights 16 \
      --compute "$d/$f.vdsh"
    "$png" same "$d/${f}16.png" "$d/${f}g$g.png" 2
  done
  if "$png" same "$d/${f}16x.png" "$d/${f}3x.png" 2; then echo "control: 3 and 16 lights"; exit 1; fi
done
# close up, most triangles out of view and many across its edges (a
# corner, the sphere, the floor under a box): the sums skip the vertices
# no triangle in view uses (vr_cull.glsl), and the frame is still the
# vertex stage's
i=0
for cam in "0,1.5,0,-9,1,-9" "5,2,5,-3,0.5,-1" "-1,1.2,2.5,-3,0.5,-1"; do
  i=$((i+1))
  for f in c s; do
    "$v" -q --vertex-sums --render "$d/${f}near$i.png" --size 96x72 --mode buf12 --lights 16 --camera "$cam" \
      --fov 25 "$d/$f.vdsh"
    "$v" -q --render "$d/${f}near${i}x.png" --size 96x72 --mode buf12 --lights 16 --camera "$cam" \
      --fov 25 --compute "$d/$f.vdsh"
    "$png" same "$d/${f}near$i.png" "$d/${f}near${i}x.png" 0
  done
done
# GLSL 3.30 with the compute and storage-buffer extensions (Mesa told
# so; other GLs ignore the variables): the same frame
MESA_GL_VERSION_OVERRIDE=3.3 MESA_GLSL_VERSION_OVERRIDE=330 "$v" -q --render "$d/c16e.png" \
  --size 96x72 --mode buf12 --lights 16 --compute "$d/c.vdsh"
"$png" same "$d/c16.png" "$d/c16e.png" 2
# a cpca stream decoded at load (--cpca-load, VR_CPCA_AT_LOAD), summed in
# compute or in the vertex stage: the same frame
for n in 3 16; do
  "$v" -q --vertex-sums --render "$d/c${n}l.png" --size 96x72 --mode buf12 --lights $n --cpca-load \
    "$d/c.vdsh"
  "$v" -q --render "$d/c${n}lx.png" --size 96x72 --mode buf12 --lights $n --cpca-load --compute \
    "$d/c.vdsh"
  "$png" same "$d/c$n.png" "$d/c${n}l.png" 2
  "$png" same "$d/c$n.png" "$d/c${n}lx.png" 2
done
# GPU memory: decoded in the compute sums, the cpca stream keeps its
# records and model only, as per pass; decoded at load, only its f32
# scratch (576 B per vertex at order 12), the records and model freed;
# once per frame both
"$v" -q --bench --bench-modes buf12,buf12-frame,buf12-compute,buf12-compute-load --bench-lights 1 \
  --frames 1 --size 32x24 --cpca-frame --compute -j "$d/bytes.json" "$d/c.vdsh"
/usr/bin/python3 - "$d/bytes.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))["scenes"][0]
b = {r["mode"]: r["buffer_bytes"] for r in s["results"]}
scratch = s["vertices"] * 576
print("buffer bytes", b, "scratch", scratch)
assert b["buf12-compute"] == b["buf12"], "decoded in the sums: the records and model only"
assert b["buf12-compute-load"] == scratch, "decoded at load: more than the scratch"
assert b["buf12-frame"] == b["buf12"] + scratch, "per frame: records, model and scratch"
assert 0 < b["buf12"] < scratch
PY
# a cpca stream's sums are computed in compute by default (the GL has
# compute shaders here), an s8s6 stream's and --vertex-sums' per pass
"$v" --render "$d/dc.png" --size 32x24 --mode buf12 "$d/c.vdsh" 2>&1 | grep "summed in compute"
"$v" --render "$d/ds.png" --size 32x24 --mode buf12 "$d/s.vdsh" 2>&1 | grep "per-vertex)"
"$v" --render "$d/dv.png" --size 32x24 --mode buf12 --vertex-sums "$d/c.vdsh" 2>&1 |
  grep "per-vertex)"
"$v" --render "$d/dx.png" --size 32x24 --mode buf12 --compute "$d/s.vdsh" 2>&1 |
  grep "summed in compute"
# the attribute modes ignore it
"$v" -q --vertex-sums --render "$d/v5.png" --size 96x72 --mode vdsh5 --lights 16 "$d/s.vdsh"
"$v" -q --render "$d/v5x.png" --size 96x72 --mode vdsh5 --lights 16 --compute "$d/s.vdsh"
"$png" same "$d/v5.png" "$d/v5x.png" 0
]=] sh ${_view} ${_png} $<TARGET_FILE:vdsh-bake> ${_rt_dir}/view_compute)
_runtime_props(runtime_view_compute)
endif()

foreach(t runtime_view_usage runtime_view_bench_json runtime_view_errors runtime_view_render runtime_view_bench
          runtime_view_frame runtime_view_window runtime_view_frames runtime_view_buffer)
  if(TEST ${t})
    _runtime_props(${t} FIXTURES_REQUIRED runtime_room)
  endif()
endforeach()
_runtime_props(runtime_view_help)

# The runtime library and vdsh-view without bake/ (-DVDSH_BAKE=OFF, with
# OpenEXR, Embree and OpenMesh made unfindable), and their target graph in
# the full configure: no vb_* target, none of those libraries. A configure
# and a build of formats/, tools/ and runtime/ (seconds).
add_test(NAME runtime_standalone
         COMMAND ${CMAKE_CURRENT_LIST_DIR}/test_runtime_standalone.sh ${CMAKE_COMMAND}
                 ${PROJECT_SOURCE_DIR} ${_rt_dir}/standalone ${CMAKE_C_COMPILER}
                 ${CMAKE_CXX_COMPILER})

# compute_probe   issue 29's order-12 work in compute shaders (GL 4.3):
#                 sums per (vertex, light) of a bake's order-12 stream
#                 checked against vdsh_sh_eval, a cpca-shaped decode per
#                 (vertex, texel) checked against C; times printed for
#                 docs/BENCHMARKS.md "On a GPU: NVIDIA H200" (measurement:
#                 the times are not asserted). Skips (77) without a GL 4.3
#                 context.
add_executable(compute_probe ${CMAKE_CURRENT_LIST_DIR}/compute_probe.c)
target_link_libraries(compute_probe PRIVATE vr_context vdsh_format m)
if(TARGET vdsh-bake)
  add_test(NAME runtime_compute_probe COMMAND sh -c [=[
rm -rf "$3"; mkdir -p "$3"
"$1" builtin:room --max-edge 1 --rays 16 --cube-size 0 --orders 12 --encoding cpca -q -o "$3/room12.vdsh" || exit 1
"$2" "$3/room12.vdsh" 3
]=] sh $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:compute_probe> ${_rt_dir}/compute_probe)
  _runtime_props(runtime_compute_probe)
endif()

# scripts/gpu_bundle (the GPU frame-time measurement of issue 29 as a
# folder that needs nothing installed): a one-scene bundle's run.sh,
# here on any GL (--any-gl), writes a bench JSON per lights-per-invocation
# group with every mode it names, from the bundle's own copies of
# vdsh-view and the bakes; without --any-gl it refuses a GL that is
# not NVIDIA's (exit 3). Skips (77) without a GL context.
if(TARGET vdsh-bake)
add_test(NAME runtime_gpu_bundle COMMAND sh -c [=[
src=$1; build=$2; d=$3
rm -rf "$d"; mkdir -p "$d"
set -e
"$src/scripts/gpu_bundle" "$d/b" --build "$build" --scenes room=builtin:room:1.5
set +e
OUT="$d/o" FRAMES=1 "$d/b/run.sh" --any-gl > "$d/run.txt" 2>&1
rc=$?
cat "$d/run.txt"
if [ $rc -ne 0 ]; then
  grep -q "could not draw" "$d/run.txt" && grep -qi "context\|EGL" "$d/o/smoke.txt" && exit 77
  exit 1
fi
set -e
for g in default 1 8; do
  /usr/bin/python3 - "$d/o/bench-room-group$g.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
got = {(r["mode"], r["lights"]) for s in j["scenes"] for r in s["results"]}
want = {(m, n) for m in ("buf12", "buf12-frame", "buf12-compute", "buf12-compute-load")
        for n in (1, 16, 64)}
want |= {("vdsh5", n) for n in (1, 16, 64)}
assert want <= got, "missing %s" % sorted(want - got)
assert "/b/s/room-c.vdsh" in json.dumps(j), "not the bundle's bakes"
PY
done
set +e
OUT="$d/o2" "$d/b/run.sh" > "$d/run2.txt" 2>&1
rc=$?
if grep -qi nvidia "$d/o2/smoke.txt"; then exit 0; fi
[ $rc -eq 3 ] && grep -q "not an NVIDIA GL" "$d/run2.txt"
]=] sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR} ${_rt_dir}/gpu_bundle)
_runtime_props(runtime_gpu_bundle)
endif()
