// The approach guard's QP (src/simulation/box_qp): the point nearest u in the metric H inside a
// box, against another route (every assignment of the coordinates to free / lower / upper, the
// one that meets the optimality conditions), and the projection's own properties: the minimiser
// is feasible, u inside the box is returned as it is, and a projection onto a convex set is
// nonexpansive in its metric (|x(u1) - x(u2)|_H <= |u1 - u2|_H: continuous, what the approach's
// servos need of their commands).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>
#include <random>

#include "simulation/box_qp.hpp"

namespace kdl_space::test {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Problem {
  Eigen::MatrixXd H;
  Eigen::VectorXd u, lo, hi;
};

/// H = B^T B + 0.05 E (B 6 x n: like A^T A + mu E of a hand's Jacobian), a box around 0 with
/// some sides infinite, u mostly outside it.
Problem random(std::mt19937& rng, int n) {
  std::normal_distribution<double> N01;
  std::uniform_real_distribution<double> U(0.05, 1.0);
  Problem p;
  Eigen::MatrixXd B(6, n);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < n; ++j) B(i, j) = N01(rng);
  p.H = B.transpose() * B;
  p.H.diagonal().array() += 0.05;
  p.u.resize(n);
  p.lo.resize(n);
  p.hi.resize(n);
  for (int j = 0; j < n; ++j) {
    p.u(j) = 2.0 * N01(rng);
    p.lo(j) = (j % 5 == 4) ? -kInf : -U(rng);
    p.hi(j) = (j % 7 == 6) ? kInf : U(rng);
  }
  return p;
}

/// Another route: over the 3^n assignments, the one whose equality-constrained minimiser is
/// feasible with every held coordinate's multiplier outward (the KKT conditions: one, H > 0).
Eigen::VectorXd byEveryActiveSet(const Problem& p) {
  const int n = static_cast<int>(p.u.size());
  int total = 1;
  for (int j = 0; j < n; ++j) total *= 3;
  Eigen::VectorXd found;
  int solutions = 0;
  for (int code = 0; code < total; ++code) {
    std::vector<int> at(n);
    bool finite = true;
    for (int j = 0, c = code; j < n; ++j, c /= 3) {
      at[j] = c % 3 - 1;  // -1 lower, 0 free, +1 upper
      if ((at[j] < 0 && !std::isfinite(p.lo(j))) || (at[j] > 0 && !std::isfinite(p.hi(j)))) finite = false;
    }
    if (!finite) continue;
    // x = u + d; held: d_j fixed; free: (H d)_F = 0.
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n);
    Eigen::VectorXd r = Eigen::VectorXd::Zero(n);
    for (int j = 0; j < n; ++j) {
      if (at[j]) {
        M(j, j) = 1.0;
        r(j) = (at[j] < 0 ? p.lo(j) : p.hi(j)) - p.u(j);
      } else {
        M.row(j) = p.H.row(j);
      }
    }
    const Eigen::VectorXd d = M.fullPivLu().solve(r);
    const Eigen::VectorXd x = p.u + d, g = p.H * d;
    bool kkt = true;
    for (int j = 0; j < n && kkt; ++j) {
      kkt = x(j) >= p.lo(j) - 1e-12 && x(j) <= p.hi(j) + 1e-12;
      if (at[j] > 0) kkt = kkt && g(j) <= 1e-12;
      if (at[j] < 0) kkt = kkt && g(j) >= -1e-12;
    }
    if (kkt) {
      found = x;
      ++solutions;
    }
  }
  EXPECT_GE(solutions, 1);
  return found;
}

double hNorm(const Eigen::MatrixXd& H, const Eigen::VectorXd& v) { return std::sqrt(v.dot(H * v)); }

TEST(NearestInBox, IsTheMinimiserTheKktConditionsSingleOutOfEveryActiveSet) {
  std::mt19937 rng(20261130);
  for (const int n : {1, 2, 3, 5, 7}) {
    for (int trial = 0; trial < 40; ++trial) {
      const Problem p = random(rng, n);
      std::vector<int> at;
      const Eigen::VectorXd x = detail::nearestInBox(p.H, p.u, p.lo, p.hi, at);
      const Eigen::VectorXd truth = byEveryActiveSet(p);
      ASSERT_EQ(truth.size(), n);
      SCOPED_TRACE("n " + std::to_string(n) + " trial " + std::to_string(trial));
      EXPECT_LE((x - truth).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + truth.cwiseAbs().maxCoeff()));
      for (int j = 0; j < n; ++j) {
        EXPECT_GE(x(j), p.lo(j));
        EXPECT_LE(x(j), p.hi(j));
        if (at[j] > 0) EXPECT_EQ(x(j), p.hi(j));
        if (at[j] < 0) EXPECT_EQ(x(j), p.lo(j));
      }
    }
  }
}

TEST(NearestInBox, InsideTheBoxIsItselfAndTheProjectionIsNonexpansiveInItsMetric) {
  std::mt19937 rng(7);
  std::normal_distribution<double> N01;
  for (int trial = 0; trial < 200; ++trial) {
    Problem p = random(rng, 7);
    std::vector<int> at;
    const Eigen::VectorXd inside = 0.5 * (p.lo.cwiseMax(-1.0) + p.hi.cwiseMin(1.0));
    EXPECT_EQ(detail::nearestInBox(p.H, inside, p.lo, p.hi, at), inside);
    for (const int a : at) EXPECT_EQ(a, 0);
    Eigen::VectorXd u2 = p.u;
    for (int j = 0; j < 7; ++j) u2(j) += (trial % 2 ? 1e-6 : 0.3) * N01(rng);
    const Eigen::VectorXd x1 = detail::nearestInBox(p.H, p.u, p.lo, p.hi, at);
    const Eigen::VectorXd x2 = detail::nearestInBox(p.H, u2, p.lo, p.hi, at);
    EXPECT_LE(hNorm(p.H, x1 - x2), hNorm(p.H, p.u - u2) * (1.0 + 1e-9) + 1e-14);
  }
}

}  // namespace
}  // namespace kdl_space::test
