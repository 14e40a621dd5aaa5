// The motion of a free-floating system over time (section 6 of the paper): integrate the
// equations of motion from a state, e.g. the one right after a capture.
#pragma once

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

#include "kdl_space/simulation/actuation.hpp"
#include "kdl_space/simulation/integrator.hpp"
#include "kdl_space/export.hpp"
#include "kdl_space/algorithm/dense_forward_dynamics.hpp"
#include "kdl_space/algorithm/forward_dynamics.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/algorithm/momentum.hpp"

namespace kdl_space {
namespace detail {
class Dynamics;
class Stepper;
struct StateLayout;
}  // namespace detail

/// Integration settings and what acts on every joint; all are the user's.
struct SimulationOptions {
  Integrator integrator = Integrator::DormandPrince54;
  double step = 1e-3;      ///< RK4 step; first trial step of the adaptive methods [s]
  double rtol = 1e-10;     ///< adaptive: relative tolerance per state component
  double atol = 1e-12;     ///< adaptive: absolute tolerance per state component
  double max_step = 0.05;  ///< adaptive: largest step [s]
  long max_steps = 1000000;  ///< run() gives up (E_MAX_STEPS) after this many steps, e.g. an unstable controller
  Vector3d gravity = Vector3d::Zero();  ///< world frame; zero in orbit
  /// The base is held still (a grounded robot): fixed-base dynamics, base twist zero; the momentum
  /// is then not an invariant (the ground takes what it must).
  bool grounded = false;
  /// The joint controls' torques (PD and callback) are limited to the model's effort limits
  /// (FloatingModel::jointProperties; a joint without one is not limited).
  bool effort_limits = true;
  /// The model's joint damping and Coulomb friction act (frictionTorque).
  bool joint_friction = true;
  /// Coulomb friction's regularisation (frictionTorque): near rest it is a damping of slope
  /// friction / v_s, which on a light joint would make the motion stiff. So each joint's v_s is
  /// max(friction_velocity, friction / (m_j friction_rate)), m_j its apparent inertia at the start
  /// of the run: the Coulomb term's rate stays below friction_rate (Simulator::frictionVelocities).
  double friction_velocity = 1e-3;  ///< the smallest v_s [rad/s or m/s]
  double friction_rate = 1e3;       ///< the largest rate of the regularised Coulomb term [1/s]
};

/// Work done on the system since the start of the run, by what did it [J]. The kinetic energy
/// changes by their sum (friction and limits take energy: <= 0).
struct EnergySplit {
  double controller = 0.0;    ///< joint controls and the torque callback
  double friction = 0.0;      ///< joint damping and Coulomb friction
  double limits = 0.0;        ///< the inelastic impacts of hard stops
  double base_control = 0.0;  ///< the base's own control
  double wrenches = 0.0;      ///< scheduled external wrenches
  double gravity = 0.0;
  double total() const { return controller + friction + limits + base_control + wrenches + gravity; }
};

/// Time, configuration and velocity of the system; run() also reports what acted at that instant.
struct SimulationState {
  double t = 0.0;
  State state;                ///< base pose (world_T_base) and joint positions
  FloatingVelocity velocity;  ///< base twist (v of the base origin; w) and joint rates
  // Outputs of run() (ignored on input):
  KDL::JntArray tau;                       ///< joint torques applied: controls (limited) + friction
  Vector6d base_wrench = Vector6d::Zero(); ///< the base control's (f; n about the base CoM), world
  EnergySplit work;                        ///< since the start of the run
  /// External impulse since the start of the run (base control, wrenches, gravity): (f; moment
  /// about the world origin) integrated. A free base's momentum changes by exactly this (a
  /// grounded base's also by what the ground takes, which is not counted).
  Vector6d impulse = Vector6d::Zero();
  /// The reaction wheels' momenta about their axes [N m s] (Simulator::setReactionWheels; empty:
  /// none, or all zero at the start of a run), and, an output, their motors' torques [N m].
  Eigen::VectorXd wheel_momentum, wheel_torque;
};

/// Joint torques from the user's own controller, added to those of the joint modes.
using TorqueCallback = std::function<void(const SimulationState&, KDL::JntArray& tau)>;

/// What happened to one joint in the last run() (times in s; NaN: never).
struct JointRecord {
  double limit_first_time = std::nan("");  ///< first accepted step outside the position limits
  double limit_worst = std::nan("");       ///< the position farthest outside them
  long stops = 0;                          ///< hard-stop impacts (LimitMode::Stop)
  double saturation_first_time = std::nan("");  ///< first step its control torque was limited
  double saturation_time = 0.0;            ///< how long it was limited (resolution: one step)
};

/// Counters of the last run().
struct SimulationStats {
  long accepted_steps = 0;
  long rejected_steps = 0;
  double min_step = 0.0, max_step = 0.0;  ///< of the accepted steps (outputs' slivers excluded)
  std::vector<JointRecord> joints;         ///< model order
  double base_saturation_time = 0.0;       ///< how long the base control was limited
  /// How long a reaction wheel was at its torque limit or its momentum capacity, and when first
  /// (NaN: never).
  double wheel_saturation_time = 0.0;
  double wheel_saturation_first_time = std::numeric_limits<double>::quiet_NaN();
  /// When the stop event (Simulator::setStopEvent) ended the run: the located instant [s]; NaN
  /// if it did not (no event, or not met before t_end, or the run failed).
  double event_time = std::numeric_limits<double>::quiet_NaN();
};

/// \brief The fastest closed-loop rate of the joint servos at a state, and the explicit step it
/// allows. For PD joint j with apparent inertia m_j (1 / (M^-1)_jj: the acceleration of a unit
/// torque from rest), rate_j is the largest |s| of m_j s^2 + kd_j s + kp_j = 0 [1/s] (kd_j with
/// the joint's damping and friction / v_s when joint friction acts): sqrt(kp_j / m_j) when
/// underdamped, (kd_j + sqrt(kd_j^2 - 4 m_j kp_j)) / (2 m_j) otherwise; an explicit Runge-Kutta
/// method is stable for steps below about 2.8 / rate (RK4's bound on the real axis; dopri5's is 3.3).
struct Stiffness {
  double fastest_rate = 0.0;  ///< [1/s]
  int fastest_joint = -1;     ///< model order; -1 without a servo
  double explicit_step = std::numeric_limits<double>::infinity();  ///< 2.8 / fastest_rate [s]
};

/// \brief Integrates the free-floating equations of motion.
///
/// The state integrated is (base position, base orientation as a unit quaternion, q, total
/// momentum (P; L about the world origin), qdot, and the work and external impulse so far). The
/// base twist follows from the momentum and the joint rates (eq. 2), so with no external force the
/// momentum is an exact invariant of every Runge-Kutta step; an external wrench (gravity, the base
/// control, scheduled wrenches) changes it by exactly its impulse. The orientation is renormalised
/// after every step (no Euler angles). A grounded base stays where it is and the joints follow
/// the fixed-base dynamics.
/// Each evaluation of the derivative is O(n): one forwardKinematics, the base twist from the
/// momentum (MomentumSolver::baseTwist) and the articulated-body forward dynamics
/// (ForwardDynamicsSolver), all reading the same Kinematics; no n x n matrix is built (except by
/// the Rosenbrock method, whose Jacobian is (13 + 2n)^2; mimic joints are constraints on the
/// recursion, O(n k + k^3) for k of them).
/// The joint torque is the control's (PD, callback; limited to the effort limit) plus friction.
/// Hard stops (LimitMode::Stop) are located in time within 1e-10 of the limit, where the joint's
/// rate is stopped by an internal impulse (momentum unchanged; the energy lost is counted in
/// EnergySplit::limits); it then stays braked until its free acceleration points away from the
/// limit. Scheduled wrenches start and end exactly on a step.
class KDL_SPACE_EXPORT Simulator {
 public:
  /// \throws ModelError unless step, rtol, atol, max_step, friction_velocity, friction_rate are
  /// finite and > 0,
  /// max_steps > 0, gravity finite and the integrator an enumerator.
  explicit Simulator(std::shared_ptr<const FloatingModel> model, SimulationOptions options = {});
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  const FloatingModel& model() const { return *model_; }
  const SimulationOptions& options() const { return options_; }
  /// \throws ModelError (a set-up call) for a joint index out of range, a mode that is no
  /// enumerator, or a gain or set point that is negative or not finite.
  void setJointControl(unsigned int joint, const JointControl& control);
  const std::vector<JointControl>& jointControls() const { return controls_; }
  /// What joint's position limits do (LimitMode::Warn for every joint by default). \throws
  /// ModelError for an index out of range, or Stop on a joint without finite limits (continuous).
  void setLimitMode(unsigned int joint, LimitMode mode);
  const std::vector<LimitMode>& limitModes() const { return limit_modes_; }
  /// \throws ModelError for a gain, set point or limit that is negative or not finite, a set point
  /// that is no rotation, or a base control on a grounded base.
  void setBaseControl(const BaseControl& control);
  const BaseControl& baseControl() const { return base_control_; }
  /// \brief Reaction wheels in the base (ReactionWheels): their momenta join the state
  /// (SimulationState::wheel_momentum) and the momentum energyAndMomentum reports; the base
  /// control's attitude torque is then theirs (wheelTorques: no external torque, the momentum of
  /// the system with its wheels is invariant), its force still an external one (thrusters).
  /// \throws ModelError for axes that are not finite or zero, limits or capacities that are not
  /// > 0 (or sized unlike the axes), or a grounded base.
  void setReactionWheels(const ReactionWheels& wheels);
  const ReactionWheels& reactionWheels() const { return wheels_; }
  /// \brief The post-capture law momentum_distribution (MomentumDistribution); off: the joints'
  /// own controls. \throws ModelError for a driven joint that is no PD joint, sizes unlike the
  /// model's joints, a rate limit that is not > 0, a negative or non-finite gain, or a grounded base.
  void setMomentumDistribution(const MomentumDistribution& law);
  const MomentumDistribution& momentumDistribution() const { return distribution_; }
  /// \brief The post-capture law impedance (GraspImpedance); off: the joints' own controls.
  /// \throws ModelError for a driven joint that is no PD joint, sizes unlike the model's joints, a
  /// contact off the model, a negative or non-finite gain, no damping, a limit not > 0, or together
  /// with momentum_distribution.
  void setGraspImpedance(const GraspImpedance& law);
  const GraspImpedance& graspImpedance() const { return impedance_; }
  /// \brief The reactionless rates at s (MomentumDistribution): the driven joints' qdot_d (the
  /// others 0), as the law computes them. For a caller that checks the law. \return 0,
  /// E_SIZE_MISMATCH, E_BAD_ARGUMENT (the law off) or a code of the dynamics.
  int reactionlessRates(const SimulationState& s, Eigen::VectorXd& qdot_d);
  /// \throws ModelError for a body out of range, a value not finite, or end <= start.
  void addWrench(const ScheduledWrench& wrench);
  const std::vector<ScheduledWrench>& wrenches() const { return wrenches_; }
  void setTorqueCallback(TorqueCallback callback) { callback_ = std::move(callback); }
  /// run() ends at the first output sample (the start included) where `stop` returns true, after
  /// the observer has seen it: s is left there. Empty (the default): run() goes on to t_end.
  /// (Evaluated at outputs only: for an instant located between them, setStopEvent.)
  void setStopCondition(std::function<bool(const SimulationState&)> stop) { stop_ = std::move(stop); }
  /// \brief A stop located in time: run() ends at the first instant where g(s) <= 0, found between
  /// steps as the hard stops are. At the start (after the stop condition), g <= 0 ends the run
  /// there. After every accepted step (a hard stop in it already applied), g is evaluated at the
  /// step's end; where it went from > 0 to <= 0, the crossing is located by the Illinois method on
  /// the step retaken from its start (bisection when the bracket shrinks slowly) until the bracket
  /// is within 1e-10 s, and the state put at its end, where g <= 0 holds (so the instant is at most
  /// 1e-10 s after the true crossing, plus the integration error). The observer sees that instant
  /// as the last output; run() returns 0 with s there and stats().event_time set.
  /// g sees t, state, velocity, work and impulse (not tau, base_wrench: not evaluated there); it
  /// is a function of the state at one instant (it may be called at times before others it saw).
  /// Where a hard stop and the crossing fall in one step, the earlier wins: a crossing before the
  /// stop's instant ends the run there and the impact did not happen (not counted); a g that the
  /// stop's impulse itself makes <= 0 ends the run at the stop, after the impact. A crossing in and
  /// out again within one step is not seen (the steps' ends are the samples of g; bound them by
  /// SimulationOptions::max_step); a NaN g counts as > 0, and after a NaN the event is put at the
  /// step's end (no bracket). g may throw (propagates as an observer's exception). Locating costs
  /// some 10 to 40 retaken steps and g evaluations, once; nothing is allocated by the simulator.
  /// Empty (the default): no event.
  void setStopEvent(std::function<double(const SimulationState&)> g) { event_ = std::move(g); }
  /// \brief The caller's way to stop a run from outside (Ctrl-C): run() calls `cancelled` before
  /// every step (accepted or rejected, so also after every output) and returns E_CANCELLED, s at
  /// the last accepted step, once it returns true. It may throw (e.g. Python's KeyboardInterrupt):
  /// the exception propagates as an observer's. Keep it cheap (an atomic flag's load); a poll that
  /// must do more (take a lock) counts its calls. Empty (the default): never cancelled.
  void setCancelPoll(std::function<bool()> cancelled) { cancelled_ = std::move(cancelled); }

