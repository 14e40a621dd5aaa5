// Rigid targets the simulation tests approach and capture (one definition, so that the approach
// and the contact-instant tests meet the same body).
#pragma once

#include "kdl_space/impact/capture.hpp"
#include "kdl_space/spatial/spatial.hpp"

namespace kdl_space::test {

/// A box target (50 kg, principal moments 2.1, 2.6, 3.0 kg m^2, CoM at its frame's origin) at
/// `position`, turned by RPY(0.3, -0.2, 0.5), with `twist` (v of the CoM; w), world frame.
inline RigidTarget box(const Vector3d& position, const Vector6d& twist) {
  RigidTarget t;
  t.mass = 50.0;
  t.inertia = Vector3d(2.1, 2.6, 3.0).asDiagonal();
  t.pose = KDL::Frame(KDL::Rotation::RPY(0.3, -0.2, 0.5), toKDL(position));
  t.twist = twist;
  return t;
}

}  // namespace kdl_space::test
