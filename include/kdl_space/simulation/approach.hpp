// The approach before a capture: the hand reaches a grasp point on a moving target by resolved
// motion rate control with the generalized Jacobian (Umetani and Yoshida, the paper's reference 4),
// the joints velocity-servoed in the real floating dynamics, until the contact condition holds.
#pragma once

#include <functional>
#include <limits>
#include <memory>
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
};

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
  void setGrounded(bool grounded) { grounded_ = grounded; }

 private:
  std::shared_ptr<const FloatingModel> model_;
  Contact hand_;
  ApproachSpec spec_;
  std::shared_ptr<ApproachTarget> target_;
  FreeFloatingSolver solver_;
  KDL::Jacobian J_, J_base_;
  bool grounded_ = false;
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
};

/// \brief Runs the approach: the joints velocity-servoed to the controller's command (a torque
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
