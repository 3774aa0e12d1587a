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
