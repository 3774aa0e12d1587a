# The installed package: `cmake --install BUILD [--prefix DIR]` puts the
# formats and runtime libraries (static, or shared with
# -DBUILD_SHARED_LIBS=ON), their public headers (include/vdsh/: both
# include/vdsh and include are include paths, so <vdsh/vdsh.h>, the
# documented form, and <vdsh.h> both work), the
# programs, a CMake config package and pkg-config files in place:
#   find_package(vdsh CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE vdsh::formats)   # .vdsh reader/writer
#   target_link_libraries(app PRIVATE vdsh::runtime)   # GL runtime (vr.h)
#   target_link_libraries(app PRIVATE vdsh::context)   # EGL/GLFW contexts
#   pkg-config --cflags --libs vdsh-formats  (or vdsh-runtime, vdsh-context)
# Shared builds install with RUNPATH $ORIGIN/../lib (top CMakeLists.txt).
# The shader files (runtime/shaders/: for other engines, README.md there)
# go to share/vdsh/shaders/, the web viewer and the three.js module
# (runtime/web/) to share/vdsh/web/: they find the shaders at ../shaders/
# as in the source tree.
# tests/install.cmake builds and runs a consumer against an installed tree.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

install(TARGETS vdsh_format vr vr_context EXPORT vdshTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        PUBLIC_HEADER DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/vdsh)
install(EXPORT vdshTargets NAMESPACE vdsh:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/vdsh)
file(GLOB VDSH_SHADER_FILES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/runtime/shaders/*.glsl)
install(FILES ${VDSH_SHADER_FILES} ${PROJECT_SOURCE_DIR}/runtime/shaders/README.md
        DESTINATION ${CMAKE_INSTALL_DATADIR}/vdsh/shaders)
install(FILES ${PROJECT_SOURCE_DIR}/runtime/web/index.html ${PROJECT_SOURCE_DIR}/runtime/web/vdsh_web.js
              ${PROJECT_SOURCE_DIR}/runtime/web/vdsh_core.js ${PROJECT_SOURCE_DIR}/runtime/web/three.html
              ${PROJECT_SOURCE_DIR}/runtime/web/vdsh_three.js
        DESTINATION ${CMAKE_INSTALL_DATADIR}/vdsh/web)

# What the package config looks up for its consumers: the public link
# dependencies always; the private ones (zlib, Threads, meshoptimizer, GLFW) only
# for static libraries, whose link interface names them. VDSH_HAVE_GLFW
# comes from runtime/CMakeLists.txt; both are TRUE or FALSE, never empty.
if(VDSH_HAVE_GLFW)
  set(VDSH_CONFIG_GLFW TRUE)
else()
  set(VDSH_CONFIG_GLFW FALSE)
endif()
if(BUILD_SHARED_LIBS)
  set(VDSH_CONFIG_STATIC FALSE)
else()
  set(VDSH_CONFIG_STATIC TRUE)
endif()
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/vdshConfig.cmake.in
                              ${CMAKE_CURRENT_BINARY_DIR}/vdshConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/vdsh)
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/vdshConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/vdshConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/vdshConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/vdsh)

# pkg-config: relocatable (prefix from the .pc file's own place, lib/pkgconfig);
# static builds list their dependencies in Libs.private.
file(RELATIVE_PATH VDSH_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
if(VDSH_HAVE_GLFW)
  set(VDSH_PC_CONTEXT_PRIVATE "egl glfw3")
else()
  set(VDSH_PC_CONTEXT_PRIVATE "egl")
endif()
foreach(pc vdsh-formats vdsh-runtime vdsh-context)
  configure_file(${CMAKE_CURRENT_LIST_DIR}/${pc}.pc.in ${CMAKE_CURRENT_BINARY_DIR}/${pc}.pc @ONLY)
  install(FILES ${CMAKE_CURRENT_BINARY_DIR}/${pc}.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endforeach()
