// The load a grasp carries while the robot holds a captured target: the wrench the target
// exerts on the robot's hand, from the accelerations of one instant (Newton-Euler over the
// target's bodies). For a rigid grasp no force law gives it (the grasp is a constraint): it is
// what the hand must apply to move the target as it moves.
#pragma once

#include <vector>

#include "kdl_space/algorithm/forward_dynamics.hpp"
#include "kdl_space/export.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/multibody/model.hpp"

namespace kdl_space {

/// \brief What the robot holds, in a model of the system after the capture.
struct HeldTarget {
  /// Per body of the model: true for the target's bodies (a target joined by joinAtGrasp: every
  /// body that is not the robot's; the grasp's massless links may be counted either way).
  std::vector<bool> bodies;
  /// A rigid target merged into a body's inertia (attachTarget): that body, -1 for none; its share
  /// of the inertia: mass [kg], CoM [m] in the body's frame, inertia about the CoM in its axes.
  int payload_body = -1;
  double payload_mass = 0.0;
  Vector3d payload_com = Vector3d::Zero();
  Matrix3d payload_I_com = Matrix3d::Zero();
  Contact contact;  ///< the robot's contact point: the moment is taken about it
};

/// \brief The wrench (f; n about the robot's contact point, world axes) the held target exerts on
/// the robot, at the state of `kin` with velocity `v` and accelerations `a` (ForwardDynamicsSolver's):
/// minus the sum over the target's bodies (and the payload's share of its body) of
/// F_i = I_i (A_i - (g; 0)) + V_i x* I_i V_i - f_ext,i (the rate of the body's momentum less gravity
/// and the external wrench on it), with the bodies' spatial velocities V_i and accelerations A_i
/// propagated outward from the base (A_i = A_parent + S_i qddot + V_i x S_i qdot, eq. of motion
/// of a tree). `f_ext`: one per body (world axes, moment about the body frame's origin), or empty.
/// The counterpart of a compliant grasp's ContactSample::wrench.
/// \return 0, E_SIZE_MISMATCH (kin of another model, `target.bodies`, qdot, qddot or a non-empty
/// f_ext of another size), E_NOT_COMPUTED (kin not valid), E_BAD_CONTACT or E_NOT_FINITE.
KDL_SPACE_EXPORT int graspWrench(const FloatingModel& model, const HeldTarget& target, const Kinematics& kin,
                                 const FloatingVelocity& v, const FloatingAcceleration& a,
                                 const std::vector<KDL::Wrench>& f_ext, const Vector3d& gravity, Vector6d& on_robot);

}  // namespace kdl_space
