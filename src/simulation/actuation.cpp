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

}  // namespace kdl_space
