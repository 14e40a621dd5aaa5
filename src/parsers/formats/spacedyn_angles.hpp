// SpaceDyn's angles (rpy2dc.m): rpy2dc(a, b, c)' = Rx(a) Ry(b) Rz(c), the rotation a link frame
// makes with its parent's (Qi), an end point's with its link's (Qe), the base's with the world (Q0).
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace kdl_space::formats {

/// Rx(a) Ry(b) Rz(c).
inline Eigen::Matrix3d spaceDynRotation(const Eigen::Vector3d& abc);

/// \brief (a, b, c) with R = Rx(a) Ry(b) Rz(c), b in [-pi/2, pi/2], whose rotation is R to round-off
/// even near b = +-pi/2 (where a and c are each ill-determined): a from R's last column, b, then c
/// from what is left, Rz(c) = (Rx(a) Ry(b))^T R.
inline Eigen::Vector3d spaceDynAngles(const Eigen::Matrix3d& R) {
  const double a = std::atan2(-R(1, 2), R(2, 2));
  const double b = std::atan2(R(0, 2), std::hypot(R(1, 2), R(2, 2)));
  const Eigen::Matrix3d rest = spaceDynRotation(Eigen::Vector3d(a, b, 0.0)).transpose() * R;
  return {a, b, std::atan2(rest(1, 0), rest(0, 0))};
}

inline Eigen::Matrix3d spaceDynRotation(const Eigen::Vector3d& abc) {
  auto axis = [](int i, double t) {
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    R(j, j) = std::cos(t), R(j, k) = -std::sin(t), R(k, j) = std::sin(t), R(k, k) = std::cos(t);
    return R;
  };
  return axis(0, abc(0)) * axis(1, abc(1)) * axis(2, abc(2));
}

}  // namespace kdl_space::formats
