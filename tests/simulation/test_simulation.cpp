// The Simulator (simulation.hpp) against closed forms, conservation laws, an independent
// integration through KDL only (the virtual-joint route), and itself at other step sizes:
//   3. a single free rigid body: the axisymmetric closed form (torque-free precession), and the
//      invariants of an asymmetric body;
//   4. free joints, no torques, 100 s: momentum and kinetic energy conserved;
//   5. RK4 is of order 4 (errors fall 16-fold per halving of the step);
//   6. the SpaceDyn two-link sample: PD servo from zero momentum, the base turns (non-holonomic);
//   7. all joints locked: the system moves as one rigid body;
//   8. a captured target stays attached (withPayload after kdl_space::collide);
//   9. the torque callback (the PD law written by hand equals JointControl::PD).
// No expected value is the library's own output, except the recorded SpaceDyn yaw, which was
// checked by two integrators and by the KDL-only route before being written down (see there).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>

#include "kdl_space/impact/collision.hpp"
#include "impact_util.hpp"
#include "kdl_space/simulation/simulation.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"
#include "virtual_joint_route.hpp"

namespace kdl_space::test {
namespace {

using ModelPtr = std::shared_ptr<const FloatingModel>;

ModelPtr load(const std::string& path) { return std::make_shared<const FloatingModel>(loadUrdfFile(path)); }

Vector3d randomVec(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return Vector3d(u(rng), u(rng), u(rng));
}

Matrix3d randomRotation(std::mt19937& rng) {
  std::normal_distribution<double> g;
  Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
  return q.normalized().toRotationMatrix();
}

KDL::Rotation toKdlRotation(const Matrix3d& R) {
  return KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2));
}

/// A state with random joints and base pose, random joint rates in [-rate, rate] and a random
/// base twist.
SimulationState randomSimulationState(const FloatingModel& model, std::mt19937& rng, double rate) {
  SimulationState s;
  s.state = randomState(model, rng);
  s.velocity.qdot = KDL::JntArray(model.nj());
  std::uniform_real_distribution<double> u(-rate, rate);
  for (unsigned int j = 0; j < model.nj(); ++j) s.velocity.qdot(j) = u(rng);
  s.velocity.base_twist = toTwist((Vector6d() << randomVec(rng, 0.1), randomVec(rng, 0.1)).finished());
  return s;
}

/// Momentum (P; L about the world origin) compared with a scale: the linear part relative to
/// |P|, the angular part relative to |L| + lever |P| (the r x P terms that enter L about the
/// origin; lever = a distance of the system from the origin).
::testing::AssertionResult momentumNear(const Vector6d& a, const Vector6d& ref, double rel, double lever) {
  const double p = ref.head<3>().norm(), l = ref.tail<3>().norm() + lever * p;
  const double e_lin = (a - ref).head<3>().norm(), e_ang = (a - ref).tail<3>().norm();
  if (e_lin <= rel * p && e_ang <= rel * l) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "momentum " << a.transpose() << "\n  expected " << ref.transpose()
                                       << "\n  differences: linear " << e_lin << ", angular " << e_ang
                                       << " (tolerance " << rel << " x " << p << ", " << l << ")";
}

double relative(double a, double ref) { return std::abs(a - ref) / std::abs(ref); }

double yawOf(const KDL::Frame& T) {
  double r, p, y;
  T.M.GetRPY(r, p, y);
  return y;
}

// ---- 3. A single free rigid body ---------------------------------------------------------------

/// A model with no joints: the root of a KDL tree alone, with the given inertia (CoM c and
/// inertia about the CoM, body axes).
ModelPtr singleBody(double m, const Vector3d& c, const Vector3d& principal) {
  const KDL::Tree tree("body");
  return std::make_shared<const FloatingModel>(
      tree, KDL::RigidBodyInertia(m, toKDL(c), KDL::RotationalInertia(principal(0), principal(1), principal(2), 0, 0, 0)));
}

