// Reading a URDF document element by element as urdfdom reads it (TinyXML), reporting everything
// urdfdom would refuse at once, where the loader stops at the first. The checker's reader; the
// graph of its links and joints is urdf_graph.hpp's. Private to the library.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "kdl_space/multibody/diagnostics.hpp"
#include "parsers/urdf/urdf_graph.hpp"

namespace kdl_space::detail {

/// A <link> with a unique name, as far as the checker needs it.
struct XmlLink {
  std::string name;
  int row = 0;                ///< line in the document
  bool has_inertial = false;
  double mass = 0.0;          ///< [kg]; NaN when its <inertial> has no readable mass
  bool inertia_read = false;  ///< mass, CoM and inertia below were read
  Eigen::Vector3d com = Eigen::Vector3d::Zero();    ///< CoM, link frame [m]
  Eigen::Matrix3d I_com = Eigen::Matrix3d::Zero();  ///< inertia about the CoM, link axes [kg m^2]
};

/// A <joint> with a unique name, as far as the checker needs it.
struct XmlJoint {
  std::string name;
  int row = 0;                ///< line in the document
  std::string type;           ///< as written ("" if missing)
  bool known_type = false;    ///< a URDF joint type
  std::string parent, child;  ///< link names ("" if missing)
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  ///< <origin>: the child frame's axes in the parent's
  Eigen::Vector3d p = Eigen::Vector3d::Zero();      ///< <origin>: its origin in the parent frame [m]
  bool has_mimic = false;     ///< a readable <mimic joint=...> (checked once all joints are read)
  std::string mimic_leader;
  double mimic_multiplier = 1.0, mimic_offset = 0.0;
};

/// What readUrdfXml read.
struct UrdfDocument {
  std::string robot;             ///< the <robot> name ("" if missing)
  int link_elements = 0;         ///< <link> elements, named or not
  int joint_elements = 0;        ///< <joint> elements, named or not
  std::vector<XmlLink> links;    ///< in document order
  std::vector<XmlJoint> joints;  ///< in document order
  /// Every <link> and <joint> has a name of its own and every joint names both its links: the
  /// graph holds the whole description.
  bool names_complete = true;
};

/// \brief Reads `xml` as urdfdom reads it: the document, the robot, every link, joint and
/// material, every number attribute; appends to `findings`, in document order, whatever urdfdom
/// would refuse and the shared rules' findings (urdf_rules.hpp, model_rules.hpp) on the inertias, axes and limits
/// as read. False when the text is not a URDF document at all (nothing was read).
bool readUrdfXml(const std::string& xml, UrdfDocument& doc, std::vector<Finding>& findings);

/// \brief The document as the loader hands it to urdfdom: every revolute joint without <limit>
/// (which urdfdom refuses) made continuous, their names appended to `changed`; `xml` itself when
/// there is none (or when it is not a URDF document: urdfdom says what is wrong).
std::string withUnlimitedRevolutesContinuous(const std::string& xml, std::vector<std::string>& changed);

/// The document's links and joints as a graph, in document order (the checker's view).
LinkGraph linkGraph(const UrdfDocument& doc);

}  // namespace kdl_space::detail
