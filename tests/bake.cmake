add_executable(test_bake test_bake.c)
target_link_libraries(test_bake PRIVATE vb_core)
add_test(NAME bake_core COMMAND test_bake)
