// The scenario's `robot.mount`: the robot's arm (or arms) on a satellite bus given as a mass and a
// box, an inertia, or its own URDF (mountArms, urdf_mount.hpp). Private to the library (yaml-cpp
// is a private dependency).
#pragma once

#include <string>

#include "kdl_space/parsers/urdf/urdf_mount.hpp"
#include "parsers/scenario/scenario_fields.hpp"

namespace kdl_space::sections {

/// A file's path as written at `f` (not empty), relative to `folder` unless absolute.
std::string filePath(const fields::Field& f, const std::string& folder);

/// \brief The robot `f` (robot: {urdf, mount: {bus, link, pose}}, or robot: {mount: {bus, arms:
/// [{urdf, link, pose}, ...]}}) joined into one URDF document. InputError naming the field.
MountedRobot mounted(const fields::Field& f, const std::string& folder);

}  // namespace kdl_space::sections
