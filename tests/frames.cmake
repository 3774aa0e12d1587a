# vdsh-frames and its core (bake/eval/frames.h): ray-traced truth for frames and
# image scores. test_frames.c, one part each (see its header):
#   frames_scores_of_handmade_frames
#                  the scores on hand-made frames (no files)
#   frames_oracle_scores_exact
#                  the truth scored as a method is exact (built-in room)
#   frames_box_shadow_matches_geometry
#                  a floor, a box and a light: the shadow's pixel count
#                  against geometry; byte-identical across thread counts
#   frames_views   views: valid, in free space, lit and shadowed, seeded;
#                  --light-rule near puts every light near a surface
#   frames_orders  order 7 and variable-order streams (c-vdsh7, c-vdsh-var)
#   frames_errors  bad input: exit 1 naming the file, usage errors exit 2
if(TARGET vb_frames)
  add_executable(test_frames ${CMAKE_CURRENT_LIST_DIR}/test_frames.c)
  target_link_libraries(test_frames PRIVATE vb_frames vt_tools m)
  add_test(NAME frames_scores_of_handmade_frames COMMAND test_frames score)
  # test name : test_frames part (its work folder is frames_<part>)
  foreach(pair oracle_scores_exact:oracle box_shadow_matches_geometry:box views:views
               orders:orders errors:errors)
    string(REPLACE ":" ";" pair ${pair})
    list(GET pair 0 name)
    list(GET pair 1 part)
    add_test(NAME frames_${name}
             COMMAND test_frames ${part} $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-frames>
                     ${CMAKE_CURRENT_BINARY_DIR}/frames_${part})
  endforeach()
endif()

