// Shared helpers of the test suite: one matrix comparison, paths, random states.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <random>
#include <string>

#include "kdl_space/multibody/state.hpp"

namespace kdl_space::test {

/// \brief Element-wise |a - b| <= rel |b| + abs for matrices of equal size; reports the worst
/// element with its indices. `what` names the quantity in the failure message.
inline ::testing::AssertionResult near(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                                       double rel, double abs, const std::string& what = "") {
  if (a.rows() != b.rows() || a.cols() != b.cols())
    return ::testing::AssertionFailure() << what << ": size " << a.rows() << "x" << a.cols()
                                         << " vs " << b.rows() << "x" << b.cols();
  double worst = 0.0;
  Eigen::Index wi = 0, wj = 0;
  for (Eigen::Index i = 0; i < a.rows(); ++i)
    for (Eigen::Index j = 0; j < a.cols(); ++j) {
      const double excess = std::abs(a(i, j) - b(i, j)) - (rel * std::abs(b(i, j)) + abs);
      if (!(excess <= worst)) {  // catches NaN too
        worst = std::isnan(excess) ? INFINITY : excess;
        wi = i;
        wj = j;
      }
    }
  if (worst > 0.0)
    return ::testing::AssertionFailure()
           << what << ": element (" << wi << "," << wj << ") is " << a(wi, wj) << ", expected "
           << b(wi, wj) << " (tolerance " << rel << " relative + " << abs << ")";
  return ::testing::AssertionSuccess();
}

/// Directory of the test data and of the bundled models (set by CMake).
inline std::string dataDir() { return KDL_SPACE_TEST_DATA_DIR; }
inline std::string urdfDir() { return KDL_SPACE_URDF_DIR; }

/// Every bundled robot, sorted: urdf/*.urdf, tests/data/models/*.urdf, tests/data/families/*.urdf.
inline std::vector<std::string> bundledRobots() {
  std::vector<std::string> files;
  for (const std::string& folder : {dataDir() + "/models", dataDir() + "/families", urdfDir()})
    for (const auto& e : std::filesystem::directory_iterator(folder))
      if (e.path().extension() == ".urdf") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

/// A random configuration: joints in [-pi, pi] (prismatic in [-0.2, 0.4] m), random base pose.
inline State randomState(const FloatingModel& model, std::mt19937& rng) {
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), pos(-2.0, 2.0), ext(-0.2, 0.4);
  State s(model);
  for (unsigned int j = 0; j < model.nj(); ++j) {
    const KDL::Joint& joint = model.bodies()[model.jointBody()[j]].segment.getJoint();
    const bool prismatic = joint.getType() == KDL::Joint::TransAxis ||
                           joint.getType() == KDL::Joint::TransX ||
                           joint.getType() == KDL::Joint::TransY || joint.getType() == KDL::Joint::TransZ;
    s.q(j) = prismatic ? ext(rng) : angle(rng);
  }
  s.world_T_base = basePose(KDL::Vector(pos(rng), pos(rng), pos(rng)), angle(rng), angle(rng) / 2, angle(rng));
  return s;
}

}  // namespace kdl_space::test
