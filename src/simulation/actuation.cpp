#include "kdl_space/simulation/actuation.hpp"

namespace kdl_space {
namespace {

/// x limited to +-limit per component in the axes of R (world -> R^T x -> clamp -> R).
Vector3d limitInAxes(const Vector3d& x, const Matrix3d& R, const Vector3d& limit, bool& saturated) {
  const Vector3d local = R.transpose() * x;
  const Vector3d clamped = local.cwiseMax(-limit).cwiseMin(limit);
  saturated = saturated || clamped != local;
  return R * clamped;
}

}  // namespace

Vector6d baseControlWrench(const BaseControl& control, const KDL::Frame& world_T_base, const KDL::Twist& base_twist,
                           bool* saturated) {
  const Matrix3d R = toEigen(world_T_base.M);
  bool limited = false;
  Vector6d w = Vector6d::Zero();
  if (control.attitude.on) {
    const BaseControl::Attitude& a = control.attitude;
    const Vector3d e = toEigen((a.set_point * world_T_base.M.Inverse()).GetRot());  // rotation vector, world axes
    w.tail<3>() = limitInAxes(a.kp * e - a.kd * toEigen(base_twist.rot), R, a.torque_limit, limited);
  }
  if (control.position.on) {
    const BaseControl::Position& p = control.position;
    const Vector3d f = p.kp * (p.set_point - toEigen(world_T_base.p)) - p.kd * toEigen(base_twist.vel);
    w.head<3>() = limitInAxes(f, R, p.force_limit, limited);
  }
  if (saturated) *saturated = limited;
  return w;
}

void wheelTorques(const ReactionWheels& wheels, const Eigen::MatrixXd& split, const Matrix3d& R, const Vector3d& n,
                  const Eigen::VectorXd& h, Eigen::VectorXd& u, bool& saturated) {
  u.noalias() = -split * (R.transpose() * n);
  for (Eigen::Index i = 0; i < wheels.count(); ++i) {
    const double limit = wheels.torque_limit(i);
    if (std::abs(u(i)) > limit) {
      u(i) = std::copysign(limit, u(i));
      saturated = true;
    }
    if (std::abs(h(i)) >= wheels.capacity(i) && u(i) * h(i) > 0.0) {  // at its top speed
      u(i) = 0.0;
      saturated = true;
    }
  }
}

Vector3d wheelReaction(const ReactionWheels& wheels, const Matrix3d& R, const Vector3d& w, const Eigen::VectorXd& h,
                       const Eigen::VectorXd& u) {
  return -R * (wheels.axes * u) - w.cross(R * (wheels.axes * h));
}

}  // namespace kdl_space
