// The solvers' set-up calls (setLocked, setGravity) check their arguments alike: a refusal is a
// ModelError that names the call, what it got and what it takes (errors.hpp), the solver unchanged.
#pragma once

#include <string>
#include <vector>

#include "spatial/message_text.hpp"
#include "kdl_space/multibody/model.hpp"

namespace kdl_space::detail {

/// \throws ModelError unless `locked` has one flag per joint of `model` (or none, where `none`
/// says so: no joint braked).
inline void checkLocked(const FloatingModel& model, const std::vector<bool>& locked, bool none, const char* who) {
  if (locked.size() == model.nj() || (none && locked.empty())) return;
  throw ModelError(std::string(who) + "::setLocked: " + std::to_string(locked.size()) + " braked-joint flags for a model of " +
                   std::to_string(model.nj()) + " joints; give one per joint, in the model's order (" +
                   listNames(model.jointNames()) + ")" + (none ? ", or none" : ""));
}

/// \throws ModelError unless every component of the gravity g is finite.
inline void checkGravity(const Vector3d& g, const char* who) {
  if (g.allFinite()) return;
  throw ModelError(std::string(who) + "::setGravity: the gravity (" + number(g.x()) + ", " + number(g.y()) + ", " +
                   number(g.z()) + ") m/s^2 is not finite; give three finite numbers (zero in orbit)");
}

}  // namespace kdl_space::detail
