// readUrdfVisuals: each link's <visual> shapes, origins and colours as written in the URDF.
#include <gtest/gtest.h>

#include <cmath>

#include "kdl_space/parsers/urdf/urdf_visuals.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space::test {
namespace {

const char* const kRobot = R"(<robot name="r">
  <material name="blue"><color rgba="0 0 1 1"/></material>
  <link name="base">
    <inertial><mass value="10"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><origin xyz="0.1 0.2 0.3"/><geometry><box size="1 2 3"/></geometry><material name="blue"/></visual>
    <visual><geometry><sphere radius="0.25"/></geometry><material name="red"><color rgba="1 0 0 0.5"/></material></visual>
  </link>
  <link name="arm">
    <inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><origin rpy="1.5707963267948966 0 0"/><geometry><cylinder radius="0.05" length="0.6"/></geometry></visual>
    <visual><geometry><mesh filename="package://r/meshes/arm.stl" scale="0.001 0.002 0.003"/></geometry></visual>
  </link>
  <link name="bare"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="k" type="fixed"><parent link="arm"/><child link="bare"/></joint>
</robot>)";

TEST(UrdfVisuals, ShapesOriginsAndColoursAsWritten) {
  const auto visuals = readUrdfVisualsString(kRobot, "robot.urdf");
  ASSERT_EQ(visuals.size(), 2u);  // "bare" has none
  EXPECT_EQ(visuals.count("bare"), 0u);
  const std::vector<LinkVisual>& base = visuals.at("base");
  ASSERT_EQ(base.size(), 2u);
  EXPECT_EQ(base[0].shape, LinkVisual::Shape::Box);
  EXPECT_EQ(base[0].size, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(base[0].origin.p, KDL::Vector(0.1, 0.2, 0.3));
  ASSERT_TRUE(base[0].rgba.has_value());  // by name: the robot-level material's colour
  EXPECT_EQ(*base[0].rgba, Eigen::Vector4d(0, 0, 1, 1));
  EXPECT_EQ(base[1].shape, LinkVisual::Shape::Sphere);
  EXPECT_EQ(base[1].size.x(), 0.25);
  ASSERT_TRUE(base[1].rgba.has_value());
  EXPECT_EQ(*base[1].rgba, Eigen::Vector4d(1, 0, 0, 0.5));  // exact in float too
  const std::vector<LinkVisual>& arm = visuals.at("arm");
  ASSERT_EQ(arm.size(), 2u);
  EXPECT_EQ(arm[0].shape, LinkVisual::Shape::Cylinder);
  EXPECT_EQ(arm[0].size.head<2>(), Eigen::Vector2d(0.05, 0.6));
  EXPECT_FALSE(arm[0].rgba.has_value());
  // rpy (pi/2, 0, 0): the visual's z along the link's -y
  const KDL::Vector z = arm[0].origin.M * KDL::Vector(0, 0, 1);
  EXPECT_NEAR(z.x(), 0.0, 1e-12);
  EXPECT_NEAR(z.y(), -1.0, 1e-12);
  EXPECT_NEAR(z.z(), 0.0, 1e-12);
  EXPECT_EQ(arm[1].shape, LinkVisual::Shape::Mesh);
  EXPECT_EQ(arm[1].mesh_file, "package://r/meshes/arm.stl");
  EXPECT_EQ(arm[1].mesh_scale, Eigen::Vector3d(0.001, 0.002, 0.003));
}

TEST(UrdfVisuals, NotAUrdfNamesTheFile) {
  try {
    readUrdfVisualsString("<robot", "broken.urdf");
    FAIL() << "no error";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.urdf"), std::string::npos) << e.what();
  }
  EXPECT_THROW(readUrdfVisuals("/nonexistent/robot.urdf"), ModelError);
}

}  // namespace
}  // namespace kdl_space::test
