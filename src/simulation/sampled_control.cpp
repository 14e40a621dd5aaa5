#include "kdl_space/simulation/sampled_control.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace kdl_space {

ControlGrid controlGrid(double output_dt, double period) {
  ControlGrid g{output_dt};
  if (period == 0.0) return g;
  if (!(period > 0.0) || !std::isfinite(period)) {
    std::ostringstream why;
    why << "control period: expected a finite period > 0 s (1 / control_rate), got " << period;
    throw InputError(why.str());
  }
  if (!(output_dt > 0.0) || !std::isfinite(output_dt)) return g;  // run() refuses it with its code
  const double r = period / output_dt;
  for (long b = 1; b <= 1000; ++b) {
    const double x = r * static_cast<double>(b);
    const long a = std::lround(x);
    if (a >= 1 && std::abs(x - static_cast<double>(a)) <= 1e-9 * x) {
      g.a = a, g.b = b;
      g.delta = a == 1 ? period : b == 1 ? output_dt : period / static_cast<double>(a);
      return g;
    }
  }
  std::ostringstream why;
  why << "output_dt: " << output_dt << " s and the control period 1 / control_rate = " << period
      << " s are not commensurate (their ratio is no fraction a / b with b <= 1000)";
  throw InputError(why.str());
}

int sampledGainWarnings(Simulator& sim, const SimulationState& s, const SampledController& controller,
                        double control_rate, std::vector<Diagnostic>& warnings) {
  const unsigned int n = sim.model().nj();
  if (!controller || !(control_rate > 0.0) || !std::isfinite(control_rate)) return E_NOERROR;  // not sampled
  if (s.state.q.rows() != n || s.velocity.qdot.rows() != n) return E_SIZE_MISMATCH;
  const double dt = 1.0 / control_rate;
  SimulationState x = s;
  Eigen::VectorXd up(n), down(n);
  const auto torque = [&](Eigen::VectorXd& tau) {
    tau.setZero();
    controller(x, tau);
    if (tau.size() != static_cast<Eigen::Index>(n)) return E_SIZE_MISMATCH;
    return tau.allFinite() ? E_NOERROR : E_NOT_FINITE;
  };
  for (unsigned int j = 0; j < n; ++j) {
    if (sim.jointControls()[j].mode == JointControl::Mode::Locked) continue;  // braked: its rate is held
    // A central difference: exact for a controller linear in the rate; delta small beside the rates
    // a manipulator reaches, large beside the round-off of its torque.
    const double qdot = s.velocity.qdot(j), delta = 1e-4 * std::max(1.0, std::abs(qdot));
    x.velocity.qdot(j) = qdot + delta;
    if (const int rc = torque(up)) return rc;
    x.velocity.qdot(j) = qdot - delta;
    if (const int rc = torque(down)) return rc;
    x.velocity.qdot(j) = qdot;
    const double kd = -(up(j) - down(j)) / (2.0 * delta);
    if (!(kd > 0.0)) continue;  // no damping fed back (or positive feedback: not this check's)
    double m = 0.0;
    if (const int rc = sim.apparentInertia(s, j, m)) return rc;
    const double b = kd * dt / m;  // the bound's derivation: sampled_control.hpp
    if (b <= kSampledGainMargin) continue;
    const std::string& name = sim.model().jointNames()[j];
    std::ostringstream why;
    why.precision(3);
    why << "the controller sampled at " << control_rate << " Hz feeds back the rate of joint '" << name << "' with kd = "
        << kd << " N m s/rad (or N s/m) against its apparent inertia " << m << " kg m^2 (or kg): kd dt / m = " << b
        << (b >= 2.0 ? ", above 2: unstable under a zero-order hold" : ", above 1: it rings at the control rate")
        << "; sample at " << kd / (m * kSampledGainMargin) << " Hz or more, or lower kd to "
        << kSampledGainMargin * m * control_rate << " or less";
    warnings.push_back(Diagnostic{name, why.str(), "sampled_gain_unstable"});
  }
  return E_NOERROR;
}

int runSampled(Simulator& sim, SimulationState& s, double t_end, double output_dt, const SampledController& controller,
               double control_rate, const std::function<void(const SimulationState&)>& observer) {
  const bool hold = controller && control_rate != 0.0;  // a rate without a controller: nothing to hold
  const ControlGrid grid = controlGrid(output_dt, hold ? 1.0 / control_rate : 0.0);
  const double t0 = s.t;
  const Eigen::Index n = sim.model().nj();
  Eigen::VectorXd command = Eigen::VectorXd::Zero(n);
  bool commanded = false;
  int controller_rc = E_NOERROR;
  // The controller's answer and the state at a control instant: sized once per run, not per call.
  Eigen::VectorXd tau(n);
  SimulationState now;
  const auto call = [&](const SimulationState& x) {
    if (tau.size() != n) tau.resize(n);  // a controller that resized it was refused: E_SIZE_MISMATCH
    tau.setZero();
    controller(x, tau);
    if (tau.size() != n) controller_rc = E_SIZE_MISMATCH;
    else if (!tau.allFinite()) controller_rc = E_NOT_FINITE;
    else command = tau;
    commanded = true;
  };
  long outputs = 0;
  int sample_rc = E_NOERROR;
  const auto sampled = [&](const SimulationState& x) {
    const long i = outputs++;
    const bool last = x.t >= t_end;
    const SimulationState* row = &x;
    if (grid.a > 0 && i > 0 && i % grid.a == 0 &&
        (!last || std::abs(t0 + static_cast<double>(i) * grid.delta - t_end) <= 1e-9 * grid.delta)) {
      call(x);  // the command held from this instant on
      now = x;
      if (const int rc = sim.actuation(now)) sample_rc = rc;
      row = &now;
    }
    if (i % grid.b != 0 && !last) return;
    if (observer) observer(*row);
  };
  struct Guard {  // the callbacks refer to this frame: they go when the run ends, however it ends
    Simulator& sim;
    bool set = false;
    ~Guard() {
      if (!set) return;
      sim.setTorqueCallback(nullptr);
      sim.setStopCondition(nullptr);
    }
  } guard{sim};
  if (controller) {
    guard.set = true;
    sim.setTorqueCallback([&](const SimulationState& x, KDL::JntArray& tau) {
      if (!hold || !commanded) call(x);  // zero-order hold: the first command at the start
      tau.data = command;
    });
    // A controller that answered with a wrong size or a non-finite torque ends the run there.
    sim.setStopCondition([&](const SimulationState&) { return controller_rc != E_NOERROR; });
  }
  const int rc = sim.run(s, t_end, grid.delta, sampled);
  return controller_rc ? controller_rc : rc ? rc : sample_rc;
}

}  // namespace kdl_space
