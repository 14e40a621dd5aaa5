// `kdl_space check` end to end: one broken URDF per problem (tests/data/broken_urdf/), each
// reported with its exact line, JSON entry and exit code; a file with several problems reports
// every one; --strict, --tip; the bundled models pass; no input crashes the tool.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "cli_runner.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

const std::string kBroken = dataDir() + "/broken_urdf/";

/// One expected finding: `element_type` is how the text names the element ("link", "joint",
/// "robot", "tip"; "" for the file as a whole).
struct Expected {
  std::string kind, element_type, element, message;

  std::string text() const {
    return element_type.empty() ? message : element_type + " '" + element + "': " + message;
  }
};

struct Case {
  std::string file;   ///< in tests/data/broken_urdf/, without ".urdf"
  std::string args;   ///< after the file name
  int rc;
  std::vector<Expected> errors, warnings;
  std::vector<Expected> notes = {};  ///< what was read and how: printed, never failing a check
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.file << c.args; }

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

std::string count(std::size_t n, const std::string& word) { return std::to_string(n) + " " + word + (n == 1 ? "" : "s"); }

// The messages, written from the requirements: the element, what is wrong, what to do.
const std::string kFreeJoint =
    "a floating joint inside the tree is not supported (only the base floats; use revolute, continuous, "
    "prismatic or fixed joints); a floating joint is accepted only from a massless root link (such as "
    "'world') to its only child, the base";

const std::string kTriangle =
    "principal moments 0.1, 0.1, 0.3 kg m^2 break the triangle inequality I1 + I2 >= I3 by 0.1 kg m^2 "
    "(33.3333 % of I3): no rigid body has this inertia; read as written (the dynamics are defined while the "
    "bodies are positive definite)";

