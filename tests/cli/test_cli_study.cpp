// `kdl_space study` end to end: the same table on any threads, from shards merged, after a
// resume; its summary JSON; the nominal sample's motion against `simulate`; plots; bad inputs
// refused with the field named and nothing written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <regex>
#include <sstream>
#include <unistd.h>

#include "cli_runner.hpp"

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using kdl_space::test::kdlSpace;
using kdl_space::test::ToolRun;
using kdl_space::test::scratchIn;
using kdl_space::test::slurp;
using kdl_space::test::spit;

const std::string kScenarios = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/";
const std::string kShippedStudy = kScenarios + "study_grasp_configuration.yaml";

std::string scratch(const std::string& name) { return scratchIn("kdl_space_cli_study", name); }

std::string write(const std::string& name, const std::string& text) {
  const std::string path = scratch(name);
  std::ofstream(path) << text;
  return path;
}

/// A study of 400 captures: a grid over the self-motion, a Latin hypercube over the tumble.
const std::string kGrasp = write("grasp.yaml", "scenario: " + kScenarios + "tumbling_box_capture.yaml\n"
                                 "samples: 400\nseed: 20261123\nsampling: latin_hypercube\n"
                                 "inputs:\n  robot.self_motion: {grid: [-1.2, 1.2, 25]}\n"
                                 "  target.tumble: {uniform: [0.05, 0.16]}\n"
                                 "limits: {joint_rate: urdf, base_rate: 0.0015}\nobjective: base_rate\n");

TEST(StudyCommand, TheTableIsTheSameOnOneThreadOnTwoAndFromThreeShardsMerged) {
  const std::string one = scratch("one.csv"), two = scratch("two.csv"), merged = scratch("merged.csv");
  ASSERT_EQ(kdlSpace("study " + kGrasp + " --threads 1 -o " + one).rc, 0);
  ASSERT_EQ(kdlSpace("study " + kGrasp + " --threads 2 --chunk-size 7 -o " + two).rc, 0);
  EXPECT_EQ(slurp(one), slurp(two));
  std::string parts;
  for (int i = 1; i <= 3; ++i) {
    const std::string part = scratch("part" + std::to_string(i) + ".csv");
    const ToolRun r = kdlSpace("study " + kGrasp + " --shard " + std::to_string(i) + "/3 -o " + part);
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find("shard " + std::to_string(i) + "/3"), std::string::npos) << r.out;
    parts += " " + part;
  }
  const ToolRun m = kdlSpace("study " + kGrasp + " --merge" + parts + " -o " + merged);
  ASSERT_EQ(m.rc, 0) << m.err;
  EXPECT_EQ(slurp(merged), slurp(one));
  // The table: a comment line naming the study's version and rows, the header, 400 rows.
  std::istringstream lines(slurp(one));
  std::string head, header, row;
  std::getline(lines, head);
  std::getline(lines, header);
  EXPECT_EQ(head.rfind("# kdl_space study; fingerprint ", 0), 0u) << head;
  EXPECT_NE(head.find("; samples 400; rows 0-400"), std::string::npos) << head;
  EXPECT_EQ(header.rfind("sample,status,robot.self_motion,target.tumble,target.tumble.axis_x", 0), 0u) << header;
  int rows = 0;
  while (std::getline(lines, row) && row.rfind("# end; rows 0-400; crc32 ", 0) != 0) ++rows;
  EXPECT_EQ(rows, 400);
  EXPECT_FALSE(std::getline(lines, row)) << "the checksum's line is the last";
}

