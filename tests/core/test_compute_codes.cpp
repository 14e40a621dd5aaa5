// Every compute call of the library with wrong sizes, bad contacts, out-of-range parameters and
// non-finite inputs: the exact code it returns, that it never throws, and that its outputs are
// untouched on an error (errors.hpp states the rule). Set-up calls throw ModelError instead.
#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <set>

#include "kdl_space/impact/collision.hpp"
#include "kdl_space/simulation/simulation.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kSentinel = 42.0;  ///< what an output holds before a call that must not touch it

using ModelPtr = std::shared_ptr<const FloatingModel>;

ModelPtr arm7() {
  static const ModelPtr model = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/space_arm7.urdf"));
  return model;
}

/// Bit-for-bit equality of two frames (an output left untouched).
bool same(const KDL::Frame& a, const KDL::Frame& b) {
  for (int i = 0; i < 3; ++i) {
    if (a.p(i) != b.p(i)) return false;
    for (int j = 0; j < 3; ++j)
      if (a.M(i, j) != b.M(i, j)) return false;
  }
  return true;
}
bool same(const KDL::Twist& a, const KDL::Twist& b) { return toEigen(a) == toEigen(b); }

// --- FreeFloatingSolver ------------------------------------------------------------------------

class SolverCodes : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_EQ(solver.compute(State(*model)), E_NOERROR); }
  ModelPtr model = arm7();
  FreeFloatingSolver solver{model};
  unsigned int n = model->nj();
  Contact tip = model->contact("end_effector", KDL::Vector(0, 0, 0.05));
};

TEST_F(SolverCodes, ComputeRefusesWrongSizeNonFiniteAndOverflowingStates) {
  State state(*model);
  state.q = KDL::JntArray(n + 1);
  EXPECT_NO_THROW(EXPECT_EQ(solver.compute(state), E_SIZE_MISMATCH));
  state = State(*model);
  state.q(2) = kInf;
  EXPECT_NO_THROW(EXPECT_EQ(solver.compute(state), E_NOT_FINITE));
  state = State(*model);
  state.world_T_base.M(1, 1) = kNaN;
  EXPECT_NO_THROW(EXPECT_EQ(solver.compute(state), E_NOT_FINITE));
  // Finite, but so far away that the first moment of mass overflows: refused, not factorised.
  state = State(*model);
  state.world_T_base.p = KDL::Vector(1e307, 0.0, 0.0);
  EXPECT_NO_THROW(EXPECT_EQ(solver.compute(state), E_NOT_FINITE));
  Matrix6d G = Matrix6d::Constant(kSentinel);
  EXPECT_EQ(solver.G_star(tip, G), E_NOT_COMPUTED) << "a failed compute discards the previous result";
  EXPECT_EQ(G, Matrix6d::Constant(kSentinel));
}

TEST_F(SolverCodes, MomentumBaseTwistAndEnergyCheckSizesAndFiniteness) {
  KDL::JntArray qdot(n), wrong(n - 1);
  const KDL::Twist twist(KDL::Vector(0.1, 0, 0), KDL::Vector(0, 0, 0.2));
  const KDL::Twist nan_twist(KDL::Vector(kNaN, 0, 0), KDL::Vector::Zero());
  Vector6d PL = Vector6d::Constant(kSentinel);
  KDL::Twist out(KDL::Vector(kSentinel, kSentinel, kSentinel), KDL::Vector(kSentinel, kSentinel, kSentinel));
  const KDL::Twist out_before = out;
  double T = kSentinel;
  EXPECT_NO_THROW({
    EXPECT_EQ(solver.momentum(twist, wrong, PL), E_SIZE_MISMATCH);
    EXPECT_EQ(solver.momentum(nan_twist, qdot, PL), E_NOT_FINITE);
    EXPECT_EQ(solver.baseTwist(PL, wrong, out), E_SIZE_MISMATCH);
    EXPECT_EQ(solver.baseTwist(Vector6d::Constant(kNaN), qdot, out), E_NOT_FINITE);
    EXPECT_EQ(solver.kineticEnergy(twist, wrong, T), E_SIZE_MISMATCH);
    EXPECT_EQ(solver.kineticEnergy(nan_twist, qdot, T), E_NOT_FINITE);
  });
  qdot(3) = kInf;
  EXPECT_EQ(solver.momentum(twist, qdot, PL), E_NOT_FINITE);
  EXPECT_EQ(solver.kineticEnergy(twist, qdot, T), E_NOT_FINITE);
  EXPECT_EQ(PL, Vector6d::Constant(kSentinel));
  EXPECT_TRUE(same(out, out_before));
  EXPECT_EQ(T, kSentinel);
}

// Every contact query of every solver against bad contacts: test_compute_codes_all_solvers.cpp.

TEST_F(SolverCodes, AnInverseInertiaThatOverflowsIsRefused) {
  // A finite offset so large that the lever arms squared overflow: the point, J and J* are
  // finite (and returned), every G is not.
  const Contact far{tip.body, KDL::Vector(1e308, 1e308, 0)};
  Matrix6d M = Matrix6d::Constant(kSentinel);
  Eigen::MatrixXd G_all = Eigen::MatrixXd::Constant(12, 12, kSentinel);
  EXPECT_NO_THROW({
    EXPECT_EQ(solver.G_star(far, M), E_NOT_FINITE);
    EXPECT_EQ(solver.G_grounded(far, M), E_NOT_FINITE);
    EXPECT_EQ(solver.G_locked(far, M), E_NOT_FINITE);
    for (Response r : {Response::FreeFloating, Response::Grounded, Response::JointsLocked})
      EXPECT_EQ(solver.G(far, r, M), E_NOT_FINITE);
    EXPECT_EQ(solver.G_star(std::vector<Contact>{tip, far}, G_all), E_NOT_FINITE);
  });
  EXPECT_EQ(M, Matrix6d::Constant(kSentinel));
  EXPECT_EQ(G_all, Eigen::MatrixXd::Constant(12, 12, kSentinel));
}