TEST(SingleRigidBody, AxisymmetricTorqueFreeClosedForm) {
  // I1 = I2 != I3 about the CoM, body axes; CoM at c from the base origin. Euler's equations give
  // body-frame w_b(t) = Rz(lambda t) w_b(0), lambda = (I3 - I1)/I1 w3; with L the world angular
  // momentum about the CoM (constant), w_world = L/I1 - lambda R e3, whose solution is
  //   R(t) = Rot(L/|L|, |L|/I1 t) R0 Rz(-lambda t)
  // (check: dR/dt R^T = [L/I1]x + R [-lambda e3]x R^T = [w_world]x). The CoM moves uniformly.
  const double m = 3.0, I1 = 2.0, I3 = 3.5;
  const Vector3d c(0.1, -0.2, 0.05);
  const ModelPtr model = singleBody(m, c, Vector3d(I1, I1, I3));
  ASSERT_EQ(model->nj(), 0u);
  std::mt19937 rng(301);
  const Matrix3d R0 = randomRotation(rng);
  const Vector3d w_b0(0.6, -0.3, 1.2), v_g(0.05, -0.02, 0.03), p0(0.3, 0.2, -0.1);
  const Vector3d p_g0 = p0 + R0 * c;
  const double lambda = (I3 - I1) / I1 * w_b0(2);
  const Vector3d L = R0 * Vector3d(I1, I1, I3).asDiagonal() * w_b0;
  const double Omega = L.norm() / I1;

  SimulationState s;
  s.state = State(*model);
  s.state.world_T_base = KDL::Frame(toKdlRotation(R0), toKDL(p0));
  s.velocity.qdot = KDL::JntArray(0);
  const Vector3d w0 = R0 * w_b0;
  s.velocity.base_twist = toTwist((Vector6d() << v_g + w0.cross(p0 - p_g0), w0).finished());

  SimulationOptions options;
  options.rtol = 1e-12;
  options.atol = 1e-14;
  Simulator sim(model, options);
  double T0;
  Vector6d h0;
  ASSERT_EQ(sim.energyAndMomentum(s, T0, h0), E_NOERROR);
  // Energy and momentum of the initial state by hand.
  EXPECT_NEAR(T0, 0.5 * m * v_g.squaredNorm() + 0.5 * w_b0.dot(Vector3d(I1, I1, I3).asDiagonal() * w_b0), 1e-14);
  const Vector6d h_expected = (Vector6d() << m * v_g, L + p_g0.cross(m * v_g)).finished();
  EXPECT_TRUE(momentumNear(h0, h_expected, 1e-14, 1.0));

  int outputs = 0;
  double worst_R = 0.0, worst_w = 0.0, worst_p = 0.0;
  ASSERT_EQ(sim.run(s, 20.0, 1.0,
                    [&](const SimulationState& x) {
                      ++outputs;
                      const double t = x.t;
                      const Matrix3d R = Eigen::AngleAxisd(Omega * t, L.normalized()).toRotationMatrix() * R0 *
                                         Eigen::AngleAxisd(-lambda * t, Vector3d::UnitZ()).toRotationMatrix();
                      const Vector3d w_b = Eigen::AngleAxisd(lambda * t, Vector3d::UnitZ()).toRotationMatrix() * w_b0;
                      const Matrix3d R_sim = toEigen(x.state.world_T_base.M);
                      const Vector3d w_sim = toEigen(x.velocity.base_twist.rot);
                      const Vector3d p_expected = p_g0 + v_g * t - R * c;
                      worst_R = std::max(worst_R, (R_sim - R).cwiseAbs().maxCoeff());
                      worst_w = std::max({worst_w, (R_sim.transpose() * w_sim - w_b).norm(), (w_sim - R * w_b).norm()});
                      worst_p = std::max(worst_p, (toEigen(x.state.world_T_base.p) - p_expected).norm());
                      // Body-frame angular velocity precesses about e3 at lambda: w3 constant.
                      EXPECT_NEAR((R_sim.transpose() * w_sim)(2), w_b0(2), 1e-9) << "t = " << t;
                      // World angular momentum about the CoM constant.
                      const Vector3d L_sim = R_sim * Vector3d(I1, I1, I3).asDiagonal() * R_sim.transpose() * w_sim;
                      EXPECT_TRUE(near(L_sim, L, 1e-10, 0.0, "L at t = " + std::to_string(t)));
                    }),
            E_NOERROR);
  EXPECT_EQ(outputs, 21);
  std::printf("[ info     ] closed form over 20 s: orientation %.2e, angular velocity %.2e, origin %.2e\n", worst_R,
              worst_w, worst_p);
  EXPECT_LE(worst_R, 1e-9);
  EXPECT_LE(worst_w, 1e-9);
  EXPECT_LE(worst_p, 1e-9);
  // Over 20 s the symmetry axis has precessed through lambda * 20 = 18 rad: the test is not
  // passed by a body that does not precess.
  ASSERT_GT(std::abs(lambda) * 20.0, 6.0);
}

