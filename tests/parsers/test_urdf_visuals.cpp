// readUrdfVisuals: each link's <visual> shapes, origins and colours as written in the URDF.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

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

namespace fs = std::filesystem;

/// A fresh folder under gtest's temporary one, with `files` (relative paths) written empty.
fs::path treeWith(const std::string& name, const std::vector<std::string>& files) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("kdl_space_meshes_" + name);
  fs::remove_all(dir);
  for (const std::string& f : files) {
    fs::create_directories((dir / f).parent_path());
    std::ofstream(dir / f) << "solid x\nendsolid x\n";
  }
  return dir;
}

TEST(UrdfVisuals, PackageMeshesAreFoundThroughTheSearchPathFirstFolderFirst) {
  const fs::path d = treeWith("package", {"one/pkg/meshes/a.stl", "two/pkg/meshes/a.stl", "two/pkg/meshes/b.dae",
                                           "three/pkg/meshes/c.stl"});
  const std::vector<std::string> path = {(d / "one").string(), (d / "two").string(), (d / "three" / "pkg").string()};
  // In both folders: the first one's.
  EXPECT_EQ(resolveMeshFile("package://pkg/meshes/a.stl", "/nowhere", path).path, (d / "one/pkg/meshes/a.stl").string());
  // Only in the second: the second's.
  EXPECT_EQ(resolveMeshFile("package://pkg/meshes/b.dae", "/nowhere", path).path, (d / "two/pkg/meshes/b.dae").string());
  // A folder that is the package itself (named pkg).
  EXPECT_EQ(resolveMeshFile("package://pkg/meshes/c.stl", "/nowhere", path).path, (d / "three/pkg/meshes/c.stl").string());
  // The order of the search path decides.
  EXPECT_EQ(resolveMeshFile("package://pkg/meshes/a.stl", "/nowhere", {path[1], path[0]}).path,
            (d / "two/pkg/meshes/a.stl").string());
  // Missing: the package and the folders searched are named.
  const MeshLocation missing = resolveMeshFile("package://pkg/meshes/z.stl", "/nowhere", path);
  EXPECT_EQ(missing.path, "");
  EXPECT_NE(missing.problem.find("meshes/z.stl"), std::string::npos) << missing.problem;
  EXPECT_NE(missing.problem.find(path[0]), std::string::npos) << missing.problem;
  EXPECT_NE(resolveMeshFile("package://pkg/meshes/a.stl", "/nowhere", {}).problem.find("pkg"), std::string::npos);
  EXPECT_EQ(resolveMeshFile("package://other/meshes/a.stl", "/nowhere", path).path, "");
}

TEST(UrdfVisuals, RelativeAbsoluteAndFileMeshesAreFoundFromTheUrdfFolder) {
  const fs::path d = treeWith("relative", {"robot/meshes/a.stl"});
  const std::string urdf_dir = (d / "robot").string(), file = (d / "robot/meshes/a.stl").string();
  EXPECT_EQ(resolveMeshFile("meshes/a.stl", urdf_dir, {}).path, file);
  EXPECT_EQ(resolveMeshFile("./meshes/../meshes/a.stl", urdf_dir, {}).path, file);
  EXPECT_EQ(resolveMeshFile(file, "/nowhere", {}).path, file);
  EXPECT_EQ(resolveMeshFile("file://" + file, "/nowhere", {}).path, file);
  const MeshLocation missing = resolveMeshFile("meshes/b.stl", urdf_dir, {});
  EXPECT_EQ(missing.path, "");
  EXPECT_NE(missing.problem.find((d / "robot/meshes/b.stl").string()), std::string::npos) << missing.problem;
  EXPECT_EQ(resolveMeshFile("meshes", urdf_dir, {}).path, "");  // a folder is no mesh
  EXPECT_EQ(resolveMeshFile("https://example.org/a.stl", urdf_dir, {}).path, "");
}

TEST(UrdfVisuals, ReadingAUrdfResolvesItsMeshesAndKeepsTheirScale) {
  const fs::path d = treeWith("read", {"robot/meshes/arm.stl", "share/r/meshes/arm.stl"});
  std::string xml = kRobot;
  const std::string relative = R"(<visual><geometry><mesh filename="meshes/arm.stl" scale="2 3 4"/></geometry></visual>
  </link>
  <link name="bare">)";
  xml.replace(xml.find("</link>\n  <link name=\"bare\">"), std::string("</link>\n  <link name=\"bare\">").size(), relative);
  const fs::path urdf = d / "robot" / "robot.urdf";
  std::ofstream(urdf) << xml;
  const auto visuals = readUrdfVisuals(urdf.string(), {(d / "share").string()});
  const std::vector<LinkVisual>& arm = visuals.at("arm");
  ASSERT_EQ(arm.size(), 3u);
  EXPECT_EQ(arm[1].mesh_path, (d / "share/r/meshes/arm.stl").string()) << arm[1].mesh_problem;
  EXPECT_EQ(arm[1].mesh_scale, Eigen::Vector3d(0.001, 0.002, 0.003));
  EXPECT_EQ(arm[2].mesh_file, "meshes/arm.stl");
  EXPECT_EQ(arm[2].mesh_path, (d / "robot/meshes/arm.stl").string()) << arm[2].mesh_problem;
  EXPECT_EQ(arm[2].mesh_scale, Eigen::Vector3d(2, 3, 4));
  // Without the search path the package mesh is named as missing; the relative one is still found.
  const auto alone = readUrdfVisuals(urdf.string());
  EXPECT_EQ(alone.at("arm")[1].mesh_path, "");
  EXPECT_NE(alone.at("arm")[1].mesh_problem.find("'r'"), std::string::npos) << alone.at("arm")[1].mesh_problem;
  EXPECT_EQ(alone.at("arm")[2].mesh_path, (d / "robot/meshes/arm.stl").string());
}

}  // namespace
}  // namespace kdl_space::test
