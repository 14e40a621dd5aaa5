// The scenario loader's `law` section: the impact law, and a compliant law's spring-damper grasp
// (private to the library).
#pragma once

#include "kdl_space/impact/impact.hpp"
#include "kdl_space/simulation/compliant_capture.hpp"
#include "parsers/scenario/scenario_fields.hpp"

namespace kdl_space::laws {

/// The impact law; `has_normal` is set when a normal is given. A compliant law's is its impulsive
/// limit, a rigid capture.
ImpactLaw law(const fields::Field& f, bool& has_normal);

/// `law.max_grasp_wrench: {force, moment}` into `force` [N] and `moment` [N m] (each left as it
/// is when not given); refused with a law that holds nothing (a point or frictional impact).
void graspLimit(const fields::Field& f, double& force, double& moment);

/// `law: {type: compliant}`: the hand's spring-damper, every field optional (CompliantGrasp's
/// defaults, a stiff gripper).
CompliantGrasp compliantLaw(const fields::Field& f);

}  // namespace kdl_space::laws