  /// \brief Brakes on: the locked joints' rates become zero by an internal impulse (momentum
  /// unchanged), as when brakes engage. Call before run() if locked joints may be moving.
  /// (A set-up call: it allocates, unlike run(); it never throws.)
  /// \return 0, E_SIZE_MISMATCH (q or qdot), E_NOT_FINITE, E_NOT_POSITIVE_DEFINITE; s untouched on
  /// an error.
  int engageBrakes(SimulationState& s);

  /// \brief Integrates from s.t to t_end. `observer` (may be empty) sees s.t, every multiple of
  /// output_dt after it, and t_end (or the instant a stop ends the run). An exception thrown by the observer or the torque callback
  /// propagates (the run stops there); run() itself never throws. The set points of `hold`
  /// controls (joints, base attitude and position) are taken from s.
  /// \return 0 or an Error code: E_SIZE_MISMATCH (s.state.q or s.velocity.qdot, or a callback
  /// that resized tau), E_NOT_FINITE (an input, the time bounds, or a state that blew up),
  /// E_BAD_ARGUMENT (output_dt <= 0, t_end < s.t, a grounded base given a twist, or a joint
  /// outside a hard stop at the start), E_MAX_STEPS when options().max_steps are spent,
  /// E_STEP_UNDERFLOW when the adaptive step falls to round-off, E_CANCELLED when the cancel poll
  /// (setCancelPoll) asked it to stop, or a code of the dynamics. On an
  /// error found before the first step s's state and velocity are untouched (unless a hard stop
  /// engaged at the start); later, s is left at the last accepted step whose state can be
  /// evaluated (s.t tells how far the run got). A run allocates nothing
  /// unless a joint has Coulomb friction (its regularisation is set at the start) or a hard stop
  /// is met.
  int run(SimulationState& s, double t_end, double output_dt,
          const std::function<void(const SimulationState&)>& observer);

