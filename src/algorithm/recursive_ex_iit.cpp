#include "kdl_space/algorithm/recursive_ex_iit.hpp"

#include <cmath>

#include "algorithm/mimic_coupling.hpp"
#include "algorithm/set_up.hpp"
#include "multibody/joint_motion.hpp"
#include "detail/multiversion.hpp"
#include "detail/lane_symmetric6d.hpp"
#include "spatial/symmetric6d.hpp"

namespace kdl_space {

RecursiveExIITSolver::RecursiveExIITSolver(std::shared_ptr<const FloatingModel> model) : model_(std::move(model)) {
  if (!model_) throw ModelError("RecursiveExIITSolver: null model");
  const std::size_t nb = model_->bodies().size();
  own_ = Kinematics(*model_);
  R_.assign(nb, Matrix3d::Identity());
  p_.assign(nb, Vector3d::Zero());
  S_.assign(nb, Vector6d::Zero());
  IA_.resize(nb);
  // Which bodies have children other than the next body (their sums go through IA_), and which
  // of those children is done first (it sets the sum; the others add to it).
  far_children_.assign(nb, 0);
  first_far_child_.assign(nb, 0);
  for (std::size_t i = nb; i-- > 1;) {
    const int parent = model_->bodies()[i].parent;
    if (parent == static_cast<int>(i) - 1) continue;
    first_far_child_[i] = !far_children_[parent];
    far_children_[parent] = 1;
  }
  U_.assign(nb, Vector6d::Zero());
  Dinv_.assign(nb, 0.0);
  path_.resize(nb);
  dq_.setZero(model_->nj());
  a_.resize(nb);
  Sp_.assign(nb, 0.0);
  locked_.assign(model_->nj(), false);
  moves_.resize(nb);
  for (std::size_t i = 0; i < nb; ++i) moves_[i] = model_->bodies()[i].joint >= 0;
  qb_.assign(nb, 0.0);
  // Mimic joints: every body's joint free in the recursion, the couplings imposed after it
  // (algorithm/mimic_coupling.hpp); one set of responses per base (free-floating, grounded).
  couplings_.free = std::make_unique<detail::MimicCoupling>(*model_);
  couplings_.grounded = std::make_unique<detail::MimicCoupling>(*couplings_.free);
}

RecursiveExIITSolver::Couplings::Couplings() = default;
RecursiveExIITSolver::Couplings::~Couplings() = default;
RecursiveExIITSolver::Couplings::Couplings(const Couplings& other)
    : free(other.free ? std::make_unique<detail::MimicCoupling>(*other.free) : nullptr),
      grounded(other.grounded ? std::make_unique<detail::MimicCoupling>(*other.grounded) : nullptr) {}
RecursiveExIITSolver::Couplings& RecursiveExIITSolver::Couplings::operator=(const Couplings& other) {
  if (this == &other) return *this;
  Couplings copy(other);
  free = std::move(copy.free);
  grounded = std::move(copy.grounded);
  return *this;
}

void RecursiveExIITSolver::setLocked(const std::vector<bool>& locked) {
  detail::checkLocked(*model_, locked, true, "RecursiveExIITSolver");
  const unsigned int n = model_->nj();
  locked_.assign(n, false);
  for (std::size_t j = 0; j < locked.size(); ++j) locked_[j] = locked[j];
  const std::vector<Body>& bodies = model_->bodies();
  for (std::size_t i = 0; i < bodies.size(); ++i) moves_[i] = bodies[i].joint >= 0 && !locked_[bodies[i].joint];
  computed_ = false;  // the articulated inertias depend on the locks
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
  const Vector3d p_b = kin.p_b;
  p_b_ = p_b;
  R_ = kin.R;  // the poses, kept for the contact queries (same sizes: no allocation)
  p_ = kin.p;
  S_ = kin.S;
  const detail::MimicCoupling& free = *couplings_.free;  // per body: the armature of the free system
  // Articulated-body inertias about p_b (world axes, four-lane blocks), leaves first. Body i's
  // is summed in registers: its rigid inertia, the articulated inertia of body i + 1 when that is
  // its child (carried from the step before: along a chain nothing goes through memory), and
  // those of its other children (summed in IA_ as they were done).
  // The carried child's own joint term, -U U^T / D, is applied late: body i's U and D take it as
  // U = B S - (U_c . S) U_c / D_c and D = S^T B S - (U_c . S)^2 / D_c, B the sum without it, so
  // the one chain of dependent operations from body to body is D_c^-1 -> D -> D^-1.
  detail::LaneSymmetric6d carry{};
  detail::Lanes carried_top{}, carried_bottom{};  // the carried child's U
  double carried_Dinv = 0.0;                      // and its D^-1 (0: no term, a fixed or locked joint)
  for (std::size_t i = nb; i-- > 0;) {
    const detail::JointMotion& j = bodies[i];
    detail::LaneSymmetric6d A;
    A.setRigidBody(j.mass, kin.com[i] - p_b, kin.I_com[i]);
    const bool chained = i + 1 < nb && bodies[i + 1].parent == static_cast<int>(i);
    if (chained) A += carry;
    if (far_children_[i]) A += IA_[i];
    const bool pending = chained && carried_Dinv != 0.0;
    detail::Lanes top{}, bottom{};
    double Dinv = 0.0;
    if (i > 0 && moves_[i]) {
      const detail::Lanes S_top = detail::load3(kin.S[i].data()), S_bottom = detail::load3(kin.S[i].data() + 3);
      A.times(kin.S[i], top, bottom);
      double D = detail::dot(S_top, S_bottom, top, bottom) + free.armature(static_cast<int>(i));
      if (pending) {
        const double us = detail::dot(S_top, S_bottom, carried_top, carried_bottom), k = carried_Dinv * us;
        top -= k * carried_top;
        bottom -= k * carried_bottom;
        D -= k * us;
      }
      if (!(D > 0.0)) return E_NOT_POSITIVE_DEFINITE;
      Dinv = 1.0 / D;
      detail::store3(top, U_[i].data());
      detail::store3(bottom, U_[i].data() + 3);
      Dinv_[i] = Dinv;
    }  // else fixed or locked: the body rides on its parent
    if (pending) A.subtractRank1(carried_top, carried_bottom, carried_Dinv);
    if (i == 0) {
      detail::Symmetric6d Omega0;
      if (!A.packed().invert(Omega0)) return E_NOT_POSITIVE_DEFINITE;
      Omega0_ = Omega0.toDense();
      break;
    }
    if (j.parent == static_cast<int>(i) - 1) {  // to the next step, its own term pending
      carry = A;
      carried_top = top, carried_bottom = bottom, carried_Dinv = Dinv;
      continue;
    }
    if (Dinv != 0.0) A.subtractRank1(top, bottom, Dinv);
    if (first_far_child_[i]) IA_[j.parent] = A;
    else IA_[j.parent] += A;
    carried_Dinv = 0.0;
  }
  grounded_ready_ = false;
  if (couplings_.free->rows() > 0) {
    if (const int rc = couple(Response::FreeFloating)) return rc;
  }
  computed_ = true;
  return E_NOERROR;
}

int RecursiveExIITSolver::couple(Response response) {
  const std::vector<detail::JointMotion>& bodies = model_->motions().bodies;
  const bool grounded = response == Response::Grounded;
  if (grounded && grounded_ready_) return E_NOERROR;
  detail::MimicCoupling& c = grounded ? *couplings_.grounded : *couplings_.free;
  const int rc = c.compute([&](int i) { return bodies[i].parent; }, [&](int i) { return moves_[i] != 0; },
                           [&](int i) -> const Vector6d& { return S_[i]; },
                           [&](int i) -> const Vector6d& { return U_[i]; }, [&](int i) { return Dinv_[i]; },
                           [&](const auto& P0, auto A0) {  // 6 x k blocks
                             if (grounded) A0.setZero();  // a base of infinite inertia
                             else A0.noalias() = (-Omega0_) * P0;
                             return true;
                           });
  grounded_ready_ = grounded && rc == E_NOERROR;
  return rc;
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
  if (h.body == path_body_) return path_count_;  // the model does not change: nor does a body's path
  int count = 0;
  for (int b = h.body; b >= 0; b = bodies[b].parent) path_[count++] = b;
  path_body_ = h.body;
  path_count_ = count;
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
  // y = w/D - (c/D^2 + 1/D) S / 2. In four-lane blocks (detail/lane_symmetric6d.hpp).
  // Each joint's update is applied to Omega one step late: with the joint before's S', y', w',
  // and P = Omega' U (Omega' without that update), w = P - S' (y'.U) - y' (S'.U) and
  // c = U.P - 2 (y'.U)(S'.U), where y'.U = (w'.U)/D' - e' (S'.U): from joint to joint only
  // w' -> w'.U -> w waits for the step before.
  using detail::Lanes;
  detail::LaneSymmetric6d Omega = detail::LaneSymmetric6d::from(response == Response::FreeFloating ? Omega0_
                                                                                                : Matrix6d::Zero());
  const Lanes zero{0.0, 0.0, 0.0, 0.0};
  Lanes S_late_top = zero, S_late_bottom = zero, y_late_top = zero, y_late_bottom = zero;
  Lanes w_late_top = zero, w_late_bottom = zero;
  double d_late = 0.0, e_late = 0.0;
  bool pending = false;  // an update not yet applied to Omega
  for (int k = count - 2; k >= 0; --k) {
    const int i = path_[k];
    if (!moves_[i]) continue;  // fixed or locked
    const double d = Dinv_[i];
    const Lanes S_top = detail::load3(S_[i].data()), S_bottom = detail::load3(S_[i].data() + 3);
    const Lanes U_top = detail::load3(U_[i].data()), U_bottom = detail::load3(U_[i].data() + 3);
    Lanes w_top, w_bottom;
    Omega.times(U_[i], w_top, w_bottom);  // P
    double c = detail::dot(U_top, U_bottom, w_top, w_bottom);
    if (pending) {
      const double SU = detail::dot(S_late_top, S_late_bottom, U_top, U_bottom);
      const double yU = d_late * detail::dot(w_late_top, w_late_bottom, U_top, U_bottom) - e_late * SU;
      w_top -= yU * S_late_top + SU * y_late_top;
      w_bottom -= yU * S_late_bottom + SU * y_late_bottom;
      c -= 2.0 * yU * SU;
      Omega.subtractRank2(S_late_top, S_late_bottom, y_late_top, y_late_bottom);
    }
    const double e = 0.5 * d * (d * c + 1.0);
    S_late_top = S_top, S_late_bottom = S_bottom;
    w_late_top = w_top, w_late_bottom = w_bottom;
    y_late_top = d * w_top - e * S_top, y_late_bottom = d * w_bottom - e * S_bottom;
    d_late = d, e_late = e;
    pending = true;
  }
  if (pending) Omega.subtractRank2(S_late_top, S_late_bottom, y_late_top, y_late_bottom);
  const Matrix6d O = Omega.dense();
  // G = X Omega X^T, X = transfer(r) = [E, -r^; 0, E] (eq. 5, 11), by 3x3 blocks: with
  // Omega = [a, b; b^T, c], G = [a - r^ b^T + e r^, e; e^T, c], e = b - r^ c.
  const Matrix3d rx = skew(R_[h.body] * toEigen(h.offset) + p_[h.body] - p_b_);
  const Matrix3d e = O.topRightCorner<3, 3>() - rx * O.bottomRightCorner<3, 3>();
  Matrix6d result;
  result.topLeftCorner<3, 3>() = O.topLeftCorner<3, 3>() - rx * O.bottomLeftCorner<3, 3>() + e * rx;
  result.topRightCorner<3, 3>() = e;
  result.bottomLeftCorner<3, 3>() = e.transpose();
  result.bottomRightCorner<3, 3>() = O.bottomRightCorner<3, 3>();
  if (couplings_.free->rows() > 0) {  // mimic joints: the couplings' share (algorithm/mimic_coupling.hpp)
    if (const int rc = couple(response)) return rc;
    (response == Response::Grounded ? *couplings_.grounded : *couplings_.free)
        .correctG(transfer(R_[h.body] * toEigen(h.offset) + p_[h.body] - p_b_), h.body, result);
  }
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
  using detail::Lanes;
  using detail::load3;
  const auto dot = [](const Vector6d& x, const Vector6d& y) {
    return detail::dot(load3(x.data()), load3(x.data() + 3), load3(y.data()), load3(y.data() + 3));
  };
  const Vector6d p0 = -transfer(r).transpose() * F;  // the impulse as a bias force at p_b
  // Inward along the path: S_i^T p_i is all the outward pass needs. The last joint's term,
  // p -= U g (g = S^T p / D), is applied a step late: S_i^T p = S_i^T p_late - (S_i^T U) g, so
  // that from joint to joint only g -> S^T p -> g waits for the step before.
  Lanes p_top = load3(p0.data()), p_bottom = load3(p0.data() + 3);
  const Vector6d* U_late = nullptr;
  double g = 0.0;
  for (int k = 0; k < count - 1; ++k) {
    const int i = path_[k];
    if (!moves_[i]) continue;
    const Lanes S_top = load3(S_[i].data()), S_bottom = load3(S_[i].data() + 3);
    double Sp = detail::dot(S_top, S_bottom, p_top, p_bottom);
    if (U_late) {
      Sp -= dot(S_[i], *U_late) * g;
      p_top -= g * load3(U_late->data());
      p_bottom -= g * load3(U_late->data() + 3);
    }
    Sp_[i] = Sp;
    U_late = &U_[i];
    g = Sp * Dinv_[i];
  }
  if (U_late) p_top -= g * load3(U_late->data()), p_bottom -= g * load3(U_late->data() + 3);
  const Vector6d p = (Vector6d() << p_top[0], p_top[1], p_top[2], p_bottom[0], p_bottom[1], p_bottom[2]).finished();
  // The base's jump (eq. 18); a grounded base does not move (eq. 23). The joints' jumps outward:
  // qdd_i = -(S_i^T p_i + U_i^T a_parent) / D_i, a_i = a_parent + S_i qdd_i. Where the parent's
  // joint moves, U_i^T a_parent = U_i^T a_grandparent + (U_i^T S_parent) qdd_parent: from joint to
  // joint only qdd waits for the step before.
  a_[0] = response == Response::FreeFloating ? Vector6d(-(Omega0_ * p)) : Vector6d::Zero();
  double qdd_before = 0.0;  // of body i - 1 when its joint moves
  for (std::size_t i = 1; i < bodies.size(); ++i) {
    const detail::JointMotion& b = bodies[i];
    const int parent = b.parent;
    if (!moves_[i]) {
      a_[i] = a_[parent];
      qb_[i] = 0.0;  // braked (or fixed): exactly no jump
      continue;
    }
    double Ua;
    if (parent > 0 && moves_[parent]) {
      const double qdd_parent = parent == static_cast<int>(i) - 1 ? qdd_before : qb_[parent];
      Ua = dot(U_[i], a_[bodies[parent].parent]) + dot(U_[i], S_[parent]) * qdd_parent;
    } else {
      Ua = dot(U_[i], a_[parent]);
    }
    const double qdd = -(Sp_[i] + Ua) * Dinv_[i];
    qb_[i] = qdd;
    qdd_before = qdd;
    detail::store3(load3(a_[parent].data()) + load3(S_[i].data()) * qdd, a_[i].data());
    detail::store3(load3(a_[parent].data() + 3) + load3(S_[i].data() + 3) * qdd, a_[i].data() + 3);
  }
  for (int k = 0; k < count - 1; ++k) Sp_[path_[k]] = 0.0;  // zero off the path, as it was
  const std::vector<int>& own = model_->jointBody();
  if (couplings_.free->rows() == 0) {
    for (unsigned int j = 0; j < model_->nj(); ++j) dq_(j) = qb_[own[j]];
  } else {  // mimic joints: the couplings' impulses take back C dq (algorithm/mimic_coupling.hpp)
    if (const int rc = couple(response)) return rc;
    detail::MimicCoupling& c = response == Response::Grounded ? *couplings_.grounded : *couplings_.free;
    c.solve([&](int i) { return qb_[i]; });
    a_[0] -= c.baseShare();
    for (unsigned int j = 0; j < model_->nj(); ++j) dq_(j) = qb_[own[j]] - c.qddShare(own[j]);
  }
  if (!a_[0].allFinite() || !dq_.allFinite()) return E_NOT_FINITE;
  d_base_twist = a_[0];  // the twist jump at p_b is the base twist jump
  dqdot.data = dq_;
  return E_NOERROR;
}

}  // namespace kdl_space
