// The post-capture laws (issue 39 item 2): `hold` (the servos hold the capture configuration, the
// wheels hold the bus's attitude) and `momentum_distribution` (MomentumDistribution: the arm takes
// up the momentum, the wheels unload it), against closed forms and an independent route:
//   1. the reactionless rates against the dense centroid terms (FreeFloatingSolver's A_m, I_g):
//      A_w qdot_d = L_g, least norm, and the base's rate zero at those rates;
//   2. a planar bus with one arm joint about its z axis: A_w by hand, and with the attitude law's
//      gains zero the wheels' unloading is exactly L_g(t) = L_g(0) exp(-k t);
//   3. a rigid bus with a wheel under `hold`'s attitude PD: the damped oscillator in closed form;
//   4. momentum_distribution turns the bus less than hold on the shipped detumble, a robot-to-
//      robot capture and a heavy arm on a light bus, with no limit exceeded and the momentum of
//      links and wheels kept.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <unistd.h>

#include "arm_variants.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "kdl_space/simulation/simulation.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

using ModelPtr = std::shared_ptr<const FloatingModel>;

ReactionWheels threeWheels(double torque_limit, double capacity) {
  ReactionWheels w;
  w.axes = Eigen::Matrix3d::Identity();
  w.torque_limit = Eigen::Vector3d::Constant(torque_limit);
  w.capacity = Eigen::Vector3d::Constant(capacity);
  return w;
}

/// The law over every joint of `sim` (each a PD servo of rate gain kd), no rate limit.
void distribute(Simulator& sim, double kd, double unload_gain) {
  const unsigned int n = sim.model().nj();
  JointControl pd;
  pd.mode = JointControl::Mode::PD;
  pd.kp = 0.0;
  pd.kd = kd;
  for (unsigned int j = 0; j < n; ++j) sim.setJointControl(j, pd);
  MomentumDistribution law;
  law.on = true;
  law.joints.assign(n, true);
  law.rate_limit = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  law.unload_gain = unload_gain;
  sim.setMomentumDistribution(law);
}

// 1. The 7-joint arm tumbling with rates of its own: the law's rates hold the links' angular
// momentum about the CoM (A_w qdot_d = L_g, A_m and L_g by the dense solver), are the least-norm
// such rates (in the row space of A_w), and with them the base does not turn (eq. 2 solved by
// the dense solver's baseTwist).
TEST(PostCaptureLaws, ReactionlessRatesAgainstTheDenseCentroidTerms) {
  const ModelPtr model = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/space_arm7.urdf"));
  Simulator sim(model);
  distribute(sim, 100.0, 0.0);
  SimulationState s;
  s.state = State(*model);
  s.state.world_T_base = KDL::Frame(KDL::Rotation::RPY(0.2, -0.1, 0.4), KDL::Vector(0.3, -0.2, 0.1));
  const double q[] = {0.3, 0.7, 0.9, 0.8, -0.2, -0.6, 0.4}, qd[] = {0.02, -0.01, 0.03, 0.0, 0.05, -0.02, 0.01};
  s.velocity.qdot = KDL::JntArray(7);
  for (int j = 0; j < 7; ++j) s.state.q(j) = q[j], s.velocity.qdot(j) = qd[j];
  s.velocity.base_twist = KDL::Twist(KDL::Vector(0.01, 0.0, -0.02), KDL::Vector(0.01, -0.03, 0.02));
  Eigen::VectorXd qdot_d;
  ASSERT_EQ(sim.reactionlessRates(s, qdot_d), E_NOERROR);
  FreeFloatingSolver dense(model);
  ASSERT_EQ(dense.compute(s.state), E_NOERROR);
  Vector6d PL_g;
  ASSERT_EQ(dense.momentum(s.velocity.base_twist, s.velocity.qdot, PL_g), E_NOERROR);
  const Eigen::Matrix<double, 3, Eigen::Dynamic> A = dense.A_m().bottomRows(3);
  const Vector3d L_g = PL_g.tail<3>();
  EXPECT_TRUE(near(Vector3d(A * qdot_d), L_g, 1e-10, 1e-14, "A_w qdot_d = L_g"));
  const Eigen::MatrixXd P = Eigen::MatrixXd::Identity(7, 7) - A.transpose() * (A * A.transpose()).inverse() * A;
  EXPECT_LT((P * qdot_d).norm(), 1e-12 * qdot_d.norm()) << "not the least-norm rates";
  KDL::JntArray rates(7);
  rates.data = qdot_d;
  KDL::Twist base;
  ASSERT_EQ(dense.baseTwist(PL_g, rates, base), E_NOERROR);
  EXPECT_LT(base.rot.Norm(), 1e-12 * L_g.norm());
}

