// A study's table summarised, a block of rows at a time in bounded memory: quantiles of each
// outcome (a mergeable sketch, exact up to its first buffer), the probability of each limit
// exceeded, the best and worst samples by the objective with their inputs, each distinct failure
// with why.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>

#include "kdl_space/study/study.hpp"
#include "study/quantile_sketch.hpp"
#include "study/study_sampling.hpp"

namespace kdl_space {
namespace {

/// A table's status as a code (a value no code can be, for a table whose status is no whole
/// number: rows handed in by a caller, not written by a study).
int statusOf(double v) {
  const bool code = std::isfinite(v) && v == std::floor(v) && std::abs(v) < 1e9;
  return code ? static_cast<int>(v) : std::numeric_limits<int>::min();
}


/// Each distinct failure's message: its first sample evaluated again (its row may come from
/// another thread, process, shard or run). In the order of first_sample.
std::vector<StudyFailure> explained(const Study& study, std::vector<StudyFailure> list, std::size_t m) {
  std::stable_sort(list.begin(), list.end(), [](const StudyFailure& a, const StudyFailure& b) {
    return a.first_sample != b.first_sample ? a.first_sample < b.first_sample : a.status < b.status;
  });
  if (list.empty()) return list;
  StudyEvaluator evaluator(std::shared_ptr<const Study>(std::shared_ptr<const Study>(), &study));  // not owned
  std::vector<double> row(m);
  for (StudyFailure& f : list) {
    const std::string stored = "status " + std::to_string(f.status) + " (" + strError(f.status) + ")";
    if (f.first_sample >= study.samples) {
      f.message = stored + "; sample " + std::to_string(f.first_sample) + " is no sample of this study";
      continue;
    }
    evaluator.evaluate(f.first_sample, row.data());
    if (statusOf(row[1]) == f.status) {
      f.message = evaluator.failure();
    } else {  // not reproduced: the table holds a row of another run
      f.message = stored + "; evaluated again, sample " + std::to_string(f.first_sample) +
                  (row[1] == 0.0 ? " computes" : " fails with status " + std::to_string(statusOf(row[1])) + ": " + evaluator.failure());
    }
  }
  return list;
}

/// A table's sample index (a double) as an index (~0 for a value that is none).
std::uint64_t sampleOf(double i) { return i >= 0.0 && i < 1e18 ? static_cast<std::uint64_t>(i) : ~std::uint64_t{0}; }

/// A computed sample as the best and worst lists keep it.
struct Ranked {
  double objective = 0.0, sample = 0.0;  ///< as in the table
  std::vector<double> inputs;
};

/// The order of the ranking: by the objective, ties by sample index (so any order of rows, any
/// cut into blocks and any merge gives the same lists); NaN after everything.
bool ranksBefore(const Ranked& a, const Ranked& b) {
  if (sketch::before(a.objective, b.objective)) return true;
  if (sketch::before(b.objective, a.objective)) return false;
  return sketch::before(a.sample, b.sample);
}

constexpr std::size_t kRanked = 5;

}  // namespace

struct StudySummarizer::State {
  struct Failed {
    int status = 0;
    std::uint64_t count = 0, first = 0;
  };
  struct Column {
    bool limit = false;  ///< an exceeds.* column: only its sum (the probability)
    sketch::ExactSum sum;
    sketch::QuantileSketch values;
    double min = 0.0, max = 0.0;
  };
  std::shared_ptr<const Study> study;
  std::vector<std::string> columns;
  std::size_t m = 0, first_outcome = 2, objective = 0;  ///< objective == m: no such column
  std::uint64_t samples = 0, failed = 0, computed = 0;
  std::vector<Failed> failures;  ///< in the order first seen
  std::vector<Column> outcomes;  ///< columns first_outcome..m-1
  std::vector<Ranked> best, worst;  ///< ascending; descending
  /// One grid point's samples (sample i is at point i mod grid): per outcome column its exact sum,
  /// a quantile sketch (for its q95; exact up to 65,536 values) and its max.
  struct Point {
    std::uint64_t count = 0, failed = 0;
    std::vector<double> inputs;  ///< the grid inputs' values (the same in every row of the point)
    std::vector<sketch::ExactSum> sum;
    std::vector<sketch::QuantileSketch> values;
    std::vector<double> max;
  };
  std::vector<std::size_t> grid_columns;  ///< the grid inputs' columns; empty: no grid
  std::uint64_t grid = 1;
  std::map<std::uint64_t, Point> points;  ///< bounded by the grid's size, not the samples

