// The simulator's stiff (Rosenbrock) step.
#include "kdl_space/simulation.hpp"

namespace kdl_space {
namespace detail {
class RosenbrockStepper {};
}  // namespace detail

void Simulator::StiffDeleter::operator()(detail::RosenbrockStepper* p) const { delete p; }
void Simulator::makeStiffStepper() { throw ModelError("simulation: the Rosenbrock integrator is not built yet"); }
double Simulator::stiffErrorExponent() const { return -1.0 / 3.0; }
int Simulator::stepRosenbrock(double, double, const Vector&, double&, bool&) { return E_BAD_ARGUMENT; }

}  // namespace kdl_space
