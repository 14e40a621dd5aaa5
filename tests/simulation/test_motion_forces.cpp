// The simulator's motion features against independent routes and closed forms, what drives it:
//   5. a single rigid body under a scheduled constant force through its CoM (closed form);
//   6. friction: dissipation never positive in a free motion; a grounded link's viscous decay
//      and Coulomb deceleration in closed form;
//   7. armature against a rotor body on a mimic joint (exact on a grounded base, O(1/N) free);
//   8. the Rosenbrock method on a stiff servo against tight dopri5, and the stiffness estimate
//      against the apparent inertia of the dense mass matrix;
//   9. effort limits: the torque exactly at the limit while the PD asks for more.
// No expected value is the library's own output.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/simulation/simulation.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

using ModelPtr = std::shared_ptr<const FloatingModel>;

ModelPtr load(const std::string& path) { return std::make_shared<const FloatingModel>(loadUrdfFile(path)); }
/// A number in full precision (std::to_string keeps 6 decimals only).
std::string num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

ModelPtr fromString(const std::string& xml) { return std::make_shared<const FloatingModel>(loadUrdfString(xml, "test")); }

SimulationState atRest(const FloatingModel& model) {
  SimulationState s;
  s.state = State(model);
  s.velocity.qdot = KDL::JntArray(model.nj());
  return s;
}

SimulationOptions tight() {
  SimulationOptions o;
  o.rtol = 1e-12;
  o.atol = 1e-14;
  return o;
}

// ---- 5. A scheduled wrench on a single body -------------------------------------------------------

TEST(MotionFeatures, SingleBodyUnderConstantForceClosedForm) {
  // A constant world force F through the CoM on [t0, t1): the CoM's velocity changes by
  // F (t1 - t0) / m, its path is the closed form below, the body's rotation is torque-free.
  // t0 = 0.43 and t1 = 1.7 give steps of unequal length before the two switches (a step that
  // saw the force at its end while ending on a switch would be caught).
  const double m = 4.0;
  const Vector3d c(0.1, -0.2, 0.05);
  const std::string urdf = R"(<robot name="one"><link name="body"><inertial><origin xyz="0.1 -0.2 0.05" rpy="0 0 0"/>
    <mass value="4"/><inertia ixx="0.5" ixy="0.02" ixz="0" iyy="0.7" iyz="-0.01" izz="0.9"/></inertial></link></robot>)";
  const ModelPtr model = std::make_shared<const FloatingModel>(loadUrdfString(urdf, "one"));
  ASSERT_EQ(model->nj(), 0u);
  ASSERT_EQ(model->totalMass(), m);
  const Vector3d F(2.0, -1.0, 0.5);
  const double t0 = 0.43, t1 = 1.7;
  for (int k = 0; k < 2; ++k) {
    SCOPED_TRACE(k == 0 ? "dopri5" : "RK4");
    SimulationOptions options;
    options.rtol = 1e-12;
    options.atol = 1e-14;
    if (k == 1) {
      options.integrator = Integrator::RK4;
      options.step = 0.1;
    }
    Simulator sim(model, options);
    ScheduledWrench w;
    w.body = 0;
    w.point = c;  // through the CoM
    w.wrench << F, Vector3d::Zero();
    w.start = t0;
    w.end = t1;
    sim.addWrench(w);
    SimulationState s;
    s.state = State(*model);
    s.velocity.qdot = KDL::JntArray(0);
    s.state.world_T_base = basePose(KDL::Vector(1.0, 0.5, -0.2), 0.3, 0.2, -0.4);
    const Vector3d omega(0.3, -0.2, 0.5), v0(0.05, 0.02, -0.01);
    s.velocity.base_twist = KDL::Twist(toKDL(v0), toKDL(omega));
    auto com = [&](const SimulationState& x) {
      return Vector3d(toEigen(x.state.world_T_base.p) + toEigen(x.state.world_T_base.M) * c);
    };
    auto com_velocity = [&](const SimulationState& x) {
      const Vector3d r = toEigen(x.state.world_T_base.M) * c;
      return Vector3d(toEigen(x.velocity.base_twist.vel) + toEigen(x.velocity.base_twist.rot).cross(r));
    };
    const Vector3d p_g0 = com(s), v_g0 = com_velocity(s);
    // The momentum is integrated exactly by any Runge-Kutta step when the force is constant over
    // each step (1e-12: round-off); the CoM position goes through the base origin and the
    // orientation, whose integration error is ~1e-13 for dopri5 at 1e-12 and ~1e-8 for RK4 at 0.1 s.
    const double tol_p = k == 0 ? 1e-10 : 1e-7;
    int outputs = 0;
    ASSERT_EQ(sim.run(s, 3.0, 0.25,
                      [&](const SimulationState& x) {
                        ++outputs;
                        const double t = x.t;
                        const double active = std::clamp(t, t0, t1) - t0;  // time under the force
                        const double after = std::max(0.0, t - t1);
                        const Vector3d v_expected = v_g0 + F / m * active;
                        const Vector3d p_expected = p_g0 + v_g0 * t + F / m * (0.5 * active * active + active * after);
                        SCOPED_TRACE("t = " + std::to_string(t));
                        EXPECT_TRUE(near(com_velocity(x), v_expected, 0.0, 1e-12, "CoM velocity"));
                        EXPECT_TRUE(near(com(x), p_expected, 0.0, tol_p, "CoM position"));
                        EXPECT_TRUE(near(x.impulse.head<3>(), F * active, 0.0, 1e-12, "linear impulse"));
                        // Work of the force = change of the CoM's kinetic energy (the rotation's
                        // energy is unchanged: no moment about the CoM).
                        EXPECT_NEAR(x.work.wrenches, 0.5 * m * (v_expected.squaredNorm() - v_g0.squaredNorm()),
                                    k == 0 ? 1e-10 : 1e-7);
                      }),
              E_NOERROR);
    EXPECT_EQ(outputs, 13);
    EXPECT_TRUE(near(com_velocity(s) - v_g0, F * (t1 - t0) / m, 0.0, 1e-12, "CoM velocity change"));
  }
}

