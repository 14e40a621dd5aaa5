// Which route computes G* (and so the capture) for a model with mimic joints: the O(n) recursion
// with the k couplings as constraints (algorithm/mimic_coupling.hpp, O(n k + k^3)) or the dense route
// (T^T H T, O(n^3)). Private to the library; header-only so that the tests call it.
#pragma once

#include <cstddef>

namespace kdl_space::detail {

/// \brief True when G* of a model with `coordinates` movable joints that are coordinates and
/// `mimic` mimic joints is faster by the recursion than by the dense route: 4 k <= n (k at most a
/// fifth of all the movable joints, n + k). Derived from kdl_space_bench's mimic section
/// (docs/benchmarks.md, "Mimic joints on the O(n) route"): the recursion's G* is 1.3x faster at
/// k / (n + k) = 1/5 (grippers N=20) and 1.7x to 5.5x below it (grippers N=30 to 100), but 0.88x at
/// 2/5 (grippers N=10) and 0.6x to 0.9x at 1/3 (hands, every N from 10 to 100). No mimic joint:
/// the recursion. The forward dynamics needs no rule: its recursion was at least as fast as the
/// dense route in every case measured but one (hands N=30, 0.94x), up to 8x faster.
inline bool mimicGStarTakesRecursion(std::size_t coordinates, std::size_t mimic) {
  return 4 * mimic <= coordinates;
}

}  // namespace kdl_space::detail
