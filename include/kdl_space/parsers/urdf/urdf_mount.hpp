// An arm (or several) mounted on a satellite bus: the bus as a mass, an inertia and a box (or its
// own URDF), each arm's URDF file as its vendor wrote it, joined into one URDF document (the arm's
// root link on a bus link by a fixed joint at a pose). What a scenario's `robot.mount` loads and
// `kdl_space mount` writes. Names are kept; an arm whose names clash with the bus's or an earlier
// arm's is prefixed ("arm2/"), and a note says so.
#pragma once

#include <Eigen/Core>
#include <kdl/frames.hpp>
#include <string>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/multibody/diagnostics.hpp"

namespace kdl_space {

/// The bus: a URDF file (`urdf`), or one rigid link `name` of `mass`, `inertia` about its CoM and
/// `com` (in the link frame), drawn as a box of `box` (x, y, z) [m] centred on the CoM when given.
struct BusBody {
  std::string urdf;  ///< the bus as a URDF file (its root link is the base); else the fields below
  std::string name = "bus";
  double mass = 0.0;                                   ///< [kg] > 0
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();   ///< [kg m^2] about the CoM, link axes
  Eigen::Vector3d com = Eigen::Vector3d::Zero();       ///< [m] link frame
  Eigen::Vector3d box = Eigen::Vector3d::Zero();       ///< [m] a box drawn at the CoM; zero: none
};

/// \brief The inertia about its centre of a uniform box of `mass` [kg] and edges `size` [m]:
/// m/12 diag(y² + z², x² + z², x² + y²).
KDL_SPACE_EXPORT Eigen::Matrix3d boxInertia(double mass, const Eigen::Vector3d& size);

/// One arm on the bus.
struct ArmMount {
  std::string urdf;     ///< the arm's URDF file (its root link goes on the bus)
  std::string link;     ///< the bus link it hangs on; empty: the bus's root link
  KDL::Frame pose = KDL::Frame::Identity();  ///< the arm root link's frame in that link's frame
};

/// The joined document and what was assumed on the way.
struct MountedRobot {
  std::string urdf;               ///< one URDF document: the bus, then each arm
  std::vector<Diagnostic> notes;  ///< names prefixed, mesh paths made absolute (Severity::Note)
  std::vector<std::string> files; ///< the files read: the bus's URDF (if any), then each arm's
};

/// \brief Joins `arms` to `bus` into one URDF document. Each arm's links, joints and materials are
/// copied as written (mimic joints, limits, visuals, collisions); a relative mesh path becomes
/// absolute (from its URDF's folder); the arm's root link hangs on its bus link by a fixed joint
/// "<root>_mount" at its pose. An arm whose link, joint or material names meet names already in
/// the document is prefixed "armK/" (K from 1, in the list's order), all of them, with a note.
/// \throws InputError naming the file (and line) when a URDF cannot be read, has no single root
/// link, or a bus link is missing; the bus's mass not > 0, its inertia or box not finite.
KDL_SPACE_EXPORT MountedRobot mountArms(const BusBody& bus, const std::vector<ArmMount>& arms);

}  // namespace kdl_space
