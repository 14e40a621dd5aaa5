#include "kdl_space/recursive_ex_iit.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace kdl_space {
RecursiveExIITSolver::RecursiveExIITSolver(std::shared_ptr<const FloatingModel> model) : model_(std::move(model)) {
  if (!model_) throw ModelError("RecursiveExIITSolver: null model");
  const std::size_t nb = model_->bodies().size();
  R_.resize(nb);
  p_.resize(nb);
  joints_.resize(nb);
  for (std::size_t i = 1; i < nb; ++i) {
    const Body& b = model_->bodies()[i];
    LocalJoint& j = joints_[i];
    const KDL::Frame pose0 = b.segment.pose(0.0);
    j.R0 = toEigen(pose0.M);
    j.p0 = toEigen(pose0.p);
    if (b.joint < 0) continue;
    const Vector3d v = b.joint_twist.head<3>(), w = b.joint_twist.tail<3>();  // at the parent's origin
    if (w.norm() > 0.0) {
      j.kind = 1;
      j.scale = w.norm();
      j.axis = w / j.scale;
      j.point = w.cross(v) / w.squaredNorm();  // the axis' point nearest the parent's origin
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
  PA_.resize(nb);
  a_.resize(nb);
  pa_.resize(nb);
}

int RecursiveExIITSolver::compute(const State& state) {
  computed_ = false;
  const std::vector<Body>& bodies = model_->bodies();
  if (state.q.rows() != model_->nj()) return E_SIZE_MISMATCH;
  if (!state.q.data.allFinite() || !allFinite(state.world_T_base)) return E_NOT_FINITE;
  p_b_ = toEigen(state.world_T_base.p);

  // Forward kinematics (KDL's segment motion, precomputed as a screw about each joint axis);
  // unit joint twists and body inertias about the base origin.
  R_[0] = toEigen(state.world_T_base.M);
  p_[0] = p_b_;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const Body& b = bodies[i];
    if (b.parent >= 0) {
      const LocalJoint& j = joints_[i];
      const Matrix3d& R_parent = R_[b.parent];
      const Vector3d& p_parent = p_[b.parent];
      if (j.kind == 1) {  // revolute: rotation about the line (axis, point), then pose(0)
        const Matrix3d R = Eigen::AngleAxisd(j.scale * state.q(b.joint), j.axis).toRotationMatrix();
        const Matrix3d RR = R_parent * R;
        R_[i].noalias() = RR * j.R0;
        p_[i] = p_parent + RR * (j.p0 - j.point) + R_parent * j.point;
      } else {
        R_[i].noalias() = R_parent * j.R0;
        p_[i] = p_parent + R_parent * (j.kind == 2 ? Vector3d(j.p0 + j.scale * state.q(b.joint) * j.axis) : j.p0);
      }
      if (b.joint >= 0) {
        // The joint's unit twist, rotated to world axes and moved from the parent's origin to p_b.
        S_[i].tail<3>().noalias() = R_parent * b.joint_twist.tail<3>();
        S_[i].head<3>().noalias() = R_parent * b.joint_twist.head<3>();
        S_[i].head<3>() += S_[i].tail<3>().cross(p_b_ - p_parent);
      }
    }
    if (b.mass == 0.0) {
      IA_[i].setZero();  // a frame-only link
      continue;
    }
    const Matrix3d& R = R_[i];
    IA_[i] = spatialInertia(b.mass, R * b.com + p_[i] - p_b_, R * b.I_com * R.transpose());
  }
  // Articulated-body inertias, leaves first.
  for (std::size_t i = bodies.size(); i-- > 1;) {
    const Body& b = bodies[i];
    if (b.joint >= 0) {
      U_[i].noalias() = IA_[i] * S_[i];
      D_[i] = S_[i].dot(U_[i]) + model_->armature()[b.joint];
      if (!(D_[i] > 0.0)) return E_NOT_POSITIVE_DEFINITE;
      IA_[b.parent].noalias() += IA_[i] - U_[i] * (U_[i].transpose() / D_[i]);
    } else {
      IA_[b.parent] += IA_[i];
    }
  }
  IA0_llt_.compute(IA_[0]);
  if (IA0_llt_.info() != Eigen::Success) return E_NOT_POSITIVE_DEFINITE;
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
  for (int b = h.body; b >= 0; b = model_->bodies()[b].parent) path_[count++] = b;
  return count;
}

int RecursiveExIITSolver::G_star(const Contact& h, Matrix6d& G) {
  if (!computed_) return E_NOT_COMPUTED;
  if (h.body < 0 || h.body >= static_cast<int>(model_->bodies().size())) return E_BAD_CONTACT;
  const std::vector<Body>& bodies = model_->bodies();
  const Vector3d r = R_[h.body] * toEigen(h.offset) + p_[h.body] - p_b_;
  const Matrix6d X = transfer(r);  // twist at p_b -> twist at h; X^T: wrench at h -> at p_b (eq. 8)
  const int count = walkPath(h);

  // Bias forces of the six unit impulses at h, from h's body to the base.
  Eigen::Matrix<double, 6, 6> P = -X.transpose();
  for (int k = 0; k < count - 1; ++k) {
    const int i = path_[k];
    PA_[i] = P;
    if (bodies[i].joint >= 0) P.noalias() -= U_[i] * ((S_[i].transpose() * P) / D_[i]);  // p + U D^-1 u, u = -S^T p
  }
  // Base: a_0 = -(I^A_0)^-1 p^A_0; then outward along the path: qdd = D^-1 (u - U^T a_parent).
  Matrix6d A;
  for (int c = 0; c < 6; ++c) A.col(c) = -IA0_llt_.solve(Vector6d(P.col(c)));  // vector solves: no blocked path
  for (int k = count - 2; k >= 0; --k) {
    const int i = path_[k];
    if (bodies[i].joint >= 0) {
      const Eigen::Matrix<double, 1, 6> qdd = -(S_[i].transpose() * PA_[i] + U_[i].transpose() * A) / D_[i];
      A.noalias() += S_[i] * qdd;
    }
  }
  G.noalias() = X * A;  // eq. 11: the twist jump at h per unit impulse at h
  symmetrize(G);  // symmetric up to round-off: exactly so, as the dense route's
  return E_NOERROR;
}

int RecursiveExIITSolver::velocityJump(const Contact& h, const Vector6d& F, Vector6d& d_base_twist,
                                       KDL::JntArray& dqdot) {
  if (!computed_) return E_NOT_COMPUTED;
  if (h.body < 0 || h.body >= static_cast<int>(model_->bodies().size())) return E_BAD_CONTACT;
  if (dqdot.rows() != model_->nj()) return E_SIZE_MISMATCH;
  if (!F.allFinite()) return E_NOT_FINITE;
  const std::vector<Body>& bodies = model_->bodies();
  const Vector3d r = R_[h.body] * toEigen(h.offset) + p_[h.body] - p_b_;
  const int count = walkPath(h);
  for (auto& p : pa_) p.setZero();
  Vector6d p = -transfer(r).transpose() * F;
  for (int k = 0; k < count - 1; ++k) {
    const int i = path_[k];
    pa_[i] = p;
    if (bodies[i].joint >= 0) p -= U_[i] * (S_[i].dot(p) / D_[i]);
  }
  a_[0] = -IA0_llt_.solve(p);
  d_base_twist = a_[0];  // the twist jump at p_b is the base twist jump
  for (std::size_t i = 1; i < bodies.size(); ++i) {
    const Body& b = bodies[i];
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
