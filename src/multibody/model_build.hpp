// Between KDL's trees and the model's bodies: the inertia conversions and the traversal that
// makes bodies and coordinates (mimic joints included) from a tree. Private to the library.
#pragma once

#include <kdl/rigidbodyinertia.hpp>
#include <string>
#include <vector>

#include "kdl_space/multibody/model.hpp"

namespace kdl_space::detail {

/// Mass, CoM and inertia about the CoM of a KDL inertia (KDL keeps the inertia about the
/// reference frame's origin) into `body`.
void splitInertia(const KDL::RigidBodyInertia& I, Body& body);

/// Throws the model's ModelError: `what 'name': message` (what: "link" or "joint").
[[noreturn]] void fail(const std::string& what, const std::string& name, const std::string& message);

/// The KDL inertia of a body's mass, CoM and inertia about the CoM.
KDL::RigidBodyInertia kdlInertia(const Body& b);

/// \brief The rule on the system's mass matrix, for what the link rules let pass without judging
/// it: a free-floating base without mass (the links may supply it), and rigid bodies with a
/// rotational inertia but no mass on movable joints. When the model has either, its mass matrix
/// (6 + n: the base twist, then the coordinates) at q = 0 must be positive definite: then a note
/// `massless_base` for a massless base, else RuleError `base_without_mass` (the base's links and
/// the joints that move with it) or `singular_inertia` (the joints that move no inertia).
void checkMassMatrix(const FloatingModel& model, std::vector<Diagnostic>& diagnostics);

}  // namespace kdl_space::detail
