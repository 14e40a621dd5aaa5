// Capture planning: of the arm configurations that grasp the target at the scenario's grasp, the
// one whose capture disturbs the servicer least (reaction-null-space planning after Yoshida and
// Nenchev, by search). What `kdl_space plan` and kdl_space.plan_capture() run.
//
// The configurations are a chart of up to four parameters, each a documented function of the
// public API, so that a caller can rebuild any of them (the tests do):
//   timing t   the capture t [s] later: the rigid target moved on along its torque-free tumble
//              (FreeRigidMotion::at), the grasp frame riding with it:
//              G(t) = T(t) T(0)^-1 H0, H0 the contact frame at the scenario's state;
//   wrist_roll the hand rotated by psi [rad] about the contact frame's own z axis (the approach
//              axis of the shipped tools, along which their contact offset points): the goal
//              G(t) Rot_z(psi); the arm's joints then come from solveInverseKinematics with the
//              scenario's state as seed and preferred posture and no restarts (IkOptions
//              restarts = 0: the branch of the scenario's configuration, not another one found
//              from elsewhere), unless the goal is H0 itself (t = 0 and psi = 0): the scenario's
//              q, as written;
//   self_motion s [rad] along a redundant arm's self-motion from there (selfMotionJoints of the
//              scenario with that q): the hand's pose held. Absent for a non-redundant arm;
//   closing_speed c [m/s] (optional: unset, the scenario's rates before the capture, as written)
//              the hand's velocity before the grasp: its twist is the grasp point's twist on the
//              target (the rigid target's v_c + w x (p_h - c), w at t; a free-floating target's
//              contact twist) plus c along the contact frame's z, the approach axis; the joint
//              rates are the smallest that give it, qdot = J*^+ (t_h - R_h M_a^-1 (P_g; L_g))
//              (eq. 4; J and the base's twist carried to h for a grounded robot; braked joints at
//              0), with the system's momentum (P_g; L_g) the scenario's state gives, and the
//              base's twist follows from that momentum (FreeFloatingSolver::baseTwist). The
//              rates before then count against the joints' velocity limits too.
// The capture of each configuration is the scenario's (solveCapture: the same base pose and
// twist, joint rates, target and law; the target at its pose and twist at t), with the rates
// before it the closing speed's where that is planned.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/operation/motion_measures.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"

