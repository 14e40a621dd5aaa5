// The robot's geometry of the overlap check (linkGeometry): each URDF visual bounded by its box
// (a cylinder of radius r and length l by 2r x 2r x l, a sphere by the cube of edge 2r, at the
// visual's origin), a link with a mesh or without a visual by its box of inertia.
#include <gtest/gtest.h>

#include "kdl_space/operation/overlap_check.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

const char* const kShapes = R"(<robot name="shapes">
  <link name="base"><inertial><mass value="12"/><inertia ixx="8" iyy="8" izz="8" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="can"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><origin xyz="0 0 0.3" rpy="0 1.5707963267948966 0"/><geometry><cylinder radius="0.05" length="0.6"/></geometry></visual>
    <visual><origin xyz="0.1 0 0"/><geometry><sphere radius="0.2"/></geometry></visual></link>
  <link name="shell"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="0.3 0.2 0.1"/></geometry></visual>
    <visual><geometry><mesh filename="shell.stl"/></geometry></visual></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="can"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="can"/><child link="shell"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>)";

TEST(OverlapCheck, VisualsAreBoundedByBoxesAndTheRestByBoxesOfInertia) {
  const FloatingModel model = loadUrdfString(kShapes);
  const LinkGeometry g = linkGeometry(model, readUrdfVisualsString(kShapes, "shapes"));
  ASSERT_EQ(g.boxes.size(), 3u);
  // base: no visual: its box of inertia, a 2 m cube (8 = 12 (2^2 + 2^2) / 12).
  EXPECT_FALSE(g.from_visuals[0]);
  ASSERT_EQ(g.boxes[0].size(), 1u);
  EXPECT_TRUE(near(g.boxes[0][0].size, Vector3d(2, 2, 2), 1e-12, 0.0, "base"));
  // can: the cylinder's box 0.1 x 0.1 x 0.6 at its origin (turned), the sphere's 0.4 cube.
  EXPECT_TRUE(g.from_visuals[1]);
  ASSERT_EQ(g.boxes[1].size(), 2u);
  EXPECT_TRUE(near(g.boxes[1][0].size, Vector3d(0.1, 0.1, 0.6), 0.0, 0.0, "cylinder"));
  EXPECT_TRUE(near(toEigen(g.boxes[1][0].pose.p), Vector3d(0, 0, 0.3), 0.0, 0.0, "cylinder's origin"));
  EXPECT_TRUE(near(toEigen(g.boxes[1][0].pose.M * KDL::Vector(0, 0, 1)), Vector3d(1, 0, 0), 0.0, 1e-12, "its axis"));
  EXPECT_TRUE(near(g.boxes[1][1].size, Vector3d(0.4, 0.4, 0.4), 0.0, 0.0, "sphere"));
  EXPECT_TRUE(near(toEigen(g.boxes[1][1].pose.p), Vector3d(0.1, 0, 0), 0.0, 0.0, "sphere's origin"));
  // shell: a mesh beside its box: the box of inertia stands for it all (a 0.245 m cube).
  EXPECT_FALSE(g.from_visuals[2]);
  ASSERT_EQ(g.boxes[2].size(), 1u);
  EXPECT_TRUE(near(g.boxes[2][0].size, Vector3d::Constant(std::sqrt(0.06)), 1e-12, 0.0, "shell"));
  // No visuals at all: every body by its box of inertia.
  EXPECT_EQ(linkGeometry(model, {}).from_visuals, std::vector<bool>(3, false));
}

}  // namespace
}  // namespace kdl_space::test
