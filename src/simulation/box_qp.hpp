// The point nearest a given one, in a quadratic metric, inside a box: the approach's joint-limit
// guard (the rates nearest the task's with every joint's rate within its bounds).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace kdl_space::detail {

/// \brief argmin (x - u)^T H (x - u) / 2 subject to lo <= x <= hi (H symmetric positive definite
/// n x n; lo <= hi, infinite bounds allowed): a strictly convex QP, so the minimiser is unique and
/// continuous in (H, u, lo, hi). By the primal active-set method (Nocedal and Wright, Numerical
/// Optimization, 2nd ed., 16.5) from the clamp of u into the box: each pass moves the free
/// coordinates to their minimiser with the others held, stopping at the first bound it meets
/// (then held), or lets go the held coordinate whose multiplier has the wrong sign; at most
/// 4 n + 4 passes (each leaves x feasible). `at` is set per coordinate: -1 held at lo, +1 at hi,
/// 0 free. u inside the box is returned as it is.
Eigen::VectorXd nearestInBox(const Eigen::MatrixXd& H, const Eigen::VectorXd& u, const Eigen::VectorXd& lo,
                             const Eigen::VectorXd& hi, std::vector<int>& at);

}  // namespace kdl_space::detail
