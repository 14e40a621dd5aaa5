// `kdl_space ik` end to end: a pose made by forward kinematics of a known in-limit configuration
// (KDL's tree solver, not the tool's route) is reached to 1e-9; the JSON's keys; the text lists
// the joints by name; an out-of-reach pose exits 3 with how far it came; usage mistakes exit 2.
#include <gtest/gtest.h>

#include <kdl/treefksolverpos_recursive.hpp>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
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

TEST(IkTool, UsageMistakesExit2) {
  EXPECT_EQ(kdlSpace("ik " + kScenario).rc, 2);                            // no --position
  EXPECT_EQ(kdlSpace("ik " + kScenario + " --position 1,2").rc, 2);       // two numbers
  const ToolRun run = kdlSpace("ik " + kScenario + " --position 1,2,3 --prefer elbow=1");
  EXPECT_EQ(run.rc, 2);
  EXPECT_NE(run.err.find("--prefer"), std::string::npos) << run.err;
}

}  // namespace
}  // namespace kdl_space::test
