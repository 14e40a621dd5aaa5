// `--html FILE` on `capture` and `study` (its nominal sample): the page is written whole or not at
// all, named in the JSON, and refused before any work where simulate's --html is refused (an
// input of the run, another output's file, a folder that cannot hold it). What the page shows in
// a browser is python/tests/test_html_outputs.py's.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"

namespace kdl_space::test {
namespace {

namespace fs = std::filesystem;

const std::string kScenarios = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/";

/// The page's data (window.KDL_DATA), as the page's script reads it.
nlohmann::json pageData(const std::string& page) {
  const std::string text = slurp(page);
  const std::string head = "window.KDL_DATA = ";
  const std::size_t from = text.find(head), to = text.find(";\n</script>", from);
  if (from == std::string::npos || to == std::string::npos) return nullptr;
  const std::string json = text.substr(from + head.size(), to - from - head.size());
  EXPECT_EQ(json.find('<'), std::string::npos) << "every < in the data is written \\u003c";
  return nlohmann::json::parse(json);
}

class Html : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::path(::testing::TempDir()) / ("html_" + std::to_string(getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  std::vector<std::string> files() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }
  std::string path(const std::string& name) const { return (dir / name).string(); }
  fs::path dir;
};

TEST_F(Html, CaptureWritesTheInstantBeforeAndAfter) {
  const std::string page = path("capture.html");
  const ToolRun r = kdlSpace("capture " + kScenarios + "tumbling_box_capture.yaml --html " + page + " --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(files(), std::vector<std::string>{"capture.html"}) << "no temporary left behind";
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("html"), page);
  const nlohmann::json data = pageData(page);
  ASSERT_FALSE(data.is_null()) << "the page holds no window.KDL_DATA";
  // Two frames at the contact instant: before the impact (phase 1, "contact") and after (2).
  EXPECT_EQ(data.at("frameCount"), 2);
  EXPECT_EQ(data.at("phases"), (std::vector<int>{1, 2}));
  EXPECT_EQ(data.at("tCapture"), 0.0);
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(data.at("impulse")[k].get<double>(), j.at("impulse")[k].get<double>());
  const Scenario sc = loadScenario(kScenarios + "tumbling_box_capture.yaml");
  EXPECT_EQ(data.at("links").size(), sc.capture.robot.model->bodies().size());
  EXPECT_FALSE(data.at("target").is_null()) << "the rigid target's box";
  EXPECT_TRUE(data.at("targetLinks").is_null());

  const ToolRun text = kdlSpace("capture " + kScenarios + "tumbling_box_capture.yaml --html " + page);
  ASSERT_EQ(text.rc, 0) << text.err;
  EXPECT_NE(text.out.find("Page: " + page), std::string::npos) << text.out;
  const ToolRun none = kdlSpace("capture " + kScenarios + "tumbling_box_capture.yaml --json");
  ASSERT_EQ(none.rc, 0) << none.err;
  EXPECT_TRUE(nlohmann::json::parse(none.out).at("html").is_null());
}

TEST_F(Html, CaptureOfAFreeFloatingTargetDrawsItsLinks) {
  const std::string page = path("robots.html");
  const ToolRun r = kdlSpace("capture " + kScenarios + "robot_to_robot_capture.yaml --html " + page);
  ASSERT_EQ(r.rc, 0) << r.err;
  const nlohmann::json data = pageData(page);
  const Scenario sc = loadScenario(kScenarios + "robot_to_robot_capture.yaml");
  const auto& target = std::get<FloatingSystem>(sc.capture.target);
  ASSERT_TRUE(data.at("targetLinks").is_array());
  ASSERT_EQ(data.at("targetLinks").size(), target.model->bodies().size());
  for (std::size_t i = 0; i < target.model->bodies().size(); ++i)
    EXPECT_EQ(data.at("targetLinks")[i].at("name"), target.model->bodies()[i].name);
  // A frame: the contact point, 7 numbers a robot link, 7 a target link (no rigid target's frame).
  EXPECT_EQ(data.at("stride"), 3 + 7 * (sc.capture.robot.model->bodies().size() + target.model->bodies().size()));
}

TEST_F(Html, CaptureRefusesWhatSimulateRefuses) {
  const std::string scenario = kScenarios + "tumbling_box_capture.yaml";
  const std::string urdf = loadScenario(scenario).robot_urdf;
  const std::string before = slurp(urdf);
  fs::create_symlink(urdf, dir / "robot.html");
  const std::string tail = "; it would be overwritten: give the output another name\n";
  struct Case {
    std::string args;
    int rc;
    std::string err;
  };
  const std::vector<Case> cases = {
      {"capture " + scenario + " --html " + scenario, 2, "kdl_space: --html " + scenario + ": is the scenario file" + tail},
      {"capture " + scenario + " --html " + path("robot.html"), 2,
       "kdl_space: --html " + path("robot.html") + ": is the robot's URDF " + urdf + tail},
      {"capture " + scenario + " --html " + path("a.svg") + " --scene " + path("a.svg"), 2,
       "kdl_space: --html and --scene name the same file " + path("a.svg") + "\n"},
  };
  for (const Case& c : cases) {
    const ToolRun r = kdlSpace(c.args);
    EXPECT_EQ(r.rc, c.rc) << c.args;
    EXPECT_EQ(r.err, c.err) << c.args;
    EXPECT_EQ(r.out, "") << c.args;
  }
  const ToolRun missing = kdlSpace("capture " + scenario + " --html " + path("no/such/folder/p.html"));
  EXPECT_EQ(missing.rc, 3);
  EXPECT_NE(missing.err.find("--html " + path("no/such/folder/p.html")), std::string::npos) << missing.err;
  EXPECT_EQ(slurp(urdf), before) << "the robot is as it was";
  EXPECT_EQ(files(), std::vector<std::string>{"robot.html"});
}

/// A small study of the tumbling box (4 samples of the wrist's roll), with a motion or not.
std::string studyFile(const fs::path& dir, const std::string& motion) {
  const std::string path = (dir / "study.yaml").string();
  spit(path, "scenario: " + kScenarios + "tumbling_box_capture.yaml\nsamples: 4\nseed: 3\n"
             "inputs: {robot.q.joint7: {uniform: [-0.2, 0.2]}}\n" + motion);
  return path;
}

TEST_F(Html, StudyDrawsItsNominalSample) {
  const std::string study = studyFile(dir, "motion: {duration: 0.5, output_step: 0.05}\n");
  const std::string page = path("nominal.html"), table = path("t.csv");
  const ToolRun r = kdlSpace("study " + study + " -o " + table + " --html " + page + " --json --threads 1");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out).at("html"), page);
  const nlohmann::json data = pageData(page);
  ASSERT_FALSE(data.is_null());
  // The study's motion after the capture: 0.5 s at 0.05 s, every sample a frame (under 30 a second).
  EXPECT_EQ(data.at("frameCount"), 11);
  EXPECT_NE(data.at("title").get<std::string>().find("nominal sample"), std::string::npos);

