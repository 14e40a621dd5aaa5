// `kdl_space ik` end to end: a pose made by forward kinematics of a known in-limit configuration
// (KDL's tree solver, not the tool's route) is reached to 1e-9; the JSON's keys; the text lists
// the joints by name; an out-of-reach pose exits 3 with how far it came; usage mistakes exit 2.
#include <gtest/gtest.h>

#include <kdl/treefksolverpos_recursive.hpp>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "kdl_space/algorithm/inverse_kinematics.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

// scenarios/tumbling_box_capture.yaml: space_arm7, contact end_effector + (0, 0, 0.05), base at the origin.
const std::string kScenario = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/tumbling_box_capture.yaml";

/// The contact frame at `q` (by name) by KDL's tree solver.
KDL::Frame contactFrameByKdl(const std::map<std::string, double>& q_by_name) {
  const FloatingModel model = loadUrdfFile(std::string(KDL_SPACE_URDF_DIR) + "/space_arm7.urdf");
  KDL::JntArray q(model.tree().getNrOfJoints());
  for (const auto& [name, element] : model.tree().getSegments()) {
    const KDL::Joint& j = GetTreeElementSegment(element).getJoint();
    if (j.getType() != KDL::Joint::Fixed) q(GetTreeElementQNr(element)) = q_by_name.at(j.getName());
  }
  KDL::TreeFkSolverPos_recursive fk(model.tree());
  KDL::Frame f;
  EXPECT_GE(fk.JntToCart(q, f, "end_effector"), 0);
  return f * KDL::Frame(KDL::Vector(0, 0, 0.05));
}

std::string triple(double a, double b, double c) {
  std::ostringstream s;
  s.precision(17);
  s << a << "," << b << "," << c;
  return s.str();
}

const std::map<std::string, double> kTruth{{"joint1", 0.3}, {"joint2", 0.8}, {"joint3", -0.7}, {"joint4", 1.1},
                                           {"joint5", -0.4}, {"joint6", 0.6}, {"joint7", 0.2}};

/// --position X,Y,Z --rpy R,P,Y of `goal`.
std::string poseArgs(const KDL::Frame& goal) {
  double r, p, y;
  goal.M.GetRPY(r, p, y);
  return " --position " + triple(goal.p.x(), goal.p.y(), goal.p.z()) + " --rpy " + triple(r, p, y);
}

TEST(IkTool, ReachesAPoseOfAKnownConfigurationTo1e9) {
  const KDL::Frame goal = contactFrameByKdl(kTruth);
  const ToolRun run = kdlSpace("ik " + kScenario + poseArgs(goal) + " --json");
  ASSERT_EQ(run.rc, 0) << run.err;
  EXPECT_EQ(run.err, "");
  const nlohmann::json j = nlohmann::json::parse(run.out);
  for (const char* key : {"scenario", "contact", "goal", "joint_names", "q", "q_by_name", "moved_joints",
                          "position_residual", "orientation_residual", "iterations", "attempts", "preference_gradient"})
    EXPECT_TRUE(j.contains(key)) << key;
  const KDL::Frame reached = contactFrameByKdl(j.at("q_by_name").get<std::map<std::string, double>>());
  // The goal went through 17 significant digits and an RPY round trip: a few 1e-16.
  EXPECT_LE(std::sqrt(KDL::dot(reached.p - goal.p, reached.p - goal.p)), 1e-9);  // KDL's Norm reads < 1e-6 as 0
  const KDL::Rotation E = goal.M.Inverse() * reached.M;  // its angle: atan2(|sin| , cos), exact near 0
  const KDL::Vector sine(E(2, 1) - E(1, 2), E(0, 2) - E(2, 0), E(1, 0) - E(0, 1));
  EXPECT_LE(std::atan2(0.5 * std::sqrt(KDL::dot(sine, sine)), 0.5 * (E(0, 0) + E(1, 1) + E(2, 2) - 1.0)), 1e-9);
  EXPECT_LE(j.at("position_residual").get<double>(), 1e-9);
  EXPECT_LE(j.at("orientation_residual").get<double>(), 1e-9);
  EXPECT_EQ(j.at("contact").at("link"), "end_effector");
  EXPECT_EQ(j.at("moved_joints").size(), 7u);
}

TEST(IkTool, PrintsTheJointAnglesByName) {
  const ToolRun run = kdlSpace("ik " + kScenario + poseArgs(contactFrameByKdl(kTruth)));
  ASSERT_EQ(run.rc, 0) << run.err;
  for (const char* text : {"joint angles", "joint1", "joint7", "residual", "iterations"})
    EXPECT_NE(run.out.find(text), std::string::npos) << text << "\n" << run.out;
}

