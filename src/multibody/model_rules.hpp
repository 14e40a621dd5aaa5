// The rules a description must satisfy to be a free-floating model (the inertias and masses of its
// links and rigid bodies), written once and shared: the loader and FloatingModel throw at the first
// error (and keep the warnings as diagnostics), checkUrdfFile reports every finding. The URDF
// readers' own rules are parsers/urdf/urdf_rules.hpp. Private to the library.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "kdl_space/multibody/diagnostics.hpp"

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

/// The first error of `findings`, or nullptr.
const Finding* firstError(const Findings& findings);

}  // namespace kdl_space::rules
