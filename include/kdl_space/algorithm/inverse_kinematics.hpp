// Inverse kinematics of a free-floating model's contact frame on KDL's solvers: the joint angles
// that put a contact frame (a link's axes, its origin moved to the contact offset) at a world pose,
// the base held where the state puts it. A set-up call (it builds KDL's chain and solvers), not a
// per-step compute call.
#pragma once

#include <limits>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>

#include "kdl_space/export.hpp"
#include "kdl_space/multibody/model.hpp"
#include "kdl_space/multibody/poses.hpp"  // contactFrame: the contact frame solved for
#include "kdl_space/multibody/state.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space {

/// \brief Which of a redundant arm's solutions (more than six joints on the contact's chain: a
/// self-motion that keeps the contact frame's pose) solveInverseKinematics returns.
enum class IkPreference {
  /// The one closest to IkOptions::preferred (the first-order condition: q - preferred has no
  /// component in the self-motion).
  Posture,
  /// \brief The reaction-minimising one: the least reactionMeasure (the base's angular rate a
  /// unit hand motion produces), after the reaction null space of Yoshida and Nenchev (Nenchev,
  /// Yoshida, Umetani, "Reaction null-space control of flexible structure mounted manipulator
  /// systems", IEEE T-RA 15(6), 1999) and the disturbance map of Dubowsky and Torres ("Path
  /// planning for space manipulators to minimize spacecraft attitude disturbances", ICRA 1991):
  /// from it the hand moves with the least turning of the base.
  Reaction,
};

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
  /// Which self-motion solution a redundant arm returns (`preferred` is unused for Reaction).
  IkPreference prefer = IkPreference::Posture;
  /// Fill IkResult::reaction_measure (a free-floating solve at each attempt's end); false leaves it
  /// NaN (a caller that solves many poses and reads only q: the capture plan).
  bool measure_reaction = true;
  /// \brief The caller's way to stop the search (Ctrl-C): called before every Newton-Raphson
  /// iteration and every attempt; true throws Cancelled. It may also throw its own exception
  /// (Python's KeyboardInterrupt), which propagates. Empty: never cancelled.
  std::function<bool()> cancelled;
};

/// A solution.
struct IkResult {
  KDL::JntArray q;                 ///< all joints (model order); joints off the chain keep the seed's
  double position_residual = 0;    ///< |p - p_goal| by the model's forward kinematics [m]
  double orientation_residual = 0; ///< rotation angle of R_goal^T R [rad]
  unsigned int iterations = 0;     ///< Newton-Raphson iterations, every attempt counted
  unsigned int attempts = 0;       ///< starts tried (1: the seed sufficed)
  std::vector<int> chain_joints;   ///< the joints that move the contact frame (model indices, base to tip)
  /// The preference's first-order residual at the solution (0 for a non-redundant arm): Posture
  /// |N (preferred - q)| [rad or m]; Reaction |N grad reactionMeasure| [1/rad].
  double preference_gradient = 0;
  /// reactionMeasure at the solution (whichever preference; NaN where J* cannot be computed).
  double reaction_measure = std::numeric_limits<double>::quiet_NaN();
};

/// \brief The reaction measure of a configuration: || W J_h^+ ||_F, the Frobenius norm of the map
/// from the contact frame's twist (v; w) to the base's angular velocity when the hand moves by the
/// least-norm rates of `joints` (the others still) with zero momentum. J_h (6 x k) is J* of
/// `contact` and W (3 x k) the angular rows of J* of the base's frame, both over the columns of
/// `joints` (model indices); + is the Moore-Penrose inverse (singular values below 1e-12 of the
/// largest dropped). Its square is the sum, over the six unit hand twists, of the squared base
/// angular rate [rad/s per m/s or rad/s]: near a singularity of J_h it grows without bound.
/// \throws ModelError for a state or contact the free-floating solver refuses.
KDL_SPACE_EXPORT double reactionMeasure(const FloatingModel& model, const State& state, const Contact& contact,
                                        const std::vector<int>& joints);

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
/// N (preferred - q) vanishes (Posture), or (Reaction) a scan along a one-dimensional
/// self-motion, then steps down N grad reactionMeasure, each projected back onto the pose. The residuals are measured by the
/// model's own forwardKinematics, not by the chain's.
/// Mimic joints (URDF <mimic>) are not coordinates: on the chain each turns with its leader
/// (chain angle multiplier * leader + offset), and the search runs in the coordinates (the chain's
/// Jacobian times the coupling, J T, as the dynamics do); off the chain they keep their relation
/// to their leaders. The limits searched are the coordinates' own.
/// \throws ModelError for a contact body outside the model, a seed of the wrong size or a
/// non-finite goal; InputError when no movable joint lies between the base and the contact link
/// (a robot without joints: it moves only with the base); IkUnreachable (an InputError) when no
/// attempt reaches the tolerances: its message gives the remaining distance [m] and angle [rad].
KDL_SPACE_EXPORT IkResult solveInverseKinematics(const FloatingModel& model, const State& seed, const Contact& contact,
                                                 const KDL::Frame& world_T_goal, const IkOptions& options = {});

}  // namespace kdl_space
