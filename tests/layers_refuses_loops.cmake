# The layers test sees an include loop (tests/data/layers_loop/): two headers that include each
# other, and spatial/ and detail/ that include each other's files. Fails unless the check fails
# naming both loops. Run: cmake -DSOURCE_DIR=<repo> -P tests/layers_refuses_loops.cmake
execute_process(COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${SOURCE_DIR}/tests/data/layers_loop
                        -P ${SOURCE_DIR}/tools/check_layers.cmake
                RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_VARIABLE out)
string(REGEX REPLACE "[ \n]+" " " said "${err}${out}")
if(rc EQUAL 0)
  message(FATAL_ERROR "check_layers.cmake passed a tree with include loops: ${said}")
endif()
foreach(expected "files on an include loop: include/kdl_space/spatial/a.hpp, include/kdl_space/spatial/b.hpp:"
                 "the library's folders on an include loop: detail, spatial:")
  string(FIND "${said}" "${expected}" at)
  if(at LESS 0)
    message(FATAL_ERROR "check_layers.cmake did not say \"${expected}\"; it said: ${said}")
  endif()
endforeach()
message(STATUS "the layers test refuses both loops")
