#include "simulation/box_qp.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstddef>

namespace kdl_space::detail {

Eigen::VectorXd nearestInBox(const Eigen::MatrixXd& H, const Eigen::VectorXd& u, const Eigen::VectorXd& lo,
                             const Eigen::VectorXd& hi, std::vector<int>& at) {
  const Eigen::Index n = u.size();
  // d = x - u, from the feasible clamp of u.
  Eigen::VectorXd d = Eigen::VectorXd::Zero(n);
  at.assign(static_cast<std::size_t>(n), 0);
  for (Eigen::Index j = 0; j < n; ++j) {
    if (u(j) > hi(j)) d(j) = hi(j) - u(j), at[static_cast<std::size_t>(j)] = 1;
    if (u(j) < lo(j)) d(j) = lo(j) - u(j), at[static_cast<std::size_t>(j)] = -1;
  }
  if (d.isZero(0.0)) return u;
  std::vector<Eigen::Index> F;
  for (Eigen::Index pass = 0; pass < 4 * n + 4; ++pass) {
    F.clear();
    for (Eigen::Index j = 0; j < n; ++j)
      if (!at[static_cast<std::size_t>(j)]) F.push_back(j);
    // The free coordinates' minimiser with the others held: H_FF d_F = -H_FW d_W.
    Eigen::VectorXd step = Eigen::VectorXd::Zero(n);
    if (!F.empty()) {
      const Eigen::Index f = static_cast<Eigen::Index>(F.size());
      Eigen::MatrixXd H_FF(f, f);
      Eigen::VectorXd rhs = Eigen::VectorXd::Zero(f);
      for (Eigen::Index a = 0; a < f; ++a) {
        for (Eigen::Index j = 0; j < n; ++j)
          if (at[static_cast<std::size_t>(j)]) rhs(a) -= H(F[a], j) * d(j);
        for (Eigen::Index c = 0; c < f; ++c) H_FF(a, c) = H(F[a], F[c]);
      }
      const Eigen::VectorXd d_F = H_FF.ldlt().solve(rhs);
      for (Eigen::Index a = 0; a < f; ++a) step(F[a]) = d_F(a) - d(F[a]);
    }
    // Along the step to the first bound it meets (that bound then held) ...
    double alpha = 1.0;
    Eigen::Index blocking = -1;
    for (const Eigen::Index j : F) {
      const double x = u(j) + d(j), to = step(j) > 0.0 ? hi(j) - x : lo(j) - x;
      if (step(j) != 0.0 && std::isfinite(to) && to / step(j) < alpha) {
        alpha = std::max(0.0, to / step(j));
        blocking = j;
      }
    }
    d += alpha * step;
    if (blocking >= 0) {
      at[static_cast<std::size_t>(blocking)] = step(blocking) > 0.0 ? 1 : -1;
      d(blocking) = (step(blocking) > 0.0 ? hi(blocking) : lo(blocking)) - u(blocking);
      continue;
    }
    // ... or, at the minimiser with these bounds held, each held coordinate's multiplier must push
    // it outwards: the one held back most for nothing is let go (round-off aside).
    const Eigen::VectorXd g = H * d;
    double worst_g = 1e-12 * H.diagonal().maxCoeff() * d.cwiseAbs().maxCoeff();
    Eigen::Index worst = -1;
    for (Eigen::Index j = 0; j < n; ++j) {
      const double wrong = at[static_cast<std::size_t>(j)] * g(j);  // > 0: moving inwards lowers the cost
      if (wrong > worst_g) worst_g = wrong, worst = j;
    }
    if (worst < 0) break;
    at[static_cast<std::size_t>(worst)] = 0;
  }
  Eigen::VectorXd x = u + d;
  for (Eigen::Index j = 0; j < n; ++j)  // held exactly at its bound (u + (b - u) may round off it)
    if (at[static_cast<std::size_t>(j)]) x(j) = at[static_cast<std::size_t>(j)] > 0 ? hi(j) : lo(j);
  return x;
}

}  // namespace kdl_space::detail
