// What an approach tracks: the target's motion before the contact, as the frame the grasp is
// given in, at any time the controller asks (Runge-Kutta stages, rejected steps). A rigid target
// moves in closed form (FreeRigidMotion); a free-floating robot target is integrated by a
// Simulator of its own beside the servicer's (the two do not interact before the contact).
#pragma once

#include <memory>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/simulation/rigid_motion.hpp"
#include "kdl_space/simulation/simulation.hpp"

namespace kdl_space {

/// \brief The target's motion as an approach sees it.
class KDL_SPACE_EXPORT ApproachTarget {
 public:
  virtual ~ApproachTarget() = default;
  /// \brief At time t (>= the start): the grasp frame, `grasp` given in the target's frame (a
  /// rigid target's frame; a robot target's contact link), and its twist (v of the grasp point;
  /// w), world. \return 0 or an Error code (E_BAD_ARGUMENT for t before the start).
  virtual int grasp(double t, const KDL::Frame& grasp, KDL::Frame& frame, Vector6d& twist) = 0;
};

/// A rigid target moving freely: FreeRigidMotion's closed form.
class KDL_SPACE_EXPORT RigidApproachTarget : public ApproachTarget {
 public:
  explicit RigidApproachTarget(FreeRigidMotion motion) : motion_(std::move(motion)) {}
  int grasp(double t, const KDL::Frame& grasp, KDL::Frame& frame, Vector6d& twist) override;
  /// The target's state at time t.
  int at(double t, RigidTarget& out) { return motion_.at(t, out); }

 private:
  FreeRigidMotion motion_;
};

/// \brief A free-floating robot target moving on its own (free, or with the brakes and servos its
/// simulator was given), from `start`.
///
/// Its state at t is the simulator's integration from the latest checkpoint at or before t; the
/// checkpoints are the states at start.t + k checkpoint_step, each integrated from the one
/// before it (extended as later times are asked for). So state(t) is a function of t alone (the
/// same answer whatever was asked before), exact to the simulator's tolerances (rtol, atol), and
/// continuous across checkpoints to those tolerances (the error accepted: a step of the
/// simulator's local error at a checkpoint, no interpolation). Momentum is an invariant of every
/// Runge-Kutta step (Simulator), so a free target's momentum is kept to round-off. Each query
/// integrates at most one checkpoint_step.
class KDL_SPACE_EXPORT FloatingApproachTarget : public ApproachTarget {
 public:
  /// \param sim the target's own simulator (its joint controls and options set; no torque
  /// callback, no stop condition); `hold` set points are taken from `start` here, once.
  /// \param link the body whose frame the grasp is given in (the target's contact link).
  /// \throws ModelError for a null simulator, a link that is no body, a checkpoint_step not
  /// finite and > 0, or a start the simulator cannot begin from (sizes, brakes).
  FloatingApproachTarget(std::unique_ptr<Simulator> sim, SimulationState start, int link,
                         double checkpoint_step = 0.01);
  int grasp(double t, const KDL::Frame& grasp, KDL::Frame& frame, Vector6d& twist) override;
  /// \brief The target's state at time t (>= start.t): base pose and twist, q, qdot.
  /// \return 0, E_BAD_ARGUMENT (t before the start), E_NOT_FINITE, or the simulator's code.
  int state(double t, SimulationState& out);
  const Simulator& simulator() const { return *sim_; }
  int link() const { return link_; }

 private:
  std::unique_ptr<Simulator> sim_;
  int link_;
  double step_;
  std::vector<SimulationState> checkpoints_;  ///< at start.t + k step_
  SimulationState scratch_;
  Kinematics kin_;
  MomentumSolver momentum_;
};

}  // namespace kdl_space
