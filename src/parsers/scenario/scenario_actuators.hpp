// The scenario loader's `robot.base_actuators`: the servicer's reaction wheels and thrusters as
// hardware (private to the library).
#pragma once

#include "kdl_space/parsers/scenario/scenario.hpp"
#include "parsers/scenario/scenario_fields.hpp"

namespace kdl_space::sections {

/// Reads and checks `robot.base_actuators`; InputError naming the field.
BaseActuators baseActuators(const fields::Field& f);

/// The base control against the actuators that must carry it: an attitude law needs wheels or
/// thrusters' torque, a position law thrusters' force (InputError naming `base_control_field`).
void checkBaseControlHardware(const BaseActuators& actuators, const BaseControl& control,
                              const fields::Field& base_control_field);

}  // namespace kdl_space::sections