# The GL frame is the one that counts: vdsh-view's shadow-only frames of a
# view set against the same streams computed in C on the runtime's path
# (vdsh-frames truth), for the default bake (log distance, drawn per
# vertex in every mode) and the paper's (distance; order 5 per fragment,
# with the basis cubemaps and as polynomials; and the default bake's streams
# drawn from buffer textures, VR_MODE_VDSH_BUFFER, and streams of orders 7,
# 9, 12 and with an order per vertex, derived from it and baked; cpca
# streams of orders 3, 7 and 12, issue 29, decoded per pass and once per
# frame):
# mean difference <= 0.002 and
# at most 0.5% of the pixels off by more than 0.1 in every frame (measured
# on llvmpipe: <= 1e-4 and 0.003%; one order for another: 0.019 and 3.7%).
# Skips (77) without GL.
if(TARGET vb_frames AND TARGET vdsh-view)
  add_executable(test_frames_gl ${CMAKE_CURRENT_LIST_DIR}/test_frames_gl.c)
  target_link_libraries(test_frames_gl PRIVATE vt_tools m)
  add_test(NAME frames_gl_vs_c COMMAND sh -c [=[
bake=$1; frames=$2; view=$3; cmp=$4; d=$5; views=$6; derive=$7
set -e
rm -rf "$d"; mkdir -p "$d"
for m in shadow paper; do
  # The shadow bake also gets a distance volume (room.sdf): mode sdf
  # against vdsh-frames' c-sdf, the same trace in GLSL and C.
  sdf=; [ $m = shadow ] && sdf="--sdf 32"
  "$bake" builtin:room --max-edge 0.5 --rays 400 --method $m --cube-size 32 $sdf -q -o "$d/$m.vdsh"
  "$frames" truth "$d/$m.vdsh" --views "$views" -o "$d/$m-c" > /dev/null
  set +e
  modes=vdsh2,vdsh3,vdsh5,vdsh5poly
  [ $m = shadow ] && modes=$modes,buf2,buf3,buf5,sdf
  "$view" "$d/$m.vdsh" --views "$views" --frames "$d/$m-gl" --modes $modes -q
  rc=$?
  set -e
  [ $rc -eq 77 ] && exit 77
  [ $rc -eq 0 ] || exit $rc
done
"$cmp" "$views" "$d/shadow-c" "$d/shadow-gl" 0.002 0.005 \
  vdsh2=c-vdsh2 vdsh3=c-vdsh3 vdsh5=c-vdsh5 vdsh5poly=c-vdsh5 \
  buf2=c-vdsh2 buf3=c-vdsh3 buf5=c-vdsh5 sdf=c-sdf
"$cmp" "$views" "$d/paper-c" "$d/paper-gl" 0.002 0.005 \
  vdsh2=c-vdsh2 vdsh3=c-vdsh3 vdsh5=c-vdsh5 vdsh5poly=c-vdsh5
# Orders above 5 and an order per vertex (up to 11; vdsh-frames names its
# C frame c-vdsh-var), derived from the default bake's order 5 with higher
# bands added (test_runtime_buffer derive), in f16, s8s6 and s8.
"$derive" derive "$d/shadow.vdsh" "$d/high.vdsh"
"$frames" truth "$d/high.vdsh" --views "$views" -o "$d/high-c" > /dev/null
"$view" "$d/high.vdsh" --views "$views" --frames "$d/high-gl" --modes buf7,buf9,buf12,adaptive -q
"$cmp" "$views" "$d/high-c" "$d/high-gl" 0.002 0.005 \
  buf7=c-vdsh7 buf9=c-vdsh9 buf12=c-vdsh12 adaptive=c-vdsh-var
# The same from the baker: orders 7, 9, 12 (s8s6) and an adaptive order up
# to 12.
"$bake" builtin:room --max-edge 0.5 --rays 400 --cube-size 0 --orders 7,9,12 \
  --adaptive-order 0.05 -q -o "$d/baked.vdsh"
"$frames" truth "$d/baked.vdsh" --views "$views" -o "$d/baked-c" > /dev/null
"$view" "$d/baked.vdsh" --views "$views" --frames "$d/baked-gl" --modes buf7,buf9,buf12,adaptive -q
"$cmp" "$views" "$d/baked-c" "$d/baked-gl" 0.002 0.005 \
  buf7=c-vdsh7 buf9=c-vdsh9 buf12=c-vdsh12 adaptive=c-vdsh-var
# cpca streams (issue 29), decoded in the vertex stage: order 12 at
# 8,54,4 (4-bit weights, no bits skipped; the default before 16,alloc:32,
# whose widths frames_gl_cpca_widths draws), and orders 3
# and 7 with 5-bit weights (fields skip the ends of words; order 3 is drawn
# from a buffer too: cpca never goes to attributes). The C frames decode
# through vdsh_stream_decode.
"$bake" builtin:room --max-edge 0.5 --rays 400 --cube-size 0 --orders 12 --encoding cpca \
  --cpca 8,54,4 -q -o "$d/cpca.vdsh"
"$bake" builtin:room --max-edge 0.5 --rays 400 --cube-size 0 --orders 3,7 --encoding cpca \
  --cpca 6,20,5 -q -o "$d/cpca5.vdsh"
for f in cpca cpca5; do
  "$frames" truth "$d/$f.vdsh" --views "$views" -o "$d/$f-c" > /dev/null
done
"$view" "$d/cpca.vdsh" --vertex-sums --views "$views" --frames "$d/cpca-gl" --modes buf12 -q
"$view" "$d/cpca5.vdsh" --vertex-sums --views "$views" --frames "$d/cpca5-gl" --modes buf3,buf7 -q
"$cmp" "$views" "$d/cpca-c" "$d/cpca-gl" 0.002 0.005 buf12=c-vdsh12
"$cmp" "$views" "$d/cpca5-c" "$d/cpca5-gl" 0.002 0.005 buf3=c-vdsh3 buf7=c-vdsh7
# The same streams decoded once per frame into a scratch (--cpca-frame,
# vr_scene_desc.cpca_decode; skipped where the GL has no shader storage
# buffers in the vertex stage, which vdsh-view reports as a failed load).
if "$view" "$d/cpca.vdsh" --cpca-frame --vertex-sums --views "$views" --frames "$d/cpcaf-gl" \
    --modes buf12 -q 2> "$d/cpcaf.err"; then
  "$view" "$d/cpca5.vdsh" --cpca-frame --vertex-sums --views "$views" --frames "$d/cpca5f-gl" \
    --modes buf3,buf7 -q
  "$cmp" "$views" "$d/cpca-c" "$d/cpcaf-gl" 0.002 0.005 buf12=c-vdsh12
  "$cmp" "$views" "$d/cpca5-c" "$d/cpca5f-gl" 0.002 0.005 buf3=c-vdsh3 buf7=c-vdsh7
else
  grep -q "shader storage" "$d/cpcaf.err" || { cat "$d/cpcaf.err"; exit 1; }
fi
# Sums in a compute shader (--compute, vr_scene_desc.sums): the cpca
# streams (decoded once per frame first) and the fixed orders of baked
# (the adaptive stream keeps the vertex stage's sums); skipped where the
# GL has no compute shaders.
if "$view" "$d/cpca.vdsh" --compute --views "$views" --frames "$d/cpcax-gl" --modes buf12 -q \
    2> "$d/cpcax.err"; then
  "$view" "$d/cpca5.vdsh" --compute --views "$views" --frames "$d/cpca5x-gl" --modes buf3,buf7 -q
  "$view" "$d/baked.vdsh" --compute --views "$views" --frames "$d/bakedx-gl" \
    --modes buf7,buf9,buf12,adaptive -q
  "$cmp" "$views" "$d/cpca-c" "$d/cpcax-gl" 0.002 0.005 buf12=c-vdsh12
  "$cmp" "$views" "$d/cpca5-c" "$d/cpca5x-gl" 0.002 0.005 buf3=c-vdsh3 buf7=c-vdsh7
  "$cmp" "$views" "$d/baked-c" "$d/bakedx-gl" 0.002 0.005 \
    buf7=c-vdsh7 buf9=c-vdsh9 buf12=c-vdsh12 adaptive=c-vdsh-var
else
  grep -q "compute shaders" "$d/cpcax.err" || { cat "$d/cpcax.err"; exit 1; }
fi
]=] sh $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-frames> $<TARGET_FILE:vdsh-view>
       $<TARGET_FILE:test_frames_gl> ${CMAKE_CURRENT_BINARY_DIR}/frames_gl
       ${CMAKE_CURRENT_LIST_DIR}/data/frames_gl.views.json $<TARGET_FILE:test_runtime_buffer>)
  set_tests_properties(frames_gl_vs_c PROPERTIES SKIP_RETURN_CODE 77)
