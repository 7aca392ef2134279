# Removes Python files from the assembled add-on that no longer have a source in
# addon/ (a renamed or deleted module would otherwise stay in an existing build
# folder and be packaged). Run by the `addon` target:
#   cmake -DADDON_DIR=... -DKEEP="a.py;b.py" -P PruneAddon.cmake
cmake_minimum_required(VERSION 3.16)
file(GLOB _present RELATIVE ${ADDON_DIR} ${ADDON_DIR}/*.py)
foreach(name IN LISTS _present)
  if(NOT name IN_LIST KEEP)
    message(STATUS "Removing ${name} from the add-on: no source in addon/")
    file(REMOVE ${ADDON_DIR}/${name})
  endif()
endforeach()
