// PyKDL objects (Debian's python3-pykdl) accepted wherever the module takes an array: a Vector
// as (3,), a Twist (vel; rot) or a Wrench (force; torque) as (6,), a Rotation as (3, 3), a Frame
// as the 4x4 homogeneous matrix, a JntArray as (n,). Duck-typed by the class's module, so the
// module does not link PyKDL.
#include "conversions.hpp"

namespace kdl_space::python {

namespace {
py::list vector3(py::handle v) {
  py::list out;
  for (int i = 0; i < 3; ++i) out.append(v[py::int_(i)]);
  return out;
}
py::list matrix3(py::handle R) {
  py::list rows;
  for (int i = 0; i < 3; ++i) {
    py::list row;
    for (int j = 0; j < 3; ++j) row.append(R[py::make_tuple(i, j)]);
    rows.append(row);
  }
  return rows;
}
}  // namespace

py::object fromPyKDL(py::handle obj) {
  const py::handle type = py::type::handle_of(obj);
  if (!py::hasattr(type, "__module__") || py::str(type.attr("__module__")).cast<std::string>() != "PyKDL")
    return py::reinterpret_borrow<py::object>(obj);
  const std::string kind = py::str(type.attr("__name__"));
  if (kind == "Vector") return vector3(obj);
  if (kind == "Twist" || kind == "Wrench") {
    py::list out = vector3(obj.attr(kind == "Twist" ? "vel" : "force"));
    for (auto x : vector3(obj.attr(kind == "Twist" ? "rot" : "torque"))) out.append(x);
    return std::move(out);
  }
  if (kind == "Rotation") return matrix3(obj);
  if (kind == "Frame") {
    py::list rows = matrix3(obj.attr("M"));
    const py::list p = vector3(obj.attr("p"));
    for (int i = 0; i < 3; ++i) rows[i].cast<py::list>().append(p[i]);
    rows.append(py::make_tuple(0.0, 0.0, 0.0, 1.0));
    return std::move(rows);
  }
  if (kind == "JntArray") {
    py::list out;
    const int n = obj.attr("rows")().cast<int>();
    for (int i = 0; i < n; ++i) out.append(obj[py::int_(i)]);
    return std::move(out);
  }
  return py::reinterpret_borrow<py::object>(obj);  // another PyKDL type: the caller says what it expected
}

}  // namespace kdl_space::python
