#include "kdl_space/multibody/overlap.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace kdl_space {

Vector3d inertiaBoxEdges(double mass, const Vector3d& principal_moments) {
  Vector3d edges = Vector3d::Zero();
  if (!(mass > 0.0)) return edges;
  const double sum = principal_moments.sum();
  for (int k = 0; k < 3; ++k) edges(k) = std::sqrt(std::max(0.0, 6.0 * (sum - 2.0 * principal_moments(k)) / mass));
  return edges;
}

OrientedBox inertiaBox(double mass, const Matrix3d& I_com, const Vector3d& com) {
  const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(0.5 * (I_com + I_com.transpose()));
  Matrix3d axes = eig.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) = -axes.col(2);
  OrientedBox box;
  box.pose.p = toKDL(com);
  box.pose.M = KDL::Rotation(axes(0, 0), axes(0, 1), axes(0, 2), axes(1, 0), axes(1, 1), axes(1, 2), axes(2, 0),
                             axes(2, 1), axes(2, 2));
  box.size = inertiaBoxEdges(mass, eig.eigenvalues());
  return box;
}

double penetrationDepth(const OrientedBox& a, const OrientedBox& b) {
  const Matrix3d A = toEigen(a.pose.M), B = toEigen(b.pose.M);  // columns: each box's axes
  const Vector3d ha = 0.5 * a.size, hb = 0.5 * b.size;
  const Vector3d d = toEigen(b.pose.p - a.pose.p);
  // Overlap of the projections on unit axis L: the half-extents' sum less the centres' distance.
  const auto overlap = [&](const Vector3d& L) {
    const double ra = (A.transpose() * L).cwiseAbs().dot(ha), rb = (B.transpose() * L).cwiseAbs().dot(hb);
    return ra + rb - std::abs(d.dot(L));
  };
  double depth = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) depth = std::min({depth, overlap(A.col(i)), overlap(B.col(i))});
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const Vector3d L = A.col(i).cross(B.col(j));
      const double n = L.norm();
      if (n > 1e-9) depth = std::min(depth, overlap(L / n));  // parallel edges: a face normal tests it
    }
  return depth;
}

std::vector<std::vector<OrientedBox>> inertiaBoxes(const FloatingModel& model) {
  std::vector<std::vector<OrientedBox>> out(model.bodies().size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const Body& b = model.bodies()[i];
    if (b.mass > 0.0) out[i].push_back(inertiaBox(b.mass, b.I_com, b.com));
  }
  return out;
}

std::vector<bool> contactBodies(const FloatingModel& model, int contact_body) {
  const std::vector<Body>& bodies = model.bodies();
  std::vector<bool> marked(bodies.size(), false);
  if (contact_body < 0 || static_cast<std::size_t>(contact_body) >= bodies.size()) return marked;
  // Up the fixed joints: the rigid body the contact's link is part of (not past the base).
  int top = contact_body;
  while (top > 0 && bodies[top].joint < 0 && bodies[top].parent > 0) top = bodies[top].parent;
  marked[top] = true;
  // Parents come before their children in model order: one pass marks the subtree.
  for (std::size_t i = 1; i < bodies.size(); ++i)
    if (bodies[i].parent >= 0 && marked[bodies[i].parent]) marked[i] = true;
  if (top == 0)  // a contact on the base marks the base and what is welded to it, not the whole robot
    for (std::size_t i = 1; i < bodies.size(); ++i) marked[i] = bodies[i].joint < 0 && marked[bodies[i].parent];
  return marked;
}

std::vector<BoxPenetration> penetrations(const Kinematics& kin, const std::vector<std::vector<OrientedBox>>& link_boxes,
                                         const std::vector<OrientedBox>& obstacles, const std::vector<bool>& skip,
                                         double allowance) {
  std::vector<BoxPenetration> out;
  const std::size_t n = std::min(link_boxes.size(), kin.R.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (i < skip.size() && skip[i]) continue;
    const KDL::Frame world_T_body = kin.pose(static_cast<int>(i));
    BoxPenetration deepest{static_cast<int>(i), -1, -std::numeric_limits<double>::infinity()};
    for (const OrientedBox& box : link_boxes[i]) {
      const OrientedBox w = inWorld(world_T_body, box);
      for (std::size_t k = 0; k < obstacles.size(); ++k) {
        const double depth = penetrationDepth(w, obstacles[k]);
        if (depth > deepest.depth) deepest.obstacle = static_cast<int>(k), deepest.depth = depth;
      }
    }
    if (deepest.obstacle >= 0 && deepest.depth > allowance) out.push_back(deepest);
  }
  std::sort(out.begin(), out.end(), [](const BoxPenetration& x, const BoxPenetration& y) { return x.depth > y.depth; });
  return out;
}

}  // namespace kdl_space
