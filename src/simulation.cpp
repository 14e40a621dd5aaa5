#include "kdl_space/simulation.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

namespace kdl_space {
namespace {

// Dormand & Prince (1980) RK5(4)7M tableau.
constexpr double kC[7] = {0.0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1.0, 1.0};
constexpr double kA[7][6] = {
    {},
    {1.0 / 5},
    {3.0 / 40, 9.0 / 40},
    {44.0 / 45, -56.0 / 15, 32.0 / 9},
    {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729},
    {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656},
    {35.0 / 384, 0.0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}};
constexpr double kB5[7] = {35.0 / 384, 0.0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84, 0.0};
constexpr double kB4[7] = {5179.0 / 57600, 0.0, 7571.0 / 16695, 393.0 / 640, -92097.0 / 339200, 187.0 / 2100, 1.0 / 40};
constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

namespace {
/// The forward dynamics of a motion: the O(n) recursion, or the dense route when joints are
/// coupled (mimic), which the recursion cannot carry.
std::variant<ForwardDynamicsSolver, DenseForwardDynamics> dynamicsFor(const std::shared_ptr<const FloatingModel>& model) {
  if (!model->mimic().empty()) return std::variant<ForwardDynamicsSolver, DenseForwardDynamics>(
      std::in_place_type<DenseForwardDynamics>, model);
  return std::variant<ForwardDynamicsSolver, DenseForwardDynamics>(std::in_place_type<ForwardDynamicsSolver>, model);
}
}  // namespace

Simulator::Simulator(std::shared_ptr<const FloatingModel> model, SimulationOptions options)
    : model_(model ? std::move(model) : throw ModelError("simulation: null model")),
      kin_(*model_),
      momentum_(model_),
      dynamics_(dynamicsFor(model_)),
      options_(options) {
  const unsigned int n = this->model().nj();
  controls_.assign(n, JointControl{});
  scratch_.state = State(this->model());
  scratch_.velocity.qdot = KDL::JntArray(n);
  tau_ = KDL::JntArray(n);
  tau_extra_ = KDL::JntArray(n);
  acc_.qddot = KDL::JntArray(n);
  const int size = 13 + 2 * static_cast<int>(n);
  k_.assign(7, Vector::Zero(size));
  x_.setZero(size);
  x_tmp_.setZero(size);
  x_new_.setZero(size);
  const auto positive = [](double x) { return std::isfinite(x) && x > 0.0; };
  if (!positive(options_.step) || !positive(options_.rtol) || !positive(options_.atol) ||
      !positive(options_.max_step) || options_.max_steps <= 0)
    throw ModelError("simulation: step, rtol, atol, max_step and max_steps must be finite and > 0");
  if (options_.integrator != Integrator::RK4 && options_.integrator != Integrator::DormandPrince54)
    throw ModelError("simulation: the integrator is not one of RK4, DormandPrince54");
  if (std::visit([&](auto& d) { return d.setGravity(options_.gravity); }, dynamics_) != E_NOERROR)
    throw ModelError("simulation: gravity must be finite");
}

void Simulator::setJointControl(unsigned int joint, const JointControl& control) {
  if (joint >= controls_.size())
    throw ModelError("simulation: joint index " + std::to_string(joint) + " out of range (the model has " +
                     std::to_string(controls_.size()) + " joints)");
  if (control.mode != JointControl::Mode::Free && control.mode != JointControl::Mode::Locked &&
      control.mode != JointControl::Mode::PD)
    throw ModelError("simulation: joint '" + model().jointNames()[joint] + "': the mode is not one of Free, Locked, PD");
  if (control.kp < 0.0 || control.kd < 0.0 || !std::isfinite(control.kp) || !std::isfinite(control.kd) ||
      !std::isfinite(control.set_point))
    throw ModelError("simulation: joint '" + model().jointNames()[joint] + "': gains must be finite and >= 0");
  controls_[joint] = control;
  std::vector<bool> locked(controls_.size());
  for (std::size_t j = 0; j < controls_.size(); ++j) locked[j] = controls_[j].mode == JointControl::Mode::Locked;
  std::visit([&](auto& d) { d.setLocked(locked); }, dynamics_);
}

int Simulator::energyAndMomentum(const SimulationState& s, double& T, Vector6d& h_O) {
  if (const int rc = forwardKinematics(*model_, s.state, kin_)) return rc;
  if (const int rc = momentum_.compute(kin_, s.velocity)) return rc;
  h_O = momentum_.momentum();
  T = momentum_.kineticEnergy();
  return E_NOERROR;
}

int Simulator::engageBrakes(SimulationState& s) {
  const unsigned int n = model().nj();
  if (s.state.q.rows() != n || s.velocity.qdot.rows() != n) return E_SIZE_MISMATCH;
  if (!s.velocity.qdot.data.allFinite() || !toEigen(s.velocity.base_twist).allFinite()) return E_NOT_FINITE;
  std::vector<unsigned int> locked;
  for (unsigned int j = 0; j < n; ++j)
    if (controls_[j].mode == JointControl::Mode::Locked && s.velocity.qdot(j) != 0.0) locked.push_back(j);
  if (locked.empty()) return E_NOERROR;
  if (const int rc = forwardKinematics(*model_, s.state, kin_)) return rc;
  // Generalized velocity nu = (base twist at p_b; qdot), mass matrix M in those coordinates:
  // nu+ = nu - M^-1 G^T (G M^-1 G^T)^-1 G nu, G selecting the locked rates. The base rows of
  // M nu (the momentum) are unchanged: the brake impulse is internal. The columns of
  // M^-1 G^T are the accelerations from rest of a unit torque on each locked joint, by the
  // articulated-body algorithm of the system without brakes or gravity (at rest the base's
  // classical acceleration is its spatial one at p_b).
  ForwardDynamicsSolver unbraked(model_);
  const FloatingVelocity rest(*model_);
  KDL::JntArray unit(n);
  FloatingAcceleration acc{Vector6d::Zero(), KDL::JntArray(n)};
  const std::size_t k = locked.size();
  Eigen::MatrixXd X(6 + n, k), GX(k, k);
  for (std::size_t i = 0; i < k; ++i) {
    unit(locked[i]) = 1.0;
    if (const int rc = unbraked.CartToJnt(kin_, rest, unit, {}, acc)) return rc;
    unit(locked[i]) = 0.0;
    X.col(i) << acc.base, acc.qddot.data;
  }
  Eigen::VectorXd nu(6 + n), G_nu(k);
  nu << toEigen(s.velocity.base_twist), s.velocity.qdot.data;
  for (std::size_t i = 0; i < k; ++i) {
    G_nu(i) = nu(6 + locked[i]);
    for (std::size_t c = 0; c < k; ++c) GX(i, c) = X(6 + locked[i], c);
  }
  const Eigen::LLT<Eigen::MatrixXd> GX_llt(GX);
  if (GX_llt.info() != Eigen::Success) return E_NOT_POSITIVE_DEFINITE;
  nu -= X * GX_llt.solve(G_nu);
  for (unsigned int j : locked) nu(6 + j) = 0.0;  // exactly
  if (!nu.allFinite()) return E_NOT_FINITE;
  s.velocity.base_twist = toTwist(nu.head<6>());
  s.velocity.qdot.data = nu.tail(n);
  return E_NOERROR;
}

void Simulator::pack(const SimulationState& s, const Vector6d& h_O, Vector& x) const {
  const unsigned int n = model().nj();
  const KDL::Frame& T = s.state.world_T_base;
  double qx, qy, qz, qw;
  T.M.GetQuaternion(qx, qy, qz, qw);
  x.head<3>() = toEigen(T.p);
  x.segment<4>(3) << qx, qy, qz, qw;
  x.segment(7, n) = s.state.q.data;
  x.segment<6>(7 + n) = h_O;
  x.tail(n) = s.velocity.qdot.data;
}

int Simulator::unpack(const Vector& x, double t, SimulationState& s) {
  const unsigned int n = model().nj();
  const Eigen::Vector4d quat = x.segment<4>(3).normalized();
  s.t = t;
  s.state.world_T_base = KDL::Frame(KDL::Rotation::Quaternion(quat(0), quat(1), quat(2), quat(3)),
                                    KDL::Vector(x(0), x(1), x(2)));
  s.state.q.data = x.segment(7, n);
  s.velocity.qdot.data = x.tail(n);
  if (const int rc = forwardKinematics(*model_, s.state, kin_)) return rc;  // the one pass of this stage
  return momentum_.baseTwist(kin_, x.segment<6>(7 + n), s.velocity.qdot, s.velocity.base_twist);  // eq. 2
}

int Simulator::derivative(double t, const Vector& x, Vector& dx) {
  const unsigned int n = model().nj();
  if (const int rc = unpack(x, t, scratch_)) return rc;
  for (unsigned int j = 0; j < n; ++j) {
    const JointControl& c = controls_[j];
    tau_(j) = c.mode == JointControl::Mode::PD
                  ? c.kp * (c.set_point - scratch_.state.q(j)) - c.kd * scratch_.velocity.qdot(j)
                  : 0.0;
  }
  if (callback_) {
    SetToZero(tau_extra_);
    callback_(scratch_, tau_extra_);
    if (tau_extra_.rows() != n) {
      tau_extra_.resize(n);  // the callback resized it: size it back for the next call
      return E_SIZE_MISMATCH;
    }
    tau_.data += tau_extra_.data;
  }
  static const std::vector<KDL::Wrench> none;
  if (const int rc = std::visit([&](auto& d) { return d.CartToJnt(kin_, scratch_.velocity, tau_, none, acc_); }, dynamics_))
    return rc;
  const Vector3d w = toEigen(scratch_.velocity.base_twist.rot);
  const Eigen::Vector4d quat = x.segment<4>(3);
  dx.head<3>() = toEigen(scratch_.velocity.base_twist.vel);
  dx.segment<3>(3) = 0.5 * (quat(3) * w + w.cross(quat.head<3>()));  // 1/2 (0, w) * q, w in world
  dx(6) = -0.5 * w.dot(quat.head<3>());
  dx.segment(7, n) = x.tail(n);
  const double mass = model().totalMass();
  const Vector3d& r_g = kin_.r_g;
  dx.segment<3>(7 + n) = mass * options_.gravity;                    // dP/dt: external force
  dx.segment<3>(10 + n) = r_g.cross(mass * options_.gravity);        // dL_O/dt: its moment
  dx.tail(n) = acc_.qddot.data;
  return E_NOERROR;
}

int Simulator::stepRK4(double t, double h, Vector& x) {
  if (int rc = derivative(t, x, k_[0])) return rc;
  x_tmp_ = x + 0.5 * h * k_[0];
  if (int rc = derivative(t + 0.5 * h, x_tmp_, k_[1])) return rc;
  x_tmp_ = x + 0.5 * h * k_[1];
  if (int rc = derivative(t + 0.5 * h, x_tmp_, k_[2])) return rc;
  x_tmp_ = x + h * k_[2];
  if (int rc = derivative(t + h, x_tmp_, k_[3])) return rc;
  x += h / 6.0 * (k_[0] + 2.0 * k_[1] + 2.0 * k_[2] + k_[3]);
  return E_NOERROR;
}

int Simulator::stepDP54(double t, double h, Vector& x, double& error, bool& trial_failed) {
  trial_failed = false;
  for (int i = 0; i < 7; ++i) {
    x_tmp_ = x;
    for (int j = 0; j < i; ++j) x_tmp_ += h * kA[i][j] * k_[j];
    if (int rc = derivative(t + kC[i] * h, x_tmp_, k_[i])) {
      trial_failed = i > 0;  // a stage away from x: a smaller step may not reach that state
      return rc;
    }
  }
  x_new_ = x;
  x_tmp_.setZero();  // the error estimate
  for (int i = 0; i < 7; ++i) {
    x_new_ += h * kB5[i] * k_[i];
    x_tmp_ += h * (kB5[i] - kB4[i]) * k_[i];
  }
  double sum = 0.0;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    const double scale = options_.atol + options_.rtol * std::max(std::abs(x(i)), std::abs(x_new_(i)));
    sum += (x_tmp_(i) / scale) * (x_tmp_(i) / scale);
  }
  error = std::sqrt(sum / static_cast<double>(x.size()));
  trial_failed = !std::isfinite(error);
  return trial_failed ? E_NOT_FINITE : E_NOERROR;
}

int Simulator::publish(const Vector& x, double t, SimulationState& s) {
  if (const int rc = unpack(x, t, scratch_)) return rc;
  s.t = scratch_.t;
  s.state.world_T_base = scratch_.state.world_T_base;
  s.state.q.data = scratch_.state.q.data;  // sizes checked by run(): no allocation
  s.velocity.base_twist = scratch_.velocity.base_twist;
  s.velocity.qdot.data = scratch_.velocity.qdot.data;
  return E_NOERROR;
}

int Simulator::run(SimulationState& s, double t_end, double output_dt,
                   const std::function<void(const SimulationState&)>& observer) {
  stats_ = {};
  const unsigned int n = model().nj();
  if (s.state.q.rows() != n || s.velocity.qdot.rows() != n) return E_SIZE_MISMATCH;
  if (!std::isfinite(t_end) || !std::isfinite(s.t) || std::isnan(output_dt)) return E_NOT_FINITE;
  if (!(output_dt > 0.0) || t_end < s.t) return E_BAD_ARGUMENT;
  double T;
  Vector6d h_O;
  if (const int rc = energyAndMomentum(s, T, h_O)) return rc;
  Vector& x = x_;
  pack(s, h_O, x);
  if (const int rc = publish(x, s.t, s)) return rc;
  if (observer) observer(s);

  // RK4 takes `step` as given; max_step bounds only the adaptive method.
  const bool adaptive = options_.integrator == Integrator::DormandPrince54;
  double t = s.t, h = adaptive ? std::min(options_.step, options_.max_step) : options_.step;
  long outputs = 1;
  const double t0 = s.t;
  // On an error, s is left at the last accepted step if its state can be evaluated (else at the
  // last output), so that the caller sees how far the run got.
  // After the first accepted step, a mass matrix that fails its factorisation (positive definite
  // at every configuration of a valid model) means the state has left the range where round-off
  // is small: the motion blew up.
  const auto failed = [&](int rc) {
    publish(x, t, s);
    return rc == E_NOT_POSITIVE_DEFINITE && stats_.accepted_steps > 0 ? static_cast<int>(E_NOT_FINITE) : rc;
  };
  while (t < t_end) {
    if (stats_.accepted_steps + stats_.rejected_steps >= options_.max_steps) return failed(E_MAX_STEPS);
    const double t_out = std::min(t0 + outputs * output_dt, t_end);
    // Land exactly on the output time when within round-off of it (no sliver steps).
    const bool lands = t_out - t <= h * (1.0 + 1e-9);
    const double h_try = lands ? t_out - t : h;
    if (options_.integrator == Integrator::RK4) {
      if (const int rc = stepRK4(t, h_try, x)) return failed(rc);
    } else {
      double error = 0.0;
      bool trial_failed = false;
      if (const int rc = stepDP54(t, h_try, x, error, trial_failed)) {
        if (!trial_failed) return failed(rc);
        error = kInf;  // the trial step went where the dynamics are undefined: a rejected step
      }
      const double factor = error == 0.0 ? 5.0 : std::clamp(0.9 * std::pow(error, -0.2), 0.2, 5.0);
      if (error > 1.0) {
        ++stats_.rejected_steps;
        h = h_try * factor;
        if (h < 1e-14 * std::max(1.0, std::abs(t))) return failed(E_STEP_UNDERFLOW);
        continue;
      }
      x = x_new_;
      if (!lands || factor < 1.0) h = std::min(h_try * factor, options_.max_step);
    }
    ++stats_.accepted_steps;
    x.segment<4>(3).normalize();  // the orientation stays a unit quaternion
    t = lands ? t_out : t + h_try;
    if (lands) {
      if (const int rc = publish(x, t, s)) return rc;
      if (observer) observer(s);
      ++outputs;
    }
  }
  return publish(x, t, s);
}

}  // namespace kdl_space