const std::vector<Case>& cases() {
  static const std::vector<Case> all = {
      {"valid", "", 0, {}, {}},
      {"not_xml", "", 3, {{"not_xml", "", "", "not XML: error reading end tag (line 5, column 1)"}}, {}},
      {"not_urdf", "", 3, {{"not_urdf", "", "", "not URDF: the top element is <sdf>, not <robot>"}}, {}},
      {"no_root", "", 3,
       {{"no_root", "robot", "no_root", "no root link: every link is the child of a joint (the joints form a loop)"},
        {"loop", "link", "base",
         "joints 'shoulder', 'back' form a cycle (base -> upper_arm -> base): a URDF describes a tree"}},
       {}},
      {"several_roots", "", 3,
       {{"several_roots", "link", "camera",
         "a second root: no joint has it as child, so it is not part of the tree of the root 'world'; "
         "attach it with a joint, or remove it"}},
       {}},
      {"loop", "", 3,
       {{"loop", "link", "forearm",
         "the child of 2 joints ('elbow', 'strut_tip'): they close a kinematic loop, and a URDF describes a "
         "tree; keep one of them (kdl_space cannot model closed chains)"}},
       {}},
      {"missing_link", "", 3,
       {{"missing_link", "joint", "elbow",
         "child link 'forarm' does not exist: add <link name=\"forarm\"/>, or correct the name"},
        // the link meant as the child is then attached to nothing
        {"several_roots", "link", "forearm",
         "a second root: no joint has it as child, so it is not part of the tree of the root 'world'; "
         "attach it with a joint, or remove it"}},
       {}},
      {"free_joint_inside", "", 3, {{"free_joint_inside", "joint", "loose", kFreeJoint}}, {}},
      {"non_positive_mass", "", 3,
       {{"non_positive_mass", "link", "forearm",
         "negative mass (-3 kg): a link's mass is > 0, or 0 for a link that only carries a frame"}},
       {}},
      // Read as written by real files: the joint that moves no mass is fixed, with a warning.
      {"massless_moving_link", "", 0, {},
       {{"joint_moves_no_mass", "joint", "wrist",
         "moves only massless links ('hand' and below): it has no inertia, so it is treated as fixed at q = 0 "
         "and is not a coordinate (give the links their mass, or the joint an armature)"}},
       {{"massless_link", "link", "hand", "massless link: it only carries a frame"}}},
      {"inertia_not_positive_definite", "", 3,
       {{"inertia_not_positive_definite", "link", "forearm",
         "inertia is not positive definite (principal moments -0.2, 0.1, 0.3 kg m^2): a body with mass has "
         "principal moments >= 0; check the signs, the products of inertia and the units"}},
       {}},
      // No rigid body has it, but the dynamics are defined: a warning with the amount (0.1 of 0.3).
      {"triangle_inequality", "", 0, {},
       {{"triangle_inequality", "link", "forearm", kTriangle}}},
      {"not_finite", "", 3,
       {{"not_finite", "link", "forearm", "<inertial><origin xyz=\"0.4 nan 0\">: 'nan' is not a finite number"}},
       {}},
      {"zero_axis", "", 3,
       {{"zero_axis", "joint", "elbow",
         "its axis (0 0 0) has zero length (or is not finite): give its direction, e.g. <axis xyz=\"0 0 1\"/>"}},
       {}},
      {"valid", " --tip gripper", 3,
       {{"unknown_tip", "tip", "gripper", "not a link of the model (its links: 'base', 'upper_arm', 'forearm')"}},
       {}},
      // A massless base is refused when its mass matrix is singular (one joint turns it freely)...
      {"base_without_mass", "", 3,
       {{"base_without_mass", "link", "base",
         "the free-floating base has no mass, and the links it carries do not supply it: the system's mass "
         "matrix is singular (the base moves with joint 'shoulder' without moving any mass); give this link an "
         "<inertial> with its mass and inertia (kdl_space reads the root link's <inertial>, which kdl_parser "
         "drops)"}},
       {}},
      // ... and read with a note when the links supply the mass (two arms on different axes).
      {"massless_base", "", 0, {}, {},
       {{"massless_base", "link", "base",
         "the free-floating base has no mass: the links it carries supply it (the system's mass matrix is "
         "positive definite at q = 0)"}}},
      // Zero mass with a rotational inertia: read as written, a warning.
      {"inertia_without_mass", "", 0, {},
       {{"inertia_without_mass", "link", "camera",
         "zero mass with a rotational inertia (principal moments 0.0001, 0.0002, 0.0003 kg m^2): read as "
         "written, a body that resists rotation but not translation (give the link its mass if it has one; no "
         "<inertial> if it only carries a frame)"}}},
      // Judged on the rigid body (forearm + sensor), not the link: a warning naming both.
      {"link_inertia_not_positive_definite", "", 0, {},
       {{"link_inertia_not_positive_definite", "link", "sensor",
         "inertia is not positive definite (principal moments -1e-06, 1e-06, 3e-06 kg m^2), but the rigid body "
         "it forms by fixed joints with 'forearm' (principal moments 0.010001, 0.201596, 0.201596 kg m^2 about "
         "its CoM) is positive definite: read as written (the dynamics see that rigid body, not the link "
         "alone)"}}},
      // A zero-mass body on a prismatic joint: that joint moves no inertia.
      {"singular_inertia", "", 3,
       {{"singular_inertia", "joint", "slider",
         "the system's mass matrix is singular at q = 0: joint 'slider' moves no inertia (the link 'pad' has a "
         "rotational inertia but no mass); give it its mass, the joint an armature, or no <inertial> to a link "
         "that only carries a frame (its joint is then treated as fixed)"}},
       {{"inertia_without_mass", "link", "pad",
         "zero mass with a rotational inertia (principal moments 0.0001, 0.0001, 0.0001 kg m^2): read as "
         "written, a body that resists rotation but not translation (give the link its mass if it has one; no "
         "<inertial> if it only carries a frame)"}}},
      {"root_inertia_dropped_by_kdl_parser", "", 0, {}, {},
       {{"root_inertia_dropped_by_kdl_parser", "link", "base",
         "root link inertia kept as the base body's inertia (kdl_parser drops it: tools built on kdl_parser "
         "alone see a massless base)"}}},
      {"massless_link", "", 0, {}, {}, {{"massless_link", "link", "tool_frame", "massless link: it only carries a frame"}}},
      {"axis_not_unit", "", 0, {},
       {{"axis_not_unit", "joint", "elbow", "axis (0 2 0) is not unit length (norm 2): it is normalised"}}},
      {"limits_exclude_zero", "", 0, {},
       {{"limits_exclude_zero", "joint", "elbow",
         "limits [0.5, 1.5] exclude 0, where inspect, capture and simulate put every joint not given a "
         "position: give q explicitly (kdl_space does not enforce limits)"}}},
      {"multiple_problems", "", 3,
       {{"zero_axis", "joint", "shoulder",
         "its axis (0 0 0) has zero length (or is not finite): give its direction, e.g. <axis xyz=\"0 0 1\"/>"},
        {"not_finite", "link", "upper_arm", "<inertial><mass value=\"nan\">: 'nan' is not a finite number"},
        {"non_positive_mass", "link", "hand",
         "negative mass (-1 kg): a link's mass is > 0, or 0 for a link that only carries a frame"},
        {"missing_link", "joint", "camera_mount",
         "child link 'camera' does not exist: add <link name=\"camera\"/>, or correct the name"},
        {"free_joint_inside", "joint", "slider",
         "a planar joint inside the tree is not supported (only the base floats; use revolute, continuous, "
         "prismatic or fixed joints); a planar joint is accepted only from a massless root link (such as "
         "'world') to its only child, the base, which then floats"}},
       {{"axis_not_unit", "joint", "elbow", "axis (0 2 0) is not unit length (norm 2): it is normalised"},
        {"triangle_inequality", "link", "forearm", kTriangle},
        {"limits_exclude_zero", "joint", "wrist",
         "limits [0.5, 1.5] exclude 0, where inspect, capture and simulate put every joint not given a "
         "position: give q explicitly (kdl_space does not enforce limits)"}}},
  };
  return all;
}

