# Installs kdl_space into a scratch prefix and imports the installed package with Debian's
# interpreter (ctest python_installed_package): the install rules and the module's RUNPATH work, and
# the installed library finds its SDF module (libkdl_space_sdf.so, loaded on the first SDF file):
# the SDF and the URDF written from it by hand give the same joints and mass.
# -DBUILD_DIR -DWORK_DIR -DPYTHON -DPACKAGE_DIR (relative to the prefix) -DURDF -DSDF -DSDF_URDF
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
# The check as a file: run() passes its arguments as a CMake list, which would split a `-c` program
# at its semicolons.
file(WRITE "${WORK_DIR}/check_installed.py" [[
import sys
import kdl_space
assert kdl_space.__file__.startswith(sys.argv[1]), kdl_space.__file__
print(kdl_space.load_urdf(sys.argv[2]))
s, u = kdl_space.load_urdf(sys.argv[3]), kdl_space.load_urdf(sys.argv[4])
print(s)
assert s.joint_names == u.joint_names and abs(s.total_mass - u.total_mass) <= 1e-12 * u.total_mass, (s, u)
]])
run(${CMAKE_COMMAND} -E env "PYTHONPATH=${WORK_DIR}/prefix/${PACKAGE_DIR}" ${PYTHON} "${WORK_DIR}/check_installed.py"
    "${WORK_DIR}/prefix" "${URDF}" "${SDF}" "${SDF_URDF}")
