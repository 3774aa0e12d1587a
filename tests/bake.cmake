add_executable(test_bake test_bake.c)
target_link_libraries(test_bake PRIVATE vb_core)
add_test(NAME bake_matches_analytic_truth COMMAND test_bake)

add_test(NAME bake_cli_deterministic_no_partial_output
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_bake_cli.sh
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-info> ${VDSH_SHARED_SCENES})

# No receiver ray starts on a surface (Embree promises nothing at t = 0):
# vb_ray_origins' origins in an unwelded L corner, a panel on a floor, a
# flat quad and a cube on a floor; the control (normal offset only) does
# start rays on the adjacent faces.
add_executable(test_origins_on_surface test_origins_on_surface.c)
target_link_libraries(test_origins_on_surface PRIVATE vb_core m)
add_test(NAME bake_origins_off_surfaces COMMAND test_origins_on_surface)

add_executable(test_hard test_hard.c)
target_link_libraries(test_hard PRIVATE vb_core)
add_test(NAME bake_hard_cases COMMAND test_hard)

add_executable(test_fit test_fit.c)
target_link_libraries(test_fit PRIVATE vb_core)
add_test(NAME bake_fit_reproduces_exact_functions COMMAND test_fit)
add_executable(test_decision test_decision.c)
target_link_libraries(test_decision PRIVATE vb_core)
add_test(NAME bake_decision_fit COMMAND test_decision)

# --quantity auto: deterministic, and it picks the better quantity per order.
find_package(Python3 COMPONENTS Interpreter QUIET)
if(Python3_Interpreter_FOUND)
  add_test(NAME bake_quantity_auto
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_bake_auto.py
                   $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-eval> $<TARGET_FILE:vdsh-info>
                   ${CMAKE_CURRENT_BINARY_DIR}/bake_auto)
endif()

# Two bakes of one scene compared stream by stream (the cross-ISA tests).
add_executable(vdsh_compare vdsh_compare.c)
target_link_libraries(vdsh_compare PRIVATE vdsh_format m)

# Every Embree kernel set the CPU supports (tests/with_each_isa.sh): the
# hard cases pass with each, and bakes agree across them. Not in the
# sanitizer build: Embree is not instrumented and the project's code is
# the same under every kernel set, so there they would repeat
# bake_hard_cases four times (the plain build runs them).
if(NOT VDSH_SANITIZE)
  add_test(NAME bake_hard_cases_isa
           COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/with_each_isa.sh $<TARGET_FILE:vdsh-bake>
                   $<TARGET_FILE:test_hard>)
  add_test(NAME bake_isa_agree
           COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_isa_agree.sh $<TARGET_FILE:vdsh-bake>
                   $<TARGET_FILE:vdsh-info> $<TARGET_FILE:vdsh_compare>
                   ${CMAKE_CURRENT_SOURCE_DIR}/with_each_isa.sh ${VDSH_SHARED_SCENES})
  # The same with --crease 60 (Sponza splits 10,706 vertices at creases):
  # corners' origins (origins.h, "Corners"). Sponza's five bakes only, about
  # two minutes on two cores: labelled slow; skipped without Sponza.
  add_test(NAME bake_isa_agree_crease
           COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_isa_agree.sh $<TARGET_FILE:vdsh-bake>
                   $<TARGET_FILE:vdsh-info> $<TARGET_FILE:vdsh_compare>
                   ${CMAKE_CURRENT_SOURCE_DIR}/with_each_isa.sh ${VDSH_SHARED_SCENES})
  set_tests_properties(bake_isa_agree_crease PROPERTIES ENVIRONMENT "VDSH_ISA_EXTRA=--crease 60"
                       SKIP_RETURN_CODE 77 LABELS slow)
  # The bake's discrete decisions across kernel sets: the light region of
  # closed objects either side of its rule, the calibration's guard, cpca
  # streams and the encoder's bytes (test_isa_decisions.sh).
  add_test(NAME bake_isa_decisions
           COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_isa_decisions.sh $<TARGET_FILE:vdsh-bake>
                   $<TARGET_FILE:vdsh-info> $<TARGET_FILE:vdsh_compare> $<TARGET_FILE:vdsh-merge>
                   $<TARGET_FILE:light_region_probe> ${CMAKE_CURRENT_SOURCE_DIR}/with_each_isa.sh
                   ${VDSH_SHARED_SCENES})
