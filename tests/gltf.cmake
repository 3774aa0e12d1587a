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
                 $<TARGET_FILE:vdsh-bake> ${CMAKE_CURRENT_BINARY_DIR}/gltf_input ${VDSH_ASSIMP_MODELS}
                 $<TARGET_FILE:vdsh-eval> $<TARGET_FILE:vdsh-info>)

#   gltf_uri          a buffer URI with %20 and '+' names the same file in
#                     vdsh-bake and vdsh-export --source (tinygltf's rule,
#                     formats/vdsh_gltf_uri.h); missing or "%00": refused
add_test(NAME gltf_uri
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_gltf_uri.py
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-export> ${CMAKE_CURRENT_BINARY_DIR}/gltf_uri)
#   gltf_source_match vdsh-export --source takes the glTF the bake recorded
#                     (size and SHA-256, external buffers included): an edited
#                     copy (one vertex moved), another quad and a changed .bin
#                     refused, nothing written; --allow-mismatch exports
add_test(NAME gltf_source_match
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_gltf_source_match.py
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-export>
                 ${CMAKE_CURRENT_BINARY_DIR}/gltf_source_match)
#   gltf_uri_rule     formats/vdsh_gltf_uri.h byte for byte against
#                     tinygltf's own dlib::urldecode (hand-picked and
#                     random URIs)
add_executable(test_gltf_uri_rule ${CMAKE_CURRENT_SOURCE_DIR}/test_gltf_uri_rule.cpp)
target_link_libraries(test_gltf_uri_rule PRIVATE vdsh_format)
add_test(NAME gltf_uri_rule COMMAND test_gltf_uri_rule)

foreach(ext gltf glb)
  _robust_fuzz_target(mesh_${ext} SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_fuzz_mesh.c
                      LIBS vb_mesh m DEFS VDSH_FUZZ_EXT="${ext}")
endforeach()

# gltf_source_views  vdsh-export --source refuses a source buffer view that
#                    does not fit its buffer (it read the VDSH attributes
#                    once the buffers were one), naming it; seconds.
add_test(NAME gltf_source_views
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_gltf_source_views.py
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-export>
                 ${CMAKE_CURRENT_BINARY_DIR}/gltf_source_views)

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
  set_tests_properties(gltf_export PROPERTIES FIXTURES_REQUIRED gltf_npm SKIP_RETURN_CODE 77)
  # web_cpca_pack   runtime/web/vdsh_core.js: a cpca stream packed for the
  #                 vertex-stage decode (vdshCpcaBufferData) and decoded as
  #                 vdsh_buffer.glsl does, against the load decode, random
  #                 streams of orders 1-16 (node alone, under a second)
  add_test(NAME web_cpca_pack
           COMMAND ${VDSH_NODE} ${CMAKE_CURRENT_SOURCE_DIR}/web_cpca_pack.mjs
                   ${PROJECT_SOURCE_DIR}/runtime/web/vdsh_core.js)
  # web_fallback_view   runtime/web/vdsh_core.js's vdshFallbackView (the
  #                     page's view of a glb without extras.vdsh.view): a
  #                     flat object (a triangle facing each way, a quad)
  #                     seen from its front, as vdsh-view sees it (the
  #                     view vdsh-export writes), a solid from the bounds
  add_test(NAME web_fallback_view
           COMMAND ${VDSH_NODE} ${CMAKE_CURRENT_SOURCE_DIR}/web_fallback_view.mjs
                   ${PROJECT_SOURCE_DIR}/runtime/web/vdsh_core.js $<TARGET_FILE:vdsh-bake>
                   $<TARGET_FILE:vdsh-export> ${CMAKE_CURRENT_BINARY_DIR}/web_fallback_view)
endif()

#   gltf_web_viewer   runtime/web in headless chromium against vdsh-view's
#                     shadow-only frame of the same view (orders 2-12 and
#                     the adaptive order), its default view against
#                     vdsh-view --render's, quantised and meshopt glb files
#                     (meshoptimizer from the npm fixture), and its error
#                     messages on the page (skips with 77 without chromium
#                     or a GL context)
find_program(VDSH_CHROMIUM chromium)
if(NOT VDSH_CHROMIUM)
  set(VDSH_CHROMIUM chromium)
endif()
add_test(NAME gltf_web_viewer
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_web_viewer.py
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-export> $<TARGET_FILE:vdsh-view>
                 ${VDSH_CHROMIUM} ${PROJECT_SOURCE_DIR}/runtime/web ${CMAKE_CURRENT_BINARY_DIR}/gltf_web
                 ${VDSH_ASSIMP_MODELS} "${VDSH_NODE}" ${CMAKE_BINARY_DIR}/npm/node_modules)
set_tests_properties(gltf_web_viewer PROPERTIES SKIP_RETURN_CODE 77 FIXTURES_REQUIRED gltf_npm)

#   gltf_web_three    runtime/web/vdsh_three.js: a three.js scene (three.js
#                     from the npm fixture) with its own point lights draws
#                     the shadows of an exported glb (orders 2-12, adaptive,
#                     paper's distance, 3 lights, vdsh-export --compress and
#                     meshopt glb, a moved scene, a --source export of a
#                     82-node glTF plain and compressed) against vdsh-view's
#                     frames; and
#                     the runtime's programs from runtime/shaders/ compiled
#                     as GLSL ES 3.00 (skips with 77 without chromium,
#                     three.js or a GL context)
add_test(NAME gltf_web_three
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_web_three.py
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-export> $<TARGET_FILE:vdsh-view>
                 ${VDSH_CHROMIUM} ${PROJECT_SOURCE_DIR}/runtime ${CMAKE_CURRENT_BINARY_DIR}/gltf_three
                 "${VDSH_NODE}" ${CMAKE_BINARY_DIR}/npm/node_modules ${VDSH_ASSIMP_MODELS})
set_tests_properties(gltf_web_three PROPERTIES SKIP_RETURN_CODE 77 FIXTURES_REQUIRED gltf_npm)

#   gltf_robust_load  vb_mesh_load_memory is vb_mesh_load for glTF too: the
#                     seeds and every assimp-testmodels glTF2 folder
#                     (valid and broken files), loaded both ways (with the
#                     other formats' seeds: the test wants >= 100 inputs)
set(_gltf_load_inputs)
foreach(c mesh_gltf mesh_glb mesh_obj mesh_ply mesh_off mesh_stl)
  list(APPEND _gltf_load_inputs ${PROJECT_SOURCE_DIR}/tests/corpus/${c})
endforeach()
file(GLOB_RECURSE _gltf_models LIST_DIRECTORIES false
     ${VDSH_ASSIMP_MODELS}/glTF2/*.gltf ${VDSH_ASSIMP_MODELS}/glTF2/*.glb)
foreach(f ${_gltf_models})
  get_filename_component(d ${f} DIRECTORY)
  list(APPEND _gltf_load_inputs ${d})
endforeach()
list(REMOVE_DUPLICATES _gltf_load_inputs)
add_test(NAME gltf_robust_load
         COMMAND test_robust_load ${CMAKE_CURRENT_BINARY_DIR}/gltf_robust_load_tmp ${_gltf_load_inputs})
