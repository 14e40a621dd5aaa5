// The one forward-kinematics pass (forwardKinematics) against KDL's own solvers: every body's
// pose against TreeFkSolverPos_recursive, every joint's twist against Segment::twist, the mass
// properties against KDL's RigidBodyInertia, the CoM against a hand sum. Random states of every
// bundled model (chains, trees, a prismatic joint).
#include <gtest/gtest.h>

#include <kdl/treefksolverpos_recursive.hpp>
#include <memory>
#include <random>

#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

std::vector<std::string> models() {
  return {urdfDir() + "/space_arm7.urdf", urdfDir() + "/dual_arm.urdf", urdfDir() + "/spacedyn_twolink.urdf",
          dataDir() + "/reference/models/arm6_public.urdf"};
}

TEST(ForwardKinematics, AgreesWithKdlSolversOnEveryBody) {
  std::mt19937 rng(808);
  for (const std::string& file : models()) {
    SCOPED_TRACE(file);
    const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(file));
    KDL::TreeFkSolverPos_recursive fk(model->tree());
    Kinematics kin(*model);
    for (int trial = 0; trial < 10; ++trial) {
      const State state = randomState(*model, rng);
      ASSERT_EQ(forwardKinematics(*model, state, kin), E_NOERROR);
      ASSERT_TRUE(kin.valid);
      EXPECT_TRUE(near(kin.p_b, toEigen(state.world_T_base.p), 0.0, 0.0, "p_b"));
      Vector3d first_moment = Vector3d::Zero();
      for (int i = 0; i < static_cast<int>(model->bodies().size()); ++i) {
        const Body& b = model->bodies()[i];
        // KDL: the pose of the segment's tip frame in the root frame, then the base pose.
        KDL::Frame root_T_body = KDL::Frame::Identity();
        if (i > 0) ASSERT_GE(fk.JntToCart(state.q, root_T_body, b.name), 0) << b.name;
        const KDL::Frame world_T_body = state.world_T_base * root_T_body;
        const double scale = 1.0 + world_T_body.p.Norm();
        EXPECT_TRUE(near(kin.p[i], toEigen(world_T_body.p), 0.0, 1e-12 * scale, b.name + " position"));
        EXPECT_TRUE(near(kin.R[i], toEigen(world_T_body.M), 0.0, 1e-13, b.name + " rotation"));
        // Mass properties: KDL's inertia moved to the world frame (rotation about the CoM).
        const KDL::RigidBodyInertia I_world = world_T_body.M * b.segment.getInertia();
        EXPECT_TRUE(near(kin.com[i], toEigen(world_T_body * toKDL(b.com)), 0.0, 1e-12 * scale, b.name + " CoM"));
        if (i > 0 && b.mass > 0.0) {
          Matrix3d I_o;  // KDL keeps the inertia about the reference point: back to the CoM
          const KDL::RotationalInertia Ir = I_world.getRotationalInertia();
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) I_o(r, c) = Ir.data[3 * r + c];
          const Vector3d c = toEigen(I_world.getCOG());
          const Matrix3d I_c = I_o + b.mass * skew(c) * skew(c);
          EXPECT_TRUE(near(kin.I_com[i], I_c, 1e-11, 1e-13 * I_c.norm(), b.name + " inertia"));
        }
        first_moment += b.mass * kin.com[i];
        // The joint's unit twist: KDL's Segment::twist (at the segment tip, parent axes) moved to
        // p_b and rotated to the world.
        if (b.joint >= 0) {
          KDL::Frame root_T_parent = KDL::Frame::Identity();
          if (b.parent > 0) ASSERT_GE(fk.JntToCart(state.q, root_T_parent, model->bodies()[b.parent].name), 0);
          const KDL::Frame world_T_parent = state.world_T_base * root_T_parent;
          const KDL::Twist tip_twist = b.segment.twist(state.q(b.joint), 1.0);  // at the tip, parent axes
          const KDL::Twist world = world_T_parent.M * tip_twist.RefPoint(-b.segment.pose(state.q(b.joint)).p);
          const Vector6d S = shiftTwist(toEigen(world), toEigen(state.world_T_base.p) - toEigen(world_T_parent.p));
          EXPECT_TRUE(near(kin.S[i], S, 0.0, 1e-12 * scale, b.name + " joint twist"));
        } else {
          EXPECT_EQ(kin.S[i], Vector6d::Zero()) << b.name;
        }
      }
      EXPECT_TRUE(near(kin.r_g, first_moment / model->totalMass(), 0.0, 1e-12 * (1.0 + kin.r_g.norm()), "r_g"));
      // pose() and point() read the same numbers
      const Contact h{static_cast<int>(model->bodies().size()) - 1, KDL::Vector(0.1, -0.2, 0.3)};
      EXPECT_TRUE(near(kin.point(h), toEigen(kin.pose(h.body) * h.offset), 0.0, 1e-12 * (1.0 + kin.point(h).norm()), "point"));
    }
  }
}

TEST(ForwardKinematics, ARefusedStateLeavesTheKinematicsInvalid) {
  const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/space_arm7.urdf"));
  Kinematics kin(*model);
  State s(*model);
  ASSERT_EQ(forwardKinematics(*model, s, kin), E_NOERROR);
  s.q(1) = std::nan("");
  EXPECT_EQ(forwardKinematics(*model, s, kin), E_NOT_FINITE);
  EXPECT_FALSE(kin.valid);
  Kinematics unsized;  // default-constructed: for no model
  EXPECT_EQ(forwardKinematics(*model, State(*model), unsized), E_SIZE_MISMATCH);
}

}  // namespace
}  // namespace kdl_space::test
