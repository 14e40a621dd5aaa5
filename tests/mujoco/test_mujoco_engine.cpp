// The MJCF export (parsers/formats/mjcf.hpp) against MuJoCo itself, an engine that shares no code
// with ours: every bundled robot written by writeMjcf and loaded by mj_loadXML has, at the keyframe
// "scenario" (the state, random), MuJoCo's mass matrix (mj_fullM) equal to our full mass matrix and
// mj_forward's accelerations (contacts, constraints and passive forces off, zero gravity and ctrl)
// equal to our forward dynamics, both in MuJoCo's velocity coordinates (the free joint: the base
// origin's linear velocity in world axes, the angular velocity in body axes), to 1e-10; its base
// pose and twist, the contact site and the target (rigid or free-floating) are the scenario's; the
// damping is MuJoCo's passive force. MuJoCo's refusals are named (a moving body without mass).
// The hand-written tests/data/mjcf/hand_arm.xml read by mjcfToUrdf is MuJoCo's dynamics too.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "kdl_space/algorithm/forward_dynamics.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/parsers/formats/mjcf.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

namespace fs = std::filesystem;

constexpr double kTol = 1e-10;

/// A model and its data, loaded by mj_loadXML from a file (MuJoCo's own reader and compiler).
struct Engine {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  std::string error;
  ~Engine() {
    if (d) mj_deleteData(d);
    if (m) mj_deleteModel(m);
  }
};

std::unique_ptr<Engine> loadFile(const std::string& path) {
  auto e = std::make_unique<Engine>();
  char error[1024] = "";
  e->m = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
  e->error = error;
  if (e->m) e->d = mj_makeData(e->m);
  return e;
}

std::unique_ptr<Engine> loadText(const std::string& xml, const std::string& tag) {
  const fs::path dir = fs::path(::testing::TempDir()) / "kdl_space_mujoco";
  fs::create_directories(dir);
  const fs::path path = dir / (tag + ".xml");
  std::ofstream(path) << xml;
  return loadFile(path.string());
}

/// MuJoCo's velocity coordinates of a system's: the base's six (free joint of the body `base`) then
/// each joint's, by name (`prefix` + the model's names).
std::vector<int> dofMap(const mjModel* m, const FloatingModel& model, const std::string& prefix) {
  const int body = mj_name2id(m, mjOBJ_BODY, (prefix + model.bodies()[0].name).c_str());
  EXPECT_GE(body, 0);
  const int free = m->body_jntadr[body];
  EXPECT_EQ(m->jnt_type[free], mjJNT_FREE);
  std::vector<int> dof;
  for (int k = 0; k < 6; ++k) dof.push_back(m->jnt_dofadr[free] + k);
  for (const std::string& name : model.jointNames()) {
    const int j = mj_name2id(m, mjOBJ_JOINT, (prefix + name).c_str());
    EXPECT_GE(j, 0) << name;
    dof.push_back(j < 0 ? 0 : m->jnt_dofadr[j]);
  }
  return dof;
}

Eigen::Matrix3d rotation(const KDL::Rotation& R) {
  Eigen::Matrix3d E;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) E(i, j) = R(i, j);
  return E;
}

double scale(const Eigen::MatrixXd& m) { return std::max(1.0, m.cwiseAbs().maxCoeff()); }

