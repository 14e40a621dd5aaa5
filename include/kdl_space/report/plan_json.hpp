// The JSON of a capture plan (`plan --json`, kdl_space.plan_capture's dict). Keys are a contract.
#pragma once

#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/planning/capture_plan.hpp"
#include "kdl_space/report/json.hpp"

namespace kdl_space::report {

/// One configuration's terms: objective, base_rate, impulse, joint_rate_jump, feasible, violation
/// (and infeasible: why not); also kdl_space.plan_capture's `optimum` and `nominal` dicts.
Json termsJson(const PlanTerms& terms);

/// The JSON object of a plan (keys are a contract: see the README).
Json planJson(const Scenario& scenario, const PlanOptions& options, const CapturePlan& plan);

}  // namespace kdl_space::report
