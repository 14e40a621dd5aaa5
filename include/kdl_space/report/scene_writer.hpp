// A 3-D picture of a scene (`kdl_space capture --scene FILE`, .svg or .png), drawn by gnuplot:
// one panel per snapshot side by side, in world coordinates, with the same axis ranges and equal
// scales in every panel. The robot is a stick figure (body frame origins joined parent to child,
// each movable joint's axis as a short arrow, each body's equivalent box of inertia), the contact
// and grasp points are markers, the target is its equivalent box and frame, or for a
// free-floating target its own stick figure.
#pragma once

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <kdl/frames.hpp>

#include "kdl_space/report/json.hpp"
#include "kdl_space/parsers/output_file.hpp"
#include "kdl_space/impact/collision.hpp"
#include "kdl_space/multibody/model.hpp"
#include "kdl_space/multibody/overlap.hpp"
#include "kdl_space/spatial/spatial.hpp"
#include "kdl_space/multibody/state.hpp"

namespace kdl_space::report {

/// A box: its centre and orientation (pose) and its edge lengths along its own axes [m].
struct SceneBox {
  KDL::Frame pose = KDL::Frame::Identity();
  Vector3d size = Vector3d::Zero();
};

/// One instant of the scene: a panel.
struct SceneSnapshot {
  std::string label;          ///< "start", "contact", "end", "impact"
  std::optional<double> t;    ///< the time [s], in the panel's title when given
  std::shared_ptr<const FloatingModel> robot;  ///< null: no robot drawn
  State robot_state;
  Contact robot_contact;      ///< body -1: no contact point drawn
  /// A rigid target: mass, inertia about its CoM (world axes), CoM (world), and the pose of its
  /// frame (drawn as three short axes).
  std::optional<RigidBody> target_body;
  KDL::Frame target_frame = KDL::Frame::Identity();
  /// A free-floating target (drawn as a stick figure, as the robot); null: none.
  std::shared_ptr<const FloatingModel> target_robot;
  State target_state;
  std::optional<Vector3d> grasp_point;  ///< world [m]
};

/// \brief The edges of the uniform box with the given mass and principal moments of inertia
/// (inertiaBoxEdges: the library's, which the overlap check uses too).
inline Vector3d equivalentBoxEdges(double mass, const Vector3d& principal_moments) {
  return inertiaBoxEdges(mass, principal_moments);
}

/// \brief The equivalent box of inertia of a body (inertiaBox): the box of uniform density with
/// the body's mass and principal moments, centred at its CoM, its edges along the principal axes.
/// `I_com`: inertia about the CoM in world axes; `com`: world. The box's axes are a right-handed
/// frame of eigenvectors (ascending moments: the first edge is the longest).
inline SceneBox equivalentBox(double mass, const Matrix3d& I_com, const Vector3d& com) {
  const OrientedBox box = inertiaBox(mass, I_com, com);
  return SceneBox{box.pose, box.size};
}

/// The gnuplot terminal for a scene file name and its number of panels (side by side); throws
/// UsageError naming `option` for another extension than .svg or .png.
std::string sceneTerminal(const std::string& path, std::size_t panels = 1, const std::string& option = "--scene");

/// \brief Draws the snapshots (one panel each, side by side) into file.tmp() with gnuplot (the
/// caller commits it). Throws UsageError for an extension other than .svg or .png, InputError
/// naming `option` and the file if the kinematics of a snapshot cannot be computed, gnuplot
/// fails or its scratch files cannot be written.
void writeScene(const AtomicFile& file, const std::vector<SceneSnapshot>& snapshots, const std::string& title,
                const std::string& option = "--scene");

}  // namespace kdl_space::report
