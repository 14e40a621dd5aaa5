#include "kdl_space/simulation/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "simulation/dynamics.hpp"
#include "simulation/simulation_layout.hpp"
#include "simulation/steppers.hpp"

namespace kdl_space {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

/// The steppers' one call into the simulator: x' = f(t, x) is derivative().
struct Simulator::Equations final : detail::Derivative {
  explicit Equations(Simulator& simulator) : sim(simulator) {}
  int f(double t, const Vector& x, Vector& dx) override { return sim.derivative(t, x, dx); }
  Simulator& sim;
};

Simulator::Simulator(std::shared_ptr<const FloatingModel> model, SimulationOptions options)
    : model_(model ? std::move(model) : throw ModelError("simulation: null model")),
      kin_(*model_),
      momentum_(model_),
      dynamics_(std::make_unique<detail::Dynamics>(model_)),
      options_(options) {
  const unsigned int n = this->model().nj();
  controls_.assign(n, JointControl{});
  limit_modes_.assign(n, LimitMode::Warn);
  at_stop_.assign(n, false);
  at_stop_before_.assign(n, false);
  at_stop_after_.assign(n, false);
  just_stopped_.assign(n, false);
  locked_now_.assign(n, false);
  saturated_.assign(n, false);
  friction_velocity_.assign(n, options_.friction_velocity);
  stats_.joints.assign(n, JointRecord{});
  scratch_.state = State(this->model());
  scratch_.velocity.qdot = KDL::JntArray(n);
  scratch_.tau = KDL::JntArray(n);
  tau_control_ = KDL::JntArray(n);
  tau_friction_ = KDL::JntArray(n);
  tau_extra_ = KDL::JntArray(n);
  acc_.qddot = KDL::JntArray(n);
  f_ext_.assign(this->model().bodies().size(), KDL::Wrench::Zero());
  const auto positive = [](double x) { return std::isfinite(x) && x > 0.0; };
  if (!positive(options_.step) || !positive(options_.rtol) || !positive(options_.atol) ||
      !positive(options_.max_step) || options_.max_steps <= 0 || !positive(options_.friction_velocity) || !positive(options_.friction_rate))
    throw ModelError(
        "simulation: step, rtol, atol, max_step, max_steps, friction_velocity and friction_rate must be finite and > 0");
  equations_ = std::make_unique<Equations>(*this);
  sizeState();  // ModelError for an integrator that is no enumerator
  if (!options_.gravity.allFinite()) throw ModelError("simulation: gravity must be finite");
  dynamics_->setGravity(options_.gravity);
  dynamics_->setGrounded(options_.grounded);
}

Simulator::~Simulator() = default;

detail::StateLayout Simulator::layout() const { return detail::StateLayout(model().nj(), wheels_.count()); }

void Simulator::sizeState() {
  const detail::StateLayout L = layout();
  for (Vector* v : {&x_, &x_tmp_, &x_new_, &x_prev_, &x_event_, &x_located_}) v->setZero(L.size);
  stepper_ = detail::makeStepper(options_.integrator, *equations_, L.size,
                                 detail::ErrorControl{options_.rtol, options_.atol, L.work});
  wheel_u_.setZero(L.m);
  scratch_.wheel_momentum.setZero(L.m);
  scratch_.wheel_torque.setZero(L.m);
}

void Simulator::setReactionWheels(const ReactionWheels& wheels) {
  const Eigen::Index m = wheels.count();
  const auto positive = [](const Eigen::VectorXd& v) { return !v.hasNaN() && (v.array() > 0.0).all(); };
  if (!wheels.axes.allFinite())
    throw ModelError("simulation: reaction wheels: the axes must be finite");
  for (Eigen::Index i = 0; i < m; ++i)
    if (wheels.axes.col(i).norm() < 1e-9)
      throw ModelError("simulation: reaction wheel " + std::to_string(i + 1) + ": its axis is zero");
  if (wheels.torque_limit.size() != m || wheels.capacity.size() != m)
    throw ModelError("simulation: reaction wheels: one torque limit and one capacity per wheel (" +
                     std::to_string(m) + " wheels)");
  if (!positive(wheels.torque_limit) || !positive(wheels.capacity))
    throw ModelError("simulation: reaction wheels: torque limits and capacities must be > 0 (infinity: none)");
  if (m > 0 && options_.grounded)
    throw ModelError("simulation: reaction wheels: the base is grounded (held still): they have nothing to turn");
  wheels_ = wheels;
  wheels_.axes.colwise().normalize();
  wheel_split_ = wheels_.axes.completeOrthogonalDecomposition().pseudoInverse();
  sizeState();
}

void Simulator::setJointControl(unsigned int joint, const JointControl& control) {
  if (joint >= controls_.size())
    throw ModelError("simulation: joint index " + std::to_string(joint) + " out of range (the model has " +
                     std::to_string(controls_.size()) + " joints)");
  const std::string who = "simulation: joint '" + model().jointNames()[joint] + "': ";
  if (control.mode != JointControl::Mode::Free && control.mode != JointControl::Mode::Locked &&
      control.mode != JointControl::Mode::PD)
    throw ModelError(who + "the mode is not one of Free, Locked, PD");
  if (control.kp < 0.0 || control.kd < 0.0 || !std::isfinite(control.kp) || !std::isfinite(control.kd) ||
      !std::isfinite(control.set_point))
    throw ModelError(who + "gains must be finite and >= 0");
  controls_[joint] = control;
  applyLocks();
}

void Simulator::setLimitMode(unsigned int joint, LimitMode mode) {
  if (joint >= limit_modes_.size())
    throw ModelError("simulation: joint index " + std::to_string(joint) + " out of range (the model has " +
                     std::to_string(limit_modes_.size()) + " joints)");
  if (mode != LimitMode::Ignore && mode != LimitMode::Warn && mode != LimitMode::Stop)
    throw ModelError("simulation: the limit mode is not one of Ignore, Warn, Stop");
  const JointProperties& p = model().jointProperties()[joint];
  if (mode == LimitMode::Stop && !(std::isfinite(p.lower) && std::isfinite(p.upper)))
    throw ModelError("simulation: joint '" + model().jointNames()[joint] +
                     "' has no position limits (a continuous joint): it has no stop");
  limit_modes_[joint] = mode;
}

void Simulator::setBaseControl(const BaseControl& control) {
  const auto gain = [](double x) { return std::isfinite(x) && x >= 0.0; };
  const auto limit = [](const Vector3d& l) { return !l.hasNaN() && (l.array() > 0.0).all(); };
  const BaseControl::Attitude& a = control.attitude;
  const BaseControl::Position& p = control.position;
  if (a.on) {
    if (!gain(a.kp) || !gain(a.kd)) throw ModelError("simulation: base_control.attitude: gains must be finite and >= 0");
    if (!limit(a.torque_limit)) throw ModelError("simulation: base_control.attitude: torque limits must be > 0");
    const Matrix3d R = toEigen(a.set_point);
    if (!R.allFinite() || (R.transpose() * R - Matrix3d::Identity()).norm() > 1e-9 || R.determinant() < 0.0)
      throw ModelError("simulation: base_control.attitude: the set point is not a rotation");
  }
  if (p.on) {
    if (!gain(p.kp) || !gain(p.kd)) throw ModelError("simulation: base_control.position: gains must be finite and >= 0");
    if (!limit(p.force_limit)) throw ModelError("simulation: base_control.position: force limits must be > 0");
    if (!p.set_point.allFinite()) throw ModelError("simulation: base_control.position: the set point must be finite");
  }
  if (control.on() && options_.grounded)
    throw ModelError("simulation: base_control: the base is grounded (held still): it has nothing to control");
  base_control_ = control;
}

void Simulator::addWrench(const ScheduledWrench& w) {
  if (w.body >= model().bodies().size())
    throw ModelError("simulation: wrench on body " + std::to_string(w.body) + ": out of range (the model has " +
                     std::to_string(model().bodies().size()) + " bodies)");
  if (!w.point.allFinite() || !w.wrench.allFinite() || !std::isfinite(w.start) || std::isnan(w.end))
    throw ModelError("simulation: wrench on link '" + model().bodies()[w.body].name + "': values must be finite");
  if (!(w.end > w.start))
    throw ModelError("simulation: wrench on link '" + model().bodies()[w.body].name + "': end must be after start");
  wrenches_.push_back(w);
}

void Simulator::applyLocks() {
  for (std::size_t j = 0; j < controls_.size(); ++j)
    locked_now_[j] = controls_[j].mode == JointControl::Mode::Locked || at_stop_[j];
  dynamics_->setLocked(locked_now_);
}

int Simulator::energyAndMomentum(const SimulationState& s, double& T, Vector6d& h_O) {
  const Eigen::Index m = wheels_.count();
  if (s.wheel_momentum.size() != 0 && s.wheel_momentum.size() != m) return E_SIZE_MISMATCH;
  if (const int rc = forwardKinematics(*model_, s.state, kin_)) return rc;
  if (const int rc = momentum_.compute(kin_, s.velocity)) return rc;
  h_O = momentum_.momentum();
  if (s.wheel_momentum.size() != 0) h_O.tail<3>() += kin_.R[0] * (wheels_.axes * s.wheel_momentum);
  T = momentum_.kineticEnergy();
  return E_NOERROR;
}

int Simulator::packOutside(const SimulationState& s) {
  const unsigned int n = model().nj();
  if (s.state.q.rows() != n || s.velocity.qdot.rows() != n) return E_SIZE_MISMATCH;
  if (!std::isfinite(s.t)) return E_NOT_FINITE;
  double T;
  Vector6d h_O;
  if (const int rc = energyAndMomentum(s, T, h_O)) return rc;
  pack(s, h_O, x_tmp_);  // x_tmp_: a stage's workspace, free between steps
  return E_NOERROR;
}

int Simulator::actuation(SimulationState& s) {
  const unsigned int n = model().nj();
  if (const int rc = packOutside(s)) return rc;
  if (const int rc = unpack(x_tmp_, s.t, scratch_)) return rc;
  if (const int rc = actuate(s.t, x_tmp_)) return rc;
  if (s.tau.rows() != n) s.tau = KDL::JntArray(n);
  s.tau.data = scratch_.tau.data;
  s.base_wrench = scratch_.base_wrench;
  s.wheel_torque = wheel_u_;
  return E_NOERROR;
}

int Simulator::accelerations(const SimulationState& s, Kinematics& kin, FloatingAcceleration& a,
                             std::vector<KDL::Wrench>& f_ext) {
  if (const int rc = packOutside(s)) return rc;
  dx_tmp_.resize(x_tmp_.size());  // free between steps, as x_tmp_
  if (const int rc = derivative(s.t, x_tmp_, dx_tmp_)) return rc;
  kin = kin_;
  a = acc_;
  const bool external = base_control_.on() || !wrenches_.empty() || wheels_.count() > 0;
  if (external) f_ext = f_ext_;
  else f_ext.clear();
  return E_NOERROR;
}

void Simulator::pack(const SimulationState& s, const Vector6d& h_O, Vector& x) const {
  const detail::StateLayout L = layout();
  const KDL::Frame& T = s.state.world_T_base;
  double qx, qy, qz, qw;
  T.M.GetQuaternion(qx, qy, qz, qw);
  x.head<3>() = toEigen(T.p);
  x.segment<4>(3) << qx, qy, qz, qw;
  x.segment(L.q, L.n) = s.state.q.data;
  x.segment<6>(L.h) = h_O;
  x.segment(L.qdot, L.n) = s.velocity.qdot.data;
  if (s.wheel_momentum.size() == L.m) x.segment(L.wheels, L.m) = s.wheel_momentum;
  else x.segment(L.wheels, L.m).setZero();
  x.segment<6>(L.work) << s.work.controller, s.work.friction, s.work.limits, s.work.base_control, s.work.wrenches,
      s.work.gravity;
  x.segment<6>(L.impulse) = s.impulse;
}

int Simulator::unpack(const Vector& x, double t, SimulationState& s) {
  const detail::StateLayout L = layout();
  if (!x.allFinite()) return E_NOT_FINITE;
  const Eigen::Vector4d quat = x.segment<4>(3).normalized();
  s.t = t;
  s.state.world_T_base = KDL::Frame(KDL::Rotation::Quaternion(quat(0), quat(1), quat(2), quat(3)),
                                    KDL::Vector(x(0), x(1), x(2)));
  s.state.q.data = x.segment(L.q, L.n);
  s.velocity.qdot.data = x.segment(L.qdot, L.n);
  const auto w = x.segment<6>(L.work);
  s.work = EnergySplit{w(0), w(1), w(2), w(3), w(4), w(5)};
  s.impulse = x.segment<6>(L.impulse);
  s.wheel_momentum = x.segment(L.wheels, L.m);
  if (const int rc = forwardKinematics(*model_, s.state, kin_)) return rc;  // the one pass of this stage
  if (options_.grounded) {
    s.velocity.base_twist = KDL::Twist::Zero();
    return E_NOERROR;
  }
  h_links_ = x.segment<6>(L.h);  // the system's with its wheels: the links' alone for eq. 2
  if (L.m > 0) h_links_.tail<3>() -= kin_.R[0] * (wheels_.axes * s.wheel_momentum);
  return momentum_.baseTwist(kin_, h_links_, s.velocity.qdot, s.velocity.base_twist);  // eq. 2
}

int Simulator::derivative(double t, const Vector& x, Vector& dx) {
  const detail::StateLayout L = layout();
  if (const int rc = unpack(x, t, scratch_)) return rc;
  if (const int rc = actuate(t, x)) return rc;
  const bool external = base_control_.on() || !wrenches_.empty() || L.m > 0;
  static const std::vector<KDL::Wrench> none;
  if (const int rc = dynamics_->CartToJnt(kin_, scratch_.velocity, scratch_.tau, external ? f_ext_ : none, acc_))
    return rc;
  const Vector3d w = toEigen(scratch_.velocity.base_twist.rot);
  const Eigen::Vector4d quat = x.segment<4>(3);
  dx.head<3>() = toEigen(scratch_.velocity.base_twist.vel);
  dx.segment<3>(3) = 0.5 * (quat(3) * w + w.cross(quat.head<3>()));  // 1/2 (0, w) * q, w in world
  dx(6) = -0.5 * w.dot(quat.head<3>());
  dx.segment(L.q, L.n) = x.segment(L.qdot, L.n);
  dx.segment<6>(L.h) = options_.grounded ? Vector6d::Zero() : external_;  // dh_O/dt: the external wrench
  dx.segment(L.qdot, L.n) = acc_.qddot.data;
  dx.segment(L.wheels, L.m) = wheel_u_;
  const auto& qdot = scratch_.velocity.qdot.data;
  dx.segment<6>(L.work) << tau_control_.data.dot(qdot), tau_friction_.data.dot(qdot), 0.0, external_power_[0],
      external_power_[1], external_power_[2];
  dx.segment<6>(L.impulse) = external_;
  return E_NOERROR;
}

int Simulator::step(double t, double h, const Vector& x, Vector& x_new, double& error, bool& trial_failed) {
  const detail::WrenchClock clock(wrench_clock_, t, h);
  return stepper_->step(t, h, x, x_new, error, trial_failed);
}

int Simulator::retake(double t, double h, const Vector& x, Vector& result) {
  const detail::WrenchClock clock(wrench_clock_, t, h);
  return stepper_->retake(t, h, x, result);
}

int Simulator::publish(const Vector& x, double t, SimulationState& s) {
  if (const int rc = unpack(x, t, scratch_)) return rc;
  if (const int rc = actuate(t, x)) return rc;
  s.t = scratch_.t;
  s.state.world_T_base = scratch_.state.world_T_base;
  s.state.q.data = scratch_.state.q.data;  // sizes checked by run(): no allocation
  s.velocity.base_twist = scratch_.velocity.base_twist;
  s.velocity.qdot.data = scratch_.velocity.qdot.data;
  s.tau.data = scratch_.tau.data;
  s.base_wrench = scratch_.base_wrench;
  s.work = scratch_.work;
  s.impulse = scratch_.impulse;
  s.wheel_momentum = scratch_.wheel_momentum;  // sized by run(): no allocation
  s.wheel_torque = wheel_u_;
  return E_NOERROR;
}

double Simulator::nextSwitch(double t) const {
  double next = kInf;
  for (const ScheduledWrench& w : wrenches_) {
    if (w.start > t) next = std::min(next, w.start);
    if (w.end > t) next = std::min(next, w.end);
  }
  return next;
}

int Simulator::run(SimulationState& s, double t_end, double output_dt,
                   const std::function<void(const SimulationState&)>& observer) {
  const unsigned int n = model().nj();
  stats_.accepted_steps = stats_.rejected_steps = 0;
  stats_.min_step = kInf;
  stats_.max_step = 0.0;
  stats_.base_saturation_time = stats_.wheel_saturation_time = 0.0;
  stats_.wheel_saturation_first_time = std::numeric_limits<double>::quiet_NaN();
  stats_.event_time = std::numeric_limits<double>::quiet_NaN();
  std::fill(stats_.joints.begin(), stats_.joints.end(), JointRecord{});
  if (s.state.q.rows() != n || s.velocity.qdot.rows() != n) return E_SIZE_MISMATCH;
  if (!std::isfinite(t_end) || !std::isfinite(s.t) || std::isnan(output_dt)) return E_NOT_FINITE;
  if (!(output_dt > 0.0) || t_end < s.t) return E_BAD_ARGUMENT;
  if (options_.grounded && toEigen(s.velocity.base_twist) != Vector6d::Zero()) return E_BAD_ARGUMENT;
  if (s.tau.rows() != n) s.tau = KDL::JntArray(n);  // an output: sized once
  if (s.wheel_momentum.size() == 0) s.wheel_momentum.setZero(wheels_.count());
  if (s.wheel_momentum.size() != wheels_.count()) return E_SIZE_MISMATCH;
  if (!s.wheel_momentum.allFinite()) return E_NOT_FINITE;
  s.wheel_torque.setZero(wheels_.count());
  s.work = EnergySplit{};
  s.impulse.setZero();
  if (const int rc = startRun(s)) return rc;
  double T;
  Vector6d h_O;
  if (const int rc = energyAndMomentum(s, T, h_O)) return rc;
  Vector& x = x_;
  pack(s, h_O, x);
  // The start must be evaluable; every later failure of the dynamics is the motion's.
  if (const int rc = derivative(s.t, x, x_new_)) return rc;
  if (const int rc = publish(x, s.t, s)) return rc;
  if (observer) observer(s);
  if (stop_ && stop_(s)) return E_NOERROR;
  if (event_) {  // the located stop: met at the start, the run ends there
    event_start_ = event_(s);
    if (event_start_ <= 0.0) {
      stats_.event_time = s.t;
      return E_NOERROR;
    }
  }

  // RK4 takes `step` as given; max_step bounds only the adaptive methods.
  const bool adaptive = stepper_->adaptive();
  double t = s.t, h = adaptive ? std::min(options_.step, options_.max_step) : options_.step;
  long outputs = 1;
  const double t0 = s.t;
  // On an error, s is left at the last accepted step if its state can be evaluated (else at the
  // last output), so that the caller sees how far the run got. A mass matrix that fails its
  // factorisation (positive definite at every configuration of a valid model, as at the start)
  // means the state has left the range where round-off is small: the motion blew up.
  const auto failed = [&](int rc) {
    publish(x, t, s);
    return rc == E_NOT_POSITIVE_DEFINITE ? static_cast<int>(E_NOT_FINITE) : rc;
  };
  while (t < t_end) {
    if (stats_.accepted_steps + stats_.rejected_steps >= options_.max_steps) return failed(E_MAX_STEPS);
    if (cancelled_ && cancelled_()) return failed(E_CANCELLED);
    const double t_out = std::min(t0 + outputs * output_dt, t_end);
    const double t_next = std::min(t_out, nextSwitch(t));
    // Land exactly on the output time (or a wrench's switch) when within round-off of it (no
    // sliver steps).
    const bool lands = t_next - t <= h * (1.0 + 1e-9);
    const double h_try = lands ? t_next - t : h;
    x_prev_ = x;
    std::copy(at_stop_.begin(), at_stop_.end(), at_stop_before_.begin());  // the step's locks (stop event)
    double error = 0.0;
    bool trial_failed = false;
    if (const int rc = step(t, h_try, x, x_new_, error, trial_failed)) {
      if (!trial_failed) return failed(rc);
      error = kInf;  // the trial step went where the dynamics are undefined: a rejected step
    }
    if (adaptive) {
      const double factor = stepper_->stepFactor(error);
      if (error > 1.0) {
        ++stats_.rejected_steps;
        h = h_try * factor;
        if (h < 1e-14 * std::max(1.0, std::abs(t))) return failed(E_STEP_UNDERFLOW);
        continue;
      }
      if (!lands || factor < 1.0) h = std::min(h_try * factor, options_.max_step);
    }
    x = x_new_;
    ++stats_.accepted_steps;
    x.segment<4>(3).normalize();  // the orientation stays a unit quaternion
    double t_new = lands ? t_next : t + h_try;
    if (const int rc = afterStep(t, h_try, x_prev_, t_new, x)) return failed(rc);
    bool event = false;  // the located stop: t_new and x moved back to it
    if (event_)
      if (const int rc = stopEvent(t, x_prev_, t_new, x, event)) return failed(rc);
    const double taken = t_new - t;
    // An output's (or the stop event's) sliver step says nothing of the motion.
    if ((!lands && !event) || stats_.accepted_steps == 1) {
      stats_.min_step = std::min(stats_.min_step, taken);
      stats_.max_step = std::max(stats_.max_step, taken);
    }
    t = t_new;
    if (t == t_out || event) {
      if (const int rc = publish(x, t, s)) return failed(rc);
      if (observer) observer(s);
      if (event) {
        stats_.event_time = t;
        break;
      }
      ++outputs;
      if (stop_ && stop_(s)) break;
    }
  }
  if (stats_.min_step == kInf) stats_.min_step = 0.0;
  return publish(x, t, s);
}

}  // namespace kdl_space
