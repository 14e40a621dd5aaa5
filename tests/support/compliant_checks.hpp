// What the compliant-capture tests share (one definition): robot_to_robot_capture.yaml's two
// free-floating systems with a compliant law, a system's momentum computed on its own, and the
// error of a compliant capture against the impulsive one (the independent route).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <variant>

#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/simulation/compliant_capture.hpp"

namespace kdl_space::test {

inline const std::string& robotToRobotScenario() {
  static const std::string path = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/robot_to_robot_capture.yaml";
  return path;
}

/// robot_to_robot_capture.yaml (two free-floating systems at their touch), with a compliant law
/// and a second of motion after the contact (no servos: the joined system moves freely).
inline Scenario compliantScenario(const CompliantGrasp& grasp = {}) {
  Scenario sc = loadScenario(robotToRobotScenario());
  sc.compliant = grasp;
  sc.simulation.duration = 1.0;
  sc.simulation.output_step = 0.05;
  sc.simulation.options.rtol = 1e-11;
  sc.simulation.options.atol = 1e-13;
  return sc;
}

/// A system's momentum (P; L about the world origin), computed on its own.
inline Vector6d momentumOf(const FloatingSystem& s) {
  Kinematics kin(*s.model);
  EXPECT_EQ(forwardKinematics(*s.model, s.state, kin), E_NOERROR);
  MomentumSolver m(s.model);
  EXPECT_EQ(m.compute(kin, s.velocity), E_NOERROR);
  return m.momentum();
}

inline Vector6d twistOf(const KDL::Twist& t) { return (Vector6d() << toEigen(t.vel), toEigen(t.rot)).finished(); }

/// The largest relative error of the compliant result against the impulsive capture: the
/// impulse, then each side's base twist and joint rates (relative to the side's velocity scale
/// after the impulsive capture: its base twist's norm plus its rates').
inline double captureError(const CompliantCaptureResult& c, const CaptureResult& r) {
  double e = (c.impulse - r.impulse.F).norm() / r.impulse.F.norm();
  const auto side = [&](const FloatingVelocity& a, const FloatingVelocity& b) {
    const double scale = twistOf(b.base_twist).norm() + b.qdot.data.norm();
    e = std::max(e, (twistOf(a.base_twist) - twistOf(b.base_twist)).norm() / scale);
    e = std::max(e, (a.qdot.data - b.qdot.data).norm() / scale);
  };
  side(c.robot_after, r.robot.after);
  if (r.floating_target) {
    side(c.target_after, r.floating_target->after);
  } else {  // a rigid target: one body, its base frame at the CoM (its twist: CaptureResult's)
    const Vector6d& b = r.target_twist_after;
    e = std::max(e, (twistOf(c.target_after.base_twist) - b).norm() / b.norm());
  }
  return e;
}

}  // namespace kdl_space::test
