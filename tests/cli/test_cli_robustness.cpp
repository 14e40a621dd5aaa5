// Every entry point of the tool against malformed input: the corpus of broken scenarios in
// tests/data/broken_scenarios (one problem per file), bad command lines, hostile files, and
// output files that are never left half-written. Each case asserts the exit code (0 ok,
// 2 usage, 3 unusable input) and the exact message on stderr, which names the file, the field
// and what is wrong.
#include <gtest/gtest.h>

#include <fcntl.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <regex>
#include <set>

#include "cli_runner.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

namespace fs = std::filesystem;

const std::string kCorpus = dataDir() + "/broken_scenarios";
const std::string kValid = kCorpus + "/valid.yaml";
const std::string kTwolink = urdfDir() + "/spacedyn_twolink.urdf";
const std::string kHint = "(run 'kdl_space --help' or 'kdl_space <command> --help')\n";

/// `text` with every "{key}" replaced.
std::string fill(std::string text, const std::vector<std::pair<std::string, std::string>>& values) {
  for (const auto& [key, value] : values)
    for (std::size_t at; (at = text.find("{" + key + "}")) != std::string::npos;) text.replace(at, key.size() + 2, value);
  return text;
}

/// The message matches `expected`, where each "{t}" stands for a number (a simulation time, or a
/// value that depends on the floating-point path of the integration, not on the input) and each
/// "{j}" for a name that does (which joint leads a motion that blew up).
::testing::AssertionResult matches(const std::string& actual, const std::string& expected) {
  std::string pattern;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    if (expected.compare(i, 3, "{t}") == 0) {
      pattern += "[-+]?[0-9][0-9.]*(e[-+][0-9]+)?";
      i += 2;
    } else if (expected.compare(i, 3, "{j}") == 0) {
      pattern += "[A-Za-z_][A-Za-z0-9_]*";
      i += 2;
    } else {
      if (std::string("\\^$.|?*+()[]{}").find(expected[i]) != std::string::npos) pattern += '\\';
      pattern += expected[i];
    }
  }
  if (std::regex_match(actual, std::regex(pattern))) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "message\n  " << actual << "expected (with {t} a number)\n  " << expected;
}

/// No crash, no stack trace, no abort: what a failure must never look like.
void expectCleanFailure(const ToolRun& r, const std::string& what) {
  EXPECT_TRUE(r.rc == 2 || r.rc == 3) << what << ": exit " << r.rc;
  for (const char* s : {"terminate", "what():", "Aborted", "Segmentation", "core dumped", "Assertion", "#0 "})
    EXPECT_EQ(r.err.find(s), std::string::npos) << what << ": " << r.err;
  EXPECT_EQ(r.out, "") << what << ": nothing on stdout when it fails";
}

// --- The corpus ----------------------------------------------------------------------------------

struct Broken {
  std::string file;      ///< in tests/data/broken_scenarios
  std::string message;   ///< stderr; {f}: the scenario's path, {models}: tests/data/reference/models
  bool simulation_only;  ///< `capture` accepts it (only `simulate` fails)
};

inline void PrintTo(const Broken& b, std::ostream* os) { *os << b.file; }

