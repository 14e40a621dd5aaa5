// The load a grasp carries after the capture (graspWrench, MotionSample::grasp_wrench; issue 39
// item 3), against a second route (tests/support/grasp_route.hpp: minus the rate of the held
// target's momentum, by a central difference along the motion, with the bodies' point twists of
// eq. 4) and physical facts:
//   1. a rigid target merged into the hand (the tumbling box), a free-floating robot joined by a
//      fixed joint, and one on a compliant grasp left compliant: every sample, 1e-7 of the scale;
//   2. a ball joint (translational capture) carries no moment about its centre;
//   3. a compliant grasp's contact rows carry the contact's own wrench; the spring-damper law
//      gives the motion's after it when the hand's links are massless;
//   4. a point impact holds nothing (NaN, JSON null); law.max_grasp_wrench below the peak warns
//      `grasp_overload`, above it does not.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "grasp_route.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/operation/motion_measures.hpp"
#include "kdl_space/report/operation_report.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

Scenario shipped(const std::string& name) {
  return loadScenario(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/" + name + ".yaml");
}

/// Every motion sample's grasp wrench against the momentum-rate route; returns the largest |f|.
double expectLoadsByMomentumRate(const OperationResult& r, const std::string& what) {
  const std::optional<HeldTarget> held = heldTarget(r);
  EXPECT_TRUE(held) << what;
  if (!held) return 0.0;
  EXPECT_FALSE(r.samples.empty()) << what;
  double peak = 0.0;
  for (const MotionSample& x : r.samples) {
    EXPECT_TRUE(x.grasp_wrench.allFinite()) << what << " t = " << x.t;
    const Vector6d route = graspWrenchByMomentumRate(r.model, *held, x);
    // The difference's truncation (eps^2 |h'''|) and round-off (|h| 1e-16 / eps) both ~1e-9 here.
    EXPECT_TRUE(near(x.grasp_wrench, route, 0.0, 1e-7 * (route.norm() + 1e-3), what + " t = " + std::to_string(x.t)));
    peak = std::max(peak, x.grasp_wrench.head<3>().norm());
  }
  return peak;
}

TEST(GraspLoad, ARigidTargetInTheHandNeedsItsMomentumRate) {
  Scenario sc = shipped("tumbling_box_capture");
  sc.simulation.duration = 2.0;
  const OperationResult r = runCaptureOperation(sc);
  ASSERT_TRUE(r.payload_attached && !r.joined);
  const double peak = expectLoadsByMomentumRate(r, "tumbling box");
  EXPECT_GT(peak, 0.0);
  EXPECT_DOUBLE_EQ(r.record.grasp.force, peak) << "the record's peak is the samples'";
}

TEST(GraspLoad, AJoinedRobotTargetNeedsItsMomentumRate) {
  Scenario sc = shipped("robot_to_robot_capture");
  sc.simulation.duration = 2.0;
  const OperationResult r = runCaptureOperation(sc);
  ASSERT_TRUE(r.joined && r.joined->grasp == GraspJoint::Rigid);
  EXPECT_GT(expectLoadsByMomentumRate(r, "robot to robot"), 0.0);
}

TEST(GraspLoad, ABallJointCarriesNoMomentAboutItsCentre) {
  Scenario sc = shipped("robot_to_robot_capture");
  sc.capture.law.kind = ImpactKind::TranslationalCapture;
  sc.simulation.duration = 1.0;
  const OperationResult r = runCaptureOperation(sc);
  ASSERT_TRUE(r.joined && r.joined->grasp == GraspJoint::Spherical);
  const double peak = expectLoadsByMomentumRate(r, "ball joint");
  ASSERT_GT(peak, 0.0);
  for (const MotionSample& x : r.samples)  // the ball joint's centre is the robot's contact point
    EXPECT_LE(x.grasp_wrench.tail<3>().norm(), 1e-9 * peak) << "t = " << x.t;
}

TEST(GraspLoad, ACompliantGraspCarriesItsSpringsAndDampersForce) {
  CompliantGrasp g;  // lock: never (the default): the springs go on holding after the contact
  g.stiffness << 1e5, 1e5, 1e5, 1e3, 1e3, 1e3;
  g.max_duration = 0.05;
  Scenario sc = shipped("robot_to_robot_capture");
  sc.compliant = g;
  sc.simulation.duration = 0.5;
  sc.simulation.output_step = 0.01;
  const OperationResult r = runCaptureOperation(sc);
  ASSERT_TRUE(r.compliant && r.joined && r.joined->grasp == GraspJoint::Compliant);
  for (const MotionSample& x : r.contact_samples) EXPECT_EQ(x.grasp_wrench, x.contact_wrench) << "t = " << x.t;
  EXPECT_GT(expectLoadsByMomentumRate(r, "compliant"), 0.0);
  // The peaks over the contact and the motion (MotionMeasurer, what plan and study read).
  MotionMeasurer measurer(*sc.capture.robot.model, 0.05, 1e-3);
  double contact_peak = 0.0;
  for (const MotionSample& x : r.contact_samples) {
    measurer.add(r, x);
    contact_peak = std::max(contact_peak, x.contact_wrench.head<3>().norm());
  }
  for (const MotionSample& x : r.samples) measurer.add(r, x);
  EXPECT_DOUBLE_EQ(measurer.peaks().peak_grasp_force, std::max(contact_peak, r.record.grasp.force));
}

TEST(GraspLoad, APointImpactHoldsNothing) {
  Scenario sc = shipped("robot_to_robot_capture");
  sc.capture.law.kind = ImpactKind::PointImpact;
  sc.capture.law.normal = Vector3d(1, 0, 0);
  sc.capture.has_normal = true;
  sc.simulation.duration = 0.2;
  const OperationResult r = runCaptureOperation(sc);
  EXPECT_FALSE(heldTarget(r));
  for (const MotionSample& x : r.samples) EXPECT_TRUE(x.grasp_wrench.array().isNaN().all());
  EXPECT_FALSE(r.record.grasp.held());
  EXPECT_TRUE(report::operationJson(sc, r, {}).at("simulation").at("grasp_load").is_null());
}

TEST(GraspLoad, AboveTheLawsLimitItWarns) {
  Scenario sc = shipped("tumbling_box_capture");
  sc.simulation.duration = 1.0;
  const OperationResult free_run = runCaptureOperation(sc);
  const double f = free_run.record.grasp.force, n = free_run.record.grasp.moment;
  ASSERT_GT(f, 0.0);
  ASSERT_GT(n, 0.0);
  const auto overloads = [](const OperationResult& r) {
    int k = 0;
    for (const Diagnostic& d : r.warnings) k += d.kind == "grasp_overload";
    return k;
  };
  EXPECT_EQ(overloads(free_run), 0) << "no limit given";
  sc.max_grasp_force = 1.01 * f;
  sc.max_grasp_moment = 1.01 * n;
  const OperationResult within = runCaptureOperation(sc);
  EXPECT_EQ(overloads(within), 0);
  const report::Json j = report::operationJson(sc, within, {}).at("simulation").at("grasp_load");
  EXPECT_NEAR(j.at("force_fraction_of_limit").get<double>(), 1.0 / 1.01, 1e-12);
  EXPECT_NEAR(j.at("moment_fraction_of_limit").get<double>(), 1.0 / 1.01, 1e-12);
  EXPECT_EQ(j.at("peak_force").get<double>(), f);
  sc.max_grasp_moment = 0.5 * n;
  const OperationResult over = runCaptureOperation(sc);
  ASSERT_EQ(overloads(over), 1);
  for (const Diagnostic& d : over.warnings)
    if (d.kind == "grasp_overload") {
      EXPECT_EQ(d.element, "law.max_grasp_wrench");
      EXPECT_NE(d.message.find("law.max_grasp_wrench.moment"), std::string::npos) << d.message;
      EXPECT_EQ(d.message.find("law.max_grasp_wrench.force"), std::string::npos) << d.message;
    }
}

}  // namespace
}  // namespace kdl_space::test
