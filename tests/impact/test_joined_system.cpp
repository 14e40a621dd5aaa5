// joinAtGrasp (joined_system.hpp): a captured free-floating target and the robot as one model,
// checked against routes that do not go through it:
//   1. the joined model of scenarios/robot_to_robot_capture.yaml vs a URDF written by hand
//      (tests/data/joined/arm7_grasps_twolink.urdf; its grasp transform from the URDFs' numbers by
//      tests/data/joined/grasp_transform.py): G*, H* (joints matched by name), total mass, r_g,
//      I_g at the capture instant and at a random state, and the forward dynamics of a random state;
//   2. after a rigid capture, every body of the joined model has the twist it had in its own
//      system (MomentumSolver's twist of each body, in each system separately), and the joined
//      momentum and energy are the capture's after; also with dual_arm as a tree target re-rooted
//      at one tool (the other arm hangs as before);
//   3. after a translational capture, a Spherical grasp: the same, the grasp point is the same
//      seen from both sides at a later random ball-joint configuration, the chart margin is 1,
//      G* of the O(n) recursion = the dense one through the massless ball links; armature and
//      joint properties carry over (a reversed joint's limits negated and swapped);
//   4. contact points too far apart (the distance named), a target with mimic joints, velocities
//      that do not satisfy the capture law: refused with InputError.
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "impact_robots.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/algorithm/forward_dynamics.hpp"
#include "kdl_space/impact/joined_system.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/simulation/simulation.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

using ModelPtr = std::shared_ptr<const FloatingModel>;
constexpr double kRel = 1e-10;

