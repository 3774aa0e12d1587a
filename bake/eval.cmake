# The evaluator (included from bake/CMakeLists.txt): its core (eval/eval.c, the
# ground truth and the scores, prefix vb_eval_) and the vdsh-eval tool.
add_library(vb_eval STATIC eval/eval.c)
target_include_directories(vb_eval PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/eval)
target_link_libraries(vb_eval PUBLIC vb_core)

add_executable(vdsh-eval tools/vdsh_eval.c)
target_link_libraries(vdsh-eval PRIVATE vb_eval vt_tools)
install(TARGETS vdsh-eval RUNTIME DESTINATION bin)

