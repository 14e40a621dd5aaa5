// The boxes of the overlap check (multibody/overlap.hpp): the separating-axis depth against cases
// worked by hand (faces, an edge across an edge, a box inside a box, apart), invariance under a
// rigid motion of both boxes, and random pairs against an independent route: the penetration
// depth of two convex bodies is min over unit n of h_A(n) + h_B(-n) (the support function of
// their Minkowski difference), searched here over a dense set of directions and refined locally,
// which can only come down to the true minimum. The box of inertia against a box built by hand,
// and the bodies that carry a contact on a model with fixed joints.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "kdl_space/multibody/overlap.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

OrientedBox box(const Vector3d& centre, const Vector3d& size, const KDL::Rotation& R = KDL::Rotation::Identity()) {
  return OrientedBox{KDL::Frame(R, toKDL(centre)), size};
}

KDL::Rotation randomRotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const double w = n(rng), x = n(rng), y = n(rng), z = n(rng);  // in this order on every compiler
  const Eigen::Quaterniond q = Eigen::Quaterniond(w, x, y, z).normalized();
  return KDL::Rotation::Quaternion(q.x(), q.y(), q.z(), q.w());
}

/// The support function of a box along n (any length): max over its points of x . n.
double support(const OrientedBox& b, const Vector3d& n) {
  double h = toEigen(b.pose.p).dot(n);
  for (int i = 0; i < 3; ++i) h += 0.5 * b.size(i) * std::abs(toEigen(b.pose.M * KDL::Vector(i == 0, i == 1, i == 2)).dot(n));
  return h;
}

/// h_A(n) + h_B(-n) for the unit n along `n`: how far B must move along n to clear A (its minimum
/// over n is the penetration depth).
double minkowski(const OrientedBox& a, const OrientedBox& b, const Vector3d& n) {
  const Vector3d u = n.normalized();
  return support(a, u) + support(b, -u);
}

/// Three draws of `d`, x then y then z.
template <typename Distribution>
Vector3d draw(Distribution& d, std::mt19937& rng) {
  const double x = d(rng), y = d(rng), z = d(rng);
  return {x, y, z};
}

/// The minimum of `minkowski` over directions: 100,000 on a Fibonacci sphere, then random steps
/// that shrink to 1e-10 rad from each of the 20 best (a descent that never goes below the minimum;
/// one start can sit in the basin of another face of A - B: it did for some boxes).
double bruteForceDepth(const OrientedBox& a, const OrientedBox& b, std::mt19937& rng) {
  const int n = 100000, starts = 20;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  std::vector<std::pair<double, Vector3d>> sampled;
  sampled.reserve(n);
  for (int k = 0; k < n; ++k) {
    const double z = 1.0 - 2.0 * (k + 0.5) / n, r = std::sqrt(1.0 - z * z);
    const Vector3d u(r * std::cos(golden * k), r * std::sin(golden * k), z);
    sampled.emplace_back(minkowski(a, b, u), u);
  }
  std::partial_sort(sampled.begin(), sampled.begin() + starts, sampled.end(),
                    [](const auto& x, const auto& y) { return x.first < y.first; });
  std::normal_distribution<double> g(0.0, 1.0);
  double best = minkowski(a, b, Vector3d::UnitX());
  for (int s = 0; s < starts; ++s) {
    auto [v_s, u_s] = sampled[s];
    for (double step = 0.02; step > 1e-10; step *= 0.7)
      for (int tries = 0; tries < 100; ++tries) {
        const double gx = g(rng), gy = g(rng), gz = g(rng);  // drawn in this order on every compiler
        const Vector3d u = (u_s + step * Vector3d(gx, gy, gz)).normalized();
        const double v = minkowski(a, b, u);
        if (v < v_s) v_s = v, u_s = u;
      }
    best = std::min(best, v_s);
  }
  return best;
}

TEST(Overlap, FaceToFaceDepthIsTheOverlapOfTheFaces) {
  // A: 2 x 2 x 2 at the origin; B: 1 x 1 x 1 at x = 1.2: |x| overlap 1 + 0.5 - 1.2 = 0.3.
  EXPECT_NEAR(penetrationDepth(box({0, 0, 0}, {2, 2, 2}), box({1.2, 0, 0}, {1, 1, 1})), 0.3, 1e-12);
  EXPECT_NEAR(penetrationDepth(box({1.2, 0, 0}, {1, 1, 1}), box({0, 0, 0}, {2, 2, 2})), 0.3, 1e-12);
  // Two long thin bars crossing, one 0.15 above the other: along z 0.1 + 0.1 - 0.15.
  EXPECT_NEAR(penetrationDepth(box({0, 0, 0}, {4, 0.2, 0.2}), box({0, 0, 0.15}, {0.2, 4, 0.2})), 0.05, 1e-12);
}

