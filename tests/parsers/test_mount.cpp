// An arm mounted on a bus (urdf_mount.hpp, a scenario's robot.mount): the joined model's mass,
// CoM and inertia are the hand computation's (rotations by Eigen from the pose's roll, pitch and
// yaw, not KDL's); the joined model equals a wrapper URDF written by text insertion to 1e-12 (G*,
// H*, J*); clashing names are prefixed and said; relative mesh paths made absolute; every refusal
// names the file or field.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "kdl_space/parsers/urdf/urdf_mount.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

namespace fs = std::filesystem;

fs::path scratch() {
  const fs::path dir = fs::path(::testing::TempDir()) / "kdl_space_mount";
  fs::create_directories(dir);
  return dir;
}

std::string write(const std::string& name, const std::string& text) {
  const fs::path p = scratch() / name;
  std::ofstream(p) << text;
  return p.string();
}

std::string slurpFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A two-link arm: a root "arm_base" (3 kg) and "upper" (2 kg) on a revolute joint about z, 0.1 m up.
const std::string kArm = R"(<robot name="little_arm">
  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>
  <link name="arm_base">
    <inertial><origin xyz="0 0 0.05"/><mass value="3"/><inertia ixx="0.02" iyy="0.03" izz="0.04" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="meshes/base.stl"/></geometry><material name="grey"/></visual>
  </link>
  <link name="upper">
    <inertial><origin xyz="0.25 0 0"/><mass value="2"/><inertia ixx="0.01" iyy="0.05" izz="0.06" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="shoulder" type="revolute"><parent link="arm_base"/><child link="upper"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
</robot>
)";

