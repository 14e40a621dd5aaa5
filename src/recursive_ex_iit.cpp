#include "kdl_space/recursive_ex_iit.hpp"

#include <Eigen/Geometry>
#include <cmath>

// The recursions are small dense 6x6 algebra: compiled twice, for the x86-64 baseline and for
// x86-64-v3 (AVX2, FMA), the loader picking the one the CPU runs (GCC's target_clones, an ifunc).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__linux__) && \
    !defined(__SANITIZE_ADDRESS__)
#define KDL_SPACE_MULTIVERSION __attribute__((target_clones("default", "arch=x86-64-v3")))
#else
#define KDL_SPACE_MULTIVERSION
#endif

namespace kdl_space {
RecursiveExIITSolver::RecursiveExIITSolver(std::shared_ptr<const FloatingModel> model) : model_(std::move(model)) {
  if (!model_) throw ModelError("RecursiveExIITSolver: null model");
  const std::size_t nb = model_->bodies().size();
  R_.resize(nb);
  p_.resize(nb);
  local_.resize(nb);
  for (std::size_t i = 0; i < nb; ++i) {
    const Body& b = model_->bodies()[i];
    LocalBody& j = local_[i];
    j.parent = b.parent;
    j.joint = b.joint;
    j.twist_v = b.joint_twist.head<3>();
    j.twist_w = b.joint_twist.tail<3>();
    j.mass = b.mass;
    j.armature = b.joint >= 0 ? model_->armature()[b.joint] : 0.0;
    j.com = b.com;
    j.I_com = b.I_com;
    if (i == 0) continue;
    const KDL::Frame pose0 = b.segment.pose(0.0);
    j.R0 = toEigen(pose0.M);
    j.p0 = toEigen(pose0.p);
    if (b.joint < 0) continue;
    const Vector3d v = b.joint_twist.head<3>(), w = b.joint_twist.tail<3>();  // at the parent's origin
    if (w.norm() > 0.0) {
      j.kind = 1;
      j.scale = w.norm();
      j.axis = w / j.scale;
      const Vector3d point = w.cross(v) / w.squaredNorm();  // the axis' point nearest the parent's origin
      const Matrix3d a = skew(j.axis), a2 = a * a;
      j.K1 = a * j.R0;
      j.K2 = a2 * j.R0;
      j.k1 = a * (j.p0 - point);
      j.k2 = a2 * (j.p0 - point);
    } else {
      j.kind = 2;
      j.scale = v.norm();
      j.axis = v / j.scale;
    }
  }
  S_.assign(nb, Vector6d::Zero());
  IA_.resize(nb);
  U_.assign(nb, Vector6d::Zero());
  D_.assign(nb, 0.0);
  path_.resize(nb);
  a_.resize(nb);
  pa_.resize(nb);
}

KDL_SPACE_MULTIVERSION int RecursiveExIITSolver::compute(const State& state) {
  computed_ = false;
  if (state.q.rows() != model_->nj()) return E_SIZE_MISMATCH;
  if (!state.q.data.allFinite() || !allFinite(state.world_T_base)) return E_NOT_FINITE;
  p_b_ = toEigen(state.world_T_base.p);
  const std::size_t nb = local_.size();

  // Forward kinematics (KDL's segment motion, precomputed as a screw about each joint axis);
  // unit joint twists and body inertias about the base origin.
  R_[0] = toEigen(state.world_T_base.M);
  p_[0] = p_b_;
  // Each result is built in registers and stored once (a store read back in pieces stalls).
  for (std::size_t i = 0; i < nb; ++i) {
    const LocalBody& j = local_[i];
    if (j.parent >= 0) {
      const Matrix3d& R_parent = R_[j.parent];
      const Vector3d& p_parent = p_[j.parent];
      if (j.kind == 1) {  // revolute: rotation about the joint's axis line, then pose(0)
        const double t = j.scale * state.q.data(j.joint), s = std::sin(t), c1 = 1.0 - std::cos(t);
        R_[i].noalias() = R_parent * (j.R0 + s * j.K1 + c1 * j.K2);
        p_[i] = p_parent + R_parent * (j.p0 + s * j.k1 + c1 * j.k2);
      } else {
        R_[i].noalias() = R_parent * j.R0;
        p_[i] = p_parent + R_parent * (j.kind == 2 ? Vector3d(j.p0 + j.scale * state.q.data(j.joint) * j.axis) : j.p0);
      }
      if (j.joint >= 0) {
        // The joint's unit twist, rotated to world axes and moved from the parent's origin to p_b.
        const Vector3d w = R_parent * j.twist_w;
        const Vector3d v = R_parent * j.twist_v + w.cross(p_b_ - p_parent);
        S_[i] << v, w;
      }
    }
    IA_[i].setZero();
    if (j.mass > 0.0) {  // else a frame-only link
      const Matrix3d& R = R_[i];
      const Matrix3d RI = R * j.I_com;
      IA_[i].addRigidBody(j.mass, R * j.com + p_[i] - p_b_, RI * R.transpose());
    }
  }
  // Articulated-body inertias, leaves first.
  for (std::size_t i = nb; i-- > 1;) {
    const LocalBody& j = local_[i];
    if (j.joint < 0) {
      IA_[j.parent] += IA_[i];
      continue;
    }
    U_[i] = IA_[i] * S_[i];
    D_[i] = S_[i].dot(U_[i]) + j.armature;
    if (!(D_[i] > 0.0)) return E_NOT_POSITIVE_DEFINITE;
    IA_[j.parent].addMinusRank1(IA_[i], U_[i], 1.0 / D_[i]);
  }
  if (!IA_[0].invert(Omega0_)) return E_NOT_POSITIVE_DEFINITE;
  computed_ = true;
  return E_NOERROR;
}

KDL::Frame RecursiveExIITSolver::bodyPose(int i) const {
  KDL::Rotation M;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) M(r, c) = R_[i](r, c);
  return KDL::Frame(M, toKDL(p_[i]));
}

