// MJCF export and import (parsers/formats/mjcf.hpp): every bundled robot written by writeMjcf, read
// back by mjcfToUrdf and loaded by the URDF loader is the same dynamics (J*, H*, G* at a contact on
// its last link, random states, 1e-12; joints matched by name); a model with mimic joints is
// refused by name; a hand-written MJCF (degrees, euler, axisangle, xyaxes, an inertial quat, a
// joint away from its body's origin) equals the same robot written as URDF by hand; every refusal
// names the file, the line and the attribute. MuJoCo itself: tests/mujoco/.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/parsers/formats/mjcf.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

namespace fs = std::filesystem;

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// `b`'s joint positions or rates (model order) for model `a`, matched by joint name.
KDL::JntArray byName(const FloatingModel& from, const KDL::JntArray& x, const FloatingModel& to) {
  KDL::JntArray y(to.nj());
  for (unsigned int j = 0; j < to.nj(); ++j) {
    const int k = from.jointIndex(to.jointNames()[j]);
    EXPECT_GE(k, 0) << "joint " << to.jointNames()[j] << " is not in the original model";
    if (k >= 0) y(j) = x(k);
  }
  return y;
}

/// P with P(i, j) = 1 where model b's joint i is model a's joint j (b's order from a's).
Eigen::MatrixXd permutation(const FloatingModel& a, const FloatingModel& b) {
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(b.nj(), a.nj());
  for (unsigned int i = 0; i < b.nj(); ++i) {
    const int k = a.jointIndex(b.jointNames()[i]);
    if (k >= 0) P(i, k) = 1.0;
  }
  return P;
}

double scale(const Eigen::MatrixXd& m) { return m.size() == 0 ? 1.0 : std::max(1.0, m.cwiseAbs().maxCoeff()); }

/// The free-floating quantities of `a` at `s` and of `b` at the same state (q by name) agree:
/// J*, H* (b's joints permuted to a's order) and G* at a contact on link `link` at `offset`.
void expectSameDynamics(const FloatingModel& a, const FloatingModel& b, const State& s, const std::string& link,
                        const KDL::Vector& offset, double tol, const std::string& what) {
  ASSERT_EQ(a.nj(), b.nj()) << what;
  ASSERT_EQ(a.bodies().size(), b.bodies().size()) << what;
  EXPECT_NEAR(a.totalMass(), b.totalMass(), tol * a.totalMass()) << what;
  auto ma = std::make_shared<const FloatingModel>(a), mb = std::make_shared<const FloatingModel>(b);
  FreeFloatingSolver sa(ma), sb(mb);
  State sb_state = s;
  sb_state.q = byName(a, s.q, b);
  ASSERT_EQ(sa.compute(s), 0) << what;
  ASSERT_EQ(sb.compute(sb_state), 0) << what;
  const Contact ha = a.contact(link, offset), hb = b.contact(link, offset);
  KDL::Jacobian Ja(a.nj()), Jb(b.nj());
  Matrix6d Ga, Gb;
  ASSERT_EQ(sa.J_star(ha, Ja), 0);
  ASSERT_EQ(sb.J_star(hb, Jb), 0);
  ASSERT_EQ(sa.G_star(ha, Ga), 0);
  ASSERT_EQ(sb.G_star(hb, Gb), 0);
  const Eigen::MatrixXd P = permutation(a, b);
  const Eigen::MatrixXd J_b = Jb.data * P, H_b = P.transpose() * sb.H_star().data * P;
  EXPECT_TRUE(near(J_b, Ja.data, tol, tol * scale(Ja.data), what + ": J*"));
  EXPECT_TRUE(near(H_b, sa.H_star().data, tol, tol * scale(sa.H_star().data), what + ": H*"));
  EXPECT_TRUE(near(Gb, Ga, tol, tol * scale(Ga), what + ": G*"));
}

