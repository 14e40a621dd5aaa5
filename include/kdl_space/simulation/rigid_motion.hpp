// The torque-free motion of a rigid target: where a tumbling body is, and how it moves, at any
// time (what the approach tracks before the capture).
#pragma once

#include <vector>

#include "kdl_space/impact/capture.hpp"
#include "kdl_space/export.hpp"

namespace kdl_space {

/// \brief A rigid body moving freely (no force, no moment): its CoM moves on a straight line, its
/// angular momentum is constant in the world and its angular velocity follows Euler's equations,
/// w(t) = R(t) I^-1 R(t)^T L (I: the inertia about the CoM in the body's frame), dR/dt = [w] R.
///
/// The attitude is integrated on a fixed grid (classical Runge-Kutta on the quaternion, steps of
/// `grid_step`, renormalised) from t = 0; a time between two grid points is one Runge-Kutta step
/// from the point before it. So at(t) is a function of t alone (the same answer, to the bit,
/// whatever was asked before), smooth between grid points and continuous across them to
/// round-off. Error per unit time ~ (|w| grid_step)^4 |w| (1e-16 rad/s for |w| = 1 rad/s and 1 ms).
///
/// Memory is bounded whatever the time asked for (issue 35, item 4): the grid is not kept, only
/// at most `max_checkpoints` of its points (every 1024 steps at first, the spacing doubled when
/// they would be more) and the last point reached. Times asked in increasing order cost one step per grid
/// step passed; a time before the last one reached starts again from the checkpoint below it.
class KDL_SPACE_EXPORT FreeRigidMotion {
 public:
  /// The target at t = 0. \throws ModelError unless its mass > 0, its inertia symmetric positive
  /// definite, its numbers finite, grid_step finite and > 0 and max_checkpoints >= 2 (4,096: 128 KiB).
  explicit FreeRigidMotion(const RigidTarget& at_zero, double grid_step = 1e-3, std::size_t max_checkpoints = 4096);

  /// \brief The target at time t >= 0: pose of its frame, twist (v of the CoM; w) in the world,
  /// and the rest as at t = 0. \return 0, E_BAD_ARGUMENT (t < 0), E_NOT_FINITE (t not finite).
  int at(double t, RigidTarget& target);

 private:
  /// The quaternion (x, y, z, w) of the target's frame after one step of length h from q.
  Eigen::Vector4d step(const Eigen::Vector4d& q, double h) const;

  /// The attitude at grid point k (k grid_step), from the nearest checkpoint or the last point.
  Eigen::Vector4d gridPoint(std::size_t k);

  RigidTarget start_;
  Matrix3d I_inv_;  ///< inverse inertia about the CoM, target-frame axes
  Vector3d L_;      ///< angular momentum about the CoM, world (constant)
  double grid_step_;
  std::size_t max_checkpoints_;
  std::size_t stride_ = 1024;               ///< grid steps between checkpoints (a power of two)
  std::vector<Eigen::Vector4d> checkpoints_;  ///< attitude at grid point j stride_
  std::size_t last_k_ = 0;                   ///< the last grid point reached
  Eigen::Vector4d last_q_;                   ///< its attitude
};

}  // namespace kdl_space
