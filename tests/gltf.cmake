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
