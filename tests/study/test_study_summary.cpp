// A study's summary streamed (StudySummarizer): the same summary whatever the blocks the rows come
// in and after merges; on a real table the same as summarizeStudy and as the statistics computed
// here from the sorted table; past its first buffer, quantiles within the bound it states and
// everything else exact. And the engine: a grid of chunks generated as needed, chunks skipped,
// a cancel seen between samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include "kdl_space/study/study.hpp"

namespace kdl_space {
namespace {

namespace fs = std::filesystem;
const std::string kScenarios = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/";

std::string studyFile(const std::string& name, const std::string& text) {
  const fs::path dir = fs::path(::testing::TempDir()) / "kdl_space_study_summary_tests";
  fs::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

/// Two summaries are the same, bit for bit.
void expectSame(const StudySummary& a, const StudySummary& b, const std::string& what) {
  SCOPED_TRACE(what);
  const auto bits = [](double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; };
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.failed, b.failed);
  EXPECT_TRUE(bits(a.quantile_rank_error, b.quantile_rank_error));
  ASSERT_EQ(a.failures.size(), b.failures.size());
  for (std::size_t k = 0; k < a.failures.size(); ++k) {
    EXPECT_EQ(a.failures[k].status, b.failures[k].status);
    EXPECT_EQ(a.failures[k].count, b.failures[k].count);
    EXPECT_EQ(a.failures[k].first_sample, b.failures[k].first_sample);
    EXPECT_EQ(a.failures[k].message, b.failures[k].message);
  }
  ASSERT_EQ(a.outcomes.size(), b.outcomes.size());
  for (std::size_t k = 0; k < a.outcomes.size(); ++k) {
    const OutcomeSummary &x = a.outcomes[k], &y = b.outcomes[k];
    EXPECT_EQ(x.name, y.name);
    for (const auto f : {&OutcomeSummary::min, &OutcomeSummary::q05, &OutcomeSummary::q25, &OutcomeSummary::median,
                         &OutcomeSummary::q75, &OutcomeSummary::q95, &OutcomeSummary::max, &OutcomeSummary::mean})
      EXPECT_TRUE(bits(x.*f, y.*f)) << x.name << ": " << x.*f << " vs " << y.*f;
  }
  ASSERT_EQ(a.probabilities.size(), b.probabilities.size());
  for (std::size_t k = 0; k < a.probabilities.size(); ++k) {
    EXPECT_EQ(a.probabilities[k].first, b.probabilities[k].first);
    EXPECT_TRUE(bits(a.probabilities[k].second, b.probabilities[k].second)) << a.probabilities[k].first;
  }
  for (const auto list : {&StudySummary::best, &StudySummary::worst}) {
    ASSERT_EQ((a.*list).size(), (b.*list).size());
    for (std::size_t k = 0; k < (a.*list).size(); ++k) {
      EXPECT_EQ((a.*list)[k].sample, (b.*list)[k].sample);
      EXPECT_TRUE(bits((a.*list)[k].objective, (b.*list)[k].objective));
      EXPECT_EQ((a.*list)[k].inputs, (b.*list)[k].inputs);
    }
  }
}

/// Rows fed in blocks of `block` rows.
StudySummary inBlocks(const std::shared_ptr<const Study>& st, const std::vector<double>& rows, std::size_t block) {
  const std::size_t m = studyColumns(*st).size(), n = rows.size() / m;
  StudySummarizer s(st);
  for (std::size_t r = 0; r < n; r += block) s.add(rows.data() + r * m, std::min(block, n - r));
  return s.finish();
}

/// Rows [from, to) summarised apart, then merged in order.
StudySummary merged(const std::shared_ptr<const Study>& st, const std::vector<double>& rows, const std::vector<std::size_t>& cuts) {
  const std::size_t m = studyColumns(*st).size();
  StudySummarizer all(st);
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    StudySummarizer part(st);
    part.add(rows.data() + cuts[k] * m, cuts[k + 1] - cuts[k]);
    all.merge(part);
  }
  return all.finish();
}

/// The p-quantile of sorted values, linear between order statistics (the summary's definition).
double quantileOf(const std::vector<double>& sorted, double p) {
  const double x = p * static_cast<double>(sorted.size() - 1);
  const std::size_t k = static_cast<std::size_t>(x);
  return k + 1 >= sorted.size() ? sorted.back() : sorted[k] + (x - static_cast<double>(k)) * (sorted[k + 1] - sorted[k]);
}

TEST(StudySummarizer, ARealTableInBlocksMergedAndAsSummarizeStudy) {
  const auto st = std::make_shared<const Study>(loadStudy(kScenarios + "study_grasp_configuration.yaml"));
  const std::vector<std::string> columns = studyColumns(*st);
  const std::size_t m = columns.size(), n = static_cast<std::size_t>(st->samples);
  std::vector<double> rows(n * m);
  runStudy(st, studyChunks(0, n, 64), 2, [&](const StudyChunk& c, const std::vector<double>& part) {
    std::copy(part.begin(), part.end(), rows.begin() + static_cast<std::ptrdiff_t>(c.begin * m));
  });
  const StudySummary whole = summarizeStudy(*st, rows);
  EXPECT_EQ(whole.quantile_rank_error, 0.0);  // 403 samples: exact
  for (const std::size_t block : {std::size_t{1}, std::size_t{7}, std::size_t{100}, n})
    expectSame(inBlocks(st, rows, block), whole, "blocks of " + std::to_string(block));
  expectSame(merged(st, rows, {0, 1, 150, 150, 402, n}), whole, "merged");
  // Against the statistics of the sorted table, computed here.
  ASSERT_FALSE(whole.outcomes.empty());
  for (const OutcomeSummary& o : whole.outcomes) {
    SCOPED_TRACE(o.name);
    const std::size_t c = static_cast<std::size_t>(std::find(columns.begin(), columns.end(), o.name) - columns.begin());
    std::vector<double> v;
    for (std::size_t r = 0; r < n; ++r) v.push_back(rows[r * m + c]);
    std::sort(v.begin(), v.end());
    EXPECT_EQ(o.min, v.front());
    EXPECT_EQ(o.max, v.back());
    EXPECT_EQ(o.q05, quantileOf(v, 0.05));
    EXPECT_EQ(o.median, quantileOf(v, 0.5));
    EXPECT_EQ(o.q95, quantileOf(v, 0.95));
    // The mean is the exact sum rounded, over n: within a rounding of the sum in long double.
    long double sum = 0.0L;
    for (const double x : v) sum += x;
    const double reference = static_cast<double>(sum) / static_cast<double>(n);
    EXPECT_NEAR(o.mean, reference, 4 * std::numeric_limits<double>::epsilon() * std::abs(reference)) << o.name;
  }
}

/// The mixed study's table made up: `n` rows, outcomes drawn here, a few failed samples.
std::vector<double> syntheticTable(const Study& st, std::size_t n, std::uint64_t seed) {
  const std::size_t m = studyColumns(st).size();
  std::mt19937_64 rng(seed);
  std::lognormal_distribution<double> heavy(0.0, 1.5);
  std::uniform_int_distribution<int> ties(0, 20);
  std::vector<double> rows(n * m);
  for (std::size_t r = 0; r < n; ++r) {
    double* row = rows.data() + r * m;
    row[0] = static_cast<double>(n - 1 - r);  // samples in reverse
    row[1] = r % 997 == 5 ? static_cast<double>(E_MAX_STEPS) : r % 1009 == 3 ? static_cast<double>(E_BAD_ARGUMENT) : 0.0;
    for (std::size_t c = 2; c < m; ++c) row[c] = c % 3 == 0 ? heavy(rng) : c % 3 == 1 ? static_cast<double>(ties(rng)) : 1.0 / heavy(rng);
  }
  return rows;
}

TEST(StudySummarizer, PastItsFirstBufferQuantilesWithinTheBoundTheRestExact) {
  const std::string text = "scenario: " + kScenarios + "tumbling_box_capture.yaml\nsamples: 1000000\nseed: 2\n"
                           "inputs: {timing: {uniform: [0, 3]}, target.mass: {uniform: [20, 80]}}\n"
                           "limits: {joint_rate: 0.1}\n";
  const auto st = std::make_shared<const Study>(loadStudy(studyFile("large.yaml", text)));
  const std::vector<std::string> columns = studyColumns(*st);
  const std::size_t m = columns.size(), n = 300000;
  std::vector<double> rows = syntheticTable(*st, n, 17);
  const std::size_t any = static_cast<std::size_t>(std::find(columns.begin(), columns.end(), "exceeds.any") - columns.begin());
  for (std::size_t r = 0; r < n; ++r) rows[r * m + any] = r % 3 == 0 ? 1.0 : 0.0;
  const StudySummary s = inBlocks(st, rows, 4096);
  // Blocks do not matter; in order, merges stay within the bound.
  expectSame(inBlocks(st, rows, 1), s, "blocks of 1");
  expectSame(inBlocks(st, rows, 77777), s, "blocks of 77777");
  const StudySummary parts = merged(st, rows, {0, 50000, 250000, n});
  // Counts, failures, best and worst, probabilities, min, max and mean: exact.
  std::vector<std::size_t> good;
  std::uint64_t steps = 0, bad = 0;
  for (std::size_t r = 0; r < n; ++r) {
    const double status = rows[r * m + 1];
    (status == 0.0 ? good.push_back(r) : void(++(status == E_MAX_STEPS ? steps : bad)));
  }
  EXPECT_EQ(s.samples, n);
  EXPECT_EQ(s.failed, steps + bad);
  ASSERT_EQ(s.failures.size(), 2u);
  EXPECT_EQ(s.failures[0].count + s.failures[1].count, steps + bad);
  const std::size_t bound_n = good.size();
  const double stated = 1.0 / 65536 + std::floor(std::log2(bound_n / 16384.0)) / 16384;
  EXPECT_GT(s.quantile_rank_error, 0.0);
  EXPECT_LE(s.quantile_rank_error, stated);
  EXPECT_LE(parts.quantile_rank_error, stated);
  std::size_t third = 0;
  for (const std::size_t r : good) third += r % 3 == 0;
  ASSERT_EQ(s.probabilities.back().first, "exceeds.any");
  EXPECT_EQ(s.probabilities.back().second, static_cast<double>(third) / static_cast<double>(good.size()));
  for (const StudySummary* x : {&s, &parts}) {
    for (const OutcomeSummary& o : x->outcomes) {
      SCOPED_TRACE(o.name);
      const std::size_t c = static_cast<std::size_t>(std::find(columns.begin(), columns.end(), o.name) - columns.begin());
      std::vector<double> v;
      for (const std::size_t r : good) v.push_back(rows[r * m + c]);
      std::sort(v.begin(), v.end());
      EXPECT_EQ(o.min, v.front());
      EXPECT_EQ(o.max, v.back());
      long double sum = 0.0L;
      for (const double y : v) sum += y;
      EXPECT_NEAR(o.mean, static_cast<double>(sum / v.size()), 4e-16 * std::abs(static_cast<double>(sum / v.size())));
      const std::uint64_t e = static_cast<std::uint64_t>(std::ceil(x->quantile_rank_error * static_cast<double>(v.size())));
      const std::pair<double, double> qs[] = {{0.05, o.q05}, {0.25, o.q25}, {0.5, o.median}, {0.75, o.q75}, {0.95, o.q95}};
      for (const auto& [p, q] : qs) {
        const std::uint64_t r = static_cast<std::uint64_t>(p * static_cast<double>(v.size() - 1));
        EXPECT_LE(v[r - e], q) << p;
        EXPECT_LE(q, v[std::min<std::uint64_t>(v.size() - 1, r + 1 + e)]) << p;
      }
    }
  }
  // Best and worst by the objective (base_rate), ties by sample.
  const std::size_t obj = static_cast<std::size_t>(std::find(columns.begin(), columns.end(), "base_rate") - columns.begin());
  std::vector<std::size_t> order = good;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const double va = rows[a * m + obj], vb = rows[b * m + obj];
    return va != vb ? va < vb : rows[a * m] < rows[b * m];
  });
  ASSERT_EQ(s.best.size(), 5u);
  ASSERT_EQ(s.worst.size(), 5u);
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_EQ(s.best[k].sample, static_cast<std::uint64_t>(rows[order[k] * m]));
    EXPECT_EQ(s.worst[k].sample, static_cast<std::uint64_t>(rows[order[order.size() - 1 - k] * m]));
    EXPECT_EQ(s.best[k].inputs[1].second, rows[order[k] * m + 3]);
    EXPECT_EQ(parts.best[k].sample, s.best[k].sample);
    EXPECT_EQ(parts.worst[k].sample, s.worst[k].sample);
  }
}