  Point& point(std::uint64_t index, const double* row) {
    auto [it, added] = points.try_emplace(index);
    Point& p = it->second;
    if (added) {
      for (const std::size_t c : grid_columns) p.inputs.push_back(row[c]);
      p.sum.resize(outcomes.size());
      p.values.resize(outcomes.size());
      p.max.assign(outcomes.size(), 0.0);
    }
    return p;
  }

  void addToPoint(const double* row, bool computed_row) {
    const std::uint64_t i = sampleOf(row[0]);
    Point& p = point(i == ~std::uint64_t{0} ? i : i % grid, row);
    if (!computed_row) {
      ++p.failed;
      return;
    }
    const bool first = p.count++ == 0;
    for (std::size_t k = 0; k < outcomes.size(); ++k) {
      const double v = row[first_outcome + k];
      p.sum[k].add(v);
      if (outcomes[k].limit) continue;
      p.values[k].add(v);
      if (first || sketch::before(p.max[k], v)) p.max[k] = v;
    }
  }

  void mergePoint(std::uint64_t index, const Point& o) {
    auto [it, added] = points.try_emplace(index, o);
    if (added) return;
    Point& p = it->second;
    for (std::size_t k = 0; k < outcomes.size() && o.count > 0; ++k) {
      p.sum[k].merge(o.sum[k]);
      if (outcomes[k].limit) continue;
      p.values[k].merge(o.values[k]);
      if (p.count == 0 || sketch::before(p.max[k], o.max[k])) p.max[k] = o.max[k];
    }
    p.count += o.count, p.failed += o.failed;
  }

  void fail(int status, std::uint64_t count, std::uint64_t first) {
    auto f = std::find_if(failures.begin(), failures.end(), [&](const Failed& x) { return x.status == status; });
    if (f == failures.end()) f = failures.insert(failures.end(), Failed{status, 0, first});
    f->count += count;
    f->first = std::min(f->first, first);
  }

  /// Keeps r if it is among the kRanked first of `list` in the order `before` (ties: after).
  template <class Before>
  static void rank(std::vector<Ranked>& list, const Ranked& r, const Before& before) {
    if (list.size() >= kRanked && !before(r, list.back())) return;
    list.insert(std::upper_bound(list.begin(), list.end(), r, before), r);
    if (list.size() > kRanked) list.pop_back();
  }
  static bool worse(const Ranked& a, const Ranked& b) { return ranksBefore(b, a); }

