#!/usr/bin/env bash
# The installed package (issue 19): formats/, tools/ and runtime/ configured
# alone (-DVDSH_BAKE=OFF), built as shared libraries, installed into a
# temporary prefix with `cmake --install`; then a program outside the tree
# (tests/install_consumer) finds it with find_package(vdsh CONFIG), builds,
# and runs (writes, reads back and checks a .vdsh; links the runtime); the
# same program builds with `pkg-config --cflags --libs vdsh-runtime`; the
# installed vdsh-info reads the consumer's file. Then the same with static
# libraries. Issue 26: the installed programs and libraries find their
# shared libraries without LD_LIBRARY_PATH (install RPATH $ORIGIN/../lib),
# also when the prefix is moved; the CMake package has no empty if() and
# finds GLFW for vdsh::context (a static consumer links the imported glfw,
# not a bare -lglfw); vdsh-context.pc builds a consumer of vr_context.h.
# The headers work as <vdsh/vdsh.h> (documented; consumer.c) and as
# <vr_context.h> (context_consumer.c), through both the CMake package and
# pkg-config. Static: libvdsh-formats' pthread is declared (.pc -pthread,
# find_dependency(Threads)) and a -static program links with the .pc flags.
# Usage: test_install.sh CMAKE SOURCE_DIR WORK_DIR C_COMPILER
set -u
cmake=$1 src=$2 work=$3 cc=$4
fail=0
rm -rf "$work"
mkdir -p "$work"
for kind in shared static; do
  shared=$([ $kind = shared ] && echo ON || echo OFF)
  b=$work/$kind/build p=$work/$kind/prefix c=$work/$kind/consumer
  if ! "$cmake" -S "$src" -B "$b" -DCMAKE_BUILD_TYPE=Release -DVDSH_BAKE=OFF \
       -DBUILD_SHARED_LIBS=$shared -DCMAKE_C_COMPILER="$cc" > "$work/$kind.cfg.log" 2>&1; then
    cat "$work/$kind.cfg.log"; echo "FAIL: $kind: configure"; exit 1
  fi
  if ! "$cmake" --build "$b" -j 2 --target vdsh_format vr vr_context vdsh-info > "$work/$kind.build.log" 2>&1; then
    tail -30 "$work/$kind.build.log"; echo "FAIL: $kind: build"; exit 1
  fi
  # vdsh-view needs the whole runtime build; the install rule of every target
  # wants it built, so build all (formats, tools, runtime: seconds).
  "$cmake" --build "$b" -j 2 > "$work/$kind.build2.log" 2>&1 || { tail -30 "$work/$kind.build2.log"; echo "FAIL: $kind: build all"; exit 1; }
  if ! "$cmake" --install "$b" --prefix "$p" > "$work/$kind.install.log" 2>&1; then
    cat "$work/$kind.install.log"; echo "FAIL: $kind: install"; exit 1
  fi
  for f in include/vdsh/vdsh.h include/vdsh/vr.h lib/cmake/vdsh/vdshConfig.cmake \
           lib/cmake/vdsh/vdshConfigVersion.cmake lib/pkgconfig/vdsh-formats.pc \
           lib/pkgconfig/vdsh-runtime.pc lib/pkgconfig/vdsh-context.pc \
           bin/vdsh-info bin/vdsh-export bin/vdsh-view share/vdsh/shaders/vdsh_common.glsl \
           share/vdsh/shaders/vdsh_buffer.glsl share/vdsh/shaders/README.md share/vdsh/web/index.html \
           share/vdsh/web/vdsh_web.js share/vdsh/web/vdsh_core.js share/vdsh/web/vdsh_three.js \
           share/vdsh/web/three.html; do
    [ -e "$p/$f" ] || { echo "FAIL: $kind: $f not installed"; fail=1; }
  done
  # Every if() in the package config tests something (issue 26: the GLFW
  # test was configured empty, `if()`, and GLFW was never looked up).
  if grep -nE '^[[:space:]]*(if|elseif)[[:space:]]*\([[:space:]]*\)' "$p/lib/cmake/vdsh/vdshConfig.cmake"; then
    echo "FAIL: $kind: vdshConfig.cmake has an empty if()"; fail=1
  fi
  # The installed programs and libraries run as installed, and from a moved
  # prefix: no LD_LIBRARY_PATH.
  rm -rf "$work/$kind/moved"
  cp -a "$p" "$work/$kind/moved"
  for q in "$p" "$work/$kind/moved"; do
    for f in "$q"/bin/* "$q"/lib/*.so*; do
      [ -e "$f" ] || continue
      missing=$(env -u LD_LIBRARY_PATH ldd "$f" 2>&1 | grep 'not found')
      [ -z "$missing" ] || { echo "$missing"; echo "FAIL: $kind: ${f#$work/} does not find its libraries"; fail=1; }
    done
  done
  if [ $kind = shared ]; then
    ls "$p"/lib/libvdsh-formats.so.* > /dev/null 2>&1 || { echo "FAIL: no shared libvdsh-formats"; fail=1; }
  else
    [ -e "$p/lib/libvdsh-formats.a" ] || { echo "FAIL: no static libvdsh-formats"; fail=1; }
  fi
  if ! "$cmake" -S "$src/tests/install_consumer" -B "$c" -DCMAKE_PREFIX_PATH="$p" \
       -DCMAKE_C_COMPILER="$cc" > "$work/$kind.consumer.log" 2>&1 ||
     ! "$cmake" --build "$c" >> "$work/$kind.consumer.log" 2>&1; then
    cat "$work/$kind.consumer.log"; echo "FAIL: $kind: consumer with find_package"; fail=1; continue
  fi
  out=$(LD_LIBRARY_PATH="$p/lib" "$c/consumer" "$work/$kind/c.vdsh") || { echo "$out"; echo "FAIL: $kind: consumer run"; fail=1; }
  echo "$kind, find_package: $out"
  echo "$out" | grep -q "read back ok" || { echo "FAIL: $kind: consumer output"; fail=1; }
  echo "$out" | grep -q "^vdsh $(sed -n 's/^project(vdsh VERSION \([0-9.]*\).*/\1/p' "$src/CMakeLists.txt") " ||
    { echo "FAIL: $kind: version"; fail=1; }
  for q in "$p" "$work/$kind/moved"; do
    env -u LD_LIBRARY_PATH "$q/bin/vdsh-info" --verify "$work/$kind/c.vdsh" > /dev/null ||
      { echo "FAIL: $kind: installed ${q#$work/}/bin/vdsh-info cannot read the consumer's file"; fail=1; }
  done
  env -u LD_LIBRARY_PATH "$p/bin/vdsh-view" --help > /dev/null 2>&1 ||
    { echo "FAIL: $kind: installed vdsh-view --help"; fail=1; }
  out=$(env -u LD_LIBRARY_PATH "$c/context_consumer") && [ "$out" = "context: linked" ] ||
    { echo "$out"; echo "FAIL: $kind: context consumer (find_package) run"; fail=1; }
  # GLFW through the package's imported target, not a bare -lglfw that
  # only the default linker path may satisfy.
  if grep -qE '(^| )-lglfw( |$)' "$c/CMakeFiles/context_consumer.dir/link.txt"; then
    echo "FAIL: $kind: vdsh::context links a bare -lglfw: $(cat "$c/CMakeFiles/context_consumer.dir/link.txt")"; fail=1
  fi
  if command -v pkg-config > /dev/null; then
    flags=$(PKG_CONFIG_PATH="$p/lib/pkgconfig" pkg-config --cflags --libs \
            $([ $kind = static ] && echo --static) vdsh-runtime) ||
      { echo "FAIL: $kind: pkg-config"; fail=1; continue; }
    if ! "$cc" -o "$work/$kind/pc-consumer" "$src/tests/install_consumer/consumer.c" $flags \
         > "$work/$kind.pc.log" 2>&1; then
      cat "$work/$kind.pc.log"; echo "FAIL: $kind: consumer with pkg-config ($flags)"; fail=1; continue
    fi
    LD_LIBRARY_PATH="$p/lib" "$work/$kind/pc-consumer" "$work/$kind/d.vdsh" | grep -q "read back ok" ||
      { echo "FAIL: $kind: pkg-config consumer run"; fail=1; }
    flags=$(PKG_CONFIG_PATH="$p/lib/pkgconfig" pkg-config --cflags --libs \
            $([ $kind = static ] && echo --static) vdsh-context) ||
      { echo "FAIL: $kind: pkg-config vdsh-context"; fail=1; continue; }
    if ! "$cc" -o "$work/$kind/pc-context" "$src/tests/install_consumer/context_consumer.c" $flags \
         > "$work/$kind.pc-context.log" 2>&1; then
      cat "$work/$kind.pc-context.log"; echo "FAIL: $kind: context consumer with pkg-config ($flags)"; fail=1; continue
    fi
    LD_LIBRARY_PATH="$p/lib" "$work/$kind/pc-context" | grep -q "context: linked" ||
      { echo "FAIL: $kind: pkg-config context consumer run"; fail=1; }
    if [ $kind = static ]; then
      # libvdsh-formats uses pthread (vdsh_output.c): its static link
      # interface says so (the .pc file and the CMake package did not), and
      # a fully static program links with the .pc file's flags alone.
      flags=$(PKG_CONFIG_PATH="$p/lib/pkgconfig" pkg-config --cflags --libs --static vdsh-formats)
      [[ " $flags " == *" -pthread "* ]] ||
        { echo "FAIL: static: pkg-config --static vdsh-formats lacks -pthread: $flags"; fail=1; }
      grep -q 'find_dependency(Threads)' "$p/lib/cmake/vdsh/vdshConfig.cmake" ||
        { echo "FAIL: static: vdshConfig.cmake does not find_dependency(Threads)"; fail=1; }
      if ! "$cc" -static -o "$work/$kind/pc-formats" "$src/tests/install_consumer/formats_consumer.c" \
           $flags > "$work/$kind.pc-formats.log" 2>&1; then
        cat "$work/$kind.pc-formats.log"; echo "FAIL: static: -static formats consumer with pkg-config ($flags)"; fail=1
      else
        "$work/$kind/pc-formats" "$work/$kind/f.txt" | grep -q "^formats .*: wrote" && [ -s "$work/$kind/f.txt" ] ||
          { echo "FAIL: static: -static formats consumer run"; fail=1; }
      fi
    fi
    echo "$kind, pkg-config: builds and runs (runtime, context)"
  fi
done
[ $fail -eq 0 ] && echo "the package installs, and a consumer builds and runs against it (shared and static)"
exit $fail