  /// Kinetic energy and momentum (P; L about the world origin) of a state, in O(n); with reaction
  /// wheels, L includes theirs (R A h: T does not, their rotors' inertia being the base's).
  /// \return 0, E_SIZE_MISMATCH (s.wheel_momentum neither empty nor one per wheel) or the code of
  /// forwardKinematics / MomentumSolver::compute; T and h_O untouched on an error.
  int energyAndMomentum(const SimulationState& s, double& T, Vector6d& h_O);
  /// The joint torques (controls limited, plus friction) and the base control's wrench that act
  /// at s, into s.tau and s.base_wrench as run() reports them at an output (the torque callback
  /// is called). For an observer whose callback changes at that instant (a sampled controller).
  /// \return 0, E_SIZE_MISMATCH, E_NOT_FINITE or a code of the dynamics; s untouched on an error.
  int actuation(SimulationState& s);
  /// \brief The accelerations at s as a run's derivative evaluates them (controls limited, friction,
  /// base control, wrenches and wheels acting), with the state's kinematics into `kin` and the
  /// external wrenches per body into `f_ext` (world axes, moment about the body frame's origin;
  /// empty when none acts): what graspWrench reads. For an observer (it allocates nothing after the
  /// first call with the same `kin`, `f_ext`); the torque callback is called, as by actuation().
  /// \return 0, E_SIZE_MISMATCH, E_NOT_FINITE or a code of the dynamics; outputs untouched on an error.
  int accelerations(const SimulationState& s, Kinematics& kin, FloatingAcceleration& a, std::vector<KDL::Wrench>& f_ext);

