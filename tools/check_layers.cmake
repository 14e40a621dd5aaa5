# Checks that the library's include graph goes one way, down the layers of docs/ARCHITECTURE.md.
# A layer is a folder, the same under include/kdl_space/ and src/:
#   0 spatial (and src/detail/)   1 multibody   2 algorithm   3 impact   4 simulation
#   5 parsers (urdf/, scenario/)  6 operation   7 study       8 planning
#   9 report (the JSON of the results, the output files: its own target over the library)
#   (tools/, python/: anything)
# A file of the library may include only files of its own folder's layer or lower ones, named by
# their folder ("kdl_space/impact/capture.hpp", "multibody/model_rules.hpp", "detail/lanes.hpp");
# no header stands at include/kdl_space/<name>.hpp (the flat paths of an earlier release are gone). A folder with no layer fails the check: give
# it one here and in docs/ARCHITECTURE.md. Also refuses a library file of more than 450 lines.
# Run: cmake -DSOURCE_DIR=<repo> -P tools/check_layers.cmake (ctest: layers).
cmake_minimum_required(VERSION 3.16)

set(kdl_space_layers spatial detail multibody algorithm impact simulation parsers operation study planning report)
set(kdl_space_ranks 0 0 1 2 3 4 5 6 7 8 9)

# The rank of a folder name (the first component of a path below include/kdl_space/ or src/).
function(rank_of folder out)
  list(FIND kdl_space_layers "${folder}" i)
  if(i LESS 0)
    set(${out} "" PARENT_SCOPE)
  else()
    list(GET kdl_space_ranks ${i} rank)
    set(${out} ${rank} PARENT_SCOPE)
  endif()
endfunction()

set(problems "")
file(GLOB flat RELATIVE "${SOURCE_DIR}" "${SOURCE_DIR}/include/kdl_space/*.hpp")
foreach(rel IN LISTS flat)
  string(APPEND problems "${rel}: a header outside the layers' folders: move it into one (include/kdl_space/<layer>/)\n")
endforeach()
file(GLOB_RECURSE files RELATIVE "${SOURCE_DIR}" "${SOURCE_DIR}/include/kdl_space/*/*.hpp" "${SOURCE_DIR}/src/*.hpp"
     "${SOURCE_DIR}/src/*.cpp")
foreach(rel IN LISTS files)
  string(REGEX REPLACE "^(include/kdl_space|src)/" "" inside "${rel}")
  string(REGEX REPLACE "/.*" "" folder "${inside}")
  if(inside STREQUAL folder)
    string(APPEND problems "${rel}: a library file outside the layers' folders: move it into one\n")
    continue()
  endif()
  rank_of("${folder}" mine)
  if(mine STREQUAL "")
    string(APPEND problems "${rel}: folder '${folder}' has no layer (add it to tools/check_layers.cmake and docs/ARCHITECTURE.md)\n")
    continue()
  endif()
  file(STRINGS "${SOURCE_DIR}/${rel}" lines)
  list(LENGTH lines length)
  if(length GREATER 450)
    string(APPEND problems "${rel}: ${length} lines: split it by concept (a file holds one job, ~400 lines at most)\n")
  endif()
  file(STRINGS "${SOURCE_DIR}/${rel}" includes REGEX "^#include \"")
  foreach(line IN LISTS includes)
    string(REGEX REPLACE "^#include \"([^\"]+)\".*" "\\1" included "${line}")
    string(REGEX REPLACE "^kdl_space/" "" path "${included}")
    if(path STREQUAL "export.hpp")
      continue()  # generated: the export macros, layer 0
    endif()
    string(REGEX REPLACE "/.*" "" theirs_folder "${path}")
    if(path STREQUAL theirs_folder)
      string(APPEND problems "${rel} includes ${included}, which is in no layer's folder\n")
      continue()
    endif()
    rank_of("${theirs_folder}" theirs)
    if(theirs STREQUAL "")
      string(APPEND problems "${rel} includes ${included}, whose folder '${theirs_folder}' has no layer\n")
    elseif(theirs GREATER mine)
      string(APPEND problems "${rel} (${folder}, layer ${mine}) includes ${included} (${theirs_folder}, layer ${theirs}): an upward edge\n")
    endif()
  endforeach()
endforeach()
# Python stands on the library and the report layer: a file of python/src/ includes the library's
# headers (kdl_space/...) and the module's own, never the tool's (tools/).
file(GLOB python_files RELATIVE "${SOURCE_DIR}" "${SOURCE_DIR}/python/src/*.hpp" "${SOURCE_DIR}/python/src/*.cpp")
foreach(rel IN LISTS python_files)
  file(STRINGS "${SOURCE_DIR}/${rel}" includes REGEX "^#include \"")
  foreach(line IN LISTS includes)
    string(REGEX REPLACE "^#include \"([^\"]+)\".*" "\\1" included "${line}")
    if(NOT included MATCHES "^kdl_space/" AND NOT EXISTS "${SOURCE_DIR}/python/src/${included}")
      string(APPEND problems "${rel} includes ${included}, which is neither the library's (kdl_space/...) nor the module's: "
                             "Python stands on the library and kdl_space/report/, not on tools/\n")
    endif()
  endforeach()
endforeach()
if(problems)
  message(FATAL_ERROR "The include graph goes up a layer, or a file has no layer:\n${problems}")
endif()
list(LENGTH files count)
message(STATUS "include graph: ${count} files in the layers' folders, every include points down or sideways")
