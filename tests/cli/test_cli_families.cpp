// Every command of the tool over every model family (issue 34; tests/support/model_families.hpp:
// no movable joint, one prismatic joint, a chain, continuous joints, a tree, a mimic gripper, a
// massless base with zero-mass and frame-only links), as a user runs them: each exits 0 with what
// an independent route says, or refuses with exit 3 and a message on stderr that says why; never a
// signal. The routes: KDL's six-virtual-joint tree (tests/support/virtual_joint_route.hpp) for G*
// and the robot's momentum, KDL's TreeFkSolverPos_recursive for the inverse kinematics' pose (the
// mimic joints put where the URDF's <mimic> elements, read here, say), the rigid target's momentum
// by hand, conservation laws. A robot without joints is an ordinary case: J* is 6 x 0, `inspect`
// says it has no movable joint, `capture`, `simulate` and `study` work, `ik` and `plan` refuse it.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/treefksolverpos_recursive.hpp>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/multibody/state.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "model_families.hpp"
#include "test_util.hpp"
#include "virtual_joint_route.hpp"

namespace kdl_space::test {

namespace {

using json = nlohmann::json;

std::string num(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

/// A JSON array of rows (or a flat array: one column) as a matrix; `cols` for an array of empty rows.
Eigen::MatrixXd matrixOf(const json& j) {
  if (j.empty()) return Eigen::MatrixXd(0, 0);
  if (!j.front().is_array()) {
    Eigen::MatrixXd v(j.size(), 1);
    for (std::size_t i = 0; i < j.size(); ++i) v(i, 0) = j[i].get<double>();
    return v;
  }
  Eigen::MatrixXd m(j.size(), j.front().size());
  for (std::size_t i = 0; i < j.size(); ++i) {
    EXPECT_EQ(j[i].size(), static_cast<std::size_t>(m.cols())) << "row " << i << " of " << j.dump();
    for (std::size_t k = 0; k < j[i].size() && k < static_cast<std::size_t>(m.cols()); ++k) m(i, k) = j[i][k].get<double>();
  }
  return m;
}

Eigen::VectorXd vectorOf(const json& j) {
  Eigen::VectorXd v(j.size());
  for (std::size_t i = 0; i < j.size(); ++i) v(i) = j[i].get<double>();
  return v;
}

/// Every <link name="..."> of the URDF text (read here, not by the loader).
std::vector<std::string> linkNames(const std::string& urdf_text) {
  std::vector<std::string> names;
  const std::regex link("<link\\s+name=\"([^\"]+)\"");
  for (auto it = std::sregex_iterator(urdf_text.begin(), urdf_text.end(), link); it != std::sregex_iterator(); ++it)
    names.push_back((*it)[1]);
  return names;
}

/// A <mimic> element of the URDF text: joint = multiplier * leader + offset.
struct MimicLine {
  std::string joint, leader;
  double multiplier = 1.0, offset = 0.0;
};

std::vector<MimicLine> mimicLines(const std::string& urdf_text) {
  std::vector<MimicLine> lines;
  const std::regex joint("<joint\\s+name=\"([^\"]+)\"[^>]*>([\\s\\S]*?)</joint>"), mimic("<mimic\\s[^>]*>"),
      attribute("(\\w+)=\"([^\"]*)\"");
  for (auto it = std::sregex_iterator(urdf_text.begin(), urdf_text.end(), joint); it != std::sregex_iterator(); ++it) {
    const std::string body = (*it)[2];
    std::smatch m;
    if (!std::regex_search(body, m, mimic)) continue;
    MimicLine line;
    line.joint = (*it)[1];
    const std::string tag = m[0];
    for (auto a = std::sregex_iterator(tag.begin(), tag.end(), attribute); a != std::sregex_iterator(); ++a) {
      if ((*a)[1] == "joint") line.leader = (*a)[2];
      if ((*a)[1] == "multiplier") line.multiplier = std::stod((*a)[2]);
      if ((*a)[1] == "offset") line.offset = std::stod((*a)[2]);
    }
    lines.push_back(line);
  }
  return lines;
}

/// The family's robot with its <mimic> elements removed (each joint its own coordinate): the
/// virtual-joint route's robot for the momentum.
FloatingModel uncoupledModel(const ModelFamily& f) {
  const std::string text = std::regex_replace(slurp(familyUrdf(f.name)), std::regex("<mimic[^>]*/>"), "");
  return loadUrdfString(text, f.name + "_uncoupled.urdf");
}

/// The base of every scenario here (robot.base).
const KDL::Frame kBasePose(KDL::Rotation::RPY(0.1, -0.2, 0.3), KDL::Vector(0, 0, 0));
const double kBaseTwist[6] = {0.01, 0, 0.02, 0.001, -0.002, 0.003};
/// The rigid box (target) of every scenario: its CoM at its pose's origin.
const double kTargetMass = 40;
const KDL::Vector kTargetPosition(2.5, 0.5, 0.3);
const KDL::Rotation kTargetRotation = KDL::Rotation::RPY(0.2, 0.1, -0.3);
const double kTargetTwist[6] = {-0.05, 0.01, 0.02, 0.03, -0.02, 0.04};

/// A scenario of the family (tests/families/test_families.cpp's shape) with the rigid box, the
/// law given and the contact at `link` + `offset`, written into this test's folder; its path.
std::string writeScenario(const ModelFamily& f, const std::string& tag, const std::string& law, const std::string& link,
                          const KDL::Vector& offset) {
  const std::string path = scratchIn("cli_families_" + f.name, tag + ".yaml");
  std::ostringstream s;
  s << "robot:\n  urdf: " << familyUrdf(f.name) << "\n  contact: {link: " << link << ", offset: [" << num(offset.x())
    << ", " << num(offset.y()) << ", " << num(offset.z()) << "]}\n"
    << "  base: {position: [0, 0, 0], rpy: [0.1, -0.2, 0.3], twist: [0.01, 0, 0.02, 0.001, -0.002, 0.003]}\n"
    << "target:\n  mass: 40\n  inertia: [[2, 0, 0], [0, 3, 0], [0, 0, 4]]\n"
    << "  pose: {position: [2.5, 0.5, 0.3], rpy: [0.2, 0.1, -0.3]}\n"
    << "  twist: [-0.05, 0.01, 0.02, 0.03, -0.02, 0.04]\n"
    << "law: " << law << "\n"
    << "simulation: {duration: 0.3, output_step: 0.1, integrator: dopri5, rtol: 1.0e-10, atol: 1.0e-12}\n";
  spit(path, s.str());
  return path;
}

std::string writeScenario(const ModelFamily& f, const std::string& tag, const std::string& law) {
  return writeScenario(f, tag, law, f.contact, KDL::Vector(f.offset[0], f.offset[1], f.offset[2]));
}

/// The momentum (P; L about the world origin) of the robot and the box before the impact, by the
/// virtual-joint route and by hand: the robot's joints at rest at q = 0 (its mimic joints at
/// their offsets), its base moving with robot.base.twist, so its momentum is the first six rows
/// of KDL's M_full times (v; w) of the base origin, which is the world origin here.
Eigen::Matrix<double, 6, 1> momentumBefore(const ModelFamily& f) {
  const FloatingModel free = uncoupledModel(f);
  State u(free);
  u.world_T_base = kBasePose;
  for (const MimicLine& m : mimicLines(slurp(familyUrdf(f.name)))) u.q(free.jointIndex(m.joint)) = m.offset;
  const VirtualJointTree vt(free, u);
  Eigen::Matrix<double, 6, 1> twist, h;
  for (int k = 0; k < 6; ++k) twist(k) = kBaseTwist[k];
  h = vt.M_full().topLeftCorner(6, 6) * twist;
  // The box: P = m v, L = R I R^T w + c x m v.
  const KDL::Vector v(kTargetTwist[0], kTargetTwist[1], kTargetTwist[2]), w(kTargetTwist[3], kTargetTwist[4], kTargetTwist[5]);
  const KDL::RotationalInertia I(2, 3, 4, 0, 0, 0);
  const KDL::Vector L = kTargetRotation * (I * (kTargetRotation.Inverse() * w)) + kTargetPosition * (kTargetMass * v);
  for (int k = 0; k < 3; ++k) {
    h(k) += kTargetMass * v(k);
    h(3 + k) += L(k);
  }
  return h;
}

/// A configuration inside the limits, the same every run: joint j at a fraction of its range (a
/// continuous joint at an angle of its own).
std::map<std::string, double> inLimits(const FloatingModel& model, int variant) {
  static const double fractions[] = {0.7, 0.3, 0.62, 0.45, 0.8, 0.25, 0.55};
  static const double angles[] = {1.1, -0.8, 2.2, -1.7};
  std::map<std::string, double> q;
  for (unsigned int j = 0; j < model.nj(); ++j) {
    const JointProperties& p = model.jointProperties()[j];
    const std::size_t k = (j + 3 * variant) % 7;
    q[model.jointNames()[j]] = std::isfinite(p.lower) && std::isfinite(p.upper)
                                   ? p.lower + fractions[k] * (p.upper - p.lower)
                                   : angles[(j + variant) % 4];
  }
  return q;
}

/// The world pose of `link`'s frame moved to `offset` by KDL's tree solver, the joints by name
/// (the mimic joints where the URDF's <mimic> puts them, the others 0), the base at world_T_base.
KDL::Frame kdlContactFrame(const FloatingModel& model, const std::vector<MimicLine>& mimics,
                           std::map<std::string, double> q_by_name, const std::string& link, const KDL::Vector& offset,
                           const KDL::Frame& world_T_base) {
  for (const MimicLine& m : mimics) q_by_name[m.joint] = m.multiplier * q_by_name.at(m.leader) + m.offset;
  KDL::JntArray q(model.tree().getNrOfJoints());
  for (const auto& [name, element] : model.tree().getSegments()) {
    const KDL::Joint& j = GetTreeElementSegment(element).getJoint();
    if (j.getType() == KDL::Joint::Fixed) continue;
    const auto it = q_by_name.find(j.getName());
    q(GetTreeElementQNr(element)) = it == q_by_name.end() ? 0.0 : it->second;
  }
  KDL::TreeFkSolverPos_recursive fk(model.tree());
  KDL::Frame f;
  EXPECT_GE(fk.JntToCart(q, f, link), 0) << link;
  return world_T_base * f * KDL::Frame(offset);
}

/// The same for a robot without joints, by KDL's chain solver from the base to `link`.
KDL::Frame kdlFixedFrame(const FloatingModel& model, const std::string& link, const KDL::Vector& offset,
                         const KDL::Frame& world_T_base) {
  KDL::Chain chain;
  EXPECT_TRUE(model.tree().getChain(model.tree().getRootSegment()->first, link, chain)) << link;
  EXPECT_EQ(chain.getNrOfJoints(), 0u) << link;
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::Frame f;
  EXPECT_GE(fk.JntToCart(KDL::JntArray(0), f), 0) << link;
  return world_T_base * f * KDL::Frame(offset);
}

/// The angle of the rotation between two orientations (atan2: exact near 0, where KDL's
/// GetRotAngle reads below 1e-6 as 0).
double angleBetween(const KDL::Rotation& a, const KDL::Rotation& b) {
  const KDL::Rotation E = a.Inverse() * b;
  const KDL::Vector sine(E(2, 1) - E(1, 2), E(0, 2) - E(2, 0), E(1, 0) - E(0, 1));
  return std::atan2(0.5 * std::sqrt(KDL::dot(sine, sine)), 0.5 * (E(0, 0) + E(1, 1) + E(2, 2) - 1.0));
}

double distance(const KDL::Vector& a, const KDL::Vector& b) { return std::sqrt(KDL::dot(a - b, a - b)); }

/// No signal: a crash shows through the shell as 128 + the signal's number.
::testing::AssertionResult noSignal(const ToolRun& r, const std::string& what) {
  if (r.rc < 128) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << what << ": exit code " << r.rc << " (a signal)\nstderr: " << r.err;
}

class CliFamilies : public ::testing::TestWithParam<ModelFamily> {};

// inspect at every link of the file (the links read from the URDF's text), each with an offset, at
// a configuration inside the limits and a base turned and moved: the contact's G* is the library's
// FreeFloatingSolver's at that state (1e-12) and KDL's six-virtual-joint tree's (1e-10 of its
// norm; not for the mimic family: the library suite couples that route by hand); J* is 6 x n and
// has min(6, n) singular values; a robot without joints has J* 6 x 0 and no singular values.
TEST_P(CliFamilies, InspectAtEveryLinkGivesTheLibrarysAndTheVirtualJointTreesGStar) {
  const ModelFamily& f = GetParam();
  const std::string urdf = familyUrdf(f.name);
  const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(urdf));
  ASSERT_EQ(model->nj(), f.joints);
  State s(*model);
  s.world_T_base = KDL::Frame(KDL::Rotation::RPY(0.4, -0.3, 0.2), KDL::Vector(0.3, -0.1, 0.2));
  std::string q_args;
  for (const auto& [name, value] : inLimits(*model, 0)) {
    s.q(model->jointIndex(name)) = value;
    q_args += " " + name + "=" + num(value);
  }
  FreeFloatingSolver solver(model);
  ASSERT_EQ(solver.compute(s), 0);
  std::unique_ptr<VirtualJointTree> route;
  if (!f.mimic) route = std::make_unique<VirtualJointTree>(*model, s);
  const KDL::Vector offset(0.05, -0.02, 0.1);
  const std::vector<std::string> links = linkNames(slurp(urdf));
  ASSERT_FALSE(links.empty());
  for (const std::string& link : links) {
    const ToolRun run = kdlSpace("inspect --urdf " + urdf + " --tip " + link + " --offset 0.05 -0.02 0.1" +
                                 (q_args.empty() ? "" : " --q" + q_args) +
                                 " --base-pos 0.3 -0.1 0.2 --base-rpy 0.4 -0.3 0.2 --json");
    ASSERT_TRUE(noSignal(run, f.name + " inspect at " + link));
    ASSERT_EQ(run.rc, 0) << f.name << " at " << link << ": " << run.err;
    const json j = json::parse(run.out);
    EXPECT_EQ(j.at("joint_names").size(), f.joints) << f.name;
    ASSERT_EQ(j.at("contacts").size(), 1u);
    const json& c = j.at("contacts")[0];
    EXPECT_EQ(c.at("link"), link);
    const Contact h = model->contact(link, offset);
    Matrix6d G_lib;
    ASSERT_EQ(solver.G_star(h, G_lib), 0) << link;
    const Eigen::MatrixXd G_tool = matrixOf(c.at("G_star"));
    const double scale = G_lib.norm();
    EXPECT_TRUE(near(G_tool, G_lib, 1e-12, 1e-15 * scale, f.name + " inspect's G* at " + link + " vs the library's"));
    if (route) {
      const Eigen::MatrixXd G_kdl = route->G(LinkPoint{link, offset});
      EXPECT_TRUE(near(G_tool, G_kdl, 0, 1e-10 * G_kdl.norm(), f.name + " inspect's G* at " + link + " vs KDL's virtual-joint tree"));
      EXPECT_NEAR(j.at("mass").get<double>(), route->M_full()(0, 0), 1e-12 * route->M_full()(0, 0)) << f.name;
    }
    // J*: 6 rows of n numbers (6 empty rows for n = 0); its singular values, min(6, n).
    const json& J = c.at("J_star");
    ASSERT_EQ(J.size(), 6u) << f.name << " at " << link << ": " << J.dump();
    for (const json& row : J) EXPECT_EQ(row.size(), f.joints) << f.name << " at " << link << ": " << J.dump();
    KDL::Jacobian J_lib(model->nj());
    ASSERT_EQ(solver.J_star(h, J_lib), 0);
    if (f.joints > 0) {
      EXPECT_TRUE(near(matrixOf(J), J_lib.data, 1e-12, 1e-15 * (J_lib.data.norm() + 1), f.name + " J* at " + link));
    }
    const json& sigma = c.at("conditioning").at("J_star_singular_values");
    ASSERT_TRUE(sigma.is_array()) << sigma.dump();
    EXPECT_EQ(sigma.size(), std::min(6u, f.joints)) << f.name << " at " << link << ": " << sigma.dump();
    if (f.joints == 0) {
      EXPECT_TRUE(j.at("H_star").empty()) << j.at("H_star").dump();
      EXPECT_TRUE(j.at("joint_margins").empty()) << j.at("joint_margins").dump();
    }
  }
}

// inspect's text: a robot without joints is said to have none (and the run, with its empty H*
// and J*^T, exits 0); a robot with joints prints its contact.
TEST_P(CliFamilies, InspectsTextSaysWhetherTheRobotHasMovableJoints) {
  const ModelFamily& f = GetParam();
  const ToolRun run = kdlSpace("inspect --urdf " + familyUrdf(f.name) + " --tip " + f.contact);
  ASSERT_TRUE(noSignal(run, f.name + " inspect"));
  ASSERT_EQ(run.rc, 0) << run.err;
  // The report is wrapped to a width (COLUMNS): its words on one line, one space apart.
  const std::string text = std::regex_replace(run.out, std::regex("\\s+"), " ");
  EXPECT_NE(text.find("link '" + f.contact + "'"), std::string::npos) << run.out;
  if (f.joints == 0) {
    EXPECT_NE(text.find("no movable joint"), std::string::npos) << f.name << ":\n" << run.out;
  } else {
    EXPECT_EQ(text.find("no movable joint"), std::string::npos) << f.name << ":\n" << run.out;
  }
}

// capture with each law: the momentum after is the momentum before (1e-12), which is the robot's by
// KDL's virtual-joint tree plus the box's by hand (1e-10); the energy does not grow; after a rigid
// capture the hand moves with the box's point.
TEST_P(CliFamilies, CaptureWithEachLawConservesTheMomentumOfRobotAndBox) {
  const ModelFamily& f = GetParam();
  const Eigen::Matrix<double, 6, 1> h_route = momentumBefore(f);
  const std::vector<std::pair<std::string, std::string>> laws{
      {"capture", "{type: capture}"},
      {"translational", "{type: translational}"},
      {"point", "{type: point, normal: [1, 0, 0], restitution: 0.5}"},
      {"friction", "{type: friction, normal: [1, 0, 0], restitution: 0.2, friction: 0.3}"}};
  for (const auto& [name, law] : laws) {
    const ToolRun run = kdlSpace("capture " + writeScenario(f, "capture_" + name, law) + " --json");
    ASSERT_TRUE(noSignal(run, f.name + " capture " + name));
    ASSERT_EQ(run.rc, 0) << f.name << " " << name << ": " << run.err;
    const json j = json::parse(run.out);
    const Eigen::VectorXd before = vectorOf(j.at("momentum_before")), after = vectorOf(j.at("momentum_after"));
    ASSERT_EQ(before.size(), 6);
    ASSERT_EQ(after.size(), 6);
    EXPECT_TRUE(near(after, before, 0, 1e-12 * before.norm(), f.name + " " + name + ": momentum after vs before"));
    EXPECT_TRUE(near(before, h_route, 0, 1e-10 * h_route.norm(), f.name + " " + name + ": momentum before vs KDL + the box"));
    EXPECT_LE(j.at("energy_after").get<double>(), j.at("energy_before").get<double>() * (1 + 1e-12)) << f.name << " " << name;
    EXPECT_EQ(j.at("robot").at("joint_names").size(), f.joints);
    EXPECT_EQ(j.at("robot").at("qdot_after").size(), f.joints);
    if (name != "capture") continue;
    // The rigid grasp: the hand's twist after is the box's at the contact point (CoM at its pose).
    const Eigen::VectorXd t = vectorOf(j.at("target").at("twist_after"));
    const Eigen::Vector3d w = t.tail<3>(), r = vectorOf(j.at("contact_point")) - Eigen::Vector3d(2.5, 0.5, 0.3);
    Eigen::Matrix<double, 6, 1> point;
    point << t.head<3>() + w.cross(r), w;
    EXPECT_TRUE(near(vectorOf(j.at("robot").at("contact_twist_after")), point, 0, 1e-12 * (point.norm() + 1),
                     f.name + " capture: the hand moves with the box's point"));
  }
}

/// The cells of a CSV line.
std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  for (std::string cell; std::getline(s, cell, ',');) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

// simulate (the capture, then 0.3 s of the joined motion): every row of the CSV carries the
// momentum after the capture (robot and box: 1e-9), the run reaches t = 0.3, the JSON's largest
// momentum changes are as small.
TEST_P(CliFamilies, SimulateRunsAndKeepsTheMomentum) {
  const ModelFamily& f = GetParam();
  const std::string csv = scratchIn("cli_families_" + f.name, "simulate.csv");
  const ToolRun run = kdlSpace("simulate " + writeScenario(f, "simulate", "{type: capture}") +
                               " --json --duration 0.3 --csv " + csv);
  ASSERT_TRUE(noSignal(run, f.name + " simulate"));
  ASSERT_EQ(run.rc, 0) << f.name << ": " << run.err;
  const json j = json::parse(run.out);
  ASSERT_TRUE(j.at("capture").is_object()) << j.dump();
  ASSERT_TRUE(j.at("simulation").is_object()) << j.dump();
  EXPECT_NEAR(j.at("simulation").at("final").at("t").get<double>(), 0.3, 1e-12);
  const Eigen::VectorXd h0 = vectorOf(j.at("capture").at("momentum_after"));
  const double tolerance = 1e-9 * (h0.norm() + 1);
  EXPECT_LE(j.at("simulation").at("max_linear_momentum_change").get<double>(), tolerance);
  EXPECT_LE(j.at("simulation").at("max_angular_momentum_change").get<double>(), tolerance);

  std::ifstream in(csv);
  std::string line;
  ASSERT_TRUE(std::getline(in, line)) << csv;
  const std::vector<std::string> header = cells(line);
  const auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    EXPECT_NE(it, header.end()) << name;
    return static_cast<std::size_t>(it - header.begin());
  };
  const std::vector<std::string> names{"P_x", "P_y", "P_z", "L_x", "L_y", "L_z"};
  std::vector<std::size_t> h_columns;
  for (const std::string& n : names) h_columns.push_back(column(n));
  const std::size_t t_column = column("t");
  int rows = 0;
  double t_last = -1;
  while (std::getline(in, line)) {
    const std::vector<std::string> row = cells(line);
    ASSERT_EQ(row.size(), header.size()) << line;
    for (int k = 0; k < 6; ++k)
      EXPECT_NEAR(std::stod(row[h_columns[k]]), h0(k), tolerance) << f.name << " " << names[k] << " at t = " << row[t_column];
    t_last = std::stod(row[t_column]);
    ++rows;
  }
  EXPECT_GE(rows, 4);  // t = 0, 0.1, 0.2, 0.3
  EXPECT_NEAR(t_last, 0.3, 1e-12);
}

// simulate with reaction wheels (robot.base_actuators) holding the bus's attitude: four wheels
// in a skewed cluster, so weak (0.05 N m, 0.01 N m s) that they reach both their torque limit
// and their capacity within the run. The momentum of the links with the wheels is the capture's
// momentum_after (the wheels start at rest), computed independently (momentumBefore: the
// virtual-joint route) to 1e-9; the work counted balances the energy; the wheels' JSON and CSV
// columns say what they did.
TEST_P(CliFamilies, SimulateWithReactionWheelsKeepsTheMomentumOfLinksAndWheels) {
  const ModelFamily& f = GetParam();
  const std::string path = writeScenario(f, "wheels", "{type: capture}");
  std::string text = slurp(path);
  text = std::regex_replace(text, std::regex("\n  contact:"),
                            "\n  base_actuators: {wheels: {axes: [[1, 0, 0], [0, 0.6, 0.8], [0, -0.8, 0.6], [1, 1, 1]], "
                            "torque_limit: 0.05, capacity: 0.01}}\n  contact:");
  text = std::regex_replace(text, std::regex("simulation: \\{"),
                            "simulation: {base_control: {attitude: {kp: 5, kd: 40, set_point: hold}}, ");
  spit(path, text);
  const std::string csv = scratchIn("cli_families_" + f.name, "wheels.csv");
  const ToolRun run = kdlSpace("simulate " + path + " --json --csv " + csv);
  ASSERT_TRUE(noSignal(run, f.name + " simulate with wheels"));
  ASSERT_EQ(run.rc, 0) << f.name << ": " << run.err;
  const json j = json::parse(run.out);
  const json& sim = j.at("simulation");
  const Eigen::VectorXd h0 = momentumBefore(f);
  const double tolerance = 1e-9 * (h0.norm() + 1);
  EXPECT_LE((vectorOf(j.at("capture").at("momentum_after")) - h0).norm(), tolerance);
  EXPECT_LE(sim.at("max_linear_momentum_change").get<double>(), tolerance);
  EXPECT_LE(sim.at("max_angular_momentum_change").get<double>(), tolerance);
  EXPECT_LE(std::abs(sim.at("energy_split").at("residual").get<double>()), 1e-9 * (sim.at("energy").get<double>() + 1));
  const json& wheels = sim.at("wheels");
  ASSERT_EQ(wheels.at("wheels").size(), 4u) << wheels.dump();
  EXPECT_GT(wheels.at("saturation_time").get<double>(), 0.0);
  double peak = 0.0;
  for (const json& w : wheels.at("wheels")) {
    peak = std::max(peak, w.at("peak_momentum").get<double>());
    EXPECT_LE(w.at("peak_momentum").get<double>(), 0.01 * (1 + 1e-6));  // never past its capacity
    EXPECT_LE(w.at("peak_torque").get<double>(), 0.05 * (1 + 1e-12));
  }
  EXPECT_GT(peak, 0.0);
  EXPECT_NE(run.err.find("wheel"), std::string::npos) << run.err;  // the saturation's warning
  std::istringstream lines(slurp(csv));
  std::string header;
  ASSERT_TRUE(std::getline(lines, header));
  EXPECT_NE(header.find(",wheel_h_1,wheel_h_2,wheel_h_3,wheel_h_4,wheel_u_1,"), std::string::npos) << header;
}

// simulate under momentum_distribution (simulation.after_capture) with three wheels: the tool
// keeps the momentum of links and wheels at the virtual-joint route's momentum before the capture
// (1e-9) and balances the energy; a robot without joints is refused (exit 3, the field named).
TEST_P(CliFamilies, SimulateUnderMomentumDistributionKeepsTheMomentumOrSaysWhyNot) {
  const ModelFamily& f = GetParam();
  const std::string path = writeScenario(f, "distribution", "{type: capture}");
  std::string text = slurp(path);
  text = std::regex_replace(text, std::regex("\n  contact:"),
                            "\n  base_actuators: {wheels: {torque_limit: 10, capacity: 10}}\n  contact:");
  text = std::regex_replace(text, std::regex("simulation: \\{[^\n]*\\}\n"),
                            "simulation:\n  duration: 0.3\n  output_step: 0.1\n  rtol: 1.0e-10\n  atol: 1.0e-12\n"
                            "  joints: {\"*\": {pd: {kp: 50, kd: 20, set_point: hold}}}\n"
                            "  base_control: {attitude: {kp: 5, kd: 40, set_point: hold}}\n"
                            "  after_capture: {law: momentum_distribution}\n");
  spit(path, text);
  const ToolRun run = kdlSpace("simulate " + path + " --json");
  ASSERT_TRUE(noSignal(run, f.name + " simulate under momentum_distribution"));
  if (f.joints == 0) {
    EXPECT_EQ(run.rc, 3) << run.err;
    EXPECT_NE(run.err.find("simulation.joints"), std::string::npos) << run.err;
    return;
  }
  ASSERT_EQ(run.rc, 0) << f.name << ": " << run.err;
  const json j = json::parse(run.out);
  const json& sim = j.at("simulation");
  const Eigen::VectorXd h0 = momentumBefore(f);
  const double tolerance = 1e-9 * (h0.norm() + 1);
  EXPECT_LE((vectorOf(j.at("capture").at("momentum_after")) - h0).norm(), tolerance);
  EXPECT_LE(sim.at("max_linear_momentum_change").get<double>(), tolerance);
  EXPECT_LE(sim.at("max_angular_momentum_change").get<double>(), tolerance);
  EXPECT_LE(std::abs(sim.at("energy_split").at("residual").get<double>()), 1e-9 * (sim.at("energy").get<double>() + 1));
}

// ik: a pose of the contact frame at another configuration (inside the limits), by KDL's tree
// solver with the mimic joints set from the URDF's <mimic>, is reached: the angles the tool prints
// put through the same solver land on it (1e-9 m, 1e-9 rad), inside the limits. At the family's
// contact and at its other one (a mimic joint on the chain, the other arm). A robot without joints
// is refused: exit 3, "no movable joint" on stderr, nothing on stdout.
TEST_P(CliFamilies, IkReachesAPoseByKdlOrSaysThereIsNoMovableJoint) {
  const ModelFamily& f = GetParam();
  const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(familyUrdf(f.name)));
  const std::vector<MimicLine> mimics = mimicLines(slurp(familyUrdf(f.name)));
  EXPECT_EQ(!mimics.empty(), f.mimic);
  struct Case {
    std::string link;
    KDL::Vector offset;
  };
  std::vector<Case> cases{{f.contact, KDL::Vector(f.offset[0], f.offset[1], f.offset[2])}};
  if (!f.other_contact.empty()) cases.push_back({f.other_contact, KDL::Vector(0.01, 0.02, 0.03)});
  int variant = 1;
  for (const Case& c : cases) {
    const std::string scenario = writeScenario(f, "ik_" + c.link, "{type: capture}", c.link, c.offset);
    const std::map<std::string, double> truth = inLimits(*model, variant++);
    // Without joints: the pose the contact frame holds already (by KDL's chain solver: its tree
    // solver reads q(0) of a tree without joints, whose JntArray has no element 0). Still refused.
    const KDL::Frame goal = f.joints == 0 ? kdlFixedFrame(*model, c.link, c.offset, kBasePose)
                                          : kdlContactFrame(*model, mimics, truth, c.link, c.offset, kBasePose);
    double roll, pitch, yaw;
    goal.M.GetRPY(roll, pitch, yaw);
    const ToolRun run = kdlSpace("ik " + scenario + " --position=" + num(goal.p.x()) + "," + num(goal.p.y()) + "," +
                                 num(goal.p.z()) + " --rpy=" + num(roll) + "," + num(pitch) + "," + num(yaw) + " --json");
    ASSERT_TRUE(noSignal(run, f.name + " ik at " + c.link));
    if (f.joints == 0) {
      EXPECT_EQ(run.rc, 3) << f.name << " at " << c.link << ": " << run.out;
      EXPECT_EQ(run.out, "");
      EXPECT_EQ(run.err.rfind("kdl_space: ", 0), 0u) << run.err;
      EXPECT_NE(run.err.find("no movable joint"), std::string::npos) << f.name << " at " << c.link << ": " << run.err;
      continue;
    }
    ASSERT_EQ(run.rc, 0) << f.name << " at " << c.link << ": " << run.err;
    const json j = json::parse(run.out);
    const auto q = j.at("q_by_name").get<std::map<std::string, double>>();
    EXPECT_EQ(q.size(), f.joints);
    const KDL::Frame reached = kdlContactFrame(*model, mimics, q, c.link, c.offset, kBasePose);
    EXPECT_LE(distance(reached.p, goal.p), 1e-9) << f.name << " at " << c.link;
    EXPECT_LE(angleBetween(goal.M, reached.M), 1e-9) << f.name << " at " << c.link;
    for (unsigned int k = 0; k < model->nj(); ++k) {
      const JointProperties& p = model->jointProperties()[k];
      const double v = q.at(model->jointNames()[k]);
      EXPECT_GE(v, p.lower) << f.name << " " << model->jointNames()[k];
      EXPECT_LE(v, p.upper) << f.name << " " << model->jointNames()[k];
    }
  }
}