/// Our full mass matrix in MuJoCo's velocity coordinates (base: the origin's linear velocity in
/// world axes, the angular velocity in body axes; then the joints, model order): from the paper's
/// [[M_a, A_m], [A_m^T, H]] in the locked twist at the CoM y = (v_b - skew(r_g - p_b) w; w), with
/// w = R w_body.
Eigen::MatrixXd ourMassMatrix(const FloatingModel& model, const State& s) {
  FreeFloatingSolver solver(std::make_shared<const FloatingModel>(model));
  EXPECT_EQ(solver.compute(s), 0);
  const int n = static_cast<int>(model.nj());
  Eigen::MatrixXd K(6 + n, 6 + n);
  K << solver.M_a(), solver.A_m(), solver.A_m().transpose(), solver.H().data;
  const Eigen::Vector3d r = solver.r_g() - toEigen(s.world_T_base.p);
  Eigen::MatrixXd T = Eigen::MatrixXd::Identity(6 + n, 6 + n);
  T.block<3, 3>(0, 3) = -skew(r) * rotation(s.world_T_base.M);
  T.block<3, 3>(3, 3) = rotation(s.world_T_base.M);
  return T.transpose() * K * T;
}

/// MuJoCo's matrix or vector at the given coordinates.
Eigen::MatrixXd pick(const Eigen::MatrixXd& M, const std::vector<int>& idx) {
  Eigen::MatrixXd P(idx.size(), M.cols() == 1 ? 1 : idx.size());
  for (std::size_t i = 0; i < idx.size(); ++i)
    for (Eigen::Index j = 0; j < P.cols(); ++j) P(i, j) = M.cols() == 1 ? M(idx[i], 0) : M(idx[i], idx[j]);
  return P;
}

Eigen::MatrixXd fullM(const Engine& e) {
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> M(e.m->nv, e.m->nv);
  mj_fullM(e.m, M.data(), e.d->qM);
  return M;
}

/// Our forward dynamics (zero torques, no wrench, zero gravity) in MuJoCo's coordinates: the base's
/// linear acceleration is d/dt of the origin's world-axes velocity, its angular R^T times the
/// world angular acceleration (d/dt of R^T w = R^T w' since R^T w x w = 0).
Eigen::VectorXd ourAcceleration(const FloatingModel& model, const State& s, const FloatingVelocity& v) {
  ForwardDynamicsSolver fd(std::make_shared<const FloatingModel>(model));
  FloatingAcceleration a;
  a.qddot.resize(model.nj());
  KDL::JntArray tau(model.nj());
  EXPECT_EQ(fd.CartToJnt(s, v, tau, {}, a), 0);
  Eigen::VectorXd x(6 + model.nj());
  x.head<3>() = a.base.head<3>();
  x.segment<3>(3) = rotation(s.world_T_base.M).transpose() * a.base.tail<3>();
  x.tail(model.nj()) = a.qddot.data;
  return x;
}

/// MuJoCo's dynamics of the system written with `prefix` at the data's state equal ours at (s, v).
void expectSameDynamics(Engine& e, const FloatingModel& model, const State& s, const FloatingVelocity& v,
                        const std::string& prefix, const std::string& what) {
  const std::vector<int> dof = dofMap(e.m, model, prefix);
  e.m->opt.disableflags |= mjDSBL_CONSTRAINT | mjDSBL_PASSIVE;  // limits, friction loss, damping off
  mj_forward(e.m, e.d);
  const Eigen::MatrixXd M_ours = ourMassMatrix(model, s), M_mj = pick(fullM(e), dof);
  EXPECT_TRUE(near(M_mj, M_ours, kTol, kTol * scale(M_ours), what + ": mass matrix"));
  const Eigen::VectorXd a_ours = ourAcceleration(model, s, v);
  const Eigen::VectorXd a_mj = pick(Eigen::Map<Eigen::VectorXd>(e.d->qacc, e.m->nv), dof);
  EXPECT_TRUE(near(a_mj, a_ours, kTol, kTol * scale(a_ours), what + ": accelerations"));
  // The damping, as MuJoCo's passive force -damping qdot.
  e.m->opt.disableflags &= ~mjDSBL_PASSIVE;
  mj_forward(e.m, e.d);
  for (unsigned int j = 0; j < model.nj(); ++j)
    EXPECT_NEAR(e.d->qfrc_passive[dof[6 + j]], -model.jointProperties()[j].damping * v.qdot(j), 1e-12)
        << what << ": " << model.jointNames()[j];
  e.m->opt.disableflags |= mjDSBL_PASSIVE;
  mj_forward(e.m, e.d);
}

