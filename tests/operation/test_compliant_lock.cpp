// When the compliant grasp locks (issue 39, item 5: law.lock): never (the grasp stays compliant
// in the motion after it), tolerance, spring_maximum (the first of the two, as before). Checked:
// - never leaves no lock impulse (the contact's impulse is its last sample's) and, with a fixed
//   damping ratio and the relative motion let die out to 1e-6, converges to the impulsive capture
//   at order 1/2 in 1/K (the independent route: solveCapture's G* of both sides);
// - on a soft gripper the springs' energy maximum comes first and its lock takes a large part of
//   the impulse; the tolerance's lock takes only what is left of the relative motion (its energy
//   share ~ catch_tolerance^2);
// - in the operation, never's grasp joints move after the contact (springs, not brakes), both
//   sides' momentum is kept to 1e-12 through the contact and the motion, and a contact that has
//   not died out by max_duration moves on compliant instead of being refused;
// - a wrong law.lock names the field and the choices.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <unistd.h>

#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/simulation/compliant_capture.hpp"
#include "compliant_checks.hpp"
#include "test_util.hpp"

namespace kdl_space {
namespace {

using test::captureError;
using test::compliantScenario;
using test::momentumOf;
using test::near;

const std::string& kScenario = test::robotToRobotScenario();

CompliantGrasp gripper(double K, GraspLock lock) {
  CompliantGrasp g;
  g.stiffness << K, K, K, 1e-2 * K, 1e-2 * K, 1e-2 * K;
  g.lock = lock;
  return g;
}

TEST(CompliantLock, NeverLeavesNoLockImpulseAndConvergesToTheImpulsiveCapture) {
  // Without a lock the springs and dampers must take all the relative motion: a damping ratio of
  // about 0.7 on every axis (D = 2 x 0.7 sqrt(10 K), as AFixedDampingRatioConvergesOnlyAtOrderOneHalf:
  // with stiffness-proportional damping an overdamped slow mode keeps a residue for 1/beta) and
  // the contact run until the relative speed is 1e-6 of its start.
  const CaptureProblem p = loadScenario(kScenario).capture;
  const FloatingSystem& target = std::get<FloatingSystem>(p.target);
  const CaptureResult impulsive = solveCapture(p);
  std::vector<double> Ks, errors;
  for (double K = 1e6; K <= 1e8 * 1.01; K *= 10.0) {
    CompliantGrasp g = gripper(K, GraspLock::Never);
    g.damping = Vector6d(2.0 * 0.7 * (g.stiffness.array() * 10.0).sqrt());
    g.catch_tolerance = 1e-6;
    const CompliantCaptureResult c = solveCompliantCapture(p.robot, target, g);
    ASSERT_EQ(c.end, ContactEnd::Settled) << K;
    EXPECT_EQ(c.catch_rule, CatchRule::None);
    EXPECT_EQ(c.lock, GraspLock::Never);
    EXPECT_EQ(c.lock_impulse, Vector6d::Zero());
    EXPECT_EQ(c.lock_loss, 0.0);
    EXPECT_EQ(c.lock_share.linear_impulse, 0.0);
    EXPECT_EQ(c.lock_share.angular_impulse, 0.0);
    EXPECT_EQ(c.lock_share.energy, 0.0);
    ASSERT_FALSE(c.history.empty());
    EXPECT_TRUE(near(c.history.back().impulse, c.impulse, 1e-12, 1e-12 * c.impulse.norm(), "impulse"));
    Ks.push_back(K);
    errors.push_back(captureError(c, impulsive));
  }
  // Order 1/2 in 1/K, as any fixed damping ratio (measured: 0.116, 0.0345, 0.0108; 0.0034 at 1e9).
  const double order = -std::log(errors.back() / errors.front()) / std::log(Ks.back() / Ks.front());
  EXPECT_GT(order, 0.4) << ::testing::PrintToString(errors);
  EXPECT_LT(order, 0.6) << ::testing::PrintToString(errors);
  EXPECT_LT(errors.back(), 0.02);
}

TEST(CompliantLock, OnASoftGripperTheEnergyMaximumLocksEarlyAndTheToleranceLeavesTheLockLittle) {
  const CaptureProblem p = loadScenario(kScenario).capture;
  const FloatingSystem& target = std::get<FloatingSystem>(p.target);
  CompliantGrasp soft = gripper(5e4, GraspLock::SpringMaximum);
  soft.damping_time = 2e-3;
  soft.max_duration = 30.0;
  const CompliantCaptureResult first = solveCompliantCapture(p.robot, target, soft);
  soft.lock = GraspLock::Tolerance;
  const CompliantCaptureResult late = solveCompliantCapture(p.robot, target, soft);
  ASSERT_EQ(first.end, ContactEnd::Caught);
  ASSERT_EQ(late.end, ContactEnd::Caught);
  EXPECT_EQ(first.catch_rule, CatchRule::SpringMaximum);
  EXPECT_EQ(late.catch_rule, CatchRule::Tolerance);
  EXPECT_LT(first.duration, late.duration);
  // Each share against its definition from the result's own terms (a second reading).
  for (const CompliantCaptureResult* c : {&first, &late}) {
    EXPECT_NEAR(c->lock_share.linear_impulse, c->lock_impulse.head<3>().norm() / c->impulse.head<3>().norm(), 1e-15);
    EXPECT_NEAR(c->lock_share.energy, c->lock_loss / (c->energy_before - c->energy_after), 1e-15);
    // The energy: kinetic before = after + dampers + springs + lock.
    EXPECT_NEAR(c->energy_before, c->energy_after + c->dissipated + c->spring_energy + c->lock_loss,
                1e-9 * c->energy_before);
  }
  // The lock at the springs' maximum stops a relative motion still under way: on this soft grasp it
  // gives nearly all of the moment's impulse (measured 99.9 %; the force's 84 %, 27 % of the
  // energy: the complaint, a rigid capture for rotation). At the tolerance the relative
  // speed sqrt(qdot^T K qdot) is 1e-3 of its start; the rotation, whose stiffness is a hundredth
  // of the translation's here, may keep up to 1e-2 of its start (measured: the lock's 2.7 % of the
  // force's impulse, 4.0 % of the moment's, 1.8e-4 of the energy).
  EXPECT_GT(first.lock_share.angular_impulse, 0.9);
  EXPECT_GT(first.lock_share.energy, 0.1);
  EXPECT_LT(late.lock_share.linear_impulse, 0.05);
  EXPECT_LT(late.lock_share.angular_impulse, 0.05);
  EXPECT_LT(late.lock_share.energy, 1e-3);
}

void expectCompliantAfter(const Scenario& sc, ContactEnd end) {
  const OperationResult r = runCaptureOperation(sc, OperationOptions{});
  ASSERT_TRUE(r.compliant && r.joined);
  const CompliantCaptureResult& c = *r.compliant;
  EXPECT_EQ(c.end, end);
  EXPECT_EQ(c.lock_impulse, Vector6d::Zero());
  ASSERT_FALSE(r.samples.empty());
  // The grasp's joints move on (springs, not brakes): some deflection changes over the motion.
  double moved = 0.0;
  for (const MotionSample& x : r.samples)
    for (int k = 0; k < 6; ++k) {
      const int j = r.joined->grasp_joints[static_cast<std::size_t>(k)];
      moved = std::max(moved, std::abs(x.q(j) - r.samples.front().q(j)));
    }
  EXPECT_GT(moved, 1e-9);
  // Both sides' momentum, each from its own model before the contact, through it and the motion.
  const Vector6d h0 = momentumOf(sc.capture.robot) + momentumOf(std::get<FloatingSystem>(sc.capture.target));
  for (const std::vector<MotionSample>* rows : {&r.contact_samples, &r.samples})
    for (const MotionSample& x : *rows)
      ASSERT_TRUE(near(x.h, h0, 1e-12, 1e-12 * h0.norm(), "momentum")) << "t = " << x.t;
}

TEST(CompliantLock, NeverTheGraspStaysCompliantInTheMotionAfterAndKeepsTheMomentum) {
  CompliantGrasp g = gripper(1e5, GraspLock::Never);
  g.max_duration = 30.0;
  expectCompliantAfter(compliantScenario(g), ContactEnd::Settled);
}

TEST(CompliantLock, NeverAContactNotDiedOutByItsMaxDurationMovesOnCompliant) {
  CompliantGrasp g = gripper(1e5, GraspLock::Never);
  g.max_duration = 0.02;  // the springs still oscillate: before, law.max_duration refused the run
  expectCompliantAfter(compliantScenario(g), ContactEnd::TimedOut);
}

TEST(CompliantLock, AWrongLockNamesTheFieldAndTheChoices) {
  const std::string dir = ::testing::TempDir() + "lock_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  std::ifstream in(kScenario);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  text = std::regex_replace(text, std::regex("\\.\\./urdf/"), std::string(KDL_SPACE_SOURCE_DIR) + "/urdf/");
  text = std::regex_replace(text, std::regex("law:\\n  type: capture"), "law:\n  type: compliant\n  lock: sometimes");
  std::ofstream(dir + "/bad.yaml") << text;
  try {
    loadScenario(dir + "/bad.yaml");
    FAIL() << "law.lock: sometimes was read";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("law.lock"), std::string::npos) << what;
    EXPECT_NE(what.find("never"), std::string::npos) << what;
    EXPECT_NE(what.find("spring_maximum"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace kdl_space
