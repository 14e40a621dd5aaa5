// The capture's Python-side types, shared by capture.cpp and simulation.cpp (the motion after a
// capture starts from them).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "conversions.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"

namespace kdl_space::python {

/// A capture problem and the models' files (for repr and the results' joint names).
struct PyProblem {
  CaptureProblem problem;
  std::string robot_source;
};

struct PyScenario {
  Scenario scenario;
};

/// \brief The one rule of every call that takes a scenario: a Scenario (load_scenario) or the path of
/// its file (str or os.PathLike), read when the call is made (the loader's InputError naming the
/// file for one it refuses; TypeError for anything else).
class ScenarioArg {
 public:
  ScenarioArg() = default;
  explicit ScenarioArg(const PyScenario* given) : given_(given) {}
  explicit ScenarioArg(Scenario loaded) : loaded_(std::make_shared<const PyScenario>(PyScenario{std::move(loaded)})) {}
  const Scenario& get() const { return loaded_ ? loaded_->scenario : given_->scenario; }

 private:
  const PyScenario* given_ = nullptr;           ///< the caller's object (alive for the call)
  std::shared_ptr<const PyScenario> loaded_;    ///< or read from the path given
};

/// One free-floating side of a result, with its joint names.
struct PySide {
  FloatingSideResult side;
  std::vector<std::string> joint_names;
};

struct PyResult {
  CaptureResult r;
  PySide robot;
  std::optional<PySide> floating_target;
  /// The robot's configuration at the capture (checkConfiguration: limits, a near-singular J*).
  std::vector<Diagnostic> warnings = {};
  /// The scenario it solved (a CaptureProblem's: the problem, its robot's URDF): what to_html draws.
  std::shared_ptr<const Scenario> scenario = nullptr;
};

}  // namespace kdl_space::python

namespace pybind11::detail {
/// ScenarioArg from a Scenario or a path (see ScenarioArg).
template <>
struct type_caster<kdl_space::python::ScenarioArg> {
  PYBIND11_TYPE_CASTER(kdl_space::python::ScenarioArg, const_name("Scenario | str | os.PathLike"));
  bool load(handle src, bool) {
    using kdl_space::python::PyScenario;
    if (isinstance<PyScenario>(src)) {
      value = kdl_space::python::ScenarioArg(&src.cast<const PyScenario&>());
      return true;
    }
    if (!isinstance<str>(src) && !hasattr(src, "__fspath__")) return false;
    const object path = module_::import("os").attr("fspath")(src);
    if (!isinstance<str>(path)) return false;  // a bytes path
    value = kdl_space::python::ScenarioArg(kdl_space::loadScenario(path.cast<std::string>()));
    return true;
  }
};
}  // namespace pybind11::detail
