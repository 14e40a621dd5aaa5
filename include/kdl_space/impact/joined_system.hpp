// After a capture of another free-floating system: the robot and the target joined into ONE
// free-floating model (the target's tree re-rooted at its contact link and hung on the robot's
// contact link), with the state and velocity that continue the motion of both.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "kdl_space/impact/collision.hpp"
#include "kdl_space/export.hpp"
#include "kdl_space/multibody/model.hpp"
#include "kdl_space/multibody/state.hpp"

namespace kdl_space {

/// How the captured target hangs on the robot's contact link.
enum class GraspJoint {
  Rigid,      ///< a fixed joint (after ImpactKind::Capture: the contact twists are equal)
  Spherical,  ///< a ball joint at the robot's contact point (after ImpactKind::TranslationalCapture)
  /// Six joints whose coordinates are the grasp's deflection (a compliant capture: a spring-damper
  /// acts on them, docs/COMPLIANT.md); the velocities given are any, e.g. those before the contact.
  Compliant,
};

/// \brief The joined model, its state and velocity, and where each side's joints went.
///
/// The joined tree: the robot's tree unchanged (same root, the robot's base inertia), then
///  - Rigid: the target's contact link hangs on the robot's contact link by a fixed joint named
///    "grasp", at their relative pose at the capture instant;
///  - Spherical: three revolute joints "grasp_rz", "grasp_ry", "grasp_rx" (massless links
///    "grasp_rz_link", "grasp_ry_link", "grasp_rx_link") whose axes meet at the robot's contact
///    point: z, then y, then x of the robot's contact link's axes, so that the relative rotation
///    is Rz(q1) Ry(q2) Rx(q3) (ZYX) followed by a fixed joint "grasp" to the target's contact link
///    at its pose at the capture instant. At the join all three angles are 0: the chart's centre,
///    pi/2 away from its only singularity, the middle angle q2 = +-pi/2 (sphericalChartMargin).
///  - Compliant: three prismatic joints "grasp_x", "grasp_y", "grasp_z" (massless links
///    "grasp_x_link"...) along the x, y, z axes of the robot's contact link, through its contact
///    point, then the three revolute joints of Spherical about the point they carry: the six
///    coordinates are the deflection of the target's contact link from its pose at the join (all
///    0 there): the translation of the grasp point in the robot contact link's axes, then the ZYX
///    angles of the relative rotation.
///  - the links on the path from the target's contact link to its old base are inverted: each
///    keeps its own frame and inertia (the base's from bodies()[0]), and hangs on its old child
///    by the old joint reversed: the same axis line, the joint's origin inverted, and the joint's
///    coordinate negated (target_joint_sign -1; limits negated and swapped). The rest of the
///    target's tree hangs as before (sign +1).
/// Names stay unique: if any link or joint name of the target is also a name of the robot's,
/// every link and joint name of the target is prefixed with "target/" (`target_prefix`). The
/// grasp's names get "_2", "_3"... if the robot or the (prefixed) target already uses them.
/// Joint limits, damping, friction and armature of both sides carry over; the robot's mimic
/// joints too.
struct JoinedSystem {
  std::shared_ptr<const FloatingModel> model;  ///< robot tree + target re-rooted at its contact link
  State state;                 ///< base pose = robot's; q of all joints of the joined model
  FloatingVelocity velocity;   ///< base twist = robot's; qdot of all joints
  std::vector<int> robot_joints;   ///< joined-model joint index of each robot joint (robot model order)
  std::vector<int> target_joints;  ///< joined-model joint index of each target joint (target model order)
  /// +1, or -1 where the re-rooting reversed the joint: q_joined = sign * q_target (and rates).
  std::vector<double> target_joint_sign;
  /// The 3 ball-joint coordinates (rz, ry, rx; Spherical), the 6 (x, y, z, rz, ry, rx; Compliant),
  /// empty for Rigid.
  std::vector<int> grasp_joints;
  GraspJoint grasp = GraspJoint::Rigid;
  std::string target_prefix;       ///< "" or "target/": what the target's names were given
};

/// \brief Joins a captured free-floating target to the robot as one model.
///
/// `robot` and `target` are the two systems at the capture instant (their states and contact
/// points; their velocities before are not read); `robot_after` and `target_after` their
/// velocities after the capture (CaptureResult::robot.after, floating_target->after). The capture
/// law makes the contact points move together: Rigid needs equal contact twists, Spherical equal
/// contact-point linear velocities (checked to 1e-6 relative); the joined velocity then moves
/// every body exactly as it moved in its own system: the robot's base twist and rates, the
/// target's rates (times the sign), and for Spherical the ball joint's rates from the relative
/// angular velocity (target's contact link minus the robot's, solved in the joint axes).
/// Compliant takes any velocities (no capture law: e.g. those before the contact): the six grasp
/// rates are the relative twist of the target's contact link at the robot's contact point (the
/// linear part in the robot contact link's axes, the angular part solved in the joint axes), so
/// that every body again moves as in its own system and the joined momentum is the sum of both.
/// The responses and braked joints of the sides are not read (the joined model is free).
/// A set-up call: \throws InputError ("robot: ...", "target: ...", "target.contact: ..." naming
/// the distance when the contact points are more than `touch_tolerance` [m] apart, "grasp: ..."
/// for velocities that do not satisfy the capture law); a target with mimic joints is refused
/// (not supported yet); ModelError if the joined model cannot be built (naming the link/joint).
KDL_SPACE_EXPORT JoinedSystem joinAtGrasp(const FloatingSystem& robot, const FloatingVelocity& robot_after,
                                          const FloatingSystem& target, const FloatingVelocity& target_after,
                                          GraspJoint grasp, double touch_tolerance = 1e-3);

/// \brief |cos(q_ry)| of a Spherical grasp at `state` of the joined model: 1 at the chart's
/// centre (the join), 0 at its singularity (q_ry = +-pi/2, where the rz and rx axes align and the
/// ball joint loses a degree of freedom): a simulator warns, or re-joins, when it falls low.
/// 1 for a Rigid grasp. \throws InputError if `state.q` has not the joined model's size.
KDL_SPACE_EXPORT double sphericalChartMargin(const JoinedSystem& joined, const State& state);

}  // namespace kdl_space
