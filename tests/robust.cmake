# Robustness (issue 5): nothing crashes, nothing is lost. Every test name
# starts with "robust". Run with: ctest -R robust
#
#   robust_fuzz_<target>   replays the committed seed corpus and the named
#                          regression inputs of each fuzz target
#                          (tests/corpus/<target>/, tests/corpus/regressions/
#                          <target>/) through the target's plain main()
#   robust_corrupt         every single-byte change (and a sample of
#                          two-byte changes) of a baked .vdsh is rejected
#   robust_load            vb_mesh_load_memory (the mesh fuzzers' entry)
#                          loads bytes exactly as vb_mesh_load loads a file
#   robust_kill            SIGKILL at many moments of a bake leaves the old
#                          outputs or complete new ones, never a partial file;
#                          SIGTERM/SIGINT leave no temporary file either
#   robust_cli_bad_input   vdsh-bake and vdsh-info on broken, truncated and
#                          malformed files: exit 1, a message naming the
#                          file, nothing written
#   robust_determinism     real scenes (VDSH_SHARED_SCENES; skips when
#                          absent): 1 vs 2 threads and repeated runs give
#                          byte-identical files
#
# Fuzz targets (one LLVMFuzzerTestOneInput each):
#   vdsh       formats/vdsh.c reader (tests/test_format_fuzz.c)
#   mesh_obj, mesh_ply, mesh_off, mesh_stl
#              vb_mesh_parse and vb_mesh_load_memory of one format
#              (tests/test_fuzz_mesh.c)
#   cubemap    vb_cubemap_read of the basis EXR files (test_fuzz_cubemap.c)
# With -DVDSH_FUZZ=ON (clang only, together with -DVDSH_SANITIZE=ON) each
# is also built as a libFuzzer binary fuzz_<target>; scripts/fuzz TARGET
# SECONDS configures build-fuzz/ that way and runs one. Such a build also
# has fuzz_run_<target>: scripts/fuzz on it for VDSH_FUZZ_SECONDS, label
# fuzz, which the default suite leaves out (scripts/test: ctest -LE fuzz);
# run them with ctest --test-dir build-fuzz -L fuzz.

option(VDSH_FUZZ "Build the libFuzzer targets fuzz_* (clang only)" OFF)
set(VDSH_FUZZ_SECONDS 60 CACHE STRING "Length of each fuzz_run_* test (libFuzzer -max_total_time)")

set(_robust_dir ${CMAKE_CURRENT_LIST_DIR})
set(_corpus ${_robust_dir}/corpus)

if(VDSH_FUZZ)
  if(NOT CMAKE_C_COMPILER_ID MATCHES "Clang" OR NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "VDSH_FUZZ=ON needs clang and clang++ (libFuzzer); "
                        "see scripts/fuzz")
  endif()
  if(NOT VDSH_SANITIZE)
    message(WARNING "VDSH_FUZZ without VDSH_SANITIZE: fuzzers will miss "
                    "memory errors that do not crash")
  endif()
  # Coverage feedback from the code under test, not only the target.
  foreach(lib vdsh_format vb_base vb_mesh vb_cubemap)
    target_compile_options(${lib} PRIVATE -fsanitize=fuzzer-no-link)
  endforeach()
endif()

