// A joint-space move: every joint from q0 to q1 along one synchronized trapezoidal profile (all
// joints start and stop together, on the straight line between the two configurations, so a
// move between two configurations inside the joints' limits stays inside them), each joint's
// rate and acceleration within its limits. What the approach's pre-grasp phase follows.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "kdl_space/export.hpp"

namespace kdl_space {

class KDL_SPACE_EXPORT JointMove {
 public:
  JointMove() = default;
  /// \brief The fastest synchronized move: the path parameter s in [0, 1] accelerates at
  /// min_j acceleration_j / |d_j|, cruises at min_j rate_j / |d_j|, decelerates (d = q1 - q0;
  /// joints that do not move set no bound). \throws ModelError for sizes that differ, limits
  /// that are not > 0, or positions that are not finite.
  JointMove(const Eigen::VectorXd& q0, const Eigen::VectorXd& q1, const std::vector<double>& rate_limits,
            const std::vector<double>& acceleration_limits);
  double duration() const { return T_; }  ///< [s]
  /// Positions and rates at `t` [s] after the start (clamped to [0, duration]).
  void at(double t, Eigen::VectorXd& q, Eigen::VectorXd& qdot) const;
  const Eigen::VectorXd& start() const { return q0_; }
  const Eigen::VectorXd& end() const { return q1_; }

 private:
  Eigen::VectorXd q0_, q1_;
  double T_ = 0.0, t_a_ = 0.0;  ///< duration, and of the acceleration (= of the deceleration)
  double sdot_ = 0.0, sddot_ = 0.0;  ///< the path's cruise rate and acceleration [1/s, 1/s^2]
};

}  // namespace kdl_space
