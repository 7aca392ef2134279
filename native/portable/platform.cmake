# What a `_radiosity` module of native/portable takes from its target platform:
# the file name Python imports it by, what it exports, what it links. Included by
# native/portable/CMakeLists.txt; the platforms other than Linux are cross-built
# with zig by tools/cross_build.py (their toolchains: tools/cross_deps.py).
#   radiosity_platform_core(<target>)           # the solver's library: what every source needs
#   radiosity_platform_module(<target> <tag>)   # tag: 310, 311, 313
# - Linux (manylinux_2_28): _radiosity.cpython-3XY-x86_64-linux-gnu.so, only
#   PyInit__radiosity exported (exports.map), Python's symbols left to the process.
# - Windows: _radiosity.cp3XY-win_amd64.pyd, linked against python3XY.dll through the
#   import library of that CPython (<deps>/libs/python3XY.lib, tools/cross_build.py);
#   libc++ is in the module, the C runtime is the Universal CRT (api-ms-win-crt-*).
# - macOS: _radiosity.cpython-3XY-darwin.so, a Mach-O dylib whose Python symbols
#   are looked up when it loads (-undefined dynamic_lookup); libc++ is in the
#   module, so it needs libSystem only.
# Every platform: no debug information (-s; the Linux module is 3 MB instead of 40).

# Windows: <windows.h> without its min/max macros (std::numeric_limits<T>::max()),
# and without near/far (windows_prelude.h).
function(radiosity_platform_core target)
  if(CMAKE_SYSTEM_NAME STREQUAL "Windows")
    target_compile_definitions(${target} PUBLIC NOMINMAX WIN32_LEAN_AND_MEAN)
    target_compile_options(${target} PUBLIC -include ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/windows_prelude.h)
  endif()
endfunction()

function(radiosity_platform_module target tag)
  set_target_properties(${target} PROPERTIES OUTPUT_NAME _radiosity PREFIX "")
  target_link_options(${target} PRIVATE -s)
  if(CMAKE_SYSTEM_NAME STREQUAL "Windows")
    set_target_properties(${target} PROPERTIES SUFFIX ".cp${tag}-win_amd64.pyd")
    target_link_libraries(${target} PRIVATE ${RADIOSITY_DEPS}/libs/python${tag}.lib)
  elseif(CMAKE_SYSTEM_NAME STREQUAL "Darwin")
    set_target_properties(${target} PROPERTIES SUFFIX ".cpython-${tag}-darwin.so")
    # zig's Mach-O linker makes no bundles (it ignores CMake's -bundle): a dylib, which
    # Python loads the same way; nor does it take an export list: hidden visibility
    # leaves PyInit__radiosity and libc++'s replaceable operator new and delete.
    target_link_options(${target} PRIVATE -shared -undefined dynamic_lookup)
  else()
    set_target_properties(${target} PROPERTIES SUFFIX ".cpython-${tag}-x86_64-linux-gnu.so")
    # The static libraries' symbols stay inside: the module exports PyInit__radiosity alone.
    target_link_options(${target} PRIVATE -Wl,--version-script=${CMAKE_CURRENT_SOURCE_DIR}/exports.map)
    set_property(TARGET ${target} APPEND PROPERTY LINK_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/exports.map)
  endif()
endfunction()