/// Every file of the corpus and what it must produce (exit 3 for all).
const std::vector<Broken>& corpus() {
  static const std::vector<Broken> cases = {
      // Not a scenario at all.
      {"not_yaml.yaml", "{f}:3: not valid YAML or JSON: end of sequence flow not found", false},
      {"empty.yaml", "{f}: the file is empty; expected a scenario file (YAML or JSON)", false},
      {"comments_only.yaml", "{f}: holds no data; a scenario is a mapping with robot, target and law (or robot and simulation)", false},
      {"top_level_list.yaml", "{f}:2: a scenario is a mapping with robot, target and law (or robot and simulation), not a list of 3", false},
      // Fields: missing, unknown, twice, without a value, of the wrong type.
      {"missing_robot.yaml", "{f}:2: robot: missing (a required field)", false},
      {"missing_target_mass.yaml", "{f}:10: target.mass: missing (a required field)", false},
      {"missing_law_type.yaml", "{f}:15: law.type: missing (a required field)", false},
      {"unknown_top_field.yaml", "{f}:21: colour: unknown field (expected one of robot, target, law, approach, simulation)", false},
      {"unknown_target_field.yaml",
       "{f}:13: target.colour: unknown field (expected one of mass, inertia, pose, com, twist)", false},
      {"duplicate_field.yaml", "{f}:11: target.mass: given twice", false},
      {"mass_no_value.yaml", "{f}:10: target.mass: has no value", false},
      {"mass_not_number.yaml", "{f}:10: target.mass: 'heavy' is not a number", false},
      {"mass_is_list.yaml", "{f}:10: target.mass: expected a number, got a list of 1", false},
      {"wrong_length_vector.yaml", "{f}:5: robot.base.position: expected a list of 3 numbers, got a list of 2", false},
      {"wrong_length_twist.yaml", "{f}:5: robot.base.twist: expected a list of 6 numbers, got a list of 5", false},
      {"inertia_wrong_shape.yaml", "{f}:11: target.inertia: expected 3 rows of 3 numbers, got a list of 2", false},
      // Numbers that are not finite.
      {"nan_value.yaml", "{f}:14: target.twist[0]: '.nan' is not a finite number", false},
      {"infinite_value.yaml", "{f}:12: target.pose.position[0]: '.inf' is not a finite number", false},
      {"huge_number.yaml", "{f}:10: target.mass: '1e400' is too large (not a finite number)", false},
      // The target's physics.
      {"negative_mass.yaml", "{f}:10: target.mass: must be > 0 kg, got -3", false},
      {"zero_mass.yaml", "{f}:10: target.mass: must be > 0 kg, got 0", false},
      {"inertia_not_positive_definite.yaml",
       "{f}:11: target.inertia: must be positive definite (principal moments -1, 1, 1 kg m^2)", false},
      {"inertia_not_symmetric.yaml",
       "{f}:11: target.inertia: must be symmetric, but row 2 column 1 is 0 and row 1 column 2 is 0.2", false},
      {"inertia_triangle_inequality.yaml",
       "{f}:11: target.inertia: is no rigid body's inertia: its principal moments break the triangle inequality "
       "I1 + I2 >= I3 (principal moments 1, 1, 3 kg m^2)",
       false},
      // The approach and the placing of the target.
      {"approach_zero_gain.yaml", "{f}:18: approach.gain: must be > 0, got 0", false},
      {"approach_negative_tolerance.yaml", "{f}:18: approach.tolerance.position: must be > 0, got -0.01", false},
      {"approach_missing_grasp.yaml", "{f}:17: approach.grasp: missing (a required field)", false},
      {"approach_unknown_field.yaml",
       "{f}:18: approach.speed: unknown field (expected one of grasp, track, gain, damping, singular_threshold, "
       "rate_limits, servo_bandwidth, null_space, tolerance, max_duration, pre_grasp, joint_limits)",
       false},
      {"target_joints_rigid.yaml",
       "{f}:21: simulation.target_joints: only a free-floating target (target.urdf with movable joints) has joints", false},
      {"grasp_without_place.yaml",
       "{f}:9: robot.grasp: is the grasp frame that robot.place: grasp solves the arm for: add robot.place: grasp", false},
      {"place_touch_rigid.yaml",
       "{f}:10: target.place: a rigid target has no contact point of its own (the point hit is the robot's contact "
       "point): place it with pose",
       false},
      {"target_not_touching.yaml",
       "{f}: target.contact: the target's contact point is 2 m from the robot's; they must touch (within 1 mm)", false},
      // The robot: its URDF, links, joints, mode, state.
      {"missing_urdf_file.yaml", "{f}:3: robot.urdf: {models}/no_such_robot.urdf: no such file", false},
      {"target_urdf_missing.yaml", "{f}:10: target.urdf: {models}/no_such_target.urdf: no such file", false},
      {"urdf_is_folder.yaml", "{f}:3: robot.urdf: {models}: is a folder, not a URDF file", false},
      {"unknown_contact_link.yaml",
       "{f}:4: robot.contact.link: the model has no link 'gripper' (its links: base, link1, link2, hand)", false},
      {"unknown_joint.yaml",
       "{f}:6: robot.q.elbow: the model has no movable joint 'elbow' (its movable joints: joint1, joint2)", false},
      {"bad_mode.yaml", "{f}:8: robot.mode: 'floating' is not one of free, grounded, locked", false},
      {"locked_unknown_joint.yaml",
       "{f}:9: robot.locked[0]: the model has no movable joint 'elbow' (its movable joints: joint1, joint2)", false},
      {"locked_twice.yaml", "{f}:9: robot.locked[1]: joint 'joint1' is listed twice", false},
      {"locked_not_a_list.yaml", "{f}:9: robot.locked: expected a list of joint names, got 'joint1'", false},
      {"locked_joint_moves.yaml",
       "{f}:9: robot.locked[1]: joint 'joint2' is braked, so its rate robot.qdot.joint2 must be 0, got 0.1", false},
      {"base_far_away.yaml",
       "{f}: robot: the free-floating quantities cannot be computed at this state (robot.base, robot.q): an input "
       "holds NaN or infinite values, or a result overflowed",
       false},
      // The impact law.
      {"bad_law_type.yaml", "{f}:15: law.type: 'bounce' is not one of capture, point, friction, translational, compliant", false},
      {"point_without_normal.yaml", "{f}:15: law.normal: missing (a required field)", false},
      {"zero_normal.yaml", "{f}:15: law.normal: has zero length", false},
      {"restitution_out_of_range.yaml", "{f}:15: law.restitution: must lie in [0, 1], got 1.5", false},
      {"negative_friction.yaml", "{f}:15: law.friction: must be >= 0, got -0.2", false},
      // The simulation section (read by capture too: a scenario is checked whole).
      {"zero_duration.yaml", "{f}:17: simulation.duration: must be > 0, got 0", false},
      {"negative_step.yaml", "{f}:20: simulation.step: must be > 0, got -0.01", false},
      {"zero_output_step.yaml", "{f}:18: simulation.output_step: must be > 0, got 0", false},
      {"bad_integrator.yaml", "{f}:19: simulation.integrator: 'euler' is not one of rk4, dopri5, rosenbrock", false},
      {"unknown_simulation_joint.yaml",
       "{f}:21: simulation.joints.elbow: the robot has no movable joint 'elbow' (its movable joints: joint1, joint2)",
       false},
      {"negative_gain.yaml", "{f}:21: simulation.joints.joint1.pd.kp: must be >= 0, got -10", false},
      {"missing_gain.yaml", "{f}:21: simulation.joints.joint1.pd.kd: missing (a required field)", false},
      {"fractional_max_steps.yaml",
       "{f}:21: simulation.max_steps: must be a whole number of steps from 1 to 1e12, got 2.5", false},
      {"pattern_matches_no_joint.yaml",
       "{f}:21: simulation.joints.wrist_*: the pattern matches no movable joint (its movable joints: joint1, joint2)",
       false},
      {"negative_pattern_gain.yaml", "{f}:21: simulation.joints.*.pd.kp: must be >= 0, got -5", false},
      {"bad_base.yaml", "{f}:21: simulation.base: 'fixed' is not one of free, grounded", false},
      {"bad_limits_mode.yaml", "{f}:21: simulation.limits: 'soft' is not one of warn, stop, ignore", false},
      {"stop_on_continuous_joint.yaml",
       "{f}:21: simulation.limits.joint2: joint 'joint2' has no position limits (a continuous joint): it has no stop",
       false},
      {"negative_base_gain.yaml", "{f}:21: simulation.base_control.attitude.kp: must be >= 0, got -1", false},
      {"negative_torque_limit.yaml", "{f}:21: simulation.base_control.attitude.torque_limit: must be > 0 on every axis",
       false},
      {"base_set_point_not_rotation.yaml",
       "{f}:21: simulation.base_control.attitude.set_point.quaternion: is not a rotation: a unit quaternion has norm 1, "
       "this one 2",
       false},
      // The base's actuators (robot.base_actuators) and the control they must carry.
      {"wheels_zero_axis.yaml", "{f}:9: robot.base_actuators.wheels.axes[1]: is zero: a wheel's spin axis has a direction",
       false},
      {"wheels_missing_capacity.yaml", "{f}:10: robot.base_actuators.wheels.capacity: missing (a required field)", false},
      {"wheels_momentum_past_capacity.yaml",
       "{f}:10: robot.base_actuators.wheels.momentum: wheel 2 starts at 2.5 N m s, past its capacity 2 N m s", false},
      {"wheels_negative_torque_limit.yaml",
       "{f}:10: robot.base_actuators.wheels.torque_limit: must be > 0 for every wheel, got -0.1 for wheel 2", false},
      {"base_position_without_thrusters.yaml",
       "{f}:24: simulation.base_control.position: robot.base_actuators has no thrusters' force_limit to move the base "
       "with",
       false},
      {"grasp_limit_on_a_point_impact.yaml",
       "{f}:15: law.max_grasp_wrench: a point impact holds nothing after it: the grasp's limit goes with a capture or "
       "compliant law",
       false},
      {"grasp_limit_not_positive.yaml", "{f}:17: law.max_grasp_wrench.moment: must be > 0, got -5", false},
      {"after_capture_unknown_law.yaml",
       "{f}:21: simulation.after_capture.law: 'detumble' is not one of hold, momentum_distribution, impedance", false},
      {"impedance_without_damping.yaml",
       "{f}:21: simulation.after_capture.damping: the arm is a damper at the grasp: give it some damping", false},
      {"impedance_gain_on_hold.yaml", "{f}:20: simulation.after_capture.stiffness: is impedance's: the law is hold", false},
      {"distribution_without_servos.yaml",
       "{f}:23: simulation.after_capture.law: momentum_distribution drives the arm's servos: give the robot's joints "
       "pd servos in simulation.joints (the law drives their rates, at after_capture.bandwidth)",
       false},
      {"distribution_without_attitude_control.yaml",
       "{f}:23: simulation.after_capture.law: momentum_distribution unloads the arm through the base's attitude "
       "control: give simulation.base_control.attitude (acting after the capture), with robot.base_actuators.wheels",
       false},
      {"wrench_ends_before_start.yaml", "{f}:21: simulation.wrenches[0].end: must be after start (2 s), got 1", false},
      {"wrench_unknown_link.yaml",
       "{f}:21: simulation.wrenches[0].link: the robot has no link 'gripper' (its links: base, link1, link2, hand)",
       false},
      {"plain_motion_without_simulation.yaml",
       "{f}:2: a scenario without target and law is a plain motion: it needs a simulation section", false},
      {"target_without_law.yaml", "{f}:2: law: missing (a required field)", false},
      {"impact_without_contact.yaml", "{f}:3: robot.contact: missing (a required field)", false},
      // A grounded simulation grounds the capture too: a base twist is refused at load (capture and simulate).
      {"grounded_base_moving.yaml",
       "{f}:21: simulation.base: grounded holds the base still, in the capture too, but robot.base.twist is not zero: "
       "give it zero, or simulation.base: free",
       false},
      // Scenarios that capture solves and simulate cannot run.
      {"stop_outside_limits.yaml",
       "{f}: simulation.limits: joint 'joint1' starts at 3.5, outside its limits [-3.14159, 3.14159] (a hard stop "
       "keeps it inside them): start it inside, or let its limits warn",
       true},
      {"step_budget_too_small.yaml",
       "{f}: simulation: 1 s in steps of at most 0.01 s (simulation.step) needs 100 steps, more than "
       "simulation.max_steps = 50",
       true},
      {"max_steps_spent.yaml",
       "{f}: simulation failed at t = {t} s of 1 s: the step budget simulation.max_steps = 400 is spent (an unstable "
       "controller? raise max_steps, or loosen rtol and atol); stiff: the servo of joint 'joint1' (closed-loop rate "
       "{t} 1/s) holds dopri5's step near {t} s ({t} steps): try integrator: rosenbrock (an rtol of 1e-6 or looser "
       "suits it)",
       true},
      // Which joint is fastest when the motion is at 1e57 follows the last bits of every stage
      // (joint2 before the base twist's packed Cholesky of issue 38, joint1 since with GCC -O2,
      // joint2 with clang -O1 under the sanitizers).
      {"blows_up.yaml",
       "{f}: simulation failed at t = {t} s of 1 s: the motion blew up to NaN or infinite values (unstable PD gains, "
       "or too large an rk4 step?): by t = {t} s joint '{j}' moved at {t} rad/s (or m/s), the base at {t} rad/s; "
       "the servo of joint 'joint1' (closed-loop rate {t} 1/s) needs explicit steps below {t} s: lower "
       "simulation.step or the gains, or use integrator: rosenbrock",
       true},
  };
  return cases;
}