/// MuJoCo's pose and twist of the base body `name` (after mj_forward) are the state's.
void expectBase(const Engine& e, const std::string& name, const State& s, const KDL::Twist& twist) {
  const int b = mj_name2id(e.m, mjOBJ_BODY, name.c_str());
  ASSERT_GE(b, 0) << name;
  EXPECT_TRUE(near(Eigen::Map<const Eigen::Vector3d>(e.d->xpos + 3 * b), toEigen(s.world_T_base.p), 0, kTol, name + " position"));
  EXPECT_TRUE(near(Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(e.d->xmat + 9 * b),
                   rotation(s.world_T_base.M), 0, kTol, name + " orientation"));
  double res[6];  // (w; v) at the body frame's origin, world axes
  mj_objectVelocity(e.m, e.d, mjOBJ_XBODY, b, res, 0);
  const Vector6d mj = (Vector6d() << res[3], res[4], res[5], res[0], res[1], res[2]).finished();
  const Vector6d ours = (Vector6d() << twist.vel.x(), twist.vel.y(), twist.vel.z(), twist.rot.x(), twist.rot.y(), twist.rot.z()).finished();
  EXPECT_TRUE(near(mj, ours, kTol, kTol, name + " twist"));
}

void expectSite(const Engine& e, const char* site, const FloatingSystem& sys) {
  const int id = mj_name2id(e.m, mjOBJ_SITE, site);
  ASSERT_GE(id, 0) << site;
  Kinematics kin(*sys.model);
  ASSERT_EQ(forwardKinematics(*sys.model, sys.state, kin), 0);
  EXPECT_TRUE(near(Eigen::Map<const Eigen::Vector3d>(e.d->site_xpos + 3 * id), kin.point(sys.contact), 0, kTol, site));
}

FloatingSystem randomSystem(const FloatingModel& model, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  FloatingSystem sys;
  sys.model = std::make_shared<const FloatingModel>(model);
  sys.state = randomState(model, rng);
  sys.velocity = FloatingVelocity(KDL::Twist(KDL::Vector(u(rng), u(rng), u(rng)), KDL::Vector(u(rng), u(rng), u(rng))),
                                  KDL::JntArray(model.nj()));
  for (unsigned int j = 0; j < model.nj(); ++j) sys.velocity.qdot(j) = 2.0 * u(rng);
  sys.contact = model.contact(model.bodies().back().name, KDL::Vector(0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng)));
  return sys;
}

/// The bundled robots MuJoCo refuses as written, and what it says: MuJoCo wants every body that a
/// joint moves to have mass and inertia of its own (> mjMINVAL), where ours needs the mass matrix
/// positive definite only (a massless link between massive ones, a massless base whose links
/// carry the mass).
const std::map<std::string, std::string>& refusedByMuJoCo() {
  static const std::map<std::string, std::string> refused{
      {"massless_parts", "mass and inertia of moving bodies must be larger than mjMINVAL"},
  };
  return refused;
}

