// JointMove: the path parameter's trapezoid (or triangle, when the move is too short to cruise).
#include "kdl_space/simulation/joint_move.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kdl_space/spatial/errors.hpp"

namespace kdl_space {

JointMove::JointMove(const Eigen::VectorXd& q0, const Eigen::VectorXd& q1, const std::vector<double>& rate_limits,
                     const std::vector<double>& acceleration_limits)
    : q0_(q0), q1_(q1) {
  const auto n = static_cast<std::size_t>(q0.size());
  if (static_cast<std::size_t>(q1.size()) != n || rate_limits.size() != n || acceleration_limits.size() != n)
    throw ModelError("JointMove: the start, the end and the limits must have one value per joint");
  if (!q0.allFinite() || !q1.allFinite()) throw ModelError("JointMove: the start and the end must be finite");
  sdot_ = sddot_ = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < n; ++j) {
    if (!(rate_limits[j] > 0.0) || !(acceleration_limits[j] > 0.0))
      throw ModelError("JointMove: joint " + std::to_string(j) + ": its rate and acceleration limits must be > 0");
    const double d = std::abs(q1(static_cast<Eigen::Index>(j)) - q0(static_cast<Eigen::Index>(j)));
    if (d == 0.0) continue;
    sdot_ = std::min(sdot_, rate_limits[j] / d);
    sddot_ = std::min(sddot_, acceleration_limits[j] / d);
  }
  if (!std::isfinite(sddot_)) {  // nothing moves (or every limit is infinite)
    sdot_ = sddot_ = 0.0;
    return;
  }
  if (!std::isfinite(sdot_) || sdot_ * sdot_ / sddot_ >= 1.0) {  // a triangle: it never cruises
    t_a_ = std::sqrt(1.0 / sddot_);
    sdot_ = sddot_ * t_a_;
    T_ = 2.0 * t_a_;
  } else {
    t_a_ = sdot_ / sddot_;
    T_ = 1.0 / sdot_ + t_a_;
  }
}

void JointMove::at(double t, Eigen::VectorXd& q, Eigen::VectorXd& qdot) const {
  t = std::clamp(t, 0.0, T_);
  double s = 1.0, v = 0.0;
  if (T_ > 0.0) {
    if (t < t_a_) {
      s = 0.5 * sddot_ * t * t;
      v = sddot_ * t;
    } else if (t <= T_ - t_a_) {
      s = 0.5 * sddot_ * t_a_ * t_a_ + sdot_ * (t - t_a_);
      v = sdot_;
    } else {
      const double r = T_ - t;
      s = 1.0 - 0.5 * sddot_ * r * r;
      v = sddot_ * r;
    }
  }
  q = t >= T_ ? q1_ : Eigen::VectorXd(q0_ + s * (q1_ - q0_));  // the end exactly at the end
  qdot = v * (q1_ - q0_);
}

}  // namespace kdl_space
