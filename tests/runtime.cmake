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
  target_link_libraries(${name} PRIVATE vr vr_context vb_cubemap vdsh_format m)
endfunction()

function(_runtime_props name)
  set_tests_properties(${name} PROPERTIES SKIP_RETURN_CODE 77 ${ARGN})
endfunction()

# GLSL against the C SH and shadow evaluation (and cubemap orientation).
_runtime_test(test_runtime_glsl)
add_test(NAME runtime_glsl COMMAND test_runtime_glsl ${_rt_dir}/glsl)
_runtime_props(runtime_glsl)

# A small bake of the built-in room for the tests below (0.2 s).
add_test(NAME runtime_fixture_room
         COMMAND vdsh-bake builtin:room --max-edge 0.5 --rays 400 -q
                 -o ${_rt_dir}/room/room.vdsh)
set_tests_properties(runtime_fixture_room PROPERTIES FIXTURES_SETUP runtime_room)
file(MAKE_DIRECTORY ${_rt_dir}/room)

# Rendering sanity: closed sphere, light behind a wall, modes, passes.
_runtime_test(test_runtime_render)
add_test(NAME runtime_render
         COMMAND test_runtime_render ${_rt_dir}/room/room.vdsh ${_rt_dir}/render)
_runtime_props(runtime_render FIXTURES_REQUIRED runtime_room)

# Bad input: missing, corrupted and truncated files, missing cubemaps.
_runtime_test(test_runtime_errors)
add_test(NAME runtime_errors COMMAND test_runtime_errors ${_rt_dir}/errors)
_runtime_props(runtime_errors)

# vdsh-view on the command line. PNG checks use test_runtime_png (stb).
add_executable(test_runtime_png ${CMAKE_CURRENT_LIST_DIR}/test_runtime_png.c)
target_include_directories(test_runtime_png PRIVATE ${VDSH_STB_INCLUDE})
target_link_libraries(test_runtime_png PRIVATE ${VDSH_STB_LIB} m)

set(_view $<TARGET_FILE:vdsh-view>)
set(_png $<TARGET_FILE:test_runtime_png>)
set(_room ${_rt_dir}/room/room.vdsh)

add_test(NAME runtime_view_help COMMAND sh -c [=[
set -e
"$1" --help | grep -q "^Usage: vdsh-view"
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
exit $fail
]=] sh ${_view} ${_room})

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
cp "$room" "$d/alone.vdsh"
expect1 alone.sh09-12.exr --render "$d/x.png" "$d/alone.vdsh"
expect1 "x/y/z.png" --render "$d/x/y/z.png" "$room"
"$v" -q --render "$d/ok.png" --size 64x48 --no-cubemaps --mode vdsh5poly "$d/alone.vdsh" || { echo "--no-cubemaps failed"; fail=1; }
exit $fail
]=] sh ${_view} ${_room} ${_rt_dir}/view_errors)

# Headless images: one render per mode and the comparison row.
add_test(NAME runtime_view_render COMMAND sh -c [=[
set -e
v=$1; png=$2; room=$3; d=$4
rm -rf "$d"; mkdir -p "$d"
for m in none cube vdsh2 vdsh3 vdsh5 vdsh5poly; do
  "$v" -q --render "$d/$m.png" --size 160x120 --mode $m "$room"
  "$png" info "$d/$m.png" 160 120
done
"$v" -q --render "$d/opts.png" --size 120x90 --mode cube --pcf --shadow-size 128 \
     --camera 5,3,5,0,0.5,0 --light 0,2,0,1,0.5,0.2 --light -3,4,2 --ambient 0.1 \
     --attenuation 1,0.1,0 --fov 75 --egl surfaceless "$room"
"$png" info "$d/opts.png" 120 90
"$v" -q --render "$d/binary.png" --size 120x90 --compare binary --lights 3 "$room"
"$png" info "$d/binary.png" 120 90
"$v" --grid "$d/grid.png" --size 128x96 "$room"
"$png" info "$d/grid.png" 640 96
]=] sh ${_view} ${_png} ${_room} ${_rt_dir}/view_render)

# The benchmark mode: every mode, 1 and 3 lights, two scenes, one process.
add_test(NAME runtime_view_bench COMMAND sh -c [=[
set -e
out=$("$1" --bench --frames 1 --size 96x72 --shadow-size 64 -q "$2" "$2")
echo "$out" | head -c 400; echo
for m in none cube cube_pcf vdsh2 vdsh3 vdsh5 vdsh5poly; do
  echo "$out" | grep -q "\"mode\": \"$m\""
done
echo "$out" | grep -q '"lights": 3'
echo "$out" | grep -q '"renderer": '
]=] sh ${_view} ${_room})

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

foreach(t runtime_view_usage runtime_view_errors runtime_view_render runtime_view_bench
          runtime_view_window)
  _runtime_props(${t} FIXTURES_REQUIRED runtime_room)
endforeach()
_runtime_props(runtime_view_help)