// 2. A planar system: a 100 kg bus (I_z 20) with one link (5 kg, I_z 0.4 about its CoM) on a
// joint about z at (1, 0) on the bus, its CoM 0.5 m further along x. Turning in the plane, so
// the wheels' gyroscopic torque is zero and everything is about z.
const char* kPlanar = R"(<robot name="planar">
  <link name="bus"><inertial><origin xyz="0 0 0"/><mass value="100"/><inertia ixx="15" ixy="0" ixz="0" iyy="18" iyz="0" izz="20"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0.5 0 0"/><mass value="5"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.4" iyz="0" izz="0.4"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="bus"/><child link="arm"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1000" velocity="10"/></joint></robot>)";

// With the base still, a unit joint rate moves the link's CoM (at c = (1.5, 0)) at z x (c - j),
// j = (1, 0): A_w = I_link + m (c - r_g) x (z x (c - j)) = 0.4 + 5 (1.5 - r_g) 0.5, r_g = 7.5 / 105.
// The law's rate is L_g / A_w. Under it the base does not turn; unloaded by the wheels with the
// attitude gains zero, the bus feels exactly -k L_g: L_g(t) = L_g(0) exp(-k t), the wheel holds
// the rest, and the base's rate stays near zero (the servo's lag only).
TEST(PostCaptureLaws, PlanarMomentumDistributionClosedForm) {
  const ModelPtr model = std::make_shared<const FloatingModel>(loadUrdfString(kPlanar, "planar"));
  const double r_g = 7.5 / 105.0, A_w = 0.4 + 5.0 * (1.5 - r_g) * 0.5, k = 0.3;
  SimulationOptions options;
  options.rtol = 1e-12;
  options.atol = 1e-14;
  Simulator sim(model, options);
  sim.setReactionWheels(threeWheels(100.0, 100.0));
  BaseControl unload;  // the attitude law on, its own gains zero: only the unloading acts
  unload.attitude.on = unload.attitude.hold = true;
  sim.setBaseControl(unload);
  distribute(sim, 200.0, k);
  SimulationState s;
  s.state = State(*model);
  s.velocity.qdot = KDL::JntArray(1);
  s.velocity.base_twist.rot = KDL::Vector(0, 0, 0.05);  // the stack spins: L_g about z
  double T;
  Vector6d h;
  ASSERT_EQ(sim.energyAndMomentum(s, T, h), E_NOERROR);
  FreeFloatingSolver dense(model);
  ASSERT_EQ(dense.compute(s.state), E_NOERROR);
  EXPECT_NEAR(dense.A_m()(5, 0), A_w, 1e-12);  // the hand-derived A_w is the solver's
  Vector6d PL_g;
  ASSERT_EQ(dense.momentum(s.velocity.base_twist, s.velocity.qdot, PL_g), E_NOERROR);
  const double L0 = PL_g(5);
  Eigen::VectorXd qdot_d;
  ASSERT_EQ(sim.reactionlessRates(s, qdot_d), E_NOERROR);
  EXPECT_NEAR(qdot_d(0), L0 / A_w, 1e-12 * L0 / A_w);
  double worst = 0.0, largest_rate = 0.0;
  ASSERT_EQ(sim.run(s, 10.0, 0.5,
                    [&](const SimulationState& x) {
                      const double expected = L0 * std::exp(-k * (x.t - 0.0));
                      // The links' L_g is the total less the wheel's (world z: the bus turns about z).
                      ASSERT_EQ(dense.compute(x.state), E_NOERROR);
                      Vector6d links;
                      ASSERT_EQ(dense.momentum(x.velocity.base_twist, x.velocity.qdot, links), E_NOERROR);
                      worst = std::max(worst, std::abs(links(5) - expected));
                      EXPECT_NEAR(x.wheel_momentum(2), L0 - expected, 1e-9 * L0) << x.t;
                      if (x.t >= 1.0) largest_rate = std::max(largest_rate, x.velocity.base_twist.rot.Norm());
                    }),
            E_NOERROR);
  EXPECT_LT(worst, 1e-9 * L0);
  // Held still once the servo caught up, but for its lag behind the decaying rates: a first-order
  // servo of bandwidth b lags k / b of them, and the base turns by as much of hold's 0.05 rad/s.
  EXPECT_LT(largest_rate, 1.2 * 0.05 * k / 20.0);
  EXPECT_GT(largest_rate, 0.0);
}