TEST_F(SolverCodes, WrongOutputSizesAndEnumValues) {
  Matrix6d M = Matrix6d::Constant(kSentinel);
  Vector6d dPL = Vector6d::Constant(kSentinel);
  KDL::JntArray dqdot(n), wrong(n + 3);
  dqdot.data.setConstant(kSentinel);
  const auto no_response = static_cast<Response>(7);
  EXPECT_NO_THROW({
    EXPECT_EQ(solver.G(tip, no_response, M), E_BAD_ARGUMENT);
    EXPECT_EQ(solver.velocityJump(tip, no_response, Vector6d::Ones(), dPL, dqdot), E_BAD_ARGUMENT);
    EXPECT_EQ(solver.velocityJump(tip, Response::FreeFloating, Vector6d::Ones(), dPL, wrong), E_SIZE_MISMATCH);
    Vector6d F = Vector6d::Ones();
    F(4) = kNaN;
    EXPECT_EQ(solver.velocityJump(tip, Response::FreeFloating, F, dPL, dqdot), E_NOT_FINITE);
    // An impulse so large that the jump overflows.
    EXPECT_EQ(solver.velocityJump(tip, Response::FreeFloating, Vector6d::Constant(1e308), dPL, dqdot), E_NOT_FINITE);
  });
  EXPECT_EQ(M, Matrix6d::Constant(kSentinel));
  EXPECT_EQ(dPL, Vector6d::Constant(kSentinel));
  EXPECT_EQ(dqdot.data, Eigen::VectorXd::Constant(n, kSentinel));

  Eigen::MatrixXd G_all = Eigen::MatrixXd::Constant(12, 11, kSentinel);
  EXPECT_EQ(solver.G_star(std::vector<Contact>{tip, tip}, G_all), E_SIZE_MISMATCH);
  EXPECT_EQ(G_all, Eigen::MatrixXd::Constant(12, 11, kSentinel));
  Eigen::MatrixXd empty(0, 0);
  EXPECT_EQ(solver.G_star(std::vector<Contact>{}, empty), E_NOERROR) << "no contact: an empty G*";

  KDL::Twist t;
  Vector6d PL = Vector6d::Zero();
  PL(5) = kInf;
  EXPECT_EQ(solver.handTwist(tip, KDL::JntArray(n), PL, t), E_NOT_FINITE);
  EXPECT_EQ(solver.handTwist(tip, KDL::JntArray(n + 1), Vector6d::Zero(), t), E_SIZE_MISMATCH);
}

// --- ForwardDynamicsSolver ---------------------------------------------------------------------

// Extent::Jacobians: J, J*, momentum and the hand's twist as the full solver's (bit for bit: the
// same operations); no n x n matrix; the queries that need H or H* return E_NOT_COMPUTED and
// leave their outputs untouched.
TEST_F(SolverCodes, TheJacobiansExtentAnswersWhatNeedsNoMassMatrix) {
  FreeFloatingSolver light(model, FreeFloatingSolver::Extent::Jacobians);
  EXPECT_EQ(light.extent(), FreeFloatingSolver::Extent::Jacobians);
  State s(*model);
  for (unsigned int j = 0; j < n; ++j) s.q(j) = 0.3 * j - 0.7;
  ASSERT_EQ(solver.compute(s), E_NOERROR);
  ASSERT_EQ(light.compute(s), E_NOERROR);
  EXPECT_EQ(light.H().rows(), 0u);
  EXPECT_EQ(light.H_star().rows(), 0u);
  KDL::Jacobian J_full(n), J_light(n), Js_full(n), Js_light(n);
  ASSERT_EQ(solver.J(tip, J_full), E_NOERROR);
  ASSERT_EQ(light.J(tip, J_light), E_NOERROR);
  ASSERT_EQ(solver.J_star(tip, Js_full), E_NOERROR);
  ASSERT_EQ(light.J_star(tip, Js_light), E_NOERROR);
  EXPECT_EQ(J_full.data, J_light.data);
  EXPECT_EQ(Js_full.data, Js_light.data);
  KDL::JntArray qdot(n);
  for (unsigned int j = 0; j < n; ++j) qdot(j) = 0.1 * j;
  const KDL::Twist base(KDL::Vector(0.01, 0.02, -0.01), KDL::Vector(0.001, 0.002, 0.003));
  Vector6d PL_full, PL_light;
  ASSERT_EQ(solver.momentum(base, qdot, PL_full), E_NOERROR);
  ASSERT_EQ(light.momentum(base, qdot, PL_light), E_NOERROR);
  EXPECT_EQ(PL_full, PL_light);
  KDL::Twist t_full, t_light;
  ASSERT_EQ(solver.handTwist(tip, qdot, PL_full, t_full), E_NOERROR);
  ASSERT_EQ(light.handTwist(tip, qdot, PL_light, t_light), E_NOERROR);
  EXPECT_TRUE(same(t_full, t_light));
  Matrix6d G = Matrix6d::Constant(kSentinel), G_locked;
  EXPECT_EQ(light.G_star(tip, G), E_NOT_COMPUTED);
  EXPECT_EQ(light.G_grounded(tip, G), E_NOT_COMPUTED);
  EXPECT_EQ(light.G(tip, Response::FreeFloating, G), E_NOT_COMPUTED);
  EXPECT_EQ(G, Matrix6d::Constant(kSentinel));
  EXPECT_EQ(light.G(tip, Response::JointsLocked, G_locked), E_NOERROR);
  Eigen::MatrixXd G_all = Eigen::MatrixXd::Constant(6, 6, kSentinel);
  EXPECT_EQ(light.G_star(std::vector<Contact>{tip}, G_all), E_NOT_COMPUTED);
  Vector6d dPL = Vector6d::Constant(kSentinel);
  KDL::JntArray dq(n);
  EXPECT_EQ(light.velocityJump(tip, Response::FreeFloating, Vector6d::Ones(), dPL, dq), E_NOT_COMPUTED);
  EXPECT_EQ(dPL, Vector6d::Constant(kSentinel));
  EXPECT_EQ(light.velocityJump(tip, Response::JointsLocked, Vector6d::Ones(), dPL, dq), E_NOERROR);
  double T = kSentinel;
  EXPECT_EQ(light.kineticEnergy(base, qdot, T), E_NOT_COMPUTED);
  EXPECT_EQ(T, kSentinel);
  EXPECT_FALSE(light.groundedAvailable());
}

