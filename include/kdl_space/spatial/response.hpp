// How a robot answers an impulse at a contact point: the paper's three cases, as an option of
// the solvers rather than separate code paths.
#pragma once

namespace kdl_space {

enum class Response {
  FreeFloating,  ///< base free: G* (eq. 11), the general case
  Grounded,      ///< base held still: G = J H^-1 J^T (eq. 22/23)
  JointsLocked,  ///< joints braked: one rigid body, R_h M_a^-1 R_h^T (eq. 20/21)
};

}  // namespace kdl_space
