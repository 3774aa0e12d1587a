#!/usr/bin/env bash
# The runtime without the bake (issue 13): formats/, tools/ and runtime/
# configure and build with -DVDSH_BAKE=OFF while CMake is told that
# OpenEXR, Embree and OpenMesh do not exist (CMAKE_DISABLE_FIND_PACKAGE_*:
# any find_package of them fails the configure); vdsh-view and vdsh-info
# then run, and the viewer's shared libraries include none of them. In the
# full configure, the dependency graph of vr and vdsh-view (cmake
# --graphviz, transitive) holds no bake/ target (vb_*) and no OpenEXR,
# Embree or OpenMesh.
# Usage: test_runtime_standalone.sh CMAKE SOURCE_DIR WORK_DIR C_COMPILER CXX_COMPILER
set -u
cmake=$1 src=$2 work=$3 cc=$4 cxx=$5
fail=0
rm -rf "$work"
mkdir -p "$work"
no_bake=(-DCMAKE_DISABLE_FIND_PACKAGE_OpenEXR=ON -DCMAKE_DISABLE_FIND_PACKAGE_embree=ON
         -DCMAKE_DISABLE_FIND_PACKAGE_OpenMesh=ON)

if ! "$cmake" -S "$src" -B "$work/alone" -DCMAKE_BUILD_TYPE=Release -DVDSH_BAKE=OFF \
     -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" "${no_bake[@]}" \
     > "$work/alone.log" 2>&1; then
  cat "$work/alone.log"; echo "FAIL: configure without bake/"; exit 1
fi
if ! "$cmake" --build "$work/alone" -j 2 --target vr vdsh-view vdsh-info > "$work/build.log" 2>&1; then
  tail -30 "$work/build.log"; echo "FAIL: build without bake/"; exit 1
fi
view=$work/alone/runtime/vdsh-view
"$view" --version | grep -q "^vdsh-view " || { echo "FAIL: vdsh-view --version"; fail=1; }
"$work/alone/tools/vdsh-info" --version | grep -q "^vdsh-info " || { echo "FAIL: vdsh-info --version"; fail=1; }
echo "ldd vdsh-view:"
ldd "$view" | sed 's/^/  /'
if ldd "$view" | grep -Ei 'openexr|imath|iex|embree|openmesh|tbb'; then
  echo "FAIL: the viewer links the bake's libraries"; fail=1
fi
[ -d "$work/alone/bake" ] && { echo "FAIL: bake/ configured with VDSH_BAKE=OFF"; fail=1; }

# The full configure's target graph: what vr and vdsh-view depend on.
mkdir -p "$work/graph"
if ! "$cmake" -S "$src" -B "$work/full" -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" \
     --graphviz="$work/graph/deps.dot" > "$work/full.log" 2>&1; then
  cat "$work/full.log"; echo "FAIL: full configure"; exit 1
fi
for t in vr vdsh-view; do
  dot=$work/graph/deps.dot.$t
  [ -f "$dot" ] || { echo "FAIL: no graph for $t"; fail=1; continue; }
  deps=$(grep -o 'label = "[^"]*"' "$dot" | sed 's/label = //; s/"//g' | sort -u | tr '\n' ' ')
  echo "$t depends on: $deps"
  if echo "$deps" | tr ' ' '\n' | grep -Ei '^vb_|openexr|imath|embree|openmesh'; then
    echo "FAIL: $t depends on the bake"; fail=1
  fi
  # the control: the graph does name the targets it should
  echo "$deps" | grep -q "vdsh_format" || { echo "FAIL: $t graph lacks vdsh_format"; fail=1; }
done
[ $fail -eq 0 ] && echo "the runtime and vdsh-view build, link and run without bake/, OpenEXR, Embree and OpenMesh"
exit $fail
