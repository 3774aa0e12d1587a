# install_package   cmake --install of formats/ and runtime/ (shared and
#                   static) into a temporary prefix; a consumer outside the
#                   tree builds with find_package(vdsh CONFIG) and with
#                   pkg-config, and runs; the installed programs run
#                   without LD_LIBRARY_PATH (tests/test_install.sh)
add_test(NAME install_package
         COMMAND ${CMAKE_CURRENT_LIST_DIR}/test_install.sh ${CMAKE_COMMAND}
                 ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_BINARY_DIR}/install_package
                 ${CMAKE_C_COMPILER})
set_tests_properties(install_package PROPERTIES TIMEOUT 900)

# install_bake_programs   this build (with the bake) installed into a
#                   temporary prefix: the bake's programs are there and run
#                   from it (a bake, its check, a glb), and
#                   scripts/bake-parallel runs the installed programs
#                   (VDSH_BAKE, VDSH_MERGE) into the whole bake's bytes;
#                   seconds (README "Using the library")
find_program(VDSH_PARALLEL parallel)
add_test(NAME install_bake_programs COMMAND bash -c [=[
cmake=$1; build=$2; src=$3; d=$4; have_parallel=$5
set -u
rm -rf "$d"; mkdir -p "$d"
"$cmake" --install "$build" --prefix "$d/prefix" > "$d/install.log" 2>&1 || { cat "$d/install.log"; exit 1; }
p=$d/prefix/bin
for t in vdsh-bake vdsh-merge vdsh-eval vdsh-frames vdsh-info vdsh-export vdsh-view; do
  [[ -x $p/$t ]] || { echo "FAIL: $t not installed"; exit 1; }
  "$p/$t" --help > /dev/null || { echo "FAIL: installed $t --help"; exit 1; }
done
run() { env -u LD_LIBRARY_PATH "$@"; }
run "$p/vdsh-bake" builtin:room --max-edge 4 --rays 16 -q -o "$d/whole.vdsh" || { echo "FAIL: installed vdsh-bake"; exit 1; }
run "$p/vdsh-info" --verify "$d/whole.vdsh" > /dev/null || { echo "FAIL: installed vdsh-info --verify"; exit 1; }
run "$p/vdsh-export" "$d/whole.vdsh" -q -o "$d/whole.glb" && [[ -s $d/whole.glb ]] || { echo "FAIL: installed vdsh-export"; exit 1; }
if [[ $have_parallel == *parallel ]]; then
  VDSH_BAKE=$p/vdsh-bake VDSH_MERGE=$p/vdsh-merge "$src/scripts/bake-parallel" 2 "$d/sharded.vdsh" -j 2 -- \
    builtin:room --max-edge 4 --rays 16 -q 2> "$d/parallel.log" || { cat "$d/parallel.log"; echo "FAIL: bake-parallel"; exit 1; }
  cmp "$d/whole.vdsh" "$d/sharded.vdsh" || { echo "FAIL: sharded bake differs from the whole bake"; exit 1; }
fi
echo "the bake's programs install and run from $d/prefix"
]=] sh ${CMAKE_COMMAND} ${PROJECT_BINARY_DIR} ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_BINARY_DIR}/install_bake_programs
    "${VDSH_PARALLEL}")
