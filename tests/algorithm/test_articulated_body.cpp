// The articulated-body forward dynamics (ForwardDynamicsSolver: Featherstone's ABA with a
// floating base, O(n)) against the composite-rigid-body route (CrbForwardDynamics in
// tests/support: FreeFloatingSolver's M_a, A_m, H, a Newton-Euler bias and a dense Cholesky
// solve of the (6+n)^2 system), on every bundled model and on random trees, with everything the
// dynamics take: velocity products, PD torques, gravity, external wrenches on several bodies,
// locked joints (still or moving), armature and payloads. The two routes share only the
// kinematics; the KDL-only route (test_dynamics.cpp) checks the same solver independently.
//
// Tolerance: 1e-10 relative per element, plus an absolute floor of 1e-12 times the norm of the
// whole reference acceleration (base; qddot). Both routes solve with the same mass matrix, so
// each carries round-off of order eps * cond(M) * ||whole acceleration||, and the base's
// acceleration is far smaller than the joints' when the base weighs hundreds of kilograms (the
// same reasoning as the velocity jump's floor in test_recursive.cpp). A wrong term (a velocity
// product, a lever arm, gravity on the wrong body, a locked joint that moves) gives errors of
// order 1 relative.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "crb_forward_dynamics.hpp"
#include "kdl_space/algorithm/forward_dynamics.hpp"
#include "kdl_space/simulation/simulation.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "random_tree.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

using ModelPtr = std::shared_ptr<const FloatingModel>;

constexpr double kRel = 1e-10;
constexpr double kFloor = 1e-12;  ///< per unit of ||(base; qddot)|| of the reference

/// Worst discrepancy of a test, printed at its end (the assertions are the near() checks).
struct Worst {
  double tolerance_fraction = 0.0, relative = 0.0;
  int comparisons = 0;
  void record(const Eigen::VectorXd& a, const Eigen::VectorXd& b, double floor) {
    for (Eigen::Index i = 0; i < a.size(); ++i) {
      const double e = std::abs(a(i) - b(i));
      tolerance_fraction = std::max(tolerance_fraction, e / (kRel * std::abs(b(i)) + floor));
      if (std::abs(b(i)) > 1e3 * floor) relative = std::max(relative, e / std::abs(b(i)));
    }
    ++comparisons;
  }
  void print(const std::string& what) const {
    std::printf("[ worst    ] %s: %d comparisons, worst %.3g of the tolerance; worst relative %.3g\n", what.c_str(),
                comparisons, tolerance_fraction, relative);
  }
};

/// What one comparison is given besides the model.
struct Loads {
  bool gravity = false, wrenches = false, pd = false, locked = false, locked_moving = false;
};

Vector6d randomTwist(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Vector6d t;
  for (int k = 0; k < 6; ++k) t(k) = u(rng);
  return t;
}

/// Both routes at a random state with random velocities and the given loads; the accelerations
/// compared element by element.
void compareAtRandomState(const ModelPtr& model, const Loads& loads, std::mt19937& rng, Worst& worst) {
  const unsigned int n = model->nj();
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  ForwardDynamicsSolver aba(model);
  CrbForwardDynamics crb(model);
  const Vector3d g = loads.gravity ? Vector3d(0.4, -1.1, -9.81) : Vector3d::Zero();
  aba.setGravity(g);
  crb.setGravity(g);

  const State state = randomState(*model, rng);
  FloatingVelocity v(*model);
  v.base_twist = toTwist(randomTwist(rng, 0.5));
  for (unsigned int j = 0; j < n; ++j) v.qdot(j) = 1.5 * u(rng);
  KDL::JntArray tau(n);
  for (unsigned int j = 0; j < n; ++j) tau(j) = 5.0 * u(rng);
  if (loads.pd)  // a PD servo on every joint toward a random set point, as JointControl::PD
    for (unsigned int j = 0; j < n; ++j) tau(j) += 80.0 * (0.5 * u(rng) - state.q(j)) - 12.0 * v.qdot(j);
  std::vector<bool> locked(n, false);
  if (loads.locked) {
    for (unsigned int j = 0; j < n; ++j) locked[j] = u(rng) < 0.0;
    if (n > 0) locked[n / 2] = true;
    for (unsigned int j = 0; j < n; ++j)
      if (locked[j] && !loads.locked_moving) v.qdot(j) = 0.0;  // a braked joint does not move...
  }  // ...unless the test asks what happens to one that still does (its velocity products stay)
  aba.setLocked(locked);
  crb.setLocked(locked);
  std::vector<KDL::Wrench> f;
  if (loads.wrenches) {  // on the base, every third body, and the last
    f.assign(model->bodies().size(), KDL::Wrench::Zero());
    for (std::size_t i = 0; i < f.size(); ++i)
      if (i % 3 == 0 || i + 1 == f.size()) {
        const Vector6d w = randomTwist(rng, 20.0);
        f[i] = toWrench(w);
      }
  }

  FloatingAcceleration a{Vector6d::Zero(), KDL::JntArray(n)}, ref{Vector6d::Zero(), KDL::JntArray(n)};
  ASSERT_EQ(aba.CartToJnt(state, v, tau, f, a), E_NOERROR);
  ASSERT_EQ(crb.CartToJnt(state, v, tau, f, ref), E_NOERROR);
  Eigen::VectorXd got(6 + n), expected(6 + n);
  got << a.base, a.qddot.data;
  expected << ref.base, ref.qddot.data;
  const double floor = kFloor * expected.norm();
  worst.record(got, expected, floor);
  EXPECT_TRUE(near(a.base.head<3>(), ref.base.head<3>(), kRel, floor, "base origin acceleration"));
  EXPECT_TRUE(near(a.base.tail<3>(), ref.base.tail<3>(), kRel, floor, "base angular acceleration"));
  EXPECT_TRUE(near(a.qddot.data, ref.qddot.data, kRel, floor, "qddot"));
  for (unsigned int j = 0; j < n; ++j)
    if (locked[j]) EXPECT_EQ(a.qddot(j), 0.0) << "locked joint " << model->jointNames()[j];
}