TEST(StudyRun, AGridOfChunksSkipsWhatItIsToldAndEqualsTheListOfChunks) {
  const auto st = std::make_shared<const Study>(loadStudy(kScenarios + "study_grasp_configuration.yaml"));
  const std::size_t m = studyColumns(*st).size();
  std::vector<StudyChunk> listed, done;
  std::vector<double> a(400 * m, -1.0), b(400 * m, -1.0);
  runStudy(st, studyChunks(130, 400, 64), 2, [&](const StudyChunk& c, const std::vector<double>& rows) {
    listed.push_back(c);
    std::copy(rows.begin(), rows.end(), a.begin() + static_cast<std::ptrdiff_t>(c.begin * m));
  });
  runStudy(st, StudyGrid{130, 400, 64}, 2, [&](const StudyChunk& c, const std::vector<double>& rows) {
    done.push_back(c);
    std::copy(rows.begin(), rows.end(), b.begin() + static_cast<std::ptrdiff_t>(c.begin * m));
  }, nullptr, [](const StudyChunk& c) { return c.begin == 192; });
  const auto by_begin = [](const StudyChunk& x, const StudyChunk& y) { return x.begin < y.begin; };
  std::sort(listed.begin(), listed.end(), by_begin);
  std::sort(done.begin(), done.end(), by_begin);
  ASSERT_EQ(listed.size(), 5u);
  ASSERT_EQ(done.size(), 4u);  // [192, 256) skipped
  for (std::size_t k = 0, j = 0; k < listed.size(); ++k) {
    if (listed[k].begin == 192) continue;
    EXPECT_EQ(done[j].begin, listed[k].begin);
    EXPECT_EQ(done[j++].end, listed[k].end);
  }
  std::fill(a.begin() + 192 * static_cast<std::ptrdiff_t>(m), a.begin() + 256 * static_cast<std::ptrdiff_t>(m), -1.0);
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
  // A grid of a billion samples in chunks of 16 lists nothing: the first chunks come at once.
  const auto big = std::make_shared<const Study>(loadStudy(studyFile("billion.yaml",
      "scenario: " + kScenarios + "tumbling_box_capture.yaml\nsamples: 1000000000\nseed: 1\n"
      "inputs: {timing: {uniform: [0, 3]}}\n")));
  std::atomic<bool> cancel{false};
  int chunks = 0;
  runStudy(big, StudyGrid{0, big->samples, 16}, 1, [&](const StudyChunk& c, const std::vector<double>&) {
    EXPECT_EQ(c.begin, 16u * static_cast<std::uint64_t>(chunks));
    cancel = ++chunks == 3;
  }, &cancel);
  EXPECT_EQ(chunks, 3);
}

