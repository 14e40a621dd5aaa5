// A study's draws, reproducible: every number of sample i comes from a counter-based generator
// keyed by (seed, i, stream), so sample i depends on nothing else (not on the samples before it,
// the threads, the shards or the engine). Private to the library.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "kdl_space/study/study.hpp"

namespace kdl_space::sampling {

/// SplitMix64's finaliser: a bijective mix of 64 bits (Steele, Lea and Flood 2014).
std::uint64_t mix(std::uint64_t x);

/// A uniform number in (0, 1) (never 0 or 1: 53 bits and a half) from (seed, sample, stream).
double unit(std::uint64_t seed, std::uint64_t sample, std::uint64_t stream);

/// \brief The image of i under a pseudo-random permutation of [0, n) keyed by (seed, stream): a
/// balanced 4-round Feistel network on the smallest even power of two >= n, cycle-walked into
/// [0, n). O(1) per index and no table, so a Latin hypercube of 10^9 samples needs no memory.
std::uint64_t permute(std::uint64_t i, std::uint64_t n, std::uint64_t seed, std::uint64_t stream);

/// The standard normal quantile Phi^-1(p), 0 < p < 1, to full double precision (Acklam's
/// rational approximation, refined by one Halley step on erfc).
double normalQuantile(double p);

/// The standard normal distribution function Phi(x) = erfc(-x / sqrt 2) / 2, accurate in the
/// lower tail (relative error ~1e-16 down to x = -37).
double normalCdf(double x);

/// The probabilities a draw uses: unit() lies in [2^-54, 1 - 2^-53] (draw() keeps a Latin
/// hypercube's below 1), a Latin hypercube's down to 2^-54 / Study::max_samples.
constexpr double lowest_unit = 0x1p-54 / 1e9, highest_unit = 1.0 - 0x1p-53;

/// \brief The value of a non-grid distribution at probability u, 0 < u < 1 (its quantile
/// function, increasing in u): a + (b - a) u; a + b Phi^-1(u), truncated to [min, max] as
/// a + b Phi^-1(Phi(alpha) + u (Phi(beta) - Phi(alpha))) with alpha, beta the bounds in standard
/// deviations (mirrored into the lower tail, where Phi resolves them); a b^Phi^-1(u).
double quantile(const Distribution& d, double u);

/// The least and greatest values a distribution draws: a range's (uniform, grid) ends, infinite
/// if high - low overflows (a + (b - a) u would be); a normal's or log-normal's extreme draws.
std::pair<double, double> drawnRange(const Distribution& d);

/// The number of points of the study's grid (the product of its grid inputs' counts; 1 without).
std::uint64_t gridSize(const Study& study);

/// The number of values a study input puts in the table (target.tumble, target.inertia.tilt,
/// target.tumble_cone: the value and an axis, 4).
int valuesOf(const StudyInput& input);

/// \brief Sample i's inputs, in the order of study.inputs (valuesOf() each): a grid input takes
/// its value at grid point i mod gridSize() (the last grid input varying fastest); the others are
/// drawn independently, or as a Latin hypercube over the study's samples.
void draw(const Study& study, std::uint64_t i, double* values);

}  // namespace kdl_space::sampling
