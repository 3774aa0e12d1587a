# Frames (included from bake/CMakeLists.txt): ray-traced truth per pixel for
# a view set, the streams on the runtime's path, image scores (eval/frames.c,
# prefix vb_frames_), and the vdsh-frames tool.
add_library(vb_frames STATIC eval/frames.c)
target_link_libraries(vb_frames PUBLIC vb_eval)

add_executable(vdsh-frames tools/vdsh_frames.c)
target_link_libraries(vdsh-frames PRIVATE vb_frames vt_tools)
install(TARGETS vdsh-frames RUNTIME DESTINATION bin)
