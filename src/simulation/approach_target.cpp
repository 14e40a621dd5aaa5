#include "kdl_space/simulation/approach_target.hpp"

#include <cmath>
#include <string>

namespace kdl_space {

int RigidApproachTarget::grasp(double t, const KDL::Frame& grasp, KDL::Frame& frame, Vector6d& twist) {
  RigidTarget b;
  if (const int rc = motion_.at(t, b)) return rc;
  const KDL::Frame g = b.pose * grasp;
  const Vector3d c = toEigen(b.pose * toKDL(b.com));
  const Vector3d w = b.twist.tail<3>();
  twist << b.twist.head<3>() + w.cross(toEigen(g.p) - c), w;  // the grasp point's velocity
  frame = g;
  return E_NOERROR;
}

FloatingApproachTarget::FloatingApproachTarget(std::unique_ptr<Simulator> sim, SimulationState start, int link,
                                               double checkpoint_step)
    : sim_(sim ? std::move(sim) : throw ModelError("FloatingApproachTarget: null simulator")),
      link_(link),
      step_(checkpoint_step),
      kin_(sim_->model()),
      momentum_(std::shared_ptr<const FloatingModel>(std::shared_ptr<const FloatingModel>(), &sim_->model())) {
  const FloatingModel& model = sim_->model();
  if (link_ < 0 || link_ >= static_cast<int>(model.bodies().size()))
    throw ModelError("FloatingApproachTarget: the grasp's link " + std::to_string(link_) + " is no body of the target");
  if (!(step_ > 0.0) || !std::isfinite(step_))
    throw ModelError("FloatingApproachTarget: the checkpoint step must be finite and > 0");
  // A `hold` set point is the target's position at the start of the approach, once: every
  // checkpoint's run would otherwise take it again from where that run starts.
  for (unsigned int j = 0; j < model.nj(); ++j) {
    JointControl c = sim_->jointControls()[j];
    if (c.mode != JointControl::Mode::PD || !c.hold) continue;
    c.hold = false;
    c.set_point = start.state.q(j);
    sim_->setJointControl(j, c);
  }
  if (const int rc = sim_->engageBrakes(start))
    throw ModelError(std::string("FloatingApproachTarget: the target's start: ") + strError(rc));
  checkpoints_.push_back(std::move(start));
  scratch_ = checkpoints_.front();
}

int FloatingApproachTarget::state(double t, SimulationState& out) {
  const double t0 = checkpoints_.front().t;
  if (!std::isfinite(t)) return E_NOT_FINITE;
  if (t < t0) return E_BAD_ARGUMENT;
  // The checkpoint at or before t (its time computed as the extension does: t0 + k step).
  std::size_t k = static_cast<std::size_t>(std::floor((t - t0) / step_));
  while (k > 0 && t0 + static_cast<double>(k) * step_ > t) --k;
  while (checkpoints_.size() <= k) {
    SimulationState next = checkpoints_.back();
    const double t_next = t0 + static_cast<double>(checkpoints_.size()) * step_;
    if (const int rc = sim_->run(next, t_next, step_, {})) return rc;
    next.t = t_next;
    checkpoints_.push_back(std::move(next));
  }
  scratch_ = checkpoints_[k];
  if (t > scratch_.t)
    if (const int rc = sim_->run(scratch_, t, t - scratch_.t, {})) return rc;
  out = scratch_;
  out.t = t;
  return E_NOERROR;
}

int FloatingApproachTarget::grasp(double t, const KDL::Frame& grasp, KDL::Frame& frame, Vector6d& twist) {
  SimulationState s;
  if (const int rc = state(t, s)) return rc;
  if (const int rc = forwardKinematics(sim_->model(), s.state, kin_)) return rc;
  if (const int rc = momentum_.compute(kin_, s.velocity)) return rc;
  const KDL::Frame g = kin_.pose(link_) * grasp;
  // The link's twist at the grasp point (a material point of the link there).
  if (const int rc = momentum_.contactTwist(Contact{link_, kin_.pose(link_).Inverse() * g.p}, twist)) return rc;
  frame = g;
  return E_NOERROR;
}

}  // namespace kdl_space
