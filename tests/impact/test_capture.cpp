// solveCapture and attachTarget (capture.hpp), the capture as one library call, checked against
// routes that do not go through it:
//   1. total momentum (linear, and angular about the world origin) is unchanged, to 1e-12
//      relative, for every law, with rigid and free-floating targets;
//   2. after a capture the robot's and the target's contact twists are equal (the law's defining
//      condition, with the target's contact twist moved from its CoM by hand);
//   3. the result is the one FloatingSide + RigidBodySide (or a second FloatingSide) + collide
//      give when built by hand, field by field; the dense method agrees with the O(n) one;
//   4. a robot-to-robot contact farther apart than the tolerance is refused, naming the gap;
//      every other refusal names its part ("robot: ", "target: ", "law: ");
//   5. RigidTarget::toWorld against a rotation written by hand (Rz Ry Rx), and attachTarget's
//      merged model: total mass and centre of mass of robot plus target.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <map>
#include <memory>
#include <random>

#include "impact_robots.hpp"
#include "impact_util.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

using ModelPtr = std::shared_ptr<const FloatingModel>;

constexpr double kRel = 1e-12;  // round-off of sums of a few dozen terms (see test_collision_properties.cpp)
constexpr int kTrials = 10;

Vector3d randomVec(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return Vector3d(u(rng), u(rng), u(rng));
}

/// A robot at a random state and velocity, touching at its tip with a small random offset.
FloatingSystem randomSystem(const RobotSpec& spec, std::mt19937& rng, Response response = Response::FreeFloating) {
  FloatingSystem s;
  s.model = cachedModel(spec.path);
  s.state = randomState(*s.model, rng);
  s.velocity = FloatingVelocity(*s.model);
  s.velocity.base_twist = toTwist((Vector6d() << randomVec(rng, 0.3), randomVec(rng, 0.2)).finished());
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (unsigned int j = 0; j < s.model->nj(); ++j) s.velocity.qdot(j) = u(rng);
  s.contact = s.model->contact(spec.tip, toKDL(randomVec(rng, 0.05)));
  s.response = response;
  return s;
}

/// A random rigid target in scenario terms: inertia diag(y+z, x+z, x+y) (triangle-valid) in its
/// own frame, a random pose near `near`, the CoM off the frame's origin, a random twist.
RigidTarget randomTarget(std::mt19937& rng, const Vector3d& near) {
  std::uniform_real_distribution<double> logm(0.0, std::log(3000.0)), sec(0.005, 0.4), angle(-M_PI, M_PI);
  RigidTarget t;
  t.mass = std::exp(logm(rng));
  const double x = t.mass * sec(rng), y = t.mass * sec(rng), z = t.mass * sec(rng);
  t.inertia = Vector3d(y + z, x + z, x + y).asDiagonal();
  t.pose = KDL::Frame(KDL::Rotation::RPY(angle(rng), angle(rng) / 2, angle(rng)), toKDL(near + randomVec(rng, 0.6)));
  t.com = randomVec(rng, 0.2);
  t.twist << randomVec(rng, 1.0), randomVec(rng, 1.0);
  return t;
}

/// The robot's contact point at its state (the hand-built route: its own FloatingSide).
Vector3d contactPointOf(const FloatingSystem& s) { return FloatingSide(s).contactPoint(); }

ImpactLaw randomLaw(ImpactKind kind, std::mt19937& rng) {
  ImpactLaw law;
  law.kind = kind;
  std::normal_distribution<double> g;
  law.normal = Vector3d(g(rng), g(rng), g(rng)).normalized();
  law.restitution = 0.5;
  law.friction = 0.4;
  return law;
}

/// The capture problem of a random robot and rigid target with `law`.
CaptureProblem rigidProblem(const RobotSpec& spec, std::mt19937& rng, const ImpactLaw& law) {
  CaptureProblem p;
  p.robot = randomSystem(spec, rng);
  p.target = randomTarget(rng, contactPointOf(p.robot));
  p.law = law;
  p.has_normal = true;
  return p;
}

/// The size of the contact twists' change: what the capture condition's round-off scales with
/// (the twists before, and the jump G F through each side's factorised inertias).
double twistScale(const CaptureResult& r, const Vector6d& target_contact_before) {
  return r.robot.contact_twist_before.norm() + target_contact_before.norm() +
         (r.G_robot.norm() + r.G_target.norm()) * r.impulse.F.norm();
}