class BrokenScenario : public ::testing::TestWithParam<Broken> {};

TEST_P(BrokenScenario, ExitsWith3AndSaysWhatIsWrong) {
  const Broken& c = GetParam();
  const std::string file = kCorpus + "/" + c.file;
  const std::string expected =
      "kdl_space: " + fill(c.message, {{"f", file}, {"models", dataDir() + "/reference/models"}}) + "\n";
  for (const std::string command : {"capture", "simulate"}) {
    SCOPED_TRACE(command);
    const ToolRun r = kdlSpace(command + " " + file);
    if (c.simulation_only && command == "capture") {
      EXPECT_EQ(r.rc, 0) << r.err;
      continue;
    }
    EXPECT_EQ(r.rc, 3);
    EXPECT_TRUE(matches(r.err, expected));
    expectCleanFailure(r, c.file);
  }
}

INSTANTIATE_TEST_SUITE_P(Corpus, BrokenScenario, ::testing::ValuesIn(corpus()),
                         [](const ::testing::TestParamInfo<Broken>& info) {
                           return info.param.file.substr(0, info.param.file.find('.'));
                         });

TEST(BrokenScenarioCorpus, EveryFileIsCoveredAndTheReferenceIsValid) {
  std::set<std::string> listed{"valid.yaml", "broken_urdf.yaml"};  // the second: test below
  for (const Broken& b : corpus()) listed.insert(b.file);
  for (const auto& entry : fs::directory_iterator(kCorpus)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() == ".yaml") EXPECT_TRUE(listed.count(name)) << name << " has no expected message here";
  }
  // The file every other one breaks in one place runs.
  for (const std::string command : {"capture", "simulate"}) {
    const ToolRun r = kdlSpace(command + " " + kValid);
    EXPECT_EQ(r.rc, 0) << command << ": " << r.err;
    EXPECT_EQ(r.err, "") << command;
  }
}