endif()

# The same bytes on any x86-64 CPU: glibc's libm paths of a CPU without
# AVX2 and FMA, and (VDSH_REFERENCE_BAKE: another build's vdsh-bake, set by
# scripts/test for the sanitizer build, which has no target_clones) the
# baseline clones against the AVX2 ones.
set(VDSH_REFERENCE_BAKE "" CACHE FILEPATH
    "Another build's vdsh-bake whose bytes bake_same_bytes_any_cpu compares")
add_executable(libm_probe libm_probe.c)
target_link_libraries(libm_probe PRIVATE m)
add_test(NAME bake_same_bytes_any_cpu
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_same_bytes_any_cpu.sh
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:libm_probe> ${VDSH_SHARED_SCENES}
                 ${VDSH_REFERENCE_BAKE})
set_tests_properties(bake_same_bytes_any_cpu PROPERTIES TIMEOUT 900)

# Sharded bakes (vdsh-bake --shard I/N, vdsh-merge): byte for byte.
add_test(NAME bake_shard
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_shard.sh
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-merge> $<TARGET_FILE:vdsh-info>
                 $<TARGET_FILE:vdsh-eval>)
# Parts of one .gltf bake whose SRCS record the source with and without
# its external buffers (a baker before 2026-11-30): merged when both match
# the file, into the whole bake's bytes; refused when they do not.
add_test(NAME bake_merge_source_record
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_merge_source_record.py
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-merge>
                 ${CMAKE_CURRENT_BINARY_DIR}/merge_source_record)
# vdsh-bake --encoding cpca (issue 29): 1 and 2 threads, 1, 3 and 7 shards
# merged give the same bytes; decode error against the f32 bake bounded;
# bad --cpca settings and mixed parts refused.
add_test(NAME bake_cpca
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_cpca_bake.sh
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-merge> $<TARGET_FILE:vdsh-info>
                 ${PROJECT_SOURCE_DIR})
# vdsh-bake --cpca auto[:BYTES] (issue 29): within the budget, the same
# bytes at 1 and 2 threads and 3 shards merged; bad budgets refused.
add_test(NAME bake_cpca_auto
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_cpca_auto.sh
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-merge> $<TARGET_FILE:vdsh-info>
                 ${PROJECT_SOURCE_DIR})
# The GNU parallel recipe (scripts/bake-parallel), with Debian's parallel:
# byte for byte, a name with quotes, a rerun bakes the missing parts only.
add_test(NAME bake_shard_parallel
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_shard_parallel.sh
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-merge> ${PROJECT_SOURCE_DIR}/scripts)
set_tests_properties(bake_shard_parallel PROPERTIES SKIP_RETURN_CODE 77)
# The Slurm recipe (scripts/bake-slurm) on a real one-node Slurm it starts
# as root (skipped, 77, otherwise): byte for byte, bad arguments submit
# nothing, a failed shard cancels the merge job.
add_test(NAME bake_shard_slurm
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_shard_slurm.sh
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-merge> ${PROJECT_SOURCE_DIR}/scripts)
set_tests_properties(bake_shard_slurm PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 300)

# Adaptive receivers (bake/lib/adaptive.h): promises and hard cases, under
# every Embree ISA (in the sanitizer build once, natively, as above).
add_executable(test_adaptive test_adaptive.c)
target_link_libraries(test_adaptive PRIVATE vb_core)
if(VDSH_SANITIZE)
  add_test(NAME bake_adaptive COMMAND test_adaptive)
