// `kdl_space plan` end to end: the JSON's keys and joint angles by name; the planned joint angles,
// written into a scenario and run through `kdl_space capture`, give the base rate the plan
// reports; the text names the joints; usage mistakes exit 2 naming the option, a scenario
// without a capture exits 3.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "cli_runner.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

const std::string kScenario = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/tumbling_box_capture.yaml";
const std::string kArm6 = dataDir() + "/scenarios/arm6_reach_capture.json";

std::string byName(const nlohmann::json& by_name) {
  std::ostringstream q;
  q.precision(17);
  for (auto it = by_name.begin(); it != by_name.end(); ++it)
    q << (it == by_name.begin() ? "" : ", ") << it.key() << ": " << it.value().get<double>();
  return q.str();
}

/// scenarios/tumbling_box_capture.yaml's capture (its robot, target and law; the motion section
/// dropped, or with `motion` kept with its servos holding) with the joints at `q`, as a file: its `q:` line replaced, its URDF path made absolute;
/// with `qdot` and `base_twist` (not null) its rates before and its base's twist replaced too.
std::string captureScenario(const nlohmann::json& q_by_name, const nlohmann::json& qdot = nullptr,
                            const nlohmann::json& base_twist = nullptr, bool motion = false) {
  const std::string q = byName(q_by_name);
  const std::string path = ::testing::TempDir() + "kdl_space_planned_" + std::to_string(getpid()) + ".yaml";
  std::ifstream in(kScenario);
  std::ofstream f(path);
  int replaced = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("simulation:", 0) == 0 && !motion) break;
    // With its motion: the servos hold the configuration of the capture (as the plan's motion).
    if (motion) line = std::regex_replace(line, std::regex("set_point: [-0-9.]+"), "set_point: hold");
    if (line.rfind("  q: {", 0) == 0) {
      line = "  q: {" + q + "}";
      ++replaced;
    }
    if (!qdot.is_null() && line.rfind("  qdot: {", 0) == 0) line = "  qdot: {" + byName(qdot) + "}";
    if (!base_twist.is_null() && line.rfind("  base: {", 0) == 0) {
      std::ostringstream t;
      t.precision(17);
      for (std::size_t k = 0; k < 6; ++k) t << (k ? ", " : "") << base_twist[k].get<double>();
      line = "  base: {position: [0, 0, 0], rpy: [0, 0, 0], twist: [" + t.str() + "]}";
    }
    if (line.rfind("  urdf: ../urdf/", 0) == 0) line = "  urdf: " + urdfDir() + "/" + line.substr(16);
    f << line << "\n";
  }
  EXPECT_EQ(replaced, 1);
  return path;
}

double baseRateOf(const nlohmann::json& capture) {
  const auto w = capture.at("robot").at("base_twist_after");
  return std::sqrt(std::pow(w[3].get<double>(), 2) + std::pow(w[4].get<double>(), 2) + std::pow(w[5].get<double>(), 2));
}