// ---- 6. Friction ----------------------------------------------------------------------------------

TEST(MotionFeatures, FrictionNeverGivesEnergy) {
  const FloatingModel plain = loadUrdfFile(urdfDir() + "/space_arm7.urdf");
  std::map<std::string, JointProperties> props;
  for (unsigned int j = 0; j < plain.nj(); ++j) {
    JointProperties p = plain.jointProperties()[j];
    p.damping = 0.5 + 0.1 * j;
    p.friction = 0.8;
    props[plain.jointNames()[j]] = p;
  }
  const ModelPtr model = std::make_shared<const FloatingModel>(plain.withJointProperties(props));
  SimulationOptions options = tight();
  options.friction_velocity = 1e-2;
  Simulator sim(model, options);
  SimulationState s = atRest(*model);
  for (unsigned int j = 0; j < model->nj(); ++j) {
    s.state.q(j) = 0.4 * std::sin(j + 1.0);
    s.velocity.qdot(j) = 0.3 * std::cos(2.0 * j + 0.3);
  }
  s.velocity.base_twist = KDL::Twist(KDL::Vector(0.01, 0.02, 0.0), KDL::Vector(0.0, 0.01, -0.02));
  double T0;
  Vector6d h0;
  ASSERT_EQ(sim.energyAndMomentum(s, T0, h0), E_NOERROR);
  double previous = 0.0;
  ASSERT_EQ(sim.run(s, 5.0, 0.1,
                    [&](const SimulationState& x) {
                      SCOPED_TRACE("t = " + std::to_string(x.t));
                      EXPECT_LE(x.work.friction, 0.0);
                      EXPECT_LE(x.work.friction, previous + 1e-14) << "friction gave energy back";
                      previous = x.work.friction;
                      double T;
                      Vector6d h;
                      ASSERT_EQ(sim.energyAndMomentum(x, T, h), E_NOERROR);
                      EXPECT_NEAR(T - T0, x.work.friction, 1e-10 * T0);
                      EXPECT_TRUE(near(h, h0, 0.0, 1e-12 * (h0.norm() + 1.0), "momentum"));
                      // The joint torque is the friction law at the state's rates (no control).
                      for (unsigned int j = 0; j < model->nj(); ++j) {
                        const JointProperties& p = model->jointProperties()[j];
                        // v_s: at least the option's, larger on a light joint (friction_rate)
                        const double v_s = sim.frictionVelocities()[j];
                        EXPECT_GE(v_s, 1e-2);
                        EXPECT_NEAR(x.tau(j), frictionTorque(x.velocity.qdot(j), p.damping, p.friction, v_s), 1e-14);
                      }
                    }),
            E_NOERROR);
  EXPECT_LT(previous, -0.1 * T0) << "friction must have taken a good part of the energy";

  // Each joint's v_s = max(friction_velocity, friction / (m_j friction_rate)), m_j = 1 / (M^-1)_jj
  // at the start, from the dense mass matrix [[M_a, A_m], [A_m^T, H]] (about the CoM).
  SimulationState start = atRest(*model);
  for (unsigned int j = 0; j < model->nj(); ++j) start.state.q(j) = 0.4 * std::sin(j + 1.0);
  FreeFloatingSolver dense(model);
  ASSERT_EQ(dense.compute(start.state), E_NOERROR);
  const unsigned int n = model->nj();
  Eigen::MatrixXd M(6 + n, 6 + n);
  M << dense.M_a(), dense.A_m(), dense.A_m().transpose(), dense.H().data;
  const Eigen::MatrixXd M_inv = M.inverse();
  for (unsigned int j = 0; j < n; ++j) {
    const double m_j = 1.0 / M_inv(6 + j, 6 + j);
    const double expected = std::max(options.friction_velocity, 0.8 / (m_j * options.friction_rate));
    EXPECT_NEAR(sim.frictionVelocities()[j], expected, 1e-9 * expected) << model->jointNames()[j];
  }
}

