#include "json_objects.hpp"

#include <cmath>

namespace kdl_space::python {

py::object toPython(const report::Json& j) {
  using Type = report::Json::value_t;
  switch (j.type()) {
    case Type::object: {
      py::dict d;
      for (const auto& [key, value] : j.items()) d[py::str(key)] = toPython(value);
      return std::move(d);
    }
    case Type::array: {
      py::list l(j.size());
      for (std::size_t i = 0; i < j.size(); ++i) l[i] = toPython(j[i]);
      return std::move(l);
    }
    case Type::string: {
      const std::string& s = j.get_ref<const std::string&>();
      return py::reinterpret_steal<py::object>(PyUnicode_DecodeUTF8(s.data(), static_cast<Py_ssize_t>(s.size()), "replace"));
    }
    case Type::boolean: return py::bool_(j.get<bool>());
    case Type::number_integer: return py::int_(j.get<std::int64_t>());
    case Type::number_unsigned: return py::int_(j.get<std::uint64_t>());
    case Type::number_float: {
      const double x = j.get<double>();
      return std::isfinite(x) ? py::object(py::float_(x)) : py::none();  // the text writes null
    }
    default: return py::none();  // null, discarded
  }
}

}  // namespace kdl_space::python
