// A study's answers per grid point (issue 26, item 4): the per-grid-point aggregates equal a
// group-by of the raw rows computed here, by hand; `objective: {outcome, statistic}` ranks grid
// points, not samples; the q.JOINT columns are the self-motion call's angles; the qdot.JOINT
// columns are the rates after the capture and exceeds.joint_rate tests them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "kdl_space/study/study.hpp"
#include "test_util.hpp"

namespace kdl_space {
namespace {

namespace fs = std::filesystem;
const std::string kScenario = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/tumbling_box_capture.yaml";

std::string studyFile(const std::string& name, const std::string& text) {
  const fs::path dir = fs::path(::testing::TempDir()) / "kdl_space_study_groups_tests";
  fs::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << "scenario: " << kScenario << "\n" << text;
  return path;
}

std::size_t column(const std::vector<std::string>& columns, const std::string& name) {
  const auto it = std::find(columns.begin(), columns.end(), name);
  EXPECT_NE(it, columns.end()) << name;
  return static_cast<std::size_t>(it - columns.begin());
}

std::vector<double> allRows(const std::shared_ptr<const Study>& st) {
  const std::size_t m = studyColumns(*st).size();
  std::vector<double> rows(st->samples * m);
  runStudy(st, studyChunks(0, st->samples, 8), 2, [&](const StudyChunk& c, const std::vector<double>& r) {
    std::copy(r.begin(), r.end(), rows.begin() + static_cast<std::ptrdiff_t>(c.begin * m));
  });
  return rows;
}

/// The p-quantile of sorted values, linear between the order statistics floor(p (n - 1)) and the
/// next (numpy's default, the summary's definition).
double quantile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const double h = p * static_cast<double>(v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (h - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

// A grid of 3 self-motion values x 2 wrist angles, 60 samples (10 a point) of random tumbles.
const char* kGrid = "samples: 60\nseed: 99\ninputs:\n  robot.self_motion: {grid: [-0.4, 0.4, 3]}\n"
                    "  robot.q.joint7: {grid: [-0.3, 0.3, 2]}\n  target.tumble: {uniform: [0.02, 0.2]}\n"
                    "limits: {joint_rate: 0.06, base_rate: 0.0015}\n";

TEST(StudyGroups, PerGridPointAggregatesEqualAGroupByOfTheRows) {
  const auto st = std::make_shared<const Study>(loadStudy(studyFile("grid.yaml", kGrid)));
  const std::vector<std::string> columns = studyColumns(*st);
  const std::size_t m = columns.size(), sm = column(columns, "robot.self_motion"), q7 = column(columns, "robot.q.joint7");
  const std::vector<double> rows = allRows(st);
  const StudySummary s = summarizeStudy(*st, rows);
  // The group-by, by hand: rows keyed by their grid inputs' values.
  std::map<std::pair<double, double>, std::vector<std::size_t>> groups;
  for (std::size_t r = 0; r < st->samples; ++r) groups[{rows[r * m + sm], rows[r * m + q7]}].push_back(r);
  ASSERT_EQ(groups.size(), 6u);
  ASSERT_EQ(s.grid_points.size(), 6u);
  std::size_t exceeded = 0;
  for (const GridPointSummary& g : s.grid_points) {
    ASSERT_EQ(g.inputs.size(), 2u);
    EXPECT_EQ(g.inputs[0].first, "robot.self_motion");
    const auto found = groups.find({g.inputs[0].second, g.inputs[1].second});
    ASSERT_NE(found, groups.end()) << g.index;
    const std::vector<std::size_t>& members = found->second;
    EXPECT_EQ(g.count + g.failed, members.size());
    for (const std::size_t r : members) EXPECT_EQ(static_cast<std::uint64_t>(rows[r * m]) % 6, g.index);
    std::size_t computed = 0;
    for (const std::size_t r : members) computed += rows[r * m + 1] == 0.0;
    ASSERT_EQ(g.count, computed);
    ASSERT_GT(computed, 0u);
    for (const GridPointSummary::Outcome& o : g.outcomes) {
      const std::size_t c = column(columns, o.name);
      std::vector<double> v;
      double sum = 0.0;
      for (const std::size_t r : members)
        if (rows[r * m + 1] == 0.0) v.push_back(rows[r * m + c]), sum += rows[r * m + c];
      const double mean = sum / static_cast<double>(v.size());
      // The summary's mean is the exact sum rounded once; this one rounds at each of <= 10 additions.
      EXPECT_NEAR(o.mean, mean, 1e-14 * std::abs(mean) + 1e-300) << o.name;
      EXPECT_EQ(o.q95, quantile(v, 0.95)) << o.name;  // exact: the point's values kept as they are
      EXPECT_EQ(o.max, *std::max_element(v.begin(), v.end())) << o.name;
    }
    for (const auto& [name, p] : g.probabilities) {
      const std::size_t c = column(columns, name);
      double n = 0.0;
      for (const std::size_t r : members)
        if (rows[r * m + 1] == 0.0) n += rows[r * m + c];
      EXPECT_EQ(p, n / static_cast<double>(computed)) << name;
      if (name == "exceeds.any") exceeded += n > 0.0;
    }
  }
  EXPECT_GT(exceeded, 0u) << "the limits are chosen so that some points exceed them";
  // The same aggregates from the rows fed in reverse, in blocks, by two summarizers merged.
  StudySummarizer a(st), b(st);
  for (std::size_t r = st->samples; r-- > 0;) (r % 2 ? a : b).add(&rows[r * m], 1);
  a.merge(b);
  const StudySummary t = a.finish();
  ASSERT_EQ(t.grid_points.size(), s.grid_points.size());
  for (std::size_t k = 0; k < s.grid_points.size(); ++k)
    for (std::size_t o = 0; o < s.grid_points[k].outcomes.size(); ++o) {
      EXPECT_EQ(t.grid_points[k].outcomes[o].mean, s.grid_points[k].outcomes[o].mean);
      EXPECT_EQ(t.grid_points[k].outcomes[o].q95, s.grid_points[k].outcomes[o].q95);
      EXPECT_EQ(t.grid_points[k].outcomes[o].max, s.grid_points[k].outcomes[o].max);
    }
}

TEST(StudyGroups, AnObjectiveWithAStatisticRanksGridPointsNotSamples) {
  const std::string text = "samples: 40\nseed: 1\ninputs:\n  robot.q.joint7: {grid: [0, 0.3, 4]}\n"
                           "  target.tumble: {uniform: [0.02, 0.2]}\nobjective: {outcome: base_rate, statistic: q95}\n";
  const Study st = loadStudy(studyFile("ranked.yaml", text));
  EXPECT_EQ(st.objective, "base_rate");
  EXPECT_EQ(st.objective_statistic, "q95");
  const std::vector<std::string> columns = studyColumns(st);
  const std::size_t m = columns.size(), rate = column(columns, "base_rate"), q7 = column(columns, "robot.q.joint7");
  // Rows made by hand: point 0 holds the single smallest sample (0.1) but a large tail (9 at
  // q95); point 2 the smallest q95 (1); points 1 and 3 in between.
  std::vector<double> rows(40 * m, 0.0);
  const double tails[4] = {9.0, 5.0, 1.0, 3.0};
  for (std::size_t i = 0; i < 40; ++i) {
    const std::size_t p = i % 4, k = i / 4;  // k-th sample of point p, 10 a point
    rows[i * m] = static_cast<double>(i);
    rows[i * m + q7] = 0.1 * static_cast<double>(p);
    rows[i * m + rate] = k == 9 ? tails[p] : (p == 0 && k == 0 ? 0.1 : 0.5);
  }
  const StudySummary s = summarizeStudy(st, rows);
  ASSERT_EQ(s.best.size(), 5u);
  EXPECT_EQ(s.best[0].sample, 0u) << "the samples still rank by the outcome";
  ASSERT_EQ(s.best_grid_points.size(), 4u);
  ASSERT_EQ(s.worst_grid_points.size(), 4u);
  // q95 of nine 0.5 (one 0.1 at point 0) and a tail t: 0.5 + 0.55 (t - 0.5).
  const std::size_t best_order[4] = {2, 3, 1, 0};
  for (std::size_t k = 0; k < 4; ++k) {
    const std::size_t p = best_order[k];
    EXPECT_EQ(s.best_grid_points[k].index, p) << k;
    // (0.95 * 9 - 8 is 0.55 to a few ulps of 9: the interpolation weight as doubles give it)
    EXPECT_NEAR(s.best_grid_points[k].objective, 0.5 + 0.55 * (tails[p] - 0.5), 1e-14 * 9 * tails[p]) << k;
    EXPECT_EQ(s.best_grid_points[k].count, 10u);
    EXPECT_EQ(s.worst_grid_points[k].index, best_order[3 - k]) << k;
    ASSERT_EQ(s.best_grid_points[k].inputs.size(), 1u);
    EXPECT_DOUBLE_EQ(s.best_grid_points[k].inputs[0].second, 0.1 * static_cast<double>(p));
  }
  // The plain objective ranks the samples only.
  const Study plain = loadStudy(studyFile("plain.yaml", "samples: 40\nseed: 1\ninputs:\n  robot.q.joint7: {grid: [0, 0.3, 4]}\n"
                                                        "  target.tumble: {uniform: [0.02, 0.2]}\nobjective: base_rate\n"));
  EXPECT_TRUE(plain.objective_statistic.empty());
  EXPECT_TRUE(summarizeStudy(plain, rows).best_grid_points.empty());
}

TEST(StudyGroups, TheSelfMotionColumnsAreTheSelfMotionCallsAngles) {
  const auto st = std::make_shared<const Study>(
      loadStudy(studyFile("sm.yaml", "seed: 1\ninputs:\n  robot.self_motion: {grid: [-0.6, 0.6, 5]}\n")));
  const std::vector<std::string> columns = studyColumns(*st);
  const std::size_t m = columns.size(), sm = column(columns, "robot.self_motion");
  const std::vector<double> rows = allRows(st);
  const std::vector<std::string>& joints = st->scenario.capture.robot.model->jointNames();
  bool moved = false;
  for (std::size_t r = 0; r < st->samples; ++r) {
    ASSERT_EQ(rows[r * m + 1], 0.0) << r;
    const std::vector<double> q = selfMotionJoints(st->scenario, rows[r * m + sm]);
    ASSERT_EQ(q.size(), joints.size());
    for (std::size_t j = 0; j < joints.size(); ++j) {
      EXPECT_EQ(rows[r * m + column(columns, "q." + joints[j])], q[j]) << joints[j];
      moved |= std::abs(q[j] - st->scenario.capture.robot.state.q(static_cast<unsigned>(j))) > 0.01;
    }
  }
  EXPECT_TRUE(moved);
}

TEST(StudyGroups, TheRateColumnsAreTheRatesAfterAndExceedsJointRateTestsThem) {
  const std::string text = "samples: 40\nseed: 5\ninputs:\n  robot.qdot.joint1: {uniform: [-0.05, 0.05]}\n"
                           "  target.tumble: {uniform: [0.02, 0.25]}\nlimits: {joint_rate: 0.04}\n";
  const auto st = std::make_shared<const Study>(loadStudy(studyFile("rates.yaml", text)));
  const std::vector<std::string> columns = studyColumns(*st);
  const std::size_t m = columns.size(), in = column(columns, "robot.qdot.joint1"), ex = column(columns, "exceeds.joint_rate");
  const std::vector<double> rows = allRows(st);
  const std::vector<std::string>& joints = st->scenario.capture.robot.model->jointNames();
  int exceeded = 0;
  for (std::size_t r = 0; r < st->samples; ++r) {
    ASSERT_EQ(rows[r * m + 1], 0.0) << r;
    bool over = false;
    for (std::size_t j = 0; j < joints.size(); ++j) {
      const double after = rows[r * m + column(columns, "qdot." + joints[j])];
      // The rate before (the scenario's, or the input's) plus the jump.
      const double before = j == 0 ? rows[r * m + in] : st->scenario.capture.robot.velocity.qdot(static_cast<unsigned>(j));
      EXPECT_NEAR(after, before + rows[r * m + column(columns, "dqdot." + joints[j])], 1e-15 + 1e-14 * std::abs(after));
      over |= std::abs(after) > 0.04;
    }
    EXPECT_EQ(rows[r * m + ex], over ? 1.0 : 0.0) << r;
    exceeded += over;
  }
  EXPECT_GT(exceeded, 0);
  EXPECT_LT(exceeded, 40);
  // Added after the columns there were: the exceeds.* columns keep their places.
  EXPECT_EQ(columns.back(), "qdot." + joints.back());
  EXPECT_EQ(column(columns, "exceeds.any") + 1, column(columns, "qdot." + joints.front()));
}

TEST(StudyGroups, TheLoaderRefusesWhatCannotBeGrouped) {
  const std::pair<std::string, std::string> cases[] = {
      {"samples: 10\nseed: 1\ninputs: {target.tumble: {uniform: [0, 0.1]}}\nobjective: {outcome: base_rate, statistic: q95}\n",
       "objective: ranks grid points, and the study has no grid input"},
      {"seed: 1\ninputs: {robot.q.joint7: {grid: [0, 1, 3]}}\nobjective: {outcome: base_rate, statistic: median}\n",
       "objective.statistic: 'median' is no statistic of base_rate: one of mean, q95, max"},
      {"seed: 1\ninputs: {robot.q.joint7: {grid: [0, 1, 3]}, target.tumble: {uniform: [0, 0.1]}}\n"
       "heat_map: {x: robot.q.joint7, y: target.tumble, outcome: base_rate}\n",
       "heat_map.y: is no grid input of this study"},
      {"seed: 1\ninputs: {robot.q.joint7: {grid: [0, 1, 3]}, robot.q.joint6: {grid: [0, 1, 3]}}\n"
       "heat_map: {x: robot.q.joint7, y: robot.q.joint6, outcome: base_rate, statistic: probability}\n",
       "heat_map.statistic: 'probability' is no statistic of base_rate"},
  };
  for (const auto& [text, expected] : cases) {
    try {
      loadStudy(studyFile("bad.yaml", text));
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
  const Study ok = loadStudy(studyFile("ok.yaml", "seed: 1\ninputs: {robot.q.joint7: {grid: [0, 1, 3]}, robot.q.joint6: "
                                                  "{grid: [0, 1, 3]}}\nheat_map: {x: robot.q.joint7, y: robot.q.joint6, "
                                                  "outcome: base_rate, statistic: q95}\n"));
  EXPECT_EQ(ok.heat_map->statistic, "q95");
}

}  // namespace
}  // namespace kdl_space
