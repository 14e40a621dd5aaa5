// Joint limits, damping and friction read into the model (issue 12, item 8), and the lenient
// readings of joints that urdfdom refuses (a revolute joint without <limit>).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/parsers/urdf/urdf_check.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"

namespace kdl_space {
namespace {

const double kInf = std::numeric_limits<double>::infinity();

std::string arm(const std::string& shoulder_extra, const std::string& elbow_type, const std::string& elbow_extra) {
  const std::string inertial =
      R"(<inertial><origin xyz="0.1 0 0"/><mass value="2"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>)";
  return R"(<?xml version="1.0"?><robot name="arm"><link name="base">)" + inertial +
         R"(</link><joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>)" +
         shoulder_extra + R"(</joint><link name="upper">)" + inertial + R"(</link><joint name="elbow" type=")" + elbow_type +
         R"("><parent link="upper"/><child link="fore"/><origin xyz="0.5 0 0"/><axis xyz="0 1 0"/>)" + elbow_extra +
         R"(</joint><link name="fore">)" + inertial + "</link></robot>";
}

TEST(JointProperties, LimitsDampingAndFrictionAreReadIntoTheModel) {
  const FloatingModel model = loadUrdfString(
      arm(R"(<limit lower="-1" upper="2" effort="30" velocity="0"/><dynamics damping="0.5" friction="0.1"/>)",
          "continuous", R"(<limit effort="10" velocity="3"/>)"));
  ASSERT_EQ(model.jointNames(), (std::vector<std::string>{"shoulder", "elbow"}));
  const JointProperties& s = model.jointProperties()[0];
  EXPECT_EQ(s.lower, -1.0);
  EXPECT_EQ(s.upper, 2.0);
  EXPECT_EQ(s.effort, 30.0);
  EXPECT_EQ(s.velocity, kInf);  // 0 is "not given"
  EXPECT_EQ(s.damping, 0.5);
  EXPECT_EQ(s.friction, 0.1);
  const JointProperties& e = model.jointProperties()[1];
  EXPECT_EQ(e.lower, -kInf);  // continuous: no position limits, whatever <limit> says
  EXPECT_EQ(e.upper, kInf);
  EXPECT_EQ(e.effort, 10.0);
  EXPECT_EQ(e.velocity, 3.0);
  EXPECT_EQ(e.damping, 0.0);
  // A payload keeps them.
  EXPECT_EQ(model.withPayload("fore", KDL::RigidBodyInertia(1.0)).jointProperties()[0].damping, 0.5);
}

TEST(JointProperties, NonsenseIsRefusedWithTheJointsName) {
  const FloatingModel model = loadUrdfString(arm(R"(<limit lower="-1" upper="1" effort="1" velocity="1"/>)", "continuous", ""));
  JointProperties bad;
  bad.lower = 1.0;
  bad.upper = -1.0;
  try {
    model.withJointProperties({{"elbow", bad}});
    ADD_FAILURE() << "lower > upper accepted";
  } catch (const ModelError& err) {
    EXPECT_NE(std::string(err.what()).find("'elbow'"), std::string::npos) << err.what();
  }
  JointProperties negative;
  negative.damping = -1.0;
  EXPECT_THROW(model.withJointProperties({{"elbow", negative}}), ModelError);
  EXPECT_THROW(model.withJointProperties({{"nowhere", JointProperties{}}}), ModelError);
}

TEST(JointProperties, RevoluteWithoutLimitIsReadAsContinuous) {
  const std::string xml = arm("", "revolute", "");  // neither joint has <limit>: urdfdom refuses both
  const FloatingModel model = loadUrdfString(xml, "toolbox.urdf");
  EXPECT_EQ(model.nj(), 2u);
  int warnings = 0;
  for (const Diagnostic& d : model.diagnostics()) warnings += d.kind == "revolute_without_limit";
  EXPECT_EQ(warnings, 2);
  EXPECT_EQ(model.jointProperties()[0].lower, -kInf);
  // The same model as written with continuous joints: the same joints, the same motion.
  const FloatingModel continuous = loadUrdfString(arm("", "continuous", "").replace(
      xml.find(R"(name="shoulder" type="revolute")"), std::string(R"(name="shoulder" type="revolute")").size(),
      R"(name="shoulder" type="continuous")"));
  ASSERT_EQ(continuous.nj(), 2u);
  for (int j = 0; j < 2; ++j)
    EXPECT_TRUE(model.bodies()[model.jointBody()[j]].joint_twist.isApprox(
        continuous.bodies()[continuous.jointBody()[j]].joint_twist, 1e-15));
  // check says the same, as a warning (one set of rules), and the file has no error.
  const UrdfReport report = checkUrdfString(xml, "toolbox.urdf");
  EXPECT_TRUE(report.errors.empty());
  int checked = 0;
  for (const Finding& f : report.warnings) checked += f.kind == "revolute_without_limit";
  EXPECT_EQ(checked, 2);
}

TEST(JointProperties, UnexpandedXacroIsNamedAsSuch) {
  const std::string xacro = R"(<?xml version="1.0"?>
<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="mass" value="2"/>
  <link name="base"><inertial><mass value="${mass}"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
</robot>)";
  try {
    loadUrdfString(xacro, "arm.urdf.xacro");
    ADD_FAILURE() << "an unexpanded xacro file loaded";
  } catch (const ModelError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("arm.urdf.xacro: not a URDF yet: an unexpanded xacro file (a <xacro:...> element at line 3)"),
              std::string::npos) << what;
    EXPECT_NE(what.find("xacro FILE.urdf.xacro > FILE.urdf"), std::string::npos) << what;
  }
  const UrdfReport report = checkUrdfString(xacro, "arm.urdf.xacro");
  ASSERT_EQ(report.errors.size(), 1u);
  EXPECT_EQ(report.errors[0].kind, "xacro");
  // xacro's output keeps the namespace attribute: that alone is no xacro file.
  std::string expanded = arm("", "continuous", "");
  expanded.replace(expanded.find(R"(<robot name="arm">)"), 18, R"(<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">)");
  EXPECT_NO_THROW(loadUrdfString(expanded));
}

TEST(JointProperties, AMobileBasesPlanarJointFromTheWorldIsDropped) {
  // A mobile manipulator's description: world -planar-> base_footprint. In orbit its base floats.
  std::string xml = arm("", "continuous", "");
  xml.replace(xml.find("<link name=\"base\">"), 0,
              R"(<link name="world"/><joint name="world_to_base" type="planar"><parent link="world"/>)"
              R"(<child link="base"/><axis xyz="0 0 1"/></joint>)");
  const FloatingModel model = loadUrdfString(xml, "mobile.urdf");
  EXPECT_EQ(model.bodies()[0].name, "base");
  EXPECT_EQ(model.nj(), 2u);
  bool said = false;
  for (const Diagnostic& d : model.diagnostics())
    said |= d.element == "world_to_base" && d.message.rfind("planar joint from the massless root 'world' dropped", 0) == 0;
  EXPECT_TRUE(said);
  EXPECT_TRUE(checkUrdfString(xml, "mobile.urdf").errors.empty());
  EXPECT_EQ(checkUrdfString(xml, "mobile.urdf").model.base, "base");
}

}  // namespace
}  // namespace kdl_space
