// Inverse kinematics of the contact frame (solveInverseKinematics): goals made by forward
// kinematics of random in-limit configurations (so they are reachable), checked by a second
// forward kinematics (KDL's TreeFkSolverPos_recursive on the model's tree, joints mapped by name),
// on the default arm, the dual-arm tree and a 6-joint arm with a prismatic and a continuous joint.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <kdl/treefksolverpos_recursive.hpp>
#include <random>
#include <string>

#include "kdl_space/algorithm/inverse_kinematics.hpp"
#include "kdl_space/algorithm/self_motion.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"

namespace kdl_space {
namespace {

struct Robot {
  std::string file, link;
};

const Robot kRobots[] = {
    {KDL_SPACE_URDF_DIR "/space_arm7.urdf", "end_effector"},
    {KDL_SPACE_URDF_DIR "/dual_arm.urdf", "right_tool"},
    {KDL_SPACE_TEST_DATA_DIR "/reference/models/arm6_public.urdf", "tool"},
};

/// World pose of link `link` + offset by KDL's tree solver (joints by name): the second route.
KDL::Frame kdlContactFrame(const FloatingModel& model, const State& s, const std::string& link, const KDL::Vector& offset) {
  const KDL::Tree& tree = model.tree();
  KDL::JntArray q(tree.getNrOfJoints());
  for (const auto& [name, element] : tree.getSegments()) {
    const KDL::Joint& j = GetTreeElementSegment(element).getJoint();
    if (j.getType() == KDL::Joint::Fixed) continue;
    q(GetTreeElementQNr(element)) = s.q(model.jointIndex(j.getName()));
  }
  KDL::TreeFkSolverPos_recursive fk(tree);
  KDL::Frame f;
  EXPECT_GE(fk.JntToCart(q, f, link), 0);
  return s.world_T_base * f * KDL::Frame(offset);
}

/// |v| (KDL's Vector::Norm reads every vector shorter than 1e-6 as 0).
double length(const KDL::Vector& v) { return std::sqrt(KDL::dot(v, v)); }

double angleBetween(const KDL::Rotation& a, const KDL::Rotation& b) {
  const Eigen::Quaterniond qa = [&] { double x, y, z, w; a.GetQuaternion(x, y, z, w); return Eigen::Quaterniond(w, x, y, z); }();
  const Eigen::Quaterniond qb = [&] { double x, y, z, w; b.GetQuaternion(x, y, z, w); return Eigen::Quaterniond(w, x, y, z); }();
  return qa.angularDistance(qb);
}

/// A configuration drawn inside the limits (a turn for unlimited joints).
KDL::JntArray inLimits(const FloatingModel& model, std::mt19937& rng) {
  KDL::JntArray q(model.nj());
  for (unsigned int j = 0; j < model.nj(); ++j) {
    const JointProperties& p = model.jointProperties()[j];
    const double lo = std::isfinite(p.lower) ? p.lower : -3.14159, hi = std::isfinite(p.upper) ? p.upper : 3.14159;
    q(j) = std::uniform_real_distribution<double>(lo, hi)(rng);
  }
  return q;
}

void expectInLimits(const FloatingModel& model, const KDL::JntArray& q) {
  for (unsigned int j = 0; j < model.nj(); ++j) {
    EXPECT_GE(q(j), model.jointProperties()[j].lower) << model.jointNames()[j];
    EXPECT_LE(q(j), model.jointProperties()[j].upper) << model.jointNames()[j];
  }
}

TEST(InverseKinematics, ReachesRandomReachablePosesTo1e9InsideTheLimits) {
  for (const Robot& robot : kRobots) {
    const FloatingModel model = loadUrdfFile(robot.file);
    const KDL::Vector offset(0.03, -0.02, 0.05);
    const Contact h = model.contact(robot.link, offset);
    std::mt19937 rng(7);
    for (int trial = 0; trial < 12; ++trial) {
      State truth(model);
      truth.world_T_base = KDL::Frame(KDL::Rotation::RPY(0.3, -0.2, 1.1), KDL::Vector(1.0, -2.0, 0.5));
      truth.q = inLimits(model, rng);
      const KDL::Frame goal = kdlContactFrame(model, truth, robot.link, offset);
      State seed = truth;
      seed.q = inLimits(model, rng);  // from elsewhere in the joint space
      const IkResult r = solveInverseKinematics(model, seed, h, goal);
      State solved = seed;
      solved.q = r.q;
      const KDL::Frame reached = kdlContactFrame(model, solved, robot.link, offset);
      SCOPED_TRACE(robot.file + " trial " + std::to_string(trial));
      EXPECT_LE(length(reached.p - goal.p), 1e-9);
      EXPECT_LE(angleBetween(reached.M, goal.M), 1e-9);
      EXPECT_LE(r.position_residual, 1e-9);
      EXPECT_LE(r.orientation_residual, 1e-9);
      EXPECT_GT(r.iterations, 0u);
      expectInLimits(model, r.q);
      for (unsigned int j = 0; j < model.nj(); ++j)  // joints off the chain (the other arm) keep the seed's
        if (std::find(r.chain_joints.begin(), r.chain_joints.end(), static_cast<int>(j)) == r.chain_joints.end())
          EXPECT_EQ(r.q(j), seed.q(j)) << model.jointNames()[j];
    }
  }
}

TEST(InverseKinematics, RedundantArmTakesThePreferredPostureOnItsSelfMotion) {
  const FloatingModel model = loadUrdfFile(KDL_SPACE_URDF_DIR "/space_arm7.urdf");
  const Contact h = model.contact("end_effector");
  State truth(model);
  truth.q = jointsByName(model, {{"joint1", 0.4}, {"joint2", -0.6}, {"joint3", 0.9}, {"joint4", -1.0},
                                 {"joint5", 0.7}, {"joint6", 0.5}, {"joint7", -0.3}});
  const KDL::Frame goal = kdlContactFrame(model, truth, "end_effector", KDL::Vector::Zero());
  State seed = truth;
  for (unsigned int j = 0; j < model.nj(); ++j) seed.q(j) += 0.15 * ((j % 2) ? 1.0 : -1.0);
  IkOptions o;
  o.preferred = truth.q;  // the pose's own posture is on the self-motion: the closest to itself
  const IkResult r = solveInverseKinematics(model, seed, h, goal, o);
  EXPECT_LE((r.q.data - truth.q.data).norm(), 1e-6);
  EXPECT_LE(r.preference_gradient, 1e-8);
  // Preferring the seed (the default) instead lands elsewhere on the self-motion, still on the pose.
  const IkResult d = solveInverseKinematics(model, seed, h, goal);
  EXPECT_LE(d.position_residual, 1e-9);
  EXPECT_LE(d.preference_gradient, 1e-8);
  EXPECT_LT((d.q.data - seed.q.data).norm(), (r.q.data - seed.q.data).norm());
}

TEST(InverseKinematics, ThePreferredPostureIsTheSameFromEverySeedWithinThePoseTolerance) {
  // The nearest configuration on the pose's self-motion is one point: seeds on either side of it
  // reach it, where its first-order condition N (preferred - q) = 0 holds to 1e-13, to within the
  // pose's tolerance (1e-10: Newton stops at half of it, so 2e-11 apart was measured).
  // (The step-halving rule before issue 38 stopped where |N (preferred - q)| was ~1e-8: its
  // solutions from these seeds differed by ~1e-8 rad.) Another route: the distance along the
  // self-motion, walked 1e-3 either way from the solution, is no smaller.
  const std::shared_ptr<const FloatingModel> model =
      std::make_shared<const FloatingModel>(loadUrdfFile(KDL_SPACE_URDF_DIR "/space_arm7.urdf"));
  const Contact h = model->contact("end_effector");
  State preferred(*model);
  preferred.q = jointsByName(*model, {{"joint2", 0.7}, {"joint3", 0.9}, {"joint4", 0.8}, {"joint6", -0.6}});
  State pose_at = preferred;
  pose_at.q = jointsByName(*model, {{"joint1", 0.3}, {"joint2", 0.2}, {"joint3", 1.2}, {"joint4", 1.1},
                                    {"joint5", -0.4}, {"joint6", -0.9}, {"joint7", 0.5}});
  const KDL::Frame goal = kdlContactFrame(*model, pose_at, "end_effector", KDL::Vector::Zero());
  IkOptions o;
  o.preferred = preferred.q;
  o.restarts = 0;
  std::vector<IkResult> results;
  for (const double shift : {-0.2, 0.0, 0.25}) {
    State seed = pose_at;
    for (unsigned int j = 0; j < model->nj(); ++j) seed.q(j) += shift * ((j % 3) ? 1.0 : -0.5);
    results.push_back(solveInverseKinematics(*model, seed, h, goal, o));
    EXPECT_LE(results.back().preference_gradient, 1e-13 * (1.0 + preferred.q.data.norm()));
  }
  for (const IkResult& r : results) EXPECT_LE((r.q.data - results[1].q.data).cwiseAbs().maxCoeff(), 1e-10);
  State solved = pose_at;
  solved.q = results[1].q;
  const double d = (solved.q.data - preferred.q.data).norm();
  for (const double s : {-1e-3, 1e-3}) {
    SelfMotion walk(model, h, solved);
    State x = solved;
    ASSERT_EQ(walk.move(x, s), E_NOERROR);
    EXPECT_GT((x.q.data - preferred.q.data).norm(), d + 1e-8);  // a minimum: f'' ~ 0.7, so ~3.5e-7 more
  }
}

TEST(InverseKinematics, UnreachablePoseIsRefusedWithTheRemainingDistance) {
  const FloatingModel model = loadUrdfFile(KDL_SPACE_URDF_DIR "/space_arm7.urdf");
  const Contact h = model.contact("end_effector");
  const State seed(model);
  // 50 m from the base; the arm reaches 0.8 + 3.5 m from the base's origin: at least 45.7 m short.
  const KDL::Frame goal(KDL::Rotation::Identity(), KDL::Vector(50.0, 0.0, 0.0));
  IkOptions o;
  o.restarts = 3;
  try {
    solveInverseKinematics(model, seed, h, goal, o);
    FAIL() << "an unreachable pose was solved";
  } catch (const IkUnreachable& e) {
    EXPECT_GE(e.best().position_residual, 50.0 - 0.8 - 3.5 - 0.2);
    EXPECT_LE(e.best().position_residual, 50.0);
    EXPECT_EQ(e.best().attempts, 4u);
    expectInLimits(model, e.best().q);
    EXPECT_NE(std::string(e.what()).find("out of reach"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(" m and "), std::string::npos) << e.what();
    const InputError* as_input = &e;  // an InputError: the tools exit 3
    EXPECT_NE(as_input, nullptr);
  }
}

TEST(InverseKinematics, RefusesAWrongSizedSeed) {
  const FloatingModel model = loadUrdfFile(KDL_SPACE_URDF_DIR "/space_arm7.urdf");
  State seed(model);
  seed.q.resize(3);
  EXPECT_THROW(solveInverseKinematics(model, seed, model.contact("end_effector"), KDL::Frame::Identity()), ModelError);
}

/// The Franka-like arm's forward kinematics from its modified-DH parameters, with Eigen only (no
/// KDL, no URDF): joint i is Rx(alpha) Tx(a) Rz(q_i) Tz(d); then the flange (0.107 m), the hand
/// turned -pi/4 about z, and the TCP (0.1034 m) or a finger (0.0584 m up, then along -y by the
/// right finger's opening, which mimics the left's).
Eigen::Isometry3d frankaLikeFrame(const Eigen::Isometry3d& world_T_base, const double q[7], double finger,
                                  bool right_finger) {
  static const double a[7] = {0, 0, 0, 0.0825, -0.0825, 0, 0.088};
  static const double d[7] = {0.333, 0, 0.316, 0, 0.384, 0, 0};
  static const double alpha[7] = {0, -M_PI / 2, M_PI / 2, M_PI / 2, -M_PI / 2, M_PI / 2, M_PI / 2};
  Eigen::Isometry3d T = world_T_base;
  for (int i = 0; i < 7; ++i)
    T = T * Eigen::AngleAxisd(alpha[i], Eigen::Vector3d::UnitX()) * Eigen::Translation3d(a[i], 0, 0) *
        Eigen::AngleAxisd(q[i], Eigen::Vector3d::UnitZ()) * Eigen::Translation3d(0, 0, d[i]);
  T = T * Eigen::Translation3d(0, 0, 0.107) * Eigen::AngleAxisd(-M_PI / 4, Eigen::Vector3d::UnitZ());
  if (right_finger) return T * Eigen::Translation3d(0, 0, 0.0584) * Eigen::Translation3d(0, -finger, 0);
  return T * Eigen::Translation3d(0, 0, 0.1034);
}

// Issue 34: ik with mimic joints. The Franka-like arm's second finger mimics the first. At the
// TCP the mimic joint is off the chain (its relation to its leader kept); at the right finger it
// is on the chain, and the search runs in the coupled coordinates (J T): the finger's opening is
// found with the arm's angles. Checked by the DH forward kinematics above to 1e-9 m and rad.
TEST(InverseKinematics, MimicFingerOnAndOffTheChainOfAFrankaLikeArm) {
  const FloatingModel model = loadUrdfFile(KDL_SPACE_TEST_DATA_DIR "/models/franka_like.urdf");
  ASSERT_EQ(model.nj(), 8u);  // seven arm joints and the left finger; the right finger follows it
  ASSERT_EQ(model.mimic().size(), 1u);
  std::mt19937 rng(3434);
  std::uniform_real_distribution<double> u(0.1, 0.9);
  for (const bool right_finger : {false, true}) {
    for (int trial = 0; trial < 2; ++trial) {
      State truth(model);
      truth.world_T_base = KDL::Frame(KDL::Rotation::RPY(0.2, -0.1, 0.3), KDL::Vector(0.5, -0.2, 0.1));
      for (unsigned int j = 0; j < model.nj(); ++j) {
        const JointProperties& p = model.jointProperties()[j];
        truth.q(j) = p.lower + u(rng) * (p.upper - p.lower);
      }
      double q_arm[7];
      for (int i = 0; i < 7; ++i) q_arm[i] = truth.q(model.jointIndex("panda_joint" + std::to_string(i + 1)));
      const int finger = model.jointIndex("panda_finger_joint1");
      Eigen::Isometry3d world_T_base;
      world_T_base.matrix().setIdentity();
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) world_T_base(r, c) = truth.world_T_base.M(r, c);
        world_T_base(r, 3) = truth.world_T_base.p(r);
      }
      const Eigen::Isometry3d goal_e = frankaLikeFrame(world_T_base, q_arm, truth.q(finger), right_finger);
      KDL::Frame goal;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) goal.M(r, c) = goal_e(r, c);
        goal.p(r) = goal_e(r, 3);
      }
      State seed(model);
      seed.world_T_base = truth.world_T_base;
      seed.q(model.jointIndex("panda_joint4")) = -1.5;  // inside its limits
      seed.q(model.jointIndex("panda_joint6")) = 1.5;
      const Contact h = model.contact(right_finger ? "panda_rightfinger" : "panda_hand_tcp");
      const IkResult r = solveInverseKinematics(model, seed, h, goal);
      expectInLimits(model, r.q);
      double q_got[7];
      for (int i = 0; i < 7; ++i) q_got[i] = r.q(model.jointIndex("panda_joint" + std::to_string(i + 1)));
      const Eigen::Isometry3d got = frankaLikeFrame(world_T_base, q_got, r.q(finger), right_finger);
      EXPECT_LE((got.translation() - goal_e.translation()).norm(), 1e-9) << "right finger " << right_finger;
      EXPECT_LE(Eigen::AngleAxisd(got.linear().transpose() * goal_e.linear()).angle(), 1e-9);
      // On the chain the finger is solved; off it the finger keeps the seed's opening.
      if (!right_finger) EXPECT_EQ(r.q(finger), seed.q(finger));
      EXPECT_EQ(std::count(r.chain_joints.begin(), r.chain_joints.end(), finger), right_finger ? 1 : 0);
    }
  }
}

