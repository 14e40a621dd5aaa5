#include "kdl_space/simulation/integrator.hpp"

#include "spatial/message_text.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space {
namespace {

struct Named {
  Integrator integrator;
  const char* name;
};
// The names users write, in the order messages list them.
constexpr Named kNames[] = {
    {Integrator::RK4, "rk4"}, {Integrator::DormandPrince54, "dopri5"}, {Integrator::Rosenbrock, "rosenbrock"}};

}  // namespace

const char* toString(Integrator integrator) {
  for (const Named& n : kNames)
    if (n.integrator == integrator) return n.name;
  return "?";
}

Integrator integratorFromName(const std::string& name) {
  std::string accepted;
  for (const Named& n : kNames) {
    if (name == n.name) return n.integrator;
    accepted += (accepted.empty() ? "" : ", ") + std::string(n.name);
  }
  throw InputError(detail::echo(name) + " is not one of " + accepted);
}

}  // namespace kdl_space
