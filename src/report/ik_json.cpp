#include "kdl_space/report/ik_json.hpp"

#include <cmath>

namespace kdl_space::report {

Json ikSolutionJson(const FloatingModel& model, const IkResult& r) {
  Json by_name = Json::object(), chain = Json::array();
  for (unsigned int j = 0; j < model.nj(); ++j) by_name[model.jointNames()[j]] = r.q(j);
  for (int j : r.chain_joints) chain.push_back(model.jointNames()[j]);
  Json j;
  j["joint_names"] = model.jointNames();
  j["q"] = toJson(r.q.data);
  j["q_by_name"] = by_name;
  j["moved_joints"] = chain;
  j["position_residual"] = r.position_residual;
  j["orientation_residual"] = r.orientation_residual;
  j["iterations"] = r.iterations;
  j["attempts"] = r.attempts;
  j["preference_gradient"] = r.preference_gradient;
  j["reaction_measure"] = std::isfinite(r.reaction_measure) ? Json(r.reaction_measure) : Json(nullptr);
  return j;
}

Json ikJson(const Scenario& sc, const KDL::Frame& goal, const IkResult& r) {
  double roll = 0, pitch = 0, yaw = 0;
  goal.M.GetRPY(roll, pitch, yaw);
  const KDL::Vector& off = sc.capture.robot.contact.offset;
  Json j;
  j["scenario"] = sc.file;
  j["contact"] = Json{{"link", sc.capture.robot.model->bodies()[sc.capture.robot.contact.body].name}, {"offset", {off.x(), off.y(), off.z()}}};
  j["goal"] = Json{{"position", {goal.p.x(), goal.p.y(), goal.p.z()}}, {"rpy", {roll, pitch, yaw}}};
  j.update(ikSolutionJson(*sc.capture.robot.model, r));
  return j;
}

}  // namespace kdl_space::report