// plan: an optimum inside the limits no worse than the scenario as written (exit 0), or a refusal
// (exit 3) whose message starts "kdl_space: "; a robot without joints is refused saying it has no
// movable joint.
TEST_P(CliFamilies, PlanFindsAnOptimumOrSaysWhyNot) {
  const ModelFamily& f = GetParam();
  const ToolRun run = kdlSpace("plan " + writeScenario(f, "plan", "{type: capture}") + " --json --scan 5");
  ASSERT_TRUE(noSignal(run, f.name + " plan"));
  ASSERT_TRUE(run.rc == 0 || run.rc == 3) << f.name << ": exit " << run.rc << ": " << run.err;
  if (f.joints == 0) {
    EXPECT_EQ(run.rc, 3) << f.name << ": " << run.out;
    EXPECT_NE(run.err.find("no movable joint"), std::string::npos) << f.name << ": " << run.err;
  }
  if (run.rc == 3) {
    EXPECT_EQ(run.err.rfind("kdl_space: ", 0), 0u) << run.err;
    EXPECT_GT(run.err.size(), std::string("kdl_space: \n").size()) << run.err;
    return;
  }
  const json j = json::parse(run.out);
  const auto model = loadUrdfFile(familyUrdf(f.name));
  const auto q = j.at("q_by_name").get<std::map<std::string, double>>();
  EXPECT_EQ(q.size(), f.joints);
  for (unsigned int k = 0; k < model.nj(); ++k) {
    const JointProperties& p = model.jointProperties()[k];
    EXPECT_GE(q.at(model.jointNames()[k]), p.lower) << f.name << " " << model.jointNames()[k];
    EXPECT_LE(q.at(model.jointNames()[k]), p.upper) << f.name << " " << model.jointNames()[k];
  }
  const double optimum = j.at("objective").get<double>();
  EXPECT_TRUE(std::isfinite(optimum)) << j.dump();
  EXPECT_LE(optimum, j.at("nominal_objective").get<double>() + 1e-12) << f.name;
}

