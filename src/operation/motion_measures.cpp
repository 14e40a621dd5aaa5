// MotionMeasurer: the peaks as the samples go by, the settling time and the momentum-determined
// rate once the run is over.
#include "kdl_space/operation/motion_measures.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "spatial/message_text.hpp"

namespace kdl_space {

MotionMeasurer::MotionMeasurer(const FloatingModel& robot, double band, double detumble_rate)
    : robot_(robot), band_(band), detumble_rate_(detumble_rate) {
  if (!(band > 0.0 && band < 1.0)) throw InputError("settling_band: must lie in (0, 1), got " + detail::number(band));
  if (!(detumble_rate > 0.0)) throw InputError("detumble_rate: must be > 0, got " + detail::number(detumble_rate));
  reset();
}

void MotionMeasurer::reset() {
  m_ = MotionMeasures{};
  m_.peak_torque.assign(robot_.nj(), 0.0);
  in_model_.clear();
  after_ = nullptr;
  first_ = true;
  t_.clear();
  w_.clear();
  detumble_ = DetumbleTime{};
  grasp_ = GraspPeak{};
  detumble_.threshold = detumble_rate_;
}

void MotionMeasurer::add(const OperationResult& so_far, const MotionSample& x) {
  if (x.phase == Phase::Approach || x.phase == Phase::Capture) return;
  grasp_.add(x);  // the grasp's load: a compliant contact's, then the held target's after it
  m_.peak_grasp_force = grasp_.force;
  m_.peak_grasp_moment = grasp_.moment;
  if (after_ != so_far.model.get()) {  // the robot's joints in the system the sample belongs to
    after_ = so_far.model.get();
    in_model_.assign(robot_.nj(), -1);
    for (unsigned int j = 0; j < robot_.nj(); ++j) in_model_[j] = after_->jointIndex(robot_.jointNames()[j]);
  }
  const Eigen::Quaterniond attitude(x.quat(3), x.quat(0), x.quat(1), x.quat(2));
  if (first_) {
    first_ = false;
    t0_ = x.t;
    attitude0_ = attitude;
  }
  for (unsigned int j = 0; j < robot_.nj(); ++j)
    if (in_model_[j] >= 0 && in_model_[j] < x.tau.size() && std::isfinite(x.tau(in_model_[j])))
      m_.peak_torque[j] = std::max(m_.peak_torque[j], std::abs(x.tau(in_model_[j])));
  const Eigen::Vector3d w = x.twist.tail<3>();
  m_.peak_base_rate = std::max(m_.peak_base_rate, w.norm());
  m_.final_base_rate = w.norm();
  m_.attitude_excursion = std::max(m_.attitude_excursion, attitude0_.angularDistance(attitude));
  detumble_.add(x.t, w.norm());
  m_.time_to_detumble = detumble_.value();
  m_.energy_dissipated = -x.work.head<4>().sum();
  t_.push_back(x.t);
  w_.push_back(w);
}

int MotionMeasurer::finish(const OperationResult& done, MotionMeasures& out) {
  // The settling time: the last sample outside the band about the final angular velocity.
  if (!w_.empty()) {
    double farthest = 0.0;
    for (const Eigen::Vector3d& w : w_) farthest = std::max(farthest, (w - w_.back()).norm());
    for (std::size_t k = w_.size(); k-- > 0;)
      if ((w_[k] - w_.back()).norm() > band_ * farthest) {
        m_.settling_time = t_[k] - t0_;
        break;
      }
  }
  for (unsigned int j = 0; j < robot_.nj(); ++j) {
    const double effort = robot_.jointProperties()[j].effort;
    if (!(effort > 0.0) || !std::isfinite(effort)) continue;
    const double ratio = m_.peak_torque[j] / effort;
    if (std::isnan(m_.peak_torque_ratio) || ratio > m_.peak_torque_ratio) {
      m_.peak_torque_ratio = ratio;
      m_.peak_torque_joint = robot_.jointNames()[j];
    }
  }
  m_.wheel_momentum_fraction = done.record.wheelMomentumFraction();
  // The stack as one rigid body: its momentum at the end over its inertia there (eq. 2 with qdot = 0).
  int rc = E_NOERROR;
  if (done.record.options.grounded) {
    m_.momentum_rate = 0.0;
  } else if (done.model && done.record.samples > 0) {
    FreeFloatingSolver solver(done.model, FreeFloatingSolver::Extent::Jacobians);
    Vector6d PL_g;
    KDL::Twist still;
    rc = solver.compute(done.end.state);
    if (!rc) rc = solver.momentum(done.end.velocity.base_twist, done.end.velocity.qdot, PL_g);
    if (!rc) rc = solver.baseTwist(PL_g, KDL::JntArray(done.model->nj()), still);
    if (!rc) m_.momentum_rate = toEigen(still).tail<3>().norm();
  }
  out = m_;
  return rc;
}

}  // namespace kdl_space
