// `kdl_space capture` end to end: reference cases written as scenario files (YAML and JSON),
// the JSON contract, the shipped example scenarios, and bad scenarios naming their field.
#include <gtest/gtest.h>

#include <fstream>

#include "cli_runner.hpp"
#include "reference_case.hpp"

namespace kdl_space::test {
namespace {

constexpr double kRel = 1e-9;
constexpr double kAbs = 1e-12;
const std::string kScenarios = dataDir() + "/scenarios/";

std::vector<std::string> keys(const nlohmann::json& j) {
  std::vector<std::string> k;
  for (const auto& item : j.items()) k.push_back(item.key());
  return k;  // nlohmann::json keeps keys sorted
}

Eigen::MatrixXd m(const nlohmann::json& j) { return ReferenceCase::mat(j); }

struct Case {
  std::string reference, scenario;
};

class CaptureTool : public ::testing::TestWithParam<Case> {};
inline void PrintTo(const Case& c, std::ostream* os) { *os << c.scenario; }

TEST_P(CaptureTool, ReproducesTheReferenceEngine) {
  const ReferenceCase c(GetParam().reference);
  const bool capture = GetParam().scenario.find("capture") != std::string::npos;
  const nlohmann::json& e = c.json.at(capture ? "capture" : "point_impact");
  const ToolRun r = kdlSpace("capture " + kScenarios + GetParam().scenario + " --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(keys(j), (std::vector<std::string>{"G_B", "G_star", "contact_point", "contact_point_in_target",
                                               "energy_after", "energy_before", "energy_lost", "grasp", "html", "impulse",
                                               "momentum_after", "momentum_before", "robot", "scene", "target",
                                               "virtual_mass", "warnings"}));
  EXPECT_EQ(keys(j.at("robot")), (std::vector<std::string>{"base_twist_after", "base_twist_before",
                                                           "contact_twist_after", "contact_twist_before",
                                                           "joint_names", "joints_treated_as_fixed", "locked_joints",
                                                           "qdot_after", "qdot_before"}));
  EXPECT_EQ(j.at("robot").at("locked_joints"), nlohmann::json::array()) << "none braked";
  EXPECT_EQ(keys(j.at("target")), (std::vector<std::string>{"twist_after", "twist_before"}));

  const nlohmann::json& robot = j.at("robot");
  EXPECT_EQ(robot.at("joint_names"), c.json.at("expected").at("joint_names"));
  if (capture) {
    EXPECT_TRUE(near(m(j.at("impulse")), m(e.at("impulse_on_robot")), kRel, kAbs, "impulse"));
    EXPECT_TRUE(near(m(robot.at("contact_twist_before")), m(e.at("contact_twist_before")), kRel, kAbs, "before"));
    Vector6d momentum;
    momentum << m(e.at("linear_momentum")), m(e.at("angular_momentum_about_origin"));
    EXPECT_TRUE(near(m(j.at("momentum_before")), momentum, kRel, kAbs, "momentum_before"));
    EXPECT_TRUE(near(m(j.at("momentum_after")), momentum, kRel, kAbs, "momentum_after"));
  } else {
    const Vector3d n = m(e.at("normal"));
    const double lambda = e.at("impulse_magnitude_on_target").get<double>();
    EXPECT_TRUE(near(m(j.at("impulse")), (Vector6d() << -lambda * n, Vector3d::Zero()).finished(), kRel, kAbs, "impulse"));
  }
  EXPECT_TRUE(near(m(robot.at("contact_twist_after")), m(e.at("contact_twist_after")), kRel, kAbs, "contact after"));
  EXPECT_TRUE(near(m(robot.at("base_twist_after")), m(e.at("base_twist_after")), kRel, kAbs, "base after"));
  EXPECT_TRUE(near(m(robot.at("qdot_after")), m(e.at("qdot_after")), kRel, kAbs, "qdot after"));
  EXPECT_TRUE(near(m(j.at("target").at("twist_after")), m(e.at("target_twist_after")), kRel, kAbs, "target after"));
  const double T0 = e.at("energy_before").get<double>(), T1 = e.at("energy_after").get<double>();
  EXPECT_NEAR(j.at("energy_before").get<double>(), T0, kRel * T0);
  EXPECT_NEAR(j.at("energy_after").get<double>(), T1, kRel * T1);
  EXPECT_NEAR(j.at("energy_lost").get<double>(), T0 - T1, kRel * T0);
  // Virtual mass along the normal: 1 / (n^T G*_vv n) of the reference's G*.
  const Vector3d n = m(c.json.at("inputs").at("target").at("contact_normal"));
  const Eigen::Matrix3d G_vv = m(c.json.at("expected").at("G_star")).topLeftCorner(3, 3);
  EXPECT_NEAR(j.at("virtual_mass").get<double>(), 1.0 / n.dot(G_vv * n), kRel / n.dot(G_vv * n));
  EXPECT_TRUE(near(m(j.at("G_star")), m(c.json.at("expected").at("G_star")), kRel, kAbs, "G_star"));
}