TEST(StudyCommand, AnInterruptedRunResumesFromTheChunksOnDisk) {
  const std::string whole = scratch("whole.csv"), resumed = scratch("resumed.csv");
  ASSERT_EQ(kdlSpace("study " + kGrasp + " --chunk-size 100 -o " + whole).rc, 0);
  // What an interrupted run leaves: finished chunks in TABLE.parts (here: rows 100-200 from a
  // shard of the same grid, and a chunk cut short, which is computed again).
  const fs::path parts = resumed + ".parts";
  fs::remove_all(parts);
  fs::create_directories(parts);
  ASSERT_EQ(kdlSpace("study " + kGrasp + " --shard 2/4 -o " + (parts / "rows-100-200.csv").string()).rc, 0);
  const std::string full = slurp((parts / "rows-100-200.csv").string());
  std::string cut = full.substr(0, full.size() / 2);
  cut.replace(cut.find("rows 100-200"), 12, "rows 200-300");
  std::ofstream((parts / "rows-200-300.csv").string()) << cut;
  const ToolRun r = kdlSpace("study " + kGrasp + " --chunk-size 100 -o " + resumed);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("300 computed"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("100 resumed from"), std::string::npos) << r.out;
  EXPECT_EQ(slurp(resumed), slurp(whole));
  EXPECT_FALSE(fs::exists(parts)) << "the chunks are removed once the table is whole";
}

