// A URDF mesh's file: where its `filename` points, kept inside the folders the user named, and its
// bytes read for a page that a user may share (nothing else on the disk, nothing fetched later).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "kdl_space/export.hpp"

namespace kdl_space {

/// The largest mesh file that is read: 64 MiB, as a URDF (the largest robots' meshes are a few MB;
/// a page holds it in base64, a third more, and the reader about five times it at its peak).
inline constexpr std::uintmax_t max_mesh_file_bytes = std::uintmax_t{64} << 20;

/// Where a mesh's filename points: `path` the regular file found (canonical: no link, no `..`), or
/// "" and `problem` saying why.
struct MeshLocation {
  std::string path;
  std::string problem;
};

/// \brief The file a URDF mesh's `filename` names (what ROS tools read), without reading it:
/// - `package://PKG/REST`: the first folder D of `package_path`, in order, where D/PKG/REST is a
///   file, or, for a D named PKG itself (a package's own folder, as ROS_PACKAGE_PATH may list),
///   D/REST. Packages are not searched for below D (no crawl for package.xml: a workspace's
///   `src` folder holding its packages one level down works; deeper ones are listed themselves).
///   A PKG or REST that climbs out (`..`) or is absolute (`package://pkg//etc/x.stl`) is refused.
/// - `file:///ABS`: /ABS; an absolute path: itself; a relative path: from `urdf_dir`.
/// - any other scheme (http://, ...): not found.
/// The file found must be, once every link in its path is followed, a regular file of at most
/// max_mesh_file_bytes inside `urdf_dir` or one of the `package_path` folders (themselves
/// resolved): a mesh that is a link to /etc/passwd, or a path out of those folders, is refused
/// with the folder it resolves to and what to do (name its folder in the search path).
/// The library reads no environment variable: the caller builds `package_path` (the tool: its
/// --mesh-path folders, then ROS_PACKAGE_PATH).
KDL_SPACE_EXPORT MeshLocation resolveMeshFile(const std::string& filename, const std::string& urdf_dir,
                                              const std::vector<std::string>& package_path);

/// A mesh file's bytes, for a page (readMeshFile).
struct MeshBytes {
  std::string bytes;    ///< the file, with what would be fetched from elsewhere removed; "" if not read
  std::string problem;  ///< why it was not read ("" when it was)
  std::string dropped;  ///< what was removed ("" when nothing): "3 texture images (<library_images>)"
};

/// \brief Reads the mesh file at `path` (a path resolveMeshFile returned) for a page that is
/// shared: opened without following a link at its name, a regular file of at most
/// max_mesh_file_bytes (checked on the open file), not empty. From a COLLADA file (`dae`) every
/// reference to another file or a URL is removed (its <library_images>: textures, which a browser
/// would fetch); the geometry stays. Never throws for a file's content.
KDL_SPACE_EXPORT MeshBytes readMeshFile(const std::string& path, bool dae);

}  // namespace kdl_space
