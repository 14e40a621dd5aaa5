// The scenario's `approach` section: how the hand reaches the grasp point before the capture.
// Private to the library (yaml-cpp is a private dependency).
#pragma once

#include "kdl_space/simulation/approach.hpp"
#include "parsers/scenario/scenario_fields.hpp"

namespace kdl_space::sections {

/// Reads and checks the `approach` section for the robot `robot`; InputError naming the field.
/// `grasp_position`: where approach.grasp.position is when omitted (none: it is required).
ApproachSpec approach(const fields::Field& f, const FloatingModel& robot, const KDL::Vector* grasp_position = nullptr);

}  // namespace kdl_space::sections
