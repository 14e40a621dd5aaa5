// The scenario's `approach` section: how the hand reaches the grasp point before the capture.
// Private to the library (yaml-cpp is a private dependency).
#pragma once

#include "kdl_space/simulation/approach.hpp"
#include "parsers/scenario/scenario_fields.hpp"

namespace kdl_space::sections {

/// Reads and checks the `approach` section for the robot `robot`; InputError naming the field.
ApproachSpec approach(const fields::Field& f, const FloatingModel& robot);

}  // namespace kdl_space::sections