TEST(MuJoCo, EveryBundledRobotHasOurMassMatrixAndAccelerations) {
  std::mt19937 rng(1234);
  int compared = 0;
  for (const std::string& file : bundledRobots()) {
    const std::string stem = fs::path(file).stem().string();
    SCOPED_TRACE(stem);
    const FloatingModel model = loadUrdfFile(file);
    if (!model.mimic().empty()) continue;  // writeMjcf refuses it (tests/parsers/test_mjcf.cpp)
    for (int k = 0; k < 3; ++k) {
      MjcfScene scene;
      scene.robot = randomSystem(model, rng);
      const auto e = loadText(writeMjcf(scene), stem);
      const auto refused = refusedByMuJoCo().find(stem);
      if (refused != refusedByMuJoCo().end()) {
        EXPECT_EQ(e->m, nullptr) << "MuJoCo now loads " << stem << ": compare it";
        EXPECT_NE(e->error.find(refused->second), std::string::npos) << e->error;
        break;
      }
      ASSERT_NE(e->m, nullptr) << e->error;
      ASSERT_EQ(e->m->nkey, 1);
      mj_resetDataKeyframe(e->m, e->d, 0);
      mj_forward(e->m, e->d);
      expectBase(*e, model.bodies()[0].name, scene.robot.state, scene.robot.velocity.base_twist);
      expectSite(*e, "contact", scene.robot);
      expectSameDynamics(*e, model, scene.robot.state, scene.robot.velocity, "", stem);
      ++compared;
    }
  }
  EXPECT_GE(compared, 3);
}

TEST(MuJoCo, ArmatureIsInTheMassMatrix) {
  const FloatingModel plain = loadUrdfFile(dataDir() + "/models/srs_arm7.urdf");
  std::vector<double> armature(plain.nj());
  for (unsigned int j = 0; j < plain.nj(); ++j) armature[j] = 0.05 * (j + 1);
  const FloatingModel model = plain.withArmature(armature);
  std::mt19937 rng(5);
  MjcfScene scene;
  scene.robot = randomSystem(model, rng);
  const auto e = loadText(writeMjcf(scene), "armature");
  ASSERT_NE(e->m, nullptr) << e->error;
  mj_resetDataKeyframe(e->m, e->d, 0);
  expectSameDynamics(*e, model, scene.robot.state, scene.robot.velocity, "", "armature");
}

TEST(MuJoCo, RigidTargetHasTheScenariosInertiaPoseAndTwist) {
  const FloatingModel model = loadUrdfFile(dataDir() + "/families/chain3.urdf");
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  MjcfScene scene;
  scene.robot = randomSystem(model, rng);
  RigidTarget t;
  t.mass = 12.5;
  // A box's inertia (MuJoCo checks A + B >= C) in axes turned against the target frame's.
  const Eigen::Matrix3d R = rotation(KDL::Rotation::RPY(u(rng), u(rng), u(rng)));
  t.inertia = R * Eigen::Vector3d(0.9, 1.3, 1.6).asDiagonal() * R.transpose();
  t.pose = basePose(KDL::Vector(u(rng), u(rng), u(rng)), u(rng), u(rng), u(rng));
  t.com = Eigen::Vector3d(0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng));
  t.twist << u(rng), u(rng), u(rng), u(rng), u(rng), u(rng);
  scene.target = t;
  const auto e = loadText(writeMjcf(scene), "rigid_target");
  ASSERT_NE(e->m, nullptr) << e->error;
  mj_resetDataKeyframe(e->m, e->d, 0);
  mj_forward(e->m, e->d);
  const RigidBody world = t.toWorld();
  const int b = mj_name2id(e->m, mjOBJ_BODY, "target");
  ASSERT_GE(b, 0);
  EXPECT_NEAR(e->m->body_mass[b], t.mass, 1e-12 * t.mass);
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> R_i(e->d->ximat + 9 * b);
  const Eigen::Matrix3d I_mj = R_i * Eigen::Map<const Eigen::Vector3d>(e->m->body_inertia + 3 * b).asDiagonal() * R_i.transpose();
  EXPECT_TRUE(near(I_mj, world.I_com, kTol, kTol * scale(world.I_com), "target inertia"));
  EXPECT_TRUE(near(Eigen::Map<const Eigen::Vector3d>(e->d->xipos + 3 * b), world.com, 0, kTol, "target CoM"));
  double res[6];  // (w; v) at the CoM, world axes
  mj_objectVelocity(e->m, e->d, mjOBJ_BODY, b, res, 0);
  const Vector6d mj = (Vector6d() << res[3], res[4], res[5], res[0], res[1], res[2]).finished();
  EXPECT_TRUE(near(mj, world.twist, kTol, kTol, "target twist"));
  // The robot beside it is unchanged.
  expectSameDynamics(*e, model, scene.robot.state, scene.robot.velocity, "", "robot beside a rigid target");
}