TEST(SingleRigidBody, AsymmetricBodyKeepsMomentumAndEnergy) {
  // Principal moments 1, 2, 2.5 and a spin close to the intermediate axis (it tumbles).
  const ModelPtr model = singleBody(5.0, Vector3d(-0.05, 0.12, 0.2), Vector3d(1.0, 2.0, 2.5));
  std::mt19937 rng(302);
  SimulationState s;
  s.state = State(*model);
  s.state.world_T_base = KDL::Frame(toKdlRotation(randomRotation(rng)), KDL::Vector(1.0, -0.5, 0.2));
  s.velocity.qdot = KDL::JntArray(0);
  const Vector3d w = toEigen(s.state.world_T_base.M) * Vector3d(0.05, 1.5, 0.08);
  s.velocity.base_twist = toTwist((Vector6d() << 0.02, 0.01, -0.03, w).finished());
  // Adaptive integrator at rtol 1e-11 (the default 1e-10 gives an energy drift of 4.6e-11 over
  // 20 s here: too close to the 1e-10 requirement for a robust test).
  SimulationOptions options;
  options.rtol = 1e-11;
  Simulator sim(model, options);
  double T0;
  Vector6d h0;
  ASSERT_EQ(sim.energyAndMomentum(s, T0, h0), E_NOERROR);
  double worst_T = 0.0, min_w1 = 1e9, max_w1 = 0.0;
  ASSERT_EQ(sim.run(s, 20.0, 0.5,
                    [&](const SimulationState& x) {
                      double T;
                      Vector6d h;
                      ASSERT_EQ(sim.energyAndMomentum(x, T, h), E_NOERROR);
                      EXPECT_TRUE(momentumNear(h, h0, 1e-10, 2.0)) << "t = " << x.t;
                      worst_T = std::max(worst_T, relative(T, T0));
                      const Vector3d w_b = toEigen(x.state.world_T_base.M).transpose() * toEigen(x.velocity.base_twist.rot);
                      min_w1 = std::min(min_w1, std::abs(w_b(1)));
                      max_w1 = std::max(max_w1, std::abs(w_b(1)));
                    }),
            E_NOERROR);
  std::printf("[ info     ] asymmetric body: worst relative energy change %.2e\n", worst_T);
  EXPECT_LE(worst_T, 1e-10);
  // It did tumble: the intermediate-axis component changed a lot.
  EXPECT_GT(max_w1 - min_w1, 0.5);
}

// ---- 4. Free joints: momentum and energy over 100 s ---------------------------------------------

class FreeMotion : public ::testing::TestWithParam<std::string> {};

TEST_P(FreeMotion, MomentumAndEnergyConservedOver100s) {
  const ModelPtr model = load(urdfDir() + "/" + GetParam() + ".urdf");
  std::mt19937 rng(401);
  SimulationState s = randomSimulationState(*model, rng, 1.0);
  Simulator sim(model);  // free joints, default adaptive integrator at default tolerances
  double T0;
  Vector6d h0;
  ASSERT_EQ(sim.energyAndMomentum(s, T0, h0), E_NOERROR);
  const double lever = s.state.world_T_base.p.Norm() + 5.0;
  const KDL::JntArray q0 = s.state.q;
  double worst_T = 0.0, worst_h = 0.0;
  ASSERT_EQ(sim.run(s, 100.0, 1.0,
                    [&](const SimulationState& x) {
                      double T;
                      Vector6d h;
                      ASSERT_EQ(sim.energyAndMomentum(x, T, h), E_NOERROR);
                      EXPECT_TRUE(momentumNear(h, h0, 1e-10, lever)) << "t = " << x.t;
                      worst_T = std::max(worst_T, relative(T, T0));
                      worst_h = std::max(worst_h, (h - h0).norm() / h0.norm());
                    }),
            E_NOERROR);
  EXPECT_DOUBLE_EQ(s.t, 100.0);
  std::printf("[ info     ] %s: 100 s, %ld steps (%ld rejected), worst relative energy change %.2e, momentum %.2e\n",
              GetParam().c_str(), sim.stats().accepted_steps, sim.stats().rejected_steps, worst_T, worst_h);
  EXPECT_LE(worst_T, 1e-8);
  EXPECT_GT((s.state.q.data - q0.data).norm(), 0.1);  // it moved
}

INSTANTIATE_TEST_SUITE_P(Robots, FreeMotion, ::testing::Values("space_arm7", "dual_arm"));

// ---- 5. RK4 is of order 4 -----------------------------------------------------------------------

TEST(RK4, ConvergesAtOrderFour) {
  // space_arm7 from a random state with joint rates up to 1 rad/s, 2 s. Error of the final state
  // (q and base position, max norm) against the adaptive Dormand-Prince at rtol 1e-13 (another
  // integrator); steps 1/64, 1/128, 1/256 s (exact in binary, below max_step, and landing on 2 s
  // exactly). Observed errors 1.5e-5, 9.3e-7, 5.9e-8 (ratios 15.6, 15.8), far above the
  // reference's own error (< 1e-11) and round-off. (At 1/32 the ratio is still pre-asymptotic,
  // 21.9.)
  const ModelPtr model = load(urdfDir() + "/space_arm7.urdf");
  std::mt19937 rng(501);
  const SimulationState s0 = randomSimulationState(*model, rng, 1.0);
  const double t_end = 2.0;
  auto finalState = [&](const SimulationOptions& options, long* steps) {
    Simulator sim(model, options);
    SimulationState s = s0;
    EXPECT_EQ(sim.run(s, t_end, t_end, nullptr), E_NOERROR);
    if (steps) *steps = sim.stats().accepted_steps;
    Eigen::VectorXd x(model->nj() + 3);
    x << s.state.q.data, toEigen(s.state.world_T_base.p);
    return x;
  };
  SimulationOptions reference;
  reference.rtol = 1e-13;
  reference.atol = 1e-15;
  const Eigen::VectorXd x_ref = finalState(reference, nullptr);
  std::vector<double> errors;
  for (double h : {1.0 / 64, 1.0 / 128, 1.0 / 256}) {
    SimulationOptions rk4;
    rk4.integrator = Integrator::RK4;
    rk4.step = h;
    long steps = 0;
    errors.push_back((finalState(rk4, &steps) - x_ref).cwiseAbs().maxCoeff());
    EXPECT_EQ(steps, std::lround(t_end / h)) << "h = " << h;
  }
  std::printf("[ info     ] RK4 errors %.3e %.3e %.3e, ratios %.2f %.2f\n", errors[0], errors[1], errors[2],
              errors[0] / errors[1], errors[1] / errors[2]);
  EXPECT_GT(errors[2], 1e-10);  // above round-off and the reference's error
  for (int i = 0; i + 1 < 3; ++i) {
    EXPECT_GT(errors[i] / errors[i + 1], 12.0);
    EXPECT_LT(errors[i] / errors[i + 1], 20.0);
  }
}

