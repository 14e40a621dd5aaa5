// Streaming statistics of one column of a study's table, in memory that does not grow with the
// number of values: an exact sum (so the mean does not depend on the order of the values, on how
// they were cut into blocks, or on merges) and a deterministic, mergeable quantile sketch with a
// rank-error bound it tracks as it goes. Private to the library (StudySummarizer uses them).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace kdl_space::sketch {

/// The order the summary sorts values by: the usual one, NaN after everything (so a NaN outcome
/// can neither make the order undefined nor hide in the middle).
inline bool before(double a, double b) { return a < b || (!std::isnan(a) && std::isnan(b)); }

/// \brief The exact sum of doubles (a fixed-point accumulator wide enough for any double and 2^64
/// of them, Kulisch's idea), rounded once to the nearest double at the end: the same value in
/// any order of addition and after any merge. Infinities and NaN are kept aside (inf + -inf: NaN).
class ExactSum {
 public:
  void add(double v);
  void merge(const ExactSum& other);
  /// The sum rounded to nearest (ties to even); +-inf past the largest double.
  double value() const;

 private:
  /// Bit k of the sum is worth 2^(k - 1074); limb i holds bits [32 i, 32 i + 32) (signed, carried
  /// lazily). 2098 bits for a double's range, 64 more for the count of additions.
  static constexpr int kLimbs = 68;
  void carry();
  std::array<std::int64_t, kLimbs> limb_{};
  std::uint32_t pending_ = 0;  ///< additions since the last carry (each limb takes < 2^32 each)
  bool nan_ = false, pos_inf_ = false, neg_inf_ = false;
};

/// \brief A deterministic mergeable quantile sketch (Manku, Rajagopalan and Lindsay's buffers,
/// 1998, as compactors): level 0 keeps up to kFirst values as they are (exact quantiles up to
/// kFirst values); a full level is sorted and every other value is kept (alternately the even and
/// the odd positions, level by level) at the next level with twice the weight. Each compaction at
/// level h moves the rank of any value by at most 2^h, so rankError(), their sum, bounds the
/// error of any rank: it is at most n/kFirst + n/kLevel per level above 0, i.e. a fraction
/// 1/65536 + floor(log2(n/16384))/16384 of n (under 0.1 % for 1e9 values). Memory: kFirst +
/// kLevel per level values, 2.2 MB at 1e9 values. Which values are kept depends only on the
/// values and the order of add() and merge(), never on how the values were cut into blocks.
class QuantileSketch {
 public:
  static constexpr std::size_t kFirst = 65536;  ///< values kept exactly
  static constexpr std::size_t kLevel = 16384;  ///< capacity of each level above 0

  void add(double v);
  void merge(const QuantileSketch& other);
  std::uint64_t count() const { return count_; }
  /// An upper bound on the error of any rank (0 while exact), in values.
  std::uint64_t rankError() const { return error_; }
  /// The p-quantiles (each p in [0, 1]) interpolated linearly between the order statistics of
  /// ranks floor(p (n - 1)) and the next, exactly as a sorted array would give them while exact,
  /// else from the weighted values kept: within rankError() of those ranks. Needs count() > 0.
  std::vector<double> quantiles(const std::vector<double>& p) const;

 private:
  void compact(std::size_t level);
  void compactFull();
  std::vector<std::vector<double>> levels_{1};
  std::vector<std::uint64_t> compactions_{0};  ///< per level: their parity picks the half kept
  std::uint64_t count_ = 0, error_ = 0;
};

}  // namespace kdl_space::sketch