INSTANTIATE_TEST_SUITE_P(
    Scenarios, CaptureTool,
    ::testing::Values(Case{"twolink_bent", "twolink_bent_capture.yaml"}, Case{"twolink_bent", "twolink_bent_point.yaml"},
                      Case{"arm6_reach", "arm6_reach_capture.json"}, Case{"arm6_reach", "arm6_reach_point.json"},
                      Case{"arm6_elbow_contact", "arm6_elbow_contact_capture.yaml"},
                      Case{"arm6_elbow_contact", "arm6_elbow_contact_point.yaml"}));

TEST(CaptureTool, ShippedScenariosRunAndConserveMomentum) {
  for (const char* name : {"tumbling_box_capture", "heavy_satellite_capture", "restitution_bounce",
                           "robot_to_robot_capture"}) {
    const ToolRun r = kdlSpace("capture " + std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/" + name + ".yaml --json");
    ASSERT_EQ(r.rc, 0) << name << ": " << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    const Eigen::MatrixXd before = m(j.at("momentum_before")), after = m(j.at("momentum_after"));
    EXPECT_TRUE(near(after, before, 1e-12, 1e-12 * before.norm(), name));
    EXPECT_GE(j.at("energy_lost").get<double>(), -1e-12 * j.at("energy_before").get<double>()) << name;
    const ToolRun text = kdlSpace("capture " + std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/" + name + ".yaml");
    ASSERT_EQ(text.rc, 0);
    for (const char* s : {"Impulse on the robot", "Kinetic energy", "joint7", "Momentum"})
      EXPECT_NE(text.out.find(s), std::string::npos) << name << ": " << s;
  }
}

/// Writes `text` as a scenario next to the test data (so relative URDF paths resolve).
std::string scenarioFile(const std::string& name, const std::string& text) {
  const std::string path = kScenarios + "tmp_" + name + "_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(path) << text;
  return path;
}

const char* kGood = R"(
robot:
  urdf: ../reference/models/spacedyn_twolink.urdf
  contact: {link: hand}
  q: {joint1: 0.5}
target:
  mass: 20
  inertia: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
  pose: {position: [5.5, 0, 0]}
  twist: [-0.1, 0, 0, 0, 0, 0]
law: {type: point, normal: [1, 0, 0], restitution: 0.5}
)";

// `robot.locked`: the braked joints are reported by name and keep rate 0 through the impact;
// without the brakes the same scenario moves them (the check can fail).
TEST(CaptureTool, BrakedJointsAreReportedAndStayStill) {
  const std::string text = R"(
robot:
  urdf: ../../../urdf/space_arm7.urdf
  contact: {link: end_effector, offset: [0, 0, 0.05]}
  base: {twist: [0.002, 0, 0, 0, 0, 0.001]}
  q: {joint2: 0.7, joint3: 0.9, joint5: -0.4, joint6: 0.6}
  qdot: {joint1: 0.02}
  mode: MODE
  locked: [joint6, joint2]
target:
  mass: 50
  inertia: [[2.1, 0, 0], [0, 2.6, 0], [0, 0, 3.0]]
  pose: {position: [0.3, -2.9, 1.7]}
  twist: [0.03, -0.02, 0.01, 0.05, 0.08, -0.06]
law: {type: capture}
)";
  for (const std::string mode : {"free", "grounded"}) {
    SCOPED_TRACE(mode);
    std::string braked = text;
    braked.replace(braked.find("MODE"), 4, mode);
    std::string free = braked;
    free.erase(free.find("  locked:"), std::string("  locked: [joint6, joint2]\n").size());
    const std::string braked_file = scenarioFile("braked_" + mode, braked), free_file = scenarioFile("free_" + mode, free);
    const ToolRun r = kdlSpace("capture " + braked_file + " --json");
    const ToolRun u = kdlSpace("capture " + free_file + " --json");
    const ToolRun summary = kdlSpace("capture " + braked_file);
    const ToolRun free_summary = kdlSpace("capture " + free_file);
    std::remove(braked_file.c_str());
    std::remove(free_file.c_str());
    ASSERT_EQ(r.rc, 0) << r.err;
    ASSERT_EQ(u.rc, 0) << u.err;
    const nlohmann::json j = nlohmann::json::parse(r.out), k = nlohmann::json::parse(u.out);
    const nlohmann::json& robot = j.at("robot");
    EXPECT_EQ(robot.at("locked_joints"), nlohmann::json::parse(R"(["joint2", "joint6"])")) << "model order";
    EXPECT_EQ(k.at("robot").at("locked_joints"), nlohmann::json::array());
    const std::vector<std::string> names = robot.at("joint_names");
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == "joint2" || names[i] == "joint6") {
        EXPECT_EQ(robot.at("qdot_after").at(i).get<double>(), 0.0) << names[i];
        EXPECT_GT(std::abs(k.at("robot").at("qdot_after").at(i).get<double>()), 1e-6) << names[i] << " moves unbraked";
      }
    if (mode == "free") {
      const Eigen::MatrixXd before = m(j.at("momentum_before")), after = m(j.at("momentum_after"));
      EXPECT_TRUE(near(after, before, 1e-9, 1e-9 * before.norm(), "momentum"));
    }
    ASSERT_EQ(summary.rc, 0) << summary.err;
    EXPECT_NE(summary.out.find("Braked joints (locked at the impact, rates stay 0): 'joint2', 'joint6'\n"),
              std::string::npos)
        << summary.out;
    EXPECT_EQ(free_summary.out.find("Braked joints"), std::string::npos);
  }
}

