# The distance volume (formats/vdsh_sdf.h, bake/lib/sdf.h): the format's
# round trip and corruption, exact distances and signs in a closed cube
# and an open room (test_sdf), and vdsh-bake --sdf byte for byte the same
# for 1 and 2 threads and every Embree kernel set the CPU has. The GL
# trace against the C one is frames_gl_vs_c (tests/frames.cmake).
add_executable(test_sdf ${CMAKE_CURRENT_LIST_DIR}/test_sdf.c)
target_link_libraries(test_sdf PRIVATE vb_core)
file(MAKE_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/sdf_unit)
add_test(NAME sdf_round_trip_exact_distances COMMAND test_sdf ${CMAKE_CURRENT_BINARY_DIR}/sdf_unit)

add_test(NAME sdf_bake_deterministic COMMAND bash -c [=[
bake=$1; each=$2; d=$3
set -e
rm -rf "$d"; mkdir -p "$d"
run() { "$bake" builtin:room --max-edge 2 --rays 16 --orders 2 --cube-size 0 --sdf 48 -q "$@"; }
run --threads 1 -o "$d/t1.vdsh"
run --threads 2 -o "$d/t2.vdsh"
cmp "$d/t1.sdf" "$d/t2.sdf"
# bad values are usage errors, and no volume without -o
set +e
run --sdf 3 -o "$d/bad.vdsh" 2>/dev/null; [ $? -eq 2 ] || exit 1
"$bake" builtin:room --sdf 16 --trace-only -q 2>/dev/null; [ $? -eq 2 ] || exit 1
set -e
[ ! -e "$d/bad.sdf" ]
# every ISA: the same bytes
bash "$each" "$bake" bash -c '"$0" builtin:room --max-edge 2 --rays 16 --orders 2 --cube-size 0 --sdf 48 -q --threads 2 -o "$1/isa.vdsh" && cmp "$1/t1.sdf" "$1/isa.sdf"' "$bake" "$d"
]=] sh $<TARGET_FILE:vdsh-bake> ${CMAKE_CURRENT_LIST_DIR}/with_each_isa.sh
     ${CMAKE_CURRENT_BINARY_DIR}/sdf_bake)

# vdsh-frames truth --sdf-k on a scene without a distance volume: an error
# naming the file it looked for, no frames (it made no c-sdf frame and
# exited 0, the option silently ignored); with the volume beside it, the
# c-sdf frames.
add_test(NAME sdf_frames_sdf_k_needs_volume COMMAND bash -c [=[
bake=$1; frames=$2; d=$3
rm -rf "$d"; mkdir -p "$d"
run() { "$bake" builtin:room:3 --max-edge 1.5 --rays 16 --orders 2 --cube-size 0 -q "$@"; }
run -o "$d/plain.vdsh" && run --sdf 16 -o "$d/vol.vdsh" || exit 1
"$frames" views "$d/vol.vdsh" -q --cameras 1 --size 32x24 -o "$d/v.json" || exit 1
msg=$("$frames" truth "$d/plain.vdsh" --views "$d/v.json" -o "$d/f0" --sdf-k 3 -q 2>&1); rc=$?
[[ $rc -eq 2 && $msg == *plain.sdf* && ! -e $d/f0 ]] ||
  { echo "FAIL: --sdf-k without a volume: exit $rc, $msg; $(ls "$d/f0" 2>/dev/null | head -3)"; exit 1; }
"$frames" truth "$d/vol.vdsh" --views "$d/v.json" -o "$d/f1" --sdf-k 3 -q || exit 1
[[ -e $d/f1/default-s0-l0-c-sdf.png ]] || { echo "FAIL: no c-sdf frame with the volume"; exit 1; }
]=] sh $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-frames> ${CMAKE_CURRENT_BINARY_DIR}/sdf_k_volume)

# A companion volume left by an earlier bake of the same output (the next
# bake had no --sdf, other receivers): vdsh-frames truth skips it, saying
# so, and writes no c-sdf frames (it wrote c-sdf frames from it, where
# vdsh-view refused to load the scene at all); named with --sdf, it is an
# error (exit 1, no frames), as the runtime's rule (vr.h, sdf_path).
add_test(NAME sdf_frames_stale_companion COMMAND bash -c [=[
bake=$1; frames=$2; d=$3
rm -rf "$d"; mkdir -p "$d"
"$bake" builtin:room:3 --max-edge 2 --rays 16 --orders 2 --cube-size 0 --sdf 16 -q -o "$d/s.vdsh" &&
"$bake" builtin:room:3 --max-edge 1.5 --rays 16 --orders 2 --cube-size 0 -q -o "$d/s.vdsh" || exit 1
[[ -e $d/s.sdf ]] || { echo "FAIL: no s.sdf left by the first bake"; exit 1; }
"$frames" views "$d/s.vdsh" -q --cameras 1 --size 32x24 -o "$d/v.json" || exit 1
# the note is said without -q (with -q only errors: tools_cli)
msg=$("$frames" truth "$d/s.vdsh" --views "$d/v.json" -o "$d/f0" 2>&1); rc=$?
[[ $rc -eq 0 && $msg == *s.sdf*"another bake"* && -e $d/f0/default-s0-l0-c-vdsh2.png && ! -e $d/f0/default-s0-l0-c-sdf.png ]] ||
  { echo "FAIL: stale companion: exit $rc, $msg; $(ls "$d/f0" 2>/dev/null | grep -c sdf) c-sdf frames"; exit 1; }
msg=$("$frames" truth "$d/s.vdsh" --views "$d/v.json" -o "$d/f1" --sdf "$d/s.sdf" -q 2>&1); rc=$?
[[ $rc -eq 1 && $msg == *s.sdf*"another bake"* && ! -e $d/f1 ]] ||
  { echo "FAIL: stale volume named with --sdf: exit $rc, $msg"; exit 1; }
echo "ok: $msg"
]=] sh $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-frames> ${CMAKE_CURRENT_BINARY_DIR}/sdf_stale)

# scripts/sdf_frames' steps without GL (tests/test_sdf_frames_script.py):
# the volume's figures from vdsh-bake --report's "sdf", a clear message
# when no pixel counts, sizes in kB below 1 MB.
if(Python3_EXECUTABLE)
  add_test(NAME sdf_frames_script_report
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_sdf_frames_script.py
                   ${PROJECT_SOURCE_DIR}/scripts $<TARGET_FILE:vdsh-bake>
                   ${CMAKE_CURRENT_BINARY_DIR}/sdf_frames_script)
endif()
