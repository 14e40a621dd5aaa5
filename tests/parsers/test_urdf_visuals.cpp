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
  EXPECT_EQ(resolveMeshFile(file, urdf_dir, {}).path, file);
  EXPECT_EQ(resolveMeshFile("file://" + file, urdf_dir, {}).path, file);
  EXPECT_EQ(resolveMeshFile(file, "/nowhere", {(d / "robot").string()}).path, file);  // in the search path
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

// --- A page is shared: nothing outside the folders the user named (issue 35, item 2) ---------------

TEST(MeshFiles, LinksAndPathsOutOfTheNamedFoldersAreRefused) {
  const fs::path d = treeWith("escape", {"robot/meshes/a.stl", "share/pkg/meshes/b.stl", "elsewhere/secret.stl"});
  const std::string urdf_dir = (d / "robot").string(), share = (d / "share").string();
  fs::create_symlink("/etc/passwd", d / "robot/meshes/passwd.stl");
  fs::create_symlink("/proc/self/environ", d / "share/pkg/meshes/environ.stl");
  fs::create_symlink(d / "elsewhere/secret.stl", d / "share/pkg/meshes/secret.stl");
  fs::create_symlink(d / "elsewhere", d / "share/pkg/linked");  // a folder link on the way
  fs::create_symlink(d / "share/pkg/meshes/b.stl", d / "robot/meshes/inside.stl");  // stays inside: read
  const std::vector<std::string> path{share};
  struct Case {
    std::string filename, needle;
  };
  for (const Case& c : std::vector<Case>{
           {"meshes/passwd.stl", "resolves to /etc/passwd"},
           {"package://pkg/meshes/environ.stl", "resolves to /proc/"},
           {"package://pkg/meshes/secret.stl", "elsewhere/secret.stl, which is outside"},
           {"package://pkg/linked/secret.stl", "is outside"},
           {"package://pkg/../../elsewhere/secret.stl", "leaves its package"},
           {"package://../elsewhere/secret.stl", "leaves its package"},
           {"package://pkg//" + (d / "elsewhere/secret.stl").string(), "leaves its package"},
           {"package://./elsewhere/secret.stl", "leaves its package"},
           {"../elsewhere/secret.stl", "is outside the robot file's folder"},
           {(d / "elsewhere/secret.stl").string(), "is outside"},
           {"file://" + (d / "elsewhere/secret.stl").string(), "is outside"},
           {"file:///etc/passwd", "is outside"},
       }) {
    const MeshLocation m = resolveMeshFile(c.filename, urdf_dir, path);
    EXPECT_EQ(m.path, "") << c.filename;
    EXPECT_NE(m.problem.find(c.needle), std::string::npos) << c.filename << ": " << m.problem;
  }
  // What is outside says what to do; a link that stays inside the named folders is read.
  EXPECT_NE(resolveMeshFile("meshes/passwd.stl", urdf_dir, path).problem.find("give --mesh-path"), std::string::npos);
  EXPECT_EQ(resolveMeshFile("meshes/inside.stl", urdf_dir, path).path, fs::canonical(d / "share/pkg/meshes/b.stl").string());
  // Naming the folder a link points into allows it (a colcon --symlink-install's src folder).
  EXPECT_EQ(resolveMeshFile("package://pkg/meshes/secret.stl", urdf_dir, {share, (d / "elsewhere").string()}).path,
            fs::canonical(d / "elsewhere/secret.stl").string());
}

TEST(MeshFiles, AFileOverTheCapIsRefusedBeforeItIsRead) {
  const fs::path d = treeWith("cap", {"robot/meshes/small.stl"});
  const fs::path big = d / "robot/meshes/big.stl";
  std::ofstream(big).close();
  fs::resize_file(big, max_mesh_file_bytes + 1);  // sparse: no disk used
  const MeshLocation m = resolveMeshFile("meshes/big.stl", (d / "robot").string(), {});
  EXPECT_EQ(m.path, "");
  EXPECT_NE(m.problem.find("67108865 bytes"), std::string::npos) << m.problem;
  EXPECT_NE(m.problem.find("more than the 64 MiB a mesh file may have"), std::string::npos) << m.problem;
  // readMeshFile checks it again on the open file (the file may grow after it was resolved).
  const MeshBytes read = readMeshFile(big.string(), false);
  EXPECT_EQ(read.bytes, "");
  EXPECT_NE(read.problem.find("more than the 64 MiB"), std::string::npos) << read.problem;
  fs::resize_file(big, max_mesh_file_bytes);
  EXPECT_EQ(resolveMeshFile("meshes/big.stl", (d / "robot").string(), {}).path, fs::canonical(big).string());
  fs::remove(big);
}

TEST(MeshFiles, ReadingRefusesLinksAndDevicesAndDropsACollada_sImages) {
  const fs::path d = treeWith("read_bytes", {"m/a.stl"});
  fs::create_symlink(d / "m/a.stl", d / "m/link.stl");
  EXPECT_NE(readMeshFile((d / "m/link.stl").string(), false).problem.find("cannot be opened"), std::string::npos)
      << "a link at the name is not followed (the path given is resolved already)";
  EXPECT_NE(readMeshFile("/dev/zero", false).problem.find("not a regular file"), std::string::npos);
  std::ofstream(d / "m/empty.stl").close();
  EXPECT_NE(readMeshFile((d / "m/empty.stl").string(), false).problem.find("empty"), std::string::npos);
  EXPECT_EQ(readMeshFile((d / "m/a.stl").string(), false).bytes, "solid x\nendsolid x\n");
  const std::string geometry = "<library_geometries><geometry id=\"g\"/></library_geometries>";
  std::ofstream(d / "m/t.dae") << "<COLLADA><library_images><image id=\"i\"><init_from>http://127.0.0.1:9/beacon.png"
                               << "</init_from></image></library_images>" << geometry
                               << "<library_images_kept/><library_images/><library_images id=\"x\">file:///etc/passwd</library_images></COLLADA>";
  const MeshBytes dae = readMeshFile((d / "m/t.dae").string(), true);
  EXPECT_EQ(dae.problem, "");
  EXPECT_EQ(dae.bytes, "<COLLADA>" + geometry + "<library_images_kept/></COLLADA>");
  EXPECT_NE(dae.dropped.find("3 <library_images>"), std::string::npos) << dae.dropped;
  EXPECT_EQ(readMeshFile((d / "m/t.dae").string(), false).dropped, "") << "an STL is not XML: kept as it is";
}

}  // namespace
}  // namespace kdl_space::test
