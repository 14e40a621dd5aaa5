// checkUrdfString / checkUrdfFile: every problem reported, and the same rules as the loader (a
// file without errors loads, a file the loader refuses has errors, with the loader's words).
#include <gtest/gtest.h>

#include "model_families.hpp"

#include <cmath>
#include <fstream>
#include <iterator>
#include <memory>
#include <random>
#include <regex>
#include <sstream>

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/parsers/urdf/urdf_check.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

const std::string kValid = readFile(dataDir() + "/broken_urdf/valid.urdf");

/// "kind element" of every finding, in order.
std::vector<std::string> summary(const std::vector<Finding>& findings) {
  std::vector<std::string> out;
  for (const Finding& f : findings) out.push_back(f.kind + " " + f.element);
  return out;
}

std::string replaced(std::string xml, const std::string& from, const std::string& to) {
  const std::size_t at = xml.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) xml.replace(at, from.size(), to);
  return xml;
}

TEST(UrdfCheck, ValidModel) {
  const UrdfReport r = checkUrdfString(kValid, "valid.urdf");
  EXPECT_EQ(r.source, "valid.urdf");
  EXPECT_TRUE(r.errors.empty()) << ::testing::PrintToString(summary(r.errors));
  EXPECT_TRUE(r.warnings.empty()) << ::testing::PrintToString(summary(r.warnings));
  EXPECT_TRUE(r.model.loaded);
  EXPECT_EQ(r.model.robot, "valid");
  EXPECT_EQ(r.model.base, "base");
  EXPECT_EQ(r.model.joint_names, (std::vector<std::string>{"shoulder", "elbow"}));
  EXPECT_DOUBLE_EQ(r.model.total_mass, 108.0);
  EXPECT_TRUE(std::isfinite(r.model.condition_H_star));
  ASSERT_EQ(r.model.condition_G_star.size(), 1u);
  EXPECT_EQ(r.model.condition_G_star[0].first, "forearm");
}

TEST(UrdfCheck, EveryProblemOfOneDocument) {
  // Four independent problems in four places: all four reported, in document order (the
  // inertia is judged on the rigid body it belongs to, once the tree is known: after the graph's).
  std::string xml = replaced(kValid, R"(<mass value="5"/>)", R"(<mass value="inf"/>)");       // upper_arm
  xml = replaced(xml, R"(<axis xyz="0 1 0"/>)", R"(<axis xyz="0 0 0"/>)");                    // elbow
  xml = replaced(xml, R"(ixx="0.01" ixy="0" ixz="0" iyy="0.2")", R"(ixx="0.01" ixy="0" ixz="0" iyy="-0.2")");  // forearm
  xml = replaced(xml, R"(<child link="forearm"/>)", R"(<child link="fore_arm"/>)");            // elbow
  const UrdfReport r = checkUrdfString(xml, "four.urdf", {"hand"});
  EXPECT_EQ(summary(r.errors), (std::vector<std::string>{"not_finite upper_arm", "zero_axis elbow",
                                                          "missing_link elbow", "several_roots forearm",
                                                          "inertia_not_positive_definite forearm",
                                                          "unknown_tip hand"}));
  EXPECT_FALSE(r.model.loaded);
  EXPECT_EQ(r.errors[0].element_type, ElementType::Link);
  EXPECT_EQ(r.errors[1].element_type, ElementType::Joint);
  EXPECT_EQ(r.errors[5].element_type, ElementType::Tip);
  EXPECT_EQ(describe(r.errors[0]), "link 'upper_arm': <inertial><mass value=\"inf\">: 'inf' is not a finite number");
}

