// The post-capture law `impedance` (GraspImpedance, issue 39 item 2): the arm as a spring-damper
// at the grasp, its force within the grasp's limit. Against closed forms and the grasp's load:
//   1. a bus and a slider on a prismatic joint through both centres of mass: the relative motion
//      is the damped oscillator mu q'' + D q' + K q = 0 (mu the reduced mass), exactly (1e-9);
//   2. the same with the force at the grasp's limit: a constant deceleration F_max / mu (1e-9);
//   3. on the tumbling box and the robot-to-robot capture with law.max_grasp_wrench: the grasp's
//      peak load (graspWrench) stays near the limit where `hold` passes it many times, the
//      momentum is kept (1e-12) and the energy balances with the controls' work;
//   4. refused where it cannot act (a joint without a servo, no damping, with momentum_distribution).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "kdl_space/simulation/simulation.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

using ModelPtr = std::shared_ptr<const FloatingModel>;

// A 100 kg bus and a 25 kg slider along x, both centres of mass on the joint's line: nothing turns,
// and the slider's displacement q relative to the bus has the reduced mass mu = 100 25 / 125 = 20 kg.
const char* kSlider = R"(<robot name="slider">
  <link name="bus"><inertial><origin xyz="0 0 0"/><mass value="100"/><inertia ixx="15" ixy="0" ixz="0" iyy="18" iyz="0" izz="20"/></inertial></link>
  <link name="slider"><inertial><origin xyz="0 0 0"/><mass value="25"/><inertia ixx="0.5" ixy="0" ixz="0" iyy="0.6" iyz="0" izz="0.7"/></inertial></link>
  <joint name="stroke" type="prismatic"><parent link="bus"/><child link="slider"/><origin xyz="1 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="1000" velocity="10"/></joint></robot>)";
constexpr double kMu = 20.0;

struct Slider {
  ModelPtr model = std::make_shared<const FloatingModel>(loadUrdfString(kSlider, "slider"));
  std::unique_ptr<Simulator> sim;
  SimulationState s;
  explicit Slider(double K, double D, double max_force) {
    SimulationOptions options;
    options.rtol = 1e-12;
    options.atol = 1e-14;
    sim = std::make_unique<Simulator>(model, options);
    JointControl servo;  // its gains are replaced by the law's (kd damps a self-motion: none here)
    servo.mode = JointControl::Mode::PD;
    servo.kp = 1e3;
    servo.kd = 50.0;
    sim->setJointControl(0, servo);
    GraspImpedance law;
    law.on = true;
    law.joints = {true};
    law.contact = model->contact("slider", KDL::Vector(0.2, 0.1, 0.0));
    law.stiffness << K, 7.0;  // the rotation's gains act on nothing here
    law.damping << D, 3.0;
    law.max_force = max_force;
    sim->setGraspImpedance(law);
    s.state = State(*model);
    s.velocity.qdot = KDL::JntArray(1);
    s.velocity.qdot(0) = 0.1;
    s.velocity.base_twist.vel = KDL::Vector(-0.02, 0.0, 0.0);
  }
};

TEST(ImpedanceLaw, TheSlidersRelativeMotionIsTheDampedOscillator) {
  const double K = 500.0, D = 40.0;  // omega_0 5 rad/s, zeta 0.2
  Slider x(K, D, std::numeric_limits<double>::infinity());
  const double w0 = std::sqrt(K / kMu), zeta = D / (2.0 * std::sqrt(K * kMu)), wd = w0 * std::sqrt(1.0 - zeta * zeta);
  const double v0 = 0.1;
  double worst = 0.0;
  ASSERT_EQ(x.sim->run(x.s, 3.0, 0.05,
                       [&](const SimulationState& st) {
                         const double q = std::exp(-zeta * w0 * st.t) * (v0 / wd) * std::sin(wd * st.t);
                         worst = std::max(worst, std::abs(st.state.q(0) - q));
                         EXPECT_NEAR(st.velocity.base_twist.rot.Norm(), 0.0, 1e-15) << "nothing turns";
                       }),
            E_NOERROR);
  EXPECT_LT(worst, 1e-9 * v0 / wd);
  EXPECT_NE(x.s.state.q(0), 0.0);
}

