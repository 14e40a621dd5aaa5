// The rules a description must satisfy to be a free-floating model, written once and shared:
// the loader and FloatingModel throw at the first error (and keep the warnings as diagnostics),
// checkUrdfFile reports every finding. Private to the library.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "kdl_space/diagnostics.hpp"

namespace kdl_space::rules {

using Findings = std::vector<Finding>;

Finding error(std::string kind, ElementType type, std::string element, std::string message);
Finding warning(std::string kind, ElementType type, std::string element, std::string message);

/// A number as the findings print it (the stream's default: 6 significant digits).
std::string number(double v);

/// \brief What an inertia about a CoM is: its principal moments (ascending) and the first rule
/// it breaks. The one test of links, rigid targets and payloads; each caller words the verdict.
struct InertiaVerdict {
  enum Kind { Ok, NotFinite, NotPositiveDefinite, TriangleInequality } kind = Ok;  ///< of the symmetric part
  bool symmetric = true;
  Eigen::Vector3d moments = Eigen::Vector3d::Zero();  ///< principal moments of the symmetric part, ascending
};
/// Symmetric means |I - I^T| <= 1e-12 |I| (Frobenius); the triangle inequality is checked with a
/// relative slack of 1e-9.
InertiaVerdict judgeInertia(const Eigen::Matrix3d& I);

/// \brief Inertial values of one link: mass [kg] and inertia about the CoM [kg m^2], any axes
/// (only its principal moments matter). Errors: `not_finite`, `non_positive_mass` (negative, or
/// zero with a rotational inertia), `inertia_not_positive_definite`, `triangle_inequality`.
void checkInertia(const std::string& link, double mass, const Eigen::Matrix3d& I_com, Findings& out);

/// \brief A free-floating base needs its mass: `base_without_mass` when `mass` is 0 (a negative
/// mass is checkInertia's; NaN, an unreadable value, is reported where it was read).
void checkBaseMass(const std::string& base, double mass, Findings& out);

/// \brief Warning `root_inertia_dropped_by_kdl_parser` when the base is the URDF root link and
/// has an <inertial>.
void checkRootInertia(const std::string& root, bool has_inertial, Findings& out);

/// \brief True when the root's joint to its only child is dropped: a `floating` joint from a
/// massless root (such as "world"), whose child then is the free-floating base.
bool dropsRootJoint(bool root_massless, std::size_t root_child_joints, const std::string& child_joint_type);

/// \brief Joint types (URDF names): `free_joint_inside` for a floating or planar joint (other
/// than the root joint dropped by dropsRootJoint, which callers skip).
void checkJointType(const std::string& joint, const std::string& type, Findings& out);

/// True for the joint types that move (revolute, continuous, prismatic).
bool isMovable(const std::string& type);

/// \brief Joint axis of a movable joint: `zero_axis` (error), `axis_not_unit` (warning: the axis
/// is normalised).
void checkAxis(const std::string& joint, const Eigen::Vector3d& axis, Findings& out);

/// \brief Joint limits of a revolute or prismatic joint: `limits_exclude_zero` (warning).
void checkLimits(const std::string& joint, double lower, double upper, Findings& out);

/// One link of a tree for checkMassDistribution; node 0 is the base, parents precede children.
struct MassNode {
  std::string link;
  int parent = -1;
  std::string joint;     ///< the joint from the parent
  bool movable = false;  ///< that joint moves
  double mass = 0.0;     ///< [kg]; NaN when unknown (not read), which no rule below reports
};

/// \brief Massless links: `non_positive_mass` for a massless link whose movable joint moves
/// only massless links (its inertia is zero, H* singular); warning `massless_link` for the
/// other massless links below the base.
void checkMassDistribution(const std::vector<MassNode>& nodes, Findings& out);

/// The deepest tree (joints from the base to a link) read safely: kdl_parser recurses once per
/// level, and a deeper chain overflows the stack.
constexpr int kMaxTreeDepth = 1000;

/// \brief `too_deep` for `link`, `depth` joints below the base, beyond kMaxTreeDepth.
void checkDepth(const std::string& link, int depth, Findings& out);

/// The deepest XML element nesting read: TinyXML (urdfdom's parser, and checkUrdfFile's)
/// recurses once per level, and a deeper document overflows the stack. A URDF nests 4 or 5.
constexpr int kMaxXmlDepth = 2000;

/// \brief Empty when TinyXML can read `xml` without nesting deeper than kMaxXmlDepth; otherwise
/// why not, a sentence that follows "not XML that can be read safely: ". A text with at most
/// kMaxXmlDepth element tags is safe whatever it holds; a larger one is measured by expat, and
/// must then be well-formed and free of DOCTYPE and processing instructions (the constructs
/// TinyXML reads differently from XML, where elements could hide from the measurement).
std::string xmlDepthProblem(const std::string& xml);

/// The first error of `findings`, or nullptr.
const Finding* firstError(const Findings& findings);

}  // namespace kdl_space::rules