TEST(UrdfCheck, NumbersAsUrdfdomReadsThem) {
  const struct {
    std::string value, kind;  // "" = accepted
  } cases[] = {
      {"5", ""}, {"+5", ""}, {"5.", ""}, {"  5", ""}, {"5e0", ""},
      {"nan", "not_finite"}, {"-inf", "not_finite"}, {"Infinity", "not_finite"}, {"1e999", "not_finite"},
      {"abc", "bad_number"}, {"5 ", "bad_number"}, {"0x5", "bad_number"}, {"5,0", "bad_number"}, {"", "bad_number"},
  };
  for (const auto& c : cases) {
    const UrdfReport r = checkUrdfString(replaced(kValid, R"(<mass value="5"/>)", "<mass value=\"" + c.value + "\"/>"));
    if (c.kind.empty()) {
      EXPECT_TRUE(r.errors.empty()) << "'" << c.value << "': " << ::testing::PrintToString(summary(r.errors));
    } else {
      ASSERT_FALSE(r.errors.empty()) << "'" << c.value << "'";
      EXPECT_EQ(r.errors[0].kind + " " + r.errors[0].element, c.kind + " upper_arm") << "'" << c.value << "'";
    }
  }
}

TEST(UrdfCheck, NotADocument) {
  EXPECT_EQ(summary(checkUrdfString("").errors), std::vector<std::string>{"not_xml "});
  EXPECT_EQ(summary(checkUrdfString(std::string("\x89PNG\r\n\x1a\n\0\0", 10)).errors), std::vector<std::string>{"not_xml "});
  EXPECT_EQ(summary(checkUrdfString("<model/>").errors), std::vector<std::string>{"not_urdf "});
  EXPECT_EQ(summary(checkUrdfFile("/nonexistent/a.urdf").errors), std::vector<std::string>{"unreadable "});
  EXPECT_EQ(summary(checkUrdfFile(dataDir()).errors), std::vector<std::string>{"unreadable "});
  EXPECT_EQ(summary(checkUrdfString(R"(<robot name="r"/>)").errors), std::vector<std::string>{"no_root r"});
}

TEST(UrdfCheck, LongChainsAreRefusedNotACrash) {
  // kdl_parser recurses once per joint: a 20000-link chain overflowed the stack.
  auto chain = [](int n) {
    const std::string inertial =
        R"(<inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>)";
    std::string xml = R"(<robot name="chain"><link name="l0">)" + inertial + "</link>";
    for (int i = 1; i <= n; ++i)
      xml += "<joint name=\"j" + std::to_string(i) + "\" type=\"continuous\"><parent link=\"l" + std::to_string(i - 1) +
             "\"/><child link=\"l" + std::to_string(i) + "\"/><origin xyz=\"0 0 0.1\"/></joint><link name=\"l" +
             std::to_string(i) + "\">" + inertial + "</link>";
    return xml + "</robot>";
  };
  EXPECT_TRUE(checkUrdfString(chain(1000)).errors.empty());
  for (const int n : {1001, 20000}) {
    const std::string xml = chain(n);
    const UrdfReport r = checkUrdfString(xml, "chain.urdf");
    ASSERT_EQ(summary(r.errors), std::vector<std::string>{"too_deep l1001"}) << n;
    EXPECT_EQ(r.errors[0].message,
              "1001 joints below the base: kdl_space reads trees at most 1000 deep (kdl_parser recurses once per joint)");
    try {
      loadUrdfString(xml, "chain.urdf");
      ADD_FAILURE() << "loaded a chain of " << n;
    } catch (const ModelError& e) {
      EXPECT_EQ(std::string(e.what()), "chain.urdf: " + describe(r.errors[0]));
    }
  }
}

TEST(UrdfCheck, LoopsThatUrdfdomAcceptsAreRefusedByBoth) {
  // urdfdom accepts a link with several parents; walking such a graph from the base without
  // remembering what was reached would never end (two paths back to 'a' double at every turn).
  const std::string inertial =
      R"(<inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>)";
  auto link = [&](const std::string& name) { return "<link name=\"" + name + "\">" + inertial + "</link>"; };
  auto joint = [](const std::string& name, const std::string& parent, const std::string& child) {
    return "<joint name=\"" + name + "\" type=\"fixed\"><parent link=\"" + parent + "\"/><child link=\"" + child +
           "\"/></joint>";
  };
  const std::string xml = R"(<robot name="r">)" + link("base") + link("a") + link("b") + link("c") +
                          joint("ja", "base", "a") + joint("jb", "a", "b") + joint("jc", "a", "c") +
                          joint("back_b", "b", "a") + joint("back_c", "c", "a") + "</robot>";
  const UrdfReport r = checkUrdfString(xml, "loops.urdf");
  EXPECT_EQ(summary(r.errors), std::vector<std::string>{"loop a"});
  EXPECT_THROW(loadUrdfString(xml, "loops.urdf"), ModelError);
}

