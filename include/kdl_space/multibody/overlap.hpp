// Oriented boxes as a coarse bound of a body's geometry (a link's visual bounded by a box, or its
// box of inertia) and how deep two of them penetrate (the separating-axis test): what warns that
// a robot link sits inside its target at the start or at the capture.
#pragma once

#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/multibody/model.hpp"
#include "kdl_space/spatial/spatial.hpp"

namespace kdl_space {

/// \brief A box: its centre and axes (pose: frame_T_box, in the frame the box is given in) and its
/// edge lengths along its own axes [m] (0 for a flat or thin body's missing extent).
struct OrientedBox {
  KDL::Frame pose = KDL::Frame::Identity();
  Vector3d size = Vector3d::Zero();
};

/// \brief The edges of the uniform box with the given mass and principal moments of inertia
/// (about its centre): edge k = sqrt(6 (I_i + I_j - I_k) / m), {i, j, k} = {0, 1, 2} (from
/// I_k = m (a_i^2 + a_j^2) / 12); an edge is 0 where the moments break the triangle inequality by
/// round-off (a flat or thin body), all are 0 without a mass.
KDL_SPACE_EXPORT Vector3d inertiaBoxEdges(double mass, const Vector3d& principal_moments);

/// \brief A body's box of inertia: the box of uniform density with its mass and principal moments,
/// centred at its CoM, its edges along the principal axes. `I_com` (about the CoM) and `com` in the
/// same frame, in which the box is returned. The axes are a right-handed frame of eigenvectors
/// (ascending moments: the first edge is the longest).
KDL_SPACE_EXPORT OrientedBox inertiaBox(double mass, const Matrix3d& I_com, const Vector3d& com);

/// \brief How deep two boxes (in one frame) penetrate: the least, over the separating-axis test's
/// 15 axes (the 3 + 3 face normals and the 9 cross products of an edge of each), of the overlap of
/// their projections, (r_a + r_b) - |d . L| (L a unit axis, d between the centres, r each box's
/// half-extent along L). This is the length of the shortest translation along those axes that
/// separates them (the minimal translation depth). > 0: they overlap by that much; <= 0: an axis
/// separates them (-value is then a lower bound of their distance). A box inside another: the
/// least distance by which it must move to get out. Cross products of (nearly) parallel edges are
/// skipped (their face normals already test that direction).
KDL_SPACE_EXPORT double penetrationDepth(const OrientedBox& a, const OrientedBox& b);

/// \brief `box` (in the frame of a body whose world pose is `world_T_body`) in world terms.
inline OrientedBox inWorld(const KDL::Frame& world_T_body, const OrientedBox& box) {
  return OrientedBox{world_T_body * box.pose, box.size};
}

/// \brief Each body's box of inertia in its own frame (model order): one box, or none for a body
/// without mass (a frame: nothing to bound).
KDL_SPACE_EXPORT std::vector<std::vector<OrientedBox>> inertiaBoxes(const FloatingModel& model);

/// \brief The bodies that touch by design at a contact on `contact_body`: that body, those welded
/// to it by fixed joints (a tool frame and its flange, up to but not past a moving joint or the
/// base) and every body below them (fingers). A contact on the base marks the base alone (and its
/// welded children). Model order, size bodies().
KDL_SPACE_EXPORT std::vector<bool> contactBodies(const FloatingModel& model, int contact_body);

/// One body's deepest penetration into an obstacle.
struct BoxPenetration {
  int body = -1;       ///< the body (model order)
  int obstacle = -1;   ///< index into the obstacles
  double depth = 0.0;  ///< penetrationDepth [m]
};

/// \brief For every body at `kin` (not marked in `skip`, which may be empty), the deepest
/// penetration of its boxes (`link_boxes[body]`, in the body's frame) into any of `obstacles`
/// (world), kept when deeper than `allowance` [m]; deepest first. `link_boxes` has one entry per
/// body (fewer: the rest have none). Pure; not for a hot path (it allocates its answer).
KDL_SPACE_EXPORT std::vector<BoxPenetration> penetrations(const Kinematics& kin,
                                                          const std::vector<std::vector<OrientedBox>>& link_boxes,
                                                          const std::vector<OrientedBox>& obstacles,
                                                          const std::vector<bool>& skip, double allowance);

}  // namespace kdl_space