TEST(StudyRun, AGridsChunksAreTheWholeRunsCutToItsRange) {
  // Chunk k of the whole study holds rows [k c, (k + 1) c): a shard's chunks are cut from those.
  const StudyGrid shard{5, 23, 8};
  ASSERT_EQ(shard.count(), 3u);
  const std::uint64_t expected[3][2] = {{5, 8}, {8, 16}, {16, 23}};
  for (std::uint64_t k = 0; k < 3; ++k) {
    EXPECT_EQ(shard.chunk(k).begin, expected[k][0]) << k;
    EXPECT_EQ(shard.chunk(k).end, expected[k][1]) << k;
  }
  EXPECT_EQ((StudyGrid{16, 32, 8}.count()), 2u) << "a range on chunk boundaries";
  EXPECT_EQ((StudyGrid{7, 7, 8}.count()), 0u);
  EXPECT_EQ((StudyGrid{0, 3, 0}.count()), 3u) << "a chunk size of 0 is taken as 1";
  // A billion samples in chunks of 16, at the top of the 64-bit range: no overflow.
  const std::uint64_t top = ~std::uint64_t{0};
  const StudyGrid high{top - 40, top, 16};
  const StudyChunk last = high.chunk(high.count() - 1);
  EXPECT_EQ(last.end, top);
  EXPECT_GT(last.end, last.begin);
  EXPECT_EQ((StudyGrid{0, 1000000000, 16}.count()), 62500000u);
}

