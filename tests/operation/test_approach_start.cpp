// approachStartWarnings: an approach's start pose checked before it runs (issue 26: a singular
// start pose, sigma_min of J* 3e-5, was learned of only when the approach failed): the shipped
// start has no warning, a joint outside its limits is named, no approach is not checked.
#include <gtest/gtest.h>

#include <string>

#include "kdl_space/operation/capture_operation.hpp"

namespace kdl_space {
namespace {

Scenario approachScenario() {
  return loadScenario(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/approach_tumbling_box.yaml");
}

TEST(ApproachStart, TheShippedStartPoseHasNoWarning) { EXPECT_TRUE(approachStartWarnings(approachScenario()).empty()); }

TEST(ApproachStart, AJointOutsideItsLimitsIsNamed) {
  Scenario sc = approachScenario();
  const int j7 = sc.capture.robot.model->jointIndex("joint7");
  sc.capture.robot.state.q(j7) = 4.75;  // limits +-4.71239
  const std::vector<Diagnostic> w = approachStartWarnings(sc);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].kind, "joint_outside_limits");
  EXPECT_EQ(w[0].element, "joint7");
}

TEST(ApproachStart, ANearSingularStartIsWarnedBeforeTheApproachRuns) {
  // The case: a start pose at a singularity of J* (sigma_min / sigma_max 5e-5, a 6-joint
  // arm's wrist pitch at 0, its roll axes in line): said before the approach, not when it fails.
  Scenario sc = loadScenario(std::string(KDL_SPACE_SOURCE_DIR) + "/tests/data/scenarios/arm6_reach_capture.json");
  sc.approach = approachScenario().approach;  // the check reads the robot's start, not the grasp
  EXPECT_TRUE(approachStartWarnings(sc).empty()) << "wrist pitch -0.5: well conditioned";
  sc.capture.robot.state.q(sc.capture.robot.model->jointIndex("wrist_pitch_joint")) = 0.0;
  const std::vector<Diagnostic> w = approachStartWarnings(sc);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].kind, "near_singular");
  EXPECT_EQ(w[0].message.rfind("at the start of the approach: ", 0), 0u) << w[0].message;
}

TEST(ApproachStart, NoApproachNoCheck) {
  Scenario sc = approachScenario();
  sc.capture.robot.state.q(sc.capture.robot.model->jointIndex("joint7")) = 4.75;
  sc.approach.reset();
  EXPECT_TRUE(approachStartWarnings(sc).empty());
}

}  // namespace
}  // namespace kdl_space