TEST(ForwardDynamicsCodes, CartToJntChecksEverySizeAndValue) {
  const ModelPtr model = arm7();
  const unsigned int n = model->nj();
  const std::size_t nb = model->bodies().size();
  ForwardDynamicsSolver fd(model);
  const State state(*model);
  FloatingVelocity v{KDL::Twist::Zero(), KDL::JntArray(n)};
  KDL::JntArray tau(n);
  FloatingAcceleration a{Vector6d::Constant(kSentinel), KDL::JntArray(n)};
  a.qddot.data.setConstant(kSentinel);
  const std::vector<KDL::Wrench> none;
  const auto expectCode = [&](int code, const State& s, const FloatingVelocity& vel, const KDL::JntArray& t,
                              const std::vector<KDL::Wrench>& f, FloatingAcceleration& acc, const char* what) {
    EXPECT_NO_THROW(EXPECT_EQ(fd.CartToJnt(s, vel, t, f, acc), code) << what);
  };
  State bad_q(*model);
  bad_q.q = KDL::JntArray(n - 1);
  expectCode(E_SIZE_MISMATCH, bad_q, v, tau, none, a, "q");
  expectCode(E_SIZE_MISMATCH, state, FloatingVelocity{KDL::Twist::Zero(), KDL::JntArray(n + 1)}, tau, none, a, "qdot");
  expectCode(E_SIZE_MISMATCH, state, v, KDL::JntArray(0), none, a, "tau");
  expectCode(E_SIZE_MISMATCH, state, v, tau, std::vector<KDL::Wrench>(nb - 1), a, "f_ext");
  FloatingAcceleration small{Vector6d::Zero(), KDL::JntArray(n - 2)};
  expectCode(E_SIZE_MISMATCH, state, v, tau, none, small, "qddot");
  KDL::JntArray nan_tau(n);
  nan_tau(0) = kNaN;
  expectCode(E_NOT_FINITE, state, v, nan_tau, none, a, "tau NaN");
  FloatingVelocity nan_v = v;
  nan_v.base_twist.rot.z(kInf);
  expectCode(E_NOT_FINITE, state, nan_v, tau, none, a, "base twist");
  std::vector<KDL::Wrench> wrenches(nb);
  wrenches[nb - 1].torque.y(kNaN);
  expectCode(E_NOT_FINITE, state, v, tau, wrenches, a, "f_ext NaN");
  State nan_state(*model);
  nan_state.q(1) = kNaN;
  expectCode(E_NOT_FINITE, nan_state, v, tau, none, a, "q NaN");
  KDL::JntArray huge(n);
  huge.data.setConstant(1e308);
  expectCode(E_NOT_FINITE, state, v, huge, none, a, "accelerations overflow");
  EXPECT_EQ(a.base, Vector6d::Constant(kSentinel));
  EXPECT_EQ(a.qddot.data, Eigen::VectorXd::Constant(n, kSentinel));
  expectCode(E_NOERROR, state, v, tau, none, a, "good");

  // From a Kinematics: one of another model (even of the same robot), one never computed, one
  // whose last forwardKinematics failed.
  const ModelPtr twin = std::make_shared<const FloatingModel>(*model);
  Kinematics other_model(*twin), never(*model), failed(*model);
  ASSERT_EQ(forwardKinematics(*twin, state, other_model), E_NOERROR);
  ASSERT_EQ(forwardKinematics(*model, nan_state, failed), E_NOT_FINITE);
  a.base.setConstant(kSentinel);
  a.qddot.data.setConstant(kSentinel);
  EXPECT_NO_THROW(EXPECT_EQ(fd.CartToJnt(other_model, v, tau, none, a), E_SIZE_MISMATCH));
  EXPECT_NO_THROW(EXPECT_EQ(fd.CartToJnt(never, v, tau, none, a), E_NOT_COMPUTED));
  EXPECT_NO_THROW(EXPECT_EQ(fd.CartToJnt(failed, v, tau, none, a), E_NOT_COMPUTED));
  Kinematics kin(*model);
  ASSERT_EQ(forwardKinematics(*model, state, kin), E_NOERROR);
  EXPECT_NO_THROW(EXPECT_EQ(fd.CartToJnt(kin, v, nan_tau, none, a), E_NOT_FINITE));
  EXPECT_NO_THROW(EXPECT_EQ(fd.CartToJnt(kin, v, tau, wrenches, a), E_NOT_FINITE));
  EXPECT_NO_THROW(EXPECT_EQ(fd.CartToJnt(kin, v, tau, none, small), E_SIZE_MISMATCH));
  EXPECT_NO_THROW(EXPECT_EQ(fd.CartToJnt(kin, v, huge, none, a), E_NOT_FINITE));
  EXPECT_EQ(a.base, Vector6d::Constant(kSentinel));
  EXPECT_EQ(a.qddot.data, Eigen::VectorXd::Constant(n, kSentinel));
  EXPECT_NO_THROW(EXPECT_EQ(fd.CartToJnt(kin, v, tau, none, a), E_NOERROR));

}

// --- Simulator ---------------------------------------------------------------------------------

SimulationState restState(const FloatingModel& model) {
  SimulationState s;
  s.state = State(model);
  s.velocity.qdot = KDL::JntArray(model.nj());
  return s;
}

