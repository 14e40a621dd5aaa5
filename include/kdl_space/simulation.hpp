// The motion of a free-floating system over time (section 6 of the paper): integrate the
// equations of motion from a state, e.g. the one right after a capture.
#pragma once

#include <functional>
#include <memory>
#include <variant>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/dense_forward_dynamics.hpp"
#include "kdl_space/forward_dynamics.hpp"
#include "kdl_space/kinematics.hpp"
#include "kdl_space/momentum.hpp"

namespace kdl_space {

/// Time integration schemes.
enum class Integrator {
  RK4,              ///< classical fixed-step Runge-Kutta, order 4
  DormandPrince54,  ///< adaptive embedded Runge-Kutta 5(4) with error control (Dormand & Prince 1980)
};

/// What drives a joint.
struct JointControl {
  enum class Mode {
    Free,    ///< zero torque
    Locked,  ///< brakes on: the joint moves with its neighbour (rate held at zero)
    PD,      ///< servo to a set point: tau = kp (set_point - q) - kd qdot
  };
  Mode mode = Mode::Free;
  double kp = 0.0, kd = 0.0, set_point = 0.0;
};

/// Integration settings; all are the user's.
struct SimulationOptions {
  Integrator integrator = Integrator::DormandPrince54;
  double step = 1e-3;      ///< RK4 step; first trial step of the adaptive method [s]
  double rtol = 1e-10;     ///< adaptive: relative tolerance per state component
  double atol = 1e-12;     ///< adaptive: absolute tolerance per state component
  double max_step = 0.05;  ///< adaptive: largest step [s]
  long max_steps = 1000000;  ///< run() gives up (E_MAX_STEPS) after this many steps, e.g. an unstable controller
  Vector3d gravity = Vector3d::Zero();  ///< world frame; zero in orbit
};

/// Time, configuration and velocity of the system.
struct SimulationState {
  double t = 0.0;
  State state;                ///< base pose (world_T_base) and joint positions
  FloatingVelocity velocity;  ///< base twist (v of the base origin; w) and joint rates
};

/// Joint torques from the user's own controller, added to those of the joint modes.
using TorqueCallback = std::function<void(const SimulationState&, KDL::JntArray& tau)>;

/// Counters of the last run().
struct SimulationStats {
  long accepted_steps = 0;
  long rejected_steps = 0;
};

/// \brief Integrates the free-floating equations of motion.
///
/// The state integrated is (base position, base orientation as a unit quaternion, q, total
/// momentum (P; L about the world origin), qdot). The base twist follows from the momentum and
/// the joint rates (eq. 2), so with no external force the momentum is an exact invariant of every
/// Runge-Kutta step; the orientation is renormalised after every step (no Euler angles).
/// Each evaluation of the derivative is O(n): one forwardKinematics, the base twist from the
/// momentum (MomentumSolver::baseTwist) and the articulated-body forward dynamics
/// (ForwardDynamicsSolver), all reading the same Kinematics; no n x n matrix is built.
class KDL_SPACE_EXPORT Simulator {
 public:
  /// \throws ModelError unless step, rtol, atol, max_step are finite and > 0, max_steps > 0,
  /// gravity finite and the integrator an enumerator.
  explicit Simulator(std::shared_ptr<const FloatingModel> model, SimulationOptions options = {});

  const FloatingModel& model() const { return *model_; }
  const SimulationOptions& options() const { return options_; }
  /// \throws ModelError (a set-up call) for a joint index out of range, a mode that is no
  /// enumerator, or a gain or set point that is negative or not finite.
  void setJointControl(unsigned int joint, const JointControl& control);
  const std::vector<JointControl>& jointControls() const { return controls_; }
  void setTorqueCallback(TorqueCallback callback) { callback_ = std::move(callback); }

  /// \brief Brakes on: the locked joints' rates become zero by an internal impulse (momentum
  /// unchanged), as when brakes engage. Call before run() if locked joints may be moving.
  /// (A set-up call: it allocates, unlike run(); it never throws.)
  /// \return 0, E_SIZE_MISMATCH (q or qdot), E_NOT_FINITE, E_NOT_POSITIVE_DEFINITE; s untouched on
  /// an error.
  int engageBrakes(SimulationState& s);

  /// \brief Integrates from s.t to t_end. `observer` (may be empty) sees s.t, every multiple of
  /// output_dt after it, and t_end. An exception thrown by the observer or the torque callback
  /// propagates (the run stops there); run() itself never throws.
  /// \return 0 or an Error code: E_SIZE_MISMATCH (s.state.q or s.velocity.qdot, or a callback
  /// that resized tau), E_NOT_FINITE (an input, the time bounds, or a state that blew up),
  /// E_BAD_ARGUMENT (output_dt <= 0 or t_end < s.t), E_MAX_STEPS when options().max_steps are
  /// spent, E_STEP_UNDERFLOW when the adaptive step falls to round-off, or a code of the
  /// dynamics. On an error found before the first step s is untouched; later, s is left at the
  /// last accepted step whose state can be evaluated (s.t tells how far the run got).
  int run(SimulationState& s, double t_end, double output_dt,
          const std::function<void(const SimulationState&)>& observer);

  /// Kinetic energy and momentum (P; L about the world origin) of a state, in O(n). \return 0 or
  /// the code of forwardKinematics / MomentumSolver::compute; T and h_O untouched on an error.
  int energyAndMomentum(const SimulationState& s, double& T, Vector6d& h_O);

  const SimulationStats& stats() const { return stats_; }

 private:
  using Vector = Eigen::VectorXd;
  void pack(const SimulationState& s, const Vector6d& h_O, Vector& x) const;
  int unpack(const Vector& x, double t, SimulationState& s);
  /// unpack() into the scratch state, then copied into s only if it succeeds.
  int publish(const Vector& x, double t, SimulationState& s);
  int derivative(double t, const Vector& x, Vector& dx);
  int stepRK4(double t, double h, Vector& x);
  /// One trial step; `trial_failed` when a stage away from x (or the error estimate) could not be
  /// evaluated, which the caller treats as a rejected step.
  int stepDP54(double t, double h, Vector& x, double& error, bool& trial_failed);

  std::shared_ptr<const FloatingModel> model_;
  Kinematics kin_;             ///< the state of the last unpack() / energyAndMomentum()
  MomentumSolver momentum_;
  /// The articulated-body recursion; the dense route for a model with mimic joints.
  std::variant<ForwardDynamicsSolver, DenseForwardDynamics> dynamics_;
  SimulationOptions options_;
  std::vector<JointControl> controls_;
  TorqueCallback callback_;
  SimulationStats stats_;
  // workspaces
  SimulationState scratch_;
  KDL::JntArray tau_, tau_extra_;
  FloatingAcceleration acc_;
  std::vector<Vector> k_;
  Vector x_, x_tmp_, x_new_;
};

}  // namespace kdl_space
