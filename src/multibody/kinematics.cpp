#include "kdl_space/multibody/kinematics.hpp"

#include <cmath>

#include "multibody/joint_motion.hpp"
#include "detail/lanes.hpp"
#include "detail/multiversion.hpp"
#include "detail/sines.hpp"

namespace kdl_space {

Kinematics::Kinematics(const FloatingModel& m)
    : model(&m),
      state(m),
      R(m.bodies().size(), Matrix3d::Identity()),
      p(m.bodies().size(), Vector3d::Zero()),
      S(m.bodies().size(), Vector6d::Zero()),
      com(m.bodies().size(), Vector3d::Zero()),
      I_com(m.bodies().size(), Matrix3d::Zero()),
      angle_((m.bodies().size() + 3) / 4 * 4, 0.0),
      sin_(angle_.size(), 0.0),
      cos_(angle_.size(), 1.0) {}

KDL::Frame Kinematics::pose(int i) const {
  KDL::Rotation M;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) M(r, c) = R[i](r, c);
  return KDL::Frame(M, toKDL(p[i]));
}

KDL_SPACE_MULTIVERSION int forwardKinematics(const FloatingModel& model, const State& state, Kinematics& kin) {
  kin.valid = false;
  const std::vector<detail::JointMotion>& bodies = model.motions().bodies;
  const std::size_t nb = bodies.size();
  if (kin.model != &model || kin.R.size() != nb || kin.state.q.rows() != model.nj()) return E_SIZE_MISMATCH;
  if (state.q.rows() != model.nj()) return E_SIZE_MISMATCH;
  if (!state.q.data.allFinite() || !allFinite(state.world_T_base)) return E_NOT_FINITE;
  const Vector3d p_b = toEigen(state.world_T_base.p);
  kin.R[0] = toEigen(state.world_T_base.M);
  kin.p[0] = p_b;
  // The joints' sines first, all at once (detail/sines.hpp); a call in the pass below would also
  // spill its registers every body.
  for (std::size_t i = 1; i < nb; ++i) {
    const detail::JointMotion& j = bodies[i];
    if (j.kind == detail::JointMotion::Revolute) kin.angle_[i] = j.scale * state.q.data(j.joint);
  }
  detail::sinesAndCosines(kin.angle_.data(), kin.sin_.data(), kin.cos_.data(), kin.angle_.size());
  // Parents first, in four-lane vectors (detail/lanes.hpp). The pose of body i - 1, the parent of
  // most bodies, stays in registers; the results are stored once.
  using detail::Lanes;
  using detail::LaneMatrix;
  const Lanes base = detail::lanes(p_b);
  LaneMatrix R = detail::lanes(kin.R[0]);
  Lanes p = base, first_moment = Lanes{0.0, 0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < nb; ++i) {
    const detail::JointMotion& j = bodies[i];
    if (j.parent >= 0) {
      const bool previous = j.parent == static_cast<int>(i) - 1;
      const LaneMatrix R_parent = previous ? R : detail::lanes(kin.R[j.parent]);
      const Lanes p_parent = previous ? p : detail::lanes(kin.p[j.parent]);
      if (j.kind == detail::JointMotion::Revolute) {  // rotation about the joint's axis line, then pose(0)
        const double s = kin.sin_[i], c1 = 1.0 - kin.cos_[i];
        R = detail::times(R_parent, Matrix3d(j.R0 + s * j.K1 + c1 * j.K2));
        p = p_parent + detail::times(R_parent, Vector3d(j.p0 + s * j.k1 + c1 * j.k2));
      } else {
        R = detail::times(R_parent, j.R0);
        p = p_parent + detail::times(R_parent, j.kind == detail::JointMotion::Prismatic
                                                   ? Vector3d(j.p0 + j.scale * state.q.data(j.joint) * j.axis)
                                                   : j.p0);
      }
      detail::store(R, kin.R[i]);
      detail::store(p, kin.p[i]);
      if (j.joint >= 0) {
        // The joint's unit twist, rotated to world axes and moved from the parent's origin to p_b.
        const Lanes w = detail::times(R_parent, j.twist_w);
        const Lanes v = detail::times(R_parent, j.twist_v) + detail::cross(w, base - p_parent);
        detail::store3(v, kin.S[i].data());
        detail::store3(w, kin.S[i].data() + 3);
      }
    }
    const Lanes c = detail::times(R, j.com) + p;
    detail::store(c, kin.com[i]);
    detail::store(detail::timesTransposed(detail::times(R, j.I_com), R), kin.I_com[i]);  // R I R^T
    first_moment += j.mass * c;
  }
  const Vector3d r_g = Vector3d(first_moment[0], first_moment[1], first_moment[2]) / model.totalMass();
  kin.p_b = p_b;
  kin.r_g = r_g;
  // Finite inputs of absurd magnitude (a base 1e300 m away) overflow: refuse.
  if (!kin.r_g.allFinite() || !kin.p.back().allFinite()) return E_NOT_FINITE;
  kin.state.world_T_base = state.world_T_base;
  kin.state.q.data = state.q.data;
  kin.valid = true;
  return E_NOERROR;
}

}  // namespace kdl_space
