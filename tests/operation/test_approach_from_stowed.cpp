// The approach from a stowed arm (issue 38 item 2): the pre-grasp move's profile against its
// closed form; the approach from stowed on the bundled arm and on a heavy arm on a light bus
// reaching its grasp with every joint inside its limits and every rate within its limit, read
// from the samples; without a pre-grasp move the guard still keeps the joints inside and the
// failure names the joint; the Jacobian that matches what holds the base, checked against the
// momentum by another route; the causes of failures; the overlaps on the way.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <unistd.h>

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/operation/overlap_check.hpp"
#include "kdl_space/simulation/joint_move.hpp"
#include "arm_variants.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

const std::string kApproach = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/approach_tumbling_box.yaml";
/// A stowed arm: the upper arm folded back along the bus, the forearm over it.
const std::string kStowed = "  q: {joint2: -1.2, joint3: 0.0, joint4: 2.6, joint6: 1.0}";

std::string slurpText(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// The shipped approach scenario with `edit` applied to its text (its URDF made absolute, or the
/// bundled arm's URDF through `urdf_edit`), written in this process's folder as `tag`.yaml.
template <typename UrdfEdit>
std::string variant(const std::string& tag, const std::function<std::string(std::string)>& edit, UrdfEdit urdf_edit) {
  const std::string dir = ::testing::TempDir() + "stowed_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/" + tag + ".urdf") << urdf_edit(slurpText(std::string(KDL_SPACE_SOURCE_DIR) + "/urdf/space_arm7.urdf"));
  std::string text = std::regex_replace(slurpText(kApproach), std::regex("\\.\\./urdf/space_arm7\\.urdf"), dir + "/" + tag + ".urdf");
  std::ofstream(dir + "/" + tag + ".yaml") << edit(text);
  return dir + "/" + tag + ".yaml";
}

std::string stowed(std::string text, const std::string& approach_lines) {
  text = std::regex_replace(text, std::regex("  q: \\{[^}]*\\}"), kStowed);
  text = std::regex_replace(text, std::regex("  max_duration: 30"), "  max_duration: 120" + approach_lines);
  return text;
}

std::string asIs(std::string urdf) { return urdf; }

// --- The pre-grasp move's profile ---------------------------------------------------------------

TEST(JointMove, OneJointIsTheClosedFormTrapezoidAndATriangleWhenShort) {
  // One joint: cruise at v for d / v - v / a, ramps of v / a: T = d / v + v / a.
  const JointMove long_move(Eigen::VectorXd::Constant(1, 0.2), Eigen::VectorXd::Constant(1, 2.2), {0.1}, {0.05});
  EXPECT_NEAR(long_move.duration(), 2.0 / 0.1 + 0.1 / 0.05, 1e-12);
  // Too short to cruise: T = 2 sqrt(d / a).
  const JointMove short_move(Eigen::VectorXd::Constant(1, 0.0), Eigen::VectorXd::Constant(1, -0.1), {0.1}, {0.05});
  EXPECT_NEAR(short_move.duration(), 2.0 * std::sqrt(0.1 / 0.05), 1e-12);
  Eigen::VectorXd q, v;
  short_move.at(0.5 * short_move.duration(), q, v);
  EXPECT_NEAR(q(0), -0.05, 1e-12);                     // halfway at half time
  EXPECT_NEAR(v(0), -0.05 * std::sqrt(0.1 / 0.05), 1e-12);  // the peak: a x T / 2
}

TEST(JointMove, SynchronizedWithinEveryLimitOnTheStraightLine) {
  Eigen::VectorXd q0(4), q1(4);
  q0 << 0.0, 1.0, -2.0, 0.5;
  q1 << 1.5, 1.0, 0.4, -0.3;
  const std::vector<double> rates{0.15, 0.2, 0.3, 0.05}, accelerations{0.1, 0.1, 0.2, 0.02};
  const JointMove move(q0, q1, rates, accelerations);
  const double T = move.duration();
  double worst_rate = 0.0, worst_acceleration = 0.0;
  Eigen::VectorXd q, v, q_prev, v_prev;
  move.at(0.0, q, v);
  EXPECT_EQ(q, q0);
  EXPECT_EQ(v, Eigen::VectorXd::Zero(4));
  const int N = 20000;
  const double h = T / N;
  for (int k = 1; k <= N; ++k) {
    v_prev = v;
    q_prev = q;
    move.at(k * h, q, v);
    for (int j = 0; j < 4; ++j) {
      worst_rate = std::max(worst_rate, std::abs(v(j)) / rates[j]);
      worst_acceleration = std::max(worst_acceleration, std::abs(v(j) - v_prev(j)) / h / accelerations[j]);
      // on the segment from q0 to q1 (so inside any box limits both ends are in)
      EXPECT_GE(q(j), std::min(q0(j), q1(j)) - 1e-15);
      EXPECT_LE(q(j), std::max(q0(j), q1(j)) + 1e-15);
    }
    // its rate is the derivative of its position (the trapezoidal rule's error: h^2 x the
    // acceleration's jump at a kink of the profile, at most 2 x its largest)
    EXPECT_LE((q - q_prev - 0.5 * h * (v + v_prev)).norm(), h * h * 0.4);
  }
  EXPECT_EQ(q, q1);
  EXPECT_EQ(v, Eigen::VectorXd::Zero(4));
  // The fastest: one joint at its rate limit or its acceleration limit, none beyond.
  EXPECT_LE(worst_rate, 1.0 + 1e-12);
  EXPECT_LE(worst_acceleration, 1.0 + 1e-6);
  EXPECT_GT(std::max(worst_rate, worst_acceleration), 1.0 - 1e-6);
  EXPECT_THROW(JointMove(q0, q1, {0.1, 0.1, 0.1}, accelerations), ModelError);
  EXPECT_THROW(JointMove(q0, q1, {0.1, 0.0, 0.1, 0.1}, accelerations), ModelError);
}

