// Reading a case of tests/data/reference (copied from ../shared/reference).
#pragma once

#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "kdl_space/spatial/spatial.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {

struct ReferenceCase {
  nlohmann::json json;
  std::shared_ptr<const FloatingModel> model;
  State state;
  Contact contact;
  KDL::Twist base_twist;
  KDL::JntArray qdot;

  explicit ReferenceCase(const std::string& name) {
    std::ifstream in(dataDir() + "/reference/" + name + ".json");
    json = nlohmann::json::parse(in);
    const nlohmann::json& inputs = json.at("inputs");
    model = std::make_shared<const FloatingModel>(
        loadUrdfFile(dataDir() + "/reference/" + inputs.at("urdf").get<std::string>()));
    state = State(*model);
    state.q = jointsByName(*model, inputs.at("q").get<std::map<std::string, double>>());
    const auto p = inputs.at("base_position").get<std::vector<double>>();
    const auto rpy = inputs.at("base_rpy").get<std::vector<double>>();
    state.world_T_base = basePose(KDL::Vector(p[0], p[1], p[2]), rpy[0], rpy[1], rpy[2]);
    const auto o = inputs.at("contact_offset").get<std::vector<double>>();
    contact = model->contact(inputs.at("contact_link").get<std::string>(), KDL::Vector(o[0], o[1], o[2]));
    base_twist = toTwist(vec(inputs.at("base_twist")));
    qdot = jointsByName(*model, inputs.at("joint_rates").get<std::map<std::string, double>>());
  }

  /// A JSON array (of numbers, or of rows) as a matrix.
  static Eigen::MatrixXd mat(const nlohmann::json& j) {
    if (!j.at(0).is_array()) {
      Eigen::MatrixXd m(j.size(), 1);
      for (std::size_t i = 0; i < j.size(); ++i) m(i, 0) = j[i].get<double>();
      return m;
    }
    Eigen::MatrixXd m(j.size(), j.at(0).size());
    for (std::size_t r = 0; r < j.size(); ++r)
      for (std::size_t c = 0; c < j[r].size(); ++c) m(r, c) = j[r][c].get<double>();
    return m;
  }
  static Vector6d vec(const nlohmann::json& j) { return mat(j); }

  /// Permutation: column of the model's joint j in the expected joint order.
  std::vector<int> expectedOrder() const {
    std::vector<int> order;
    for (const auto& name : json.at("expected").at("joint_names")) order.push_back(model->jointIndex(name));
    return order;
  }
};

}  // namespace kdl_space::test
