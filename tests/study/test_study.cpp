// Studies through the public API (study.hpp): each row is the capture of the problem its inputs
// describe (checked against solveCapture by the paper's dense route, the problem built here by
// hand), the rows do not depend on threads or chunks, the summary's statistics, the loader's
// refusals naming the field.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <unistd.h>

#include "kdl_space/study/study.hpp"
#include "study_rows.hpp"
#include "test_util.hpp"

namespace kdl_space {
namespace {

namespace fs = std::filesystem;
const std::string kScenarios = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/";

/// This test process's temporary folder: ctest runs the tests of this file side by side, and a file
/// that two of them rewrite at once is read empty.
fs::path studyDir() { return fs::path(::testing::TempDir()) / ("kdl_space_study_tests_" + std::to_string(getpid())); }

/// A study file in the test's temporary folder.
std::string studyFile(const std::string& name, const std::string& text) {
  const fs::path dir = studyDir();
  fs::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

std::size_t column(const std::vector<std::string>& columns, const std::string& name) {
  const auto it = std::find(columns.begin(), columns.end(), name);
  EXPECT_NE(it, columns.end()) << name;
  return static_cast<std::size_t>(it - columns.begin());
}

const char* kMixed = R"(scenario: SCENARIO
samples: 24
seed: 11
inputs:
  robot.q.joint2: {uniform: [0.5, 0.9]}
  robot.qdot.joint1: {normal: {mean: 0.02, std: 0.01}}
  target.mass: {uniform: [20, 80]}
  target.twist.wz: {uniform: [-0.1, 0.1]}
  target.grasp.y: {uniform: [-0.05, 0.05]}
  timing: {uniform: [0, 3]}
limits: {joint_rate: 0.1, base_rate: 0.0015}
)";

std::string mixedStudy() {
  std::string text = kMixed;
  text.replace(text.find("SCENARIO"), 8, kScenarios + "tumbling_box_capture.yaml");
  return studyFile("mixed.yaml", text);
}

TEST(Study, EachRowIsTheCaptureItsInputsDescribe) {
  const auto st = std::make_shared<const Study>(loadStudy(mixedStudy()));
  const std::vector<std::string> columns = studyColumns(*st);
  StudyEvaluator evaluator(st);
  std::vector<double> row(columns.size());
  const Scenario& sc = st->scenario;
  const FloatingSystem& r0 = sc.capture.robot;
  FreeFloatingSolver dense(r0.model);
  const auto hand = [&](const State& s) {  // the contact frame, by the dense solver's poses
    EXPECT_EQ(dense.compute(s), 0);
    const KDL::Frame b = dense.bodyPose(r0.contact.body);
    return KDL::Frame(b.M, b * r0.contact.offset);
  };
  const KDL::Frame F0 = hand(r0.state);
  const RigidTarget& t0 = std::get<RigidTarget>(sc.capture.target);
  for (std::uint64_t i = 0; i < st->samples; ++i) {
    evaluator.evaluate(i, row.data());
    ASSERT_EQ(row[column(columns, "status")], 0.0) << i;
    ASSERT_EQ(row[0], static_cast<double>(i));
    // The problem, by hand.
    CaptureProblem p = sc.capture;
    p.method = ExIITMethod::Dense;
    p.robot.state.q(1) = row[column(columns, "robot.q.joint2")];
    p.robot.velocity.qdot(0) = row[column(columns, "robot.qdot.joint1")];
    RigidTarget t = t0;
    const double m = row[column(columns, "target.mass")];
    t.inertia = t0.inertia * (m / t0.mass);
    t.mass = m;
    t.twist(5) = row[column(columns, "target.twist.wz")];
    FreeRigidMotion tumble(t);
    ASSERT_EQ(tumble.at(row[column(columns, "timing")], t), 0);
    const KDL::Frame F = hand(p.robot.state);
    const KDL::Vector grasp = t0.pose.Inverse() * F0.p + KDL::Vector(0, row[column(columns, "target.grasp.y")], 0);
    t.pose.M = F.M * F0.M.Inverse() * t.pose.M;
    t.pose.p = F.p - t.pose.M * grasp;
    p.target = t;
    const CaptureResult c = solveCapture(p);
    // The row, against it (the recursive route against the dense one: 1e-9).
    for (int k = 0; k < 6; ++k) {
      const char* names[] = {"impulse.fx", "impulse.fy", "impulse.fz", "impulse.nx", "impulse.ny", "impulse.nz"};
      EXPECT_NEAR(row[column(columns, names[k])], c.impulse.F(k), 1e-9 * c.impulse.F.norm()) << i << " " << names[k];
    }
    const Vector6d base = toEigen(c.robot.after.base_twist);
    EXPECT_NEAR(row[column(columns, "base.wz")], base(5), 1e-9 * base.norm()) << i;
    EXPECT_NEAR(row[column(columns, "base_rate")], base.tail<3>().norm(), 1e-9 * base.norm()) << i;
    const double jump7 = c.robot.after.qdot(6) - c.robot.before.qdot(6);
    EXPECT_NEAR(row[column(columns, "dqdot.joint7")], jump7, 1e-9 * (c.robot.after.qdot.data.norm() + 1e-12)) << i;
    EXPECT_NEAR(row[column(columns, "energy_lost")], c.energyLost(), 1e-9 * c.energy_before) << i;
    // The limits, from the row's own numbers.
    double fastest = 0.0;
    for (unsigned j = 0; j < 7; ++j) fastest = std::max(fastest, std::abs(c.robot.after.qdot(j)));
    EXPECT_EQ(row[column(columns, "exceeds.joint_rate")], fastest > 0.1 ? 1.0 : 0.0) << i;
    EXPECT_EQ(row[column(columns, "exceeds.base_rate")], base.tail<3>().norm() > 0.0015 ? 1.0 : 0.0) << i;
  }
}

TEST(Study, RowsAreTheSameOnAnyThreadsAndChunks) {
  const auto st = std::make_shared<const Study>(loadStudy(kScenarios + "study_grasp_configuration.yaml"));
  const std::vector<double> one = test::studyTable(st, 1, 400), two = test::studyTable(st, 2, 7),
                            three = test::studyTable(st, 3, 64);
  EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(one.data(), three.data(), one.size() * sizeof(double)), 0);
  // A chunk grid is the same from any start: the chunks of [130, 400) are those of [0, 400) cut.
  const std::vector<StudyChunk> cut = studyChunks(130, 400, 64);
  ASSERT_EQ(cut.size(), 5u);
  EXPECT_EQ(cut[0].begin, 130u);
  EXPECT_EQ(cut[0].end, 192u);
  EXPECT_EQ(cut[4].begin, 384u);
  EXPECT_EQ(cut[4].end, 400u);
}

TEST(Study, ACancelledRunStopsAndAThrowingReportPropagates) {
  const auto st = std::make_shared<const Study>(loadStudy(kScenarios + "study_grasp_configuration.yaml"));
  std::atomic<bool> cancel{true};
  int reports = 0;
  runStudy(st, studyChunks(0, st->samples, 10), 2, [&](const StudyChunk&, const std::vector<double>&) { ++reports; }, &cancel);
  EXPECT_EQ(reports, 0);
  EXPECT_THROW(runStudy(st, studyChunks(0, st->samples, 10), 2,
                        [&](const StudyChunk&, const std::vector<double>&) { throw InputError("disk full"); }),
               InputError);
}

TEST(Study, SummaryQuantilesProbabilitiesAndRanks) {
  const Study st = loadStudy(mixedStudy());
  const std::vector<std::string> columns = studyColumns(st);
  const std::size_t m = columns.size(), rate = column(columns, "base_rate"), any = column(columns, "exceeds.any");
  // 11 computed samples with base_rate 0, 1, ..., 10 (in reverse order) and one that failed.
  std::vector<double> rows(12 * m, 0.0);
  for (std::size_t r = 0; r < 11; ++r) {
    rows[r * m] = static_cast<double>(r);
    rows[r * m + rate] = static_cast<double>(10 - r);
    rows[r * m + any] = r < 3 ? 1.0 : 0.0;
  }
  rows[11 * m] = 11, rows[11 * m + 1] = E_BAD_ARGUMENT, rows[11 * m + rate] = NAN;
  const StudySummary s = summarizeStudy(st, rows);
  EXPECT_EQ(s.samples, 12u);
  EXPECT_EQ(s.failed, 1u);
  const auto o = std::find_if(s.outcomes.begin(), s.outcomes.end(), [](const OutcomeSummary& x) { return x.name == "base_rate"; });
  ASSERT_NE(o, s.outcomes.end());
  EXPECT_EQ(o->min, 0.0);
  EXPECT_EQ(o->max, 10.0);
  EXPECT_DOUBLE_EQ(o->median, 5.0);
  EXPECT_DOUBLE_EQ(o->q05, 0.5);   // 0.05 * 10 between order statistics 0 and 1
  EXPECT_DOUBLE_EQ(o->q25, 2.5);
  EXPECT_DOUBLE_EQ(o->q95, 9.5);
  EXPECT_DOUBLE_EQ(o->mean, 5.0);
  const auto p = std::find_if(s.probabilities.begin(), s.probabilities.end(), [](const auto& x) { return x.first == "exceeds.any"; });
  ASSERT_NE(p, s.probabilities.end());
  EXPECT_DOUBLE_EQ(p->second, 3.0 / 11.0);
  ASSERT_EQ(s.best.size(), 5u);
  EXPECT_EQ(s.best[0].sample, 10u);  // base_rate 0
  EXPECT_EQ(s.worst[0].sample, 0u);  // base_rate 10
  EXPECT_EQ(s.best[0].inputs.size(), 6u);
  EXPECT_EQ(s.best[0].inputs[0].first, "robot.q.joint2");
}

/// The path of the failing study's scenario (failingStudy).
std::string failingScenario() { return (studyDir() / "failing_scenario.yaml").string(); }

/// A study of the tumbling box whose samples fail for known reasons: joint2 drawn beyond its
/// limit (2.967 rad), where the scenario's hard stops refuse to start the motion (an InputError
/// from the motion's set-up: E_BAD_ARGUMENT) and, for the others, a motion after the capture whose
/// step budget (3 steps) is spent (E_MAX_STEPS): it fits the budget by the estimate (one step of
/// 0.5 s: max_step and output_step 0.5 s), but the adaptive steps start at 1 ms. (A mass drawn <= 0
/// is refused at load now: no sample fails for it.)
std::string failingStudy() {
  std::ifstream in(kScenarios + "tumbling_box_capture.yaml");
  std::string scenario((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  scenario.replace(scenario.find("../urdf/"), 8, std::string(KDL_SPACE_SOURCE_DIR) + "/urdf/");
  scenario.replace(scenario.find("  atol:"), 0, "  max_steps: 3\n  max_step: 0.5\n  limits: stop\n");
  const std::string path = studyFile("failing_scenario.yaml", scenario);
  EXPECT_EQ(path, failingScenario());
  return studyFile("failing.yaml", "scenario: " + path + "\nsamples: 40\nseed: 5\n"
                   "inputs: {robot.q.joint3: {normal: {mean: 2.9, std: 0.1}}}\nmotion: {duration: 0.5, output_step: 0.5}\n");
}

/// What the motion's set-up says of joint3 started at q (capture_operation.cpp's checkStart).
std::string outsideItsStop(double q) {
  std::ostringstream why;
  why << failingScenario() << ": simulation.limits: joint 'joint3' starts at " << q
      << ", outside its limits [-2.96706, 2.96706] (a hard stop keeps it inside them): start it inside, or let its limits warn";
  return why.str();
}

TEST(Study, TheSummaryKeepsTheMessageOfTheFirstSampleOfEachFailure) {
  const auto st = std::make_shared<const Study>(loadStudy(failingStudy()));
  const std::size_t m = studyColumns(*st).size();
  // Evaluated here: each failed sample says why.
  StudyEvaluator evaluator(st);
  std::vector<double> row(m);
  std::map<int, std::uint64_t> count, first;
  double first_q = 0.0;
  for (std::uint64_t i = 0; i < st->samples; ++i) {
    evaluator.evaluate(i, row.data());
    const int status = static_cast<int>(row[1]);
    ASSERT_TRUE(status == E_BAD_ARGUMENT || status == E_MAX_STEPS) << i << ": " << status;
    if (count[status]++ == 0) first[status] = i;
    const double q = row[2];
    EXPECT_EQ(status == E_BAD_ARGUMENT, std::abs(q) > 2.96706) << i;
    EXPECT_EQ(evaluator.failure(), status == E_BAD_ARGUMENT ? outsideItsStop(q)
                                                            : "motion: the motion after the capture cannot be simulated "
                                                              "for 0.5 s: " + std::string(strError(E_MAX_STEPS)));
    if (status == E_BAD_ARGUMENT && count[status] == 1) first_q = q;
  }
  ASSERT_GT(count[E_BAD_ARGUMENT], 0u);
  ASSERT_GT(count[E_MAX_STEPS], 0u);
  // The table from two threads in chunks of 7 (in the order they complete), its rows reversed:
  // the summary evaluates each failure's first sample again, so its message does not depend on
  // where or in which order the rows were computed.
  std::vector<double> done;
  runStudy(st, studyChunks(0, st->samples, 7), 2,
           [&](const StudyChunk&, const std::vector<double>& part) { done.insert(done.end(), part.begin(), part.end()); });
  ASSERT_EQ(done.size(), static_cast<std::size_t>(st->samples) * m);
  std::vector<double> rows;
  for (std::size_t r = st->samples; r-- > 0;) {
    const auto at = done.begin() + static_cast<std::ptrdiff_t>(r * m);
    rows.insert(rows.end(), at, at + static_cast<std::ptrdiff_t>(m));
  }
  const StudySummary s = summarizeStudy(*st, rows);
  EXPECT_EQ(s.failed, st->samples);
  ASSERT_EQ(s.failures.size(), 2u);
  EXPECT_LT(s.failures[0].first_sample, s.failures[1].first_sample) << "in the order of their first sample";
  for (const StudyFailure& f : s.failures) {
    SCOPED_TRACE(f.status);
    EXPECT_EQ(f.count, count[f.status]);
    EXPECT_EQ(f.first_sample, first[f.status]);
  }
  const StudyFailure& bad = s.failures[s.failures[0].status == E_BAD_ARGUMENT ? 0 : 1];
  EXPECT_EQ(bad.message, outsideItsStop(first_q));
  const StudyFailure& steps = s.failures[s.failures[0].status == E_MAX_STEPS ? 0 : 1];
  EXPECT_EQ(steps.message, "motion: the motion after the capture cannot be simulated for 0.5 s: " +
                               std::string(strError(E_MAX_STEPS)));
  // A row that does not fail when evaluated again (another run's, or a caller's): said so.
  std::vector<double> good(m);
  StudyEvaluator(std::make_shared<const Study>(loadStudy(mixedStudy()))).evaluate(3, good.data());
  ASSERT_EQ(good[1], 0.0);
  good[1] = E_MAX_STEPS;
  const StudySummary other = summarizeStudy(loadStudy(mixedStudy()), good);
  ASSERT_EQ(other.failures.size(), 1u);
  EXPECT_EQ(other.failures[0].first_sample, 3u);
  EXPECT_EQ(other.failures[0].message, "status -105 (" + std::string(strError(E_MAX_STEPS)) +
                                           "); evaluated again, sample 3 computes");
}

/// The message of loadStudy for a study file, or "" if it loads.
std::string refusal(const std::string& name, const std::string& text) {
  try {
    loadStudy(studyFile(name, text));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Study, DrawsThatStayInTheirDomainLoad) {
  const std::string head = "scenario: " + kScenarios + "tumbling_box_capture.yaml\nsamples: 50\nseed: 3\n";
  for (const std::string inputs : {"{target.mass: {normal: {mean: 10, std: 20, min: 1}}}",
                                   "{target.mass: {log_normal: {median: 50, factor: 1.5}}}",
                                   "{target.mass: {normal: {mean: 50, std: 2}}}",  // 0 lies 25 std below: never drawn
                                   "{timing: {normal: {mean: 1, std: 1, min: 0, max: 3}}}",
                                   "{target.tumble: {normal: {mean: 0.1, std: 0.1, min: 0}}}"}) {
    SCOPED_TRACE(inputs);
    const std::string why = refusal("in_domain.yaml", head + "inputs: " + inputs + "\n");
    EXPECT_EQ(why, "");
  }
  // A truncated mass draws only masses inside its bounds, and each sample computes.
  const auto st = std::make_shared<const Study>(
      loadStudy(studyFile("truncated_mass.yaml", head + "inputs: {target.mass: {normal: {mean: 10, std: 20, min: 1, max: 25}}}\n")));
  ASSERT_EQ(st->inputs[0].distribution.kind, Distribution::Kind::Normal);
  EXPECT_EQ(st->inputs[0].distribution.min, 1.0);
  EXPECT_EQ(st->inputs[0].distribution.max, 25.0);
  StudyEvaluator evaluator(st);
  std::vector<double> row(studyColumns(*st).size());
  for (std::uint64_t i = 0; i < st->samples; ++i) {
    evaluator.evaluate(i, row.data());
    EXPECT_EQ(row[1], 0.0) << i << ": " << evaluator.failure();
    EXPECT_GE(row[2], 1.0);
    EXPECT_LE(row[2], 25.0);
  }
}

/// A copy of the repository's study folder (the grasp study, its scenario, its URDF) under `dir`,
/// each file's "\n" written as `newline`.
std::string copyStudyFolder(const fs::path& dir, const std::string& newline) {
  const fs::path source = KDL_SPACE_SOURCE_DIR;
  for (const char* file : {"scenarios/study_grasp_configuration.yaml", "scenarios/tumbling_box_capture.yaml", "urdf/space_arm7.urdf"}) {
    std::ifstream in(source / file, std::ios::binary);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(text.find('\r'), std::string::npos) << file;
    std::string converted;
    for (const char c : text) converted += c == '\n' ? newline : std::string(1, c);
    fs::create_directories((dir / file).parent_path());
    std::ofstream(dir / file, std::ios::binary) << converted;
  }
  return (dir / "scenarios/study_grasp_configuration.yaml").string();
}

TEST(Study, TheFingerprintDoesNotDependOnLineEndings) {
  const fs::path root = studyDir();
  const Study lf = loadStudy(copyStudyFolder(root / "lf", "\n"));
  const Study crlf = loadStudy(copyStudyFolder(root / "crlf", "\r\n"));
  EXPECT_EQ(crlf.fingerprint, lf.fingerprint);
  EXPECT_EQ(lf.fingerprint, loadStudy(kScenarios + "study_grasp_configuration.yaml").fingerprint);
  // A change of the content is another study; so is a lone "\r" (no line ending).
  std::ofstream(root / "lf/scenarios/study_grasp_configuration.yaml", std::ios::app) << "# edited\n";
  EXPECT_NE(loadStudy((root / "lf/scenarios/study_grasp_configuration.yaml").string()).fingerprint, lf.fingerprint);
  copyStudyFolder(root / "cr", "\n");
  std::ofstream(root / "cr/urdf/space_arm7.urdf", std::ios::app) << "\r";
  EXPECT_NE(loadStudy((root / "cr/scenarios/study_grasp_configuration.yaml").string()).fingerprint, lf.fingerprint);
}

TEST(Study, TheLoaderBoundsWhatItReads) {
  // A study file over the size limit: refused before it is read, its size said.
  const std::string huge = studyFile("huge_study.yaml", "");
  fs::resize_file(huge, (std::uintmax_t{16} << 20) + 1);  // sparse: nothing written
  std::string why;
  try {
    loadStudy(huge);
  } catch (const InputError& e) {
    why = e.what();
  }
  EXPECT_EQ(why, huge + ": is 16777217 bytes (16 MiB), more than the 16 MiB a study file (YAML or JSON) may have (is it "
                        "the right file?)");
  // A field of 15 MiB (the largest a study file of at most 16 MiB holds, in round numbers): quoted
  // cut, with its length.
  const std::string field(15u << 20, 'x');
  const std::string length = "(" + std::to_string(field.size()) + " characters)";
  const std::string head = "scenario: " + kScenarios + "tumbling_box_capture.yaml\nsamples: 10\nseed: 1\n";
  // (YAML limits an implicit key to 1024 characters: a longer one is an explicit key, "? KEY".)
  for (const std::string& text : {head + "inputs: {timing: {uniform: [0, 1]}}\nsampling: " + field + "\n",
                                   head + "inputs:\n  ? " + field + "\n  : {uniform: [0, 1]}\n",
                                   head + "inputs:\n  ? robot.q." + field + "\n  : {uniform: [0, 1]}\n"}) {
    const std::string message = refusal("long_field.yaml", text);
    EXPECT_LT(message.size(), 600u) << message.substr(0, 600);
    EXPECT_NE(message.find(length), std::string::npos) << message.substr(0, 600);
  }
}

TEST(Study, TheLoaderNamesTheFieldThatIsWrong) {
  const std::string head = "scenario: " + kScenarios + "tumbling_box_capture.yaml\n";
  struct Case {
    std::string text, expect;
  } cases[] = {
      {head + "samples: 10\nseed: 1\ninputs: {target.spin: {uniform: [0, 1]}}\n", "inputs.target.spin: is no input of a study"},
      {head + "samples: 10\nseed: 1\ninputs: {robot.q.elbow: {uniform: [0, 1]}}\n", "no movable joint 'elbow'"},
      {head + "samples: 10\nseed: 1\ninputs: {target.mass: {uniform: [3, 3]}}\n", "inputs.target.mass.uniform: is an empty range"},
      {head + "samples: 10\nseed: 1\ninputs: {target.mass: {uniform: [-3, 3]}}\n", "inputs.target.mass: takes values >= 0"},
      {head + "samples: 10\nseed: 1\ninputs: {timing: {normal: {mean: 1, std: 0}}}\n", "inputs.timing.normal.std: must be > 0"},
      {head + "samples: 0\nseed: 1\ninputs: {timing: {uniform: [0, 1]}}\n", "samples: must be >= 1, got 0"},
      {head + "samples: 1000000000000\nseed: 1\ninputs: {timing: {uniform: [0, 1]}}\n", "samples: must be at most 1e9"},
      {head + "samples: 10\nseed: 1.5\ninputs: {timing: {uniform: [0, 1]}}\n", "seed: must be a whole number"},
      {head + "samples: 10\nseed: -3\ninputs: {timing: {uniform: [0, 1]}}\n", "seed: must be a whole number"},
      {head + "samples: 10\nseed: abc\ninputs: {timing: {uniform: [0, 1]}}\n", "seed: must be a whole number"},
      {head + "samples: 10\ninputs: {timing: {uniform: [0, 1]}}\n", "seed: missing"},
      {head + "samples: 10\nseed: 1\ninputs: {timing: {grid: [0, 1, 0]}}\n", "must be >= 1 point"},
      {head + "samples: 10\nseed: 1\ninputs: {timing: {uniform: [0, 1], normal: {mean: 0, std: 1}}}\n", "give one distribution"},
      {head + "samples: 10\nseed: 1\ninputs: {}\n", "inputs: a study varies at least one input"},
      {head + "samples: 10\nseed: 1\ninputs: {timing: {uniform: [0, 1]}}\nobjective: spin\n", "objective: is no outcome"},
      {head + "samples: 10\nseed: 1\ninputs: {timing: {uniform: [0, 1]}}\nlimits: {joint_torque: 5}\n",
       "limits.joint_torque: the torques are those of the motion"},
      {head + "samples: 10\nseed: 1\ninputs: {timing: {uniform: [0, 1]}}\nsampling: sobol\n", "sampling: 'sobol' is not one of"},
      {"scenario: missing.yaml\nsamples: 10\nseed: 1\ninputs: {timing: {uniform: [0, 1]}}\n", "missing.yaml"},
      {"scenario: " + kScenarios + "approach_tumbling_box.yaml\nsamples: 10\nseed: 1\ninputs: {timing: {uniform: [0, 1]}}\n",
       "scenario: has an approach"},
      {"scenario: " + kScenarios + "compliant_capture.yaml\nsamples: 10\nseed: 1\ninputs: {timing: {uniform: [0, 1]}}\n",
       "scenario: has law type compliant"},
      {"scenario: " + kScenarios + "robot_to_robot_capture.yaml\nsamples: 10\nseed: 1\ninputs: {target.mass: {uniform: [1, 2]}}\n",
       "the target is a free-floating system"},
      {"scenario: " + kScenarios + "robot_to_robot_capture.yaml\nsamples: 10\nseed: 1\ninputs: {robot.q.joint2: {uniform: [0, 0.1]}}\n"
       "motion: {duration: 1}\n", "motion: no motion follows"},
      // Checked up front: the motion against the step budget, as `simulate` does (the tumbling box:
      // max_step 0.05 s, max_steps 1e6): every sample would spend it.
      {head + "samples: 10\nseed: 1\ninputs: {timing: {uniform: [0, 1]}}\nmotion: {duration: 1e9}\n",
       "motion.duration: 1e+09 s in steps of at most 0.05 s (the scenario's simulation.max_step) needs 2e+10 steps, more "
       "than the scenario's simulation.max_steps = 1000000: give a duration of at most 50000 s (or raise "
       "simulation.max_steps in " + kScenarios + "tumbling_box_capture.yaml)"},
      {head + "samples: 10\nseed: 1\ninputs: {timing: {uniform: [0, 1]}}\nmotion: {duration: 10, output_step: 1e-6}\n",
       "motion.duration: 10 s in steps of at most 1e-06 s (motion.output_step) needs 1e+07 steps"},
      // Draws that leave the input's domain: refused at load, with what to use.
      {head + "samples: 10\nseed: 1\ninputs: {target.mass: {normal: {mean: 10, std: 20}}}\n",
       "inputs.target.mass: takes values > 0 (a mass), but this normal draws down to -"},
      {head + "samples: 10\nseed: 1\ninputs: {target.mass: {normal: {mean: 10, std: 20}}}\n",
       "use {normal: {mean: 10, std: 20, min: M}} with M > 0 (truncated) or {log_normal: {median: 10, factor: F}}"},
      {head + "samples: 10\nseed: 1\ninputs: {target.mass: {normal: {mean: 10, std: 20, min: 0}}}\n",
       "inputs.target.mass: takes values > 0 (a mass), but this normal draws down to 0"},
      {head + "samples: 10\nseed: 1\ninputs: {timing: {normal: {mean: 1, std: 1}}}\n",
       "inputs.timing: takes values >= 0 (a delay), but this normal draws down to -"},
      {head + "samples: 10\nseed: 1\ninputs: {target.tumble: {normal: {mean: 0.1, std: 0.1}}}\n",
       "use {normal: {mean: 0.1, std: 0.1, min: 0}} (truncated)"},
      {head + "samples: 10\nseed: 1\ninputs: {target.mass: {uniform: [0, 3]}}\n", "inputs.target.mass: a mass must be > 0 kg"},
      {head + "samples: 10\nseed: 1\ninputs: {target.mass: {grid: [0, 3, 4]}}\n", "inputs.target.mass: a mass must be > 0 kg"},
      {head + "samples: 10\nseed: 1\ninputs: {target.mass: {log_normal: {median: 10, factor: 1e300}}}\n",
       "inputs.target.mass: this log-normal draws values that are not finite numbers"},
      {head + "samples: 10\nseed: 1\ninputs: {target.twist.vx: {uniform: [-1.7e308, 1.7e308]}}\n",
       "inputs.target.twist.vx: this range draws values that are not finite numbers"},
      {head + "samples: 10\nseed: 1\ninputs: {target.twist.vx: {grid: [-1.7e308, 1.7e308, 3]}}\n",
       "inputs.target.twist.vx: this range draws values that are not finite numbers"},
      {head + "samples: 10\nseed: 1\ninputs: {robot.q.joint2: {normal: {mean: 1e308, std: 1e307}}}\n",
       "inputs.robot.q.joint2: this normal draws values that are not finite numbers"},
      {head + "samples: 10\nseed: 1\ninputs: {target.twist.vx: {uniform: [0, .inf]}}\n", "is not a finite number"},
      {head + "samples: 10\nseed: 1\ninputs: {timing: {normal: {mean: 1, std: 1, min: 2, max: 2}}}\n",
       "inputs.timing.normal: is truncated to an empty range"},
      {head + "samples: 10\nseed: 1\ninputs: {timing: {normal: {mean: 0, std: 1, min: 40, max: 41}}}\n",
       "has a probability below 1e-250 under this normal"},
      {head + "samples: 10\nseed: 1\ninputs: {timing: {log_normal: {median: 1, factor: 1}}}\n",
       "inputs.timing.log_normal.factor: must be > 1"},
      {head + "samples: 10\nseed: 1\ninputs: {timing: {log_normal: {median: 0, factor: 2}}}\n",
       "inputs.timing.log_normal.median: must be > 0"},
  };
  int k = 0;
  for (const Case& c : cases) {
    const std::string name = "broken_" + std::to_string(k++) + ".yaml";
    const std::string why = refusal(name, c.text);
    EXPECT_NE(why.find(c.expect), std::string::npos) << name << ": expected '" << c.expect << "' in '" << why << "'";
    EXPECT_NE(why.find(name), std::string::npos) << "the file is named: " << why;
  }
}

}  // namespace
}  // namespace kdl_space

namespace kdl_space {
namespace {
// Angles in degrees where a person writes them: {deg: DIST} for an angle, {deg_per_s: DIST} for a
// rate, converted once at load into the same distribution in radians (bit for bit: x * pi / 180);
// a unit that does not fit the input is refused by name.
TEST(Study, DistributionsInDegreesAreTheRadiansOnes) {
  const std::string head = "scenario: " + kScenarios + "tumbling_box_capture.yaml\nsamples: 8\nseed: 4\ninputs:\n";
  const Study deg = loadStudy(studyFile("deg.yaml", head + "  robot.q.joint2: {deg: {uniform: [20, 50]}}\n"
                                                           "  target.twist.wz: {deg_per_s: {normal: {mean: 1, std: 2, min: -3, max: 5}}}\n"
                                                           "  target.tumble: {deg_per_s: {grid: [0, 4, 3]}}\n"));
  const double k = M_PI / 180.0;
  const Distribution& q = deg.inputs[0].distribution;
  EXPECT_EQ(q.a, 20 * k);
  EXPECT_EQ(q.b, 50 * k);
  const Distribution& w = deg.inputs[1].distribution;
  EXPECT_EQ(w.a, 1 * k);
  EXPECT_EQ(w.b, 2 * k);
  EXPECT_EQ(w.min, -3 * k);
  EXPECT_EQ(w.max, 5 * k);
  EXPECT_EQ(deg.inputs[2].distribution.b, 4 * k);
  EXPECT_EQ(deg.inputs[2].distribution.count, 3);
  EXPECT_NE(refusal("deg_mass.yaml", head + "  target.mass: {deg: {uniform: [20, 50]}}\n").find("is not an angle or an angular rate"),
            std::string::npos);
  EXPECT_NE(refusal("deg_rate.yaml", head + "  robot.q.joint2: {deg_per_s: {uniform: [20, 50]}}\n").find("is an angle: {deg: ...}"),
            std::string::npos);
}
}  // namespace
}  // namespace kdl_space
