add_executable(test_bake test_bake.c)
target_link_libraries(test_bake PRIVATE vb_core)
add_test(NAME bake_core COMMAND test_bake)

add_test(NAME bake_cli
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_bake_cli.sh
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-info>)

add_executable(test_hard test_hard.c)
target_link_libraries(test_hard PRIVATE vb_core)
add_test(NAME bake_hard_cases COMMAND test_hard)

add_executable(test_fit test_fit.c)
target_link_libraries(test_fit PRIVATE vb_core)
target_compile_definitions(test_fit PRIVATE VDSH_TEST_DATA="${CMAKE_CURRENT_SOURCE_DIR}/data")
add_test(NAME bake_fit COMMAND test_fit)

# --quantity auto: deterministic, and it picks the better quantity per order.
find_package(Python3 COMPONENTS Interpreter QUIET)
if(Python3_Interpreter_FOUND)
  add_test(NAME bake_quantity_auto
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_bake_auto.py
                   $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-eval> $<TARGET_FILE:vdsh-info>
                   ${CMAKE_CURRENT_BINARY_DIR}/bake_auto)
endif()
