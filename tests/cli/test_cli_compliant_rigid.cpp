// `kdl_space capture --json` with `law: {type: compliant}` on a rigid target (the tumbling box of
// scenarios/tumbling_box_capture.yaml): the contact integrated with the box as one free body,
// beside the rigid capture it tends to.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <unistd.h>

#include "cli_runner.hpp"
#include "reference_case.hpp"

namespace kdl_space::test {
namespace {

Eigen::MatrixXd m(const nlohmann::json& j) { return ReferenceCase::mat(j); }

/// tumbling_box_capture.yaml with `law` replaced by `law: <law>` (URDF paths absolute), in a
/// scratch folder of this process.
std::string boxWithLaw(const std::string& law) {
  std::ifstream in(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/tumbling_box_capture.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  const std::size_t from = s.find("law:");
  const std::size_t to = s.find("simulation:", from);
  s.replace(from, to - from, "law: " + law + "\n");
  for (std::size_t at = s.find("../urdf/"); at != std::string::npos; at = s.find("../urdf/", at))
    s.replace(at, 8, std::string(KDL_SPACE_SOURCE_DIR) + "/urdf/");
  const std::string path = ::testing::TempDir() + "kdl_space_compliant_box_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(path) << s;
  return path;
}

TEST(CaptureTool, CompliantContactOfARigidTarget) {
  const std::string file = boxWithLaw("{type: compliant}");
  const ToolRun r = kdlSpace("capture " + file + " --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.contains("compliant"));
  const nlohmann::json& c = j.at("compliant");
  EXPECT_EQ(c.at("end"), "caught");
  EXPECT_GT(c.at("duration").get<double>(), 0.0);
  EXPECT_GT(c.at("peak_force").get<double>(), 0.0);
  // The default gripper (1e6 N/m, beta 1 ms): the impulse and the box's twist after near the
  // rigid capture's (the error ~ the contact's duration: docs/COMPLIANT.md).
  const Eigen::MatrixXd F = m(j.at("impulse")), Fc = m(c.at("impulse"));
  EXPECT_LE((Fc - F).norm(), 1e-2 * F.norm());
  const Eigen::MatrixXd w = m(j.at("target").at("twist_after")), wc = m(c.at("target").at("base_twist_after"));
  EXPECT_LE((wc - w).norm(), 1e-2 * w.norm());
  EXPECT_TRUE(c.at("target").at("qdot_after").empty());  // one body, no joints
  EXPECT_TRUE(near(m(c.at("momentum_after")), m(j.at("momentum_before")), 1e-12, 0.0, "momentum"));
  const double lost = c.at("energy_before").get<double>() - c.at("energy_after").get<double>();
  EXPECT_NEAR(lost, c.at("energy_dissipated").get<double>() + c.at("spring_energy").get<double>() +
                        c.at("lock_loss").get<double>(), 1e-8 * c.at("energy_before").get<double>());
  EXPECT_EQ(c.at("history").at("t").back().get<double>(), c.at("duration").get<double>());

  const ToolRun text = kdlSpace("capture " + file);
  ASSERT_EQ(text.rc, 0) << text.err;
  EXPECT_NE(text.out.find("Compliant contact"), std::string::npos) << text.out;

  // A box without mass is refused, naming the field.
  std::ifstream in(file);
  std::stringstream yaml;
  yaml << in.rdbuf();
  std::string s = yaml.str();
  s.replace(s.find("mass: 50"), 8, "mass: 0");
  const std::string massless = ::testing::TempDir() + "kdl_space_compliant_box0_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(massless) << s;
  const ToolRun bad = kdlSpace("capture " + massless + " --json");
  EXPECT_EQ(bad.rc, 3) << bad.err;
  EXPECT_NE(bad.err.find("mass"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace kdl_space::test