// Disabled: documents a discrepancy reported to the maintainers. SimulationOptions documents
// `step` as the RK4 step and `max_step` as an adaptive-only bound (README: "rk4 (fixed `step`)").
// (Regression: run() used to clip the RK4 step to max_step, and to add a sliver step when the
// accumulated time fell just short of an output time.)
TEST(RK4, StepLargerThanMaxStepIsHonoured) {
  const ModelPtr model = load(urdfDir() + "/spacedyn_twolink.urdf");
  SimulationOptions options;
  options.integrator = Integrator::RK4;
  options.step = 0.1;
  Simulator sim(model, options);
  SimulationState s;
  s.state = State(*model);
  s.velocity.qdot = KDL::JntArray(2);
  s.velocity.qdot(0) = 0.5;
  ASSERT_EQ(sim.run(s, 1.0, 1.0, nullptr), E_NOERROR);
  EXPECT_EQ(sim.stats().accepted_steps, 10);
}

// An unstable controller (negative damping through the callback) cannot hang run(): the step
// budget stops it with E_MAX_STEPS.
TEST(Simulator, StepBudgetStopsARunaway) {
  const ModelPtr model = load(urdfDir() + "/spacedyn_twolink.urdf");
  SimulationOptions options;
  options.max_steps = 2000;
  Simulator sim(model, options);
  sim.setTorqueCallback([](const SimulationState& x, KDL::JntArray& tau) {
    tau.data = 1e4 * x.velocity.qdot.data;  // pumps energy in
  });
  SimulationState s;
  s.state = State(*model);
  s.velocity.qdot = KDL::JntArray(2);
  s.velocity.qdot(0) = 0.5;
  EXPECT_EQ(sim.run(s, 100.0, 1.0, nullptr), E_MAX_STEPS);
  EXPECT_LE(sim.stats().accepted_steps + sim.stats().rejected_steps, 2000);
}

// ---- 6. The SpaceDyn two-link sample --------------------------------------------------------------

/// The SpaceDyn sample's recorded final base yaw [rad] at t = 10 s (13.398 degrees). Obtained with
/// the library's RK4 at h = 1e-3 (0.23383902352127053) and at h = 2.5e-4 (0.23383902352110009), and
/// with Dormand-Prince at rtol 1e-12 (0.23383902352109831): all agree to 2e-13. Independently, the
/// KDL-only virtual-joint route integrated with its own RK4 (test below) gives the same value.
constexpr double kSpaceDynFinalYaw = 0.233839023521;
// Achieved joint angles at 10 s (set point -pi/6 = -0.5235987756, pi/3 = 1.0471975512):
//   q1 = -0.5235998218, q2 = 1.0471970767 (errors 1.0e-6 and 4.7e-7 rad); base origin
//   (-0.0069169151, 0.0588900483, 0) m.

SimulationState spaceDynInitial(const FloatingModel& model) {
  SimulationState s;
  s.state = State(model);
  s.state.q(0) = M_PI / 6;
  s.state.q(1) = -M_PI / 3;
  s.velocity.qdot = KDL::JntArray(2);
  return s;
}

void spaceDynControls(Simulator& sim) {
  const double set_points[2] = {-M_PI / 6, M_PI / 3};
  for (unsigned int j = 0; j < 2; ++j) sim.setJointControl(j, JointControl{JointControl::Mode::PD, 10.0, 5.0, set_points[j]});
}

