# Mesh input (bake/lib/mesh.h): loading, validation, welding, normals, the
# built-in room and its variants, refinement, OBJ output, SHA-256.
#   mesh_load_clean_weld_refine
#                no data needed: fixtures are written to a temporary folder
#   mesh_parse   the readers alone, on bytes in memory
#   mesh_shared_scenes_load_expected_counts
#                the real scenes in VDSH_SHARED_SCENES (skips when absent)
#   mesh_assimp_models_load_or_refuse
#                Debian's assimp-testmodels in VDSH_ASSIMP_MODELS, including
#                the malformed files (skips when absent)
# Timings (load of Sponza and lost_empire, refinement of the room and of
# Sponza to 0.2 m): `test_mesh bench <scenes folder>`, not part of the suite.
add_executable(test_mesh ${CMAKE_CURRENT_LIST_DIR}/test_mesh.c)
# vb_core for Embree: the built-in rooms are checked closed by rays.
target_link_libraries(test_mesh PRIVATE vb_core m)

add_test(NAME mesh_load_clean_weld_refine COMMAND test_mesh unit ${CMAKE_CURRENT_BINARY_DIR})
add_test(NAME mesh_shared_scenes_load_expected_counts COMMAND test_mesh scenes ${VDSH_SHARED_SCENES})
add_test(NAME mesh_assimp_models_load_or_refuse COMMAND test_mesh assimp ${VDSH_ASSIMP_MODELS})
set_tests_properties(mesh_shared_scenes_load_expected_counts mesh_assimp_models_load_or_refuse
                     PROPERTIES SKIP_RETURN_CODE 77)

# The strict readers (bake/lib/mesh_parse.h) on bytes: the values bakes depend
# on, and the files OpenMesh's readers misread that are now refused.
add_executable(test_mesh_parse ${CMAKE_CURRENT_LIST_DIR}/test_mesh_parse.c)
target_link_libraries(test_mesh_parse PRIVATE vb_mesh m)
add_test(NAME mesh_parse COMMAND test_mesh_parse ${VDSH_ASSIMP_MODELS})

# What loading found, on vdsh-bake's stderr (and -q, and vdsh-eval quiet).
add_test(NAME mesh_report_cli
         COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/test_mesh_cli.sh
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-eval>)

# The ear clipping's time bound (bake/lib/mesh_read.h triangulate_polygon):
# past it a polygon falls back to its fan, valid triangles (in range,
# distinct corners) partly outside a concave face; every shorter budget
# gives exactly the fan, and a file whose first polygon spends a file's
# budget fans the next too (see the test's header).
add_executable(test_triangulate ${CMAKE_CURRENT_LIST_DIR}/test_triangulate.cpp)
target_link_libraries(test_triangulate PRIVATE vb_mesh m)
add_test(NAME mesh_triangulate_time_bound COMMAND test_triangulate)