namespace kdl_space {

/// One planned parameter's range; lower == upper fixes it there (not searched).
struct PlanRange {
  double lower = 0.0, upper = 0.0;
  bool searched() const { return upper > lower; }
};

/// What planCapture searches and minimises.
struct PlanOptions {
  /// The objective: the weighted sum of the named terms (each weight > 0). At the instant of the
  /// capture (computed in microseconds: the fast proxy):
  ///   "base_rate"        |w| of the base after the capture [rad/s]
  ///   "impulse"          |f|, the linear part of the impulse on the robot [N s]
  ///   "joint_rate_jump"  max_j |qdot_j after - qdot_j before| [rad/s or m/s]
  /// Over the operation: the motion after the capture over `horizon` (runOperationFrom: the
  /// scenario's simulation section, its PD servos holding the capture configuration, its base
  /// control, a compliant law's contact), read at its output samples (MotionMeasures):
  ///   "peak_base_rate"     max |w| of the base [rad/s]
  ///   "final_base_rate"    |w| of the base at the horizon [rad/s]
  ///   "attitude_excursion" the base's largest turn from its attitude at the capture [rad]
  ///   "settling_time"      when the base's w last left its band about its final value [s]
  ///   "peak_torque_ratio"  max_j max_t |tau_j| / effort_j (the URDF's effort limits) [-]
  ///   "peak_grasp_force"   the grasp's largest |f| on the robot, in a compliant contact and while
  ///                        the captured target is held (MotionSample::grasp_wrench) [N]
  ///   "peak_grasp_moment"  and |n| [N m]
  std::vector<std::pair<std::string, double>> weights{{"base_rate", 1.0}};
  /// The motion after each capture that the operation terms score [s], > 0. Unset: the
  /// scenario's simulation.duration. Given (or an operation term weighted), the optimum and the
  /// nominal report their MotionMeasures (PlanTerms::motion) whatever the objective.
  std::optional<double> horizon;
  std::optional<double> output_step;  ///< where the motion is read [s]; unset: the scenario's
  double settling_band = 0.05;        ///< the settling time's band, relative (0, 1)
  /// The self-motion's range [rad of joint-space arc length]. Unset: [-1, 1] for an arm with a
  /// one-parameter self-motion (7 joints on the path to the contact), fixed at 0 otherwise.
  std::optional<PlanRange> self_motion;
  PlanRange wrist_roll{-1.5707963267948966, 1.5707963267948966};  ///< [rad]
  PlanRange timing{0.0, 0.0};  ///< [s], >= 0; a rigid target only
  /// The hand's closing speed on the grasp before the capture [m/s], >= 0. Unset: the scenario's
  /// joint rates and base twist before the capture, as written.
  std::optional<PlanRange> closing_speed;
  /// Points per searched parameter of the first scan (a grid over the box), >= 2 ...
  unsigned int scan = 21;
  /// ... and at most this many points in all: with more parameters searched, each gets
  /// max(2, floor(scan_limit^(1/d))) points (4 parameters: 10 each by default).
  unsigned int scan_limit = 10000;
  /// Local polishes (NLopt LN_BOBYQA, or LN_COBYLA in one dimension) from the scan's best local
  /// minima, at most this many.
  unsigned int polish_starts = 5;
  unsigned int polish_evaluations = 300;  ///< per polish
  /// Polled between configurations (may be empty): true stops the search; the plan then has
  /// `cancelled` set and holds the best found so far (if any).
  std::function<bool()> cancelled;
};

/// The terms at one configuration.
struct PlanTerms {
  double base_rate = 0.0, impulse = 0.0, joint_rate_jump = 0.0;
  double objective = 0.0;  ///< the weighted sum
  /// Inside every joint's position limits and, after the capture, its URDF velocity limit.
  bool feasible = false;
  /// How far outside: the sum over the joints of the position and rate excesses (0: feasible).
  double violation = 0.0;
  std::string infeasible;  ///< why not (the first joint and limit), or what could not be computed
  /// The motion after the capture over the horizon (PlanOptions::horizon): when an operation term
  /// is weighted, or the horizon is given (the optimum and the nominal only); unset otherwise.
  std::optional<MotionMeasures> motion;
};

/// A planned capture.
struct CapturePlan {
  std::vector<std::string> joint_names;  ///< model order
  std::vector<double> q;                 ///< the optimum's joint angles [rad or m]
  std::vector<double> qdot_before;       ///< the joint rates before its capture
  std::vector<double> base_twist_before; ///< the base's twist before it (v of its origin; w), world
  std::vector<double> qdot_after;        ///< the joint rates after its capture
  /// The parameters, in the order self_motion, wrist_roll, timing, closing_speed (present ones
  /// only), their values.
  std::vector<std::pair<std::string, double>> parameters;
  std::vector<std::string> searched;     ///< the names of those that were searched
  PlanTerms optimum;                     ///< at the optimum (always feasible)
  PlanTerms nominal;                     ///< the scenario as written (may be infeasible)
  std::vector<double> nominal_q;
  double horizon = 0.0;                  ///< of the motion the measures read [s] (0: none measured)
  unsigned int evaluations = 0;          ///< configurations computed, scan and polishes
  bool cancelled = false;                ///< PlanOptions::cancelled stopped the search
};

/// \brief The configuration that minimises the objective over the box of `options` under the
/// joints' position and rate limits (the chart above). Deterministic: a scan on a fixed grid,
/// then NLopt local polishes from its best local minima. The limits are hard constraints: a
/// configuration outside them (or one that cannot be reached or computed) scores a penalty
/// (1e6 + the violation) the optimiser sees, and the reported optimum is the best feasible
/// configuration evaluated.
/// \throws InputError "plan: ..." for a scenario with nothing to plan (no rigid-target capture,
/// no searched parameter), an unknown term or a weight <= 0 ("objective: ..."), a range that
/// cannot be used ("self_motion: ...", "wrist_roll: ...", "timing: ..."), an operation term the
/// scenario cannot measure ("objective: ...": a grasp load without a compliant law, a torque
/// ratio without effort limits), a horizon <= 0 ("horizon: ..."), or no feasible configuration in
/// the box. A configuration whose motion fails (blows up, runs out of steps) is infeasible.
KDL_SPACE_EXPORT CapturePlan planCapture(const Scenario& scenario, const PlanOptions& options = {});

/// The names of the objective's terms, in the order of the documentation.
KDL_SPACE_EXPORT const std::vector<std::string>& planObjectiveTerms();

/// Whether a term is read over the operation (the motion after the capture), not at its instant.
KDL_SPACE_EXPORT bool isOperationTerm(const std::string& term);

}  // namespace kdl_space