TEST(SpaceDynSample, TwoLinkPdFromZeroMomentum) {
  const ModelPtr model = load(urdfDir() + "/spacedyn_twolink.urdf");
  ASSERT_EQ(model->nj(), 2u);
  ASSERT_EQ(model->jointNames()[0], "joint1");
  SimulationState s = spaceDynInitial(*model);
  Simulator sim(model);
  spaceDynControls(sim);
  double worst_h = 0.0, worst_tilt = 0.0;
  ASSERT_EQ(sim.run(s, 10.0, 0.1,
                    [&](const SimulationState& x) {
                      double T;
                      Vector6d h;
                      ASSERT_EQ(sim.energyAndMomentum(x, T, h), E_NOERROR);
                      worst_h = std::max(worst_h, h.cwiseAbs().maxCoeff());
                      double r, p, y;
                      x.state.world_T_base.M.GetRPY(r, p, y);
                      worst_tilt = std::max({worst_tilt, std::abs(r), std::abs(p), std::abs(x.state.world_T_base.p.z())});
                    }),
            E_NOERROR);
  EXPECT_LE(worst_h, 1e-12) << "momentum must stay zero";
  EXPECT_LE(worst_tilt, 1e-12) << "the motion must stay in the x-y plane";
  EXPECT_NEAR(s.state.q(0), -M_PI / 6, 1e-3);
  EXPECT_NEAR(s.state.q(1), M_PI / 3, 1e-3);
  const double yaw = yawOf(s.state.world_T_base);
  std::printf("[ info     ] SpaceDyn sample at 10 s: q = (%.10f, %.10f), base yaw %.12f rad, origin (%.10f, %.10f)\n",
              s.state.q(0), s.state.q(1), yaw, s.state.world_T_base.p.x(), s.state.world_T_base.p.y());
  EXPECT_GT(std::abs(yaw), 0.1) << "the base attitude must change (non-holonomic)";
  EXPECT_NEAR(yaw, kSpaceDynFinalYaw, 1e-6);
}

TEST(SpaceDynSample, IntegratorsAgreeOnTheFinalYaw) {
  const ModelPtr model = load(urdfDir() + "/spacedyn_twolink.urdf");
  double yaws[2];
  for (int k = 0; k < 2; ++k) {
    SimulationOptions options;
    if (k == 0) {
      options.integrator = Integrator::RK4;
      options.step = 5e-4;
    } else {
      options.rtol = 1e-12;
      options.atol = 1e-14;
    }
    Simulator sim(model, options);
    spaceDynControls(sim);
    SimulationState s = spaceDynInitial(*model);
    ASSERT_EQ(sim.run(s, 10.0, 10.0, nullptr), E_NOERROR);
    yaws[k] = yawOf(s.state.world_T_base);
  }
  EXPECT_NEAR(yaws[0], yaws[1], 1e-6);
  EXPECT_NEAR(yaws[0], kSpaceDynFinalYaw, 1e-6);
}

TEST(SpaceDynSample, KdlRouteIntegrationAgrees) {
  // The same motion integrated with no kdl_space solver at all: the virtual-joint tree with
  // coordinates theta = (x, y, z, a, b, c; q1, q2), base pose Trans(x, y, z) Rx(a) Ry(b) Rz(c)
  // (the base starts at the identity), theta_dd = M^-1 (tau_full - c) from KDL's
  // TreeIdSolver_RNE, classical RK4 written here, h = 2.5e-3 s. The motion is planar, so a = b = 0
  // and the yaw is c.
  const ModelPtr model = load(urdfDir() + "/spacedyn_twolink.urdf");
  const VirtualJointDynamics route(*model);
  const int N = route.size();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2 * N);
  x(6) = M_PI / 6;
  x(7) = -M_PI / 3;
  const Eigen::Vector2d set_point(-M_PI / 6, M_PI / 3);
  auto f = [&](const Eigen::VectorXd& y) {
    const Eigen::VectorXd theta = y.head(N), theta_d = y.tail(N);
    const Eigen::VectorXd tau = 10.0 * (set_point - theta.tail(2)) - 5.0 * theta_d.tail(2);
    Eigen::VectorXd dy(2 * N);
    dy << theta_d, route.forwardDynamics(theta, theta_d, tau, KDL::Vector::Zero());
    return dy;
  };
  const double h = 2.5e-3;
  for (int step = 0; step < 4000; ++step) {
    const Eigen::VectorXd k1 = f(x), k2 = f(x + 0.5 * h * k1), k3 = f(x + 0.5 * h * k2), k4 = f(x + h * k3);
    x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  EXPECT_NEAR(x(3), 0.0, 1e-12);
  EXPECT_NEAR(x(4), 0.0, 1e-12);
  std::printf("[ info     ] KDL route at 10 s: yaw %.12f, q = (%.10f, %.10f), origin (%.10f, %.10f)\n", x(5), x(6),
              x(7), x(0), x(1));
  EXPECT_NEAR(x(5), kSpaceDynFinalYaw, 1e-6);
  // And the library's state at 10 s against it.
  SimulationState s = spaceDynInitial(*model);
  Simulator sim(model);
  spaceDynControls(sim);
  ASSERT_EQ(sim.run(s, 10.0, 10.0, nullptr), E_NOERROR);
  EXPECT_NEAR(yawOf(s.state.world_T_base), x(5), 1e-6);
  EXPECT_NEAR(s.state.q(0), x(6), 1e-6);
  EXPECT_NEAR(s.state.q(1), x(7), 1e-6);
  EXPECT_NEAR(s.state.world_T_base.p.x(), x(0), 1e-6);
  EXPECT_NEAR(s.state.world_T_base.p.y(), x(1), 1e-6);
}

