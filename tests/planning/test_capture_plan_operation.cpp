// planCapture's operation objectives (what the bus feels over the motion after the capture): the
// optimum against a dense grid of the same objective, each grid point's motion run through the
// public operation (runOperationFrom) and its peaks read here from the samples; the measures
// against their definitions (attitude from the quaternions, the settling band, the torques); the
// momentum-determined rate against the stack's inertia summed body by body; the refusals.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <regex>
#include <unistd.h>

#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/operation/motion_measures.hpp"
#include "kdl_space/planning/capture_plan.hpp"
#include "kdl_space/study/study.hpp"
#include "arm_variants.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

const std::string kDefault = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/tumbling_box_capture.yaml";
constexpr double kHorizon = 2.0;

/// The tumbling-box scenario on a variant of the bundled arm: its URDF through `edit`, both
/// written in a folder of this test process named `tag`.
template <typename Edit>
std::string defaultOn(const std::string& tag, Edit edit, const std::string& law = "") {
  const std::string dir = ::testing::TempDir() + tag + "_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  std::ifstream in(std::string(KDL_SPACE_SOURCE_DIR) + "/urdf/space_arm7.urdf");
  std::ofstream(dir + "/arm7.urdf") << edit(std::string(std::istreambuf_iterator<char>(in), {}));
  std::ifstream scenario(kDefault);
  const std::string text(std::istreambuf_iterator<char>(scenario), {});
  std::string sc = std::regex_replace(text, std::regex("\\.\\./urdf/space_arm7\\.urdf"), dir + "/arm7.urdf");
  if (!law.empty()) sc = std::regex_replace(sc, std::regex("law:\\n  type: capture\\n  normal: [^\\n]*\\n"), "law: " + law + "\n");
  std::ofstream(dir + "/capture.yaml") << sc;
  return dir + "/capture.yaml";
}

/// A heavy arm on a light bus (arm_variants.hpp).
std::string heavyArmOnLightBus() {
  return defaultOn("heavy_arm", [](const std::string& urdf) { return test::heavyArmOnLightBus(urdf); });
}

/// The peak |w| of the base over the motion after a capture at joints `q`, from the samples of the
/// public operation (the scenario's servos holding, kHorizon s), read here; NaN outside the
/// joints' limits or where it fails.
double peakBaseRate(const Scenario& sc, const std::vector<double>& q) {
  CaptureProblem p = sc.capture;
  const FloatingModel& model = *p.robot.model;
  for (unsigned int j = 0; j < model.nj(); ++j) {
    if (q[j] < model.jointProperties()[j].lower || q[j] > model.jointProperties()[j].upper) return NAN;
    p.robot.state.q(j) = q[j];
  }
  OperationOptions o;
  o.duration = kHorizon;
  o.hold_servos = true;
  OperationResult r;
  try {
    r = runOperationFrom(sc, p, o);
  } catch (const Error&) {
    return NAN;
  }
  const CaptureResult& c = *r.capture;
  for (unsigned int j = 0; j < model.nj(); ++j)
    if (std::abs(c.robot.after.qdot(j)) > model.jointProperties()[j].velocity) return NAN;
  double peak = 0.0;
  for (const MotionSample& x : r.samples) peak = std::max(peak, x.twist.tail<3>().norm());
  return peak;
}

