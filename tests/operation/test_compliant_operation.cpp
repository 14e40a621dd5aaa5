// The compliant capture inside the operation (issue 28, law type compliant): the contact's samples
// as rows of the run, what moves on after it (the joined system with its grasp locked when caught,
// the robot and the target apart when it opened), the momentum of both sides kept from before the
// contact to the end of the motion (against the two systems' momenta computed on their own), the
// motion after it tending to the impulsive operation's as the stiffness grows, and the refusals.
#include <gtest/gtest.h>

#include <cmath>

#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "compliant_checks.hpp"
#include "test_util.hpp"

namespace kdl_space {
namespace {

using test::compliantScenario;
using test::momentumOf;
using test::near;

/// Both sides' momentum before the contact, each from its own model.
Vector6d momentumBefore(const Scenario& sc) {
  return momentumOf(sc.capture.robot) + momentumOf(std::get<FloatingSystem>(sc.capture.target));
}

TEST(CompliantOperation, CaughtThenTheJoinedSystemMovesOnWithBothSidesMomentum) {
  CompliantGrasp latching;
  latching.lock = GraspLock::SpringMaximum;  // caught, then locked (lock: never in test_compliant_lock)
  const Scenario sc = compliantScenario(latching);
  std::vector<MotionSample> seen;
  OperationOptions o;
  o.observer = [&](const OperationResult& so_far, const MotionSample& x) {
    EXPECT_EQ(static_cast<std::size_t>(x.q.size()), so_far.model->nj()) << "a sample in the joints of the model";
    seen.push_back(x);
  };
  const OperationResult r = runCaptureOperation(sc, o);
  ASSERT_TRUE(r.compliant);
  ASSERT_TRUE(r.capture) << "the impulsive limit beside it";
  const CompliantCaptureResult& c = *r.compliant;
  ASSERT_EQ(c.end, ContactEnd::Caught);
  ASSERT_TRUE(r.joined);
  EXPECT_EQ(r.joined->grasp, GraspJoint::Compliant);
  EXPECT_EQ(r.model, c.joined.model);
  EXPECT_TRUE(r.payload_attached);

  // The contact's rows: one per history sample, from the contact instant, with its wrench.
  ASSERT_EQ(r.contact_samples.size(), c.history.size());
  ASSERT_GT(c.history.size(), 2u);
  for (std::size_t i = 0; i < c.history.size(); ++i) {
    const MotionSample& x = r.contact_samples[i];
    EXPECT_EQ(x.phase, Phase::Contact);
    EXPECT_DOUBLE_EQ(x.t, r.t_capture + c.history[i].t);
    EXPECT_EQ(x.contact_wrench, c.history[i].wrench);
  }
  // The motion starts where the contact ended; the grasp stays locked at its deflection.
  ASSERT_FALSE(r.samples.empty());
  EXPECT_DOUBLE_EQ(r.samples.front().t, r.t_capture + c.duration);
  EXPECT_NEAR(r.samples.back().t, r.t_capture + c.duration + sc.simulation.duration, 1e-12);
  for (const MotionSample& x : r.samples) {
    EXPECT_EQ(x.phase, Phase::Post);
    EXPECT_TRUE(std::isnan(x.contact_wrench(0)));
    for (int k = 0; k < 6; ++k) {
      const int j = r.joined->grasp_joints[k];
      EXPECT_EQ(x.q(j), c.joined.state.q(j)) << "grasp joint " << k << " moved at t = " << x.t;
      EXPECT_EQ(x.qd(j), 0.0);
    }
  }
  // Both sides' momentum, computed on their own before the contact, through the contact and the
  // joined motion: every sample's (an internal force, then a free system), to 1e-12 of |h|
  // (each step's round-off; L about the world origin sums r x P over bodies metres away).
  const Vector6d h0 = momentumBefore(sc);
  for (const std::vector<MotionSample>* rows : {&r.contact_samples, &r.samples})
    for (const MotionSample& x : *rows)
      ASSERT_TRUE(near(x.h, h0, 1e-12, 1e-12 * h0.norm(), "momentum")) << "t = " << x.t;

  // The observer saw the contact's rows and the motion's, in time order, in one system's joints.
  ASSERT_EQ(seen.size(), r.contact_samples.size() + r.samples.size());
  for (std::size_t i = 1; i < seen.size(); ++i) EXPECT_LE(seen[i - 1].t, seen[i].t);
  EXPECT_EQ(seen.front().phase, Phase::Contact);
  EXPECT_EQ(seen.back().phase, Phase::Post);
}

/// The robot's joint rates and base twist at the end of the motion after the capture.
Eigen::VectorXd finalRobotVelocity(const Scenario& sc, const OperationResult& r) {
  const FloatingModel& robot = *sc.capture.robot.model;
  Eigen::VectorXd v(6 + robot.nj());
  v.head<6>() = r.samples.back().twist;
  for (unsigned int j = 0; j < robot.nj(); ++j)
    v(6 + j) = r.samples.back().qd(r.model->jointIndex(robot.jointNames()[j]));
  return v;
}

TEST(CompliantOperation, TheMotionAfterTendsToTheImpulsiveOperationsAsTheStiffnessGrows) {
  Scenario impulsive = compliantScenario();
  impulsive.compliant.reset();  // law: capture, the paper's rigid capture
  const OperationResult rigid = runCaptureOperation(impulsive);
  ASSERT_FALSE(rigid.compliant);
  const Eigen::VectorXd v_rigid = finalRobotVelocity(impulsive, rigid);
  std::vector<double> errors;
  // K = 1e9, 1e10, 1e11 N/m (and 1e7 ... 1e9 N m/rad), D = beta K (docs/COMPLIANT.md). Measured:
  // 2.1e-5, 2.7e-6, 2.9e-7 (from 1e7 N/m on: 4.1e-4, 1.1e-4: the order reaches 1 as the contact's
  // duration becomes ~ m / (beta K)).
  for (const double scale : {1e3, 1e4, 1e5}) {
    CompliantGrasp g;
    g.lock = GraspLock::SpringMaximum;  // the latching gripper (lock: never has its own test)
    g.stiffness *= scale;
    const Scenario sc = compliantScenario(g);
    const OperationResult r = runCaptureOperation(sc);
    ASSERT_EQ(r.compliant->end, ContactEnd::Caught);
    errors.push_back((finalRobotVelocity(sc, r) - v_rigid).norm() / v_rigid.norm());
  }
  // First order in 1/K (the capture itself, the locked deflection and the contact's duration are
  // all O(1/K)): the fitted order over the last decade (measured 0.98), and the stiffest's error.
  const double order = std::log10(errors[1] / errors[2]);
  EXPECT_GE(order, 0.9) << errors[0] << " " << errors[1] << " " << errors[2];
  EXPECT_GE(std::log10(errors[0] / errors[1]), 0.8) << errors[0] << " " << errors[1];
  EXPECT_LT(errors[2], 1e-6) << errors[2];
}

TEST(CompliantOperation, OpenedTheRobotAndTheTargetMoveOnApart) {
  // A nearly elastic hand with a one-sided contact whose normal opposes the closing velocity: the
  // target is pushed back and the contact opens.
  Scenario sc = compliantScenario();
  const CaptureResult limit = solveCapture(sc.capture);
  const Vector3d v_rel = limit.floating_target->contact_twist_before.head<3>() - limit.robot.contact_twist_before.head<3>();
  CompliantGrasp g;
  g.damping_time = 1e-6;
  g.normal = -v_rel.normalized();  // from the robot's contact point toward the target: closing
  sc.compliant = g;
  const OperationResult r = runCaptureOperation(sc);
  ASSERT_TRUE(r.compliant);
  const CompliantCaptureResult& c = *r.compliant;
  ASSERT_EQ(c.end, ContactEnd::Opened);
  EXPECT_FALSE(r.joined);
  EXPECT_EQ(r.model, sc.capture.robot.model);
  EXPECT_FALSE(r.payload_attached);
  ASSERT_TRUE(r.target_motion) << "the free-floating target moves on by itself";
  EXPECT_NEAR(r.target_motion->end.t, r.t_capture + c.duration + sc.simulation.duration, 1e-12);
  // The contact's rows in the robot's joints only.
  for (const MotionSample& x : r.contact_samples) EXPECT_EQ(static_cast<unsigned int>(x.q.size()), r.model->nj());
  // Each side's momentum after the contact, computed on its own, sums to both sides' before.
  ASSERT_FALSE(r.samples.empty());
  const Vector6d h_robot = r.samples.front().h;
  const Vector6d h0 = momentumBefore(sc);
  EXPECT_TRUE(near(h_robot + momentumOf(c.target_end), h0, 1e-12, 1e-12 * h0.norm(), "both sides"));
  EXPECT_TRUE(near(h_robot, momentumOf(c.robot_end), 1e-12, 1e-12 * h_robot.norm(), "the robot's"));
  for (const MotionSample& x : r.samples)
    ASSERT_TRUE(near(x.h, h_robot, 1e-12, 1e-12 * h_robot.norm(), "the robot alone")) << x.t;
  EXPECT_LE(r.target_motion->dP, 1e-12 * momentumOf(c.target_end).norm() + 1e-15);
  // The target bounced: its contact point recedes along the normal.
  EXPECT_GT(c.target_after.base_twist.vel.Norm() + c.target_after.base_twist.rot.Norm(), 0.0);
}

TEST(CompliantOperation, AContactThatOpensAtTheTouchIsWarnedAbout) {
  // The normal along the relative velocity: the target moves away from the hand.
  Scenario sc = compliantScenario();
  const CaptureResult limit = solveCapture(sc.capture);
  const Vector3d v_rel = limit.floating_target->contact_twist_before.head<3>() - limit.robot.contact_twist_before.head<3>();
  CompliantGrasp g;
  g.normal = v_rel.normalized();
  sc.compliant = g;
  const OperationResult r = runCaptureOperation(sc);
  ASSERT_EQ(r.compliant->end, ContactEnd::Opened);
  EXPECT_LE(r.compliant->duration, 1e-9);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0].kind, "contact_opened_at_touch");
  // A contact that closes first (the test above) is not warned about.
  g.normal = -v_rel.normalized();
  g.damping_time = 1e-6;
  sc.compliant = g;
  const OperationResult bounce = runCaptureOperation(sc);
  ASSERT_EQ(bounce.compliant->end, ContactEnd::Opened);
  for (const Diagnostic& d : bounce.warnings) EXPECT_NE(d.kind, "contact_opened_at_touch");
}