TEST(CaptureTool, BadScenariosNameTheField) {
  const std::string good = kGood;
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    const auto at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return s.replace(at, from.size(), to);
  };
  const struct {
    std::string name, text, needle;
  } cases[] = {
      {"mass", with("mass: 20", "mass: -3"), "target.mass"},
      {"restitution", with("restitution: 0.5", "restitution: 1.5"), "law.restitution"},
      {"normal", with("normal: [1, 0, 0]", "normal: [0, 0, 0]"), "law.normal"},
      {"inertia", with("[[1, 0, 0], [0, 1, 0], [0, 0, 1]]", "[[1, 0, 0], [0, -1, 0], [0, 0, 1]]"), "target.inertia"},
      {"joint", with("joint1: 0.5", "elbow: 0.5"), "elbow"},
      {"link", with("link: hand", "link: gripper"), "gripper"},
      {"urdf", with("spacedyn_twolink.urdf", "missing.urdf"), "missing.urdf"},
      {"law", with("type: point", "type: bounce"), "law.type"},
      {"unknown", with("law:", "colour: red\nlaw:"), "colour"},
      {"number", with("mass: 20", "mass: heavy"), "target.mass"},
      {"missing", with("  mass: 20\n", ""), "target.mass"},
      {"yaml", with("law: {", "law: {{"), "YAML"},
  };
  for (const auto& c : cases) {
    const std::string file = scenarioFile(c.name, c.text);
    const ToolRun r = kdlSpace("capture " + file);
    std::remove(file.c_str());
    EXPECT_EQ(r.rc, 3) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(c.needle), std::string::npos) << c.name << ": " << r.err;
    EXPECT_EQ(r.out, "") << c.name;
  }
  const std::string file = scenarioFile("good", good);
  EXPECT_EQ(kdlSpace("capture " + file).rc, 0);
  std::remove(file.c_str());
  EXPECT_EQ(kdlSpace("capture /nonexistent.yaml").rc, 3);
  EXPECT_EQ(kdlSpace("capture").rc, 2);
}

}  // namespace
}  // namespace kdl_space::test

