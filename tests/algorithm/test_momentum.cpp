// MomentumSolver (O(n)) against the paper's dense formulas in FreeFloatingSolver: momentum
// (eq. 2), kinetic energy, hand twist (eq. 4), locked G (eq. 20), and the base twist from the
// momentum, over random states and velocities of every bundled model.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

constexpr double kRel = 1e-10;

// The rotors' energy: with an armature a_j on every joint, T = 1/2 nu^T M nu with a on H's diagonal
// (the dense route), and exactly 1/2 sum a_j qdot_j^2 more than without.
TEST(MomentumSolver, KineticEnergyCountsTheRotors) {
  std::mt19937 rng(77);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto bare = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/space_arm7.urdf"));
  std::vector<double> armature(bare->nj());
  for (double& a : armature) a = 2.0 + u(rng);
  const auto geared = std::make_shared<const FloatingModel>(bare->withArmature(armature));
  FreeFloatingSolver dense(geared);
  MomentumSolver fast(geared), fast_bare(bare);
  Kinematics kin(*geared), kin_bare(*bare);
  const State state = randomState(*geared, rng);
  FloatingVelocity v(*geared);
  v.base_twist = KDL::Twist(KDL::Vector(u(rng), u(rng), u(rng)), KDL::Vector(u(rng), u(rng), u(rng)));
  double rotors = 0.0;
  for (unsigned int j = 0; j < geared->nj(); ++j) {
    v.qdot(j) = u(rng);
    rotors += 0.5 * armature[j] * v.qdot(j) * v.qdot(j);
  }
  ASSERT_EQ(dense.compute(state), E_NOERROR);
  ASSERT_EQ(forwardKinematics(*geared, state, kin), E_NOERROR);
  ASSERT_EQ(forwardKinematics(*bare, state, kin_bare), E_NOERROR);
  ASSERT_EQ(fast.compute(kin, v), E_NOERROR);
  ASSERT_EQ(fast_bare.compute(kin_bare, v), E_NOERROR);
  double T = 0.0;
  ASSERT_EQ(dense.kineticEnergy(v.base_twist, v.qdot, T), E_NOERROR);
  EXPECT_NEAR(fast.kineticEnergy(), T, kRel * T);
  EXPECT_NEAR(fast.kineticEnergy() - fast_bare.kineticEnergy(), rotors, kRel * T);
  EXPECT_TRUE(near(fast.momentum(), fast_bare.momentum(), kRel, 1e-12, "the rotors' momentum is neglected, as in H"));
}

TEST(MomentumSolver, AgreesWithTheDenseFormulas) {
  std::mt19937 rng(4242);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const std::string& file : {urdfDir() + "/space_arm7.urdf", urdfDir() + "/dual_arm.urdf",
                                  urdfDir() + "/spacedyn_twolink.urdf", dataDir() + "/reference/models/arm6_public.urdf"}) {
    SCOPED_TRACE(file);
    const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(file));
    FreeFloatingSolver dense(model);
    MomentumSolver fast(model);
    Kinematics kin(*model);
    for (int trial = 0; trial < 10; ++trial) {
      const State state = randomState(*model, rng);
      FloatingVelocity v(*model);
      v.base_twist = KDL::Twist(KDL::Vector(u(rng), u(rng), u(rng)), KDL::Vector(u(rng), u(rng), u(rng)));
      for (unsigned int j = 0; j < model->nj(); ++j) v.qdot(j) = u(rng);
      ASSERT_EQ(dense.compute(state), E_NOERROR);
      ASSERT_EQ(forwardKinematics(*model, state, kin), E_NOERROR);
      ASSERT_EQ(fast.compute(kin, v), E_NOERROR);

      Vector6d PL_g;
      double T = 0.0;
      ASSERT_EQ(dense.momentum(v.base_twist, v.qdot, PL_g), E_NOERROR);
      ASSERT_EQ(dense.kineticEnergy(v.base_twist, v.qdot, T), E_NOERROR);
      const double scale = PL_g.norm();
      EXPECT_TRUE(near(fast.momentumAtCoM(), PL_g, kRel, 1e-12 * scale, "(P_g; L_g)"));
      EXPECT_TRUE(near(fast.momentum(), shiftMomentum(PL_g, -dense.r_g()), kRel, 1e-12 * scale, "(P; L_O)"));
      EXPECT_NEAR(fast.kineticEnergy(), T, kRel * T);
      EXPECT_TRUE(near(fast.r_g(), dense.r_g(), 0.0, 1e-12 * (1.0 + dense.r_g().norm()), "r_g"));
      EXPECT_TRUE(near(fast.I_g(), dense.I_g(), kRel, 1e-12 * dense.I_g().norm(), "I_g"));
      Vector6d v_g;
      v_g << PL_g.head<3>() / model->totalMass(), dense.I_g().llt().solve(Vector3d(PL_g.tail<3>()));
      EXPECT_TRUE(near(fast.centroidTwist(), v_g, kRel, 1e-12 * v_g.norm(), "centroid twist"));

      for (int body = 0; body < static_cast<int>(model->bodies().size()); body += 2) {
        const Contact h{body, KDL::Vector(u(rng), u(rng), u(rng))};
        KDL::Twist t_dense;
        Vector6d t_fast;
        ASSERT_EQ(dense.handTwist(h, v.qdot, PL_g, t_dense), E_NOERROR);
        ASSERT_EQ(fast.contactTwist(h, t_fast), E_NOERROR);
        EXPECT_TRUE(near(t_fast, toEigen(t_dense), kRel, 1e-11 * toEigen(t_dense).norm(), "contact twist (eq. 4)"));
        Matrix6d G_dense, G_fast;
        ASSERT_EQ(dense.G_locked(h, G_dense), E_NOERROR);
        ASSERT_EQ(fast.G_locked(h, G_fast), E_NOERROR);
        EXPECT_TRUE(near(G_fast, G_dense, kRel, 1e-12 * G_dense.norm(), "locked G (eq. 20)"));
      }

      // The inverse: the base twist that gives this momentum with these rates is the one given.
      KDL::Twist back;
      ASSERT_EQ(fast.baseTwist(kin, fast.momentum(), v.qdot, back), E_NOERROR);
      EXPECT_TRUE(near(toEigen(back), toEigen(v.base_twist), kRel, 1e-11, "base twist from momentum"));
    }
  }
}

}  // namespace
}  // namespace kdl_space::test
