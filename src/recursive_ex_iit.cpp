#include "kdl_space/recursive_ex_iit.hpp"

#include <cmath>

#include "detail/joint_motion.hpp"
#include "detail/multiversion.hpp"
#include "detail/symmetric6d.hpp"

namespace kdl_space {

RecursiveExIITSolver::RecursiveExIITSolver(std::shared_ptr<const FloatingModel> model) : model_(std::move(model)) {
  if (!model_) throw ModelError("RecursiveExIITSolver: null model");
  model_->refuseMimic("RecursiveExIITSolver");
  const std::size_t nb = model_->bodies().size();
  own_ = Kinematics(*model_);
  R_.assign(nb, Matrix3d::Identity());
  p_.assign(nb, Vector3d::Zero());
  S_.assign(nb, Vector6d::Zero());
  IA_.resize(nb);
  U_.assign(nb, Vector6d::Zero());
  D_.assign(nb, 0.0);
  Dinv_.assign(nb, 0.0);
  path_.resize(nb);
  dq_.setZero(model_->nj());
  a_.resize(nb);
  Sp_.assign(nb, 0.0);
  locked_.assign(model_->nj(), false);
  moves_.resize(nb);
  for (std::size_t i = 0; i < nb; ++i) moves_[i] = model_->bodies()[i].joint >= 0;
}

int RecursiveExIITSolver::setLocked(const std::vector<bool>& locked) {
  const unsigned int n = model_->nj();
  if (!locked.empty() && locked.size() != n) return E_SIZE_MISMATCH;
  locked_.assign(n, false);
  for (std::size_t j = 0; j < locked.size(); ++j) locked_[j] = locked[j];
  const std::vector<Body>& bodies = model_->bodies();
  for (std::size_t i = 0; i < bodies.size(); ++i) moves_[i] = bodies[i].joint >= 0 && !locked_[bodies[i].joint];
  computed_ = false;  // the articulated inertias depend on the locks
  return E_NOERROR;
}

RecursiveExIITSolver::~RecursiveExIITSolver() = default;
RecursiveExIITSolver::RecursiveExIITSolver(const RecursiveExIITSolver&) = default;
RecursiveExIITSolver& RecursiveExIITSolver::operator=(const RecursiveExIITSolver&) = default;

int RecursiveExIITSolver::compute(const State& state) {
  computed_ = false;
  if (const int rc = forwardKinematics(*model_, state, own_)) return rc;
  return compute(own_);
}

KDL_SPACE_MULTIVERSION int RecursiveExIITSolver::compute(const Kinematics& kin) {
  computed_ = false;
  const std::vector<detail::JointMotion>& bodies = model_->motions().bodies;
  const std::size_t nb = bodies.size();
  if (kin.model != model_.get() || kin.R.size() != nb) return E_SIZE_MISMATCH;
  if (!kin.valid) return E_NOT_COMPUTED;
  p_b_ = kin.p_b;
  const std::vector<double>& armature = model_->armature();
  // Body inertias about the base origin (world axes); the poses kept for the contact queries.
  for (std::size_t i = 0; i < nb; ++i) {
    R_[i] = kin.R[i];
    p_[i] = kin.p[i];
    S_[i] = kin.S[i];
    if (bodies[i].mass > 0.0) IA_[i].setRigidBody(bodies[i].mass, kin.com[i] - p_b_, kin.I_com[i]);
    else IA_[i].setZero();  // a frame
  }
  // Articulated-body inertias, leaves first.
  for (std::size_t i = nb; i-- > 1;) {
    const detail::JointMotion& j = bodies[i];
    if (!moves_[i]) {  // fixed or locked: the body rides on its parent
      IA_[j.parent] += IA_[i];
      continue;
    }
    U_[i] = IA_[i] * S_[i];
    D_[i] = S_[i].dot(U_[i]) + armature[j.joint];
    if (!(D_[i] > 0.0)) return E_NOT_POSITIVE_DEFINITE;
    Dinv_[i] = 1.0 / D_[i];
    IA_[j.parent].addMinusRank1(IA_[i], U_[i], Dinv_[i]);
  }
  detail::Symmetric6d Omega0;
  if (!IA_[0].invert(Omega0)) return E_NOT_POSITIVE_DEFINITE;
  Omega0_ = Omega0.toDense();
  computed_ = true;
  return E_NOERROR;
}

KDL::Frame RecursiveExIITSolver::bodyPose(int i) const {
  KDL::Rotation M;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) M(r, c) = R_[i](r, c);
  return KDL::Frame(M, toKDL(p_[i]));
}

int RecursiveExIITSolver::ready(const Contact& h) const { return contactCode(computed_, h, R_.size()); }

int RecursiveExIITSolver::walkPath(const Contact& h) {
  const std::vector<detail::JointMotion>& bodies = model_->motions().bodies;
  int count = 0;
  for (int b = h.body; b >= 0; b = bodies[b].parent) path_[count++] = b;
  return count;
}

int RecursiveExIITSolver::G_star(const Contact& h, Matrix6d& G) { return this->G(h, Response::FreeFloating, G); }