else()
  add_test(NAME bake_adaptive
           COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/with_each_isa.sh $<TARGET_FILE:vdsh-bake>
                   $<TARGET_FILE:test_adaptive>)
endif()

# Refinement of long thin triangles to a maximum edge: receivers near
# area / edge^2, bounded aspect ratio (issue 26).
add_executable(test_refine_shape test_refine_shape.c)
target_link_libraries(test_refine_shape PRIVATE vb_core)
add_test(NAME bake_refine_shape COMMAND $<TARGET_FILE:test_refine_shape>)
set_tests_properties(bake_refine_shape PROPERTIES TIMEOUT 60)

# Origin repair skips receivers on zero-area triangles only (drawn nowhere):
# counted, no probe rays, the other receivers' repair unchanged (issue 26).
add_test(NAME bake_origins_zero_area
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_origins_zero_area.sh
                 $<TARGET_FILE:vdsh-bake>)
set_tests_properties(bake_origins_zero_area PROPERTIES TIMEOUT 60)

# The s8, s8s6 scales are over the drawn receivers only (receivers whose
# triangles all have no area do not set them), in the whole bake and in
# vdsh-merge (byte for byte, 1 and 3 shards).
add_test(NAME bake_quant_drawn
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_quant_drawn.sh
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-merge> $<TARGET_FILE:vdsh-info>
                 ${PROJECT_SOURCE_DIR}/python)
set_tests_properties(bake_quant_drawn PROPERTIES TIMEOUT 60)

# No FMA instruction in the programs (tests/test_no_fma.sh).
add_test(NAME build_no_fma
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_no_fma.sh $<TARGET_FILE:vdsh-bake>
                 $<TARGET_FILE:vdsh-merge> $<TARGET_FILE:vdsh-eval> $<TARGET_FILE:vdsh-frames>
                 $<TARGET_FILE:vdsh-info>)
set_tests_properties(build_no_fma PROPERTIES SKIP_RETURN_CODE 77)

# The light placement's decisions (vdsh_light.h) printed for comparison
# across Embree's kernel sets (test_isa_decisions.sh).
add_executable(light_region_probe light_region_probe.c)
target_link_libraries(light_region_probe PRIVATE vb_core)
# Counts for telling objects from rooms (docs/ACCURACY.md, "Objects or
# rooms"): a measuring tool, no test.
add_executable(object_rule_probe object_rule_probe.c)
target_link_libraries(object_rule_probe PRIVATE vb_core)
# vdsh-view's light pool (vr_scene_place_pool: the grid tracer's
# vdsh_view_free_space) and the bake side's placement (vb_scene_place_lights:
# Embree's probes, measured in double) with the same seed, one rule
# (formats/vdsh_light.c vdsh_light_place, limit included): 64 positions
# equal bit for bit, in a room (the bounds), around a closed cube and over
# a flat quad (the grown region); 32 in a scene whose free space is small
# pockets.
add_executable(light_pool_agree light_pool_agree.c)
target_include_directories(light_pool_agree PRIVATE ${PROJECT_SOURCE_DIR}/runtime)
target_link_libraries(light_pool_agree PRIVATE vb_core vr vdsh_format m)
add_test(NAME bake_light_pool_agree COMMAND sh -c [=[
bake=$1; probe=$2; data=$3; d=$4; fail=0
rm -rf "$d"; mkdir -p "$d"
printf 'v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 3 4 8 7\nf 2 3 7 6\nf 1 5 8 4\n' > "$d/cube.obj"
for s in "$d/cube.obj" "$data/room_box.obj"; do
  n=$(basename "$s" .obj)
  "$bake" "$s" --rays 16 --cube-size 0 -q -o "$d/$n.vdsh" || exit 1
  "$probe" "$d/$n.vdsh" 64 || fail=1
done
# A flat quad: every candidate of its bounds lies on its plane; the
# bake's probes (Embree, no hit promised at the ray's start) saw no face
# there and placed all 64 lights on the quad, where the runtime's found
# them not free and grew the region (0 of 64 equal).
printf 'v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 4 3\nf 1 3 2\n' > "$d/quad.obj"
"$bake" "$d/quad.obj" --method lsq --rays 16 --cube-size 0 -q -o "$d/quad.vdsh" || exit 1
"$probe" "$d/quad.vdsh" 64 || fail=1
# Free space in small pockets (about 1 candidate in 900 free, the region
# the bounds): the runtime gave up at 256 candidates per light and placed
# 9 of 32 where the bake placed 32.
"$probe" --pockets "$d/pockets.obj" 0.025 || exit 1
"$bake" "$d/pockets.obj" --method lsq --max-edge 10 --rays 16 --cube-size 0 -q -o "$d/pockets.vdsh" || exit 1
"$probe" "$d/pockets.vdsh" 32 || fail=1
exit $fail
]=] sh $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:light_pool_agree> ${CMAKE_CURRENT_SOURCE_DIR}/data
    ${CMAKE_CURRENT_BINARY_DIR}/light_pool_agree_tmp)

