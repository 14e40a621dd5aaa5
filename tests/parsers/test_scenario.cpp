// loadScenario (scenario.hpp): the bundled and test scenarios load into the library's types with
// the values their files hold, and a broken file is refused with an InputError that names the
// file, the line and the field (the same messages `kdl_space capture` prints: tests/cli checks
// the whole corpus end to end; here a few through the library alone).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "kdl_space/parsers/scenario/scenario.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

namespace fs = std::filesystem;

const std::string kShipped = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/";
const std::string kBroken = dataDir() + "/broken_scenarios/";

TEST(LoadScenario, ARigidTargetInTheFilesTerms) {
  const Scenario s = loadScenario(kShipped + "tumbling_box_capture.yaml");
  EXPECT_EQ(s.file, kShipped + "tumbling_box_capture.yaml");
  EXPECT_EQ(s.robot_urdf, fs::path(std::string(KDL_SPACE_SOURCE_DIR) + "/urdf/space_arm7.urdf").lexically_normal().string());
  EXPECT_EQ(s.target_urdf, "");
  EXPECT_FALSE(s.rigid_target_system);  // a rigid target by numbers: no file to draw from
  const CaptureProblem& p = s.capture;
  ASSERT_TRUE(p.robot.model);
  EXPECT_EQ(p.robot.model->jointNames().size(), 7u);
  EXPECT_EQ(p.robot.contact.body, p.robot.model->bodyIndex("end_effector"));
  EXPECT_TRUE(near(toEigen(p.robot.contact.offset), Vector3d(0, 0, 0.05), 0.0, 0.0, "offset"));
  EXPECT_EQ(p.robot.response, Response::FreeFloating);
  EXPECT_EQ(p.robot.state.q(p.robot.model->jointIndex("joint3")), 0.9);
  EXPECT_EQ(p.robot.state.q(p.robot.model->jointIndex("joint1")), 0.0);
  EXPECT_EQ(p.robot.velocity.qdot(p.robot.model->jointIndex("joint4")), -0.03);
  EXPECT_TRUE(near(toEigen(p.robot.velocity.base_twist), (Vector6d() << 0.002, 0, 0, 0, 0, 0.001).finished(), 0, 0, "twist"));
  ASSERT_TRUE(std::holds_alternative<RigidTarget>(p.target));
  const RigidTarget& t = std::get<RigidTarget>(p.target);
  EXPECT_EQ(t.mass, 50.0);
  EXPECT_TRUE(near(t.inertia, Vector3d(2.1, 2.6, 3.0).asDiagonal().toDenseMatrix(), 0, 0, "inertia in the target frame"));
  EXPECT_TRUE(near(toEigen(t.pose.p), Vector3d(0.32, -2.88, 1.69), 0, 0, "pose.position"));
  EXPECT_TRUE(near(toEigen(t.pose.M), toEigen(KDL::Rotation::RPY(0.3, -0.2, 0.5)), 0, 0, "pose.rpy"));
  EXPECT_TRUE(near(t.com, Vector3d::Zero(), 0, 0, "com"));
  EXPECT_TRUE(near(t.twist, (Vector6d() << 0.03, -0.02, 0.01, 0.05, 0.08, -0.06).finished(), 0, 0, "twist"));
  EXPECT_EQ(p.law.kind, ImpactKind::Capture);
  EXPECT_TRUE(p.has_normal);
  EXPECT_TRUE(near(p.law.normal, Vector3d(0, -1, 0), 0, 0, "normal"));
  EXPECT_EQ(p.method, ExIITMethod::Recursive);
  // The simulation section.
  EXPECT_EQ(s.simulation.duration, 20.0);
  EXPECT_EQ(s.simulation.output_step, 0.05);
  EXPECT_EQ(s.simulation.options.integrator, Integrator::DormandPrince54);
  EXPECT_EQ(s.simulation.options.rtol, 1e-10);
  ASSERT_EQ(s.simulation.joints.size(), 7u);
  EXPECT_EQ(s.simulation.joints[1].first, static_cast<unsigned int>(p.robot.model->jointIndex("joint2")));
  EXPECT_EQ(s.simulation.joints[1].second.mode, JointControl::Mode::PD);
  EXPECT_EQ(s.simulation.joints[1].second.set_point, 0.7);
  // It solves.
  EXPECT_NO_THROW(solveCapture(p));
}

