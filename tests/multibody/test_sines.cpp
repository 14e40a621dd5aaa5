// detail::sinesAndCosines (src/detail/sines): glibc's vector sines (libmvec) where there, against
// std::sin and std::cos, for every count (the four-, two- and one-at-a-time parts).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "detail/sines.hpp"

namespace {

TEST(Sines, AgreeWithTheScalarFunctionsForEveryCount) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> angle(-10.0, 10.0);
  std::vector<double> special{0.0, -0.0, M_PI / 2, -M_PI / 2, M_PI, -M_PI, 1e-300, 3e-8, 1e6, -1e6, 1e22};
  const double eps = std::numeric_limits<double>::epsilon();
  for (std::size_t n = 0; n <= 2 * special.size() + 5; ++n) {
    std::vector<double> t(n), s(n + 1, std::nan("")), c(n + 1, std::nan(""));
    for (std::size_t i = 0; i < n; ++i) t[i] = i < special.size() && n % 2 ? special[i] : angle(rng);
    s[n] = c[n] = 7.0;  // past the end: not written
    kdl_space::detail::sinesAndCosines(t.data(), s.data(), c.data(), n);
    for (std::size_t i = 0; i < n; ++i) {
      // within 4 ulp of the correctly rounded value (libmvec's bound); std::sin is within 1
      EXPECT_NEAR(s[i], std::sin(t[i]), 5 * eps * std::max(std::abs(std::sin(t[i])), 0x1p-1022)) << "n " << n << " t " << t[i];
      EXPECT_NEAR(c[i], std::cos(t[i]), 5 * eps * std::max(std::abs(std::cos(t[i])), 0x1p-1022)) << "n " << n << " t " << t[i];
    }
    EXPECT_EQ(s[n], 7.0);
    EXPECT_EQ(c[n], 7.0);
  }
}

}  // namespace