// study: a study of four samples of the box's mass and spin computes every sample (status 0).
TEST_P(CliFamilies, AStudyComputesEverySample) {
  const ModelFamily& f = GetParam();
  const std::string scenario = writeScenario(f, "study_scenario", "{type: capture}");
  const std::string study = scratchIn("cli_families_" + f.name, "study.yaml");
  const std::string table = scratchIn("cli_families_" + f.name, "study.csv");
  std::filesystem::remove(table);
  spit(study, "scenario: " + scenario + "\nsamples: 4\nseed: 34\ninputs:\n  target.mass: {uniform: [20, 60]}\n"
              "  target.twist.wx: {normal: {mean: 0.03, std: 0.01}}\n");
  const ToolRun run = kdlSpace("study " + study + " --threads 1 -o " + table);
  ASSERT_TRUE(noSignal(run, f.name + " study"));
  ASSERT_EQ(run.rc, 0) << f.name << ": " << run.err;
  std::istringstream lines(slurp(table));
  std::string line;
  std::vector<std::string> header;
  int rows = 0;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header.empty()) {
      header = cells(line);
      continue;
    }
    const std::vector<std::string> row = cells(line);
    ASSERT_EQ(row.size(), header.size()) << line;
    const auto status = std::find(header.begin(), header.end(), "status");
    ASSERT_NE(status, header.end()) << line;
    EXPECT_EQ(row[status - header.begin()], "0") << f.name << ": " << line << "\n" << run.out;
    ++rows;
  }
  EXPECT_EQ(rows, 4) << slurp(table);
}

