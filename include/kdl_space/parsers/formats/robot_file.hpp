// A robot's description in any format kdl_space reads: URDF, SDF (Gazebo), MJCF (MuJoCo) or
// SpaceDyn's LP function; what every command and Python take where they take a URDF file.
#pragma once

#include <string>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/multibody/diagnostics.hpp"
#include "kdl_space/multibody/model.hpp"
#include "kdl_space/parsers/urdf/urdf_check.hpp"

namespace kdl_space {

enum class RobotFormat { Urdf, Sdf, Mjcf, SpaceDyn };

/// "URDF", "SDF", "MJCF", "SpaceDyn LP".
KDL_SPACE_EXPORT const char* formatName(RobotFormat format);

/// \brief The format of `path`: ".urdf", ".sdf", ".m" (SpaceDyn's LP), ".mjcf"; for ".xml" and any
/// other name, the document's root element (<robot>, <sdf>, <mujoco>) of a regular file; URDF if none
/// says otherwise.
KDL_SPACE_EXPORT RobotFormat robotFormat(const std::string& path);

/// \brief What `path` is called in messages, by its name alone (nothing is read): "SDF file", "SpaceDyn LP
/// file", "MJCF or URDF file" (.xml), "MJCF file", else "URDF file".
KDL_SPACE_EXPORT std::string robotFileKind(const std::string& path);

/// A description read as a URDF document: the file's own text for a URDF, else the conversion.
struct RobotDocument {
  RobotFormat format = RobotFormat::Urdf;
  std::string urdf;               ///< the URDF document (empty for a URDF file: read the file itself)
  std::vector<Diagnostic> notes;  ///< what the conversion assumed (Severity::Note)
};

/// \brief `path` in its format (robotFormat) as a URDF document (sdfToUrdf, mjcfToUrdf, spaceDynToUrdf).
/// \throws InputError naming the file, line and field as the format's reader does.
KDL_SPACE_EXPORT RobotDocument readRobotDocument(const std::string& path);

/// \brief The model of `path` in any format: loadUrdfFile for a URDF, else the URDF document of
/// readRobotDocument loaded with the file's name in messages, its notes among the diagnostics.
KDL_SPACE_EXPORT FloatingModel loadRobotFile(const std::string& path);

/// \brief checkUrdfFile for a description in any format: a URDF file as it is; another format's
/// URDF document (its reader's refusal an error `unreadable` naming the file and line; what it
/// assumed, notes `converted`). Never throws (beyond std::bad_alloc).
KDL_SPACE_EXPORT UrdfReport checkRobotFile(const std::string& path, const std::vector<std::string>& tips = {});

}  // namespace kdl_space
