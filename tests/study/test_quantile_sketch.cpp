// The streamed statistics behind a study's summary (src/study/quantile_sketch, private): the exact
// sum against sums known exactly, and the quantile sketch against the exact order statistics of a
// million values of several distributions (uniform, heavy-tailed, ties, sorted, reversed), within
// the bound it reports, which stays under the bound stated in its header and docs/studies.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include "study/quantile_sketch.hpp"

namespace kdl_space {
namespace {

using sketch::ExactSum;
using sketch::QuantileSketch;

double sumOf(const std::vector<double>& values) {
  ExactSum s;
  for (const double v : values) s.add(v);
  return s.value();
}

TEST(ExactSum, SumsKnownExactly) {
  EXPECT_EQ(sumOf({}), 0.0);
  EXPECT_EQ(sumOf({1e308, 1e308, -1e308, -1e308, 1e-300}), 1e-300);  // a naive sum: inf, then nan
  EXPECT_EQ(sumOf({1.0, 1e100, 1.0, -1e100}), 2.0);                   // a naive sum: 0
  const double tiny = std::ldexp(1.0, -1074);                          // the smallest subnormal
  EXPECT_EQ(sumOf({tiny, tiny, tiny}), 3 * tiny);
  EXPECT_EQ(sumOf({-tiny, 1.0, -1.0}), -tiny);
  // Rounding to nearest, ties to even, on everything below the 53 bits kept.
  EXPECT_EQ(sumOf({1.0, std::ldexp(1.0, -53)}), 1.0);                                     // a tie: even
  EXPECT_EQ(sumOf({1.0, std::ldexp(1.0, -53), std::ldexp(1.0, -1000)}), 1.0 + std::ldexp(1.0, -52));  // above it
  EXPECT_EQ(sumOf({1.0 + std::ldexp(1.0, -52), std::ldexp(1.0, -53)}), 1.0 + std::ldexp(1.0, -51));  // a tie: even
  EXPECT_EQ(sumOf({-1.0, -std::ldexp(1.0, -53), -std::ldexp(1.0, -1074)}), -(1.0 + std::ldexp(1.0, -52)));
  EXPECT_EQ(sumOf({1.7e308, 1.7e308}), HUGE_VAL);  // past the largest double
  EXPECT_EQ(sumOf({1.7e308, 1.7e308, -1.7e308}), 1.7e308);
  EXPECT_TRUE(std::isnan(sumOf({1.0, NAN})));
  EXPECT_TRUE(std::isnan(sumOf({HUGE_VAL, -HUGE_VAL})));
  EXPECT_EQ(sumOf({HUGE_VAL, 1.0, 1e308}), HUGE_VAL);
}

TEST(ExactSum, EqualsAnIntegerSumInAnyOrderAndAfterMerges) {
  // Values k 2^-30 with |k| < 2^48: their sum is an int64 times 2^-30, which converts to the
  // nearest double (k's sum < 2^62 in magnitude), an exact reference by another route.
  std::mt19937_64 rng(3);
  std::vector<double> values;
  std::int64_t k_sum = 0;
  for (int i = 0; i < 20000; ++i) {
    const std::int64_t k = static_cast<std::int64_t>(rng() >> 16) - (std::int64_t{1} << 47);
    k_sum += k;
    values.push_back(std::ldexp(static_cast<double>(k), -30));
  }
  const double exact = std::ldexp(static_cast<double>(k_sum), -30);
  double naive = 0.0;
  for (const double v : values) naive += v;
  EXPECT_NE(naive, exact) << "the values are chosen so that a naive sum rounds";
  EXPECT_EQ(sumOf(values), exact);
  std::shuffle(values.begin(), values.end(), rng);
  EXPECT_EQ(sumOf(values), exact);
  ExactSum a, b, c;
  for (std::size_t i = 0; i < values.size(); ++i) (i % 3 == 0 ? a : i % 3 == 1 ? b : c).add(values[i]);
  c.merge(a);
  c.merge(b);
  EXPECT_EQ(c.value(), exact);
}

/// The stated bound on rankError() / n for n values (docs/studies.md).
double statedBound(double n) {
  const double levels = n > QuantileSketch::kLevel ? std::floor(std::log2(n / QuantileSketch::kLevel)) : 0.0;
  return 1.0 / QuantileSketch::kFirst + levels / QuantileSketch::kLevel;
}

/// The sketch's p-quantile lies between the exact order statistics of ranks floor(p (n - 1)) - E
/// and floor(p (n - 1)) + 1 + E, E = rankError().
void expectWithinBound(const QuantileSketch& s, std::vector<double> values, const std::string& what) {
  SCOPED_TRACE(what);
  std::sort(values.begin(), values.end());
  const std::uint64_t n = values.size(), e = s.rankError();
  ASSERT_EQ(s.count(), n);
  EXPECT_LE(static_cast<double>(e) / static_cast<double>(n), statedBound(static_cast<double>(n)));
  const std::vector<double> p = {0.0, 0.001, 0.05, 0.25, 0.5, 0.75, 0.95, 0.999, 1.0};
  const std::vector<double> q = s.quantiles(p);
  for (std::size_t k = 0; k < p.size(); ++k) {
    const std::uint64_t r = static_cast<std::uint64_t>(std::floor(p[k] * static_cast<double>(n - 1)));
    const double lo = values[r >= e ? r - e : 0], hi = values[std::min(n - 1, r + 1 + e)];
    EXPECT_LE(lo, q[k]) << "p " << p[k] << " rank error " << e;
    EXPECT_LE(q[k], hi) << "p " << p[k] << " rank error " << e;
  }
}

QuantileSketch sketchOf(const std::vector<double>& values) {
  QuantileSketch s;
  for (const double v : values) s.add(v);
  return s;
}

TEST(QuantileSketch, ExactWhileTheValuesFitItsFirstBuffer) {
  std::mt19937_64 rng(11);
  std::lognormal_distribution<double> draw(0.0, 2.0);
  std::vector<double> values(QuantileSketch::kFirst);
  for (double& v : values) v = draw(rng);
  const QuantileSketch s = sketchOf(values);
  EXPECT_EQ(s.rankError(), 0u);
  std::vector<double> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  const std::vector<double> p = {0.0, 0.05, 0.25, 0.5, 0.75, 0.95, 0.99999, 1.0};
  const std::vector<double> q = s.quantiles(p);
  for (std::size_t k = 0; k < p.size(); ++k) {  // linear interpolation between order statistics
    const double x = p[k] * static_cast<double>(sorted.size() - 1);
    const std::size_t j = static_cast<std::size_t>(x);
    const double expected = j + 1 >= sorted.size() ? sorted.back() : sorted[j] + (x - j) * (sorted[j + 1] - sorted[j]);
    EXPECT_EQ(q[k], expected) << p[k];
  }
  // One more value and it is a sketch: level 0's 65,536 values halve into 32,768 of weight 2,
  // more than level 1 holds, halved again into 16,384 of weight 4: a bound of 1 + 2 ranks.
  QuantileSketch more = s;
  more.add(1.0);
  EXPECT_EQ(more.rankError(), 3u);
}

TEST(QuantileSketch, AMillionValuesOfEachKindWithinTheBound) {
  const std::size_t n = 1000000;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> uniform(-3.0, 7.0);
  std::cauchy_distribution<double> cauchy(0.0, 1.0);
  std::uniform_int_distribution<int> few(0, 9);
  const std::vector<std::pair<std::string, std::function<double(std::size_t)>>> kinds = {
      {"uniform", [&](std::size_t) { return uniform(rng); }},
      {"cauchy (heavy tails)", [&](std::size_t) { return cauchy(rng); }},
      {"ten values (ties)", [&](std::size_t) { return static_cast<double>(few(rng)); }},
      {"sorted", [&](std::size_t i) { return static_cast<double>(i); }},
      {"reversed", [&](std::size_t i) { return -static_cast<double>(i); }},
      {"sawtooth", [&](std::size_t i) { return static_cast<double>(i % 1000); }},
  };
  for (const auto& [name, draw] : kinds) {
    std::vector<double> values(n);
    for (std::size_t i = 0; i < n; ++i) values[i] = draw(i);
    const QuantileSketch s = sketchOf(values);
    EXPECT_GT(s.rankError(), 0u) << name;
    expectWithinBound(s, values, name);
  }
  // Four million: more levels.
  std::vector<double> values(4 * n);
  for (double& v : values) v = uniform(rng) * uniform(rng);
  expectWithinBound(sketchOf(values), values, "4e6 products of uniforms");
}

TEST(QuantileSketch, MergedSketchesAreWithinTheirBoundAndDeterministic) {
  std::mt19937_64 rng(8);
  std::exponential_distribution<double> draw(2.0);
  std::vector<double> values(1500000);
  for (double& v : values) v = draw(rng);
  // Uneven parts, one of them exact (under the first buffer) and one empty.
  const std::vector<std::size_t> cuts = {0, 1000, 1000, 400000, 1100000, values.size()};
  const auto merged = [&] {
    QuantileSketch all;
    for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
      QuantileSketch part;
      for (std::size_t i = cuts[k]; i < cuts[k + 1]; ++i) part.add(values[i]);
      all.merge(part);
    }
    return all;
  };
  const QuantileSketch a = merged(), b = merged();
  expectWithinBound(a, values, "merged");
  const std::vector<double> p = {0.05, 0.25, 0.5, 0.75, 0.95};
  EXPECT_EQ(a.quantiles(p), b.quantiles(p));  // bit for bit
  EXPECT_EQ(a.rankError(), b.rankError());
  // Exact sketches merge exactly.
  QuantileSketch x = sketchOf({3.0, 1.0}), y = sketchOf({2.0, 4.0, 0.0});
  x.merge(y);
  EXPECT_EQ(x.rankError(), 0u);
  EXPECT_EQ(x.quantiles({0.0, 0.5, 0.625, 1.0}), (std::vector<double>{0.0, 2.0, 2.5, 4.0}));
}

TEST(QuantileSketch, NaNSortsLast) {
  const QuantileSketch s = sketchOf({NAN, 2.0, 1.0, 3.0});
  const std::vector<double> q = s.quantiles({0.0, 0.5, 1.0});
  EXPECT_EQ(q[0], 1.0);
  EXPECT_EQ(q[1], 2.5);
  EXPECT_TRUE(std::isnan(q[2]));
}

}  // namespace
}  // namespace kdl_space
