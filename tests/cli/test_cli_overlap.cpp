// The overlap warning where a user sees it (issue 27, item 6): a robot link inside its target's
// box of inertia at the capture (`capture`, `simulate`) and at the start of an approach, on stderr
// ("kdl_space: warning: LINK: ...") and in the JSON's warnings (kind overlap, link, depth, moment);
// the link that holds the contact is not checked; the shipped scenarios do not warn.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_runner.hpp"

namespace kdl_space::test {
namespace {

std::string write(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

/// A base (a 1 m cube of visual around its origin), a stick link1 (visual 0.1 x 0.1 x 1, z from
/// 0.5 to 1.5 at q = 0) and a hand link2 (z from 1.5 to 2). Each test writes its own copy (`name`):
/// ctest runs the tests of this file side by side, and one copy rewritten while another test reads
/// it is an empty file.
std::string stickArm(const std::string& name) {
  const char* inertial = R"(<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>)";
  return write(name + "_stick_arm.urdf",
               std::string(R"(<robot name="stick">
  <link name="base">)") + R"(<inertial><mass value="100"/><inertia ixx="10" iyy="10" izz="10" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="1 1 1"/></geometry></visual></link>
  <link name="link1">)" + inertial + R"(<visual><origin xyz="0 0 0.5"/><geometry><box size="0.1 0.1 1"/></geometry></visual></link>
  <link name="link2">)" + inertial + R"(<visual><origin xyz="0 0 0.25"/><geometry><cylinder radius="0.05" length="0.5"/></geometry></visual></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="link1"/><origin xyz="0 0 0.5"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="link1"/><child link="link2"/><origin xyz="0 0 1"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
</robot>)");
}

/// The stick arm holding a 12 kg target whose box of inertia is a 2 m cube (I = m (2^2 + 2^2) / 12
/// = 8) centred at z = `z`: at z = 1.6 it spans z 0.6..2.6, x and y -1..1: link1 (0.5..1.5, 0.1
/// wide) is in it, 0.9 deep (out downwards: 1.5 - 0.6; sideways 1 + 0.05, upwards 2.6 - 0.5);
/// the base (up to z 0.5) is 0.1 below it; link2 holds the contact.
std::string swallowed(const std::string& name, const std::string& extra = "") {
  return write(name, "robot:\n  urdf: " + stickArm(name) +
                         "\n  contact: {link: link2, offset: [0, 0, 0.5]}\n"
                         "target:\n  mass: 12\n  inertia: [[8, 0, 0], [0, 8, 0], [0, 0, 8]]\n"
                         "  pose: {position: [0, 0, 1.6]}\n  twist: [0.01, 0, 0, 0, 0, 0]\n"
                         "law: {type: capture}\nsimulation: {duration: 0.1, output_step: 0.05}\n" + extra);
}

std::size_t count(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

TEST(OverlapWarning, ALinkInsideTheTargetIsWarnedAtTheCaptureWithItsDepth) {
  const std::string sc = swallowed("overlap_capture.yaml");
  const ToolRun run = kdlSpace("capture " + sc);
  ASSERT_EQ(run.rc, 0) << run.err;
  EXPECT_EQ(count(run.err, "kdl_space: warning: link1: at the capture: link 'link1' (its visuals' bounding boxes) "
                           "penetrates the target's box of inertia by 0.9 m"), 1u) << run.err;
  EXPECT_EQ(count(run.err, "overlap"), 0u) << run.err;  // the message says it in words
  EXPECT_EQ(count(run.err, "kdl_space: warning:"), 1u) << run.err;  // not the base (apart), not link2 (the hand)
  const ToolRun json = kdlSpace("capture " + sc + " --json");
  ASSERT_EQ(json.rc, 0) << json.err;
  EXPECT_EQ(json.err, "");
  const nlohmann::json w = nlohmann::json::parse(json.out).at("warnings");
  ASSERT_EQ(w.size(), 1u) << w.dump();
  EXPECT_EQ(w[0].at("kind"), "overlap");
  EXPECT_EQ(w[0].at("element"), "link1");
  EXPECT_EQ(w[0].at("link"), "link1");
  EXPECT_EQ(w[0].at("target"), "target");
  EXPECT_EQ(w[0].at("moment"), "capture");
  EXPECT_EQ(w[0].at("geometry"), "visuals");
  EXPECT_NEAR(w[0].at("depth").get<double>(), 0.9, 1e-9);
}

TEST(OverlapWarning, SimulateWarnsAtTheCaptureInTextAndJson) {
  const std::string sc = swallowed("overlap_simulate.yaml");
  const ToolRun run = kdlSpace("simulate " + sc);
  ASSERT_EQ(run.rc, 0) << run.err;
  EXPECT_EQ(count(run.err, "kdl_space: warning: link1: at the capture: link 'link1'"), 1u) << run.err;
  const ToolRun json = kdlSpace("simulate " + sc + " --json");
  ASSERT_EQ(json.rc, 0) << json.err;
  const nlohmann::json w = nlohmann::json::parse(json.out).at("warnings");
  ASSERT_EQ(w.size(), 1u) << w.dump();
  EXPECT_EQ(w[0].at("kind"), "overlap");
  EXPECT_NEAR(w[0].at("depth").get<double>(), 0.9, 1e-9);
}

TEST(OverlapWarning, TheTargetMovedAwayWarnsNoMore) {
  // At z = 2.55 the cube spans 1.55..3.55: link1 (up to 1.5) is 0.05 below it.
  std::ifstream in(swallowed("overlap_apart_src.yaml"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find("[0, 0, 1.6]"), 11, "[0, 0, 2.55]");
  const ToolRun run = kdlSpace("capture " + write("overlap_apart.yaml", text));
  ASSERT_EQ(run.rc, 0) << run.err;
  EXPECT_EQ(run.err, "");
}

TEST(OverlapWarning, AnApproachWarnsOfItsStartPoseBeforeItRuns) {
  // The start pose, warned of before the approach runs (its grasp is where the hand starts).
  const std::string sc = swallowed("overlap_approach.yaml",
                                   "approach:\n  grasp: {position: [0, 0, 0.4]}\n  track: position\n  gain: 1.0\n"
                                   "  tolerance: {position: 0.001}\n  max_duration: 0.05\n");
  const ToolRun run = kdlSpace("simulate " + sc);
  EXPECT_EQ(count(run.err, "kdl_space: warning: link1: at the start of the approach: link 'link1' (its visuals' "
                           "bounding boxes) penetrates the target's box of inertia by 0.9 m"), 1u) << run.err;
}

TEST(OverlapWarning, NoShippedScenarioWarns) {
  // dual_arm_captures_robot.yaml places the target robot so that its hand touches the tool; its
  // base's yaw turns the target robot away from the servicer (at yaw 0 the two satellites' boxes of
  // inertia overlapped by 0.34 m: this check found it).
  const std::string dir = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/";
  int runs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".yaml" || entry.path().filename().string().rfind("study_", 0) == 0) continue;
    SCOPED_TRACE(entry.path().string());
    const ToolRun run = kdlSpace("simulate " + entry.path().string() + " --duration 0.05 --json");
    ASSERT_EQ(run.rc, 0) << run.err;
    ++runs;
    const nlohmann::json j = nlohmann::json::parse(run.out);
    for (const nlohmann::json& w : j.at("warnings")) EXPECT_NE(w.at("kind"), "overlap") << w.dump();
  }
  EXPECT_GE(runs, 14);
}

}  // namespace
}  // namespace kdl_space::test