// check: no error in any family's file, and the joints it counts are the family's.
// kdl_space mount: the family's robot as an arm on a bus given as mass and box (robot.mount),
// written as one URDF: the bus's mass and box inertia added, the robot's joints kept, and inspect
// on the written file gives the G* of the library's model of the same scenario; the arm's file is
// never overwritten.
TEST_P(CliFamilies, MountPutsTheRobotOnABusAsOneUrdf) {
  const ModelFamily& f = GetParam();
  const FloatingModel alone = loadUrdfFile(familyUrdf(f.name));
  const std::string scenario = scratchIn("cli_families_" + f.name, "mount.yaml");
  spit(scenario, "robot:\n  urdf: " + familyUrdf(f.name) + "\n  mount: {bus: {name: servicer, mass: 800, box: [1.5, 1.2, 1.0]}, " +
                     "pose: {position: [0.8, 0, 0.6], rpy: {deg: [0, 20, 0]}}}\n  contact: {link: " + f.contact + "}\n" +
                     "simulation: {duration: 1}\n");
  const std::string out = scratchIn("cli_families_" + f.name, "mounted.urdf");
  const ToolRun run = kdlSpace("mount " + scenario + " -o " + out + " --json");
  ASSERT_TRUE(noSignal(run, f.name + " mount"));
  ASSERT_EQ(run.rc, 0) << f.name << ": " << run.err;
  const json j = json::parse(run.out);
  EXPECT_NEAR(j.at("mass").get<double>(), 800 + alone.totalMass(), 1e-12 * (800 + alone.totalMass())) << f.name;
  std::vector<std::string> joints = j.at("joints").get<std::vector<std::string>>(), expected = alone.jointNames();
  std::sort(joints.begin(), joints.end());
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(joints, expected) << f.name;
  const auto written = std::make_shared<const FloatingModel>(loadUrdfFile(out));
  EXPECT_EQ(written->bodies()[0].name, "servicer");
  const ToolRun inspect = kdlSpace("inspect --urdf " + out + " --tip " + f.contact + " --json");
  ASSERT_EQ(inspect.rc, 0) << f.name << ": " << inspect.err;
  FreeFloatingSolver solver(written);
  ASSERT_EQ(solver.compute(State(*written)), 0);
  Matrix6d G;
  ASSERT_EQ(solver.G_star(written->contact(f.contact), G), 0);
  const Eigen::MatrixXd G_tool = matrixOf(json::parse(inspect.out).at("contacts")[0].at("G_star"));
  EXPECT_TRUE(near(G_tool, G, 1e-12, 1e-15 * G.norm(), f.name + " inspect of the mounted robot"));
  // the robot's own file is an input: never the output
  const std::string before = slurp(familyUrdf(f.name));
  const ToolRun over = kdlSpace("mount " + scenario + " -o " + familyUrdf(f.name));
  EXPECT_EQ(over.rc, 2) << over.err;
  EXPECT_NE(over.err.find("it would be overwritten"), std::string::npos) << over.err;
  EXPECT_EQ(slurp(familyUrdf(f.name)), before);
}

