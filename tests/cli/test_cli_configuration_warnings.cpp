// The configuration warnings where a user sees them (issue 26, items 1-2): a joint left out of q
// outside its limits and a near-singular J* on stderr ("kdl_space: warning: ...", once each) in
// inspect, capture and simulate; an approach's start pose checked before it runs; the grasp point
// in the target's frame; robot.place: grasp's residual in the capture's output, and its refusal
// with an approach; `ik --prefer reaction`.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.hpp"
#include "kdl_space/multibody/poses.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "kdl_space/report/capture_report.hpp"

namespace kdl_space::test {
namespace {

const std::string kScenarios = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/";

std::size_t count(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

std::string write(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

/// The arm of limits_exclude_zero.urdf (elbow limited to [0.5, 1.5]) with its elbow left out of
/// q: at 0, outside its limits; a rigid target held at the forearm's end.
std::string elbowLeftOut() {
  return write("elbow_left_out.yaml",
               "robot:\n  urdf: " KDL_SPACE_TEST_DATA_DIR "/broken_urdf/limits_exclude_zero.urdf\n"
               "  contact: {link: forearm, offset: [0.8, 0, 0]}\n"
               "  q: {shoulder: 0.2}\n"
               "target:\n  mass: 20\n  inertia: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n"
               "  pose: {position: [1.5, 0.5, 0.5]}\n  twist: [0.01, 0, 0, 0, 0, 0.01]\n"
               "law: {type: capture}\n");
}

TEST(ConfigurationWarnings, AJointLeftOutOfQOutsideItsLimitsIsWarnedOnStderrOnce) {
  const ToolRun run = kdlSpace("capture " + elbowLeftOut());
  ASSERT_EQ(run.rc, 0) << run.err;
  EXPECT_EQ(count(run.err, "kdl_space: warning: elbow: at 0, outside its limits [0.5, 1.5]"), 1u) << run.err;
  EXPECT_NE(run.err.find("a joint left out of q is at 0"), std::string::npos) << run.err;
  const ToolRun json = kdlSpace("capture " + elbowLeftOut() + " --json");
  ASSERT_EQ(json.rc, 0) << json.err;
  EXPECT_EQ(json.err, "");  // a --json run: the warnings are in the JSON
  const nlohmann::json j = nlohmann::json::parse(json.out);
  ASSERT_EQ(j.at("warnings").size(), 1u);
  EXPECT_EQ(j.at("warnings")[0].at("kind"), "joint_outside_limits");
  EXPECT_EQ(j.at("warnings")[0].at("element"), "elbow");
}

TEST(ConfigurationWarnings, InspectAndSimulateWarnOnStderrToo) {
  const ToolRun inspect = kdlSpace("inspect --urdf " KDL_SPACE_TEST_DATA_DIR "/broken_urdf/limits_exclude_zero.urdf --tip forearm --q shoulder=0.1");
  ASSERT_EQ(inspect.rc, 0) << inspect.err;
  EXPECT_EQ(count(inspect.err, "kdl_space: warning: elbow: at 0, outside its limits"), 1u) << inspect.err;
  const std::string plain = write("elbow_left_out_motion.yaml",
                                  "robot:\n  urdf: " KDL_SPACE_TEST_DATA_DIR "/broken_urdf/limits_exclude_zero.urdf\n"
                                  "  contact: {link: forearm, offset: [0.8, 0, 0]}\n  q: {shoulder: 0.2}\n"
                                  "target:\n  mass: 20\n  inertia: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n"
                                  "  pose: {position: [1.5, 0.5, 0.5]}\n  twist: [0.01, 0, 0, 0, 0, 0.01]\n"
                                  "law: {type: capture}\nsimulation: {duration: 0.1, output_step: 0.05}\n");
  const ToolRun simulate = kdlSpace("simulate " + plain);
  ASSERT_EQ(simulate.rc, 0) << simulate.err;
  EXPECT_EQ(count(simulate.err, "kdl_space: warning: elbow: at 0, outside its limits"), 1u) << simulate.err;
}

TEST(ConfigurationWarnings, NoWarningNoStderr) {
  const ToolRun run = kdlSpace("capture " + kScenarios + "tumbling_box_capture.yaml");
  ASSERT_EQ(run.rc, 0) << run.err;
  EXPECT_EQ(run.err, "");
}

/// scenarios/approach_tumbling_box.yaml from another start pose (robot.q), max_duration capped.
std::string approachFrom(const std::string& name, const std::string& q, double max_duration) {
  std::ifstream in(kScenarios + "approach_tumbling_box.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = text.find("  q: {joint2: 0.7, joint3: 1.1, joint4: 1.1, joint6: -0.6}");
  EXPECT_NE(at, std::string::npos);
  text.replace(at, text.find('\n', at) - at, "  q: " + q);
  const std::size_t d = text.find("max_duration: 30");
  EXPECT_NE(d, std::string::npos);
  text.replace(d, 16, "max_duration: " + std::to_string(max_duration));
  text.replace(text.find("../urdf/"), 8, KDL_SPACE_URDF_DIR "/");
  return write(name, text);
}

// The case (a start pose learned of only when the approach failed): the start is checked
// before the approach runs; here a joint outside its limits, which the approach still runs from.
TEST(ApproachStart, AStartJointOutsideItsLimitsIsInTheJsonAndOnStderr) {
  const ToolRun run = kdlSpace("simulate " +
                               approachFrom("approach_outside.yaml", "{joint2: 0.7, joint3: 1.1, joint4: 1.1, joint6: "
                                                                     "-0.6, joint7: 4.75}", 30) +
                               " --duration 0.1 --json");
  ASSERT_EQ(run.rc, 0) << run.err;
  EXPECT_EQ(count(run.err, "kdl_space: warning: joint7: at the start of the approach: at 4.75, outside its limits"), 1u)
      << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  bool found = false;
  for (const nlohmann::json& w : j.at("warnings"))
    found = found || (w.at("element") == "joint7" &&
                      w.at("message").get<std::string>().rfind("at the start of the approach: ", 0) == 0);
  EXPECT_TRUE(found) << j.at("warnings").dump();
}

/// robot_to_robot_capture.yaml's robot and free-floating target, the robot's arm solved to hold a
/// grasp frame fixed on the target's base (robot.place: grasp) at the target's contact point (its
/// link `hand`, 5 m along the base's x at q = 0: spacedyn_twolink.urdf).
std::string graspOnFloatingTarget(const std::string& extra) {
  return write("grasp_floating" + std::to_string(extra.size()) + ".yaml",
               "robot:\n  urdf: " KDL_SPACE_URDF_DIR "/space_arm7.urdf\n"
               "  contact: {link: end_effector, offset: [0, 0, 0.05]}\n"
               "  q: {joint2: 0.7, joint3: 0.9, joint4: 0.8, joint6: -0.6}\n"
               "  grasp: {target_frame: {position: [5, 0, 0], rpy: [3.0, 0.1, 0.2]}}\n"
               "  place: grasp\n"
               "target:\n  urdf: " KDL_SPACE_URDF_DIR "/spacedyn_twolink.urdf\n  contact: {link: hand}\n"
               "  base: {position: [-4.68, -2.7, 1.6], twist: [0.01, 0.02, 0, 0, 0, 0.01]}\n"
               "law:\n  type: capture\n" + extra);
}

TEST(GraspResidual, CaptureReportsTheGraspSolveAndTheGraspPointInTheTargetsFrame) {
  const ToolRun run = kdlSpace("capture " + graspOnFloatingTarget("") + " --json");
  ASSERT_EQ(run.rc, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  ASSERT_TRUE(j.at("grasp").is_object()) << j.dump();
  EXPECT_LE(j.at("grasp").at("residual_position").get<double>(), 1e-9);
  EXPECT_LE(j.at("grasp").at("residual_rotation").get<double>(), 1e-9);
  EXPECT_GE(j.at("grasp").at("iterations").get<int>(), 1);
  // The angles it solved, by name: at them the contact point is where the capture happened
  const nlohmann::json& solved = j.at("grasp").at("q");
  ASSERT_EQ(solved.size(), 7u) << solved.dump();
  const kdl_space::FloatingModel arm = kdl_space::loadUrdfFile(KDL_SPACE_URDF_DIR "/space_arm7.urdf");
  kdl_space::State at(arm);
  for (auto it = solved.begin(); it != solved.end(); ++it) at.q(arm.jointIndex(it.key())) = it.value().get<double>();
  const KDL::Frame hand = kdl_space::contactFrame(arm, at, arm.contact("end_effector", KDL::Vector(0, 0, 0.05)));
  const std::vector<double> point = j.at("contact_point").get<std::vector<double>>();
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(hand.p(k), point[k], 1e-12);
  // The hand holds the grasp frame: the contact point is the frame's origin in the target's
  // (base) frame, as the scenario wrote it.
  const std::vector<double> p = j.at("contact_point_in_target").get<std::vector<double>>();
  ASSERT_EQ(p.size(), 3u);
  EXPECT_NEAR(p[0], 5.0, 1e-9);
  EXPECT_NEAR(p[1], 0.0, 1e-9);
  EXPECT_NEAR(p[2], 0.0, 1e-9);
  const ToolRun text = kdlSpace("capture " + graspOnFloatingTarget(""));
  ASSERT_EQ(text.rc, 0) << text.err;
  EXPECT_NE(text.out.find("Grasp (robot.place: grasp): the contact frame holds robot.grasp.target_frame to "),
            std::string::npos) << text.out;
  EXPECT_NE(text.out.find("  at joint1 = "), std::string::npos) << text.out;  // the solved angles
  EXPECT_NE(text.out.find("m in the target's frame"), std::string::npos) << text.out;
  // Without robot.place: grasp there is no solve to report.
  const ToolRun plain = kdlSpace("capture " + kScenarios + "robot_to_robot_capture.yaml --json");
  ASSERT_EQ(plain.rc, 0) << plain.err;
  EXPECT_TRUE(nlohmann::json::parse(plain.out).at("grasp").is_null());
}

TEST(GraspResidual, PlaceGraspWithAnApproachIsRefused) {
  const std::string path = write(
      "grasp_and_approach.yaml",
      "robot:\n  urdf: " KDL_SPACE_URDF_DIR "/space_arm7.urdf\n  contact: {link: end_effector, offset: [0, 0, 0.05]}\n"
      "  q: {joint2: 0.7, joint3: 0.9, joint4: 0.8, joint6: -0.6}\n"
      "  grasp: {target_frame: {position: [0.1, 0.0, -0.2], rpy: [3.0, 0.1, 0.2]}}\n  place: grasp\n"
      "target:\n  mass: 50\n  inertia: [[2.1, 0, 0], [0, 2.6, 0], [0, 0, 3.0]]\n"
      "  pose: {position: [0.32, -2.88, 1.69], rpy: [0.3, -0.2, 0.5]}\n"
      "law: {type: capture}\n"
      "approach:\n  grasp: {position: [0.1, 0, -0.2], rpy: [3.0, 0.1, 0.2]}\n  max_duration: 5\n");
  const ToolRun run = kdlSpace("simulate " + path);
  EXPECT_EQ(run.rc, 3) << run.err;
  EXPECT_NE(run.err.find("grasp_and_approach.yaml:6: robot.place: puts the hand at the grasp before anything moves"),
            std::string::npos) << run.err;
}

TEST(IkPreference, ReactionNoWorseThanPostureAndRefusesAPosture) {
  const std::string scenario = kScenarios + "tumbling_box_capture.yaml";
  const std::string goal = " --position 0.4,-0.9,0.9 --rpy 2.5,0.2,-0.4 --json";
  const ToolRun posture = kdlSpace("ik " + scenario + goal);
  const ToolRun reaction = kdlSpace("ik " + scenario + goal + " --prefer reaction");
  ASSERT_EQ(posture.rc, 0) << posture.err;
  ASSERT_EQ(reaction.rc, 0) << reaction.err;
  const nlohmann::json a = nlohmann::json::parse(posture.out), b = nlohmann::json::parse(reaction.out);
  EXPECT_LE(b.at("position_residual").get<double>(), 1e-9);
  EXPECT_LE(b.at("orientation_residual").get<double>(), 1e-9);
  EXPECT_LE(b.at("reaction_measure").get<double>(), a.at("reaction_measure").get<double>());
  const ToolRun both = kdlSpace("ik " + scenario + goal + " --prefer reaction --prefer joint1=0.2");
  EXPECT_EQ(both.rc, 2);
  EXPECT_NE(both.err.find("--prefer reaction"), std::string::npos) << both.err;
}

}  // namespace
}  // namespace kdl_space::test

// A joint outside its limits at a capture says what put it there: after an approach, its controller
// (not robot.q's rule that an omitted joint is at 0, a guess there).
TEST(ConfigurationWarnings, AfterAnApproachTheHintNamesTheApproach) {
  const kdl_space::Scenario sc = kdl_space::loadScenario(KDL_SPACE_SOURCE_DIR "/scenarios/approach_tumbling_box.yaml");
  kdl_space::CaptureProblem p = sc.capture;
  const int j = p.robot.model->jointIndex("joint2");
  ASSERT_GE(j, 0);
  p.robot.state.q(j) = p.robot.model->jointProperties()[j].upper + 0.3;  // where a controller might leave it
  bool said = false;
  for (const kdl_space::Diagnostic& d : kdl_space::report::captureWarnings(sc, p)) {
    if (d.kind != "joint_outside_limits") continue;
    EXPECT_EQ(d.message.find("left out of q"), std::string::npos) << d.message;
    said |= d.message.find("the approach's controller drove it there") != std::string::npos;
  }
  EXPECT_TRUE(said);
}
