// What every binding file shares: NumPy <-> Eigen with the argument's name in the error, the
// wrappers of the model, contact and state (they keep the model alive), and the error rule (a
// nonzero return code of a compute call becomes kdl_space.ComputeError).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/multibody/model.hpp"
#include "kdl_space/spatial/spatial.hpp"
#include "kdl_space/multibody/state.hpp"

namespace kdl_space::python {
namespace py = pybind11;

/// A nonzero return code of a compute call: kdl_space.ComputeError with `.code` (errors.cpp).
class ComputeError : public std::runtime_error {
 public:
  ComputeError(int code, const std::string& what) : std::runtime_error(what), code_(code) {}
  int code() const { return code_; }

 private:
  int code_;
};

/// \brief `value` as a T (py::cast), or TypeError "NAME: expected TAKES, got TYPE" naming the argument
/// (pybind11's own cast error is a RuntimeError "Unable to cast ..." that names neither).
template <typename T>
T argumentAs(py::handle value, const std::string& name, const char* takes) {
  const auto wrong = [&] {
    return py::type_error(name + ": expected " + takes + ", got " +
                          std::string(py::str(py::type::handle_of(value).attr("__name__"))) + " " +
                          std::string(py::repr(value)).substr(0, 60));
  };
  try {
    return py::cast<T>(value);
  } catch (const py::cast_error&) {
    throw wrong();
  } catch (py::error_already_set& e) {  // a conversion Python refused (dict(2.0): "not iterable")
    if (!e.matches(PyExc_TypeError) && !e.matches(PyExc_ValueError)) throw;
    throw wrong();
  }
}

/// Throws ComputeError "<what>: <strError(code)>" unless code is 0.
inline void check(int code, const std::string& what) {
  if (code != 0) throw ComputeError(code, what + ": " + strError(code));
}

/// A PyKDL object (Vector, Twist, Wrench, Rotation, Frame, JntArray) as nested lists of its
/// numbers (a Frame: its 4x4 matrix; a Twist: (vel; rot)); anything else as it is (pykdl.cpp).
py::object fromPyKDL(py::handle obj);

/// A float64 array of the given shape from any array-like (PyKDL objects too); cols < 0: a vector (n,).
/// \throws ValueError naming `name`, the expected and the given shape.
Eigen::MatrixXd fromNumpy(py::handle obj, const char* name, long rows, long cols = -1);
inline Vector6d vec6(py::handle obj, const char* name) { return fromNumpy(obj, name, 6); }
inline Vector3d vec3(py::handle obj, const char* name) { return fromNumpy(obj, name, 3); }
inline Matrix6d mat6(py::handle obj, const char* name) { return fromNumpy(obj, name, 6, 6); }
inline Matrix3d mat3(py::handle obj, const char* name) { return fromNumpy(obj, name, 3, 3); }
/// A new (rows, cols) float64 array (C order), or (rows,) for a vector.
py::array_t<double> toNumpy(const Eigen::Ref<const Eigen::MatrixXd>& m, bool vector = false);
inline py::array_t<double> toNumpy6(const Vector6d& v) { return toNumpy(v, true); }
inline py::array_t<double> toNumpyVec(const Eigen::VectorXd& v) { return toNumpy(v, true); }
/// A pose as a 4x4 homogeneous matrix, and back (a 4x4 array, or (position, rpy)).
py::array_t<double> frameToNumpy(const KDL::Frame& f);
KDL::Frame frameFromPython(py::handle obj, const char* name);

/// kdl_space.Model: the shared immutable model and the file it came from.
struct Model {
  std::shared_ptr<const FloatingModel> ptr;
  std::string source;
};

/// kdl_space.Contact: a link and an offset in its frame, on one model.
struct PyContact {
  std::shared_ptr<const FloatingModel> model;
  Contact contact;
  std::string link;
};

/// kdl_space.State: configuration and velocity of one model.
struct PyState {
  std::shared_ptr<const FloatingModel> model;
  State state;
  FloatingVelocity velocity;
};

/// Joint values (q, qdot) from an array (nj,) or a dict name -> value (others 0).
KDL::JntArray jointValues(const FloatingModel& model, py::handle obj, const char* name);

/// Throws ValueError unless `c` is a contact on `model`.
void checkContact(const FloatingModel& model, const PyContact& c);

/// Runs f with the GIL released and `mutex` held (one solver serves one thread at a time).
template <class F>
auto withoutGil(std::mutex& mutex, F&& f) {
  py::gil_scoped_release nogil;
  std::lock_guard<std::mutex> lock(mutex);
  return f();
}

void bindErrors(py::module_& m);
void bindModel(py::module_& m);
void bindSolvers(py::module_& m);
void bindImpact(py::module_& m);
void bindCapture(py::module_& m);
void bindForwardDynamics(py::module_& m);
void bindSimulation(py::module_& m);
void bindStudy(py::module_& m);
void bindOperation(py::module_& m);
void bindPoses(py::module_& m);
void bindInverseKinematics(py::module_& m);
void bindPlanning(py::module_& m);
void bindFormats(py::module_& m);

}  // namespace kdl_space::python