  const std::string still = studyFile(dir, "");  // no motion: the capture's instant
  const ToolRun s = kdlSpace("study " + still + " -o " + table + " --html " + page + " --threads 1");
  ASSERT_EQ(s.rc, 0) << s.err;
  EXPECT_NE(s.out.find("Page of the nominal sample: " + page), std::string::npos) << s.out;
  EXPECT_EQ(pageData(page).at("frameCount"), 2);
}

TEST_F(Html, StudyRefusesAPageOverItsInputsOrOutputs) {
  const std::string study = studyFile(dir, "");
  const std::string table = path("t.csv");
  const std::string tail = "; it would be overwritten: give the output another name\n";
  const ToolRun onto_study = kdlSpace("study " + study + " -o " + table + " --html " + study);
  EXPECT_EQ(onto_study.rc, 2);
  EXPECT_EQ(onto_study.err, "kdl_space: --html " + study + ": is the study file" + tail);
  const ToolRun same = kdlSpace("study " + study + " -o " + table + " --html " + path("s.json") + " --summary " + path("s.json"));
  EXPECT_EQ(same.rc, 2);
  EXPECT_EQ(same.err, "kdl_space: --html and --summary name the same file " + path("s.json") + "\n");
  const ToolRun shard = kdlSpace("study " + study + " --shard 1/2 --html " + path("p.html"));
  EXPECT_EQ(shard.rc, 2);
  EXPECT_NE(shard.err.find("--html " + path("p.html")), std::string::npos) << shard.err;
  EXPECT_EQ(files(), std::vector<std::string>{"study.yaml"}) << "nothing written";
}


