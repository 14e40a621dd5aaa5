// One configuration of the capture plan's chart (include/kdl_space/planning/capture_plan.hpp):
// the parameters -> the arm's joints -> the capture -> the objective's terms and the limits.
// Private to the library.
#pragma once

#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/planning/capture_plan.hpp"
#include "kdl_space/simulation/rigid_motion.hpp"
#include "kdl_space/algorithm/self_motion.hpp"

namespace kdl_space {

/// The parameters of one configuration; closing_speed NaN: the scenario's rates before the capture.
struct PlanPoint {
  double self_motion = 0.0, wrist_roll = 0.0, timing = 0.0;
  double closing_speed = std::numeric_limits<double>::quiet_NaN();
};

/// The chart's parameter names, in the order of the documentation (and of CapturePlan::parameters).
const std::vector<std::string>& planParameters();

class PlanEvaluator {
 public:
  /// \throws InputError "plan: ..." / "objective: ..." / "<parameter>: ..." for what planCapture refuses.
  PlanEvaluator(const Scenario& scenario, const PlanOptions& options);
  /// The terms at `x`; the joints and the rates before and after into `joints` (may be null).
  /// Never throws for a configuration that cannot be reached or computed: infeasible, and why.
  /// With `measure` (or an operation term weighted), the motion after the capture too (terms.motion).
  PlanTerms evaluate(const PlanPoint& x, CapturePlan* joints = nullptr, bool measure = false);
  /// The horizon the measures read [s]: 0 when neither an operation term nor a horizon was asked.
  double horizon() const { return horizon_; }
  /// The penalised objective the optimiser sees: the objective, or 1e6 + the violation.
  static double score(const PlanTerms& terms);
  bool redundant() const { return redundant_; }
  const PlanOptions& options() const { return options_; }  ///< with the self-motion's range resolved

 private:
  /// The joints after the inverse kinematics of (wrist_roll, timing), kept for the next call with
  /// the same pair (a scan varies the self-motion fastest); false: unreachable (why in `why`).
  bool handPlaced(const PlanPoint& x, std::string& why);
  /// The rates before the capture that close on the grasp at `closing_speed` (capture_plan.hpp)
  /// into robot.velocity; false: the arm cannot give the hand that twist (why in `why`).
  bool closing(FloatingSystem& robot, double closing_speed, std::string& why);
  void setUpClosing();
  void setUpMotion();
  /// The motion after the capture of problem_ (its measures into t.motion); false: it failed (why in t).
  bool measured(PlanTerms& t);
  /// The excess over the position limits, the rate limits after the capture and, when the plan
  /// set them (`rates_before`), before it.
  double violation(const FloatingSystem& robot, const KDL::JntArray& qdot_after, bool rates_before, std::string& why) const;

  const Scenario& scenario_;
  PlanOptions options_;
  bool redundant_ = false;
  KDL::Frame hand0_;  ///< the contact frame at the scenario's state (H0)
  std::optional<FreeRigidMotion> tumble_;  ///< a rigid target's motion (timing searched)
  CaptureSolver capture_;
  bool score_motion_ = false;  ///< an operation term is weighted: every evaluation runs the motion
  double horizon_ = 0.0;
  std::optional<MotionMeasurer> measurer_;
  CaptureProblem problem_;
  // The last (wrist_roll, timing) placed: its joints, its self-motion and the target then.
  std::optional<std::pair<double, double>> placed_key_;
  bool placed_ok_ = false;
  std::string placed_why_;
  State placed_;
  std::unique_ptr<SelfMotion> self_motion_;
  RigidTarget target_at_;
  // The hand's velocity before the grasp (closing_speed planned): the robot's dynamics, its
  // momentum (P_g; L_g) at the scenario's state, and a free-floating target's grasp-point twist.
  std::unique_ptr<FreeFloatingSolver> dynamics_;
  Vector6d PL_g_ = Vector6d::Zero();
  Vector6d floating_target_twist_ = Vector6d::Zero();
};

}  // namespace kdl_space
