// A URDF's <visual> geometry per link (what a viewer draws; the dynamics never reads it).
#pragma once

#include <Eigen/Core>
#include <kdl/frames.hpp>

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "kdl_space/export.hpp"

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

/// Where a mesh's filename points: `path` the regular file found, or "" and `problem` saying why.
struct MeshLocation {
  std::string path;
  std::string problem;
};

/// \brief The file a URDF mesh's `filename` names (what ROS tools read), without reading it:
/// - `package://PKG/REST`: the first folder D of `package_path`, in order, where D/PKG/REST is a
///   file, or, for a D named PKG itself (a package's own folder, as ROS_PACKAGE_PATH may list),
///   D/REST. Packages are not searched for below D (no crawl for package.xml: a workspace's
///   `src` folder holding its packages one level down works; deeper ones are listed themselves).
/// - `file:///ABS`: /ABS; an absolute path: itself; a relative path: from `urdf_dir`.
/// - any other scheme (http://, ...): not found.
/// The library reads no environment variable: the caller builds `package_path` (the tool: its
/// --mesh-path folders, then ROS_PACKAGE_PATH).
KDL_SPACE_EXPORT MeshLocation resolveMeshFile(const std::string& filename, const std::string& urdf_dir,
                                              const std::vector<std::string>& package_path);

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
