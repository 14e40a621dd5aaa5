// Reaction wheels in the base (Simulator::setReactionWheels) against closed forms and a second
// route written here:
//   1. a body spinning about a principal axis, braked by one wheel at its torque limit until the
//      wheel reaches its capacity (piecewise linear: exact for RK4);
//   2. a dual-spin body (stored wheel momentum, no motor torque) tumbling about no principal
//      axis, against Euler's equations I w' = -w x (I w + A h) integrated in the test;
//   3. the 7-joint arm with a four-wheel pyramid holding the bus's attitude while the arm moves:
//      the momentum of the system with its wheels conserved to 1e-12, the energy balanced by the
//      work counted, the wheels saturated and the attitude held.
// No expected value is the library's own output.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "kdl_space/simulation/simulation.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

using ModelPtr = std::shared_ptr<const FloatingModel>;

const char* kBody = R"(<robot name="bus"><link name="bus"><inertial><origin xyz="0 0 0" rpy="0 0 0"/>
    <mass value="100"/><inertia ixx="10" ixy="0" ixz="0" iyy="14" iyz="0" izz="20"/></inertial></link></robot>)";

ModelPtr body() { return std::make_shared<const FloatingModel>(loadUrdfString(kBody, "bus")); }

ReactionWheels wheels(const Eigen::Matrix<double, 3, Eigen::Dynamic>& axes, double torque_limit, double capacity) {
  ReactionWheels w;
  w.axes = axes;
  w.torque_limit = Eigen::VectorXd::Constant(axes.cols(), torque_limit);
  w.capacity = Eigen::VectorXd::Constant(axes.cols(), capacity);
  return w;
}

SimulationState atRest(const FloatingModel& model) {
  SimulationState s;
  s.state = State(model);
  s.velocity.qdot = KDL::JntArray(model.nj());
  return s;
}

// The bus spins at w0 about its z axis (a principal one: the gyroscopic term is zero). A rate
// damper far past the wheel's torque limit u_max brakes it: I_z w' = -u_max while the wheel
// takes up h = u_max t, until h reaches the capacity C at t_C = C / u_max; then the wheel
// stops taking momentum and w stays at w0 - C / I_z. The kink at t_C is resolved by dopri5's step
// control (to ~1e-11 here); everywhere else the motion is linear in t.
TEST(ReactionWheels, TorqueLimitThenCapacityClosedForm) {
  const ModelPtr model = body();
  const double I_z = 20.0, w0 = 0.3, u_max = 0.5, C = 1.4;  // t_C = 2.8 s, between outputs
  SimulationOptions options;
  options.rtol = 1e-12;
  options.atol = 1e-14;
  Simulator sim(model, options);
  sim.setReactionWheels(wheels(Eigen::Vector3d::UnitZ(), u_max, C));
  BaseControl c;
  c.attitude.on = c.attitude.hold = true;
  c.attitude.kd = 1e4;  // asks for 3,000 N m: the wheel gives 0.5
  sim.setBaseControl(c);
  SimulationState s = atRest(*model);
  s.velocity.base_twist.rot = KDL::Vector(0.0, 0.0, w0);
  int checked = 0;
  ASSERT_EQ(sim.run(s, 5.0, 0.25,
                    [&](const SimulationState& x) {
                      const double t = x.t, tc = std::min(t, C / u_max);
                      EXPECT_NEAR(x.velocity.base_twist.rot.z(), w0 - u_max * tc / I_z, 1e-10) << t;
                      ASSERT_EQ(x.wheel_momentum.size(), 1);
                      EXPECT_NEAR(x.wheel_momentum(0), u_max * tc, 1e-9) << t;
                      // The torque the bus feels is the wheel's reaction, then nothing.
                      EXPECT_NEAR(x.base_wrench(5), t < C / u_max ? -u_max : 0.0, 1e-12) << t;
                      EXPECT_NEAR(x.wheel_torque(0), t < C / u_max ? u_max : 0.0, 1e-12) << t;
                      ++checked;
                    }),
            E_NOERROR);
  EXPECT_EQ(checked, 21);
  // Saturated all along: first at the torque limit, then at the capacity; no impulse from outside.
  EXPECT_NEAR(sim.stats().wheel_saturation_time, 5.0, 1e-12);
  EXPECT_EQ(sim.stats().wheel_saturation_first_time, 0.0);
  EXPECT_EQ(s.impulse.norm(), 0.0);
  // The motor's work on the bus is the bus's energy change: 1/2 I_z (w^2 - w0^2).
  const double w1 = w0 - C / I_z;
  EXPECT_NEAR(s.work.base_control, 0.5 * I_z * (w1 * w1 - w0 * w0), 1e-9);
}

