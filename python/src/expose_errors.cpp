// The library's errors as Python exceptions (kdl_space.Error, the binding of kdl_space::Error, and
// its subclasses ModelError, InputError, ComputeError with `.code`), and the NumPy conversions that name the argument.
#include <cmath>
#include <sstream>

#include "conversions.hpp"
#include "kdl_space/parsers/output_file.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space::python {

namespace {
std::string shapeText(const std::vector<long>& shape) {
  std::ostringstream s;
  s << "(";
  for (std::size_t i = 0; i < shape.size(); ++i) s << (i ? ", " : "") << shape[i];
  s << (shape.size() == 1 ? ",)" : ")");
  return s.str();
}
}  // namespace

Eigen::MatrixXd fromNumpy(py::handle given, const char* name, long rows, long cols) {
  const std::vector<long> expected = cols < 0 ? std::vector<long>{rows} : std::vector<long>{rows, cols};
  using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
  const py::object obj = fromPyKDL(given);
  if (!obj.is_none()) {  // forcecast would drop an imaginary part without a word
    const py::array as_given = py::array::ensure(obj);
    if (as_given && as_given.dtype().kind() == 'c')
      throw py::value_error(std::string(name) + ": expected real numbers, got a complex array");
    PyErr_Clear();
  }
  Array a;
  if (!obj.is_none()) a = Array::ensure(obj);
  if (obj.is_none() || !a) {  // a default array_t is an empty array, not a null one
    PyErr_Clear();
    throw py::type_error(std::string(name) + ": expected an array of numbers of shape " + shapeText(expected) +
                         ", got " + std::string(py::str(py::type::handle_of(obj).attr("__name__"))));
  }
  std::vector<long> shape(a.shape(), a.shape() + a.ndim());
  if (shape != expected)
    throw py::value_error(std::string(name) + ": expected shape " + shapeText(expected) + ", got " + shapeText(shape));
  Eigen::MatrixXd m(rows, cols < 0 ? 1 : cols);
  const double* data = a.data();
  for (long i = 0; i < m.rows(); ++i)
    for (long j = 0; j < m.cols(); ++j) m(i, j) = data[i * m.cols() + j];
  return m;
}

py::array_t<double> toNumpy(const Eigen::Ref<const Eigen::MatrixXd>& m, bool vector) {
  py::array_t<double> a = vector ? py::array_t<double>(m.size())
                                 : py::array_t<double>(std::vector<py::ssize_t>{m.rows(), m.cols()});
  double* out = a.mutable_data();
  for (long i = 0; i < m.rows(); ++i)
    for (long j = 0; j < m.cols(); ++j) out[i * m.cols() + j] = m(i, j);
  return a;
}

py::array_t<double> frameToNumpy(const KDL::Frame& f) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = toEigen(f.M);
  T.topRightCorner<3, 1>() = toEigen(f.p);
  return toNumpy(T);
}

KDL::Frame frameFromPython(py::handle given, const char* name) {
  const py::object obj = fromPyKDL(given);  // a PyKDL.Frame: its 4x4 matrix
  if (py::isinstance<py::tuple>(obj) || py::isinstance<py::list>(obj)) {
    py::sequence s = py::reinterpret_borrow<py::sequence>(obj);
    if (s.size() == 2) {
      const std::string n(name);
      const Vector3d p = vec3(s[0], (n + "[0] (position)").c_str());
      const Vector3d rpy = vec3(s[1], (n + "[1] (rpy)").c_str());
      return basePose(toKDL(p), rpy(0), rpy(1), rpy(2));
    }
  }
  const Eigen::MatrixXd T = fromNumpy(obj, name, 4, 4);
  // A pose is a rotation and a position: anything else would give wrong results without a word.
  // (Non-finite entries pass here: the compute calls answer them with E_NOT_FINITE.)
  if (T.allFinite()) {
    const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
    const double orthonormal = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    const double det = R.determinant();
    if (orthonormal > 1e-9 || std::abs(det - 1.0) > 1e-9) {
      std::ostringstream why;
      why << name << ": the upper-left 3x3 is no rotation: max |R^T R - I| = " << orthonormal << ", det R = " << det
          << " (a rotation has R^T R = I and det R = +1, to 1e-9; a mirror or a scale is no pose)";
      throw py::value_error(why.str());
    }
    const Eigen::RowVector4d last = T.row(3);
    if ((last - Eigen::RowVector4d(0.0, 0.0, 0.0, 1.0)).cwiseAbs().maxCoeff() > 1e-9) {
      std::ostringstream why;
      why << name << ": the last row of a 4x4 pose is (0, 0, 0, 1), got (" << last(0) << ", " << last(1) << ", "
          << last(2) << ", " << last(3) << ")";
      throw py::value_error(why.str());
    }
  }
  KDL::Frame f;
  for (int i = 0; i < 3; ++i) {
    f.p(i) = T(i, 3);
    for (int j = 0; j < 3; ++j) f.M(i, j) = T(i, j);
  }
  return f;
}