TEST(StudyRun, ACancelStopsAChunkWithinASample) {
  // One chunk of 2,000 samples, each a capture and half a second of motion after it (about 13 s
  // on one thread): cancelled after 100 ms.
  const auto st = std::make_shared<const Study>(loadStudy(studyFile("long.yaml",
      "scenario: " + kScenarios + "tumbling_box_capture.yaml\nsamples: 1000000\nseed: 1\n"
      "inputs: {timing: {uniform: [0, 3]}, robot.q.joint2: {uniform: [0.5, 0.9]}}\nmotion: {duration: 0.5}\n")));
  using Clock = std::chrono::steady_clock;
  std::atomic<bool> cancel{false};
  Clock::time_point cancelled;
  std::thread canceller([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    cancelled = Clock::now();
    cancel = true;
  });
  int reports = 0;
  runStudy(st, StudyGrid{0, 2000, 2000}, 1, [&](const StudyChunk&, const std::vector<double>&) { ++reports; },
           &cancel);
  const double latency = std::chrono::duration<double>(Clock::now() - cancelled).count();
  canceller.join();
  EXPECT_EQ(reports, 0) << "a chunk cut short is not reported";
  EXPECT_LT(latency, 2.0);
  RecordProperty("cancel_latency_ms", std::to_string(latency * 1e3));
  std::printf("cancel latency: %.2f ms\n", latency * 1e3);
}

}  // namespace
}  // namespace kdl_space
