#include "kdl_space/simulation/compliant_capture.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/impact/rigid_body_system.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/spatial/errors.hpp"
#include "spatial/message_text.hpp"
#include "simulation/compliant_probe.hpp"

namespace kdl_space {
namespace {

using detail::kAxisOf;
using detail::Probe;
constexpr double kInfinite = std::numeric_limits<double>::infinity();

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

/// Braked joints of one side (its `locked`, or all with Response::JointsLocked).
bool braked(const FloatingSystem& side, unsigned int j) {
  return side.response == Response::JointsLocked || (j < side.locked.size() && side.locked[j]);
}

/// The impulse on the robot from its momentum h_before to h (the moment moved to p).
Vector6d impulseAbout(const Vector6d& h, const Vector6d& h_before, const Vector3d& p) {
  const Vector6d dh = h - h_before;
  return (Vector6d() << dh.head<3>(), dh.tail<3>() - p.cross(dh.head<3>())).finished();
}

/// What the end criteria are measured against: the relative speed^2 at the touch, and a force.
struct EndScales {
  double speed2 = 0.0;  ///< s0 = qdot^T K qdot at the touch
  double force = 1.0;   ///< [N]: the spring's force after the slowest time scale at the touch's speed
};

/// The contact's end criteria at a state, each > 0 while the contact goes on and crossing to <= 0
/// where it ends; +inf where inactive. All are functions of the state alone (no accelerations),
/// as the stop event needs, and normalised (dimensionless, ~1 at the touch).
struct EndCriteria {
  double speed = kInfinite;    ///< the relative speed over its start, minus catch_tolerance
  double closing = kInfinite;  ///< without a normal: dV/dt of the springs, scaled (the hand closes while > 0)
  double opening = kInfinite;  ///< with a normal: -n^T f, f the force on the robot (it pushes while > 0)
  double least() const { return std::min(speed, std::min(closing, opening)); }
};

EndCriteria endCriteria(Probe& probe, const CompliantGrasp& grasp, const EndScales& at, const SimulationState& x) {
  EndCriteria c;
  if (at.speed2 == 0.0) {  // no relative motion at the touch: caught there
    c.speed = -1.0;
    return c;
  }
  // (a) caught: sqrt(qdot^T K qdot) <= catch_tolerance * its start.
  c.speed = std::sqrt(probe.relativeSpeed2(x) / at.speed2) - grasp.catch_tolerance;
  if (!grasp.normal && grasp.lock != GraspLock::SpringMaximum) {
    // Only the tolerance ends it (GraspLock::Tolerance, Never).
  } else if (!grasp.normal) {
    // (b) caught: the first maximum of the springs' energy V = 1/2 q^T K q, where dV/dt = q^T K qdot
    // falls to 0: the hand has stopped closing (the relative motion's first rest in the springs'
    // metric). Scaled by sqrt(2 V s0) (Cauchy-Schwarz: within the relative speed's ratio): it tends
    // to 1 at the touch, where V = 0 and dV/dt = 0 (the spring not yet loaded: positive).
    const double V = probe.springEnergy(x.state);
    c.closing = V > 0.0 ? probe.springPower(x) / std::sqrt(2.0 * V * at.speed2) : 1.0;
  } else if (x.t > 0.0) {
    // (c) opened: the force on the robot would pull it toward the target, n^T f >= 0. (At the
    // touch with no damping f = 0: positive there; it pushes once the spring is loaded.)
    c.opening = -grasp.normal->normalized().dot(probe.sample(x, 0.0).wrench.head<3>()) / at.force;
  } else {
    c.opening = 1.0;
  }
  return c;
}

/// The contact's slowest time scale (the output step is a fortieth of it): tau_a = min(sqrt(m/K), m/D) (its
/// period, or its rate's relaxation when overdamped; m the apparent inertia the grasp joint
/// meets) among the axes that carry at least 1e-3 of the relative motion (K qdot^2): they decide
/// when it is caught. (A light, heavily damped axis relaxes within the first samples; the
/// integrator's steps resolve it.) The samples are the force history's; the end of the contact
/// is located between them.
double contactTimeScale(Simulator& sim, const SimulationState& s, const JoinedSystem& js, const Vector6d& K,
                        const Vector6d& D, double s0, double max_duration) {
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
  if (scale == 0.0) scale = max_duration;
  return std::min(scale, max_duration);
}

/// The history's peak force (and its wrench) and peak moment.
void setPeaks(CompliantCaptureResult& res) {
  for (const ContactSample& c : res.history) {
    if (c.wrench.head<3>().norm() > res.peak_force) {
      res.peak_force = c.wrench.head<3>().norm();
      res.peak_force_wrench = c.wrench;
    }
    res.peak_moment = std::max(res.peak_moment, c.wrench.tail<3>().norm());
  }
}

CompliantCaptureResult solve(const FloatingSystem& robot, const FloatingSystem& target, const CompliantGrasp& grasp,
                             const CompliantRun& run) {
  const SimulationOptions& options = run.options;
  checkGrasp(grasp);
  if (robot.response == Response::Grounded || target.response == Response::Grounded)
    throw InputError("law.type: a compliant capture joins two free-floating systems (a grounded side is not supported)");
  CompliantCaptureResult res;
  res.lock = grasp.lock;
  res.joined = joinAtGrasp(robot, robot.velocity, target, target.velocity, GraspJoint::Compliant);
  JoinedSystem& js = res.joined;
  const Vector6d K = grasp.stiffness, D = grasp.dampingPerAxis();

  SimulationOptions opt = options;
  opt.grounded = false;
  opt.gravity = Vector3d::Zero();  // the contact's time scale: gravity changes nothing in it
  if (opt.integrator == Integrator::RK4) opt.integrator = Integrator::DormandPrince54;  // its step adapts to the contact
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
  const double s0 = probe.relativeSpeed2(s);
  const double scale = contactTimeScale(sim, s, js, K, D, s0, grasp.max_duration);
  const double dt = scale / 40.0;
  // (The steps end at the outputs: the end criteria, sampled at the steps' ends, are seen at least
  // this often.)

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
  // The end of the contact, located between the steps (the simulator's stop event, to 1e-10 s):
  // the first zero of the least of the active criteria (endCriteria).
  const EndScales scales{s0, std::sqrt(K.maxCoeff() * s0) * scale};
  sim.setStopEvent([&](const SimulationState& x) { return endCriteria(probe, grasp, scales, x).least(); });
  if (const int rc = sim.run(s, grasp.max_duration, dt, observe))
    throw InputError(std::string("contact: the integration failed at t = ") + detail::number(s.t) + " s: " +
                     strError(rc));
  res.steps = sim.stats().accepted_steps;
  ContactEnd end = ContactEnd::TimedOut;
  if (std::isfinite(sim.stats().event_time)) {  // which criterion ended it: the least at the end
    const EndCriteria c = endCriteria(probe, grasp, scales, s);
    if (c.opening <= std::min(c.speed, c.closing)) {
      end = ContactEnd::Opened;
    } else if (grasp.lock == GraspLock::Never) {
      end = ContactEnd::Settled;
    } else {
      end = ContactEnd::Caught;
      res.catch_rule = c.speed <= c.closing ? CatchRule::Tolerance : CatchRule::SpringMaximum;
    }
  }
  res.end = end;
  res.duration = s.t;
  setPeaks(res);
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
  const auto share = [](double part, double whole) { return whole > 0.0 ? part / whole : 0.0; };
  res.lock_share.linear_impulse = share(res.lock_impulse.head<3>().norm(), res.impulse.head<3>().norm());
  res.lock_share.angular_impulse = share(res.lock_impulse.tail<3>().norm(), res.impulse.tail<3>().norm());
  res.lock_share.energy = lock_from ? share(res.lock_loss, res.energy_before - res.energy_after) : 0.0;
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
  if (const auto* target = std::get_if<FloatingSystem>(&problem.target)) return solve(problem.robot, *target, grasp, run);
  // A rigid target: one free body touched where the robot's contact point is.
  const FloatingSystem& robot = problem.robot;
  Kinematics kin(*robot.model);
  if (forwardKinematics(*robot.model, robot.state, kin))
    throw InputError("robot: the state before the contact cannot be computed");
  const RigidTarget& rigid = std::get<RigidTarget>(problem.target);
  return solve(robot, rigidBodySystem(rigid, kin.point(robot.contact), rigid.twist), grasp, run);
}

}  // namespace kdl_space