// export and import over every family: SpaceDyn's LP and MuJoCo's MJCF written from a scenario, read
// back (import, and inspect on the files themselves), the same G* at the contact (the LP's contact end
// point, the MJCF's link); mimic families refused by name (exit 3); no input is overwritten.
TEST_P(CliFamilies, ExportAndImportKeepTheSystem) {
  const ModelFamily& f = GetParam();
  const std::string dir = scratchIn("cli_families_" + f.name, "export");
  const std::string scenario = dir + ".yaml";
  spit(scenario, "robot:\n  urdf: " + familyUrdf(f.name) + "\n  contact: {link: " + f.contact + "}\nsimulation: {duration: 1}\n");
  const auto original = std::make_shared<const FloatingModel>(loadUrdfFile(familyUrdf(f.name)));
  FreeFloatingSolver ours(original);
  ASSERT_EQ(ours.compute(State(*original)), 0);
  Matrix6d G;
  ASSERT_EQ(ours.G_star(original->contact(f.contact), G), 0);
  const ToolRun sd = kdlSpace("export " + scenario + " --spacedyn " + dir + " --name fam --json");
  const ToolRun mj = kdlSpace("export " + scenario + " --mjcf " + dir + "/scene.xml");
  ASSERT_TRUE(noSignal(sd, f.name + " export --spacedyn") && noSignal(mj, f.name + " export --mjcf"));
  if (f.mimic) {
    EXPECT_EQ(sd.rc, 3) << sd.err;
    EXPECT_NE(sd.err.find("(mimic)"), std::string::npos) << sd.err;
    EXPECT_EQ(mj.rc, 3) << mj.err;
    EXPECT_NE(mj.err.find("mimic"), std::string::npos) << mj.err;
    return;
  }
  ASSERT_EQ(sd.rc, 0) << f.name << ": " << sd.err;
  ASSERT_EQ(mj.rc, 0) << f.name << ": " << mj.err;
  const std::string lp = dir + "/fam_LP.m", xml = dir + "/scene.xml";
  for (const std::string& file : {lp, xml}) {
    const ToolRun back = kdlSpace("import " + std::string(file == lp ? "--spacedyn " : "--mjcf ") + file + " -o " + file + ".urdf --json");
    ASSERT_EQ(back.rc, 0) << f.name << " " << file << ": " << back.err;
    EXPECT_NEAR(json::parse(back.out).at("mass").get<double>(), original->totalMass(), 1e-12 * original->totalMass()) << file;
    // the contact: MJCF keeps the link and its frame; the LP has it as its end point "contact" (not on the base)
    const std::string tip = file == xml ? f.contact : "contact";
    const bool on_base = original->contact(f.contact).body == 0;
    if (file == lp && (on_base || original->nj() == 0)) continue;
    const std::string offset = file == xml ? " --offset 0 0 0" : "";
    const ToolRun inspect = kdlSpace("inspect --urdf " + file + " --tip " + tip + offset + " --json");  // the file itself, not its URDF
    ASSERT_EQ(inspect.rc, 0) << f.name << " " << file << ": " << inspect.err;
    const Eigen::MatrixXd G_tool = matrixOf(json::parse(inspect.out).at("contacts")[0].at("G_star"));
    EXPECT_TRUE(near(G_tool, G, 1e-12, 1e-12 * G.norm(), f.name + " inspect of " + file));
  }
  const std::string before = slurp(familyUrdf(f.name));
  const ToolRun over = kdlSpace("export " + scenario + " --urdf " + familyUrdf(f.name));
  EXPECT_EQ(over.rc, 2) << over.err;
  EXPECT_EQ(slurp(familyUrdf(f.name)), before);
}