TEST(Overlap, SeparatedBoxesHaveNoDepth) {
  EXPECT_NEAR(penetrationDepth(box({0, 0, 0}, {2, 2, 2}), box({2, 0, 0}, {1, 1, 1})), -0.5, 1e-12);
  EXPECT_LE(penetrationDepth(box({0, 0, 0}, {1, 1, 1}), box({3, 3, 3}, {1, 1, 1}, KDL::Rotation::RPY(0.3, 0.2, 0.1))), 0.0);
}

TEST(Overlap, BoxInsideABoxMustMoveOutThroughTheNearestFace) {
  // 0.2 cube at x = 0.5 inside a 2 cube: 0.6 along +x takes it out (its far face to x = 1).
  EXPECT_NEAR(penetrationDepth(box({0, 0, 0}, {2, 2, 2}), box({0.5, 0, 0}, {0.2, 0.2, 0.2})), 0.6, 1e-12);
  // The Franka case: a thin link (0.1 x 0.1 x 0.3) in the middle of a 1.5 m box: 0.75 + 0.05.
  EXPECT_NEAR(penetrationDepth(box({0, 0, 0}, {1.5, 1.5, 1.5}), box({0, 0, 0}, {0.1, 0.1, 0.3})), 0.8, 1e-12);
}

TEST(Overlap, EdgeAcrossEdgeIsFoundOnTheirCrossProduct) {
  // A: a 2 cube turned 45 deg about z (a vertical edge at x = sqrt 2); B: a 2 cube turned 45 deg
  // about y (an edge along y at x = -sqrt 2 from its centre), at x = 2 sqrt 2 - delta: the edges
  // cross with delta of penetration along x, an axis that is a face normal of neither.
  const double delta = 0.05;
  const OrientedBox a = box({0, 0, 0}, {2, 2, 2}, KDL::Rotation::RotZ(M_PI / 4));
  const OrientedBox b = box({2 * std::sqrt(2.0) - delta, 0, 0}, {2, 2, 2}, KDL::Rotation::RotY(M_PI / 4));
  EXPECT_NEAR(penetrationDepth(a, b), delta, 1e-12);
}

TEST(Overlap, DepthIsUnchangedByARigidMotionOfBoth) {
  std::mt19937 rng(27);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const OrientedBox a = box({u(rng), u(rng), u(rng)}, Vector3d(0.2, 0.2, 0.2) + Vector3d::Random().cwiseAbs(), randomRotation(rng));
    const OrientedBox b = box({u(rng), u(rng), u(rng)}, Vector3d(0.2, 0.2, 0.2) + Vector3d::Random().cwiseAbs(), randomRotation(rng));
    const KDL::Frame T(randomRotation(rng), KDL::Vector(u(rng), u(rng), u(rng)));
    EXPECT_NEAR(penetrationDepth(inWorld(T, a), inWorld(T, b)), penetrationDepth(a, b), 1e-12);
    EXPECT_NEAR(penetrationDepth(b, a), penetrationDepth(a, b), 1e-12);
  }
}

TEST(Overlap, RandomPairsAgreeWithTheMinkowskiSupportMinimum) {
  std::mt19937 rng(4027);
  std::uniform_real_distribution<double> u(-0.8, 0.8), e(0.1, 1.5);
  int overlapping = 0;
  for (int trial = 0; trial < 40; ++trial) {
    // Each number drawn in a statement of its own: the order of a call's arguments is the compiler's.
    const Vector3d size_a = draw(e, rng), at_b = draw(u, rng), size_b = draw(e, rng);
    const KDL::Rotation turn_a = randomRotation(rng), turn_b = randomRotation(rng);
    const OrientedBox a = box(Vector3d::Zero(), size_a, turn_a);
    const OrientedBox b = box(at_b, size_b, turn_b);
    const double sat = penetrationDepth(a, b);
    if (sat <= 0.0) continue;  // apart: the minimum over directions is then no distance, only a bound
    ++overlapping;
    EXPECT_NEAR(sat, bruteForceDepth(a, b, rng), 1e-7) << "trial " << trial;
  }
  EXPECT_GE(overlapping, 20);
}

TEST(Overlap, BoxOfInertiaIsTheUniformBoxWithThatInertia) {
  // A 3 kg box 0.6 x 0.4 x 0.2: I = m/12 (b^2 + c^2, a^2 + c^2, a^2 + b^2), turned and moved.
  const double m = 3.0, a = 0.6, b = 0.4, c = 0.2;
  const Vector3d moments(m / 12 * (b * b + c * c), m / 12 * (a * a + c * c), m / 12 * (a * a + b * b));
  EXPECT_TRUE(near(inertiaBoxEdges(m, moments), Vector3d(a, b, c), 1e-12, 0.0, "edges"));
  const KDL::Rotation R = KDL::Rotation::RPY(0.4, -0.3, 1.1);
  const Matrix3d Re = toEigen(R);
  const Vector3d com(0.1, -0.2, 0.3);
  const OrientedBox got = inertiaBox(m, Re * moments.asDiagonal() * Re.transpose(), com);
  // The same set of corners as the box drawn by hand (the axes may come in another order or sign).
  const OrientedBox want = box(com, {a, b, c}, R);
  for (int k = 0; k < 8; ++k) {
    const Vector3d s(k & 1 ? 0.5 : -0.5, k & 2 ? 0.5 : -0.5, k & 4 ? 0.5 : -0.5);
    const Vector3d corner = toEigen(got.pose * toKDL(Vector3d(s.cwiseProduct(got.size))));
    double nearest = 1e9;
    for (int l = 0; l < 8; ++l) {
      const Vector3d t(l & 1 ? 0.5 : -0.5, l & 2 ? 0.5 : -0.5, l & 4 ? 0.5 : -0.5);
      nearest = std::min(nearest, (corner - toEigen(want.pose * toKDL(Vector3d(t.cwiseProduct(want.size))))).norm());
    }
    EXPECT_LT(nearest, 1e-12) << "corner " << k;
  }
  EXPECT_TRUE(inertiaBoxEdges(0.0, moments).isZero());
}

