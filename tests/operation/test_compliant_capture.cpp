// solveCompliantCapture (simulation/compliant_capture.hpp): the capture of
// scenarios/robot_to_robot_capture.yaml's free-floating two-link target through a spring-damper
// grasp, against the impulsive capture of the same contact state solved by solveCapture (an
// independent route: G* of both sides, no integration):
//   1. a sweep of the stiffness over four decades with stiffness-proportional damping
//      (D = beta K): the error of the impulse and of the velocities after (both sides) falls at
//      first order in 1/K (log-log fit) and is below 1e-6 relative at the stiffest; with a fixed
//      damping ratio (D ~ sqrt(K)) only at order 1/2, as docs/COMPLIANT.md says;
//   2. the momentum (P; L) of both sides is conserved through the contact and the lock to 1e-12
//      relative (against solveCapture's momentum before), and the sides' own momenta (each from
//      its own model) add up to it;
//   3. the energy balance: kinetic before = kinetic after + dampers' work + spring energy locked
//      in + the lock's loss, every term >= 0; the peak force is the largest of the history; the
//      impulse so far of the last sample plus the lock's is the impulse (1e-12), and the force of
//      the samples is the impulse's rate (Simpson between samples, within its error term);
//   1'. the same convergence for a rigid target (the tumbling box) against its rigid capture;
//   4. a bounce: with a light damping and the normal given, the contact opens when the force
//      would pull; with springs alone the kinetic energy taken is what the springs hold (the
//      springs' sign); a spring of the wrong sign is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>
#include <variant>

#include "kdl_space/impact/capture.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/simulation/compliant_capture.hpp"
#include "compliant_checks.hpp"