TEST(BrokenScenarioCorpus, ABrokenRobotUrdfIsReportedAtItsField) {
  // The URDF's own message comes from the loader (urdf_loader.cpp); the scenario names the field
  // and the file before it.
  const std::string file = kCorpus + "/broken_urdf.yaml";
  for (const std::string command : {"capture", "simulate"}) {
    const ToolRun r = kdlSpace(command + " " + file);
    EXPECT_EQ(r.rc, 3) << command;
    const std::string prefix = "kdl_space: " + file + ":3: robot.urdf: " + kCorpus + "/not_a_robot.urdf: ";
    EXPECT_EQ(r.err.rfind(prefix, 0), 0u) << r.err;
    EXPECT_GT(r.err.size(), prefix.size() + 1) << "says what is wrong with the URDF: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    expectCleanFailure(r, command);
  }
}

// --- Hostile files -------------------------------------------------------------------------------

class HostileFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::path(::testing::TempDir()) / ("kdl_space_hostile_" + std::to_string(getpid()));
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  std::string write(const std::string& name, const std::string& bytes) const {
    const std::string path = (dir / name).string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }
  fs::path dir;
};

TEST_F(HostileFiles, ScenarioFilesThatAreNoScenario) {
  std::string all_bytes;
  for (int repeat = 0; repeat < 4; ++repeat)
    for (int b = 0; b < 256; ++b) all_bytes += static_cast<char>(b);
  const std::string bytes = write("bytes.yaml", all_bytes);
  const std::string folder = (dir / "folder.yaml").string();
  fs::create_directories(folder);
  const struct {
    std::string args, err;
  } cases[] = {
      {"capture " + bytes, "kdl_space: " + bytes +
                               ":1: a scenario is a mapping with robot, target and law (or robot and simulation), not "
                               "'" + std::string(40, '?') + "..." + std::string(36, '?') + "' (1508 characters)\n"},
      {"simulate " + folder, "kdl_space: " + folder + ": is a folder, not a scenario file (YAML or JSON)\n"},
      {"capture /nonexistent/scenario.yaml", "kdl_space: /nonexistent/scenario.yaml: no such file\n"},
      // An endless device: refused, not read until memory runs out.
      {"capture /dev/zero", "kdl_space: /dev/zero: is not a regular file; expected a scenario file (YAML or JSON)\n"},
  };
  for (const auto& c : cases) {
    const ToolRun r = kdlSpace(c.args);
    EXPECT_EQ(r.rc, 3) << c.args;
    EXPECT_EQ(r.err, c.err) << c.args;
    expectCleanFailure(r, c.args);
  }
  // Random bytes: whatever the parser makes of them, one short printable line naming the file.
  std::mt19937 rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    std::string noise;
    for (int i = 0; i < 3000; ++i) noise += static_cast<char>(rng() & 0xff);
    const std::string file = write("noise" + std::to_string(trial) + ".yaml", noise);
    for (const std::string command : {"capture ", "simulate "}) {
      const ToolRun r = kdlSpace(command + file);
      EXPECT_EQ(r.rc, 3) << file;
      EXPECT_EQ(r.err.rfind("kdl_space: " + file, 0), 0u) << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
      EXPECT_LT(r.err.size(), 400u) << r.err;
      for (const char ch : r.err) EXPECT_TRUE(ch == '\n' || (ch >= 0x20 && ch < 0x7f)) << "unprintable: " << r.err;
      expectCleanFailure(r, file);
    }
  }
}

