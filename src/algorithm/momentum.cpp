#include "kdl_space/algorithm/momentum.hpp"

#include <Eigen/Cholesky>

#include "multibody/joint_motion.hpp"
#include "spatial/symmetric6d.hpp"
#include "detail/lanes.hpp"
#include "detail/multiversion.hpp"

namespace kdl_space {

MomentumSolver::MomentumSolver(std::shared_ptr<const FloatingModel> model) : model_(std::move(model)) {
  if (!model_) throw ModelError("MomentumSolver: null model");
  const std::size_t nb = model_->bodies().size();
  V_.assign(nb, Vector6d::Zero());
  R_.assign(nb, Matrix3d::Identity());
  p_.assign(nb, Vector3d::Zero());
}

KDL_SPACE_MULTIVERSION void MomentumSolver::sweep(const Kinematics& kin, const Vector6d& V_b, const Eigen::VectorXd& qdot,
                                                  Vector6d& h_b, double& twoT) {
  const std::vector<detail::JointMotion>& bodies = model_->motions().bodies;
  // In four-lane vectors (detail/lanes.hpp); the twist of body i - 1, the parent of most bodies,
  // stays in registers.
  using detail::Lanes;
  const Lanes zero{0.0, 0.0, 0.0, 0.0}, base = detail::lanes(kin.p_b);
  Lanes v = zero, w = zero;  // the twist of the body before
  Lanes P_sum = zero, L_sum = zero, first_moment = zero, energy = zero, mr2 = zero;
  detail::LaneMatrix I_sum{{zero, zero, zero}}, mrr{{zero, zero, zero}};  // sum_i I_i, sum_i m_i r_i r_i^T
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const detail::JointMotion& b = bodies[i];
    if (b.parent < 0) {
      v = detail::load3(V_b.data()), w = detail::load3(V_b.data() + 3);
    } else {
      if (b.parent != static_cast<int>(i) - 1)
        v = detail::load3(V_[b.parent].data()), w = detail::load3(V_[b.parent].data() + 3);
      if (b.joint >= 0) {
        const double qd = qdot(b.joint);
        v += detail::load3(kin.S[i].data()) * qd;
        w += detail::load3(kin.S[i].data() + 3) * qd;
      }
    }
    detail::store3(v, V_[i].data());
    detail::store3(w, V_[i].data() + 3);
    if (!(b.mass > 0.0) && kin.I_com[i].isZero(0.0)) continue;  // a frame-only link (issue 28: zero mass, inertia kept)
    const Lanes r = detail::lanes(kin.com[i]) - base;
    const Lanes v_c = v + detail::cross(w, r);  // CoM velocity
    const Lanes P = b.mass * v_c;
    const detail::LaneMatrix I = detail::lanes(kin.I_com[i]);
    const Lanes Iw = detail::times(I, w[0], w[1], w[2]);
    P_sum += P;
    L_sum += Iw + detail::cross(r, P);  // about p_b
    energy += P * v_c + w * Iw;
    const Lanes mr = b.mass * r;
    first_moment += mr;
    mr2 += mr * r;
    for (int k = 0; k < 3; ++k) {
      mrr.c[k] += mr * r[k];
      I_sum.c[k] += I.c[k];
    }
  }
  h_b << P_sum[0], P_sum[1], P_sum[2], L_sum[0], L_sum[1], L_sum[2];
  twoT = detail::sum3(energy);
  // sum_i I_i about p_b (spatialInertia's blocks): [[w E, -skew(c)], [skew(c), I_b]], c = first
  // moment, I_b = sum_i (I_i + m_i (|r_i|^2 E - r_i r_i^T)) (parallel axes)
  const Vector3d c(first_moment[0], first_moment[1], first_moment[2]);
  Matrix3d I_b;
  for (int k = 0; k < 3; ++k) {
    const Lanes col = I_sum.c[k] - mrr.c[k];
    I_b.col(k) = Vector3d(col[0], col[1], col[2]);
  }
  I_b.diagonal().array() += detail::sum3(mr2);
  I_tot_.topLeftCorner<3, 3>() = model_->totalMass() * Matrix3d::Identity();
  I_tot_.topRightCorner<3, 3>() = -skew(c);
  I_tot_.bottomLeftCorner<3, 3>() = skew(c);
  I_tot_.bottomRightCorner<3, 3>() = I_b;
}

