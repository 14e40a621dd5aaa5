// The end of a compliant contact (solveCompliantCapture, simulation/compliant_capture.hpp) located
// between the integrator's steps, against closed forms. Two free bodies whose centres of mass sit
// at the grasp point (so no force of the grasp has a moment about either: the six grasp axes
// decouple, the rotations stay 0; the robot's inertia is made large enough that the moment of the
// deflected grasp cannot turn it): each translational axis is a damped oscillator in the relative
// displacement x,
//   mu x'' + D x' + K x = 0,   x(0) = 0,   x'(0) = v0,   mu = m_r m_t / (m_r + m_t),
// with (underdamped, omega_n = sqrt(K / mu), zeta = D / (2 sqrt(K mu)) < 1, sigma = zeta omega_n,
// omega_d = omega_n sqrt(1 - zeta^2))
//   x(t)  = v0 / omega_d e^(-sigma t) sin(omega_d t),
//   x'(t) = v0 e^(-sigma t) (cos(omega_d t) - sigma / omega_d sin(omega_d t)).
// x' first vanishes (the compression's maximum) at t* = atan(omega_d / sigma) / omega_d.
//   1. one axis: the catch at relative speed = catch_tolerance times its start: the root of
//      x'(t) = tol v0 on (0, t*) (bisection of the closed form), and with a vanishing tolerance t*
//      itself; both within 1e-9 s (the simulator's bracket is 1e-10 s; the integration's error at
//      rtol 1e-12 moves the instant by ~1e-12 of the contact's time scale);
//   2. two axes at different frequencies: the catch at the first maximum of the springs' energy
//      V = 1/2 (K_x x^2 + K_y y^2), the first root of dV/dt = K_x x x' + K_y y y' (bisection), to
//      1e-9 s, while the relative speed is still far above the tolerance.
// The old rule ended the contact at an output sample: each test checks the true instant lies more
// than 1e-7 s from every output sample (the only instants the old rule could end on), so the old
// rule would miss it by a hundred times the tolerance at least; the margins are printed.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "kdl_space/impact/rigid_body_system.hpp"
#include "kdl_space/simulation/compliant_capture.hpp"

