// The rules a description must satisfy to be a free-floating model (the inertias and masses of its
// links and rigid bodies), written once and shared: the loader and FloatingModel throw at the first
// error (and keep the warnings as diagnostics), checkUrdfFile reports every finding. The URDF
// readers' own rules are parsers/urdf/urdf_rules.hpp. Private to the library.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "kdl_space/multibody/diagnostics.hpp"
#include "kdl_space/spatial/errors.hpp"

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
/// (only its principal moments matter). Errors: `not_finite`, `non_positive_mass` (negative).
/// Warnings, for what is read as it is written or within round-off: `inertia_without_mass` (zero
/// mass with a rotational inertia: kept, a body that resists rotation and not translation),
/// `point_mass` (no rotational inertia beyond m 1e-12 m^2), `inertia_round_off` (a principal moment zero or
/// negative within round-off: read as 0), `triangle_inequality` (I1 + I2 < I3, with the amount).
/// A negative principal moment beyond round-off is not judged here: the rigid body the link
/// belongs to is (checkRigidBodies), not every link.
void checkInertia(const std::string& link, double mass, const Eigen::Matrix3d& I_com, Findings& out);

/// Whether an inertia (about the CoM) has a negative principal moment beyond round-off.
bool negativeBeyondRoundOff(double mass, const Eigen::Matrix3d& I_com);

/// The inertia as the model reads it: negative principal moments within round-off (which
/// checkInertia lets pass) set to zero; otherwise unchanged (beyond round-off it is read as
/// written: the rigid body it belongs to was judged instead).
Eigen::Matrix3d withoutNegativeMoments(double mass, const Eigen::Matrix3d& I);

/// One link of a tree for the mass rules below; node 0 is the base, parents precede children.
struct MassNode {
  std::string link;
  int parent = -1;
  std::string joint;     ///< the joint from the parent
  bool movable = false;  ///< that joint moves
  double mass = 0.0;     ///< [kg]; NaN when unknown (not read), which no rule below reports
  double armature = 0.0; ///< rotor inertia of that joint (a joint with one is a coordinate)
  bool rotational = false;  ///< the link has a rotational inertia (its inertia about the CoM is not zero)
  // For checkRigidBodies (left at their defaults, the link counts as a massless frame there):
  bool inertia_known = false;  ///< com and I_com below were read
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  ///< the link frame's axes in its parent's (at q = 0)
  Eigen::Vector3d p = Eigen::Vector3d::Zero();      ///< the link frame's origin in its parent's [m]
  Eigen::Vector3d com = Eigen::Vector3d::Zero();    ///< CoM, link frame [m]
  Eigen::Matrix3d I_com = Eigen::Matrix3d::Zero();  ///< inertia about the CoM, link axes [kg m^2]
};

/// \brief The rigid bodies of the dynamics are composites: a link and every link joined to it
/// by fixed joints. The nodes of the composite of node `head` (itself first), in node order.
std::vector<int> composite(const std::vector<MassNode>& nodes, int head);

/// \brief The inertia rules on the rigid bodies of the dynamics (the composites), not on each
/// link: for every link whose own inertia has a negative principal moment beyond round-off, the
/// composite it belongs to (its inertia about its CoM, from its links at their fixed poses) is
/// judged. Composite positive semidefinite: warning `link_inertia_not_positive_definite` naming the
/// link and the composite (read as written). Not: error `inertia_not_positive_definite`.
void checkRigidBodies(const std::vector<MassNode>& nodes, Findings& out);

/// The mass of the composite of node `head`, and whether it has a rotational inertia.
std::pair<double, bool> compositeMass(const std::vector<MassNode>& nodes, int head);

/// \brief Massless links. Warning `joint_moves_no_mass` for each movable joint without
/// armature that moves only massless links without rotational inertia (no inertia: H* would be
/// singular): the model treats it as fixed at q = 0. Note `massless_link` for the other massless
/// links below the base (a link with a rotational inertia but no mass has its warning instead).
/// Whether a massless base or a joint moving only rotational inertias leaves the mass matrix
/// positive definite is the model's to say (FloatingModel: `base_without_mass`,
/// `singular_inertia`), from its mass matrix.
void checkMassDistribution(const std::vector<MassNode>& nodes, Findings& out);

/// \brief A ModelError that carries the finding of the rule that refused (the checker reports
/// its kind when the model refuses a file the reader could not judge).
class RuleError : public ModelError {
 public:
  explicit RuleError(Finding finding);
  RuleError(Finding finding, const std::string& what) : ModelError(what), finding_(std::move(finding)) {}
  ~RuleError() override;
  const Finding& finding() const { return finding_; }

 protected:
  std::exception_ptr renamed(const std::string& what) const override;

 private:
  Finding finding_;
};

/// The first error of `findings`, or nullptr.
const Finding* firstError(const Findings& findings);

}  // namespace kdl_space::rules
