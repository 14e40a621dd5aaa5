// planCapture against dense grids: each grid point's configuration built from the public API as
// capture_plan.hpp defines the chart (FreeRigidMotion for the capture instant, the contact frame
// rolled about its z and solveInverseKinematics, selfMotionJoints), its capture by solveCapture and
// the limits checked here; the planner's optimum must be no worse than the grid's best, feasible,
// and reproduce its own numbers through solveCapture. Also the refusals.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "kdl_space/algorithm/inverse_kinematics.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/planning/capture_plan.hpp"
#include "kdl_space/simulation/rigid_motion.hpp"
#include "kdl_space/study/study.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

const std::string kDefault = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/tumbling_box_capture.yaml";
const std::string kArm6 = dataDir() + "/scenarios/arm6_reach_capture.json";
constexpr double kHalfPi = 1.5707963267948966;

/// The chart of capture_plan.hpp, rebuilt from the public API: the joints, the target at t, and
/// the grasp frame the hand is asked to hold; false where it cannot be reached.
struct Configuration {
  std::vector<double> q;
  RigidTarget target;
  KDL::Frame goal;
};

bool configure(const Scenario& sc, double s, double psi, double t, Configuration& c) {
  const FloatingSystem& robot = sc.capture.robot;
  const RigidTarget& target0 = std::get<RigidTarget>(sc.capture.target);
  const KDL::Frame H0 = contactFrame(*robot.model, robot.state, robot.contact);
  c.target = target0;
  KDL::Frame grasp = H0;
  if (t > 0.0) {
    // One motion per target: at(t) is a function of t alone (and extends its grid as asked).
    static std::map<std::string, std::unique_ptr<FreeRigidMotion>> tumbles;  // by scenario file
    std::unique_ptr<FreeRigidMotion>& tumble = tumbles[sc.file];
    if (!tumble) tumble = std::make_unique<FreeRigidMotion>(target0);
    EXPECT_EQ(tumble->at(t, c.target), 0);
    grasp = c.target.pose * target0.pose.Inverse() * H0;
  }
  c.goal = grasp * KDL::Frame(KDL::Rotation::RotZ(psi));
  Scenario moved = sc;
  if (psi != 0.0 || t != 0.0) {
    IkOptions o;
    o.preferred = robot.state.q;
    o.restarts = 0;
    try {
      moved.capture.robot.state.q = solveInverseKinematics(*robot.model, robot.state, robot.contact, c.goal, o).q;
    } catch (const InputError&) {
      return false;
    }
  }
  c.q.assign(moved.capture.robot.state.q.data.data(), moved.capture.robot.state.q.data.data() + robot.model->nj());
  if (s != 0.0) {
    try {
      c.q = selfMotionJoints(moved, s);
    } catch (const InputError&) {
      return false;
    }
  }
  return true;
}

/// |w| of the base after the capture at `c` by solveCapture; NaN outside the joints' position or
/// velocity limits (or where the capture cannot be computed).
double baseRate(const Scenario& sc, const Configuration& c, CaptureResult* out = nullptr) {
  CaptureProblem p = sc.capture;
  const FloatingModel& model = *p.robot.model;
  for (unsigned int j = 0; j < model.nj(); ++j) p.robot.state.q(j) = c.q[j];
  p.target = c.target;
  CaptureResult r;
  try {
    r = solveCapture(p);
  } catch (const Error&) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  if (out) *out = r;
  for (unsigned int j = 0; j < model.nj(); ++j) {
    const JointProperties& lim = model.jointProperties()[j];
    if (c.q[j] < lim.lower || c.q[j] > lim.upper || std::abs(r.robot.after.qdot(j)) > lim.velocity)
      return std::numeric_limits<double>::quiet_NaN();
  }
  return toEigen(r.robot.after.base_twist).tail<3>().norm();
}

struct GridBest {
  double value = std::numeric_limits<double>::infinity();
  int feasible = 0;
};

