// The JSON of a capture plan (`plan --json`, kdl_space.plan_capture's dict). Keys are a contract.
#pragma once

#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/planning/capture_plan.hpp"
#include "kdl_space/report/json.hpp"

namespace kdl_space::report {

/// What the bus felt over a motion after a capture: peak_base_rate, final_base_rate,
/// attitude_excursion, settling_time, peak_torque_by_name (the robot's `joint_names`),
/// peak_torque_ratio, peak_torque_joint, peak_grasp_force, peak_grasp_moment, momentum_rate
/// (NaN: null).
Json measuresJson(const MotionMeasures& m, const std::vector<std::string>& joint_names);

/// One configuration's terms: objective, base_rate, impulse, joint_rate_jump, feasible, violation
/// (and infeasible: why not; motion: measuresJson, when measured); also kdl_space.plan_capture's
/// `optimum` and `nominal` dicts.
Json termsJson(const PlanTerms& terms, const std::vector<std::string>& joint_names);

/// The JSON object of a plan (keys are a contract: see the README).
Json planJson(const Scenario& scenario, const PlanOptions& options, const CapturePlan& plan);

}  // namespace kdl_space::report