TEST(LoadScenario, AFreeFloatingTarget) {
  const Scenario s = loadScenario(kShipped + "robot_to_robot_capture.yaml");
  ASSERT_TRUE(std::holds_alternative<FloatingSystem>(s.capture.target));
  EXPECT_FALSE(s.rigid_target_system);  // only a rigid target read from a URDF
  const FloatingSystem& t = std::get<FloatingSystem>(s.capture.target);
  ASSERT_TRUE(t.model);
  EXPECT_EQ(t.model->jointNames(), (std::vector<std::string>{"joint1", "joint2"}));
  EXPECT_EQ(t.contact.body, t.model->bodyIndex("hand"));
  EXPECT_EQ(t.velocity.qdot(1), -0.02);
  EXPECT_EQ(s.target_urdf,
            fs::path(std::string(KDL_SPACE_SOURCE_DIR) + "/urdf/spacedyn_twolink.urdf").lexically_normal().string());
  EXPECT_FALSE(s.capture.has_normal);
  // No simulation section: the defaults.
  EXPECT_EQ(s.simulation.duration, SimulationSpec().duration);
  EXPECT_TRUE(s.simulation.joints.empty());
  const CaptureResult r = solveCapture(s.capture);
  EXPECT_TRUE(r.floating_target.has_value());
}

TEST(LoadScenario, BrakedJointsOfTheRobotAndOfAFreeFloatingTarget) {
  const Scenario s = loadScenario(dataDir() + "/scenarios/braked_robot_to_robot.yaml");
  const FloatingSystem& robot = s.capture.robot;
  ASSERT_TRUE(std::holds_alternative<FloatingSystem>(s.capture.target));
  const FloatingSystem& target = std::get<FloatingSystem>(s.capture.target);
  EXPECT_EQ(robot.locked, (std::vector<bool>{false, false, false, false, false, true, true}));  // model order
  EXPECT_EQ(target.locked, (std::vector<bool>{false, true}));
  const CaptureResult r = solveCapture(s.capture);
  ASSERT_TRUE(r.floating_target.has_value());
  EXPECT_EQ(r.robot.after.qdot(robot.model->jointIndex("joint6")), 0.0);
  EXPECT_EQ(r.robot.after.qdot(robot.model->jointIndex("joint7")), 0.0);
  EXPECT_EQ(r.floating_target->after.qdot(target.model->jointIndex("joint2")), 0.0);
  EXPECT_NE(r.robot.after.qdot(robot.model->jointIndex("joint5")), 0.0) << "an unbraked joint moves";
  EXPECT_TRUE(near(r.momentum_after, r.momentum_before, 1e-9, 1e-9 * r.momentum_before.norm(), "momentum"));
  // Without the brakes the same capture moves those joints.
  CaptureProblem unbraked = s.capture;
  unbraked.robot.locked.clear();
  std::get<FloatingSystem>(unbraked.target).locked.clear();
  EXPECT_NE(solveCapture(unbraked).robot.after.qdot(robot.model->jointIndex("joint7")), 0.0);
}

