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
