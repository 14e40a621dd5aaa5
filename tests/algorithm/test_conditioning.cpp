// Conditioning figures against matrices whose singular values are known in closed form, joint
// margins against the URDF's limits, and the configuration warnings (a joint outside its limits,
// a near-singular J*; each absent when it should be). NumPy's SVD of the library's own J* and a
// URDF forward kinematics check the same on the bundled arms in python/tests/test_poses.py.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "kdl_space/algorithm/conditioning.hpp"
#include "kdl_space/multibody/poses.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

// J = U diag(s) V^T with U, V rotations (Givens): the singular values are s, sorted.
TEST(Conditioning, SingularValuesConditionAndManipulabilityOfAKnownMatrix) {
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(6, 7);
  const double s[6] = {0.5, 3.0, 2.0, 1e-4, 1.0, 0.25};
  for (int i = 0; i < 6; ++i) S(i, i) = s[i];
  Eigen::MatrixXd U = Eigen::MatrixXd::Identity(6, 6), V = Eigen::MatrixXd::Identity(7, 7);
  const double a = 0.3, b = -1.1;
  U.block<2, 2>(1, 1) << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  V.block<2, 2>(4, 4) << std::cos(b), -std::sin(b), std::sin(b), std::cos(b);
  const Eigen::MatrixXd J = U * S * V.transpose();
  const Conditioning c = conditioning(J, 2.0 * J);
  const double sorted[6] = {3.0, 2.0, 1.0, 0.5, 0.25, 1e-4};
  ASSERT_EQ(c.sigma_J_star.size(), 6);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(c.sigma_J_star(i), sorted[i], 1e-14);
  EXPECT_NEAR(c.condition_number, 3.0 / 1e-4, 1e-12 * 3e4 * 100);
  const double product = 3.0 * 2.0 * 1.0 * 0.5 * 0.25 * 1e-4;
  EXPECT_NEAR(c.manipulability_J_star, product, 1e-14 * product * 100);
  EXPECT_NEAR(c.manipulability_J, 64.0 * product, 64.0 * 1e-14 * product * 100);  // 2^6
  EXPECT_LT(c.ratio(), kNearSingularRatio);
  const Conditioning singular = conditioning(Eigen::MatrixXd::Zero(6, 2), Eigen::MatrixXd::Zero(6, 2));
  EXPECT_TRUE(std::isinf(singular.condition_number));
  EXPECT_EQ(singular.ratio(), 0.0);
}

TEST(Conditioning, MarginsAndWarningsAtTheLimits) {
  const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/space_arm7.urdf"));
  State state(*model);
  const int j4 = model->jointIndex("joint4");  // limits +-2.79253 in the URDF
  state.q(j4) = 2.5;
  std::vector<JointMargin> m = jointMargins(*model, state.q);
  EXPECT_TRUE(m[j4].limited);
  EXPECT_NEAR(m[j4].margin(), 2.79253 - 2.5, 1e-15);
  EXPECT_NEAR(m[j4].to_lower, 2.5 + 2.79253, 1e-15);
  Conditioning c;
  std::vector<Diagnostic> warnings;
  state.q(model->jointIndex("joint2")) = 0.7;
  ASSERT_EQ(checkConfiguration(model, state, model->contact("end_effector"), c, warnings), E_NOERROR);
  EXPECT_TRUE(warnings.empty()) << warnings.front().message;
  state.q(j4) = 3.0;
  ASSERT_EQ(checkConfiguration(model, state, model->contact("end_effector"), c, warnings), E_NOERROR);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].kind, "joint_outside_limits");
  EXPECT_EQ(warnings[0].element, "joint4");
  EXPECT_TRUE(m[j4].limited && jointMargins(*model, state.q)[j4].outside());
}

TEST(Poses, LinkPoseRefusesABodyItDoesNotHave) {
  const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/space_arm7.urdf"));
  KDL::Frame f;
  EXPECT_EQ(linkPose(*model, State(*model), -1, f), E_BAD_CONTACT);
  EXPECT_EQ(linkPose(*model, State(*model), static_cast<int>(model->bodies().size()), f), E_BAD_CONTACT);
  State bad(*model);
  bad.q(0) = std::nan("");
  EXPECT_EQ(linkPose(*model, bad, 1, f), E_NOT_FINITE);
  // A quaternion (x, y, z, w) with w >= 0: a half turn and a bit about z.
  const PoseFigures p = poseFigures(KDL::Frame(KDL::Rotation::RotZ(M_PI + 0.2)));
  EXPECT_GE(p.quaternion(3), 0.0);
  EXPECT_NEAR(p.quaternion(2), -std::sin((M_PI + 0.2) / 2), 1e-15);
  EXPECT_NEAR(p.rpy(2), -M_PI + 0.2, 1e-15);
}

}  // namespace
}  // namespace kdl_space::test
