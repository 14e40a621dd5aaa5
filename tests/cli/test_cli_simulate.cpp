// `kdl_space simulate` end to end: the CSV and the plot are written and readable, momentum is
// kept, bad input fails cleanly and leaves no partial file behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>

#include "cli_runner.hpp"
#include "reference_case.hpp"

namespace kdl_space::test {
namespace {

namespace fs = std::filesystem;
const std::string kScenario = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/tumbling_box_capture.yaml";

std::string scratch(const std::string& name) { return scratchIn("kdl_space_sim", name); }

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream s(line);
  for (std::string cell; std::getline(s, cell, ',');) cells.push_back(cell);
  return cells;
}

TEST(SimulateTool, WritesAReadableCsvAndPlot) {
  const std::string csv = scratch("run.csv"), svg = scratch("run.svg"), png = scratch("run.png");
  const ToolRun r = kdlSpace("simulate " + kScenario + " --duration 2 --csv " + csv + " --plot " + svg + " --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.contains("capture") && j.contains("simulation"));
  EXPECT_EQ(j.at("simulation").at("csv"), csv);
  EXPECT_TRUE(j.at("simulation").at("payload_attached").get<bool>());

  // CSV: header with named columns, one row per 0.05 s output step from 0 to 2 s, numbers only.
  std::ifstream in(csv);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  const std::vector<std::string> header = split(line);
  const std::vector<std::string> joints = j.at("simulation").at("joint_names");
  EXPECT_EQ(header.front(), "t");
  // The columns added since end the header: grasp_distance, then the grasp's load (issue 39).
  const std::vector<std::string> grasp{"grasp_fx", "grasp_fy", "grasp_fz", "grasp_nx", "grasp_ny", "grasp_nz"};
  ASSERT_GE(header.size(), 9u);
  EXPECT_EQ(std::vector<std::string>(header.end() - 6, header.end()), grasp);
  EXPECT_EQ(header[header.size() - 7], "grasp_distance");
  EXPECT_EQ(header[header.size() - 9], "work_gravity");
  for (const std::string& name : joints) {
    EXPECT_NE(std::find(header.begin(), header.end(), "q_" + name), header.end()) << name;
    EXPECT_NE(std::find(header.begin(), header.end(), "qdot_" + name), header.end()) << name;
  }
  for (const char* col : {"base_x", "base_qw", "base_wz", "P_x", "L_z"})
    EXPECT_NE(std::find(header.begin(), header.end(), col), header.end()) << col;
  std::vector<std::vector<double>> rows;
  double peak_force = 0.0, peak_moment = 0.0;  // the grasp's load, as the CSV has it
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::vector<std::string> cells = split(line);
    ASSERT_EQ(cells.size(), header.size()) << line;
    EXPECT_EQ(cells[header.size() - 8], "post");  // the phase: after the impact
    EXPECT_EQ(cells[header.size() - 7], "");      // grasp_distance: empty after the impact
    Eigen::Matrix<double, 6, 1> w;
    for (int k = 0; k < 6; ++k) w(k) = std::stod(cells[header.size() - 6 + k]);  // the box is held: every row
    peak_force = std::max(peak_force, w.head<3>().norm());
    peak_moment = std::max(peak_moment, w.tail<3>().norm());
    cells.resize(header.size() - 8);
    for (const std::string& cell : cells) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  const nlohmann::json& load = j.at("simulation").at("grasp_load");  // the JSON's peaks are the rows' (17 digits)
  EXPECT_NEAR(load.at("peak_force").get<double>(), peak_force, 1e-14 * peak_force);
  EXPECT_NEAR(load.at("peak_moment").get<double>(), peak_moment, 1e-14 * peak_moment);
  EXPECT_GT(peak_force, 0.0);
  ASSERT_EQ(rows.size(), 41u);  // t = 0, 0.05, ..., 2
  EXPECT_DOUBLE_EQ(rows.front()[0], 0.0);
  EXPECT_DOUBLE_EQ(rows.back()[0], 2.0);
  // Momentum columns equal the capture's momentum after the impact (robot + target), every row:
  // two routes (the momentum before plus the impulse; a sweep over the bodies' velocities after)
  // whose round-off differs by about 1e-12 of the norm: 1.05e-12 in the baseline build the
  // sanitizers use (no FMA), which rounds otherwise than the x86-64-v3/v4 clones. Hence 1e-11.
  const Eigen::MatrixXd h0 = ReferenceCase::mat(j.at("capture").at("momentum_after"));
  const auto col = [&](const std::string& name) { return std::find(header.begin(), header.end(), name) - header.begin(); };
  for (const auto& row : rows) {
    const std::vector<std::string> names{"P_x", "P_y", "P_z", "L_x", "L_y", "L_z"};
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(row[col(names[k])], h0(k), 1e-11 * h0.norm()) << names[k];
    // The base quaternion stays unit.
    const double qn = std::hypot(std::hypot(row[col("base_qx")], row[col("base_qy")]),
                                 std::hypot(row[col("base_qz")], row[col("base_qw")]));
    EXPECT_NEAR(qn, 1.0, 1e-12);
  }
  // Each joint's peak torque (simulation.joint_torques, issue 39): the largest |tau_JOINT| of the
  // rows, against the effort limit the URDF gives it (read here with a regular expression).
  std::ifstream urdf_in(std::string(KDL_SPACE_SOURCE_DIR) + "/urdf/space_arm7.urdf");
  const std::string urdf((std::istreambuf_iterator<char>(urdf_in)), std::istreambuf_iterator<char>());
  const nlohmann::json& torques = j.at("simulation").at("joint_torques");
  ASSERT_EQ(torques.size(), joints.size());
  for (std::size_t k = 0; k < joints.size(); ++k) {
    const nlohmann::json& t = torques[k];
    EXPECT_EQ(t.at("joint"), joints[k]);
    double peak = 0.0;
    for (const auto& row : rows) peak = std::max(peak, std::abs(row[col("tau_" + joints[k])]));
    EXPECT_NEAR(t.at("peak_torque").get<double>(), peak, 1e-15 * peak) << joints[k];
    std::smatch effort;
    const std::regex joint_limit("<joint name=\"" + joints[k] + "\"[\\s\\S]*?effort=\"([0-9.eE+-]+)\"");
    ASSERT_TRUE(std::regex_search(urdf, effort, joint_limit)) << joints[k];
    EXPECT_EQ(t.at("effort_limit").get<double>(), std::stod(effort[1])) << joints[k];
    EXPECT_NEAR(t.at("fraction_of_effort").get<double>(), peak / std::stod(effort[1]), 1e-15) << joints[k];
  }
  EXPECT_GT(torques[1].at("peak_torque").get<double>(), 0.0) << "the servos hold the arm";
  // The plot is an SVG document with three panels' worth of curves.
  std::ifstream plot(svg);
  std::stringstream text;
  text << plot.rdbuf();
  EXPECT_NE(text.str().find("<svg"), std::string::npos);
  EXPECT_NE(text.str().find("</svg>"), std::string::npos);
  EXPECT_NE(text.str().find("base attitude"), std::string::npos);
  EXPECT_NE(text.str().find("joint7"), std::string::npos);

  ASSERT_EQ(kdlSpace("simulate " + kScenario + " --duration 0.5 --plot " + png).rc, 0);
  std::ifstream png_in(png, std::ios::binary);
  char magic[8] = {};
  png_in.read(magic, 8);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
  fs::remove_all(fs::path(csv).parent_path());
}

TEST(SimulateTool, ReadableSummary) {
  const ToolRun r = kdlSpace("simulate " + kScenario + " --duration 1");
  ASSERT_EQ(r.rc, 0) << r.err;
  for (const char* s : {"Impulse on the robot", "After the impact: the target is attached", "Final base attitude",
                        "joint7", "Largest change over the run"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s;
}

TEST(SimulateTool, BadInputFailsCleanlyAndLeavesNoFile) {
  const std::string csv = scratch("bad.csv"), plot = scratch("bad.svg");
  // A scenario that loads but cannot be simulated (a step budget too small), and bad options.
  const std::string scenario = scratch("small_budget.yaml");
  std::ifstream in(kScenario);
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  yaml.replace(yaml.find("rtol: 1.0e-10"), 13, "rtol: 1.0e-10\n  max_steps: 10");
  for (const std::string dir : {std::string("../urdf/")})
    yaml.replace(yaml.find(dir), dir.size(), std::string(KDL_SPACE_SOURCE_DIR) + "/urdf/");
  std::ofstream(scenario) << yaml;
  const struct {
    std::string args;
    int rc;
    std::string needle;
  } cases[] = {
      {"simulate " + scenario + " --csv " + csv + " --plot " + plot, 3, "more than simulation.max_steps = 10"},
      {"simulate " + kScenario + " --duration -1 --csv " + csv, 2, "duration"},
      {"simulate " + kScenario + " --plot " + scratch("bad.gif"), 2, ".svg or .png"},
      {"simulate /nonexistent.yaml --csv " + csv, 3, "nonexistent"},
      {"simulate " + kScenario + " --csv /nonexistent/dir/run.csv", 3, "/nonexistent/dir/run.csv"},
  };
  for (const auto& c : cases) {
    const ToolRun r = kdlSpace(c.args);
    EXPECT_EQ(r.rc, c.rc) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.needle), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(csv)) << c.args;
    EXPECT_FALSE(fs::exists(plot)) << c.args;
    for (const auto& entry : fs::directory_iterator(fs::path(csv).parent_path()))
      EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << "left behind: " << entry.path();
  }
  fs::remove_all(fs::path(csv).parent_path());
}

}  // namespace
}  // namespace kdl_space::test
