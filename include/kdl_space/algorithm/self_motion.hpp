// The self-motion of a redundant arm: joint motions that keep the hand's pose (the base held),
// the one-parameter family of configurations that grasp the same point the same way. What a
// study's `robot.self_motion` samples and `plan` searches (kdl_space.self_motion in Python).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/export.hpp"

namespace kdl_space {

/// \brief Moves along the self-motion of the joints on the path to contact h.
class KDL_SPACE_EXPORT SelfMotion {
 public:
  /// \throws InputError "robot.self_motion: ..." unless the path to h has exactly one joint more
  /// than its Jacobian's rank 6 at `nominal` (a one-parameter self-motion).
  SelfMotion(std::shared_ptr<const FloatingModel> model, const Contact& h, const State& nominal);
  /// \brief `state` moved by arc length s [rad, in joint space] along the self-motion, in steps
  /// of at most 0.05 (midpoint rule, each step pulled back onto the hand's pose by Gauss-Newton).
  /// The direction at s > 0 is the one whose largest joint component is positive at the start.
  /// \return 0, or E_NOT_FINITE / E_NOT_POSITIVE_DEFINITE when the arm meets a singularity (its
  /// Jacobian loses rank) or the hand's pose cannot be held to 1e-10.
  int move(State& state, double s);

 private:
  int direction(const State& state, const Eigen::VectorXd& previous, Eigen::VectorXd& v);
  int handFrame(const State& state, KDL::Frame& F);
  int holdHand(State& state, const KDL::Frame& F0);
  FreeFloatingSolver solver_;
  Contact h_;
  std::vector<int> path_;  ///< the joints that move the hand (model order)
  KDL::Jacobian J_;
  Eigen::MatrixXd J_path_;
};

}  // namespace kdl_space
