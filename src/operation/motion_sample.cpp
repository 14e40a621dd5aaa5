#include "kdl_space/operation/motion_sample.hpp"

#include <cmath>

namespace kdl_space {

const char* toString(Phase phase) {
  switch (phase) {
    case Phase::Approach: return "approach";
    case Phase::Capture: return "capture";
    case Phase::Post: return "post";
    case Phase::Motion: return "motion";
    case Phase::Contact: return "contact";
  }
  return "?";
}

int sampleOf(Simulator& sim, const SimulationState& x, Phase phase, MotionSample& smp) {
  smp.t = x.t;
  smp.p = toEigen(x.state.world_T_base.p);
  x.state.world_T_base.M.GetQuaternion(smp.quat(0), smp.quat(1), smp.quat(2), smp.quat(3));
  smp.twist = toEigen(x.velocity.base_twist);
  smp.q = x.state.q.data;
  smp.qd = x.velocity.qdot.data;
  smp.tau = x.tau.data;
  smp.base_wrench = x.base_wrench;
  smp.work << x.work.controller, x.work.friction, x.work.limits, x.work.base_control, x.work.wrenches, x.work.gravity;
  smp.impulse = x.impulse;
  smp.wheel_momentum = x.wheel_momentum;
  smp.wheel_torque = x.wheel_torque;
  smp.phase = phase;
  const int rc = sim.energyAndMomentum(x, smp.T, smp.h);
  if (rc) smp.T = std::nan(""), smp.h.setConstant(std::nan(""));
  return rc;
}

}  // namespace kdl_space
