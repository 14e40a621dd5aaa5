// A study's inputs on the target as engineers state its uncertainty (issue 38): each principal
// moment of inertia by its own factor, the principal axes turned within a cone, the tumble's axis
// within a cone about the scenario's, its rate over a range. Each row is the capture of the target
// built here by an independent route (the principal frame from an SVD, the turn by KDL's
// Rodrigues rotation, the capture by the dense route); the rows are bit-identical on any threads
// and chunks; what no rigid body can be is refused at load, naming the input.
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "kdl_space/study/study.hpp"
#include "study_rows.hpp"
#include "test_util.hpp"

namespace kdl_space {
namespace {

namespace fs = std::filesystem;
const std::string kBox = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/tumbling_box_capture.yaml";

std::string shapeStudyFile(const std::string& name, const std::string& inputs, const std::string& extra = "") {
  const fs::path dir = fs::path(::testing::TempDir()) / ("kdl_space_shape_tests_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << "scenario: " << kBox << "\nsamples: 40\nseed: 2026\n" << extra << "inputs:\n" << inputs;
  return path;
}

double at(const std::vector<std::string>& columns, const std::vector<double>& row, const std::string& name) {
  const auto it = std::find(columns.begin(), columns.end(), name);
  EXPECT_NE(it, columns.end()) << name;
  return it == columns.end() ? NAN : row[static_cast<std::size_t>(it - columns.begin())];
}

// The box's moments are 2.1, 2.6, 3.0 kg m^2: +-15 % keeps every corner a rigid body (3.45 <= 1.785 + 2.21).
const char* kShapeInputs =
    "  target.inertia.I1: {uniform: [0.85, 1.15]}\n"
    "  target.inertia.I2: {normal: {mean: 1.0, std: 0.05, min: 0.85, max: 1.15}}\n"
    "  target.inertia.I3: {uniform: [0.85, 1.15]}\n"
    "  target.inertia.tilt: {deg: {uniform: [0, 10]}}\n"
    "  target.tumble: {deg_per_s: {uniform: [1, 3]}}\n"
    "  target.tumble_cone: {deg: {uniform: [0, 10]}}\n"
    "  target.mass: {uniform: [40, 60]}\n";

TEST(TargetShapeStudy, EachRowIsTheCaptureOfTheTargetItsInputsDescribe) {
  const auto st = std::make_shared<const Study>(loadStudy(shapeStudyFile("shape.yaml", kShapeInputs)));
  const std::vector<std::string> columns = studyColumns(*st);
  for (const char* c : {"target.inertia.tilt.axis_x", "target.tumble_cone.axis_z", "target.tumble.axis_y"})
    EXPECT_NE(std::find(columns.begin(), columns.end(), c), columns.end()) << c;
  StudyEvaluator evaluator(st);
  std::vector<double> row(columns.size());
  const RigidTarget& t0 = std::get<RigidTarget>(st->scenario.capture.target);
  // The principal frame by an SVD (an SPD matrix's singular vectors are its principal axes), ascending.
  const Eigen::JacobiSVD<Matrix3d> svd(t0.inertia, Eigen::ComputeFullU);
  Matrix3d axes;
  Vector3d moments;
  for (int k = 0; k < 3; ++k) axes.col(k) = svd.matrixU().col(2 - k), moments(k) = svd.singularValues()(2 - k);
  const Vector3d n = t0.twist.tail<3>().normalized();
  double largest_tilt = 0.0, largest_cone = 0.0;
  for (std::uint64_t i = 0; i < st->samples; ++i) {
    evaluator.evaluate(i, row.data());
    ASSERT_EQ(at(columns, row, "status"), 0.0) << i << ": " << evaluator.failure();
    // Degrees read as radians: within [0, 10 deg]; the rate within [1, 3] deg/s.
    const double tilt = at(columns, row, "target.inertia.tilt"), cone = at(columns, row, "target.tumble_cone");
    const double rate = at(columns, row, "target.tumble");
    EXPECT_TRUE(tilt >= 0.0 && tilt <= 10.0 * M_PI / 180.0) << tilt;
    EXPECT_TRUE(cone >= 0.0 && cone <= 10.0 * M_PI / 180.0) << cone;
    EXPECT_TRUE(rate >= M_PI / 180.0 && rate <= 3.0 * M_PI / 180.0) << rate;
    largest_tilt = std::max(largest_tilt, tilt), largest_cone = std::max(largest_cone, cone);
    // The tumble's axis: a unit vector at the cone's angle from the scenario's axis, the same in
    // target.tumble's columns (its rate is about it).
    const Vector3d a(at(columns, row, "target.tumble_cone.axis_x"), at(columns, row, "target.tumble_cone.axis_y"),
                     at(columns, row, "target.tumble_cone.axis_z"));
    EXPECT_NEAR(a.norm(), 1.0, 1e-15);
    EXPECT_NEAR(std::atan2(n.cross(a).norm(), n.dot(a)), cone, 1e-12);
    for (const char* c : {"x", "y", "z"})
      EXPECT_EQ(at(columns, row, std::string("target.tumble.axis_") + c), at(columns, row, std::string("target.tumble_cone.axis_") + c));
    // The target, by hand: the moments by their factors, the axes turned by KDL's rotation about
    // the drawn axis, the mass's scale, the twist's w the rate about the cone's axis.
    const KDL::Vector u(at(columns, row, "target.inertia.tilt.axis_x"), at(columns, row, "target.inertia.tilt.axis_y"),
                        at(columns, row, "target.inertia.tilt.axis_z"));
    EXPECT_NEAR(u.Norm(), 1.0, 1e-15);
    const Matrix3d A = toEigen(KDL::Rotation::Rot(u, tilt)) * axes;
    const Vector3d f(at(columns, row, "target.inertia.I1"), at(columns, row, "target.inertia.I2"), at(columns, row, "target.inertia.I3"));
    RigidTarget t = t0;
    t.mass = at(columns, row, "target.mass");
    t.inertia = (t.mass / t0.mass) * A * f.cwiseProduct(moments).asDiagonal() * A.transpose();
    t.twist.tail<3>() = rate * a;
    CaptureProblem p = st->scenario.capture;
    p.method = ExIITMethod::Dense;
    p.target = t;
    const CaptureResult c = solveCapture(p);
    const char* names[] = {"impulse.fx", "impulse.fy", "impulse.fz", "impulse.nx", "impulse.ny", "impulse.nz"};
    for (int k = 0; k < 6; ++k)
      EXPECT_NEAR(at(columns, row, names[k]), c.impulse.F(k), 1e-9 * c.impulse.F.norm()) << i << " " << names[k];
    EXPECT_NEAR(at(columns, row, "base_rate"), toEigen(c.robot.after.base_twist).tail<3>().norm(),
                1e-9 * toEigen(c.robot.after.base_twist).norm()) << i;
    EXPECT_NEAR(at(columns, row, "energy_lost"), c.energyLost(), 1e-9 * c.energy_before) << i;
  }
  EXPECT_GT(largest_tilt, 5.0 * M_PI / 180.0);  // the draws spread over the ranges
  EXPECT_GT(largest_cone, 5.0 * M_PI / 180.0);
}

TEST(TargetShapeStudy, AConeAloneKeepsTheScenariosRateAndTheShapeInputsNeedNotComeTogether) {
  const auto st = std::make_shared<const Study>(loadStudy(shapeStudyFile(
      "cone.yaml", "  target.tumble_cone: {uniform: [0.1, 0.2]}\n  target.inertia.I3: {uniform: [0.9, 1.1]}\n")));
  const std::vector<std::string> columns = studyColumns(*st);
  StudyEvaluator evaluator(st);
  std::vector<double> row(columns.size());
  const RigidTarget& t0 = std::get<RigidTarget>(st->scenario.capture.target);
  ASSERT_TRUE(t0.inertia.isDiagonal(0.0));  // the box's frame is principal: diag(2.1, 2.6, 3.0), I3 the largest
  for (std::uint64_t i = 0; i < 10; ++i) {
    evaluator.evaluate(i, row.data());
    ASSERT_EQ(at(columns, row, "status"), 0.0) << evaluator.failure();
    RigidTarget t = t0;
    t.inertia(2, 2) *= at(columns, row, "target.inertia.I3");
    t.twist.tail<3>() = t0.twist.tail<3>().norm() * Vector3d(at(columns, row, "target.tumble_cone.axis_x"),
                                                             at(columns, row, "target.tumble_cone.axis_y"),
                                                             at(columns, row, "target.tumble_cone.axis_z"));
    CaptureProblem p = st->scenario.capture;
    p.method = ExIITMethod::Dense;
    p.target = t;
    const CaptureResult c = solveCapture(p);
    EXPECT_NEAR(at(columns, row, "impulse.force"), c.impulse.F.head<3>().norm(), 1e-9 * c.impulse.F.norm()) << i;
    EXPECT_NEAR(at(columns, row, "impulse.moment"), c.impulse.F.tail<3>().norm(), 1e-9 * c.impulse.F.norm()) << i;
  }
}

TEST(TargetShapeStudy, RowsAreBitIdenticalOnAnyThreadsAndChunks) {
  for (const char* sampling : {"random", "latin_hypercube"}) {
    const auto st = std::make_shared<const Study>(
        loadStudy(shapeStudyFile("threads.yaml", kShapeInputs, std::string("sampling: ") + sampling + "\n")));
    const std::vector<double> one = test::studyTable(st, 1, 40), three = test::studyTable(st, 3, 7);
    EXPECT_EQ(std::memcmp(one.data(), three.data(), one.size() * sizeof(double)), 0) << sampling;
  }
}

TEST(TargetShapeStudy, WhatNoRigidBodyCanBeIsRefusedNamingTheInput) {
  const auto refused = [](const std::string& inputs, const std::string& expected) {
    try {
      loadStudy(shapeStudyFile("bad.yaml", inputs));
      ADD_FAILURE() << "accepted:\n" << inputs;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  // 2.1 x 1.3 + 2.6 x 1.3 = 6.11 >= 3 x 1.3, but 3.0 x 1.3 = 3.9 > 2.1 x 0.7 + 2.6 x 0.7 = 3.29.
  refused("  target.inertia.I1: {uniform: [0.7, 1.3]}\n  target.inertia.I2: {uniform: [0.7, 1.3]}\n"
          "  target.inertia.I3: {uniform: [0.7, 1.3]}\n",
          "inputs.target.inertia.I3: the principal moments 2.1, 2.6, 3 kg m^2 times the factors I1 x 0.7, I2 x 0.7, "
          "I3 x 1.3 (the ends of their draws) give 1.47, 1.82, 3.9 kg m^2: I3 exceeds the sum of the other two");
  refused("  target.inertia.I2: {uniform: [0, 1.1]}\n", "target.inertia.I2: a factor must be > 0, but the range reaches 0");
  refused("  target.inertia.I2: {normal: {mean: 1, std: 0.2}}\n", "target.inertia.I2: takes values > 0 (a factor)");
  refused("  target.inertia.I4: {uniform: [0.9, 1.1]}\n", "is no input of a study (target.inertia.I1, target.inertia.I2, target.inertia.I3)");
  refused("  target.inertia.tilt: {deg_per_s: {uniform: [0, 10]}}\n", "is an angle: {deg: ...}, not {deg_per_s: ...}");
  refused("  target.tumble_cone: {deg: {uniform: [0, 10]}}\n  target.twist.wz: {uniform: [0, 0.1]}\n",
          "target.twist.wz: sets the target's angular velocity, which target.tumble_cone turns within its cone");
  // A target that does not turn has no axis to make a cone about.
  const std::string still = shapeStudyFile("still.yaml", "");
  std::string text;
  {
    std::ifstream in(kBox);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::size_t at_twist = text.find("  twist: [0.03, -0.02, 0.01, 0.05, 0.08, -0.06]");
  ASSERT_NE(at_twist, std::string::npos);
  text.replace(at_twist, std::string("  twist: [0.03, -0.02, 0.01, 0.05, 0.08, -0.06]").size(), "  twist: [0.03, -0.02, 0.01, 0, 0, 0]");
  const std::size_t at_urdf = text.find("../urdf/space_arm7.urdf");  // the copy is elsewhere: the URDF by its full path
  ASSERT_NE(at_urdf, std::string::npos);
  text.replace(at_urdf, std::string("../urdf/space_arm7.urdf").size(), std::string(KDL_SPACE_URDF_DIR) + "/space_arm7.urdf");
  const std::string scenario = (fs::path(still).parent_path() / "still_box.yaml").string();
  std::ofstream(scenario) << text;
  std::ofstream(still) << "scenario: " << scenario << "\nsamples: 4\nseed: 1\ninputs:\n  target.tumble_cone: {uniform: [0, 0.1]}\n";
  try {
    loadStudy(still);
    ADD_FAILURE() << "a cone about no tumble was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("target.tumble_cone: is a cone about the target's tumble axis, and the "
                                         "scenario's target does not turn"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace kdl_space