// Euler's equations of the bus with a stored wheel momentum h_b (body axes, constant: no motor
// torque), I w' = -w x (I w + h_b), integrated here by RK4 at a fine step; the simulator's
// world-frame twist rotated into the body. A free tumble, so the wheel's reaction is only its
// gyroscopic part: the bus's kinetic energy is constant and L + R h_b is invariant.
TEST(ReactionWheels, DualSpinBodyMatchesEulersEquations) {
  const ModelPtr model = body();
  const Eigen::Matrix3d I = Eigen::Vector3d(10.0, 14.0, 20.0).asDiagonal();
  Eigen::Matrix<double, 3, 2> axes;
  axes << 1.0, 0.0, 0.0, 0.6, 0.0, 0.8;  // wheel 2 between y and z
  const Eigen::Vector2d h(0.8, -1.1);
  const Eigen::Vector3d h_b = axes * h;
  SimulationOptions options;
  options.rtol = 1e-12;
  options.atol = 1e-14;
  Simulator sim(model, options);
  sim.setReactionWheels(wheels(axes, 1.0, 10.0));
  SimulationState s = atRest(*model);
  s.state.world_T_base.M = KDL::Rotation::RPY(0.2, -0.4, 0.9);
  const Eigen::Vector3d w_body0(0.15, -0.25, 0.1);
  s.velocity.base_twist.rot = s.state.world_T_base.M * KDL::Vector(w_body0(0), w_body0(1), w_body0(2));
  s.wheel_momentum = h;
  double T0 = 0.0, T = 0.0;
  Vector6d h0, h1;
  ASSERT_EQ(sim.energyAndMomentum(s, T0, h0), E_NOERROR);
  const double T_expected = 0.5 * w_body0.dot(I * w_body0);
  EXPECT_NEAR(T0, T_expected, 1e-15);  // the wheels' spin energy is not the bus's
  const double t_end = 10.0;
  ASSERT_EQ(sim.run(s, t_end, t_end, nullptr), E_NOERROR);
  ASSERT_EQ(sim.energyAndMomentum(s, T, h1), E_NOERROR);
  EXPECT_LT((h1 - h0).norm(), 1e-12 * h0.norm());
  EXPECT_NEAR(T, T0, 1e-10 * T0);
  EXPECT_TRUE(near(s.wheel_momentum, Eigen::VectorXd(h), 0.0, 0.0, "wheel momentum unchanged"));
  // The second route.
  const auto f = [&](const Eigen::Vector3d& w) -> Eigen::Vector3d {
    return I.inverse() * (-w.cross(I * w + h_b));
  };
  Eigen::Vector3d w = w_body0;
  const int steps = 100000;
  const double dt = t_end / steps;
  for (int k = 0; k < steps; ++k) {
    const Eigen::Vector3d k1 = f(w), k2 = f(w + 0.5 * dt * k1), k3 = f(w + 0.5 * dt * k2), k4 = f(w + dt * k3);
    w += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  const KDL::Vector w_world = s.velocity.base_twist.rot;
  const KDL::Vector w_sim = s.state.world_T_base.M.Inverse() * w_world;
  EXPECT_TRUE(near(Eigen::Vector3d(w_sim.x(), w_sim.y(), w_sim.z()), w, 1e-9, 0.0, "body rate at 10 s"));
  // Without the wheels' momentum the body would tumble otherwise: the check sees the term.
  Eigen::Vector3d w_free = w_body0;
  const auto g = [&](const Eigen::Vector3d& v) -> Eigen::Vector3d { return I.inverse() * (-v.cross(I * v)); };
  for (int k = 0; k < steps; ++k) {
    const Eigen::Vector3d k1 = g(w_free), k2 = g(w_free + 0.5 * dt * k1), k3 = g(w_free + 0.5 * dt * k2),
                          k4 = g(w_free + dt * k3);
    w_free += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  EXPECT_GT((w_free - w).norm(), 1e-2);
}

// The 7-joint arm swings two joints while four wheels in a pyramid (the usual cluster: any three
// span the space) hold the bus's attitude. The wheels take up the arm's reaction: the momentum
// of the links with the wheels is kept to 1e-12 of its size (no external impulse at all), the
// bus's kinetic energy plus nothing else changes by the work counted (controller, friction, the
// wheels' motors), and with a torque limit below the attitude law's demand they saturate.
TEST(ReactionWheels, ArmWithAPyramidKeepsTheMomentumAndTheAttitude) {
  const ModelPtr model = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/space_arm7.urdf"));
  const double b = std::cos(0.5 * std::acos(-1.0 / 3.0));  // the pyramid's elevation
  Eigen::Matrix<double, 3, 4> axes;
  const double c = std::sqrt(1.0 - b * b);
  axes << c, -c, 0.0, 0.0, 0.0, 0.0, c, -c, b, b, b, b;
  for (const double limit : {100.0, 0.05}) {
    SCOPED_TRACE("wheel torque limit " + std::to_string(limit));
    const double capacity = limit < 1.0 ? 20.0 : 500.0;
    SimulationOptions options;
    options.rtol = 1e-10;
    options.atol = 1e-12;
    Simulator sim(model, options);
    sim.setReactionWheels(wheels(axes, limit, capacity));
    BaseControl control;
    control.attitude.on = control.attitude.hold = true;
    control.attitude.kp = 400.0;
    control.attitude.kd = 1500.0;
    sim.setBaseControl(control);
    JointControl pd;
    pd.mode = JointControl::Mode::PD;
    pd.kp = 200.0;
    pd.kd = 150.0;
    pd.set_point = 0.8;
    sim.setJointControl(0, pd);
    pd.set_point = -0.5;
    sim.setJointControl(1, pd);
    SimulationState s = atRest(*model);
    s.state.world_T_base.M = KDL::Rotation::RPY(0.1, 0.2, -0.3);
    s.velocity.base_twist.rot = KDL::Vector(0.01, -0.02, 0.015);  // a slow tumble to take out too
    s.velocity.base_twist.vel = KDL::Vector(0.02, 0.0, -0.01);
    double T0 = 0.0;
    Vector6d h0;
    ASSERT_EQ(sim.energyAndMomentum(s, T0, h0), E_NOERROR);
    double worst_h = 0.0, worst_T = 0.0, largest_wheel = 0.0;
    const KDL::Rotation start = s.state.world_T_base.M;
    ASSERT_EQ(sim.run(s, 20.0, 0.1,
                      [&](const SimulationState& x) {
                        double T = 0.0;
                        Vector6d h;
                        ASSERT_EQ(sim.energyAndMomentum(x, T, h), E_NOERROR);
                        worst_h = std::max(worst_h, (h - h0).norm());
                        worst_T = std::max(worst_T, std::abs(T - T0 - x.work.total()));
                        largest_wheel = std::max(largest_wheel, x.wheel_momentum.cwiseAbs().maxCoeff());
                        EXPECT_EQ(x.impulse.norm(), 0.0);
                      }),
              E_NOERROR);
    EXPECT_LT(worst_h, 1e-12 * std::max(1.0, h0.norm()));
    EXPECT_LT(worst_T, 1e-9);
    EXPECT_GT(largest_wheel, 0.5);  // the wheels did take momentum
    const double attitude_error = (s.state.world_T_base.M * start.Inverse()).GetRot().Norm();
    if (limit < 1.0) {  // too weak: at their limit, and the bus turns away
      EXPECT_GT(sim.stats().wheel_saturation_time, 1.0);
      EXPECT_GT(attitude_error, 0.1);
    } else {
      EXPECT_EQ(sim.stats().wheel_saturation_time, 0.0);
      EXPECT_TRUE(std::isnan(sim.stats().wheel_saturation_first_time));
      EXPECT_LT(attitude_error, 5e-3);  // (the PD settles in ~30 s on this bus)
    }
  }
}

TEST(ReactionWheels, BadWheelsAreRefused) {
  const ModelPtr model = body();
  Simulator sim(model);
  ReactionWheels w = wheels(Eigen::Vector3d::UnitZ(), 1.0, 1.0);
  w.axes.setZero();
  EXPECT_THROW(sim.setReactionWheels(w), ModelError);
  w = wheels(Eigen::Vector3d::UnitZ(), 0.0, 1.0);
  EXPECT_THROW(sim.setReactionWheels(w), ModelError);
  w = wheels(Eigen::Vector3d::UnitZ(), 1.0, std::nan(""));
  EXPECT_THROW(sim.setReactionWheels(w), ModelError);
  w = wheels(Eigen::Vector3d::UnitZ(), 1.0, 1.0);
  w.capacity.resize(2);
  w.capacity << 1.0, 1.0;
  EXPECT_THROW(sim.setReactionWheels(w), ModelError);
  SimulationOptions grounded;
  grounded.grounded = true;
  Simulator held(model, grounded);
  EXPECT_THROW(held.setReactionWheels(wheels(Eigen::Vector3d::UnitZ(), 1.0, 1.0)), ModelError);
  // A state with the wrong number of wheel momenta is refused by run(), not read past.
  sim.setReactionWheels(wheels(Eigen::Vector3d::UnitZ(), 1.0, 1.0));
  SimulationState s = atRest(*model);
  s.wheel_momentum = Eigen::VectorXd::Zero(3);
  EXPECT_EQ(sim.run(s, 1.0, 0.5, nullptr), E_SIZE_MISMATCH);
}

}  // namespace
}  // namespace kdl_space::test
