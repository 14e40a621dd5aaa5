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

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/algorithm/inverse_kinematics.hpp"
#include "kdl_space/algorithm/momentum.hpp"
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
  bool closing = false;      ///< the rates before are `velocity` (closingRates), not the scenario's
  FloatingVelocity velocity;
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

/// The grasp point's twist on a rigid target (v at p; w), world frame.
Vector6d pointTwist(const RigidTarget& target, const Vector3d& p) {
  Vector6d t = target.twist;
  t.head<3>() += target.twist.tail<3>().cross(p - toEigen(target.pose * toKDL(target.com)));
  return t;
}

/// The chart's rates before the capture at closing speed `speed` (capture_plan.hpp), rebuilt
/// here: the hand's twist the grasp point's plus speed along the contact frame's z; the joint
/// rates J*^+ (t_h - R_h M_a^-1 (P_g; L_g)) by an SVD's least squares; the base's twist from the
/// scenario's momentum. False where the arm cannot give that twist.
bool closingRates(const Scenario& sc, Configuration& c, double speed) {
  const FloatingSystem& robot = sc.capture.robot;
  const unsigned int n = robot.model->nj();
  FreeFloatingSolver at_scenario(robot.model), here(robot.model);
  Vector6d PL_g;
  EXPECT_EQ(at_scenario.compute(robot.state), 0);
  EXPECT_EQ(at_scenario.momentum(robot.velocity.base_twist, robot.velocity.qdot, PL_g), 0);
  State s = robot.state;
  for (unsigned int j = 0; j < n; ++j) s.q(j) = c.q[j];
  EXPECT_EQ(here.compute(s), 0);
  KDL::Jacobian J_star(n);
  KDL::Twist still;
  EXPECT_EQ(here.J_star(robot.contact, J_star), 0);
  EXPECT_EQ(here.handTwist(robot.contact, KDL::JntArray(n), PL_g, still), 0);
  const KDL::Frame hand = contactFrame(*robot.model, s, robot.contact);
  Vector6d t_h = pointTwist(c.target, toEigen(hand.p));
  t_h.head<3>() += speed * toEigen(hand.M.UnitZ());
  const Vector6d b = t_h - toEigen(still);
  const Eigen::MatrixXd A = J_star.data;
  const Eigen::VectorXd qdot = A.jacobiSvd(Eigen::ComputeThinU | Eigen::ComputeThinV).solve(b);
  if ((A * qdot - b).norm() > 1e-9 * std::max(1.0, b.norm())) return false;
  c.velocity.qdot = KDL::JntArray(n);
  c.velocity.qdot.data = qdot;
  EXPECT_EQ(here.baseTwist(PL_g, c.velocity.qdot, c.velocity.base_twist), 0);
  c.closing = true;
  return true;
}

/// |w| of the base after the capture at `c` by solveCapture; NaN outside the joints' position or
/// velocity limits (or where the capture cannot be computed).
double baseRate(const Scenario& sc, const Configuration& c, CaptureResult* out = nullptr) {
  CaptureProblem p = sc.capture;
  const FloatingModel& model = *p.robot.model;
  for (unsigned int j = 0; j < model.nj(); ++j) p.robot.state.q(j) = c.q[j];
  if (c.closing) p.robot.velocity = c.velocity;
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
    if (c.q[j] < lim.lower || c.q[j] > lim.upper || std::abs(r.robot.after.qdot(j)) > lim.velocity ||
        (c.closing && std::abs(p.robot.velocity.qdot(j)) > lim.velocity))
      return std::numeric_limits<double>::quiet_NaN();
  }
  return toEigen(r.robot.after.base_twist).tail<3>().norm();
}

struct GridBest {
  double value = std::numeric_limits<double>::infinity();
  int feasible = 0;
};

double at(const PlanRange& r, int i) { return i == 40 ? r.upper : r.lower + (r.upper - r.lower) * i / 40.0; }

/// The smallest base_rate over a 41 x 41 grid of the wrist roll and the closing speed (the
/// self-motion 0, the capture now): one inverse kinematics per roll, the closing rates per speed.
GridBest rollAndClosingGrid(const Scenario& sc, const PlanRange& roll, const PlanRange& closing) {
  GridBest best;
  for (int i = 0; i <= 40; ++i) {
    Configuration placed;
    if (!configure(sc, 0.0, at(roll, i), 0.0, placed)) continue;
    for (int k = 0; k <= 40; ++k) {
      Configuration c = placed;
      if (!closingRates(sc, c, at(closing, k))) continue;
      const double v = baseRate(sc, c);
      if (std::isnan(v)) continue;
      ++best.feasible;
      best.value = std::min(best.value, v);
    }
  }
  return best;
}

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