void bindErrors(py::module_& m) {
  // kdl_space.Error is the binding of the C++ base (errors.hpp): a C++ ModelError or InputError
  // arrives as its subclass, any other kdl_space::Error as Error itself.
  static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
  error.doc() = "Base of the errors kdl_space raises (the C++ library's kdl_space::Error and its message).";
  static py::exception<ModelError> model_error(m, "ModelError", error.ptr());
  model_error.doc() = "A model or an object that a loader, constructor or set-up call cannot build as asked; the "
                      "message names the file, the link or joint and what is wrong.";
  static py::exception<InputError> input_error(m, "InputError", error.ptr());
  input_error.doc() = "A scenario, study or capture input that cannot be used; the message names the file, the "
                      "field and what is wrong.";
  static py::exception<ComputeError> compute_error(m, "ComputeError", error.ptr());
  compute_error.doc() = "A compute call returned an error code: `.code` is the code (e.g. E_NOT_FINITE = "
                        "-102), the message the call and strError(code).";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ComputeError& e) {
      py::object instance = py::handle(compute_error.ptr())(e.what());
      instance.attr("code") = e.code();
      PyErr_SetObject(compute_error.ptr(), instance.ptr());
    } catch (const ModelError& e) {
      model_error(e.what());
    } catch (const InputError& e) {
      input_error(e.what());
    } catch (const Cancelled& e) {  // a cancel poll said stop: what Ctrl-C raises
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    } catch (const Error& e) {
      error(e.what());
    } catch (const UsageError& e) {  // a request to change before anything runs (an output on an input)
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const py::cast_error& e) {  // a cast no argumentAs named: a TypeError all the same
      PyErr_SetString(PyExc_TypeError, (std::string("an argument has the wrong type: ") + e.what()).c_str());
    }
  });
  py::module_ codes = m.def_submodule("codes", "The return codes of compute calls (ComputeError.code).");
  for (auto [n, c] : std::vector<std::pair<const char*, int>>{
           {"E_NOERROR", E_NOERROR}, {"E_SIZE_MISMATCH", E_SIZE_MISMATCH}, {"E_NOT_COMPUTED", E_NOT_COMPUTED},
           {"E_NOT_FINITE", E_NOT_FINITE}, {"E_NOT_POSITIVE_DEFINITE", E_NOT_POSITIVE_DEFINITE},
           {"E_BAD_CONTACT", E_BAD_CONTACT}, {"E_MAX_STEPS", E_MAX_STEPS}, {"E_BAD_ARGUMENT", E_BAD_ARGUMENT},
           {"E_STEP_UNDERFLOW", E_STEP_UNDERFLOW}, {"E_CANCELLED", E_CANCELLED}}) {
    codes.attr(n) = c;
    m.attr(n) = c;
  }
  m.def("str_error", &strError, py::arg("code"), "The library's text for a return code.");
}

}  // namespace kdl_space::python
