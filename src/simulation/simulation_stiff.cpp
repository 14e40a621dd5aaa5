// The simulator's stiff step: RODAS3 (detail/rosenbrock.hpp) on the same derivative as the
// explicit methods.
#include "detail/rosenbrock.hpp"
#include "kdl_space/simulation/simulation.hpp"
#include "simulation/simulation_layout.hpp"

namespace kdl_space {

void Simulator::StiffDeleter::operator()(detail::RosenbrockStepper* p) const { delete p; }

void Simulator::makeStiffStepper() {
  stiff_.reset(new detail::RosenbrockStepper(detail::StateLayout(model().nj()).size));
}

double Simulator::stiffErrorExponent() const { return -1.0 / (detail::RosenbrockStepper::embedded_order + 1); }

int Simulator::stepRosenbrock(double t, double h, const Vector& x, double& error, bool& trial_failed) {
  const detail::WrenchClock clock(wrench_clock_, t, h);
  // A lambda holding only `this` is stored inside std::function: no allocation.
  const int rc = stiff_->step([this](double s, const Vector& y, Vector& dy) { return derivative(s, y, dy); }, t, h, x,
                              x_new_, error, options_.rtol, options_.atol);
  // A stage (or a Jacobian column) where the dynamics are undefined: a smaller step may avoid it.
  trial_failed = rc == E_NOT_FINITE || rc == E_NOT_POSITIVE_DEFINITE;
  return rc;
}

}  // namespace kdl_space
