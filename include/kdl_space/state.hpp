// The configuration of a free-floating system: base pose in the world and joint positions.
#pragma once

#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <map>
#include <string>

#include "kdl_space/model.hpp"

namespace kdl_space {

/// Base pose (world_T_base) and joint positions q (model order, size nj()).
struct State {
  KDL::Frame world_T_base = KDL::Frame::Identity();
  KDL::JntArray q;

  State() = default;
  /// Identity base pose, all joints at 0.
  explicit State(const FloatingModel& model) : q(model.nj()) {}
};

/// Base pose in URDF convention: position, then roll-pitch-yaw about fixed axes
/// (R = Rz(yaw) Ry(pitch) Rx(roll)).
inline KDL::Frame basePose(const KDL::Vector& position, double roll, double pitch, double yaw) {
  return KDL::Frame(KDL::Rotation::RPY(roll, pitch, yaw), position);
}

/// \brief A joint-indexed vector (positions or rates) from values by joint name; joints not
/// named are 0. \throws ModelError naming an unknown joint.
KDL::JntArray jointsByName(const FloatingModel& model, const std::map<std::string, double>& values);

}  // namespace kdl_space
