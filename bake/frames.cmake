# Frames (included from bake/CMakeLists.txt): ray-traced truth per pixel for
# a view set, the streams on the runtime's path, image scores (frames.c,
# prefix vb_frames_), and the vdsh-frames tool.
add_library(vb_frames STATIC frames.c)
target_link_libraries(vb_frames PUBLIC vb_eval)

add_executable(vdsh-frames vdsh_frames.c)
target_link_libraries(vdsh-frames PRIVATE vb_frames vt_tools)
install(TARGETS vdsh-frames RUNTIME DESTINATION bin)
