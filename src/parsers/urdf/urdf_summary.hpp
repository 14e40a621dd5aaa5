// The physics summary of a URDF file the checker found no error in: the loaded model's figures
// and the condition numbers of H* and G* at q = 0. The only part of the checker that loads the
// model and runs a solver. Private to the library.
#pragma once

#include <string>
#include <vector>

#include "kdl_space/parsers/urdf/urdf_check.hpp"

namespace kdl_space::detail {

/// \brief When `report` has no errors: loads `xml` (the loader applies the checker's rules, so
/// it loads), fills `report.model` from `loaded` on (base, joints, mass, the condition numbers of
/// H* at q = 0 with the base at the origin, and of G* at `tips`, else at every link that carries
/// no other link); adds the errors `singular_inertia` and, should the loader still refuse the
/// file, `refused_by_loader` in the loader's words.
/// \return the condition numbers in words, for a message ("at q = 0, cond(H*) = ..."), or why
/// they were not computed.
/// Up to kDenseJoints (free_floating_solver.hpp) the dense route (cond(H*) by its eigenvalues,
/// O(n^3)); a larger model's G* at the tips comes from the O(n) recursion and cond(H*) is not
/// computed (the note `large_model` says so).
std::string measureModel(const std::string& xml, const std::vector<std::string>& tips, UrdfReport& report);

}  // namespace kdl_space::detail