  /// The servos' fastest rate at a state (O(n^2): one articulated-body pass per PD joint).
  /// \return 0 or a code of the dynamics.
  int stiffness(const SimulationState& s, Stiffness& result);
  /// The inertia joint j's torque meets at s: 1 / (M^-1)_jj, the acceleration of a unit torque
  /// from rest, with the brakes of the joint controls. \return 0, E_SIZE_MISMATCH, E_BAD_ARGUMENT
  /// (j out of range or braked), or a code of the dynamics.
  int apparentInertia(const SimulationState& s, unsigned int j, double& m);

  const SimulationStats& stats() const { return stats_; }
  /// Each joint's v_s of the last run (model order; see SimulationOptions::friction_rate).
  const std::vector<double>& frictionVelocities() const { return friction_velocity_; }

 private:
  /// 1 / (M^-1)_jj at the state of kin_: the inertia joint j's torque meets (the acceleration of a
  /// unit torque from rest), with the dynamics' locks.
  int apparentInertia(unsigned int j, double& m);
  using Vector = Eigen::VectorXd;
  detail::StateLayout layout() const;
  /// The integrated state's vectors and stepper sized for the joints and wheels.
  void sizeState();
  void pack(const SimulationState& s, const Vector6d& h_O, Vector& x) const;
  /// A state given from outside a run (its sizes and t checked, its momentum computed) into x_tmp_.
  int packOutside(const SimulationState& s);
  int unpack(const Vector& x, double t, SimulationState& s);
  /// unpack() into the scratch state with its torques and work, then copied into s only if it
  /// succeeds.
  int publish(const Vector& x, double t, SimulationState& s);
  /// The joint torques (controls limited, then friction) and the external wrenches at scratch_,
  /// unpacked from x (whose momentum gives gravity's power on a free base).
  int actuate(double t, const Vector& x);
  /// x' = f(t, x), the equations of motion the steppers integrate (through Equations).
  int derivative(double t, const Vector& x, Vector& dx);
  /// One step of the integrator from (t, x) into x_new (detail::Stepper::step), with the wrench
  /// clock at the step's midpoint.
  int step(double t, double h, const Vector& x, Vector& x_new, double& error, bool& trial_failed);
  /// The step of length h from (t, x) again, without error control, to locate an event inside it.
  int retake(double t, double h, const Vector& x, Vector& result);
  /// Set-up of a run at s: hold set points, hard stops checked (E_BAD_ARGUMENT for a joint
  /// outside one), joints at a stop and moving into it stopped.
  int startRun(SimulationState& s);
  void applyLocks();
  /// The rates of `joints` stopped by an internal impulse (momentum kept; the base held when
  /// grounded). s.velocity changed; E_ codes as engageBrakes.
  int stopJoints(SimulationState& s, const std::vector<unsigned int>& joints);
  /// After an accepted step from x_prev (t_prev, length h) to x at t: a hard stop crossed is
  /// located, the state put at the limit and the joint stopped; stopped joints pulled away are
  /// released; excursions and saturation recorded. `t` and `x` may move back to the stop.
  int afterStep(double t_prev, double h, const Vector& x_prev, double& t, Vector& x);
  /// After afterStep on an accepted step from (t_prev, x_prev) to (t, x): the stop event's g at the
  /// step's end, and where it crossed to <= 0, the crossing located (setStopEvent); `t` and `x`
  /// move back to it, `fired` tells. The locks of the step (at_stop_before_) are put back for the
  /// retaken steps; a hard stop of this step after the crossing is undone.
  int stopEvent(double t_prev, const Vector& x_prev, double& t, Vector& x, bool& fired);
  /// g of the stop event at (t, x), unpacked into scratch_.
  int eventValue(double t, const Vector& x, double& g);
  /// Overshoot of the hard stops (> 0: past a limit) at x.
  double overshoot(const Vector& x) const;
  /// The time of the next wrench switch after t (infinity if none).
  double nextSwitch(double t) const;

