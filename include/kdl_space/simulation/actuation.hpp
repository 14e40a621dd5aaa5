// What acts on a free-floating system during a motion besides its own dynamics: the joints'
// controls (free, braked, PD servo), their effort limits and friction, the base's own attitude and
// position control (reaction wheels, thrusters), and external wrenches on a time schedule. Each
// is evaluated at a state by a plain function, so that a test can check it on its own.
#pragma once

#include <kdl/frames.hpp>
#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/multibody/model.hpp"
#include "kdl_space/spatial/spatial.hpp"

namespace kdl_space {

/// What drives a joint.
struct JointControl {
  enum class Mode {
    Free,    ///< zero torque
    Locked,  ///< brakes on: the joint moves with its neighbour (rate held at zero)
    PD,      ///< servo to a set point: tau = kp (set_point - q) - kd qdot
  };
  Mode mode = Mode::Free;
  double kp = 0.0, kd = 0.0, set_point = 0.0;
  /// PD only: the set point is the joint's position at the start of the motion (Simulator::run
  /// fills set_point from the state it starts from).
  bool hold = false;
};

/// What a joint's position limits do in a motion.
enum class LimitMode {
  Ignore,  ///< nothing
  Warn,    ///< the motion goes on; the excursions are recorded (SimulationStats::joints)
  Stop,    ///< hard stops: an inelastic impact at the limit, then held there while pushed into it
};

/// \brief The joint friction torque: viscous damping and a regularised Coulomb friction,
/// tau_f = -damping qdot - friction tanh(qdot / v_s) (URDF <dynamics damping friction>).
/// The regularisation keeps the motion smooth: the Coulomb torque is a damping of slope
/// friction / v_s near rest, so a joint under a torque below `friction` creeps at about
/// v_s atanh(tau / friction) instead of sticking exactly. Its power tau_f qdot is never positive.
inline double frictionTorque(double qdot, double damping, double friction, double v_s) {
  if (friction == 0.0) return -damping * qdot;  // the same number, without tanh (a tenth of a motion's time)
  return -damping * qdot - friction * std::tanh(qdot / v_s);
}

/// \brief The satellite's own control of its base (reaction wheels, thrusters), applied as an
/// external wrench on the base body; the momentum then changes by its impulse.
struct BaseControl {
  /// Attitude PD toward a set point: n = kp e - kd w, e the rotation vector of
  /// set_point * R_base^-1 (world axes); each component in the base's axes limited to
  /// +-torque_limit (a wheel per base axis).
  struct Attitude {
    bool on = false;
    bool hold = false;  ///< the set point is the base's orientation at the start of the motion
    KDL::Rotation set_point = KDL::Rotation::Identity();  ///< world_R_base wanted
    double kp = 0.0, kd = 0.0;                            ///< [N m/rad], [N m s/rad]
    Vector3d torque_limit = Vector3d::Constant(std::numeric_limits<double>::infinity());  ///< [N m]
  };
  /// Position PD of the base frame's origin: f = kp (set_point - p_b) - kd v_b, each component in
  /// the base's axes limited to +-force_limit (thrusters fixed to the base), acting through the
  /// base body's centre of mass (no moment).
  struct Position {
    bool on = false;
    bool hold = false;  ///< the set point is the base's position at the start of the motion
    Vector3d set_point = Vector3d::Zero();  ///< world [m]
    double kp = 0.0, kd = 0.0;              ///< [N/m], [N s/m]
    Vector3d force_limit = Vector3d::Constant(std::numeric_limits<double>::infinity());  ///< [N]
  };
  Attitude attitude;
  Position position;
  /// The phases of a capture operation in which it acts (a scenario's `base_control.phases`):
  /// the approach (`in_approach`), and the motion after the capture, or a plain motion without
  /// one (`after_capture`). By default after the capture only: an approach opts in. A Simulator
  /// alone does not read them: it applies the control it is given whenever that is on().
  bool in_approach = false;
  bool after_capture = true;
  bool on() const { return attitude.on || position.on; }
};

/// \brief The base control's wrench (f; n), world axes, the moment about the base body's centre
/// of mass (f acts through it). `world_T_base` and `base_twist` (v of the base origin; w) are the
/// base's; `saturated` tells whether a limit was reached on any axis.
KDL_SPACE_EXPORT Vector6d baseControlWrench(const BaseControl& control, const KDL::Frame& world_T_base,
                                            const KDL::Twist& base_twist, bool* saturated = nullptr);

/// \brief Reaction wheels fixed in the base: a cluster of m wheels, one column of `axes` per wheel
/// (its spin axis in the base's axes; normalised by Simulator::setReactionWheels). Each wheel's
/// momentum h_i about its axis [N m s] is part of the simulated state; its motor's torque
/// u_i = dh_i/dt is limited to +-torque_limit_i, and to zero in the direction past its momentum
/// capacity +-capacity_i (the wheel at its top speed: saturated). The bus feels the reaction
/// -d/dt (R A h) = -R A u - w x R A h (world axes; R the base's orientation, w its angular rate):
/// an internal torque, so the momentum of the system with its wheels, (P; L + R A h), is
/// invariant. The wheels' rotor inertia is taken as part of the base's (as SpaceDyn's and
/// Basilisk's simple wheel models): their spin energy is not counted, their motors' work on the
/// bus is (EnergySplit::base_control).
struct ReactionWheels {
  Eigen::Matrix<double, 3, Eigen::Dynamic> axes;  ///< 3 x m, base axes
  Eigen::VectorXd torque_limit;                   ///< m [N m], > 0 (infinity: none)
  Eigen::VectorXd capacity;                       ///< m [N m s], > 0 (infinity: none)
  Eigen::Index count() const { return axes.cols(); }
};

/// \brief The wheels' motor torques u (m) for a torque n wanted on the bus (world axes, the base
/// control's): u = -A+ (R^T n) by the least-norm split `split` = A+ (m x 3), then each limited to
/// +-torque_limit_i and set to zero where it would drive |h_i| past capacity_i. `saturated` tells
/// whether a limit acted. The gyroscopic part of the reaction (wheelReaction) is not compensated.
KDL_SPACE_EXPORT void wheelTorques(const ReactionWheels& wheels, const Eigen::MatrixXd& split, const Matrix3d& R,
                                   const Vector3d& n, const Eigen::VectorXd& h, Eigen::VectorXd& u, bool& saturated);

/// \brief The torque the wheels exert on the bus (world axes): -R A u - w x (R A h).
KDL_SPACE_EXPORT Vector3d wheelReaction(const ReactionWheels& wheels, const Matrix3d& R, const Vector3d& w,
                                        const Eigen::VectorXd& h, const Eigen::VectorXd& u);

/// \brief The post-capture law `momentum_distribution`, after Dimitrov and Yoshida's bias momentum
/// approach: the arm's joints take up the stack's angular momentum so that the base does not turn,
/// and the base's attitude actuators (its wheels) unload it from the arm.
///  - The joints it drives (`joints`, each a PD joint of the simulator) are rate servos,
///    tau_j = kv_j (qdot_d,j - qdot_j), kv_j = bandwidth H*_jj with H*_jj the inertia the joint
///    meets with the others held and the base free, at the start of the run (their PD gains no
///    longer act), tracking the reactionless rates:
///    the least-norm qdot_d over them with A_w qdot = L_g, the base's angular velocity zero
///    (eq. 2 in the centroid's coordinates: I_g w = L_g - A_w qdot, A_w the angular rows of A_m,
///    L_g the links' angular momentum about the system's CoM, the other joints' rates as they
///    are); a damped inverse below a singular value of 1e-2 of the largest; scaled down as a whole
///    to the joints' rate limits (`rate_limit`; infinity: none).
///  - The base control's attitude torque gets -unload_gain L_g: the wheels (or thrusters) draw
///    the momentum out of the links, and as it goes the reactionless rates and the arm come to rest.
struct MomentumDistribution {
  bool on = false;
  std::vector<bool> joints;      ///< model order: driven by the law
  Eigen::VectorXd rate_limit;    ///< model order [rad/s or m/s]; infinity: none
  double unload_gain = 0.0;      ///< [1/s], >= 0
  double bandwidth = 20.0;       ///< the rate servos' [1/s], > 0
};

/// \brief The post-capture law `impedance`: the arm as a spring-damper at the grasp, so that the
/// hand yields to the held target instead of stopping it at once (a Cartesian impedance without
/// force sensing). The joints it drives (`joints`, PD joints of the simulator, whose servos it
/// replaces) get tau = J^T F + tau_N, J the fixed-base Jacobian of `contact` over them (world axes,
/// the twist of the contact point the joints alone give it), with
///   F = -K e - D J qdot,
/// e the contact frame's displacement from its pose relative to the base at the start of the run
/// (the position; the rotation vector), in world axes; K = diag(stiffness(0) I, stiffness(1) I),
/// D alike. F's force and moment are each scaled down to max_force and max_moment (the grasp's
/// limit, law.max_grasp_wrench): the arm gives way rather than pass it. The driven joints' self-
/// motion (a redundant arm's) is damped by tau_N = -P Kd P qdot, Kd the servos' kd, P = I - B+ B
/// over the driven joints, B (6 x driven) the hand's acceleration per unit joint torque from rest
/// with the base free (H*^-1 by the dynamics): B tau_N = 0, so it accelerates no hand and loads no
/// grasp, and it only dissipates. Zero for an arm of 6 joints or fewer at full rank.
struct GraspImpedance {
  bool on = false;
  std::vector<bool> joints;  ///< model order: driven by the law
  Contact contact;           ///< the grasp: the robot's contact point in the model that moves
  /// (translation [N/m], rotation [N m/rad]), >= 0
  Eigen::Vector2d stiffness = Eigen::Vector2d::Zero();
  /// (translation [N s/m], rotation [N m s/rad]), >= 0, not both 0
  Eigen::Vector2d damping = Eigen::Vector2d::Zero();
  double max_force = std::numeric_limits<double>::infinity();   ///< [N]
  double max_moment = std::numeric_limits<double>::infinity();  ///< [N m]
};

/// \brief An external wrench on a body over a time window (a thruster firing, a push): the force
/// f acts at `point` (in the body's frame) and the couple n is added; both in world axes, or in
/// the body's axes (turning with it) when `body_axes`.
struct ScheduledWrench {
  unsigned int body = 0;                 ///< index in FloatingModel::bodies()
  Vector3d point = Vector3d::Zero();     ///< body frame [m]
  Vector6d wrench = Vector6d::Zero();    ///< (f; n) [N; N m]
  bool body_axes = false;
  double start = 0.0;                                          ///< [s]
  double end = std::numeric_limits<double>::infinity();        ///< active on [start, end)
  bool activeAt(double t) const { return t >= start && t < end; }
};

}  // namespace kdl_space
