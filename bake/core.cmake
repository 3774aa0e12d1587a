# The bake core and the command-line tools (included from bake/CMakeLists.txt).
add_library(vb_core STATIC lib/sampling.c lib/scene.c lib/origins.c lib/bake.c lib/stream.c
            lib/fit.c lib/decision.c lib/method.c lib/parallel.c
            lib/adaptive.c lib/sdf.c)
target_link_libraries(vb_core PUBLIC vb_mesh vdsh_format embree Threads::Threads m)
# A whole bake as one straight line (job.h): load, refine, bake, fill the
# file, write it with its basis cubemaps.
add_library(vb_job STATIC lib/job.c)
target_link_libraries(vb_job PUBLIC vb_core vb_cubemap)
add_executable(vdsh-bake tools/vdsh_bake.c)
target_link_libraries(vdsh-bake PRIVATE vb_job vt_tools)
install(TARGETS vdsh-bake RUNTIME DESTINATION bin)
# Join a sharded bake's parts (vdsh-bake --shard I/N) byte for byte.
add_executable(vdsh-merge tools/vdsh_merge.c)
target_link_libraries(vdsh-merge PRIVATE vb_job vt_tools)
install(TARGETS vdsh-merge RUNTIME DESTINATION bin)
