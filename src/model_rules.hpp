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
Finding note(std::string kind, ElementType type, std::string element, std::string message);

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

/// Round-off in an inertia: a principal moment within max(kRoundOffRelative * the largest,
/// mass * kRoundOffLength^2) of zero is read as zero.
constexpr double kRoundOffRelative = 1e-6;
constexpr double kRoundOffLength = 1e-3;  ///< [m]

/// \brief Inertial values of one link: mass [kg] and inertia about the CoM [kg m^2], any axes
/// (only its principal moments matter). Errors: `not_finite`, `non_positive_mass` (negative, or
/// zero with a rotational inertia), `inertia_not_positive_definite` (a negative principal moment
/// beyond round-off). Warnings, for what is read as it is written or within round-off:
/// `point_mass` (no rotational inertia beyond m 1e-12 m^2), `inertia_round_off` (a principal moment zero or
/// negative within round-off: read as 0), `triangle_inequality` (I1 + I2 < I3, with the amount).
/// The composite bodies are what must be positive definite, not every link.
void checkInertia(const std::string& link, double mass, const Eigen::Matrix3d& I_com, Findings& out);

/// The inertia as the model reads it: negative principal moments (round-off, which checkInertia
/// lets pass) set to zero; otherwise unchanged.
Eigen::Matrix3d withoutNegativeMoments(const Eigen::Matrix3d& I);

/// \brief Note `root_inertia_dropped_by_kdl_parser` when the base is the URDF root link and has
/// an <inertial> (kdl_space keeps it; tools built on kdl_parser alone would not).
void checkRootInertia(const std::string& root, bool has_inertial, Findings& out);

/// \brief True when the root's joint to its only child is dropped: a `floating` or `planar`
/// joint (a mobile base's) from a massless root (such as "world"), whose child then is the
/// free-floating base.
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

/// \brief Warning `revolute_without_limit`: a revolute joint without <limit> (urdfdom refuses
/// it) is read as continuous.
void checkRevoluteWithoutLimit(const std::string& joint, Findings& out);

/// \brief Note `mimic_joint`: a movable joint with <mimic> follows its leader (q = multiplier *
/// q_leader + offset): not a coordinate. Error `bad_mimic` when the leader is no movable joint
/// (`leader_movable`) or the multiplier is zero or not finite, or the offset not finite.
void checkMimic(const std::string& joint, const std::string& leader, bool leader_movable, double multiplier,
                double offset, Findings& out);

/// \brief Error `bad_mimic` on a joint whose <mimic> chain (joint -> leader -> its leader ...)
/// comes back to itself: none of them is a coordinate. `follows` maps a mimic joint to its leader.
void checkMimicCycles(const std::vector<std::pair<std::string, std::string>>& follows, Findings& out);

/// One link of a tree for the mass rules below; node 0 is the base, parents precede children.
struct MassNode {
  std::string link;
  int parent = -1;
  std::string joint;     ///< the joint from the parent
  bool movable = false;  ///< that joint moves
  double mass = 0.0;     ///< [kg]; NaN when unknown (not read), which no rule below reports
  double armature = 0.0; ///< rotor inertia of that joint (a joint with one is a coordinate)
};

/// \brief The rigid bodies of the dynamics are composites: a link and every link joined to it
/// by fixed joints. The nodes of the composite of node `head` (itself first), in node order.
std::vector<int> composite(const std::vector<MassNode>& nodes, int head);

/// \brief The base composite (the root and every link fixed to it) needs mass:
/// `base_without_mass` naming its links when their masses add up to 0.
void checkBaseComposite(const std::vector<MassNode>& nodes, Findings& out);

/// \brief Massless links. Warning `joint_moves_no_mass` for each movable joint without
/// armature that moves only massless links (no inertia: H* would be singular): the model treats
/// it as fixed at q = 0. Note `massless_link` for the other massless links below the base.
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

/// \brief Empty when `xml` is not an unexpanded xacro file; otherwise what gives it away (a
/// <xacro:...> element, ${...}, $(arg ...) or $(find ...) outside comments; not the xmlns:xacro
/// attribute, which xacro's output keeps) and on which line.
std::string xacroProblem(const std::string& xml);

/// The first error of `findings`, or nullptr.
const Finding* firstError(const Findings& findings);

}  // namespace kdl_space::rules
