// The capture operation as one call: from a scenario, the approach (the hand reaches the grasp
// point on the moving target), the capture at the contact instant (the paper's impulsive law, or a
// compliant contact integrated over its duration), the system that moves on after it (the robot
// with a payload, the captured robot joined into one tree, or both sides apart) and its motion:
// what `kdl_space simulate` runs, what a study's motion after a capture runs, and
// `kdl_space.run_operation` in Python.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "kdl_space/algorithm/grasp_wrench.hpp"
#include "kdl_space/export.hpp"
#include "kdl_space/impact/joined_system.hpp"
#include "kdl_space/multibody/diagnostics.hpp"
#include "kdl_space/operation/motion_record.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/simulation/compliant_capture.hpp"
#include "kdl_space/simulation/sampled_control.hpp"

namespace kdl_space {

struct OperationResult;

/// What to run, and what to see while it runs.
struct OperationOptions {
  std::optional<double> duration;     ///< of the motion after the capture [s]; unset: the scenario's
  std::optional<double> output_step;  ///< [s]; unset: the scenario's simulation.output_step
  bool approach = true;  ///< run the scenario's approach (false: the capture at the scenario's states)
  bool motion = true;    ///< integrate the motion after the capture (false: stop at the capture)
  /// PD joints hold the configuration at the start of the motion (their set points taken from it),
  /// whatever the scenario's set points: a study's motion after a capture.
  bool hold_servos = false;
  /// Every output sample in time order, with the result so far (its `model` is the system the
  /// sample's joints belong to). The approach's samples (and a compliant contact's) come once the
  /// capture has told which system moves on (the target's joints, if it joins, are NaN in the
  /// approach's; a target that bounced off is not in the contact's). It may throw: the run stops
  /// there and the exception propagates.
  std::function<void(const OperationResult& so_far, const MotionSample& sample)> observer;
  bool keep_samples = true;  ///< keep the samples in the result (false: the observer and the record only)
  /// A controller of the motion after the capture (its torques add to the scenario's joint modes),
  /// called at control_rate [Hz] with a zero-order hold, or at every evaluation when 0. A sampled
  /// one is probed first at the start of the motion (sampledGainWarnings: 2 nj extra calls).
  SampledController controller;
  double control_rate = 0.0;
  bool check_sampled_gains = true;  ///< false: no probe (a controller whose calls change its state)
  /// Polled before every step of every phase (Simulator::setCancelPoll): once it returns true the
  /// run stops with an OperationError of code E_CANCELLED (at t = how far it got); it may throw
  /// instead (the exception propagates). Empty: never cancelled.
  std::function<bool()> cancelled;
};

/// What the robot holds in the motion after the capture of `r` (in r.model, from r.at_contact): a
/// joined target's bodies (the names that are not the robot's), or a rigid target merged into the
/// contact link (its share of that link's inertia); none after an impact that lets the target go,
/// or without a capture. What graspWrench reads.
KDL_SPACE_EXPORT std::optional<HeldTarget> heldTarget(const OperationResult& r);

/// Whether the scenario's law holds the target after the capture (a capture, a translational
/// capture, a compliant grasp): its samples then carry the grasp's load (MotionSample::grasp_wrench).
KDL_SPACE_EXPORT bool holdsTarget(const Scenario& sc);

/// \brief How many output samples a run of the operation can produce at most: the approach's (if
/// the scenario has one and options.approach: approach.max_duration / output_step + 1) and the
/// motion's (if options.motion: duration / output_step + 1). A compliant contact's samples, at its
/// own finer step, are not counted (they come as its time scale requires). For a caller that
/// keeps or writes them to refuse a run too large before it starts (a double: it may exceed any
/// integer).
KDL_SPACE_EXPORT double estimatedOutputRows(const Scenario& scenario, const OperationOptions& options = {});

/// What the approach did.
struct ApproachOutcome {
  ApproachRecord record;
  /// A rigid target at the end of the approach (a free-floating robot target's state then is
  /// OperationResult::at_contact.target; this stays default).
  RigidTarget target_at_contact;
  /// The warnings about the pose it started from (approachStartWarnings), found before it ran.
  std::vector<Diagnostic> start_warnings = {};
  /// What the arm went through on its way, at the output samples (kind `overlap`): a link inside
  /// the target's boxes (overlapWarnings' rules; the hand's bodies and the link that carries them,
  /// which closes on the target by design, are not checked: the capture's check is theirs) or inside its
  /// own bus (busOverlapWarnings), one warning per link and obstacle: from when, how deep at most
  /// and when (details {link, target, depth, moment: "approach", from, deepest_at}).
  std::vector<Diagnostic> overlaps = {};
};

/// \brief The warnings about the pose an approach starts from (the scenario's robot state and
/// contact, checkConfiguration): a joint outside its limits (named), J* near a singularity
/// (sigma_min / sigma_max below kNearSingularRatio, with the singular values), each message
/// beginning "at the start of the approach: ". Known before the approach runs: a near-singular
/// start otherwise shows only as an approach that never reaches its grasp. None without an
/// approach. Builds a solver of its own (a set-up call).
KDL_SPACE_EXPORT std::vector<Diagnostic> approachStartWarnings(const Scenario& scenario);

/// A free-floating target that separated after a point impact, moved on by itself.
struct TargetMotion {
  SimulationState end;
  double dP = 0.0, dL = 0.0, T = 0.0;  ///< momentum drift over the run, kinetic energy after the impact
};

/// Everything the operation did (what `kdl_space simulate --json` prints).
struct KDL_SPACE_EXPORT OperationResult {
  double duration = 0.0;     ///< of the motion after the capture (after the contact, if compliant) [s]
  double output_step = 0.0;  ///< [s]
  std::optional<ApproachOutcome> approach;
  /// The capture problem at the contact instant (after an approach: the states then).
  CaptureProblem at_contact;
  /// Unset for a plain motion. With a compliant law: the impulsive capture of the same contact
  /// (its limit as the stiffness grows), beside `compliant`; what moves on comes from `compliant`.
  std::optional<CaptureResult> capture;
  /// A compliant capture (law type compliant): the contact integrated from t_capture over its
  /// duration (solveCompliantCapture). Caught: the joined system (the grasp's six joints braked at
  /// their deflection) moves on; opened: the robot alone, a free-floating target by itself
  /// (target_motion). The motion after starts at its end, t_capture + compliant->duration.
  std::optional<CompliantCaptureResult> compliant;
  std::optional<JoinedSystem> joined;    ///< the captured target joined to the robot's tree
  std::shared_ptr<const FloatingModel> model;  ///< what moves after the capture
  bool payload_attached = false;  ///< model is the robot with the target as a payload, or joined
  double t_capture = 0.0;         ///< the contact instant (0 without an approach) [s]
  /// The reaction wheels' momenta at the contact instant (robot.base_actuators: the scenario's at
  /// the start, or where the approach left them) [N m s]; empty without wheels. A capture's impulse
  /// and a compliant contact leave them as they are.
  Eigen::VectorXd wheel_momentum_at_contact;
  std::vector<MotionSample> approach_samples;  ///< the last one: the contact instant
  /// A compliant contact's samples (Phase::Contact, kept whatever keep_samples: they come before
  /// the system after it is known), in the joints of `model`.
  std::vector<MotionSample> contact_samples;
  std::vector<MotionSample> samples;           ///< of the motion after the capture (keep_samples)
  /// The motion's records and aggregates (also without kept samples; none without a motion:
  /// record.samples is 0)
  MotionRecord record;
  SimulationState end;            ///< the state at the end of the motion
  std::optional<TargetMotion> target_motion;  ///< a free-floating target that separated
  double min_chart_margin = 1.0;  ///< a ball joint's least distance from its chart's singularity
  /// What the motion after the capture found that a user should see (kind, element: the joint):
  /// `sampled_gain_unstable` (sampledGainWarnings: options.controller's rate feedback beyond what
  /// its zero-order hold keeps stable) and `stiff` (a servo whose stiffness held an explicit
  /// integrator's steps far below the output step: stiffnessAdvice), and
  /// `contact_opened_at_touch` (element law.normal: a compliant contact that opened at once, its
  /// target not closing on the hand).
  std::vector<Diagnostic> warnings;
  /// The phases the scenario's base control acted in, of those that ran: "approach", "after".
  std::vector<std::string> base_control_phases;
};

/// \brief A failed operation: the scenario's terms (what grew, when, what to try), the code of the
/// failed computation (0 when none: an approach that never reached its grasp), and what had been
/// done until then (`partial`: the approach's samples of an approach that failed, say).
class KDL_SPACE_EXPORT OperationError : public InputError {
 public:
  OperationError(const std::string& what, int code, std::shared_ptr<const OperationResult> partial)
      : InputError(what), code_(code), partial_(std::move(partial)) {}
  int code() const { return code_; }
  const std::shared_ptr<const OperationResult>& partial() const { return partial_; }

