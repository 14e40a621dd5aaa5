// Random KDL trees and their parts, for the cross-route tests: several arms, branches hanging off
// mid-arm segments, revolute / prismatic / fixed joints with random origins and axes, random
// segment poses, full inertia tensors, massless intermediate links and frame-only leaves.
#pragma once

#include <kdl/frames.hpp>
#include <kdl/rigidbodyinertia.hpp>
#include <kdl/tree.hpp>
#include <random>

namespace kdl_space::test {

/// A vector with components uniform in [-scale, scale].
KDL::Vector randomVector(std::mt19937& rng, double scale);
/// A unit vector, uniform on the sphere.
KDL::Vector randomUnit(std::mt19937& rng);
/// A rotation, uniform.
KDL::Rotation randomRotation(std::mt19937& rng);
/// A valid rotational inertia about the CoM: R diag(a, b, c) R^T with a, b, c > 0 strictly inside
/// the triangle inequality, principal moments of order `scale`.
KDL::RotationalInertia randomRotationalInertia(std::mt19937& rng, double scale);
/// A link: 0.5-20 kg, CoM within 0.2 m of the frame, full inertia tensor.
KDL::RigidBodyInertia randomLinkInertia(std::mt19937& rng);
/// A base: 100-1000 kg, CoM within 0.3 m, full inertia tensor.
KDL::RigidBodyInertia randomBaseInertia(std::mt19937& rng);

/// What a generated tree holds (to check that the generator covers the cases it should).
struct Coverage {
  int arms = 0, branches = 0, revolute = 0, prismatic = 0, fixed_massive = 0, massless_inner = 0,
      frame_leaves = 0;
};

struct RandomTree {
  KDL::Tree tree{"base"};
  KDL::RigidBodyInertia base_inertia;
  Coverage coverage;
};

/// A random tree: root "base", 2-4 arms of 1-8 segments, some with a sub-arm (1-4 segments)
/// hanging off a middle segment, some ending in a massless frame-only leaf. Every movable joint
/// moves some mass.
RandomTree randomTree(std::mt19937& rng);

/// How many random trees the cross-route tests draw, and from which seed.
constexpr int kRandomTrees = 30;
constexpr unsigned kTreeSeed = 20250117;

}  // namespace kdl_space::test