double at(const PlanRange& r, int i) { return i == 40 ? r.upper : r.lower + (r.upper - r.lower) * i / 40.0; }

/// The smallest base_rate over a 41 x 41 grid of two parameters (the third fixed).
template <typename Point>
GridBest grid(const Scenario& sc, const PlanRange& a, const PlanRange& b, Point point) {
  GridBest best;
  for (int i = 0; i <= 40; ++i)
    for (int k = 0; k <= 40; ++k) {
      Configuration c;
      if (!point(at(a, i), at(b, k), c)) continue;
      const double v = baseRate(sc, c);
      if (std::isnan(v)) continue;
      ++best.feasible;
      best.value = std::min(best.value, v);
    }
  return best;
}

double parameter(const CapturePlan& plan, const std::string& name) {
  for (const auto& [n, v] : plan.parameters)
    if (n == name) return v;
  return 0.0;
}

/// The plan's joints put the hand at the grasp its parameters name, inside the limits, and
/// reproduce its base_rate through solveCapture.
void expectReproduced(const Scenario& sc, const CapturePlan& plan) {
  Configuration c;
  ASSERT_TRUE(configure(sc, 0.0, parameter(plan, "wrist_roll"), parameter(plan, "timing"), c));
  const FloatingSystem& robot = sc.capture.robot;
  State at_plan = robot.state;
  for (unsigned int j = 0; j < robot.model->nj(); ++j) at_plan.q(j) = plan.q[j];
  const KDL::Frame hand = contactFrame(*robot.model, at_plan, robot.contact);
  EXPECT_LE((toEigen(hand.p) - toEigen(c.goal.p)).norm(), 1e-9);
  const KDL::Rotation E = c.goal.M.Inverse() * hand.M;
  EXPECT_LE((Vector3d(E(2, 1) - E(1, 2), E(0, 2) - E(2, 0), E(1, 0) - E(0, 1))).norm(), 2e-9);
  c.q = plan.q;
  const double v = baseRate(sc, c);
  ASSERT_FALSE(std::isnan(v)) << "the plan is outside the limits";
  EXPECT_NEAR(v, plan.optimum.base_rate, 1e-12 * plan.optimum.base_rate);
}

/// A redundant arm's plan over its self-motion and wrist roll against the 41 x 41 grid of the same box.
void expectNoWorseThanTheGrid(const std::string& scenario, const PlanOptions& o) {
  const Scenario sc = loadScenario(scenario);
  const auto start = std::chrono::steady_clock::now();
  const CapturePlan plan = planCapture(sc, o);
  const double planning = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(plan.optimum.feasible);
  ASSERT_EQ(plan.searched, (std::vector<std::string>{"self_motion", "wrist_roll"}));
  const GridBest best = grid(sc, *o.self_motion, o.wrist_roll, [&](double s, double psi, Configuration& c) {
    return configure(sc, s, psi, 0.0, c);
  });
  ASSERT_GT(best.feasible, 100);
  EXPECT_LE(plan.optimum.objective, best.value) << "planning took " << planning << " s";
  // A plan that did nothing would report the nominal: the grid finds better, so must the planner.
  EXPECT_LT(best.value, plan.nominal.objective);
  expectReproduced(sc, plan);
  // The nominal is the scenario as written: its capture by solveCapture.
  Configuration nominal;
  ASSERT_TRUE(configure(sc, 0.0, 0.0, 0.0, nominal));
  CaptureResult r;
  baseRate(sc, nominal, &r);
  EXPECT_EQ(plan.nominal.base_rate, toEigen(r.robot.after.base_twist).tail<3>().norm());
}

TEST(CapturePlan, DefaultArmNoWorseThanA41x41GridOfSelfMotionAndWristRoll) {
  // A box whose optimum lies inside it (in the default box it is a corner, which a scan holds).
  PlanOptions o;
  o.self_motion = PlanRange{-2.0, 2.0};
  o.wrist_roll = PlanRange{-2 * kHalfPi, 2 * kHalfPi};
  expectNoWorseThanTheGrid(kDefault, o);
}