TEST(UrdfCheck, SingularInertiaAtZero) {
  // Two coincident axes with a massless link between them: H* is singular, the model unusable.
  const std::string xml = replaced(kValid, R"(<axis xyz="0 1 0"/>)", R"(<axis xyz="0 0 1"/>)");
  const std::string twin = replaced(replaced(xml, R"(<origin xyz="1 0 0" rpy="0 0 0"/>)", R"(<origin xyz="0 0 0"/>)"),
                                    R"(<mass value="5"/>)", R"(<mass value="0"/>)");
  const std::string massless = replaced(twin, R"(<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.4" iyz="0" izz="0.4"/>)",
                                        R"(<inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/>)");
  const UrdfReport r = checkUrdfString(massless);
  EXPECT_EQ(summary(r.errors), std::vector<std::string>{"singular_inertia "});
  EXPECT_TRUE(std::isinf(r.model.condition_H_star));
}

TEST(UrdfCheck, MaterialsAsUrdfdomReadsThem) {
  const std::string link = R"(<link name="base"><inertial><mass value="1"/>)"
                           R"(<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>)";
  auto robot = [&](const std::string& materials) { return R"(<robot name="r">)" + materials + link + "</robot>"; };
  const std::string red = R"(<material name="red"><color rgba="1 0 0 1"/></material>)";
  EXPECT_TRUE(checkUrdfString(robot(red)).errors.empty());
  // urdfdom ignores an rgba of the wrong size: so does the check (the file loads).
  EXPECT_TRUE(checkUrdfString(robot(R"(<material name="m"><color rgba="1 0 0"/></material>)")).errors.empty());
  EXPECT_EQ(summary(checkUrdfString(robot(red + red)).errors), std::vector<std::string>{"duplicate_name r"});
  EXPECT_EQ(summary(checkUrdfString(robot(R"(<material name="m"><color rgba="2 0 0 1"/></material>)")).errors),
            std::vector<std::string>{"bad_number r"});
  EXPECT_EQ(summary(checkUrdfString(robot(R"(<material name="m"/>)")).errors), std::vector<std::string>{"malformed r"});
  for (const std::string& m : {red, std::string(R"(<material name="m"><color rgba="1 0 0"/></material>)"),
                               red + red, std::string(R"(<material name="m"/>)")}) {
    bool loads = true;
    try {
      loadUrdfString(robot(m));
    } catch (const ModelError&) {
      loads = false;
    }
    EXPECT_EQ(loads, checkUrdfString(robot(m)).errors.empty()) << m;
  }
}

TEST(UrdfCheck, SameRuleSameWordsAsTheLoader) {
  // One implementation of each rule: the loader's refusal is the check's first error.
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {R"(ixx="0.01" ixy="0" ixz="0" iyy="0.2")", R"(ixx="-0.05" ixy="0" ixz="0" iyy="0.2")"},  // not PD
           {R"(<axis xyz="0 1 0"/>)", R"(<axis/>)"},                          // zero axis
           {R"(<mass value="3"/>)", R"(<mass value="-3"/>)"},                 // negative mass
       }) {
    const std::string xml = replaced(kValid, from, to);
    const UrdfReport r = checkUrdfString(xml, "case.urdf");
    ASSERT_EQ(r.errors.size(), 1u) << to << ": " << ::testing::PrintToString(summary(r.errors));
    try {
      loadUrdfString(xml, "case.urdf");
      ADD_FAILURE() << "the loader accepted " << to;
    } catch (const ModelError& e) {
      EXPECT_EQ(std::string(e.what()), "case.urdf: " + describe(r.errors[0]));
    }
  }
  // And a warning of the check is a diagnostic of the loaded model, in the same words.
  const std::string xml = replaced(kValid, R"(<axis xyz="0 1 0"/>)", R"(<axis xyz="0 2 0"/>)");
  const UrdfReport r = checkUrdfString(xml);
  ASSERT_EQ(r.warnings.size(), 1u);
  const FloatingModel model = loadUrdfString(xml);
  bool found = false;
  for (const Diagnostic& d : model.diagnostics()) found |= d.element == "elbow" && d.message == r.warnings[0].message;
  EXPECT_TRUE(found);
}