TEST_F(HostileFiles, UrdfFilesThatAreNoUrdf) {
  const std::string empty = write("empty.urdf", "");
  const std::string folder = (dir / "folder.urdf").string();
  fs::create_directories(folder);
  const struct {
    std::string urdf, err;
  } cases[] = {
      {empty, "kdl_space: " + empty + ": the file is empty; expected a URDF file\n"},
      {folder, "kdl_space: " + folder + ": is a folder, not a URDF file\n"},
      {"/nonexistent/robot.urdf", "kdl_space: /nonexistent/robot.urdf: no such file\n"},
      {"/dev/urandom", "kdl_space: /dev/urandom: is not a regular file; expected a URDF file\n"},
  };
  for (const auto& c : cases) {
    const ToolRun r = kdlSpace("inspect --urdf " + c.urdf + " --tip hand");
    EXPECT_EQ(r.rc, 3) << c.urdf;
    EXPECT_EQ(r.err, c.err);
    expectCleanFailure(r, c.urdf);
  }
  // Binary garbage: the loader's message (urdf_loader.cpp), after the file name.
  const std::string garbage = write("garbage.urdf", std::string("\x00\xff\x01<robot\x7f", 9) + std::string(500, '\xfe'));
  const ToolRun r = kdlSpace("inspect --urdf " + garbage + " --tip hand");
  EXPECT_EQ(r.rc, 3);
  EXPECT_EQ(r.err.rfind("kdl_space: " + garbage + ": ", 0), 0u) << r.err;
  expectCleanFailure(r, garbage);
}

