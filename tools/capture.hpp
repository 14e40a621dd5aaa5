// `kdl_space capture SCENARIO [--json]`: the impact of the robot with its target, everything
// before and after.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <ostream>
#include <string>

#include "cli_common.hpp"
#include "scenario.hpp"

namespace kdl_space::cli {

struct CaptureOptions {
  std::string scenario;
  bool json = false;
};

/// A solved impact: both sides (holding their state after), the impulse, the contact point.
struct CaptureRun {
  std::unique_ptr<FreeFloatingSolver> robot_solver, target_solver;
  std::unique_ptr<FloatingSide> robot;
  std::unique_ptr<ImpactSide> target;
  Impulse impulse;
  Vector3d p_h = Vector3d::Zero();
};

/// Solves the scenario's impact; throws InputError for anything unusable.
CaptureRun solveCapture(const Scenario& scenario);
/// The capture JSON object (the keys are a contract: see the README).
Json captureJson(const Scenario& scenario, const CaptureRun& run);
/// The readable summary.
void printCaptureSummary(std::ostream& out, const Scenario& scenario, const CaptureRun& run);

CLI::App* addCapture(CLI::App& app, CaptureOptions& options);
void runCapture(const CaptureOptions& options, std::ostream& out);

}  // namespace kdl_space::cli
