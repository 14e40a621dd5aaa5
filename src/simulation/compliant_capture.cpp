#include "kdl_space/simulation/compliant_capture.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <string>

#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/spatial/errors.hpp"
#include "detail/text.hpp"

namespace kdl_space {
namespace {

/// The grasp joints' order is (x, y, z, rz, ry, rx); the law's axes are (x, y, z, about x, y, z).
constexpr int kAxisOf[6] = {0, 1, 2, 5, 4, 3};

void checkPositive(const Vector6d& v, const std::string& field, bool zero_ok) {
  for (int k = 0; k < 6; ++k)
    if (!std::isfinite(v(k)) || v(k) < 0.0 || (!zero_ok && v(k) == 0.0))
      throw InputError("law." + field + ": each of the six values must be finite and " +
                       (zero_ok ? ">= 0" : "> 0") + ", got " + detail::number(v(k)) + " (axis " +
                       std::to_string(k + 1) + ")");
}

void checkGrasp(const CompliantGrasp& g) {
  checkPositive(g.stiffness, "stiffness", false);
  if (g.damping) checkPositive(*g.damping, "damping", true);
  else if (!std::isfinite(g.damping_time) || g.damping_time < 0.0)
    throw InputError("law.damping_time: must be finite and >= 0 [s], got " + detail::number(g.damping_time));
  if (!std::isfinite(g.catch_tolerance) || g.catch_tolerance <= 0.0 || g.catch_tolerance >= 1.0)
    throw InputError("law.catch_tolerance: must lie in (0, 1), got " + detail::number(g.catch_tolerance));
  if (!std::isfinite(g.max_duration) || g.max_duration <= 0.0)
    throw InputError("law.max_duration: must be finite and > 0 [s], got " + detail::number(g.max_duration));
  if (g.normal && (!g.normal->allFinite() || g.normal->norm() == 0.0))
    throw InputError("law.normal: must be a finite non-zero vector");
}

/// Reads the joined state at the samples: the grasp's wrench, the sides' own momenta.
class Probe {
 public:
  Probe(const JoinedSystem& js, const FloatingSystem& robot, const FloatingSystem& target, const Vector6d& K,
        const Vector6d& D)
      : js_(js), robot_(robot), target_(target), K_(K), D_(D), kin_(*js.model), rkin_(*robot.model),
        tkin_(*target.model), rmom_(robot.model), tmom_(target.model) {
    const FloatingModel& m = *js.model;
    for (int k = 0; k < 6; ++k)
      for (std::size_t b = 0; b < m.bodies().size(); ++b)
        if (m.bodies()[b].joint == js.grasp_joints[k]) body_[k] = static_cast<int>(b);
    robot_contact_ = robot.contact;  // the robot's bodies keep their indices in the joined model
    target_base_ = m.bodyIndex(js.target_prefix + target.model->bodies()[0].name);
  }
  /// tau on the grasp joints (model order of the grasp: x, y, z, rz, ry, rx).
  double torque(int k, const SimulationState& s) const {
    const int j = js_.grasp_joints[k], a = kAxisOf[k];
    return -K_(a) * s.state.q(j) - D_(a) * s.velocity.qdot(j);
  }
  double relativeSpeed2(const SimulationState& s) const {
    double sum = 0.0;
    for (int k = 0; k < 6; ++k) sum += K_(kAxisOf[k]) * std::pow(s.velocity.qdot(js_.grasp_joints[k]), 2);
    return sum;
  }
  double springEnergy(const State& st) const {
    double V = 0.0;
    for (int k = 0; k < 6; ++k) V += 0.5 * K_(kAxisOf[k]) * std::pow(st.q(js_.grasp_joints[k]), 2);
    return V;
  }
  /// The sample: the wrench W on the target's side of the grasp solves S^T W = tau (the massless
  /// grasp links pass it on unchanged); the robot gets -W, moved to its contact point.
  ContactSample sample(const SimulationState& s, double t0) {
    ContactSample out;
    out.t = s.t - t0;
    if (forwardKinematics(*js_.model, s.state, kin_)) throw InputError("contact: the joined state cannot be computed");
    Matrix6d S;
    Vector6d tau;
    for (int k = 0; k < 6; ++k) {
      S.col(k) = kin_.S[body_[k]];
      tau(k) = torque(k, s);
      out.deflection(k) = s.state.q(js_.grasp_joints[k]);
    }
    const Vector6d W = S.transpose().fullPivLu().solve(tau);
    const Vector3d f = -W.head<3>();
    const Vector3d n_b = -W.tail<3>();  // about the base origin p_b
    const Vector3d p_c = kin_.point(robot_contact_);
    out.wrench << f, n_b - (p_c - kin_.p_b).cross(f);
    return out;
  }
  /// Splits the joined state into each side's own state and velocity, and their momenta.
  void split(const SimulationState& s, FloatingSystem& r_end, FloatingSystem& t_end, Vector6d& h_r, Vector6d& h_t) {
    const FloatingModel& rm = *robot_.model;
    const FloatingModel& tm = *target_.model;
    r_end = robot_;
    t_end = target_;
    State& rs = r_end.state;
    State& ts = t_end.state;
    FloatingVelocity& rv = r_end.velocity;
    FloatingVelocity& tv = t_end.velocity;
    rs.world_T_base = s.state.world_T_base;
    rv = FloatingVelocity(rm);
    rv.base_twist = s.velocity.base_twist;
    for (unsigned int j = 0; j < rm.nj(); ++j) {
      rs.q(j) = s.state.q(js_.robot_joints[j]);
      rv.qdot(j) = s.velocity.qdot(js_.robot_joints[j]);
    }
    if (forwardKinematics(*js_.model, s.state, kin_)) throw InputError("contact: the joined state cannot be computed");
    MomentumSolver jm(js_.model);
    if (jm.compute(kin_, s.velocity)) throw InputError("contact: the joined velocity cannot be computed");
    Vector6d base_twist;
    jm.contactTwist(Contact{target_base_, KDL::Vector::Zero()}, base_twist);
    ts.world_T_base = kin_.pose(target_base_);
    tv = FloatingVelocity(tm);
    tv.base_twist = KDL::Twist(KDL::Vector(base_twist(0), base_twist(1), base_twist(2)),
                               KDL::Vector(base_twist(3), base_twist(4), base_twist(5)));
    for (unsigned int j = 0; j < tm.nj(); ++j) {
      ts.q(j) = js_.target_joint_sign[j] * s.state.q(js_.target_joints[j]);
      tv.qdot(j) = js_.target_joint_sign[j] * s.velocity.qdot(js_.target_joints[j]);
    }
    if (forwardKinematics(rm, rs, rkin_) || rmom_.compute(rkin_, rv) || forwardKinematics(tm, ts, tkin_) ||
        tmom_.compute(tkin_, tv))
      throw InputError("contact: a side's state after the contact cannot be computed");
    h_r = rmom_.momentum();
    h_t = tmom_.momentum();
  }

