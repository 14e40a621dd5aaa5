// A report's JSON (kdl_space/report/) as Python objects, without text in between: objects as dicts
// (in the report's key order), arrays as lists, numbers as int or float, a number that is not
// finite as None (as the JSON text writes it), strings as str (bytes that are not UTF-8 replaced).
#pragma once

#include <pybind11/pybind11.h>

#include "kdl_space/report/json.hpp"

namespace kdl_space::python {

namespace py = pybind11;

/// `j` as the dict, list, str, int, float, bool or None that json.loads(jsonText(j)) returns.
py::object toPython(const report::Json& j);

}  // namespace kdl_space::python