// ---- 7. Locked joints: one rigid body -----------------------------------------------------------

TEST(LockedJoints, SystemMovesAsOneRigidBody) {
  const ModelPtr model = load(urdfDir() + "/dual_arm.urdf");
  const unsigned int n = model->nj();
  std::mt19937 rng(701);
  SimulationState s = randomSimulationState(*model, rng, 1.0);
  Simulator sim(model);
  for (unsigned int j = 0; j < n; ++j) sim.setJointControl(j, JointControl{JointControl::Mode::Locked});
  double T_before, T_after;
  Vector6d h_before, h_after;
  ASSERT_EQ(sim.energyAndMomentum(s, T_before, h_before), E_NOERROR);
  ASSERT_GT(s.velocity.qdot.data.norm(), 0.5);
  ASSERT_EQ(sim.engageBrakes(s), E_NOERROR);
  for (unsigned int j = 0; j < n; ++j) EXPECT_EQ(s.velocity.qdot(j), 0.0);
  ASSERT_EQ(sim.energyAndMomentum(s, T_after, h_after), E_NOERROR);
  const double lever = s.state.world_T_base.p.Norm() + 3.0;
  EXPECT_TRUE(momentumNear(h_after, h_before, 1e-12, lever)) << "the brake impulse is internal";
  EXPECT_LT(T_after, T_before) << "the brakes dissipate";

  const double w = model->totalMass();
  const Vector3d P = h_before.head<3>(), v_g = P / w;
  FreeFloatingSolver solver(model);
  ASSERT_EQ(solver.compute(s.state), E_NOERROR);
  const Vector3d r_g0 = solver.r_g();
  const KDL::JntArray q0 = s.state.q;
  int outputs = 0;
  double worst_w = 0.0;
  ASSERT_EQ(sim.run(s, 5.0, 0.25,
                    [&](const SimulationState& x) {
                      ++outputs;
                      SCOPED_TRACE("t = " + std::to_string(x.t));
                      EXPECT_TRUE(near(x.state.q.data, q0.data, 0.0, 1e-14, "joint angles"));
                      EXPECT_TRUE(near(x.velocity.qdot.data, Eigen::VectorXd::Zero(n), 0.0, 0.0, "joint rates"));
                      ASSERT_EQ(solver.compute(x.state), E_NOERROR);
                      // The CoM moves uniformly at P / w.
                      EXPECT_TRUE(near(solver.r_g(), r_g0 + v_g * x.t, 0.0, 1e-10, "CoM"));
                      const Vector3d w_b = toEigen(x.velocity.base_twist.rot);
                      const Vector3d v_b = toEigen(x.velocity.base_twist.vel);
                      const Vector3d p_b = toEigen(x.state.world_T_base.p);
                      EXPECT_TRUE(near(v_b + w_b.cross(solver.r_g() - p_b), v_g, 0.0, 1e-12 * (v_g.norm() + 1.0), "v_g"));
                      // w = I_g(t)^-1 L_g, L_g = L_O - r_g x P constant in the world.
                      const Vector3d L_g = h_before.tail<3>() - solver.r_g().cross(P);
                      const Vector3d w_expected = solver.I_g().ldlt().solve(L_g);
                      worst_w = std::max(worst_w, (w_b - w_expected).norm() / w_expected.norm());
                      EXPECT_TRUE(near(w_b, w_expected, 1e-10, 1e-12 * w_expected.norm(), "base angular velocity"));
                      double T;
                      Vector6d h;
                      ASSERT_EQ(sim.energyAndMomentum(x, T, h), E_NOERROR);
                      EXPECT_NEAR(T, 0.5 * w * v_g.squaredNorm() + 0.5 * L_g.dot(w_expected), 1e-10 * T_after);
                      EXPECT_NEAR(T, T_after, 1e-10 * T_after);
                    }),
            E_NOERROR);
  EXPECT_EQ(outputs, 21);
  std::printf("[ info     ] locked: worst relative |w - I_g^-1 L_g| %.2e\n", worst_w);
}