TEST(IkTool, OutOfReachExits3WithTheRemainingDistance) {
  const ToolRun run = kdlSpace("ik " + kScenario + " --position 50,0,0 --restarts 2");
  EXPECT_EQ(run.rc, 3);
  EXPECT_EQ(run.out, "");
  EXPECT_NE(run.err.find("tumbling_box_capture.yaml"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("out of reach"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find(" m and "), std::string::npos) << run.err;
}

TEST(IkTool, AGoalBeyondTheRangeOfDoublesExits3NotAnAbort) {
  // From ~1e150 m the squared distance overflows: no attempt was recorded, and the message read an
  // empty vector (SIGABRT in Eigen's bounds check). Refused as out of reach, the tool and the place.
  for (const char* position : {"1e200,0,0", "-1e308,1e308,0", "0,0,1e160"}) {
    const ToolRun run = kdlSpace("ik " + kScenario + " --position " + position + " --restarts 1");
    EXPECT_EQ(run.rc, 3) << position << ": " << run.err;
    EXPECT_NE(run.err.find("out of reach"), std::string::npos) << run.err;
  }
}

TEST(IkTool, UsageMistakesExit2) {
  EXPECT_EQ(kdlSpace("ik " + kScenario).rc, 2);                            // no --position
  EXPECT_EQ(kdlSpace("ik " + kScenario + " --position 1,2").rc, 2);       // two numbers
  const ToolRun run = kdlSpace("ik " + kScenario + " --position 1,2,3 --prefer elbow=1");
  EXPECT_EQ(run.rc, 2);
  EXPECT_NE(run.err.find("--prefer"), std::string::npos) << run.err;
}

/// A scenario whose robot holds the rigid target's grasp frame (robot.place: grasp).
std::string graspScenario(const std::string& name, const std::string& target_position) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << "robot:\n  urdf: " << KDL_SPACE_URDF_DIR << "/space_arm7.urdf\n"
                      << "  contact: {link: end_effector, offset: [0, 0, 0.05]}\n"
                      << "  base: {position: [0.1, -0.2, 0.3], rpy: [0.1, 0.2, -0.3]}\n"
                      << "  q: {joint2: 0.7, joint3: 0.9, joint4: 0.8, joint6: -0.6}\n"
                      << "  grasp: {target_frame: {position: [0.1, 0.0, -0.2], rpy: [3.0, 0.1, 0.2]}}\n"
                      << "  place: grasp\n"
                      << "target:\n  mass: 50\n  inertia: [[2.1, 0, 0], [0, 2.6, 0], [0, 0, 3.0]]\n"
                      << "  pose: {position: " << target_position << ", rpy: [0.3, -0.2, 0.5]}\n"
                      << "law: {type: capture}\n";
  return path;
}

TEST(GraspPlacement, TheContactFrameHoldsTheTargetsGraspFrame) {
  const Scenario sc = loadScenario(graspScenario("grasp_ok.yaml", "[0.32, -2.88, 1.69]"));
  ASSERT_TRUE(sc.grasp_solution.has_value());
  const KDL::Frame grasp = KDL::Frame(KDL::Rotation::RPY(0.3, -0.2, 0.5), KDL::Vector(0.32, -2.88, 1.69)) *
                           KDL::Frame(KDL::Rotation::RPY(3.0, 0.1, 0.2), KDL::Vector(0.1, 0.0, -0.2));
  std::map<std::string, double> q;
  const FloatingModel& model = *sc.capture.robot.model;
  for (unsigned int j = 0; j < model.nj(); ++j) q[model.jointNames()[j]] = sc.capture.robot.state.q(j);
  // KDL's tree solver, with the scenario's base pose in front
  const KDL::Frame held = sc.capture.robot.state.world_T_base * contactFrameByKdl(q);
  EXPECT_LE(std::sqrt(KDL::dot(held.p - grasp.p, held.p - grasp.p)), 1e-9);
  const KDL::Rotation E = grasp.M.Inverse() * held.M;
  const KDL::Vector sine(E(2, 1) - E(1, 2), E(0, 2) - E(2, 0), E(1, 0) - E(0, 1));
  EXPECT_LE(std::atan2(0.5 * std::sqrt(KDL::dot(sine, sine)), 0.5 * (E(0, 0) + E(1, 1) + E(2, 2) - 1.0)), 1e-9);
  EXPECT_LE(sc.grasp_solution->position_residual, 1e-9);
  EXPECT_EQ(kdlSpace("capture " + graspScenario("grasp_ok.yaml", "[0.32, -2.88, 1.69]") + " --json").rc, 0);
}

TEST(GraspPlacement, AGraspOutOfReachNamesTheFieldAndTheDistance) {
  for (const char* where : {"[40, 0, 0]", "[1.0e200, 0, 0]"}) {
    const ToolRun run = kdlSpace("capture " + graspScenario("grasp_far.yaml", where));
    EXPECT_EQ(run.rc, 3) << where << ": " << run.err;
    EXPECT_NE(run.err.find("grasp_far.yaml:7: robot.place: the grasp frame: inverse kinematics: the pose is out of reach"),
              std::string::npos) << run.err;
  }
}

}  // namespace
}  // namespace kdl_space::test