TEST_P(CliFamilies, CheckFindsNoError) {
  const ModelFamily& f = GetParam();
  const ToolRun run = kdlSpace("check " + familyUrdf(f.name) + " --json");
  ASSERT_TRUE(noSignal(run, f.name + " check"));
  EXPECT_EQ(run.rc, 0) << f.name << ": " << run.out << run.err;
  const json j = json::parse(run.out);
  EXPECT_TRUE(j.at("errors").empty()) << j.at("errors").dump();
  EXPECT_EQ(j.at("model").at("joint_names").size(), f.joints) << j.at("model").dump();
}

// Above kDenseJoints (a 501-link tree): inspect and capture take the O(n) routes (issue 35, item 8).
// inspect's G* at each point and over both (cross blocks) equal the dense solver's, computed here;
// H* is null and a diagnostic says why; capture conserves momentum.
TEST(CliLargeModel, InspectAndCaptureTakeTheLinearRoutes) {
  const std::string urdf = scratchIn("cli_large", "tree.urdf");
  spit(urdf, largeTree(501));
  const ToolRun run = kdlSpace("inspect --urdf " + urdf + " --tip l50 --offset 0.1 0 0 --tip l300 --q j3=0.4 j250=-1.1 --json");
  ASSERT_TRUE(noSignal(run, "inspect"));
  ASSERT_EQ(run.rc, 0) << run.err;
  const json j = json::parse(run.out);
  EXPECT_TRUE(j.at("H_star").is_null());
  bool noted = false;
  for (const json& d : j.at("diagnostics")) noted |= d.get<std::string>().find("H* (n x n) is not formed above 400") != std::string::npos;
  EXPECT_TRUE(noted) << j.at("diagnostics").dump();

  const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(urdf));
  State s(*model);
  s.q(model->jointIndex("j3")) = 0.4;
  s.q(model->jointIndex("j250")) = -1.1;
  FreeFloatingSolver dense(model);
  ASSERT_EQ(dense.compute(s), 0);
  const std::vector<Contact> contacts{model->contact("l50", KDL::Vector(0.1, 0, 0)), model->contact("l300")};
  Eigen::MatrixXd G_all(12, 12);
  ASSERT_EQ(dense.G_star(contacts, G_all), 0);
  const double scale = G_all.norm();
  EXPECT_TRUE(near(matrixOf(j.at("G_star_all")), G_all, 0, 1e-10 * scale, "G* over both points"));
  for (int i = 0; i < 2; ++i) {
    Matrix6d G, G_grounded;
    ASSERT_EQ(dense.G_star(contacts[i], G), 0);
    ASSERT_EQ(dense.G_grounded(contacts[i], G_grounded), 0);
    const json& c = j.at("contacts").at(i);
    EXPECT_TRUE(near(matrixOf(c.at("G_star")), G, 0, 1e-10 * scale, "G*"));
    EXPECT_TRUE(near(matrixOf(c.at("G_grounded")), G_grounded, 0, 1e-10 * scale, "G grounded"));
    EXPECT_EQ(c.at("J_star").at(0).size(), 500u);
  }

  // A link it has not: the message lists the first 40 of its 501 links, not all.
  const ToolRun missing = kdlSpace("inspect --urdf " + urdf + " --tip l9999");
  EXPECT_EQ(missing.rc, 3) << missing.err;
  EXPECT_NE(missing.err.find("has no link 'l9999' (its links: base, l1, l2,"), std::string::npos) << missing.err;
  EXPECT_NE(missing.err.find(", l39, ... and 461 more)"), std::string::npos) << missing.err;
  EXPECT_LT(missing.err.size(), 600u) << missing.err;

  const std::string scenario = scratchIn("cli_large", "capture.yaml");
  spit(scenario, "robot:\n  urdf: tree.urdf\n  contact: {link: l50}\n"
                 "  base: {position: [0, 0, 0], rpy: [0, 0, 0], twist: [0.002, 0, 0, 0, 0, 0.001]}\n"
                 "target:\n  mass: 50\n  inertia: [[2.1, 0, 0], [0, 2.6, 0], [0, 0, 3.0]]\n"
                 "  pose: {position: [20, 0, 0], rpy: [0.3, -0.2, 0.5]}\n"
                 "  twist: [0.03, -0.02, 0.01, 0.05, 0.08, -0.06]\nlaw:\n  type: capture\n");
  const ToolRun cap = kdlSpace("capture " + scenario + " --json");
  ASSERT_TRUE(noSignal(cap, "capture"));
  ASSERT_EQ(cap.rc, 0) << cap.err;
  const json c = json::parse(cap.out);
  const Eigen::MatrixXd before = matrixOf(c.at("momentum_before")), after = matrixOf(c.at("momentum_after"));
  EXPECT_TRUE(near(after, before, 0, 1e-10 * before.norm(), "momentum"));
}

std::string familyName(const ::testing::TestParamInfo<ModelFamily>& info) { return info.param.name; }
INSTANTIATE_TEST_SUITE_P(EveryKindOfRobot, CliFamilies, ::testing::ValuesIn(modelFamilies()), familyName);

}  // namespace
}  // namespace kdl_space::test
