// The immutable free-floating model: a KDL tree whose root segment is the base (the satellite),
// the base's own inertia (which kdl_parser drops), joint order and names, and an index-based
// traversal computed once.
#pragma once

#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <kdl/rigidbodyinertia.hpp>
#include <kdl/tree.hpp>
#include <limits>
#include <memory>
#include <map>
#include <string>
#include <vector>

#include "kdl_space/multibody/diagnostics.hpp"
#include "kdl_space/export.hpp"

namespace kdl_space {
namespace detail {
struct MotionTable;  // src/multibody/joint_motion.hpp
}

/// One rigid link of the model, in traversal order (a parent always precedes its children).
struct Body {
  std::string name;        ///< link (KDL segment) name
  int parent = -1;         ///< index of the parent body; -1 for the base
  /// Index of the coordinate that moves the joint from the parent (for a mimic joint, its
  /// leader's); -1 if fixed or base.
  int joint = -1;
  /// The joint's own value is multiplier * q(joint) + offset (1 and 0 but for a mimic joint).
  double multiplier = 1.0;
  double offset = 0.0;
  KDL::Segment segment;    ///< joint + pose of this body's frame in the parent body's frame
  /// Joint twist (v; w) per unit rate of its coordinate (times the multiplier of a mimic joint),
  /// in the parent's axes at the parent frame's origin: constant for revolute and prismatic
  /// joints (zero if fixed). Computed once from KDL's Segment::twist.
  Eigen::Matrix<double, 6, 1> joint_twist = Eigen::Matrix<double, 6, 1>::Zero();
  double mass = 0.0;       ///< [kg]
  Eigen::Vector3d com = Eigen::Vector3d::Zero();       ///< CoM, this body's frame [m]
  Eigen::Matrix3d I_com = Eigen::Matrix3d::Zero();     ///< inertia about the CoM, body axes [kg m^2]
};

/// \brief What a description says of a joint beyond its motion (URDF <limit> and <dynamics>): read
/// into the model, used by the simulation. Infinite where the description gives no limit (the
/// URDF loader reads an effort or velocity limit of 0, which files write for "not given", as none).
struct JointProperties {
  double lower = -std::numeric_limits<double>::infinity();  ///< position limits [rad or m]
  double upper = std::numeric_limits<double>::infinity();
  double effort = std::numeric_limits<double>::infinity();    ///< [N m or N]
  double velocity = std::numeric_limits<double>::infinity();  ///< [rad/s or m/s]
  double damping = 0.0;   ///< viscous [N m s/rad or N s/m]
  double friction = 0.0;  ///< Coulomb [N m or N]
};

/// A joint that follows another: its value is multiplier * (the leader's) + offset (URDF <mimic>).
struct Mimic {
  std::string joint, leader;
  double multiplier = 1.0;
  double offset = 0.0;
};

/// A movable joint of the description that the model treats as fixed (at q = 0), and why.
struct FixedJoint {
  std::string joint;
  std::string reason;
};

/// A contact point h: a body plus an offset in that body's frame (MATH.md conventions).
struct Contact {
  int body = -1;                    ///< index into FloatingModel::bodies()
  KDL::Vector offset = KDL::Vector::Zero();  ///< in the body's frame [m]
};

/// \brief The free-floating link system A of the paper: base body 0 and links 1..N (a chain or a
/// tree), n movable joints (revolute, continuous, prismatic; fixed joints merge rigidly).
///
/// Immutable once built; solvers share it through `std::shared_ptr<const FloatingModel>`.
/// Joint order is the KDL tree's joint numbering (q_nr), fixed here once.
class KDL_SPACE_EXPORT FloatingModel {
 public:
  /// \brief Builds the model from a KDL tree whose root segment is the base, plus the base
  /// body's inertia (in the base frame, as KDL segments hold theirs).
  ///
  /// The rigid bodies of the dynamics are composites (a link and every link fixed to it): their
  /// inertias must be positive semidefinite (a link's alone need not be); links may be point
  /// masses, massless frames, or bodies with a rotational inertia but no mass. A massless base
  /// composite is allowed when the system's mass matrix at q = 0 is positive definite (the links
  /// supply the mass). A movable joint that moves only massless links without inertia and has no
  /// armature is fixed at q = 0 (fixedJoints()); an inertia negative within round-off is read
  /// with that moment 0. Each is a diagnostic.
  /// \param armature optional rotor inertia per joint of `tree` (its q_nr order), added to H's
  /// diagonal; kept for the joints that stay coordinates.
  /// \throws ModelError naming the link or joint when the model cannot be used.
  /// \param mimic joints that follow others: they are not coordinates (J T, T^T H T); the dense
  /// solvers use the coupling, the O(n) ones impose it as constraints (algorithm/mimic_coupling.hpp).
  FloatingModel(const KDL::Tree& tree, const KDL::RigidBodyInertia& base_inertia,
                std::vector<double> armature = {}, std::vector<Diagnostic> diagnostics = {},
                std::vector<Mimic> mimic = {});