endif()

# cpca streams with a width per basis vector (--cpca K,alloc:BYTES, bits 0
# and a widths table, issue 29; with f16 bases and with s8, ,bases:8): orders 3 (every vector 8 bits) and 12
# (2 to 6 bits, fields skipping the ends of words), drawn per pass and
# once per frame (vr_buffer.c's BUF_CPCA_UNPACK) against vdsh_stream_decode's
# C frames, within frames_gl_vs_c's bounds. Skips (77) without GL; the
# per-frame half where the GL has no shader storage buffers.
if(TARGET vb_frames AND TARGET vdsh-view)
  add_test(NAME frames_gl_cpca_widths COMMAND sh -c [=[
bake=$1; frames=$2; view=$3; cmp=$4; d=$5; views=$6; info=$7
set -e
rm -rf "$d"; mkdir -p "$d"
for w in w w8; do # f16 bases, then s8 (--cpca ...,bases:8)
  s8=; [ $w = w8 ] && s8=,bases:8
  "$bake" builtin:room --max-edge 0.5 --rays 400 --cube-size 0 --orders 3,12 --encoding cpca \
    --cpca 6,alloc:24$s8 -q -o "$d/$w.vdsh"
  # the order-12 stream's widths are not all one (else this is the uniform case)
  "$info" "$d/$w.vdsh" > "$d/info.txt"
  grep "widths:" "$d/info.txt" | grep -q "x.*,.*x" || { cat "$d/info.txt"; exit 1; }
  [ $w = w ] || grep -q "s8 bases" "$d/info.txt" || { cat "$d/info.txt"; exit 1; }
  "$frames" truth "$d/$w.vdsh" --views "$views" -o "$d/$w-c" > /dev/null
  set +e
  "$view" "$d/$w.vdsh" --views "$views" --frames "$d/$w-gl" --modes buf3,buf12 -q
  rc=$?
  set -e
  [ $rc -eq 77 ] && exit 77
  [ $rc -eq 0 ] || exit $rc
  "$cmp" "$views" "$d/$w-c" "$d/$w-gl" 0.002 0.005 buf3=c-vdsh3 buf12=c-vdsh12
  if "$view" "$d/$w.vdsh" --cpca-frame --views "$views" --frames "$d/${w}f-gl" --modes buf3,buf12 \
      -q 2> "$d/wf.err"; then
    "$cmp" "$views" "$d/$w-c" "$d/${w}f-gl" 0.002 0.005 buf3=c-vdsh3 buf12=c-vdsh12
  else
    grep -q "shader storage" "$d/wf.err" || { cat "$d/wf.err"; exit 1; }
  fi
done
]=] sh $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-frames> $<TARGET_FILE:vdsh-view>
       $<TARGET_FILE:test_frames_gl> ${CMAKE_CURRENT_BINARY_DIR}/frames_gl_cpca_widths
       ${CMAKE_CURRENT_LIST_DIR}/data/frames_gl.views.json $<TARGET_FILE:vdsh-info>)
  set_tests_properties(frames_gl_cpca_widths PROPERTIES SKIP_RETURN_CODE 77)