// ---- Bundled models ---------------------------------------------------------------------------

struct ModelCase {
  std::string name, path;
};
inline void PrintTo(const ModelCase& c, std::ostream* os) { *os << c.name; }

std::vector<ModelCase> bundledModels() {
  return {{"space_arm7", urdfDir() + "/space_arm7.urdf"},
          {"dual_arm", urdfDir() + "/dual_arm.urdf"},
          {"spacedyn_twolink", urdfDir() + "/spacedyn_twolink.urdf"},
          {"arm6_public", dataDir() + "/reference/models/arm6_public.urdf"},
          {"reference_spacedyn_twolink", dataDir() + "/reference/models/spacedyn_twolink.urdf"}};
}

class ArticulatedBody : public ::testing::TestWithParam<ModelCase> {
 protected:
  ModelPtr model() const { return std::make_shared<const FloatingModel>(loadUrdfFile(GetParam().path)); }
  void check(const ModelPtr& m, const Loads& loads, unsigned seed, const std::string& what) {
    std::mt19937 rng(seed);
    Worst worst;
    for (int s = 0; s < 20; ++s) {
      SCOPED_TRACE(what + ", state " + std::to_string(s));
      compareAtRandomState(m, loads, rng, worst);
    }
    worst.print(GetParam().name + ": " + what);
  }
};

TEST_P(ArticulatedBody, VelocityProductsAndTorques) { check(model(), {}, 1, "velocity products"); }
TEST_P(ArticulatedBody, PdGravityAndWrenches) { check(model(), {true, true, true}, 2, "PD, gravity, wrenches"); }
TEST_P(ArticulatedBody, LockedJoints) { check(model(), {true, true, true, true}, 3, "locked"); }
TEST_P(ArticulatedBody, LockedJointsStillMoving) {
  check(model(), {true, true, true, true, true}, 4, "locked, still moving");
}
TEST_P(ArticulatedBody, Armature) {
  const ModelPtr m = model();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 2.0);
  std::vector<double> armature(m->nj());
  for (double& a : armature) a = u(rng);
  check(std::make_shared<const FloatingModel>(m->withArmature(armature)), {true, true, true, true}, 6, "armature");
}
TEST_P(ArticulatedBody, Payload) {
  // A captured 40 kg box merged into the last body (withPayload), off its frame and tilted.
  const ModelPtr m = model();
  const KDL::RigidBodyInertia box(40.0, KDL::Vector(0.3, -0.1, 0.2), KDL::RotationalInertia(2.0, 1.5, 1.2, 0.1, -0.2, 0.05));
  const ModelPtr merged = std::make_shared<const FloatingModel>(m->withPayload(m->bodies().back().name, box));
  check(merged, {true, true, true, true}, 7, "payload");
}

INSTANTIATE_TEST_SUITE_P(Bundled, ArticulatedBody, ::testing::ValuesIn(bundledModels()),
                         [](const ::testing::TestParamInfo<ModelCase>& info) { return info.param.name; });

// ---- Random trees -----------------------------------------------------------------------------

