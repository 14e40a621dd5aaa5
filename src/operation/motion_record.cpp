#include "kdl_space/operation/motion_record.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace kdl_space {

void MotionRecord::takeFrom(const Simulator& sim) {
  options = sim.options();
  stats = sim.stats();
  controls = sim.jointControls();
  limit_modes = sim.limitModes();
  base_control = sim.baseControl();
  wheels = sim.reactionWheels();
  friction_velocities = sim.frictionVelocities();
}

double MotionRecord::wheelMomentumFraction() const {
  if (wheels.count() == 0 || wheel_peak_momentum.size() != wheels.count()) return std::numeric_limits<double>::quiet_NaN();
  return (wheel_peak_momentum.array() / wheels.capacity.array()).maxCoeff();
}

void MotionRecord::add(const MotionSample& x) {
  if (samples++ == 0) first = x;
  last = x;
  const double rate = x.twist.tail<3>().norm();
  detumble.add(x.t, rate);
  peak_base_rate = std::max(peak_base_rate, rate);
  grasp.add(x);
  if (x.tau.size() > 0) {
    if (peak_torque.size() != x.tau.size()) peak_torque.setZero(x.tau.size());
    peak_torque = peak_torque.cwiseMax(x.tau.cwiseAbs());
  }
  const Eigen::Quaterniond q0(first.quat(3), first.quat(0), first.quat(1), first.quat(2));
  attitude_excursion = std::max(attitude_excursion, q0.angularDistance(Eigen::Quaterniond(x.quat(3), x.quat(0), x.quat(1), x.quat(2))));
  max_linear_momentum_change = std::max(max_linear_momentum_change, (x.h.head<3>() - first.h.head<3>()).norm());
  max_angular_momentum_change = std::max(max_angular_momentum_change, (x.h.tail<3>() - first.h.tail<3>()).norm());
  max_energy_change = std::max(max_energy_change, std::abs(x.T - first.T));
  const Vector6d e = x.h - first.h - x.impulse;
  balance_linear = std::max(balance_linear, e.head<3>().norm());
  balance_angular = std::max(balance_angular, e.tail<3>().norm());
  torques = torques || (x.tau.size() > 0 && x.tau.cwiseAbs().maxCoeff() > 0.0);
  if (x.wheel_momentum.size() > 0) {
    if (wheel_peak_momentum.size() != x.wheel_momentum.size()) {
      wheel_peak_momentum.setZero(x.wheel_momentum.size());
      wheel_peak_torque.setZero(x.wheel_momentum.size());
    }
    wheel_peak_momentum = wheel_peak_momentum.cwiseMax(x.wheel_momentum.cwiseAbs());
    if (x.wheel_torque.size() == x.wheel_momentum.size())
      wheel_peak_torque = wheel_peak_torque.cwiseMax(x.wheel_torque.cwiseAbs());
  }
}

double MotionRecord::meanStep() const {
  const long steps = stats.accepted_steps;
  return steps == 0 ? 0.0 : (t_reached - t_start) / static_cast<double>(steps);
}

std::vector<std::string> MotionRecord::lockedJoints() const {
  std::vector<std::string> out;
  for (std::size_t j = 0; j < controls.size(); ++j)
    if (controls[j].mode == JointControl::Mode::Locked) out.push_back(model->jointNames()[j]);
  return out;
}

std::string stiffnessAdvice(const MotionRecord& r) {
  const Stiffness& st = r.stiffness;
  const SimulationOptions& o = r.options;
  if (st.fastest_joint < 0) return {};
  const std::string joint = "'" + r.model->jointNames()[st.fastest_joint] + "'";
  std::ostringstream why;
  why.precision(3);
  if (o.integrator == Integrator::RK4 && o.step > st.explicit_step) {
    why << "simulation.step = " << o.step << " s is above the stable step " << st.explicit_step
        << " s of joint " << joint << " (closed-loop rate " << st.fastest_rate
        << " 1/s): lower the step or the gains, or use integrator: rosenbrock";
    return why.str();
  }
  // An explicit adaptive run whose steps are far below the output step, with a servo fast enough
  // to hold them there.
  const double mean = r.meanStep();
  if (o.integrator == Integrator::DormandPrince54 && mean > 0.0 && mean < 0.01 * r.output_step &&
      st.explicit_step < 0.01 * r.output_step) {
    why << "stiff: the servo of joint " << joint << " (closed-loop rate " << st.fastest_rate
        << " 1/s) holds dopri5's step near " << mean << " s (" << r.stats.accepted_steps
        << " steps): try integrator: rosenbrock (an rtol of 1e-6 or looser suits it)";
    return why.str();
  }
  return {};
}

}  // namespace kdl_space
