// What the bus feels over the motion after a capture: the measures an engineer judges a capture
// configuration by (what `kdl_space plan`'s operation objectives score): the base's peak and final
// angular rate, its attitude excursion and settling time, each joint's peak torque against its
// effort limit, a compliant grasp's peak wrench, and the stack's momentum-determined rate (what
// no configuration changes much: the momentum the capture conserves over the stack's inertia).
// Read at the output samples of runCaptureOperation (as a study's motion peaks are), so a
// `simulate` run of the same configuration prints the same values.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/operation/capture_operation.hpp"

namespace kdl_space {

struct MotionMeasures {
  /// max |w| of the base over the samples of the motion after the capture (its first: just after
  /// the impact, or the end of a compliant contact) [rad/s]
  double peak_base_rate = 0.0;
  double final_base_rate = 0.0;  ///< |w| of the base at the last sample (the horizon's end) [rad/s]
  /// max over those samples of the angle of R(t) R(t_0)^T, R the base's attitude, t_0 the first
  /// sample's instant (the contact instant with an impulsive law, the touch with a compliant one) [rad]
  double attitude_excursion = 0.0;
  /// [s] after the first sample: the instant of the last sample at which the base's angular
  /// velocity w (a vector) is farther from its final value than `band` times its farthest
  /// (the classic settling band, relative to the final value); 0 when w never moves
  double settling_time = 0.0;
  /// Per joint of the robot (its model order): max |tau_j| applied over the motion [N m or N]
  std::vector<double> peak_torque;
  /// max_j peak_torque_j / effort_j over the joints with a finite effort limit > 0 (NaN: none has one)
  double peak_torque_ratio = std::numeric_limits<double>::quiet_NaN();
  std::string peak_torque_joint;  ///< where that maximum is (empty: NaN)
  /// The grasp's largest |f| [N] and |n| [N m] on the robot (MotionSample::grasp_wrench) over a
  /// compliant contact's samples and the motion after a capture that holds the target; NaN when
  /// nothing is held (a point impact; the impulsive capture itself is an impulse)
  double peak_grasp_force = std::numeric_limits<double>::quiet_NaN();
  double peak_grasp_moment = std::numeric_limits<double>::quiet_NaN();
  /// The base's |w| once the stack's joints are still: the system after the capture at its last
  /// sample's configuration, moving as one rigid body with that sample's momentum (baseTwist with
  /// qdot = 0) [rad/s]; 0 for a grounded base
  double momentum_rate = std::numeric_limits<double>::quiet_NaN();
  /// DetumbleTime over the motion's samples at the measurer's threshold [s] (NaN: not detumbled)
  double time_to_detumble = std::numeric_limits<double>::quiet_NaN();
  /// The largest fraction of its momentum capacity a reaction wheel used (NaN without wheels; with finish())
  double wheel_momentum_fraction = std::numeric_limits<double>::quiet_NaN();
  /// MotionRecord::energyDissipated at the last sample [J]
  double energy_dissipated = 0.0;
};

/// \brief Collects MotionMeasures from an operation's samples: give add() as (or from)
/// OperationOptions::observer, then finish() with the result once the run returned.
class KDL_SPACE_EXPORT MotionMeasurer {
 public:
  /// `robot`: the robot whose joints' torques are measured (its names are looked up in the
  /// system after the capture); `band` (0, 1): the settling band's width; `detumble_rate` [rad/s]:
  /// time_to_detumble's threshold. \throws InputError for a band outside (0, 1) or a rate <= 0.
  MotionMeasurer(const FloatingModel& robot, double band = 0.05, double detumble_rate = 1e-3);
  /// One sample, in time order (the approach's are skipped; the contact's give the grasp wrench).
  void add(const OperationResult& so_far, const MotionSample& x);
  /// \brief The measures of the samples seen (settling time and momentum rate need the whole run).
  /// \return 0, or the code of the momentum rate's dynamics at the last sample (its value NaN).
  int finish(const OperationResult& done, MotionMeasures& out);
  /// Forget the samples seen, for the next run.
  void reset();
  /// The peaks of the samples seen so far (the settling time and the momentum rate come with finish()).
  const MotionMeasures& peaks() const { return m_; }

 private:
  const FloatingModel& robot_;
  double band_;
  double detumble_rate_;
  DetumbleTime detumble_;
  GraspPeak grasp_;
  MotionMeasures m_;
  std::vector<int> in_model_;  ///< the robot's joints in the system after the capture
  const FloatingModel* after_ = nullptr;
  bool first_ = true;
  double t0_ = 0.0;
  Eigen::Quaterniond attitude0_ = Eigen::Quaterniond::Identity();
  std::vector<double> t_;            ///< the motion's sample instants
  std::vector<Eigen::Vector3d> w_;   ///< and the base's angular velocity at them
  MotionSample last_;
};

}  // namespace kdl_space
