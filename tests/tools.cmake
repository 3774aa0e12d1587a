# Tests of tools/ (what every program shares: vt_cli numbers, vt_json) and
# of the programs' shared behaviour. Every test name starts with "tools".
#   tools_numbers_json_png_views
#                test_tools.c: the number rules, JSON strings (any bytes),
#                exact numbers, NaN as null, the reader
#   tools_cli    test_tools_cli.py: every program end to end - JSON with odd
#                paths parses, one value means one number everywhere, bad
#                numbers exit 2 naming the option, outputs are atomic; the
#                programs' one convention (--help, --version, messages), an
#                output that is an input refused, outputs checked before a
#                bake, cubemaps and .vdsh written together, every JSON
#                strict (no duplicate keys), progress in logs
add_executable(test_tools ${CMAKE_CURRENT_LIST_DIR}/test_tools.c)
target_link_libraries(test_tools PRIVATE vt_tools m)
add_test(NAME tools_numbers_json_png_views COMMAND test_tools ${CMAKE_CURRENT_BINARY_DIR}/tools_unit)

find_package(Python3 COMPONENTS Interpreter QUIET)
if(Python3_Interpreter_FOUND)
  add_test(NAME tools_cli
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_tools_cli.py
                   $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-eval> $<TARGET_FILE:vdsh-info>
                   $<TARGET_FILE:vdsh-view> $<TARGET_FILE:vdsh-merge>
                   $<TARGET_FILE:vdsh-export> $<TARGET_FILE:vdsh-frames>
                   ${CMAKE_CURRENT_BINARY_DIR}/tools_cli)
endif()
