// A URDF document written from links and joints: what the readers of other formats (SDF,
// SpaceDyn's LP) hand to the URDF loader, so one set of rules checks every model. Private to parsers/.
#pragma once

#include <Eigen/Core>
#include <kdl/frames.hpp>
#include <optional>
#include <string>
#include <vector>

#include "kdl_space/multibody/model.hpp"

class TiXmlElement;

namespace kdl_space::formats {

/// A link's <inertial>: `mass` [kg] and `inertia` about the CoM in the axes of `origin` (in the link frame).
struct UrdfInertial {
  double mass = 0.0;
  KDL::Frame origin = KDL::Frame::Identity();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
};

/// A <visual>: one geometry ("box", "cylinder", "sphere", "mesh") at `origin` in the link frame.
struct UrdfVisual {
  KDL::Frame origin = KDL::Frame::Identity();
  std::string geometry;               ///< box | cylinder | sphere | mesh
  Eigen::Vector3d size = Eigen::Vector3d::Zero();  ///< box: edges; cylinder: (radius, length, 0); sphere: (radius, 0, 0); mesh: scale
  std::string mesh;                   ///< mesh: an absolute file name
  std::optional<Eigen::Vector4d> rgba;
};

struct UrdfLink {
  std::string name;
  std::optional<UrdfInertial> inertial;
  std::vector<UrdfVisual> visuals;
};

/// A joint: `origin` is the child link's frame in the parent link's frame, `axis` in the child's.
struct UrdfJoint {
  std::string name, type, parent, child;  ///< type: revolute | continuous | prismatic | fixed
  KDL::Frame origin = KDL::Frame::Identity();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  JointProperties properties;             ///< limits written where finite, dynamics where not zero
};

/// The document: <robot name>, the links, then the joints, numbers to 17 digits (read back exactly).
std::string urdfText(const std::string& robot, const std::vector<UrdfLink>& links, const std::vector<UrdfJoint>& joints);

/// Appends `in` to the URDF <link> element `link` as its <inertial> (origin, mass, the inertia's upper triangle).
void appendInertial(TiXmlElement& link, const UrdfInertial& in);

/// An XML document of `root` (declaration, two-space indent): what the URDF writers return.
std::string xmlText(const TiXmlElement& root);

/// "%.17g": a double written so that it reads back exactly.
std::string exactNumber(double v);

/// \brief URDF's roll, pitch, yaw of `R` (R = Rz(yaw) Ry(pitch) Rx(roll)), such that the rotation
/// they make is R to round-off even near pitch = +-pi/2, where KDL's GetRPY approximates (about
/// 1e-8 rad there): roll from R's last row, pitch, then yaw from what is left, Rz(yaw) = R (Ry Rx)^T.
KDL::Vector urdfRpy(const KDL::Rotation& R);

}  // namespace kdl_space::formats
