# python_reader_matches_c_reader
#                   python/ (numpy only) installed with pip from the
#                   checkout (--no-build-isolation --no-index: Debian's pip
#                   and setuptools), which it must leave as it was;
#                   against the C reader: baked files, the
#                   corpus, a 400-file corruption sweep, the SH table
add_test(NAME python_reader_matches_c_reader
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_python_reader.py
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-info> ${PROJECT_SOURCE_DIR}
                 ${CMAKE_CURRENT_BINARY_DIR}/python_reader)

# python_eval_matches_c_library
#                   python/vdsh/evaluate.py (installed as above) against the
#                   C library (formats/vdsh_sh.c, vdsh_shadow.c) through
#                   test_python_eval_ref: the SH basis at orders 1-16, and
#                   distances and shadows of thousands of vertex-light
#                   pairs over orders 1-16, the adaptive order, every
#                   encoding, every quantity, methods paper/lsq/shadow/
#                   decision, log offsets; `python -m vdsh info` against
#                   vdsh-info --json
add_executable(test_python_eval_ref ${CMAKE_CURRENT_LIST_DIR}/test_python_eval_ref.c)
target_link_libraries(test_python_eval_ref PRIVATE vdsh_format m)
add_test(NAME python_eval_matches_c_library
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_python_eval.py
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-info>
                 $<TARGET_FILE:test_python_eval_ref> ${PROJECT_SOURCE_DIR}
                 ${CMAKE_CURRENT_BINARY_DIR}/python_eval)

# python_info_cli  `python -m vdsh info` on a user's mistakes: --json onto
#                  its own input, into a missing folder, through /dev/stdout
#                  redirected to a file (never replacing the link); inputs
#                  that are not regular files (/dev/zero, a FIFO). Imports
#                  python/ from the checkout; seconds.
add_test(NAME python_info_cli
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_python_info_cli.py
                 ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_BINARY_DIR}/python_info_cli)

# format_plurals    a count of 1 said in the singular ("truncated: 1 byte",
#                   "1 chunk announced", "(1 vertex)", "its 1 triangle"):
#                   the C reader (vdsh-info), the Python reader, the mesh
#                   readers (vdsh-bake); other counts keep the plural
add_test(NAME format_plurals
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_plurals.py
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-info> ${PROJECT_SOURCE_DIR}
                 ${CMAKE_CURRENT_BINARY_DIR}/plurals $<TARGET_FILE:vdsh-eval>)

# format_mesh_not_vdsh
#                   a mesh of every format vdsh-bake reads, handed to each
#                   program that reads a .vdsh (vdsh-info, --verify,
#                   vdsh-eval, vdsh-frames, vdsh-export, vdsh-merge,
#                   vdsh-view where built, python -m vdsh info): exit 1 and
#                   one message, "not a .vdsh file: a PLY mesh; bake it
#                   first: vdsh-bake MODEL -o MODEL.vdsh"
set(_mesh_not_vdsh_programs $<TARGET_FILE:vdsh-info> $<TARGET_FILE:vdsh-eval>
    $<TARGET_FILE:vdsh-frames> $<TARGET_FILE:vdsh-export> $<TARGET_FILE:vdsh-merge>)
if(TARGET vdsh-view)
  list(APPEND _mesh_not_vdsh_programs $<TARGET_FILE:vdsh-view>)
endif()
add_test(NAME format_mesh_not_vdsh
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_mesh_not_vdsh.py
                 ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_BINARY_DIR}/mesh_not_vdsh
                 ${_mesh_not_vdsh_programs})
