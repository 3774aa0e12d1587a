# glTF 2.0 input and export (issue 18).
#
#   gltf_input        hand-written fixtures (.gltf and .glb) and Debian's
#                     assimp-testmodels glTF2 files through vdsh-bake
#   robust_fuzz_mesh_gltf, robust_fuzz_mesh_glb
#                     the glTF reader's fuzz targets on their seed corpora
#                     (tests/corpus/mesh_gltf, mesh_glb: written by
#                     tests/gltf_fixtures.py)
add_test(NAME gltf_input
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_gltf_input.py
                 $<TARGET_FILE:vdsh-bake> ${CMAKE_CURRENT_BINARY_DIR}/gltf_input ${VDSH_ASSIMP_MODELS})

foreach(ext gltf glb)
  _robust_fuzz_target(mesh_${ext} SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_fuzz_mesh.c
                      LIBS vb_mesh m DEFS VDSH_FUZZ_EXT="${ext}")
endforeach()

# npm packages (gltf-validator) into the build dir, once: a fixture.
#   gltf_export       bake -> vdsh-export -> the Khronos glTF Validator
find_program(VDSH_NODE node)
add_test(NAME gltf_npm_setup
         COMMAND bash ${PROJECT_SOURCE_DIR}/scripts/npm_gltf_tools ${CMAKE_BINARY_DIR}/npm)
set_tests_properties(gltf_npm_setup PROPERTIES FIXTURES_SETUP gltf_npm SKIP_RETURN_CODE 77)
if(VDSH_NODE)
  add_test(NAME gltf_export
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_gltf_export.py
                   $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-export> ${VDSH_NODE}
                   ${CMAKE_BINARY_DIR}/npm/node_modules ${CMAKE_CURRENT_BINARY_DIR}/gltf_export
                   ${VDSH_ASSIMP_MODELS})
  set_tests_properties(gltf_export PROPERTIES FIXTURES_REQUIRED gltf_npm)
endif()

#   gltf_web_viewer   runtime/web in headless chromium against vdsh-view's
#                     shadow-only frame of the same view (skips with 77
#                     without chromium or a GL context)
find_program(VDSH_CHROMIUM chromium)
if(NOT VDSH_CHROMIUM)
  set(VDSH_CHROMIUM chromium)
endif()
add_test(NAME gltf_web_viewer
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_web_viewer.py
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-export> $<TARGET_FILE:vdsh-view>
                 ${VDSH_CHROMIUM} ${PROJECT_SOURCE_DIR}/runtime/web ${CMAKE_CURRENT_BINARY_DIR}/gltf_web
                 ${VDSH_ASSIMP_MODELS})
set_tests_properties(gltf_web_viewer PROPERTIES SKIP_RETURN_CODE 77)