// simulation.joints and simulation.limits by name and pattern: "*" is the default, a later
// pattern wins over an earlier one, a name over every pattern, in whatever order they are written.
TEST(LoadScenario, JointPatternsResolveByPrecedence) {
  const std::string path = (fs::path(::testing::TempDir()) / "patterns.yaml").string();
  std::ofstream(path) << "robot:\n  urdf: " << urdfDir() << "/space_arm7.urdf\n  contact: {link: end_effector}\n"
                      << "simulation:\n  joints:\n    joint6: locked\n    \"joint[5-7]\": free\n"
                      << "    \"*\": {pd: {kp: 10, kd: 2, set_point: hold}}\n    \"joint?\": {pd: {kp: 20, kd: 3, set_point: 0.5}}\n"
                      << "  limits: {\"*\": stop, \"joint[1-2]\": ignore, joint1: warn}\n";
  const Scenario s = loadScenario(path);
  EXPECT_FALSE(s.impact);
  std::map<unsigned int, JointControl> c(s.simulation.joints.begin(), s.simulation.joints.end());
  ASSERT_EQ(c.size(), 7u);
  for (unsigned int j : {0u, 1u, 2u, 3u}) {  // "joint?" (written after "*") wins over "*"
    EXPECT_EQ(c[j].mode, JointControl::Mode::PD);
    EXPECT_EQ(c[j].kp, 20.0);
    EXPECT_FALSE(c[j].hold);
    EXPECT_EQ(c[j].set_point, 0.5);
  }
  // "joint[5-7]" and "joint?" both match joint5 and joint7: the one written later wins
  EXPECT_EQ(c[4].mode, JointControl::Mode::PD);
  EXPECT_EQ(c[6].mode, JointControl::Mode::PD);
  EXPECT_EQ(c[5].mode, JointControl::Mode::Locked) << "a name wins over every pattern";
  std::map<unsigned int, LimitMode> l(s.simulation.limits.begin(), s.simulation.limits.end());
  EXPECT_EQ(l[0], LimitMode::Warn);
  EXPECT_EQ(l[1], LimitMode::Ignore);
  for (unsigned int j = 2; j < 7; ++j) EXPECT_EQ(l[j], LimitMode::Stop);
}

TEST(LoadScenario, EveryShippedAndTestScenarioLoadsAndSolves) {
  int count = 0;
  for (const std::string& folder : {kShipped, dataDir() + "/scenarios/"})
    for (const auto& entry : fs::directory_iterator(folder)) {
      const std::string ext = entry.path().extension().string();
      if (ext != ".yaml" && ext != ".json") continue;
      if (entry.path().filename().string().rfind("study_", 0) == 0) continue;  // a study (tests/study)
      SCOPED_TRACE(entry.path().string());
      const Scenario s = loadScenario(entry.path().string());
      ASSERT_TRUE(s.capture.robot.model);
      ++count;
      if (!s.impact) continue;  // a plain motion: no impact to solve
      // A robot target's approach: the two touch where the approach ends, not at the start (its
      // capture there: tests/operation/test_approach_robot_target.cpp).
      if (s.approach && std::holds_alternative<FloatingSystem>(s.capture.target)) continue;
      const bool point = s.capture.law.kind == ImpactKind::PointImpact || s.capture.law.kind == ImpactKind::FrictionalImpact;
      if (point) EXPECT_TRUE(s.capture.has_normal);
      EXPECT_NO_THROW(solveCapture(s.capture));
    }
  EXPECT_GE(count, 10);
}

TEST(LoadScenario, PointImpactLaw) {
  const Scenario s = loadScenario(kShipped + "restitution_bounce.yaml");
  EXPECT_EQ(s.capture.law.kind, ImpactKind::PointImpact);
  EXPECT_EQ(s.capture.law.restitution, 0.6);
  EXPECT_TRUE(s.capture.has_normal);
}

