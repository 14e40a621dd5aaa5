// Between KDL's trees and the model's bodies: the inertia conversions and the traversal that
// makes bodies and coordinates (mimic joints included) from a tree. Private to the library.
#pragma once

#include <kdl/rigidbodyinertia.hpp>
#include <string>

#include "kdl_space/multibody/model.hpp"

namespace kdl_space::detail {

/// Mass, CoM and inertia about the CoM of a KDL inertia (KDL keeps the inertia about the
/// reference frame's origin) into `body`.
void splitInertia(const KDL::RigidBodyInertia& I, Body& body);

/// Throws the model's ModelError: `what 'name': message` (what: "link" or "joint").
[[noreturn]] void fail(const std::string& what, const std::string& name, const std::string& message);

/// The KDL inertia of a body's mass, CoM and inertia about the CoM.
KDL::RigidBodyInertia kdlInertia(const Body& b);

}  // namespace kdl_space::detail