TEST(StudyCommand, SummaryJsonPlotsAndTheBestConfigurations) {
  const std::string table = scratch("s.csv"), plot = scratch("s.svg"), map = scratch("s_map.svg"), summary = scratch("s.json");
  const ToolRun r = kdlSpace("study " + kShippedStudy + " -o " + table + " --plot " + plot + " --heat-map " + map + " --summary " +
                             summary + " --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j, json::parse(slurp(summary)));
  for (const char* key : {"study", "fingerprint", "table", "samples", "failed", "seed", "outcomes", "probabilities",
                          "objective", "best", "worst", "failures"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["samples"], 31 * 13);  // its grid
  EXPECT_EQ(j["failed"], 0);
  EXPECT_EQ(j["failures"], json::array());
  EXPECT_EQ(j["objective"], "base_rate");
  const json& q = j["outcomes"]["base_rate"];
  EXPECT_LE(q["min"].get<double>(), q["q05"].get<double>());
  EXPECT_LE(q["q05"].get<double>(), q["median"].get<double>());
  EXPECT_LE(q["median"].get<double>(), q["max"].get<double>());
  EXPECT_EQ(j["best"][0]["objective"], q["min"]);
  EXPECT_EQ(j["worst"][0]["objective"], q["max"]);
  EXPECT_TRUE(j["best"][0]["inputs"].contains("robot.self_motion"));
  EXPECT_TRUE(j["probabilities"].contains("exceeds.any"));
  EXPECT_GT(fs::file_size(plot), 1000u);
  EXPECT_GT(fs::file_size(map), 1000u);
  EXPECT_NE(slurp(map).find("<svg"), std::string::npos);
}

/// The CSV lines of a file, each split at its commas.
std::vector<std::vector<std::string>> csvLines(const std::string& path) {
  std::vector<std::vector<std::string>> lines;
  std::istringstream in(slurp(path));
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::istringstream l(line);
    for (std::string cell; std::getline(l, cell, ',');) cells.push_back(cell);
    lines.push_back(cells);
  }
  return lines;
}

// 3 x 4 grid points, 5 samples each (a random tumble): the heat map's cells and the groups' CSV.
const std::string kCells = write("cells.yaml", "scenario: " + kScenarios + "tumbling_box_capture.yaml\n"
                                 "samples: 60\nseed: 3\ninputs:\n  robot.q.joint6: {grid: [-0.2, 0.2, 3]}\n"
                                 "  robot.q.joint7: {grid: [-0.3, 0.3, 4]}\n  target.tumble: {uniform: [0.02, 0.2]}\n"
                                 "limits: {base_rate: 0.0015}\nobjective: {outcome: base_rate, statistic: q95}\n"
                                 "heat_map: {x: robot.q.joint7, y: robot.q.joint6, outcome: base_rate, statistic: max}\n");

TEST(StudyCommand, TheHeatMapHasOneValueACellTheGroupsCsvOneRowAPoint) {
  const std::string table = scratch("cells.csv"), map = scratch("cells_map.csv"), groups = scratch("cells_groups.csv");
  const ToolRun r = kdlSpace("study " + kCells + " -o " + table + " --heat-map " + map + " --groups " + groups + " --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["grid_inputs"], json::array({"robot.q.joint6", "robot.q.joint7"}));
  ASSERT_EQ(j["grid_points"].size(), 12u);
  EXPECT_EQ(j["objective_statistic"], "q95");
  ASSERT_EQ(j["best_grid_points"].size(), 5u);
  // The heat map: 12 cells (not 60 points), each (x, y) once, its value the max of its 5 samples.
  const auto cells = csvLines(map);
  ASSERT_EQ(cells.size(), 13u);
  EXPECT_EQ(cells[0], (std::vector<std::string>{"robot.q.joint7", "robot.q.joint6", "base_rate.max"}));
  std::set<std::pair<double, double>> seen;
  for (std::size_t k = 1; k < cells.size(); ++k) {
    ASSERT_EQ(cells[k].size(), 3u);
    EXPECT_TRUE(seen.insert({std::stod(cells[k][0]), std::stod(cells[k][1])}).second) << "a cell twice";
  }
  // The same maxima from the raw table, grouped here.
  std::map<std::pair<double, double>, double> max_by_cell;
  const auto rows = csvLines(table);
  const auto& header = rows[1];
  const auto at = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  for (std::size_t k = 2; k + 1 < rows.size(); ++k) {
    const std::pair<double, double> key{std::stod(rows[k][at("robot.q.joint7")]), std::stod(rows[k][at("robot.q.joint6")])};
    const double v = std::stod(rows[k][at("base_rate")]);
    max_by_cell[key] = max_by_cell.count(key) ? std::max(max_by_cell[key], v) : v;
  }
  ASSERT_EQ(max_by_cell.size(), 12u);
  for (std::size_t k = 1; k < cells.size(); ++k)
    EXPECT_EQ(std::stod(cells[k][2]), (max_by_cell[{std::stod(cells[k][0]), std::stod(cells[k][1])}]));
  // The groups' CSV: the grid inputs, count, failed, each outcome's mean, q95, max, P(exceeds.*).
  const auto g = csvLines(groups);
  ASSERT_EQ(g.size(), 13u);
  EXPECT_EQ(g[0][0], "robot.q.joint6");
  EXPECT_EQ(g[0][1], "robot.q.joint7");
  EXPECT_EQ(g[0][2], "count");
  EXPECT_NE(std::find(g[0].begin(), g[0].end(), "base_rate.q95"), g[0].end());
  EXPECT_EQ(g[0].back(), "P(exceeds.any)");
  for (std::size_t k = 1; k < g.size(); ++k) {
    EXPECT_EQ(g[k].size(), g[0].size());
    EXPECT_EQ(g[k][2], "5");
    const json& point = j["grid_points"][k - 1];
    EXPECT_EQ(std::stod(g[k][0]), point["inputs"]["robot.q.joint6"].get<double>());
    const std::size_t q95 = static_cast<std::size_t>(std::find(g[0].begin(), g[0].end(), "base_rate.q95") - g[0].begin());
    EXPECT_EQ(std::stod(g[k][q95]), point["outcomes"]["base_rate"]["q95"].get<double>());
  }
  // The picture: drawn from the same cells.
  const std::string svg = scratch("cells_map.svg");
  ASSERT_EQ(kdlSpace("study " + kCells + " -o " + table + " --heat-map " + svg).rc, 0);
  EXPECT_NE(slurp(svg).find("<svg"), std::string::npos);
}

TEST(StudyCommand, TheSummaryNamesWhyTheFirstSampleOfEachFailureFailed) {
  // joint3 drawn beyond its hard stop (2.96706 rad) is refused by the motion's set-up (status
  // E_BAD_ARGUMENT, -106): the summary keeps the library's message, the same from one run, from
  // shards merged and in the text summary. (A target mass that could be drawn <= 0 is refused at load.)
  std::string text = slurp(kScenarios + "tumbling_box_capture.yaml");
  text.replace(text.find("../urdf/"), 8, std::string(KDL_SPACE_SOURCE_DIR) + "/urdf/");
  text.replace(text.find("  atol:"), 0, "  limits: stop\n");
  const std::string scenario = write("stops.yaml", text);
  const std::string study = write("failing.yaml", "scenario: " + scenario + "\nsamples: 30\nseed: 5\n"
                                  "inputs: {robot.q.joint3: {normal: {mean: 2.9, std: 0.1}}}\nmotion: {duration: 0.05}\n");
  const std::string table = scratch("failing.csv");
  const ToolRun r = kdlSpace("study " + study + " -o " + table + " --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  const json j = json::parse(r.out);
  ASSERT_EQ(j["failures"].size(), 1u) << j.dump(2);
  const json& f = j["failures"][0];
  EXPECT_EQ(f["status"], -106);
  EXPECT_EQ(f["count"], j["failed"]);
  EXPECT_GT(f["count"].get<int>(), 0);
  // The first sample: the first row whose status is -106; its joint3 (the third column) in the message.
  std::istringstream lines(slurp(table));
  std::string line;
  std::getline(lines, line);
  std::getline(lines, line);
  long first = -1;
  double q = 0.0;
  for (long i = 0; first < 0 && std::getline(lines, line); ++i)
    if (line.find(",-106,") != std::string::npos) first = i, q = std::stod(line.substr(line.find(",-106,") + 6));
  EXPECT_EQ(f["first_sample"], first);
  std::ostringstream message;
  message << scenario << ": simulation.limits: joint 'joint3' starts at " << q
          << ", outside its limits [-2.96706, 2.96706] (a hard stop keeps it inside them): start it inside, or let its limits warn";
  EXPECT_EQ(f["message"], message.str());
  // From two shards merged: the same failures.
  std::string parts;
  for (int i = 1; i <= 2; ++i) {
    const std::string part = scratch("failing_part" + std::to_string(i) + ".csv");
    ASSERT_EQ(kdlSpace("study " + study + " --shard " + std::to_string(i) + "/2 -o " + part).rc, 0);
    parts += " " + part;
  }
  const ToolRun m = kdlSpace("study " + study + " --merge" + parts + " -o " + scratch("failing_merged.csv") + " --json");
  ASSERT_EQ(m.rc, 0) << m.err;
  EXPECT_EQ(json::parse(m.out)["failures"], j["failures"]);
  // The text summary says it under its first line.
  const ToolRun t = kdlSpace("study " + study + " -o " + table);
  ASSERT_EQ(t.rc, 0) << t.err;
  const std::string expected = "  status -106: " + std::to_string(f["count"].get<int>()) + " samples, the first " +
                               std::to_string(first) + ": " + message.str() + "\n";
  EXPECT_NE(t.out.find(" could not be computed), seed 5; table " + table + "\n" + expected), std::string::npos) << t.out;
}

// The detumble columns (issue 39): one sample at the shipped detumble's own configuration, 60 s of
// motion under each law; its time_to_detumble, attitude_excursion, wheel_momentum_fraction and
// energy_dissipated are `simulate`'s simulation.detumble of the same scenario (the study's servos
// hold the capture configuration, as the scenario's `set_point: hold` do).
TEST(StudyCommand, TheDetumbleColumnsAreSimulates) {
  for (const std::string law : {"hold", "momentum_distribution"}) {
    SCOPED_TRACE(law);
    std::string text = slurp(kScenarios + "detumble_with_wheels.yaml");
    text = std::regex_replace(text, std::regex("\\.\\./urdf"), kScenarios + "../urdf");
    text += "  after_capture: {law: " + law + "}\n";
    const std::string scenario = write("detumble_" + law + ".yaml", text);
    const std::string study = write("detumble_study_" + law + ".yaml", "scenario: " + scenario + "\nseed: 1\n"
                                    "inputs: {target.mass: {grid: [50, 50, 1]}}\nmotion: {duration: 60, output_step: 0.1}\n");
    const std::string table = scratch("detumble_" + law + ".csv");
    const ToolRun s = kdlSpace("study " + study + " -o " + table);
    ASSERT_EQ(s.rc, 0) << s.err;
    const ToolRun sim = kdlSpace("simulate " + scenario + " --json");
    ASSERT_EQ(sim.rc, 0) << sim.err;
    const json d = json::parse(sim.out).at("simulation").at("detumble");
    std::istringstream t(slurp(table));
    std::string line, header;
    std::getline(t, line);  // the CRC line
    std::getline(t, header);
    std::getline(t, line);
    const auto split = [](const std::string& row) {
      std::vector<std::string> cells;
      std::stringstream ss(row);
      for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
      return cells;
    };
    const std::vector<std::string> names = split(header), values = split(line);
    for (const char* column : {"time_to_detumble", "attitude_excursion", "wheel_momentum_fraction", "energy_dissipated"}) {
      const auto at = std::find(names.begin(), names.end(), column);
      ASSERT_NE(at, names.end()) << column << " in " << header;
      const double value = std::stod(values[static_cast<std::size_t>(at - names.begin())]);
      ASSERT_TRUE(d.at(column).is_number()) << column << ": " << d.dump();
      EXPECT_NEAR(value, d.at(column).get<double>(), 1e-9 * (std::abs(value) + 1e-3)) << column;
    }
    // ... and the grasp's load (the hand holds the box): simulate's simulation.grasp_load.
    const json g = json::parse(sim.out).at("simulation").at("grasp_load");
    for (const auto& [column, key] : {std::pair{"peak_grasp_force", "peak_force"}, std::pair{"peak_grasp_moment", "peak_moment"}}) {
      const auto at = std::find(names.begin(), names.end(), column);
      ASSERT_NE(at, names.end()) << column << " in " << header;
      const double value = std::stod(values[static_cast<std::size_t>(at - names.begin())]);
      EXPECT_GT(value, 0.0) << column;
      EXPECT_NEAR(value, g.at(key).get<double>(), 1e-9 * value) << column;
    }
  }
}

TEST(StudyCommand, TheNominalSamplesMotionIsSimulates) {
  // One sample at the scenario's own inputs (a one-point grid), a second of motion after it: its
  // peaks are those of `simulate` of the scenario (whose servos hold the capture configuration).
  const std::string study = write("nominal.yaml", "scenario: " + kScenarios + "tumbling_box_capture.yaml\nseed: 1\n"
                                  "inputs: {robot.q.joint2: {grid: [0.7, 0.7, 1]}}\n"
                                  "motion: {duration: 1.0, output_step: 0.05}\nlimits: {joint_torque: 50}\n");
  const std::string table = scratch("nominal.csv"), csv = scratch("nominal_motion.csv");
  ASSERT_EQ(kdlSpace("study " + study + " -o " + table + " --json").rc, 0);
  ASSERT_EQ(kdlSpace("simulate " + kScenarios + "tumbling_box_capture.yaml --duration 1 --csv " + csv).rc, 0);
  std::istringstream t(slurp(table)), m(slurp(csv));
  std::string line, header;
  std::getline(t, line);
  std::getline(t, header);
  std::getline(t, line);
  const auto split = [](const std::string& s) {
    std::vector<std::string> cells;
    std::stringstream ss(s);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    return cells;
  };
  const std::vector<std::string> names = split(header), values = split(line);
  std::getline(m, header);
  const std::vector<std::string> motion_names = split(header);
  std::vector<double> peak(7, 0.0);
  const std::size_t phase = static_cast<std::size_t>(std::find(motion_names.begin(), motion_names.end(), "phase") - motion_names.begin());
  int post = 0;
  while (std::getline(m, line)) {
    const std::vector<std::string> cells = split(line);
    ASSERT_LT(phase, cells.size());
    if (cells[phase] != "post") continue;  // the rows after the capture
    ++post;
    for (std::size_t c = 0; c < cells.size(); ++c)
      for (int j = 0; j < 7; ++j)
        if (motion_names[c] == "tau_joint" + std::to_string(j + 1)) peak[j] = std::max(peak[j], std::abs(std::stod(cells[c])));
  }
  EXPECT_EQ(post, 21);
  for (int j = 0; j < 7; ++j) {
    const auto at = std::find(names.begin(), names.end(), "peak_torque.joint" + std::to_string(j + 1));
    ASSERT_NE(at, names.end());
    const double study_peak = std::stod(values[static_cast<std::size_t>(at - names.begin())]);
    EXPECT_NEAR(study_peak, peak[j], 1e-9 * std::max(peak[j], 1e-6)) << "joint" << j + 1;
  }
  EXPECT_GT(peak[0] + peak[1], 0.0);
}

TEST(StudyCommand, BadInputsNameTheFieldAndWriteNothing) {
  const std::string head = "scenario: " + kScenarios + "tumbling_box_capture.yaml\n";
  struct Case {
    std::string args, expect;
    int rc;
  } cases[] = {
      {write("unknown.yaml", head + "samples: 5\nseed: 1\ninputs: {target.spin: {uniform: [0, 1]}}\n"),
       "inputs.target.spin: is no input of a study", 3},
      {write("empty_range.yaml", head + "samples: 5\nseed: 1\ninputs: {timing: {uniform: [1, 1]}}\n"),
       "inputs.timing.uniform: is an empty range", 3},
      {write("zero.yaml", head + "samples: 0\nseed: 1\ninputs: {timing: {uniform: [0, 1]}}\n"), "samples: must be >= 1", 3},
      {write("huge.yaml", head + "samples: 1000000000000\nseed: 1\ninputs: {timing: {uniform: [0, 1]}}\n"),
       "samples: must be at most 1e9", 3},
      {write("seed.yaml", head + "samples: 5\nseed: 0.5\ninputs: {timing: {uniform: [0, 1]}}\n"), "seed: must be a whole number", 3},
      {kGrasp + " --shard 0/3", "--shard 0/3: expected i/N with 1 <= i <= N", 2},
      {kGrasp + " --shard 4/3", "--shard 4/3: expected i/N", 2},
      {kGrasp + " --shard 1/-3", "--shard 1/-3: expected i/N", 2},
      {kGrasp + " --shard 1/3x", "--shard 1/3x: expected i/N", 2},
      // One past what 64 bits hold: not read as 18446744073709551615 shards.
      {kGrasp + " --shard 1/18446744073709551617",
       "--shard 1/18446744073709551617: 18446744073709551617 is too large: at most 400 shards (the study's samples)", 2},
      {kGrasp + " --shard 1/3 --merge x.csv", "--shard and --merge", 2},
      {kGrasp + " --heat-map map.txt", "--heat-map map.txt: the file name must end in .svg or .png", 2},
  };
  for (const Case& c : cases) {
    const std::string table = scratch("never.csv");
    fs::remove(table);
    const ToolRun r = kdlSpace("study " + c.args + " -o " + table);
    EXPECT_EQ(r.rc, c.rc) << c.args << ": " << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.args << ": " << r.err;
    EXPECT_FALSE(fs::exists(table)) << c.args;
    EXPECT_EQ(r.err.find("terminate"), std::string::npos);
  }
  // Merging: a missing shard, a part of another study (another seed), a part given twice.
  const std::string a = scratch("m1.csv"), b = scratch("m2.csv"), other = scratch("other.csv");
  ASSERT_EQ(kdlSpace("study " + kGrasp + " --shard 1/2 -o " + a).rc, 0);
  ASSERT_EQ(kdlSpace("study " + kGrasp + " --shard 2/2 -o " + b).rc, 0);
  std::string text = slurp(kGrasp);
  text.replace(text.find("seed: 20261123"), 14, "seed: 20261124");
  const std::string reseeded = write("reseeded.yaml", text);
  ASSERT_EQ(kdlSpace("study " + reseeded + " --shard 2/2 -o " + other).rc, 0);
  const std::string out = scratch("m.csv");
  fs::remove(out);
  ToolRun r = kdlSpace("study " + kGrasp + " --merge " + a + " -o " + out);
  EXPECT_EQ(r.rc, 3);
  EXPECT_NE(r.err.find("rows 200-400 are in no part (a shard is missing)"), std::string::npos) << r.err;
  r = kdlSpace("study " + kGrasp + " --merge " + a + " " + other + " -o " + out);
  EXPECT_EQ(r.rc, 3);
  EXPECT_NE(r.err.find(other + ": holds rows of another study"), std::string::npos) << r.err;
  r = kdlSpace("study " + kGrasp + " --merge " + a + " " + a + " " + b + " -o " + out);
  EXPECT_EQ(r.rc, 3);
  EXPECT_NE(r.err.find("both hold the rows from 0"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