KDL_SPACE_MULTIVERSION int RecursiveExIITSolver::G(const Contact& h, Response response, Matrix6d& G) {
  if (const int rc = ready(h)) return rc;
  if (response != Response::FreeFloating && response != Response::Grounded) return E_BAD_ARGUMENT;
  const int count = walkPath(h);
  // Outward along the path, the inverse inertia a wrench at body i meets (about p_b):
  // Omega_0 = (I^A_0)^-1 (a grounded base: 0), Omega_i = T_i Omega_parent T_i^T + S_i D_i^-1 S_i^T
  // with T_i = 1 - S_i D_i^-1 U_i^T (an impulse's bias force crossing joint i inward is T_i^T
  // times it). Expanded with w = Omega U, c = U^T w: Omega - (S y^T + y S^T),
  // y = w/D - (c/D^2 + 1/D) S / 2. Dense here: Eigen vectorises the column updates.
  Matrix6d O = response == Response::FreeFloating ? Omega0_ : Matrix6d::Zero();
  for (int k = count - 2; k >= 0; --k) {
    const int i = path_[k];
    if (!moves_[i]) continue;  // fixed or locked
    const double d = Dinv_[i];
    const Vector6d& S = S_[i];
    const Vector6d w = O.leftCols<3>() * U_[i].head<3>() + O.rightCols<3>() * U_[i].tail<3>();  // two chains
    const Vector6d y = d * w - (0.5 * d * (d * U_[i].dot(w) + 1.0)) * S;
    for (int c = 0; c < 6; ++c) O.col(c) -= S * y(c) + y * S(c);
  }
  // G = X Omega X^T, X = transfer(r) = [E, -r^; 0, E] (eq. 5, 11), by 3x3 blocks: with
  // Omega = [a, b; b^T, c], G = [a - r^ b^T + e r^, e; e^T, c], e = b - r^ c.
  const Matrix3d rx = skew(R_[h.body] * toEigen(h.offset) + p_[h.body] - p_b_);
  const Matrix3d e = O.topRightCorner<3, 3>() - rx * O.bottomRightCorner<3, 3>();
  Matrix6d result;
  result.topLeftCorner<3, 3>() = O.topLeftCorner<3, 3>() - rx * O.bottomLeftCorner<3, 3>() + e * rx;
  result.topRightCorner<3, 3>() = e;
  result.bottomLeftCorner<3, 3>() = e.transpose();
  result.bottomRightCorner<3, 3>() = O.bottomRightCorner<3, 3>();
  symmetrize(result);  // symmetric up to round-off: exactly so, as the dense route's
  if (!result.allFinite()) return E_NOT_FINITE;
  G = result;
  return E_NOERROR;
}

int RecursiveExIITSolver::velocityJump(const Contact& h, const Vector6d& F, Vector6d& d_base_twist,
                                       KDL::JntArray& dqdot) {
  return velocityJump(h, Response::FreeFloating, F, d_base_twist, dqdot);
}

KDL_SPACE_MULTIVERSION int RecursiveExIITSolver::velocityJump(const Contact& h, Response response, const Vector6d& F,
                                                              Vector6d& d_base_twist, KDL::JntArray& dqdot) {
  if (const int rc = ready(h)) return rc;
  if (response != Response::FreeFloating && response != Response::Grounded) return E_BAD_ARGUMENT;
  if (dqdot.rows() != model_->nj()) return E_SIZE_MISMATCH;
  if (!F.allFinite()) return E_NOT_FINITE;
  const std::vector<detail::JointMotion>& bodies = model_->motions().bodies;
  const Vector3d r = R_[h.body] * toEigen(h.offset) + p_[h.body] - p_b_;
  const int count = walkPath(h);
  Vector6d p = -transfer(r).transpose() * F;  // the impulse as a bias force at p_b
  for (int k = 0; k < count - 1; ++k) {  // inward along the path: S_i^T p_i is all the outward pass needs
    const int i = path_[k];
    if (!moves_[i]) continue;
    const double Sp = S_[i].dot(p);
    Sp_[i] = Sp;
    p -= U_[i] * (Sp * Dinv_[i]);
  }
  // The base's jump (eq. 18); a grounded base does not move (eq. 23). The joints' jumps outward.
  a_[0] = response == Response::FreeFloating ? Vector6d(-(Omega0_ * p)) : Vector6d::Zero();
  for (std::size_t i = 1; i < bodies.size(); ++i) {
    const detail::JointMotion& b = bodies[i];
    const Vector6d& a_parent = a_[b.parent];
    if (moves_[i]) {
      const double qdd = -(Sp_[i] + U_[i].dot(a_parent)) * Dinv_[i];
      dq_(b.joint) = qdd;
      a_[i] = a_parent + S_[i] * qdd;
    } else {
      a_[i] = a_parent;
      if (b.joint >= 0) dq_(b.joint) = 0.0;  // braked: exactly no jump
    }
  }
  for (int k = 0; k < count - 1; ++k) Sp_[path_[k]] = 0.0;  // zero off the path, as it was
  if (!a_[0].allFinite() || !dq_.allFinite()) return E_NOT_FINITE;
  d_base_twist = a_[0];  // the twist jump at p_b is the base twist jump
  dqdot.data = dq_;
  return E_NOERROR;
}

}  // namespace kdl_space
