# Tests of formats/: the .vdsh library (test_format), the fuzz target's
# replay, and the vdsh-info tool run on files a fixture writes.
# Included by tests/CMakeLists.txt; every test name starts with "format".

add_executable(test_format ${CMAKE_CURRENT_LIST_DIR}/test_format.c)
target_link_libraries(test_format PRIVATE vdsh_format)
add_test(NAME format_round_trip_and_reader_rules COMMAND test_format)

# formats/vdsh_output.h: atomic output files (every program's writer).
add_executable(test_output ${CMAKE_CURRENT_LIST_DIR}/test_output.c)
target_link_libraries(test_output PRIVATE vdsh_format Threads::Threads)
add_test(NAME format_output_written_atomically COMMAND test_output ${CMAKE_CURRENT_BINARY_DIR}/format_output)

add_executable(test_format_tool ${CMAKE_CURRENT_LIST_DIR}/test_format_tool.c)
target_link_libraries(test_format_tool PRIVATE vdsh_format)

add_executable(test_format_fuzz ${CMAKE_CURRENT_LIST_DIR}/test_format_fuzz.c)
target_link_libraries(test_format_fuzz PRIVATE vdsh_format)

# Fixture files for the tool tests, written by the library itself.
set(_fx ${CMAKE_CURRENT_BINARY_DIR}/format_fixtures)
add_test(NAME format_fixtures_make COMMAND test_format_tool make ${_fx})
add_test(NAME format_fixtures_clean COMMAND test_format_tool clean ${_fx})
set_tests_properties(format_fixtures_make PROPERTIES
                     FIXTURES_SETUP vdsh_format_files)
set_tests_properties(format_fixtures_clean PROPERTIES
                     FIXTURES_CLEANUP vdsh_format_files)

set(_expect $<TARGET_FILE:test_format_tool> expect)
set(_info $<TARGET_FILE:vdsh-info>)
set(_format_tool_tests)

# Usage: name, then the arguments of `test_format_tool expect`. A function,
# not a macro, so escapes in the arguments are not parsed twice; and no '['
# in them: an unbalanced bracket stops CMake splitting ${ARGN}.
function(_format_tool_test name)
  add_test(NAME ${name} COMMAND ${_expect} ${ARGN})
  set_tests_properties(${name} PROPERTIES FIXTURES_REQUIRED vdsh_format_files)
endfunction()

_format_tool_test(format_info_summary 0
  --out "order 5 (25 coefficients), f16, method paper, quantity distance"
  --out "order 3 (9 coefficients), f32, method full, quantity log-distance"
  --out "40 vertices, 60 triangles"
  --out "sha256 a0a1a2a3a4a5a6a7a8a9aaabacadaeafb0b1b2b3b4b5b6b7b8b9babbbcbdbebf"
  --out "window hann (param 2.5)"
  --out "50 bytes per vertex"
  --out "coefficient 0: min 7.5, max 11.4"
  --out "rays traced 100000, missed 2500 (2.50%)"
  --out "total 11.000 s, 2 threads"
  -- ${_info} ${_fx}/good.vdsh)
_format_tool_test(format_info_verify 0
  --out "HEAD" --out "COEF" --out "time" --out " ok"
  --out "valid: every rule"
  -- ${_info} --verify ${_fx}/good.vdsh)
_format_tool_test(format_info_json 0
  --out "\"streams\":" --out "\"sha256\":\t\"000102"
  --out "\\\"quoted\\\"\\\\caf"
  -- ${_info} --json - ${_fx}/good.vdsh)
_format_tool_test(format_info_corrupt 1
  --out "MISMATCH" --err "corrupt.vdsh: chunk 6 'COEF' at offset"
  --err "CRC mismatch"
  -- ${_info} --verify ${_fx}/corrupt.vdsh)
_format_tool_test(format_info_corrupt_summary 1
  --err "corrupt.vdsh: chunk 6 'COEF'"
  -- ${_info} ${_fx}/corrupt.vdsh)
_format_tool_test(format_info_truncated 1
  --out "incomplete" --err "truncated.vdsh: truncated"
  -- ${_info} --verify ${_fx}/truncated.vdsh)
_format_tool_test(format_info_not_vdsh 1
  --err "text.vdsh: not a .vdsh file"
  -- ${_info} ${_fx}/text.vdsh)
