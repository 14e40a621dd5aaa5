// The simulator's time integration schemes and their names, as scenarios, the tool and the
// Python module write them ("rk4", "dopri5", "rosenbrock").
#pragma once

#include <string>

#include "kdl_space/export.hpp"

namespace kdl_space {

/// Time integration schemes.
enum class Integrator {
  RK4,              ///< classical fixed-step Runge-Kutta, order 4
  DormandPrince54,  ///< adaptive embedded Runge-Kutta 5(4) with error control (Dormand & Prince 1980)
  Rosenbrock,       ///< adaptive linearly implicit (stiff) method: RODAS3 (Sandu et al. 1997)
};

/// The integrator's name: "rk4", "dopri5" or "rosenbrock" (a static string; "?" for a value
/// that is no enumerator).
KDL_SPACE_EXPORT const char* toString(Integrator integrator);

/// The integrator of a name toString() gives. \throws InputError "'NAME' is not one of rk4,
/// dopri5, rosenbrock" for any other text (the name shown as messages show input: at most 40
/// printable characters).
KDL_SPACE_EXPORT Integrator integratorFromName(const std::string& name);

}  // namespace kdl_space