TEST(LockedJoints, EngageBrakesOnSomeJointsKeepsMomentum) {
  // Brakes on half the joints of space_arm7: those rates become zero, the others change by the
  // internal impulse; momentum is unchanged and energy does not rise.
  const ModelPtr model = load(urdfDir() + "/space_arm7.urdf");
  std::mt19937 rng(702);
  SimulationState s = randomSimulationState(*model, rng, 1.0);
  Simulator sim(model);
  for (unsigned int j = 0; j < model->nj(); j += 2) sim.setJointControl(j, JointControl{JointControl::Mode::Locked});
  double T0, T1;
  Vector6d h0, h1;
  ASSERT_EQ(sim.energyAndMomentum(s, T0, h0), E_NOERROR);
  const KDL::JntArray qdot0 = s.velocity.qdot;
  ASSERT_EQ(sim.engageBrakes(s), E_NOERROR);
  ASSERT_EQ(sim.energyAndMomentum(s, T1, h1), E_NOERROR);
  for (unsigned int j = 0; j < model->nj(); ++j) {
    if (j % 2 == 0) EXPECT_EQ(s.velocity.qdot(j), 0.0);
  }
  EXPECT_GT((s.velocity.qdot.data - qdot0.data).norm(), 0.0);
  EXPECT_TRUE(momentumNear(h1, h0, 1e-12, s.state.world_T_base.p.Norm() + 4.0));
  EXPECT_LE(T1, T0);
  // The run keeps the locked joints still.
  const KDL::JntArray q0 = s.state.q;
  ASSERT_EQ(sim.run(s, 2.0, 2.0, nullptr), E_NOERROR);
  for (unsigned int j = 0; j < model->nj(); j += 2) EXPECT_NEAR(s.state.q(j), q0(j), 1e-14);
}

// ---- 8. A captured target stays attached -----------------------------------------------------------

TEST(Capture, CapturedTargetStaysAttached) {
  const ModelPtr model = load(urdfDir() + "/space_arm7.urdf");
  const unsigned int n = model->nj();
  std::mt19937 rng(801);
  SimulationState s = randomSimulationState(*model, rng, 0.5);
  FreeFloatingSolver solver(model);
  ASSERT_EQ(solver.compute(s.state), E_NOERROR);
  const Contact hand = model->contact("end_effector");
  Vector3d p_h;
  ASSERT_EQ(solver.contactPoint(hand, p_h), E_NOERROR);

  // The target: 150 kg, inertia R diag R^T, CoM 0.6 m from the grasp point, tumbling.
  RigidBody target;
  target.mass = 150.0;
  const Matrix3d Rt = randomRotation(rng);
  target.I_com = Rt * Vector3d(20.0, 30.0, 40.0).asDiagonal() * Rt.transpose();
  target.I_com = (0.5 * (target.I_com + target.I_com.transpose())).eval();
  target.com = p_h + Vector3d(0.2, -0.4, 0.4);
  target.twist << 0.3, -0.1, 0.2, 0.05, -0.08, 0.1;

  FloatingSide robot(solver.sharedModel(), solver.state(), hand, s.velocity);
  RigidBodySide body(target, p_h);
  collideOk(robot, body, ImpactLaw{ImpactKind::Capture});
  const Vector6d h_pre = robot.momentumBefore() + body.momentumBefore();
  const Vector6d h_post = robot.momentumAfter() + body.momentumAfter();
  const double T_post = robot.energyAfter() + body.energyAfter();
  const double lever = p_h.norm() + target.com.norm() + 2.0;

  // The target's inertia in the end_effector frame at the capture instant.
  const KDL::Frame ee = solver.bodyPose(model->bodyIndex("end_effector"));
  const Matrix3d R_ee = toEigen(ee.M);
  const Vector3d cog = R_ee.transpose() * (target.com - toEigen(ee.p));
  const Matrix3d I_ee = R_ee.transpose() * target.I_com * R_ee;
  const KDL::RigidBodyInertia payload(
      target.mass, toKDL(cog), KDL::RotationalInertia(I_ee(0, 0), I_ee(1, 1), I_ee(2, 2), I_ee(0, 1), I_ee(0, 2), I_ee(1, 2)));
  const ModelPtr merged = std::make_shared<const FloatingModel>(model->withPayload("end_effector", payload));
  ASSERT_EQ(merged->nj(), n);
  EXPECT_NEAR(merged->totalMass(), model->totalMass() + target.mass, 1e-12);

  SimulationState m;
  m.state = s.state;
  m.velocity = robot.after();
  Simulator sim(merged);
  double T0;
  Vector6d h0;
  ASSERT_EQ(sim.energyAndMomentum(m, T0, h0), E_NOERROR);
  // (a) the merged system's momentum and energy at t = 0 are those of robot + target after.
  // 1e-11: the x86-64 baseline build (no FMA: CPUs without AVX2, and tools/sanitize.sh, where
  // recursive_ex_iit.cpp has no x86-64-v3 clone) differs here by 1.3e-12 relative.
  EXPECT_TRUE(momentumNear(h0, h_post, 1e-11, lever));
  EXPECT_TRUE(momentumNear(h0, h_pre, 1e-11, lever)) << "capture conserves momentum";
  EXPECT_NEAR(T0, T_post, 1e-10 * T_post);
  // The target's implied motion at t = 0: the material point of the merged end_effector at the
  // target's CoM moves with the target's twist after the capture.
  FreeFloatingSolver merged_solver(merged);
  ASSERT_EQ(merged_solver.compute(m.state), E_NOERROR);
  const Contact target_com = merged->contact("end_effector", toKDL(cog));
  Vector3d p_c;
  ASSERT_EQ(merged_solver.contactPoint(target_com, p_c), E_NOERROR);
  EXPECT_TRUE(near(p_c, target.com, 0.0, 1e-12, "target CoM"));
  Vector6d PL_g;
  ASSERT_EQ(merged_solver.momentum(m.velocity.base_twist, m.velocity.qdot, PL_g), E_NOERROR);
  KDL::Twist t_c;
  ASSERT_EQ(merged_solver.handTwist(target_com, m.velocity.qdot, PL_g, t_c), E_NOERROR);
  EXPECT_TRUE(near(toEigen(t_c), body.twistAfter(), 0.0, 1e-10 * body.twistAfter().norm(), "target twist after"));

  // (b) over 5 s the momentum stays the pre-capture total; the energy stays constant.
  double worst_T = 0.0;
  ASSERT_EQ(sim.run(m, 5.0, 0.5,
                    [&](const SimulationState& x) {
                      double T;
                      Vector6d h;
                      ASSERT_EQ(sim.energyAndMomentum(x, T, h), E_NOERROR);
                      EXPECT_TRUE(momentumNear(h, h_pre, 1e-11, lever)) << "t = " << x.t;
                      worst_T = std::max(worst_T, relative(T, T_post));
                    }),
            E_NOERROR);
  std::printf("[ info     ] captured target: worst relative energy change over 5 s %.2e\n", worst_T);
  EXPECT_LE(worst_T, 1e-9);
  // The joints moved: the payload rode on a moving arm.
  EXPECT_GT((m.state.q.data - s.state.q.data).norm(), 0.05);
}