  void add(const double* row) {
    ++samples;
    if (!grid_columns.empty()) addToPoint(row, row[1] == 0.0);
    if (row[1] != 0.0) {
      ++failed;
      fail(statusOf(row[1]), 1, sampleOf(row[0]));
      return;
    }
    const bool first = computed++ == 0;
    for (std::size_t c = first_outcome; c < m; ++c) {
      Column& col = outcomes[c - first_outcome];
      const double v = row[c];
      col.sum.add(v);
      if (col.limit) continue;
      col.values.add(v);
      if (first || sketch::before(v, col.min)) col.min = v;
      if (first || sketch::before(col.max, v)) col.max = v;
    }
    if (objective >= m) return;
    const Ranked key{row[objective], row[0], {}};
    const bool is_best = best.size() < kRanked || ranksBefore(key, best.back());
    const bool is_worst = worst.size() < kRanked || worse(key, worst.back());
    if (!is_best && !is_worst) return;
    const Ranked r{key.objective, key.sample, std::vector<double>(row + 2, row + first_outcome)};
    if (is_best) rank(best, r, ranksBefore);
    if (is_worst) rank(worst, r, worse);
  }
};

StudySummarizer::StudySummarizer(std::shared_ptr<const Study> study) : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.columns = studyColumns(*study);
  s.m = s.columns.size();
  for (const StudyInput& in : study->inputs) s.first_outcome += static_cast<std::size_t>(sampling::valuesOf(in));
  s.objective = static_cast<std::size_t>(std::find(s.columns.begin(), s.columns.end(), study->objective) - s.columns.begin());
  s.outcomes.resize(s.m - s.first_outcome);
  for (std::size_t c = s.first_outcome; c < s.m; ++c) s.outcomes[c - s.first_outcome].limit = s.columns[c].rfind("exceeds.", 0) == 0;
  std::size_t c = 2;
  for (const StudyInput& in : study->inputs) {
    if (in.distribution.kind == Distribution::Kind::Grid) s.grid_columns.push_back(c);
    c += static_cast<std::size_t>(sampling::valuesOf(in));
  }
  s.grid = sampling::gridSize(*study);
  s.study = std::move(study);
}

StudySummarizer::~StudySummarizer() = default;
StudySummarizer::StudySummarizer(StudySummarizer&&) noexcept = default;
StudySummarizer& StudySummarizer::operator=(StudySummarizer&&) noexcept = default;

void StudySummarizer::add(const double* rows, std::size_t n) {
  for (std::size_t r = 0; r < n; ++r) state_->add(rows + r * state_->m);
}

void StudySummarizer::merge(const StudySummarizer& other) {
  State& s = *state_;
  const State& o = *other.state_;
  for (const State::Failed& f : o.failures) s.fail(f.status, f.count, f.first);
  for (std::size_t c = 0; c < s.outcomes.size() && c < o.outcomes.size(); ++c) {
    State::Column& a = s.outcomes[c];
    const State::Column& b = o.outcomes[c];
    a.sum.merge(b.sum);
    if (a.limit || o.computed == 0) continue;
    a.values.merge(b.values);
    if (s.computed == 0 || sketch::before(b.min, a.min)) a.min = b.min;
    if (s.computed == 0 || sketch::before(a.max, b.max)) a.max = b.max;
  }
  for (const auto& [index, p] : o.points) s.mergePoint(index, p);
  for (const Ranked& r : o.best) State::rank(s.best, r, ranksBefore);
  for (const Ranked& r : o.worst) State::rank(s.worst, r, State::worse);
  s.samples += o.samples, s.failed += o.failed, s.computed += o.computed;
}

namespace {

/// A grid point's aggregate by name: an outcome's mean, q95 or max, an exceeds.* probability.
std::optional<double> statisticOf(const GridPointSummary& p, const std::string& outcome, const std::string& statistic) {
  for (const GridPointSummary::Outcome& o : p.outcomes)
    if (o.name == outcome) return statistic == "q95" ? o.q95 : statistic == "max" ? o.max : o.mean;
  for (const auto& [name, v] : p.probabilities)
    if (name == outcome) return v;
  return std::nullopt;
}

}  // namespace

