// One configuration of the capture plan's chart (include/kdl_space/planning/capture_plan.hpp):
// the parameters -> the arm's joints -> the capture -> the objective's terms and the limits.
// Private to the library.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "kdl_space/impact/capture.hpp"
#include "kdl_space/planning/capture_plan.hpp"
#include "kdl_space/simulation/rigid_motion.hpp"
#include "study/study_self_motion.hpp"

namespace kdl_space {

/// The parameters of one configuration.
struct PlanPoint {
  double self_motion = 0.0, wrist_roll = 0.0, timing = 0.0;
};

class PlanEvaluator {
 public:
  /// \throws InputError "plan: ..." / "objective: ..." / "<parameter>: ..." for what planCapture refuses.
  PlanEvaluator(const Scenario& scenario, const PlanOptions& options);
  /// The terms at `x`; the joints and rates after into `q`, `qdot_after` (may be null). Never
  /// throws for a configuration that cannot be reached or computed: infeasible, and why.
  PlanTerms evaluate(const PlanPoint& x, std::vector<double>* q = nullptr, std::vector<double>* qdot_after = nullptr);
  /// The penalised objective the optimiser sees: the objective, or 1e6 + the violation.
  static double score(const PlanTerms& terms);
  bool redundant() const { return redundant_; }
  const PlanOptions& options() const { return options_; }  ///< with the self-motion's range resolved

 private:
  /// The joints after the inverse kinematics of (wrist_roll, timing), kept for the next call with
  /// the same pair (a scan varies the self-motion fastest); false: unreachable (why in `why`).
  bool handPlaced(const PlanPoint& x, std::string& why);
  double violation(const std::vector<double>& q, const KDL::JntArray& qdot_after, std::string& why) const;

  const Scenario& scenario_;
  PlanOptions options_;
  bool redundant_ = false;
  KDL::Frame hand0_;  ///< the contact frame at the scenario's state (H0)
  std::optional<FreeRigidMotion> tumble_;  ///< a rigid target's motion (timing searched)
  CaptureSolver capture_;
  CaptureProblem problem_;
  // The last (wrist_roll, timing) placed: its joints, its self-motion and the target then.
  std::optional<std::pair<double, double>> placed_key_;
  bool placed_ok_ = false;
  std::string placed_why_;
  State placed_;
  std::unique_ptr<SelfMotion> self_motion_;
  RigidTarget target_at_;
};

}  // namespace kdl_space
