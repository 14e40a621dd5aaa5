// `kdl_space simulate --plot FILE`: the panels of the base's angular rate (deg/s), of the base
// control's torque (when the scenario has one) and of the servos' hold error q - set point (when
// the joints are servoed), checked in gnuplot's own input: a `gnuplot` first on PATH keeps a copy
// of the script and of its data file, then runs the real gnuplot. The data's columns are checked
// against the CSV of the same run, the panels against what the scenario has.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <regex>
#include <sstream>

#include "cli_runner.hpp"

namespace kdl_space::test {
namespace {

namespace fs = std::filesystem;
const std::string kScenarios = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/";

using Table = std::vector<std::vector<double>>;

std::vector<std::string> splitBy(const std::string& line, char by) {
  std::vector<std::string> cells;
  std::stringstream s(line);
  for (std::string cell; std::getline(s, cell, by);)
    if (!(by == ' ' && cell.empty())) cells.push_back(cell);
  if (!line.empty() && line.back() == by && by == ',') cells.emplace_back();
  return cells;
}

double number(const std::string& cell) { return cell.empty() || cell == "NaN" ? std::nan("") : std::stod(cell); }

class PlotPanels : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratchIn("kdl_space_plot", ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    const ToolRun which = shellOut("command -v gnuplot");
    ASSERT_EQ(which.rc, 0) << "gnuplot is not installed (Debian package gnuplot-nox)";
    const std::string gnuplot = which.out.substr(0, which.out.find('\n'));
    fs::create_directories(dir_ + "/bin");
    spit(dir_ + "/bin/gnuplot", "#!/bin/sh\ncp \"$1\" '" + dir_ + "/plot.gp'\ncp \"${1%.gp}.dat\" '" + dir_ +
                                    "/plot.dat'\nexec '" + gnuplot + "' \"$@\"\n");
    fs::permissions(dir_ + "/bin/gnuplot", fs::perms::owner_all);
    path_ = std::getenv("PATH") ? std::getenv("PATH") : "";
    setenv("PATH", (dir_ + "/bin:" + path_).c_str(), 1);
  }
  void TearDown() override {
    setenv("PATH", path_.c_str(), 1);
    fs::remove_all(dir_);
  }
  static ToolRun shellOut(const std::string& command) {
    FILE* pipe = popen(command.c_str(), "r");
    std::string out;
    char buffer[4096];
    while (std::size_t n = fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
    const int status = pclose(pipe);
    return {WEXITSTATUS(status), out, ""};
  }
  /// Runs simulate with --csv and --plot; reads the CSV (header, rows), the script and its data.
  void simulate(const std::string& scenario, const std::string& more = "") {
    const std::string csv = dir_ + "/run.csv";
    const ToolRun r = kdlSpace("simulate " + scenario + " " + more + " --csv " + csv + " --plot " + dir_ + "/run.svg");
    ASSERT_EQ(r.rc, 0) << r.err;
    std::stringstream lines(slurp(csv));
    std::string line;
    std::getline(lines, line);
    head_ = splitBy(line, ',');
    csv_.clear();
    phases_.clear();
    const std::size_t phase = std::find(head_.begin(), head_.end(), "phase") - head_.begin();
    ASSERT_LT(phase, head_.size());
    while (std::getline(lines, line)) {
      std::vector<std::string> cells = splitBy(line, ',');
      ASSERT_EQ(cells.size(), head_.size()) << line;
      phases_.push_back(cells[phase]);
      std::vector<double> row;
      for (const std::string& c : cells) row.push_back(c == phases_.back() ? std::nan("") : number(c));
      csv_.push_back(row);
    }
    script_ = slurp(dir_ + "/plot.gp");
    ASSERT_FALSE(script_.empty()) << "the fake gnuplot kept no script";
    dat_.clear();
    std::stringstream data(slurp(dir_ + "/plot.dat"));
    while (std::getline(data, line)) {
      std::vector<double> row;
      for (const std::string& c : splitBy(line, ' ')) row.push_back(number(c));
      dat_.push_back(row);
    }
    ASSERT_EQ(dat_.size(), csv_.size()) << "a data row per sample";
  }
  double csv(std::size_t row, const std::string& column) const {
    const auto at = std::find(head_.begin(), head_.end(), column);
    EXPECT_NE(at, head_.end()) << column;
    return at == head_.end() ? std::nan("") : csv_[row][at - head_.begin()];
  }
  /// The data column of the curve titled `title` in the panel whose y label starts with `panel`
  /// (-1 when there is no such panel or curve).
  int column(const std::string& panel, const std::string& title) const {
    const std::size_t at = script_.find("set ylabel '" + panel);
    if (at == std::string::npos) return -1;
    const std::size_t plot = script_.find("\nplot ", at), end = script_.find('\n', plot + 1);
    const std::string line = script_.substr(plot, end - plot);
    const std::regex curve("using 1:([0-9]+) with lines title '([^']*)'");
    for (std::sregex_iterator m(line.begin(), line.end(), curve), none; m != none; ++m)
      if ((*m)[2] == title) return std::stoi((*m)[1]) - 1;  // gnuplot counts from 1
    return -1;
  }
  bool has(const std::string& panel) const { return script_.find("set ylabel '" + panel) != std::string::npos; }

  std::string dir_, path_, script_;
  std::vector<std::string> head_, phases_;
  Table csv_, dat_;
};

// The data file holds 12 significant digits: 1e-10 of a value (its 17-digit CSV twin differs there).
void expectClose(double got, double want, const std::string& what) {
  EXPECT_NEAR(got, want, 1e-10 * std::abs(want) + 1e-300) << what;
}

TEST_F(PlotPanels, AttitudeControlAndServosShowRateTorqueAndHoldError) {
  // Every joint servoed ("*"), joint1 and joint2 to set points 1.0 and 0.2, the others held where
  // the motion starts; the base's attitude held by its control.
  simulate(kScenarios + "base_attitude_control.yaml", "--duration 3");
  ASSERT_TRUE(has("base angular rate [deg/s]")) << script_;
  ASSERT_TRUE(has("base control torque [N m]")) << script_;
  ASSERT_TRUE(has("servo hold error q - set point")) << script_;
  EXPECT_FALSE(has("joint position")) << "every joint is servoed: the hold error instead of the angles";
  EXPECT_FALSE(has("base control force")) << "no position control";
  const std::map<std::string, double> set_points{{"joint1", 1.0}, {"joint2", 0.2}};
  for (std::size_t i = 0; i < csv_.size(); ++i) {
    for (const char* c : {"x", "y", "z"}) {
      const int w = column("base angular rate", std::string("w_") + c), n = column("base control torque", std::string("n_") + c);
      ASSERT_GE(w, 0);
      ASSERT_GE(n, 0);
      expectClose(dat_[i][w], csv(i, std::string("base_w") + c) * 180 / M_PI, "w_" + std::string(c));
      expectClose(dat_[i][n], csv(i, std::string("base_control_n") + c), "n_" + std::string(c));
    }
    for (int j = 1; j <= 7; ++j) {
      const std::string name = "joint" + std::to_string(j);
      const int e = column("servo hold error", name);
      ASSERT_GE(e, 0) << name;
      const double set_point = set_points.count(name) ? set_points.at(name) : csv(0, "q_" + name);  // hold: the start's
      EXPECT_NEAR(dat_[i][e], csv(i, "q_" + name) - set_point, 1e-10 * std::abs(dat_[i][e]) + 1e-15) << name << " row " << i;
    }
  }
  EXPECT_GT(std::abs(csv(csv_.size() - 1, "base_control_nz")), 1e-6) << "the control acts";
}

TEST_F(PlotPanels, AFreeMotionHasNeitherHoldErrorNorBaseControl) {
  const std::string scenario = dir_ + "/free.yaml";
  spit(scenario, "robot:\n  urdf: " + std::string(KDL_SPACE_SOURCE_DIR) +
                     "/urdf/space_arm7.urdf\n  q: {joint2: 0.7}\n  qdot: {joint1: 0.2}\n  base: {position: [0, 0, 0], "
                     "rpy: [0, 0, 0], twist: [0, 0, 0, 0.01, -0.02, 0.03]}\nsimulation:\n  duration: 1\n  output_step: 0.1\n");
  simulate(scenario);
  EXPECT_TRUE(has("base angular rate [deg/s]"));
  EXPECT_TRUE(has("joint position"));
  EXPECT_FALSE(has("servo hold error")) << script_;
  EXPECT_FALSE(has("base control")) << script_;
  const int wz = column("base angular rate", "w_z");
  ASSERT_GE(wz, 0);
  for (std::size_t i = 0; i < csv_.size(); ++i) expectClose(dat_[i][wz], csv(i, "base_wz") * 180 / M_PI, "w_z");
  EXPECT_GT(std::abs(dat_[0][wz]), 1.0) << "0.03 rad/s is 1.7 deg/s";
}

TEST_F(PlotPanels, AfterAnApproachTheHoldErrorStartsAtTheCapture) {
  // The servos ("*": hold) act after the capture: the angles stay (the approach's motion), the hold
  // error is q - q at the capture, and missing before it.
  simulate(kScenarios + "approach_tumbling_box.yaml", "--duration 1");
  EXPECT_TRUE(has("joint position"));
  ASSERT_TRUE(has("servo hold error"));
  const auto post = std::find(phases_.begin(), phases_.end(), "post") - phases_.begin();
  ASSERT_LT(post, static_cast<long>(phases_.size()));
  ASSERT_GT(post, 1);
  for (int j = 1; j <= 7; ++j) {
    const std::string name = "joint" + std::to_string(j);
    const int e = column("servo hold error", name);
    ASSERT_GE(e, 0) << name;
    for (std::size_t i = 0; i < csv_.size(); ++i) {
      if (static_cast<long>(i) < post) {
        EXPECT_TRUE(std::isnan(dat_[i][e])) << name << " row " << i << ": no servo in the approach";
        continue;
      }
      EXPECT_NEAR(dat_[i][e], csv(i, "q_" + name) - csv(post, "q_" + name), 1e-10 * std::abs(dat_[i][e]) + 1e-15)
          << name << " row " << i;
    }
  }
}

}  // namespace
}  // namespace kdl_space::test
