# The solver's C++ unit tests (native/core/*/*_test.cpp) built for the portable
# build's target, against the same radiosity_portable_core as the modules: for the
# platforms tools/cross_build.py builds (RADIOSITY_UNIT_TESTS=ON), where the
# Windows program runs under Wine and the macOS ones are only linked
# (tests/platforms). GoogleTest from Debian's source package (libgtest-dev's
# /usr/src/googletest), compiled with the same toolchain.
set(RADIOSITY_GTEST_SOURCE /usr/src/googletest/googletest CACHE PATH "GoogleTest's source")
if(NOT EXISTS ${RADIOSITY_GTEST_SOURCE}/CMakeLists.txt)
  message(FATAL_ERROR "No GoogleTest source in ${RADIOSITY_GTEST_SOURCE}: install libgtest-dev (make deps)")
endif()
set(gtest_force_shared_crt ON CACHE BOOL "" FORCE)
set(gtest_disable_pthreads ON CACHE BOOL "" FORCE)   # its own threads are not needed: no death tests
add_subdirectory(${RADIOSITY_GTEST_SOURCE} ${CMAKE_BINARY_DIR}/googletest EXCLUDE_FROM_ALL)
# GoogleTest 1.12's gtest-internal.h uses FLT_MAX and DBL_MAX, which zig's macOS
# headers leave undefined there (the macOS unit tests did not compile; including
# <cfloat> first instead left INFINITY undefined in libc++'s <random>): defined as
# the compiler's own values, as <float.h> defines them, for whatever includes gtest.h.
if(CMAKE_SYSTEM_NAME STREQUAL "Darwin")
  target_compile_definitions(gtest PUBLIC FLT_MAX=__FLT_MAX__ DBL_MAX=__DBL_MAX__)
endif()
file(GLOB TEST_SOURCES CONFIGURE_DEPENDS ${NATIVE}/core/*/*_test.cpp)
add_executable(radiosity_tests ${TEST_SOURCES})
target_include_directories(radiosity_tests PRIVATE ${NATIVE})
target_link_libraries(radiosity_tests PRIVATE radiosity_portable_core gtest_main)
target_link_options(radiosity_tests PRIVATE -s)
set_target_properties(radiosity_tests PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/unit-tests)
