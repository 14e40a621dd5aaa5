// A capture that lasts: the robot and a free-floating target joined at the grasp by a
// spring-damper (a 6-joint compliant grasp, joinAtGrasp's GraspJoint::Compliant), the contact
// integrated in the simulator until the relative motion is caught (the grasp then locks) or the
// contact opens (docs/COMPLIANT.md). As the stiffness grows it tends to the impulsive capture.
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/impact/joined_system.hpp"
#include "kdl_space/simulation/simulation.hpp"

namespace kdl_space {

/// \brief When the compliant grasp locks (CompliantGrasp::lock, the scenario's law.lock).
enum class GraspLock {
  /// At the first instant the relative speed has fallen to catch_tolerance of its start, or
  /// (without a normal) the springs' energy reaches its first maximum: the hand has stopped
  /// closing. The lock (brakes) then stops the rest of the relative motion: a latching gripper.
  SpringMaximum,
  /// Only when the relative speed has fallen to catch_tolerance of its start: the springs and
  /// dampers take the capture, the lock a remainder of order catch_tolerance^2 of the energy.
  Tolerance,
  /// Never: the contact's integration ends when the relative speed has fallen to catch_tolerance
  /// (or at max_duration) and the grasp stays compliant in the motion after it (its six joints
  /// PD servos to zero deflection with the grasp's stiffness and damping): no lock impulse.
  Never,
};

/// \brief The hand's compliance: a spring-damper per axis of the robot's contact link, acting on
/// the deflection of the grasp (GraspJoint::Compliant's six coordinates: x, y, z of the grasp
/// point [m]; the ZYX angles about z, y, x [rad]). The defaults are a stiff gripper.
struct CompliantGrasp {
  /// (x, y, z [N/m]; about x, y, z [N m/rad]), the robot contact link's axes.
  Vector6d stiffness = (Vector6d() << 1e6, 1e6, 1e6, 1e4, 1e4, 1e4).finished();
  /// Per axis, the same order [N s/m; N m s/rad]; empty: damping_time * stiffness.
  std::optional<Vector6d> damping;
  /// beta [s] of the stiffness-proportional (Rayleigh) damping D = beta K used when `damping` is
  /// empty. With beta fixed the contact lasts ~ m / (beta K) and the capture converges to the
  /// impulsive one at first order in 1/K (with a fixed damping ratio: order 1/2).
  double damping_time = 1e-3;
  /// The relative motion is caught at the first instant where its speed sqrt(qdot^T K qdot) over
  /// the grasp joints falls to catch_tolerance times its value at the touch, or (without a
  /// `normal`) where the springs' energy V = 1/2 q^T K q reaches its first maximum (dV/dt = q^T K
  /// qdot falls to 0: the hand has stopped closing). Both are located between the integrator's
  /// steps (Simulator::setStopEvent, to 1e-10 s), not at the output samples.
  double catch_tolerance = 1e-3;
  double max_duration = 1.0;  ///< [s]: the contact ends (neither caught nor opened) after this
  /// Unit normal from the robot's contact point toward the target (world, at the start): if
  /// given, the contact is one-sided until the catch: it opens (a bounce) at the first instant the
  /// force on the robot would pull it toward the target (n^T f >= 0, located as the catch), and it
  /// is caught only when the relative
  /// speed falls below catch_tolerance (the fingers close on a target that has come to rest in
  /// the hand; not at a minimum). Empty: the grasp holds from the touch (a closed gripper).
  std::optional<Vector3d> normal;
  /// When the grasp locks (GraspLock).
  GraspLock lock = GraspLock::Never;
  /// The damping per axis (damping, else damping_time * stiffness).
  Vector6d dampingPerAxis() const { return damping ? *damping : Vector6d(damping_time * stiffness); }
  /// The spring-damper of grasp joint k (JoinedSystem::grasp_joints order: x, y, z, rz, ry, rx) as
  /// a PD servo to zero deflection: tau = -K q - D qdot, what holds a grasp left compliant.
  JointControl jointSpring(int k) const {
    constexpr int axis[6] = {0, 1, 2, 5, 4, 3};  // the stiffness's axis of grasp joint k
    JointControl c;
    c.mode = JointControl::Mode::PD;
    c.kp = stiffness(axis[k]);
    c.kd = dampingPerAxis()(axis[k]);
    return c;
  }
};

/// One output sample of the contact.
struct ContactSample {
  double t = 0.0;                        ///< [s] since the start of the contact
  Vector6d wrench = Vector6d::Zero();    ///< on the robot: (f; n about its contact point), world
  Vector6d deflection = Vector6d::Zero();  ///< the grasp's six coordinates (x, y, z, rz, ry, rx)
  /// The impulse on the robot so far: its own momentum's change since the start of the contact
  /// (exact, not a quadrature of `wrench`), the moment about its contact point at the start.
  Vector6d impulse = Vector6d::Zero();
};

/// How the contact ended: caught (the grasp locked), opened (a bounce), timed out, or settled
/// (GraspLock::Never: the relative motion died out to catch_tolerance; the grasp stays compliant).
enum class ContactEnd { Caught, Opened, TimedOut, Settled };

/// The lock's part of the capture: of the impulse's force and moment (|lock| / |whole|, each 0
/// when the whole is 0), and of the kinetic energy the contact took (lock_loss / (energy_before
/// - energy_after)). 0 with GraspLock::Never.
struct LockShare {
  double linear_impulse = 0.0, angular_impulse = 0.0, energy = 0.0;
};

/// Which criterion caught the relative motion (CompliantGrasp::catch_tolerance): its speed fell to
/// the tolerance, or the springs' energy reached its first maximum. None unless caught.
enum class CatchRule { None, Tolerance, SpringMaximum };

/// Everything about an integrated compliant capture (world frame; momentum about the origin).
struct CompliantCaptureResult {
  ContactEnd end = ContactEnd::TimedOut;
  CatchRule catch_rule = CatchRule::None;  ///< what caught it (end == Caught)
  GraspLock lock = GraspLock::SpringMaximum;  ///< the grasp's rule (CompliantGrasp::lock)
  /// [s]: the located instant of the catch or the opening (within 1e-10 s after it, plus the
  /// integration's error), max_duration if timed out
  double duration = 0.0;
  double peak_force = 0.0, peak_moment = 0.0;  ///< largest |f|, |n| of the samples [N], [N m]
  Vector6d peak_force_wrench = Vector6d::Zero();  ///< the sample's wrench where |f| peaks
  /// The output samples, from the start to the end: every multiple of the output step (a
  /// fortieth of the slowest time scale), then the located end (its spacing to the one before is
  /// shorter).
  std::vector<ContactSample> history;
  /// The impulse on the robot: its own momentum's change over the contact, (f; n about the
  /// robot's contact point at the start), as CaptureResult::impulse.F.
  Vector6d impulse = Vector6d::Zero();
  /// The part of `impulse` the lock gave at the catch (the residual relative motion stopped at
  /// once; not in `history`), the moment about the same point. Zero unless caught.
  Vector6d lock_impulse = Vector6d::Zero();
  FloatingVelocity robot_after, target_after;  ///< each side's base twist and rates at the end
  /// Each side at the end of the contact as a system of its own (its model, state, velocity after
  /// the lock, contact and brakes): what moves on after a bounce. A rigid target is the free body
  /// of one link the contact joined (its model: one body at the CoM, the target frame's axes).
  FloatingSystem robot_end, target_end;
  /// The joined system at the end (the grasp's joints braked if caught: its velocity after the lock).
  JoinedSystem joined;
  Vector6d momentum_before = Vector6d::Zero(), momentum_after = Vector6d::Zero();  ///< both sides
  /// Each side's own momentum at the end (its own model): their sum is momentum_after.
  Vector6d robot_momentum_after = Vector6d::Zero(), target_momentum_after = Vector6d::Zero();
  double energy_before = 0.0;  ///< kinetic, both sides [J]
  double energy_after = 0.0;   ///< kinetic at the end (after the lock) [J]
  double dissipated = 0.0;     ///< the dampers' work taken [J]
  double spring_energy = 0.0;  ///< held in the springs at the end (locked in by a catch) [J]
  double lock_loss = 0.0;      ///< taken by the lock of the residual relative motion [J]
  LockShare lock_share;        ///< the lock's part of the impulse and of the energy taken
  long steps = 0;              ///< the integrator's accepted steps
};

/// \brief Integrates the compliant capture of the free-floating `target` by `robot` from their
/// states and velocities (before the contact): joinAtGrasp(..., GraspJoint::Compliant), the torque
/// tau = -K q - D qdot on the six grasp joints (an internal force: the momentum is an invariant
/// of the integrator), output samples at a fortieth of the slowest time scale of the axes that
/// carry the relative motion, until the catch (the grasp joints braked by engageBrakes: momentum
/// kept), the opening or max_duration; the catch and the opening are located between the
/// integrator's steps (CompliantGrasp::catch_tolerance, normal).
/// Joints braked on either side (FloatingSystem::locked, Response::JointsLocked) stay braked.
/// A set-up call: \throws InputError ("law.stiffness: ..." etc. for a parameter that is not
/// finite and > 0, joinAtGrasp's errors, "contact: ..." with the simulator's code when the
/// integration fails).
KDL_SPACE_EXPORT CompliantCaptureResult solveCompliantCapture(const FloatingSystem& robot, const FloatingSystem& target,
                                                              const CompliantGrasp& grasp,
                                                              const SimulationOptions& options = {});

/// Sees every output sample of the contact in time order: the joined system's simulator and
/// state (t from 0 at the touch), and the sample. It may throw (the exception propagates).
using ContactObserver = std::function<void(Simulator& sim, const SimulationState& x, const ContactSample& sample)>;

/// How to run a compliant contact.
struct CompliantRun {
  /// The integrator's (grounded and gravity are ignored; rk4 runs as dopri5: a fixed step chosen
  /// for a motion would not resolve a contact of milliseconds).
  SimulationOptions options;
  /// Simulator::setCancelPoll of the contact's run (empty: never): a true ends it with an
  /// InputError naming E_CANCELLED; a poll that throws stops it there (propagates).
  std::function<bool()> cancelled;
  ContactObserver observer;  ///< empty: none
};

/// \brief The compliant capture of the problem's target, free-floating or rigid (a rigid target is
/// one free body, rigidBodySystem (impact/rigid_body_system.hpp): its mass and inertia at its CoM,
/// the target frame's axes, its twist RigidTarget::twist, touched at the robot's contact point).
/// The problem's law and touch tolerance are not used (the grasp's spring-damper is the law).
/// \throws as above, and InputError ("target.mass: ...") for a rigid target whose mass is not
/// finite and > 0.
KDL_SPACE_EXPORT CompliantCaptureResult solveCompliantCapture(const CaptureProblem& problem, const CompliantGrasp& grasp,
                                                              const CompliantRun& run = {});

}  // namespace kdl_space