namespace kdl_space::test {
namespace {

/// The shipped scenario `name` with its `law` (up to its simulation section, if any) replaced by
/// `law: <law>` (URDF paths absolute), in gtest's temporary folder under a name of this process.
std::string withLaw(const std::string& name, const std::string& law) {
  std::ifstream in(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/" + name + ".yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  const std::size_t from = s.find("law:");
  const std::size_t to = s.find("simulation:", from);
  s.replace(from, to == std::string::npos ? std::string::npos : to - from, "law: " + law + "\n");
  for (std::size_t at = s.find("../urdf/"); at != std::string::npos; at = s.find("../urdf/", at))
    s.replace(at, 8, std::string(KDL_SPACE_SOURCE_DIR) + "/urdf/");
  const std::string path = ::testing::TempDir() + "kdl_space_" + name + "_law_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(path) << s;
  return path;
}

/// `capture FILE --json` of a compliant law: the contact beside the impulsive capture. The
/// default gripper (1e6 N/m, beta 1 ms) is close to the impulsive limit: the impulse within 1e-2
/// (docs/COMPLIANT.md: the error ~ the contact's duration); momentum kept, energy balanced; the
/// text shows it too. Returns the JSON.
nlohmann::json compliantBesideImpulsive(const std::string& file) {
  const ToolRun r = kdlSpace("capture " + file + " --json");
  EXPECT_EQ(r.rc, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j.contains("compliant"));
  const nlohmann::json& c = j.at("compliant");
  EXPECT_EQ(c.at("end"), "caught");
  EXPECT_GT(c.at("duration").get<double>(), 0.0);
  EXPECT_GT(c.at("peak_force").get<double>(), 0.0);
  const Eigen::MatrixXd F = m(j.at("impulse")), Fc = m(c.at("impulse"));
  EXPECT_LE((Fc - F).norm(), 1e-2 * F.norm());
  EXPECT_TRUE(near(m(c.at("momentum_after")), m(j.at("momentum_before")), 1e-12, 0.0, "momentum"));
  const double lost = c.at("energy_before").get<double>() - c.at("energy_after").get<double>();
  EXPECT_NEAR(lost, c.at("energy_dissipated").get<double>() + c.at("spring_energy").get<double>() +
                        c.at("lock_loss").get<double>(), 1e-8 * c.at("energy_before").get<double>());
  const std::size_t n = c.at("history").at("t").size();
  EXPECT_GT(n, 2u);
  EXPECT_EQ(c.at("history").at("wrench").size(), n);
  EXPECT_EQ(c.at("history").at("deflection").size(), n);
  EXPECT_EQ(c.at("history").at("t").back().get<double>(), c.at("duration").get<double>());
  const ToolRun text = kdlSpace("capture " + file);
  EXPECT_EQ(text.rc, 0) << text.err;
  EXPECT_NE(text.out.find("Compliant contact"), std::string::npos) << text.out;
  return j;
}

TEST(CaptureTool, CompliantContactBesideTheImpulsiveCapture) {
  compliantBesideImpulsive(withLaw("robot_to_robot_capture", "{type: compliant, lock: spring_maximum}"));
}

/// The default gripper stays compliant (law.lock: never): the contact ends when the relative
/// motion has died out (or at law.max_duration), the lock takes no share of the impulse or the
/// energy, and the momentum and energy balance as for a latching gripper.
TEST(CaptureTool, CompliantByDefaultTheGraspNeverLocks) {
  const ToolRun r = kdlSpace("capture " + withLaw("robot_to_robot_capture", "{type: compliant}") + " --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const nlohmann::json& c = j.at("compliant");
  EXPECT_EQ(c.at("lock"), "never");
  EXPECT_TRUE(c.at("end") == "settled" || c.at("end") == "timed_out") << c.at("end");
  EXPECT_TRUE(c.at("catch_rule").is_null());
  for (const char* share : {"linear_impulse", "angular_impulse", "energy"})
    EXPECT_EQ(c.at("lock_share").at(share).get<double>(), 0.0) << share;
  EXPECT_EQ(c.at("lock_loss").get<double>(), 0.0);
  EXPECT_EQ(m(c.at("lock_impulse")).norm(), 0.0);
  EXPECT_TRUE(near(m(c.at("momentum_after")), m(j.at("momentum_before")), 1e-12, 0.0, "momentum"));
  const double lost = c.at("energy_before").get<double>() - c.at("energy_after").get<double>();
  EXPECT_NEAR(lost, c.at("energy_dissipated").get<double>() + c.at("spring_energy").get<double>(),
              1e-8 * c.at("energy_before").get<double>());
}

/// A rigid target (the tumbling box) joined as one free body, beside the rigid capture.
TEST(CaptureTool, CompliantContactOfARigidTarget) {
  const std::string file = withLaw("tumbling_box_capture", "{type: compliant, lock: spring_maximum}");
  const nlohmann::json j = compliantBesideImpulsive(file);
  const nlohmann::json& c = j.at("compliant");
  const Eigen::MatrixXd w = m(j.at("target").at("twist_after")), wc = m(c.at("target").at("base_twist_after"));
  EXPECT_LE((wc - w).norm(), 1e-2 * w.norm());
  EXPECT_TRUE(c.at("target").at("qdot_after").empty());  // one body, no joints

  // A box without mass is refused, naming the field.
  std::string s = slurp(file);
  s.replace(s.find("mass: 50"), 8, "mass: 0");
  const std::string massless = ::testing::TempDir() + "kdl_space_compliant_box0_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(massless) << s;
  const ToolRun bad = kdlSpace("capture " + massless + " --json");
  EXPECT_EQ(bad.rc, 3) << bad.err;
  EXPECT_NE(bad.err.find("mass"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace kdl_space::test