# A file the tools write that is not a .vdsh is named for what it is: the
# distance volume (its magic begins "VDSH": it was called a .vdsh damaged
# in a text-mode transfer) and a glb.
_format_tool_test(format_info_names_other_files 1
  --err "volume.sdf: not a .vdsh file: a VDSH distance volume"
  --err "scene.glb: not a .vdsh file: a binary glTF"
  -- ${_info} ${_fx}/volume.sdf ${_fx}/scene.glb)
_format_tool_test(format_info_verify_names_other_files 1
  --err "volume.sdf: not a .vdsh file: a VDSH distance volume"
  -- ${_info} --verify ${_fx}/volume.sdf)
_format_tool_test(format_info_missing 1
  --err "no-such-file.vdsh: cannot open"
  -- ${_info} ${_fx}/no-such-file.vdsh)
# One bad file among good ones: all are printed, the exit code says 1.
_format_tool_test(format_info_several 1
  --out "good.vdsh\n" --err "corrupt.vdsh"
  -- ${_info} ${_fx}/good.vdsh ${_fx}/corrupt.vdsh ${_fx}/good.vdsh)
_format_tool_test(format_info_bad_option 2
  --err "unrecognized option '--no-such-option'" --err "Try 'vdsh-info --help'" -- ${_info} --no-such-option ${_fx}/good.vdsh)
_format_tool_test(format_info_no_file 2
  --err "no input file" -- ${_info})
_format_tool_test(format_info_help 0
  --out "usage:" --out "--verify" -- ${_info} --help)
_format_tool_test(format_info_version 0
  --out "vdsh-info ${PROJECT_VERSION}" -- ${_info} --version)

add_test(NAME format_fuzz_replay
         COMMAND test_format_fuzz ${_fx}/good.vdsh ${_fx}/corrupt.vdsh
                 ${_fx}/truncated.vdsh ${_fx}/text.vdsh)
set(_format_tool_tests format_fuzz_replay)

# The JSON must parse, and say what the file holds.
find_package(Python3 COMPONENTS Interpreter QUIET)
if(Python3_Interpreter_FOUND)
  add_test(NAME format_info_json_parses
           COMMAND ${Python3_EXECUTABLE} -c
"import json, subprocess, sys
def run(*a):
    p = subprocess.run([sys.argv[1], *a], capture_output=True, text=True)
    return p.returncode, json.loads(p.stdout)
rc, d = run('--json', '-', sys.argv[2])
assert rc == 0 and d['valid'] and d['vertex_count'] == 40, d
assert [s['order'] for s in d['streams']] == [5, 3], d['streams']
assert d['streams'][0]['coefficients'] == 25
assert d['sources'][1]['name'] == 'scenes/\"quoted\"\\\\caf\\u00e9.obj', d['sources']
assert len(d['sources'][0]['sha256']) == 64
assert d['timings']['threads'] == 2 and d['stats']['rays_missed'] == 2500
rc, d = run('--json', '-', '--verify', sys.argv[3])
assert rc == 1 and not d['valid'] and d['result'] == 'CRC mismatch', d
assert sum(not c['crc_ok'] for c in d['chunks']) == 1, d['chunks']
print('ok')"
           ${_info} ${_fx}/good.vdsh ${_fx}/corrupt.vdsh)
  list(APPEND _format_tool_tests format_info_json_parses)
endif()

set_tests_properties(${_format_tool_tests} PROPERTIES
                     FIXTURES_REQUIRED vdsh_format_files)