TEST(CapturePlan, SecondRedundantArmNoWorseThanA41x41GridOfSelfMotionAndWristRoll) {
  // tests/data's S-R-S arm (axes z y z y z y z, unlike the default arm's), in the default box,
  // where its optimum is inside (s = -0.59, roll = 0.16).
  PlanOptions o;
  o.self_motion = PlanRange{-1.0, 1.0};
  expectNoWorseThanTheGrid(dataDir() + "/scenarios/srs_arm7_capture.yaml", o);
}

TEST(CapturePlan, SixJointArmNoWorseThanA41x41GridOfWristRollAndCaptureInstant) {
  const Scenario sc = loadScenario(kArm6);
  PlanOptions o;
  o.timing = PlanRange{0.0, 2.0};
  const CapturePlan plan = planCapture(sc, o);
  ASSERT_EQ(plan.searched, (std::vector<std::string>{"wrist_roll", "timing"}));
  const GridBest best = grid(sc, PlanRange{-kHalfPi, kHalfPi}, o.timing, [&](double psi, double t, Configuration& c) {
    return configure(sc, 0.0, psi, t, c);
  });
  ASSERT_GT(best.feasible, 100);
  EXPECT_LE(plan.optimum.objective, best.value);
  EXPECT_LT(best.value, plan.nominal.objective);
  expectReproduced(sc, plan);
}

TEST(CapturePlan, AWeightedSumIsTheSumOfItsTerms) {
  const Scenario sc = loadScenario(kArm6);
  PlanOptions o;
  o.weights = {{"base_rate", 1.0}, {"impulse", 0.01}, {"joint_rate_jump", 0.1}};
  o.scan = 9;
  const CapturePlan plan = planCapture(sc, o);
  const PlanTerms& t = plan.optimum;
  EXPECT_NEAR(t.objective, t.base_rate + 0.01 * t.impulse + 0.1 * t.joint_rate_jump, 1e-15 * t.objective);
  EXPECT_LE(t.objective, plan.nominal.objective);
  // The impulse term is |f| of the capture's impulse, by solveCapture at the plan's joints.
  Configuration c;
  ASSERT_TRUE(configure(sc, 0.0, parameter(plan, "wrist_roll"), 0.0, c));
  c.q = plan.q;
  CaptureResult r;
  baseRate(sc, c, &r);
  EXPECT_NEAR(t.impulse, r.impulse.F.head<3>().norm(), 1e-12 * t.impulse);
}

TEST(CapturePlan, RefusesWhatItCannotPlan) {
  const Scenario arm6 = loadScenario(kArm6);
  const auto refused = [&](const PlanOptions& o, const std::string& start) {
    try {
      planCapture(arm6, o);
      ADD_FAILURE() << "accepted; expected " << start;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(start, 0), 0u) << e.what();
    }
  };
  PlanOptions o;
  o.weights = {{"base_spin", 1.0}};
  refused(o, "objective: unknown term 'base_spin'");
  o.weights = {{"impulse", -1.0}};
  refused(o, "objective: the weight of impulse");
  o = PlanOptions{};
  o.wrist_roll = PlanRange{};
  refused(o, "plan: nothing to plan");
  o = PlanOptions{};
  o.self_motion = PlanRange{-1.0, 1.0};  // a six-joint arm has no self-motion
  refused(o, "self_motion: cannot be searched");
  o = PlanOptions{};
  o.timing = PlanRange{-1.0, 0.0};
  refused(o, "timing: must be >= 0");
  const Scenario plain = loadScenario(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/base_attitude_control.yaml");
  EXPECT_THROW(planCapture(plain), InputError);
}

}  // namespace
}  // namespace kdl_space::test