/// Momentum before and after agree to kRel of the largest momentum involved.
::testing::AssertionResult conserved(const CaptureResult& r) {
  const double scale = std::max(r.momentum_before.norm(), r.impulse.F.norm() * (1.0 + r.contact_point.norm()));
  return near(r.momentum_after, r.momentum_before, 0.0, kRel * scale, "momentum");
}

const ImpactKind kLaws[] = {ImpactKind::Capture, ImpactKind::PointImpact, ImpactKind::FrictionalImpact,
                            ImpactKind::TranslationalCapture};

class SolveCapture : public ::testing::TestWithParam<RobotSpec> {};
INSTANTIATE_TEST_SUITE_P(Robots, SolveCapture, ::testing::ValuesIn(impactRobots()),
                         [](const ::testing::TestParamInfo<RobotSpec>& info) { return info.param.name; });

// ---- 1, 2: conservation and the capture condition -----------------------------------------------
TEST_P(SolveCapture, ConservesMomentumAndCapturesWithEqualContactTwists) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < kTrials; ++trial)
    for (const ImpactKind kind : kLaws) {
      const CaptureProblem p = rigidProblem(GetParam(), rng, randomLaw(kind, rng));
      const CaptureResult r = solveCapture(p);
      EXPECT_TRUE(conserved(r)) << "law " << static_cast<int>(kind) << ", trial " << trial;
      EXPECT_LE(r.energy_after, r.energy_before * (1.0 + kRel)) << "energy never rises";
      if (kind != ImpactKind::Capture) continue;
      // The target's material point at the contact: its CoM twist moved there by hand.
      const RigidBody b = std::get<RigidTarget>(p.target).toWorld();
      const Vector3d r_bc = r.contact_point - b.com;
      Vector6d target_contact = r.target_twist_after, target_contact_before = r.target_twist_before;
      target_contact.head<3>() += r.target_twist_after.tail<3>().cross(r_bc);
      target_contact_before.head<3>() += r.target_twist_before.tail<3>().cross(r_bc);
      const double scale = twistScale(r, target_contact_before);
      EXPECT_TRUE(near(r.robot.contact_twist_after, target_contact, 0.0, kRel * scale, "contact twists after"));
    }
}

// ---- 3: the same as the sides and collide built by hand ----------------------------------------
void expectSameAsByHand(const CaptureProblem& p, const CaptureResult& r) {
  FloatingSide robot(p.robot);
  const RigidTarget& t = std::get<RigidTarget>(p.target);
  RigidBodySide target(t.toWorld(), robot.contactPoint());
  const Impulse impulse = collideOk(robot, target, p.law);
  // The same code path: equal to the last bit.
  EXPECT_TRUE(near(r.impulse.F, impulse.F, 0.0, 0.0, "impulse"));
  EXPECT_EQ(r.impulse.separating, impulse.separating);
  EXPECT_EQ(r.impulse.sticking, impulse.sticking);
  EXPECT_TRUE(near(r.contact_point, robot.contactPoint(), 0.0, 0.0, "contact point"));
  EXPECT_TRUE(near(toEigen(r.robot.before.base_twist), toEigen(robot.before().base_twist), 0.0, 0.0, "base before"));
  EXPECT_TRUE(near(toEigen(r.robot.after.base_twist), toEigen(robot.after().base_twist), 0.0, 0.0, "base after"));
  EXPECT_TRUE(near(r.robot.before.qdot.data, robot.before().qdot.data, 0.0, 0.0, "qdot before"));
  EXPECT_TRUE(near(r.robot.after.qdot.data, robot.after().qdot.data, 0.0, 0.0, "qdot after"));
  EXPECT_TRUE(near(r.robot.contact_twist_before, robot.contactTwistBefore(), 0.0, 0.0, "contact twist before"));
  EXPECT_TRUE(near(r.robot.contact_twist_after, robot.contactTwistAfter(), 0.0, 0.0, "contact twist after"));
  EXPECT_TRUE(near(r.robot.centroid_twist_after, robot.centroidTwistAfter(), 0.0, 0.0, "centroid twist after"));
  EXPECT_TRUE(near(r.target_twist_before, target.twistBefore(), 0.0, 0.0, "target before"));
  EXPECT_TRUE(near(r.target_twist_after, target.twistAfter(), 0.0, 0.0, "target after"));
  EXPECT_TRUE(near(r.G_robot, robot.G(), 0.0, 0.0, "G robot"));
  EXPECT_TRUE(near(r.G_target, target.G(), 0.0, 0.0, "G target"));
  EXPECT_TRUE(near(r.momentum_before, robot.momentumBefore() + target.momentumBefore(), 0.0, 0.0, "momentum before"));
  EXPECT_TRUE(near(r.momentum_after, robot.momentumAfter() + target.momentumAfter(), 0.0, 0.0, "momentum after"));
  EXPECT_EQ(r.energy_before, robot.energyBefore() + target.energyBefore());
  EXPECT_EQ(r.energy_after, robot.energyAfter() + target.energyAfter());
  EXPECT_FALSE(r.floating_target.has_value());
  const KDL::Frame pose = robot.kinematics().pose(p.robot.contact.body);
  EXPECT_TRUE(near(toEigen(r.contact_body_pose.M), toEigen(pose.M), 0.0, 0.0, "contact body attitude"));
  EXPECT_TRUE(near(toEigen(r.contact_body_pose.p), toEigen(pose.p), 0.0, 0.0, "contact body position"));
  // The virtual mass along the normal, by the formula.
  const Vector3d n = p.law.normal.normalized();
  ASSERT_TRUE(r.virtual_mass.has_value());
  EXPECT_NEAR(*r.virtual_mass, 1.0 / n.dot(r.G_robot.topLeftCorner<3, 3>() * n), kRel * *r.virtual_mass);
}