# formats/vdsh_scene_view.h: the default view from a mesh (rays through
# the grid against every triangle, free space, room and object, lights
# moved out of solids).
add_executable(test_scene_view ${CMAKE_CURRENT_LIST_DIR}/test_scene_view.c)
target_link_libraries(test_scene_view PRIVATE vdsh_format m)
add_test(NAME format_scene_view COMMAND test_scene_view unit)
# The 2CylinderEngine (Debian's assimp-testmodels; skipped without it),
# baked coarse: every default light lights what the camera sees of it
# (light 0 stood inside its end cap, the view mostly dark).
if(TARGET vdsh-bake)
  add_test(NAME format_scene_view_engine_lights COMMAND bash -c [=[
glb=/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb
[ -e "$glb" ] || { echo "no $glb: skipped"; exit 77; }
rm -rf "$3"; mkdir -p "$3"
"$1" "$glb" --max-edge 1000 --rays 1 --orders 1 --cube-size 0 -q -o "$3/engine.vdsh" || exit 1
"$2" object-lights "$3/engine.vdsh"
]=] sh $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:test_scene_view> ${CMAKE_CURRENT_BINARY_DIR}/scene_view_engine)
  set_tests_properties(format_scene_view_engine_lights PROPERTIES SKIP_RETURN_CODE 77)
  # The fandisk (../shared/scenes; skipped without it): light 0, in its
  # bounds, faced 23% of what the fit camera sees of it (the default frame
  # dark but a notch); the camera turns toward it (vdsh_view_compute).
  add_test(NAME format_scene_view_fandisk_key COMMAND bash -c [=[
obj=$4/fandisk/fandisk.obj
[ -e "$obj" ] || { echo "no $obj: skipped"; exit 77; }
rm -rf "$3"; mkdir -p "$3"
"$1" "$obj" --rays 1 --orders 1 --cube-size 0 -q -o "$3/fandisk.vdsh" || exit 1
"$2" object-lights "$3/fandisk.vdsh"
]=] sh $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:test_scene_view> ${CMAKE_CURRENT_BINARY_DIR}/scene_view_fandisk
           ${VDSH_SHARED_SCENES})
  set_tests_properties(format_scene_view_fandisk_key PROPERTIES SKIP_RETURN_CODE 77)
endif()

# format_det_math   formats/vdsh_det.h (the bake's sin, cos, exp, log, atan2,
#                   acos, the same bits on every CPU) within 1-4 ulp of libm
add_executable(test_det_math ${CMAKE_CURRENT_LIST_DIR}/test_det_math.c)
target_include_directories(test_det_math PRIVATE ${PROJECT_SOURCE_DIR}/formats)
target_link_libraries(test_det_math PRIVATE m)
add_test(NAME format_det_math_matches_libm COMMAND test_det_math)

# format_cpca       the cpca encoding (issue 29): encoder, writer, reader
#                   and decoder on a synthetic order-7 stream: round trip,
#                   decode to the bit, error bounded, determinism, every
#                   reading rule broken (CRCs fixed) and every truncation
#                   refused, K,B,BITS parsing
add_executable(test_cpca ${CMAKE_CURRENT_LIST_DIR}/test_cpca.c)
target_link_libraries(test_cpca PRIVATE vdsh_format m)
add_test(NAME format_cpca COMMAND test_cpca)
# cpca_widths_tool: scripts/cpca_study's `K.B.wTe` settings (a width per
# basis vector, measurement only; not a test)
add_executable(cpca_widths_tool ${CMAKE_CURRENT_LIST_DIR}/cpca_widths_tool.c)
target_link_libraries(cpca_widths_tool PRIVATE vdsh_format m)
# format_cpca_python  python/vdsh decodes test_cpca's stream to the C
#                   decode's floats bit for bit, and refuses a bad index
add_test(NAME format_cpca_python
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_cpca_python.py
                 $<TARGET_FILE:test_cpca> ${PROJECT_SOURCE_DIR}
                 ${CMAKE_CURRENT_BINARY_DIR}/format_cpca_python)

# format_cpca_refit_uniform, _lights  the cpca encoder's quantisation-aware refit (issue 29)
#                   on a real order-12 bake (builtin room, uniform metric
#                   and a light pool): never raises the clusters' metric
#                   error, lowers it here, the format unchanged, records
#                   decode to the reported error, vdsh_cpca_encode the
#                   default rounds' stream
add_executable(test_cpca_refit ${CMAKE_CURRENT_LIST_DIR}/test_cpca_refit.c)
target_link_libraries(test_cpca_refit PRIVATE vdsh_format m)
foreach(_metric uniform lights)
  add_test(NAME format_cpca_refit_${_metric}
           COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/test_cpca_refit.sh $<TARGET_FILE:vdsh-bake>
                   $<TARGET_FILE:test_cpca_refit> $<TARGET_FILE:light_pool_tool> ${_metric})
endforeach()
# cpca_kchoice_tool: the K,alloc:BYTES fit at several K with each one's
# pool score (issue 29, the choice of K; measurement only).
add_executable(cpca_kchoice_tool ${CMAKE_CURRENT_LIST_DIR}/cpca_kchoice_tool.c)
target_link_libraries(cpca_kchoice_tool PRIVATE vdsh_format m)