namespace kdl_space::test {
namespace {

constexpr double kMassRobot = 40.0, kMassTarget = 10.0;
constexpr double kMu = kMassRobot * kMassTarget / (kMassRobot + kMassTarget);  // 8 kg

/// The damped oscillator of one grasp axis, from x(0) = 0, x'(0) = v0.
struct Oscillator {
  double K, D, v0;
  double omega_n() const { return std::sqrt(K / kMu); }
  double sigma() const { return D / (2.0 * kMu); }
  double omega_d() const { return std::sqrt(omega_n() * omega_n() - sigma() * sigma()); }
  double x(double t) const { return v0 / omega_d() * std::exp(-sigma() * t) * std::sin(omega_d() * t); }
  double xdot(double t) const {
    return v0 * std::exp(-sigma() * t) * (std::cos(omega_d() * t) - sigma() / omega_d() * std::sin(omega_d() * t));
  }
  double peak() const { return std::atan(omega_d() / sigma()) / omega_d(); }  ///< t*: x' = 0
};

/// The root of f on [a, b] (f(a) > 0 >= f(b)) by bisection, to the last bit of t.
double bisect(const std::function<double(double)>& f, double a, double b) {
  for (int i = 0; i < 200 && b - a > 0.0; ++i) {
    const double m = 0.5 * (a + b);
    if (m == a || m == b) break;
    (f(m) > 0.0 ? a : b) = m;
  }
  return b;
}

/// Two free bodies touching at the world origin, their CoMs there; the target moves at `v`
/// (world, the robot's contact axes) relative to the robot at rest.
CaptureProblem twoBodies(const Vector3d& v) {
  RigidTarget robot_body;
  robot_body.mass = kMassRobot;
  // The grasp's force acts at the target's CoM, displaced from the robot's by the deflection q:
  // on two axes q and f are not parallel, and the moment q x f turns the robot (and with it the
  // grasp's axes), coupling the axes by ~1e-8 over the contact. An inertia this large keeps the
  // robot from turning (the coupling ~1e-16): the axes stay the closed form's.
  robot_body.inertia = Matrix3d::Identity() * 1e9;
  CaptureProblem p;
  p.robot = rigidBodySystem(robot_body, Vector3d::Zero(), Vector6d::Zero());
  RigidTarget t;
  t.mass = kMassTarget;
  t.inertia = Matrix3d::Identity() * 0.5;
  t.twist << v, Vector3d::Zero();
  p.target = t;
  return p;
}

CompliantRun tightRun() {
  CompliantRun run;
  run.options.rtol = 1e-12;
  run.options.atol = 1e-15;
  return run;
}

/// The distance from t to the nearest output sample before the end (the old rule's grid).
double offGrid(const CompliantCaptureResult& c, double t) {
  double d = std::abs(t);
  for (std::size_t i = 0; i + 1 < c.history.size(); ++i) d = std::min(d, std::abs(c.history[i].t - t));
  return d;
}

TEST(CompliantContactEnd, OneAxisCaughtAtTheToleranceAndAtTheCompressionsMaximum) {
  const Oscillator x{1e6, 2.0 * 0.3 * std::sqrt(1e6 * kMu), -0.2};  // zeta 0.3, closing at 0.2 m/s
  CompliantGrasp g;
  g.lock = GraspLock::SpringMaximum;  // the catch rules, measured on a latching gripper
  g.stiffness << x.K, 1e6, 1e6, 1e4, 1e4, 1e4;
  g.damping = (Vector6d() << x.D, 100.0, 100.0, 1.0, 1.0, 1.0).finished();
  const CaptureProblem p = twoBodies(Vector3d(x.v0, 0.0, 0.0));

  // The tolerance rule: x'(t) = tol v0, before t*.
  const double t_peak = x.peak();
  const double t_tol = bisect([&](double t) { return x.xdot(t) / x.v0 - g.catch_tolerance; }, 0.0, t_peak);
  const CompliantCaptureResult c = solveCompliantCapture(p, g, tightRun());
  ASSERT_EQ(c.end, ContactEnd::Caught);
  EXPECT_EQ(c.catch_rule, CatchRule::Tolerance);
  EXPECT_NEAR(c.duration, t_tol, 1e-9);
  RecordProperty("tolerance_instant_error_s", std::to_string(c.duration - t_tol));
  EXPECT_NEAR(c.history.back().deflection(0), x.x(c.duration), 1e-9 * std::abs(x.x(t_tol)));
  EXPECT_GT(offGrid(c, t_tol), 1e-7) << "the old rule's grid would have been within 1e-7 s";
  std::cout << "tolerance rule: t = " << c.duration << " s, closed form " << t_tol << " s, error "
            << c.duration - t_tol << " s; nearest output sample " << offGrid(c, t_tol) << " s away\n";

  // A vanishing tolerance: the maximum of the compression, t* = atan(omega_d / sigma) / omega_d.
  g.catch_tolerance = 1e-12;
  const CompliantCaptureResult m = solveCompliantCapture(p, g, tightRun());
  ASSERT_EQ(m.end, ContactEnd::Caught);
  EXPECT_NEAR(m.duration, t_peak, 1e-9);
  RecordProperty("peak_instant_error_s", std::to_string(m.duration - t_peak));
  EXPECT_GT(offGrid(m, t_peak), 1e-7);
  std::cout << "compression maximum: t = " << m.duration << " s, t* " << t_peak << " s, error " << m.duration - t_peak
            << " s; nearest output sample " << offGrid(m, t_peak) << " s away\n";
  // Nothing moved off the axis.
  EXPECT_LE(m.history.back().deflection.tail<5>().norm(), 1e-12 * std::abs(x.x(t_peak)));
}

TEST(CompliantContactEnd, TwoAxesCaughtAtTheSpringsEnergyMaximum) {
  const Oscillator x{1e6, 2.0 * 0.2 * std::sqrt(1e6 * kMu), -0.2};
  const Oscillator y{2.3e6, 2.0 * 0.1 * std::sqrt(2.3e6 * kMu), 0.15};
  CompliantGrasp g;
  g.lock = GraspLock::SpringMaximum;  // the catch rules, measured on a latching gripper
  g.stiffness << x.K, y.K, 1e6, 1e4, 1e4, 1e4;
  g.damping = (Vector6d() << x.D, y.D, 100.0, 1.0, 1.0, 1.0).finished();
  const CaptureProblem p = twoBodies(Vector3d(x.v0, y.v0, 0.0));
  // dV/dt > 0 from the touch until its first root (the earlier peak of the two axes bounds it).
  const auto dV = [&](double t) { return x.K * x.x(t) * x.xdot(t) + y.K * y.x(t) * y.xdot(t); };
  const double t_end = std::max(x.peak(), y.peak());
  double a = 1e-9 * t_end, b = t_end;
  for (double t = a; t <= t_end; t += 1e-3 * t_end)  // the first sign change on a fine grid
    if (dV(t) <= 0.0) {
      b = t;
      break;
    } else {
      a = t;
    }
  const double t_max = bisect(dV, a, b);
  const double s0 = x.K * x.v0 * x.v0 + y.K * y.v0 * y.v0;
  const double speed = std::sqrt((x.K * std::pow(x.xdot(t_max), 2) + y.K * std::pow(y.xdot(t_max), 2)) / s0);
  ASSERT_GT(speed, 10.0 * g.catch_tolerance);  // the energy's maximum comes first, by far

  const CompliantCaptureResult c = solveCompliantCapture(p, g, tightRun());
  ASSERT_EQ(c.end, ContactEnd::Caught);
  EXPECT_EQ(c.catch_rule, CatchRule::SpringMaximum);
  EXPECT_NEAR(c.duration, t_max, 1e-9);
  RecordProperty("energy_maximum_instant_error_s", std::to_string(c.duration - t_max));
  // The state there is the closed form's at that instant (the integration at rtol 1e-12; the
  // axes still move, so not at t_max's: 1e-10 s at ~0.1 m/s is ~1e-11 m).
  EXPECT_NEAR(c.history.back().deflection(0), x.x(c.duration), 1e-9 * std::abs(x.x(t_max)));
  EXPECT_NEAR(c.history.back().deflection(1), y.x(c.duration), 1e-9 * std::abs(y.x(t_max)));
  EXPECT_GT(offGrid(c, t_max), 1e-7);
  std::cout << "springs' energy maximum: t = " << c.duration << " s, closed form " << t_max << " s, error "
            << c.duration - t_max << " s; nearest output sample " << offGrid(c, t_max) << " s away\n";
  // The residual relative motion the lock stops: the momentum is kept through it.
  EXPECT_LE((c.momentum_after - c.momentum_before).norm(), 1e-12 * c.momentum_before.norm());
}

}  // namespace
}  // namespace kdl_space::test
