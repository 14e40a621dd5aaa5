// runCaptureOperation against its parts called by hand (the approach, solveCapture, the simulator
// from the scenario), the conservation laws across the capture, the observer against the kept
// samples, the options (no motion, no kept samples, a controller that adds nothing), and a failed
// approach's partial result. No expected value is the operation's own output.
#include <gtest/gtest.h>

#include <cmath>

#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/simulation/sampled_control.hpp"
#include "test_util.hpp"

namespace kdl_space {
namespace {

using test::near;
using test::urdfDir;

std::string scenarioPath(const std::string& name) { return std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/" + name; }

OperationOptions shortRun(double duration = 0.5) {
  OperationOptions o;
  o.duration = duration;
  return o;
}

TEST(CaptureOperation, CaptureIsSolveCaptureAndTheMotionStartsFromItsVelocities) {
  const Scenario sc = loadScenario(scenarioPath("tumbling_box_capture.yaml"));
  const OperationResult r = runCaptureOperation(sc, shortRun());
  const CaptureResult by_hand = solveCapture(sc.capture);
  ASSERT_TRUE(r.capture);
  EXPECT_EQ(r.capture->impulse.F, by_hand.impulse.F);
  EXPECT_EQ(r.capture->robot.after.qdot.data, by_hand.robot.after.qdot.data);
  // A rigid target captured rigidly rides as a payload: its mass joins the robot's.
  EXPECT_TRUE(r.payload_attached);
  EXPECT_FALSE(r.joined);
  const RigidTarget& box = std::get<RigidTarget>(sc.capture.target);
  double robot_mass = 0.0, system_mass = 0.0;
  for (const auto& b : sc.capture.robot.model->bodies()) robot_mass += b.mass;
  for (const auto& b : r.model->bodies()) system_mass += b.mass;
  EXPECT_NEAR(system_mass, robot_mass + box.mass, 1e-9 * system_mass);
  // The first sample is the state right after the capture: the robot's joint rates after it.
  ASSERT_FALSE(r.samples.empty());
  const MotionSample& first = r.samples.front();
  EXPECT_EQ(first.t, 0.0);
  EXPECT_EQ(first.phase, Phase::Post);
  EXPECT_TRUE(near(first.qd, by_hand.robot.after.qdot.data, 1e-12, 1e-14, "qdot after"));
  // Momentum: the system after the capture (robot and payload, swept by the simulator) carries
  // what both sides had before the impact, and keeps it (no external force).
  EXPECT_TRUE(near(first.h, by_hand.momentum_before, 1e-9, 1e-9, "momentum after the capture"));
  EXPECT_TRUE(near(r.record.last.h, by_hand.momentum_before, 1e-9, 1e-9, "momentum at the end"));
  EXPECT_NEAR(r.record.last.t, 0.5, 1e-12);
  EXPECT_EQ(r.end.t, r.record.last.t);
}

TEST(CaptureOperation, ObserverSeesTheKeptSamplesAndTheRecordTheirAggregates) {
  const Scenario sc = loadScenario(scenarioPath("tumbling_box_capture.yaml"));
  OperationOptions o = shortRun();
  std::vector<MotionSample> seen;
  o.observer = [&](const OperationResult& so_far, const MotionSample& x) {
    EXPECT_EQ(so_far.model->nj(), static_cast<unsigned int>(x.q.size()));
    seen.push_back(x);
  };
  const OperationResult r = runCaptureOperation(sc, o);
  ASSERT_EQ(seen.size(), r.samples.size());
  EXPECT_EQ(static_cast<long>(seen.size()), r.record.samples);
  double dP = 0.0, dT = 0.0, bL = 0.0;
  for (std::size_t i = 0; i < seen.size(); ++i) {
    EXPECT_EQ(seen[i].t, r.samples[i].t);
    EXPECT_EQ(seen[i].q, r.samples[i].q);
    dP = std::max(dP, (seen[i].h.head<3>() - seen[0].h.head<3>()).norm());
    dT = std::max(dT, std::abs(seen[i].T - seen[0].T));
    bL = std::max(bL, (seen[i].h - seen[0].h - seen[i].impulse).tail<3>().norm());
  }
  EXPECT_EQ(r.record.max_linear_momentum_change, dP);
  EXPECT_EQ(r.record.max_energy_change, dT);
  EXPECT_EQ(r.record.balance_angular, bL);
  // Without kept samples: the same record, nothing stored.
  o.observer = nullptr;
  o.keep_samples = false;
  const OperationResult lean = runCaptureOperation(sc, o);
  EXPECT_TRUE(lean.samples.empty());
  EXPECT_EQ(lean.record.samples, r.record.samples);
  EXPECT_EQ(lean.record.last.q, r.record.last.q);
  EXPECT_EQ(lean.record.max_linear_momentum_change, r.record.max_linear_momentum_change);
}

TEST(CaptureOperation, MotionIsTheScenarioSimulatorRunByHand) {
  const Scenario sc = loadScenario(scenarioPath("tumbling_box_capture.yaml"));
  const OperationResult r = runCaptureOperation(sc, shortRun());
  // By hand: the capture, the payload attached, the scenario's simulator from the state after.
  const CaptureResult c = solveCapture(sc.capture);
  const std::shared_ptr<const FloatingModel> model = attachTarget(sc.capture, c);
  std::unique_ptr<Simulator> sim = makeSimulator(sc, model, false);
  SimulationState s;
  s.state = sc.capture.robot.state;
  s.velocity = c.robot.after;
  ASSERT_EQ(sim->engageBrakes(s), 0);
  ASSERT_EQ(sim->run(s, 0.5, sc.simulation.output_step, nullptr), 0);
  EXPECT_TRUE(near(r.end.state.q.data, s.state.q.data, 1e-12, 1e-14, "q at the end"));
  EXPECT_TRUE(near(toEigen(r.end.velocity.base_twist), toEigen(s.velocity.base_twist), 1e-12, 1e-14, "base twist"));
  EXPECT_EQ(r.record.stats.accepted_steps, sim->stats().accepted_steps);
}

TEST(CaptureOperation, WithoutMotionItStopsAtTheCapture) {
  const Scenario sc = loadScenario(scenarioPath("robot_to_robot_capture.yaml"));
  OperationOptions o;
  o.motion = false;
  const OperationResult r = runCaptureOperation(sc, o);
  ASSERT_TRUE(r.capture);
  ASSERT_TRUE(r.joined);  // a free-floating target captured rigidly joins the robot's tree
  EXPECT_EQ(r.model, r.joined->model);
  EXPECT_EQ(r.model->nj(), sc.capture.robot.model->nj() + std::get<FloatingSystem>(sc.capture.target).model->nj());
  EXPECT_TRUE(r.samples.empty());
  EXPECT_EQ(r.record.samples, 0);
}

TEST(CaptureOperation, ApproachEndsAtTheContactInstantAndTheMotionGoesOnFromThere) {
  const Scenario sc = loadScenario(scenarioPath("approach_tumbling_box.yaml"));
  const OperationResult r = runCaptureOperation(sc, shortRun());
  ASSERT_TRUE(r.approach);
  ASSERT_TRUE(r.approach->record.reached);
  ASSERT_FALSE(r.approach_samples.empty());
  EXPECT_EQ(r.approach_samples.back().phase, Phase::Capture);
  EXPECT_EQ(r.approach_samples.front().phase, Phase::Approach);
  EXPECT_EQ(r.t_capture, r.approach_samples.back().t);
  EXPECT_EQ(r.samples.front().t, r.t_capture);
  EXPECT_NEAR(r.end.t, r.t_capture + 0.5, 1e-9);
  // The capture is solved at the states of the contact instant, which the approach reached.
  const CaptureResult at_contact = solveCapture(r.at_contact);
  EXPECT_EQ(r.capture->impulse.F, at_contact.impulse.F);
  EXPECT_LE(r.approach->record.final_distance, sc.approach->position_tolerance);
  EXPECT_TRUE(near(r.approach_samples.back().q, r.at_contact.robot.state.q.data, 0, 0, "q at contact"));
}

TEST(CaptureOperation, AnApproachThatNeverReachesFailsWithWhatItDid) {
  Scenario sc = loadScenario(scenarioPath("approach_tumbling_box.yaml"));
  sc.approach->max_duration = 0.3;
  try {
    runCaptureOperation(sc, shortRun());
    FAIL() << "the approach cannot reach the grasp point in 0.3 s";
  } catch (const OperationError& e) {
    EXPECT_NE(std::string(e.what()).find("approach: the hand never reached the grasp point in 0.3 s"), std::string::npos)
        << e.what();
    EXPECT_EQ(e.code(), E_NOERROR);
    ASSERT_TRUE(e.partial());
    ASSERT_TRUE(e.partial()->approach);
    EXPECT_FALSE(e.partial()->approach->record.reached);
    EXPECT_GE(e.partial()->approach_samples.size(), 6u);  // 0.3 s at 0.05 s
    EXPECT_FALSE(e.partial()->capture);
  }
}

TEST(CaptureOperation, ControllerOfZeroTorqueChangesNothingAndTheRunsAreEqual) {
  const Scenario sc = loadScenario(scenarioPath("tumbling_box_capture.yaml"));
  const OperationResult plain = runCaptureOperation(sc, shortRun());
  for (double rate : {0.0, 20.0}) {
    OperationOptions o = shortRun();
    int calls = 0;
    o.controller = [&](const SimulationState&, Eigen::VectorXd& tau) { tau.setZero(), ++calls; };
    o.control_rate = rate;
    o.check_sampled_gains = false;  // the calls of the run alone (the gains' probe: test_motion_warnings.cpp)
    const OperationResult r = runCaptureOperation(sc, o);
    EXPECT_GT(calls, 0);
    EXPECT_TRUE(near(r.end.state.q.data, plain.end.state.q.data, 1e-12, 1e-14, "q with a zero controller"));
    if (rate > 0.0) EXPECT_EQ(calls, 1 + static_cast<int>(std::lround(0.5 * rate)));  // t0, then every 1/rate
  }
}

TEST(CaptureOperation, RunBeyondTheStepBudgetIsRefusedBeforeItStarts) {
  Scenario sc = loadScenario(scenarioPath("tumbling_box_capture.yaml"));
  sc.simulation.options.max_steps = 10;
  bool observed = false;
  OperationOptions o = shortRun(1.0);
  o.observer = [&](const OperationResult&, const MotionSample&) { observed = true; };
  try {
    runCaptureOperation(sc, o);
    FAIL() << "1 s at output steps of 0.05 s needs 20 steps";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("more than simulation.max_steps = 10"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(observed);
}

TEST(CaptureOperation, CancelledRunStopsInTheApproachOrTheMotionWithWhatItDid) {
  const Scenario sc = loadScenario(scenarioPath("approach_tumbling_box.yaml"));
  // Cancelled in the approach: no step of the motion is taken.
  long polls = 0;
  OperationOptions o = shortRun(5.0);
  o.cancelled = [&] { return ++polls > 20; };
  try {
    runCaptureOperation(sc, o);
    FAIL() << "cancelled after 20 steps";
  } catch (const OperationError& e) {
    EXPECT_EQ(e.code(), E_CANCELLED);
    EXPECT_NE(std::string(e.what()).find("the approach was cancelled at t = "), std::string::npos) << e.what();
    ASSERT_TRUE(e.partial());
    EXPECT_FALSE(e.partial()->capture);
  }
  // Cancelled in the motion after the capture: the polls of the approach, then some of the motion.
  polls = 0;
  OperationOptions plain = shortRun(5.0);
  long approach_polls = 0;
  plain.motion = false;
  plain.cancelled = [&] { return ++approach_polls < 0; };
  const OperationResult reached = runCaptureOperation(sc, plain);
  o.cancelled = [&] { return ++polls > approach_polls + 10; };
  try {
    runCaptureOperation(sc, o);
    FAIL() << "cancelled 10 steps into the motion";
  } catch (const OperationError& e) {
    EXPECT_EQ(e.code(), E_CANCELLED);
    EXPECT_NE(std::string(e.what()).find("the simulation was cancelled at t = "), std::string::npos) << e.what();
    ASSERT_TRUE(e.partial() && e.partial()->capture);
    EXPECT_GT(e.partial()->end.t, reached.t_capture);
    EXPECT_LT(e.partial()->end.t, reached.t_capture + 5.0);
  }
}

TEST(CaptureOperation, OutputRowsAreEstimatedFromTheDurationsAndTheOutputStep) {
  Scenario sc = loadScenario(scenarioPath("approach_tumbling_box.yaml"));
  // By hand: each run gives its start, every output step after it, and its end.
  sc.simulation.output_step = 0.05;
  sc.approach->max_duration = 30.0;
  OperationOptions o = shortRun(20.0);
  EXPECT_EQ(estimatedOutputRows(sc, o), (600.0 + 1.0) + (400.0 + 1.0));
  o.duration = 20.01;  // a last, shorter interval
  EXPECT_EQ(estimatedOutputRows(sc, o), (600.0 + 1.0) + (401.0 + 1.0));
  o.approach = false;
  EXPECT_EQ(estimatedOutputRows(sc, o), 401.0 + 1.0);
  o.output_step = 1e-6, o.duration = 1e5;  // beyond any integer row count a vector could hold
  EXPECT_EQ(estimatedOutputRows(sc, o), 1e11 + 1.0);
  o.motion = false;
  EXPECT_EQ(estimatedOutputRows(sc, o), 0.0);
}

}  // namespace
}  // namespace kdl_space