// --- The approach from stowed --------------------------------------------------------------------

/// Every approach sample's joints inside their limits and rates within `rates` x their limits
/// (1.01: the servos track the command within 1 %), read from the samples.
void expectWithinLimits(const Scenario& sc, const OperationResult& r, double rates = 1.01) {
  const FloatingModel& model = *sc.capture.robot.model;
  ASSERT_GT(r.approach_samples.size(), 100u);
  double worst_position = -1.0, worst_rate = 0.0;
  for (const MotionSample& x : r.approach_samples)
    for (unsigned int j = 0; j < model.nj(); ++j) {
      const JointProperties& p = model.jointProperties()[j];
      worst_position = std::max({worst_position, x.q(j) - p.upper, p.lower - x.q(j)});
      worst_rate = std::max(worst_rate, std::abs(x.qd(j)) / sc.approach->rate_limits[j]);
    }
  EXPECT_LT(worst_position, 0.0) << "a joint left its limits";
  if (rates > 0.0) EXPECT_LE(worst_rate, rates) << "a joint's rate beyond its limit";
}

void expectReachedFromStowed(const std::string& path, ApproachBase base = ApproachBase::Free) {
  const Scenario sc = loadScenario(path);
  ASSERT_TRUE(sc.approach && sc.approach->pre_grasp);
  OperationOptions o;
  o.duration = 0.5;
  const OperationResult r = runCaptureOperation(sc, o);
  ASSERT_TRUE(r.approach);
  const ApproachRecord& rec = r.approach->record;
  EXPECT_TRUE(rec.reached) << rec.cause;
  EXPECT_GT(rec.pre_grasp_duration, 1.0);
  ASSERT_EQ(rec.pre_grasp_q.size(), 7u);
  EXPECT_LT(rec.pre_grasp_duration, rec.duration);
  EXPECT_EQ(rec.base, base);
  expectWithinLimits(sc, r);
  // The pre-grasp pose is the inverse kinematics': inside every limit.
  for (unsigned int j = 0; j < 7; ++j) {
    EXPECT_LT(rec.pre_grasp_q[j], sc.capture.robot.model->jointProperties()[j].upper);
    EXPECT_GT(rec.pre_grasp_q[j], sc.capture.robot.model->jointProperties()[j].lower);
  }
}

TEST(ApproachFromStowed, TheBundledArmReachesItsGraspInsideItsLimits) {
  expectReachedFromStowed(variant("bundled", [](std::string t) { return stowed(t, "\n  pre_grasp: {standoff: 0.15}"); }, asIs));
}

TEST(ApproachFromStowed, AHeavyArmOnALightBusHeldByItsControlReachesItsGraspInsideItsLimits) {
  // The arm's links four times as heavy on an 80 kg bus whose attitude and position control act
  // in the approach (wheels and thrusters): the grounded Jacobian, the pre-grasp move, the final
  // approach; every joint inside its limits, every rate within its limit.
  expectReachedFromStowed(variant("heavy_held", [](std::string t) {
    return stowed(t, "\n  pre_grasp: {standoff: 0.15}\n  singular_threshold: 0.01") +
           "  base_control:\n    phases: [approach]\n    attitude: {kp: 2000, kd: 4000, set_point: hold}\n"
           "    position: {kp: 2000, kd: 4000, set_point: hold}\n";
  }, heavyArmOnLightBus), ApproachBase::Held);
}