/// A grounded base and one link on a revolute joint about z: mass 2 at (0.3, 0.1, 0) from the
/// axis, izz 0.05 about its CoM: I_axis = 0.05 + 2 (0.3^2 + 0.1^2) = 0.25.
std::string oneLink(double damping, double friction) {
  return R"(<robot name="pendulum"><link name="base"><inertial><origin xyz="0 0 0"/><mass value="10"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
    <joint name="j" type="continuous"><parent link="base"/><child link="arm"/><origin xyz="0.2 -0.1 0.3" rpy="0 0 0"/>
    <axis xyz="0 0 1"/><dynamics damping=")" +
         num(damping) + R"(" friction=")" + num(friction) + R"("/></joint>
    <link name="arm"><inertial><origin xyz="0.3 0.1 0"/><mass value="2"/>
    <inertia ixx="0.04" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.05"/></inertial></link></robot>)";
}
constexpr double kAxisInertia = 0.05 + 2.0 * (0.3 * 0.3 + 0.1 * 0.1);

TEST(MotionFeatures, ViscousDampingDecaysExponentially) {
  const double d = 0.1, qd0 = 1.5;
  const ModelPtr model = fromString(oneLink(d, 0.0));
  ASSERT_EQ(model->nj(), 1u);
  ASSERT_EQ(model->jointProperties()[0].damping, d);
  SimulationOptions options = tight();
  options.grounded = true;
  Simulator sim(model, options);
  SimulationState s = atRest(*model);
  s.velocity.qdot(0) = qd0;
  const double rate = d / kAxisInertia;
  ASSERT_EQ(sim.run(s, 5.0, 0.5,
                    [&](const SimulationState& x) {
                      SCOPED_TRACE("t = " + std::to_string(x.t));
                      // qdot = qdot0 exp(-d t / I), q = qdot0 I / d (1 - exp(-d t / I)).
                      EXPECT_NEAR(x.velocity.qdot(0), qd0 * std::exp(-rate * x.t), 1e-9);
                      EXPECT_NEAR(x.state.q(0), qd0 / rate * (1.0 - std::exp(-rate * x.t)), 1e-9);
                    }),
            E_NOERROR);
  EXPECT_LT(s.velocity.qdot(0), 0.2 * qd0);
}

TEST(MotionFeatures, CoulombFrictionDeceleratesLinearly) {
  // tau = -f tanh(qdot / v_s): while qdot >= 0.2 = 2000 v_s, 1 - tanh <= 2 exp(-4000), nothing in
  // double precision, so the deceleration is f / I exactly there; the motion is followed until
  // qdot = 0.2 (t = 2.25 s), before the regularised zone near rest.
  const double f = 0.2, qd0 = 2.0, v_s = 1e-4;
  const ModelPtr model = fromString(oneLink(0.0, f));
  SimulationOptions options = tight();
  options.grounded = true;
  options.friction_velocity = v_s;
  Simulator sim(model, options);
  SimulationState s = atRest(*model);
  s.velocity.qdot(0) = qd0;
  const double a = f / kAxisInertia;  // 0.8 rad/s^2
  int outputs = 0;
  ASSERT_EQ(sim.run(s, 2.25, 0.25,
                    [&](const SimulationState& x) {
                      ++outputs;
                      SCOPED_TRACE("t = " + std::to_string(x.t));
                      EXPECT_NEAR(x.velocity.qdot(0), qd0 - a * x.t, 1e-9);
                      EXPECT_NEAR(x.state.q(0), qd0 * x.t - 0.5 * a * x.t * x.t, 1e-9);
                      EXPECT_NEAR(x.work.friction, -f * (qd0 * x.t - 0.5 * a * x.t * x.t), 1e-9);
                    }),
            E_NOERROR);
  EXPECT_EQ(outputs, 10);
}

