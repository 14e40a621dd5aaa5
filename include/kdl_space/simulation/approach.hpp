// The approach before a capture: the hand reaches a grasp point on a moving target by resolved
// motion rate control with the generalized Jacobian (Umetani and Yoshida, the paper's reference 4),
// the joints velocity-servoed in the real floating dynamics, until the contact condition holds.
#pragma once

#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/simulation/approach_target.hpp"
#include "kdl_space/simulation/rigid_motion.hpp"
#include "kdl_space/simulation/simulation.hpp"

namespace kdl_space {

/// What the redundancy of the arm (n > task rows) is used for.
enum class NullSpaceTask {
  None,      ///< the minimum-norm joint rates of the damped pseudo-inverse
  Reaction,  ///< of the rates that do the task, those that least turn the base (least squares on w_base)
};

/// The approach, as the scenario's `approach` section gives it.
struct ApproachSpec {
  KDL::Frame grasp = KDL::Frame::Identity();  ///< grasp frame in the target's frame
  bool orientation = true;  ///< track the grasp frame's orientation too (else position only: 3 rows)
  double gain = 1.0;        ///< K [1/s]: v_ref = v_grasp + K e
  /// Damped least squares: J+ = J^T (J J^T + l^2 E)^-1 with l^2 = damping^2 (1 - (s/threshold)^2)
  /// for a smallest singular value s of J* below `threshold`, 0 above it.
  double damping = 0.05;
  double threshold = 0.05;
  /// Per joint (model order) [rad/s or m/s]; the command is scaled down as a whole (its
  /// direction kept) when a joint would exceed its limit. Empty: the model's velocity limits.
  std::vector<double> rate_limits;
  double servo_bandwidth = 20.0;  ///< [1/s]: tau_j = kv_j (qdot_cmd_j - qdot_j), kv_j = bandwidth m_j
  NullSpaceTask null_space = NullSpaceTask::None;
  double position_tolerance = 5e-3;     ///< contact: |p_grasp - p_hand| [m]
  double orientation_tolerance = 0.05;  ///< contact: angle between hand and grasp frames [rad]
  double speed_tolerance = std::numeric_limits<double>::infinity();  ///< contact: relative speed [m/s]
  double max_duration = 60.0;  ///< [s]: no contact by then: the approach failed
  /// Joint limits (positions): a joint within `limit_zone` x its range of a limit is pushed away in
  /// the null space (the gradient of sum ((q - mid) / half range)^2, Liegeois), and its rate toward
  /// the limit is never more than limit_gain x its distance from a guard twice the servo's lag at
  /// full rate (2 rate_limit / servo_bandwidth) inside it (the rates then the nearest to the task's
  /// within every such bound, the hand's twist given up least): it stops at the limit, not past it.
  /// Joints without limits are free.
  double limit_zone = 0.1;
  double limit_gain = 2.0;  ///< [1/s]
  /// The joint-space move to a pre-grasp pose first (unset: none): see JointMove (joint_move.hpp).
  struct PreGrasp {
    double standoff = 0.2;      ///< [m] back from the grasp along the contact frame's z (the approach axis)
    double rate = 0.5;          ///< fraction of each joint's rate limit the move may use, (0, 1]
    double acceleration = 0.1;  ///< [rad/s^2 or m/s^2] per joint
  };
  std::optional<PreGrasp> pre_grasp;
};

/// What the resolved-rate control assumes of the base, from what holds it during the approach.
enum class ApproachBase {
  Free,          ///< nothing holds it: J* and the momentum's drift (eq. 4)
  Held,          ///< grounded, or its attitude and position both controlled: the fixed-base J
  AttitudeHeld,  ///< its attitude controlled, its position free: J - [A_m,P / w; 0], drift (P / w; 0)
};

/// The Jacobian's name as the reports give it: "generalized (J*)", "grounded (J)",
/// "attitude held (J - [A_mP / w; 0])".
KDL_SPACE_EXPORT const char* toString(ApproachBase base);

/// The URDF's velocity limits per joint (model order), infinity where a joint has none: the
/// approach's rate limits unless the spec gives its own.
KDL_SPACE_EXPORT std::vector<double> defaultRateLimits(const FloatingModel& model);

/// The controller's view of one instant.
struct ApproachCommand {
  KDL::JntArray qdot;        ///< the commanded joint rates
  Vector6d error = Vector6d::Zero();  ///< (p_grasp - p_hand; rotation vector hand -> grasp), world
  Vector6d reference = Vector6d::Zero();  ///< v_ref = grasp twist + K e (rows used: 3 or 6)
  Vector6d drift = Vector6d::Zero();  ///< the hand's twist from the momentum alone (eq. 4's R_h term)
  double sigma_min = 0.0;    ///< smallest singular value of J* (rows used) [m/rad or 1]
  double damping = 0.0;      ///< l of the damped least squares used
  double scale = 1.0;        ///< the factor the rate limits put on the command (1: none)
  double relative_speed = 0.0;  ///< |v_hand - v_grasp point| [m/s]
  /// The joints clamped at their limit guard (model order; empty: none): their rate toward the
  /// limit bounded, the task re-solved by the others.
  std::vector<int> clamped;
};

/// \brief Resolved motion rate control with J*: qdot = J*+ (v_ref - R_h M_a^-1 (P_g; L_g)), so
/// that the hand's twist t_h = J* qdot + R_h M_a^-1 (P_g; L_g) (eq. 4) is v_ref: the controller
/// uses the momentum the system has, not zero.
class KDL_SPACE_EXPORT ApproachController {
 public:
  /// \throws ModelError for a null model, a hand that is no body, a gain, damping, threshold,
  /// bandwidth or tolerance that is not finite and > 0 (damping >= 0), rate limits of the wrong
  /// size or not > 0.
  ApproachController(std::shared_ptr<const FloatingModel> model, const Contact& hand, ApproachSpec spec,
                     FreeRigidMotion target);
  /// Any target's motion (a rigid one, a free-floating robot integrated beside the servicer):
  /// spec.grasp is in the frame its grasp() takes it in. 	hrows as above, and for a null target.
  ApproachController(std::shared_ptr<const FloatingModel> model, const Contact& hand, ApproachSpec spec,
                     std::shared_ptr<ApproachTarget> target);
  const ApproachSpec& spec() const { return spec_; }
  const Contact& hand() const { return hand_; }
  const std::shared_ptr<const FloatingModel>& model() const { return model_; }
  /// The grasp frame and the twist (v of the grasp point; w) at time t.
  int grasp(double t, KDL::Frame& frame, Vector6d& twist);
  /// The commanded joint rates at s (and what they came from).
  int command(const SimulationState& s, ApproachCommand& out);
  /// A rigid target's state at time t (E_BAD_ARGUMENT for another target: see targetMotion()).
  int target(double t, RigidTarget& out);
  /// The target's motion the controller tracks.
  ApproachTarget& targetMotion() { return *target_; }
  /// A grounded base (held still): the fixed-base J and no drift instead of J* and the momentum's
  /// term (runApproach sets it from the simulator's options); the reaction null space does nothing.
  void setGrounded(bool grounded) { base_ = grounded ? ApproachBase::Held : ApproachBase::Free; }
  /// What holds the base (runApproach sets it from the simulator: grounded, or its base control).
  void setBase(ApproachBase base) { base_ = base; }
  ApproachBase base() const { return base_; }
  /// The command fades in over `duration` [s] from `t0` (after a pre-grasp move: the servos take
  /// the switch from rest smoothly); duration 0: at once.
  void setFadeIn(double t0, double duration) { fade_t0_ = t0, fade_ = duration; }

