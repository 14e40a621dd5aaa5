// A study's table summarised: quantiles of each outcome, the probability of each limit exceeded,
// the best and worst samples by the objective with their inputs.
#include <algorithm>
#include <cmath>

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
