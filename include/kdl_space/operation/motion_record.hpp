// What a motion did beyond its samples: the simulator's records (limits, saturation, steps), the
// set-up that produced them, and the running aggregates of its samples (drift of the invariants,
// the momentum balance, the energy split), kept as the samples go by: nothing grows with the run.
#pragma once

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/operation/motion_sample.hpp"

namespace kdl_space {

/// \brief The time to detumble, streamed over a run's samples: from the first sample to the first
/// one after which the base's angular rate |w| stays below `threshold` to the end [s]; 0 when it
/// never reaches it, NaN when the last sample is still at or above it (not detumbled in the run).
struct DetumbleTime {
  double threshold = 1e-3;  ///< [rad/s]
  void add(double t, double rate) {
    if (std::isnan(t_start_)) t_start_ = t;
    if (!(rate < threshold)) above_ = true, settled_ = std::numeric_limits<double>::quiet_NaN();
    else if (std::isnan(settled_)) settled_ = above_ ? t : t_start_;
  }
  double value() const { return settled_ - t_start_; }

 private:
  double t_start_ = std::numeric_limits<double>::quiet_NaN();
  double settled_ = std::numeric_limits<double>::quiet_NaN();
  bool above_ = false;
};

/// The largest load the grasp carried over samples (MotionSample::grasp_wrench's |f| and |n|, and
/// when): NaN while nothing held has been seen.
struct GraspPeak {
  double force = std::numeric_limits<double>::quiet_NaN();   ///< [N]
  double moment = std::numeric_limits<double>::quiet_NaN();  ///< [N m]
  double t_force = std::numeric_limits<double>::quiet_NaN(), t_moment = std::numeric_limits<double>::quiet_NaN();
  void add(const MotionSample& x) {
    if (!x.grasp_wrench.allFinite()) return;
    const double f = x.grasp_wrench.head<3>().norm(), n = x.grasp_wrench.tail<3>().norm();
    if (!(f <= force)) force = f, t_force = x.t;  // NaN at first: taken
    if (!(n <= moment)) moment = n, t_moment = x.t;
  }
  bool held() const { return !std::isnan(force); }
};

struct KDL_SPACE_EXPORT MotionRecord {
  std::shared_ptr<const FloatingModel> model;  ///< the system that moved
  SimulationOptions options;
  SimulationStats stats;                       ///< of the run
  std::vector<JointControl> controls;          ///< model order
  std::vector<LimitMode> limit_modes;          ///< model order
  BaseControl base_control;
  ReactionWheels wheels;                       ///< none: count() 0
  std::vector<double> friction_velocities;     ///< v_s per joint (SimulationOptions::friction_rate)
  Stiffness stiffness;                         ///< the servos' at the start of the run
  double output_step = 0.0;
  double t_start = 0.0, t_reached = 0.0;       ///< the run's start, and how far it got [s]

  // The samples' aggregates (add):
  long samples = 0;
  MotionSample first, last;
  double max_linear_momentum_change = 0.0;   ///< max |P - P_0| [N s]
  double max_angular_momentum_change = 0.0;  ///< max |L - L_0| [N m s]
  double max_energy_change = 0.0;            ///< max |T - T_0| [J]
  /// The momentum balance: max |h - h_0 - impulse| (P and L parts).
  double balance_linear = 0.0, balance_angular = 0.0;
  bool torques = false;  ///< some joint torque acted (a controller, friction)
  /// Each reaction wheel's largest |momentum| [N m s] and |motor torque| [N m] over the samples.
  Eigen::VectorXd wheel_peak_momentum, wheel_peak_torque;
  /// What the detumble took (the base's rate against DetumbleTime::threshold, `simulation.detumble_rate`)
  DetumbleTime detumble;
  double attitude_excursion = 0.0;  ///< max angle of R(t) R(t_0)^T over the samples [rad]
  double peak_base_rate = 0.0;      ///< max |w| of the base [rad/s]
  GraspPeak grasp;                  ///< the load the grasp carried (nothing held: NaN)
  Eigen::VectorXd peak_torque;      ///< per joint (model order): max |tau_j| applied [N m or N]
  /// The largest fraction of its capacity a wheel used (NaN without wheels).
  double wheelMomentumFraction() const;
  /// The kinetic energy the joints' controls, friction, hard stops and the base control took out
  /// of the system: -(their work) at the last sample [J].
  double energyDissipated() const { return -last.work.head<4>().sum(); }

  /// The simulator's set-up and records after (or during) its run.
  void takeFrom(const Simulator& sim);
  /// One more sample, in time order.
  void add(const MotionSample& x);
  /// Mean accepted step [s] (0 before any).
  double meanStep() const;
  /// The joints braked through the motion (JointControl::Mode::Locked), by name.
  std::vector<std::string> lockedJoints() const;
};

/// \brief Whether the run was held back by a stiff servo, and what to try (empty: it was not):
/// an RK4 step above the servos' stable step, or dopri5's steps far below the output step.
KDL_SPACE_EXPORT std::string stiffnessAdvice(const MotionRecord& r);

}  // namespace kdl_space
