# Checks that the library's include graph goes one way, down the layers of docs/ARCHITECTURE.md:
#   0 spatial   1 model   2 state/kinematics   3 solvers   4 impact/collision   5 capture
#   6 dynamics/simulation   7 loaders/checker   (8 tools: may include anything of the library)
# Every header and source of include/kdl_space/ and src/ has a layer (by its name below); a file
# may include only files of its own layer or lower ones. A file with no layer fails the check:
# give it one here. Also refuses a library file of more than 450 lines. Run: cmake -DSOURCE_DIR=<repo> -P tools/check_layers.cmake (ctest: layers).
cmake_minimum_required(VERSION 3.16)

function(layer_of name out)
  get_filename_component(stem "${name}" NAME_WE)
  set(table
    "export,spatial,errors,text,symmetric6d,lanes,lane_symmetric6d,multiversion,rosenbrock,sines,response=0"
    "diagnostics,model,model_build,model_rules,joint_motion=1"
    "state,kinematics,momentum=2"
    "free_floating_solver,recursive_ex_iit=3"
    "impact,impact_friction,collision=4"
    "capture,joined_system=5"
    "forward_dynamics,dense_forward_dynamics,simulation,simulation_events,simulation_stiff,simulation_layout,actuation,approach,rigid_motion=6"
    "urdf_loader,urdf_check,urdf_xml,urdf_graph,urdf_numbers,urdf_summary,scenario,scenario_fields,scenario_sections,scenario_approach,scenario_simulator,input_file=7"
    "study,study_loader,study_run,study_sampling,study_self_motion,study_summary=8")
  foreach(row IN LISTS table)
    string(REGEX REPLACE ".*=" "" rank "${row}")
    string(REGEX REPLACE "=.*" "" names "${row}")
    string(REPLACE "," "|" alternatives "${names}")
    if(stem MATCHES "^(${alternatives})$")
      set(${out} ${rank} PARENT_SCOPE)
      return()
    endif()
  endforeach()
  set(${out} "" PARENT_SCOPE)
endfunction()

file(GLOB_RECURSE files "${SOURCE_DIR}/include/kdl_space/*.hpp" "${SOURCE_DIR}/src/*.hpp" "${SOURCE_DIR}/src/*.cpp")
set(problems "")
foreach(file IN LISTS files)
  file(RELATIVE_PATH rel "${SOURCE_DIR}" "${file}")
  layer_of("${file}" mine)
  if(mine STREQUAL "")
    string(APPEND problems "${rel}: has no layer (add it to tools/check_layers.cmake and docs/ARCHITECTURE.md)\n")
    continue()
  endif()
  file(STRINGS "${file}" lines)
  list(LENGTH lines length)
  if(length GREATER 450)
    string(APPEND problems "${rel}: ${length} lines: split it (a file holds one job, ~400 lines at most)\n")
  endif()
  file(STRINGS "${file}" includes REGEX "^#include \"")
  foreach(line IN LISTS includes)
    string(REGEX REPLACE "^#include \"([^\"]+)\".*" "\\1" included "${line}")
    layer_of("${included}" theirs)
    if(theirs STREQUAL "")
      string(APPEND problems "${rel}: includes ${included}, which has no layer\n")
    elseif(theirs GREATER mine)
      string(APPEND problems "${rel} (layer ${mine}) includes ${included} (layer ${theirs}): an upward edge\n")
    endif()
  endforeach()
endforeach()
if(problems)
  message(FATAL_ERROR "The include graph goes up a layer:\n${problems}")
endif()
list(LENGTH files count)
message(STATUS "include graph: ${count} files, every include points down or sideways")
