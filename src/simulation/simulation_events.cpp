// The simulator's forces and events: the joint torques and external wrenches of a state, brakes
// and hard stops (impulses that keep the momentum), what a run records, and the servos' stiffness.
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "kdl_space/simulation/simulation.hpp"
#include "simulation/dynamics.hpp"
#include "simulation/simulation_layout.hpp"

namespace kdl_space {
namespace {

constexpr double kStopTolerance = 1e-10;  ///< how close to its limit a hard stop is put [rad or m]

/// The twist (v at p_b; w) of body i, world axes: the base's plus its joints' along the path.
Vector6d bodyTwist(const FloatingModel& model, const Kinematics& kin, const FloatingVelocity& v, int i) {
  Vector6d V = toEigen(v.base_twist);
  for (int b = i; b > 0; b = model.bodies()[b].parent)
    if (model.bodies()[b].joint >= 0) V += kin.S[b] * v.qdot(model.bodies()[b].joint);
  return V;
}

}  // namespace

int Simulator::actuate(double t, const Vector& x) {
  const unsigned int n = model().nj();
  const KDL::JntArray& q = scratch_.state.q;
  const KDL::JntArray& qdot = scratch_.velocity.qdot;
  if (distribution_.on)
    if (const int rc = distributionRates()) return rc;
  for (unsigned int j = 0; j < n; ++j) {
    const JointControl& c = controls_[j];
    if (distribution_.on && distribution_.joints[j])  // a rate servo on the reactionless rate
      tau_control_(j) = distribution_gain_(j) * (distribution_rates_(j) - qdot(j));
    else
      tau_control_(j) = c.mode == JointControl::Mode::PD ? c.kp * (c.set_point - q(j)) - c.kd * qdot(j) : 0.0;
  }
  if (impedance_.on)  // the driven joints': J^T F, the grasp's impedance
    if (const int rc = impedanceTorques(qdot)) return rc;
  if (callback_) {
    SetToZero(tau_extra_);
    callback_(scratch_, tau_extra_);
    if (tau_extra_.rows() != n) {
      tau_extra_.resize(n);  // the callback resized it: size it back for the next call
      return E_SIZE_MISMATCH;
    }
    tau_control_.data += tau_extra_.data;
  }
  const std::vector<JointProperties>& props = model().jointProperties();
  for (unsigned int j = 0; j < n; ++j) {
    const double effort = props[j].effort;
    double& u = tau_control_(j);
    saturated_[j] = options_.effort_limits && std::isfinite(effort) && effort > 0.0 && std::abs(u) > effort;
    if (saturated_[j]) u = std::copysign(effort, u);
    tau_friction_(j) = options_.joint_friction ? frictionTorque(qdot(j), props[j].damping, props[j].friction,
                                                                friction_velocity_[j])
                                               : 0.0;
    scratch_.tau(j) = u + tau_friction_(j);
  }

  // External wrenches: per body for the dynamics (moment about the body's origin), summed about
  // the world origin for the momentum, and their power.
  external_.setZero();
  std::fill(std::begin(external_power_), std::end(external_power_), 0.0);
  scratch_.base_wrench.setZero();
  base_saturated_ = wheel_saturated_ = false;
  const auto apply = [&](int body, const Vector3d& r, const Vector3d& f, const Vector3d& m, double& power) {
    f_ext_[body].force += toKDL(f);
    f_ext_[body].torque += toKDL(m + (r - kin_.p[body]).cross(f));
    external_.head<3>() += f;
    external_.tail<3>() += r.cross(f) + m;
    const Vector6d V = bodyTwist(model(), kin_, scratch_.velocity, body);
    power += f.dot(V.head<3>() + V.tail<3>().cross(r - kin_.p_b)) + m.dot(V.tail<3>());
  };
  const bool wheels = wheels_.count() > 0;
  if (base_control_.on() || !wrenches_.empty() || wheels) {
    std::fill(f_ext_.begin(), f_ext_.end(), KDL::Wrench::Zero());
    if (base_control_.on()) {
      scratch_.base_wrench = baseControlWrench(base_control_, scratch_.state.world_T_base,
                                               scratch_.velocity.base_twist, &base_saturated_);
      // momentum_distribution: the attitude actuators draw the links' momentum out, within their
      // limits (the wheels' below; the thrusters' the control's own, per base axis).
      if (distribution_.on && base_control_.attitude.on) {
        Vector3d n = scratch_.base_wrench.tail<3>() - distribution_.unload_gain * L_g_;
        if (!wheels) {
          const Matrix3d& R = kin_.R[0];
          const Vector3d local = R.transpose() * n, limit = base_control_.attitude.torque_limit;
          const Vector3d clamped = local.cwiseMax(-limit).cwiseMin(limit);
          base_saturated_ = base_saturated_ || clamped != local;
          n = R * clamped;
        }
        scratch_.base_wrench.tail<3>() = n;
      }
      // With wheels the attitude torque is theirs (below), an internal one.
      const Vector3d thrust_torque = wheels ? Vector3d::Zero() : Vector3d(scratch_.base_wrench.tail<3>());
      apply(0, kin_.com[0], scratch_.base_wrench.head<3>(), thrust_torque, external_power_[0]);
    }
    if (wheels) {  // the wheels' motors, and the reaction the bus feels (a couple: no momentum changes)
      const Vector3d w = toEigen(scratch_.velocity.base_twist.rot);
      wheel_u_.setZero();
      if (base_control_.attitude.on)
        wheelTorques(wheels_, wheel_split_, kin_.R[0], scratch_.base_wrench.tail<3>(), scratch_.wheel_momentum,
                     wheel_u_, wheel_saturated_);
      const Vector3d n = wheelReaction(wheels_, kin_.R[0], w, scratch_.wheel_momentum, wheel_u_);
      scratch_.base_wrench.tail<3>() = n;
      f_ext_[0].torque += toKDL(n);
      external_power_[0] += n.dot(w);
    }
    for (const ScheduledWrench& w : wrenches_) {
      if (!w.activeAt(std::isnan(wrench_clock_) ? t : wrench_clock_)) continue;
      const Matrix3d& R = kin_.R[w.body];
      Vector3d f = w.wrench.head<3>(), m = w.wrench.tail<3>();
      if (w.body_axes) {
        f = R * f;
        m = R * m;
      }
      apply(static_cast<int>(w.body), kin_.p[w.body] + R * w.point, f, m, external_power_[1]);
    }
  }
  if (options_.gravity != Vector3d::Zero()) {  // M g at the CoM; its power M g . v_g = g . P
    const Vector3d weight = model().totalMass() * options_.gravity;
    external_.head<3>() += weight;
    external_.tail<3>() += kin_.r_g.cross(weight);
    if (options_.grounded) {  // P is no state of a grounded base
      if (const int rc = momentum_.compute(kin_, scratch_.velocity)) return rc;
      external_power_[2] = options_.gravity.dot(momentum_.momentum().head<3>());
    } else {
      external_power_[2] = options_.gravity.dot(x.segment<3>(layout().h));
    }
  }
  return E_NOERROR;
}

int Simulator::engageBrakes(SimulationState& s) {
  const unsigned int n = model().nj();
  if (s.state.q.rows() != n || s.velocity.qdot.rows() != n) return E_SIZE_MISMATCH;
  if (!s.velocity.qdot.data.allFinite() || !toEigen(s.velocity.base_twist).allFinite()) return E_NOT_FINITE;
  std::vector<unsigned int> locked;
  for (unsigned int j = 0; j < n; ++j)
    if (controls_[j].mode == JointControl::Mode::Locked && s.velocity.qdot(j) != 0.0) locked.push_back(j);
  return stopJoints(s, locked);
}

int Simulator::stopJoints(SimulationState& s, const std::vector<unsigned int>& joints) {
  const unsigned int n = model().nj();
  if (joints.empty()) return E_NOERROR;
  if (const int rc = forwardKinematics(*model_, s.state, kin_)) return rc;
  // Generalized velocity nu = (base twist at p_b; qdot), mass matrix M in those coordinates:
  // nu+ = nu - M^-1 G^T (G M^-1 G^T)^-1 G nu, G selecting the joints to stop. The base rows of
  // M nu (the momentum) are unchanged: the impulse is internal (a grounded base's rows are held).
  // The columns of M^-1 G^T are the accelerations from rest of a unit torque on each joint, by
  // the forward dynamics of the system with those joints free and no gravity (at rest the base's
  // classical acceleration is its spatial one at p_b).
  detail::Dynamics free = *dynamics_;
  std::vector<bool> locks = locked_now_;
  for (unsigned int j : joints) locks[j] = false;
  free.setLocked(locks);
  free.setGravity(Vector3d::Zero());
  const FloatingVelocity rest(*model_);
  KDL::JntArray unit(n);
  FloatingAcceleration acc{Vector6d::Zero(), KDL::JntArray(n)};
  static const std::vector<KDL::Wrench> none;
  const std::size_t k = joints.size();
  Eigen::MatrixXd X(6 + n, k), GX(k, k);
  for (std::size_t i = 0; i < k; ++i) {
    unit(joints[i]) = 1.0;
    if (const int rc = free.CartToJnt(kin_, rest, unit, none, acc)) return rc;
    unit(joints[i]) = 0.0;
    X.col(i) << acc.base, acc.qddot.data;
  }
  Eigen::VectorXd nu(6 + n), G_nu(k);
  nu << toEigen(s.velocity.base_twist), s.velocity.qdot.data;
  for (std::size_t i = 0; i < k; ++i) {
    G_nu(i) = nu(6 + joints[i]);
    for (std::size_t c = 0; c < k; ++c) GX(i, c) = X(6 + joints[i], c);
  }
  const Eigen::LLT<Eigen::MatrixXd> GX_llt(GX);
  if (GX_llt.info() != Eigen::Success) return E_NOT_POSITIVE_DEFINITE;
  nu -= X * GX_llt.solve(G_nu);
  for (unsigned int j : joints) nu(6 + j) = 0.0;  // exactly
  if (options_.grounded) nu.head<6>().setZero();
  if (!nu.allFinite()) return E_NOT_FINITE;
  s.velocity.base_twist = toTwist(nu.head<6>());
  s.velocity.qdot.data = nu.tail(n);
  return E_NOERROR;
}

double Simulator::overshoot(const Vector& x) const {
  const detail::StateLayout L = layout();
  double worst = -std::numeric_limits<double>::infinity();
  for (int j = 0; j < L.n; ++j) {
    if (limit_modes_[j] != LimitMode::Stop || at_stop_[j] || controls_[j].mode == JointControl::Mode::Locked) continue;
    const JointProperties& p = model().jointProperties()[j];
    const double q = x(L.q + j);
    worst = std::max({worst, q - p.upper, p.lower - q});
  }
  return worst;
}

int Simulator::startRun(SimulationState& s) {
  const unsigned int n = model().nj();
  for (unsigned int j = 0; j < n; ++j)
    if (controls_[j].mode == JointControl::Mode::PD && controls_[j].hold) controls_[j].set_point = s.state.q(j);
  if (base_control_.attitude.hold) base_control_.attitude.set_point = s.state.world_T_base.M;
  if (base_control_.position.hold) base_control_.position.set_point = toEigen(s.state.world_T_base.p);
  std::fill(at_stop_.begin(), at_stop_.end(), false);
  applyLocks();
  if (distribution_.on)
    if (const int rc = distributionGains(s)) return rc;
  if (impedance_.on)
    if (const int rc = impedanceStart(s)) return rc;
  // The Coulomb regularisation of each joint, from its apparent inertia here.
  std::fill(friction_velocity_.begin(), friction_velocity_.end(), options_.friction_velocity);
  bool any_friction = false;
  for (const JointProperties& p : model().jointProperties()) any_friction = any_friction || p.friction > 0.0;
  if (options_.joint_friction && any_friction) {
    if (const int rc = forwardKinematics(*model_, s.state, kin_)) return rc;
    for (unsigned int j = 0; j < n; ++j) {
      const double f = model().jointProperties()[j].friction;
      double m = 0.0;
      if (f <= 0.0 || locked_now_[j]) continue;
      if (const int rc = apparentInertia(j, m)) return rc;
      friction_velocity_[j] = std::max(options_.friction_velocity, f / (m * options_.friction_rate));
    }
  }
  std::vector<unsigned int> stop;
  for (unsigned int j = 0; j < n; ++j) {
    if (limit_modes_[j] != LimitMode::Stop || controls_[j].mode == JointControl::Mode::Locked) continue;
    const JointProperties& p = model().jointProperties()[j];
    const double q = s.state.q(j), qdot = s.velocity.qdot(j);
    if (q > p.upper + kStopTolerance || q < p.lower - kStopTolerance) return E_BAD_ARGUMENT;
    if ((q >= p.upper - kStopTolerance && qdot > 0.0) || (q <= p.lower + kStopTolerance && qdot < 0.0)) stop.push_back(j);
  }
  if (stop.empty()) return E_NOERROR;
  double T_before, T_after;
  Vector6d h;
  if (const int rc = energyAndMomentum(s, T_before, h)) return rc;
  if (const int rc = stopJoints(s, stop)) return rc;
  if (const int rc = energyAndMomentum(s, T_after, h)) return rc;
  s.work.limits += T_after - T_before;
  for (unsigned int j : stop) {
    at_stop_[j] = true;
    ++stats_.joints[j].stops;
  }
  applyLocks();
  return E_NOERROR;
}

int Simulator::afterStep(double t_prev, double h, const Vector& x_prev, double& t, Vector& x) {
  const detail::StateLayout L = layout();
  const std::vector<JointProperties>& props = model().jointProperties();
  // Saturation over the step, as seen by its last evaluation (resolution: one step).
  for (int j = 0; j < L.n; ++j) {
    if (!saturated_[j]) continue;
    JointRecord& r = stats_.joints[j];
    if (std::isnan(r.saturation_first_time)) r.saturation_first_time = t_prev;
    r.saturation_time += t - t_prev;
  }
  if (base_saturated_) stats_.base_saturation_time += t - t_prev;
  if (wheel_saturated_) {
    if (std::isnan(stats_.wheel_saturation_first_time)) stats_.wheel_saturation_first_time = t_prev;
    stats_.wheel_saturation_time += t - t_prev;
  }

  // 1. A hard stop crossed: the instant located by the Illinois method on the step's length.
  std::fill(just_stopped_.begin(), just_stopped_.end(), false);
  if (overshoot(x) > 0.0) {
    double a = 0.0, b = 1.0, ga = overshoot(x_prev), gb = overshoot(x), theta = 0.0;
    x_event_ = x_prev;
    // A step from a limit (a joint just released): first a point inside, then the crossing after it.
    for (double probe = 0.5; ga >= 0.0 && probe > 1e-6; probe *= 0.5) {
      if (const int rc = retake(t_prev, probe * h, x_prev, x_event_)) return rc;
      const double g = overshoot(x_event_);
      if (g < 0.0) a = probe, ga = g;
      else b = probe, gb = g;
    }
    if (ga >= 0.0) x_event_ = x_prev;  // it leaves the limit at once: stopped where it is
    int side = 0;
    for (int iteration = 0; ga < 0.0 && iteration < 100; ++iteration) {
      theta = (a * gb - b * ga) / (gb - ga);
      if (const int rc = retake(t_prev, theta * h, x_prev, x_event_)) return rc;
      const double g = overshoot(x_event_);
      if (std::abs(g) <= kStopTolerance || b - a < 1e-15) break;
      if (g > 0.0) {
        b = theta, gb = g;
        if (side == 1) ga *= 0.5;
        side = 1;
      } else {
        a = theta, ga = g;
        if (side == -1) gb *= 0.5;
        side = -1;
      }
    }
    x = x_event_;
    x.segment<4>(3).normalize();
    t = t_prev + theta * h;
    if (const int rc = unpack(x, t, scratch_)) return rc;
    std::vector<unsigned int> stop;  // the joints at a limit and moving out of it
    for (int j = 0; j < L.n; ++j) {
      if (limit_modes_[j] != LimitMode::Stop || at_stop_[j] || controls_[j].mode == JointControl::Mode::Locked) continue;
      double& q = scratch_.state.q(j);
      const double qdot = scratch_.velocity.qdot(j);
      if (q >= props[j].upper - kStopTolerance && qdot >= 0.0) q = props[j].upper;
      else if (q <= props[j].lower + kStopTolerance && qdot <= 0.0) q = props[j].lower;
      else continue;
      stop.push_back(static_cast<unsigned int>(j));
    }
    double T_before, T_after;
    Vector6d h_O;
    if (const int rc = energyAndMomentum(scratch_, T_before, h_O)) return rc;
    if (const int rc = stopJoints(scratch_, stop)) return rc;
    if (const int rc = energyAndMomentum(scratch_, T_after, h_O)) return rc;
    x.segment(L.q, L.n) = scratch_.state.q.data;
    x.segment(L.qdot, L.n) = scratch_.velocity.qdot.data;
    x(L.work + 2) += T_after - T_before;  // EnergySplit::limits
    for (unsigned int j : stop) {
      at_stop_[j] = true;
      just_stopped_[j] = true;
      ++stats_.joints[j].stops;
    }
    applyLocks();
  }

  // 2. Joints at a stop are released when their free acceleration points away from the limit (not
  // in the step that stopped them: each stop holds for a step at least, so the run moves on).
  if (std::find(at_stop_.begin(), at_stop_.end(), true) != at_stop_.end()) {
    for (int j = 0; j < L.n; ++j) locked_now_[j] = controls_[j].mode == JointControl::Mode::Locked;
    dynamics_->setLocked(locked_now_);
    static const std::vector<KDL::Wrench> none;
    int rc = unpack(x, t, scratch_);
    if (!rc) rc = actuate(t, x);
    if (!rc)
      rc = dynamics_->CartToJnt(kin_, scratch_.velocity, scratch_.tau,
                                base_control_.on() || !wrenches_.empty() ? f_ext_ : none, acc_);
    if (rc) {
      applyLocks();
      return rc;
    }
    for (int j = 0; j < L.n; ++j) {
      if (!at_stop_[j] || just_stopped_[j]) continue;
      const bool at_upper = x(L.q + j) >= props[j].upper;
      if (at_upper ? acc_.qddot(j) < 0.0 : acc_.qddot(j) > 0.0) at_stop_[j] = false;
    }
    applyLocks();
  }

  // 3. Excursions past the limits (every joint not ignored).
  for (int j = 0; j < L.n; ++j) {
    if (limit_modes_[j] == LimitMode::Ignore) continue;
    const double q = x(L.q + j), over = std::max(q - props[j].upper, props[j].lower - q);
    if (!(over > 0.0)) continue;
    JointRecord& r = stats_.joints[j];
    if (std::isnan(r.limit_first_time)) r.limit_first_time = t;
    const double worst_over = std::isnan(r.limit_worst)
                                  ? -1.0
                                  : std::max(r.limit_worst - props[j].upper, props[j].lower - r.limit_worst);
    if (over > worst_over) r.limit_worst = q;
  }
  return E_NOERROR;
}

int Simulator::apparentInertia(unsigned int j, double& m) {
  static const std::vector<KDL::Wrench> none;
  const FloatingVelocity rest(*model_);  // set-up calls only: allocates
  KDL::JntArray unit(model().nj());
  FloatingAcceleration base_line{Vector6d::Zero(), KDL::JntArray(model().nj())}, acc = base_line;
  const auto solve = [&](FloatingAcceleration& a) { return dynamics_->CartToJnt(kin_, rest, unit, none, a); };
  if (const int rc = solve(base_line)) return rc;  // gravity alone: subtracted below
  unit(j) = 1.0;
  if (const int rc = solve(acc)) return rc;
  m = 1.0 / (acc.qddot(j) - base_line.qddot(j));
  return std::isfinite(m) && m > 0.0 ? E_NOERROR : E_NOT_POSITIVE_DEFINITE;
}

int Simulator::apparentInertia(const SimulationState& s, unsigned int j, double& m) {
  if (s.state.q.rows() != model().nj()) return E_SIZE_MISMATCH;
  if (j >= model().nj() || controls_[j].mode == JointControl::Mode::Locked) return E_BAD_ARGUMENT;
  applyLocks();
  if (const int rc = forwardKinematics(*model_, s.state, kin_)) return rc;
  return apparentInertia(j, m);
}

int Simulator::stiffness(const SimulationState& s, Stiffness& result) {
  const unsigned int n = model().nj();
  if (s.state.q.rows() != n) return E_SIZE_MISMATCH;
  if (const int rc = forwardKinematics(*model_, s.state, kin_)) return rc;
  Stiffness out;
  const std::vector<JointProperties>& props = model().jointProperties();
  for (unsigned int j = 0; j < n; ++j) {
    if (locked_now_[j]) continue;
    const JointControl& c = controls_[j];
    const bool rate_servo = distribution_.on && distribution_.joints[j];  // momentum_distribution's
    const double kp = c.mode == JointControl::Mode::PD && !rate_servo ? c.kp : 0.0;
    double kd = rate_servo ? distribution_gain_(j) : c.mode == JointControl::Mode::PD ? c.kd : 0.0;
    if (options_.joint_friction) kd += props[j].damping + props[j].friction / friction_velocity_[j];
    if (kp == 0.0 && kd == 0.0) continue;
    double m = 0.0;  // the joint's apparent inertia
    if (const int rc = apparentInertia(j, m)) return rc;
    const double disc = kd * kd - 4.0 * m * kp;  // roots of m s^2 + kd s + kp
    const double rate = disc >= 0.0 ? (kd + std::sqrt(disc)) / (2.0 * m) : std::sqrt(kp / m);
    if (rate > out.fastest_rate) {
      out.fastest_rate = rate;
      out.fastest_joint = static_cast<int>(j);
    }
  }
  if (out.fastest_rate > 0.0) out.explicit_step = 2.8 / out.fastest_rate;
  result = out;
  return E_NOERROR;
}

}  // namespace kdl_space