CaptureProblem scenarioProblem(ImpactKind kind) {
  CaptureProblem p = loadScenario(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/robot_to_robot_capture.yaml").capture;
  p.law.kind = kind;
  return p;
}

JoinedSystem join(const CaptureProblem& p, const CaptureResult& r, GraspJoint grasp) {
  return joinAtGrasp(p.robot, r.robot.after, std::get<FloatingSystem>(p.target), r.floating_target->after, grasp);
}

/// q of `to` from q of `from`, joints matched by name.
KDL::JntArray byName(const FloatingModel& from, const KDL::JntArray& q, const FloatingModel& to) {
  KDL::JntArray out(to.nj());
  EXPECT_EQ(from.nj(), to.nj());
  for (unsigned int j = 0; j < from.nj(); ++j) {
    const int k = to.jointIndex(from.jointNames()[j]);
    EXPECT_GE(k, 0) << from.jointNames()[j];
    if (k >= 0) out(k) = q(j);
  }
  return out;
}

/// The whole-system quantities of both models at the same state (joined's q mapped by name).
void compareModels(const ModelPtr& joined, const ModelPtr& hand, const State& s) {
  State sh(*hand);
  sh.world_T_base = s.world_T_base;
  sh.q = byName(*joined, s.q, *hand);
  FreeFloatingSolver a(joined), b(hand);
  ASSERT_EQ(a.compute(s), 0);
  ASSERT_EQ(b.compute(sh), 0);
  EXPECT_NEAR(joined->totalMass(), hand->totalMass(), kRel * hand->totalMass());
  EXPECT_TRUE(near(a.r_g(), b.r_g(), kRel, kRel, "r_g"));
  EXPECT_TRUE(near(a.I_g(), b.I_g(), kRel, kRel * b.I_g().norm(), "I_g"));
  Matrix6d Ga, Gb;
  ASSERT_EQ(a.G_star(joined->contact("end_effector", KDL::Vector(0, 0, 0.05)), Ga), 0);
  ASSERT_EQ(b.G_star(hand->contact("end_effector", KDL::Vector(0, 0, 0.05)), Gb), 0);
  EXPECT_TRUE(near(Ga, Gb, kRel, kRel * Gb.norm(), "G*"));
  Eigen::MatrixXd Hb(joined->nj(), joined->nj());  // hand's H* in the joined model's order
  for (unsigned int i = 0; i < joined->nj(); ++i)
    for (unsigned int j = 0; j < joined->nj(); ++j)
      Hb(i, j) = b.H_star()(hand->jointIndex(joined->jointNames()[i]), hand->jointIndex(joined->jointNames()[j]));
  EXPECT_TRUE(near(a.H_star().data, Hb, kRel, kRel * Hb.norm(), "H*"));
}

TEST(JoinedSystem, RigidJoinIsTheHandWrittenUrdf) {
  const CaptureProblem p = scenarioProblem(ImpactKind::Capture);
  const CaptureResult r = solveCapture(p);
  const JoinedSystem js = join(p, r, GraspJoint::Rigid);
  const ModelPtr hand = std::make_shared<const FloatingModel>(loadUrdfFile(dataDir() + "/joined/arm7_grasps_twolink.urdf"));
  EXPECT_EQ(js.target_prefix, "target/");  // link1, link2, joint1, joint2 are the arm's too
  EXPECT_EQ(js.model->nj(), 9u);
  EXPECT_TRUE(js.grasp_joints.empty());
  EXPECT_EQ(js.target_joint_sign, (std::vector<double>{-1.0, -1.0}));  // both on the path hand -> base
  for (unsigned int j = 0; j < 2; ++j) {
    EXPECT_EQ(js.model->jointNames()[js.target_joints[j]], "target/" + std::get<FloatingSystem>(p.target).model->jointNames()[j]);
    const JointProperties& jp = js.model->jointProperties()[js.target_joints[j]];
    EXPECT_DOUBLE_EQ(jp.lower, -3.14159);
    EXPECT_DOUBLE_EQ(jp.upper, 3.14159);
    EXPECT_DOUBLE_EQ(jp.effort, 100.0);
  }
  for (unsigned int j = 0; j < p.robot.model->nj(); ++j)
    EXPECT_EQ(js.model->jointNames()[js.robot_joints[j]], p.robot.model->jointNames()[j]);
  compareModels(js.model, hand, js.state);

  std::mt19937 rng(7);
  const State s = randomState(*js.model, rng);
  compareModels(js.model, hand, s);
  // Forward dynamics of a random state and velocity, torques on every joint.
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  FloatingVelocity v(*js.model);
  v.base_twist = KDL::Twist(KDL::Vector(u(rng), u(rng), u(rng)), KDL::Vector(u(rng), u(rng), u(rng)) * 0.3);
  KDL::JntArray tau(js.model->nj());
  for (unsigned int j = 0; j < js.model->nj(); ++j) v.qdot(j) = u(rng), tau(j) = 10.0 * u(rng);
  State sh(*hand);
  sh.world_T_base = s.world_T_base;
  sh.q = byName(*js.model, s.q, *hand);
  const FloatingVelocity vh(v.base_twist, byName(*js.model, v.qdot, *hand));
  FloatingAcceleration aj, ah;
  aj.qddot.resize(js.model->nj());
  ah.qddot.resize(hand->nj());
  ForwardDynamicsSolver fj(js.model), fh(hand);
  ASSERT_EQ(fj.CartToJnt(s, v, tau, {}, aj), 0);
  ASSERT_EQ(fh.CartToJnt(sh, vh, byName(*js.model, tau, *hand), {}, ah), 0);
  EXPECT_TRUE(near(aj.base, ah.base, kRel, kRel * ah.base.norm(), "base acceleration"));
  const KDL::JntArray qdd = byName(*hand, ah.qddot, *js.model);
  EXPECT_TRUE(near(aj.qddot.data, qdd.data, kRel, kRel * qdd.data.norm(), "qddot"));

  // The motion after the capture: 2 s of the joined model from the join, and of the hand-written
  // URDF from the same state, end in the same state (free joints, dopri5 at rtol 1e-12).
  SimulationOptions options;
  options.rtol = 1e-12;
  options.atol = 1e-14;
  Simulator sim_j(js.model, options), sim_h(hand, options);
  SimulationState xj, xh;
  xj.state = js.state;
  xj.velocity = js.velocity;
  xh.state = State(*hand);
  xh.state.world_T_base = js.state.world_T_base;
  xh.state.q = byName(*js.model, js.state.q, *hand);
  xh.velocity = FloatingVelocity(js.velocity.base_twist, byName(*js.model, js.velocity.qdot, *hand));
  ASSERT_EQ(sim_j.run(xj, 2.0, 0.5, {}), 0);
  ASSERT_EQ(sim_h.run(xh, 2.0, 0.5, {}), 0);
  EXPECT_TRUE(near(byName(*hand, xh.state.q, *js.model).data, xj.state.q.data, 1e-9, 1e-10, "q after 2 s"));
  EXPECT_TRUE(near(byName(*hand, xh.velocity.qdot, *js.model).data, xj.velocity.qdot.data, 1e-9, 1e-10, "qdot after 2 s"));
  EXPECT_TRUE(near(toEigen(xh.state.world_T_base.p), toEigen(xj.state.world_T_base.p), 1e-9, 1e-10, "base after 2 s"));
  EXPECT_TRUE(near(toEigen(xh.velocity.base_twist), toEigen(xj.velocity.base_twist), 1e-9, 1e-10, "base twist after 2 s"));
  EXPECT_GT((xj.state.q.data - js.state.q.data).norm(), 1e-3);  // it moved
}

/// Twist of the origin of each body of `m` at (kin, v), by body name with `prefix`.
std::map<std::string, Vector6d> bodyTwists(const ModelPtr& m, const State& s, const FloatingVelocity& v,
                                           const std::string& prefix = "") {
  Kinematics kin(*m);
  EXPECT_EQ(forwardKinematics(*m, s, kin), 0);
  MomentumSolver ms(m);
  EXPECT_EQ(ms.compute(kin, v), 0);
  std::map<std::string, Vector6d> out;
  for (std::size_t i = 0; i < m->bodies().size(); ++i) {
    Vector6d t;
    EXPECT_EQ(ms.contactTwist(Contact{static_cast<int>(i), KDL::Vector::Zero()}, t), 0);
    out[prefix + m->bodies()[i].name] = t;
  }
  return out;
}

/// Every body of both sides moves in the joined system as it did in its own; momentum and energy
/// are the capture's after.
void expectContinues(const CaptureProblem& p, const CaptureResult& r, const JoinedSystem& js) {
  const FloatingSystem& target = std::get<FloatingSystem>(p.target);
  auto joined = bodyTwists(js.model, js.state, js.velocity);
  auto robot = bodyTwists(p.robot.model, p.robot.state, r.robot.after);
  auto tgt = bodyTwists(target.model, target.state, r.floating_target->after, js.target_prefix);
  double scale = 0.0;
  for (const auto& [name, t] : joined) scale = std::max(scale, t.norm());
  std::size_t seen = 0;
  for (const auto* side : {&robot, &tgt})
    for (const auto& [name, t] : *side) {
      ASSERT_TRUE(joined.count(name)) << name;
      EXPECT_TRUE(near(joined[name], t, kRel, kRel * scale, "twist of " + name));
      ++seen;
    }
  const std::size_t grasp_links = js.grasp_joints.size();
  EXPECT_EQ(seen + grasp_links, joined.size());
  // Momentum and energy.
  Kinematics kin(*js.model);
  ASSERT_EQ(forwardKinematics(*js.model, js.state, kin), 0);
  MomentumSolver ms(js.model);
  ASSERT_EQ(ms.compute(kin, js.velocity), 0);
  EXPECT_TRUE(near(ms.momentum(), r.momentum_after, kRel, kRel * r.momentum_after.norm(), "momentum"));
  EXPECT_NEAR(ms.kineticEnergy(), r.energy_after, kRel * r.energy_after);
}

TEST(JoinedSystem, RigidJoinContinuesBothMotions) {
  const CaptureProblem p = scenarioProblem(ImpactKind::Capture);
  const CaptureResult r = solveCapture(p);
  expectContinues(p, r, join(p, r, GraspJoint::Rigid));
}

/// space_arm7 captures dual_arm at its left tool, both at random states and velocities, the
/// target's base placed so that the contact points coincide.
CaptureProblem randomTreeProblem(ImpactKind kind, std::mt19937& rng, const std::string& target_link = "left_tool") {
  CaptureProblem p;
  p.law.kind = kind;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto system = [&](const std::string& file, const std::string& link, KDL::Vector offset) {
    FloatingSystem s;
    s.model = cachedModel(urdfDir() + "/" + file);
    s.state = randomState(*s.model, rng);
    s.velocity = FloatingVelocity(*s.model);
    s.velocity.base_twist = KDL::Twist(KDL::Vector(u(rng), u(rng), u(rng)) * 0.1, KDL::Vector(u(rng), u(rng), u(rng)) * 0.05);
    for (unsigned int j = 0; j < s.model->nj(); ++j) s.velocity.qdot(j) = 0.2 * u(rng);
    s.contact = s.model->contact(link, offset);
    return s;
  };
  p.robot = system("space_arm7.urdf", "end_effector", KDL::Vector(0, 0, 0.05));
  FloatingSystem t = system("dual_arm.urdf", target_link, KDL::Vector(0.01, -0.02, 0.03));
  const Vector3d gap = FloatingSide(p.robot).contactPoint() - FloatingSide(t).contactPoint();
  t.state.world_T_base.p += toKDL(gap);
  p.target = t;
  return p;
}

TEST(JoinedSystem, TreeTargetReRootedAtOneTool) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 3; ++trial) {
    const CaptureProblem p = randomTreeProblem(ImpactKind::Capture, rng);
    const CaptureResult r = solveCapture(p);
    const JoinedSystem js = join(p, r, GraspJoint::Rigid);
    EXPECT_EQ(js.target_prefix, "target/");  // "satellite" is both bases' name
    const FloatingModel& tm = *std::get<FloatingSystem>(p.target).model;
    for (unsigned int j = 0; j < tm.nj(); ++j)  // the left arm is reversed, the right one is not
      EXPECT_EQ(js.target_joint_sign[j], tm.jointNames()[j].rfind("left_", 0) == 0 ? -1.0 : 1.0) << tm.jointNames()[j];
    expectContinues(p, r, js);
  }
  // Grasped at its base: nothing is reversed.
  const CaptureProblem p = randomTreeProblem(ImpactKind::Capture, rng, "satellite");
  const CaptureResult r = solveCapture(p);
  const JoinedSystem js = join(p, r, GraspJoint::Rigid);
  for (const double sign : js.target_joint_sign) EXPECT_EQ(sign, 1.0);
  expectContinues(p, r, js);
}

