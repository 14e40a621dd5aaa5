#include "kdl_space/algorithm/free_floating_solver.hpp"

#include <cmath>

#include "algorithm/set_up.hpp"

namespace kdl_space {
// The factorisations are sized here, constructed in place (assigning Eigen::LLT(n) would copy
// its uninitialised info member: undefined behaviour, reported by UBSan; factorising the identity
// to size them cost n^3 / 3 flops, seconds at thousands of joints).
// With Extent::Jacobians every n x n member stays 0 x 0.
FreeFloatingSolver::FreeFloatingSolver(std::shared_ptr<const FloatingModel> model, Extent extent)
    : model_(std::move(model)),
      extent_(extent),
      H_star_llt_(model_ && extent == Extent::Full ? static_cast<Eigen::Index>(model_->nj()) : 0),
      H_llt_(model_ && extent == Extent::Full ? static_cast<Eigen::Index>(model_->nj()) : 0) {
  if (!model_) throw ModelError("FreeFloatingSolver: null model");
  if (extent != Extent::Full && extent != Extent::Jacobians) throw ModelError("FreeFloatingSolver: no such extent");
  const std::size_t nb = model_->bodies().size();
  const unsigned int n = model_->nj();
  const unsigned int n_dense = extent == Extent::Full ? n : 0;
  world_T_body_.resize(nb);
  own_ = Kinematics(*model_);
  state_ = State(*model_);
  I_c_.resize(nb);
  I_body_.resize(nb);
  Sb_.assign(nb, Vector6d::Zero());
  A_m_.setZero(6, n);
  Am_work_.setZero(6, n);
  J_work_.setZero(6, n);
  X_work_.setZero(n, 6);
  dqdot_work_.setZero(n);
  H_.resize(n_dense);
  H_star_.resize(n_dense);
  if (extent == Extent::Full) reserveContacts(2);  // dual-arm without allocation
  locked_.assign(n, false);
  H_locked_work_.setZero(n_dense, n_dense);
}

void FreeFloatingSolver::setLocked(const std::vector<bool>& locked) {
  detail::checkLocked(*model_, locked, true, "FreeFloatingSolver");
  const unsigned int n = model_->nj();
  locked_.assign(n, false);
  for (std::size_t j = 0; j < locked.size(); ++j) locked_[j] = locked[j];
  any_locked_ = false;
  for (unsigned int j = 0; j < n; ++j) any_locked_ = any_locked_ || locked_[j];
  computed_ = false;  // the factorisations depend on the locks
  H_ok_ = false;
}

void FreeFloatingSolver::dropLocked(Eigen::Ref<Matrix6Xd> J) const {
  if (!any_locked_) return;
  for (Eigen::Index j = 0; j < J.cols(); ++j)
    if (locked_[j]) J.col(j).setZero();
}

int FreeFloatingSolver::compute(const State& state) {
  computed_ = false;
  H_ok_ = false;
  if (const int rc = forwardKinematics(*model_, state, own_)) return rc;
  return compute(own_);
}

int FreeFloatingSolver::compute(const Kinematics& kin) {
  computed_ = false;
  H_ok_ = false;
  const std::vector<Body>& bodies = model_->bodies();
  const unsigned int n = model_->nj();
  if (kin.model != model_.get() || kin.R.size() != bodies.size()) return E_SIZE_MISMATCH;
  if (!kin.valid) return E_NOT_COMPUTED;
  world_T_base_ = kin.state.world_T_base;
  const bool full = extent_ == Extent::Full;
  H_.data.setZero();
  for (std::size_t i = 0; i < bodies.size(); ++i) world_T_body_[i] = kin.pose(static_cast<int>(i));
  r_g_ = kin.r_g;

  // Spatial inertia of every body about r_g (world axes), then composites (children first).
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    I_body_[i] = spatialInertia(bodies[i].mass, kin.com[i] - r_g_, kin.I_com[i]);
    I_c_[i] = I_body_[i];
  }
  for (std::size_t i = bodies.size(); i-- > 1;) I_c_[bodies[i].parent] += I_c_[i];

