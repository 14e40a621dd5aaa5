// Gazebo's model files (SDFormat, read by Debian's libsdformat): one model, a tree of links rooted
// at its canonical link, read as the URDF document the loader checks (one set of rules for every
// format; loadRobotFile, robot_file.hpp, loads any of them).
#pragma once

#include <string>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/multibody/diagnostics.hpp"

namespace kdl_space {

/// \brief The SDF file `path` (one <model>, or a URDF file, which SDFormat converts) as one URDF
/// document. Each link's frame becomes its URDF frame moved to the joint that carries it (a URDF
/// joint frame is its child link's frame): inertials, visuals and child joints are re-expressed;
/// the root is the canonical link. Revolute, continuous, prismatic and fixed joints are read with
/// their limits, damping and friction (SDFormat's "no limit" defaults read as none); a joint to
/// `world` is dropped (the base floats) with a note; box, cylinder, sphere and mesh visuals are
/// kept (a mesh's relative or file:// URI made absolute; a model:// URI left out, noted).
/// \param notes gets what was assumed (Severity::Note), each naming its link or joint.
/// \throws InputError "FILE[:LINE]: what" for SDFormat's errors, a world or several models, a
/// nested model, a ball, universal, screw or other joint, links not reached from the canonical link.
KDL_SPACE_EXPORT std::string sdfToUrdf(const std::string& path, std::vector<Diagnostic>& notes);

}  // namespace kdl_space