// ---- 9. PD servo and torque callback --------------------------------------------------------------

TEST(TorqueCallback, HandWrittenPdEqualsJointControlPd) {
  const ModelPtr model = load(urdfDir() + "/space_arm7.urdf");
  const unsigned int n = model->nj();
  std::mt19937 rng(901);
  const SimulationState s0 = randomSimulationState(*model, rng, 0.5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<JointControl> pd(n);
  for (unsigned int j = 0; j < n; ++j) pd[j] = JointControl{JointControl::Mode::PD, 10.0 + 2.0 * j, 4.0, u(rng)};

  SimulationState a = s0, b = s0, c = s0;
  Simulator with_modes(model), with_callback(model), free_joints(model);
  for (unsigned int j = 0; j < n; ++j) with_modes.setJointControl(j, pd[j]);
  long calls = 0;
  with_callback.setTorqueCallback([&](const SimulationState& x, KDL::JntArray& tau) {
    ++calls;
    for (unsigned int j = 0; j < n; ++j)
      tau(j) = pd[j].kp * (pd[j].set_point - x.state.q(j)) - pd[j].kd * x.velocity.qdot(j);
  });
  ASSERT_EQ(with_modes.run(a, 3.0, 3.0, nullptr), E_NOERROR);
  ASSERT_EQ(with_callback.run(b, 3.0, 3.0, nullptr), E_NOERROR);
  ASSERT_EQ(free_joints.run(c, 3.0, 3.0, nullptr), E_NOERROR);
  EXPECT_GT(calls, 0);
  EXPECT_TRUE(near(b.state.q.data, a.state.q.data, 0.0, 1e-12, "q"));
  EXPECT_TRUE(near(b.velocity.qdot.data, a.velocity.qdot.data, 0.0, 1e-12, "qdot"));
  EXPECT_TRUE(near(toEigen(b.state.world_T_base.p), toEigen(a.state.world_T_base.p), 0.0, 1e-12, "base position"));
  EXPECT_TRUE(near(toEigen(b.velocity.base_twist), toEigen(a.velocity.base_twist), 0.0, 1e-12, "base twist"));
  // The torques change the motion.
  EXPECT_GT((b.state.q.data - c.state.q.data).norm(), 0.1);
}

TEST(TorqueCallback, CallbackTorquesAddToJointModes) {
  // PD on every joint plus a callback adding a constant torque tau_c: the PD servo then settles
  // at q = set_point + tau_c / kp (static equilibrium of tau = kp (s - q) - kd qdot + tau_c).
  const ModelPtr model = load(urdfDir() + "/spacedyn_twolink.urdf");
  SimulationState s;
  s.state = State(*model);
  s.velocity.qdot = KDL::JntArray(2);
  Simulator sim(model);
  sim.setJointControl(0, JointControl{JointControl::Mode::PD, 20.0, 10.0, 0.3});
  sim.setJointControl(1, JointControl{JointControl::Mode::PD, 20.0, 10.0, -0.2});
  sim.setTorqueCallback([](const SimulationState&, KDL::JntArray& tau) {
    tau(0) = 2.0;
    tau(1) = -1.0;
  });
  ASSERT_EQ(sim.run(s, 40.0, 40.0, nullptr), E_NOERROR);
  EXPECT_NEAR(s.state.q(0), 0.3 + 2.0 / 20.0, 1e-5);
  EXPECT_NEAR(s.state.q(1), -0.2 - 1.0 / 20.0, 1e-5);
}

}  // namespace
}  // namespace kdl_space::test