// ---- 7. Armature against a rotor body ---------------------------------------------------------------

/// Two links (joints about z and y) on a base; with `rotor`, a disk of axial inertia I_a / N^2
/// (transverse I_a / (2 N^2)) and 1 g on the base, on the axis of joint 1, turning N times as
/// fast (a mimic joint); without it the base carries the same 1 g at that point.
std::string rotorArm(double N, bool rotor) {
  const double I_a = 0.2, I_r = I_a / (N * N);
  std::string xml = R"(<robot name="geared"><link name="base"><inertial><origin xyz="0.05 0 0"/><mass value="10"/>
    <inertia ixx="2" ixy="0.1" ixz="0" iyy="3" iyz="0" izz="4"/></inertial></link>
    <joint name="joint1" type="revolute"><parent link="base"/><child link="link1"/><origin xyz="0.5 0 0" rpy="0 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="0" velocity="0"/></joint>
    <link name="link1"><inertial><origin xyz="0.4 0 0.02"/><mass value="1.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.05" iyz="0" izz="0.05"/></inertial></link>
    <joint name="joint2" type="revolute"><parent link="link1"/><child link="link2"/><origin xyz="0.8 0 0" rpy="0 0 0"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="0" velocity="0"/></joint>
    <link name="link2"><inertial><origin xyz="0.3 0 0.05"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.04" iyz="0" izz="0.04"/></inertial></link>)";
  if (rotor) {
    xml += R"(<joint name="rotor_joint" type="continuous"><parent link="base"/><child link="rotor"/>
      <origin xyz="0.5 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/><mimic joint="joint1" multiplier=")" +
           num(N) + R"("/></joint>
      <link name="rotor"><inertial><origin xyz="0 0 0"/><mass value="0.001"/><inertia ixx=")" +
           num(I_r / 2) + R"(" ixy="0" ixz="0" iyy=")" + num(I_r / 2) + R"(" iyz="0" izz=")" +
           num(I_r) + R"("/></inertial></link>)";
  }
  return xml + "</robot>";
}

ModelPtr armatureModel() {
  const FloatingModel plain = loadUrdfString(rotorArm(1.0, false), "armature");
  const FloatingModel with_mass = plain.withPayload("base", KDL::RigidBodyInertia(0.001, KDL::Vector(0.5, 0, 0)));
  std::vector<double> armature(plain.nj(), 0.0);
  armature[with_mass.jointIndex("joint1")] = 0.2;
  return std::make_shared<const FloatingModel>(with_mass.withArmature(armature));
}

