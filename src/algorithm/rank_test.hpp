// The rank test of a hand's Jacobian J (6 x n, n >= 6), shared by the inverse kinematics and the
// self-motion: every singular value of J is above sigma exactly when J J^T - sigma^2 E (= R^T R -
// sigma^2 E, J^T = Q R) is positive definite, which a 6 x 6 Cholesky decides (an eigensolver cost
// a fifth of a plan).
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>

namespace kdl_space::detail {

/// Every singular value of J above sqrt(sigma2), from J J^T.
inline bool gramAbove(Eigen::Matrix<double, 6, 6> JJt, double sigma2) {
  JJt.diagonal().array() -= sigma2;
  return Eigen::LLT<Eigen::Matrix<double, 6, 6>>(JJt).info() == Eigen::Success;
}

/// Every singular value of J above sqrt(sigma2), R the 6 x 6 upper triangle of J^T = Q R.
inline bool singularValuesAbove(const Eigen::Matrix<double, 6, 6>& R, double sigma2) {
  return gramAbove(R.transpose() * R, sigma2);
}

/// J's smallest singular value above `ratio` times its Frobenius norm (which lies between its
/// largest and sqrt(6) times that).
inline bool wellConditioned(const Eigen::Matrix<double, 6, 6>& R, double ratio) {
  return singularValuesAbove(R, ratio * ratio * R.squaredNorm());
}

}  // namespace kdl_space::detail
