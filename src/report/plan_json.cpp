#include "kdl_space/report/plan_json.hpp"

#include <cmath>

namespace kdl_space::report {

Json measuresJson(const MotionMeasures& m, const std::vector<std::string>& joint_names) {
  Json by_name = Json::object();
  for (std::size_t j = 0; j < joint_names.size() && j < m.peak_torque.size(); ++j) by_name[joint_names[j]] = m.peak_torque[j];
  Json j;
  j["peak_base_rate"] = m.peak_base_rate;
  j["final_base_rate"] = m.final_base_rate;
  j["attitude_excursion"] = m.attitude_excursion;
  j["settling_time"] = m.settling_time;
  j["peak_torque_by_name"] = by_name;
  j["peak_torque_ratio"] = m.peak_torque_ratio;
  j["peak_torque_joint"] = m.peak_torque_joint;
  j["peak_grasp_force"] = m.peak_grasp_force;
  j["peak_grasp_moment"] = m.peak_grasp_moment;
  j["momentum_rate"] = m.momentum_rate;
  j["time_to_detumble"] = m.time_to_detumble;  // null: not detumbled within the horizon
  j["wheel_momentum_fraction"] = m.wheel_momentum_fraction;
  j["energy_dissipated"] = m.energy_dissipated;
  return j;
}

Json termsJson(const PlanTerms& t, const std::vector<std::string>& joint_names) {
  Json j;
  j["objective"] = t.objective;
  j["base_rate"] = t.base_rate;
  j["impulse"] = t.impulse;
  j["joint_rate_jump"] = t.joint_rate_jump;
  j["feasible"] = t.feasible;
  j["violation"] = t.violation;
  if (!t.feasible) j["infeasible"] = t.infeasible;
  if (t.motion) j["motion"] = measuresJson(*t.motion, joint_names);
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
  j["optimum"] = termsJson(plan.optimum, plan.joint_names);
  j["nominal_objective"] = plan.nominal.objective;
  j["nominal"] = termsJson(plan.nominal, plan.joint_names);
  j["nominal_q_by_name"] = nominal_by_name;
  j["evaluations"] = plan.evaluations;
  if (plan.horizon > 0.0) {  // the motion after the capture was measured
    j["horizon"] = plan.horizon;
    j["momentum_rate"] = plan.optimum.motion ? plan.optimum.motion->momentum_rate : std::nan("");
  }
  return j;
}

}  // namespace kdl_space::report