FloatingSystem systemAt(const FloatingModel& model, std::mt19937& rng, const KDL::Vector& offset) {
  FloatingSystem sys;
  sys.model = std::make_shared<const FloatingModel>(model);
  sys.state = randomState(model, rng);
  sys.velocity = FloatingVelocity(model);
  sys.contact = model.contact(model.bodies().back().name, offset);
  return sys;
}

TEST(Mjcf, RoundTripOfEveryBundledRobotKeepsItsDynamics) {
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  int written = 0;
  for (const std::string& file : bundledRobots()) {
    SCOPED_TRACE(file);
    const FloatingModel model = loadUrdfFile(file);
    const KDL::Vector offset(u(rng), u(rng), u(rng));
    MjcfScene scene;
    scene.robot = systemAt(model, rng, offset);
    if (!model.mimic().empty()) {  // franka_like's and mimic_gripper's fingers: the refusal instead (RefusesMimicJoints)
      EXPECT_THROW(writeMjcf(scene), ModelError);
      continue;
    }
    std::vector<Diagnostic> notes;
    const std::string urdf = mjcfToUrdf(writeMjcf(scene), fs::path(file).filename().string() + ".xml", notes);
    const FloatingModel back = loadUrdfString(urdf, file + " (MJCF round trip)");
    for (int k = 0; k < 3; ++k)
      expectSameDynamics(model, back, randomState(model, rng), model.bodies().back().name, offset, 1e-12,
                         fs::path(file).stem().string());
    // The joints' limits, damping and friction, by name.
    for (unsigned int j = 0; j < model.nj(); ++j) {
      const JointProperties& p = model.jointProperties()[j];
      const JointProperties& q = back.jointProperties()[back.jointIndex(model.jointNames()[j])];
      EXPECT_EQ(p.lower, q.lower) << model.jointNames()[j];
      EXPECT_EQ(p.upper, q.upper) << model.jointNames()[j];
      EXPECT_EQ(p.damping, q.damping) << model.jointNames()[j];
      EXPECT_EQ(p.friction, q.friction) << model.jointNames()[j];
    }
    ++written;
  }
  EXPECT_EQ(written, 11);  // 3 in urdf/, 2 models, 8 families, less the two with mimic joints (franka_like, mimic_gripper)
}

TEST(Mjcf, RefusesMimicJointsByName) {
  for (const char* file : {"/families/mimic_gripper.urdf", "/models/franka_like.urdf"}) {
    const FloatingModel model = loadUrdfFile(dataDir() + file);
    ASSERT_FALSE(model.mimic().empty()) << file;
    MjcfScene scene;
    scene.robot.model = std::make_shared<const FloatingModel>(model);
    scene.robot.state = State(model);
    scene.robot.contact = model.contact(model.bodies().back().name);
    try {
      writeMjcf(scene);
      ADD_FAILURE() << file << ": a model with mimic joints was written";
    } catch (const ModelError& e) {
      for (const Mimic& m : model.mimic()) EXPECT_NE(std::string(e.what()).find(m.joint), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("mimic"), std::string::npos) << e.what();
    }
  }
}

TEST(Mjcf, ArmatureComesBackAsNotesThatRestoreIt) {
  const FloatingModel plain = loadUrdfFile(dataDir() + "/models/srs_arm7.urdf");
  std::vector<double> armature(plain.nj());
  for (unsigned int j = 0; j < plain.nj(); ++j) armature[j] = 0.1 * (j + 1);
  const FloatingModel model = plain.withArmature(armature);
  std::mt19937 rng(7);
  MjcfScene scene;
  scene.robot = systemAt(model, rng, KDL::Vector(0, 0, 0.1));
  std::vector<Diagnostic> notes;
  const FloatingModel back = loadUrdfString(mjcfToUrdf(writeMjcf(scene), "arm.xml", notes));
  std::vector<double> restored(back.nj(), 0.0);
  int found = 0;
  for (const Diagnostic& d : notes)
    if (d.kind == "armature") {
      ASSERT_EQ(d.details.size(), 1u);
      restored[back.jointIndex(d.element)] = std::get<double>(d.details[0].second);
      ++found;
    }
  EXPECT_EQ(found, static_cast<int>(plain.nj()));
  expectSameDynamics(model, back.withArmature(restored), randomState(model, rng), model.bodies().back().name,
                     KDL::Vector(0, 0, 0.1), 1e-12, "armature");
}