bool same(const SimulationState& a, const SimulationState& b) {
  return a.t == b.t && same(a.state.world_T_base, b.state.world_T_base) && a.state.q.data == b.state.q.data &&
         same(a.velocity.base_twist, b.velocity.base_twist) && a.velocity.qdot.data == b.velocity.qdot.data;
}

TEST(SimulatorCodes, RunRefusesBadArgumentsAndLeavesTheStateUntouched) {
  const ModelPtr model = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/spacedyn_twolink.urdf"));
  Simulator sim(model);
  SimulationState s = restState(*model);
  s.velocity.qdot(0) = 0.1;
  const SimulationState original = s;
  const struct {
    const char* what;
    double t_end, output_dt;
    int code;
  } cases[] = {
      {"t_end before s.t", -1.0, 0.1, E_BAD_ARGUMENT}, {"output_dt 0", 1.0, 0.0, E_BAD_ARGUMENT},
      {"output_dt < 0", 1.0, -0.1, E_BAD_ARGUMENT},    {"t_end NaN", kNaN, 0.1, E_NOT_FINITE},
      {"t_end inf", kInf, 0.1, E_NOT_FINITE},          {"output_dt NaN", 1.0, kNaN, E_NOT_FINITE},
  };
  for (const auto& c : cases) {
    EXPECT_NO_THROW(EXPECT_EQ(sim.run(s, c.t_end, c.output_dt, nullptr), c.code) << c.what);
    EXPECT_TRUE(same(s, original)) << c.what;
  }
  SimulationState wrong = s;
  wrong.state.q = KDL::JntArray(3);
  EXPECT_EQ(sim.run(wrong, 1.0, 0.1, nullptr), E_SIZE_MISMATCH);
  wrong = s;
  wrong.velocity.qdot = KDL::JntArray(1);
  EXPECT_EQ(sim.run(wrong, 1.0, 0.1, nullptr), E_SIZE_MISMATCH);
  wrong = s;
  wrong.velocity.qdot(1) = kNaN;
  EXPECT_EQ(sim.run(wrong, 1.0, 0.1, nullptr), E_NOT_FINITE);
  wrong = s;
  wrong.t = kNaN;
  EXPECT_EQ(sim.run(wrong, 1.0, 0.1, nullptr), E_NOT_FINITE);
  wrong = s;
  wrong.state.world_T_base.p.x(kInf);
  EXPECT_EQ(sim.run(wrong, 1.0, 0.1, nullptr), E_NOT_FINITE);
  EXPECT_TRUE(same(s, original));
}

TEST(SimulatorCodes, ACallbackThatResizesTauIsRefusedAndTheSimulatorRecovers) {
  const ModelPtr model = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/spacedyn_twolink.urdf"));
  Simulator sim(model);
  sim.setTorqueCallback([](const SimulationState&, KDL::JntArray& tau) { tau.resize(5); });
  SimulationState s = restState(*model);
  EXPECT_NO_THROW(EXPECT_EQ(sim.run(s, 0.1, 0.05, nullptr), E_SIZE_MISMATCH));
  sim.setTorqueCallback([](const SimulationState&, KDL::JntArray& tau) { tau(0) = 0.1; });
  EXPECT_EQ(sim.run(s, 0.1, 0.05, nullptr), E_NOERROR);
  sim.setTorqueCallback([](const SimulationState&, KDL::JntArray& tau) { tau(1) = kNaN; });
  EXPECT_EQ(sim.run(s, 0.2, 0.05, nullptr), E_NOT_FINITE);
}

TEST(SimulatorCodes, AFailedRunLeavesTheLastGoodStep) {
  const ModelPtr model = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/spacedyn_twolink.urdf"));
  SimulationOptions options;
  options.integrator = Integrator::RK4;
  options.step = 0.01;
  options.max_steps = 25;
  Simulator sim(model, options);
  SimulationState s = restState(*model);
  s.velocity.qdot(0) = 0.3;
  double last_output = -1.0;
  EXPECT_EQ(sim.run(s, 10.0, 1.0, [&](const SimulationState& x) { last_output = x.t; }), E_MAX_STEPS);
  EXPECT_EQ(last_output, 0.0) << "no output time was reached";
  EXPECT_NEAR(s.t, 0.25, 1e-12) << "s is at the 25th step, not at the last output";
  EXPECT_TRUE(s.state.q.data.allFinite());
  EXPECT_NE(s.state.q(0), 0.0) << "the joint moved";
}

TEST(SimulatorCodes, EngageBrakesAndEnergyCheckSizes) {
  const ModelPtr model = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/spacedyn_twolink.urdf"));
  Simulator sim(model);
  sim.setJointControl(1, {JointControl::Mode::Locked});
  SimulationState s = restState(*model);
  s.velocity.qdot = KDL::JntArray(1);  // fewer rates than joints: was read past its end
  const SimulationState original = s;
  EXPECT_NO_THROW(EXPECT_EQ(sim.engageBrakes(s), E_SIZE_MISMATCH));
  EXPECT_TRUE(same(s, original));
  s = restState(*model);
  s.velocity.qdot(1) = kNaN;
  EXPECT_EQ(sim.engageBrakes(s), E_NOT_FINITE);
  s.velocity.qdot(1) = 0.2;
  EXPECT_EQ(sim.engageBrakes(s), E_NOERROR);
  EXPECT_EQ(s.velocity.qdot(1), 0.0);

  double T = kSentinel;
  Vector6d h = Vector6d::Constant(kSentinel);
  SimulationState wrong = restState(*model);
  wrong.velocity.qdot = KDL::JntArray(4);
  EXPECT_NO_THROW(EXPECT_EQ(sim.energyAndMomentum(wrong, T, h), E_SIZE_MISMATCH));
  wrong = restState(*model);
  wrong.state.q = KDL::JntArray(0);
  EXPECT_EQ(sim.energyAndMomentum(wrong, T, h), E_SIZE_MISMATCH);
  wrong = restState(*model);
  wrong.velocity.base_twist.vel.x(kNaN);
  EXPECT_EQ(sim.energyAndMomentum(wrong, T, h), E_NOT_FINITE);
  EXPECT_EQ(T, kSentinel);
  EXPECT_EQ(h, Vector6d::Constant(kSentinel));
}