class CheckTool : public ::testing::TestWithParam<Case> {};

TEST_P(CheckTool, ReportsEachProblemWithItsLineAndExitCode) {
  const Case& c = GetParam();
  const std::string path = kBroken + c.file + ".urdf";
  const ToolRun r = kdlSpace("check " + path + c.args);
  EXPECT_EQ(r.rc, c.rc) << r.out << r.err;
  EXPECT_EQ(r.err, "") << "the report goes to stdout; nothing from urdfdom or kdl_parser";

  // Every finding line, in order, then the model note when the model loads, then the count.
  std::vector<std::string> expected;
  for (const Expected& e : c.errors) expected.push_back(path + ": error: " + e.text());
  for (const Expected& e : c.warnings) expected.push_back(path + ": warning: " + e.text());
  for (const Expected& e : c.notes) expected.push_back(path + ": note: " + e.text());
  std::vector<std::string> got = lines(r.out);
  ASSERT_FALSE(got.empty());
  EXPECT_EQ(got.back(), count(c.errors.size(), "error") + ", " + count(c.warnings.size(), "warning"));
  got.pop_back();
  if (c.errors.empty()) {
    ASSERT_FALSE(got.empty());
    EXPECT_EQ(got.back().rfind(path + ": note: base 'base', ", 0), 0u) << got.back();
    got.pop_back();
    // What the joints' <limit> and <dynamics> gave: every file here limits all its joints.
    ASSERT_FALSE(got.empty());
    EXPECT_EQ(got.back().rfind(path + ": note: of the ", 0), 0u) << got.back();
    got.pop_back();
  }
  EXPECT_EQ(got, expected);
}

TEST_P(CheckTool, JsonHasTheSameEntries) {
  const Case& c = GetParam();
  const ToolRun r = kdlSpace("check " + kBroken + c.file + ".urdf" + c.args + " --json");
  EXPECT_EQ(r.rc, c.rc) << r.out << r.err;
  EXPECT_EQ(r.err, "");
  const nlohmann::json j = nlohmann::json::parse(r.out);
  std::vector<std::string> keys;
  for (const auto& item : j.items()) keys.push_back(item.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"errors", "model", "notes", "warnings"}));  // sorted
  auto entries = [](const std::vector<Expected>& list) {
    nlohmann::json a = nlohmann::json::array();
    for (const Expected& e : list) a.push_back({{"kind", e.kind}, {"element", e.element}, {"message", e.message}});
    return a;
  };
  EXPECT_EQ(j.at("errors"), entries(c.errors));
  EXPECT_EQ(j.at("warnings"), entries(c.warnings));
  EXPECT_EQ(j.at("notes"), entries(c.notes));
  EXPECT_EQ(j.at("model").at("loaded").get<bool>(), c.errors.empty());
}

TEST_P(CheckTool, InspectOfAFileThatDoesNotLoadSaysWhatCheckSays) {
  const Case& c = GetParam();
  if (c.errors.empty() || !c.args.empty()) return;  // it loads (an unknown --tip is check's own)
  const std::string path = kBroken + c.file + ".urdf";
  const ToolRun r = kdlSpace("inspect --urdf " + path + " --tip base");
  EXPECT_EQ(r.rc, 3);
  std::string expected;
  for (const Expected& e : c.errors) expected += (expected.empty() ? "" : "\n") + path + ": error: " + e.text();
  EXPECT_EQ(r.err, "kdl_space: " + expected + "\n");
}

