// Private to the simulator: the forward dynamics a motion runs, chosen once per model.
#pragma once

#include <memory>
#include <variant>
#include <vector>

#include "kdl_space/algorithm/dense_forward_dynamics.hpp"
#include "kdl_space/algorithm/forward_dynamics.hpp"

namespace kdl_space::detail {

/// \brief The accelerations of a motion: the O(n) articulated-body recursion, for every model (mimic
/// joints as constraints on it: O(n k + k^3) for k of them). Measured against the dense route
/// (docs/benchmarks.md, "Mimic joints"), it was as fast or faster in every case but one: 1.2x to 8x
/// with four mimic joints on 10 to 100 joints, 1.0x to 1.5x with a third of them mimic, 0.94x
/// there at 30 joints only; so no rule on k here (G*'s is multibody/mimic_route.hpp). The seam
/// keeps the dense composite-rigid-body route (O(n^3)) as an alternative, which no model takes now.
/// Both keep ForwardDynamicsSolver's contract, so the simulator never asks which route it runs.
/// A copy is an independent solver (stopJoints' with other locks and no gravity).
class Dynamics {
 public:
  explicit Dynamics(const std::shared_ptr<const FloatingModel>& model)
      : route_(Route(std::in_place_type<ForwardDynamicsSolver>, model)) {}

  void setGravity(const Vector3d& g) {
    std::visit([&](auto& d) { d.setGravity(g); }, route_);
  }
  void setGrounded(bool grounded) {
    std::visit([&](auto& d) { d.setGrounded(grounded); }, route_);
  }
  void setLocked(const std::vector<bool>& locked) {
    std::visit([&](auto& d) { d.setLocked(locked); }, route_);
  }
  int CartToJnt(const Kinematics& kin, const FloatingVelocity& velocity, const KDL::JntArray& tau,
                const std::vector<KDL::Wrench>& f_ext, FloatingAcceleration& acceleration) {
    return std::visit([&](auto& d) { return d.CartToJnt(kin, velocity, tau, f_ext, acceleration); }, route_);
  }

 private:
  using Route = std::variant<ForwardDynamicsSolver, DenseForwardDynamicsSolver>;
  Route route_;
};

}  // namespace kdl_space::detail
