# install_package   cmake --install of formats/ and runtime/ (shared and
#                   static) into a temporary prefix; a consumer outside the
#                   tree builds with find_package(vdsh CONFIG) and with
#                   pkg-config, and runs; the installed programs run
#                   without LD_LIBRARY_PATH (tests/test_install.sh)
add_test(NAME install_package
         COMMAND ${CMAKE_CURRENT_LIST_DIR}/test_install.sh ${CMAKE_COMMAND}
                 ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_BINARY_DIR}/install_package
                 ${CMAKE_C_COMPILER})
set_tests_properties(install_package PROPERTIES TIMEOUT 900)