 private:
  int code_;
  std::shared_ptr<const OperationResult> partial_;
};

/// \brief Runs the scenario's operation: its approach (if it has one and options.approach), the
/// capture (if it has a target), then options.duration of motion after it (options.motion).
/// \throws InputError naming the scenario's file and field for what the scenario asks that cannot
/// be done (a run beyond its step budget, a grounded base given a twist, a joint outside its hard
/// stop); OperationError for a phase that failed (an approach that never reached its grasp, a
/// motion that blew up), with what was done until then.
KDL_SPACE_EXPORT OperationResult runCaptureOperation(const Scenario& scenario, const OperationOptions& options = {});

/// \brief The operation from its contact instant (t = 0) at a given capture problem: its capture
/// (a compliant law's contact, or the impulsive law's), the system that moves on and its motion;
/// runCaptureOperation without the approach, at `at_contact` instead of the scenario's (a planned
/// or drawn configuration: the same robot and target, other states). options.approach is ignored.
/// \throws as runCaptureOperation.
KDL_SPACE_EXPORT OperationResult runOperationFrom(const Scenario& scenario, const CaptureProblem& at_contact,
                                                  const OperationOptions& options = {});

/// \brief The motion after a capture alone: `capture` solved for `at_contact` (a scenario's
/// problem, or one a study drew from it), the system that moves on after it, and its motion from
/// t_capture. `result` gets everything of that (approach and the rest untouched).
/// \throws as runCaptureOperation.
KDL_SPACE_EXPORT void runMotionAfterCapture(const Scenario& scenario, const CaptureProblem& at_contact,
                                            const std::optional<CaptureResult>& capture, double t_capture,
                                            const OperationOptions& options, OperationResult& result);

/// \brief After a capture that joins the target to the robot (a free-floating target captured
/// rigidly or translationally, a rigid target captured translationally): the joined system.
KDL_SPACE_EXPORT std::optional<JoinedSystem> joinedAfterCapture(const CaptureProblem& problem, const CaptureResult& capture);

}  // namespace kdl_space
