// A study's table summarised, a block of rows at a time in bounded memory: quantiles of each
// outcome (a mergeable sketch, exact up to its first buffer), the probability of each limit
// exceeded, the best and worst samples by the objective with their inputs, each distinct failure
// with why.
#include <algorithm>
#include <cmath>
#include <limits>

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
  for (const Ranked& r : o.best) State::rank(s.best, r, ranksBefore);
  for (const Ranked& r : o.worst) State::rank(s.worst, r, State::worse);
  s.samples += o.samples, s.failed += o.failed, s.computed += o.computed;
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
  return s;
}

StudySummary summarizeStudy(const Study& study, const std::vector<double>& rows) {
  StudySummarizer summarizer(std::shared_ptr<const Study>(std::shared_ptr<const Study>(), &study));  // not owned
  const std::size_t m = studyColumns(study).size();
  summarizer.add(rows.data(), rows.size() / m);
  return summarizer.finish();
}

}  // namespace kdl_space