TEST(SimulatorCodes, SetUpCallsThrowModelError) {
  const ModelPtr model = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/spacedyn_twolink.urdf"));
  const auto options = [](auto change) {
    SimulationOptions o;
    change(o);
    return o;
  };
  EXPECT_THROW(Simulator(model, options([](SimulationOptions& o) { o.step = kNaN; })), ModelError);
  EXPECT_THROW(Simulator(model, options([](SimulationOptions& o) { o.max_step = kInf; })), ModelError);
  EXPECT_THROW(Simulator(model, options([](SimulationOptions& o) { o.atol = 0.0; })), ModelError);
  EXPECT_THROW(Simulator(model, options([](SimulationOptions& o) { o.max_steps = 0; })), ModelError);
  EXPECT_THROW(Simulator(model, options([](SimulationOptions& o) { o.gravity.z() = kNaN; })), ModelError);
  EXPECT_THROW(Simulator(model, options([](SimulationOptions& o) { o.integrator = static_cast<Integrator>(9); })),
               ModelError);
  Simulator sim(model);
  EXPECT_THROW(sim.setJointControl(2, {}), ModelError);
  EXPECT_THROW(sim.setJointControl(0, {static_cast<JointControl::Mode>(5)}), ModelError);
  EXPECT_THROW(sim.setJointControl(0, {JointControl::Mode::PD, -1.0, 1.0, 0.0}), ModelError);
  EXPECT_THROW(sim.setJointControl(0, {JointControl::Mode::PD, 1.0, 1.0, kNaN}), ModelError);
}

// --- Impact functions ----------------------------------------------------------------------------

struct ImpactInputs {
  Matrix6d G_A = Matrix6d::Identity() * 0.5, G_B = Matrix6d::Identity() * 0.02;
  Vector6d t_A = (Vector6d() << 0.3, 0.1, 0.0, 0.0, 0.0, 0.1).finished();
  Vector6d t_B = Vector6d::Zero();
};

TEST(ImpactCodes, SolveImpactChecksInputsAndLaw) {
  const ImpactInputs in;
  const ImpactLaw point{ImpactKind::PointImpact, Vector3d::UnitX(), 0.5, 0.0};
  const ImpactLaw friction{ImpactKind::FrictionalImpact, Vector3d::UnitX(), 0.5, 0.3};
  const auto with = [](ImpactLaw law, auto change) {
    change(law);
    return law;
  };
  const struct {
    const char* what;
    ImpactLaw law;
    int code;
  } cases[] = {
      {"zero normal", with(point, [](ImpactLaw& l) { l.normal.setZero(); }), E_BAD_ARGUMENT},
      {"NaN normal", with(point, [](ImpactLaw& l) { l.normal.y() = kNaN; }), E_NOT_FINITE},
      {"restitution 1.5", with(point, [](ImpactLaw& l) { l.restitution = 1.5; }), E_BAD_ARGUMENT},
      {"restitution -0.1", with(friction, [](ImpactLaw& l) { l.restitution = -0.1; }), E_BAD_ARGUMENT},
      {"restitution NaN", with(point, [](ImpactLaw& l) { l.restitution = kNaN; }), E_NOT_FINITE},
      {"friction -1", with(friction, [](ImpactLaw& l) { l.friction = -1.0; }), E_BAD_ARGUMENT},
      {"friction inf", with(friction, [](ImpactLaw& l) { l.friction = kInf; }), E_NOT_FINITE},
      {"kind", with(point, [](ImpactLaw& l) { l.kind = static_cast<ImpactKind>(17); }), E_BAD_ARGUMENT},
  };
  for (const auto& c : cases) {
    Impulse impulse;
    impulse.F.setConstant(kSentinel);
    EXPECT_NO_THROW(EXPECT_EQ(solveImpact(in.G_A, in.G_B, in.t_A, in.t_B, c.law, impulse), c.code) << c.what);
    EXPECT_EQ(impulse.F, Vector6d::Constant(kSentinel)) << c.what;
  }
  // Unused parameters are not checked: a capture ignores the normal and the restitution.
  Impulse capture;
  EXPECT_EQ(solveImpact(in.G_A, in.G_B, in.t_A, in.t_B, with(point, [](ImpactLaw& l) {
                          l.kind = ImpactKind::Capture;
                          l.normal.setZero();
                          l.restitution = 7.0;
                        }),
                        capture),
            E_NOERROR);
  EXPECT_EQ(capture.F, solveImpact(in.G_A, in.G_B, in.t_A, in.t_B, ImpactLaw{ImpactKind::Capture}).F)
      << "the checked form gives the value form's impulse";

  // Non-finite inputs, and G_A + G_B that no law can use.
  Impulse impulse;
  impulse.F.setConstant(kSentinel);
  Matrix6d nan_G = in.G_A;
  nan_G(2, 3) = kNaN;
  Vector6d inf_t = in.t_B;
  inf_t(0) = -kInf;
  EXPECT_EQ(solveImpact(nan_G, in.G_B, in.t_A, in.t_B, point, impulse), E_NOT_FINITE);
  EXPECT_EQ(solveImpact(in.G_A, in.G_B, in.t_A, inf_t, point, impulse), E_NOT_FINITE);
  const Matrix6d zero = Matrix6d::Zero();
  for (ImpactKind kind : {ImpactKind::Capture, ImpactKind::PointImpact, ImpactKind::FrictionalImpact,
                          ImpactKind::TranslationalCapture}) {
    EXPECT_NO_THROW(EXPECT_EQ(solveImpact(zero, zero, in.t_A, in.t_B, with(friction, [&](ImpactLaw& l) { l.kind = kind; }),
                                          impulse),
                              E_NOT_POSITIVE_DEFINITE))
        << static_cast<int>(kind);
  }
  EXPECT_EQ(impulse.F, Vector6d::Constant(kSentinel));
  // An impulse that overflows is reported, not returned.
  Vector6d fast = in.t_A;
  fast(0) = 1e308;
  EXPECT_EQ(solveImpact(Matrix6d::Identity() * 1e-10, zero, fast, in.t_B, ImpactLaw{ImpactKind::Capture}, impulse),
            E_NOT_FINITE);
  EXPECT_EQ(impulse.F, Vector6d::Constant(kSentinel));
}