// TinyXML descends once per nesting level and overflowed the stack at 200,000 levels: every
// command that reads a URDF must refuse such a file with the loader's message.
TEST_F(HostileFiles, AFieldOfMegabytesIsNotEchoedWhole) {
  // A URDF path of a million characters: the message shows its start and its end, not all of it.
  std::ifstream valid(kValid);
  std::stringstream text;
  text << valid.rdbuf();
  std::string yaml = text.str();
  const std::string huge(1000000, 'y');
  yaml.replace(yaml.find("../reference/models/spacedyn_twolink.urdf"), std::string("../reference/models/spacedyn_twolink.urdf").size(), huge);
  const std::string scenario = write("huge_field.yaml", yaml);
  const ToolRun r = kdlSpace("capture " + scenario);
  EXPECT_EQ(r.rc, 3) << r.err.substr(0, 300);
  EXPECT_LT(r.err.size(), 400u) << r.err.substr(0, 300);
  EXPECT_NE(r.err.find("robot.urdf: "), std::string::npos) << r.err.substr(0, 300);
  EXPECT_NE(r.err.find("yyyy...yyyy"), std::string::npos) << r.err.substr(0, 300);
  EXPECT_NE(r.err.find(": no such file"), std::string::npos) << r.err.substr(0, 300);
}

