// approachStartWarnings: an approach's start pose checked before it runs (issue 26: a singular
// start pose, sigma_min of J* 3e-5, was learned of only when the approach failed). The singular
// start is confirmed by an SVD of J* here (Eigen's, of the solver's J*), not by the library's check.
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <string>

#include "kdl_space/algorithm/conditioning.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/operation/capture_operation.hpp"

namespace kdl_space {
namespace {

Scenario approachScenario() {
  return loadScenario(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/approach_tumbling_box.yaml");
}

double sigmaRatio(const FloatingSystem& robot) {
  FreeFloatingSolver solver(robot.model);
  KDL::Jacobian J(robot.model->nj());
  EXPECT_EQ(solver.compute(robot.state), 0);
  EXPECT_EQ(solver.J_star(robot.contact, J), 0);
  const Eigen::VectorXd s = Eigen::JacobiSVD<Eigen::MatrixXd>(J.data).singularValues();
  return s(s.size() - 1) / s(0);
}

TEST(ApproachStart, TheShippedStartPoseHasNoWarning) { EXPECT_TRUE(approachStartWarnings(approachScenario()).empty()); }

TEST(ApproachStart, AStretchedOutArmIsNearSingular) {
  Scenario sc = approachScenario();
  sc.capture.robot.state.q.data.setZero();  // joints 1, 3, 5, 7 on one axis
  ASSERT_LT(sigmaRatio(sc.capture.robot), kNearSingularRatio);
  const std::vector<Diagnostic> w = approachStartWarnings(sc);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].kind, "near_singular");
  EXPECT_EQ(w[0].element, "contact 'end_effector'");
  EXPECT_EQ(w[0].message.rfind("at the start of the approach: J* is near a singularity here: sigma_min / sigma_max = ", 0), 0u)
      << w[0].message;
}

TEST(ApproachStart, AJointOutsideItsLimitsIsNamed) {
  Scenario sc = approachScenario();
  const int j7 = sc.capture.robot.model->jointIndex("joint7");
  sc.capture.robot.state.q(j7) = 4.75;  // limits +-4.71239
  const std::vector<Diagnostic> w = approachStartWarnings(sc);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].kind, "joint_outside_limits");
  EXPECT_EQ(w[0].element, "joint7");
}

TEST(ApproachStart, NoApproachNoCheck) {
  Scenario sc = approachScenario();
  sc.capture.robot.state.q.data.setZero();
  sc.approach.reset();
  EXPECT_TRUE(approachStartWarnings(sc).empty());
}

}  // namespace
}  // namespace kdl_space