int MomentumSolver::compute(const Kinematics& kin, const FloatingVelocity& v) {
  computed_ = false;
  const std::size_t nb = model_->bodies().size();
  if (kin.model != model_.get() || kin.R.size() != nb || v.qdot.rows() != model_->nj()) return E_SIZE_MISMATCH;
  if (!kin.valid) return E_NOT_COMPUTED;
  if (!allFinite(v.base_twist) || !v.qdot.data.allFinite()) return E_NOT_FINITE;
  Vector6d h_b;
  double twoT = 0.0;
  sweep(kin, toEigen(v.base_twist), v.qdot.data, h_b, twoT);
  // The rotors' own energy, as the armature on H's diagonal (their momentum is neglected, as in H)
  const std::vector<double>& armature = model_->armature();
  twoT += Eigen::Map<const Eigen::VectorXd>(armature.data(), model_->nj()).dot(v.qdot.data.cwiseAbs2());
  p_b_ = kin.p_b;
  r_g_ = kin.r_g;
  R_ = kin.R;  // same sizes: no allocation
  p_ = kin.p;
  // I_g = I_b - w skew(r)^T skew(r) with r = r_g - p_b (parallel axes, eq. 3)
  const Vector3d r = r_g_ - p_b_;
  I_g_ = I_tot_.bottomRightCorner<3, 3>() -
         model_->totalMass() * (r.squaredNorm() * Matrix3d::Identity() - r * r.transpose());
  PL_g_ = shiftMomentum(h_b, r);   // L_g = L_b - (r_g - p_b) x P
  h_O_ = shiftMomentum(h_b, -p_b_);  // L_O = L_b + p_b x P
  T_ = 0.5 * twoT;
  const Eigen::LLT<Matrix3d> I_g_llt(I_g_);
  if (I_g_llt.info() != Eigen::Success) return E_NOT_POSITIVE_DEFINITE;
  v_g_ << PL_g_.head<3>() / model_->totalMass(), I_g_llt.solve(Vector3d(PL_g_.tail<3>()));  // eq. 12
  if (!h_O_.allFinite() || !v_g_.allFinite() || !std::isfinite(T_) || !I_g_.allFinite()) return E_NOT_FINITE;
  computed_ = true;
  return E_NOERROR;
}

int MomentumSolver::contactTwist(const Contact& h, Vector6d& t_h) const {
  if (const int rc = contactCode(computed_, h, V_.size())) return rc;
  const Vector6d t = shiftTwist(V_[h.body], R_[h.body] * toEigen(h.offset) + p_[h.body] - p_b_);
  if (!t.allFinite()) return E_NOT_FINITE;
  t_h = t;
  return E_NOERROR;
}

int MomentumSolver::G_locked(const Contact& h, Matrix6d& G) const {
  if (const int rc = contactCode(computed_, h, V_.size())) return rc;
  // eq. 20: the whole system as one rigid body (w, I_g) touched at r_gh = p_h - r_g
  Matrix6d result = rigidBodyG(model_->totalMass(), I_g_, R_[h.body] * toEigen(h.offset) + p_[h.body] - r_g_);
  symmetrize(result);
  if (!result.allFinite()) return E_NOT_FINITE;
  G = result;
  return E_NOERROR;
}

int MomentumSolver::baseTwist(const Kinematics& kin, const Vector6d& h_O, const KDL::JntArray& qdot,
                              KDL::Twist& base_twist) {
  if (kin.model != model_.get() || kin.R.size() != V_.size() || qdot.rows() != model_->nj()) return E_SIZE_MISMATCH;
  if (!kin.valid) return E_NOT_COMPUTED;
  if (!h_O.allFinite() || !qdot.data.allFinite()) return E_NOT_FINITE;
  // Momentum of the joint motion with the base still, and the locked inertia, about p_b; then
  // I_tot V_b = h_b - h_q (eq. 2 about p_b).
  Vector6d h_q;
  double twoT = 0.0;
  sweep(kin, Vector6d::Zero(), qdot.data, h_q, twoT);
  computed_ = false;  // V_ now holds another velocity's twists
  // By the packed root-free Cholesky of the recursions (a simulation's every stage asks: Eigen's
  // LLT of the 6x6 and its solve took a tenth of a 10 s motion's time).
  detail::Symmetric6d I;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c <= r; ++c) I.a[detail::Symmetric6d::index(r, c)] = I_tot_(r, c);
  Vector6d V_b;
  if (!I.solve(shiftMomentum(h_O, kin.p_b) - h_q, V_b)) return E_NOT_POSITIVE_DEFINITE;
  if (!V_b.allFinite()) return E_NOT_FINITE;
  base_twist = toTwist(V_b);
  return E_NOERROR;
}

}  // namespace kdl_space
