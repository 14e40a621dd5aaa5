// A study's table summarised: quantiles of each outcome, the probability of each limit exceeded,
// the best and worst samples by the objective with their inputs, each distinct failure with why.
#include <algorithm>
#include <cmath>
#include <limits>

#include "kdl_space/study/study.hpp"
#include "study/study_sampling.hpp"

namespace kdl_space {
namespace {

/// The p-quantile of sorted values, interpolated linearly between order statistics.
double quantile(const std::vector<double>& sorted, double p) {
  const double x = p * static_cast<double>(sorted.size() - 1);
  const std::size_t k = static_cast<std::size_t>(std::floor(x));
  if (k + 1 >= sorted.size()) return sorted.back();
  return sorted[k] + (x - static_cast<double>(k)) * (sorted[k + 1] - sorted[k]);
}

/// A table's status as a code (a value no code can be, for a table whose status is no whole
/// number: rows handed in by a caller, not written by a study).
int statusOf(double v) {
  const bool code = std::isfinite(v) && v == std::floor(v) && std::abs(v) < 1e9;
  return code ? static_cast<int>(v) : std::numeric_limits<int>::min();
}

/// Each distinct status of the failed rows: how many, the first sample, and why (that sample
/// evaluated again: its row may come from another thread, process, shard or run).
std::vector<StudyFailure> failures(const Study& study, const std::vector<double>& rows, std::size_t m) {
  std::vector<StudyFailure> list;
  for (std::size_t r = 0; r < rows.size() / m; ++r) {
    if (rows[r * m + 1] == 0.0) continue;
    const int status = statusOf(rows[r * m + 1]);
    const double i = rows[r * m];
    const std::uint64_t sample = i >= 0.0 && i < 1e18 ? static_cast<std::uint64_t>(i) : ~std::uint64_t{0};
    auto f = std::find_if(list.begin(), list.end(), [&](const StudyFailure& x) { return x.status == status; });
    if (f == list.end()) f = list.insert(list.end(), StudyFailure{status, 0, sample, ""});
    ++f->count;
    f->first_sample = std::min(f->first_sample, sample);
  }
  std::sort(list.begin(), list.end(), [](const StudyFailure& a, const StudyFailure& b) { return a.first_sample < b.first_sample; });
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

}  // namespace

StudySummary summarizeStudy(const Study& study, const std::vector<double>& rows) {
  const std::vector<std::string> columns = studyColumns(study);
  const std::size_t m = columns.size(), count = rows.size() / m;
  std::size_t first_outcome = 2;
  for (const StudyInput& in : study.inputs) first_outcome += static_cast<std::size_t>(sampling::valuesOf(in));
  StudySummary s;
  s.samples = count;
  std::vector<std::size_t> good;
  for (std::size_t r = 0; r < count; ++r) (rows[r * m + 1] == 0.0 ? good.push_back(r) : void(++s.failed));
  s.failures = failures(study, rows, m);
  std::vector<double> values(good.size());
  for (std::size_t c = first_outcome; c < m; ++c) {
    for (std::size_t k = 0; k < good.size(); ++k) values[k] = rows[good[k] * m + c];
    if (columns[c].rfind("exceeds.", 0) == 0) {
      double exceeded = 0.0;
      for (const double v : values) exceeded += v;
      s.probabilities.emplace_back(columns[c], good.empty() ? 0.0 : exceeded / static_cast<double>(good.size()));
      continue;
    }
    if (good.empty()) continue;
    std::sort(values.begin(), values.end());
    OutcomeSummary o;
    o.name = columns[c];
    o.min = values.front(), o.max = values.back();
    o.q05 = quantile(values, 0.05), o.q25 = quantile(values, 0.25), o.median = quantile(values, 0.5);
    o.q75 = quantile(values, 0.75), o.q95 = quantile(values, 0.95);
    double sum = 0.0;
    for (const double v : values) sum += v;
    o.mean = sum / static_cast<double>(values.size());
    s.outcomes.push_back(o);
  }
  // Best and worst by the objective (ties by sample index, so any order of rows gives the same).
  const std::size_t obj = static_cast<std::size_t>(std::find(columns.begin(), columns.end(), study.objective) - columns.begin());
  if (obj >= m) return s;
  std::vector<std::size_t> order = good;
  const auto less = [&](std::size_t a, std::size_t b) {
    const double va = rows[a * m + obj], vb = rows[b * m + obj];
    return va != vb ? va < vb : rows[a * m] < rows[b * m];
  };
  std::sort(order.begin(), order.end(), less);
  const auto digest = [&](std::size_t r) {
    SampleDigest d;
    d.sample = static_cast<std::uint64_t>(rows[r * m]);
    d.objective = rows[r * m + obj];
    for (std::size_t c = 2; c < first_outcome; ++c) d.inputs.emplace_back(columns[c], rows[r * m + c]);
    return d;
  };
  const std::size_t k = std::min<std::size_t>(5, order.size());
  for (std::size_t i = 0; i < k; ++i) s.best.push_back(digest(order[i]));
  for (std::size_t i = 0; i < k; ++i) s.worst.push_back(digest(order[order.size() - 1 - i]));
  return s;
}

}  // namespace kdl_space