TEST_F(HostileFiles, DeeplyNestedUrdfIsRefusedByEveryCommand) {
  std::string xml = "<robot name=\"deep\">";
  for (int i = 0; i < 200000; ++i) xml += "<a>";
  const std::string urdf = write("nested.urdf", xml + "</robot>");
  const std::string why = ": not XML that can be read safely: elements nested more than 2000 deep (a URDF nests 4 or 5)\n";
  const ToolRun inspect = kdlSpace("inspect --urdf " + urdf + " --tip hand");
  EXPECT_EQ(inspect.rc, 3);
  EXPECT_EQ(inspect.err, "kdl_space: " + urdf + ": error" + why);  // in check's words
  expectCleanFailure(inspect, "inspect");
  std::ifstream in(kCorpus + "/broken_urdf.yaml");
  std::string scenario((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  scenario.replace(scenario.find("not_a_robot.urdf"), std::string("not_a_robot.urdf").size(), "nested.urdf");
  const std::string file = write("nested.yaml", scenario);
  for (const std::string command : {"capture", "simulate"}) {
    const ToolRun r = kdlSpace(command + " " + file);
    EXPECT_EQ(r.rc, 3) << command;
    EXPECT_EQ(r.err, "kdl_space: " + file + ":3: robot.urdf: " + urdf + why) << command;
    expectCleanFailure(r, command);
  }
}

// --- Command lines -------------------------------------------------------------------------------

struct CommandLine {
  std::string args;
  int rc;
  std::string err;
};

void expectAll(const std::vector<CommandLine>& cases) {
  for (const CommandLine& c : cases) {
    const ToolRun r = kdlSpace(c.args);
    EXPECT_EQ(r.rc, c.rc) << c.args << "\n" << r.err;
    EXPECT_EQ(r.err, c.err) << c.args;
    expectCleanFailure(r, c.args);
  }
}

TEST(CommandLines, UsageErrorsExitWith2) {
  expectAll({
      {"", 2, "kdl_space: A subcommand is required\n" + kHint},
      {"frobnicate", 2, "kdl_space: unknown command 'frobnicate' (commands: inspect, capture, simulate, check, study, ik, plan, mount, export, import)\n" + kHint},
      {"capture", 2, "kdl_space: SCENARIO is required\n" + kHint},
      {"capture " + kValid + " " + kValid, 2, "kdl_space: The following argument was not expected: " + kValid + "\n" + kHint},
      {"capture " + kValid + " --bogus", 2, "kdl_space: The following argument was not expected: --bogus\n" + kHint},
      {"simulate " + kValid + " --duration abc", 2, "kdl_space: --duration: 'abc' is not a number\n" + kHint},
      {"simulate " + kValid + " --duration 0", 2, "kdl_space: --duration: '0' is not > 0\n" + kHint},
      {"simulate " + kValid + " --duration -1", 2, "kdl_space: --duration: '-1' is not > 0\n" + kHint},
      {"simulate " + kValid + " --duration nan", 2, "kdl_space: --duration: 'nan' is not a finite number\n" + kHint},
      {"simulate " + kValid + " --duration inf", 2, "kdl_space: --duration: 'inf' is not a finite number\n" + kHint},
      {"simulate " + kValid + " --duration 1e400", 2,
       "kdl_space: --duration: '1e400' is too large (not a finite number)\n" + kHint},
      {"simulate " + kValid + " --csv", 2, "kdl_space: --csv: 1 required FILE missing\n" + kHint},
      {"simulate " + kValid + " --csv ''", 2, "kdl_space: --csv: the file name is empty\n" + kHint},
      {"simulate " + kValid + " --plot run.gif", 2, "kdl_space: --plot run.gif: the file name must end in .svg or .png\n"},
      {"simulate " + kValid + " --csv " + kValid, 2,
       "kdl_space: --csv " + kValid + ": is the scenario file; it would be overwritten: give the output another name\n"},
      {"inspect --urdf " + kTwolink, 2, "kdl_space: --tip is required\n" + kHint},
      {"inspect --tip hand", 2, "kdl_space: --urdf is required\n" + kHint},
      {"inspect --urdf " + kTwolink + " --tip hand --offset a b c", 2, "kdl_space: --offset: 'a' is not a number\n" + kHint},
      {"inspect --urdf " + kTwolink + " --tip hand --offset 1 2", 2, "kdl_space: --offset: 3 required FLOAT missing\n" + kHint},
      {"inspect --urdf " + kTwolink + " --tip hand --base-pos 1 2 nan", 2,
       "kdl_space: --base-pos: 'nan' is not a finite number\n" + kHint},
      {"inspect --urdf " + kTwolink + " --tip hand --base-rpy 0 0 1e999", 2,
       "kdl_space: --base-rpy: '1e999' is too large (not a finite number)\n" + kHint},
      {"inspect --urdf " + kTwolink + " --tip hand --q joint1=abc", 2, "kdl_space: --q joint1: 'abc' is not a number\n"},
      {"inspect --urdf " + kTwolink + " --tip hand --q joint1=1 --q joint1=2", 2, "kdl_space: --q joint1 given twice\n"},
  });
}

TEST(CommandLines, UnusableInputsExitWith3) {
  expectAll({
      {"inspect --urdf " + kTwolink + " --tip hand >/dev/full", 3, "kdl_space: cannot write the output to stdout\n"},
      {"inspect --urdf " + kTwolink + " --tip gripper", 3,
       "kdl_space: --tip gripper: " + kTwolink + " has no link 'gripper' (its links: base, link1, link2, hand)\n"},
      {"inspect --urdf " + kTwolink + " --tip hand --q elbow=1", 3,
       "kdl_space: --q elbow: " + kTwolink + " has no movable joint 'elbow' (its movable joints: joint1, joint2)\n"},
      {"inspect --urdf " + kTwolink + " --tip hand --base-pos 1e308 0 0", 3,
       "kdl_space: " + kTwolink +
           ": the free-floating quantities cannot be computed at this state (--q, --base-pos, --base-rpy): an input "
           "holds NaN or infinite values, or a result overflowed\n"},
      {"inspect --urdf " + kTwolink + " --tip hand --offset 1e308 1e308 0", 3,
       "kdl_space: --tip hand --offset 1e+308 1e+308 0: the contact quantities cannot be computed: an input holds NaN "
       "or infinite values, or a result overflowed\n"},
  });
}

// --- Output files --------------------------------------------------------------------------------

class OutputFiles : public HostileFiles {
 protected:
  static std::string file(const std::string& path) { return slurp(path); }
  /// Files in the scratch folder whose name is not in `expected` (temporaries left behind).
  std::vector<std::string> strays(const std::set<std::string>& expected) const {
    std::vector<std::string> found;
    for (const auto& entry : fs::directory_iterator(dir))
      if (!expected.count(entry.path().filename().string())) found.push_back(entry.path().filename().string());
    return found;
  }
};

TEST_F(OutputFiles, FoldersThatCannotTakeTheFileAreRefusedBeforeAnyWork) {
  const std::string file = write("file.txt", "not a folder");
  const std::string sub = (dir / "sub").string();
  fs::create_directories(sub);
  // /sys takes no new file, even from root; the reason (EACCES, or EROFS where it is mounted
  // read-only) is the system's.
  const int fd = open("/sys/kdl_space_probe", O_WRONLY | O_CREAT | O_EXCL, 0600);
  ASSERT_LT(fd, 0) << "a file could be created in /sys";
  const std::string why_not_sys = std::strerror(errno);
  expectAll({
      {"simulate " + kValid + " --csv /nonexistent/dir/run.csv", 3,
       "kdl_space: --csv /nonexistent/dir/run.csv: the folder '/nonexistent/dir' does not exist\n"},
      {"simulate " + kValid + " --plot /nonexistent/dir/run.svg", 3,
       "kdl_space: --plot /nonexistent/dir/run.svg: the folder '/nonexistent/dir' does not exist\n"},
      {"simulate " + kValid + " --csv " + file + "/run.csv", 3,
       "kdl_space: --csv " + file + "/run.csv: '" + file + "' is not a folder\n"},
      {"simulate " + kValid + " --csv " + sub, 3, "kdl_space: --csv " + sub + ": is a folder; give a file name\n"},
      // The finished file is renamed over its name: a device must not be replaced.
      {"simulate " + kValid + " --csv /dev/null", 3,
       "kdl_space: --csv /dev/null: exists and is not a regular file; give the name of a file\n"},
      {"simulate " + kValid + " --csv /sys/run.csv", 3,
       "kdl_space: --csv /sys/run.csv: cannot create a file in the folder '/sys': " + why_not_sys + "\n"},
      {"simulate " + kValid + " --csv " + sub + "/a.svg --plot " + sub + "/a.svg", 2,
       "kdl_space: --csv and --plot name the same file " + sub + "/a.svg\n"},
  });
  EXPECT_EQ(strays({"file.txt", "sub"}), std::vector<std::string>{});
  EXPECT_TRUE(fs::is_empty(sub));
}

TEST_F(OutputFiles, NoOutputReplacesAFileTheRunReads) {
  // A copy of a scenario, its robot, a study of it, and links to them: the guard must hold (if it
  // failed, only these copies would be lost).
  const std::string urdf = write("robot.urdf", file(urdfDir() + "/spacedyn_twolink.urdf"));
  std::string text = file(kValid);
  text.replace(text.find("../reference/models/spacedyn_twolink.urdf"), std::string("../reference/models/spacedyn_twolink.urdf").size(),
               "robot.urdf");
  const std::string scenario = write("run.yaml", text);
  const std::string study = write("study.yaml", "scenario: run.yaml\nsamples: 4\nseed: 1\ninputs: {timing: {uniform: [0, 1]}}\n");
  fs::create_symlink(urdf, dir / "link.urdf");
  fs::create_hard_link(urdf, dir / "hard.urdf");
  fs::create_hard_link(urdf, dir / "robot.svg");  // a picture's name, the robot's bytes
  fs::create_directories(dir / "sub");
  const std::string dotted = (dir / "sub" / ".." / "robot.urdf").string();
  const std::string d = dir.string();
  const std::string tail = "; it would be overwritten: give the output another name\n";
  expectAll({
      {"simulate " + scenario + " --csv " + urdf, 2, "kdl_space: --csv " + urdf + ": is the robot's URDF" + tail},
      {"simulate " + scenario + " --csv " + d + "/link.urdf", 2,
       "kdl_space: --csv " + d + "/link.urdf: is the robot's URDF " + urdf + tail},
      {"simulate " + scenario + " --csv " + d + "/hard.urdf", 2,
       "kdl_space: --csv " + d + "/hard.urdf: is the robot's URDF " + urdf + tail},
      {"simulate " + scenario + " --csv " + dotted, 2, "kdl_space: --csv " + dotted + ": is the robot's URDF " + urdf + tail},
      {"capture " + scenario + " --scene " + d + "/robot.svg", 2,
       "kdl_space: --scene " + d + "/robot.svg: is the robot's URDF " + urdf + tail},
      {"study " + study + " -o " + scenario, 2, "kdl_space: --table " + scenario + ": is the scenario file" + tail},
      {"study " + study + " -o " + urdf, 2, "kdl_space: --table " + urdf + ": is the robot's URDF" + tail},
      {"study " + study + " --summary " + study, 2, "kdl_space: --summary " + study + ": is the study file" + tail},
  });
  EXPECT_EQ(file(urdf), file(urdfDir() + "/spacedyn_twolink.urdf")) << "the robot is as it was";
  EXPECT_EQ(file(scenario), text);
}

TEST_F(OutputFiles, ARunThatFailsMidwayLeavesNoFileAndKeepsAnOldOne) {
  const std::string csv = (dir / "run.csv").string(), plot = (dir / "run.svg").string();
  // Fails after 400 integration steps, with the CSV half written under its temporary name.
  ToolRun r = kdlSpace("simulate " + kCorpus + "/max_steps_spent.yaml --csv " + csv + " --plot " + plot);
  EXPECT_EQ(r.rc, 3) << r.err;
  EXPECT_NE(r.err.find("simulation.max_steps = 400 is spent"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(csv));
  EXPECT_FALSE(fs::exists(plot));
  EXPECT_EQ(strays({}), std::vector<std::string>{}) << "no temporary left behind";

  // A file of the same name from an earlier run is left as it was, not half overwritten.
  write("run.csv", "an earlier run\n");
  r = kdlSpace("simulate " + kCorpus + "/blows_up.yaml --csv " + csv);
  EXPECT_EQ(r.rc, 3) << r.err;
  std::ifstream in(csv);
  std::stringstream kept;
  kept << in.rdbuf();
  EXPECT_EQ(kept.str(), "an earlier run\n");
  EXPECT_EQ(strays({"run.csv"}), std::vector<std::string>{});
}

TEST_F(OutputFiles, ACompleteRunRenamesItsFilesIntoPlace) {
  const std::string csv = (dir / "run.csv").string(), plot = (dir / "run.svg").string();
  const ToolRun r = kdlSpace("simulate " + kValid + " --csv " + csv + " --plot " + plot);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(strays({"run.csv", "run.svg"}), std::vector<std::string>{}) << "no temporary left behind";
  std::ifstream in(csv);
  std::string line;
  int rows = -1;  // the header
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, 21) << "t = 0, 0.05, ..., 1";
  std::ifstream svg(plot);
  std::stringstream text;
  text << svg.rdbuf();
  EXPECT_NE(text.str().find("</svg>"), std::string::npos) << "a complete SVG";
}

}  // namespace
}  // namespace kdl_space::test
