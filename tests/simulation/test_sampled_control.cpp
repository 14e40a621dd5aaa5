// The zero-order hold (runSampled): the grid of control instants and samples, the command held
// between control instants (the torques reported at the samples), the controller called once per
// instant, and against a continuous PD of the same gains (the hold's error shrinks with the period).
#include <gtest/gtest.h>

#include <cmath>

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "kdl_space/simulation/sampled_control.hpp"
#include "test_util.hpp"

namespace kdl_space {
namespace {

using test::near;
using test::urdfDir;

TEST(ControlGrid, CommonGridOfSamplesAndControls) {
  // samples every 0.05 s, control at 100 Hz: a grid of 0.01 s, a control every step, a sample every 5
  ControlGrid g = controlGrid(0.05, 0.01);
  EXPECT_EQ(g.a, 1);
  EXPECT_EQ(g.b, 5);
  EXPECT_DOUBLE_EQ(g.delta, 0.01);
  // samples every 0.01 s, control at 40 Hz (0.025 s): 5 ms grid, control every 5, sample every 2
  g = controlGrid(0.01, 0.025);
  EXPECT_EQ(g.a, 5);
  EXPECT_EQ(g.b, 2);
  EXPECT_NEAR(g.delta, 0.005, 1e-15);
  g = controlGrid(0.05, 0.0);  // no control instants
  EXPECT_EQ(g.a, 0);
  EXPECT_EQ(g.delta, 0.05);
  EXPECT_THROW(controlGrid(0.05, 0.05 * std::sqrt(2.0)), InputError);  // no fraction a / b, b <= 1000
  EXPECT_THROW(controlGrid(0.05, -1.0), InputError);
}

class SampledControl : public ::testing::Test {
 protected:
  void SetUp() override {
    model = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/spacedyn_twolink.urdf"));
    start.state = State(*model);
    start.velocity = FloatingVelocity(*model);
    start.velocity.qdot(0) = 0.3;
    start.velocity.qdot(1) = -0.2;
  }
  std::shared_ptr<const FloatingModel> model;
  SimulationState start;
};

TEST_F(SampledControl, CommandIsHeldBetweenControlInstants) {
  Simulator sim(model);
  std::vector<double> instants;
  std::vector<Eigen::VectorXd> commands;
  const SampledController pd = [&](const SimulationState& x, Eigen::VectorXd& tau) {
    tau = -5.0 * x.state.q.data - 2.0 * x.velocity.qdot.data;
    instants.push_back(x.t);
    commands.push_back(tau);
  };
  std::vector<double> t;
  std::vector<Eigen::VectorXd> applied;
  SimulationState s = start;
  ASSERT_EQ(runSampled(sim, s, 0.5, 0.01, pd, 20.0, [&](const SimulationState& x) {
              t.push_back(x.t);
              applied.push_back(x.tau.data);
            }),
            0);
  ASSERT_EQ(instants.size(), 11u);  // t = 0, 0.05, ..., 0.5
  for (std::size_t k = 0; k < instants.size(); ++k) EXPECT_NEAR(instants[k], 0.05 * static_cast<double>(k), 1e-12);
  ASSERT_EQ(t.size(), 51u);
  // The torque at each sample is the last command (the joints have no friction): held, not
  // recomputed from the state.
  for (std::size_t i = 0; i < t.size(); ++i) {
    const std::size_t k = static_cast<std::size_t>(std::floor(t[i] / 0.05 + 1e-9));
    EXPECT_TRUE(near(applied[i], commands[k], 0, 0, "held command")) << "t = " << t[i];
  }
  // The callback is gone after the run: a plain run applies no torque.
  SimulationState again = start;
  ASSERT_EQ(sim.run(again, 0.1, 0.05, [&](const SimulationState& x) { EXPECT_EQ(x.tau.data.norm(), 0.0); }), 0);
}

TEST_F(SampledControl, FastHoldApproachesTheContinuousController) {
  const auto pd = [](const SimulationState& x, Eigen::VectorXd& tau) {
    tau = -5.0 * x.state.q.data - 2.0 * x.velocity.qdot.data;
  };
  SimulationState continuous = start;
  Simulator sim(model);
  ASSERT_EQ(runSampled(sim, continuous, 1.0, 0.1, pd, 0.0, nullptr), 0);
  double previous = INFINITY;
  for (double rate : {50.0, 200.0, 800.0}) {
    SimulationState held = start;
    ASSERT_EQ(runSampled(sim, held, 1.0, 0.1, pd, rate, nullptr), 0);
    const double error = (held.state.q.data - continuous.state.q.data).norm();
    EXPECT_LT(error, 0.5 * previous) << "rate " << rate;  // first order in the period: / 4 per step here
    previous = error;
  }
  EXPECT_LT(previous, 2e-3);
}

TEST_F(SampledControl, RateGainBeyondTheHoldsBoundIsWarnedAndDoesDiverge) {
  // Each joint's rate gain set to b m_j / dt, m_j = 1 / (H*^-1)_jj from the free-floating solver
  // (the check reads the simulator's dynamics instead): b = 0.5 is stable and quiet, b = 2.5 is
  // past the zero-order hold's bound kd dt / m < 2 on every joint and diverges.
  FreeFloatingSolver solver(model);
  ASSERT_EQ(solver.compute(start.state), 0);
  const Eigen::VectorXd m = solver.H_star().data.inverse().diagonal().cwiseInverse();
  const double rate = 100.0, dt = 1.0 / rate;
  for (double b : {0.5, 2.5}) {
    const Eigen::VectorXd kd = b * m / dt;
    int calls = 0;
    const SampledController damper = [&](const SimulationState& x, Eigen::VectorXd& tau) {
      ++calls;
      tau = -kd.cwiseProduct(x.velocity.qdot.data);
    };
    SimulationOptions unlimited;
    unlimited.effort_limits = false;  // a saturated torque would turn the divergence into a bounded ringing
    Simulator sim(model, unlimited);
    std::vector<Diagnostic> warnings;
    ASSERT_EQ(sampledGainWarnings(sim, start, damper, rate, warnings), 0);
    EXPECT_EQ(calls, 4);  // two a joint
    SimulationState s = start;
    double fastest = 0.0;  // the largest joint rate over the run
    const int rc = runSampled(sim, s, 1.0, 0.01, damper, rate, [&](const SimulationState& x) {
      if (x.velocity.qdot.data.allFinite()) fastest = std::max(fastest, x.velocity.qdot.data.norm());
    });
    if (b < 1.0) {
      EXPECT_TRUE(warnings.empty()) << warnings.front().message;
      ASSERT_EQ(rc, 0);
      EXPECT_LE(fastest, start.velocity.qdot.data.norm());                             // never grew
      EXPECT_LT(s.velocity.qdot.data.norm(), 0.1 * start.velocity.qdot.data.norm());  // damped out
    } else {
      ASSERT_EQ(warnings.size(), 2u);
      for (unsigned int j = 0; j < 2; ++j) {
        EXPECT_EQ(warnings[j].kind, "sampled_gain_unstable");
        EXPECT_EQ(warnings[j].element, model->jointNames()[j]);
        EXPECT_NE(warnings[j].message.find("above 2: unstable"), std::string::npos) << warnings[j].message;
      }
      // |1 - b| = 1.5 a period: a hundredfold within some 12 periods (then the arm's nonlinear
      // dynamics at such rates take over, or the run fails)
      EXPECT_TRUE(rc != 0 || fastest > 100.0 * start.velocity.qdot.data.norm()) << "rc " << rc << ", max |qdot| " << fastest;
    }
  }
  // A continuous controller (no rate) has no hold: nothing to check, not even a call.
  int calls = 0;
  std::vector<Diagnostic> none;
  Simulator sim(model);
  ASSERT_EQ(sampledGainWarnings(sim, start, [&](const SimulationState&, Eigen::VectorXd& tau) { ++calls, tau.setZero(); },
                                0.0, none),
            0);
  EXPECT_EQ(calls, 0);
  EXPECT_TRUE(none.empty());
}

TEST_F(SampledControl, WithoutAControllerTheRateIsNotUsedAndTheRunIsPlain) {
  Simulator sim(model);
  SimulationState sampled = start, plain = start;
  int seen = 0;
  ASSERT_EQ(runSampled(sim, sampled, 0.5, 0.05, nullptr, 20.0, [&](const SimulationState&) { ++seen; }), 0);
  ASSERT_EQ(sim.run(plain, 0.5, 0.05, nullptr), 0);
  EXPECT_EQ(seen, 11);
  EXPECT_EQ(sampled.state.q.data, plain.state.q.data);
}

TEST_F(SampledControl, ControllerOfTheWrongSizeEndsTheRun) {
  Simulator sim(model);
  SimulationState s = start;
  const int rc = runSampled(sim, s, 0.5, 0.05, [](const SimulationState&, Eigen::VectorXd& tau) { tau.resize(5); }, 20.0,
                            nullptr);
  EXPECT_EQ(rc, E_SIZE_MISMATCH);
  EXPECT_LT(s.t, 0.5);
}

TEST_F(SampledControl, CancelPollIsAskedBeforeEveryStepAndStopsTheRunThere) {
  SimulationOptions o;
  o.integrator = Integrator::RK4;
  o.step = 1e-3;
  Simulator sim(model, o);
  // A single output at the end: only the poll can stop the run before it.
  long polls = 0;
  sim.setCancelPoll([&] { return ++polls > 100; });
  SimulationState s = start;
  int outputs = 0;
  const int rc = runSampled(sim, s, 10.0, 10.0, nullptr, 0.0, [&](const SimulationState&) { ++outputs; });
  EXPECT_EQ(rc, E_CANCELLED);
  EXPECT_STREQ(strError(rc), "cancelled by the caller");
  EXPECT_EQ(polls, 101);
  EXPECT_EQ(sim.stats().accepted_steps, 100) << "a poll before every step";
  EXPECT_NEAR(s.t, 0.1, 1e-12) << "s at the last step accepted";
  EXPECT_TRUE(s.state.q.data.allFinite());
  EXPECT_EQ(outputs, 1) << "the start only";

  // A poll that throws: the exception propagates (Python's KeyboardInterrupt), the run stops.
  struct Stop {};
  sim.setCancelPoll([&] {
    if (++polls > 150) throw Stop{};
    return false;
  });
  s = start;
  EXPECT_THROW(runSampled(sim, s, 10.0, 10.0, nullptr, 0.0, nullptr), Stop);

  // Cleared: the run goes to its end.
  sim.setCancelPoll(nullptr);
  s = start;
  EXPECT_EQ(runSampled(sim, s, 0.5, 0.5, nullptr, 0.0, nullptr), E_NOERROR);
  EXPECT_EQ(s.t, 0.5);
}

}  // namespace
}  // namespace kdl_space