TEST(Mjcf, DocumentHasTheSceneSettingsAndTheKeyframeOfTheState) {
  const FloatingModel model = loadUrdfFile(dataDir() + "/families/two_arms.urdf");
  std::mt19937 rng(3);
  MjcfScene scene;
  scene.robot = systemAt(model, rng, KDL::Vector(0.1, 0, 0));
  RigidTarget box;
  box.mass = 4.0;
  scene.target = box;
  const std::string xml = writeMjcf(scene);
  for (const char* piece : {"angle=\"radian\"", "gravity=\"0 0 0\"", "<flag contact=\"disable\"/>", "<freejoint",
                            "<site name=\"contact\"", "<body name=\"target\"", "<key name=\"scenario\"", "diaginertia"})
    EXPECT_NE(xml.find(piece), std::string::npos) << piece << "\n" << xml;
  EXPECT_EQ(xml.find("fullinertia"), std::string::npos);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(xml, m, std::regex("qpos=\"([^\"]*)\" qvel=\"([^\"]*)\"")));
  const auto count = [](const std::string& s) {
    std::istringstream in(s);
    int n = 0;
    for (std::string w; in >> w;) ++n;
    return n;
  };
  EXPECT_EQ(count(m[1]), 7 + static_cast<int>(model.nj()) + 7);  // two free joints, the robot's hinges
  EXPECT_EQ(count(m[2]), 6 + static_cast<int>(model.nj()) + 6);
  // 17 significant digits: the base's x position reads back exactly from the keyframe.
  std::istringstream in(m[1].str());
  double x = 0;
  in >> x;
  EXPECT_EQ(x, scene.robot.state.world_T_base.p.x());
}

TEST(Mjcf, HandWrittenFileEqualsTheSameRobotWrittenAsUrdfByHand) {
  std::vector<Diagnostic> notes;
  const std::string file = dataDir() + "/mjcf/hand_arm.xml";
  const FloatingModel read = loadUrdfString(mjcfToUrdf(readText(file), file, notes), file);
  const FloatingModel hand = loadUrdfFile(dataDir() + "/mjcf/hand_arm.urdf");
  std::mt19937 rng(11);
  for (int k = 0; k < 4; ++k)
    expectSameDynamics(hand, read, randomState(hand, rng), "tool", KDL::Vector(0.02, -0.01, 0.03), 1e-12, "hand_arm");
  for (unsigned int j = 0; j < hand.nj(); ++j) {
    const JointProperties& p = hand.jointProperties()[j];
    const JointProperties& q = read.jointProperties()[read.jointIndex(hand.jointNames()[j])];
    for (const auto& [a, b] : {std::pair(p.lower, q.lower), std::pair(p.upper, q.upper)})
      EXPECT_TRUE(a == b || std::abs(a - b) <= 1e-15) << hand.jointNames()[j] << ": " << a << " vs " << b;
    EXPECT_EQ(p.damping, q.damping);
    EXPECT_EQ(p.friction, q.friction);
  }
  bool target_noted = false, geoms_noted = false;
  for (const Diagnostic& d : notes) {
    target_noted = target_noted || (d.element == "box_target" && d.severity == Severity::Note);
    geoms_noted = geoms_noted || d.message.find("1 geoms") != std::string::npos;
  }
  EXPECT_TRUE(target_noted);
  EXPECT_TRUE(geoms_noted);  // the base's box (the plane is the world's)
}