TEST(ArticulatedBodyRandomTrees, AgreeWithTheCompositeRigidBodyRoute) {
  std::mt19937 rng(kTreeSeed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Worst worst;
  for (int t = 0; t < kRandomTrees; ++t) {
    SCOPED_TRACE("random tree " + std::to_string(t));
    const RandomTree rt = randomTree(rng);
    ModelPtr model = std::make_shared<const FloatingModel>(rt.tree, rt.base_inertia);
    std::mt19937 state_rng(1000 + t);
    if (t % 2) {  // armature on every other tree
      std::vector<double> armature(model->nj());
      for (double& a : armature) a = 2.0 * u(rng);
      model = std::make_shared<const FloatingModel>(model->withArmature(armature));
    }
    for (const Loads& loads : {Loads{}, Loads{true, true, true}, Loads{true, true, true, true},
                               Loads{true, true, true, true, true}})
      for (int s = 0; s < 3; ++s) compareAtRandomState(model, loads, state_rng, worst);
  }
  worst.print("random trees");
}

TEST(ArticulatedBodyRandomTrees, PayloadOnEveryArm) {
  std::mt19937 rng(kTreeSeed + 1);
  Worst worst;
  for (int t = 0; t < 10; ++t) {
    SCOPED_TRACE("random tree " + std::to_string(t));
    const RandomTree rt = randomTree(rng);
    auto model = std::make_shared<const FloatingModel>(rt.tree, rt.base_inertia);
    const std::string link = model->bodies()[1 + t % (model->bodies().size() - 1)].name;
    model = std::make_shared<const FloatingModel>(model->withPayload(link, randomLinkInertia(rng)));
    for (int s = 0; s < 3; ++s) compareAtRandomState(model, {true, true, true, true}, rng, worst);
  }
  worst.print("random trees + payload");
}

// ---- The same solver from a Kinematics and from a State -----------------------------------------

TEST(ArticulatedBodyKinematics, FromKinematicsEqualsFromState) {
  const ModelPtr model = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/dual_arm.urdf"));
  const unsigned int n = model->nj();
  std::mt19937 rng(8);
  ForwardDynamicsSolver a(model), b(model);
  a.setGravity(Vector3d(0, 0, -9.81));
  b.setGravity(Vector3d(0, 0, -9.81));
  Kinematics kin(*model);
  for (int s = 0; s < 5; ++s) {
    const State state = randomState(*model, rng);
    FloatingVelocity v(*model);
    v.base_twist = toTwist(randomTwist(rng, 0.3));
    for (unsigned int j = 0; j < n; ++j) v.qdot(j) = 0.2 * j - 0.5;
    KDL::JntArray tau(n);
    FloatingAcceleration from_state{Vector6d::Zero(), KDL::JntArray(n)}, from_kin = from_state;
    ASSERT_EQ(a.CartToJnt(state, v, tau, {}, from_state), E_NOERROR);
    ASSERT_EQ(forwardKinematics(*model, state, kin), E_NOERROR);
    ASSERT_EQ(b.CartToJnt(kin, v, tau, {}, from_kin), E_NOERROR);
    EXPECT_EQ(from_state.base, from_kin.base);
    EXPECT_EQ(from_state.qddot.data, from_kin.qddot.data);
  }
}

// ---- The simulator on it against the simulator loop on the dense route --------------------------

TEST(ArticulatedBodySimulation, SimulatorAgreesWithTheDenseLoop) {
  // 2 s of space_arm7 from a moving state, one joint PD-servoed and one locked, dopri5 at
  // rtol 1e-10: the two loops take the same steps (their derivatives differ by round-off) and
  // end at the same state to well within the integration tolerance.
  const ModelPtr model = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/space_arm7.urdf"));
  const unsigned int n = model->nj();
  SimulationOptions options;
  Simulator sim(model, options);
  CrbSimulator dense(model, options);
  const JointControl pd{JointControl::Mode::PD, 40.0, 8.0, 0.3}, locked{JointControl::Mode::Locked};
  sim.setJointControl(1, pd);
  dense.setJointControl(1, pd);
  sim.setJointControl(3, locked);
  dense.setJointControl(3, locked);
  SimulationState s;
  std::mt19937 rng(9);
  s.state = randomState(*model, rng);
  s.velocity.qdot = KDL::JntArray(n);
  for (unsigned int j = 0; j < n; ++j) s.velocity.qdot(j) = j == 3 ? 0.0 : 0.3 - 0.1 * j;
  s.velocity.base_twist = KDL::Twist(KDL::Vector(0.01, -0.02, 0.005), KDL::Vector(0.01, 0.02, -0.01));
  SimulationState r = s;
  ASSERT_EQ(sim.run(s, 2.0, 2.0, {}), E_NOERROR);
  ASSERT_EQ(dense.run(r, 2.0), E_NOERROR);
  EXPECT_EQ(sim.stats().accepted_steps, dense.stats().accepted_steps);
  EXPECT_GT(sim.stats().accepted_steps, 10);
  EXPECT_TRUE(near(s.state.q.data, r.state.q.data, 1e-8, 1e-10, "q"));
  EXPECT_TRUE(near(s.velocity.qdot.data, r.velocity.qdot.data, 1e-8, 1e-10, "qdot"));
  EXPECT_TRUE(near(toEigen(s.state.world_T_base.p), toEigen(r.state.world_T_base.p), 1e-8, 1e-10, "base position"));
  EXPECT_TRUE(near(toEigen(s.velocity.base_twist), toEigen(r.velocity.base_twist), 1e-8, 1e-10, "base twist"));
}

}  // namespace
}  // namespace kdl_space::test
