#include "kdl_space/report/plan_json.hpp"

namespace kdl_space::report {

Json termsJson(const PlanTerms& t) {
  Json j;
  j["objective"] = t.objective;
  j["base_rate"] = t.base_rate;
  j["impulse"] = t.impulse;
  j["joint_rate_jump"] = t.joint_rate_jump;
  j["feasible"] = t.feasible;
  j["violation"] = t.violation;
  if (!t.feasible) j["infeasible"] = t.infeasible;
  return j;
}

Json planJson(const Scenario& sc, const PlanOptions& options, const CapturePlan& plan) {
  Json by_name = Json::object(), nominal_by_name = Json::object(), params = Json::object(), weights = Json::object();
  for (std::size_t j = 0; j < plan.joint_names.size(); ++j) {
    by_name[plan.joint_names[j]] = plan.q[j];
    nominal_by_name[plan.joint_names[j]] = plan.nominal_q[j];
  }
  for (const auto& [name, value] : plan.parameters) params[name] = value;
  for (const auto& [name, w] : options.weights) weights[name] = w;
  Json j;
  j["scenario"] = sc.file;
  j["weights"] = weights;
  j["joint_names"] = plan.joint_names;
  j["q"] = plan.q;
  j["q_by_name"] = by_name;
  j["qdot_before"] = plan.qdot_before;
  j["base_twist_before"] = plan.base_twist_before;
  j["qdot_after"] = plan.qdot_after;
  j["parameters"] = params;
  j["searched"] = plan.searched;
  j["objective"] = plan.optimum.objective;
  j["optimum"] = termsJson(plan.optimum);
  j["nominal_objective"] = plan.nominal.objective;
  j["nominal"] = termsJson(plan.nominal);
  j["nominal_q_by_name"] = nominal_by_name;
  j["evaluations"] = plan.evaluations;
  return j;
}

}  // namespace kdl_space::report