  /// \brief Same from a chain: its first segment hangs on a base named `base_name`.
  FloatingModel(const KDL::Chain& chain, const KDL::RigidBodyInertia& base_inertia,
                const std::string& base_name = "base", std::vector<double> armature = {});

  /// The joints that follow others (not coordinates).
  const std::vector<Mimic>& mimic() const { return mimic_; }
  /// \brief Throws ModelError naming `who` and the mimic joints when the model has any: for the
  /// computations that cannot couple joints (inverse kinematics; the solvers all can).
  void refuseMimic(const std::string& who) const;
  /// Number of movable joints n (the coordinates: mimic joints are not).
  unsigned int nj() const { return static_cast<unsigned int>(joint_names_.size()); }
  /// Bodies in traversal order; body 0 is the base.
  const std::vector<Body>& bodies() const { return bodies_; }
  /// Joint names in model order.
  const std::vector<std::string>& jointNames() const { return joint_names_; }
  /// Index of the body each joint moves (model order).
  const std::vector<int>& jointBody() const { return joint_body_; }
  /// Limits, damping and friction per joint (model order; none unless given).
  const std::vector<JointProperties>& jointProperties() const { return joint_properties_; }
  /// \brief A copy of this model with the joints' limits, damping and friction, by joint name
  /// (names of joints that are not coordinates, fixed or mimic, are ignored).
  /// \throws ModelError for a name that is no joint of the description's, or a property that
  /// is NaN, a negative damping, friction, effort or velocity limit, or lower > upper.
  FloatingModel withJointProperties(const std::map<std::string, JointProperties>& by_name) const;
  /// Rotor inertia per joint (zeros unless given).
  const std::vector<double>& armature() const { return armature_; }
  /// Problems found that do not stop the computation, and what was assumed to read the tree.
  const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }
  /// The movable joints of the given tree that are not coordinates (they move no mass): fixed at
  /// q = 0 in tree().
  const std::vector<FixedJoint>& fixedJoints() const { return fixed_joints_; }
  /// The KDL tree (root segment = base; the base inertia is in `bodies()[0]`, not in the tree).
  const KDL::Tree& tree() const { return tree_; }
  /// Total mass w [kg].
  double totalMass() const { return total_mass_; }
  /// Each body's joint motion, precomputed for forward kinematics (library internal).
  const detail::MotionTable& motions() const { return *motions_; }

  /// Index of the joint named `name`, or -1.
  int jointIndex(const std::string& name) const;
  /// Index of the body (link) named `name`, or -1.
  int bodyIndex(const std::string& name) const;
  /// \brief A contact point on link `link` at `offset` (link frame).
  /// \throws ModelError if the model has no such link.
  Contact contact(const std::string& link, const KDL::Vector& offset = KDL::Vector::Zero()) const;

  /// A copy of this model with rotor inertias (model order, size nj()) on the joints.
  FloatingModel withArmature(std::vector<double> armature) const;

  /// \brief A copy of this model with a rigid payload merged into link `link` (e.g. a captured
  /// target): `inertia` is the payload's, in that link's frame (KDL convention: mass, CoM, and
  /// rotational inertia about the CoM at construction). \throws ModelError for an unknown link.
  FloatingModel withPayload(const std::string& link, const KDL::RigidBodyInertia& inertia) const;

 private:
  void build(const KDL::RigidBodyInertia& base_inertia, const std::vector<double>& armature);
  void validate();
  void checkComposites();
  void checkArmature() const;
  std::vector<double> treeArmature() const;

  KDL::Tree tree_;
  std::vector<Body> bodies_;
  std::vector<std::string> joint_names_;
  std::vector<int> joint_body_;
  std::vector<double> armature_;
  std::vector<JointProperties> joint_properties_;
  std::vector<Diagnostic> diagnostics_;
  std::vector<FixedJoint> fixed_joints_;
  std::vector<Mimic> mimic_;
  double total_mass_ = 0.0;
  std::shared_ptr<const detail::MotionTable> motions_;  ///< immutable: shared by copies
};

}  // namespace kdl_space
