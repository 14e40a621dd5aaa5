// base_control.phases: in which phases of the capture operation the satellite's own control acts.
// The approach of approach_tumbling_box.yaml with an attitude control added: by default (after the
// capture) its approach is the approach without any base control, sample for sample; with
// `phases: [approach, after]` the control's impulse changes the system's momentum during the
// approach (it is conserved without one). The phases the run reports, and the refusals.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "kdl_space/operation/capture_operation.hpp"
#include "test_util.hpp"

namespace kdl_space {
namespace {

using test::urdfDir;

/// approach_tumbling_box.yaml (whose simulation section comes last) with `extra` appended to its
/// simulation section, written where a test may write.
std::string approachScenario(const std::string& name, const std::string& extra) {
  std::ifstream in(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/approach_tumbling_box.yaml");
  std::stringstream text;
  text << in.rdbuf();
  const std::string yaml = std::regex_replace(text.str(), std::regex(R"(\.\./urdf/)"), urdfDir() + "/") + extra;
  const std::string path = ::testing::TempDir() + "kdl_space_" + name + ".yaml";
  std::ofstream(path) << yaml;
  return path;
}

const char* const kAttitude = "  base_control:\n    attitude: {kp: 400, kd: 1500, set_point: hold, torque_limit: 2.0}\n";

OperationOptions approachOnly() {
  OperationOptions o;
  o.motion = false;  // the approach and the capture
  return o;
}

TEST(BaseControlPhases, DefaultActsAfterTheCaptureOnlyAndTheApproachOptsIn) {
  const Scenario none = loadScenario(approachScenario("no_base_control", ""));
  const Scenario by_default = loadScenario(approachScenario("base_control_default", kAttitude));
  const Scenario opted_in =
      loadScenario(approachScenario("base_control_approach", std::string(kAttitude) + "    phases: [approach, after]\n"));
  EXPECT_FALSE(by_default.simulation.base_control.in_approach);
  EXPECT_TRUE(by_default.simulation.base_control.after_capture);
  EXPECT_TRUE(opted_in.simulation.base_control.in_approach);
  EXPECT_TRUE(opted_in.simulation.base_control.after_capture);

  const OperationResult free_run = runCaptureOperation(none, approachOnly());
  const OperationResult default_run = runCaptureOperation(by_default, approachOnly());
  const OperationResult controlled = runCaptureOperation(opted_in, approachOnly());
  // By default the approach is the uncontrolled one: the same computation, so the same numbers.
  ASSERT_EQ(default_run.approach_samples.size(), free_run.approach_samples.size());
  for (std::size_t i = 0; i < free_run.approach_samples.size(); ++i) {
    const MotionSample &a = default_run.approach_samples[i], &b = free_run.approach_samples[i];
    EXPECT_EQ(a.quat, b.quat) << "t = " << a.t;
    EXPECT_EQ(a.twist, b.twist) << "t = " << a.t;
    EXPECT_EQ(a.impulse, Vector6d::Zero()) << "t = " << a.t;
  }
  EXPECT_EQ(default_run.t_capture, free_run.t_capture);
  // Opted in: the wheels' torque is an external impulse on the robot during the approach (the
  // robot's momentum, conserved without it, changes by it), so its base turns otherwise.
  ASSERT_FALSE(controlled.approach_samples.empty());
  const MotionSample& last = controlled.approach_samples.back();
  const double impulse = last.impulse.tail<3>().norm();
  EXPECT_GT(impulse, 1e-3) << "the attitude control's angular impulse [N m s] over the approach";
  EXPECT_NEAR((last.h - controlled.approach_samples.front().h - last.impulse).norm(), 0.0, 1e-8 * (1.0 + impulse));
  const std::size_t k = std::min(controlled.approach_samples.size(), free_run.approach_samples.size()) - 1;
  EXPECT_GT((controlled.approach_samples[k].twist - free_run.approach_samples[k].twist).tail<3>().norm(), 1e-6)
      << "the base's angular rate at t = " << controlled.approach_samples[k].t;
  // What each run says it did (no motion after the capture here).
  EXPECT_TRUE(free_run.base_control_phases.empty());
  EXPECT_TRUE(default_run.base_control_phases.empty());
  EXPECT_EQ(controlled.base_control_phases, std::vector<std::string>{"approach"});
}

/// A plain motion (no target: the `after` phase is the whole run) of the arm with an attitude
/// control of the base, its phases as given ("" : the default).
std::string plainMotion(const std::string& name, const std::string& phases) {
  const std::string path = ::testing::TempDir() + "kdl_space_" + name + ".yaml";
  std::ofstream(path) << "robot:\n  urdf: " << urdfDir() << "/space_arm7.urdf\n  q: {joint2: 0.7, joint4: 0.8}\n"
                      << "  qdot: {joint1: 0.2, joint4: -0.3}\nsimulation:\n  duration: 0.2\n  output_step: 0.05\n"
                      << kAttitude << phases;
  return path;
}

TEST(BaseControlPhases, MotionAfterTheCaptureIsControlledUnlessThePhasesLeaveItOut) {
  const OperationResult after = runCaptureOperation(loadScenario(plainMotion("base_control_after", "")));
  EXPECT_TRUE(after.record.base_control.on());
  EXPECT_GT(after.record.last.impulse.tail<3>().norm(), 0.0);  // the arm's swing turns the base: the wheels answer
  EXPECT_EQ(after.base_control_phases, std::vector<std::string>{"after"});
  const OperationResult approach_only =
      runCaptureOperation(loadScenario(plainMotion("base_control_approach_only", "    phases: [approach]\n")));
  EXPECT_FALSE(approach_only.record.base_control.on());
  EXPECT_TRUE(approach_only.base_control_phases.empty());
  EXPECT_EQ(approach_only.record.last.impulse, Vector6d::Zero());
}

TEST(BaseControlPhases, UnknownOrNoPhaseIsRefusedByName) {
  const auto refusal = [](const std::string& name, const std::string& phases) {
    try {
      loadScenario(approachScenario(name, std::string(kAttitude) + "    phases: " + phases + "\n"));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refusal("phase_unknown", "[approach, sideways]")
                .find("simulation.base_control.phases[1]: 'sideways' is not one of approach, after"),
            std::string::npos)
      << refusal("phase_unknown", "[approach, sideways]");
  EXPECT_NE(refusal("phase_empty", "[]").find("simulation.base_control.phases: is empty"), std::string::npos)
      << refusal("phase_empty", "[]");
  EXPECT_NE(refusal("phase_scalar", "after").find("simulation.base_control.phases: expected a list"), std::string::npos)
      << refusal("phase_scalar", "after");
}

}  // namespace
}  // namespace kdl_space