int RecursiveExIITSolver::walkPath(const Contact& h) {
  int count = 0;
  for (int b = h.body; b >= 0; b = local_[b].parent) path_[count++] = b;
  return count;
}

KDL_SPACE_MULTIVERSION int RecursiveExIITSolver::G_star(const Contact& h, Matrix6d& G) {
  if (!computed_) return E_NOT_COMPUTED;
  if (h.body < 0 || h.body >= static_cast<int>(local_.size())) return E_BAD_CONTACT;
  const int count = walkPath(h);
  // Outward along the path, the inverse inertia a wrench at body i meets (about p_b):
  // Omega_0 = (I^A_0)^-1, Omega_i = T_i Omega_parent T_i^T + S_i D_i^-1 S_i^T with
  // T_i = 1 - S_i D_i^-1 U_i^T (an impulse's bias force crossing joint i inward is T_i^T times it).
  // Expanded with w = Omega U, c = U^T w: Omega - (S y^T + y S^T), y = w/D - (c/D^2 + 1/D) S / 2.
  // Dense here: Eigen vectorises the column updates, which a packed triangle does not allow.
  Matrix6d O = Omega0_.toDense();
  for (int k = count - 2; k >= 0; --k) {
    const int i = path_[k];
    if (local_[i].joint < 0) continue;
    const double d = 1.0 / D_[i];
    const Vector6d& S = S_[i];
    const Vector6d w = O.leftCols<3>() * U_[i].head<3>() + O.rightCols<3>() * U_[i].tail<3>();  // two chains
    const Vector6d y = d * w - (0.5 * d * (d * U_[i].dot(w) + 1.0)) * S;
    for (int c = 0; c < 6; ++c) O.col(c) -= S * y(c) + y * S(c);
  }
  // G* = X Omega X^T, X = transfer(r) = [E, -r^; 0, E] (eq. 5, 11), by 3x3 blocks: with
  // Omega = [a, b; b^T, c], G* = [a - r^ b^T + e r^, e; e^T, c], e = b - r^ c.
  const Matrix3d rx = skew(R_[h.body] * toEigen(h.offset) + p_[h.body] - p_b_);
  const Matrix3d e = O.topRightCorner<3, 3>() - rx * O.bottomRightCorner<3, 3>();
  G.topLeftCorner<3, 3>() = O.topLeftCorner<3, 3>() - rx * O.bottomLeftCorner<3, 3>() + e * rx;
  G.topRightCorner<3, 3>() = e;
  G.bottomLeftCorner<3, 3>() = e.transpose();
  G.bottomRightCorner<3, 3>() = O.bottomRightCorner<3, 3>();
  symmetrize(G);  // symmetric up to round-off: exactly so, as the dense route's
  return E_NOERROR;
}

int RecursiveExIITSolver::velocityJump(const Contact& h, const Vector6d& F, Vector6d& d_base_twist,
                                       KDL::JntArray& dqdot) {
  if (!computed_) return E_NOT_COMPUTED;
  if (h.body < 0 || h.body >= static_cast<int>(local_.size())) return E_BAD_CONTACT;
  if (dqdot.rows() != model_->nj()) return E_SIZE_MISMATCH;
  if (!F.allFinite()) return E_NOT_FINITE;
  const Vector3d r = R_[h.body] * toEigen(h.offset) + p_[h.body] - p_b_;
  const int count = walkPath(h);
  for (auto& p : pa_) p.setZero();
  Vector6d p = -transfer(r).transpose() * F;
  for (int k = 0; k < count - 1; ++k) {
    const int i = path_[k];
    pa_[i] = p;
    if (local_[i].joint >= 0) p -= U_[i] * (S_[i].dot(p) / D_[i]);
  }
  a_[0] = -(Omega0_ * p);
  d_base_twist = a_[0];  // the twist jump at p_b is the base twist jump
  for (std::size_t i = 1; i < local_.size(); ++i) {
    const LocalBody& b = local_[i];
    a_[i] = a_[b.parent];
    if (b.joint >= 0) {
      const double qdd = -(S_[i].dot(pa_[i]) + U_[i].dot(a_[b.parent])) / D_[i];
      dqdot(b.joint) = qdd;
      a_[i] += S_[i] * qdd;
    }
  }
  return E_NOERROR;
}

}  // namespace kdl_space
