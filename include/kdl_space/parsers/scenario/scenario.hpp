// Capture scenarios (YAML or JSON files): what the robot is, where and how fast it moves, what it
// hits and with which impact law (a CaptureProblem), and what to simulate after the impact. What
// `kdl_space capture` and `simulate` read; a library user can build the same types in code.
#pragma once

#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "kdl_space/algorithm/inverse_kinematics.hpp"
#include "kdl_space/simulation/approach.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/multibody/diagnostics.hpp"
#include "kdl_space/parsers/urdf/urdf_visuals.hpp"
#include "kdl_space/export.hpp"
#include "kdl_space/simulation/simulation.hpp"
#include "kdl_space/simulation/compliant_capture.hpp"

namespace kdl_space {

/// The `simulation` section: the motion (after the impact, or from the robot's initial state).
struct SimulationSpec {
  double duration = 20.0;     ///< [s] (the tool's --duration overrides it)
  double output_step = 0.05;  ///< output row spacing [s]
  SimulationOptions options;  ///< options.grounded: see `base`
  /// `base: free | grounded`; unset: the robot's mode holds (grounded if it was grounded).
  std::optional<bool> grounded;
  /// By joint index of the robot, resolved from names and patterns ("*", "wrist_*"): exact names
  /// win over patterns, later patterns over earlier ones, "*" is the default. Joints not listed
  /// keep the mode of the robot (locked for `mode: locked` and `robot.locked`, else free).
  std::vector<std::pair<unsigned int, JointControl>> joints;
  std::vector<std::pair<unsigned int, LimitMode>> limits;  ///< resolved as `joints`; default warn
  /// `target_joints`: a captured free-floating target's joints after the capture, by the target's
  /// joint index (its model order), resolved as `joints` (default: its own mode, free or braked).
  std::vector<std::pair<unsigned int, JointControl>> target_joints;
  BaseControl base_control;
  std::vector<ScheduledWrench> wrenches;
  /// `after_capture`: the law of the motion after the capture (or of a plain motion).
  enum class Law {
    Hold,                  ///< `hold`: the joints' controls as `joints` gives them (the default)
    MomentumDistribution,  ///< `momentum_distribution`: MomentumDistribution over the robot's PD joints
    Impedance,             ///< `impedance`: GraspImpedance over the robot's PD joints, at its contact
  };
  Law after_capture = Law::Hold;
  double unload_gain = 0.2;  ///< momentum_distribution's [1/s]
  double bandwidth = 20.0;   ///< momentum_distribution's rate servos' [1/s]
  /// impedance's (translation [N/m], rotation [N m/rad]) and (translation [N s/m], rotation [N m s/rad])
  Eigen::Vector2d impedance_stiffness{50.0, 20.0};
  Eigen::Vector2d impedance_damping{100.0, 40.0};
  /// `detumble_rate`: the base's angular rate below which the stack counts as detumbled
  /// (MotionRecord::detumble, MotionMeasures::time_to_detumble) [rad/s]
  double detumble_rate = 1e-3;
};

/// \brief `robot.base_actuators`: the servicer's reaction wheels and thrusters as hardware. With
/// them, the base control's attitude torque is the wheels' (internal: the momentum of the system
/// with its wheels is kept) or, without wheels, the thrusters', limited to thruster_torque; its
/// force the thrusters', limited to thruster_force (each also by the control's own limit).
/// Without them (`given` false) the base control is an external wrench within its own limits.
struct BaseActuators {
  bool given = false;
  ReactionWheels wheels;           ///< none: count() 0
  Eigen::VectorXd wheel_momentum;  ///< the wheels' momenta at the start [N m s]
  bool thrusters = false;
  /// Per base axis [N], [N m]; infinity: that kind of thrust is absent.
  Vector3d thruster_force = Vector3d::Constant(std::numeric_limits<double>::infinity());
  Vector3d thruster_torque = Vector3d::Constant(std::numeric_limits<double>::infinity());
};

/// A scenario file, read and checked.
struct Scenario {
  std::string file;         ///< the path it was read from
  std::string robot_urdf;   ///< the robot's URDF (resolved path); empty for a mounted robot (robot.mount)
  /// A mounted robot's URDF document (robot.mount: its arms on a bus, mountArms), what robot_urdf
  /// holds otherwise; empty when robot_urdf is the robot's.
  std::string robot_document;
  std::vector<std::string> robot_files;  ///< the files the robot is read from: robot_urdf, or the bus's and arms'
  std::vector<Diagnostic> robot_notes;   ///< what mounting assumed (names prefixed, mesh paths made absolute)
  /// The target's URDF (resolved path): a free-floating target, or a rigid one read from a file
  /// (one without movable joints, or the links from `target.link` down); empty for a rigid target
  /// given by numbers.
  std::string target_urdf;
  /// The target's description as a URDF document when target_urdf is in another format (SDF, MJCF,
  /// SpaceDyn's LP: readRobotDocument); empty for a URDF file. robot_document is the robot's.
  std::string target_document;
  /// A rigid target read from target_urdf: the file's system at the scenario's state (its joints
  /// held where target.q puts them, its base at target.base) and the body whose frame is the
  /// target's frame (target.link's, or the root's), whose subtree it is. What a viewer poses the
  /// links' visuals from; the dynamics uses capture.target. Unset for every other target.
  std::optional<FloatingSystem> rigid_target_system;
  int rigid_target_body = 0;
  /// false: a plain motion (no `target`, no `law`): `capture` holds only the robot (whose
  /// `contact` may then be omitted: the base's origin).
  bool impact = true;
  CaptureProblem capture;   ///< robot, target, law (ExIITMethod::Recursive, touch tolerance 1 mm)
  /// `law: {type: compliant, ...}`: the hand's spring-damper (docs/COMPLIANT.md); capture.law is
  /// then the rigid capture (ImpactKind::Capture), the impulsive limit reported beside it.
  std::optional<CompliantGrasp> compliant;
  /// `law.max_grasp_wrench: {force, moment}`: the load the grasp may carry [N], [N m] (infinite
  /// when not given), against the motion's peak grasp wrench (MotionRecord::peak_grasp_force).
  double max_grasp_force = std::numeric_limits<double>::infinity();
  double max_grasp_moment = std::numeric_limits<double>::infinity();
  /// The `approach` section: the robot starts from its initial state, reaches the grasp point on
  /// the moving target, and the law applies at the contact instant, from the states then. For a
  /// free-floating robot target its `grasp` is in the frame of target.contact's link, its origin
  /// the contact point, and its position tolerance at most the capture's touch tolerance.
  std::optional<ApproachSpec> approach;
  SimulationSpec simulation;
  BaseActuators base_actuators;  ///< `robot.base_actuators`
  /// `robot.place: grasp`: the inverse kinematics that put the robot's contact frame at the
  /// target's grasp frame (`robot.grasp.target_frame`, in the target's frame); its q is
  /// capture.robot.state.q (joints off the contact's chain keep robot.q).
  std::optional<IkResult> grasp_solution;
  /// The grasp frame in the target's frame (a rigid target's `pose` frame, a free-floating
  /// target's base frame): `robot.grasp.target_frame` with `robot.place: grasp`, or
  /// `approach.grasp` (a robot target's: its contact link's pose in its base frame at the
  /// scenario's state, times the grasp); unset without either (what the pictures draw as the grasp frame).
  std::optional<KDL::Frame> grasp_frame;
};

/// \brief Reads and checks a scenario file; URDF paths are relative to the scenario's folder.
/// Every number is finite, every name exists in its model, a rigid target's mass and inertia
/// are those of a rigid body; a free-floating target's contact is checked by solveCapture.
/// The joints a system's `locked:` list brakes at the impact are in its FloatingSystem::locked
/// (`capture.robot.locked`: what a simulation keeps braked after the impact too).
/// \throws InputError "FILE[:LINE]: FIELD: what is wrong" (e.g. "s.yaml:10: target.mass: must
/// be > 0 kg, got -3") for every problem of the file, its own (missing, empty, not YAML)
/// included; a URDF it names that loads no model is the loader's ModelError with the same
/// \brief The robot's visuals (readUrdfVisuals) from its URDF, or from its document when it is
/// mounted (robot.mount) or in another format; none for neither (a robot built in code).
KDL_SPACE_EXPORT std::map<std::string, std::vector<LinkVisual>> robotVisuals(const Scenario& scenario,
                                                                           const std::vector<std::string>& package_path = {});
/// The target's visuals as robotVisuals' (none for a target given by numbers).
KDL_SPACE_EXPORT std::map<std::string, std::vector<LinkVisual>> targetVisuals(const Scenario& scenario,
                                                                            const std::vector<std::string>& package_path = {});

/// "FILE:LINE: robot.urdf: " in front (catch Error for both).
KDL_SPACE_EXPORT Scenario loadScenario(const std::string& path);

/// The fewest steps a run can take (fewestSteps).
struct StepEstimate {
  double steps = 0.0;           ///< ceil(duration / longest)
  double longest = 0.0;         ///< the longest step [s]
  const char* limited_by = "";  ///< what bounds it: "output_step", "step" (rk4) or "max_step" (adaptive)
};

/// \brief The fewest steps a run of `duration` [s] with rows every `output_step` [s] takes under
/// `spec`'s options: every step is at most max_step (adaptive) or step (rk4) long, and each output
/// row ends a step. A run whose estimate exceeds options.max_steps cannot finish: `simulate` and
/// a study's `motion` are refused before they start.
KDL_SPACE_EXPORT StepEstimate fewestSteps(const SimulationSpec& spec, double duration, double output_step);

/// \brief The simulator as the scenario says, for `model` (the robot's, or the robot with a
/// captured payload, or a joined system: the robot's joints are found by name). The robot's mode
/// holds through the motion (a grounded base stays grounded, braked joints stay braked) unless the
/// simulation section changes it. For an approach (`approach`) the joints are left free for its
/// velocity servo (the section's joint controls act after the capture). The base control is set
/// in the phases its `phases` name (BaseControl::in_approach, after_capture).
/// \throws ModelError as the Simulator's set-up calls.
KDL_SPACE_EXPORT std::unique_ptr<Simulator> makeSimulator(const Scenario& sc, const std::shared_ptr<const FloatingModel>& model,
                                                          bool approach);

}  // namespace kdl_space
