// One output row of `kdl_space simulate`: what the CSV and the plot show.
#pragma once

#include <Eigen/Core>
#include <limits>

namespace kdl_space::cli {

struct Sample {
  double t = 0.0;                              ///< [s]
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< base position [m]
  Eigen::Vector4d quat = Eigen::Vector4d::Zero();  ///< base attitude: x y z w
  Eigen::Matrix<double, 6, 1> twist;           ///< base twist (v; w)
  Eigen::VectorXd q, qd;                       ///< joint positions and rates
  Eigen::Matrix<double, 6, 1> h;               ///< total momentum (P; L about the world origin)
  double T = 0.0;                              ///< kinetic energy [J]
  Eigen::VectorXd tau;                         ///< joint torques applied (controls + friction)
  Eigen::Matrix<double, 6, 1> base_wrench = Eigen::Matrix<double, 6, 1>::Zero();  ///< base control (f; n)
  /// Work since the start: controller, friction, limits, base control, wrenches, gravity [J].
  Eigen::Matrix<double, 6, 1> work = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> impulse = Eigen::Matrix<double, 6, 1>::Zero();  ///< external, since the start
  /// "approach", "capture" (the approach's last row: the instant of contact, before the impact),
  /// "post" (after the impact) or "motion" (a plain motion).
  const char* phase = "post";
  double grasp_distance = std::numeric_limits<double>::quiet_NaN();  ///< hand to grasp point [m] (approach)
};

}  // namespace kdl_space::cli