// The same planar system with thrusters instead of wheels: the unloading is an external torque,
// held to the attitude control's limit per base axis like the rest of it; the momentum then
// changes by exactly its impulse.
TEST(PostCaptureLaws, DistributionThroughThrustersStaysWithinTheirTorqueLimit) {
  const ModelPtr model = std::make_shared<const FloatingModel>(loadUrdfString(kPlanar, "planar"));
  SimulationOptions options;
  options.rtol = 1e-12;
  options.atol = 1e-14;
  Simulator sim(model, options);
  BaseControl thrusters;
  thrusters.attitude.on = thrusters.attitude.hold = true;
  thrusters.attitude.torque_limit = Vector3d::Constant(0.01);  // [N m]: k L_g asks ~0.1
  sim.setBaseControl(thrusters);
  distribute(sim, 200.0, 0.3);
  SimulationState s;
  s.state = State(*model);
  s.velocity.qdot = KDL::JntArray(1);
  s.velocity.base_twist.rot = KDL::Vector(0, 0, 0.05);
  double T;
  Vector6d h0, h;
  ASSERT_EQ(sim.energyAndMomentum(s, T, h0), E_NOERROR);
  double largest = 0.0, balance = 0.0;
  ASSERT_EQ(sim.run(s, 5.0, 0.1,
                    [&](const SimulationState& x) {
                      largest = std::max(largest, x.base_wrench.tail<3>().cwiseAbs().maxCoeff());
                      ASSERT_EQ(sim.energyAndMomentum(x, T, h), E_NOERROR);
                      balance = std::max(balance, (h - h0 - x.impulse).norm());
                    }),
            E_NOERROR);
  EXPECT_LE(largest, 0.01 * (1 + 1e-12));
  EXPECT_GT(largest, 0.0099);
  EXPECT_GT(sim.stats().base_saturation_time, 1.0);
  EXPECT_LT(balance, 1e-12);
  EXPECT_GT(std::abs(s.impulse(5)), 0.04);  // 0.01 N m for most of 5 s
}