TEST(CompliantOperation, AContactThatNeverEndsIsRefusedWithWhatWasDone) {
  CompliantGrasp g;
  g.lock = GraspLock::SpringMaximum;  // a latching gripper must be caught (never moves on compliant)
  g.max_duration = 1e-5;  // far shorter than the contact (~ 1e-3 s)
  const Scenario sc = compliantScenario(g);
  try {
    runCaptureOperation(sc);
    FAIL() << "a contact that was neither caught nor opened must be refused";
  } catch (const OperationError& e) {
    EXPECT_NE(std::string(e.what()).find("law.max_duration"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(sc.file), std::string::npos) << e.what();
    ASSERT_TRUE(e.partial());
    ASSERT_TRUE(e.partial()->compliant);
    EXPECT_EQ(e.partial()->compliant->end, ContactEnd::TimedOut);
    EXPECT_FALSE(e.partial()->contact_samples.empty());
  }
}

TEST(CompliantOperation, CancelledInTheContactStopsThere) {
  const Scenario sc = compliantScenario();
  int polls = 0;
  OperationOptions o;
  o.cancelled = [&] { return ++polls > 5; };  // the contact is the first phase (no approach)
  try {
    runCaptureOperation(sc, o);
    FAIL() << "the run must stop";
  } catch (const OperationError& e) {
    EXPECT_EQ(e.code(), E_CANCELLED);
    EXPECT_NE(std::string(e.what()).find("compliant contact"), std::string::npos) << e.what();
  }
  EXPECT_LE(polls, 7) << "it stopped at the first polls";
}

}  // namespace
}  // namespace kdl_space
