#include "kdl_space/algorithm/dense_forward_dynamics.hpp"

#include "algorithm/set_up.hpp"

namespace kdl_space {
namespace {

/// The sizes and finiteness of CartToJnt's inputs: 0 or the code.
int inputs(const FloatingModel& m, const FloatingVelocity& velocity, const KDL::JntArray& tau,
           const std::vector<KDL::Wrench>& f_ext, const FloatingAcceleration& acceleration) {
  const unsigned int n = m.nj();
  if (velocity.qdot.rows() != n || tau.rows() != n || acceleration.qddot.rows() != n ||
      (!f_ext.empty() && f_ext.size() != m.bodies().size()))
    return E_SIZE_MISMATCH;
  if (!velocity.qdot.data.allFinite() || !tau.data.allFinite() || !toEigen(velocity.base_twist).allFinite())
    return E_NOT_FINITE;
  for (const KDL::Wrench& f : f_ext)
    if (!toEigen(f).allFinite()) return E_NOT_FINITE;
  return E_NOERROR;
}

}  // namespace

DenseForwardDynamicsSolver::DenseForwardDynamicsSolver(std::shared_ptr<const FloatingModel> model) : solver_(std::move(model)) {
  const std::size_t nb = this->model().bodies().size();
  const unsigned int n = this->model().nj();
  locked_.assign(n, false);
  V_.resize(nb);
  A_.resize(nb);
  F_.resize(nb);
  c_.setZero(6 + n);
  rhs_.setZero(6 + n);
  M_.setZero(6 + n, 6 + n);
  M_llt_.compute(Eigen::MatrixXd::Identity(6 + n, 6 + n));  // sized
}

void DenseForwardDynamicsSolver::setGravity(const Vector3d& g) {
  detail::checkGravity(g, "DenseForwardDynamicsSolver");
  gravity_ = g;
}

void DenseForwardDynamicsSolver::setLocked(const std::vector<bool>& locked) {
  detail::checkLocked(model(), locked, false, "DenseForwardDynamicsSolver");
  locked_ = locked;  // the same size: no allocation (the Simulator changes the brakes in a run)
}

int DenseForwardDynamicsSolver::CartToJnt(const State& state, const FloatingVelocity& velocity, const KDL::JntArray& tau,
                                    const std::vector<KDL::Wrench>& f_ext, FloatingAcceleration& acceleration) {
  if (const int rc = inputs(model(), velocity, tau, f_ext, acceleration)) return rc;
  if (const int rc = solver_.compute(state)) return rc;
  return solve(toEigen(state.world_T_base.p), velocity, tau, f_ext, acceleration);
}

int DenseForwardDynamicsSolver::CartToJnt(const Kinematics& kin, const FloatingVelocity& velocity, const KDL::JntArray& tau,
                                    const std::vector<KDL::Wrench>& f_ext, FloatingAcceleration& acceleration) {
  if (const int rc = inputs(model(), velocity, tau, f_ext, acceleration)) return rc;
  if (const int rc = solver_.compute(kin)) return rc;
  return solve(kin.p_b, velocity, tau, f_ext, acceleration);
}

int DenseForwardDynamicsSolver::solve(const Vector3d& p_b, const FloatingVelocity& velocity, const KDL::JntArray& tau,
                                const std::vector<KDL::Wrench>& f_ext, FloatingAcceleration& acceleration) {
  const std::vector<Body>& bodies = model().bodies();
  const unsigned int n = model().nj();
  const FreeFloatingSolver& k = solver_;
  const Vector3d& P = k.r_g();  // the fixed point of this instant
  if (grounded_ && toEigen(velocity.base_twist) != Vector6d::Zero()) return E_BAD_ARGUMENT;

  // Newton-Euler with zero accelerations: velocity products, gravity, external wrenches.
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const Body& b = bodies[i];
    if (b.parent < 0) {
      V_[i] = shiftTwist(toEigen(velocity.base_twist), P - p_b);
      A_[i] << -gravity_, Vector3d::Zero();  // gravity as an acceleration of the frame
    } else {
      V_[i] = V_[b.parent];
      A_[i] = A_[b.parent];
      if (b.joint >= 0) {
        const Vector6d Sqd = k.bodyJointTwist(static_cast<int>(i)) * velocity.qdot(b.joint);
        V_[i] += Sqd;
        A_[i] += crossMotion(V_[i], Sqd);
      }
    }
    const Matrix6d& I = k.bodyInertia(static_cast<int>(i));
    F_[i] = I * A_[i] + crossForce(V_[i], I * V_[i]);
    if (!f_ext.empty()) {
      const Vector3d f = toEigen(f_ext[i].force);
      const Vector3d o = toEigen(k.bodyPose(static_cast<int>(i)).p);
      F_[i].head<3>() -= f;
      F_[i].tail<3>() -= toEigen(f_ext[i].torque) + (o - P).cross(f);  // moment moved to P
    }
  }
  c_.setZero();  // a coordinate sums over the joints it moves (mimic)
  for (std::size_t i = bodies.size(); i-- > 1;) {
    F_[bodies[i].parent] += F_[i];
    if (bodies[i].joint >= 0) c_(6 + bodies[i].joint) += k.bodyJointTwist(static_cast<int>(i)).dot(F_[i]);
  }
  c_.head<6>() = F_[0];

  // [[M_a, A_m], [A_m^T, H]] at the CoM; locked joints held (row and column replaced).
  M_.topLeftCorner<6, 6>() = k.M_a();
  M_.topRightCorner(6, n) = k.A_m();
  M_.bottomLeftCorner(n, 6) = k.A_m().transpose();
  M_.bottomRightCorner(n, n) = k.H().data;
  rhs_.head<6>() = -c_.head<6>();
  rhs_.tail(n) = tau.data - c_.tail(n);
  const auto hold = [&](Eigen::Index k) {
    M_.row(k).setZero();
    M_.col(k).setZero();
    M_(k, k) = 1.0;
    rhs_(k) = 0.0;
  };
  for (unsigned int j = 0; j < n; ++j)
    if (locked_[j]) hold(6 + j);
  if (grounded_)  // the base's true acceleration is zero (gravity is in the bias)
    for (Eigen::Index k = 0; k < 6; ++k) hold(k);
  M_llt_.compute(M_);
  if (M_llt_.info() != Eigen::Success) return E_NOT_POSITIVE_DEFINITE;
  M_llt_.solveInPlace(rhs_);
  if (!rhs_.allFinite()) return E_NOT_FINITE;

  // Base: spatial acceleration at P -> acceleration of the base origin.
  const Vector6d a_g = rhs_.head<6>();
  const Vector3d w = toEigen(velocity.base_twist.rot), v_b = toEigen(velocity.base_twist.vel);
  Vector6d base;
  base.head<3>() = a_g.head<3>() + a_g.tail<3>().cross(p_b - P) + w.cross(v_b);
  base.tail<3>() = a_g.tail<3>();
  if (!base.allFinite()) return E_NOT_FINITE;
  acceleration.base = base;
  acceleration.qddot.data = rhs_.tail(n);
  return E_NOERROR;
}

}  // namespace kdl_space