/// The plan over the self-motion by peak_base_rate against a 41-point grid of the same box.
void expectNoWorseThanTheGrid(const std::string& scenario) {
  const Scenario sc = loadScenario(scenario);
  PlanOptions o;
  o.weights = {{"peak_base_rate", 1.0}};
  o.self_motion = PlanRange{-1.0, 1.0};
  o.wrist_roll = PlanRange{0.0, 0.0};
  o.horizon = kHorizon;
  o.scan = 9;
  o.polish_starts = 2;
  o.polish_evaluations = 40;
  const CapturePlan plan = planCapture(sc, o);
  ASSERT_TRUE(plan.optimum.feasible);
  ASSERT_TRUE(plan.optimum.motion && plan.nominal.motion);
  EXPECT_EQ(plan.horizon, kHorizon);
  double best = std::numeric_limits<double>::infinity(), worst = 0.0;
  int feasible = 0;
  for (int i = 0; i <= 40; ++i) {
    const double s = -1.0 + 2.0 * i / 40.0;
    const double v = peakBaseRate(sc, selfMotionJoints(sc, s));
    if (std::isnan(v)) continue;
    ++feasible;
    best = std::min(best, v);
    worst = std::max(worst, v);
  }
  ASSERT_GT(feasible, 20);
  EXPECT_LE(plan.optimum.objective, best * (1.0 + 1e-12));
  EXPECT_EQ(plan.optimum.objective, plan.optimum.motion->peak_base_rate);
  // The objective varies over the box, so a search that did nothing would show.
  EXPECT_GT(worst, best * 1.01);
  // The optimum's joints reproduce its prediction through the operation, read here.
  EXPECT_NEAR(peakBaseRate(sc, plan.q), plan.optimum.motion->peak_base_rate, 1e-12 * plan.optimum.objective);
  // And the nominal's is the scenario's as written.
  std::vector<double> q0(sc.capture.robot.model->nj());
  for (unsigned int j = 0; j < q0.size(); ++j) q0[j] = sc.capture.robot.state.q(j);
  EXPECT_NEAR(peakBaseRate(sc, q0), plan.nominal.motion->peak_base_rate, 1e-12 * plan.nominal.motion->peak_base_rate);
}

TEST(CapturePlanOperation, DefaultArmPeakBaseRateNoWorseThanA41PointGrid) { expectNoWorseThanTheGrid(kDefault); }

TEST(CapturePlanOperation, HeavyArmOnALightBusPeakBaseRateNoWorseThanA41PointGrid) {
  expectNoWorseThanTheGrid(heavyArmOnLightBus());
}

/// The measures of one run, recomputed here from its kept samples by their definitions.
void expectMeasuresOfTheirDefinitions(const Scenario& sc, const OperationResult& r, const MotionMeasures& m, double band) {
  std::vector<const MotionSample*> after;
  for (const MotionSample& x : r.samples) after.push_back(&x);
  ASSERT_GT(after.size(), 10u);
  const MotionSample& first = *after.front();
  const MotionSample& last = *after.back();
  double peak = 0.0, excursion = 0.0, farthest = 0.0;
  const Eigen::Quaterniond q0(first.quat(3), first.quat(0), first.quat(1), first.quat(2));
  for (const MotionSample* x : after) {
    peak = std::max(peak, x->twist.tail<3>().norm());
    const Eigen::Quaterniond q(x->quat(3), x->quat(0), x->quat(1), x->quat(2));
    // The angle of R R0^T from its trace (another route than the quaternions' distance).
    const Eigen::Matrix3d R = q.toRotationMatrix() * q0.toRotationMatrix().transpose();
    excursion = std::max(excursion, std::acos(std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0)));
    farthest = std::max(farthest, (x->twist.tail<3>() - last.twist.tail<3>()).norm());
  }
  double settling = 0.0;
  for (const MotionSample* x : after)
    if ((x->twist.tail<3>() - last.twist.tail<3>()).norm() > band * farthest) settling = x->t - first.t;
  EXPECT_EQ(m.peak_base_rate, peak);
  EXPECT_EQ(m.final_base_rate, last.twist.tail<3>().norm());
  EXPECT_NEAR(m.attitude_excursion, excursion, 1e-7);  // acos near 1 loses half the digits
  EXPECT_GT(excursion, 1e-4);
  EXPECT_EQ(m.settling_time, settling);
  EXPECT_GT(settling, 0.0);
  // The torques: each robot joint's largest |tau| by name, against its effort limit.
  const FloatingModel& robot = *sc.capture.robot.model;
  double ratio = 0.0;
  std::string where;
  for (unsigned int j = 0; j < robot.nj(); ++j) {
    const int k = r.model->jointIndex(robot.jointNames()[j]);
    double tau = 0.0;
    for (const MotionSample* x : after) tau = std::max(tau, std::abs(x->tau(k)));
    EXPECT_EQ(m.peak_torque[j], tau) << robot.jointNames()[j];
    if (tau / robot.jointProperties()[j].effort > ratio) ratio = tau / robot.jointProperties()[j].effort, where = robot.jointNames()[j];
  }
  EXPECT_EQ(m.peak_torque_ratio, ratio);
  EXPECT_EQ(m.peak_torque_joint, where);
  EXPECT_GT(ratio, 0.0);
}

