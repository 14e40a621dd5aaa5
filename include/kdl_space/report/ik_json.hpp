// The JSON of an inverse-kinematics solution (`ik --json`, kdl_space.ik's dict). Keys are a contract.
#pragma once

#include <kdl/frames.hpp>

#include "kdl_space/algorithm/inverse_kinematics.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/report/json.hpp"

namespace kdl_space::report {

/// The solution's keys (joint_names, q, q_by_name, moved_joints, the residuals, iterations,
/// attempts, preference_gradient, reaction_measure); also kdl_space.ik's dict.
Json ikSolutionJson(const FloatingModel& model, const IkResult& result);

/// The JSON object of a solution: the scenario, contact and goal, then ikSolutionJson (keys are a
/// contract: see the README).
Json ikJson(const Scenario& scenario, const KDL::Frame& goal, const IkResult& result);

}  // namespace kdl_space::report