  // Joint twists moved to r_g; A_m and H by the composite-rigid-body pass, body by body: a
  // coordinate that moves several joints (mimic) sums their terms (H = T^T H_joints T).
  for (std::size_t b = 1; b < bodies.size(); ++b)
    if (bodies[b].joint >= 0) Sb_[b] = shiftTwist(kin.S[b], r_g_ - kin.p_b);
  A_m_.setZero();
  for (std::size_t b = 1; b < bodies.size(); ++b) {
    const int j = bodies[b].joint;
    if (j < 0) continue;
    const Vector6d F = I_c_[b] * Sb_[b];  // momentum about r_g of the subtree moved by this joint
    A_m_.col(j) += F;
    if (!full) continue;  // Extent::Jacobians: A_m only
    H_(j, j) += Sb_[b].dot(F);
    for (int a = bodies[b].parent; a >= 0; a = bodies[a].parent) {
      const int k = bodies[a].joint;
      if (k < 0) continue;
      const double x = Sb_[a].dot(F);
      H_(k, j) += x;
      H_(j, k) += x;
    }
  }
  if (full)
    for (unsigned int j = 0; j < n; ++j) H_(j, j) += model_->armature()[j];

  I_g_ = I_c_[0].bottomRightCorner<3, 3>();  // eq. 3 (about r_g the coupling block vanishes)
  M_a_ = centroidInertia(w(), I_g_);          // eq. 12
  // Finite inputs of absurd magnitude (a base 1e300 m away) overflow here: refuse, not factorise.
  if (!r_g_.allFinite() || !I_g_.allFinite() || !H_.data.allFinite() || !A_m_.allFinite()) return E_NOT_FINITE;
  I_g_llt_.compute(I_g_);
  if (I_g_llt_.info() != Eigen::Success) return E_NOT_POSITIVE_DEFINITE;

  Am_work_ = A_m_;
  M_a_solveInPlace(Am_work_);
  if (!full) return finish(kin.state);
  H_star_.data = H_.data;
  H_star_.data.noalias() -= A_m_.transpose().lazyProduct(Am_work_);  // eq. 7
  symmetrize(H_star_.data);
  if (!H_star_.data.allFinite()) return E_NOT_FINITE;
  if (any_locked_) {
    // Braked coordinates removed: with their rows and columns those of the identity and their
    // Jacobian columns 0 (dropLocked), J_f H_ff^-1 J_f^T is J H'^-1 J^T and their jumps are 0.
    const auto unlock = [this](const Eigen::MatrixXd& M) {
      H_locked_work_ = M;
      for (Eigen::Index j = 0; j < M.rows(); ++j)
        if (locked_[j]) {
          H_locked_work_.row(j).setZero();
          H_locked_work_.col(j).setZero();
          H_locked_work_(j, j) = 1.0;
        }
    };
    unlock(H_.data);
    H_llt_.compute(H_locked_work_);
    H_ok_ = H_llt_.info() == Eigen::Success;
    unlock(H_star_.data);
    H_star_llt_.compute(H_locked_work_);
  } else {
    H_llt_.compute(H_.data);
    H_ok_ = H_llt_.info() == Eigen::Success;
    H_star_llt_.compute(H_star_.data);
  }
  if (H_star_llt_.info() != Eigen::Success) return E_NOT_POSITIVE_DEFINITE;
  return finish(kin.state);
}

int FreeFloatingSolver::finish(const State& state) {
  state_.world_T_base = state.world_T_base;
  state_.q.data = state.q.data;
  computed_ = true;
  return E_NOERROR;
}

int FreeFloatingSolver::readyDense(const Contact& h) const {
  if (const int rc = ready(h)) return rc;
  return extent_ == Extent::Full ? E_NOERROR : E_NOT_COMPUTED;
}

void FreeFloatingSolver::M_a_solveInPlace(Eigen::Ref<Matrix6Xd> x) const {
  x.topRows<3>() /= w();
  for (Eigen::Index c = 0; c < x.cols(); ++c) {  // column by column: fixed-size, no allocation
    const Vector3d angular = I_g_llt_.solve(Vector3d(x.col(c).tail<3>()));
    x.col(c).tail<3>() = angular;
  }
}