// base - j1 (revolute) - upper - j2 (revolute) - wrist - flange (fixed) - tool (fixed) - finger (revolute).
const char* const kArm = R"(<robot name="arm">
  <link name="base"><inertial><mass value="10"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="upper"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="wrist"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="flange"><inertial><mass value="0.5"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tool"/>
  <link name="finger"><inertial><mass value="0.1"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="upper"/><child link="wrist"/><origin xyz="0 0 1"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="weld" type="fixed"><parent link="wrist"/><child link="flange"/><origin xyz="0 0 1"/></joint>
  <joint name="tcp" type="fixed"><parent link="flange"/><child link="tool"/><origin xyz="0 0 0.1"/></joint>
  <joint name="grip" type="revolute"><parent link="tool"/><child link="finger"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>)";

TEST(Overlap, ContactBodiesAreTheWeldedHandAndWhatHangsFromIt) {
  const FloatingModel model = loadUrdfString(kArm);
  const auto index = [&](const std::string& name) {
    for (std::size_t i = 0; i < model.bodies().size(); ++i)
      if (model.bodies()[i].name == name) return static_cast<int>(i);
    ADD_FAILURE() << "no body " << name;
    return -1;
  };
  const auto marked = [&](const std::string& contact) {
    std::vector<std::string> names;
    const std::vector<bool> m = contactBodies(model, index(contact));
    for (std::size_t i = 0; i < m.size(); ++i)
      if (m[i]) names.push_back(model.bodies()[i].name);
    std::sort(names.begin(), names.end());
    return names;
  };
  // A tool frame welded to the flange, welded to the wrist: the wrist is the hand, with the finger.
  EXPECT_EQ(marked("tool"), (std::vector<std::string>{"finger", "flange", "tool", "wrist"}));
  EXPECT_EQ(marked("finger"), (std::vector<std::string>{"finger"}));
  EXPECT_EQ(marked("upper"), (std::vector<std::string>{"finger", "flange", "tool", "upper", "wrist"}));
  EXPECT_EQ(marked("base"), (std::vector<std::string>{"base"}));
}

TEST(Overlap, PenetrationsNameTheLinksDeeperThanTheAllowanceDeepestFirst) {
  const FloatingModel model = loadUrdfString(kArm);
  Kinematics kin(model);
  ASSERT_EQ(forwardKinematics(model, State(model), kin), E_NOERROR);
  // Each body gets a 0.2 cube at its origin: base z=0, upper z=0, wrist z=1, flange z=2, tool z=2.1.
  std::vector<std::vector<OrientedBox>> boxes(model.bodies().size(), {box({0, 0, 0}, {0.2, 0.2, 0.2})});
  const OrientedBox obstacle = box({0, 0, 1.5}, {1, 1, 1.1});  // z from 0.95 to 2.05
  const std::vector<BoxPenetration> p = penetrations(kin, boxes, {obstacle}, {}, 0.01);
  std::vector<std::pair<std::string, double>> got;
  for (const BoxPenetration& x : p) got.emplace_back(model.bodies()[x.body].name, x.depth);
  ASSERT_EQ(got.size(), 4u);
  // wrist 0.9..1.1 against 0.95..2.05: out downwards by 1.1 - 0.95 = 0.15; flange 1.9..2.1: 2.05 - 1.9
  // = 0.15; tool 2.0..2.2: 0.05; finger (at the tool's origin) 0.05. The base and upper (z = 0) are out.
  EXPECT_NEAR(got[0].second, 0.15, 1e-12);
  EXPECT_NEAR(got[1].second, 0.15, 1e-12);
  EXPECT_NEAR(got[2].second, 0.05, 1e-12);
  EXPECT_NEAR(got[3].second, 0.05, 1e-12);
  // A larger allowance keeps the deep ones; the contact's bodies skipped leave none.
  EXPECT_EQ(penetrations(kin, boxes, {obstacle}, {}, 0.1).size(), 2u);
  EXPECT_TRUE(penetrations(kin, boxes, {obstacle}, contactBodies(model, 2), 0.01).empty());
}

}  // namespace
}  // namespace kdl_space::test