 private:
  std::shared_ptr<const FloatingModel> model_;
  Contact hand_;
  ApproachSpec spec_;
  std::shared_ptr<ApproachTarget> target_;
  FreeFloatingSolver solver_;
  KDL::Jacobian J_, J_base_;
  ApproachBase base_ = ApproachBase::Free;
  double fade_t0_ = 0.0, fade_ = 0.0;
  /// The joint limits (ApproachSpec::limit_zone, limit_gain) on the task's rates `qdot` (A the
  /// task's rows of the Jacobian, l2 its damping): the joints in their zones pushed away in the
  /// null space; then, if a rate would carry a joint past its guard, the rates nearest the task's
  /// inside every guard (a box-constrained least squares: the joints held at a guard out).
  void limitJoints(const KDL::JntArray& q, const Eigen::MatrixXd& A, double l2, Eigen::VectorXd& qdot,
                   std::vector<int>& clamped) const;
};

/// What an approach did.
struct ApproachRecord {
  bool reached = false;
  /// The first instant the contact condition held, located between the steps (within 1e-10 s)
  double t_contact = std::numeric_limits<double>::quiet_NaN();
  double duration = 0.0;               ///< of the approach [s]
  double closest_distance = std::numeric_limits<double>::infinity();  ///< [m], over the output samples and the contact
  double closest_time = 0.0;
  double final_distance = 0.0, final_angle = 0.0;  ///< at the end of the approach [m, rad]
  double min_sigma = std::numeric_limits<double>::infinity();  ///< smallest singular value of J* met
  double max_damping = 0.0;
  double min_scale = 1.0;              ///< the smallest rate-limit factor
  double base_rotation = 0.0;          ///< the base's attitude change over the approach [rad]
  std::vector<double> kv;              ///< the servo gains used (model order)
  ApproachBase base = ApproachBase::Free;  ///< the Jacobian the control used
  /// Per joint (model order): how long [s] of the output samples it was clamped at its limit guard
  std::vector<double> time_at_limit;
  double time_rate_limited = 0.0;      ///< [s] of the samples with the command scaled below 0.99
  double time_near_singular = 0.0;     ///< [s] of the samples with sigma_min below the threshold
  double output_step = 0.0;            ///< the samples' spacing these times count
  /// The pre-grasp move (ApproachSpec::pre_grasp): its duration [s] (0: none), the joints it went
  /// to (model order: the inverse kinematics of the pre-grasp pose), and how far the hand was from
  /// that pose when it ended [m] (the base turned under it)
  double pre_grasp_duration = 0.0;
  std::vector<double> pre_grasp_q;
  double pre_grasp_miss = 0.0;
  /// Not reached: why, in words (a joint held at its limit, rates saturated, a singularity, out of
  /// reach, the pre-grasp pose out of reach, or too slow); empty when reached.
  std::string cause;
};

/// \brief Runs the approach: with spec().pre_grasp, first the joint-space move (JointMove, each
/// joint within pre_grasp.rate x its rate limit and pre_grasp.acceleration, its rates
/// velocity-servoed to the profile's plus gain x its position error) to the inverse kinematics
/// (within the joints' limits, preferring the start's posture, with the base where it is) of the
/// pre-grasp pose: the grasp frame at the move's end, backed off `standoff` along its z (three
/// passes: the move's duration sets where the target is); then the joints velocity-servoed to the controller's command (a torque
/// callback on `sim`, with its effort limits), from s until the contact condition holds or
/// spec().max_duration has passed. The contact instant is the first time the condition holds,
/// located between the steps (Simulator::setStopEvent on the largest of the margins
/// distance / position_tolerance - 1, angle / orientation_tolerance - 1 when the orientation is
/// tracked, relative speed / speed_tolerance - 1 when that is finite): within 1e-10 s of the true
/// crossing plus the integration error, not at the next output sample. s is left at the contact
/// instant (or the end), where the condition holds. `observer` sees every output sample with the
/// controller's command, and the contact instant as the last one. (The simulator's stop condition
/// and stop event are set for the run and cleared after it.)
/// \return 0 (reached or not: see record.reached) or the simulator's code.
KDL_SPACE_EXPORT int runApproach(Simulator& sim, ApproachController& controller, SimulationState& s, double output_dt,
                                 const std::function<void(const SimulationState&, const ApproachCommand&)>& observer,
                                 ApproachRecord& record);

}  // namespace kdl_space