TEST(UrdfCheck, AgreesWithTheLoaderOnRandomDamage) {
  // Random damage to valid files: the check finds errors exactly when the loader refuses the
  // file, and never needs the loader to find them (no `refused_by_loader`).
  // Every element urdfdom reads: materials, visuals, collisions, limits, dynamics, safety, mimic.
  const std::string everything =
      R"(<robot name="m"><material name="red"><color rgba="1 0 0 1"/></material>)"
      R"(<link name="base"><inertial><origin xyz="0 0 0" rpy="0 0 0"/><mass value="10"/>)"
      R"(<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial><visual><origin xyz="0 0 0"/>)"
      R"(<geometry><box size="1 1 1"/></geometry><material name="red"><color rgba="1 0 0 1"/></material></visual>)"
      R"(<collision><geometry><cylinder radius="1" length="2"/></geometry></collision></link>)"
      R"(<joint name="slide" type="prismatic"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>)"
      R"(<limit lower="-1" upper="1" effort="1" velocity="1"/><dynamics damping="1" friction="0"/>)"
      R"(<safety_controller soft_lower_limit="-1" soft_upper_limit="1" k_position="1" k_velocity="1"/>)"
      R"(<calibration rising="0" falling="0"/></joint>)"
      R"(<link name="arm"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>)"
      R"(</inertial><visual><geometry><mesh filename="a.stl" scale="1 1 1"/></geometry></visual>)"
      R"(<collision><geometry><sphere radius="1"/></geometry></collision></link>)"
      R"(<joint name="turn" type="revolute"><parent link="arm"/><child link="hand"/><axis xyz="1 0 0"/>)"
      R"(<limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="slide" multiplier="1" offset="0"/>)"
      R"(</joint><link name="hand"><inertial><mass value="1"/>)"
      R"(<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>)";
  ASSERT_TRUE(checkUrdfString(everything).errors.empty());
  const std::vector<std::string> sources = {kValid, readFile(urdfDir() + "/spacedyn_twolink.urdf"),
                                            readFile(dataDir() + "/broken_urdf/massless_link.urdf"), everything};
  const std::vector<std::string> values = {"nan", "inf", "-1", "0", "abc", "1 2", "0 0 0", "2 0 0", "", "1e999",
                                           " 1", "1 ", "forarm", "floating", "planar", "fixed", "continuous",
                                           "prismatic", "hinge", "0.5 1.5", "0 0 1", "1e-400", "base", "world"};
  const std::regex attribute(R"re(\s(\w+)="([^"]*)")re");
  std::mt19937 rng(6);
  int refused = 0, loaded = 0;
  for (int trial = 0; trial < 600; ++trial) {
    std::string xml = sources[trial % sources.size()];
    std::vector<std::pair<std::size_t, std::size_t>> spans;  // the value of every attribute
    for (auto it = std::sregex_iterator(xml.begin(), xml.end(), attribute); it != std::sregex_iterator(); ++it)
      spans.emplace_back(it->position(2), it->length(2));
    for (int k = 0; k < 1 + trial % 3; ++k) {
      const auto [at, length] = spans[std::uniform_int_distribution<std::size_t>(0, spans.size() - 1)(rng)];
      const std::string& v = values[std::uniform_int_distribution<std::size_t>(0, values.size() - 1)(rng)];
      xml.replace(at, length, v);
      spans.clear();
      for (auto it = std::sregex_iterator(xml.begin(), xml.end(), attribute); it != std::sregex_iterator(); ++it)
        spans.emplace_back(it->position(2), it->length(2));
    }
    const UrdfReport r = checkUrdfString(xml, "damaged.urdf");
    bool loads = true;
    std::string why;
    try {
      loadUrdfString(xml, "damaged.urdf");
    } catch (const ModelError& e) {
      loads = false;
      why = e.what();
    }
    (loads ? loaded : refused)++;
    for (const Finding& f : r.errors) EXPECT_NE(f.kind, "refused_by_loader") << f.message << "\n" << xml;
    EXPECT_EQ(r.errors.empty(), loads) << why << "\n" << ::testing::PrintToString(summary(r.errors)) << "\n" << xml;
  }
  EXPECT_GT(refused, 50);
  EXPECT_GT(loaded, 20);
}

}  // namespace
}  // namespace kdl_space::test