# A light pool placed by the project's rule, written as f32 (the pool of
# vdsh-bake --cpca ...,light:A, for scripts/cpca_study's `l` settings).
add_executable(light_pool_tool light_pool_tool.c)
target_link_libraries(light_pool_tool PRIVATE vb_core)
# The cpca encoder's light-density metric (--cpca ...,light:A): light:0
# the uniform metric, light:1 and 0.5 valid other fits, the default's
# bytes, bad values refused; parts carry the pool (lpol), mismatched or
# damaged pools refused by the merge and the readers; light_pool_tool's
# bake:1 is the part's pool; margin:S and starts:N (starts keeps the start
# with the fewest pool decisions differing: cpca_kchoice_tool --score),
# recorded in parts, merged byte-identical; the study knobs.
add_test(NAME bake_cpca_lightmix
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_cpca_lightmix.py
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-merge> $<TARGET_FILE:vdsh-info>
                 ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_BINARY_DIR}/bake_cpca_lightmix
                 $<TARGET_FILE:light_pool_tool> $<TARGET_FILE:cpca_kchoice_tool>)

# scripts/cpca_study's cache in --work (tests/test_cpca_study_cache.py):
# bakes, truth and light pools named by what made them (mesh and its
# bytes, edge, method, --rays; the view set's bytes; --light-pool,
# --light-seed), not by scene and fit alone: a rerun with other settings
# reused the first run's bakes. The streams' frame scores named by the
# view set too; --views-dir DIR (DIR/NAME.views.json) in --help, a
# missing folder or view set refused before any bake.
add_test(NAME scripts_cpca_study_cache
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_cpca_study_cache.py
                 ${PROJECT_SOURCE_DIR}/scripts ${CMAKE_CURRENT_BINARY_DIR}/scripts_cpca_study_cache)

# -o /dev/null, /dev/stdout or a FIFO: the file in place, byte for byte,
# and no basis cubemaps beside it (they went into /dev), unless
# --cubemap-dir; --sdf with such an OUT refused; vdsh-merge the same.
add_test(NAME bake_stream_output
         COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test_bake_stream_output.sh
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-merge>)
set_tests_properties(bake_stream_output PROPERTIES TIMEOUT 60)
# vdsh-bake --up-axis: the cube on its floor written z-up (and -z, x, -x,
# -y up) bakes to the y-up bake's receivers and coefficients; the file
# records the axis (vdsh-info, python -m vdsh info); vdsh-eval turns the
# sources the same way (the y-up figures); --up-axis y: the same bytes.
add_test(NAME bake_up_axis
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_up_axis.py
                 $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-info> $<TARGET_FILE:vdsh-eval>
                 $<TARGET_FILE:vdsh-frames> ${PROJECT_SOURCE_DIR}
                 ${CMAKE_CURRENT_BINARY_DIR}/up_axis)