TEST_P(SolveCapture, EqualsTheSidesAndCollideBuiltByHand) {
  std::mt19937 rng(12);
  for (int trial = 0; trial < kTrials; ++trial)
    for (const ImpactKind kind : kLaws) {
      SCOPED_TRACE("law " + std::to_string(static_cast<int>(kind)) + ", trial " + std::to_string(trial));
      const CaptureProblem p = rigidProblem(GetParam(), rng, randomLaw(kind, rng));
      expectSameAsByHand(p, solveCapture(p));
    }
}

TEST_P(SolveCapture, GroundedAndLockedRobotsToo) {
  std::mt19937 rng(13);
  for (const Response response : {Response::Grounded, Response::JointsLocked}) {
    CaptureProblem p = rigidProblem(GetParam(), rng, randomLaw(ImpactKind::Capture, rng));
    p.robot.response = response;
    const CaptureResult r = solveCapture(p);
    expectSameAsByHand(p, r);
    if (response == Response::JointsLocked) EXPECT_TRUE(conserved(r));
  }
}

TEST_P(SolveCapture, DenseMethodAgreesWithTheRecursiveOne) {
  std::mt19937 rng(14);
  for (const ImpactKind kind : kLaws) {
    CaptureProblem p = rigidProblem(GetParam(), rng, randomLaw(kind, rng));
    const CaptureResult fast = solveCapture(p);
    p.method = ExIITMethod::Dense;
    const CaptureResult dense = solveCapture(p);
    const double scale = dense.impulse.F.norm() + 1e-3;
    EXPECT_TRUE(near(fast.impulse.F, dense.impulse.F, 1e-9, 1e-9 * scale, "impulse"));
    EXPECT_TRUE(near(fast.G_robot, dense.G_robot, 1e-9, 1e-9 * dense.G_robot.norm(), "G*"));
    EXPECT_TRUE(near(fast.robot.after.qdot.data, dense.robot.after.qdot.data, 1e-9, 1e-9, "qdot after"));
  }
}

TEST(SolveCapture, NoNormalNoVirtualMass) {
  std::mt19937 rng(15);
  CaptureProblem p = rigidProblem(impactRobots()[0], rng, randomLaw(ImpactKind::Capture, rng));
  p.has_normal = false;
  EXPECT_FALSE(solveCapture(p).virtual_mass.has_value());
}

// ---- Robot to robot: 1, 2, 3 and 4 -------------------------------------------------------------
/// A free-floating target whose contact point is put at the robot's, then moved by `gap`.
CaptureProblem robotToRobot(std::mt19937& rng, const Vector3d& gap) {
  CaptureProblem p;
  p.robot = randomSystem(impactRobots()[0], rng);
  FloatingSystem other = randomSystem(impactRobots()[2], rng);
  const Vector3d shift = contactPointOf(p.robot) - contactPointOf(other) + gap;
  other.state.world_T_base.p += toKDL(shift);
  p.target = other;
  p.law.kind = ImpactKind::Capture;
  return p;
}