TEST(ImpactCodes, VirtualMassAndRigidBodyG) {
  double m = kSentinel;
  const Matrix6d G = Matrix6d::Identity() * 0.25;
  EXPECT_EQ(virtualMass(G, Vector3d(0, 2, 0), m), E_NOERROR);
  EXPECT_DOUBLE_EQ(m, 4.0) << "n is made unit";
  m = kSentinel;
  Matrix6d singular = G;
  singular(1, 1) = 0.0;
  EXPECT_NO_THROW({
    EXPECT_EQ(virtualMass(G, Vector3d::Zero(), m), E_BAD_ARGUMENT);
    EXPECT_EQ(virtualMass(G, Vector3d(kNaN, 0, 0), m), E_NOT_FINITE);
    EXPECT_EQ(virtualMass(singular, Vector3d::UnitY(), m), E_NOT_POSITIVE_DEFINITE);
    EXPECT_EQ(virtualMass(-G, Vector3d::UnitY(), m), E_NOT_POSITIVE_DEFINITE);
  });
  EXPECT_EQ(m, kSentinel);

  Matrix6d G_B = Matrix6d::Constant(kSentinel);
  const Matrix3d I = Vector3d(1.0, 2.0, 2.5).asDiagonal();
  EXPECT_NO_THROW({
    EXPECT_EQ(rigidBodyG(0.0, I, Vector3d::Zero(), G_B), E_BAD_ARGUMENT);
    EXPECT_EQ(rigidBodyG(-2.0, I, Vector3d::Zero(), G_B), E_BAD_ARGUMENT);
    EXPECT_EQ(rigidBodyG(kNaN, I, Vector3d::Zero(), G_B), E_NOT_FINITE);
    EXPECT_EQ(rigidBodyG(2.0, -I, Vector3d::Zero(), G_B), E_NOT_POSITIVE_DEFINITE);
    EXPECT_EQ(rigidBodyG(2.0, I, Vector3d(0, kInf, 0), G_B), E_NOT_FINITE);
  });
  EXPECT_EQ(G_B, Matrix6d::Constant(kSentinel));
  EXPECT_EQ(rigidBodyG(2.0, I, Vector3d(0.1, 0, 0), G_B), E_NOERROR);
  EXPECT_EQ(G_B, rigidBodyG(2.0, I, Vector3d(0.1, 0, 0)));
}

// --- Impact sides and collide -----------------------------------------------------------------

class SideCodes : public ::testing::Test {
 protected:
  void SetUp() override {
    state.q(1) = 0.7;
    state.q(3) = 0.8;
    ASSERT_EQ(solver.compute(state), E_NOERROR);
    velocity.qdot(0) = 0.02;
    velocity.base_twist = KDL::Twist(KDL::Vector(0.002, 0, 0), KDL::Vector(0, 0, 0.001));
    ASSERT_EQ(solver.contactPoint(tip, p_h), E_NOERROR);
    box.mass = 50.0;
    box.I_com = Vector3d(2.1, 2.6, 3.0).asDiagonal();
    box.com = p_h + Vector3d(0.0, -0.3, 0.0);
    box.twist << 0.03, -0.02, 0.01, 0.05, 0.08, -0.06;
  }
  ModelPtr model = arm7();
  FreeFloatingSolver solver{model};
  State state{*model};
  Contact tip = model->contact("end_effector", KDL::Vector(0, 0, 0.05));
  FloatingVelocity velocity{KDL::Twist::Zero(), KDL::JntArray(model->nj())};
  Vector3d p_h;
  RigidBody box;
};

/// The state after of a floating side, to compare before and after a refused call.
struct AfterState {
  explicit AfterState(const FloatingSide& s)
      : base(toEigen(s.after().base_twist)), qdot(s.after().qdot.data), contact(s.contactTwistAfter()),
        momentum(s.momentumAfter()), energy(s.energyAfter()), centroid(s.centroidTwistAfter()) {}
  bool operator==(const AfterState& o) const {
    return base == o.base && qdot == o.qdot && contact == o.contact && momentum == o.momentum && energy == o.energy &&
           centroid == o.centroid;
  }
  Vector6d base;
  Eigen::VectorXd qdot;
  Vector6d contact, momentum;
  double energy;
  Vector6d centroid;
};

TEST_F(SideCodes, ApplyImpulseRefusesNonFiniteAndOverflowingImpulses) {
  for (Response response : {Response::FreeFloating, Response::Grounded, Response::JointsLocked}) {
    for (ExIITMethod method : {ExIITMethod::Recursive, ExIITMethod::Dense}) {
      SCOPED_TRACE("response " + std::to_string(static_cast<int>(response)) + ", method " +
                   std::to_string(static_cast<int>(method)));
      FloatingSide robot(solver.sharedModel(), solver.state(), tip, velocity, response, method);
      ASSERT_EQ(robot.applyImpulse(Vector6d::Constant(0.1)), E_NOERROR);
      const AfterState good(robot);
      Vector6d F = Vector6d::Zero();
      F(3) = kNaN;
      EXPECT_NO_THROW(EXPECT_EQ(robot.applyImpulse(F), E_NOT_FINITE));
      EXPECT_NO_THROW(EXPECT_EQ(robot.applyImpulse(Vector6d::Constant(1e308)), E_NOT_FINITE));
      EXPECT_TRUE(AfterState(robot) == good) << "the state after is untouched";
    }
  }
  RigidBody light = box;  // 0.1 mg: a huge impulse makes its velocity overflow
  light.mass = 1e-7;
  light.I_com *= 1e-7;
  RigidBodySide target(light, p_h);
  ASSERT_EQ(target.applyImpulse(Vector6d::Constant(0.1)), E_NOERROR);
  const Vector6d good = target.twistAfter();
  EXPECT_NO_THROW(EXPECT_EQ(target.applyImpulse(Vector6d::Constant(kInf)), E_NOT_FINITE));
  EXPECT_NO_THROW(EXPECT_EQ(target.applyImpulse(Vector6d::Constant(1e308)), E_NOT_FINITE));
  EXPECT_EQ(target.twistAfter(), good);
}

