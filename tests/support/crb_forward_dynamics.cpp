#include "crb_forward_dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace kdl_space::test {
namespace {

// Dormand & Prince (1980) RK5(4)7M tableau, as the Simulator's.
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

}  // namespace

// --- The simulation loop on it ------------------------------------------------------------------

CrbSimulator::CrbSimulator(std::shared_ptr<const FloatingModel> model, SimulationOptions options)
    : dynamics_(std::move(model)), options_(options) {
  const unsigned int n = dynamics_.model().nj();
  controls_.assign(n, JointControl{});
  scratch_.state = State(dynamics_.model());
  scratch_.velocity.qdot = KDL::JntArray(n);
  tau_ = KDL::JntArray(n);
  acc_.qddot = KDL::JntArray(n);
  const int size = 13 + 2 * static_cast<int>(n);
  k_.assign(7, Vector::Zero(size));
  x_.setZero(size);
  x_tmp_.setZero(size);
  x_new_.setZero(size);
  dynamics_.setGravity(options_.gravity);
}

void CrbSimulator::setJointControl(unsigned int joint, const JointControl& control) {
  controls_.at(joint) = control;
  std::vector<bool> locked(controls_.size());
  for (std::size_t j = 0; j < controls_.size(); ++j) locked[j] = controls_[j].mode == JointControl::Mode::Locked;
  dynamics_.setLocked(locked);
}

int CrbSimulator::unpack(const Vector& x, double t, SimulationState& s) {
  const unsigned int n = dynamics_.model().nj();
  const Eigen::Vector4d quat = x.segment<4>(3).normalized();
  s.t = t;
  s.state.world_T_base = KDL::Frame(KDL::Rotation::Quaternion(quat(0), quat(1), quat(2), quat(3)),
                                    KDL::Vector(x(0), x(1), x(2)));
  s.state.q.data = x.segment(7, n);
  s.velocity.qdot.data = x.tail(n);
  FreeFloatingSolver& k = dynamics_.kinematics();
  if (const int rc = k.compute(s.state)) return rc;
  Vector6d PL_g = x.segment<6>(7 + n);
  PL_g.tail<3>() -= k.r_g().cross(PL_g.head<3>());  // L_g = L_O - r_g x P
  return k.baseTwist(PL_g, s.velocity.qdot, s.velocity.base_twist);  // eq. 2
}

int CrbSimulator::derivative(double t, const Vector& x, Vector& dx) {
  const unsigned int n = dynamics_.model().nj();
  if (const int rc = unpack(x, t, scratch_)) return rc;
  for (unsigned int j = 0; j < n; ++j) {
    const JointControl& c = controls_[j];
    tau_(j) = c.mode == JointControl::Mode::PD
                  ? c.kp * (c.set_point - scratch_.state.q(j)) - c.kd * scratch_.velocity.qdot(j)
                  : 0.0;
  }
  if (const int rc = dynamics_.CartToJnt(scratch_.state, scratch_.velocity, tau_, {}, acc_)) return rc;
  const Vector3d w = toEigen(scratch_.velocity.base_twist.rot);
  const Eigen::Vector4d quat = x.segment<4>(3);
  dx.head<3>() = toEigen(scratch_.velocity.base_twist.vel);
  dx.segment<3>(3) = 0.5 * (quat(3) * w + w.cross(quat.head<3>()));
  dx(6) = -0.5 * w.dot(quat.head<3>());
  dx.segment(7, n) = x.tail(n);
  const double mass = dynamics_.model().totalMass();
  const Vector3d& r_g = dynamics_.kinematics().r_g();
  dx.segment<3>(7 + n) = mass * options_.gravity;
  dx.segment<3>(10 + n) = r_g.cross(mass * options_.gravity);
  dx.tail(n) = acc_.qddot.data;
  return E_NOERROR;
}

int CrbSimulator::stepRK4(double t, double h, Vector& x) {
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

int CrbSimulator::stepDP54(double t, double h, Vector& x, double& error) {
  for (int i = 0; i < 7; ++i) {
    x_tmp_ = x;
    for (int j = 0; j < i; ++j) x_tmp_ += h * kA[i][j] * k_[j];
    if (int rc = derivative(t + kC[i] * h, x_tmp_, k_[i])) return rc;
  }
  x_new_ = x;
  x_tmp_.setZero();
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
  return std::isfinite(error) ? E_NOERROR : E_NOT_FINITE;
}

int CrbSimulator::run(SimulationState& s, double t_end) {
  stats_ = {};
  const unsigned int n = dynamics_.model().nj();
  // The momentum about the world origin, as the Simulator's energyAndMomentum, by the dense route.
  FreeFloatingSolver& k = dynamics_.kinematics();
  Vector6d h_O;
  if (const int rc = k.compute(s.state)) return rc;
  if (const int rc = k.momentum(s.velocity.base_twist, s.velocity.qdot, h_O)) return rc;
  h_O.tail<3>() += k.r_g().cross(h_O.head<3>());  // L_O = L_g + r_g x P
  Vector& x = x_;
  double qx, qy, qz, qw;
  s.state.world_T_base.M.GetQuaternion(qx, qy, qz, qw);
  x.head<3>() = toEigen(s.state.world_T_base.p);
  x.segment<4>(3) << qx, qy, qz, qw;
  x.segment(7, n) = s.state.q.data;
  x.segment<6>(7 + n) = h_O;
  x.tail(n) = s.velocity.qdot.data;

  const bool adaptive = options_.integrator == Integrator::DormandPrince54;
  double t = s.t, h = adaptive ? std::min(options_.step, options_.max_step) : options_.step;
  while (t < t_end) {
    if (stats_.accepted_steps + stats_.rejected_steps >= options_.max_steps) return E_MAX_STEPS;
    const bool lands = t_end - t <= h * (1.0 + 1e-9);
    const double h_try = lands ? t_end - t : h;
    if (!adaptive) {
      if (const int rc = stepRK4(t, h_try, x)) return rc;
    } else {
      double error = 0.0;
      if (stepDP54(t, h_try, x, error)) error = std::numeric_limits<double>::infinity();
      const double factor = error == 0.0 ? 5.0 : std::clamp(0.9 * std::pow(error, -0.2), 0.2, 5.0);
      if (error > 1.0) {
        ++stats_.rejected_steps;
        h = h_try * factor;
        if (h < 1e-14 * std::max(1.0, std::abs(t))) return E_STEP_UNDERFLOW;
        continue;
      }
      x = x_new_;
      if (!lands || factor < 1.0) h = std::min(h_try * factor, options_.max_step);
    }
    ++stats_.accepted_steps;
    x.segment<4>(3).normalize();
    t = lands ? t_end : t + h_try;
  }
  if (const int rc = unpack(x, t, scratch_)) return rc;
  s.t = scratch_.t;
  s.state.world_T_base = scratch_.state.world_T_base;
  s.state.q.data = scratch_.state.q.data;
  s.velocity.base_twist = scratch_.velocity.base_twist;
  s.velocity.qdot.data = scratch_.velocity.qdot.data;
  return E_NOERROR;
}

}  // namespace kdl_space::test