TEST(JoinedSystem, ArmatureAndJointPropertiesCarryOver) {
  CaptureProblem p = scenarioProblem(ImpactKind::Capture);
  FloatingSystem& target = std::get<FloatingSystem>(p.target);
  JointProperties j1;
  j1.lower = -1.0, j1.upper = 2.0, j1.effort = 7.0, j1.velocity = 0.5, j1.damping = 0.3, j1.friction = 0.2;
  target.model = std::make_shared<const FloatingModel>(
      target.model->withArmature({0.1, 0.2}).withJointProperties({{"joint1", j1}}));
  p.robot.model = std::make_shared<const FloatingModel>(p.robot.model->withArmature(std::vector<double>(7, 0.05)));
  const CaptureResult r = solveCapture(p);
  const JoinedSystem js = join(p, r, GraspJoint::Rigid);
  const int k = js.model->jointIndex("target/joint1");
  ASSERT_GE(k, 0);
  const JointProperties& got = js.model->jointProperties()[k];  // reversed: [-upper, -lower]
  EXPECT_EQ(got.lower, -2.0);
  EXPECT_EQ(got.upper, 1.0);
  EXPECT_EQ(got.effort, 7.0);
  EXPECT_EQ(got.velocity, 0.5);
  EXPECT_EQ(got.damping, 0.3);
  EXPECT_EQ(got.friction, 0.2);
  EXPECT_EQ(js.model->armature()[k], 0.1);
  EXPECT_EQ(js.model->armature()[js.model->jointIndex("target/joint2")], 0.2);
  EXPECT_EQ(js.model->armature()[js.model->jointIndex("joint3")], 0.05);
  EXPECT_EQ(js.model->jointProperties()[js.model->jointIndex("joint3")].upper, 2.96706);
  expectContinues(p, r, js);  // the rotors' energy included
}