 private:
  const JoinedSystem& js_;
  const FloatingSystem& robot_;
  const FloatingSystem& target_;
  Vector6d K_, D_;
  Kinematics kin_, rkin_, tkin_;
  MomentumSolver rmom_, tmom_;
  int body_[6] = {0, 0, 0, 0, 0, 0};
  Contact robot_contact_;
  int target_base_ = -1;
};

/// Braked joints of one side (its `locked`, or all with Response::JointsLocked).
bool braked(const FloatingSystem& side, unsigned int j) {
  return side.response == Response::JointsLocked || (j < side.locked.size() && side.locked[j]);
}

/// The impulse on the robot from its momentum h_before to h (the moment moved to p).
Vector6d impulseAbout(const Vector6d& h, const Vector6d& h_before, const Vector3d& p) {
  const Vector6d dh = h - h_before;
  return (Vector6d() << dh.head<3>(), dh.tail<3>() - p.cross(dh.head<3>())).finished();
}

CompliantCaptureResult solve(const FloatingSystem& robot, const FloatingSystem& target, const CompliantGrasp& grasp,
                             const CompliantRun& run) {
  const SimulationOptions& options = run.options;
  checkGrasp(grasp);
  if (robot.response == Response::Grounded || target.response == Response::Grounded)
    throw InputError("law.type: a compliant capture joins two free-floating systems (a grounded side is not supported)");
  CompliantCaptureResult res;
  res.joined = joinAtGrasp(robot, robot.velocity, target, target.velocity, GraspJoint::Compliant);
  JoinedSystem& js = res.joined;
  const Vector6d K = grasp.stiffness, D = grasp.dampingPerAxis();

  SimulationOptions opt = options;
  opt.grounded = false;
  opt.gravity = Vector3d::Zero();  // the contact's time scale: gravity changes nothing in it
  Simulator sim(js.model, opt);
  sim.setCancelPoll(run.cancelled);
  for (unsigned int j = 0; j < robot.model->nj(); ++j)
    if (braked(robot, j)) sim.setJointControl(js.robot_joints[j], {JointControl::Mode::Locked});
  for (unsigned int j = 0; j < target.model->nj(); ++j)
    if (braked(target, j)) sim.setJointControl(js.target_joints[j], {JointControl::Mode::Locked});
  Probe probe(js, robot, target, K, D);
  sim.setTorqueCallback([&](const SimulationState& s, KDL::JntArray& tau) {
    for (int k = 0; k < 6; ++k) tau(js.grasp_joints[k]) += probe.torque(k, s);
  });

  SimulationState s;
  s.state = js.state;
  s.velocity = js.velocity;
  if (const int rc = sim.energyAndMomentum(s, res.energy_before, res.momentum_before))
    throw InputError(std::string("contact: the joined system cannot be evaluated: ") + strError(rc));
  // The output step: a fortieth of the slowest time scale tau_a = min(sqrt(m/K), m/D) (its
  // period, or its rate's relaxation when overdamped; m the apparent inertia the grasp joint
  // meets) among the axes that carry at least 1e-3 of the relative motion (K qdot^2): they decide
  // when it is caught. (A light, heavily damped axis relaxes within the first samples; the
  // integrator's steps resolve it.) With D = beta K every tau_a is ~ 1/K, so the catch is located
  // to ~ 1/K as the stiffness grows.
  const double s0 = probe.relativeSpeed2(s);
  double scale = 0.0;
  for (int k = 0; k < 6; ++k) {
    double m = 0.0;
    if (const int rc = sim.apparentInertia(s, js.grasp_joints[k], m))
      throw InputError(std::string("contact: the grasp's inertia cannot be computed: ") + strError(rc));
    const int a = kAxisOf[k];
    double tau = std::sqrt(m / K(a));
    if (D(a) > 0.0) tau = std::min(tau, m / D(a));
    if (K(a) * std::pow(s.velocity.qdot(js.grasp_joints[k]), 2) >= 1e-3 * s0) scale = std::max(scale, tau);
  }
  if (scale == 0.0) scale = grasp.max_duration;
  scale = std::min(scale, grasp.max_duration);
  const double dt = scale / 40.0;

  const double tol2 = grasp.catch_tolerance * grasp.catch_tolerance * s0;
  SimulationState prev = s;
  double prev_speed2 = s0;
  bool at_min = false;
  ContactEnd end = ContactEnd::TimedOut;
  // The robot's momentum and contact point before the contact: the impulse so far is its change.
  Kinematics rkin(*robot.model);
  MomentumSolver rmom(robot.model);
  if (forwardKinematics(*robot.model, robot.state, rkin) || rmom.compute(rkin, robot.velocity))
    throw InputError("robot: the state before the contact cannot be computed");
  const Vector6d h_robot_before = rmom.momentum();
  const Vector3d p = rkin.point(robot.contact);
  FloatingSystem r_now, t_now;
  const auto observe = [&](const SimulationState& x) {
    ContactSample c = probe.sample(x, 0.0);
    Vector6d h_r, h_t;
    probe.split(x, r_now, t_now, h_r, h_t);
    c.impulse = impulseAbout(h_r, h_robot_before, p);
    res.history.push_back(c);
    if (run.observer) run.observer(sim, x, c);
  };
  sim.setStopCondition([&](const SimulationState& x) {
    const double v2 = probe.relativeSpeed2(x);
    if (s0 == 0.0 || v2 <= tol2) {
      end = ContactEnd::Caught;
      return true;
    }
    // The first minimum below half the speed; a contact with a normal waits for the tolerance.
    if (!grasp.normal && v2 > prev_speed2 && prev_speed2 < 0.25 * s0) {
      end = ContactEnd::Caught;
      at_min = true;
      return true;
    }
    if (grasp.normal && x.t > 0.0 && grasp.normal->normalized().dot(res.history.back().wrench.head<3>()) > 0.0) {
      end = ContactEnd::Opened;
      return true;
    }
    prev = x;
    prev_speed2 = v2;
    return false;
  });
  if (const int rc = sim.run(s, grasp.max_duration, dt, observe))
    throw InputError(std::string("contact: the integration failed at t = ") + detail::number(s.t) + " s: " +
                     strError(rc));
  res.steps = sim.stats().accepted_steps;
  if (at_min) {  // the minimum was the sample before: the contact ends there
    s = prev;
    res.history.pop_back();
  }
  res.end = end;
  res.duration = s.t;
  for (const ContactSample& c : res.history) {
    if (c.wrench.head<3>().norm() > res.peak_force) {
      res.peak_force = c.wrench.head<3>().norm();
      res.peak_force_wrench = c.wrench;
    }
    res.peak_moment = std::max(res.peak_moment, c.wrench.tail<3>().norm());
  }
  // Energy: the callback's work is -(spring energy now) - (the dampers' work).
  Vector6d h;
  double T_end = 0.0;
  if (const int rc = sim.energyAndMomentum(s, T_end, h))
    throw InputError(std::string("contact: the end state cannot be evaluated: ") + strError(rc));
  res.spring_energy = probe.springEnergy(s.state);
  res.dissipated = -s.work.controller - res.spring_energy;
  std::optional<Vector6d> lock_from;  // the robot's momentum before the lock
  if (end == ContactEnd::Caught) {
    Vector6d h_r, h_t;
    probe.split(s, r_now, t_now, h_r, h_t);
    lock_from = h_r;
    for (int k = 0; k < 6; ++k) sim.setJointControl(js.grasp_joints[k], {JointControl::Mode::Locked});
    if (const int rc = sim.engageBrakes(s))
      throw InputError(std::string("contact: the grasp cannot be locked: ") + strError(rc));
  }
  if (const int rc = sim.energyAndMomentum(s, res.energy_after, res.momentum_after))
    throw InputError(std::string("contact: the end state cannot be evaluated: ") + strError(rc));
  res.lock_loss = T_end - res.energy_after;
  js.state = s.state;
  js.velocity = s.velocity;
  probe.split(s, res.robot_end, res.target_end, res.robot_momentum_after, res.target_momentum_after);
  res.robot_after = res.robot_end.velocity;
  res.target_after = res.target_end.velocity;
  // The impulse on the robot: its momentum's change, the moment moved to its contact point at
  // the start.
  res.impulse = impulseAbout(res.robot_momentum_after, h_robot_before, p);
  if (lock_from) res.lock_impulse = impulseAbout(res.robot_momentum_after, *lock_from, p);
  return res;
}

}  // namespace

CompliantCaptureResult solveCompliantCapture(const FloatingSystem& robot, const FloatingSystem& target,
                                             const CompliantGrasp& grasp, const SimulationOptions& options) {
  CompliantRun run;
  run.options = options;
  return solve(robot, target, grasp, run);
}

CompliantCaptureResult solveCompliantCapture(const CaptureProblem& problem, const CompliantGrasp& grasp,
                                             const CompliantRun& run) {
  const auto* target = std::get_if<FloatingSystem>(&problem.target);
  if (!target) throw InputError("target: a compliant capture of a rigid target is not supported yet");
  return solve(problem.robot, *target, grasp, run);
}

}  // namespace kdl_space
