// The exact sum and the quantile sketch behind a study's streamed summary (quantile_sketch.hpp).
#include "study/quantile_sketch.hpp"

#include <algorithm>
#include <cstring>
#include <utility>

namespace kdl_space::sketch {

void ExactSum::add(double v) {
  if (!std::isfinite(v)) {
    (std::isnan(v) ? nan_ : v > 0 ? pos_inf_ : neg_inf_) = true;
    return;
  }
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  const int exponent = static_cast<int>((bits >> 52) & 0x7ff);
  std::uint64_t mantissa = bits & ((std::uint64_t{1} << 52) - 1);
  if (exponent != 0) mantissa |= std::uint64_t{1} << 52;
  // v = +-mantissa 2^(position - 1074): bits [position, position + 53) of the accumulator.
  const int position = exponent == 0 ? 0 : exponent - 1;
  const int at = position / 32, shift = position % 32;
  const std::uint64_t low = (mantissa << shift) & 0xffffffffULL;
  const std::uint64_t mid = (mantissa >> (32 - shift)) & 0xffffffffULL;  // shift < 32: defined
  const std::uint64_t high = shift == 0 ? 0 : mantissa >> (64 - shift);
  const std::int64_t sign = bits >> 63 ? -1 : 1;
  limb_[at] += sign * static_cast<std::int64_t>(low);
  limb_[at + 1] += sign * static_cast<std::int64_t>(mid);
  limb_[at + 2] += sign * static_cast<std::int64_t>(high);
  if (++pending_ == (1u << 30)) carry();  // a limb stays below 2^62 in magnitude
}

void ExactSum::carry() {
  for (int i = 0; i + 1 < kLimbs; ++i) {
    const std::int64_t c = limb_[i] >> 32;  // floor division: limb_[i] - (c << 32) in [0, 2^32)
    limb_[i] -= c * (std::int64_t{1} << 32);
    limb_[i + 1] += c;
  }
  pending_ = 0;
}

void ExactSum::merge(const ExactSum& other) {
  ExactSum o = other;
  o.carry();
  carry();
  for (int i = 0; i < kLimbs; ++i) limb_[i] += o.limb_[i];
  carry();
  nan_ |= o.nan_, pos_inf_ |= o.pos_inf_, neg_inf_ |= o.neg_inf_;
}

double ExactSum::value() const {
  if (nan_ || (pos_inf_ && neg_inf_)) return std::nan("");
  if (pos_inf_ || neg_inf_) return pos_inf_ ? HUGE_VAL : -HUGE_VAL;
  ExactSum s = *this;
  s.carry();  // now limbs 0..kLimbs-2 in [0, 2^32), the last one carries the sign
  const bool negative = s.limb_[kLimbs - 1] < 0;
  if (negative) {
    for (std::int64_t& l : s.limb_) l = -l;
    s.carry();
  }
  const auto& l = s.limb_;
  int top = kLimbs - 1;
  while (top >= 0 && l[top] == 0) --top;
  if (top < 0) return 0.0;
  int length = 32 * top;  // the number of bits of the magnitude
  for (std::uint64_t x = static_cast<std::uint64_t>(l[top]); x; x >>= 1) ++length;
  const auto bit = [&](int k) { return (static_cast<std::uint64_t>(l[k / 32]) >> (k % 32)) & 1; };
  // The 53 leading bits (all of them if fewer: a subnormal or small normal, exact), rounded to
  // nearest, ties to even, on the bits below.
  const int cut = std::max(0, length - 53);
  std::uint64_t mantissa = 0;
  for (int k = length - 1; k >= cut; --k) mantissa = (mantissa << 1) | bit(k);
  if (cut > 0 && bit(cut - 1)) {
    bool sticky = false;
    for (int k = 0; k < cut - 1 && !sticky; ++k) sticky = bit(k) != 0;
    if (sticky || (mantissa & 1)) ++mantissa;
  }
  const double magnitude = std::ldexp(static_cast<double>(mantissa), cut - 1074);
  return negative ? -magnitude : magnitude;
}

void QuantileSketch::add(double v) {
  if (levels_[0].size() >= kFirst) compact(0);
  levels_[0].push_back(v);
  ++count_;
}

void QuantileSketch::compact(std::size_t h) {
  if (levels_.size() == h + 1) {
    levels_.emplace_back();
    compactions_.push_back(0);
  }
  std::vector<double>& level = levels_[h];
  std::sort(level.begin(), level.end(), before);
  // An even count is halved; with an odd count the largest value stays here, unweighted.
  const std::size_t even = level.size() & ~std::size_t{1};
  std::vector<double>& up = levels_[h + 1];
  for (std::size_t k = compactions_[h] % 2; k < even; k += 2) up.push_back(level[k]);
  level.erase(level.begin(), level.begin() + static_cast<std::ptrdiff_t>(even));
  ++compactions_[h];
  error_ += std::uint64_t{1} << h;  // every rank moves by at most one weight of this level
  if (up.size() > kLevel) compact(h + 1);
}

void QuantileSketch::compactFull() {
  for (std::size_t h = 0; h < levels_.size(); ++h)
    if (levels_[h].size() > (h == 0 ? kFirst : kLevel)) compact(h);
}

void QuantileSketch::merge(const QuantileSketch& other) {
  for (std::size_t h = 0; h < other.levels_.size(); ++h) {
    if (h == levels_.size()) {
      levels_.emplace_back();
      compactions_.push_back(0);
    }
    levels_[h].insert(levels_[h].end(), other.levels_[h].begin(), other.levels_[h].end());
  }
  count_ += other.count_;
  error_ += other.error_;
  compactFull();
}

std::vector<double> QuantileSketch::quantiles(const std::vector<double>& p) const {
  // The kept values with their weights, sorted: the weighted order statistics.
  std::vector<std::pair<double, std::uint64_t>> kept;
  for (std::size_t h = 0; h < levels_.size(); ++h)
    for (const double v : levels_[h]) kept.emplace_back(v, std::uint64_t{1} << h);
  std::sort(kept.begin(), kept.end(), [](const auto& a, const auto& b) { return before(a.first, b.first); });
  std::vector<std::uint64_t> end(kept.size());  // the ranks [end - weight, end) of each kept value
  std::uint64_t total = 0;
  for (std::size_t k = 0; k < kept.size(); ++k) end[k] = total += kept[k].second;
  const auto at = [&](std::uint64_t rank) {
    return kept[static_cast<std::size_t>(std::upper_bound(end.begin(), end.end(), rank) - end.begin())].first;
  };
  std::vector<double> q;
  for (const double pk : p) {
    const double x = pk * static_cast<double>(total - 1);
    const std::uint64_t k = static_cast<std::uint64_t>(std::floor(x));
    if (k + 1 >= total) {
      q.push_back(kept.back().first);
      continue;
    }
    const double a = at(k), b = at(k + 1);
    q.push_back(a + (x - static_cast<double>(k)) * (b - a));
  }
  return q;
}

}  // namespace kdl_space::sketch
