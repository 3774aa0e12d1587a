# vdsh-frames and its core (bake/frames.h): ray-traced truth for frames and
# image scores. test_frames.c, one part each (see its header):
#   frames_score   the scores on hand-made frames (no files)
#   frames_oracle  the truth scored as a method is exact (built-in room)
#   frames_box     a floor, a box and a light: the shadow's pixel count
#                  against geometry; byte-identical across thread counts
#   frames_views   views: valid, in free space, lit and shadowed, seeded
#   frames_errors  bad input: exit 1 naming the file, usage errors exit 2
if(TARGET vb_frames)
  add_executable(test_frames ${CMAKE_CURRENT_LIST_DIR}/test_frames.c)
  target_link_libraries(test_frames PRIVATE vb_frames vt_tools m)
  add_test(NAME frames_score COMMAND test_frames score)
  foreach(part oracle box views errors)
    add_test(NAME frames_${part}
             COMMAND test_frames ${part} $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-frames>
                     ${CMAKE_CURRENT_BINARY_DIR}/frames_${part})
  endforeach()
endif()