endif()

# scripts/frames: an unknown scene name is an error; a mesh path is a scene
# (test_frames_script.py; the mesh part skips, 77, without GL).
find_package(Python3 COMPONENTS Interpreter QUIET)
if(Python3_Interpreter_FOUND AND TARGET vb_frames AND TARGET vdsh-view)
  add_test(NAME frames_script
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_frames_script.py
                   ${PROJECT_SOURCE_DIR}/scripts ${PROJECT_BINARY_DIR}
                   ${CMAKE_CURRENT_BINARY_DIR}/frames_script)
  set_tests_properties(frames_script PROPERTIES SKIP_RETURN_CODE 77)
endif()

# The readers' --light-region (test_light_region_readers.py): vdsh-frames
# views' eyes and lights in the file's region, the bounds (auto) or a box;
# truth and score refuse it; vdsh-view's default lights by the image they
# draw (file = grown = the recorded box, auto another; skipped without GL).
if(Python3_Interpreter_FOUND AND TARGET vb_frames AND TARGET vdsh-view)
  add_test(NAME light_region_readers
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_light_region_readers.py
                   $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-frames> $<TARGET_FILE:vdsh-view>
                   ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_BINARY_DIR}/light_region_readers)
endif()

# scripts/frames_gap at its smallest (test_frames_gap.py): validation room
# 3 at --max-edge 1, 64 x 48 C frames, order 2, with a shadow variant; the
# squared error's split by pixel class adds up, and matches vdsh-frames
# score's RMSE; shadow's recall is 1.00 against itself; val-spider runs
# where assimp's models are installed. No GL.
if(Python3_Interpreter_FOUND AND TARGET vb_frames)
  add_test(NAME frames_gap_script
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_frames_gap.py
                   ${PROJECT_SOURCE_DIR}/scripts ${PROJECT_BINARY_DIR})
endif()

# scripts/view_pools at its smallest (test_view_pools.py): validation room
# 3 at --max-edge 1, 64 x 48 C frames, order 2, two pools of two views; the
# default's bake again differs by 0 with the interval [0, 0], --method
# shadow's differences and t interval over pools are recomputed from the
# JSON; bad arguments are errors naming them. No GL.
if(Python3_Interpreter_FOUND AND TARGET vb_frames)
  add_test(NAME view_pools_script
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_view_pools.py
                   ${PROJECT_SOURCE_DIR}/scripts ${PROJECT_BINARY_DIR})
endif()