int FreeFloatingSolver::momentum(const KDL::Twist& base_twist, const KDL::JntArray& qdot,
                                 Vector6d& PL_g) const {
  if (!computed_) return E_NOT_COMPUTED;
  if (qdot.rows() != model_->nj()) return E_SIZE_MISMATCH;
  if (!allFinite(base_twist) || !qdot.data.allFinite()) return E_NOT_FINITE;
  const Vector6d y = shiftTwist(toEigen(base_twist), r_g_ - toEigen(world_T_base_.p));
  Vector6d PL;
  PL.noalias() = M_a_ * y + A_m_ * qdot.data;  // eq. 2
  if (!PL.allFinite()) return E_NOT_FINITE;
  PL_g = PL;
  return E_NOERROR;
}

int FreeFloatingSolver::baseTwist(const Vector6d& PL_g, const KDL::JntArray& qdot,
                                  KDL::Twist& base_twist) const {
  if (!computed_) return E_NOT_COMPUTED;
  if (qdot.rows() != model_->nj()) return E_SIZE_MISMATCH;
  if (!PL_g.allFinite() || !qdot.data.allFinite()) return E_NOT_FINITE;
  Vector6d y = PL_g - A_m_ * qdot.data;
  M_a_solveInPlace(y);
  y = shiftTwist(y, toEigen(world_T_base_.p) - r_g_);
  if (!y.allFinite()) return E_NOT_FINITE;
  base_twist = toTwist(y);
  return E_NOERROR;
}

int FreeFloatingSolver::kineticEnergy(const KDL::Twist& base_twist, const KDL::JntArray& qdot,
                                      double& T) const {
  if (!computed_ || extent_ != Extent::Full) return E_NOT_COMPUTED;
  if (qdot.rows() != model_->nj()) return E_SIZE_MISMATCH;
  if (!allFinite(base_twist) || !qdot.data.allFinite()) return E_NOT_FINITE;
  const Vector6d y = shiftTwist(toEigen(base_twist), r_g_ - toEigen(world_T_base_.p));
  double qHq = 0.0;  // q^T H q without a temporary
  for (Eigen::Index j = 0; j < H_.data.cols(); ++j) qHq += qdot(j) * H_.data.col(j).dot(qdot.data);
  const double energy = 0.5 * y.dot(M_a_ * y) + y.dot(A_m_ * qdot.data) + 0.5 * qHq;
  if (!std::isfinite(energy)) return E_NOT_FINITE;
  T = energy;
  return E_NOERROR;
}

int FreeFloatingSolver::ready(const Contact& h) const { return contactCode(computed_, h, model_->bodies().size()); }

int FreeFloatingSolver::contactPoint(const Contact& h, Vector3d& p_h) const {
  if (const int rc = ready(h)) return rc;
  const Vector3d p = toEigen(world_T_body_[h.body] * h.offset);
  if (!p.allFinite()) return E_NOT_FINITE;
  p_h = p;
  return E_NOERROR;
}

int FreeFloatingSolver::R_h(const Contact& h, Matrix6d& R) const {
  Vector3d p_h;
  if (const int rc = contactPoint(h, p_h)) return rc;
  const Vector3d r_gh = p_h - r_g_;
  if (!r_gh.allFinite()) return E_NOT_FINITE;
  R = transfer(r_gh);  // eq. 5
  return E_NOERROR;
}

void FreeFloatingSolver::fixedBaseJacobian(const Contact& h, Eigen::Ref<Matrix6Xd> J) const {
  const std::vector<Body>& bodies = model_->bodies();
  const Vector3d r_gh = toEigen(world_T_body_[h.body] * h.offset) - r_g_;
  J.setZero();
  for (int b = h.body; b >= 0; b = bodies[b].parent)
    if (bodies[b].joint >= 0) J.col(bodies[b].joint) += shiftTwist(Sb_[b], r_gh);
}

void FreeFloatingSolver::generalizedJacobian(const Contact& h, Eigen::Ref<Matrix6Xd> J_star) const {
  fixedBaseJacobian(h, J_star);
  const Vector3d r_gh = toEigen(world_T_body_[h.body] * h.offset) - r_g_;
  // J* = J - R_h M_a^-1 A_m (eq. 4); Am_work_ holds M_a^-1 A_m since compute().
  for (Eigen::Index j = 0; j < J_star.cols(); ++j) {
    const Vector6d x = Am_work_.col(j);
    J_star.col(j).head<3>() -= x.head<3>() - r_gh.cross(x.tail<3>());
    J_star.col(j).tail<3>() -= x.tail<3>();
  }
}

