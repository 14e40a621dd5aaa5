// The frictional point impact's slip process (docs/IMPACT.md): Coulomb friction through the
// impact by Routh's method in impulse space with Stronge's energetic restitution. Private to the
// library: solveImpact (impact.cpp) checks the inputs and calls it for FrictionalImpact, mu > 0.
#pragma once

#include "kdl_space/spatial/spatial.hpp"

namespace kdl_space::friction {

/// Result of the slip process.
struct SlipProcess {
  Vector3d P = Vector3d::Zero();  ///< impulse on B
  bool sticking = false;          ///< the contact ends the impact without slip
  /// The step budget was spent (a chattering contact) and the impact completed by the
  /// maximum-dissipation impulse.
  bool completed_by_max_dissipation = false;
};

/// \brief The force impulse P on B of a frictional point impact (A receives -P).
/// \param W translational block of G_A + G_B (positive definite): du = -W dP
/// \param n unit normal from A toward B; \param mu friction coefficient > 0; \param e Stronge's
/// energetic restitution in [0, 1]; \param u0 relative velocity v_A - v_B before, n.u0 > 0.
/// Every increment lies in the friction cone; energy can only be lost. Allocation-free.
SlipProcess solveSlipProcess(const Matrix3d& W, const Vector3d& n, double mu, double e, const Vector3d& u0);

}  // namespace kdl_space::friction
