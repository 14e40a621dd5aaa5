#include "kdl_space/simulation/rigid_motion.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace kdl_space {

namespace {
Matrix3d rotationOf(const Eigen::Vector4d& q) {
  return Eigen::Quaterniond(q(3), q(0), q(1), q(2)).toRotationMatrix();
}
}  // namespace

FreeRigidMotion::FreeRigidMotion(const RigidTarget& at_zero, double grid_step, std::size_t max_checkpoints)
    : start_(at_zero), grid_step_(grid_step), max_checkpoints_(max_checkpoints) {
  if (max_checkpoints < 2) throw ModelError("FreeRigidMotion: max_checkpoints must be at least 2");
  if (!(at_zero.mass > 0.0) || !std::isfinite(at_zero.mass)) throw ModelError("FreeRigidMotion: the mass must be finite and > 0");
  if (!at_zero.inertia.allFinite() || !at_zero.com.allFinite() || !at_zero.twist.allFinite() || !allFinite(at_zero.pose))
    throw ModelError("FreeRigidMotion: the inertia, CoM, pose and twist must be finite");
  if (!(grid_step > 0.0) || !std::isfinite(grid_step)) throw ModelError("FreeRigidMotion: the grid step must be finite and > 0");
  const Eigen::LLT<Matrix3d> llt(at_zero.inertia);
  if (llt.info() != Eigen::Success || !at_zero.inertia.isApprox(at_zero.inertia.transpose(), 1e-12))
    throw ModelError("FreeRigidMotion: the inertia must be symmetric positive definite");
  I_inv_ = llt.solve(Matrix3d::Identity());
  const Matrix3d R = toEigen(at_zero.pose.M);
  L_ = R * at_zero.inertia * R.transpose() * at_zero.twist.tail<3>();
  Eigen::Vector4d q;
  at_zero.pose.M.GetQuaternion(q(0), q(1), q(2), q(3));
  checkpoints_.push_back(q);
  last_q_ = q;
}

Eigen::Vector4d FreeRigidMotion::gridPoint(std::size_t k) {
  // From the last point reached when it is on the way, else from the checkpoint below k.
  const std::size_t below = std::min(k / stride_, checkpoints_.size() - 1);
  if (last_k_ > k || below * stride_ > last_k_) {
    last_k_ = below * stride_;
    last_q_ = checkpoints_[below];
  }
  while (last_k_ < k) {
    last_q_ = step(last_q_, grid_step_);
    ++last_k_;
    if (last_k_ % stride_ == 0 && last_k_ / stride_ == checkpoints_.size()) {
      checkpoints_.push_back(last_q_);
      if (checkpoints_.size() > max_checkpoints_) {  // every other one kept: the stride doubles
        for (std::size_t j = 0; 2 * j < checkpoints_.size(); ++j) checkpoints_[j] = checkpoints_[2 * j];
        checkpoints_.resize((checkpoints_.size() + 1) / 2);
        stride_ *= 2;
      }
    }
  }
  return last_q_;
}

Eigen::Vector4d FreeRigidMotion::step(const Eigen::Vector4d& q, double h) const {
  // dq/dt = 1/2 (0, w) (x) q with w = R I^-1 R^T L (world angular velocity: left product)
  const auto rate = [this](const Eigen::Vector4d& x) {
    const Matrix3d R = rotationOf(x);
    const Vector3d w = R * (I_inv_ * (R.transpose() * L_));
    const Eigen::Quaterniond d = Eigen::Quaterniond(0.0, w.x(), w.y(), w.z()) * Eigen::Quaterniond(x(3), x(0), x(1), x(2));
    return Eigen::Vector4d(0.5 * d.x(), 0.5 * d.y(), 0.5 * d.z(), 0.5 * d.w());
  };
  const Eigen::Vector4d k1 = rate(q), k2 = rate(q + 0.5 * h * k1), k3 = rate(q + 0.5 * h * k2), k4 = rate(q + h * k3);
  return (q + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)).normalized();
}

int FreeRigidMotion::at(double t, RigidTarget& target) {
  if (!std::isfinite(t)) return E_NOT_FINITE;
  if (t < 0.0) return E_BAD_ARGUMENT;
  const double grid_index = std::floor(t / grid_step_);
  if (!(grid_index < 9.0e15)) return E_BAD_ARGUMENT;  // beyond the grid's exact integers
  const auto k = static_cast<std::size_t>(grid_index);
  const Eigen::Vector4d q = step(gridPoint(k), t - static_cast<double>(k) * grid_step_);
  const Matrix3d R = rotationOf(q);
  const Vector3d w = R * (I_inv_ * (R.transpose() * L_));
  const Vector3d c = toEigen(start_.pose * toKDL(start_.com)) + t * start_.twist.head<3>();  // CoM, world
  RigidTarget out = start_;
  out.pose.M = KDL::Rotation::Quaternion(q(0), q(1), q(2), q(3));
  out.pose.p = toKDL(c - R * start_.com);
  out.twist.tail<3>() = w;
  target = out;
  return E_NOERROR;
}

}  // namespace kdl_space