INSTANTIATE_TEST_SUITE_P(BrokenUrdf, CheckTool, ::testing::ValuesIn(cases()));

TEST(CheckTool, EveryFileOfTheCorpusIsTested) {
  // One file per problem: a new file without a case above would go untested.
  std::set<std::string> tested;
  for (const Case& c : cases()) tested.insert(c.file);
  for (const char* name : {"valid", "not_xml", "not_urdf", "no_root", "several_roots", "loop", "missing_link",
                           "free_joint_inside", "non_positive_mass", "massless_moving_link",
                           "inertia_not_positive_definite", "triangle_inequality", "not_finite", "zero_axis",
                           "base_without_mass", "root_inertia_dropped_by_kdl_parser", "massless_link",
                           "axis_not_unit", "limits_exclude_zero", "mass_ratio", "multiple_problems",
                           "massless_base", "inertia_without_mass", "link_inertia_not_positive_definite",
                           "singular_inertia"}) {
    EXPECT_TRUE(std::ifstream(kBroken + name + ".urdf").good()) << name;
    if (std::string(name) != "mass_ratio") EXPECT_TRUE(tested.count(name)) << name;  // mass_ratio: below
  }
}

TEST(CheckTool, MassRatioWarningGivesTheConditionNumbers) {
  const std::string path = kBroken + "mass_ratio.urdf";
  const ToolRun r = kdlSpace("check " + path + " --json");
  ASSERT_EQ(r.rc, 0) << r.out << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("errors"), nlohmann::json::array());
  ASSERT_EQ(j.at("warnings").size(), 1u) << j.dump(2);
  const nlohmann::json& w = j.at("warnings")[0];
  EXPECT_EQ(w.at("kind"), "mass_ratio");
  EXPECT_EQ(w.at("element"), "forearm");  // the lightest moving link
  const std::string message = w.at("message");
  const std::string start =
      "the base 'base' (2e+07 kg) is 6.66667e+06 times heavier than this moving link (3 kg), above 1e+06: "
      "H* and G* may be ill-conditioned (at q = 0, cond(H*) = ";
  EXPECT_EQ(message.rfind(start, 0), 0u) << message;
  // The numbers printed are the model summary's.
  const nlohmann::json& m = j.at("model");
  const double cond_H = m.at("condition_H_star").get<double>();
  ASSERT_EQ(m.at("condition_G_star").size(), 1u);
  EXPECT_EQ(m.at("condition_G_star")[0].at("link"), "forearm");
  std::ostringstream numbers;
  numbers << cond_H << ", cond(G*) = ";
  const nlohmann::json& g = m.at("condition_G_star")[0].at("condition");
  if (g.is_null()) numbers << "inf"; else numbers << g.get<double>();
  numbers << " at 'forearm')";
  EXPECT_EQ(message.substr(start.size()), numbers.str());
  // A planar two-joint arm on a nearly immovable base: G* tends to the grounded G, singular.
  EXPECT_TRUE(g.is_null() || g.get<double>() > 1e6) << g;

  const ToolRun text = kdlSpace("check " + path);
  EXPECT_EQ(text.rc, 0);
  EXPECT_EQ(lines(text.out).front(), path + ": warning: link 'forearm': " + message);
  EXPECT_EQ(kdlSpace("check " + path + " --strict").rc, 3);
}

TEST(CheckTool, ValidModelSummary) {
  const ToolRun r = kdlSpace("check " + kBroken + "valid.urdf --json");
  ASSERT_EQ(r.rc, 0) << r.out << r.err;
  const nlohmann::json m = nlohmann::json::parse(r.out).at("model");
  EXPECT_EQ(m.at("robot"), "valid");
  EXPECT_EQ(m.at("base"), "base");  // the floating joint from the massless 'world' is dropped
  EXPECT_EQ(m.at("links"), 3);   // 'world' and 'free_flyer' are not part of the model
  EXPECT_EQ(m.at("joints"), 2);
  EXPECT_EQ(m.at("joint_names"), nlohmann::json({"shoulder", "elbow"}));
  EXPECT_DOUBLE_EQ(m.at("total_mass").get<double>(), 108.0);
  EXPECT_GE(m.at("condition_H_star").get<double>(), 1.0);
  ASSERT_EQ(m.at("condition_G_star").size(), 1u);  // the one link that carries no other
  EXPECT_EQ(m.at("condition_G_star")[0].at("link"), "forearm");
}

