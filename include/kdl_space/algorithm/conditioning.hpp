// How well conditioned a configuration is for a capture: the singular values of the generalized
// Jacobian J* (eq. 4), its condition number, the manipulability of J* and of the fixed-base J,
// each joint's margin to its limits, and the warnings a tool or binding shows about them.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/export.hpp"
#include "kdl_space/multibody/diagnostics.hpp"
#include "kdl_space/multibody/model.hpp"
#include "kdl_space/multibody/state.hpp"

namespace kdl_space {

/// \brief A configuration is "near a singularity of J*" when sigma_min / sigma_max of J* is below
/// this ratio (1 / condition number). J*'s rows mix m/rad and 1/1, so the ratio depends on the
/// units (metres): 1e-3 flags a hand that loses a direction long before it is exactly singular
/// (a 0.5 m arm: 0.5 mm/s of hand speed per rad/s in its worst direction).
constexpr double kNearSingularRatio = 1e-3;

/// \brief Conditioning of a contact point's Jacobians (6 x n each).
struct Conditioning {
  /// Singular values of J*, largest first, min(6, n) of them (Eigen's JacobiSVD).
  Eigen::VectorXd sigma_J_star;
  /// sigma_max / sigma_min of J*; +infinity when sigma_min is 0 (or n = 0).
  double condition_number = std::numeric_limits<double>::infinity();
  /// Yoshikawa's manipulability of J*: the product of its singular values, which is
  /// sqrt(det(J* J*^T)) for n >= 6 and sqrt(det(J*^T J*)) for n < 6 (J* J*^T is then singular).
  double manipulability_J_star = 0.0;
  /// The same of the fixed-base J (base held still).
  double manipulability_J = 0.0;
  /// sigma_min / sigma_max of J* (0 when n = 0): compared with kNearSingularRatio.
  double ratio() const { return condition_number > 0 ? 1.0 / condition_number : 0.0; }
};

/// The conditioning of J* and J (both 6 x n, same n). Not for a hot path: it runs two SVDs.
KDL_SPACE_EXPORT Conditioning conditioning(const Eigen::MatrixXd& J_star, const Eigen::MatrixXd& J);

/// \brief One joint's margin to its limits at q: signed, negative outside.
struct JointMargin {
  int joint = -1;                  ///< model order
  bool limited = false;            ///< false for a continuous joint (no margin)
  double to_lower = std::numeric_limits<double>::infinity();  ///< q - lower [rad or m]
  double to_upper = std::numeric_limits<double>::infinity();  ///< upper - q [rad or m]
  /// min(to_lower, to_upper): the distance to the nearer limit, negative outside the limits.
  double margin() const { return to_lower < to_upper ? to_lower : to_upper; }
  bool outside() const { return limited && margin() < 0.0; }
};

/// Every coordinate's margin at q (model order, size nj()); q must have nj() values.
KDL_SPACE_EXPORT std::vector<JointMargin> jointMargins(const FloatingModel& model, const KDL::JntArray& q);

/// \brief The warnings about a configuration: a joint outside its limits (kind
/// `joint_outside_limits`, element the joint) and, with `c`, J* near a singularity (kind
/// `near_singular`, element `contact`: sigma_min / sigma_max < kNearSingularRatio).
KDL_SPACE_EXPORT std::vector<Diagnostic> configurationWarnings(const FloatingModel& model, const KDL::JntArray& q,
                                                               const Conditioning* c, const std::string& contact);

/// \brief The conditioning of contact `h` at `state` and the warnings about that configuration
/// (limits, singularity): what `capture`, `simulate` and the bindings check at a capture.
/// Builds a solver of its own (not for a hot path).
/// \return 0, or the solver's code (then `c` and `warnings` hold the limit warnings only).
KDL_SPACE_EXPORT int checkConfiguration(const std::shared_ptr<const FloatingModel>& model, const State& state,
                                        const Contact& h, Conditioning& c, std::vector<Diagnostic>& warnings);

}  // namespace kdl_space
