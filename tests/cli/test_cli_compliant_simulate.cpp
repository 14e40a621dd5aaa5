// `kdl_space simulate` of a compliant capture (issue 28): scenarios/compliant_capture.yaml runs the
// approach of the moving robot target, the contact integrated over its duration and the joined
// motion after it. The CSV's contact rows and wrench columns against the JSON's force history,
// the JSON's keys, the text, the plot and the page; a scenario of another law keeps its columns.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "cli_runner.hpp"

namespace kdl_space::test {
namespace {

namespace fs = std::filesystem;

const std::string kScenario = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/compliant_capture.yaml";

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  std::string cell;
  while (std::getline(in, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  int column(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return static_cast<int>(i);
    return -1;
  }
};

Csv readCsv(const std::string& path) {
  std::stringstream in(slurp(path));
  Csv csv;
  std::string line;
  std::getline(in, line);
  csv.header = split(line);
  while (std::getline(in, line)) csv.rows.push_back(split(line));
  return csv;
}

TEST(CompliantSimulate, TheContactsRowsCarryTheForceHistoryAndTheJoinedMotionFollows) {
  const std::string csv_path = scratchIn("compliant_simulate", "run.csv");
  const std::string plot = scratchIn("compliant_simulate", "run.svg");
  const std::string html = scratchIn("compliant_simulate", "run.html");
  const ToolRun r = kdlSpace("simulate " + kScenario + " --duration 1 --csv " + csv_path + " --plot " + plot +
                             " --html " + html + " --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.at("capture").is_object()) << "the impulsive limit beside the contact";
  const nlohmann::json& c = j.at("compliant");
  ASSERT_TRUE(c.is_object());
  // The shipped gripper stays compliant (law.lock: never, the default): no lock, no share for it.
  EXPECT_EQ(c.at("lock"), "never");
  EXPECT_TRUE(c.at("end") == "settled" || c.at("end") == "timed_out") << c.at("end");
  EXPECT_TRUE(c.at("catch_rule").is_null());
  EXPECT_EQ(c.at("lock_share").at("angular_impulse").get<double>(), 0.0);
  EXPECT_EQ(c.at("lock_loss").get<double>(), 0.0);
  EXPECT_FALSE(j.at("simulation").at("stiffness").at("stiff").get<bool>()) << j.at("simulation").at("stiffness");
  const double t_start = c.at("t_start").get<double>(), duration = c.at("duration").get<double>();
  EXPECT_DOUBLE_EQ(t_start, j.at("approach").at("t_contact").get<double>());
  EXPECT_DOUBLE_EQ(c.at("t_end").get<double>(), t_start + duration);
  EXPECT_EQ(j.at("simulation").at("target_joined").at("grasp"), "compliant");
  EXPECT_NEAR(j.at("simulation").at("final").at("t").get<double>(), t_start + duration + 1.0, 1e-9);
  const std::vector<std::string> names = c.at("robot").at("joint_names");
  EXPECT_EQ(names.size(), c.at("robot").at("qdot_after").size());

  // The CSV: the contact's rows (phase "contact"), one per history sample, with its wrench; the
  // other rows leave the wrench columns empty.
  const Csv csv = readCsv(csv_path);
  const int fx = csv.column("contact_fx"), phase = csv.column("phase"), t = csv.column("t");
  ASSERT_GE(fx, 0);
  ASSERT_EQ(csv.header[csv.header.size() - 7], "contact_nz") << "added last: the columns before keep their places";
  const int gx = csv.column("grasp_fx");  // the grasp's load, added after (issue 39): every row from the touch on
  ASSERT_EQ(gx, static_cast<int>(csv.header.size()) - 6);
  const nlohmann::json& history = c.at("history");
  std::size_t k = 0;
  std::vector<std::string> phases;
  for (const auto& row : csv.rows) {
    ASSERT_EQ(row.size(), csv.header.size());
    if (phases.empty() || phases.back() != row[phase]) phases.push_back(row[phase]);
    if (row[phase] != "contact") {
      for (int i = 0; i < 6; ++i) EXPECT_EQ(row[fx + i], "") << row[phase];
      for (int i = 0; i < 6; ++i) EXPECT_EQ(row[gx + i].empty(), row[phase] != "post") << row[phase];
      continue;
    }
    for (int i = 0; i < 6; ++i) EXPECT_EQ(row[gx + i], row[fx + i]);  // the contact's wrench is the grasp's load
    ASSERT_LT(k, history.at("t").size());
    EXPECT_NEAR(std::stod(row[t]), t_start + history.at("t")[k].get<double>(), 1e-12);
    for (int i = 0; i < 6; ++i) {
      const double w = history.at("wrench")[k][i].get<double>();
      EXPECT_NEAR(std::stod(row[fx + i]), w, 1e-15 * std::abs(w) + 1e-300);
    }
    ++k;
  }
  EXPECT_EQ(k, history.at("t").size());
  EXPECT_EQ(phases, (std::vector<std::string>{"approach", "capture", "contact", "post"}));
  EXPECT_TRUE(fs::exists(plot));
  EXPECT_NE(slurp(html).find("compliant contact"), std::string::npos);

  // The text: the contact beside the impulsive capture, and what moved on after it.
  const ToolRun text = kdlSpace("simulate " + kScenario + " --duration 0.2");
  ASSERT_EQ(text.rc, 0) << text.err;
  EXPECT_NE(text.out.find("Compliant contact"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("After the compliant contact"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("six grasp joints held by the gripper's springs and dampers"), std::string::npos) << text.out;
  fs::remove_all(fs::path(csv_path).parent_path());
}

TEST(CompliantSimulate, AnotherLawKeepsItsColumns) {
  const std::string csv_path = scratchIn("compliant_simulate_other", "run.csv");
  const ToolRun r = kdlSpace("simulate " + std::string(KDL_SPACE_SOURCE_DIR) +
                             "/scenarios/robot_to_robot_capture.yaml --duration 0.1 --csv " + csv_path + " --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::parse(r.out).at("compliant").is_null());
  const Csv csv = readCsv(csv_path);
  EXPECT_EQ(csv.header[csv.header.size() - 7], "grasp_distance");
  EXPECT_EQ(csv.header.back(), "grasp_nz");  // a rigid capture holds the target: its load, last
  EXPECT_EQ(csv.column("contact_fx"), -1);
  fs::remove_all(fs::path(csv_path).parent_path());
}

}  // namespace
}  // namespace kdl_space::test
