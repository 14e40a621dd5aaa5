// `kdl_space capture --scene FILE`: the 3-D picture of the impact (gnuplot, .svg or .png), and
// the equivalent box of inertia it draws for every body (kdl_space/report/scene_writer.hpp).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <kdl/frames.hpp>
#include <sstream>

#include "kdl_space/report/scene_writer.hpp"
#include "cli_runner.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"

namespace kdl_space::test {
namespace {

namespace fs = std::filesystem;
using report::equivalentBox;
using report::equivalentBoxEdges;

const std::string kScenarios = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/";

/// The inertia about its centre of a uniform box with edges `e` along its own axes.
Vector3d boxMoments(double m, const Vector3d& e) {
  return m / 12.0 * Vector3d(e.y() * e.y() + e.z() * e.z(), e.x() * e.x() + e.z() * e.z(), e.x() * e.x() + e.y() * e.y());
}

TEST(EquivalentBox, ABoxsInertiaGivesBackItsEdges) {
  const double m = 50.0;
  const Vector3d e(0.4, 0.7, 1.1);
  EXPECT_LT((equivalentBoxEdges(m, boxMoments(m, e)) - e).cwiseAbs().maxCoeff(), 1e-12);

  // Turned and moved: the same edges (longest first: the smallest moment is about the longest
  // edge), centred at the CoM, along the box's own axes.
  const KDL::Rotation R = KDL::Rotation::RPY(0.3, -0.2, 0.5);
  const Matrix3d Rm = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R.data);
  const Matrix3d I = Rm * boxMoments(m, e).asDiagonal() * Rm.transpose();
  const Vector3d com(0.32, -2.88, 1.69);
  const report::SceneBox box = equivalentBox(m, I, com);
  EXPECT_LT((box.size - Vector3d(1.1, 0.7, 0.4)).cwiseAbs().maxCoeff(), 1e-12) << box.size.transpose();
  EXPECT_LT((toEigen(box.pose.p) - com).norm(), 1e-15);
  const Matrix3d B = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(box.pose.M.data);
  EXPECT_NEAR(B.determinant(), 1.0, 1e-12) << "a right-handed frame";
  for (int k = 0; k < 3; ++k)  // the box's k-th edge lies along the body's axis 2 - k
    EXPECT_NEAR(std::abs(B.col(k).dot(Rm.col(2 - k))), 1.0, 1e-12) << k;
  // The box's inertia, rebuilt from what was drawn, is the body's.
  const Matrix3d back = B * boxMoments(m, box.size).asDiagonal() * B.transpose();
  EXPECT_LT((back - I).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(EquivalentBox, ThinAndPointBodies) {
  // A rod along x: no width; a point mass and a massless body: no box.
  const double m = 3.0, L = 2.0;
  const Vector3d rod = equivalentBoxEdges(m, Vector3d(0.0, m * L * L / 12, m * L * L / 12));
  EXPECT_LT((rod - Vector3d(L, 0, 0)).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(equivalentBoxEdges(m, Vector3d::Zero()), Vector3d::Zero());
  EXPECT_EQ(equivalentBoxEdges(0.0, Vector3d(1, 1, 1)), Vector3d::Zero());
  // Round-off that breaks the triangle inequality gives 0, not NaN.
  EXPECT_EQ(equivalentBoxEdges(1.0, Vector3d(1.0, 1.0, 2.0 + 1e-15))(2), 0.0);
}

// --- the tool ------------------------------------------------------------------------------------

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

/// Bodies of a model with mass (each drawn as a box of 12 edges).
std::size_t massive(const FloatingModel& model) {
  std::size_t n = 0;
  for (const Body& b : model.bodies()) n += b.mass > 0.0;
  return n;
}

class Scene : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::path(::testing::TempDir()) / ("kdl_space_scene_" + std::to_string(getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  /// Every file in the scratch folder.
  std::vector<std::string> files() const {
    std::vector<std::string> found;
    for (const auto& entry : fs::directory_iterator(dir)) found.push_back(entry.path().filename().string());
    std::sort(found.begin(), found.end());
    return found;
  }
  fs::path dir;
};

/// The straight segments drawn (an "L" of a path: each segment of a "with vectors" plot is at least
/// one, and the legend's sample one more) by the plots whose legend is `title`: gnuplot's SVG
/// holds each plot in a group <g id="gnuplot_plot_..."> and joins the segments of one colour into
/// one <path>, a segment that starts where the last one ended without a new "M".
std::size_t segments(const std::string& svg, const std::string& title) {
  const std::string mark = "<g id=\"gnuplot_plot_";
  std::size_t total = 0;
  for (std::size_t at = svg.find(mark); at != std::string::npos;) {
    const std::size_t next = svg.find(mark, at + 1);
    const std::string chunk = svg.substr(at, next == std::string::npos ? std::string::npos : next - at);
    if (chunk.find(">" + title + "<") != std::string::npos)
      for (std::size_t k = 0; k + 1 < chunk.size(); ++k)
        total += chunk[k] == 'L' && (std::isdigit(static_cast<unsigned char>(chunk[k + 1])) || chunk[k + 1] == '-');
    at = next;
  }
  return total;
}

/// A complete SVG of one panel titled "impact", with the contact point's legend, and the robot
/// drawn whole: a segment per link (and one from the contact link to the contact point), per
/// joint axis, per edge of the bodies' boxes.
void expectScene(const std::string& svg, const FloatingModel& robot) {
  EXPECT_TRUE(svg.rfind("<?xml", 0) == 0 || svg.rfind("<svg", 0) == 0) << svg.substr(0, 80);
  EXPECT_NE(svg.find("</svg>"), std::string::npos) << "a complete SVG";
  EXPECT_NE(svg.find(">impact<"), std::string::npos) << "the panel's title";
  EXPECT_NE(svg.find(">contact point<"), std::string::npos);
  const std::size_t n = robot.bodies().size();
  EXPECT_GE(count(svg, "<path") + count(svg, "<polyline"), n) << "at least a path per link";
  EXPECT_GE(segments(svg, "robot"), n) << "n - 1 links and the contact point's";
  EXPECT_GE(segments(svg, "robot joint axes"), robot.nj());
  EXPECT_GE(segments(svg, "robot boxes of inertia"), 12 * (massive(robot) - 1));
  EXPECT_GE(segments(svg, "robot base box"), 12u);
}

TEST_F(Scene, CaptureDrawsTheRobotAndARigidTarget) {
  const std::string scenario = kScenarios + "tumbling_box_capture.yaml", svg = (dir / "scene.svg").string();
  const ToolRun r = kdlSpace("capture " + scenario + " --scene " + svg);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_NE(r.out.find("Scene: " + svg + "\n"), std::string::npos) << r.out;
  EXPECT_EQ(files(), std::vector<std::string>{"scene.svg"}) << "no temporary left behind";
  const Scenario sc = loadScenario(scenario);
  const std::string text = slurp(svg);
  expectScene(text, *sc.capture.robot.model);
  EXPECT_GE(segments(text, "target (box of inertia)"), 12u);
  EXPECT_GE(segments(text, "target frame (x, y, z)"), 3u);
  EXPECT_NE(text.find("robot joint axes"), std::string::npos);
  EXPECT_EQ(text.find("grasp point"), std::string::npos) << "a rigid target is grasped at the contact point";
}

TEST_F(Scene, CaptureDrawsAFreeFloatingTargetAsAStickFigure) {
  const std::string scenario = kScenarios + "robot_to_robot_capture.yaml", svg = (dir / "scene.svg").string();
  const ToolRun r = kdlSpace("capture " + scenario + " --scene " + svg + " --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out).at("scene"), svg);
  EXPECT_EQ(files(), std::vector<std::string>{"scene.svg"});
  const Scenario sc = loadScenario(scenario);
  const FloatingModel& robot = *sc.capture.robot.model;
  const FloatingModel& target = *std::get<FloatingSystem>(sc.capture.target).model;
  const std::string text = slurp(svg);
  expectScene(text, robot);
  EXPECT_NE(text.find(">grasp point<"), std::string::npos);
  EXPECT_GE(segments(text, "target"), target.bodies().size() - 1);
  EXPECT_GE(segments(text, "target joint axes"), target.nj());
  EXPECT_GE(segments(text, "target base box"), 12u);
}

TEST_F(Scene, SimulateDrawsTheStartTheContactAndTheEnd) {
  const std::string svg = (dir / "operation.svg").string(), csv = (dir / "operation.csv").string();
  const ToolRun r = kdlSpace("simulate " + kScenarios + "approach_tumbling_box.yaml --duration 1 --scene " + svg +
                             " --csv " + csv + " --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(files(), (std::vector<std::string>{"operation.csv", "operation.svg"})) << "no temporary left behind";
  const std::string text = slurp(svg);
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const double t_c = j.at("approach").at("t_contact").get<double>();
  for (const char* panel : {">start, t = 0 s<", ">end, t = "}) EXPECT_NE(text.find(panel), std::string::npos) << panel;
  std::ostringstream contact;
  contact << ">contact, t = " << t_c << " s<";
  EXPECT_NE(text.find(contact.str()), std::string::npos) << contact.str();
  EXPECT_EQ(count(text, ">grasp point<"), 2u) << "at the start and at the contact";
  const Scenario sc = loadScenario(kScenarios + "approach_tumbling_box.yaml");
  // three stick figures of the arm, two boxes of the target (at the end it is the arm's payload)
  EXPECT_GE(segments(text, "robot"), 3 * sc.capture.robot.model->bodies().size());
  EXPECT_GE(segments(text, "target (box of inertia)"), 24u);
  // --scene and --csv may not name the same file
  const ToolRun same = kdlSpace("simulate " + kScenarios + "approach_tumbling_box.yaml --scene " + svg + " --csv " + svg);
  EXPECT_EQ(same.rc, 2);
  EXPECT_NE(same.err.find("name the same file " + svg), std::string::npos) << same.err;
}

TEST_F(Scene, JsonSaysNullWithoutAScene) {
  const ToolRun r = kdlSpace("capture " + kScenarios + "tumbling_box_capture.yaml --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::parse(r.out).at("scene").is_null());
}

TEST_F(Scene, APngToo) {
  const std::string png = (dir / "scene.png").string();
  const ToolRun r = kdlSpace("capture " + kScenarios + "tumbling_box_capture.yaml --scene " + png);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(files(), std::vector<std::string>{"scene.png"});
  EXPECT_EQ(slurp(png).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
}

TEST_F(Scene, AFileThatCannotBeWrittenIsRefusedByNameAndNothingIsLeft) {
  const std::string scenario = kScenarios + "tumbling_box_capture.yaml";
  const std::string gif = (dir / "scene.gif").string();
  ToolRun r = kdlSpace("capture " + scenario + " --scene " + gif);
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "kdl_space: --scene " + gif + ": the file name must end in .svg or .png\n");
  EXPECT_EQ(r.out, "");

  r = kdlSpace("capture " + scenario + " --scene /nonexistent/dir/scene.svg");
  EXPECT_EQ(r.rc, 3);
  EXPECT_EQ(r.err, "kdl_space: --scene /nonexistent/dir/scene.svg: the folder '/nonexistent/dir' does not exist\n");

  // A folder that takes no new file (/sys refuses even root).
  r = kdlSpace("capture " + scenario + " --scene /sys/scene.svg");
  EXPECT_EQ(r.rc, 3);
  EXPECT_EQ(r.err.rfind("kdl_space: --scene /sys/scene.svg: cannot create a file in the folder '/sys': ", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists("/sys/scene.svg"));

  const fs::path locked = dir / "locked";
  fs::create_directories(locked);
  fs::permissions(locked, fs::perms::owner_read | fs::perms::owner_exec);
  const std::string inside = (locked / "scene.svg").string();
  r = kdlSpace("capture " + scenario + " --scene " + inside);
  if (geteuid() != 0) {  // root writes anywhere
    EXPECT_EQ(r.rc, 3);
    EXPECT_EQ(r.err.rfind("kdl_space: --scene " + inside + ": cannot create a file in the folder", 0), 0u) << r.err;
    EXPECT_TRUE(fs::is_empty(locked));
  }
  fs::permissions(locked, fs::perms::owner_all);

  r = kdlSpace("capture " + scenario + " --scene ''");
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("--scene: the file name is empty"), std::string::npos) << r.err;
  EXPECT_EQ(files(), std::vector<std::string>{"locked"}) << "no file, no temporary";
}

}  // namespace
}  // namespace kdl_space::test