TEST(SolveCaptureRobotToRobot, ConservesMomentumAndLeavesNoRelativeTwist) {
  std::mt19937 rng(21);
  for (int trial = 0; trial < kTrials; ++trial) {
    const CaptureProblem p = robotToRobot(rng, Vector3d::Zero());
    const CaptureResult r = solveCapture(p);
    EXPECT_TRUE(conserved(r)) << trial;
    ASSERT_TRUE(r.floating_target.has_value());
    const FloatingSideResult& t = *r.floating_target;
    const double scale = twistScale(r, t.contact_twist_before);
    EXPECT_TRUE(near(r.robot.contact_twist_after, t.contact_twist_after, 0.0, kRel * scale, "contact twists after"));
    EXPECT_TRUE(near(r.target_twist_after, t.centroid_twist_after, 0.0, 0.0, "target twist = its centroid twist"));
    // By hand: two FloatingSides and collide.
    FloatingSide robot(p.robot), target(std::get<FloatingSystem>(p.target));
    const Impulse impulse = collideOk(robot, target, p.law);
    EXPECT_TRUE(near(r.impulse.F, impulse.F, 0.0, 0.0, "impulse"));
    EXPECT_TRUE(near(t.after.qdot.data, target.after().qdot.data, 0.0, 0.0, "target qdot after"));
    EXPECT_TRUE(near(toEigen(t.after.base_twist), toEigen(target.after().base_twist), 0.0, 0.0, "target base after"));
    EXPECT_TRUE(near(r.G_target, target.G(), 0.0, 0.0, "target G*"));
  }
}