namespace kdl_space::test {
namespace {

CaptureProblem scenarioProblem() { return loadScenario(robotToRobotScenario()).capture; }

/// A line of the measured convergence (the test's output; docs/COMPLIANT.md's tables).
void print(double K, const CompliantCaptureResult& c, double error) {
  std::cout << "K " << K << "  duration " << c.duration << " s  error " << error << "  caught by "
            << (c.catch_rule == CatchRule::Tolerance ? "tolerance" : "springs' energy maximum") << "\n";
}

/// Stiffness K on the translational axes, K / 100 [N m/rad] on the rotational ones.
CompliantGrasp gripper(double K) {
  CompliantGrasp g;
  g.lock = GraspLock::SpringMaximum;  // the latching gripper: these tests measure its catch
  g.stiffness << K, K, K, 1e-2 * K, 1e-2 * K, 1e-2 * K;
  return g;
}

/// Least-squares slope of log(error) against log(K).
double slope(const std::vector<double>& K, const std::vector<double>& e) {
  const double n = static_cast<double>(K.size());
  double mx = 0.0, my = 0.0, sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < K.size(); ++i) mx += std::log(K[i]) / n, my += std::log(e[i]) / n;
  for (std::size_t i = 0; i < K.size(); ++i) {
    sxy += (std::log(K[i]) - mx) * (std::log(e[i]) - my);
    sxx += std::pow(std::log(K[i]) - mx, 2);
  }
  return sxy / sxx;
}

TEST(CompliantCapture, ConvergesToTheImpulsiveCaptureAtFirstOrderInOneOverK) {
  const CaptureProblem p = scenarioProblem();
  const FloatingSystem& target = std::get<FloatingSystem>(p.target);
  const CaptureResult impulsive = solveCapture(p);
  std::vector<double> Ks, errors;
  for (double K = 1e8; K <= 1e11 * 1.01; K *= 10.0) {
    CompliantGrasp g = gripper(K);
    g.damping_time = 1e-2;  // D = beta K
    const CompliantCaptureResult c = solveCompliantCapture(p.robot, target, g);
    ASSERT_EQ(c.end, ContactEnd::Caught) << K;
    Ks.push_back(K);
    errors.push_back(captureError(c, impulsive));
    RecordProperty("error_K" + std::to_string(Ks.size()), std::to_string(errors.back()));
    print(K, c, errors.back());
  }
  // The contact lasts ~ m / (beta K) and the error is first order in it: the fitted order is 1
  // up to the pre-asymptotic drift of the softest setting (a few per cent).
  EXPECT_LE(slope(Ks, errors), -0.97) << ::testing::PrintToString(errors);
  EXPECT_LE(std::log(errors[errors.size() - 1] / errors[errors.size() - 2]) / std::log(10.0), -0.99);
  EXPECT_LE(errors.back(), 1e-6);
  EXPECT_LE(errors[errors.size() - 2], 1.1e-5);  // 1e-6 at 1e10 (a tenth of 1e11's)
}

TEST(CompliantCapture, AFixedDampingRatioConvergesOnlyAtOrderOneHalf) {
  const CaptureProblem p = scenarioProblem();
  const FloatingSystem& target = std::get<FloatingSystem>(p.target);
  const CaptureResult impulsive = solveCapture(p);
  std::vector<double> Ks, errors;
  for (double K = 1e6; K <= 1e9 * 1.01; K *= 10.0) {
    CompliantGrasp g = gripper(K);
    g.damping = Vector6d(2.0 * 0.7 * (g.stiffness.array() * 10.0).sqrt());  // ratio ~0.7 for ~10 kg
    const CompliantCaptureResult c = solveCompliantCapture(p.robot, target, g);
    ASSERT_EQ(c.end, ContactEnd::Caught) << K;
    Ks.push_back(K);
    errors.push_back(captureError(c, impulsive));
    print(K, c, errors.back());
  }
  const double order = -slope(Ks, errors);
  EXPECT_GT(order, 0.35) << ::testing::PrintToString(errors);
  EXPECT_LT(order, 0.65) << ::testing::PrintToString(errors);
}

/// The force of every sample is the rate of the impulse so far (ContactSample::impulse, exact from
/// the robot's momentum; the wrench from S^T W = tau: two routes). Simpson's rule over each pair of
/// equal output steps h, [t_(i-1), t_(i+1)]:
///   I(t_(i+1)) - I(t_(i-1)) = h/3 (f_(i-1) + 4 f_i + f_(i+1)) - h^5/90 f^(4)(xi),
/// its error term bounded with f^(4) estimated from the samples' fourth differences around the
/// pair (Delta^4 f / h^4, the largest of those touching it, times 2 for f^(4) varying between
/// them), plus the round-off of the impulses (1e-13 of the largest: momenta differenced).
void expectForceIsTheImpulsesRate(const CompliantCaptureResult& c) {
  const std::vector<ContactSample>& x = c.history;
  const std::size_t n = x.size() - 1;  // the last sample is the located end: its step is shorter
  ASSERT_GE(n, 8u);
  const double h = x[1].t - x[0].t;
  double largest = 0.0;
  for (const ContactSample& y : x) largest = std::max(largest, y.impulse.head<3>().norm());
  const auto f = [&](std::size_t i) { return Vector3d(x[i].wrench.head<3>()); };
  const auto fourth = [&](std::size_t i) {  // |Delta^4 f| centred on i (2 <= i <= n - 3)
    return (f(i - 2) - 4.0 * f(i - 1) + 6.0 * f(i) - 4.0 * f(i + 1) + f(i + 2)).norm();
  };
  int checked = 0;
  for (std::size_t i = 3; i + 4 < n; i += 2) {
    EXPECT_NEAR(x[i + 1].t - x[i - 1].t, 2.0 * h, 1e-12 * x[i + 1].t);
    double d4 = 0.0;
    for (std::size_t k = i - 1; k <= i + 1; ++k) d4 = std::max(d4, fourth(k));
    const double bound = 2.0 * h / 90.0 * d4 + 1e-13 * largest;
    const Vector3d simpson = h / 3.0 * (f(i - 1) + 4.0 * f(i) + f(i + 1));
    const Vector3d exact = x[i + 1].impulse.head<3>() - x[i - 1].impulse.head<3>();
    EXPECT_LE((exact - simpson).norm(), bound) << "samples " << i - 1 << " to " << i + 1 << " of " << n;
    ++checked;
  }
  EXPECT_GE(checked, 3);
}

// A rigid target (the tumbling box: one free body) tends to its rigid capture (solveCapture,
// ImpactKind::Capture: G_B of the body, no integration) as the robot target does, with the
// momentum of both kept through the contact.
TEST(CompliantCapture, ARigidTargetConvergesToItsRigidCapture) {
  const CaptureProblem p =
      loadScenario(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/tumbling_box_capture.yaml").capture;
  ASSERT_TRUE(std::holds_alternative<RigidTarget>(p.target));
  ASSERT_EQ(p.law.kind, ImpactKind::Capture);
  const CaptureResult impulsive = solveCapture(p);
  std::vector<double> Ks, errors;
  for (double K = 1e8; K <= 1e11 * 1.01; K *= 10.0) {
    CompliantGrasp g = gripper(K);
    g.damping_time = 1e-2;  // D = beta K
    const CompliantCaptureResult c = solveCompliantCapture(p, g);
    ASSERT_EQ(c.end, ContactEnd::Caught) << K;
    const Vector6d& h = impulsive.momentum_before;
    EXPECT_LE((c.momentum_before - h).norm(), 1e-12 * h.norm());
    EXPECT_LE((c.momentum_after - h).norm(), 1e-12 * h.norm());
    EXPECT_LE((c.robot_momentum_after + c.target_momentum_after - h).norm(), 1e-12 * h.norm());
    EXPECT_LE((c.history.back().impulse + c.lock_impulse - c.impulse).norm(), 1e-12 * c.impulse.norm());
    Ks.push_back(K);
    errors.push_back(captureError(c, impulsive));
    print(K, c, errors.back());
  }
  // (The softest setting is pre-asymptotic: the fit over 1e8..1e11 is ~0.97, the last decade 1.)
  EXPECT_LE(slope(Ks, errors), -0.97) << ::testing::PrintToString(errors);
  EXPECT_LE(std::log(errors[errors.size() - 1] / errors[errors.size() - 2]) / std::log(10.0), -0.99);
  EXPECT_LE(errors.back(), 1e-6) << ::testing::PrintToString(errors);

  // A free body needs a mass.
  for (const double mass : {0.0, -1.0, std::nan("")}) {
    CaptureProblem q = p;
    std::get<RigidTarget>(q.target).mass = mass;
    try {
      solveCompliantCapture(q, gripper(1e6));
      ADD_FAILURE() << "a target of mass " << mass << " was accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("target.mass: a rigid target must have a finite mass > 0 [kg]", 0), 0u)
          << e.what();
    }
  }
}

TEST(CompliantCapture, ConservesMomentumAndBalancesEnergy) {
  const CaptureProblem p = scenarioProblem();
  const FloatingSystem& target = std::get<FloatingSystem>(p.target);
  const CaptureResult impulsive = solveCapture(p);
  for (const double K : {1e6, 1e9}) {
    CompliantGrasp g = gripper(K);
    const CompliantCaptureResult c = solveCompliantCapture(p.robot, target, g);
    ASSERT_EQ(c.end, ContactEnd::Caught);
    const Vector6d& h = impulsive.momentum_before;
    const double tol = 1e-12 * h.norm();
    EXPECT_LE((c.momentum_before - h).norm(), tol);
    EXPECT_LE((c.momentum_after - h).norm(), tol);
    EXPECT_LE((c.robot_momentum_after + c.target_momentum_after - h).norm(), tol);
    // The robot's momentum changed by the impulse (moment moved to the contact point).
    EXPECT_NEAR(c.energy_before, impulsive.energy_before, 1e-12 * impulsive.energy_before);
    const double lost = c.energy_before - c.energy_after;
    EXPECT_NEAR(lost, c.dissipated + c.spring_energy + c.lock_loss, 1e-8 * c.energy_before);
    EXPECT_GT(c.dissipated, 0.0);
    EXPECT_GE(c.spring_energy, 0.0);
    EXPECT_GE(c.lock_loss, 0.0);
    // The impulsive capture loses what the contact's dampers, springs and lock take together, as
    // the stiffness grows.
    if (K == 1e9) EXPECT_NEAR(lost, impulsive.energyLost(), 1e-4 * impulsive.energyLost());
    // The peak is the history's largest force.
    ASSERT_GE(c.history.size(), 10u);
    double peak = 0.0;
    for (const ContactSample& x : c.history) peak = std::max(peak, x.wrench.head<3>().norm());
    EXPECT_EQ(c.peak_force, peak);
    EXPECT_NEAR(c.duration, c.history.back().t, 1e-15);
    // The impulse so far at the last sample (the end, before the lock) and the lock's: the robot's
    // whole change of momentum (three momenta of one route: round-off of the momenta, ~1e-16 of
    // the largest, which the impulse's size bounds here).
    EXPECT_LE((c.history.back().impulse + c.lock_impulse - c.impulse).norm(), 1e-12 * c.impulse.norm());
    expectForceIsTheImpulsesRate(c);
  }
}

TEST(CompliantCapture, OpensWhenTheSpringWouldPullAndRefusesAWrongSpring) {
  const CaptureProblem p = scenarioProblem();
  const FloatingSystem& target = std::get<FloatingSystem>(p.target);
  const CaptureResult impulsive = solveCapture(p);
  CompliantGrasp g = gripper(1e6);
  g.damping_time = 1e-5;  // a light damping: the spring gives back what it took
  // The normal along which the contact pushes: the impulse's force on the robot points from the
  // target toward the robot (-n).
  g.normal = Vector3d(-impulsive.impulse.F.head<3>().normalized());
  const CompliantCaptureResult c = solveCompliantCapture(p.robot, target, g);
  EXPECT_EQ(c.end, ContactEnd::Opened);
  EXPECT_GT(c.duration, 0.0);
  EXPECT_EQ(c.lock_loss, 0.0);
  // Located where n^T f crosses to >= 0 (within 1e-10 s after: f changes by ~ its peak's rate
  // times that), every sample before pushing.
  EXPECT_GE(g.normal->dot(c.history.back().wrench.head<3>()), 0.0);
  EXPECT_LE(g.normal->dot(c.history.back().wrench.head<3>()), 1e-6 * c.peak_force);
  for (std::size_t i = 1; i + 1 < c.history.size(); ++i) EXPECT_LT(g.normal->dot(c.history[i].wrench.head<3>()), 0.0);

  // Springs alone (no damping): the kinetic energy the contact took is what the springs hold
  // at the opening (a spring of the wrong sign would give energy instead of taking it).
  CompliantGrasp elastic = gripper(1e6);
  elastic.damping = Vector6d::Zero();
  elastic.normal = g.normal;
  const CompliantCaptureResult b = solveCompliantCapture(p.robot, target, elastic);
  EXPECT_EQ(b.end, ContactEnd::Opened);
  EXPECT_NEAR(b.dissipated, 0.0, 1e-9 * b.energy_before);
  EXPECT_GT(b.spring_energy, 1e-6 * b.energy_before);
  EXPECT_NEAR(b.energy_before - b.energy_after, b.spring_energy, 1e-8 * b.energy_before);

  CompliantGrasp wrong = gripper(1e6);
  wrong.stiffness(2) = -1e6;
  EXPECT_THROW(solveCompliantCapture(p.robot, target, wrong), InputError);
}

}  // namespace
}  // namespace kdl_space::test
