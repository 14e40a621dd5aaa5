// A rigid target as a free-floating system of one body: what joinAtGrasp can join to the robot
// (the spherical capture's joined motion, the compliant capture's contact).
#pragma once

#include "kdl_space/export.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/impact/collision.hpp"

namespace kdl_space {

/// \brief The rigid target `t` as a free-floating system of one body and no joints: its base frame
/// at the CoM (world: t.pose * t.com) with the axes of the target frame, the inertia t.inertia about
/// the CoM in those axes, moving with `twist_at_com` ((v of the CoM; w), world frame, as
/// RigidTarget::twist), touched at `contact_point` (world). A set-up call: \throws InputError
/// ("target.mass: ...") for a mass that is not finite and > 0, ("target.inertia: ...") for an
/// inertia that is not finite.
KDL_SPACE_EXPORT FloatingSystem rigidBodySystem(const RigidTarget& t, const Vector3d& contact_point,
                                                const Vector6d& twist_at_com);

}  // namespace kdl_space
