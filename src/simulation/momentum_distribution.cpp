// The post-capture law momentum_distribution (simulation/actuation.hpp, MomentumDistribution):
// the reactionless joint rates that keep the base from turning while the links hold the stack's
// angular momentum, after Dimitrov and Yoshida's bias momentum approach.
#include <Eigen/Eigenvalues>
#include <cmath>

#include "kdl_space/simulation/simulation.hpp"

namespace kdl_space {

void Simulator::setMomentumDistribution(const MomentumDistribution& law) {
  const unsigned int n = model().nj();
  if (law.on) {
    if (law.joints.size() != n || law.rate_limit.size() != n)
      throw ModelError("simulation: momentum_distribution: one flag and one rate limit per joint (" +
                       std::to_string(n) + " joints)");
    if (!std::isfinite(law.unload_gain) || law.unload_gain < 0.0)
      throw ModelError("simulation: momentum_distribution: the unload gain must be finite and >= 0");
    if (!std::isfinite(law.bandwidth) || !(law.bandwidth > 0.0))
      throw ModelError("simulation: momentum_distribution: the servos' bandwidth must be finite and > 0");
    if (options_.grounded)
      throw ModelError("simulation: momentum_distribution: the base is grounded (held still): nothing to keep from turning");
    bool any = false;
    for (unsigned int j = 0; j < n; ++j) {
      if (!law.joints[j]) continue;
      any = true;
      if (controls_[j].mode != JointControl::Mode::PD)
        throw ModelError("simulation: momentum_distribution: joint '" + model().jointNames()[j] +
                         "' is no PD servo (the law drives the servos' rates)");
      if (!(law.rate_limit(j) > 0.0))
        throw ModelError("simulation: momentum_distribution: joint '" + model().jointNames()[j] +
                         "': its rate limit must be > 0");
    }
    if (!any) throw ModelError("simulation: momentum_distribution: it drives no joint");
  }
  distribution_ = law;
  distribution_rates_.setZero(n);
  distribution_gain_.setZero(n);
  distribution_A_.setZero(3, n);
  unit_velocity_ = FloatingVelocity(model());
}

int Simulator::distributionGains(const SimulationState& s) {
  // H*_jj, the inertia joint j meets with the others held and the base free: twice the kinetic
  // energy of a unit rate with the base moving as the zero momentum makes it (eq. 2).
  if (const int rc = forwardKinematics(*model_, s.state, kin_)) return rc;
  for (unsigned int j = 0; j < model().nj(); ++j) {
    if (!distribution_.joints[j]) continue;
    unit_velocity_.qdot(j) = 1.0;
    int rc = momentum_.baseTwist(kin_, Vector6d::Zero(), unit_velocity_.qdot, unit_velocity_.base_twist);
    if (rc == E_NOERROR) rc = momentum_.compute(kin_, unit_velocity_);
    unit_velocity_.qdot(j) = 0.0;
    unit_velocity_.base_twist = KDL::Twist::Zero();
    if (rc) return rc;
    distribution_gain_(j) = distribution_.bandwidth * 2.0 * momentum_.kineticEnergy();
  }
  return E_NOERROR;
}

int Simulator::distributionRates() {
  const unsigned int n = model().nj();
  const Vector3d& r_g = kin_.r_g;
  L_g_ = h_links_.tail<3>() - r_g.cross(h_links_.head<3>());
  // A_w column by column: the angular momentum about r_g of a unit rate with the base still.
  Vector3d b = L_g_;  // what the driven joints must hold: L_g less what the others' rates hold
  for (unsigned int j = 0; j < n; ++j) {
    const double rate = scratch_.velocity.qdot(j);
    if (!distribution_.joints[j] && rate == 0.0) continue;
    unit_velocity_.qdot(j) = 1.0;
    const int rc = momentum_.compute(kin_, unit_velocity_);
    unit_velocity_.qdot(j) = 0.0;
    if (rc) return rc;
    const Vector6d& h = momentum_.momentum();
    const Vector3d column = h.tail<3>() - r_g.cross(h.head<3>());
    if (distribution_.joints[j]) distribution_A_.col(j) = column;
    else b -= column * rate;
  }
  // qdot_d = A^T (A A^T + lambda^2 E)^-1 b: the least-norm solution, damped only where the
  // smallest singular value of A falls below 1e-2 of the largest.
  const Matrix3d AAt = distribution_A_ * distribution_A_.transpose();
  const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(AAt);
  const Vector3d s = eig.eigenvalues().cwiseMax(0.0);  // sigma^2, ascending
  const double floor = 1e-4 * s(2);                    // (1e-2 sigma_max)^2
  Vector3d inv = Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    const double damping = s(k) < floor ? floor - s(k) : 0.0;  // sigma^2 + lambda^2 >= (1e-2 sigma_max)^2
    if (s(2) > 0.0) inv(k) = 1.0 / (s(k) + damping);
  }
  const Vector3d y = eig.eigenvectors() * inv.asDiagonal() * (eig.eigenvectors().transpose() * b);
  distribution_rates_.noalias() = distribution_A_.transpose() * y;
  double scale = 1.0;
  for (unsigned int j = 0; j < n; ++j)
    if (distribution_.joints[j] && std::abs(distribution_rates_(j)) > distribution_.rate_limit(j))
      scale = std::min(scale, distribution_.rate_limit(j) / std::abs(distribution_rates_(j)));
  distribution_rates_ *= scale;
  return distribution_rates_.allFinite() ? E_NOERROR : E_NOT_FINITE;
}

int Simulator::reactionlessRates(const SimulationState& s, Eigen::VectorXd& qdot_d) {
  if (!distribution_.on) return E_BAD_ARGUMENT;
  const unsigned int n = model().nj();
  if (s.state.q.rows() != n || s.velocity.qdot.rows() != n) return E_SIZE_MISMATCH;
  double T;
  Vector6d h_O;
  if (const int rc = energyAndMomentum(s, T, h_O)) return rc;
  pack(s, h_O, x_tmp_);
  if (const int rc = unpack(x_tmp_, s.t, scratch_)) return rc;
  if (const int rc = distributionRates()) return rc;
  qdot_d = distribution_rates_;
  return E_NOERROR;
}

}  // namespace kdl_space
