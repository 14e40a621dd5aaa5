// What bounds the readers' work on a hostile file: a file over its limit is refused before it is
// read (a scenario over 16 MiB, a URDF over max_input_file_bytes, 64 MiB), a mapping's keys are checked for duplicates in O(n) (a large
// mapping loads in a fraction of a second), and a message quotes at most ~80 characters of a field.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "kdl_space/parsers/input_file.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/parsers/urdf/urdf_check.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

namespace fs = std::filesystem;

const std::string kSource = KDL_SPACE_SOURCE_DIR;

fs::path tempDir() {
  const fs::path dir = fs::path(::testing::TempDir()) / "kdl_space_input_limits";
  fs::create_directories(dir);
  return dir;
}

std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = (tempDir() / name).string();
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

/// The bundled tumbling-box capture with its URDF's path absolute (so it loads from anywhere).
std::string tumblingBox() {
  std::ifstream in(kSource + "/scenarios/tumbling_box_capture.yaml");
  std::stringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  text.replace(text.find("../urdf/"), 8, kSource + "/urdf/");
  return text;
}

/// loadScenario's message for a file, or "" if it loads.
std::string scenarioRefusal(const std::string& path) {
  try {
    loadScenario(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(InputLimits, AFileOverTheLimitIsRefusedBeforeItIsRead) {
  // Sparse files: one byte over the limit, their content never written (nor read). A scenario
  // (YAML or JSON) may have 16 MiB, a URDF 64 MiB.
  const std::uintmax_t yaml_limit = std::uintmax_t{16} << 20;
  const std::string scenario = (tempDir() / "huge_scenario.yaml").string();
  std::ofstream(scenario).close();
  fs::resize_file(scenario, yaml_limit + 1);
  const std::string why = scenarioRefusal(scenario);
  EXPECT_EQ(why, scenario + ": is 16777217 bytes (16 MiB), more than the 16 MiB a scenario file (YAML or JSON) may have "
                            "(is it the right file?)");

  const std::uintmax_t size = max_input_file_bytes + 1;
  const std::string expect = "is " + std::to_string(size) + " bytes (64 MiB), more than the 64 MiB a ";

  const std::string urdf = (tempDir() / "huge.urdf").string();
  std::ofstream(urdf).close();
  fs::resize_file(urdf, size);
  try {
    loadUrdfFile(urdf);
    ADD_FAILURE() << "a URDF over the limit loads";
  } catch (const ModelError& e) {
    EXPECT_EQ(std::string(e.what()), urdf + ": " + expect + "URDF file may have (is it the right file?)");
  }
  const UrdfReport report = checkUrdfFile(urdf);
  ASSERT_EQ(report.errors.size(), 1u);
  EXPECT_NE(report.errors[0].message.find(expect + "URDF file"), std::string::npos) << report.errors[0].message;

  // A scenario that names it: refused at its field, the URDF's size said.
  std::string text = tumblingBox();
  text.replace(text.find(kSource + "/urdf/space_arm7.urdf"), (kSource + "/urdf/space_arm7.urdf").size(), urdf);
  const std::string named = scenarioRefusal(writeFile("names_huge.yaml", text));
  EXPECT_NE(named.find("robot.urdf"), std::string::npos) << named;
  EXPECT_NE(named.find(expect + "URDF file"), std::string::npos) << named;

  // At the limit: read (and refused for what it holds, not for its size).
  fs::resize_file(scenario, yaml_limit);
  EXPECT_EQ(scenarioRefusal(scenario).find("more than the 16 MiB"), std::string::npos);
  fs::remove(scenario);
  fs::remove(urdf);
}

/// The tumbling-box scenario with `n` joint patterns under simulation.joints, each a distinct
/// pattern that matches joint1 ("joint[1aaaa]", ...); the last a copy of the first if `twice`.
std::string manyKeys(int n, bool twice) {
  std::string keys = "  joints:\n";
  std::string first;
  for (int k = 0; k < n; ++k) {
    std::string key = "joint[1";
    for (int digit = 0, rest = k; digit < 4; ++digit, rest /= 26) key += static_cast<char>('a' + rest % 26);
    key += "]";
    if (k == 0) first = key;
    keys += "    \"" + (twice && k == n - 1 ? first : key) + "\": free\n";
  }
  std::string text = tumblingBox();
  const std::string joints = "  joints:";
  const std::size_t at = text.find(joints);
  text.replace(at, text.find('\n', at) + 1 - at, keys);
  return text;
}

TEST(InputLimits, DuplicateKeysAreFoundInALargeMappingQuickly) {
  // 200,000 keys: O(n^2) comparisons (2e10) took minutes; hashed, well under a second of checks.
  const int n = 200000;
  const std::string distinct = writeFile("many_keys.yaml", manyKeys(n, false));
  const auto t0 = std::chrono::steady_clock::now();
  const std::string why = scenarioRefusal(distinct);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(why, "");
  EXPECT_LT(seconds, 30.0) << "200,000 keys loaded in " << seconds << " s";

  const std::string doubled = writeFile("many_keys_twice.yaml", manyKeys(n, true));
  const std::string twice = scenarioRefusal(doubled);
  // Named at its second place: the last line of simulation.joints.
  std::ifstream in(doubled);
  std::string text;
  int last_line = 0;
  for (int l = 1; std::getline(in, text); ++l)
    if (text == "    \"joint[1aaaa]\": free") last_line = l;
  EXPECT_EQ(twice, doubled + ":" + std::to_string(last_line) + ": simulation.joints.joint[1aaaa]: given twice");
}

TEST(InputLimits, AMessageQuotesAtMost80CharactersOfAField) {
  // 15 MiB: the largest field a scenario file (16 MiB at most) can hold, in round numbers; a
  // URDF's name below is 20 MiB.
  const std::string huge(15u << 20, 'x');
  const std::string length = "(" + std::to_string(huge.size()) + " characters)";
  const std::string shown = "'" + std::string(40, 'x') + "..." + std::string(36, 'x') + "' " + length;
  const std::string text = tumblingBox();
  const auto refusal = [&](const std::string& name, const std::string& from, const std::string& to) {
    std::string t = text;
    t.replace(t.find(from), from.size(), to);
    return scenarioRefusal(writeFile(name, t));
  };
  // YAML limits an implicit key to 1024 characters: a longer one is an explicit key ("? KEY").
  const std::string pd = "{pd: {kp: 400, kd: 300, set_point: 0.7}}";
  struct Case {
    std::string what, message;
  } cases[] = {
      // a value echoed: the law's type
      {"a value", refusal("long_value.yaml", "type: capture", "type: " + huge)},
      // a key of the file in the field's path: an unknown field
      {"a key", refusal("long_key.yaml", "law:\n", "law:\n  ? " + huge + "\n  : 1\n")},
      // a joint name in the file, not in the model
      {"a name", refusal("long_name.yaml", "    joint2: " + pd, "    ? " + huge + "\n    : " + pd)},
      // a number that is no number
      {"a number", refusal("long_number.yaml", "mass: 50", "mass: " + huge)},
      // a path: the URDF's
      {"a path", refusal("long_path.yaml", kSource + "/urdf/space_arm7.urdf", "/" + huge)},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    EXPECT_LT(c.message.size(), 400u) << c.message.substr(0, 400);
    EXPECT_NE(c.message.find(c.what == "a path" ? "(15728641 characters)" : length), std::string::npos) << c.message.substr(0, 400);
  }
  EXPECT_NE(cases[0].message.find("law.type: " + shown + " is not one of"), std::string::npos) << cases[0].message;

  // A URDF's link name of 20 MiB.
  const std::string name(20u << 20, 'x');
  const std::string urdf = "<robot name='r'><link name='" + name + "'><inertial><mass value='-1'/>"
                           "<inertia ixx='1' iyy='1' izz='1' ixy='0' ixz='0' iyz='0'/></inertial></link></robot>";
  try {
    loadUrdfString(urdf, "long_link.urdf");
    ADD_FAILURE() << "a negative mass loads";
  } catch (const Error& e) {
    const std::string why = e.what();
    EXPECT_LT(why.size(), 400u) << why.substr(0, 400);
    EXPECT_NE(why.find("(20971520 characters)"), std::string::npos) << why.substr(0, 400);
  }
  const UrdfReport report = checkUrdfString(urdf, "long_link.urdf");
  ASSERT_FALSE(report.errors.empty());
  for (const Finding& f : report.errors) EXPECT_LT(describe(f).size(), 400u) << describe(f).substr(0, 400);
}

}  // namespace
}  // namespace kdl_space::test