TEST(ImpedanceLaw, AtTheGraspsLimitTheSliderDeceleratesUniformly) {
  const double F = 0.5;  // D v0 = 100 N would pass it: the force stays at F while the slider moves out
  Slider x(0.0, 1000.0, F);
  const double v0 = 0.1, t_stop = v0 * kMu / F;  // 4 s
  ASSERT_EQ(x.sim->run(x.s, 0.9 * t_stop, 0.1,
                       [&](const SimulationState& st) {
                         EXPECT_NEAR(st.velocity.qdot(0), v0 - F / kMu * st.t, 1e-9 * v0) << st.t;
                         EXPECT_NEAR(st.state.q(0), v0 * st.t - 0.5 * F / kMu * st.t * st.t, 1e-9 * v0) << st.t;
                       }),
            E_NOERROR);
}

TEST(ImpedanceLaw, RefusedWhereItCannotAct) {
  Slider x(1.0, 1.0, 1.0);
  GraspImpedance law = x.sim->graspImpedance();
  const auto refused = [&](const GraspImpedance& l, const std::string& why) {
    try {
      x.sim->setGraspImpedance(l);
      ADD_FAILURE() << "accepted; expected " << why;
    } catch (const ModelError& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  };
  GraspImpedance bad = law;
  bad.damping.setZero();
  refused(bad, "it needs some damping");
  bad = law;
  bad.max_force = 0.0;
  refused(bad, "the grasp's limits must be > 0");
  bad = law;
  bad.contact.body = 5;
  refused(bad, "the contact is not on the model");
  JointControl free_joint;
  x.sim->setJointControl(0, free_joint);
  refused(law, "joint 'stroke' is no PD servo");
}

/// The shipped scenario with the grasp's limit, `after_capture: {law: <law>}`, `seconds` of motion.
OperationResult withLaw(const std::string& name, SimulationSpec::Law law, double force, double moment, double seconds) {
  Scenario sc = loadScenario(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/" + name + ".yaml");
  sc.max_grasp_force = force;
  sc.max_grasp_moment = moment;
  sc.simulation.after_capture = law;
  sc.simulation.duration = seconds;
  sc.simulation.output_step = 0.01;
  if (sc.simulation.joints.empty())  // robot_to_robot_capture's arm moves freely: give it servos to replace
    for (unsigned int j = 0; j < sc.capture.robot.model->nj(); ++j) {
      JointControl c;
      c.mode = JointControl::Mode::PD;
      c.kp = 300.0;
      c.kd = 200.0;
      c.set_point = sc.capture.robot.state.q(j);
      sc.simulation.joints.emplace_back(j, c);
    }
  return runCaptureOperation(sc);
}

void expectTheGraspYields(const std::string& name, double force, double moment) {
  SCOPED_TRACE(name);
  const OperationResult hold = withLaw(name, SimulationSpec::Law::Hold, force, moment, 5.0);
  const OperationResult yields = withLaw(name, SimulationSpec::Law::Impedance, force, moment, 5.0);
  ASSERT_TRUE(hold.record.grasp.held() && yields.record.grasp.held());
  // hold passes the limit several times over; the impedance keeps the grasp's load near it (the
  // commanded force is within it; the hand link's own inertia and the other joints add a little).
  EXPECT_GT(hold.record.grasp.force, 2.0 * force);
  EXPECT_LT(yields.record.grasp.force, 1.1 * force);
  EXPECT_LT(yields.record.grasp.moment, 1.1 * moment);
  for (const Diagnostic& d : yields.warnings) EXPECT_NE(d.kind, "grasp_overload") << d.message;
  // Momentum kept (no external wrench), energy: the kinetic energy's change is the controls' work.
  const Vector6d h0 = yields.samples.front().h;
  for (const MotionSample& x : yields.samples)
    ASSERT_TRUE(near(x.h, h0, 0.0, 1e-12 * h0.norm(), "momentum")) << "t = " << x.t;
  const MotionSample& last = yields.samples.back();
  EXPECT_NEAR(last.T - yields.samples.front().T, last.work.sum(), 1e-8 * yields.samples.front().T);
  EXPECT_LT(last.T, yields.samples.front().T) << "the impedance dissipates";
}

TEST(ImpedanceLaw, TheTumblingBoxsGraspStaysNearItsLimit) { expectTheGraspYields("tumbling_box_capture", 3.0, 2.0); }

TEST(ImpedanceLaw, TheRobotTargetsGraspStaysNearItsLimit) { expectTheGraspYields("robot_to_robot_capture", 0.5, 0.5); }

}  // namespace
}  // namespace kdl_space::test
