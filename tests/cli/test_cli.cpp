// `kdl_space inspect` end to end: the JSON contract, the values against the independent
// reference engine, the readable report, and every exit code.
#include <gtest/gtest.h>

#include <fstream>

#include "cli_runner.hpp"
#include "reference_case.hpp"

namespace kdl_space::test {
namespace {

const std::string kTwolink = dataDir() + "/reference/models/spacedyn_twolink.urdf";

TEST(Cli, InspectJsonMatchesTheReferenceEngine) {
  // twolink_bent from tests/data/reference: the tool's output against the independent engine.
  const ReferenceCase c("twolink_bent");
  const nlohmann::json& e = c.json.at("expected");
  const ToolRun r = kdlSpace("inspect --urdf " + kTwolink +
                         " --tip hand --q joint1=0.5235987755982988 joint2=-1.0471975511965976"
                         " --base-pos 0.3 -0.2 0.1 --base-rpy 0 0 0.4 --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.err, "") << "nothing on stderr on success (no kdl_parser or urdfdom chatter)";
  const nlohmann::json j = nlohmann::json::parse(r.out);

  std::vector<std::string> keys;
  for (const auto& item : j.items()) keys.push_back(item.key());
  // Exactly the contract's keys (a JSON object is unordered: compare sorted).
  EXPECT_EQ(keys, (std::vector<std::string>{"G_star_all", "H_star", "I_g", "com", "contacts", "diagnostics",
                                            "joint_margins", "joint_names", "joints_treated_as_fixed", "mass",
                                            "warnings"}));
  ASSERT_EQ(j.at("contacts").size(), 1u);
  const nlohmann::json& h = j.at("contacts")[0];
  std::vector<std::string> contact_keys;
  for (const auto& item : h.items()) contact_keys.push_back(item.key());
  EXPECT_EQ(contact_keys, (std::vector<std::string>{"G_grounded", "G_locked", "G_star", "J_star", "conditioning",
                                                    "link", "offset", "point", "pose"}));

  EXPECT_EQ(j.at("joint_names"), e.at("joint_names"));
  EXPECT_EQ(h.at("link"), "hand");
  const auto m = [](const nlohmann::json& x) { return ReferenceCase::mat(x); };
  EXPECT_NEAR(j.at("mass").get<double>(), e.at("mass").get<double>(), 1e-9 * 12);
  EXPECT_TRUE(near(m(j.at("com")), m(e.at("com")), 1e-9, 1e-12, "com"));
  EXPECT_TRUE(near(m(j.at("I_g")), m(e.at("I_g")), 1e-9, 1e-12, "I_g"));
  EXPECT_TRUE(near(m(j.at("H_star")), m(e.at("H_star")), 1e-9, 1e-12, "H_star"));
  EXPECT_TRUE(near(m(h.at("point")), m(e.at("hand_position")), 1e-9, 1e-12, "point"));
  EXPECT_TRUE(near(m(h.at("J_star")), m(e.at("J_star")), 1e-9, 1e-12, "J_star"));
  EXPECT_TRUE(near(m(h.at("G_star")), m(e.at("G_star")), 1e-9, 1e-12, "G_star"));
  EXPECT_TRUE(near(m(h.at("G_grounded")), m(e.at("G_grounded")), 1e-9, 1e-12, "G_grounded"));
  EXPECT_TRUE(near(m(h.at("G_locked")), m(e.at("G_locked")), 1e-9, 1e-12, "G_locked"));
  EXPECT_TRUE(near(m(j.at("G_star_all")), m(e.at("G_star")), 1e-9, 1e-12, "G_star_all"));

  // The planar arm's grounded G is singular: said in the diagnostics, not an error.
  bool singular_reported = false;
  for (const auto& d : j.at("diagnostics")) singular_reported |= d.get<std::string>().find("rank 2 of 6") != std::string::npos;
  EXPECT_TRUE(singular_reported) << j.at("diagnostics").dump();
}

TEST(Cli, SeveralContactsGiveTheCoupledMatrix) {
  const ToolRun r = kdlSpace("inspect --urdf " + urdfDir() + "/dual_arm.urdf --tip left_tool --offset 0 0 0.1 "
                         "--tip right_tool --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("contacts").size(), 2u);
  EXPECT_EQ(j.at("contacts")[0].at("offset"), nlohmann::json({0.0, 0.0, 0.1}));
  EXPECT_EQ(j.at("contacts")[1].at("offset"), nlohmann::json({0.0, 0.0, 0.0}));
  const Eigen::MatrixXd all = ReferenceCase::mat(j.at("G_star_all"));
  ASSERT_EQ(all.rows(), 12);
  for (int k = 0; k < 2; ++k)
    EXPECT_TRUE(near(all.block(6 * k, 6 * k, 6, 6), ReferenceCase::mat(j.at("contacts")[k].at("G_star")),
                     1e-12, 1e-15, "diagonal block"));
  EXPECT_GT(all.block(0, 6, 6, 6).norm(), 0.0) << "the arms share the base: cross-coupling";
}

TEST(Cli, ReadableReportNamesJointsAndQuantities) {
  const ToolRun r = kdlSpace("inspect --urdf " + urdfDir() + "/space_arm7.urdf --tip end_effector --q joint2=0.5");
  ASSERT_EQ(r.rc, 0) << r.err;
  for (const char* s : {"Total mass w = 478.5 kg", "I_g", "H*", "J*", "G*", "G grounded", "G locked",
                        "Diagnostics:", "joint1", "joint7", "end_effector"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s;
  // A joint-indexed row starts with its joint name.
  EXPECT_NE(r.out.find("\n  joint7 "), std::string::npos);
}

TEST(Cli, UsageErrorsExitWith2) {
  for (const std::string& args :
       {std::string(""), std::string("inspect --tip hand"), "inspect --urdf " + kTwolink,
        "inspect --urdf " + kTwolink + " --tip hand --bogus", "inspect --urdf " + kTwolink + " --offset 0 0 1 --tip hand",
        "inspect --urdf " + kTwolink + " --tip hand --q joint1", "inspect --urdf " + kTwolink + " --tip hand --q joint1=abc",
        "inspect --urdf " + kTwolink + " --tip hand --base-pos 1 2", std::string("frobnicate")}) {
    const ToolRun r = kdlSpace(args);
    EXPECT_EQ(r.rc, 2) << args << "\n" << r.err;
    EXPECT_FALSE(r.err.empty()) << args;
    EXPECT_EQ(r.out, "") << args;
  }
  EXPECT_EQ(kdlSpace("inspect --help").rc, 0);
}

TEST(Cli, UnusableInputsExitWith3AndNameTheProblem) {
  const std::string broken = ::testing::TempDir() + "kdl_space_cli_planar.urdf";
  std::ofstream(broken) << R"(<robot name="r"><link name="b"><inertial><mass value="1"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
    <joint name="slider" type="planar"><parent link="b"/><child link="c"/></joint>
    <link name="c"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>
    </inertial></link></robot>)";
  const struct {
    std::string args, needle;
  } cases[] = {
      {"inspect --urdf /nonexistent/robot.urdf --tip hand", "/nonexistent/robot.urdf"},
      {"inspect --urdf " + kTwolink + " --tip gripper", "gripper"},
      {"inspect --urdf " + kTwolink + " --tip hand --q elbow=1", "elbow"},
      {"inspect --urdf " + broken + " --tip c", "slider"},
  };
  for (const auto& c : cases) {
    const ToolRun r = kdlSpace(c.args);
    EXPECT_EQ(r.rc, 3) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.needle), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("WARN"), std::string::npos) << "no kdl_parser chatter: " << r.err;
    EXPECT_EQ(r.out, "");
  }
}

}  // namespace
}  // namespace kdl_space::test
