// The approach's phases beside its resolved-rate control (private to runApproach): the pre-grasp
// move, and the cause of an approach that did not reach its grasp.
#pragma once

#include <functional>
#include <string>

#include "kdl_space/simulation/approach.hpp"

namespace kdl_space::approach_phases {

/// \brief The pre-grasp move (ApproachSpec::pre_grasp): the joints velocity-servoed (gains
/// rec.kv) along a JointMove to the inverse kinematics of the pre-grasp pose (the grasp frame at
/// the move's end backed off the standoff along its z; a free base where the move will leave it),
/// rate = the profile's + gain x the position error, within the rate limits. `rec` gets its
/// duration, joints and miss, or its cause when it cannot be made (then it returns 0 unrun).
/// \return 0 or the simulator's code. The caller clears the torque callback.
int preGrasp(Simulator& sim, ApproachController& controller, SimulationState& s, double output_dt, ApproachRecord& rec,
             const std::function<void(const SimulationState&)>& watch);

/// \brief Why an approach that ended at `s` did not reach its grasp, in words: out of the arm's
/// reach, a joint held at its limit guard, a singularity, saturated rates, or too slow (the first
/// that its record shows).
std::string approachCause(const ApproachRecord& r, ApproachController& controller, const FloatingModel& model,
                          const SimulationState& s);

}  // namespace kdl_space::approach_phases
