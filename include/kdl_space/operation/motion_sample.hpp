// One output sample of a capture operation: what its CSV row, its plot and its records read.
#pragma once

#include <Eigen/Core>
#include <limits>

#include "kdl_space/export.hpp"
#include "kdl_space/simulation/simulation.hpp"

namespace kdl_space {

/// The phase a sample belongs to.
enum class Phase {
  Approach,  ///< the hand on its way to the grasp point
  Capture,   ///< the approach's last sample: the contact instant, before the impact
  Post,      ///< after the impact
  Motion,    ///< a plain motion (a scenario without an impact)
  Contact,   ///< during a compliant capture's contact (law type compliant), after the touch
};

/// The phase's name in the CSV and the JSON: "approach", "capture", "post", "motion", "contact".
KDL_SPACE_EXPORT const char* toString(Phase phase);

struct MotionSample {
  double t = 0.0;                                 ///< [s]
  Eigen::Vector3d p = Eigen::Vector3d::Zero();     ///< base position [m]
  Eigen::Vector4d quat = Eigen::Vector4d::Zero();  ///< base attitude: x y z w
  Vector6d twist = Vector6d::Zero();               ///< base twist (v; w)
  Eigen::VectorXd q, qd;                           ///< joint positions and rates (model order)
  Vector6d h = Vector6d::Zero();                   ///< total momentum (P; L about the world origin)
  double T = 0.0;                                  ///< kinetic energy [J]
  Eigen::VectorXd tau;                             ///< joint torques applied (controls + friction)
  Vector6d base_wrench = Vector6d::Zero();         ///< base control (f; n)
  /// Work since the start: controller, friction, limits, base control, wrenches, gravity [J].
  Vector6d work = Vector6d::Zero();
  Vector6d impulse = Vector6d::Zero();  ///< external, since the start of the run
  Phase phase = Phase::Post;
  double grasp_distance = std::numeric_limits<double>::quiet_NaN();  ///< hand to grasp point [m] (approach)
  /// The compliant contact's wrench on the robot (f; n about its contact point), world [N, N m]
  /// (ContactSample::wrench): Phase::Contact only, NaN in the other phases.
  Vector6d contact_wrench = Vector6d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// The load the grasp carries: the wrench the held target exerts on the robot (f; n about its
  /// contact point), world [N, N m]: a compliant contact's (contact_wrench) in Phase::Contact, and
  /// after a capture that holds the target (a rigid, ball or compliant grasp, or a rigid target
  /// merged into the hand) graspWrench's in Phase::Post; NaN where nothing is held.
  Vector6d grasp_wrench = Vector6d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// The reaction wheels' momenta [N m s] and motor torques [N m] (Simulator::setReactionWheels);
  /// empty without wheels.
  Eigen::VectorXd wheel_momentum, wheel_torque;
};

/// \brief The sample of a state of `sim`'s run (its energy and momentum computed in O(n)).
/// \return 0 or the code of Simulator::energyAndMomentum (T and h are then NaN).
KDL_SPACE_EXPORT int sampleOf(Simulator& sim, const SimulationState& x, Phase phase, MotionSample& out);

}  // namespace kdl_space
