// The self-motion of a redundant arm: joint motions that keep the hand's pose (the base held),
// the one-parameter family of configurations that grasp the same point the same way. What a
// study's `robot.self_motion` samples and `plan` searches (kdl_space.self_motion in Python).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/export.hpp"

namespace kdl_space {

/// \brief Moves along the self-motion of the joints on the path to contact h.
class KDL_SPACE_EXPORT SelfMotion {
 public:
  /// The walk's step [rad of arc length in joint space]: the checkpoints lie at its multiples.
  static constexpr double kStep = 0.05;

  /// \throws InputError "robot.self_motion: ..." unless the path to h has exactly one joint more
  /// than its Jacobian's rank 6 at `nominal` (a one-parameter self-motion).
  SelfMotion(std::shared_ptr<const FloatingModel> model, const Contact& h, const State& nominal);
  /// \brief `state` moved by arc length s [rad, in joint space] along the self-motion: steps of
  /// kStep from `state` to the checkpoint at the largest multiple of kStep within |s|, then one
  /// step of what remains (midpoint rule, each step pulled back onto the hand's pose by
  /// Gauss-Newton). So the result is continuous in s, and the walk's checkpoints are kept: a move
  /// from the same state (bit for bit) walks only from the nearest checkpoint (what a scan along
  /// the self-motion and a local search around it ask for).
  /// The direction at s > 0 is the one whose largest joint component is positive at the start.
  /// \return 0, or E_NOT_FINITE / E_NOT_POSITIVE_DEFINITE when the arm meets a singularity (its
  /// Jacobian loses rank) or the hand's pose cannot be held to 1e-10.
  int move(State& state, double s);

 private:
  using PathJacobian = Eigen::Matrix<double, 6, 7>;
  using PathVector = Eigen::Matrix<double, 7, 1>;
  /// A point of the walk: the path's joints there and the direction its last step took.
  struct Checkpoint {
    PathVector q;
    PathVector v;
  };
  int pathJacobian(const State& state);
  int pathJacobian();  ///< at the state the kinematics last computed
  int direction(const State& state, const PathVector* previous, PathVector& v);
  int handFrame(const State& state, KDL::Frame& F);
  int holdHand(State& state, const KDL::Frame& F0);
  /// One midpoint step of h from `state` (`previous`: the direction the walk came along, or null
  /// at the start); its direction into `v_mid`.
  int step(State& state, double h, const PathVector* previous, PathVector& v_mid);
  /// The walk from `state` (a new start: the checkpoints are cleared).
  int restart(const State& state);
  /// The walk extended to `k` checkpoints on the side `way` (0: s > 0, 1: s < 0).
  int extend(int way, std::size_t k);

  // Kinematics only (no mass properties): the hand's frame and its fixed-base Jacobian.
  std::shared_ptr<const FloatingModel> model_;
  Kinematics kin_;
  Contact h_;
  std::vector<int> path_;  ///< the joints that move the hand (model order)
  Matrix6Xd J_;            ///< the hand's Jacobian (v at the hand; w), every coordinate
  State mid_;              ///< a step's midpoint (workspace)
  PathJacobian J_path_;
  // The walk from the last start: its state, hand frame, and checkpoints at (k + 1) kStep on
  // each side; a side stops at a failure (its code kept, returned for any s beyond it).
  bool started_ = false;
  State start_;
  KDL::Frame F0_;
  std::vector<Checkpoint> walk_[2];
  int failed_[2] = {0, 0};
};

}  // namespace kdl_space