TEST(CheckTool, StrictTurnsWarningsIntoFailure) {
  const std::string path = kBroken + "axis_not_unit.urdf";
  const ToolRun relaxed = kdlSpace("check " + path);
  EXPECT_EQ(relaxed.rc, 0);
  const ToolRun strict = kdlSpace("check " + path + " --strict");
  EXPECT_EQ(strict.rc, 3);
  EXPECT_EQ(lines(strict.out).back(), "0 errors, 1 warning (--strict: warnings fail the check)");
  EXPECT_EQ(kdlSpace("check " + path + " --strict --json").rc, 3);
  // Without warnings, --strict passes.
  EXPECT_EQ(kdlSpace("check " + kBroken + "valid.urdf --strict").rc, 0);
}

TEST(CheckTool, GoodTipsGiveTheirConditionNumbers) {
  const ToolRun r = kdlSpace("check " + kBroken + "valid.urdf --tip upper_arm --tip forearm --json");
  ASSERT_EQ(r.rc, 0) << r.out << r.err;
  const nlohmann::json g = nlohmann::json::parse(r.out).at("model").at("condition_G_star");
  ASSERT_EQ(g.size(), 2u);
  EXPECT_EQ(g[0].at("link"), "upper_arm");
  EXPECT_EQ(g[1].at("link"), "forearm");
  // A good tip and a bad one: only the bad one is reported.
  const ToolRun mixed = kdlSpace("check " + kBroken + "valid.urdf --tip forearm --tip world");
  EXPECT_EQ(mixed.rc, 3);
  EXPECT_EQ(lines(mixed.out).front(), kBroken + "valid.urdf: error: tip 'world': not a link of the model (its "
                                                 "links: 'base', 'upper_arm', 'forearm')");
}

TEST(CheckTool, BundledModelsPass) {
  for (const char* name : {"space_arm7.urdf", "dual_arm.urdf", "spacedyn_twolink.urdf"}) {
    const ToolRun r = kdlSpace("check " + urdfDir() + "/" + name + " --json");
    EXPECT_EQ(r.rc, 0) << name << "\n" << r.out << r.err;
    EXPECT_EQ(r.err, "") << name;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("errors"), nlohmann::json::array()) << name;
    EXPECT_TRUE(j.at("model").at("loaded").get<bool>()) << name;
    // Clean: no warning (--strict passes); their base is the root link with its inertia, a note.
    EXPECT_EQ(j.at("warnings"), nlohmann::json::array()) << name;
    EXPECT_EQ(kdlSpace("check " + urdfDir() + "/" + name + " --strict").rc, 0) << name;
    bool root_inertia = false;
    for (const auto& w : j.at("notes")) root_inertia |= w.at("kind") == "root_inertia_dropped_by_kdl_parser";
    EXPECT_TRUE(root_inertia) << name;
  }
}

// The tool reads an SDF through the library's SDF module (libkdl_space_sdf.so, loaded on the first
// SDF file): the hand-written pair of tests/data/sdf/ gives the same model summary.
TEST(CheckTool, AnSdfIsTheModelOfItsUrdf) {
  const std::string dir = dataDir() + "/sdf/offset_joint_arm";
  const ToolRun sdf = kdlSpace("check " + dir + ".sdf --json");
  const ToolRun urdf = kdlSpace("check " + dir + ".urdf --json");
  ASSERT_EQ(sdf.rc, 0) << sdf.out << sdf.err;
  ASSERT_EQ(urdf.rc, 0) << urdf.out << urdf.err;
  const nlohmann::json s = nlohmann::json::parse(sdf.out).at("model"), u = nlohmann::json::parse(urdf.out).at("model");
  EXPECT_EQ(s.at("joint_names"), u.at("joint_names"));
  EXPECT_EQ(s.at("links"), u.at("links"));
  EXPECT_NEAR(s.at("total_mass").get<double>(), u.at("total_mass").get<double>(), 1e-12 * u.at("total_mass").get<double>());
  EXPECT_NEAR(s.at("condition_H_star").get<double>(), u.at("condition_H_star").get<double>(),
              1e-9 * u.at("condition_H_star").get<double>());
}