# scripts/score_bootstrap (test_score_bootstrap.py): on made-up score
# files, the ratio of two vdsh-frames scores is the pooled one, its
# bootstrap interval over views holds it (0 and [0, 0] for a file against
# itself); files of other views, truth or masks, a scene row the views do
# not pool to, no score JSON or a missing file refused with the file
# named. No bake.
if(Python3_Interpreter_FOUND)
  add_test(NAME scripts_score_bootstrap
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_score_bootstrap.py
                   ${PROJECT_SOURCE_DIR}/scripts ${CMAKE_CURRENT_BINARY_DIR}/scripts_score_bootstrap)
endif()

# scripts/false_probe at its smallest (test_false_probe.py): on
# frames_gap --keep's run of validation room 3 (--max-edge 1, 64 x 48,
# order 2), a default frame with false shadow is probed; its numpy path
# redraws every false pixel of the C frame in false shadow, the split by
# false vertices adds up, a missing run is an error naming the file.
# About 20 seconds. No GL.
if(Python3_Interpreter_FOUND AND TARGET vb_frames)
  add_test(NAME false_probe_script
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_false_probe.py
                   ${PROJECT_SOURCE_DIR}/scripts ${PROJECT_BINARY_DIR}
                   ${CMAKE_CURRENT_BINARY_DIR}/false_probe_script)
endif()

# scripts/mottling at its smallest (test_mottling.py): validation room 3
# at --max-edge 1, 64 x 48 C frames, order 3; a twin bake's row is the
# same with noise 0, the figures in range, a test scene refused. No GL.
if(Python3_Interpreter_FOUND AND TARGET vb_frames)
  add_test(NAME mottling_script
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_mottling.py
                   ${PROJECT_SOURCE_DIR}/scripts ${PROJECT_BINARY_DIR}
                   ${CMAKE_CURRENT_BINARY_DIR}/mottling_script)
endif()

# scripts/order_curve's encoding axis (issue 29; test_order_curve.py):
# validation room 3 at --max-edge 0.6, 100 rays, orders 3 and 7 in s8s6
# and cpca 4,12,4, and an adaptive order (cap 7) in each, C frames at 128
# x 96: a row per order and encoding with frame scores; bytes per vertex
# are the spec's records (cpca: plus its model over the receivers; its
# adaptive order a fixed stream of the cap); an unknown encoding, a
# --scenes word that is no scene and a run with every mesh missing are
# errors; --frames on an unlisted scene makes its view set. No GL.
if(Python3_Interpreter_FOUND AND TARGET vb_frames)
  add_test(NAME order_curve_script
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_order_curve.py
                   ${PROJECT_SOURCE_DIR}/scripts ${PROJECT_BINARY_DIR})
endif()

# scripts/speed_vs_error at its smallest (test_speed_vs_error.py): --resume
# reuses only evaluations of the same arguments; no scene to sweep is an
# error that leaves --doc as it was.
if(Python3_EXECUTABLE AND TARGET vb_frames)
  add_test(NAME speed_vs_error_script
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/test_speed_vs_error.py
                   ${PROJECT_SOURCE_DIR}/scripts ${PROJECT_BINARY_DIR})
endif()

# scripts/pareto --quick: the speed-against-error report at its smallest
# (the room at --max-edge 1, the 3-view test set, a few modes, 1 and 3
# lights): its CSV and JSON rows complete and finite, the GL counts of
# vdsh-view --bench-counts against the mesh (one lighting pass: one
# primitive per triangle; a cube-map frame with one light: seven draws of
# the mesh), and its Pareto front on a synthetic input. 77 without GL.
# The full report (scripts/pareto) is a benchmark, not a test.
if(Python3_Interpreter_FOUND AND TARGET vb_frames AND TARGET vdsh-view)
  add_test(NAME pareto_quick
           COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/scripts/pareto --quick
                   --build ${PROJECT_BINARY_DIR} --work ${CMAKE_CURRENT_BINARY_DIR}/pareto_quick)
  set_tests_properties(pareto_quick PROPERTIES SKIP_RETURN_CODE 77)
endif()