/// The message of the Error that solveCapture throws, or "" if it does not.
std::string refusal(const CaptureProblem& p) {
  try {
    solveCapture(p);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(SolveCaptureRobotToRobot, RefusesContactsFartherApartThanTheTolerance) {
  std::mt19937 rng(22);
  CaptureProblem p = robotToRobot(rng, Vector3d(0.0, 0.002, 0.0));
  const std::string why = refusal(p);
  EXPECT_EQ(why.rfind("target.contact: the target's contact point is 0.002", 0), 0u) << why;
  EXPECT_NE(why.find(" m from the robot's; they must touch (within 1 mm)"), std::string::npos) << why;
  p.touch_tolerance = 3e-3;
  EXPECT_EQ(refusal(p), "");
  EXPECT_EQ(refusal(robotToRobot(rng, Vector3d(0.0, 0.0, 0.0009))), "") << "0.9 mm apart touch";
  for (const double bad : {-1e-3, std::nan("")}) {
    p.touch_tolerance = bad;
    EXPECT_EQ(refusal(p).rfind("target.contact: the touch tolerance", 0), 0u) << bad;
  }
}

// ---- 4: refusals name their part ---------------------------------------------------------------
TEST(SolveCaptureRefusals, NameThePart) {
  std::mt19937 rng(31);
  const CaptureProblem good = rigidProblem(impactRobots()[2], rng, randomLaw(ImpactKind::PointImpact, rng));
  const auto starts = [](const std::string& text, const std::string& prefix) {
    return ::testing::AssertionResult(text.rfind(prefix, 0) == 0) << "'" << text << "' starts with '" << prefix << "'";
  };
  CaptureProblem p = good;
  p.robot.state.world_T_base.p = KDL::Vector(NAN, 0, 0);
  EXPECT_TRUE(starts(refusal(p), "robot: the free-floating quantities cannot be computed at this state (robot.base, "
                                 "robot.q): " + std::string(strError(E_NOT_FINITE))));
  EXPECT_THROW(solveCapture(p), InputError) << "the problem's state: an input";
  p = good;
  p.robot.velocity.qdot = KDL::JntArray(p.robot.model->nj() + 1);
  EXPECT_TRUE(starts(refusal(p), "robot: FloatingSide: "));
  EXPECT_THROW(solveCapture(p), ModelError) << "the side's refusal keeps its kind, the part in front";
  p = good;
  p.robot.model = nullptr;
  EXPECT_TRUE(starts(refusal(p), "robot: "));
  EXPECT_THROW(solveCapture(p), InputError);
  p = good;
  std::get<RigidTarget>(p.target).mass = -1.0;
  EXPECT_EQ(refusal(p), "target: mass must be a finite value > 0");
  EXPECT_THROW(solveCapture(p), ModelError) << "RigidBodySide's own";
  p = good;
  std::get<RigidTarget>(p.target).inertia(0, 0) = -5.0;
  EXPECT_TRUE(starts(refusal(p), "target: "));
  p = good;
  p.law.restitution = 2.0;
  EXPECT_TRUE(starts(refusal(p), "law: the impact cannot be solved: " + std::string(strError(E_BAD_ARGUMENT))));
  EXPECT_THROW(solveCapture(p), InputError);
  p = good;
  FloatingSystem other = randomSystem(impactRobots()[0], rng);
  other.state.q(0) = INFINITY;
  p.target = other;
  EXPECT_TRUE(starts(refusal(p), "target: the free-floating quantities cannot be computed at this state (target.base, "
                                 "target.q)"));
  EXPECT_EQ(refusal(good), "");
}

// ---- 5: the target in world terms, and attached ------------------------------------------------
TEST(RigidTarget, ToWorldRotatesTheInertiaAndPlacesTheCoM) {
  RigidTarget t;
  t.mass = 12.0;
  t.inertia << 2.0, 0.1, -0.2, 0.1, 3.0, 0.3, -0.2, 0.3, 4.0;
  const double roll = 0.3, pitch = -0.7, yaw = 1.1;
  t.pose = basePose(KDL::Vector(1.0, -2.0, 0.5), roll, pitch, yaw);
  t.com = Vector3d(0.1, 0.2, -0.3);
  t.twist << 0.1, 0.2, 0.3, -0.4, 0.5, -0.6;
  // R = Rz(yaw) Ry(pitch) Rx(roll), written with Eigen (URDF's fixed-axis roll-pitch-yaw).
  const Matrix3d R = (Eigen::AngleAxisd(yaw, Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Vector3d::UnitY()) *
                      Eigen::AngleAxisd(roll, Vector3d::UnitX()))
                         .toRotationMatrix();
  const RigidBody b = t.toWorld();
  EXPECT_EQ(b.mass, t.mass);
  EXPECT_TRUE(near(b.I_com, R * t.inertia * R.transpose(), 1e-14, 1e-14, "I_com"));
  EXPECT_TRUE(near(b.com, R * t.com + Vector3d(1.0, -2.0, 0.5), 1e-14, 1e-14, "com"));
  EXPECT_TRUE(near(b.twist, t.twist, 0.0, 0.0, "twist (world frame already)"));
}

TEST(AttachTarget, MergesTheTargetIntoTheContactLinkAfterACapture) {
  std::mt19937 rng(41);
  for (const RobotSpec& spec : impactRobots()) {
    const CaptureProblem p = rigidProblem(spec, rng, randomLaw(ImpactKind::Capture, rng));
    const CaptureResult r = solveCapture(p);
    const ModelPtr merged = attachTarget(p, r);
    ASSERT_TRUE(merged);
    const RigidBody b = std::get<RigidTarget>(p.target).toWorld();
    EXPECT_NEAR(merged->totalMass(), p.robot.model->totalMass() + b.mass, kRel * merged->totalMass()) << spec.name;
    EXPECT_EQ(merged->jointNames(), p.robot.model->jointNames());
    // The merged system's CoM at the robot's state: the mass-weighted CoM of robot and target.
    Kinematics robot_kin(*p.robot.model), merged_kin(*merged);
    ASSERT_EQ(forwardKinematics(*p.robot.model, p.robot.state, robot_kin), E_NOERROR);
    ASSERT_EQ(forwardKinematics(*merged, p.robot.state, merged_kin), E_NOERROR);
    const Vector3d expected = (p.robot.model->totalMass() * robot_kin.r_g + b.mass * b.com) / merged->totalMass();
    EXPECT_TRUE(near(merged_kin.r_g, expected, 0.0, 1e-12 * (1.0 + expected.norm()), spec.name + " CoM"));
  }
}

TEST(AttachTarget, KeepsTheRobotAfterAPointImpactAndRefusesWhatItCannotJoin) {
  std::mt19937 rng(42);
  for (const ImpactKind kind : {ImpactKind::PointImpact, ImpactKind::FrictionalImpact}) {
    const CaptureProblem p = rigidProblem(impactRobots()[0], rng, randomLaw(kind, rng));
    EXPECT_EQ(attachTarget(p, solveCapture(p)), p.robot.model) << "the same model: the target separates";
  }
  const auto refusal = [](const CaptureProblem& p) {
    try {
      attachTarget(p, solveCapture(p));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const CaptureProblem translational = rigidProblem(impactRobots()[0], rng, randomLaw(ImpactKind::TranslationalCapture, rng));
  EXPECT_EQ(refusal(translational),
            "law.type: simulate does not model a translational capture (the target would turn freely about the "
            "contact point, a spherical joint); `capture` solves its impact");
  EXPECT_EQ(refusal(robotToRobot(rng, Vector3d::Zero())),
            "target.urdf: simulate does not join two free-floating systems into one after a capture yet; `capture` "
            "solves the impact");
}

}  // namespace
}  // namespace kdl_space::test