/// The momentum-determined rate by another route: the stack's inertia about its centre of mass
/// summed body by body (KDL's RigidBodyInertia carried to the world), its angular momentum about
/// that centre from the last sample's (P; L about the origin); w = I_c^-1 L_c.
double stackRate(const OperationResult& r) {
  const FloatingModel& model = *r.model;
  Kinematics kin(model);
  EXPECT_EQ(forwardKinematics(model, r.end.state, kin), 0);
  KDL::RigidBodyInertia total = KDL::RigidBodyInertia::Zero();
  for (unsigned int b = 0; b < model.bodies().size(); ++b) {
    const Body& body = model.bodies()[b];
    const Eigen::Matrix3d& I = body.I_com;
    const KDL::RotationalInertia Ic(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2));
    total = total + kin.pose(static_cast<int>(b)) * KDL::RigidBodyInertia(body.mass, toKDL(body.com), Ic);
  }
  const Vector3d c = toEigen(total.getCOG());
  const KDL::RotationalInertia about_c = total.RefPoint(total.getCOG()).getRotationalInertia();
  const Eigen::Matrix3d I_c = Eigen::Map<const Eigen::Matrix3d>(about_c.data);
  const Vector6d h = r.samples.back().h;
  const Vector3d L_c = h.tail<3>() - c.cross(h.head<3>());
  return I_c.ldlt().solve(L_c).norm();
}

TEST(CapturePlanOperation, MeasuresAreTheirDefinitionsOnTheSamples) {
  for (const std::string& file : {kDefault, heavyArmOnLightBus()}) {
    const Scenario sc = loadScenario(file);
    OperationOptions o;
    o.duration = 3.0;
    o.hold_servos = true;
    MotionMeasurer measurer(*sc.capture.robot.model, 0.05);
    o.observer = [&](const OperationResult& so_far, const MotionSample& x) { measurer.add(so_far, x); };
    const OperationResult r = runOperationFrom(sc, sc.capture, o);
    MotionMeasures m;
    ASSERT_EQ(measurer.finish(r, m), 0);
    expectMeasuresOfTheirDefinitions(sc, r, m, 0.05);
    // A rigid capture holds the box: the grasp's load is the samples' largest grasp wrench.
    double force = 0.0, moment = 0.0;
    for (const MotionSample& x : r.samples) {
      force = std::max(force, x.grasp_wrench.head<3>().norm());
      moment = std::max(moment, x.grasp_wrench.tail<3>().norm());
    }
    EXPECT_GT(force, 0.0) << file;
    EXPECT_EQ(m.peak_grasp_force, force) << file;
    EXPECT_EQ(m.peak_grasp_moment, moment) << file;
    const double w = stackRate(r);
    EXPECT_NEAR(m.momentum_rate, w, 1e-9 * w) << file;
    // Servos holding: the joints come nearly to rest, so the base's last rate is near the stack's.
    EXPECT_NEAR(m.final_base_rate, m.momentum_rate, 0.5 * m.momentum_rate) << file;
  }
}