namespace kdl_space {
namespace {

TEST(UrdfCheckMassRatio, SaysWhenTheLightLinkHangsOnAFixedJoint) {
  // A 1e7 kg station, a 2 kg arm link, a 1 g sensor fixed to it: the lightest link that moves
  // is the sensor, on a fixed joint; the words say so. Without the sensor: the arm link, moving.
  const auto robot = [](bool sensor) {
    const auto inertial = [](const std::string& m, const std::string& i) {
      return "<inertial><mass value=\"" + m + "\"/><inertia ixx=\"" + i + "\" iyy=\"" + i + "\" izz=\"" + i +
             "\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>";
    };
    std::string xml = "<robot name=\"r\"><link name=\"station\">" + inertial("1e7", "1e8") +
                      "</link><joint name=\"j\" type=\"continuous\"><parent link=\"station\"/><child link=\"arm\"/>"
                      "<axis xyz=\"0 0 1\"/></joint><link name=\"arm\">" + inertial("2", "0.1") + "</link>";
    if (sensor)
      xml += "<joint name=\"mount\" type=\"fixed\"><parent link=\"arm\"/><child link=\"sensor\"/></joint>"
             "<link name=\"sensor\">" + inertial("0.001", "1e-7") + "</link>";
    return xml + "</robot>";
  };
  const auto ratioWarning = [](const UrdfReport& r) {
    for (const Finding& f : r.warnings)
      if (f.kind == "mass_ratio") return f;
    return Finding{};
  };
  const Finding with = ratioWarning(checkUrdfString(robot(true)));
  EXPECT_EQ(with.element, "sensor");
  EXPECT_NE(with.message.find("times heavier than this link on a fixed joint (it moves with its parent) (0.001 kg)"),
            std::string::npos) << with.message;
  const Finding without = ratioWarning(checkUrdfString(robot(false)));
  EXPECT_EQ(without.element, "arm");
  EXPECT_NE(without.message.find("times heavier than this moving link (2 kg)"), std::string::npos) << without.message;
}

}  // namespace
}  // namespace kdl_space

namespace kdl_space::test {
namespace {

TEST(UrdfCheck, ALargeModelIsMeasuredByTheLinearRouteWithTheSameGStar) {
  // 501 links (500 joints), above kDenseJoints: cond(H*) not computed (a note says why),
  // cond(G*) at the leaves by the O(n) recursion, equal to the dense route's (computed here).
  const std::string xml = largeTree(501);
  const UrdfReport r = checkUrdfString(xml, "tree.urdf");
  ASSERT_TRUE(r.errors.empty()) << ::testing::PrintToString(summary(r.errors));
  EXPECT_TRUE(std::isnan(r.model.condition_H_star));
  bool noted = false;
  for (const Finding& f : r.notes) noted |= f.kind == "large_model" && f.message.find("500 joints") == 0;
  EXPECT_TRUE(noted) << ::testing::PrintToString(summary(r.notes));
  const auto model = std::make_shared<const FloatingModel>(loadUrdfString(xml, "tree.urdf"));
  FreeFloatingSolver dense(model);
  ASSERT_EQ(dense.compute(State(*model)), E_NOERROR);
  ASSERT_EQ(r.model.condition_G_star.size(), 10u);  // the arms' tips
  for (const auto& [link, condition] : r.model.condition_G_star) {
    Matrix6d G;
    ASSERT_EQ(dense.G_star(model->contact(link), G), E_NOERROR);
    EXPECT_NEAR(condition, spectralFigures(G).condition, 1e-7 * spectralFigures(G).condition) << link;
  }
  // Below the bound the dense route still measures cond(H*).
  EXPECT_TRUE(std::isfinite(checkUrdfString(largeTree(101), "small.urdf").model.condition_H_star));
}

}  // namespace
}  // namespace kdl_space::test
