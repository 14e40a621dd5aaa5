// The robots the impact tests run over (a chain, a tree, the SpaceDyn two-link sample and the
// public 6-axis arm), each with its contact link, and their models loaded once per test binary.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {

struct RobotSpec {
  std::string name;
  std::string path;
  std::string tip;  ///< the contact link
};

inline std::vector<RobotSpec> impactRobots() {
  return {{"space_arm7", urdfDir() + "/space_arm7.urdf", "end_effector"},
          {"dual_arm", urdfDir() + "/dual_arm.urdf", "left_tool"},
          {"spacedyn_twolink", urdfDir() + "/spacedyn_twolink.urdf", "hand"},
          {"arm6_public", dataDir() + "/reference/models/arm6_public.urdf", "tool"}};
}

/// The model of a URDF file, loaded on first use.
inline std::shared_ptr<const FloatingModel> cachedModel(const std::string& path) {
  static std::map<std::string, std::shared_ptr<const FloatingModel>> cache;
  auto it = cache.find(path);
  if (it == cache.end()) it = cache.emplace(path, std::make_shared<const FloatingModel>(loadUrdfFile(path))).first;
  return it->second;
}

}  // namespace kdl_space::test