TEST(MuJoCo, FreeFloatingTargetIsItsOwnFreeTree) {
  const FloatingModel robot = loadUrdfFile(dataDir() + "/models/srs_arm7.urdf");
  const FloatingModel target = loadUrdfFile(dataDir() + "/families/two_arms.urdf");
  std::mt19937 rng(21);
  MjcfScene scene;
  scene.robot = randomSystem(robot, rng);
  FloatingSystem other = randomSystem(target, rng);
  scene.target = other;
  const auto e = loadText(writeMjcf(scene), "floating_target");
  ASSERT_NE(e->m, nullptr) << e->error;
  mj_resetDataKeyframe(e->m, e->d, 0);
  mj_forward(e->m, e->d);
  expectBase(*e, "target/" + target.bodies()[0].name, other.state, other.velocity.base_twist);
  expectSite(*e, "target_contact", other);
  expectSite(*e, "contact", scene.robot);
  expectSameDynamics(*e, target, other.state, other.velocity, "target/", "free-floating target");
  expectSameDynamics(*e, robot, scene.robot.state, scene.robot.velocity, "", "robot beside a free-floating target");
}

TEST(MuJoCo, HandWrittenFileReadByUsIsMuJoCosDynamics) {
  const std::string file = dataDir() + "/mjcf/hand_arm.xml";
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  std::vector<Diagnostic> notes;
  const FloatingModel model = loadUrdfString(mjcfToUrdf(text.str(), file, notes), file);
  const auto e = loadFile(file);
  ASSERT_NE(e->m, nullptr) << e->error;
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::vector<int> dof = dofMap(e->m, model, "");
  for (int k = 0; k < 3; ++k) {
    // A state set in MuJoCo's coordinates directly, and the same in ours.
    State s = randomState(model, rng);
    FloatingVelocity v(KDL::Twist(KDL::Vector(u(rng), u(rng), u(rng)), KDL::Vector(u(rng), u(rng), u(rng))),
                       KDL::JntArray(model.nj()));
    for (unsigned int j = 0; j < model.nj(); ++j) v.qdot(j) = u(rng);
    mj_resetData(e->m, e->d);
    const int free = e->m->body_jntadr[mj_name2id(e->m, mjOBJ_BODY, "base")];
    double* qpos = e->d->qpos + e->m->jnt_qposadr[free];
    const Eigen::Quaterniond quat(rotation(s.world_T_base.M));
    const double pose[7] = {s.world_T_base.p.x(), s.world_T_base.p.y(), s.world_T_base.p.z(), quat.w(), quat.x(), quat.y(), quat.z()};
    std::copy(pose, pose + 7, qpos);
    const KDL::Vector w_body = s.world_T_base.M.Inverse(v.base_twist.rot);
    const double vel[6] = {v.base_twist.vel.x(), v.base_twist.vel.y(), v.base_twist.vel.z(), w_body.x(), w_body.y(), w_body.z()};
    for (int i = 0; i < 6; ++i) e->d->qvel[dof[i]] = vel[i];
    for (unsigned int j = 0; j < model.nj(); ++j) {
      const int joint = mj_name2id(e->m, mjOBJ_JOINT, model.jointNames()[j].c_str());
      e->d->qpos[e->m->jnt_qposadr[joint]] = s.q(j);
      e->d->qvel[dof[6 + j]] = v.qdot(j);
    }
    mj_forward(e->m, e->d);
    expectBase(*e, "base", s, v.base_twist);
    expectSameDynamics(*e, model, s, v, "", "hand_arm.xml");
  }
}

}  // namespace
}  // namespace kdl_space::test