TEST(PlanTool, ThePlannedJointsReproduceTheObjectiveThroughCapture) {
  const ToolRun run = kdlSpace("plan " + kScenario + " --scan 11 --json");
  ASSERT_EQ(run.rc, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  for (const char* key : {"scenario", "weights", "joint_names", "q", "q_by_name", "qdot_after", "parameters", "searched",
                          "objective", "optimum", "nominal_objective", "nominal", "nominal_q_by_name", "evaluations"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j.at("q_by_name").size(), 7u);
  EXPECT_TRUE(j.at("parameters").contains("self_motion"));
  EXPECT_TRUE(j.at("parameters").contains("wrist_roll"));
  const double planned = j.at("objective").get<double>();
  EXPECT_LT(planned, j.at("nominal_objective").get<double>());

  const std::string path = captureScenario(j.at("q_by_name"));
  const ToolRun capture = kdlSpace("capture " + path + " --json");
  std::remove(path.c_str());
  ASSERT_EQ(capture.rc, 0) << capture.err;
  // 17 significant digits each way: the same joints, the same capture, to round-off.
  EXPECT_NEAR(baseRateOf(nlohmann::json::parse(capture.out)), planned, 1e-9 * planned);

  // The nominal (the scenario's own q) through capture too.
  const std::string nominal = captureScenario(j.at("nominal_q_by_name"));
  const ToolRun as_written = kdlSpace("capture " + nominal + " --json");
  std::remove(nominal.c_str());
  ASSERT_EQ(as_written.rc, 0) << as_written.err;
  EXPECT_NEAR(baseRateOf(nlohmann::json::parse(as_written.out)), j.at("nominal_objective").get<double>(),
              1e-9 * j.at("nominal_objective").get<double>());
}

/// A CSV's columns by name, its rows after the capture (phase post).
struct Csv {
  std::map<std::string, std::size_t> column;
  std::vector<std::vector<std::string>> rows;
  double at(std::size_t row, const std::string& name) const { return std::stod(rows[row][column.at(name)]); }
};

Csv readPostRows(const std::string& path) {
  Csv c;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::stringstream header(line);
  for (std::string name; std::getline(header, name, ',');) c.column.emplace(name, c.column.size());
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    cells.resize(c.column.size());
    if (cells[c.column.at("phase")] == "post") c.rows.push_back(cells);
  }
  return c;
}

// The operation objective's optimum, written into the scenario and run by `simulate`: the bus's
// peak and final rate, its attitude excursion and the joints' peak torques that the plan
// predicted are what the simulation's CSV shows (1e-9).
TEST(PlanTool, ThePredictedMotionIsWhatSimulateShowsAtThoseAngles) {
  const ToolRun run = kdlSpace("plan " + kScenario + " --objective peak_base_rate --horizon 3 --scan 7 --polish-starts 1 --json");
  ASSERT_EQ(run.rc, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j.at("horizon").get<double>(), 3.0);
  const nlohmann::json& m = j.at("optimum").at("motion");
  for (const char* key : {"peak_base_rate", "final_base_rate", "attitude_excursion", "settling_time", "peak_torque_by_name",
                          "peak_torque_ratio", "peak_torque_joint", "peak_grasp_force", "peak_grasp_moment", "momentum_rate"})
    EXPECT_TRUE(m.contains(key)) << key;
  EXPECT_GT(m.at("peak_grasp_force").get<double>(), 0.0);  // a rigid capture: the hand holds the box
  EXPECT_EQ(j.at("momentum_rate"), m.at("momentum_rate"));
  EXPECT_TRUE(j.at("nominal").contains("motion"));
  EXPECT_EQ(j.at("objective"), m.at("peak_base_rate"));

  const std::string path = captureScenario(j.at("q_by_name"), nullptr, nullptr, true);
  const std::string csv = path + ".csv";
  const ToolRun sim = kdlSpace("simulate " + path + " --duration 3 --csv " + csv);
  ASSERT_EQ(sim.rc, 0) << sim.err;
  const Csv c = readPostRows(csv);
  std::remove(path.c_str());
  std::remove(csv.c_str());
  ASSERT_GT(c.rows.size(), 50u);
  const auto w = [&](std::size_t r) {
    return std::sqrt(std::pow(c.at(r, "base_wx"), 2) + std::pow(c.at(r, "base_wy"), 2) + std::pow(c.at(r, "base_wz"), 2));
  };
  const auto quat = [&](std::size_t r) {
    return std::array<double, 4>{c.at(r, "base_qx"), c.at(r, "base_qy"), c.at(r, "base_qz"), c.at(r, "base_qw")};
  };
  double peak = 0.0, excursion = 0.0;
  const std::array<double, 4> q0 = quat(0);
  for (std::size_t r = 0; r < c.rows.size(); ++r) {
    peak = std::max(peak, w(r));
    const std::array<double, 4> q = quat(r);
    const double dot = std::abs(q0[0] * q[0] + q0[1] * q[1] + q0[2] * q[2] + q0[3] * q[3]);
    excursion = std::max(excursion, 2.0 * std::acos(std::min(1.0, dot)));
  }
  const double predicted = m.at("peak_base_rate").get<double>();
  EXPECT_NEAR(peak, predicted, 1e-9 * predicted);
  EXPECT_NEAR(w(c.rows.size() - 1), m.at("final_base_rate").get<double>(), 1e-9 * predicted);
  EXPECT_NEAR(excursion, m.at("attitude_excursion").get<double>(), 1e-7);  // acos near 1: half the digits
  for (auto it = m.at("peak_torque_by_name").begin(); it != m.at("peak_torque_by_name").end(); ++it) {
    double tau = 0.0;
    for (std::size_t r = 0; r < c.rows.size(); ++r) tau = std::max(tau, std::abs(c.at(r, "tau_" + it.key())));
    EXPECT_NEAR(tau, it.value().get<double>(), 1e-9 * std::max(1.0, tau)) << it.key();
  }
  // The text says what the bus feels and the momentum's share.
  const ToolRun text = kdlSpace("plan " + kScenario + " --horizon 1 --scan 5 --polish-starts 0");
  ASSERT_EQ(text.rc, 0) << text.err;
  for (const char* words : {"after: peak base rate", "attitude excursion", "settling", "effort limit",
                            "momentum-determined rate"})
    EXPECT_NE(text.out.find(words), std::string::npos) << words << "\n" << text.out;
}

TEST(PlanTool, APlannedClosingSpeedGivesTheRatesBeforeThatReproduceItThroughCapture) {
  const ToolRun run = kdlSpace("plan " + kScenario + " --scan 7 --closing-speed 0.01,0.05 --json");
  ASSERT_EQ(run.rc, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  ASSERT_EQ(j.at("searched"), (nlohmann::json{"self_motion", "wrist_roll", "closing_speed"}));
  const double c = j.at("parameters").at("closing_speed").get<double>();
  EXPECT_GE(c, 0.01);
  EXPECT_LE(c, 0.05);
  nlohmann::json qdot = nlohmann::json::object();
  for (std::size_t k = 0; k < 7; ++k) qdot[j.at("joint_names")[k].get<std::string>()] = j.at("qdot_before")[k];
  ASSERT_EQ(j.at("base_twist_before").size(), 6u);
  const std::string path = captureScenario(j.at("q_by_name"), qdot, j.at("base_twist_before"));
  const ToolRun capture = kdlSpace("capture " + path + " --json");
  std::remove(path.c_str());
  ASSERT_EQ(capture.rc, 0) << capture.err;
  const double planned = j.at("objective").get<double>();
  EXPECT_NEAR(baseRateOf(nlohmann::json::parse(capture.out)), planned, 1e-9 * planned);
  // The text names the rates before the capture.
  const ToolRun text = kdlSpace("plan " + kScenario + " --scan 5 --closing-speed 0.01,0.05");
  ASSERT_EQ(text.rc, 0) << text.err;
  EXPECT_NE(text.out.find("before the capture, closing on the grasp"), std::string::npos) << text.out;
}

TEST(PlanTool, PrintsTheJointAnglesByNameAndBothObjectives) {
  const ToolRun run = kdlSpace("plan " + kArm6 + " --scan 9 --objective joint_rate_jump");
  ASSERT_EQ(run.rc, 0) << run.err;
  for (const char* text : {"optimum", "nominal", "wrist_roll", "shoulder_yaw_joint", "wrist_roll_joint", "joint_rate_jump"})
    EXPECT_NE(run.out.find(text), std::string::npos) << text << "\n" << run.out;
}

TEST(PlanTool, UsageMistakesExit2NamingTheOption) {
  const auto expect = [](const std::string& args, int rc, const std::string& words) {
    const ToolRun run = kdlSpace("plan " + args);
    EXPECT_EQ(run.rc, rc) << args << "\n" << run.err;
    EXPECT_NE(run.err.find(words), std::string::npos) << args << "\n" << run.err;
    EXPECT_EQ(run.out, "");
  };
  expect(kArm6 + " --objective base_spin", 2, "--objective: unknown objective 'base_spin'");
  expect(kArm6 + " --weights base_rate=1,impulse=-2", 2, "--weights");
  expect(kArm6 + " --weights base_rate=1,spin=2", 2, "--weights: unknown objective 'spin'");
  expect(kArm6 + " --weights base_rate", 2, "--weights");
  expect(kArm6 + " --wrist-roll 0,0", 2, "nothing to plan");
  expect(kArm6 + " --self-motion -1,1", 2, "--self-motion");
  expect(kArm6 + " --wrist-roll 1,-1", 2, "--wrist-roll");
  expect(kArm6 + " --horizon 0", 2, "--horizon");
  expect(kArm6 + " --horizon -2", 2, "--horizon");
  expect(kArm6 + " --settling-band 1.5", 2, "--settling-band");
  expect(dataDir() + "/scenarios/arm6_reach_point.json --objective peak_grasp_force", 2,
         "--weights: peak_grasp_force is the load of a grasp that holds the target");
  expect(kArm6 + " --closing-speed -0.1,0.1", 2, "--closing-speed: must be >= 0");
  expect(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/base_attitude_control.yaml", 3, "no capture to plan");
}

}  // namespace
}  // namespace kdl_space::test