TEST(CapturePlan, SixJointArmNoWorseThanA41x41GridOfWristRollAndClosingSpeed) {
  const Scenario sc = loadScenario(kArm6);
  PlanOptions o;
  o.closing_speed = PlanRange{0.0, 0.1};
  const CapturePlan plan = planCapture(sc, o);
  ASSERT_EQ(plan.searched, (std::vector<std::string>{"wrist_roll", "closing_speed"}));
  const GridBest best = rollAndClosingGrid(sc, o.wrist_roll, *o.closing_speed);
  ASSERT_GT(best.feasible, 100);
  EXPECT_LE(plan.optimum.objective, best.value);
  // Its numbers through solveCapture, with the joints and the rates before that it reports.
  Configuration c;
  ASSERT_TRUE(configure(sc, 0.0, parameter(plan, "wrist_roll"), 0.0, c));
  c.q = plan.q;
  c.closing = true;
  c.velocity = FloatingVelocity(*sc.capture.robot.model);
  c.velocity.qdot.data = Eigen::Map<const Eigen::VectorXd>(plan.qdot_before.data(), 6);
  c.velocity.base_twist = toTwist(Eigen::Map<const Vector6d>(plan.base_twist_before.data()));
  EXPECT_NEAR(baseRate(sc, c), plan.optimum.base_rate, 1e-12 * plan.optimum.base_rate);
}

TEST(CapturePlan, ClosingRatesGiveTheHandTheGraspPointsTwistWithTheScenariosMomentum) {
  // The redundant arm, all four parameters: a scan of 6 points a parameter (scan_limit 1300;
  // the default gives 10, at 8x the time), and still no worse than a 41 x 41 grid of a slice of
  // its box (self-motion 0, capture now).
  const Scenario sc = loadScenario(dataDir() + "/scenarios/srs_arm7_capture.yaml");
  PlanOptions o;
  o.scan_limit = 1300;
  o.self_motion = PlanRange{-1.0, 1.0};
  o.timing = PlanRange{0.0, 2.0};
  o.closing_speed = PlanRange{0.01, 0.08};
  const CapturePlan plan = planCapture(sc, o);
  ASSERT_EQ(plan.searched, (std::vector<std::string>{"self_motion", "wrist_roll", "timing", "closing_speed"}));
  EXPECT_LE(plan.evaluations, o.scan_limit + o.polish_starts * o.polish_evaluations + 2);
  const GridBest best = rollAndClosingGrid(sc, o.wrist_roll, *o.closing_speed);
  ASSERT_GT(best.feasible, 100);
  EXPECT_LE(plan.optimum.objective, best.value);

  // Its rates before, by the second route (MomentumSolver's sweep, not J*): the hand moves with the
  // grasp point plus the closing speed along its z, and the system's momentum is the scenario's.
  const FloatingSystem& robot = sc.capture.robot;
  const unsigned int n = robot.model->nj();
  MomentumSolver second(robot.model);
  Kinematics kin(*robot.model);
  ASSERT_EQ(forwardKinematics(*robot.model, robot.state, kin), 0);
  ASSERT_EQ(second.compute(kin, robot.velocity), 0);
  const Vector6d scenario_momentum = second.momentumAtCoM();  // (P_g; L_g): the chart holds it
  State s = robot.state;
  for (unsigned int j = 0; j < n; ++j) s.q(j) = plan.q[j];
  FloatingVelocity v(*robot.model);
  v.qdot.data = Eigen::Map<const Eigen::VectorXd>(plan.qdot_before.data(), n);
  v.base_twist = toTwist(Eigen::Map<const Vector6d>(plan.base_twist_before.data()));
  ASSERT_EQ(forwardKinematics(*robot.model, s, kin), 0);
  ASSERT_EQ(second.compute(kin, v), 0);
  EXPECT_LE((second.momentumAtCoM() - scenario_momentum).norm(), 1e-12 * std::max(1.0, scenario_momentum.norm()));
  Vector6d hand_twist;
  ASSERT_EQ(second.contactTwist(robot.contact, hand_twist), 0);
  RigidTarget target = std::get<RigidTarget>(sc.capture.target);
  FreeRigidMotion tumble(target);
  ASSERT_EQ(tumble.at(parameter(plan, "timing"), target), 0);
  const KDL::Frame hand = contactFrame(*robot.model, s, robot.contact);
  Vector6d expected = pointTwist(target, toEigen(hand.p));
  expected.head<3>() += parameter(plan, "closing_speed") * toEigen(hand.M.UnitZ());
  EXPECT_LE((hand_twist - expected).norm(), 1e-12 * expected.norm()) << hand_twist.transpose() << "\n" << expected.transpose();
  // The smallest such rates: no share along the self-motion (J*'s null space).
  FreeFloatingSolver here(robot.model);
  ASSERT_EQ(here.compute(s), 0);
  KDL::Jacobian J_star(n);
  ASSERT_EQ(here.J_star(robot.contact, J_star), 0);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J_star.data, Eigen::ComputeFullV);
  EXPECT_LE(std::abs(svd.matrixV().col(n - 1).dot(v.qdot.data)), 1e-12 * v.qdot.data.norm());
  // Inside the rate limits before the capture too.
  for (unsigned int j = 0; j < n; ++j) EXPECT_LE(std::abs(v.qdot(j)), robot.model->jointProperties()[j].velocity);
}

