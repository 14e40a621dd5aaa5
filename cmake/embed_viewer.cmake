# Turns the page of `--html` (src/report/viewer/: page.html with the placeholders of its style and
# scripts, viewer.css, errors.js, viewer.js) into a header of two strings: kHtmlHead, the page up to
# its data and libraries (@DATA_AND_LIBRARIES@, which html_writer.cpp writes), and kHtmlBody, the
# rest. Run at build time: cmake -DVIEWER_DIR=<dir> -DOUTPUT=<header> -P cmake/embed_viewer.cmake.
cmake_minimum_required(VERSION 3.16)
file(READ "${VIEWER_DIR}/page.html" page)
file(READ "${VIEWER_DIR}/viewer.css" css)
file(READ "${VIEWER_DIR}/errors.js" errors)
file(READ "${VIEWER_DIR}/viewer.js" viewer)
set(delimiter "kdlviewer")
foreach(part page css errors viewer)
  string(FIND "${${part}}" ")${delimiter}\"" at)
  if(NOT at EQUAL -1)
    message(FATAL_ERROR "src/report/viewer: the text ')${delimiter}\"' would end the embedded string; reword it")
  endif()
endforeach()
foreach(placeholder VIEWER_CSS ERRORS_JS VIEWER_JS DATA_AND_LIBRARIES)
  string(FIND "${page}" "@${placeholder}@" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "src/report/viewer/page.html: the placeholder @${placeholder}@ is missing")
  endif()
endforeach()
string(REPLACE "@VIEWER_CSS@" "${css}" page "${page}")
string(REPLACE "@ERRORS_JS@" "${errors}" page "${page}")
string(REPLACE "@VIEWER_JS@" "${viewer}" page "${page}")
string(REPLACE "@DATA_AND_LIBRARIES@" ")${delimiter}\";\n\ninline const char* const kHtmlBody = R\"${delimiter}(" page "${page}")
file(WRITE "${OUTPUT}.tmp"
     "// Generated from src/report/viewer/ by cmake/embed_viewer.cmake: edit those files, not this one.\n"
     "#pragma once\n\nnamespace kdl_space::report {\n\n"
     "inline const char* const kHtmlHead = R\"${delimiter}(${page})${delimiter}\";\n\n"
     "}  // namespace kdl_space::report\n")
# Replaced only when it changed: no rebuild of the writer for an unchanged page.
execute_process(COMMAND ${CMAKE_COMMAND} -E copy_if_different "${OUTPUT}.tmp" "${OUTPUT}")
file(REMOVE "${OUTPUT}.tmp")
