// A FloatingSide's state after an impulse, computed without another pass over the bodies (the
// contact twist by eq. 18, the energy by the impulse's work, the momentum by eq. 8), against
// the same quantities computed from its velocities after (MomentumSolver); and reset() against
// a side built afresh. Every response and method, random states and impulses, every bundled model.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "kdl_space/impact/collision.hpp"
#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

FloatingVelocity randomVelocity(const FloatingModel& model, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  FloatingVelocity v(model);
  v.base_twist = KDL::Twist(KDL::Vector(u(rng), u(rng), u(rng)), KDL::Vector(u(rng), u(rng), u(rng)));
  for (unsigned int j = 0; j < model.nj(); ++j) v.qdot(j) = u(rng);
  return v;
}

TEST(FloatingSideState, AfterAnImpulseEqualsItsVelocitiesAfter) {
  std::mt19937 rng(77);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (const std::string& file : {urdfDir() + "/space_arm7.urdf", urdfDir() + "/dual_arm.urdf",
                                  dataDir() + "/reference/models/arm6_public.urdf"}) {
    const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(file));
    MomentumSolver check(model);
    Kinematics kin(*model);
    for (Response response : {Response::FreeFloating, Response::Grounded, Response::JointsLocked})
      for (ExIITMethod method : {ExIITMethod::Recursive, ExIITMethod::Dense})
        for (int trial = 0; trial < 5; ++trial) {
          SCOPED_TRACE(file + ", response " + std::to_string(static_cast<int>(response)) + ", method " +
                       std::to_string(static_cast<int>(method)));
          const State state = randomState(*model, rng);
          const Contact h{static_cast<int>(model->bodies().size()) - 1, KDL::Vector(0.05, -0.1, 0.2)};
          FloatingSide side(model, state, h, randomVelocity(*model, rng), response, method);
          Vector6d F;
          for (int k = 0; k < 6; ++k) F(k) = u(rng);
          ASSERT_EQ(side.applyImpulse(F), E_NOERROR);
          ASSERT_EQ(forwardKinematics(*model, state, kin), E_NOERROR);
          ASSERT_EQ(check.compute(kin, side.after()), E_NOERROR);
          Vector6d t_h;
          ASSERT_EQ(check.contactTwist(h, t_h), E_NOERROR);
          const double T = check.kineticEnergy();
          EXPECT_NEAR(side.energyAfter(), T, 1e-10 * std::max(T, side.energyBefore()));
          EXPECT_TRUE(near(side.contactTwistAfter(), t_h, 1e-9, 1e-10 * t_h.norm(), "contact twist after"));
          EXPECT_TRUE(near(side.momentumAfter(), check.momentum(), 1e-10, 1e-11 * check.momentum().norm(), "momentum after"));
          EXPECT_TRUE(near(side.centroidTwistAfter(), check.centroidTwist(), 1e-9,
                           1e-10 * check.centroidTwist().norm(), "centroid twist after"));
        }
  }
}

TEST(FloatingSideState, ResetEqualsASideBuiltAfresh) {
  std::mt19937 rng(78);
  const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/dual_arm.urdf"));
  const Contact h = model->contact(model->bodies().back().name, KDL::Vector(0.0, 0.0, 0.1));
  for (Response response : {Response::FreeFloating, Response::Grounded, Response::JointsLocked}) {
    FloatingSide side(model, randomState(*model, rng), h, randomVelocity(*model, rng), response);
    const State state = randomState(*model, rng);
    const FloatingVelocity v = randomVelocity(*model, rng);
    ASSERT_EQ(side.reset(state, v), E_NOERROR);
    const FloatingSide fresh(model, state, h, v, response);
    EXPECT_EQ(side.G(), fresh.G());
    EXPECT_EQ(side.contactTwistBefore(), fresh.contactTwistBefore());
    EXPECT_EQ(side.momentumBefore(), fresh.momentumBefore());
    EXPECT_EQ(side.energyBefore(), fresh.energyBefore());
    // A refused reset leaves a side that answers nothing until the next good one.
    State bad = state;
    bad.q(0) = std::nan("");
    EXPECT_EQ(side.reset(bad, v), E_NOT_FINITE);
    EXPECT_EQ(side.applyImpulse(Vector6d::Ones()), E_NOT_COMPUTED);
    EXPECT_EQ(side.reset(state, FloatingVelocity{KDL::Twist::Zero(), KDL::JntArray(3)}), E_SIZE_MISMATCH);
    ASSERT_EQ(side.reset(state, v), E_NOERROR);
    EXPECT_EQ(side.applyImpulse(Vector6d::Ones()), E_NOERROR);
  }
}

}  // namespace
}  // namespace kdl_space::test