// A robot without movable joints has nothing to solve: refused, saying why.
TEST(InverseKinematics, ARobotWithoutJointsIsRefusedSayingWhy) {
  const std::string urdf = R"(<robot name="r"><link name="bus"><inertial><mass value="100"/>
      <inertia ixx="10" iyy="11" izz="12" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <joint name="f" type="fixed"><parent link="bus"/><child link="fixture"/><origin xyz="1 0 0"/></joint>
      <link name="fixture"/></robot>)";
  const FloatingModel model = loadUrdfString(urdf, "rigid.urdf");
  try {
    solveInverseKinematics(model, State(model), model.contact("fixture"), KDL::Frame(KDL::Vector(1, 0, 0)));
    FAIL() << "a robot without joints was solved";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no movable joint"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'fixture'"), std::string::npos) << e.what();
  }
}

// A goal so far away that squared distances overflow: refused as out of reach, not a crash.
TEST(InverseKinematics, AGoalBeyondTheRangeOfDoublesIsOutOfReach) {
  const FloatingModel model = loadUrdfFile(KDL_SPACE_URDF_DIR "/space_arm7.urdf");
  IkOptions o;
  o.restarts = 1;
  EXPECT_THROW(solveInverseKinematics(model, State(model), model.contact("end_effector"),
                                      KDL::Frame(KDL::Vector(1e200, 0, 0)), o),
               IkUnreachable);
}

}  // namespace
}  // namespace kdl_space