# New regression folders are picked up without a manual re-configure.
file(GLOB _robust_regressions LIST_DIRECTORIES true CONFIGURE_DEPENDS
     ${_corpus}/regressions/*)

# _robust_fuzz_target(NAME SOURCES src... LIBS lib... [DEFS def...])
function(_robust_fuzz_target name)
  cmake_parse_arguments(F "" "" "SOURCES;LIBS;DEFS" ${ARGN})
  add_executable(test_fuzz_${name} ${F_SOURCES} ${_robust_dir}/test_fuzz_main.c)
  target_compile_definitions(test_fuzz_${name} PRIVATE VDSH_LIBFUZZER ${F_DEFS})
  target_link_libraries(test_fuzz_${name} PRIVATE ${F_LIBS})
  set(dirs ${_corpus}/${name})
  if(EXISTS ${_corpus}/regressions/${name})
    list(APPEND dirs ${_corpus}/regressions/${name})
  endif()
  add_test(NAME robust_fuzz_${name} COMMAND test_fuzz_${name} ${dirs})
  if(VDSH_FUZZ)
    add_executable(fuzz_${name} ${F_SOURCES})
    target_compile_definitions(fuzz_${name} PRIVATE VDSH_LIBFUZZER ${F_DEFS})
    target_compile_options(fuzz_${name} PRIVATE -fsanitize=fuzzer)
    target_link_options(fuzz_${name} PRIVATE -fsanitize=fuzzer)
    target_link_libraries(fuzz_${name} PRIVATE ${F_LIBS})
    math(EXPR limit "${VDSH_FUZZ_SECONDS} + 300")
    add_test(NAME fuzz_run_${name}
             COMMAND bash ${PROJECT_SOURCE_DIR}/scripts/fuzz ${name} ${VDSH_FUZZ_SECONDS})
    set_tests_properties(fuzz_run_${name} PROPERTIES LABELS fuzz TIMEOUT ${limit}
                         ENVIRONMENT VDSH_FUZZ_BUILD=${CMAKE_BINARY_DIR})
  endif()
endfunction()

_robust_fuzz_target(vdsh SOURCES ${_robust_dir}/test_format_fuzz.c LIBS vdsh_format)
foreach(ext obj ply off stl)
  _robust_fuzz_target(mesh_${ext} SOURCES ${_robust_dir}/test_fuzz_mesh.c
                      LIBS vb_mesh m DEFS VDSH_FUZZ_EXT="${ext}")
endforeach()
_robust_fuzz_target(cubemap SOURCES ${_robust_dir}/test_fuzz_cubemap.c
                    LIBS vb_cubemap m)

# Corruption sweep: files baked by vdsh-bake, every byte changed.
add_executable(test_robust_corrupt ${_robust_dir}/test_robust_corrupt.c)
target_link_libraries(test_robust_corrupt PRIVATE vdsh_format)
add_test(NAME robust_corrupt
         COMMAND test_robust_corrupt $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-info>
                 ${CMAKE_CURRENT_BINARY_DIR}/robust_corrupt)

# SIGKILL at many moments of a bake: old outputs or complete new ones.
add_executable(test_robust_kill ${_robust_dir}/test_robust_kill.c)
target_link_libraries(test_robust_kill PRIVATE vt_tools m)
add_test(NAME robust_kill
         COMMAND test_robust_kill $<TARGET_FILE:vdsh-bake> ${CMAKE_CURRENT_BINARY_DIR}/robust_kill)

# Bad input at the command line: vdsh-bake and vdsh-info.
add_test(NAME robust_cli_bad_input
         COMMAND bash ${_robust_dir}/test_robust_cli.sh $<TARGET_FILE:vdsh-bake>
                 $<TARGET_FILE:vdsh-info> ${VDSH_ASSIMP_MODELS})

# Byte-identical bakes of the real scenes across thread counts and runs:
# with every Embree kernel set the CPU supports (with_each_isa.sh, whose
# widest set is the native run); in the sanitizer build, or without the
# scenes (it then skips), once natively.
if(EXISTS ${VDSH_SHARED_SCENES} AND NOT VDSH_SANITIZE)
  add_test(NAME robust_determinism_isa
           COMMAND bash ${_robust_dir}/with_each_isa.sh $<TARGET_FILE:vdsh-bake>
                   bash ${_robust_dir}/test_robust_determinism.sh $<TARGET_FILE:vdsh-bake>
                   ${VDSH_SHARED_SCENES})
  set_tests_properties(robust_determinism_isa PROPERTIES TIMEOUT 1800)
else()
  add_test(NAME robust_determinism
           COMMAND bash ${_robust_dir}/test_robust_determinism.sh $<TARGET_FILE:vdsh-bake>
                   ${VDSH_SHARED_SCENES})
  set_tests_properties(robust_determinism PROPERTIES SKIP_RETURN_CODE 77)
endif()

# vb_mesh_load_memory (what the mesh fuzzers call) is vb_mesh_load: the
# seed corpora and Debian's assimp models, loaded both ways.
set(_load_inputs ${_corpus}/mesh_obj ${_corpus}/mesh_ply ${_corpus}/mesh_off ${_corpus}/mesh_stl)
foreach(sub OBJ PLY OFF STL invalid)
  if(IS_DIRECTORY ${VDSH_ASSIMP_MODELS}/${sub})
    list(APPEND _load_inputs ${VDSH_ASSIMP_MODELS}/${sub})
  endif()
endforeach()
add_executable(test_robust_load ${_robust_dir}/test_robust_load.c)
target_link_libraries(test_robust_load PRIVATE vb_mesh)
add_test(NAME robust_load
         COMMAND test_robust_load ${CMAKE_CURRENT_BINARY_DIR}/robust_load_tmp ${_load_inputs})

# SIGTERM while a program writes leaves no temporary file (vdsh-merge,
# vdsh-frames truth, vdsh-eval, vdsh-export, vdsh-info --json, vdsh-view
# --render): an
# LD_PRELOAD shim sends it at a chosen rename, deterministically. Not in a
# sanitizer build (its runtime must come first among preloaded libraries).
if(NOT VDSH_SANITIZE AND TARGET vdsh-frames AND TARGET vdsh-export)
  add_library(kill_at_rename MODULE ${CMAKE_CURRENT_LIST_DIR}/kill_at_rename.c)
  target_link_libraries(kill_at_rename PRIVATE ${CMAKE_DL_LIBS})
  add_test(NAME robust_signal_leaves_no_temporary
           COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/test_signal_temporaries.sh
                   $<TARGET_FILE:kill_at_rename> $<TARGET_FILE:vdsh-bake>
                   $<TARGET_FILE:vdsh-merge> $<TARGET_FILE:vdsh-frames>
                   $<TARGET_FILE:vdsh-eval> $<TARGET_FILE:vdsh-export> $<TARGET_FILE:vdsh-info>
                   $<$<TARGET_EXISTS:vdsh-view>:$<TARGET_FILE:vdsh-view>>)
  # vdsh-frames truth's folder whole or not at all: killed (the shim) or
  # failed part-way, no partial truth in DIR; an earlier truth kept.
  add_test(NAME robust_truth_whole_or_none
           COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/test_truth_whole.sh
                   $<TARGET_FILE:kill_at_rename> $<TARGET_FILE:vdsh-bake>
                   $<TARGET_FILE:vdsh-frames>)
endif()
