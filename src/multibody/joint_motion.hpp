// How each body moves with its joint, precomputed once per model from KDL's segments so that
// forward kinematics needs no KDL call per body: a speed internal of the library, not API.
#pragma once

#include <vector>

#include "kdl_space/multibody/model.hpp"
#include "kdl_space/spatial/spatial.hpp"

namespace kdl_space::detail {

/// One body's joint motion, in its parent's frame: pose(q) = screw(q) * pose(0), q its
/// coordinate (for a mimic joint, its leader's: scale and axis carry the multiplier, pose(0) the
/// offset), the screw about
/// the joint's axis (revolute: rotation by t = scale q about the line through the axis point;
/// prismatic: translation by scale q along `axis`). Revolute, by Rodrigues' formula
/// Rot(a, t) = E + sin t a^ + (1 - cos t) a^ a^ folded into pose(0):
/// pose(q) = (R0 + s K1 + (1 - c) K2, p0 + s k1 + (1 - c) k2), s = sin t, c = cos t.
struct JointMotion {
  enum Kind { Fixed, Revolute, Prismatic };
  int parent = -1, joint = -1;  ///< as Body
  Kind kind = Fixed;
  Vector3d axis = Vector3d::UnitZ();  ///< unit, parent frame
  double scale = 1.0;                 ///< KDL's joint scale
  Matrix3d R0 = Matrix3d::Identity(), K1 = Matrix3d::Zero(), K2 = Matrix3d::Zero();
  Vector3d p0 = Vector3d::Zero(), k1 = Vector3d::Zero(), k2 = Vector3d::Zero();
  Vector3d twist_v = Vector3d::Zero(), twist_w = Vector3d::Zero();  ///< Body::joint_twist (parent origin)
  double mass = 0.0;
  Vector3d com = Vector3d::Zero();       ///< body frame
  Matrix3d I_com = Matrix3d::Zero();     ///< body axes
};

/// The joint motions of every body of a model (model().bodies() order).
struct MotionTable {
  std::vector<JointMotion> bodies;
  explicit MotionTable(const std::vector<Body>& bodies);
};

}  // namespace kdl_space::detail