TEST(JoinedSystem, SphericalAfterTranslationalCapture) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 3; ++trial) {
    const CaptureProblem p = trial == 0 ? scenarioProblem(ImpactKind::TranslationalCapture)
                                        : randomTreeProblem(ImpactKind::TranslationalCapture, rng);
    const CaptureResult r = solveCapture(p);
    const JoinedSystem js = join(p, r, GraspJoint::Spherical);
    ASSERT_EQ(js.grasp_joints.size(), 3u);
    EXPECT_EQ(sphericalChartMargin(js, js.state), 1.0);
    // The target turns relative to the hand (its angular velocity is its own).
    const Vector6d rel = r.floating_target->contact_twist_after - r.robot.contact_twist_after;
    EXPECT_GT(rel.tail<3>().norm(), 1e-6);
    EXPECT_LT(rel.head<3>().norm(), 1e-12 * (1.0 + r.robot.contact_twist_after.norm()));
    expectContinues(p, r, js);
    // Later: a random configuration of everything, the ball joint included: the grasp point is
    // where both sides see it.
    State s = randomState(*js.model, rng);
    Kinematics kin(*js.model);
    ASSERT_EQ(forwardKinematics(*js.model, s, kin), 0);
    const FloatingSystem& target = std::get<FloatingSystem>(p.target);
    const Contact on_robot = js.model->contact(p.robot.model->bodies()[p.robot.contact.body].name, p.robot.contact.offset);
    const Contact on_target = js.model->contact(js.target_prefix + target.model->bodies()[target.contact.body].name,
                                                target.contact.offset);
    EXPECT_LT((kin.point(on_robot) - kin.point(on_target)).norm(), 1e-12);
    EXPECT_NEAR(sphericalChartMargin(js, s), std::abs(std::cos(s.q(js.grasp_joints[1]))), 1e-15);
    // The massless ball links are no obstacle to the O(n) recursions: G* by both routes, and the
    // articulated-body forward dynamics runs (finite accelerations at the join).
    Matrix6d G_rec, G_dense;
    RecursiveExIITSolver rec(js.model);
    FreeFloatingSolver dense(js.model);
    ASSERT_EQ(rec.compute(s), 0);
    ASSERT_EQ(dense.compute(s), 0);
    ASSERT_EQ(rec.G_star(on_robot, G_rec), 0);
    ASSERT_EQ(dense.G_star(on_robot, G_dense), 0);
    EXPECT_TRUE(near(G_rec, G_dense, 1e-9, 1e-9 * G_dense.norm(), "G* of the spherical join"));
    FloatingAcceleration acc;
    acc.qddot.resize(js.model->nj());
    ForwardDynamicsSolver fd(js.model);
    ASSERT_EQ(fd.CartToJnt(js.state, js.velocity, KDL::JntArray(js.model->nj()), {}, acc), 0);
    EXPECT_TRUE(acc.qddot.data.allFinite());
  }
}