TEST(CapturePlan, ClosingOnAFreeFloatingTargetMatchesItsContactTwist) {
  Scenario sc = loadScenario(dataDir() + "/scenarios/braked_robot_to_robot.yaml");
  PlanOptions o;
  o.self_motion = PlanRange{};
  o.wrist_roll = PlanRange{};
  o.closing_speed = PlanRange{0.03, 0.05};  // > 0: the closing term is part of the check
  // Its robot brakes two joints: five cannot give the hand a 6-D twist, and the plan says so.
  try {
    planCapture(sc, o);
    ADD_FAILURE() << "a five-joint arm closed on the grasp";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot give the hand the grasp point's twist"), std::string::npos) << e.what();
  }
  sc.capture.robot.locked.clear();
  // A target that moves ten times slower than the scenario's: the arm follows it within its rate limits.
  FloatingSystem& slower = std::get<FloatingSystem>(sc.capture.target);
  slower.velocity.base_twist = slower.velocity.base_twist * 0.1;
  slower.velocity.qdot.data *= 0.1;
  const CapturePlan plan = planCapture(sc, o);
  ASSERT_EQ(plan.searched, (std::vector<std::string>{"closing_speed"}));
  // The target's contact twist by the second route (MomentumSolver on the target's state).
  const FloatingSystem& target = std::get<FloatingSystem>(sc.capture.target);
  MomentumSolver on_target(target.model), on_robot(sc.capture.robot.model);
  Kinematics kin_t(*target.model), kin_r(*sc.capture.robot.model);
  ASSERT_EQ(forwardKinematics(*target.model, target.state, kin_t), 0);
  ASSERT_EQ(on_target.compute(kin_t, target.velocity), 0);
  Vector6d grasp_point;
  ASSERT_EQ(on_target.contactTwist(target.contact, grasp_point), 0);
  const FloatingSystem& robot = sc.capture.robot;
  FloatingVelocity v(*robot.model);
  v.qdot.data = Eigen::Map<const Eigen::VectorXd>(plan.qdot_before.data(), robot.model->nj());
  v.base_twist = toTwist(Eigen::Map<const Vector6d>(plan.base_twist_before.data()));
  ASSERT_EQ(forwardKinematics(*robot.model, robot.state, kin_r), 0);
  ASSERT_EQ(on_robot.compute(kin_r, v), 0);
  Vector6d hand_twist;
  ASSERT_EQ(on_robot.contactTwist(robot.contact, hand_twist), 0);
  const KDL::Frame hand = contactFrame(*robot.model, robot.state, robot.contact);
  Vector6d expected = grasp_point;
  expected.head<3>() += parameter(plan, "closing_speed") * toEigen(hand.M.UnitZ());
  EXPECT_LE((hand_twist - expected).norm(), 1e-12 * expected.norm()) << hand_twist.transpose() << "\n" << expected.transpose();
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
  o = PlanOptions{};
  o.closing_speed = PlanRange{-0.1, 0.1};
  refused(o, "closing_speed: must be >= 0");
  const Scenario plain = loadScenario(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/base_attitude_control.yaml");
  EXPECT_THROW(planCapture(plain), InputError);
}

}  // namespace
}  // namespace kdl_space::test
