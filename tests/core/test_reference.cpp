// Every free-floating quantity of every case in tests/data/reference (values from an
// independent rigid-body engine, no KDL), to 1e-9 relative (1e-12 absolute where zero).
#include <gtest/gtest.h>

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "reference_case.hpp"

namespace kdl_space::test {
namespace {

constexpr double kRel = 1e-9;
constexpr double kAbs = 1e-12;

class Reference : public ::testing::TestWithParam<std::string> {};

TEST_P(Reference, FreeFloatingQuantities) {
  const ReferenceCase c(GetParam());
  const nlohmann::json& e = c.json.at("expected");
  FreeFloatingSolver solver(c.model);
  ASSERT_EQ(solver.compute(c.state), E_NOERROR);

  // Joint order: compare through the names, not positions.
  const std::vector<int> order = c.expectedOrder();
  ASSERT_EQ(order.size(), c.model->nj());
  for (int j : order) ASSERT_GE(j, 0);

  EXPECT_NEAR(solver.w(), e.at("mass").get<double>(), kRel * e.at("mass").get<double>());
  EXPECT_TRUE(near(solver.r_g(), ReferenceCase::mat(e.at("com")), kRel, kAbs, "com"));
  EXPECT_TRUE(near(solver.I_g(), ReferenceCase::mat(e.at("I_g")), kRel, kAbs, "I_g"));
  Vector3d p_h;
  ASSERT_EQ(solver.contactPoint(c.contact, p_h), E_NOERROR);
  EXPECT_TRUE(near(p_h, ReferenceCase::mat(e.at("hand_position")), kRel, kAbs, "hand_position"));

  KDL::Jacobian J_star(c.model->nj());
  ASSERT_EQ(solver.J_star(c.contact, J_star), E_NOERROR);
  Eigen::MatrixXd J_star_ordered(6, order.size()), H_star_ordered(order.size(), order.size());
  for (std::size_t a = 0; a < order.size(); ++a) {
    J_star_ordered.col(a) = J_star.data.col(order[a]);
    for (std::size_t b = 0; b < order.size(); ++b) H_star_ordered(a, b) = solver.H_star()(order[a], order[b]);
  }
  EXPECT_TRUE(near(J_star_ordered, ReferenceCase::mat(e.at("J_star")), kRel, kAbs, "J_star"));
  EXPECT_TRUE(near(H_star_ordered, ReferenceCase::mat(e.at("H_star")), kRel, kAbs, "H_star"));

  Matrix6d G;
  ASSERT_EQ(solver.G_star(c.contact, G), E_NOERROR);
  EXPECT_TRUE(near(G, ReferenceCase::mat(e.at("G_star")), kRel, kAbs, "G_star"));
  ASSERT_EQ(solver.G_grounded(c.contact, G), E_NOERROR);
  EXPECT_TRUE(near(G, ReferenceCase::mat(e.at("G_grounded")), kRel, kAbs, "G_grounded"));
  ASSERT_EQ(solver.G_locked(c.contact, G), E_NOERROR);
  EXPECT_TRUE(near(G, ReferenceCase::mat(e.at("G_locked")), kRel, kAbs, "G_locked"));
}

TEST_P(Reference, MomentumAndHandTwistBeforeImpact) {
  // The reference's contact twist before the impact, from the base twist and joint rates,
  // through the momentum (eq. 2) and eq. 4; and its linear momentum of the robot alone.
  const ReferenceCase c(GetParam());
  FreeFloatingSolver solver(c.model);
  ASSERT_EQ(solver.compute(c.state), E_NOERROR);
  Vector6d PL;
  ASSERT_EQ(solver.momentum(c.base_twist, c.qdot, PL), E_NOERROR);
  KDL::Twist t_h;
  ASSERT_EQ(solver.handTwist(c.contact, c.qdot, PL, t_h), E_NOERROR);
  EXPECT_TRUE(near(toEigen(t_h), ReferenceCase::mat(c.json.at("capture").at("contact_twist_before")),
                   kRel, kAbs, "contact_twist_before"));
  KDL::Twist back;
  ASSERT_EQ(solver.baseTwist(PL, c.qdot, back), E_NOERROR);
  EXPECT_TRUE(near(toEigen(back), toEigen(c.base_twist), kRel, kAbs, "base twist round trip"));
}

INSTANTIATE_TEST_SUITE_P(AllCases, Reference,
                         ::testing::Values("twolink_q0", "twolink_bent", "twolink_3d", "arm6_home",
                                           "arm6_reach", "arm6_elbow_contact"));

}  // namespace
}  // namespace kdl_space::test
