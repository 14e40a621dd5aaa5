// Building a FloatingModel from URDF (urdfdom + kdl_parser), keeping what kdl_parser drops.
#pragma once

#include <string>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/multibody/model.hpp"

namespace kdl_space {

/// \brief Loads a URDF file as a free-floating model; the root link is the base (satellite).
///
/// The root link's <inertial> (dropped by kdl_parser) is read from urdfdom and kept as the
/// base inertia. A `floating` joint from a massless root (e.g. "world") to its only child is
/// dropped and the child becomes the base (reported as a diagnostic); any other floating or
/// planar joint is refused. Nothing is printed: urdfdom's and kdl_parser's messages are
/// captured into the error or the diagnostics. The rules are checkUrdfFile's (urdf_check.hpp),
/// which reports every problem of a file at once; this throws at the first.
/// \throws ModelError whose message starts with the file name and names the link or joint.
KDL_SPACE_EXPORT FloatingModel loadUrdfFile(const std::string& path);

/// Same as loadUrdfFile for a URDF document in memory; `source` names it in messages; `notes` (what
/// a conversion to URDF assumed: readRobotDocument) come first among the model's diagnostics.
KDL_SPACE_EXPORT FloatingModel loadUrdfString(const std::string& xml, const std::string& source = "<urdf string>",
                                              std::vector<Diagnostic> notes = {});

}  // namespace kdl_space
