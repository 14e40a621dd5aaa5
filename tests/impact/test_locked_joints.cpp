// Joints braked at the impact (RecursiveExIITSolver::setLocked, FreeFloatingSolver::setLocked,
// FloatingSystem::locked), checked against the INDEPENDENT route: the same model with those
// joints made fixed at their current position (a KDL tree copy, tests/support lockJoints), whose
// G*, grounded G, velocity jump and whole capture the unlocked solvers give:
//   1. G (FreeFloating and Grounded) of both routes, recursive and dense, equals the fixed
//      model's, and differs from the unlocked model's (the locks do something);
//   2. the velocity jump: the free joints' and the base's equal the fixed model's, the braked
//      joints' is exactly 0;
//   3. a whole capture (solveCapture) equals the fixed model's; momentum is conserved, the
//      braked joints' rates after are exactly 0;
//   4. FloatingSide refuses a braked joint that moves and a brake vector of the wrong size,
//      naming them; reset keeps the brakes; a mimic leader braked brakes its follower.
// Tolerances: 1e-9 relative (to the largest element of the reference).
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <random>

#include "impact_robots.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"
#include "virtual_joint_route.hpp"

namespace kdl_space::test {
namespace {

using ModelPtr = std::shared_ptr<const FloatingModel>;
constexpr double kRel = 1e-9;

/// a == b to kRel relative to b's largest element.
::testing::AssertionResult same(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const std::string& what) {
  return near(a, b, kRel, kRel * std::max(b.cwiseAbs().maxCoeff(), 1e-300), what);
}

struct LockCase {
  std::string name;
  std::string urdf;
  std::string tip;
  std::vector<std::string> locked;
};
inline void PrintTo(const LockCase& c, std::ostream* os) { *os << c.name; }
std::string caseName(const ::testing::TestParamInfo<LockCase>& info) { return info.param.name; }

std::vector<LockCase> lockCases() {
  const std::string arm7 = urdfDir() + "/space_arm7.urdf", dual = urdfDir() + "/dual_arm.urdf";
  return {{"arm7_joints_2_and_5", arm7, "end_effector", {"joint2", "joint5"}},
          {"arm7_wrist", arm7, "end_effector", {"joint5", "joint6", "joint7"}},
          {"dual_arm_other_arm", dual, "left_tool",
           {"right_joint1", "right_joint2", "right_joint3", "right_joint4", "right_joint5", "right_joint6"}},
          {"dual_arm_shoulder", dual, "left_tool", {"left_joint1"}},
          {"dual_arm_other_shoulder", dual, "left_tool", {"right_joint2"}}};
}

/// The model, a state, the brake flags, and the model with those joints fixed at that state.
struct Braked {
  ModelPtr model, fixed;
  State state, fixed_state;
  std::vector<bool> locked;
  std::vector<int> full_index;  ///< per joint of `fixed`: its index in `model`
  Contact h, fixed_h;
  FloatingVelocity v, fixed_v;  ///< the braked joints' rates 0; the others the same
};

Braked setup(const LockCase& c, unsigned seed) {
  Braked s;
  s.model = cachedModel(c.urdf);
  const unsigned int n = s.model->nj();
  std::mt19937 rng(seed);
  s.state = randomState(*s.model, rng);  // a configuration far from q = 0
  s.locked.assign(n, false);
  std::map<std::string, double> lock_at;
  for (const std::string& name : c.locked) {
    const int j = s.model->jointIndex(name);
    if (j < 0) throw std::invalid_argument("no joint " + name);
    s.locked[j] = true;
    lock_at[name] = s.state.q(j);
  }
  s.fixed = std::make_shared<const FloatingModel>(lockJoints(s.model->tree(), lock_at), baseInertia(*s.model));
  const unsigned int m = s.fixed->nj();
  if (m + c.locked.size() != n) throw std::logic_error("the fixed model has the wrong number of joints");
  s.fixed_state = State(*s.fixed);
  s.fixed_state.world_T_base = s.state.world_T_base;
  std::uniform_real_distribution<double> u(-0.8, 0.8);
  s.v = FloatingVelocity(*s.model);
  s.v.base_twist = KDL::Twist(KDL::Vector(u(rng), u(rng), u(rng)) * 0.2, KDL::Vector(u(rng), u(rng), u(rng)) * 0.1);
  for (unsigned int j = 0; j < n; ++j) s.v.qdot(j) = s.locked[j] ? 0.0 : u(rng);
  s.fixed_v = FloatingVelocity(*s.fixed);
  s.fixed_v.base_twist = s.v.base_twist;
  for (unsigned int k = 0; k < m; ++k) {
    const int j = s.model->jointIndex(s.fixed->jointNames()[k]);
    s.full_index.push_back(j);
    s.fixed_state.q(k) = s.state.q(j);
    s.fixed_v.qdot(k) = s.v.qdot(j);
  }
  const KDL::Vector offset(0.03, -0.02, 0.05);
  s.h = s.model->contact(c.tip, offset);
  s.fixed_h = s.fixed->contact(c.tip, offset);
  return s;
}

class LockedJoints : public ::testing::TestWithParam<LockCase> {};

// --- 1 and 2: the solvers ---------------------------------------------------------------------------

TEST_P(LockedJoints, GAndVelocityJumpEqualThoseOfTheModelWithTheJointsFixed) {
  for (unsigned seed : {3u, 17u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const Braked s = setup(GetParam(), seed);
    const unsigned int n = s.model->nj(), m = s.fixed->nj();
    // The reference: the dense paper formulas on the fixed model (no locks).
    FreeFloatingSolver reference(s.fixed);
    ASSERT_EQ(reference.compute(s.fixed_state), E_NOERROR);
    FreeFloatingSolver dense(s.model), unlocked(s.model);
    RecursiveExIITSolver recursive(s.model);
    dense.setLocked(s.locked);
    recursive.setLocked(s.locked);
    EXPECT_EQ(recursive.locked(), s.locked);
    EXPECT_EQ(dense.locked(), s.locked);
    ASSERT_EQ(dense.compute(s.state), E_NOERROR);
    ASSERT_EQ(unlocked.compute(s.state), E_NOERROR);
    ASSERT_EQ(recursive.compute(s.state), E_NOERROR);
    Vector6d F;
    F << 3.0, -1.5, 2.0, 0.4, -0.7, 0.25;
    for (Response r : {Response::FreeFloating, Response::Grounded}) {
      const std::string rn = r == Response::FreeFloating ? "free" : "grounded";
      SCOPED_TRACE(rn);
      Matrix6d G_ref, G_dense, G_rec, G_unlocked;
      ASSERT_EQ(reference.G(s.fixed_h, r, G_ref), E_NOERROR);
      ASSERT_EQ(dense.G(s.h, r, G_dense), E_NOERROR);
      ASSERT_EQ(recursive.G(s.h, r, G_rec), E_NOERROR);
      ASSERT_EQ(unlocked.G(s.h, r, G_unlocked), E_NOERROR);
      EXPECT_TRUE(same(G_dense, G_ref, "dense G, " + rn));
      EXPECT_TRUE(same(G_rec, G_ref, "recursive G, " + rn));
      if (r == Response::FreeFloating)  // (grounded, the other arm's brakes do not change G)
        EXPECT_GT((G_unlocked - G_ref).norm(), 1e-8 * G_ref.norm()) << "the locks change G* (by more than the tolerance)";
      if (r == Response::FreeFloating) {
        Matrix6d G_star;
        ASSERT_EQ(recursive.G_star(s.h, G_star), E_NOERROR);
        EXPECT_TRUE(same(G_star, G_ref, "recursive G_star"));
        ASSERT_EQ(dense.G_star(s.h, G_star), E_NOERROR);
        EXPECT_TRUE(same(G_star, G_ref, "dense G_star"));
        // Two contacts at once (dense): the diagonal block is the one-contact G*.
        Eigen::MatrixXd G_all(12, 12), G_all_ref(12, 12);
        const Contact base_h = s.model->contact(s.model->bodies()[0].name), fixed_base_h = s.fixed->contact(s.model->bodies()[0].name);
        ASSERT_EQ(dense.G_star(std::vector<Contact>{s.h, base_h}, G_all), E_NOERROR);
        ASSERT_EQ(reference.G_star(std::vector<Contact>{s.fixed_h, fixed_base_h}, G_all_ref), E_NOERROR);
        EXPECT_TRUE(same(G_all, G_all_ref, "dense two-contact G*"));
      }

      // The velocity jump: the reference's dense one, and the recursion on the fixed model.
      KDL::JntArray dq_ref(m), dq_dense(n), dq_rec(n), dq_rec_ref(m);
      Vector6d dPL_ref, dPL_dense, d_base_rec, d_base_rec_ref;
      ASSERT_EQ(reference.velocityJump(s.fixed_h, r, F, dPL_ref, dq_ref), E_NOERROR);
      ASSERT_EQ(dense.velocityJump(s.h, r, F, dPL_dense, dq_dense), E_NOERROR);
      ASSERT_EQ(recursive.velocityJump(s.h, r, F, d_base_rec, dq_rec), E_NOERROR);
      RecursiveExIITSolver fixed_recursive(s.fixed);
      ASSERT_EQ(fixed_recursive.compute(s.fixed_state), E_NOERROR);
      ASSERT_EQ(fixed_recursive.velocityJump(s.fixed_h, r, F, d_base_rec_ref, dq_rec_ref), E_NOERROR);
      EXPECT_TRUE(same(dPL_dense, dPL_ref, "dense momentum jump"));
      EXPECT_TRUE(same(d_base_rec, d_base_rec_ref, "recursive base twist jump"));
      Eigen::VectorXd free_dense(m), free_rec(m);
      for (unsigned int k = 0; k < m; ++k) free_dense(k) = dq_dense(s.full_index[k]), free_rec(k) = dq_rec(s.full_index[k]);
      EXPECT_TRUE(same(free_dense, dq_ref.data, "dense free joints' jump"));
      EXPECT_TRUE(same(free_rec, dq_ref.data, "recursive free joints' jump"));
      for (unsigned int j = 0; j < n; ++j)
        if (s.locked[j]) {
          EXPECT_EQ(dq_dense(j), 0.0) << "dense, braked " << s.model->jointNames()[j];
          EXPECT_EQ(dq_rec(j), 0.0) << "recursive, braked " << s.model->jointNames()[j];
        }
    }
  }
}

// --- 3: the whole capture -----------------------------------------------------------------------

TEST_P(LockedJoints, CaptureEqualsThatOfTheModelWithTheJointsFixed) {
  const Braked s = setup(GetParam(), 29);
  for (ExIITMethod method : {ExIITMethod::Recursive, ExIITMethod::Dense})
    for (Response r : {Response::FreeFloating, Response::Grounded})
      for (ImpactKind kind : {ImpactKind::Capture, ImpactKind::PointImpact}) {
        SCOPED_TRACE(std::string(method == ExIITMethod::Dense ? "dense" : "recursive") + ", " +
                     (r == Response::FreeFloating ? "free" : "grounded") + ", " +
                     (kind == ImpactKind::Capture ? "capture" : "point impact"));
        CaptureProblem p;
        p.method = method;
        p.law.kind = kind;
        p.law.normal = Vector3d(0.6, -0.48, 0.64);
        p.law.restitution = 0.4;
        p.has_normal = true;
        p.robot.model = s.model;
        p.robot.state = s.state;
        p.robot.velocity = s.v;
        p.robot.contact = s.h;
        p.robot.response = r;
        p.robot.locked = s.locked;
        RigidTarget target;
        target.mass = 35.0;
        target.inertia = Vector3d(1.2, 1.6, 2.0).asDiagonal();
        target.pose = KDL::Frame(KDL::Rotation::RPY(0.2, -0.1, 0.4), FloatingSide(p.robot).kinematics().pose(s.h.body) * s.h.offset);
        target.com = Vector3d(0.1, 0.0, -0.05);
        target.twist << -0.3, 0.2, 0.1, 0.05, -0.02, 0.03;
        p.target = target;
        CaptureProblem q = p;
        q.robot.model = s.fixed;
        q.robot.state = s.fixed_state;
        q.robot.velocity = s.fixed_v;
        q.robot.contact = s.fixed_h;
        q.robot.locked = {};
        const CaptureResult a = solveCapture(p), b = solveCapture(q);
        EXPECT_TRUE(same(a.impulse.F, b.impulse.F, "impulse"));
        EXPECT_TRUE(same(a.G_robot, b.G_robot, "G of the robot"));
        EXPECT_TRUE(same(toEigen(a.robot.after.base_twist), toEigen(b.robot.after.base_twist), "base twist after"));
        EXPECT_TRUE(same(a.robot.contact_twist_after, b.robot.contact_twist_after, "contact twist after"));
        EXPECT_TRUE(same(a.target_twist_after, b.target_twist_after, "target twist after"));
        EXPECT_NEAR(a.energy_after, b.energy_after, kRel * b.energy_before);
        EXPECT_TRUE(same(a.momentum_after, b.momentum_after, "momentum after"));
        Eigen::VectorXd free_after(s.fixed->nj());
        for (unsigned int k = 0; k < s.fixed->nj(); ++k) free_after(k) = a.robot.after.qdot(s.full_index[k]);
        EXPECT_TRUE(same(free_after, b.robot.after.qdot.data, "free joints' rates after"));
        for (unsigned int j = 0; j < s.model->nj(); ++j)
          if (s.locked[j]) EXPECT_EQ(a.robot.after.qdot(j), 0.0) << "braked " << s.model->jointNames()[j];
        if (r == Response::FreeFloating)  // the ground takes momentum from a grounded robot
          EXPECT_TRUE(same(a.momentum_after, a.momentum_before, "momentum conserved"));
        EXPECT_LE(a.energy_after, a.energy_before * (1.0 + kRel));
      }
}

INSTANTIATE_TEST_SUITE_P(BundledModels, LockedJoints, ::testing::ValuesIn(lockCases()), caseName);

// --- 4: FloatingSide's refusals, reset, mimic ------------------------------------------------------

TEST(LockedJointsSide, RefusesABrakedJointThatMovesAndAVectorOfTheWrongSize) {
  const Braked s = setup(lockCases()[0], 5);
  FloatingVelocity moving = s.v;
  moving.qdot(s.model->jointIndex("joint5")) = 0.25;
  try {
    FloatingSide side(s.model, s.state, s.h, moving, Response::FreeFloating, ExIITMethod::Recursive, s.locked);
    ADD_FAILURE() << "a braked joint that moves was accepted";
  } catch (const ModelError& e) {
    EXPECT_EQ(std::string(e.what()),
              "FloatingSide: joint 'joint5' is braked but its rate before the impact is 0.25, not 0 (a braked joint "
              "does not move)");
  }
  try {
    FloatingSide side(s.model, s.state, s.h, s.v, Response::Grounded, ExIITMethod::Dense, std::vector<bool>(3, true));
    ADD_FAILURE() << "a brake vector of the wrong size was accepted";
  } catch (const ModelError& e) {
    EXPECT_EQ(std::string(e.what()), "FloatingSide: 3 joint brakes given for the model's 7 joints");
  }
  // Through the FloatingSystem and solveCapture: the robot's part named, the side's kind kept.
  FloatingSystem sys{s.model, s.state, moving, s.h, Response::FreeFloating, s.locked};
  EXPECT_THROW(FloatingSide{sys}, ModelError);
  CaptureProblem p;
  p.robot = sys;
  RigidTarget t;
  t.mass = 10.0;
  t.pose.p = toKDL(FloatingSide(s.model, s.state, s.h, s.v).contactPoint());
  p.target = t;
  try {
    solveCapture(p);
    ADD_FAILURE() << "solveCapture accepted a braked joint that moves";
  } catch (const ModelError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("robot: FloatingSide: joint 'joint5' is braked", 0), 0u) << e.what();
  }
}

TEST(LockedJointsSide, ResetKeepsTheBrakes) {
  const LockCase c = lockCases()[2];
  const Braked s = setup(c, 7), t = setup(c, 8);
  for (ExIITMethod method : {ExIITMethod::Recursive, ExIITMethod::Dense}) {
    FloatingSide side(s.model, s.state, s.h, s.v, Response::FreeFloating, method, s.locked);
    EXPECT_EQ(side.locked(), s.locked);
    ASSERT_EQ(side.reset(t.state, t.v), E_NOERROR);
    const FloatingSide fresh(t.model, t.state, t.h, t.v, Response::FreeFloating, method, t.locked);
    EXPECT_EQ(side.locked(), s.locked);
    EXPECT_TRUE(same(side.G(), fresh.G(), "G after reset"));
    Vector6d F;
    F << 1.0, 2.0, -1.0, 0.1, 0.0, -0.2;
    ASSERT_EQ(side.applyImpulse(F), E_NOERROR);
    for (unsigned int j = 0; j < s.model->nj(); ++j)
      if (s.locked[j]) EXPECT_EQ(side.after().qdot(j), 0.0) << s.model->jointNames()[j];
    FloatingVelocity moving = t.v;
    moving.qdot(s.model->jointIndex("right_joint3")) = 0.1;
    EXPECT_EQ(side.reset(t.state, moving), E_BAD_ARGUMENT) << "a braked joint that moves";
    EXPECT_EQ(side.applyImpulse(F), E_NOT_COMPUTED);
  }
}

TEST(LockedJointsSide, JointsLockedAcceptsASubset) {
  const Braked s = setup(lockCases()[0], 9);
  const FloatingSide all(s.model, s.state, s.h, s.v, Response::JointsLocked);
  const FloatingSide subset(s.model, s.state, s.h, s.v, Response::JointsLocked, ExIITMethod::Recursive, s.locked);
  EXPECT_EQ(subset.G(), all.G());
}

// A mimic leader braked brakes its follower (the dense route, which a capture side of a mimic model takes):
// the same as the model with both joints fixed.
TEST(LockedJointsSide, ABrakedMimicLeaderBrakesItsFollower) {
  const std::string urdf = R"(<robot name="m">
  <link name="base"><inertial><mass value="50"/><inertia ixx="5" iyy="6" izz="7" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="a"><inertial><origin xyz="0.3 0 0"/><mass value="4"/><inertia ixx="0.1" iyy="0.2" izz="0.25" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b"><inertial><origin xyz="0.2 0.05 0"/><mass value="3"/><inertia ixx="0.1" iyy="0.15" izz="0.2" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="c"><inertial><origin xyz="0.1 0 0.02"/><mass value="2"/><inertia ixx="0.05" iyy="0.06" izz="0.07" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="continuous"><parent link="base"/><child link="a"/><origin xyz="0.5 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="j2" type="continuous"><parent link="a"/><child link="b"/><origin xyz="0.6 0 0"/><axis xyz="0 1 0"/></joint>
  <joint name="j3" type="continuous"><parent link="b"/><child link="c"/><origin xyz="0.4 0 0"/><axis xyz="1 0 0"/>
    <mimic joint="j2" multiplier="0.5" offset="0.1"/></joint>
</robot>)";
  const auto model = std::make_shared<const FloatingModel>(loadUrdfString(urdf));
  ASSERT_EQ(model->nj(), 2u);
  State state(*model);
  state.q(model->jointIndex("j1")) = 0.7;
  state.q(model->jointIndex("j2")) = -0.4;
  FloatingVelocity v(*model);
  v.qdot(model->jointIndex("j1")) = 0.3;
  std::vector<bool> locked(2, false);
  locked[model->jointIndex("j2")] = true;
  const Contact h = model->contact("c", KDL::Vector(0.1, 0, 0));
  // The reference: j2 and j3 fixed at their values (j3 = 0.5 j2 + 0.1).
  const auto fixed = std::make_shared<const FloatingModel>(
      lockJoints(model->tree(), {{"j2", -0.4}, {"j3", 0.5 * -0.4 + 0.1}}), baseInertia(*model));
  ASSERT_EQ(fixed->nj(), 1u);
  State fixed_state(*fixed);
  fixed_state.q(0) = 0.7;
  FloatingVelocity fixed_v(*fixed);
  fixed_v.qdot(0) = 0.3;
  const Contact fixed_h = fixed->contact("c", KDL::Vector(0.1, 0, 0));
  for (Response r : {Response::FreeFloating, Response::Grounded}) {
    const FloatingSide side(model, state, h, v, r, ExIITMethod::Recursive, locked);  // takes the dense route
    const FloatingSide ref(fixed, fixed_state, fixed_h, fixed_v, r);
    EXPECT_TRUE(same(side.G(), ref.G(), "G with a braked mimic leader"));
  }
}

}  // namespace
}  // namespace kdl_space::test