TEST(CapturePlanOperation, CompliantGraspLoadIsTheLargestWrenchOfTheContactAndTheHold) {
  // The tumbling box grasped by a soft compliant hand (the shipped compliant scenario needs its approach).
  const Scenario sc = loadScenario(defaultOn("compliant", [](const std::string& urdf) { return urdf; },
                                             "{type: compliant, stiffness: [2.0e5, 2.0e5, 2.0e5, 2.0e3, 2.0e3, 2.0e3]}"));
  PlanOptions o;
  o.weights = {{"peak_grasp_force", 1.0}, {"peak_base_rate", 100.0}};
  o.self_motion = PlanRange{-0.3, 0.3};
  o.wrist_roll = PlanRange{0.0, 0.0};
  o.horizon = 0.5;
  o.scan = 3;
  o.polish_starts = 0;
  const CapturePlan plan = planCapture(sc, o);
  ASSERT_TRUE(plan.nominal.motion);
  // The nominal by the operation itself: its contact's samples.
  OperationOptions run;
  run.duration = 0.5;
  run.hold_servos = true;
  const OperationResult r = runOperationFrom(sc, sc.capture, run);
  ASSERT_TRUE(r.compliant);
  double force = 0.0, moment = 0.0;
  for (const MotionSample& x : r.contact_samples) {
    force = std::max(force, x.contact_wrench.head<3>().norm());
    moment = std::max(moment, x.contact_wrench.tail<3>().norm());
  }
  for (const MotionSample& x : r.samples) {  // the grasp stays compliant (lock: never) and holds the box
    ASSERT_TRUE(x.grasp_wrench.allFinite()) << "t = " << x.t;
    force = std::max(force, x.grasp_wrench.head<3>().norm());
    moment = std::max(moment, x.grasp_wrench.tail<3>().norm());
  }
  EXPECT_GT(force, 0.0);
  EXPECT_EQ(plan.nominal.motion->peak_grasp_force, force);
  EXPECT_EQ(plan.nominal.motion->peak_grasp_moment, moment);
  // The objective is the weighted sum of its terms.
  const MotionMeasures& m = *plan.optimum.motion;
  EXPECT_NEAR(plan.optimum.objective, m.peak_grasp_force + 100.0 * m.peak_base_rate, 1e-12 * plan.optimum.objective);
  EXPECT_LE(plan.optimum.objective, plan.nominal.objective);
}

TEST(CapturePlanOperation, AHorizonReportsTheMotionWhateverTheObjective) {
  const Scenario sc = loadScenario(kDefault);
  PlanOptions o;
  o.wrist_roll = PlanRange{0.0, 0.0};
  o.scan = 5;
  o.polish_starts = 1;
  const CapturePlan instant = planCapture(sc, o);
  EXPECT_FALSE(instant.optimum.motion);
  EXPECT_EQ(instant.horizon, 0.0);
  o.horizon = 1.0;
  const CapturePlan measured = planCapture(sc, o);
  ASSERT_TRUE(measured.optimum.motion && measured.nominal.motion);
  EXPECT_EQ(measured.q, instant.q);  // the instant objective: the same search, the same optimum
  EXPECT_EQ(measured.evaluations, instant.evaluations);
  EXPECT_GT(measured.optimum.motion->momentum_rate, 0.0);
}

TEST(CapturePlanOperation, RefusesWhatItCannotMeasure) {
  const Scenario sc = loadScenario(kDefault);
  const auto refused = [&](PlanOptions o, const std::string& expected) {
    o.wrist_roll = PlanRange{0.0, 0.0};
    try {
      planCapture(sc, o);
      ADD_FAILURE() << "accepted; expected " << expected;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  PlanOptions o;
  {
    Scenario point = sc;  // a point impact lets the box go: nothing is held
    point.capture.law.kind = ImpactKind::PointImpact;
    point.capture.law.normal = Vector3d(0, -1, 0);
    PlanOptions g;
    g.weights = {{"peak_grasp_force", 1.0}};
    g.wrist_roll = PlanRange{0.0, 0.0};
    try {
      planCapture(point, g);
      ADD_FAILURE() << "a point impact's grasp load was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("objective: peak_grasp_force is the load of a grasp that holds the target"),
                std::string::npos)
          << e.what();
    }
  }
  o.weights = {{"peak_base_rate", 1.0}};
  o.horizon = 0.0;
  refused(o, "horizon: must be finite and > 0");
  o.horizon = std::nan("");
  refused(o, "horizon: must be finite and > 0");
  o.horizon = 1.0;
  o.settling_band = 1.0;
  refused(o, "settling_band: must lie in (0, 1)");
  o.settling_band = 0.05;
  o.output_step = -1.0;
  refused(o, "output_step: must be finite and > 0");
  o.output_step.reset();
  o.weights = {{"peak_torque_ratio", 1.0}};
  const Scenario no_effort = loadScenario(defaultOn("no_effort", [](const std::string& urdf) {
    return std::regex_replace(urdf, std::regex("effort=\"[0-9.]+\""), "effort=\"0\"");
  }));
  try {
    o.wrist_roll = PlanRange{0.0, 0.0};
    planCapture(no_effort, o);
    ADD_FAILURE() << "a torque ratio without effort limits was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("peak_torque_ratio: no joint of the robot has an effort limit"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace kdl_space::test
