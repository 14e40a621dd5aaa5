// The sines and cosines of many angles at once, a speed internal of forward kinematics: glibc's
// vector maths library (libmvec) takes four angles per call where the CPU has AVX2 and two
// otherwise; std::sin and std::cos where libmvec is not there (another C library, another CPU).
// libmvec's results are within 4 ulp of the correctly rounded ones (glibc's manual).
#pragma once

#include <cstddef>

namespace kdl_space::detail {

/// s[i] = sin(t[i]), c[i] = cos(t[i]) for i < n (t finite). Any n; a multiple of 4 is fastest.
void sinesAndCosines(const double* t, double* s, double* c, std::size_t n);

}  // namespace kdl_space::detail
