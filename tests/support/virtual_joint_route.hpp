// The INDEPENDENT route of MATH.md ("Independent checks"): the free-floating system as a
// grounded KDL tree (or chain) with six virtual joints in front of the base, evaluated with
// KDL's own solvers only. Nothing here calls kdl_space's solver code; from the FloatingModel it
// reads only the KDL tree, the base body's mass/CoM/inertia (which the KDL tree does not hold),
// the armature and the joint names.
//
//   world -[TransX]- -[TransY]- -[TransZ]- -[RotX]- -[RotY]- -[RotZ]-> <base link> -> model segments
//
// The first virtual segment's tip carries the base position, the sixth's the base orientation
// and the base inertia; all virtual joints sit at 0. At that instant the virtual joint rates are
// exactly the base twist (linear velocity of the base frame's origin; angular velocity; both in
// world axes), the virtual generalized forces are (force; moment about the base origin), and the
// joint-space inertia of the grounded tree is the full floating mass matrix M_full.
//
// Coordinates of every matrix returned here: the 6 virtual coordinates first, then the model's
// joints in the MODEL's order (mapped from KDL's q_nr by joint name).
#pragma once

#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/tree.hpp>
#include <kdl/treeidsolver.hpp>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "kdl_space/impact/collision.hpp"
#include "kdl_space/multibody/model.hpp"
#include "kdl_space/multibody/state.hpp"

namespace kdl_space::test {

/// A contact point named by link (the KDL segment name) and an offset in that link's frame.
struct LinkPoint {
  std::string link;
  KDL::Vector offset = KDL::Vector::Zero();
};

/// Names of the six virtual joints (and of their segments, except the sixth: the base link).
extern const char* const kVirtualJointNames[6];

/// \brief The grounded virtual-joint KDL tree of a FloatingModel at one State.
/// M_full is computed in the constructor, column by column with KDL::TreeIdSolver_RNE
/// (zero gravity, zero velocity, unit acceleration); Jacobians with KDL::TreeJntToJacSolver;
/// poses with KDL::TreeFkSolverPos_recursive.
class VirtualJointTree {
 public:
  VirtualJointTree(const FloatingModel& model, const State& state);

  const KDL::Tree& tree() const { return tree_; }
  /// Number of real joints n.
  int n() const { return n_; }
  /// Joint positions of the virtual tree (KDL q_nr order).
  const KDL::JntArray& q() const { return q_tree_; }
  /// KDL q_nr of coordinate a (0..5 virtual, 6 + j for model joint j).
  int treeIndex(int a) const { return index_[a]; }

  /// Full floating mass matrix ((6+n) x (6+n)), armature included.
  const Eigen::MatrixXd& M_full() const { return M_full_; }
  /// Fixed-base H: lower-right n x n block of M_full.
  Eigen::MatrixXd H() const { return M_full_.bottomRightCorner(n_, n_); }
  /// World pose of a link's frame (KDL forward kinematics of the virtual tree).
  KDL::Frame pose(const std::string& link) const;
  /// 6 x (6+n) Jacobian of the point (world axes, reference point = the contact point).
  Eigen::MatrixXd J_full(const LinkPoint& h) const;
  /// Fixed-base J: the columns of the real joints of J_full (6 x n).
  Eigen::MatrixXd J(const LinkPoint& h) const { return J_full(h).rightCols(n_); }
  /// G_ref = J_full M_full^-1 J_full^T over one or several contact points (6k x 6k).
  Eigen::MatrixXd G(const std::vector<LinkPoint>& contacts) const;
  Eigen::MatrixXd G(const LinkPoint& h) const { return G(std::vector<LinkPoint>{h}); }
  /// Grounded G = J H^-1 J^T from the KDL J and H.
  Eigen::MatrixXd G_grounded(const LinkPoint& h) const;

 private:
  KDL::Tree tree_;
  int n_ = 0;
  std::vector<int> index_;  ///< coordinate -> KDL q_nr
  KDL::JntArray q_tree_;
  Eigen::MatrixXd M_full_;
};

/// \brief The same for a chain model, through KDL's chain solvers: the chain
/// virtual_tree.getChain(<root>, tip); M_full from KDL::ChainDynParam::JntToMass, Jacobians
/// from KDL::ChainJntToJacSolver, poses from KDL::ChainFkSolverPos_recursive. Every real joint
/// of the model must lie on the path to `tip` (throws std::invalid_argument otherwise).
class VirtualJointChain {
 public:
  VirtualJointChain(const FloatingModel& model, const State& state, const std::string& tip);

