// A study's draws, reproducible: every number of sample i comes from a counter-based generator
// keyed by (seed, i, stream), so sample i depends on nothing else (not on the samples before it,
// the threads, the shards or the engine). Private to the library.
#pragma once

#include <cstdint>
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

/// The number of points of the study's grid (the product of its grid inputs' counts; 1 without).
std::uint64_t gridSize(const Study& study);

/// The number of values a study input puts in the table (target.tumble: its rate and axis, 4).
int valuesOf(const StudyInput& input);

/// \brief Sample i's inputs, in the order of study.inputs (valuesOf() each): a grid input takes
/// its value at grid point i mod gridSize() (the last grid input varying fastest); the others are
/// drawn independently, or as a Latin hypercube over the study's samples.
void draw(const Study& study, std::uint64_t i, double* values);

}  // namespace kdl_space::sampling