int FreeFloatingSolver::J(const Contact& h, KDL::Jacobian& J) {
  if (const int rc = ready(h)) return rc;
  if (J.columns() != model_->nj()) return E_SIZE_MISMATCH;
  fixedBaseJacobian(h, J_work_);
  if (!J_work_.allFinite()) return E_NOT_FINITE;
  J.data = J_work_;
  return E_NOERROR;
}

int FreeFloatingSolver::J_star(const Contact& h, KDL::Jacobian& J_star) {
  if (const int rc = ready(h)) return rc;
  if (J_star.columns() != model_->nj()) return E_SIZE_MISMATCH;
  generalizedJacobian(h, J_work_);
  if (!J_work_.allFinite()) return E_NOT_FINITE;
  J_star.data = J_work_;
  return E_NOERROR;
}

int FreeFloatingSolver::G_locked(const Contact& h, Matrix6d& G) const {
  Vector3d p_h;
  if (const int rc = contactPoint(h, p_h)) return rc;
  Matrix6d G_locked = rigidBodyG(w(), I_g_, p_h - r_g_);  // eq. 20: R_h M_a^-1 R_h^T
  symmetrize(G_locked);
  if (!G_locked.allFinite()) return E_NOT_FINITE;
  G = G_locked;
  return E_NOERROR;
}

int FreeFloatingSolver::G_star(const Contact& h, Matrix6d& G) {
  if (const int rc = readyDense(h)) return rc;
  Matrix6d G_star;
  if (const int rc = G_locked(h, G_star)) return rc;
  generalizedJacobian(h, J_work_);
  dropLocked(J_work_);
  X_work_ = J_work_.transpose();
  for (int c = 0; c < 6; ++c) H_star_llt_.solveInPlace(X_work_.col(c));  // vector solves: no allocation
  G_star.noalias() += J_work_.lazyProduct(X_work_);  // eq. 11
  symmetrize(G_star);
  if (!G_star.allFinite()) return E_NOT_FINITE;
  G = G_star;
  return E_NOERROR;
}

int FreeFloatingSolver::G_grounded(const Contact& h, Matrix6d& G) {
  if (const int rc = readyDense(h)) return rc;
  if (!H_ok_) return E_NOT_POSITIVE_DEFINITE;
  fixedBaseJacobian(h, J_work_);
  dropLocked(J_work_);
  X_work_ = J_work_.transpose();
  for (int c = 0; c < 6; ++c) H_llt_.solveInPlace(X_work_.col(c));
  Matrix6d G_grounded;
  G_grounded.noalias() = J_work_.lazyProduct(X_work_);  // eq. 22
  symmetrize(G_grounded);
  if (!G_grounded.allFinite()) return E_NOT_FINITE;
  G = G_grounded;
  return E_NOERROR;
}

int FreeFloatingSolver::handTwist(const Contact& h, const KDL::JntArray& qdot, const Vector6d& PL_g,
                                  KDL::Twist& t_h) {
  Matrix6d R;
  if (const int rc = R_h(h, R)) return rc;
  if (qdot.rows() != model_->nj()) return E_SIZE_MISMATCH;
  if (!qdot.data.allFinite() || !PL_g.allFinite()) return E_NOT_FINITE;
  generalizedJacobian(h, J_work_);
  Vector6d v_g = PL_g;
  M_a_solveInPlace(v_g);
  Vector6d t;
  t.noalias() = J_work_ * qdot.data;
  t.noalias() += R * v_g;  // eq. 4
  if (!t.allFinite()) return E_NOT_FINITE;
  t_h = toTwist(t);
  return E_NOERROR;
}

int FreeFloatingSolver::G(const Contact& h, Response response, Matrix6d& G) {
  switch (response) {
    case Response::FreeFloating: return G_star(h, G);
    case Response::Grounded: return G_grounded(h, G);
    case Response::JointsLocked: return G_locked(h, G);
  }
  return E_BAD_ARGUMENT;  // not one of the enumerators
}

