# Installs kdl_space into a scratch prefix and imports the installed package with Debian's
# interpreter (ctest python_installed_package): the install rules and the module's RUNPATH work.
# -DBUILD_DIR -DWORK_DIR -DPYTHON -DPACKAGE_DIR (relative to the prefix) -DURDF
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()
file(REMOVE_RECURSE "${WORK_DIR}")
run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix")
foreach(f __init__.py __init__.pyi py.typed)
  if(NOT EXISTS "${WORK_DIR}/prefix/${PACKAGE_DIR}/kdl_space/${f}")
    message(FATAL_ERROR "not installed: ${PACKAGE_DIR}/kdl_space/${f}")
  endif()
endforeach()
run(${CMAKE_COMMAND} -E env "PYTHONPATH=${WORK_DIR}/prefix/${PACKAGE_DIR}"
    ${PYTHON} -c "import kdl_space, sys; assert kdl_space.__file__.startswith(sys.argv[1]), kdl_space.__file__; \
m = kdl_space.load_urdf(sys.argv[2]); print(m)" "${WORK_DIR}/prefix" "${URDF}")