TEST(CheckTool, UsageErrorsExitWith2) {
  for (const std::string& args : {std::string("check"), "check " + kBroken + "valid.urdf --bogus",
                                  "check " + kBroken + "valid.urdf --tip", std::string("check a.urdf b.urdf")}) {
    const ToolRun r = kdlSpace(args);
    EXPECT_EQ(r.rc, 2) << args << "\n" << r.out << r.err;
    EXPECT_FALSE(r.err.empty()) << args;
    EXPECT_EQ(r.out, "") << args;
  }
  EXPECT_EQ(kdlSpace("check --help").rc, 0);
}

TEST(CheckTool, NeverCrashesOnWhatIsNotAUrdf) {
  const std::string dir = ::testing::TempDir() + "kdl_space_check_inputs_" + std::to_string(getpid());
  ASSERT_EQ(std::system(("mkdir -p " + dir).c_str()), 0);
  std::ofstream(dir + "/empty.urdf").close();
  {
    std::ofstream garbage(dir + "/garbage.urdf", std::ios::binary);
    for (int i = 0; i < 4096; ++i) garbage.put(static_cast<char>((i * 7919 + 13) % 256));
  }
  std::ofstream(dir + "/deep.urdf") << std::string(100000, '<') + "robot>";
  {
    std::ofstream nested(dir + "/nested.urdf");
    for (int i = 0; i < 100000; ++i) nested << "<a>";
  }
  const struct {
    std::string file, message;
  } cases[] = {
      {"/nonexistent/robot.urdf", "error: cannot open the file: No such file or directory"},
      {dir, "error: is a directory, not a URDF file"},
      {"/dev/zero", "error: not a regular file (a device, pipe or socket)"},
      {dir + "/empty.urdf", "error: not XML: the file is empty"},
      {dir + "/garbage.urdf", "error: not XML: "},
      {dir + "/deep.urdf", "error: not URDF: no <robot> element"},
      {dir + "/nested.urdf", "error: not XML that can be read safely: elements nested more than 2000 deep (a URDF "
                             "nests 4 or 5)"},
  };
  for (const auto& c : cases) {
    const ToolRun r = kdlSpace("check " + c.file);
    EXPECT_EQ(r.rc, 3) << c.file << "\n" << r.out << r.err;
    EXPECT_EQ(r.err, "") << c.file;
    const std::vector<std::string> out = lines(r.out);
    ASSERT_EQ(out.size(), 2u) << r.out;
    EXPECT_EQ(out[0].rfind(c.file + ": " + c.message, 0), 0u) << out[0];
    EXPECT_EQ(out[1], "1 error, 0 warnings");
    const ToolRun j = kdlSpace("check " + c.file + " --json");
    EXPECT_EQ(j.rc, 3);
    EXPECT_TRUE(nlohmann::json::accept(j.out)) << j.out;
  }
  ASSERT_EQ(std::system(("rm -rf " + dir).c_str()), 0);
}

}  // namespace
}  // namespace kdl_space::test

namespace kdl_space::test {
namespace {

TEST(CheckTool, ManyNotesOfAKindAreOneLine) {
  // A humanoid's massless frames: one line that counts them; --json lists each.
  const std::string path = dataDir() + "/real_patterns/humanoid44.urdf";
  const ToolRun json = kdlSpace("check " + path + " --json");
  ASSERT_EQ(json.rc, 0) << json.err;
  std::size_t massless = 0;
  const nlohmann::json report = nlohmann::json::parse(json.out);
  for (const auto& n : report.at("notes")) massless += n.at("kind") == "massless_link";
  ASSERT_GT(massless, 3u);
  const ToolRun text = kdlSpace("check " + path);
  std::size_t lines_about_it = 0;
  std::istringstream in(text.out);
  for (std::string line; std::getline(in, line);)
    if (line.find("massless_link") != std::string::npos || line.find("massless link") != std::string::npos) {
      ++lines_about_it;
      EXPECT_NE(line.find(std::to_string(massless) + " notes massless_link ("), std::string::npos) << line;
      EXPECT_NE(line.find("and " + std::to_string(massless - 3) + " more; each in --json"), std::string::npos) << line;
    }
  EXPECT_EQ(lines_about_it, 1u) << text.out;
}

}  // namespace
}  // namespace kdl_space::test