TEST_F(SideCodes, ASideCannotGoStaleBehindItsCaller) {
  // The side owns its state and solvers: a caller's solver computing another state (or failing
  // to) changes nothing of the side's G*, velocity jump, momentum or energy.
  for (ExIITMethod method : {ExIITMethod::Recursive, ExIITMethod::Dense}) {
    ASSERT_EQ(solver.compute(state), E_NOERROR);
    FloatingSide robot(solver.sharedModel(), solver.state(), tip, velocity, Response::FreeFloating, method);
    FloatingSide reference(model, state, tip, velocity, Response::FreeFloating, method);
    State other = state;
    other.q(0) += 0.7;
    ASSERT_EQ(solver.compute(other), E_NOERROR);
    State bad = state;
    bad.q(0) = kNaN;
    ASSERT_EQ(solver.compute(bad), E_NOT_FINITE);
    EXPECT_EQ(robot.G(), reference.G());
    ASSERT_EQ(robot.applyImpulse(Vector6d::Ones()), E_NOERROR);
    ASSERT_EQ(reference.applyImpulse(Vector6d::Ones()), E_NOERROR);
    EXPECT_TRUE(AfterState(robot) == AfterState(reference));
    EXPECT_EQ(robot.momentumAfter(), reference.momentumAfter());
    EXPECT_EQ(robot.energyAfter(), reference.energyAfter());
  }
}

/// Expects a ModelError whose message starts with `prefix` and holds `fragment`.
template <typename Build>
void expectModelError(Build build, const std::string& prefix, const std::string& fragment) {
  try {
    build();
    ADD_FAILURE() << "no ModelError; expected \"" << prefix << "..." << fragment << "\"";
  } catch (const ModelError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(prefix, 0), 0u) << what;
    EXPECT_NE(what.find(fragment), std::string::npos) << what;
  }
}

TEST(SolverSetUp, SetLockedAndSetGravityThrowModelErrorNamingTheProblem) {
  // Set-up calls: a refusal is a ModelError naming the call and the model's joints (or the
  // value), and the solver keeps what it had.
  const ModelPtr model = arm7();
  const unsigned int n = model->nj();
  const std::string joints = "(joint1, joint2, joint3, joint4, joint5, joint6, joint7)";
  ForwardDynamicsSolver fd(model);
  DenseForwardDynamicsSolver crb(model);
  expectModelError([&] { fd.setLocked(std::vector<bool>(n + 1)); }, "ForwardDynamicsSolver::setLocked: 8 braked-joint flags",
                   "a model of 7 joints; give one per joint, in the model's order " + joints);
  expectModelError([&] { crb.setLocked({}); }, "DenseForwardDynamicsSolver::setLocked: 0 braked-joint flags", joints);
  EXPECT_EQ(fd.locked(), std::vector<bool>(n, false)) << "unchanged after a refusal";
  // The impact solvers' brakes: size nj() or empty (none); a refusal keeps the locks.
  RecursiveExIITSolver recursive(model);
  FreeFloatingSolver dense(model);
  std::vector<bool> one(n, false);
  one[0] = true;
  recursive.setLocked(one);
  dense.setLocked(one);
  for (const std::size_t size : {std::size_t{1}, std::size_t{n - 1}, std::size_t{n + 1}}) {
    const std::string flags = std::to_string(size) + " braked-joint flags for a model of 7 joints";
    expectModelError([&] { recursive.setLocked(std::vector<bool>(size, true)); }, "RecursiveExIITSolver::setLocked: " + flags,
                     joints + ", or none");
    expectModelError([&] { dense.setLocked(std::vector<bool>(size, true)); }, "FreeFloatingSolver::setLocked: " + flags,
                     joints + ", or none");
  }
  EXPECT_EQ(recursive.locked(), one) << "unchanged after a refusal";
  EXPECT_EQ(dense.locked(), one) << "unchanged after a refusal";
  recursive.setLocked({});
  dense.setLocked({});
  EXPECT_EQ(recursive.locked(), std::vector<bool>(n, false)) << "empty: none";
  EXPECT_EQ(dense.locked(), std::vector<bool>(n, false)) << "empty: none";
  expectModelError([&] { fd.setGravity(Vector3d(0, 0, kNaN)); }, "ForwardDynamicsSolver::setGravity: the gravity (0, 0, nan)",
                   "is not finite");
  expectModelError([&] { crb.setGravity(Vector3d(kInf, 0, 0)); }, "DenseForwardDynamicsSolver::setGravity: the gravity (inf, 0, 0)",
                   "is not finite");
  EXPECT_EQ(fd.gravity(), Vector3d::Zero()) << "unchanged after a refusal";
  fd.setGravity(Vector3d(0, 0, -9.81));
  EXPECT_EQ(fd.gravity(), Vector3d(0, 0, -9.81));
}