  const KDL::Chain& chain() const { return chain_; }
  int n() const { return n_; }
  const Eigen::MatrixXd& M_full() const { return M_full_; }
  Eigen::MatrixXd H() const { return M_full_.bottomRightCorner(n_, n_); }
  /// World pose of a link on the chain.
  KDL::Frame pose(const std::string& link) const;
  Eigen::MatrixXd J_full(const LinkPoint& h) const;
  Eigen::MatrixXd J(const LinkPoint& h) const { return J_full(h).rightCols(n_); }
  Eigen::MatrixXd G(const LinkPoint& h) const;
  Eigen::MatrixXd G_grounded(const LinkPoint& h) const;

 private:
  /// Number of chain segments up to and including `link` (ChainJntToJacSolver's seg_nr).
  int segmentCount(const std::string& link) const;

  KDL::Chain chain_;
  int n_ = 0;
  std::vector<int> index_;  ///< coordinate -> chain joint index
  KDL::JntArray q_chain_;
  Eigen::MatrixXd M_full_;
};

/// \brief The virtual-joint tree as a grounded system with ARBITRARY virtual joint positions:
/// generalized coordinates theta = (x, y, z, a, b, c; q) (virtual first, then the model's joints
/// in model order), with the base pose world_T_base = Trans(offset.p + (x, y, z)) Rx(a) Ry(b)
/// Rz(c) offset.M. KDL only (TreeIdSolver_RNE, TreeFkSolverPos_recursive); used for the
/// independent forward dynamics and for integrating the motion with a route that shares no code
/// with kdl_space. Armature (model order) is added as a plain rotor inertia on the real joints.
class VirtualJointDynamics {
 public:
  VirtualJointDynamics(const FloatingModel& model, const KDL::Frame& offset = KDL::Frame::Identity());
  // The KDL solvers keep a reference to tree_: not copyable, not movable.
  VirtualJointDynamics(const VirtualJointDynamics&) = delete;
  VirtualJointDynamics& operator=(const VirtualJointDynamics&) = delete;
  ~VirtualJointDynamics();

  const KDL::Tree& tree() const { return tree_; }
  int n() const { return n_; }
  /// Number of coordinates 6 + n.
  int size() const { return 6 + n_; }

  /// \brief Generalized forces (coordinate order) for positions theta, rates theta_d and
  /// accelerations theta_dd, with `gravity` (world) and external wrenches f_ext (KDL
  /// convention: per segment name, in that segment's frame, moment about its origin).
  Eigen::VectorXd inverseDynamics(const Eigen::VectorXd& theta, const Eigen::VectorXd& theta_d,
                                  const Eigen::VectorXd& theta_dd, const KDL::Vector& gravity,
                                  const KDL::WrenchMap& f_ext = KDL::WrenchMap()) const;
  /// Mass matrix (coordinate order, armature included), column by column from inverseDynamics.
  Eigen::MatrixXd massMatrix(const Eigen::VectorXd& theta) const;
  /// theta_dd = M^-1 (tau_full - c), tau_full = (0 on the virtual joints; tau).
  Eigen::VectorXd forwardDynamics(const Eigen::VectorXd& theta, const Eigen::VectorXd& theta_d,
                                  const Eigen::VectorXd& tau, const KDL::Vector& gravity,
                                  const KDL::WrenchMap& f_ext = KDL::WrenchMap()) const;
  /// World pose of a link at theta.
  KDL::Frame pose(const Eigen::VectorXd& theta, const std::string& link) const;

 private:
  KDL::JntArray toTree(const Eigen::VectorXd& x) const;
  Eigen::VectorXd fromTree(const KDL::JntArray& x) const;

  KDL::Tree tree_;
  int n_ = 0;
  std::vector<int> index_;  ///< coordinate -> KDL q_nr
  Eigen::VectorXd armature_;
  struct Solvers;
  std::unique_ptr<Solvers> solvers_;
};

/// \brief A copy of `tree` in which the joints named in `locked_at` are fixed (KDL::Joint::None)
/// at the given positions: each such segment keeps its name and inertia, its pose in the parent
/// becomes seg.pose(q). Throws std::invalid_argument if a named joint is not in the tree.
KDL::Tree lockJoints(const KDL::Tree& tree, const std::map<std::string, double>& locked_at);

/// Base inertia of a model as a KDL inertia in the base frame (from bodies()[0]).
KDL::RigidBodyInertia baseInertia(const FloatingModel& model, double scale = 1.0);

/// The virtual-joint KDL tree alone (used by both classes).
KDL::Tree buildVirtualTree(const FloatingModel& model, const KDL::Frame& world_T_base);

}  // namespace kdl_space::test