/// The largest difference between the two models' states at the outputs of 2 s of the same PD motion.
double motionDifference(const ModelPtr& a, const ModelPtr& b, bool grounded) {
  double worst = 0.0;
  std::vector<SimulationState> out[2];
  const ModelPtr models[2] = {a, b};
  for (int k = 0; k < 2; ++k) {
    const FloatingModel& m = *models[k];
    SimulationOptions options = tight();
    options.grounded = grounded;
    if (grounded) options.gravity = Vector3d(0.0, 0.0, -9.81);
    Simulator sim(models[k], options);
    sim.setJointControl(m.jointIndex("joint1"), JointControl{JointControl::Mode::PD, 20.0, 3.0, 0.8});
    sim.setJointControl(m.jointIndex("joint2"), JointControl{JointControl::Mode::PD, 10.0, 1.0, -0.5});
    SimulationState s = atRest(m);
    s.state.world_T_base = basePose(KDL::Vector(0.1, 0.2, 0.3), 0.1, -0.2, 0.3);
    s.state.q(m.jointIndex("joint2")) = 0.3;
    s.velocity.qdot(m.jointIndex("joint1")) = 0.5;
    if (!grounded) s.velocity.base_twist = KDL::Twist(KDL::Vector(0.01, 0, 0), KDL::Vector(0.05, -0.03, 0.02));
    EXPECT_EQ(sim.run(s, 2.0, 0.25, [&](const SimulationState& x) { out[k].push_back(x); }), E_NOERROR);
  }
  EXPECT_EQ(out[0].size(), out[1].size());
  for (std::size_t i = 0; i < std::min(out[0].size(), out[1].size()); ++i) {
    const SimulationState &x = out[0][i], &y = out[1][i];
    for (const char* name : {"joint1", "joint2"}) {
      const int ja = a->jointIndex(name), jb = b->jointIndex(name);
      worst = std::max({worst, std::abs(x.state.q(ja) - y.state.q(jb)), std::abs(x.velocity.qdot(ja) - y.velocity.qdot(jb))});
    }
    worst = std::max({worst, (toEigen(x.state.world_T_base.p) - toEigen(y.state.world_T_base.p)).norm(),
                      (toEigen(x.state.world_T_base.M) - toEigen(y.state.world_T_base.M)).norm(),
                      (toEigen(x.velocity.base_twist) - toEigen(y.velocity.base_twist)).norm()});
  }
  return worst;
}

TEST(MotionFeatures, ArmatureEqualsRotorOnAGroundedBase) {
  // On a fixed base the rotor's axis is fixed in space: its kinetic energy is exactly
  // 1/2 (I_a / N^2) (N qdot)^2 = 1/2 I_a qdot^2, its CoM does not move: the armature is exact.
  const ModelPtr armature = armatureModel();
  const ModelPtr rotor = fromString(rotorArm(50.0, true));
  ASSERT_EQ(rotor->nj(), 2u);
  ASSERT_EQ(rotor->mimic().size(), 1u);
  const double d = motionDifference(armature, rotor, true);
  std::printf("[ info     ] grounded armature vs rotor (N = 50): %.2e\n", d);
  // Both integrated to rtol 1e-12: the difference is the integration error.
  EXPECT_LE(d, 1e-9);
}

TEST(MotionFeatures, ArmatureApproachesRotorLikeOneOverN) {
  // Free-floating, the rotor also turns with the base: its energy has the cross term
  // (I_a / N) qdot (w_base . axis), which the armature model neglects: the difference is O(1/N).
  const ModelPtr armature = armatureModel();
  const double d100 = motionDifference(armature, fromString(rotorArm(100.0, true)), false);
  const double d1000 = motionDifference(armature, fromString(rotorArm(1000.0, true)), false);
  std::printf("[ info     ] free-floating armature vs rotor: N = 100 %.3e, N = 1000 %.3e, ratio %.3f\n", d100, d1000,
              d100 / d1000);
  EXPECT_GT(d1000, 1e-8) << "the gyroscopic term must be visible above the integration error";
  EXPECT_NEAR(d100 / d1000, 10.0, 1.0);
}

// ---- 8. Rosenbrock on a stiff servo -----------------------------------------------------------------

