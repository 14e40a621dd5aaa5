// A study's inputs on the target's shape and tumble as engineers state their uncertainty: each
// principal moment of inertia by its own factor (target.inertia.I1..I3, the moments in ascending
// order), the principal axes turned by an angle about a random axis (target.inertia.tilt), and the
// tumble's axis within a cone about the scenario's (target.tumble_cone). Private to the library:
// the loader checks them (checkTargetShape), draw() gives the cone's axis (coneAxis), the
// evaluator sets the target (TargetShape::apply).
#pragma once

#include <Eigen/Core>

#include "kdl_space/impact/capture.hpp"
#include "kdl_space/study/study.hpp"

namespace kdl_space {
namespace fields {
class Field;
}

/// \brief The unit vector at angle theta from the unit vector n, at azimuth phi about it (from a
/// fixed perpendicular of n: the cross product of n with the axis of its smallest component).
Vector3d coneAxis(const Vector3d& n, double theta, double phi);

/// The scenario's rigid target's principal frame and moments, and its tumble, from which a
/// sample's target is made.
struct TargetShape {
  explicit TargetShape(const RigidTarget& nominal);
  Matrix3d axes;        ///< principal axes (columns) in the target frame, a rotation
  Vector3d moments;     ///< principal moments [kg m^2], ascending: I1 <= I2 <= I3
  double mass = 0.0;    ///< [kg]
  Vector3d w = Vector3d::Zero();  ///< the nominal angular velocity (world) [rad/s]

  /// \brief The target's inertia for moment factors `factor`, axes turned by `tilt` [rad] about the
  /// unit vector `tilt_axis` (target frame), at mass `target.mass` (scaled as target.mass does):
  /// mass / mass0 * T A diag(factor * moments) A^T T^T, T the tilt's rotation, A the axes.
  Matrix3d inertia(const Vector3d& factor, double tilt, const Vector3d& tilt_axis, double mass_now) const;
};

/// \brief Checks, after all inputs are read, what the shape inputs need of the scenario and of
/// each other: moment factors whose extreme draws keep the triangle inequality (the box of their
/// ranges has its worst case at a corner: the inequality is linear), a cone about a nominal tumble
/// (the scenario's target turns), no target.twist.w* beside the cone. \throws InputError at the
/// input that is wrong.
void checkTargetShape(const fields::Field& inputs, const Study& study);

}  // namespace kdl_space
