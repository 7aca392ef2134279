# Copies the shared libraries that MODULE needs, other than the system's own
# (glibc's, libstdc++, libgcc_s), into LIBS_DIR and points each copy's RUNPATH at
# $ORIGIN, so the module and its libraries load from wherever the add-on is
# unpacked, as auditwheel grafts a wheel's libraries. Run in script mode:
#   cmake -DMODULE=... -DLIBS_DIR=... -DPATCHELF=... -P BundleLibraries.cmake
# The allowed set is the one tests/native/test_package.py holds the package to.
set(SYSTEM_LIBRARIES
  "^(.*/)?ld-linux-x86-64\\.so\\.2$" "^(.*/)?lib(c|m|dl|rt|pthread)\\.so\\.[0-9]+$"
  "^(.*/)?libstdc\\+\\+\\.so\\.6$" "^(.*/)?libgcc_s\\.so\\.1$")

file(REMOVE_RECURSE ${LIBS_DIR})  # so that every dependency resolves to its system copy
file(GET_RUNTIME_DEPENDENCIES
  LIBRARIES ${MODULE}
  RESOLVED_DEPENDENCIES_VAR resolved
  UNRESOLVED_DEPENDENCIES_VAR unresolved
  POST_EXCLUDE_REGEXES ${SYSTEM_LIBRARIES})
if(unresolved)
  message(FATAL_ERROR "${MODULE} needs libraries that were not found: ${unresolved}")
endif()
file(MAKE_DIRECTORY ${LIBS_DIR})
foreach(library IN LISTS resolved)
  # Resolved by soname (e.g. libtbb.so.12, a symlink): keep that name, copy the file.
  get_filename_component(soname ${library} NAME)
  get_filename_component(real ${library} REALPATH)
  file(COPY_FILE ${real} ${LIBS_DIR}/${soname})
  execute_process(COMMAND ${PATCHELF} --set-rpath "$ORIGIN" ${LIBS_DIR}/${soname}
                  RESULT_VARIABLE failed)
  if(failed)
    message(FATAL_ERROR "patchelf could not set the RUNPATH of ${LIBS_DIR}/${soname}")
  endif()
  message(STATUS "Bundled ${soname} (from ${real})")
endforeach()