TEST(MotionFeatures, RosenbrockOnAStiffWristAgreesWithTightDopri5) {
  const ModelPtr model = load(urdfDir() + "/space_arm7.urdf");
  const unsigned int n = model->nj(), wrist = n - 1;
  SimulationState s0 = atRest(*model);
  for (unsigned int j = 0; j < n; ++j) s0.state.q(j) = 0.3 * std::sin(0.7 * j + 0.2);
  // Apparent inertia of the wrist, 1 / (M^-1)_jj with M the dense (6 + n)^2 free-floating mass
  // matrix [[M_a, A_m], [A_m^T, H]] about the CoM.
  FreeFloatingSolver dense(model);
  ASSERT_EQ(dense.compute(s0.state), E_NOERROR);
  Eigen::MatrixXd M(6 + n, 6 + n);
  M << dense.M_a(), dense.A_m(), dense.A_m().transpose(), dense.H().data;
  const Eigen::MatrixXd Minv = M.inverse();
  const double m_wrist = 1.0 / Minv(6 + wrist, 6 + wrist);
  // Gains on the wrist: kd / m = 1e5 1/s, kp / m = 1e9 1/s^2 (overdamped: closed-loop rates
  // 8.9e4 and 1.1e4 1/s; not critically damped, where the rate is ill-conditioned); mild servos
  // elsewhere, whose motion limits the Rosenbrock steps at rtol 1e-7 to ~5e-3 s, while dopri5 is
  // held below its stability bound 3.3 / 8.9e4 s.
  std::vector<JointControl> controls(n);
  for (unsigned int j = 0; j < n; ++j) controls[j] = JointControl{JointControl::Mode::PD, 30.0, 10.0, 0.2 - 0.1 * j};
  controls[wrist] = JointControl{JointControl::Mode::PD, 1e9 * m_wrist, 1e5 * m_wrist, 0.5};
  double expected_rate = 0.0;
  int expected_joint = -1;
  for (unsigned int j = 0; j < n; ++j) {
    const double mj = 1.0 / Minv(6 + j, 6 + j);
    // The joint alone as a servo: m s^2 + kd s + kp = 0; its rate is the largest |s| (the
    // spectral radius of [[0, 1], [-kp/m, -kd/m]]).
    Eigen::Matrix2d A;
    A << 0.0, 1.0, -controls[j].kp / mj, -controls[j].kd / mj;
    const double r = A.eigenvalues().cwiseAbs().maxCoeff();
    if (r > expected_rate) {
      expected_rate = r;
      expected_joint = static_cast<int>(j);
    }
  }
  ASSERT_EQ(expected_joint, static_cast<int>(wrist));
  ASSERT_GE(expected_rate, 1e4);

  SimulationState result[2];
  long steps[2];
  for (int k = 0; k < 2; ++k) {
    SimulationOptions options;
    options.joint_friction = false;
    options.effort_limits = false;
    if (k == 0) {
      options.integrator = Integrator::Rosenbrock;
      options.rtol = 1e-7;
      options.atol = 1e-9;
    } else {
      options.rtol = 1e-11;
      options.atol = 1e-13;
      options.max_steps = 10000000;
    }
    Simulator sim(model, options);
    for (unsigned int j = 0; j < n; ++j) sim.setJointControl(j, controls[j]);
    if (k == 0) {
      Stiffness st;
      ASSERT_EQ(sim.stiffness(s0, st), E_NOERROR);
      EXPECT_EQ(st.fastest_joint, static_cast<int>(wrist));
      EXPECT_NEAR(st.fastest_rate, expected_rate, 1e-9 * expected_rate);
      EXPECT_NEAR(st.explicit_step, 2.8 / expected_rate, 1e-9 * st.explicit_step);
      EXPECT_LT(st.explicit_step, 2.8 / 1e4);
      EXPECT_LT(st.explicit_step, 2.8 * m_wrist / controls[wrist].kd * 2.0) << "the damping's rate kd / m bounds it";
    }
    result[k] = s0;
    ASSERT_EQ(sim.run(result[k], 0.5, 0.5, nullptr), E_NOERROR);
    steps[k] = sim.stats().accepted_steps + sim.stats().rejected_steps;
    std::printf("[ info     ] %s: %ld accepted, %ld rejected, steps in [%.2e, %.2e]\n", k == 0 ? "Rosenbrock" : "dopri5",
                sim.stats().accepted_steps, sim.stats().rejected_steps, sim.stats().min_step, sim.stats().max_step);
  }
  std::printf("[ info     ] stiff wrist (rate %.3g 1/s), 0.5 s: Rosenbrock %ld steps, dopri5 %ld steps\n", expected_rate,
              steps[0], steps[1]);
  const SimulationState &a = result[0], &b = result[1];
  // Rosenbrock at rtol 1e-7 over a damped motion: its global error ~1e-7 to 1e-6.
  EXPECT_TRUE(near(a.state.q.data, b.state.q.data, 0.0, 1e-6, "q"));
  EXPECT_TRUE(near(a.velocity.qdot.data, b.velocity.qdot.data, 0.0, 1e-6, "qdot"));
  EXPECT_TRUE(near(toEigen(a.state.world_T_base.p), toEigen(b.state.world_T_base.p), 0.0, 1e-6, "base position"));
  EXPECT_TRUE(near(toEigen(a.state.world_T_base.M), toEigen(b.state.world_T_base.M), 0.0, 1e-6, "base rotation"));
  EXPECT_NEAR(a.state.q(wrist), 0.5, 1e-3) << "the stiff servo has settled";
  EXPECT_LT(steps[0] * 5, steps[1]) << "Rosenbrock should need far fewer steps";
}