/// The message loadScenario throws for `file`, or "" if it loads.
std::string refusal(const std::string& file) {
  try {
    loadScenario(file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(LoadScenario, RefusesABrokenFileNamingTheLineAndField) {
  EXPECT_EQ(refusal(kBroken + "valid.yaml"), "");
  EXPECT_EQ(refusal(kBroken + "negative_mass.yaml"), kBroken + "negative_mass.yaml:10: target.mass: must be > 0 kg, got -3");
  EXPECT_EQ(refusal(kBroken + "inertia_not_symmetric.yaml"),
            kBroken + "inertia_not_symmetric.yaml:11: target.inertia: must be symmetric, but row 2 column 1 is 0 and "
                      "row 1 column 2 is 0.2");
  EXPECT_EQ(refusal(kBroken + "inertia_triangle_inequality.yaml"),
            kBroken + "inertia_triangle_inequality.yaml:11: target.inertia: is no rigid body's inertia: its principal "
                      "moments break the triangle inequality I1 + I2 >= I3 (principal moments 1, 1, 3 kg m^2)");
  EXPECT_EQ(refusal(kBroken + "unknown_joint.yaml"),
            kBroken + "unknown_joint.yaml:6: robot.q.elbow: the model has no movable joint 'elbow' (its movable "
                      "joints: joint1, joint2)");
  EXPECT_EQ(refusal(kBroken + "huge_number.yaml"),
            kBroken + "huge_number.yaml:10: target.mass: '1e400' is too large (not a finite number)");
  EXPECT_EQ(refusal(kBroken + "empty.yaml"), kBroken + "empty.yaml: the file is empty; expected a scenario file (YAML or JSON)");
  EXPECT_EQ(refusal(kBroken + "locked_joint_moves.yaml"),
            kBroken + "locked_joint_moves.yaml:9: robot.locked[1]: joint 'joint2' is braked, so its rate "
                      "robot.qdot.joint2 must be 0, got 0.1");
  EXPECT_EQ(refusal("/nonexistent/scenario.yaml"), "/nonexistent/scenario.yaml: no such file");
}

// --- Angles in degrees where a person writes them ------------------------------------------------

/// A scenario (a plain motion) of a base, a hinge and a slide, with `robot` (YAML after "robot:"
/// and the URDF) in a scratch folder.
std::string degreesScenario(const std::string& name, const std::string& robot) {
  const fs::path dir = fs::path(::testing::TempDir()) / "kdl_space_degrees";
  fs::create_directories(dir);
  std::ofstream(dir / "hinge_slide.urdf") << R"(<robot name="hs">
  <link name="base"><inertial><mass value="50"/><inertia ixx="2" iyy="3" izz="4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><mass value="5"/><inertia ixx="0.2" iyy="0.3" izz="0.4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tip"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
  <joint name="slide" type="prismatic"><parent link="arm"/><child link="tip"/><origin xyz="1 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>
)";
  const std::string path = (dir / name).string();
  std::ofstream(path) << "simulation: {duration: 1}\nrobot:\n  urdf: hinge_slide.urdf\n" << robot;
  return path;
}

// `{deg: x}` for an angle, `{deg: [r, p, y]}` for a pose's rpy, `{deg_per_s: x}` for a revolute
// joint's rate: converted once at load, the same state as the radians written out; a prismatic
// joint's value or rate in degrees, and any other key, refused naming the field.
TEST(LoadScenario, AnglesInDegreesAreConvertedOnceAtLoad) {
  const Scenario d = loadScenario(degreesScenario(
      "deg.yaml", "  base: {position: [1, 2, 3], rpy: {deg: [10, -20, 30]}}\n"
                  "  q: {hinge: {deg: 30}, slide: 0.2}\n  qdot: {hinge: {deg_per_s: -5}, slide: 0.01}\n"));
  char rad[256];
  const double k = 3.14159265358979323846 / 180.0;
  std::snprintf(rad, sizeof rad,
                "  base: {position: [1, 2, 3], rpy: [%.17g, %.17g, %.17g]}\n  q: {hinge: %.17g, slide: 0.2}\n"
                "  qdot: {hinge: %.17g, slide: 0.01}\n",
                10 * k, -20 * k, 30 * k, 30 * k, -5 * k);
  const Scenario r = loadScenario(degreesScenario("rad.yaml", rad));
  const State& a = d.capture.robot.state;
  const State& b = r.capture.robot.state;
  for (int i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(a.world_T_base.p(i), b.world_T_base.p(i));
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(a.world_T_base.M(i, j), b.world_T_base.M(i, j), 1e-15);
  }
  double roll = 0, pitch = 0, yaw = 0;
  a.world_T_base.M.GetRPY(roll, pitch, yaw);
  EXPECT_NEAR(roll, 3.14159265358979323846 / 18, 1e-15);  // 10 degrees, independently
  EXPECT_NEAR(pitch, -3.14159265358979323846 / 9, 1e-15);
  EXPECT_NEAR(yaw, 3.14159265358979323846 / 6, 1e-15);
  const FloatingModel& m = *d.capture.robot.model;
  EXPECT_NEAR(a.q(m.jointIndex("hinge")), 3.14159265358979323846 / 6, 1e-15);
  EXPECT_EQ(a.q(m.jointIndex("slide")), 0.2);
  EXPECT_NEAR(d.capture.robot.velocity.qdot(m.jointIndex("hinge")), -3.14159265358979323846 / 36, 1e-16);
  EXPECT_EQ(d.capture.robot.velocity.qdot(m.jointIndex("slide")), 0.01);
  EXPECT_EQ(a.q.data, b.q.data);
  EXPECT_DOUBLE_EQ(d.capture.robot.velocity.qdot(m.jointIndex("hinge")), r.capture.robot.velocity.qdot(m.jointIndex("hinge")));

  const auto refused = [](const std::string& name, const std::string& robot) {
    const std::string path = degreesScenario(name, robot);
    const std::string why = refusal(path);
    return why.substr(0, path.size()) == path ? why.substr(path.size()) : why;
  };
  EXPECT_EQ(refused("slide_deg.yaml", "  q: {slide: {deg: 3}}\n"),
            ":4: robot.q.slide: joint 'slide' is prismatic: its value is a length in m, not an angle");
  EXPECT_EQ(refused("slide_rate.yaml", "  qdot: {slide: {deg_per_s: 3}}\n"),
            ":4: robot.qdot.slide: joint 'slide' is prismatic: its rate is a speed in m/s, not an angle");
  EXPECT_NE(refused("rate_as_angle.yaml", "  q: {hinge: {deg_per_s: 3}}\n").find("robot.q.hinge"), std::string::npos);
  EXPECT_NE(refused("rate_as_angle.yaml", "  q: {hinge: {deg_per_s: 3}}\n").find("deg_per_s"), std::string::npos);
  EXPECT_NE(refused("rad_key.yaml", "  base: {rpy: {rad: [0, 0, 0]}}\n").find("robot.base.rpy"), std::string::npos);
  EXPECT_EQ(refused("two.yaml", "  base: {rpy: {deg: [1, 2]}}\n"),
            ":4: robot.base.rpy.deg: expected a list of 3 numbers, got a list of 2");
  EXPECT_EQ(refused("list.yaml", "  q: {hinge: [30]}\n"),
            ":4: robot.q.hinge: expected an angle [rad], or {deg: VALUE}, got a list of 1");
  EXPECT_EQ(refused("not_map.yaml", "  q: [1, 2]\n"), ":4: robot.q: expected a mapping NAME: VALUE, got a list of 2");
  EXPECT_EQ(refused("unknown.yaml", "  q: {elbow: {deg: 3}}\n"),
            ":4: robot.q.elbow: the model has no movable joint 'elbow' (its movable joints: hinge, slide)");
}

// --- The compliant law -------------------------------------------------------------------------

/// robot_to_robot_capture.yaml (a free-floating target) with `law` (YAML after "law:"), in a
/// scratch folder; `tumbling` takes the tumbling box (a rigid target) instead.
std::string withLaw(const std::string& name, const std::string& law, bool tumbling = false) {
  std::ifstream in(kShipped + (tumbling ? "tumbling_box_capture.yaml" : "robot_to_robot_capture.yaml"));
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  const std::size_t from = s.find("law:");
  std::size_t to = s.find("\n", from);
  while (to + 1 < s.size() && (s[to + 1] == ' ' || s[to + 1] == '#')) to = s.find("\n", to + 1);
  s.replace(from, to - from, "law: " + law);
  for (std::size_t at = s.find("../urdf/"); at != std::string::npos; at = s.find("../urdf/", at))
    s.replace(at, 8, std::string(KDL_SPACE_SOURCE_DIR) + "/urdf/");
  const fs::path dir = fs::path(::testing::TempDir()) / "kdl_space_compliant_law";
  fs::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << s;
  return path;
}

TEST(LoadScenario, CompliantLawDefaultsAndOverrides) {
  const Scenario d = loadScenario(withLaw("default.yaml", "{type: compliant}"));
  ASSERT_TRUE(d.compliant);
  EXPECT_EQ(d.capture.law.kind, ImpactKind::Capture);  // the impulsive limit beside it
  const CompliantGrasp defaults;
  EXPECT_EQ(d.compliant->stiffness, defaults.stiffness);
  EXPECT_FALSE(d.compliant->damping);
  EXPECT_EQ(d.compliant->damping_time, defaults.damping_time);
  EXPECT_FALSE(d.compliant->normal);
  const Scenario o = loadScenario(withLaw("override.yaml",
      "{type: compliant, stiffness: [1, 2, 3, 4, 5, 6], damping: [0, 1, 0, 1, 0, 1], catch_tolerance: 0.01, "
      "max_duration: 2, normal: [0, 0, 2]}"));
  ASSERT_TRUE(o.compliant);
  EXPECT_EQ(o.compliant->stiffness, (Vector6d() << 1, 2, 3, 4, 5, 6).finished());
  ASSERT_TRUE(o.compliant->damping);
  EXPECT_EQ(*o.compliant->damping, (Vector6d() << 0, 1, 0, 1, 0, 1).finished());
  EXPECT_EQ(o.compliant->catch_tolerance, 0.01);
  EXPECT_EQ(o.compliant->max_duration, 2.0);
  ASSERT_TRUE(o.compliant->normal);
  EXPECT_EQ(*o.compliant->normal, Vector3d(0, 0, 1));
  EXPECT_EQ(loadScenario(withLaw("beta.yaml", "{type: compliant, damping_time: 0.02}")).compliant->damping_time, 0.02);
  EXPECT_FALSE(loadScenario(kShipped + "robot_to_robot_capture.yaml").compliant);
}

TEST(LoadScenario, CompliantLawRefusals) {
  const auto tail = [](const std::string& message) { return message.substr(message.find(": law") + 2); };
  EXPECT_EQ(tail(refusal(withLaw("k.yaml", "{type: compliant, stiffness: [1, 1, 0, 1, 1, 1]}"))),
            "law.stiffness: each value must be > 0 (x, y, z [N/m or N s/m]; about x, y, z [N m/rad or N m s/rad]), got 0");
  EXPECT_EQ(tail(refusal(withLaw("d.yaml", "{type: compliant, damping: [1, 1, -1, 1, 1, 1]}"))),
            "law.damping: each value must be >= 0 (x, y, z [N/m or N s/m]; about x, y, z [N m/rad or N m s/rad]), got -1");
  EXPECT_EQ(tail(refusal(withLaw("both.yaml", "{type: compliant, damping: [1, 1, 1, 1, 1, 1], damping_time: 1}"))),
            "law.damping_time: give damping (per axis) or damping_time (D = damping_time * stiffness), not both");
  EXPECT_EQ(tail(refusal(withLaw("tol.yaml", "{type: compliant, catch_tolerance: 1}"))),
            "law.catch_tolerance: must be < 1, got 1");
  EXPECT_EQ(tail(refusal(withLaw("six.yaml", "{type: compliant, stiffness: [1, 1, 1]}"))),
            "law.stiffness: expected a list of 6 numbers, got a list of 3");
  EXPECT_EQ(tail(refusal(withLaw("key.yaml", "{type: compliant, restitution: 0.5}"))).substr(0, 29),
            "law.restitution: unknown fiel");
}

// A rigid target takes the compliant law too (one free body joined at the grasp).
TEST(LoadScenario, CompliantLawOnARigidTarget) {
  const Scenario s = loadScenario(withLaw("rigid.yaml", "{type: compliant, damping_time: 0.002}", true));
  ASSERT_TRUE(s.compliant);
  EXPECT_EQ(s.compliant->damping_time, 0.002);
  EXPECT_EQ(s.capture.law.kind, ImpactKind::Capture);  // the impulsive limit beside it
  ASSERT_TRUE(std::holds_alternative<RigidTarget>(s.capture.target));
  EXPECT_EQ(std::get<RigidTarget>(s.capture.target).mass, 50.0);
}


// --- A rigid target read from a URDF ---------------------------------------------------------

/// A copy of the tumbling-box scenario whose target is `target` (YAML lines), in a scratch folder.
std::string withTarget(const std::string& name, const std::string& target) {
  std::ifstream in(kShipped + "tumbling_box_capture.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  const std::size_t from = s.find("target:\n"), to = s.find("law:\n");
  s.replace(from, to - from, "target:\n" + target);
  const std::size_t urdf = s.find("../urdf/");
  s.replace(urdf, 8, std::string(KDL_SPACE_SOURCE_DIR) + "/urdf/");
  const fs::path dir = fs::path(::testing::TempDir()) / "kdl_space_rigid_urdf";
  fs::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << s;
  return path;
}

TEST(LoadScenario, ARigidTargetFromAUrdfIsTheSameBodyAsByNumbers) {
  // satellite_panel.urdf: a 100 kg hub (10, 12, 14 kg m^2) and a 5 kg panel (1, 0.1, 1.1) fixed
  // 1.5 m along y. By hand: CoM 1.5 * 5 / 105 along y; parallel axes about it on x and z:
  // 100 (1.5/21)^2 + 5 (1.5 * 20/21)^2 = 4725/441.
  const double shift = 4725.0 / 441.0;
  const std::string base = "  base: {position: [-0.6, -2.9, 1.7], rpy: [0.3, -0.2, 0.5], twist: [0.03, -0.02, 0.01, 0.05, 0.08, -0.06]}\n";
  const Scenario from_urdf = loadScenario(withTarget("satellite_urdf.yaml", "  urdf: " + dataDir() + "/rigid_target/satellite_panel.urdf\n" + base));
  ASSERT_TRUE(std::holds_alternative<RigidTarget>(from_urdf.capture.target));
  const RigidTarget& t = std::get<RigidTarget>(from_urdf.capture.target);
  EXPECT_NEAR(t.mass, 105.0, 1e-12);
  EXPECT_TRUE(near(t.com, Vector3d(0, 7.5 / 105.0, 0), 1e-12, 1e-14, "CoM in the hub's frame"));
  EXPECT_TRUE(near(t.inertia, Vector3d(11.0 + shift, 12.1, 15.1 + shift).asDiagonal().toDenseMatrix(), 1e-12, 1e-12, "inertia"));
  // the same body by numbers: the twist of the base origin moved to the CoM by hand
  const KDL::Frame pose(KDL::Rotation::RPY(0.3, -0.2, 0.5), KDL::Vector(-0.6, -2.9, 1.7));
  const Vector3d c = toEigen(pose * KDL::Vector(0, 7.5 / 105.0, 0));
  const Vector3d w(0.05, 0.08, -0.06), v_o(0.03, -0.02, 0.01);
  const Vector3d v_c = v_o + w.cross(c - Vector3d(-0.6, -2.9, 1.7));
  std::ostringstream numbers;
  numbers.precision(17);
  numbers << "  mass: 105\n  inertia: [[" << 11.0 + shift << ", 0, 0], [0, 12.1, 0], [0, 0, " << 15.1 + shift << "]]\n"
          << "  pose: {position: [-0.6, -2.9, 1.7], rpy: [0.3, -0.2, 0.5]}\n  com: [0, " << 7.5 / 105.0 << ", 0]\n"
          << "  twist: [" << v_c.x() << ", " << v_c.y() << ", " << v_c.z() << ", 0.05, 0.08, -0.06]\n";
  const Scenario by_numbers = loadScenario(withTarget("satellite_numbers.yaml", numbers.str()));
  const CaptureResult a = solveCapture(from_urdf.capture), b = solveCapture(by_numbers.capture);
  EXPECT_TRUE(near(a.impulse.F, b.impulse.F, 1e-10, 1e-14, "impulse"));
  // (1e-10: the inertia summed in another order, through the capture's conditioning)
  EXPECT_TRUE(near(a.robot.after.qdot.data, b.robot.after.qdot.data, 1e-10, 1e-14, "joint rates after"));
  EXPECT_TRUE(near(a.target_twist_after, b.target_twist_after, 1e-10, 1e-14, "target after"));
  EXPECT_NEAR(a.energyLost(), b.energyLost(), 1e-12 * a.energy_before);
}

TEST(LoadScenario, ALinkSubtreeOfAUrdfIsOneRigidBodyAtItsJointAngles) {
  // boom.urdf: the boom (2 kg, CoM 0.5 m out, 0.01/0.2/0.2) and a 1 kg gripper fixed 1 m out.
  // By hand, in the boom's frame: CoM 2/3 m out; I_yy = I_zz = 0.2 + 0.01 + 2 (1/6)^2 + 1 (1/3)^2.
  const Scenario s = loadScenario(withTarget(
      "boom.yaml", "  urdf: " + dataDir() + "/rigid_target/boom.urdf\n  link: boom\n  q: {boom_joint: 0.3}\n"
                   "  base: {position: [-0.6, -2.9, 1.7]}\n"));
  const RigidTarget& t = std::get<RigidTarget>(s.capture.target);
  EXPECT_NEAR(t.mass, 3.0, 1e-12);
  EXPECT_TRUE(near(t.com, Vector3d(2.0 / 3.0, 0, 0), 1e-12, 1e-14, "CoM"));
  const double I = 0.21 + 2.0 / 36.0 + 1.0 / 9.0;
  EXPECT_TRUE(near(t.inertia, Vector3d(0.02, I, I).asDiagonal().toDenseMatrix(), 1e-12, 1e-14, "inertia"));
  EXPECT_TRUE(near(toEigen(t.pose.M), toEigen(KDL::Rotation::RotZ(0.3)), 1e-14, 1e-14, "the boom's frame"));
  EXPECT_TRUE(near(toEigen(t.pose.p), Vector3d(-0.6, -2.9, 2.2), 1e-14, 1e-14, "at the joint"));
  // The file's system is kept for the pictures: its state where target.q and target.base put it,
  // the target's body the boom's.
  ASSERT_TRUE(s.rigid_target_system);
  EXPECT_EQ(s.rigid_target_body, s.rigid_target_system->model->bodyIndex("boom"));
  EXPECT_EQ(s.rigid_target_system->state.q(0), 0.3);
  EXPECT_EQ(s.rigid_target_system->state.world_T_base.p, KDL::Vector(-0.6, -2.9, 1.7));
  // the links from a fixed one down: the gripper alone
  const Scenario gripper = loadScenario(withTarget(
      "gripper.yaml", "  urdf: " + dataDir() + "/rigid_target/boom.urdf\n  link: gripper\n  q: {boom_joint: 0.3}\n"));
  EXPECT_NEAR(std::get<RigidTarget>(gripper.capture.target).mass, 1.0, 1e-12);
  EXPECT_EQ(gripper.rigid_target_body, gripper.rigid_target_system->model->bodyIndex("gripper"));
  // a rigid URDF target has no contact of its own; a link that is not in the file is named
  try {
    loadScenario(withTarget("contact.yaml", "  urdf: " + dataDir() + "/rigid_target/satellite_panel.urdf\n  contact: {link: hub}\n"));
    ADD_FAILURE() << "a contact on a rigid URDF target accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("target.contact: the target is read as one rigid body (its file has no movable joint)"),
              std::string::npos)
        << e.what();
  }
  try {
    loadScenario(withTarget("nolink.yaml", "  urdf: " + dataDir() + "/rigid_target/boom.urdf\n  link: antenna\n"));
    ADD_FAILURE() << "an unknown link accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("target.link: the model has no link 'antenna' (its links: hub, boom, gripper)"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace kdl_space::test

namespace kdl_space::test {
namespace {
// `simulation.base: grounded` means grounded in the capture too: the robot's response is the grounded
// one (its G, not G*), and a base twist, which a held base cannot have, is refused naming the field.
TEST(LoadScenario, AGroundedSimulationGroundsTheCaptureToo) {
  const std::string target = "target: {mass: 20, inertia: [[1, 0, 0], [0, 1, 0], [0, 0, 1]], pose: {position: [1.5, 0, 0]}, "
                             "twist: [-0.1, 0, 0, 0, 0, 0]}\nlaw: {type: capture}\n";
  const auto write = [&](const std::string& name, const std::string& robot_extra) {
    const std::string path = degreesScenario(name, "  contact: {link: tip}\n" + robot_extra);
    std::string text;
    {
      std::ifstream in(path);
      text.assign(std::istreambuf_iterator<char>(in), {});
    }
    text.replace(text.find("simulation: {duration: 1}"), 25, "simulation: {duration: 1, base: grounded}");
    std::ofstream(path) << text << target;
    return path;
  };
  const Scenario sc = loadScenario(write("grounded.yaml", ""));
  EXPECT_EQ(sc.capture.robot.response, Response::Grounded);
  try {
    loadScenario(write("grounded_moving.yaml", "  base: {twist: [0, 0, 0, 0, 0, 0.1]}\n"));
    ADD_FAILURE() << "a grounded base with a twist loaded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("simulation.base: grounded holds the base still, in the capture too"), std::string::npos)
        << e.what();
  }
}
}  // namespace
}  // namespace kdl_space::test
