// The state of a free-floating system: its configuration (base pose in the world, joint
// positions) and its velocity (base twist, joint rates).
#pragma once

#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <map>
#include <string>

#include "kdl_space/export.hpp"
#include "kdl_space/multibody/model.hpp"

namespace kdl_space {

/// Base pose (world_T_base) and joint positions q (model order, size nj()).
struct State {
  KDL::Frame world_T_base = KDL::Frame::Identity();
  KDL::JntArray q;

  State() = default;
  /// Identity base pose, all joints at 0.
  explicit State(const FloatingModel& model) : q(model.nj()) {}
};

/// Velocity of a free-floating system: base twist (linear velocity of the base frame's origin,
/// angular velocity; world frame) and joint rates (model order).
struct FloatingVelocity {
  KDL::Twist base_twist = KDL::Twist::Zero();
  KDL::JntArray qdot;

  FloatingVelocity() = default;
  /// Base at rest, all joint rates 0.
  explicit FloatingVelocity(const FloatingModel& model) : qdot(model.nj()) {}
  FloatingVelocity(const KDL::Twist& base_twist_, const KDL::JntArray& qdot_) : base_twist(base_twist_), qdot(qdot_) {}
};

/// Base pose in URDF convention: position, then roll-pitch-yaw about fixed axes
/// (R = Rz(yaw) Ry(pitch) Rx(roll)).
inline KDL::Frame basePose(const KDL::Vector& position, double roll, double pitch, double yaw) {
  return KDL::Frame(KDL::Rotation::RPY(roll, pitch, yaw), position);
}

/// \brief A joint-indexed vector (positions or rates) from values by joint name; joints not
/// named are 0. \throws ModelError naming an unknown joint.
KDL_SPACE_EXPORT KDL::JntArray jointsByName(const FloatingModel& model, const std::map<std::string, double>& values);

}  // namespace kdl_space