// ---- 9. Effort saturation ----------------------------------------------------------------------------

TEST(MotionFeatures, EffortLimitSaturatesThePd) {
  const ModelPtr model = load(urdfDir() + "/spacedyn_twolink.urdf");
  const double effort = model->jointProperties()[0].effort;
  ASSERT_EQ(effort, 100.0);
  const JointControl pd{JointControl::Mode::PD, 1e4, 10.0, 1.0};
  for (bool limited : {true, false}) {
    SCOPED_TRACE(limited ? "limited" : "not limited");
    SimulationOptions options = tight();
    options.effort_limits = limited;
    Simulator sim(model, options);
    sim.setJointControl(0, pd);
    SimulationState s = atRest(*model);
    int saturated_outputs = 0;
    double largest = 0.0;
    ASSERT_EQ(sim.run(s, 1.0, 0.05,
                      [&](const SimulationState& x) {
                        const double raw = pd.kp * (pd.set_point - x.state.q(0)) - pd.kd * x.velocity.qdot(0);
                        if (limited && std::abs(raw) > effort) {
                          ++saturated_outputs;
                          EXPECT_EQ(x.tau(0), std::copysign(effort, raw)) << "t = " << x.t;
                        } else {
                          EXPECT_NEAR(x.tau(0), raw, 1e-12 * std::abs(raw) + 1e-12) << "t = " << x.t;
                        }
                        EXPECT_EQ(x.tau(1), 0.0);
                        largest = std::max(largest, std::abs(x.tau(0)));
                      }),
              E_NOERROR);
    if (limited) EXPECT_EQ(largest, effort); else EXPECT_GT(largest, 10.0 * effort);
    if (limited) {
      EXPECT_GT(saturated_outputs, 2);
      EXPECT_GT(sim.stats().joints[0].saturation_time, 0.0);
      EXPECT_EQ(sim.stats().joints[0].saturation_first_time, 0.0);
    } else {
      EXPECT_EQ(sim.stats().joints[0].saturation_time, 0.0);
      EXPECT_TRUE(std::isnan(sim.stats().joints[0].saturation_first_time));
    }
  }
}

// `hold` set points of the base control are the base's pose at the start of the run (not the
// identity): the arm swings, the base is pulled back to where it started.
TEST(MotionFeatures, BaseControlHoldsTheStartPose) {
  const ModelPtr model = load(urdfDir() + "/space_arm7.urdf");
  SimulationOptions options;
  options.rtol = 1e-9;
  options.atol = 1e-11;
  Simulator sim(model, options);
  BaseControl c;
  c.attitude.on = c.attitude.hold = true;
  c.attitude.kp = 400.0;
  c.attitude.kd = 1500.0;
  c.position.on = c.position.hold = true;
  c.position.kp = 50.0;
  c.position.kd = 400.0;
  sim.setBaseControl(c);
  JointControl pd;
  pd.mode = JointControl::Mode::PD;
  pd.kp = 200.0;
  pd.kd = 150.0;
  pd.set_point = 0.5;
  sim.setJointControl(0, pd);
  SimulationState s = atRest(*model);
  const KDL::Frame start(KDL::Rotation::RPY(0.3, -0.2, 0.5), KDL::Vector(1.0, 2.0, 3.0));
  s.state.world_T_base = start;
  double largest = 0.0;  // the base does move: the hold is not trivially met
  ASSERT_EQ(sim.run(s, 60.0, 1.0,
                    [&](const SimulationState& x) {
                      largest = std::max(largest, (x.state.world_T_base.M * start.M.Inverse()).GetRot().Norm());
                    }),
            E_NOERROR);
  EXPECT_GT(largest, 1e-5);  // (with the identity as set point it would turn by ~0.6 rad)
  EXPECT_LT((s.state.world_T_base.M * start.M.Inverse()).GetRot().Norm(), 1e-3);
  EXPECT_LT((s.state.world_T_base.p - start.p).Norm(), 1e-3);
  EXPECT_NEAR(s.state.q(0), 0.5, 1e-3);
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(sim.baseControl().attitude.set_point(r, k), start.M(r, k));
  EXPECT_TRUE(near(sim.baseControl().position.set_point, toEigen(start.p), 0.0, 0.0, "position set point"));
}

}  // namespace
}  // namespace kdl_space::test
