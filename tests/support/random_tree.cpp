#include "random_tree.hpp"

#include <Eigen/Core>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "kdl_space/spatial/spatial.hpp"

namespace kdl_space::test {

KDL::Vector randomVector(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return KDL::Vector(u(rng), u(rng), u(rng));
}

KDL::Vector randomUnit(std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  KDL::Vector v;
  do v = KDL::Vector(g(rng), g(rng), g(rng));
  while (v.Norm() < 1e-3);
  v.Normalize();
  return v;
}

KDL::Rotation randomRotation(std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::Vector4d q;
  do q = Eigen::Vector4d(g(rng), g(rng), g(rng), g(rng));
  while (q.norm() < 1e-3);
  q.normalize();
  return KDL::Rotation::Quaternion(q(0), q(1), q(2), q(3));
}

/// A valid rotational inertia about the CoM: R diag(a, b, c) R^T with a, b, c > 0 strictly inside
/// the triangle inequality, principal moments of order `scale`.
KDL::RotationalInertia randomRotationalInertia(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> moment(0.2 * scale, scale), inside(0.1, 0.9);
  const double a = moment(rng), b = moment(rng);
  const double lo = std::abs(a - b), hi = a + b;
  const double c = lo + inside(rng) * (hi - lo);
  const Eigen::Matrix3d R = toEigen(randomRotation(rng));
  const Eigen::Matrix3d I = R * Eigen::Vector3d(a, b, c).asDiagonal() * R.transpose();
  return KDL::RotationalInertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2));
}

KDL::RigidBodyInertia randomLinkInertia(std::mt19937& rng) {
  std::uniform_real_distribution<double> mass(0.5, 20.0), radius2(0.005, 0.05);
  const double m = mass(rng);
  return KDL::RigidBodyInertia(m, randomVector(rng, 0.2), randomRotationalInertia(rng, m * radius2(rng)));
}

KDL::RigidBodyInertia randomBaseInertia(std::mt19937& rng) {
  std::uniform_real_distribution<double> mass(100.0, 1000.0), radius2(0.2, 1.0);
  const double m = mass(rng);
  return KDL::RigidBodyInertia(m, randomVector(rng, 0.3), randomRotationalInertia(rng, m * radius2(rng)));
}

/// A random tree: root "base", 2-4 arms of 1-8 segments, some with a sub-arm (1-4 segments)
/// hanging off a middle segment, some ending in a massless frame-only leaf.
RandomTree randomTree(std::mt19937& rng) {
  struct Spec {
    std::string name, parent;
    KDL::Joint joint;
    KDL::Frame tip;
    bool massive = true;
    bool frame_leaf = false;
  };
  std::vector<Spec> specs;  // parents precede children
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto randomSegment = [&](const std::string& name, const std::string& parent) {
    Spec s;
    s.name = name;
    s.parent = parent;
    const double kind = u(rng);
    const KDL::Vector origin = randomVector(rng, 0.3);
    if (kind < 0.5)
      s.joint = KDL::Joint(name + "_joint", origin, randomUnit(rng), KDL::Joint::RotAxis);
    else if (kind < 0.75)
      s.joint = KDL::Joint(name + "_joint", origin, randomUnit(rng), KDL::Joint::TransAxis);
    else
      s.joint = KDL::Joint(name + "_joint", KDL::Joint::None);
    s.tip = KDL::Frame(randomRotation(rng), randomVector(rng, 0.6));  // tip pose at q = 0
    s.massive = u(rng) < 0.85;
    specs.push_back(s);
  };
  auto frameLeaf = [&](const std::string& name, const std::string& parent) {
    Spec s;
    s.name = name;
    s.parent = parent;
    s.joint = KDL::Joint(name + "_joint", KDL::Joint::None);
    s.tip = KDL::Frame(randomRotation(rng), randomVector(rng, 0.3));
    s.massive = false;
    s.frame_leaf = true;
    specs.push_back(s);
  };

  RandomTree out;
  const int arms = std::uniform_int_distribution<int>(2, 4)(rng);
  out.coverage.arms = arms;
  for (int a = 0; a < arms; ++a) {
    const std::string arm = "arm" + std::to_string(a);
    const int length = std::uniform_int_distribution<int>(1, 8)(rng);
    const int branch_at = length >= 3 && u(rng) < 0.5 ? std::uniform_int_distribution<int>(1, length - 2)(rng) : -1;
    std::string parent = "base";
    for (int k = 0; k < length; ++k) {
      const std::string name = arm + "_link" + std::to_string(k);
      randomSegment(name, parent);
      if (k == branch_at) {
        ++out.coverage.branches;
        std::string sub_parent = name;
        const int sub_length = std::uniform_int_distribution<int>(1, 4)(rng);
        for (int j = 0; j < sub_length; ++j) {
          const std::string sub = arm + "_sub_link" + std::to_string(j);
          randomSegment(sub, sub_parent);
          sub_parent = sub;
        }
        if (u(rng) < 0.5) frameLeaf(arm + "_sub_frame", sub_parent);
      }
      parent = name;
    }
    if (u(rng) < 0.5) frameLeaf(arm + "_tool_frame", parent);
  }

  // Every movable joint must move some mass: leaves first, give the body of a joint whose subtree
  // is massless a mass of its own.
  std::vector<double> subtree(specs.size(), 0.0);
  for (std::size_t i = specs.size(); i-- > 0;) {
    subtree[i] += specs[i].massive ? 1.0 : 0.0;
    if (specs[i].joint.getType() != KDL::Joint::None && subtree[i] == 0.0) {
      specs[i].massive = true;
      subtree[i] = 1.0;
    }
    for (std::size_t p = 0; p < i; ++p)
      if (specs[p].name == specs[i].parent) subtree[p] += subtree[i];
  }

  out.base_inertia = randomBaseInertia(rng);
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const Spec& s = specs[i];
    const KDL::RigidBodyInertia I = s.massive ? randomLinkInertia(rng) : KDL::RigidBodyInertia::Zero();
    if (!out.tree.addSegment(KDL::Segment(s.name, s.joint, s.tip, I), s.parent))
      throw std::runtime_error("random tree: cannot add " + s.name);
    switch (s.joint.getType()) {
      case KDL::Joint::RotAxis: ++out.coverage.revolute; break;
      case KDL::Joint::TransAxis: ++out.coverage.prismatic; break;
      default:
        if (s.massive) ++out.coverage.fixed_massive;
        break;
    }
    if (s.frame_leaf) ++out.coverage.frame_leaves;
    else if (!s.massive) ++out.coverage.massless_inner;
  }
  return out;
}

}  // namespace kdl_space::test
