// The model families of the property suite (issue 34, after manif's MANIF_TEST: the contracts
// written once, instantiated for every kind of robot): each family a small URDF in
// tests/data/families/, with the contact points a capture uses and what a planner or an inverse
// kinematics can do on it. The library's suite (tests/families/) and the tool's
// (tests/cli/test_cli_families.cpp) and Python's (python/tests/test_families.py) run every public
// entry over each.
#pragma once

#include <fstream>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

namespace kdl_space::test {

/// One family.
struct ModelFamily {
  std::string name;     ///< also the file's stem: tests/data/families/<name>.urdf
  std::string contact;  ///< the link a capture grasps at (offset below, in its frame)
  double offset[3] = {0, 0, 0};
  /// A second contact of interest (a mimic finger on the chain), or "".
  std::string other_contact;
  unsigned int joints = 0;  ///< coordinates (mimic joints are not)
  bool mimic = false;       ///< has <mimic> joints
};

/// How GoogleTest prints a family in a failure: its name.
inline void PrintTo(const ModelFamily& f, std::ostream* os) { *os << f.name; }

inline std::string familyUrdf(const std::string& name) {
  return std::string(KDL_SPACE_TEST_DATA_DIR) + "/families/" + name + ".urdf";
}

/// Every family: no movable joint (a rigid body; a bus with panels, a point-mass tank and frames
/// on fixed joints), one prismatic joint, a chain with a fixed tool frame, continuous joints, a
/// tree (two arms), a mimic gripper (contact off the mimic joint's chain, and on it), massless
/// base, zero-mass and frame-only links.
inline const std::vector<ModelFamily>& modelFamilies() {
  static const std::vector<ModelFamily> families{
      {"rigid_body", "body", {0.4, 0.1, -0.2}, "", 0, false},
      {"rigid_bus", "grapple_fixture", {0, 0, 0.05}, "sensor_frame", 0, false},
      {"one_prismatic", "tool", {0, 0, 0}, "", 1, false},
      {"chain3", "tool", {0, 0, 0}, "", 3, false},
      {"continuous_chain", "tip", {0, 0, 0}, "", 2, false},
      {"two_arms", "left_tool", {0, 0, 0}, "right_tool", 4, false},
      {"mimic_gripper", "tool", {0, 0, 0}, "right_finger", 4, true},
      {"massless_parts", "a_tool", {0, 0, 0}, "b_fore", 5, false},
  };
  return families;
}

/// Above the families: a tree of `links` links (the commands' O(n) routes from kDenseJoints = 400
/// joints): 10 arms of revolute joints (alternating axes) from a heavy base.
inline std::string largeTree(int links) {
  std::ostringstream x;
  x << "<robot name=\"tree\">\n";
  const auto link = [&](const std::string& name, double mass) {
    x << "<link name=\"" << name << "\"><inertial><mass value=\"" << mass
      << "\"/><inertia ixx=\"0.01\" iyy=\"0.02\" izz=\"0.015\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>\n";
  };
  link("base", 100.0);
  const int arm = (links - 1) / 10;
  for (int i = 1; i < links; ++i) {
    link("l" + std::to_string(i), 1.0 + 0.001 * i);
    const bool first = (i - 1) % arm == 0;
    x << "<joint name=\"j" << i << "\" type=\"revolute\"><parent link=\"" << (first ? "base" : "l" + std::to_string(i - 1))
      << "\"/><child link=\"l" << i << "\"/><origin xyz=\"0.1 0.02 0\" rpy=\"0 0 " << (first ? 0.6 * (i / arm) : 0.1)
      << "\"/><axis xyz=\"" << (i % 3 == 0) << " " << (i % 3 == 1) << " " << (i % 3 == 2)
      << "\"/><limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/></joint>\n";
  }
  x << "</robot>\n";
  return x.str();
}

}  // namespace kdl_space::test
