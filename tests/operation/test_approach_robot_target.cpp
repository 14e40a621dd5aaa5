// The approach of a free-floating robot target (issue 28): the target's motion during the approach
// (FloatingApproachTarget) against the Simulator run alone on the target, its momentum kept, the
// grasp twist against the grasp frame's motion; the whole operation (approach, capture at the
// contact instant, joined motion) against its parts solved by hand; the scenario's refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/simulation/approach_target.hpp"
#include "test_util.hpp"

namespace kdl_space {
namespace {

using test::near;

std::string scenarioPath(const std::string& name) { return std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/" + name; }

const FloatingSystem& robotTarget(const Scenario& sc) { return std::get<FloatingSystem>(sc.capture.target); }

/// The target's momentum (P; L about the world origin) at a state.
Vector6d momentumOf(const FloatingSystem& t, const State& state, const FloatingVelocity& v) {
  Kinematics kin(*t.model);
  EXPECT_EQ(forwardKinematics(*t.model, state, kin), E_NOERROR);
  MomentumSolver m(t.model);
  EXPECT_EQ(m.compute(kin, v), E_NOERROR);
  return m.momentum();
}

/// The target alone: a free Simulator with the scenario's options, integrated in one run.
SimulationState aloneTo(const Scenario& sc, double t) {
  const FloatingSystem& target = robotTarget(sc);
  Simulator sim(target.model, sc.simulation.options);
  SimulationState s;
  s.state = target.state;
  s.velocity = target.velocity;
  EXPECT_EQ(sim.run(s, t, 0.05, {}), E_NOERROR);
  return s;
}

FloatingApproachTarget motionOf(const Scenario& sc) {
  const FloatingSystem& target = robotTarget(sc);
  SimulationState start;
  start.state = target.state;
  start.velocity = target.velocity;
  return FloatingApproachTarget(std::make_unique<Simulator>(target.model, sc.simulation.options), start,
                                target.contact.body);
}

void expectSameState(const SimulationState& a, const SimulationState& b, double tol, const char* what) {
  EXPECT_TRUE(near(a.state.q.data, b.state.q.data, tol, tol, what));
  EXPECT_TRUE(near(a.velocity.qdot.data, b.velocity.qdot.data, tol, tol, what));
  EXPECT_TRUE(near(toEigen(a.state.world_T_base.p), toEigen(b.state.world_T_base.p), tol, tol, what));
  EXPECT_LT((a.state.world_T_base.M * b.state.world_T_base.M.Inverse()).GetRot().Norm(), tol) << what;
  EXPECT_TRUE(near(toEigen(a.velocity.base_twist), toEigen(b.velocity.base_twist), tol, tol, what));
}

TEST(ApproachRobotTarget, TargetMotionIsTheSimulatorsAloneAndKeepsItsMomentum) {
  const Scenario sc = loadScenario(scenarioPath("approach_robot_target.yaml"));
  FloatingApproachTarget motion = motionOf(sc);
  const FloatingSystem& target = robotTarget(sc);
  const Vector6d h0 = momentumOf(target, target.state, target.velocity);
  // Asked out of order, the same time twice: a function of t alone.
  SimulationState a, b, c;
  ASSERT_EQ(motion.state(1.2345, a), E_NOERROR);
  ASSERT_EQ(motion.state(0.3, b), E_NOERROR);
  ASSERT_EQ(motion.state(1.2345, c), E_NOERROR);
  EXPECT_EQ(a.state.q.data, c.state.q.data);
  EXPECT_EQ(a.velocity.qdot.data, c.velocity.qdot.data);
  EXPECT_EQ(a.t, 1.2345);
  // The Simulator alone in one run: the same motion to its tolerances (rtol 1e-10 over ~1 s).
  expectSameState(a, aloneTo(sc, 1.2345), 1e-8, "at 1.2345 s");
  expectSameState(b, aloneTo(sc, 0.3), 1e-8, "at 0.3 s");
  // The target moves (its joints swing, its base turns), and keeps its momentum to round-off.
  EXPECT_GT((a.state.q.data - target.state.q.data).norm(), 1e-3);
  const Vector6d h = momentumOf(target, a.state, a.velocity);
  EXPECT_TRUE(near(h, h0, 1e-12, 1e-12 * h0.norm(), "the free target's momentum"));
  SimulationState before;
  EXPECT_EQ(motion.state(-1e-3, before), E_BAD_ARGUMENT);
}

TEST(ApproachRobotTarget, GraspTwistIsTheGraspFramesRateOfChange) {
  const Scenario sc = loadScenario(scenarioPath("approach_robot_target.yaml"));
  FloatingApproachTarget motion = motionOf(sc);
  const KDL::Frame grasp(KDL::Rotation::RPY(0.3, -0.2, 0.1), KDL::Vector(0.02, -0.01, 0.03));
  const double t = 0.8, h = 1e-4;
  KDL::Frame g, gm, gp;
  Vector6d twist, unused;
  ASSERT_EQ(motion.grasp(t, grasp, g, twist), E_NOERROR);
  ASSERT_EQ(motion.grasp(t - h, grasp, gm, unused), E_NOERROR);
  ASSERT_EQ(motion.grasp(t + h, grasp, gp, unused), E_NOERROR);
  // Central differences: O(h^2 |accel|) ~ 1e-10, plus the integration's 1e-10 / h.
  const Vector3d v = toEigen(gp.p - gm.p) / (2 * h);
  const Vector3d w = toEigen((gp.M * gm.M.Inverse()).GetRot()) / (2 * h);
  EXPECT_TRUE(near(twist.head<3>(), v, 1e-6, 1e-8, "the grasp point's velocity"));
  EXPECT_TRUE(near(twist.tail<3>(), w, 1e-6, 1e-8, "the contact link's angular velocity"));
  EXPECT_GT(twist.norm(), 1e-3);  // it moves
}

class ApproachRobotTargetRun : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scenario_ = std::make_unique<Scenario>(loadScenario(scenarioPath("approach_robot_target.yaml")));
    OperationOptions o;
    o.duration = 1.0;
    result_ = std::make_unique<OperationResult>(runCaptureOperation(*scenario_, o));
  }
  static void TearDownTestSuite() {
    result_.reset();
    scenario_.reset();
  }
  static std::unique_ptr<Scenario> scenario_;
  static std::unique_ptr<OperationResult> result_;
};
std::unique_ptr<Scenario> ApproachRobotTargetRun::scenario_;
std::unique_ptr<OperationResult> ApproachRobotTargetRun::result_;

TEST_F(ApproachRobotTargetRun, TheHandReachesTheMovingTargetsContactPoint) {
  const Scenario& sc = *scenario_;
  const OperationResult& r = *result_;
  ASSERT_TRUE(r.approach);
  ASSERT_TRUE(r.approach->record.reached);
  const double t = r.t_capture;
  EXPECT_GT(t, 0.5);  // it started away from the grasp
  EXPECT_EQ(r.approach->record.t_contact, t);
  // The robot's hand and the target's contact point at the contact instant: within 0.5 mm (half
  // the capture's touch tolerance: the approach's default position tolerance for a robot target).
  const FloatingSystem& robot = r.at_contact.robot;
  const FloatingSystem& target = std::get<FloatingSystem>(r.at_contact.target);
  Kinematics kr(*robot.model), kt(*target.model);
  ASSERT_EQ(forwardKinematics(*robot.model, robot.state, kr), E_NOERROR);
  ASSERT_EQ(forwardKinematics(*target.model, target.state, kt), E_NOERROR);
  EXPECT_LE((kr.point(robot.contact) - kt.point(target.contact)).norm(), 0.5e-3 * (1.0 + 1e-9));
  // At the start they were far apart.
  Kinematics kr0(*robot.model), kt0(*target.model);
  ASSERT_EQ(forwardKinematics(*robot.model, sc.capture.robot.state, kr0), E_NOERROR);
  ASSERT_EQ(forwardKinematics(*target.model, robotTarget(sc).state, kt0), E_NOERROR);
  EXPECT_GT((kr0.point(robot.contact) - kt0.point(target.contact)).norm(), 0.05);
  // The target at the contact instant: its free motion integrated alone to then, its momentum kept.
  SimulationState at;
  at.state = target.state;
  at.velocity = target.velocity;
  expectSameState(at, aloneTo(sc, t), 1e-8, "the target at the contact instant");
  const FloatingSystem& t0 = robotTarget(sc);
  const Vector6d h0 = momentumOf(t0, t0.state, t0.velocity);
  EXPECT_TRUE(near(momentumOf(target, target.state, target.velocity), h0, 1e-12, 1e-12 * h0.norm(),
                   "the target's momentum over the approach"));
}

TEST_F(ApproachRobotTargetRun, CaptureAtTheContactInstantAndTheJoinedMotionFollow) {
  const OperationResult& r = *result_;
  ASSERT_TRUE(r.capture);
  // The capture is the paper's law at the states of the contact instant.
  const CaptureResult by_hand = solveCapture(r.at_contact);
  EXPECT_TRUE(near(r.capture->impulse.F, by_hand.impulse.F, 1e-12, 1e-12, "impulse"));
  ASSERT_TRUE(r.capture->floating_target);
  EXPECT_GT(r.capture->impulse.F.norm(), 0.0);
  // Joined (a rigid capture of a free-floating target), moving on from the capture with the
  // momentum both sides had before it.
  ASSERT_TRUE(r.joined);
  ASSERT_GT(r.record.samples, 0);
  EXPECT_EQ(r.record.first.t, r.t_capture);
  EXPECT_NEAR(r.end.t, r.t_capture + 1.0, 1e-12);
  // The capture keeps the momentum exactly; the join welds the target's contact point to the
  // robot's, which the approach brought within d (<= 1 mm): each target body's velocity in the
  // joined system is off by w x d (w: the common angular velocity after), so its linear momentum
  // by at most m_target |w| |d|. The joined motion then keeps it (no external force).
  // (The impulse acts at the robot's contact point and its opposite at the target's, d apart: the
  // angular momentum changes by at most |d| |f|.)
  const double scale = by_hand.momentum_before.norm();
  EXPECT_TRUE(near(by_hand.momentum_after.head<3>(), by_hand.momentum_before.head<3>(), 1e-12, 1e-12 * scale,
                   "linear momentum through the capture"));
  const FloatingSystem& robot = r.at_contact.robot;
  const FloatingSystem& target = std::get<FloatingSystem>(r.at_contact.target);
  Kinematics kr(*robot.model), kt(*target.model);
  ASSERT_EQ(forwardKinematics(*robot.model, robot.state, kr), E_NOERROR);
  ASSERT_EQ(forwardKinematics(*target.model, target.state, kt), E_NOERROR);
  const double gap = (kr.point(robot.contact) - kt.point(target.contact)).norm();
  double m_target = 0.0;
  for (const Body& b : target.model->bodies()) m_target += b.mass;
  EXPECT_LE((by_hand.momentum_after.tail<3>() - by_hand.momentum_before.tail<3>()).norm(),
            gap * by_hand.impulse.F.head<3>().norm() * (1 + 1e-9) + 1e-12);
  const double w = r.capture->robot.contact_twist_after.tail<3>().norm();
  EXPECT_LE((r.record.first.h.head<3>() - by_hand.momentum_before.head<3>()).norm(), 1.001 * m_target * w * gap + 1e-12);
  EXPECT_TRUE(near(r.record.last.h, r.record.first.h, 1e-9, 1e-9 * scale, "momentum over the joined motion"));
  // The approach's samples come first, the last at the contact instant.
  ASSERT_FALSE(r.approach_samples.empty());
  EXPECT_EQ(r.approach_samples.back().t, r.t_capture);
  EXPECT_EQ(r.approach_samples.back().phase, Phase::Capture);
}

TEST(ApproachRobotTarget, TheTargetsBrakesHoldDuringTheApproach) {
  // approach_robot_target.yaml with the target's elbow braked (target.locked): its own simulator
  // keeps it braked while it moves; the capture takes it braked.
  std::ifstream in(scenarioPath("approach_robot_target.yaml"));
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const std::string qdot = "  qdot: {joint1: 0.03, joint2: -0.02}\n";
  ASSERT_NE(yaml.find(qdot), std::string::npos);
  yaml.replace(yaml.find(qdot), qdot.size(), "  qdot: {joint1: 0.03}\n  locked: [joint2]\n");
  for (std::size_t at; (at = yaml.find("../urdf/")) != std::string::npos;) yaml.replace(at, 8, test::urdfDir() + "/");
  const std::string path = ::testing::TempDir() + "approach_robot_locked_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(path) << yaml;
  const Scenario sc = loadScenario(path);
  std::filesystem::remove(path);
  OperationOptions o;
  o.duration = 0.1;
  const OperationResult r = runCaptureOperation(sc, o);
  ASSERT_TRUE(r.approach && r.approach->record.reached);
  const FloatingSystem& start = robotTarget(sc);
  const FloatingSystem& at = std::get<FloatingSystem>(r.at_contact.target);
  const int elbow = start.model->jointIndex("joint2"), shoulder = start.model->jointIndex("joint1");
  EXPECT_EQ(at.state.q(elbow), start.state.q(elbow));
  EXPECT_EQ(at.velocity.qdot(elbow), 0.0);
  EXPECT_GT(std::abs(at.state.q(shoulder) - start.state.q(shoulder)), 1e-3);  // the free joint moved
  ASSERT_TRUE(r.capture && r.capture->floating_target);
  EXPECT_EQ(r.capture->floating_target->after.qdot(elbow), 0.0);  // braked through the capture too
}

// --- The scenario's refusals -----------------------------------------------------------------

std::string withApproach(const std::string& approach, const std::string& extra_target = "") {
  std::ifstream in(scenarioPath("robot_to_robot_capture.yaml"));
  std::stringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  if (!extra_target.empty()) {
    const std::string key = "  contact: {link: hand}\n";
    text.insert(text.find(key) + key.size(), extra_target);
  }
  for (std::size_t at; (at = text.find("../urdf/")) != std::string::npos;) text.replace(at, 8, test::urdfDir() + "/");
  const std::string path = ::testing::TempDir() + "approach_robot_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(path) << text << approach;
  return path;
}

std::string refusal(const std::string& path) {
  try {
    loadScenario(path);
  } catch (const InputError& e) {
    std::filesystem::remove(path);
    return e.what();
  }
  std::filesystem::remove(path);
  return "";
}

TEST(ApproachRobotTargetScenario, GraspIsTheContactLinksAndRefusedOffTheContactPoint) {
  const std::string ok = withApproach("approach:\n  grasp: {rpy: [0, 0, 0.5]}\n");
  const Scenario sc = loadScenario(ok);
  std::filesystem::remove(ok);
  ASSERT_TRUE(sc.approach);
  EXPECT_EQ(sc.approach->position_tolerance, 0.5 * sc.capture.touch_tolerance);  // 0.5 mm by default
  EXPECT_TRUE(near(toEigen(sc.approach->grasp.p), toEigen(robotTarget(sc).contact.offset), 0, 0, "grasp origin"));
  // The pictures' grasp frame is in the target's base frame: the contact link's pose then.
  const FloatingSystem& t = robotTarget(sc);
  Kinematics kin(*t.model);
  ASSERT_EQ(forwardKinematics(*t.model, t.state, kin), E_NOERROR);
  ASSERT_TRUE(sc.grasp_frame);
  const KDL::Frame expected = t.state.world_T_base.Inverse() * kin.pose(t.contact.body) * sc.approach->grasp;
  EXPECT_TRUE(KDL::Equal(*sc.grasp_frame, expected, 1e-12));

  const std::string off = refusal(withApproach("approach:\n  grasp: {position: [0.1, 0, 0]}\n"));
  EXPECT_NE(off.find("approach.grasp.position"), std::string::npos) << off;
  EXPECT_NE(off.find("target.contact.offset"), std::string::npos) << off;
  const std::string loose = refusal(withApproach("approach:\n  grasp: {}\n  tolerance: {position: 0.005}\n"));
  EXPECT_NE(loose.find("approach.tolerance.position"), std::string::npos) << loose;
  EXPECT_NE(loose.find("less than 0.001"), std::string::npos) << loose;
  const std::string placed = refusal(withApproach("approach:\n  grasp: {}\n", "  place: touch\n"));
  EXPECT_NE(placed.find("target.place"), std::string::npos) << placed;
}

}  // namespace
}  // namespace kdl_space