  std::shared_ptr<const FloatingModel> model_;
  Kinematics kin_;             ///< the state of the last unpack() / energyAndMomentum()
  MomentumSolver momentum_;
  /// The articulated-body recursion (mimic joints as constraints on it: src/simulation/dynamics.hpp).
  std::unique_ptr<detail::Dynamics> dynamics_;
  SimulationOptions options_;
  std::vector<JointControl> controls_;
  std::vector<LimitMode> limit_modes_;
  std::vector<bool> at_stop_;  ///< joints held at a hard stop now
  /// at_stop_ during the step being taken, and after afterStep: the stop event's retakes need the
  /// step's own locks.
  std::vector<bool> at_stop_before_, at_stop_after_;
  std::vector<bool> just_stopped_;  ///< stopped in this step (afterStep's)
  std::vector<bool> locked_now_;  ///< braked or at a stop: what the dynamics hold
  std::vector<double> friction_velocity_;  ///< v_s per joint
  BaseControl base_control_;
  ReactionWheels wheels_;
  Eigen::MatrixXd wheel_split_;  ///< A+ (m x 3): the least-norm split of a torque among the wheels
  Eigen::VectorXd wheel_u_;      ///< the wheels' motor torques at the last actuate()
  MomentumDistribution distribution_;
  GraspImpedance impedance_;
  Eigen::Matrix<double, 6, Eigen::Dynamic> impedance_J_;  ///< 6 x n: the contact's fixed-base Jacobian
  Matrix3d impedance_R0_ = Matrix3d::Identity();   ///< the contact frame relative to the base at the start
  Vector3d impedance_p0_ = Vector3d::Zero();
  Eigen::VectorXd impedance_tau_, impedance_kdq_, impedance_along_;  ///< n: workspaces
  /// 6 x n: the hand's acceleration per unit torque of each driven joint from rest (H*^-1 through
  /// the dynamics): the self-motion's damping is kept out of its range, so it loads no grasp.
  Eigen::Matrix<double, 6, Eigen::Dynamic> impedance_B_;
  FloatingVelocity impedance_rest_;
  KDL::JntArray impedance_unit_;
  FloatingAcceleration impedance_acc_;
  /// impedance's torques at the state of kin_ into tau_control_ (the driven joints').
  int impedanceTorques(const KDL::JntArray& qdot);
  /// impedance's reference: the contact frame relative to the base at s.
  int impedanceStart(const SimulationState& s);
  /// At kin_ and scratch_ (unpacked, with its links' momentum h_links_): the law's rates into
  /// distribution_rates_, and the links' angular momentum about the CoM into L_g_.
  int distributionRates();
  /// momentum_distribution's rate servos at the start of a run: kv_j = bandwidth H*_jj at s.
  int distributionGains(const SimulationState& s);
  Vector6d h_links_ = Vector6d::Zero();  ///< the links' momentum (P; L about the origin) at the last unpack()
  Vector3d L_g_ = Vector3d::Zero();
  Eigen::VectorXd distribution_rates_;
  Eigen::VectorXd distribution_gain_;    ///< kv_j = bandwidth m_j, set at the start of a run
  Eigen::Matrix3Xd distribution_A_;      ///< A_w over the driven joints (3 x n, unused columns zero)
  FloatingVelocity unit_velocity_;       ///< a unit rate, the base still
  bool wheel_saturated_ = false;
  std::vector<ScheduledWrench> wrenches_;
  TorqueCallback callback_;
  std::function<bool(const SimulationState&)> stop_;
  std::function<bool()> cancelled_;
  std::function<double(const SimulationState&)> event_;
  double event_start_ = 0.0;  ///< g of the stop event at the start of the step being taken
  SimulationStats stats_;
  // workspaces
  SimulationState scratch_;
  KDL::JntArray tau_control_, tau_friction_, tau_extra_;
  std::vector<bool> saturated_;
  bool base_saturated_ = false;
  std::vector<KDL::Wrench> f_ext_;  ///< per body, world axes, moment about the body's origin
  Vector6d external_ = Vector6d::Zero();  ///< sum of external wrenches (f; moment about the origin)
  /// During a step, the time at which the scheduled wrenches are read: its midpoint. A step never
  /// straddles a switch, but its last stages sit on the switch that ends it, where activeAt()
  /// tells the next interval's state. NaN outside a step (outputs: the stage time itself).
  double wrench_clock_ = std::numeric_limits<double>::quiet_NaN();
  double external_power_[3] = {0.0, 0.0, 0.0};  ///< base control, wrenches, gravity [W]
  FloatingAcceleration acc_;
  Vector x_, x_tmp_, x_new_, x_prev_, x_event_;
  Vector dx_tmp_;  ///< accelerations()'s derivative
  Vector x_located_;  ///< the stop event's: the retaken state at the bracket's end where g <= 0
  struct Equations;  ///< derivative() as the steppers call it (detail::Derivative)
  std::unique_ptr<Equations> equations_;
  std::unique_ptr<detail::Stepper> stepper_;  ///< options().integrator's, on equations_
};

}  // namespace kdl_space
