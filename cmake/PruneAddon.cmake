# Removes Python files from the assembled add-on that no longer have a source in
# addon/ (a renamed, moved or deleted module would otherwise stay in an existing
# build folder and be packaged), and the caches and folders they leave. Run by
# the `addon` target:
#   cmake -DADDON_DIR=... -DKEEP="a.py;ui/b.py" -P PruneAddon.cmake
cmake_minimum_required(VERSION 3.16)
file(GLOB_RECURSE _present RELATIVE ${ADDON_DIR} ${ADDON_DIR}/*.py)
foreach(name IN LISTS _present)
  if(NOT name IN_LIST KEEP)
    message(STATUS "Removing ${name} from the add-on: no source in addon/")
    file(REMOVE ${ADDON_DIR}/${name})
  endif()
endforeach()
# Sub-package folders left with nothing but Python's caches (or nothing).
file(GLOB _folders LIST_DIRECTORIES true RELATIVE ${ADDON_DIR} ${ADDON_DIR}/*)
foreach(folder IN LISTS _folders)
  if(IS_DIRECTORY ${ADDON_DIR}/${folder} AND NOT folder STREQUAL "__pycache__")
    file(GLOB_RECURSE _inside RELATIVE ${ADDON_DIR}/${folder} ${ADDON_DIR}/${folder}/*)
    list(FILTER _inside EXCLUDE REGEX "(^|/)__pycache__/")
    if(NOT _inside)
      message(STATUS "Removing ${folder}/ from the add-on: no source in addon/")
      file(REMOVE_RECURSE ${ADDON_DIR}/${folder})
    endif()
  endif()
endforeach()