TEST(JoinedSystem, RefusesBadInput) {
  const CaptureProblem p = scenarioProblem(ImpactKind::Capture);
  const CaptureResult r = solveCapture(p);
  FloatingSystem far = std::get<FloatingSystem>(p.target);
  far.state.world_T_base.p += KDL::Vector(0.0, 0.02, 0.0);
  try {
    joinAtGrasp(p.robot, r.robot.after, far, r.floating_target->after, GraspJoint::Rigid);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("target.contact: the target's contact point is 0.02 m from the robot's"),
              std::string::npos)
        << e.what();
  }
  // Within a wider tolerance it is accepted.
  EXPECT_NO_THROW(joinAtGrasp(p.robot, r.robot.after, far, r.floating_target->after, GraspJoint::Rigid, 0.05));
  // Velocities before the capture do not move the contact points together.
  try {
    joinAtGrasp(p.robot, r.robot.before, std::get<FloatingSystem>(p.target), r.floating_target->before,
                GraspJoint::Rigid);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("grasp: the contact points do not move together"), std::string::npos) << e.what();
  }
  // A target with a mimic joint.
  const std::string link = R"(<inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>)";
  const std::string urdf =
      R"(<robot name="m"><link name="b"><inertial><mass value="5"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>)"
      R"(<joint name="a" type="revolute"><parent link="b"/><child link="la"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>)"
      R"(<link name="la">)" + link + R"(</link>)"
      R"(<joint name="f" type="revolute"><parent link="b"/><child link="lf"/><origin xyz="-1 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="a" multiplier="2"/></joint>)"
      R"(<link name="lf">)" + link + R"(</link></robot>)";
  FloatingSystem mimic;
  mimic.model = std::make_shared<const FloatingModel>(loadUrdfString(urdf, "mimic.urdf"));
  mimic.state = State(*mimic.model);
  mimic.velocity = FloatingVelocity(*mimic.model);
  mimic.contact = mimic.model->contact("la");
  try {
    joinAtGrasp(p.robot, r.robot.after, mimic, mimic.velocity, GraspJoint::Rigid);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("target: the model has mimic joints ('f')"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace kdl_space::test
