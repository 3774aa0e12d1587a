add_executable(test_sh test_sh.c)
target_link_libraries(test_sh PRIVATE vdsh_format vb_core)
add_test(NAME sh_basis COMMAND test_sh)
