// `kdl_space simulate` of an approach to a free-floating robot target (issue 28) against
// `kdl_space capture` of a scenario written from the states the run reports at the contact
// instant: the same mathematics, so the same impulse and velocities after, to round-off.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"

namespace kdl_space::test {
namespace {

const std::string kSource = KDL_SPACE_SOURCE_DIR;

/// A system of a `kdl_space capture` scenario at a state the run reported.
nlohmann::json systemAt(const nlohmann::json& state, const std::string& urdf, const nlohmann::json& contact) {
  return {{"urdf", urdf},
          {"contact", contact},
          {"base", {{"position", state.at("base_position")}, {"rpy", state.at("base_rpy")}, {"twist", state.at("base_twist")}}},
          {"q", state.at("q")},
          {"qdot", state.at("qdot")}};
}

/// Every number of `a` within tol (relative to the largest of b's numbers at that key) of b's.
void expectNumbersNear(const nlohmann::json& a, const nlohmann::json& b, double tol, const std::string& where) {
  ASSERT_EQ(a.type(), b.type()) << where;
  if (a.is_number()) {
    EXPECT_NEAR(a.get<double>(), b.get<double>(), tol) << where;
  } else if (a.is_array() || a.is_object()) {
    ASSERT_EQ(a.size(), b.size()) << where;
    for (auto it = a.begin(); it != a.end(); ++it) {
      const std::string key = a.is_object() ? it.key() : std::to_string(std::distance(a.begin(), it));
      expectNumbersNear(*it, a.is_object() ? b.at(it.key()) : b.at(std::distance(a.begin(), it)), tol, where + "." + key);
    }
  }
}

TEST(ApproachRobotTargetTool, CaptureAtTheReportedContactStatesIsTheOperationsCapture) {
  const ToolRun run = kdlSpace("simulate " + kSource + "/scenarios/approach_robot_target.yaml --duration 0.5 --json");
  ASSERT_EQ(run.rc, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  const nlohmann::json& approach = j.at("approach");
  ASSERT_TRUE(approach.at("reached").get<bool>());
  const nlohmann::json& at = approach.at("states_at_contact");
  EXPECT_EQ(at.at("t"), approach.at("t_contact"));
  ASSERT_TRUE(at.at("target").is_object());
  ASSERT_TRUE(j.at("simulation").at("target_joined").is_object());  // the joined motion followed

  // The same capture as `kdl_space capture` (a JSON file is a scenario too).
  const nlohmann::json scenario = {
      {"robot", systemAt(at.at("robot"), kSource + "/urdf/space_arm7.urdf",
                         {{"link", "end_effector"}, {"offset", {0, 0, 0.05}}})},
      {"target", systemAt(at.at("target"), kSource + "/urdf/spacedyn_twolink.urdf", {{"link", "hand"}})},
      {"law", {{"type", "capture"}}}};
  const std::string file = scratchIn("kdl_space_approach_robot", "at_contact.json");
  spit(file, scenario.dump());
  const ToolRun cap = kdlSpace("capture " + file + " --json");
  ASSERT_EQ(cap.rc, 0) << cap.err;
  const nlohmann::json c = nlohmann::json::parse(cap.out);
  const nlohmann::json& o = j.at("capture");
  expectNumbersNear(o.at("impulse"), c.at("impulse"), 1e-9, "impulse");
  for (const char* side : {"robot", "target"})
    for (const char* key : {"base_twist_before", "base_twist_after", "qdot_before", "qdot_after"})
      expectNumbersNear(o.at(side).at(key), c.at(side).at(key), 1e-9, std::string(side) + "." + key);
  expectNumbersNear(o.at("momentum_after"), c.at("momentum_after"), 1e-9, "momentum_after");
  EXPECT_GT(std::abs(c.at("impulse").at(0).get<double>()) + std::abs(c.at("impulse").at(1).get<double>()) +
                std::abs(c.at("impulse").at(2).get<double>()),
            0.0);
}

}  // namespace
}  // namespace kdl_space::test
