// The rules a URDF file must satisfy that are the readers' own (joint types, axes, limits, mimic
// joints, the depth of the tree and of the XML, unexpanded xacro), written once and shared by the
// loader and checkUrdfFile. The rules on the model itself (inertias, masses) are the model's:
// multibody/model_rules.hpp. Private to the library.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "multibody/model_rules.hpp"

namespace kdl_space::rules {

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

/// The largest |multiplier| of a <mimic>: a gear or a gripper's coupling is a few units; past it
/// the coupled inertia (multiplier^2 times the follower's) overflows in the dynamics.
constexpr double kMaxMimicMultiplier = 1e6;

/// \brief Note `mimic_joint`: a movable joint with <mimic> follows its leader (q = multiplier *
/// q_leader + offset): not a coordinate. Error `bad_mimic` when the leader is no movable joint
/// (`leader_movable`) or the multiplier is zero, not finite or beyond kMaxMimicMultiplier, or the
/// offset not finite.
void checkMimic(const std::string& joint, const std::string& leader, bool leader_movable, double multiplier,
                double offset, Findings& out);

/// \brief Error `bad_mimic` on a joint whose <mimic> chain (joint -> leader -> its leader ...)
/// comes back to itself: none of them is a coordinate. `follows` maps a mimic joint to its leader.
void checkMimicCycles(const std::vector<std::pair<std::string, std::string>>& follows, Findings& out);

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

}  // namespace kdl_space::rules
