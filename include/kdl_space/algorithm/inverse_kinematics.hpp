// Inverse kinematics of a free-floating model's contact frame on KDL's solvers: the joint angles
// that put a contact frame (a link's axes, its origin moved to the contact offset) at a world pose,
// the base held where the state puts it. A set-up call (it builds KDL's chain and solvers), not a
// per-step compute call.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>

#include "kdl_space/export.hpp"
#include "kdl_space/multibody/model.hpp"
#include "kdl_space/multibody/state.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space {

/// How solveInverseKinematics searches.
struct IkOptions {
  double position_tolerance = 1e-10;     ///< largest accepted |p - p_goal| [m]
  double orientation_tolerance = 1e-10;  ///< largest accepted rotation angle of R_goal^T R [rad]
  unsigned int max_iterations = 500;     ///< Newton-Raphson iterations per attempt
  /// Attempts after the first (from the seed): deterministic starts spread over the joints' limits.
  unsigned int restarts = 16;
  /// The posture a redundant arm prefers (model order, size nj()): among the solutions, the one
  /// where q - preferred has no component in the self-motion (null space of the contact frame's
  /// Jacobian), the first-order condition of the closest one. Unset: the seed's q.
  std::optional<KDL::JntArray> preferred;
};

/// A solution.
struct IkResult {
  KDL::JntArray q;                 ///< all joints (model order); joints off the chain keep the seed's
  double position_residual = 0;    ///< |p - p_goal| by the model's forward kinematics [m]
  double orientation_residual = 0; ///< rotation angle of R_goal^T R [rad]
  unsigned int iterations = 0;     ///< Newton-Raphson iterations, every attempt counted
  unsigned int attempts = 0;       ///< starts tried (1: the seed sufficed)
  std::vector<int> chain_joints;   ///< the joints that move the contact frame (model indices, base to tip)
  /// Null-space norm |N (preferred - q)| at the solution (0 for a non-redundant arm) [rad or m]
  double preference_gradient = 0;
};

/// \brief The pose was not reached within the tolerances after every restart (out of reach, or
/// only outside the joints' limits). Carries how far the best attempt came and its joint angles.
class KDL_SPACE_EXPORT IkUnreachable : public InputError {
 public:
  IkUnreachable(const std::string& what, IkResult best) : InputError(what), best_(std::move(best)) {}
  ~IkUnreachable() override;
  /// The best attempt (inside the limits): its angles and residuals.
  const IkResult& best() const { return best_; }

 protected:
  std::exception_ptr renamed(const std::string& what) const override;

 private:
  IkResult best_;
};

/// \brief The joint angles that put the contact frame of `contact` (the axes of link
/// `contact.body`, origin at `contact.offset` in that link's frame) at `world_T_goal`, with the
/// base at `seed.world_T_base`; every joint inside its limits (JointProperties lower/upper).
///
/// Method: the chain from the base to the contact link (KDL::Tree::getChain; a tree's other
/// branches keep the seed's angles); Newton-Raphson steps over KDL's ChainIkSolverVel_pinv, each
/// at most 0.5 rad (or m) per joint and clamped to the limits, as ChainIkSolverPos_NR_JL does but
/// with an error twist accurate to round-off (KDL's diff, which NR_JL and LMA test convergence
/// with, reads rotations below ~1e-6 rad as none); a start where that fails is retried by KDL's
/// ChainIkSolverPos_LMA (Levenberg-Marquardt, clamped into the limits) finished by the same steps;
/// then from the next of `restarts` deterministic starts. For a redundant chain (more than six
/// joints) null-space steps q += N (preferred - q), each projected back onto the pose, until
/// N (preferred - q) vanishes. The residuals are measured by the
/// model's own forwardKinematics, not by the chain's.
/// \throws ModelError for a model with mimic joints, a contact body outside the model, a seed of
/// the wrong size or a non-finite goal; IkUnreachable (an InputError) when no attempt reaches
/// the tolerances: its message gives the remaining distance [m] and angle [rad].
KDL_SPACE_EXPORT IkResult solveInverseKinematics(const FloatingModel& model, const State& seed, const Contact& contact,
                                                 const KDL::Frame& world_T_goal, const IkOptions& options = {});

/// World pose of the contact frame of `contact` at `state` (the link's axes, origin at the offset).
/// \throws ModelError for a state of the wrong size or a contact body outside the model.
KDL_SPACE_EXPORT KDL::Frame contactFrame(const FloatingModel& model, const State& state, const Contact& contact);

}  // namespace kdl_space
