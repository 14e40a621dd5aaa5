#include "kdl_space/simulation/approach.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <string>

#include "simulation/box_qp.hpp"
#include "simulation/pre_grasp.hpp"

namespace kdl_space {

namespace {
[[noreturn]] void refuse(const std::string& what) { throw ModelError("ApproachController: " + what); }

void positive(double x, const char* what) {
  if (!(x > 0.0) || !std::isfinite(x)) refuse(std::string(what) + " must be finite and > 0");
}

/// The robot's joint rates could not be commanded at a stage: run() stops with this code.
struct CommandFailed {
  int rc;
};
}  // namespace

std::vector<double> defaultRateLimits(const FloatingModel& model) {
  std::vector<double> limits(model.nj(), std::numeric_limits<double>::infinity());
  for (unsigned int j = 0; j < model.nj(); ++j) {
    const double v = model.jointProperties()[j].velocity;
    if (std::isfinite(v) && v > 0.0) limits[j] = v;
  }
  return limits;
}

ApproachController::ApproachController(std::shared_ptr<const FloatingModel> model, const Contact& hand,
                                       ApproachSpec spec, FreeRigidMotion target)
    : ApproachController(std::move(model), hand, std::move(spec),
                         std::make_shared<RigidApproachTarget>(std::move(target))) {}

ApproachController::ApproachController(std::shared_ptr<const FloatingModel> model, const Contact& hand,
                                       ApproachSpec spec, std::shared_ptr<ApproachTarget> target)
    : model_(std::move(model)), hand_(hand), spec_(std::move(spec)), target_(std::move(target)),
      solver_(model_ ? model_ : throw ModelError("ApproachController: null model"), FreeFloatingSolver::Extent::Jacobians) {
  if (!target_) refuse("null target");
  const unsigned int n = model_->nj();
  if (hand_.body < 0 || hand_.body >= static_cast<int>(model_->bodies().size())) refuse("the hand is no body of the model");
  if (!allFinite(hand_.offset) || !allFinite(spec_.grasp)) refuse("the hand offset and the grasp frame must be finite");
  positive(spec_.gain, "the gain");
  positive(spec_.threshold, "the singular value threshold");
  positive(spec_.servo_bandwidth, "the servo bandwidth");
  positive(spec_.position_tolerance, "the position tolerance");
  positive(spec_.orientation_tolerance, "the orientation tolerance");
  positive(spec_.max_duration, "the longest approach");
  positive(spec_.limit_gain, "the limit gain");
  if (!(spec_.limit_zone >= 0.0 && spec_.limit_zone < 0.5)) refuse("the limit zone must lie in [0, 0.5)");
  if (spec_.pre_grasp) {
    if (!(spec_.pre_grasp->standoff >= 0.0) || !std::isfinite(spec_.pre_grasp->standoff))
      refuse("the pre-grasp standoff must be finite and >= 0");
    if (!(spec_.pre_grasp->rate > 0.0 && spec_.pre_grasp->rate <= 1.0)) refuse("the pre-grasp rate must lie in (0, 1]");
    positive(spec_.pre_grasp->acceleration, "the pre-grasp acceleration");
  }
  if (!(spec_.damping >= 0.0) || !std::isfinite(spec_.damping)) refuse("the damping must be finite and >= 0");
  if (!(spec_.speed_tolerance > 0.0)) refuse("the speed tolerance must be > 0");
  if (spec_.rate_limits.empty()) spec_.rate_limits = defaultRateLimits(*model_);
  if (spec_.rate_limits.size() != n) refuse(std::to_string(spec_.rate_limits.size()) + " rate limits for " + std::to_string(n) + " joints");
  for (double v : spec_.rate_limits)
    if (!(v > 0.0)) refuse("a rate limit must be > 0");
  J_ = KDL::Jacobian(n);
  J_base_ = KDL::Jacobian(n);
}

int ApproachController::grasp(double t, KDL::Frame& frame, Vector6d& twist) {
  return target_->grasp(t, spec_.grasp, frame, twist);
}

int ApproachController::target(double t, RigidTarget& out) {
  auto* rigid = dynamic_cast<RigidApproachTarget*>(target_.get());
  return rigid ? rigid->at(t, out) : E_BAD_ARGUMENT;
}

const char* toString(ApproachBase base) {
  switch (base) {
    case ApproachBase::Held: return "grounded (J)";
    case ApproachBase::AttitudeHeld: return "attitude held (J - [A_mP / w; 0])";
    default: return "generalized (J*)";
  }
}

void ApproachController::limitJoints(const KDL::JntArray& q, const Eigen::MatrixXd& A, double l2, Eigen::VectorXd& qdot,
                                     std::vector<int>& clamped_out) const {
  const unsigned int n = model_->nj();
  clamped_out.clear();
  const auto limited = [&](unsigned int j) {
    const JointProperties& p = model_->jointProperties()[j];
    return std::isfinite(p.lower) && std::isfinite(p.upper);
  };
  // The push away from a limit, inside its zone: the gradient of sum ((q - mid) / half range)^2
  // in effect, as large as limit_gain x the depth into the zone (at most half the rate limit).
  Eigen::VectorXd z = Eigen::VectorXd::Zero(n);
  for (unsigned int j = 0; j < n; ++j) {
    if (!limited(j)) continue;
    const JointProperties& p = model_->jointProperties()[j];
    const double zone = spec_.limit_zone * (p.upper - p.lower), cap = 0.5 * spec_.rate_limits[j];
    if (p.upper - q(j) < zone) z(j) = -std::min(spec_.limit_gain * (zone - (p.upper - q(j))), cap);
    else if (q(j) - p.lower < zone) z(j) = std::min(spec_.limit_gain * (zone - (q(j) - p.lower)), cap);
  }
  if (!z.isZero(0.0)) {  // N z, N = E - J+ J of the damped least squares
    const Eigen::MatrixXd AAt = A * A.transpose();
    const Eigen::LDLT<Eigen::MatrixXd> damped(AAt + (l2 + 1e-300) * Eigen::MatrixXd::Identity(A.rows(), A.rows()));
    qdot += z - A.transpose() * damped.solve(A * z);
  }
  // The guard: a joint's rate toward its limit at most limit_gain x its distance from a guard,
  // which stands the servo's lag at the full rate (rate / bandwidth) twice inside the limit (the
  // joint follows its command that far behind, so it stops at the limit, not past it).
  Eigen::VectorXd lo = Eigen::VectorXd::Constant(n, -std::numeric_limits<double>::infinity());
  Eigen::VectorXd hi = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  bool inside = true;
  for (unsigned int j = 0; j < n; ++j) {
    if (!limited(j)) continue;
    const JointProperties& p = model_->jointProperties()[j];
    const double lag = std::min(2.0 * spec_.rate_limits[j] / spec_.servo_bandwidth, 0.25 * (p.upper - p.lower));
    hi(j) = spec_.limit_gain * (p.upper - lag - q(j));
    lo(j) = -spec_.limit_gain * (q(j) - p.lower - lag);
    inside = inside && qdot(j) <= hi(j) && qdot(j) >= lo(j);
  }
  if (inside) return;
  // The rates nearest the task's inside the box: a change of the hand's twist costs A^T A, a
  // joint's own change mu (the damping, at least 1e-6 of |A|^2): the null space fixes what it can,
  // the hand gives up the least of its twist for the rest. Unique and continuous in the state
  // (the clamp-and-re-solve this replaced jumped between sets of clamped joints, and the servos
  // chattered: 1.9 x a wrist's rate limit).
  Eigen::MatrixXd H = A.transpose() * A;
  H.diagonal().array() += std::max(l2, 1e-6 * A.squaredNorm());
  std::vector<int> at;
  qdot = detail::nearestInBox(H, qdot, lo, hi, at);
  for (unsigned int j = 0; j < n; ++j)
    if (at[j]) clamped_out.push_back(static_cast<int>(j));
}

int ApproachController::command(const SimulationState& s, ApproachCommand& out) {
  const unsigned int n = model_->nj();
  if (s.velocity.qdot.rows() != n) return E_SIZE_MISMATCH;
  if (const int rc = solver_.compute(s.state)) return rc;
  Vector6d PL_g;
  if (const int rc = solver_.momentum(s.velocity.base_twist, s.velocity.qdot, PL_g)) return rc;
  const KDL::JntArray still(n);
  KDL::Twist drift, t_h;
  if (base_ == ApproachBase::Held) {  // the base held: t_h = J qdot
    if (const int rc = solver_.J(hand_, J_)) return rc;
    t_h = toTwist(J_.data * s.velocity.qdot.data);
  } else if (base_ == ApproachBase::AttitudeHeld) {
    // w_b = 0, the linear momentum P = w v_b + A_mP qdot: v_b = (P - A_mP qdot) / w, so
    // t_h = (J - [A_mP / w; 0]) qdot + (P / w; 0).
    if (const int rc = solver_.J(hand_, J_)) return rc;
    J_.data.topRows(3) -= solver_.A_m().topRows(3) / solver_.w();
    Vector6d d = Vector6d::Zero();
    d.head<3>() = PL_g.head<3>() / solver_.w();
    drift = toTwist(d);
    t_h = toTwist(J_.data * s.velocity.qdot.data + d);
  } else {
    if (const int rc = solver_.J_star(hand_, J_)) return rc;
    if (const int rc = solver_.handTwist(hand_, still, PL_g, drift)) return rc;  // eq. 4, qdot = 0
    if (const int rc = solver_.handTwist(hand_, s.velocity.qdot, PL_g, t_h)) return rc;
  }
  KDL::Frame G;
  Vector6d grasp_twist;
  if (const int rc = grasp(s.t, G, grasp_twist)) return rc;
  const KDL::Frame& link = solver_.bodyPose(hand_.body);
  const KDL::Vector p_hand = link * hand_.offset;
  Vector6d e;
  e << toEigen(G.p - p_hand), toEigen((G.M * link.M.Inverse()).GetRot());
  const Vector6d reference = grasp_twist + spec_.gain * e;
  const int m = spec_.orientation ? 6 : 3;
  const Eigen::MatrixXd A = J_.data.topRows(m);
  const Eigen::VectorXd b = (reference - toEigen(drift)).head(m);
  // Damped least squares (Nakamura; Maciejewski): the damping grows as J* nears a singularity.
  const Eigen::MatrixXd AAt = A * A.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(AAt, Eigen::EigenvaluesOnly);
  const double sigma = std::sqrt(std::max(eig.eigenvalues()(0), 0.0));
  const double ratio = sigma / spec_.threshold;
  const double l2 = ratio < 1.0 ? spec_.damping * spec_.damping * (1.0 - ratio * ratio) : 0.0;
  const Eigen::LDLT<Eigen::MatrixXd> damped(AAt + l2 * Eigen::MatrixXd::Identity(m, m));  // J J^T + l^2 E
  Eigen::VectorXd qdot = A.transpose() * damped.solve(b);
  if (spec_.null_space == NullSpaceTask::Reaction && base_ == ApproachBase::Free && static_cast<int>(n) > m) {
    // Of qdot + N z (N = E - J+ J*: rates that leave the hand's twist alone), the one whose base
    // angular velocity w_b = A_w qdot + c (the base's J* and drift) is least.
    if (const int rc = solver_.J_star(Contact{0, KDL::Vector::Zero()}, J_base_)) return rc;
    KDL::Twist base_drift;
    if (const int rc = solver_.handTwist(Contact{0, KDL::Vector::Zero()}, still, PL_g, base_drift)) return rc;
    const Eigen::MatrixXd N = Eigen::MatrixXd::Identity(n, n) - A.transpose() * damped.solve(A);  // E - J+ J
    const Eigen::MatrixXd B = J_base_.data.bottomRows(3) * N;
    const Vector3d w_b = J_base_.data.bottomRows(3) * qdot + toEigen(base_drift).tail<3>();
    // Damped (mu = 1% of |A_w|^2): where the null space hardly turns the base, it is not driven hard.
    const Matrix3d BBt = B * B.transpose();
    const double mu = 1e-2 * J_base_.data.bottomRows(3).squaredNorm() + 1e-300;
    const Eigen::VectorXd z = -B.transpose() * (BBt + mu * Matrix3d::Identity()).ldlt().solve(w_b);
    qdot += N * z;
  }
  limitJoints(s.state.q, A, l2, qdot, out.clamped);
  double scale = 1.0;
  for (unsigned int j = 0; j < n; ++j)
    if (std::abs(qdot(j)) * scale > spec_.rate_limits[j]) scale = spec_.rate_limits[j] / std::abs(qdot(j));
  qdot *= scale * (fade_ > 0.0 ? std::clamp((s.t - fade_t0_) / fade_, 0.0, 1.0) : 1.0);
  if (!qdot.allFinite()) return E_NOT_FINITE;
  if (out.qdot.rows() != n) out.qdot = KDL::JntArray(n);
  out.qdot.data = qdot;
  out.error = e;
  out.reference = reference;
  out.drift = toEigen(drift);
  out.sigma_min = sigma;
  out.damping = std::sqrt(l2);
  out.scale = scale;
  out.relative_speed = (toEigen(t_h).head<3>() - grasp_twist.head<3>()).norm();
  return E_NOERROR;
}

namespace {
/// The contact condition as one number: the largest of the margins of the rows in use, each
/// normalised by its tolerance (distance / tol - 1; the angle's when the orientation is tracked;
/// the relative speed's when its tolerance is finite). <= 0 exactly when all hold; continuous in
/// the state, so its first crossing of 0 is the first instant the condition holds.
double contactMargin(const ApproachSpec& spec, const ApproachCommand& c) {
  double g = c.error.head<3>().norm() / spec.position_tolerance - 1.0;
  if (spec.orientation) g = std::max(g, c.error.tail<3>().norm() / spec.orientation_tolerance - 1.0);
  if (std::isfinite(spec.speed_tolerance)) g = std::max(g, c.relative_speed / spec.speed_tolerance - 1.0);
  return g;
}
}  // namespace

namespace {

/// One run of the simulator with the approach's callbacks, cleared after it (also on a throw);
/// a command that failed inside is its code.
template <typename Run>
int guarded(Simulator& sim, Run run) {
  int rc = E_NOERROR;
  try {
    rc = run();
  } catch (const CommandFailed& f) {
    rc = f.rc;
  } catch (...) {
    sim.setTorqueCallback({});
    sim.setStopCondition({});
    sim.setStopEvent({});
    throw;
  }
  sim.setTorqueCallback({});
  sim.setStopEvent({});
  return rc;
}

}  // namespace

int runApproach(Simulator& sim, ApproachController& controller, SimulationState& s, double output_dt,
                const std::function<void(const SimulationState&, const ApproachCommand&)>& observer,
                ApproachRecord& record) {
  const FloatingModel& model = sim.model();
  const unsigned int n = model.nj();
  const ApproachSpec& spec = controller.spec();
  ApproachRecord rec;
  rec.kv.assign(n, 0.0);
  for (unsigned int j = 0; j < n; ++j) {
    if (sim.jointControls()[j].mode == JointControl::Mode::Locked) continue;  // braked: not servoed
    double m = 0.0;
    if (const int rc = sim.apparentInertia(s, j, m)) return rc;
    rec.kv[j] = spec.servo_bandwidth * m;
  }
  // The Jacobian that matches what holds the base (its control acts in the approach if it is on).
  const BaseControl& held = sim.baseControl();
  rec.base = sim.options().grounded ? ApproachBase::Held
             : held.attitude.on     ? (held.position.on ? ApproachBase::Held : ApproachBase::AttitudeHeld)
                                    : ApproachBase::Free;
  controller.setBase(rec.base);
  rec.time_at_limit.assign(n, 0.0);
  rec.output_step = output_dt;
  const KDL::Rotation base_start = s.state.world_T_base.M;
  ApproachCommand stage, sample, probe;
  int failure = E_NOERROR;
  double last_seen = -std::numeric_limits<double>::infinity();
  bool in_control = false;
  const auto watch = [&](const SimulationState& x) {
    if (x.t == last_seen) return;  // the pre-grasp move's end is the control's start
    last_seen = x.t;
    if ((failure = controller.command(x, sample))) return;  // stops the run: returned below
    const double distance = sample.error.head<3>().norm(), angle = sample.error.tail<3>().norm();
    if (distance < rec.closest_distance) {
      rec.closest_distance = distance;
      rec.closest_time = x.t;
    }
    rec.final_distance = distance;
    rec.final_angle = angle;
    rec.min_sigma = std::min(rec.min_sigma, sample.sigma_min);
    rec.max_damping = std::max(rec.max_damping, sample.damping);
    rec.min_scale = std::min(rec.min_scale, sample.scale);
    if (in_control) {  // the resolved-rate control's own samples (not the pre-grasp move's)
      for (const int j : sample.clamped) rec.time_at_limit[static_cast<std::size_t>(j)] += output_dt;
      if (sample.scale < 0.99) rec.time_rate_limited += output_dt;
      if (sample.sigma_min < spec.threshold) rec.time_near_singular += output_dt;
    }
    if (observer) observer(x, sample);
  };
  sim.setStopCondition([&](const SimulationState&) { return failure != E_NOERROR; });
  const double t0 = s.t;
  int rc = E_NOERROR;
  if (spec.pre_grasp) rc = guarded(sim, [&] { return approach_phases::preGrasp(sim, controller, s, output_dt, rec, watch); });
  if (rc == E_NOERROR && rec.cause.empty()) {
    in_control = true;
    if (spec.pre_grasp) controller.setFadeIn(s.t, 2.0);  // from rest at the pre-grasp pose
    sim.setTorqueCallback([&](const SimulationState& x, KDL::JntArray& tau) {
      if (const int crc = controller.command(x, stage)) throw CommandFailed{crc};
      for (unsigned int j = 0; j < n; ++j) tau(j) += rec.kv[j] * (stage.qdot(j) - x.velocity.qdot(j));
    });
    // The contact instant located between the steps (the simulator's stop event): the run ends
    // there and its last output, the capture's state, is that instant.
    sim.setStopEvent([&](const SimulationState& x) {
      if (const int erc = controller.command(x, probe)) throw CommandFailed{erc};
      return contactMargin(spec, probe);
    });
    rc = guarded(sim, [&] { return sim.run(s, std::max(t0 + spec.max_duration, s.t), output_dt, watch); });
  }
  sim.setStopCondition({});
  if (rc == E_NOERROR) rc = failure;
  rec.reached = rc == E_NOERROR && rec.cause.empty() && std::isfinite(sim.stats().event_time);
  if (rec.reached) rec.t_contact = s.t;
  rec.duration = s.t - t0;
  rec.base_rotation = (s.state.world_T_base.M * base_start.Inverse()).GetRot().Norm();
  if (!rec.reached && rc == E_NOERROR && rec.cause.empty())
    rec.cause = approach_phases::approachCause(rec, controller, model, s);
  record = rec;
  return rc;
}

}  // namespace kdl_space