TEST(ApproachFromStowed, AHeavyArmOnALightBusStaysInsideItsLimitsAndSaysWhyItStops) {
  // The same with only the bus's attitude held (a free bus turns ~60 degrees under this arm): the
  // attitude-held Jacobian. The bus recoils along the arm's pull and the hand stops 8 mm short,
  // the Jacobian near a singularity (a virtual manipulator about the stack's centre of mass,
  // stretched out): no joint leaves its limits and the failure says why, and what to do.
  const Scenario sc = loadScenario(variant("heavy", [](std::string t) {
    return stowed(t, "\n  pre_grasp: {standoff: 0.15}\n  singular_threshold: 0.01") +
           "  base_control:\n    phases: [approach]\n    attitude: {kp: 2000, kd: 4000, set_point: hold}\n";
  }, heavyArmOnLightBus));
  OperationOptions o;
  o.duration = 0.5;
  std::shared_ptr<const OperationResult> r;
  try {
    r = std::make_shared<const OperationResult>(runCaptureOperation(sc, o));
  } catch (const OperationError& e) {
    ASSERT_TRUE(e.partial() && e.partial()->approach) << e.what();
    r = e.partial();
    EXPECT_FALSE(r->approach->record.cause.empty());
    EXPECT_NE(std::string(e.what()).find(r->approach->record.cause), std::string::npos);
    EXPECT_NE(r->approach->record.cause.find("near a singularity"), std::string::npos) << r->approach->record.cause;
    EXPECT_NE(r->approach->record.cause.find("recoils along the arm's pull"), std::string::npos);
    EXPECT_NE(r->approach->record.cause.find("base_control.position"), std::string::npos);
  }
  EXPECT_EQ(r->approach->record.base, ApproachBase::AttitudeHeld);
  EXPECT_GT(r->approach->record.pre_grasp_duration, 1.0);
  EXPECT_LT(r->approach->record.closest_distance, 0.05);
  expectWithinLimits(sc, *r, 0.0);
}

TEST(ApproachFromStowed, WithoutAPreGraspTheGuardKeepsTheJointsInsideAndTheFailureNamesTheJoint) {
  const Scenario sc = loadScenario(variant("no_pre_grasp", [](std::string t) {
    return std::regex_replace(stowed(t, ""), std::regex("max_duration: 120"), "max_duration: 30");
  }, asIs));
  OperationOptions o;
  o.duration = 0.5;
  try {
    runCaptureOperation(sc, o);
    FAIL() << "reached from stowed without a pre-grasp move (it did not before)";
  } catch (const OperationError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("joint joint3 held at its limit for"), std::string::npos) << what;
    ASSERT_TRUE(e.partial() && e.partial()->approach);
    const ApproachRecord& rec = e.partial()->approach->record;
    EXPECT_FALSE(rec.reached);
    EXPECT_GT(rec.time_at_limit[2], 10.0);
    // The commands stay within the rate limits and change continuously (the guard's rates are a
    // strictly convex QP's: before, its clamp-and-re-solve switched between sets of clamped joints
    // and the servos chattered, 1.95 x a wrist's limit). The servos still lag: held at its guard,
    // joint3 decelerates while the others speed up, and a velocity servo (kv = bandwidth x the
    // joint's apparent inertia) lets the coupling carry it to 1.25 x its limit (measured).
    expectWithinLimits(sc, *e.partial(), 1.3);
  }
}

TEST(ApproachFromStowed, APreGraspOutOfReachIsNamed) {
  const Scenario sc = loadScenario(variant("far", [](std::string t) {
    t = stowed(t, "\n  pre_grasp: {standoff: 0.15}");
    return std::regex_replace(t, std::regex("position: \\[-0.92, -2.03, 0.62\\]"), "position: [-9.0, -2.03, 0.62]");
  }, asIs));
  OperationOptions o;
  o.duration = 0.5;
  try {
    runCaptureOperation(sc, o);
    FAIL() << "a target 9 m away was reached";
  } catch (const OperationError& e) {
    EXPECT_NE(std::string(e.what()).find("the pre-grasp pose (0.15 m back from the grasp) is out of reach"),
              std::string::npos)
        << e.what();
  }
}

TEST(ApproachFromStowed, TheArmsWayThroughTheBusAndTheTargetIsWarnedOf) {
  const Scenario sc =
      loadScenario(variant("overlap", [](std::string t) { return stowed(t, "\n  pre_grasp: {standoff: 0.15}"); }, asIs));
  OperationOptions o;
  o.duration = 0.5;
  const OperationResult r = runCaptureOperation(sc, o);
  ASSERT_TRUE(r.approach);
  // Each overlap's depth against the boxes themselves at the instant it names.
  bool bus = false;
  for (const Diagnostic& d : r.approach->overlaps) {
    EXPECT_EQ(d.kind, "overlap");
    EXPECT_NE(d.message.find("during the approach"), std::string::npos);
    std::string target;
    double depth = 0.0;
    for (const auto& [k, v] : d.details) {
      if (k == "target") target = std::get<std::string>(v);
      if (k == "depth") depth = std::get<double>(v);
    }
    EXPECT_GT(depth, kOverlapAllowance);
    bus |= target == "bus";
  }
  EXPECT_TRUE(bus) << "this start folds the arm through its bus's box on the way (measured 0.45 m)";
}

