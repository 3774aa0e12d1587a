# Cube-face conventions (formats/vdsh_cube.c) and SH basis cubemap files
# (bake/lib/cubemap_exr.c). Run with: ctest -R cube
find_package(OpenEXR REQUIRED)

set(VDSH_CUBE_TEST_DIR ${CMAKE_CURRENT_BINARY_DIR}/cube_tmp)

# The C test also uses OpenEXRCore directly, to make files our writer
# refuses to write (no envmap, wrong shape, float or uint channels, NaN).
add_executable(test_cube test_cube.c)
target_link_libraries(test_cube PRIVATE vb_cubemap vdsh_format
                      OpenEXR::OpenEXRCore m)

add_test(NAME cube_conventions COMMAND test_cube conventions)
add_test(NAME cube_files COMMAND test_cube files ${VDSH_CUBE_TEST_DIR}/files)
add_test(NAME cube_errors COMMAND test_cube errors ${VDSH_CUBE_TEST_DIR}/errors)

# What `exrheader` (Debian package openexr) says about a written file.
add_test(NAME cube_exrheader
         COMMAND sh -c [=[
command -v exrheader >/dev/null 2>&1 || { echo "exrheader not found"; exit 77; }
set -e
mkdir -p "$1"
"$2" write "$1/basis.exr" 8
out=$(exrheader "$1/basis.exr")
echo "$out"
echo "$out" | grep -q "envmap (type envmap): cube-face map"
echo "$out" | grep -q "dataWindow (type box2i): (0 0) - (7 47)"
echo "$out" | grep -q "A, 16-bit floating-point"
]=] sh ${VDSH_CUBE_TEST_DIR}/exrheader $<TARGET_FILE:test_cube>)
set_tests_properties(cube_exrheader PROPERTIES SKIP_RETURN_CODE 77)

# Against OpenEXR's own C++ implementation: CubeMap::faceAndPixelPosition,
# pixelPosition and direction, and the C++ file reader and writer.
add_executable(test_cube_openexr test_cube_openexr.cpp)
target_link_libraries(test_cube_openexr PRIVATE vb_cubemap vdsh_format
                      OpenEXR::OpenEXR)
add_test(NAME cube_openexr
         COMMAND test_cube_openexr ${VDSH_CUBE_TEST_DIR}/openexr)
