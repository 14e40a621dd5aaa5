// What the motion after the capture warns about (OperationResult::warnings): a servo so stiff
// that an explicit integrator's steps shrink far below the output step, named by its joint (a
// "*" pattern that gives a 15 g finger the arm's gains), and a controller sampled at a control
// rate whose rate gain its zero-order hold cannot keep stable (the joints expected from H*
// computed here, not from the check's own route), with the controller's extra calls counted.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "test_util.hpp"

namespace kdl_space {
namespace {

using test::urdfDir;

std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "kdl_space_" + name;
  std::ofstream(path) << text;
  return path;
}

/// space_arm7.urdf with a 15 g finger on a prismatic joint `finger_joint` at the end effector.
std::string armWithFinger() {
  std::ifstream in(urdfDir() + "/space_arm7.urdf");
  std::stringstream text;
  text << in.rdbuf();
  const std::string finger = R"(  <joint name="finger_joint" type="prismatic">
    <parent link="end_effector"/>
    <child link="finger"/>
    <origin xyz="0 0 0.02" rpy="0 0 0"/>
    <axis xyz="1 0 0"/>
    <limit lower="-0.04" upper="0.04" effort="20" velocity="0.2"/>
  </joint>
  <link name="finger">
    <inertial>
      <origin xyz="0 0 0.02" rpy="0 0 0"/>
      <mass value="0.015"/>
      <inertia ixx="2e-6" ixy="0" ixz="0" iyy="2e-6" iyz="0" izz="1e-6"/>
    </inertial>
  </link>
</robot>)";
  return writeFile("arm_with_finger.urdf", std::regex_replace(text.str(), std::regex("</robot>"), finger));
}

const Diagnostic* find(const std::vector<Diagnostic>& warnings, const std::string& kind, const std::string& element) {
  for (const Diagnostic& d : warnings)
    if (d.kind == kind && d.element == element) return &d;
  return nullptr;
}

TEST(MotionWarnings, StarPatternOnALightFingerIsReportedStiffByTheFingersName) {
  // The arm's joints have gains of their own; "*" catches the finger too: kd / m = 300 / 0.015 =
  // 2e4 1/s, so dopri5's stable step is some 1e-4 s against an output step of 0.05 s.
  const std::string urdf = armWithFinger();
  const Scenario sc = loadScenario(writeFile("finger_star.yaml", "robot:\n  urdf: " + urdf +
                                                                     "\n  q: {joint2: 0.7, joint4: 0.8, joint6: -0.6}\n"
                                                                     "  qdot: {joint1: 0.1, joint6: 0.3, joint7: -0.5}\n"
                                                                     "simulation:\n  duration: 0.3\n  output_step: 0.05\n"
                                                                     "  joints:\n"
                                                                     "    \"*\": {pd: {kp: 400, kd: 300, set_point: hold}}\n"
                                                                     "    \"joint[1-7]\": {pd: {kp: 40, kd: 5, set_point: hold}}\n"));
  const OperationResult r = runCaptureOperation(sc);
  const Diagnostic* stiff = find(r.warnings, "stiff", "finger_joint");
  ASSERT_NE(stiff, nullptr) << "warnings: " << r.warnings.size();
  EXPECT_NE(stiff->message.find("stiff"), std::string::npos) << stiff->message;
  EXPECT_NE(stiff->message.find("'finger_joint'"), std::string::npos) << stiff->message;
  EXPECT_NE(stiff->message.find("rosenbrock"), std::string::npos) << stiff->message;
  // The steps were indeed tiny: below 1 % of the output step on average.
  EXPECT_LT(r.record.meanStep(), 0.01 * 0.05);
  // With rosenbrock the same servos are no longer stiff for the integrator: no warning.
  Scenario implicit = sc;
  implicit.simulation.options.integrator = Integrator::Rosenbrock;
  EXPECT_EQ(find(runCaptureOperation(implicit).warnings, "stiff", "finger_joint"), nullptr);
}

/// A plain motion of the default arm (free-floating, no servo of its own) for a sampled controller.
Scenario plainArm() {
  return loadScenario(writeFile("plain_arm.yaml", "robot:\n  urdf: " + urdfDir() +
                                                      "/space_arm7.urdf\n  q: {joint2: 0.7, joint4: 0.8, joint6: -0.6}\n"
                                                      "  qdot: {joint1: 0.05, joint6: 0.1}\n"
                                                      "simulation:\n  duration: 0.2\n  output_step: 0.05\n"));
}

TEST(MotionWarnings, SampledPdBeyondItsHoldsStabilityIsWarnedPerJoint) {
  const Scenario sc = plainArm();
  const FloatingSystem& robot = sc.capture.robot;
  const unsigned int n = robot.model->nj();
  // The apparent inertia of each joint from H* (base free), independently of the check's route.
  FreeFloatingSolver solver(robot.model);
  ASSERT_EQ(solver.compute(robot.state), 0);
  const Eigen::MatrixXd H_star_inv = solver.H_star().data.inverse();
  const double rate = 200.0, kd = 30.0;  // a continuous servo's gain, sampled at 200 Hz
  std::vector<std::string> expected;
  for (unsigned int j = 0; j < n; ++j)
    if (kd / rate * H_star_inv(j, j) > 1.0) expected.push_back(robot.model->jointNames()[j]);
  ASSERT_FALSE(expected.empty());        // the wrist's joints: some, not all
  ASSERT_LT(expected.size(), std::size_t{n});
  OperationOptions o;
  long calls = 0;
  o.controller = [&](const SimulationState& x, Eigen::VectorXd& tau) {
    ++calls;
    tau = -kd * x.velocity.qdot.data;
  };
  o.control_rate = rate;
  OperationResult r;
  try {
    r = runCaptureOperation(sc, o);
  } catch (const OperationError& e) {  // it may well blow up: the warnings came first
    ASSERT_TRUE(e.partial());
    r = *e.partial();
    EXPECT_NE(std::string(e.what()).find("sampled at 200 Hz"), std::string::npos) << e.what();
  }
  std::vector<std::string> warned;
  for (const Diagnostic& d : r.warnings)
    if (d.kind == "sampled_gain_unstable") warned.push_back(d.element);
  EXPECT_EQ(warned, expected);
  const Diagnostic* first = find(r.warnings, "sampled_gain_unstable", expected.front());
  ASSERT_NE(first, nullptr);
  EXPECT_NE(first->message.find("200 Hz"), std::string::npos) << first->message;
  EXPECT_GE(calls, 2 * static_cast<long>(n));  // the probe: two calls a joint

  // The same gain at a rate where every joint keeps kd dt / m <= 1: no warning, no probe effect on
  // the motion (the controller is a function of the state).
  double fastest = 0.0;
  for (unsigned int j = 0; j < n; ++j) fastest = std::max(fastest, kd * H_star_inv(j, j));
  o.control_rate = 1000.0 * std::ceil(fastest / 1000.0);
  o.output_step = 0.01;  // a whole number (<= 1000) of periods: a common grid
  const OperationResult fast = runCaptureOperation(sc, o);
  EXPECT_EQ(find(fast.warnings, "sampled_gain_unstable", expected.front()), nullptr);
  EXPECT_TRUE(fast.warnings.empty());
  o.check_sampled_gains = false;
  const OperationResult unchecked = runCaptureOperation(sc, o);
  EXPECT_EQ(unchecked.end.state.q.data, fast.end.state.q.data);
}

}  // namespace
}  // namespace kdl_space