// 3. `hold`'s attitude law through a wheel on a rigid bus, unsaturated: I_z th'' = -kp th - kd th',
// th(0) = 0, th'(0) = w0: th = (w0 / w_d) exp(-zeta w_n t) sin(w_d t).
TEST(PostCaptureLaws, HoldsAttitudeLawThroughAWheelIsTheDampedOscillator) {
  const ModelPtr model = std::make_shared<const FloatingModel>(loadUrdfString(
      R"(<robot name="bus"><link name="bus"><inertial><origin xyz="0 0 0"/><mass value="100"/>
         <inertia ixx="15" ixy="0" ixz="0" iyy="18" iyz="0" izz="20"/></inertial></link></robot>)", "bus"));
  const double I = 20.0, kp = 8.0, kd = 4.0, w0 = 0.02;
  const double wn = std::sqrt(kp / I), zeta = kd / (2.0 * std::sqrt(kp * I)), wd = wn * std::sqrt(1.0 - zeta * zeta);
  SimulationOptions options;
  options.rtol = 1e-12;
  options.atol = 1e-14;
  Simulator sim(model, options);
  sim.setReactionWheels(threeWheels(10.0, 10.0));
  BaseControl c;
  c.attitude.on = c.attitude.hold = true;
  c.attitude.kp = kp;
  c.attitude.kd = kd;
  sim.setBaseControl(c);
  SimulationState s;
  s.state = State(*model);
  s.velocity.qdot = KDL::JntArray(0);
  s.velocity.base_twist.rot = KDL::Vector(0, 0, w0);
  int checked = 0;
  ASSERT_EQ(sim.run(s, 20.0, 0.5,
                    [&](const SimulationState& x) {
                      const double th = (w0 / wd) * std::exp(-zeta * wn * x.t) * std::sin(wd * x.t);
                      double roll, pitch, yaw;
                      x.state.world_T_base.M.GetRPY(roll, pitch, yaw);
                      EXPECT_NEAR(yaw, th, 1e-10) << x.t;
                      EXPECT_NEAR(x.wheel_momentum(2), I * (w0 - x.velocity.base_twist.rot.z()), 1e-10) << x.t;
                      ++checked;
                    }),
            E_NOERROR);
  EXPECT_EQ(checked, 41);
  EXPECT_EQ(sim.stats().wheel_saturation_time, 0.0);
}

// --- 4. The shipped cases ---------------------------------------------------------------------

std::string slurpText(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string scratchFile(const std::string& name, const std::string& text) {
  const std::filesystem::path path = std::filesystem::path(::testing::TempDir()) / ("laws_" + std::to_string(::getpid())) / name;
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path) << text;
  return path.string();
}

struct Outcome {
  double excursion = 0.0;       ///< the bus's largest turn from the first sample after the capture [rad]
  double rate_ratio = 0.0;      ///< max_j |qdot_j| / velocity limit over the motion after
  double effort_time = 0.0;     ///< how long a joint torque was at its limit
  double momentum_change = 0.0; ///< links and wheels, relative to the momentum's norm
};

Outcome run(const std::string& path) {
  const Scenario sc = loadScenario(path);
  const OperationResult r = runCaptureOperation(sc);
  Outcome o;
  const FloatingModel& m = *r.model;
  Eigen::Quaterniond first;
  bool have = false;
  for (const MotionSample& x : r.samples) {
    const Eigen::Quaterniond a(x.quat(3), x.quat(0), x.quat(1), x.quat(2));
    if (!have) first = a, have = true;
    o.excursion = std::max(o.excursion, first.angularDistance(a));
    for (unsigned int j = 0; j < m.nj(); ++j) {
      const double v = m.jointProperties()[j].velocity;
      if (std::isfinite(v)) o.rate_ratio = std::max(o.rate_ratio, std::abs(x.qd(j)) / v);
    }
  }
  for (const JointRecord& j : r.record.stats.joints) o.effort_time += j.saturation_time;
  o.momentum_change = std::max(r.record.max_linear_momentum_change, r.record.max_angular_momentum_change) /
                      r.samples.front().h.norm();
  return o;
}

/// A shipped scenario's robot, target and law (its own simulation section dropped), the URDFs
/// under `urdf_dir`, with wheels on the robot and this motion: the servos hold (their kd the law's
/// rate gain), the wheels' attitude law, and `law` after the capture.
std::string withLaw(const std::string& scenario, const std::string& urdf_dir, const std::string& law) {
  std::string t = slurpText(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/" + scenario);
  t = std::regex_replace(t, std::regex("\\.\\./urdf"), urdf_dir);
  t = std::regex_replace(t, std::regex("\nsimulation:[\\s\\S]*$"), "\n");
  t = std::regex_replace(t, std::regex("\n  contact:"), "\n  base_actuators: {wheels: {torque_limit: 0.5, capacity: 20}}\n  contact:",
                         std::regex_constants::format_first_only);
  return t + "simulation:\n  duration: 30\n  output_step: 0.1\n  joints:\n"
             "    \"*\": {pd: {kp: 400, kd: 300, set_point: hold}}\n"
             "    \"joint[5-7]\": {pd: {kp: 60, kd: 40, set_point: hold}}\n"
             "  base_control: {attitude: {kp: 20, kd: 200, set_point: hold}}\n"
             "  after_capture: {law: " + law + "}\n";
}

void expectDistributionTurnsTheBusLess(const std::string& tag, const std::string& scenario, const std::string& urdf_dir) {
  SCOPED_TRACE(tag);
  const Outcome hold = run(scratchFile(tag + "_hold.yaml", withLaw(scenario, urdf_dir, "hold")));
  const Outcome md = run(scratchFile(tag + "_md.yaml", withLaw(scenario, urdf_dir, "momentum_distribution")));
  // Measured: 0.050 against 0.0040 rad (tumbling box), 0.0023 against 0.00056 (robot to robot),
  // 0.14 against 0.0058 (heavy arm on a light bus).
  EXPECT_LT(md.excursion, 0.5 * hold.excursion) << "hold " << hold.excursion << " rad, distribution " << md.excursion;
  for (const Outcome* o : {&hold, &md}) {
    EXPECT_LE(o->rate_ratio, 1.0 + 1e-6);
    EXPECT_EQ(o->effort_time, 0.0);
    EXPECT_LT(o->momentum_change, 1e-12);  // relative: issue 39's "done when"
  }
}

const std::string kUrdf = std::string(KDL_SPACE_SOURCE_DIR) + "/urdf";

TEST(PostCaptureLaws, DistributionTurnsTheBusLessAfterTheTumblingBox) {
  expectDistributionTurnsTheBusLess("tumbling_box", "tumbling_box_capture.yaml", kUrdf);
}

TEST(PostCaptureLaws, DistributionTurnsTheBusLessAfterARobotToRobotCapture) {
  expectDistributionTurnsTheBusLess("robot_to_robot", "robot_to_robot_capture.yaml", kUrdf);
}

TEST(PostCaptureLaws, DistributionTurnsTheBusLessWithAHeavyArmOnALightBus) {
  const std::string dir = std::filesystem::path(scratchFile("heavy/space_arm7.urdf", "")).parent_path().string();
  std::ofstream(dir + "/space_arm7.urdf") << heavyArmOnLightBus(slurpText(kUrdf + "/space_arm7.urdf"));
  std::filesystem::copy_file(kUrdf + "/spacedyn_twolink.urdf", dir + "/spacedyn_twolink.urdf",
                             std::filesystem::copy_options::overwrite_existing);
  expectDistributionTurnsTheBusLess("heavy_arm", "tumbling_box_capture.yaml", dir);
}

}  // namespace
}  // namespace kdl_space::test