/// The summary's grid points (their aggregates) and, with an objective's statistic, their ranking.
void StudySummarizer::gridPoints(const State& st, StudySummary& s) {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  for (const auto& [index, p] : st.points) {
    GridPointSummary g;
    g.index = index, g.count = p.count, g.failed = p.failed;
    for (std::size_t k = 0; k < st.grid_columns.size(); ++k) g.inputs.emplace_back(st.columns[st.grid_columns[k]], p.inputs[k]);
    const double n = static_cast<double>(p.count);
    for (std::size_t k = 0; k < st.outcomes.size(); ++k) {
      const std::string& name = st.columns[st.first_outcome + k];
      const double mean = p.count ? p.sum[k].value() / n : nan;
      if (st.outcomes[k].limit) {
        g.probabilities.emplace_back(name, mean);
        continue;
      }
      g.outcomes.push_back({name, mean, p.count ? p.values[k].quantiles({0.95})[0] : nan, p.count ? p.max[k] : nan});
    }
    s.grid_points.push_back(std::move(g));
  }
  const Study& study = *st.study;
  if (study.objective_statistic.empty()) return;
  std::vector<GridPointDigest> ranked;
  for (const GridPointSummary& g : s.grid_points) {
    const std::optional<double> v = statisticOf(g, study.objective, study.objective_statistic);
    if (g.count > 0 && v) ranked.push_back(GridPointDigest{g.index, g.count, *v, g.inputs});
  }
  // By the statistic (NaN last), ties by the point's index: the same for any order of the rows.
  std::sort(ranked.begin(), ranked.end(), [](const GridPointDigest& a, const GridPointDigest& b) {
    if (sketch::before(a.objective, b.objective)) return true;
    if (sketch::before(b.objective, a.objective)) return false;
    return a.index < b.index;
  });
  const std::size_t k = std::min(kRanked, ranked.size());
  s.best_grid_points.assign(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(k));
  std::stable_sort(ranked.begin(), ranked.end(), [](const GridPointDigest& a, const GridPointDigest& b) {
    return sketch::before(b.objective, a.objective);  // largest first, ties keep the index order
  });
  s.worst_grid_points.assign(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(k));
}

StudySummary StudySummarizer::finish() const {
  const State& st = *state_;
  StudySummary s;
  s.samples = st.samples, s.failed = st.failed;
  for (const State::Failed& f : st.failures) s.failures.push_back(StudyFailure{f.status, f.count, f.first, ""});
  s.failures = explained(*st.study, std::move(s.failures), st.m);
  const double n = static_cast<double>(st.computed);
  for (std::size_t c = st.first_outcome; c < st.m; ++c) {
    const State::Column& col = st.outcomes[c - st.first_outcome];
    if (col.limit) {
      s.probabilities.emplace_back(st.columns[c], st.computed == 0 ? 0.0 : col.sum.value() / n);
      continue;
    }
    if (st.computed == 0) continue;
    const std::vector<double> q = col.values.quantiles({0.05, 0.25, 0.5, 0.75, 0.95});
    OutcomeSummary o;
    o.name = st.columns[c];
    o.min = col.min, o.max = col.max;
    o.q05 = q[0], o.q25 = q[1], o.median = q[2], o.q75 = q[3], o.q95 = q[4];
    o.mean = col.sum.value() / n;
    s.outcomes.push_back(o);
    s.quantile_rank_error = std::max(s.quantile_rank_error, static_cast<double>(col.values.rankError()) / n);
  }
  const auto digests = [&](const std::vector<Ranked>& list, std::vector<SampleDigest>& out) {
    for (const Ranked& r : list) {
      SampleDigest d;
      d.sample = sampleOf(r.sample);
      d.objective = r.objective;
      for (std::size_t c = 2; c < st.first_outcome; ++c) d.inputs.emplace_back(st.columns[c], r.inputs[c - 2]);
      out.push_back(std::move(d));
    }
  };
  digests(st.best, s.best);
  digests(st.worst, s.worst);
  gridPoints(st, s);
  return s;
}

StudySummary summarizeStudy(const Study& study, const std::vector<double>& rows) {
  StudySummarizer summarizer(std::shared_ptr<const Study>(std::shared_ptr<const Study>(), &study));  // not owned
  const std::size_t m = studyColumns(study).size();
  summarizer.add(rows.data(), rows.size() / m);
  return summarizer.finish();
}

}  // namespace kdl_space
