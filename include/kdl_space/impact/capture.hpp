// The capture as one library call: a capture problem (the robot at one instant, what it meets,
// the impact law) -> a capture result (the impulse and everything before and after, the
// numbers `kdl_space capture --json` prints), and the model that moves on after a rigid capture.
#pragma once

#include <memory>
#include <optional>
#include <variant>

#include "kdl_space/impact/collision.hpp"
#include "kdl_space/export.hpp"

namespace kdl_space {

/// \brief A rigid target in the terms of a scenario file: its inertia about the CoM in its own
/// frame, the pose of that frame in the world, the CoM in that frame, the twist at the CoM in the
/// world frame. RigidBody is the same body with everything in the world frame (toWorld()).
struct RigidTarget {
  double mass = 0.0;                             ///< [kg]
  Matrix3d inertia = Matrix3d::Identity();       ///< about the CoM, target-frame axes [kg m^2]
  KDL::Frame pose = KDL::Frame::Identity();      ///< target frame in the world
  Vector3d com = Vector3d::Zero();               ///< CoM in the target frame [m]
  Vector6d twist = Vector6d::Zero();             ///< (v of the CoM; w), world frame

  /// The same body in world terms (inertia rotated to world axes, CoM in the world).
  KDL_SPACE_EXPORT RigidBody toWorld() const;
};

/// \brief The rigid body that the links of `model` from body `body` down (its subtree; body 0: the
/// whole model) make at `state`, every joint held where `state` puts it: the composite mass, CoM
/// and inertia, given in the frame of `body` at its world pose, moving with the base's twist
/// `base_twist` (v of the base frame's origin; w) as one rigid body. A set-up call: \throws
/// InputError for a body out of range, a state that cannot be computed, or a subtree without mass.
KDL_SPACE_EXPORT RigidTarget rigidSubtree(const FloatingModel& model, const State& state, int body,
                                          const KDL::Twist& base_twist);

/// What the robot meets: a rigid body, or another free-floating system (whose contact point must
/// coincide with the robot's within `CaptureProblem::touch_tolerance`).
using CaptureTarget = std::variant<RigidTarget, FloatingSystem>;

/// A capture (or any impact) to solve.
struct CaptureProblem {
  FloatingSystem robot;
  CaptureTarget target;
  ImpactLaw law;
  /// Whether the law's normal is meaningful (point impacts; optional for captures): the virtual
  /// mass along it is reported.
  bool has_normal = false;
  /// How the free-floating G* and velocity jumps are computed (the O(n) recursion by default: no
  /// n x n matrix is built).
  ExIITMethod method = ExIITMethod::Recursive;
  double touch_tolerance = 1e-3;  ///< [m], robot-to-robot contact
};

/// One free-floating side of a solved impact.
struct FloatingSideResult {
  FloatingVelocity before, after;               ///< base twist and joint rates
  Vector6d contact_twist_before = Vector6d::Zero(), contact_twist_after = Vector6d::Zero();
  /// Locked twist at the system's CoM: (v_g; w_g) = M_a^-1 (P_g; L_g).
  Vector6d centroid_twist_before = Vector6d::Zero(), centroid_twist_after = Vector6d::Zero();
};

/// Everything about a solved impact (world frame; momentum angular part about the world origin).
struct CaptureResult {
  Impulse impulse;                              ///< on the robot at the contact point
  Vector3d contact_point = Vector3d::Zero();    ///< the robot's contact point in the world
  FloatingSideResult robot;
  /// The target's twist at its CoM (a free-floating target: its locked twist at its CoM).
  Vector6d target_twist_before = Vector6d::Zero(), target_twist_after = Vector6d::Zero();
  std::optional<FloatingSideResult> floating_target;  ///< set for a free-floating target
  Matrix6d G_robot = Matrix6d::Zero();          ///< the robot's G for its response (G*, G, locked G)
  Matrix6d G_target = Matrix6d::Zero();         ///< the target's (G_B, or its G*)
  Vector6d momentum_before = Vector6d::Zero(), momentum_after = Vector6d::Zero();  ///< both sides
  double energy_before = 0.0, energy_after = 0.0;  ///< both sides [J]
  double energyLost() const { return energy_before - energy_after; }
  /// 1 / (n^T G_vv n) of the robot along the law's normal; empty without a normal, or where the
  /// robot cannot move its contact point along it (infinite).
  std::optional<double> virtual_mass;
  /// World pose of the robot's contact body at the impact (where a captured target is attached).
  KDL::Frame contact_body_pose = KDL::Frame::Identity();
};

/// \brief Solves the capture problem: both sides at their states (FloatingSide, RigidBodySide),
/// the impulse from the law (collide), everything after. O(n) per free-floating side with
/// ExIITMethod::Recursive. A set-up call: \throws InputError for the problem's own fields, or the
/// ModelError of a side that refuses its state (FloatingSide, RigidBodySide), with a message
/// that starts with the part concerned ("robot: ...", "target: ...", "target.contact: ...",
/// "law: ...").
KDL_SPACE_EXPORT CaptureResult solveCapture(const CaptureProblem& problem);

/// \brief solveCapture for many problems of one robot (a study, a sweep): the robot's side, its
/// solvers and workspaces, is kept and reset to each problem's state while the model, contact,
/// response, method and braked joints stay those of the last problem. A capture of a rigid target
/// then allocates nothing; the result is solveCapture's, bit for bit. One per thread.
class KDL_SPACE_EXPORT CaptureSolver {
 public:
  CaptureSolver();
  ~CaptureSolver();
  CaptureSolver(const CaptureSolver&) = delete;
  CaptureSolver& operator=(const CaptureSolver&) = delete;
  /// \brief Solves `problem` (see solveCapture); the result stays valid until the next call.
  /// \throws InputError or ModelError as solveCapture.
  const CaptureResult& solve(const CaptureProblem& problem);

 private:
  /// The kept side answers for `problem`'s robot after a reset (same set-up).
  bool reusable(const CaptureProblem& problem) const;
  std::unique_ptr<FloatingSide> robot_;
  ExIITMethod method_ = ExIITMethod::Recursive;
  CaptureResult result_;
};

/// \brief The model that moves on after the impact solved by `result = solveCapture(problem)`:
/// after a rigid capture of a rigid target, the robot with the target merged into its contact
/// link (the target's inertia in that link's frame at the impact, result.contact_body_pose);
/// after a point impact (frictional or not), the robot's own model, the same pointer (the target
/// separates). A set-up call: \throws InputError ("law.type: ..." for a translational capture,
/// "target.urdf: ..." for a free-floating target), or the ModelError of the merged model
/// ("target: cannot attach ...").
KDL_SPACE_EXPORT std::shared_ptr<const FloatingModel> attachTarget(const CaptureProblem& problem, const CaptureResult& result);

/// A rigid target's inertia in a link's frame (`world_T_link`, at the capture instant): what
/// attachTarget adds to the contact link. Mass [kg], CoM [m] in the link's frame, inertia about
/// the CoM in its axes [kg m^2].
struct LinkPayload {
  double mass = 0.0;
  Vector3d com = Vector3d::Zero();
  Matrix3d I_com = Matrix3d::Zero();
};
KDL_SPACE_EXPORT LinkPayload payloadInLink(const RigidTarget& target, const KDL::Frame& world_T_link);

}  // namespace kdl_space