// --- The Jacobian that matches the base -------------------------------------------------------

TEST(ApproachBase, AnAttitudeHeldBaseTracksWithTheMixedJacobianOfTheLinearMomentum) {
  // With the base's attitude held (w_b = 0) and its position free, the linear momentum
  // P = sum m_i v_i fixes the base's velocity. Another route: the momentum of the base twist
  // (v_b; 0) is linear in v_b: solve it from three unit probes and check that the hand's twist
  // J qdot + (v_b; 0) is the controller's reference.
  const Scenario sc = loadScenario(kApproach);
  const std::shared_ptr<const FloatingModel>& model = sc.capture.robot.model;
  ApproachSpec spec = *sc.approach;
  spec.rate_limits.assign(model->nj(), 1e3);  // no scaling: the rates are the task's
  ApproachController controller(model, sc.capture.robot.contact, spec,
                                FreeRigidMotion(std::get<RigidTarget>(sc.capture.target)));
  controller.setBase(ApproachBase::AttitudeHeld);
  SimulationState s;
  s.state = sc.capture.robot.state;
  s.velocity = sc.capture.robot.velocity;
  s.velocity.base_twist = KDL::Twist(KDL::Vector(0.01, -0.02, 0.005), KDL::Vector::Zero());
  ApproachCommand cmd;
  ASSERT_EQ(controller.command(s, cmd), E_NOERROR);
  ASSERT_EQ(cmd.scale, 1.0);
  ASSERT_EQ(cmd.damping, 0.0);
  FreeFloatingSolver solver(model);
  ASSERT_EQ(solver.compute(s.state), E_NOERROR);
  Vector6d PL0, PL;
  ASSERT_EQ(solver.momentum(s.velocity.base_twist, s.velocity.qdot, PL0), E_NOERROR);  // the system's
  ASSERT_EQ(solver.momentum(KDL::Twist::Zero(), cmd.qdot, PL), E_NOERROR);
  Eigen::Matrix3d M;
  for (int k = 0; k < 3; ++k) {
    Vector6d probe;
    KDL::Vector e = KDL::Vector::Zero();
    e(k) = 1.0;
    ASSERT_EQ(solver.momentum(KDL::Twist(e, KDL::Vector::Zero()), KDL::JntArray(model->nj()), probe), E_NOERROR);
    M.col(k) = probe.head<3>();
  }
  const Vector3d v_b = M.lu().solve(PL0.head<3>() - PL.head<3>());
  KDL::Jacobian J(model->nj());
  ASSERT_EQ(solver.J(sc.capture.robot.contact, J), E_NOERROR);
  Vector6d t_h = J.data * cmd.qdot.data;
  t_h.head<3>() += v_b;
  EXPECT_LE((t_h - cmd.reference).norm(), 1e-12 * cmd.reference.norm()) << (t_h - cmd.reference).transpose();
  // The free base's J* gives another rate: the two Jacobians differ.
  controller.setBase(ApproachBase::Free);
  ApproachCommand free;
  ASSERT_EQ(controller.command(s, free), E_NOERROR);
  EXPECT_GT((free.qdot.data - cmd.qdot.data).norm(), 1e-6);
}

TEST(ApproachBase, TheRunUsesTheJacobianOfWhatHoldsTheBase) {
  // An attitude control acting in the approach: the attitude-held Jacobian; both: the grounded one.
  const auto jacobian = [](const std::string& base_control) {
    const Scenario sc = loadScenario(variant("base_" + std::to_string(base_control.size()), [&](std::string t) {
      return t + "  base_control:\n    phases: [approach]\n" + base_control;
    }, asIs));
    OperationOptions o;
    o.motion = false;
    return runCaptureOperation(sc, o).approach->record.base;
  };
  EXPECT_EQ(jacobian("    attitude: {kp: 2000, kd: 4000, set_point: hold}\n"), ApproachBase::AttitudeHeld);
  EXPECT_EQ(jacobian("    attitude: {kp: 2000, kd: 4000, set_point: hold}\n    position: {kp: 500, kd: 2000, set_point: hold}\n"),
            ApproachBase::Held);
  EXPECT_STREQ(toString(ApproachBase::AttitudeHeld), "attitude held (J - [A_mP / w; 0])");
}

}  // namespace
}  // namespace kdl_space::test
