// The post-capture law impedance (simulation/actuation.hpp, GraspImpedance): the arm as a
// spring-damper at the grasp, its force limited to the grasp's.
#include <Eigen/Cholesky>
#include <cmath>

#include "kdl_space/simulation/simulation.hpp"
#include "simulation/dynamics.hpp"

namespace kdl_space {

void Simulator::setGraspImpedance(const GraspImpedance& law) {
  const unsigned int n = model().nj();
  if (law.on) {
    const auto fail = [](const std::string& why) { throw ModelError("simulation: impedance: " + why); };
    if (law.joints.size() != n) fail("one flag per joint (" + std::to_string(n) + " joints)");
    if (law.contact.body < 0 || law.contact.body >= static_cast<int>(model().bodies().size()) || !allFinite(law.contact.offset))
      fail("the contact is not on the model");
    if (!law.stiffness.allFinite() || !law.damping.allFinite() || (law.stiffness.array() < 0.0).any() ||
        (law.damping.array() < 0.0).any())
      fail("the stiffness and damping must be finite and >= 0");
    if (!(law.damping.maxCoeff() > 0.0)) fail("it needs some damping (translation or rotation)");
    if (!(law.max_force > 0.0) || !(law.max_moment > 0.0)) fail("the grasp's limits must be > 0");
    if (distribution_.on) fail("momentum_distribution drives the same servos");
    bool any = false;
    for (unsigned int j = 0; j < n; ++j) {
      if (!law.joints[j]) continue;
      any = true;
      if (controls_[j].mode != JointControl::Mode::PD)
        fail("joint '" + model().jointNames()[j] + "' is no PD servo (the law replaces the servos)");
    }
    if (!any) fail("it drives no joint");
  }
  impedance_ = law;
  impedance_J_.setZero(6, n);
  impedance_B_.setZero(6, n);
  impedance_rest_ = FloatingVelocity(model());
  impedance_unit_ = KDL::JntArray(n);
  impedance_acc_.qddot = KDL::JntArray(n);
  impedance_tau_.setZero(n);
  impedance_kdq_.setZero(n);
  impedance_along_.setZero(n);
}

int Simulator::impedanceStart(const SimulationState& s) {
  if (const int rc = forwardKinematics(*model_, s.state, kin_)) return rc;
  const int c = impedance_.contact.body;
  impedance_R0_ = kin_.R[0].transpose() * kin_.R[c];
  impedance_p0_ = kin_.R[0].transpose() * (kin_.point(impedance_.contact) - kin_.p_b);
  return E_NOERROR;
}

int Simulator::impedanceTorques(const KDL::JntArray& qdot) {
  // J: each joint on the path from the contact's body to the base, its unit twist moved to the
  // contact point (a mimic joint adds to its leader's column); the driven joints' columns are the law's.
  const int c = impedance_.contact.body;
  const Vector3d x = kin_.point(impedance_.contact);
  impedance_J_.setZero();
  for (int b = c; b > 0; b = model().bodies()[b].parent) {
    const int j = model().bodies()[b].joint;
    if (j < 0) continue;
    const Vector6d& S = kin_.S[b];
    impedance_J_.col(j).head<3>() += S.head<3>() + S.tail<3>().cross(x - kin_.p_b);
    impedance_J_.col(j).tail<3>() += S.tail<3>();
  }
  // B: the hand's acceleration from rest per unit torque of each driven joint (the base free),
  // less that of no torque (gravity's, on a test bed).
  static const std::vector<KDL::Wrench> none;
  const auto hand = [&](int j, Vector6d& out) {
    if (j >= 0) impedance_unit_(j) = 1.0;
    const int rc = dynamics_->CartToJnt(kin_, impedance_rest_, impedance_unit_, none, impedance_acc_);
    if (j >= 0) impedance_unit_(j) = 0.0;
    const Vector6d& a = impedance_acc_.base;  // at rest: the base origin's acceleration; the angular one
    out.head<3>() = a.head<3>() + a.tail<3>().cross(x - kin_.p_b);
    out.tail<3>() = a.tail<3>();
    out.noalias() += impedance_J_ * impedance_acc_.qddot.data;
    return rc;
  };
  Vector6d drift;
  if (const int rc = hand(-1, drift)) return rc;
  impedance_B_.setZero();
  for (unsigned int j = 0; j < model().nj(); ++j) {
    if (!impedance_.joints[j]) continue;
    Vector6d a;
    if (const int rc = hand(static_cast<int>(j), a)) return rc;
    impedance_B_.col(j) = a - drift;
  }
  for (unsigned int j = 0; j < model().nj(); ++j)
    if (!impedance_.joints[j]) impedance_J_.col(j).setZero();
  // e: the contact frame's displacement from its start relative to the base, in world axes.
  const Matrix3d& Rb = kin_.R[0];
  const Matrix3d R_rel = Rb.transpose() * kin_.R[c];
  const Eigen::AngleAxisd turn(R_rel * impedance_R0_.transpose());
  Vector6d e;
  e.head<3>() = (x - kin_.p_b) - Rb * impedance_p0_;
  e.tail<3>() = Rb * (turn.angle() * turn.axis());
  const Vector6d v = impedance_J_ * qdot.data;
  Vector6d F;
  F.head<3>() = -impedance_.stiffness(0) * e.head<3>() - impedance_.damping(0) * v.head<3>();
  F.tail<3>() = -impedance_.stiffness(1) * e.tail<3>() - impedance_.damping(1) * v.tail<3>();
  const double f = F.head<3>().norm(), m = F.tail<3>().norm();
  if (f > impedance_.max_force) F.head<3>() *= impedance_.max_force / f;  // the grasp's limit: yield
  if (m > impedance_.max_moment) F.tail<3>() *= impedance_.max_moment / m;
  impedance_tau_.noalias() = impedance_J_.transpose() * F;  // (workspaces: a run allocates nothing)
  // The self-motion's damping: -P Kd P qdot with P = I - B+ B (B+ = B^T (B B^T + eps)^-1, eps 1e-12
  // of its scale) over the driven joints: it dissipates, and B tau = 0: it accelerates no hand.
  Matrix6d BBt = impedance_B_ * impedance_B_.transpose();
  BBt.diagonal().array() += 1e-12 * (BBt.trace() + 1e-300);
  const Eigen::LDLT<Matrix6d> BBt_ldlt(BBt);
  const auto project = [&](Eigen::VectorXd& v) {  // v <- P v
    const Vector6d Bv = impedance_B_ * v;
    const Vector6d y = BBt_ldlt.solve(Bv);
    impedance_along_.noalias() = impedance_B_.transpose() * y;
    v -= impedance_along_;
  };
  for (unsigned int j = 0; j < model().nj(); ++j) impedance_kdq_(j) = impedance_.joints[j] ? qdot(j) : 0.0;
  project(impedance_kdq_);
  for (unsigned int j = 0; j < model().nj(); ++j) impedance_kdq_(j) *= impedance_.joints[j] ? controls_[j].kd : 0.0;
  project(impedance_kdq_);
  for (unsigned int j = 0; j < model().nj(); ++j)
    if (impedance_.joints[j]) tau_control_(j) = impedance_tau_(j) - impedance_kdq_(j);
  return E_NOERROR;
}

}  // namespace kdl_space