// --- --mesh-path on capture and study; no output replaces a mesh the page embeds (issue 25's rule)

/// Standard base64 (what the page embeds a mesh's bytes as), to find a file's bytes in KDL_DATA.
std::string base64(const std::string& bytes) {
  static const char* const kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    unsigned v = 0;
    for (std::size_t k = 0; k < 3; ++k) v = v << 8 | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k) out += k <= n ? kDigits[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

/// The tumbling box's capture with the arm's link2 drawn by a binary STL (one triangle) named
/// package://pkg/meshes/hand.stl, under DIR/share (what --mesh-path gives); ROS_PACKAGE_PATH unset.
class HtmlMeshes : public Html {
 protected:
  void SetUp() override {
    Html::SetUp();
    unsetenv("ROS_PACKAGE_PATH");  // the tool's children search --mesh-path only
    share = (dir / "share").string();
    fs::create_directories(dir / "share" / "pkg" / "meshes");
    mesh = (dir / "share" / "pkg" / "meshes" / "hand.stl").string();
    std::string stl(80, ' ');
    const auto put = [&](const void* p, std::size_t n) { stl.append(static_cast<const char*>(p), n); };
    const std::uint32_t count = 1;
    put(&count, 4);
    const float t[12] = {0, 0, 1, 0, 0, 0, 0.1f, 0, 0, 0, 0.1f, 0};  // normal, 3 vertices
    put(t, sizeof t);
    put("\0\0", 2);
    spit(mesh, stl);
    std::string urdf = slurp(std::string(KDL_SPACE_SOURCE_DIR) + "/urdf/space_arm7.urdf");
    const std::string link2 = "<link name=\"link2\">";
    urdf.insert(urdf.find(link2) + link2.size(),
                "<visual><geometry><mesh filename=\"package://pkg/meshes/hand.stl\"/></geometry></visual>");
    spit(path("arm.urdf"), urdf);
    std::string yaml = slurp(kScenarios + "tumbling_box_capture.yaml");
    yaml.replace(yaml.find("../urdf/space_arm7.urdf"), std::string("../urdf/space_arm7.urdf").size(), path("arm.urdf"));
    scenario = path("scenario.yaml");
    spit(scenario, yaml);
    bytes = slurp(mesh);
  }
  /// The files of the page's KDL_DATA.meshes whose bytes are the mesh's.
  std::size_t embedded(const std::string& page) const {
    const nlohmann::json data = pageData(page);
    if (data.is_null()) return 0;
    return std::count_if(data.at("meshes").begin(), data.at("meshes").end(),
                         [&](const nlohmann::json& m) { return m.at("data") == base64(bytes); });
  }
  std::string share, mesh, scenario, bytes;
};

TEST_F(HtmlMeshes, CaptureAndStudyFindMeshesThroughMeshPath) {
  const std::string page = path("capture.html");
  const ToolRun r = kdlSpace("capture " + scenario + " --html " + page + " --mesh-path " + share + " --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(embedded(page), 1u) << "the page embeds hand.stl once";
  EXPECT_EQ(pageData(page).at("meshes").size(), 1u);
  // Without it: the link's box, and the warning in the JSON as simulate gives it.
  const ToolRun without = kdlSpace("capture " + scenario + " --html " + page + " --json");
  ASSERT_EQ(without.rc, 0) << without.err;
  EXPECT_EQ(embedded(page), 0u);
  const nlohmann::json warnings = nlohmann::json::parse(without.out).at("warnings");
  EXPECT_TRUE(std::any_of(warnings.begin(), warnings.end(), [](const nlohmann::json& w) {
    return w.at("kind") == "mesh_not_drawn" && w.at("element") == "link2";
  })) << warnings.dump();

  for (const std::string motion : {"", "motion: {duration: 0.2, output_step: 0.05}\n"}) {
    const std::string study = path("study.yaml");
    spit(study, "scenario: " + scenario + "\nsamples: 2\nseed: 3\ninputs: {robot.q.joint7: {uniform: [-0.2, 0.2]}}\n" + motion);
    const std::string nominal = path("nominal.html");
    const ToolRun s = kdlSpace("study " + study + " -o " + path("t.csv") + " --html " + nominal + " --mesh-path " + share +
                               " --threads 1");
    ASSERT_EQ(s.rc, 0) << s.err;
    EXPECT_EQ(embedded(nominal), 1u) << motion;
  }
  EXPECT_EQ(slurp(mesh), bytes);
}

TEST_F(HtmlMeshes, NoOutputReplacesAMeshThePageEmbeds) {
  const std::string tail = "; it would be overwritten: give the output another name\n";
  const std::string what = ": is the mesh package://pkg/meshes/hand.stl of link link2";
  const std::string page = path("page.html");
  // The mesh itself, and a symbolic link to it (the same file, by inode) with the scene's extension.
  fs::create_symlink(mesh, dir / "mesh.svg");
  fs::create_symlink(mesh, dir / "mesh.csv");
  const std::string svg = path("mesh.svg"), csv = path("mesh.csv");
  struct Case {
    std::string args, option, output;
  };
  const std::vector<Case> cases = {
      {"simulate " + scenario + " --duration 0.1 --html " + page + " --csv " + mesh, "--csv", mesh},
      {"simulate " + scenario + " --duration 0.1 --html " + page + " --scene " + svg, "--scene", svg},
      {"simulate " + scenario + " --duration 0.1 --html " + mesh, "--html", mesh},
      {"capture " + scenario + " --html " + page + " --scene " + svg, "--scene", svg},
      {"capture " + scenario + " --html " + mesh, "--html", mesh},
  };
  for (const Case& c : cases) {
    const ToolRun r = kdlSpace(c.args + " --mesh-path " + share);
    EXPECT_EQ(r.rc, 2) << c.args;
    EXPECT_EQ(r.err.rfind("kdl_space: " + c.option + " " + c.output + what, 0), 0u) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(tail), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "") << c.args;
    EXPECT_EQ(slurp(mesh), bytes) << c.args << ": the mesh is as it was";
    EXPECT_FALSE(fs::exists(page)) << c.args << ": nothing written";
  }
  const std::string study = path("study.yaml");
  spit(study, "scenario: " + scenario + "\nsamples: 2\nseed: 3\ninputs: {robot.q.joint7: {uniform: [-0.2, 0.2]}}\n");
  const ToolRun s = kdlSpace("study " + study + " -o " + csv + " --html " + page + " --mesh-path " + share);
  EXPECT_EQ(s.rc, 2) << s.err;
  EXPECT_EQ(s.err.rfind("kdl_space: --table " + csv + what, 0), 0u) << s.err;
  EXPECT_EQ(slurp(mesh), bytes);
  EXPECT_TRUE(fs::is_symlink(dir / "mesh.csv"));
  EXPECT_FALSE(fs::exists(page));
}

}  // namespace
}  // namespace kdl_space::test