/// URDF's fixed-axis roll, pitch, yaw: R = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Matrix3d rpy(double r, double p, double y) {
  return (Eigen::AngleAxisd(y, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(p, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

TEST(Mount, TheJoinedMassCoMAndInertiaAreTheHandComputation) {
  const std::string arm = write("little_arm.urdf", kArm);
  BusBody bus;
  bus.mass = 1200;
  bus.box = Eigen::Vector3d(2.0, 1.8, 1.6);
  bus.inertia = boxInertia(bus.mass, bus.box);
  bus.com = Eigen::Vector3d(0.1, 0.0, -0.05);
  ArmMount a{arm, "", KDL::Frame(KDL::Rotation::RPY(0.3, -0.2, 0.5), KDL::Vector(1.0, 0.2, 0.9))};
  const MountedRobot joined = mountArms(bus, {a});
  ASSERT_EQ(joined.files, std::vector<std::string>{arm});
  const auto model = std::make_shared<const FloatingModel>(loadUrdfString(joined.urdf, "joined"));
  ASSERT_EQ(model->nj(), 1u);
  ASSERT_EQ(model->jointNames()[0], "shoulder");
  EXPECT_EQ(model->bodies()[0].name, "bus");

  // By hand: each body's mass, CoM and inertia in the world (the bus's frame, q = 0.4).
  const double q = 0.4;
  struct Part {
    double m;
    Eigen::Vector3d c;
    Eigen::Matrix3d I;
  };
  const Eigen::Matrix3d R0 = rpy(0.3, -0.2, 0.5);
  const Eigen::Vector3d p0(1.0, 0.2, 0.9);
  const Eigen::Matrix3d R1 = R0 * Eigen::AngleAxisd(q, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d p1 = p0 + R0 * Eigen::Vector3d(0, 0, 0.1);
  const Eigen::Matrix3d box = (1200.0 / 12.0) * Eigen::Vector3d(1.8 * 1.8 + 1.6 * 1.6, 2.0 * 2.0 + 1.6 * 1.6,
                                                                2.0 * 2.0 + 1.8 * 1.8).asDiagonal();
  const std::vector<Part> parts{
      {1200.0, Eigen::Vector3d(0.1, 0.0, -0.05), box},
      {3.0, p0 + R0 * Eigen::Vector3d(0, 0, 0.05), R0 * Eigen::Vector3d(0.02, 0.03, 0.04).asDiagonal() * R0.transpose()},
      {2.0, p1 + R1 * Eigen::Vector3d(0.25, 0, 0), R1 * Eigen::Vector3d(0.01, 0.05, 0.06).asDiagonal() * R1.transpose()}};
  double M = 0;
  Eigen::Vector3d mc = Eigen::Vector3d::Zero();
  for (const Part& p : parts) M += p.m, mc += p.m * p.c;
  const Eigen::Vector3d r_g = mc / M;
  Eigen::Matrix3d I_g = Eigen::Matrix3d::Zero();
  for (const Part& p : parts) I_g += p.I - p.m * skew(p.c - r_g) * skew(p.c - r_g);  // eq. 3

  State s(*model);
  s.q(0) = q;
  Kinematics kin(*model);
  ASSERT_EQ(forwardKinematics(*model, s, kin), 0);
  MomentumSolver momentum(model);
  ASSERT_EQ(momentum.compute(kin, FloatingVelocity(*model)), 0);
  EXPECT_NEAR(model->totalMass(), M, 1e-12 * M);
  EXPECT_TRUE(near(momentum.r_g(), r_g, 0, 1e-14, "r_g"));
  EXPECT_TRUE(near(momentum.I_g(), I_g, 0, 1e-12 * I_g.norm(), "I_g"));
}

/// `arm_text` with a bus link and its mount joint inserted after <robot ...> by text: the wrapper
/// a user writes by hand.
std::string wrapper(const std::string& arm_text, const std::string& root, const std::string& pose_xyz,
                    const std::string& pose_rpy) {
  const std::string bus =
      "\n<link name=\"bus\"><inertial><origin xyz=\"0.1 -0.2 0.05\" rpy=\"0 0 0\"/><mass value=\"900\"/>"
      "<inertia ixx=\"310\" ixy=\"4\" ixz=\"-2\" iyy=\"280\" iyz=\"3\" izz=\"350\"/></inertial></link>\n"
      "<joint name=\"" + root + "_mount\" type=\"fixed\"><origin xyz=\"" + pose_xyz + "\" rpy=\"" + pose_rpy +
      "\"/><parent link=\"bus\"/><child link=\"" + root + "\"/></joint>\n";
  std::smatch m;
  EXPECT_TRUE(std::regex_search(arm_text, m, std::regex("<robot[^>]*>")));
  const std::size_t at = m.position(0) + m.length(0);
  return arm_text.substr(0, at) + bus + arm_text.substr(at);
}

TEST(Mount, TheJoinedModelIsTheHandWrittenWrappersTo1e12) {
  for (const char* file : {"space_arm7.urdf", "dual_arm.urdf", "spacedyn_twolink.urdf"}) {
    const std::string arm = urdfDir() + "/" + file;
    const FloatingModel alone = loadUrdfFile(arm);
    const std::string root = alone.bodies()[0].name;
    BusBody bus;
    bus.mass = 900;
    bus.com = Eigen::Vector3d(0.1, -0.2, 0.05);
    bus.inertia << 310, 4, -2, 4, 280, 3, -2, 3, 350;
    const MountedRobot joined =
        mountArms(bus, {ArmMount{arm, "", KDL::Frame(KDL::Rotation::RPY(0.25, 0.5, -1.0), KDL::Vector(1.2, -0.3, 0.8))}});
    double r = 0, p = 0, y = 0;
    KDL::Rotation::RPY(0.25, 0.5, -1.0).GetRPY(r, p, y);
    char xyz[128], angles[128];
    std::snprintf(xyz, sizeof xyz, "%.17g %.17g %.17g", 1.2, -0.3, 0.8);
    std::snprintf(angles, sizeof angles, "%.17g %.17g %.17g", r, p, y);
    const auto mine = std::make_shared<const FloatingModel>(loadUrdfString(joined.urdf, "joined"));
    const auto theirs = std::make_shared<const FloatingModel>(loadUrdfString(wrapper(slurpFile(arm), root, xyz, angles), "wrapper"));
    ASSERT_EQ(mine->nj(), theirs->nj()) << file;
    ASSERT_EQ(mine->jointNames(), theirs->jointNames()) << file;
    FreeFloatingSolver a(mine), b(theirs);
    State sa(*mine), sb(*theirs);
    for (unsigned int j = 0; j < mine->nj(); ++j) sa.q(j) = sb.q(j) = 0.3 * std::sin(1.0 + 2.1 * j);
    sa.world_T_base = sb.world_T_base = KDL::Frame(KDL::Rotation::RPY(0.1, 0.2, 0.3), KDL::Vector(0.5, 0.4, -0.2));
    ASSERT_EQ(a.compute(sa), 0);
    ASSERT_EQ(b.compute(sb), 0);
    EXPECT_TRUE(near(a.H_star().data, b.H_star().data, 0, 1e-12 * b.H_star().data.norm(), std::string(file) + " H*"));
    for (const Body& body : alone.bodies()) {
      const Contact ha = mine->contact(body.name, KDL::Vector(0.02, 0.01, -0.03));
      const Contact hb = theirs->contact(body.name, KDL::Vector(0.02, 0.01, -0.03));
      Matrix6d Ga, Gb;
      ASSERT_EQ(a.G_star(ha, Ga), 0);
      ASSERT_EQ(b.G_star(hb, Gb), 0);
      EXPECT_TRUE(near(Ga, Gb, 0, 1e-12 * Gb.norm(), std::string(file) + " G* at " + body.name));
      KDL::Jacobian Ja(mine->nj()), Jb(theirs->nj());
      ASSERT_EQ(a.J_star(ha, Ja), 0);
      ASSERT_EQ(b.J_star(hb, Jb), 0);
      EXPECT_TRUE(near(Ja.data, Jb.data, 0, 1e-12 * (Jb.data.norm() + 1), std::string(file) + " J* at " + body.name));
    }
  }
}

TEST(Mount, TwoArmsOfOneFileArePrefixedAndSaidSo) {
  const std::string arm = write("little_arm.urdf", kArm);
  BusBody bus;
  bus.mass = 500;
  bus.inertia = boxInertia(500, Eigen::Vector3d(1, 1, 1));
  const MountedRobot joined = mountArms(bus, {ArmMount{arm, "", KDL::Frame(KDL::Vector(0.5, 0, 0))},
                                              ArmMount{arm, "bus", KDL::Frame(KDL::Vector(-0.5, 0, 0))}});
  const FloatingModel m = loadUrdfString(joined.urdf, "joined");
  std::vector<std::string> names = m.jointNames();
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"arm2/shoulder", "shoulder"}));
  EXPECT_GE(m.bodyIndex("arm2/upper"), 0);
  EXPECT_NEAR(m.totalMass(), 500 + 2 * 5, 1e-12);
  ASSERT_FALSE(joined.notes.empty());
  bool said = false;
  for (const Diagnostic& d : joined.notes)
    said |= d.message.find("every link and joint of it prefixed 'arm2/'") != std::string::npos;
  EXPECT_TRUE(said);
  // The one material, defined the same way twice, is written once; the mesh path is absolute.
  EXPECT_EQ(std::regex_search(joined.urdf, std::regex("<material name=\"grey\">[\\s\\S]*<material name=\"grey\">")), false);
  EXPECT_NE(joined.urdf.find("filename=\"" + (scratch() / "meshes/base.stl").string() + "\""), std::string::npos);
}

TEST(Mount, ABusFromItsOwnUrdfAndAnArmOnItsDeck) {
  const std::string arm = write("little_arm.urdf", kArm);
  const std::string bus_file = write("bus.urdf", R"(<robot name="servicer">
  <link name="core"><inertial><mass value="800"/><inertia ixx="200" iyy="220" izz="250" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="deck"><inertial><origin xyz="0 0 0.02"/><mass value="40"/><inertia ixx="2" iyy="2" izz="4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="deck_joint" type="fixed"><parent link="core"/><child link="deck"/><origin xyz="0 0 1"/></joint>
</robot>
)");
  BusBody bus;
  bus.urdf = bus_file;
  const MountedRobot joined = mountArms(bus, {ArmMount{arm, "deck", KDL::Frame::Identity()}});
  EXPECT_EQ(joined.files, (std::vector<std::string>{bus_file, arm}));
  const FloatingModel m = loadUrdfString(joined.urdf, "joined");
  EXPECT_EQ(m.bodies()[0].name, "core");
  EXPECT_NEAR(m.totalMass(), 845.0, 1e-12);
  // the arm's root 1 m up (on the deck): its base link's frame
  State s(m);
  Kinematics kin(m);
  ASSERT_EQ(forwardKinematics(m, s, kin), 0);
  EXPECT_NEAR(kin.pose(m.bodyIndex("upper")).p.z(), 1.1, 1e-15);
}

std::string refusal(const BusBody& bus, const std::vector<ArmMount>& arms) {
  try {
    mountArms(bus, arms);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Mount, RefusesWhatCannotBeJoinedNamingTheFile) {
  const std::string arm = write("little_arm.urdf", kArm);
  BusBody bus;
  bus.mass = 100;
  bus.inertia = boxInertia(100, Eigen::Vector3d(1, 1, 1));
  const std::string missing = (scratch() / "nope.urdf").string();
  EXPECT_EQ(refusal(bus, {ArmMount{missing}}), missing + ": no such file");
  EXPECT_EQ(refusal(bus, {ArmMount{arm, "deck"}}), arm + ": arm 1 hangs on the bus link 'deck', which the bus has not");
  const std::string two_roots = write("two_roots.urdf", R"(<robot name="r"><link name="a"/><link name="b"/></robot>)");
  EXPECT_EQ(refusal(bus, {ArmMount{two_roots}}),
            two_roots + ": arm 1: expected one root link (a link no joint has as its child), found 2");
  const std::string not_xml = write("not_xml.urdf", "<robot name=\"r\"><link name=\"a\">\n</robot>");
  EXPECT_NE(refusal(bus, {ArmMount{not_xml}}).find(not_xml + ":"), std::string::npos);
  EXPECT_NE(refusal(bus, {ArmMount{not_xml}}).find("not an XML document"), std::string::npos);
  BusBody weightless = bus;
  weightless.mass = 0;
  EXPECT_EQ(refusal(weightless, {ArmMount{arm}}), "bus.mass: must be a finite mass > 0 kg, got 0");
}

// robot.mount in a scenario: the arm on a bus given as mass and box, loaded, capture solved; the
// scenario's inputs are the arm's file; a target may not be mounted; fields refused by name.
TEST(Mount, AScenarioMountsItsArmOnABusGivenAsMassAndBox) {
  write("little_arm.urdf", kArm);
  const std::string path = write("mounted.yaml", R"(robot:
  urdf: little_arm.urdf
  mount: {bus: {mass: 1200, box: [2, 1.8, 1.6]}, pose: {position: [1, 0, 0.9], rpy: {deg: [0, 90, 0]}}}
  contact: {link: upper, offset: [0.5, 0, 0]}
  q: {shoulder: {deg: 20}}
target: {mass: 20, inertia: [[1, 0, 0], [0, 1, 0], [0, 0, 1]], pose: {position: [1.9, 0.2, 0.9]}, twist: [0, -0.05, 0, 0, 0, 0.1]}
law: {type: capture}
)");
  const Scenario sc = loadScenario(path);
  EXPECT_TRUE(sc.robot_urdf.empty());
  EXPECT_EQ(sc.robot_files, std::vector<std::string>{(scratch() / "little_arm.urdf").string()});
  EXPECT_NE(sc.robot_document.find("<link name=\"bus\">"), std::string::npos);
  EXPECT_NEAR(sc.capture.robot.model->totalMass(), 1205.0, 1e-12);
  const CaptureResult r = solveCapture(sc.capture);
  EXPECT_TRUE(near(r.momentum_after, r.momentum_before, 0, 1e-10 * r.momentum_before.norm(), "momentum"));
  EXPECT_FALSE(robotVisuals(sc).empty());  // the arm's mesh and the bus's box

  const auto refused = [](const std::string& name, const std::string& text) {
    const std::string p = write(name, text);
    try {
      loadScenario(p);
    } catch (const Error& e) {
      return std::string(e.what()).substr(p.size());
    }
    return std::string();
  };
  EXPECT_EQ(refused("no_inertia.yaml", "robot:\n  urdf: little_arm.urdf\n  mount: {bus: {mass: 10}}\n"),
            ":3: robot.mount.bus: give the bus's inertia (about its CoM) or a box (uniform density): bus: {mass, box: [x, y, z]}");
  EXPECT_EQ(refused("both.yaml", "robot:\n  urdf: little_arm.urdf\n  mount: {bus: {urdf: b.urdf, mass: 10}}\n"),
            ":3: robot.mount.bus.mass: the bus is its URDF file (bus.urdf) or a body (mass, box or inertia), not both");
  EXPECT_EQ(refused("arms_and_urdf.yaml",
                    "robot:\n  urdf: little_arm.urdf\n  mount: {bus: {mass: 10, box: [1, 1, 1]}, arms: [{urdf: little_arm.urdf}]}\n"),
            ":2: robot.urdf: with mount.arms each arm names its urdf there: remove robot.urdf");
  EXPECT_NE(refused("bad_key.yaml", "robot:\n  urdf: little_arm.urdf\n  mount: {bus: {mass: 10, box: [1, 1, 1]}, at: 3}\n")
                .find("robot.mount"),
            std::string::npos);
  EXPECT_EQ(refused("mounted_target.yaml",
                    "robot:\n  urdf: little_arm.urdf\n  contact: {link: upper}\ntarget:\n  urdf: little_arm.urdf\n"
                    "  contact: {link: upper}\n  mount: {bus: {mass: 10, box: [1, 1, 1]}}\nlaw: {type: capture}\n"),
            ":7: target.mount: only the robot is mounted (its arms on a bus): give the target's urdf");
}

}  // namespace
}  // namespace kdl_space::test