TEST_F(SideCodes, SideConstructorsThrowModelErrorNamingTheProblem) {
  FloatingVelocity short_rates{KDL::Twist::Zero(), KDL::JntArray(2)};
  expectModelError([&] { FloatingSide(solver.sharedModel(), solver.state(), tip, short_rates); }, "FloatingSide: ",
                   "2 joint rates given for the model's 7 joints");
  FloatingVelocity nan_twist = velocity;
  nan_twist.base_twist.vel.y(kNaN);
  expectModelError([&] { FloatingSide(solver.sharedModel(), solver.state(), tip, nan_twist); }, "FloatingSide: ", "NaN or infinite");
  expectModelError([&] { FloatingSide(solver.sharedModel(), solver.state(), Contact{99, KDL::Vector::Zero()}, velocity); }, "FloatingSide: ",
                   strError(E_BAD_CONTACT));
  expectModelError([&] { FloatingSide(solver.sharedModel(), solver.state(), Contact{tip.body, KDL::Vector(0, kNaN, 0)}, velocity); },
                   "FloatingSide: ", strError(E_NOT_FINITE));
  expectModelError([&] { FloatingSide(solver.sharedModel(), solver.state(), tip, velocity, static_cast<Response>(3)); }, "FloatingSide: ",
                   "not one of FreeFloating, Grounded, JointsLocked");
  State nan_state = solver.state();
  nan_state.q(2) = kNaN;
  expectModelError([&] { FloatingSide(model, nan_state, tip, velocity); }, "FloatingSide: the state", strError(E_NOT_FINITE));
  expectModelError([&] { FloatingSide(nullptr, solver.state(), tip, velocity); }, "FloatingSide: ", "null model");
  expectModelError([&] { FloatingSide(model, solver.state(), tip, velocity, Response::FreeFloating, static_cast<ExIITMethod>(5)); },
                   "FloatingSide: ", "not one of Recursive, Dense");

  RigidBody light = box;
  light.mass = 0.0;
  expectModelError([&] { RigidBodySide(light, p_h); }, "target: ", "mass");
  RigidBody flat = box;
  flat.I_com(2, 2) = -1.0;
  expectModelError([&] { RigidBodySide(flat, p_h); }, "target: ", "positive definite");
  expectModelError([&] { RigidBodySide(box, Vector3d(kNaN, 0, 0)); }, "target: ", "finite");
}

/// A side that refuses every impulse, to reach collide()'s other paths.
class RefusingSide : public ImpactSide {
 public:
  explicit RefusingSide(const ImpactSide& like) : G_(like.G()), t_(like.contactTwistBefore()) {}
  const Matrix6d& G() const override { return G_; }
  const Vector6d& contactTwistBefore() const override { return t_; }
  Vector6d contactTwistAfter() const override { return t_; }
  Vector6d momentumBefore() const override { return Vector6d::Zero(); }
  Vector6d momentumAfter() const override { return Vector6d::Zero(); }
  double energyBefore() const override { return 0.0; }
  double energyAfter() const override { return 0.0; }
  int applyImpulse(const Vector6d&) override {
    ++calls;
    return E_NOT_FINITE;
  }
  int calls = 0;

 private:
  Matrix6d G_;
  Vector6d t_;
};

TEST_F(SideCodes, CollideReportsWhichPartRefusedAndKeepsNothing) {
  FloatingSide robot(solver.sharedModel(), solver.state(), tip, velocity);
  RigidBodySide target(box, p_h);
  const AfterState robot_before(robot);
  const Vector6d target_before = target.twistAfter();
  Impulse impulse;
  impulse.F.setConstant(kSentinel);
  ImpactFault fault = ImpactFault::None;

  // The law refuses: nothing is applied.
  const ImpactLaw bad_law{ImpactKind::PointImpact, Vector3d::UnitY(), 2.0, 0.0};
  EXPECT_NO_THROW(EXPECT_EQ(collide(robot, target, bad_law, impulse, &fault), E_BAD_ARGUMENT));
  EXPECT_EQ(fault, ImpactFault::Law);
  // Side A refuses: B never sees the impulse.
  RefusingSide refusing_robot(robot);
  EXPECT_NO_THROW(EXPECT_EQ(collide(refusing_robot, target, ImpactLaw{}, impulse, &fault), E_NOT_FINITE));
  EXPECT_EQ(fault, ImpactFault::SideA);
  EXPECT_EQ(target.twistAfter(), target_before);
  // Side B refuses: A is reset to its state before.
  RefusingSide refusing_target(target);
  EXPECT_NO_THROW(EXPECT_EQ(collide(robot, refusing_target, ImpactLaw{}, impulse, &fault), E_NOT_FINITE));
  EXPECT_EQ(fault, ImpactFault::SideB);
  EXPECT_EQ(refusing_target.calls, 1);
  EXPECT_TRUE(AfterState(robot) == robot_before);
  EXPECT_EQ(impulse.F, Vector6d::Constant(kSentinel)) << "the impulse is untouched on every error";

  // Success: the fault is reset, both sides hold their state after.
  EXPECT_EQ(collide(robot, target, ImpactLaw{}, impulse, &fault), E_NOERROR);
  EXPECT_EQ(fault, ImpactFault::None);
  EXPECT_TRUE((robot.contactTwistAfter() - target.contactTwistAfter()).norm() < 1e-12) << "captured";
  EXPECT_EQ(collide(robot, target, ImpactLaw{}, impulse), E_NOERROR) << "the fault is optional";
}

TEST(ErrorText, EveryCodeHasItsOwnText) {
  const int codes[] = {E_NOERROR,     E_SIZE_MISMATCH, E_NOT_COMPUTED,  E_NOT_FINITE, E_NOT_POSITIVE_DEFINITE,
                       E_BAD_CONTACT, E_MAX_STEPS,     E_BAD_ARGUMENT, E_STEP_UNDERFLOW, E_CANCELLED};
  std::set<std::string> texts{strError(12345)};
  for (int c : codes) texts.insert(strError(c));
  EXPECT_EQ(texts.size(), std::size(codes) + 1) << "distinct, and none is the unknown code's";
}

}  // namespace
}  // namespace kdl_space::test
