// The library calls behind `inspect`, `capture`, `ik`, `plan` and `export` on one scenario file: what
// fuzz_commands drives, and what test_fuzz_regressions.cpp replays on the inputs it found.
// Returns normally for every outcome a caller can handle (a result, a code, a kdl_space::Error);
// anything else escapes (another exception) or crashes: a finding.
#pragma once

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "kdl_space/algorithm/conditioning.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/algorithm/inverse_kinematics.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/multibody/poses.hpp"
#include "kdl_space/parsers/formats/mjcf.hpp"
#include "kdl_space/parsers/formats/spacedyn_lp.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/planning/capture_plan.hpp"

namespace kdl_space::fuzz {

/// inspect's quantities at the scenario's robot contact (tools/inspect_command.cpp's calls).
inline void driveInspect(const FloatingSystem& robot) {
  const auto& model = robot.model;
  FreeFloatingSolver solver(model);
  if (solver.compute(robot.state) != E_NOERROR) return;
  const unsigned int n = model->nj();
  KDL::Jacobian J_star(n), J(n);
  Matrix6d G_star, G_grounded, G_locked;
  Vector3d p;
  if (solver.contactPoint(robot.contact, p) || solver.J_star(robot.contact, J_star) || solver.J(robot.contact, J) ||
      solver.G_star(robot.contact, G_star) || solver.G_locked(robot.contact, G_locked))
    return;
  solver.G_grounded(robot.contact, G_grounded);  // E_NOT_POSITIVE_DEFINITE is an answer
  const Conditioning c = conditioning(J_star.data, J.data);
  configurationWarnings(*model, robot.state.q, &c, "contact");
  Conditioning c2;
  std::vector<Diagnostic> warnings;
  checkConfiguration(model, robot.state, robot.contact, c2, warnings);
  contactFrame(*model, robot.state, robot.contact);
}

/// export's writers on the scenario (SpaceDyn's LP and SV, the MJCF scene) and the MJCF read back.
inline void driveExport(const Scenario& sc) {
  try {
    writeSpaceDyn(sc.capture.robot, "fuzz");
  } catch (const Error&) {
  }
  try {
    std::vector<Diagnostic> notes;
    const std::string xml = writeMjcf(MjcfScene{sc.capture.robot, sc.impact ? std::optional<CaptureTarget>(sc.capture.target) : std::nullopt});
    loadUrdfString(mjcfToUrdf(xml, "fuzz.xml", notes), "fuzz.xml");
  } catch (const Error&) {
  }
}

/// Loads the scenario and runs inspect, capture, ik, plan and export on it.
inline void driveCommands(const std::string& scenario_path) {
  Scenario sc;
  try {
    sc = loadScenario(scenario_path);
  } catch (const Error&) {
    return;  // refused at load: the reader's fuzz target covers that
  }
  const FloatingSystem& robot = sc.capture.robot;
  try {
    driveInspect(robot);
  } catch (const Error&) {
  }
  driveExport(sc);
  if (sc.impact) {
    try {
      solveCapture(sc.capture);
    } catch (const Error&) {
    }
  }
  try {  // ik: the contact frame to the rigid target's frame (or 0.1 m along the contact's z)
    IkOptions o;
    o.restarts = 2;
    o.max_iterations = 60;
    KDL::Frame goal = contactFrame(*robot.model, robot.state, robot.contact) * KDL::Frame(KDL::Vector(0, 0, 0.1));
    if (const auto* rigid = std::get_if<RigidTarget>(&sc.capture.target)) goal = rigid->pose;
    solveInverseKinematics(*robot.model, robot.state, robot.contact, goal, o);
  } catch (const Error&) {
  }
  if (sc.impact) {
    try {
      PlanOptions o;
      o.scan = 3;
      o.polish_starts = 1;
      o.polish_evaluations = 20;
      planCapture(sc, o);
    } catch (const Error&) {
    }
  }
}

}  // namespace kdl_space::fuzz