TEST(Mjcf, FullInertiaIsReadInTheBodyAxes) {
  const std::string xml = R"(<mujoco><compiler angle="radian"/><worldbody>
    <body name="b"><freejoint/><inertial pos="0 0 0" mass="3" fullinertia="1 2 3 0.1 -0.2 0.3"/>
    <body name="c" pos="0.1 0.2 0.3"><joint name="j" pos="0.01 0 0" axis="0 1 0"/>
    <inertial pos="0.5 0 0" mass="2" fullinertia="0.4 0.5 0.6 0.01 0.02 0.03"/></body></body></worldbody></mujoco>)";
  std::vector<Diagnostic> notes;
  const FloatingModel m = loadUrdfString(mjcfToUrdf(xml, "inline.xml", notes));
  Eigen::Matrix3d I0, I1;
  I0 << 1, 0.1, -0.2, 0.1, 2, 0.3, -0.2, 0.3, 3;
  I1 << 0.4, 0.01, 0.02, 0.01, 0.5, 0.03, 0.02, 0.03, 0.6;
  EXPECT_TRUE(near(m.bodies()[0].I_com, I0, 0, 1e-15, "base inertia"));
  const Body& c = m.bodies()[m.bodyIndex("c")];
  EXPECT_TRUE(near(c.I_com, I1, 0, 1e-15, "link inertia"));
  EXPECT_TRUE(near(c.com, Eigen::Vector3d(0.49, 0, 0), 0, 1e-15, "CoM in the link frame at the joint"));
}

struct Refusal {
  const char* file;
  int line;
  const char* where;  ///< the element and attribute named
  const char* why;
};

TEST(Mjcf, EveryRefusalNamesTheFileTheLineAndTheAttribute) {
  const std::vector<Refusal> refusals{
      {"ball_joint", 6, "<joint type=\"ball\">", "ball joint"},
      {"unknown_joint_type", 6, "<joint type=\"screw\">", "unknown joint type"},
      {"not_finite", 6, "<joint range=\"-1 nan\">", "'nan' is not a finite number"},
      {"not_a_number", 6, "<joint pos=\"0 0 x\">", "'x' is not a number"},
      {"too_large", 6, "<joint damping=\"1e400\">", "not a finite number"},
      {"wrong_count", 6, "<joint axis=\"0 1\">", "3 numbers expected, 2 found"},
      {"two_joints", 6, "<joint>", "a second joint"},
      {"nested_free", 6, "<freejoint>", "free joint below"},
      {"joint_ref", 6, "<joint ref=\"0.3\">", "reference position"},
      {"missing_mass", 6, "<inertial>", "no mass attribute"},
      {"missing_inertia", 6, "<inertial>", "neither diaginertia nor fullinertia"},
      {"two_orientations", 6, "<body euler=\"0 0 1\">", "orientation twice"},
      {"default_class", 6, "<joint class=\"arm\">", "default classes"},
      {"global_coordinates", 2, "<compiler coordinate=\"global\">", "local coordinates"},
      {"include_file", 2, "<include file=\"robot.xml\">", "included files"},
      {"not_xml", 4, "", "not an XML document"},  // </worldbody> closes no <worldbody>: <body> is open
      {"no_body", 2, "<worldbody>", "no <body>"},
  };
  for (const Refusal& r : refusals) {
    const std::string path = dataDir() + "/mjcf/broken/" + r.file + ".xml";
    std::vector<Diagnostic> notes;
    try {
      mjcfToUrdf(readText(path), path, notes);
      ADD_FAILURE() << r.file << ": read";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path + ":" + std::to_string(r.line) + ": " + r.where, 0), 0u) << r.file << ": " << what;
      EXPECT_NE(what.find(r.why), std::string::npos) << r.file << ": " << what;
    }
  }
}

}  // namespace
}  // namespace kdl_space::test
