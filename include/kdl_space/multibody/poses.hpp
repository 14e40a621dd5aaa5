// Poses of links and contact frames from the per-state kinematics (forwardKinematics), and the
// figures a user reads off a pose (position, rotation matrix, quaternion, roll-pitch-yaw).
#pragma once

#include <Eigen/Core>
#include <kdl/frames.hpp>

#include "kdl_space/export.hpp"
#include "kdl_space/multibody/kinematics.hpp"

namespace kdl_space {

/// \brief One pose in the four forms a user meets: world position [m], rotation matrix
/// world_R_frame, unit quaternion (x, y, z, w) with w >= 0 (KDL::Rotation::GetQuaternion's order,
/// the order of every `*_quaternion` of the tools' JSON), and URDF roll-pitch-yaw about fixed axes
/// (R = Rz(yaw) Ry(pitch) Rx(roll)) [rad].
struct PoseFigures {
  Vector3d position = Vector3d::Zero();
  Matrix3d rotation = Matrix3d::Identity();
  Eigen::Vector4d quaternion = Eigen::Vector4d(0, 0, 0, 1);  ///< (x, y, z, w)
  Vector3d rpy = Vector3d::Zero();                           ///< (roll, pitch, yaw)
};

/// The four forms of `world_T_frame`.
KDL_SPACE_EXPORT PoseFigures poseFigures(const KDL::Frame& world_T_frame);

/// \brief The contact frame of `h`: its origin at the contact point, its axes the link's
/// (world_T_link * Frame(offset)). `kin` must hold a successful forwardKinematics and h.body
/// must be one of its bodies (contactCode checks both). The one definition of a contact frame:
/// the overload below, inverse kinematics and the tools all come here.
inline KDL::Frame contactFrame(const Kinematics& kin, const Contact& h) {
  return kin.pose(h.body) * KDL::Frame(h.offset);
}

/// \brief The contact frame of `contact` at `state` (the base where the state puts it): the
/// overload above on a Kinematics of its own (it allocates: for a loop over states keep one).
/// \throws ModelError for a state of the wrong size or a contact body outside the model.
KDL_SPACE_EXPORT KDL::Frame contactFrame(const FloatingModel& model, const State& state, const Contact& contact);

/// \brief The world pose of link `body` (index into model.bodies()) at `state`, the base where
/// the state puts it: forwardKinematics into a Kinematics of its own (it allocates: for a loop
/// over states keep one Kinematics and read Kinematics::pose).
/// \return 0; E_BAD_CONTACT for a body outside [0, bodies); forwardKinematics' codes.
KDL_SPACE_EXPORT int linkPose(const FloatingModel& model, const State& state, int body, KDL::Frame& world_T_link);

}  // namespace kdl_space
