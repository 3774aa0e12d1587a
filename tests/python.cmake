# python_reader     python/ (numpy only) installed with pip from the
#                   checkout (--no-build-isolation --no-index: Debian's pip
#                   and setuptools), which it must leave as it was;
#                   against the C reader: baked files, the
#                   corpus, a 400-file corruption sweep, the SH table
add_test(NAME python_reader
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_python_reader.py
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-info> ${PROJECT_SOURCE_DIR}
                 ${CMAKE_CURRENT_BINARY_DIR}/python_reader)
