// The grasp's load by a second route (tests of graspWrench, issue 39): minus the rate of the held
// target's momentum, by a central difference along the motion's tangent at a sample. The
// target's momentum sums its bodies' (and a merged payload's) m v_c and I_c w + c x m v_c, with
// each body's point twist from the momentum solver (eq. 4), not from graspWrench's recursion; the
// accelerations are the articulated-body solver's at the sample's torques. Only for a motion with
// no external wrench on the target (no gravity, no scheduled wrench on it).
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "kdl_space/algorithm/forward_dynamics.hpp"
#include "kdl_space/algorithm/grasp_wrench.hpp"
#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/operation/motion_sample.hpp"

namespace kdl_space::test {

/// The held target's momentum (P; L about the world origin) at a state and velocity.
inline Vector6d heldMomentum(const std::shared_ptr<const FloatingModel>& model, const HeldTarget& held,
                             const State& state, const FloatingVelocity& v) {
  Kinematics kin(*model);
  EXPECT_EQ(forwardKinematics(*model, state, kin), E_NOERROR);
  MomentumSolver momentum(model);
  EXPECT_EQ(momentum.compute(kin, v), E_NOERROR);
  Vector6d h = Vector6d::Zero();
  const auto add = [&](int i, double m, const Vector3d& com_in_body, const Matrix3d& I_world) {
    Vector6d t;
    EXPECT_EQ(momentum.contactTwist(Contact{i, toKDL(com_in_body)}, t), E_NOERROR);
    const Vector3d c = kin.R[i] * com_in_body + kin.p[i];
    h.head<3>() += m * t.head<3>();
    h.tail<3>() += I_world * t.tail<3>() + c.cross(m * t.head<3>());
  };
  for (std::size_t i = 0; i < model->bodies().size(); ++i) {
    const Body& b = model->bodies()[i];
    if (held.bodies[i]) add(static_cast<int>(i), b.mass, b.com, kin.I_com[i]);
    if (static_cast<int>(i) == held.payload_body)
      add(static_cast<int>(i), held.payload_mass, held.payload_com,
          kin.R[i] * held.payload_I_com * kin.R[i].transpose());
  }
  return h;
}

/// The wrench on the robot at its contact point, -(d/dt of the held momentum) with the moment
/// moved from the world origin, by a central difference of step eps [s] along the tangent
/// (pose, q, twist, qdot) + s (twist, qdot, accelerations) at sample x (O(eps^2)).
inline Vector6d graspWrenchByMomentumRate(const std::shared_ptr<const FloatingModel>& model, const HeldTarget& held,
                                          const MotionSample& x, double eps = 1e-4) {
  const unsigned int n = model->nj();
  State state(*model);
  state.world_T_base = KDL::Frame(KDL::Rotation::Quaternion(x.quat(0), x.quat(1), x.quat(2), x.quat(3)), toKDL(x.p));
  state.q.data = x.q;
  FloatingVelocity v;
  v.base_twist = toTwist(x.twist);
  v.qdot = KDL::JntArray(n);
  v.qdot.data = x.qd;
  KDL::JntArray tau(n);
  tau.data = x.tau;
  ForwardDynamicsSolver dynamics(model);
  FloatingAcceleration a;
  a.qddot = KDL::JntArray(n);
  EXPECT_EQ(dynamics.CartToJnt(state, v, tau, {}, a), E_NOERROR);
  const auto along = [&](double s) {
    State st = state;
    st.world_T_base.p += toKDL(s * x.twist.head<3>());
    // exp(s [w]) R by Eigen: KDL::Rot returns the identity below an angle of 1e-6 rad
    const Vector3d turn = s * x.twist.tail<3>();
    const Matrix3d R = (turn.norm() > 0.0 ? Eigen::AngleAxisd(turn.norm(), turn.normalized()).toRotationMatrix()
                                          : Matrix3d::Identity()) *
                       toEigen(state.world_T_base.M);
    st.world_T_base.M = KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2));
    st.q.data += s * x.qd;
    FloatingVelocity vs = v;
    vs.base_twist = toTwist(x.twist + s * a.base);
    vs.qdot.data += s * a.qddot.data;
    return heldMomentum(model, held, st, vs);
  };
  const Vector6d rate = (along(eps) - along(-eps)) / (2.0 * eps);
  Kinematics kin(*model);
  EXPECT_EQ(forwardKinematics(*model, state, kin), E_NOERROR);
  const Vector3d c = kin.point(held.contact);
  Vector6d w;
  w.head<3>() = -rate.head<3>();
  w.tail<3>() = -rate.tail<3>() + c.cross(rate.head<3>());
  return w;
}

}  // namespace kdl_space::test