int FreeFloatingSolver::velocityJump(const Contact& h, Response response, const Vector6d& F,
                                     Vector6d& dPL_g, KDL::JntArray& dqdot) {
  Matrix6d R;
  if (const int rc = R_h(h, R)) return rc;
  if (dqdot.rows() != model_->nj()) return E_SIZE_MISMATCH;
  if (!F.allFinite()) return E_NOT_FINITE;
  if (response != Response::JointsLocked)
    if (const int rc = readyDense(h)) return rc;
  Vector6d dPL = Vector6d::Zero();
  dqdot_work_.setZero();
  switch (response) {
    case Response::FreeFloating:
      generalizedJacobian(h, J_work_);
      dropLocked(J_work_);
      dqdot_work_.noalias() = J_work_.transpose() * F;
      H_star_llt_.solveInPlace(dqdot_work_);  // eq. 18: dqdot = H*^-1 J*^T F
      dPL.noalias() = R.transpose() * F;      // eq. 8
      break;
    case Response::Grounded:
      if (!H_ok_) return E_NOT_POSITIVE_DEFINITE;
      fixedBaseJacobian(h, J_work_);
      dropLocked(J_work_);
      dqdot_work_.noalias() = J_work_.transpose() * F;
      H_llt_.solveInPlace(dqdot_work_);  // eq. 23
      break;
    case Response::JointsLocked:
      dPL.noalias() = R.transpose() * F;  // eq. 21
      break;
    default:
      return E_BAD_ARGUMENT;  // not one of the enumerators
  }
  if (!dPL.allFinite() || !dqdot_work_.allFinite()) return E_NOT_FINITE;
  dPL_g = dPL;
  dqdot.data = dqdot_work_;
  return E_NOERROR;
}

void FreeFloatingSolver::reserveContacts(std::size_t k) {
  if (static_cast<Eigen::Index>(6 * k) <= J_all_work_.rows()) return;
  J_all_work_.resize(6 * k, model_->nj());
  X_all_work_.resize(model_->nj(), 6 * k);
  G_all_work_.resize(6 * k, 6 * k);
  R_all_work_.resize(k);
}

int FreeFloatingSolver::G_star(const std::vector<Contact>& contacts, Eigen::MatrixXd& G) {
  const Eigen::Index k = static_cast<Eigen::Index>(contacts.size());
  for (const Contact& h : contacts)
    if (const int rc = readyDense(h)) return rc;
  if (G.rows() != 6 * k || G.cols() != 6 * k) return E_SIZE_MISMATCH;
  reserveContacts(contacts.size());  // no allocation up to the reserved count
  auto J_all = J_all_work_.topRows(6 * k);
  auto X = X_all_work_.leftCols(6 * k);
  const bool joints = model_->nj() > 0;  // none: no J* term (and no block of a 6k x 0 matrix: PITFALLS)
  for (Eigen::Index i = 0; i < k; ++i) {
    if (const int rc = R_h(contacts[i], R_all_work_[i])) return rc;
    if (!joints) continue;
    generalizedJacobian(contacts[i], J_work_);
    dropLocked(J_work_);
    J_all.middleRows<6>(6 * i) = J_work_;
  }
  auto G_all = G_all_work_.topLeftCorner(6 * k, 6 * k);
  if (joints) {
    X = J_all.transpose();
    for (Eigen::Index c = 0; c < X.cols(); ++c) H_star_llt_.solveInPlace(X.col(c));  // one factorisation of H*
    G_all.noalias() = J_all.lazyProduct(X);
  } else {
    G_all.setZero();
  }
  for (Eigen::Index i = 0; i < k; ++i) {
    Matrix6d Y = R_all_work_[i].transpose();
    M_a_solveInPlace(Y);
    for (Eigen::Index j = 0; j < k; ++j) G_all.block<6, 6>(6 * j, 6 * i).noalias() += R_all_work_[j] * Y;  // eq. 11
  }
  symmetrize(G_all);
  if (!G_all.allFinite()) return E_NOT_FINITE;
  G = G_all;
  return E_NOERROR;
}

}  // namespace kdl_space
