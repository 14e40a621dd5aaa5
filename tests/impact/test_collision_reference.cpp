// Capture and point-impact cases of tests/data/reference (solved there from the full
// floating-base mass matrix as an impulsive constraint problem, not from G*), to 1e-9 relative.
#include <gtest/gtest.h>

#include "kdl_space/impact/collision.hpp"
#include "impact_util.hpp"
#include "reference_case.hpp"

namespace kdl_space::test {
namespace {

constexpr double kRel = 1e-9;
constexpr double kAbs = 1e-12;

struct Scene {
  explicit Scene(const std::string& name) : c(name), solver(c.model) {
    EXPECT_EQ(solver.compute(c.state), E_NOERROR);
    const nlohmann::json& t = c.json.at("inputs").at("target");
    target.mass = t.at("mass").get<double>();
    target.I_com = ReferenceCase::mat(t.at("inertia_about_com_world"));
    target.com = ReferenceCase::mat(t.at("com"));
    target.twist = ReferenceCase::vec(t.at("twist_at_com"));
    solver.contactPoint(c.contact, p_h);
  }
  ReferenceCase c;
  FreeFloatingSolver solver;
  RigidBody target;
  Vector3d p_h;

  void expectRobotAfter(const FloatingSide& robot, const RigidBodySide& body, const nlohmann::json& e) {
    EXPECT_TRUE(near(robot.contactTwistAfter(), ReferenceCase::mat(e.at("contact_twist_after")), kRel, kAbs, "contact_twist_after"));
    EXPECT_TRUE(near(body.twistAfter(), ReferenceCase::mat(e.at("target_twist_after")), kRel, kAbs, "target_twist_after"));
    EXPECT_TRUE(near(toEigen(robot.after().base_twist), ReferenceCase::mat(e.at("base_twist_after")), kRel, kAbs, "base_twist_after"));
    const std::vector<int> order = c.expectedOrder();
    Eigen::VectorXd qdot(order.size());
    for (std::size_t a = 0; a < order.size(); ++a) qdot(a) = robot.after().qdot(order[a]);
    EXPECT_TRUE(near(qdot, ReferenceCase::mat(e.at("qdot_after")), kRel, kAbs, "qdot_after"));
    const double T0 = e.at("energy_before").get<double>(), T1 = e.at("energy_after").get<double>();
    EXPECT_NEAR(robot.energyBefore() + body.energyBefore(), T0, kRel * T0);
    EXPECT_NEAR(robot.energyAfter() + body.energyAfter(), T1, kRel * T1);
  }
};

class CollisionReference : public ::testing::TestWithParam<std::string> {};

TEST_P(CollisionReference, Capture) {
  Scene s(GetParam());
  const nlohmann::json& e = s.c.json.at("capture");
  FloatingSide robot(s.solver.sharedModel(), s.solver.state(), s.c.contact, {s.c.base_twist, s.c.qdot});
  RigidBodySide body(s.target, s.p_h);
  EXPECT_TRUE(near(robot.contactTwistBefore(), ReferenceCase::mat(e.at("contact_twist_before")), kRel, kAbs, "contact_twist_before"));
  const Impulse impulse = collideOk(robot, body, ImpactLaw{ImpactKind::Capture});
  EXPECT_TRUE(near(impulse.F, ReferenceCase::mat(e.at("impulse_on_robot")), kRel, kAbs, "impulse_on_robot"));
  s.expectRobotAfter(robot, body, e);
  Vector6d momentum;
  momentum << ReferenceCase::mat(e.at("linear_momentum")), ReferenceCase::mat(e.at("angular_momentum_about_origin"));
  EXPECT_TRUE(near(robot.momentumBefore() + body.momentumBefore(), momentum, kRel, kAbs, "momentum before"));
  EXPECT_TRUE(near(robot.momentumAfter() + body.momentumAfter(), momentum, kRel, kAbs, "momentum after"));
}

TEST_P(CollisionReference, PointImpact) {
  Scene s(GetParam());
  const nlohmann::json& e = s.c.json.at("point_impact");
  FloatingSide robot(s.solver.sharedModel(), s.solver.state(), s.c.contact, {s.c.base_twist, s.c.qdot});
  RigidBodySide body(s.target, s.p_h);
  ImpactLaw law{ImpactKind::PointImpact, ReferenceCase::mat(e.at("normal")), e.at("restitution").get<double>()};
  const Impulse impulse = collideOk(robot, body, law);
  EXPECT_EQ(!impulse.separating, e.at("approaching").get<bool>());
  const double lambda = e.at("impulse_magnitude_on_target").get<double>();
  EXPECT_TRUE(near(-impulse.F, (Vector6d() << lambda * law.normal, Vector3d::Zero()).finished(), kRel, kAbs, "impulse"));
  s.expectRobotAfter(robot, body, e);
}

INSTANTIATE_TEST_SUITE_P(AllCases, CollisionReference,
                         ::testing::Values("twolink_q0", "twolink_bent", "twolink_3d", "arm6_home",
                                           "arm6_reach", "arm6_elbow_contact"));

}  // namespace
}  // namespace kdl_space::test
