// The scenario loader's `simulation` section (private to the library).
#pragma once

#include "kdl_space/scenario.hpp"
#include "scenario_fields.hpp"

namespace kdl_space::sections {

/// Reads and checks the `simulation` section for the robot `robot`; InputError naming the field.
SimulationSpec simulation(const fields::Field& f, const FloatingModel& robot);

}  // namespace kdl_space::sections
