// A URDF's <visual> geometry per link (what a viewer draws; the dynamics never reads it).
#pragma once

#include <Eigen/Core>
#include <kdl/frames.hpp>

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/parsers/urdf/mesh_file.hpp"

namespace kdl_space {

/// One <visual> of a link: its shape, its pose in the link's frame and its colour.
struct LinkVisual {
  enum class Shape { Box, Cylinder, Sphere, Mesh };
  Shape shape = Shape::Box;
  /// Box: its edges; cylinder: radius, length (along the visual's z), 0; sphere: radius, 0, 0 [m].
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  std::string mesh_file;                                    ///< a mesh's filename, as written
  Eigen::Vector3d mesh_scale = Eigen::Vector3d::Ones();     ///< a mesh's scale
  std::string mesh_path;     ///< the file mesh_file resolves to (resolveMeshFile); "" when not found
  std::string mesh_problem;  ///< why it was not found ("" when it was)
  KDL::Frame origin = KDL::Frame::Identity();               ///< link_T_visual
  std::optional<Eigen::Vector4d> rgba;                      ///< the material's colour, when given
};

/// \brief Every link's visuals, by link name (links without one are absent). A material named
/// on a visual without a colour of its own takes the colour of the robot-level material of that
/// name. A mesh's file is resolved (resolveMeshFile, relative paths from the URDF's folder)
/// through `package_path`. \throws ModelError naming the file when it cannot be read or is no
/// URDF (the loader's messages).
KDL_SPACE_EXPORT std::map<std::string, std::vector<LinkVisual>> readUrdfVisuals(
    const std::string& path, const std::vector<std::string>& package_path = {});

/// Same for a URDF document in memory; `source` names it in messages, and its folder is where
/// relative mesh paths start.
KDL_SPACE_EXPORT std::map<std::string, std::vector<LinkVisual>> readUrdfVisualsString(
    const std::string& xml, const std::string& source, const std::vector<std::string>& package_path = {});

}  // namespace kdl_space
