#include "virtual_joint_route.hpp"

#include <Eigen/Cholesky>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntspaceinertiamatrix.hpp>
#include <kdl/treefksolverpos_recursive.hpp>
#include <kdl/treeidsolver_recursive_newton_euler.hpp>
#include <kdl/treejnttojacsolver.hpp>
#include <map>
#include <stdexcept>

namespace kdl_space::test {

/// The grounded tree's root: not "world", which real models name their base's root link.
const char* const kVirtualRoot = "kdl_space_virtual_route_world";

const char* const kVirtualJointNames[6] = {"virtual_tx", "virtual_ty", "virtual_tz",
                                           "virtual_rx", "virtual_ry", "virtual_rz"};

namespace {

/// Adds, below `parent_name` of `dst`, a copy of every segment below `src` (same segments).
void copySubtree(const KDL::SegmentMap::const_iterator& src, const std::string& parent_name, KDL::Tree& dst) {
  for (const auto& child : GetTreeElementChildren(src->second)) {
    if (!dst.addSegment(GetTreeElementSegment(child->second), parent_name))
      throw std::runtime_error("virtual route: cannot add segment " + child->first);
    copySubtree(child, child->first, dst);
  }
}

/// Coordinate -> joint index of a KDL structure, by joint name (virtual joints first).
std::vector<int> coordinateIndex(const FloatingModel& model, const std::map<std::string, int>& by_name) {
  std::vector<int> index(6 + model.nj(), -1);
  for (int a = 0; a < 6; ++a) index[a] = by_name.at(kVirtualJointNames[a]);
  for (unsigned int j = 0; j < model.nj(); ++j) {
    const auto it = by_name.find(model.jointNames()[j]);
    if (it == by_name.end())
      throw std::invalid_argument("virtual route: joint " + model.jointNames()[j] + " not found");
    index[6 + j] = it->second;
  }
  return index;
}

/// Reorders a square KDL-indexed matrix into coordinate order.
Eigen::MatrixXd reorder(const Eigen::MatrixXd& M_kdl, const std::vector<int>& index) {
  const int m = static_cast<int>(index.size());
  Eigen::MatrixXd M(m, m);
  for (int a = 0; a < m; ++a)
    for (int b = 0; b < m; ++b) M(a, b) = M_kdl(index[a], index[b]);
  return M;
}

Eigen::MatrixXd reorderColumns(const Eigen::MatrixXd& J_kdl, const std::vector<int>& index) {
  Eigen::MatrixXd J(J_kdl.rows(), index.size());
  for (std::size_t a = 0; a < index.size(); ++a) J.col(a) = J_kdl.col(index[a]);
  return J;
}

void addArmature(const FloatingModel& model, Eigen::MatrixXd& M_full) {
  for (unsigned int j = 0; j < model.nj(); ++j) M_full(6 + j, 6 + j) += model.armature()[j];
}

Eigen::MatrixXd delassus(const Eigen::MatrixXd& J, const Eigen::MatrixXd& M) {
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(M);
  if (ldlt.info() != Eigen::Success) throw std::runtime_error("virtual route: LDLT failed");
  return J * ldlt.solve(J.transpose());
}

}  // namespace

KDL::RigidBodyInertia baseInertia(const FloatingModel& model, double scale) {
  const Body& base = model.bodies()[0];
  const Eigen::Matrix3d& I = base.I_com;
  return KDL::RigidBodyInertia(
      scale * base.mass, KDL::Vector(base.com.x(), base.com.y(), base.com.z()),
      KDL::RotationalInertia(scale * I(0, 0), scale * I(1, 1), scale * I(2, 2), scale * I(0, 1),
                             scale * I(0, 2), scale * I(1, 2)));
}

KDL::Tree buildVirtualTree(const FloatingModel& model, const KDL::Frame& world_T_base) {
  const KDL::SegmentMap::const_iterator root = model.tree().getRootSegment();
  const std::string base_name = root->first;
  const KDL::Joint::JointType types[6] = {KDL::Joint::TransX, KDL::Joint::TransY, KDL::Joint::TransZ,
                                          KDL::Joint::RotX,   KDL::Joint::RotY,   KDL::Joint::RotZ};
  KDL::Tree tree(kVirtualRoot);
  std::string parent = kVirtualRoot;
  for (int a = 0; a < 6; ++a) {
    const bool last = a == 5;
    const std::string name = last ? base_name : std::string(kVirtualJointNames[a]);
    const KDL::Frame f_tip = a == 0 ? KDL::Frame(world_T_base.p)
                             : last ? KDL::Frame(world_T_base.M)
                                    : KDL::Frame::Identity();
    const KDL::RigidBodyInertia I = last ? baseInertia(model) : KDL::RigidBodyInertia::Zero();
    if (!tree.addSegment(KDL::Segment(name, KDL::Joint(kVirtualJointNames[a], types[a]), f_tip, I), parent))
      throw std::runtime_error("virtual route: cannot add virtual segment " + name);
    parent = name;
  }
  copySubtree(root, base_name, tree);
  return tree;
}

// --- Tree -----------------------------------------------------------------------------------

namespace {
/// The KDL tree's joint number (q_nr) of every movable joint, by joint name.
std::map<std::string, int> jointNumbers(const KDL::Tree& tree) {
  std::map<std::string, int> by_name;
  for (const auto& [name, element] : tree.getSegments()) {
    const KDL::Segment& seg = GetTreeElementSegment(element);
    if (seg.getJoint().getType() != KDL::Joint::None)
      by_name[seg.getJoint().getName()] = static_cast<int>(GetTreeElementQNr(element));
  }
  return by_name;
}
}  // namespace

VirtualJointTree::VirtualJointTree(const FloatingModel& model, const State& state)
    : tree_(buildVirtualTree(model, state.world_T_base)), n_(static_cast<int>(model.nj())) {
  index_ = coordinateIndex(model, jointNumbers(tree_));
  const unsigned int nt = tree_.getNrOfJoints();
  if (nt != 6 + model.nj()) throw std::runtime_error("virtual route: joint count mismatch");

  q_tree_ = KDL::JntArray(nt);  // virtual joints at 0
  for (int j = 0; j < n_; ++j) q_tree_(index_[6 + j]) = state.q(j);

  // M_full column by column: tau = M(q) e_k with zero gravity and zero velocity.
  KDL::TreeIdSolver_RNE rne(tree_, KDL::Vector::Zero());
  KDL::JntArray zero(nt), qdd(nt), tau(nt);
  const KDL::WrenchMap no_external_forces;
  Eigen::MatrixXd M_kdl(nt, nt);
  for (unsigned int k = 0; k < nt; ++k) {
    qdd.data.setZero();
    qdd(k) = 1.0;
    if (rne.CartToJnt(q_tree_, zero, qdd, no_external_forces, tau) != 0)
      throw std::runtime_error("virtual route: TreeIdSolver_RNE failed");
    M_kdl.col(k) = tau.data;
  }
  M_full_ = reorder(M_kdl, index_);
  addArmature(model, M_full_);
}

KDL::Frame VirtualJointTree::pose(const std::string& link) const {
  KDL::TreeFkSolverPos_recursive fk(tree_);
  KDL::Frame f;
  if (fk.JntToCart(q_tree_, f, link) < 0) throw std::invalid_argument("virtual route: no link " + link);
  return f;
}

Eigen::MatrixXd VirtualJointTree::J_full(const LinkPoint& h) const {
  KDL::TreeJntToJacSolver solver(tree_);
  KDL::Jacobian jac(tree_.getNrOfJoints());
  if (solver.JntToJac(q_tree_, jac, h.link) != 0)
    throw std::invalid_argument("virtual route: no Jacobian for link " + h.link);
  // KDL: reference point = the link frame's origin, world axes. Move it to the contact point.
  jac.changeRefPoint(pose(h.link).M * h.offset);
  return reorderColumns(jac.data, index_);
}

Eigen::MatrixXd VirtualJointTree::G(const std::vector<LinkPoint>& contacts) const {
  Eigen::MatrixXd J_all(6 * contacts.size(), 6 + n_);
  for (std::size_t i = 0; i < contacts.size(); ++i) J_all.middleRows(6 * i, 6) = J_full(contacts[i]);
  return delassus(J_all, M_full_);
}

Eigen::MatrixXd VirtualJointTree::G_grounded(const LinkPoint& h) const { return delassus(J(h), H()); }

// --- Chain ----------------------------------------------------------------------------------

VirtualJointChain::VirtualJointChain(const FloatingModel& model, const State& state, const std::string& tip)
    : n_(static_cast<int>(model.nj())) {
  const KDL::Tree tree = buildVirtualTree(model, state.world_T_base);
  if (!tree.getChain(kVirtualRoot, tip, chain_)) throw std::invalid_argument("virtual route: no chain to " + tip);
  std::map<std::string, int> by_name;
  int k = 0;
  for (unsigned int s = 0; s < chain_.getNrOfSegments(); ++s) {
    const KDL::Joint& joint = chain_.getSegment(s).getJoint();
    if (joint.getType() != KDL::Joint::None) by_name[joint.getName()] = k++;
  }
  index_ = coordinateIndex(model, by_name);  // throws if a model joint is off the chain
  const unsigned int nc = chain_.getNrOfJoints();
  if (nc != 6 + model.nj()) throw std::invalid_argument("virtual route: the chain misses joints");

  q_chain_ = KDL::JntArray(nc);
  for (int j = 0; j < n_; ++j) q_chain_(index_[6 + j]) = state.q(j);
  KDL::ChainDynParam dyn(chain_, KDL::Vector::Zero());
  KDL::JntSpaceInertiaMatrix M(nc);
  if (dyn.JntToMass(q_chain_, M) != 0) throw std::runtime_error("virtual route: JntToMass failed");
  M_full_ = reorder(M.data, index_);
  addArmature(model, M_full_);
}

int VirtualJointChain::segmentCount(const std::string& link) const {
  for (unsigned int s = 0; s < chain_.getNrOfSegments(); ++s)
    if (chain_.getSegment(s).getName() == link) return static_cast<int>(s) + 1;
  throw std::invalid_argument("virtual route: link " + link + " is not on the chain");
}

KDL::Frame VirtualJointChain::pose(const std::string& link) const {
  KDL::ChainFkSolverPos_recursive fk(chain_);
  KDL::Frame f;
  if (fk.JntToCart(q_chain_, f, segmentCount(link)) < 0) throw std::runtime_error("virtual route: chain FK failed");
  return f;
}

Eigen::MatrixXd VirtualJointChain::J_full(const LinkPoint& h) const {
  KDL::ChainJntToJacSolver solver(chain_);
  KDL::Jacobian jac(chain_.getNrOfJoints());
  if (solver.JntToJac(q_chain_, jac, segmentCount(h.link)) != 0)
    throw std::runtime_error("virtual route: ChainJntToJacSolver failed");
  jac.changeRefPoint(pose(h.link).M * h.offset);
  return reorderColumns(jac.data, index_);
}

Eigen::MatrixXd VirtualJointChain::G(const LinkPoint& h) const { return delassus(J_full(h), M_full_); }

Eigen::MatrixXd VirtualJointChain::G_grounded(const LinkPoint& h) const { return delassus(J(h), H()); }

// --- Dynamics with arbitrary virtual coordinates ---------------------------------------------

struct VirtualJointDynamics::Solvers {
  explicit Solvers(const KDL::Tree& tree) : fk(tree) {}
  KDL::TreeFkSolverPos_recursive fk;
};

VirtualJointDynamics::VirtualJointDynamics(const FloatingModel& model, const KDL::Frame& offset)
    : tree_(buildVirtualTree(model, offset)), n_(static_cast<int>(model.nj())) {
  index_ = coordinateIndex(model, jointNumbers(tree_));
  if (tree_.getNrOfJoints() != 6 + model.nj()) throw std::runtime_error("virtual route: joint count mismatch");
  armature_ = Eigen::VectorXd::Zero(6 + n_);
  for (int j = 0; j < n_; ++j) armature_(6 + j) = model.armature()[j];
  solvers_ = std::make_unique<Solvers>(tree_);
}

VirtualJointDynamics::~VirtualJointDynamics() = default;

KDL::JntArray VirtualJointDynamics::toTree(const Eigen::VectorXd& x) const {
  if (x.size() != size()) throw std::invalid_argument("virtual route: coordinate vector of wrong size");
  KDL::JntArray a(size());
  for (int i = 0; i < size(); ++i) a(index_[i]) = x(i);
  return a;
}

Eigen::VectorXd VirtualJointDynamics::fromTree(const KDL::JntArray& a) const {
  Eigen::VectorXd x(size());
  for (int i = 0; i < size(); ++i) x(i) = a(index_[i]);
  return x;
}

Eigen::VectorXd VirtualJointDynamics::inverseDynamics(const Eigen::VectorXd& theta, const Eigen::VectorXd& theta_d,
                                                      const Eigen::VectorXd& theta_dd, const KDL::Vector& gravity,
                                                      const KDL::WrenchMap& f_ext) const {
  KDL::TreeIdSolver_RNE rne(tree_, gravity);
  KDL::JntArray tau(size());
  if (rne.CartToJnt(toTree(theta), toTree(theta_d), toTree(theta_dd), f_ext, tau) != 0)
    throw std::runtime_error("virtual route: TreeIdSolver_RNE failed");
  return fromTree(tau) + armature_.cwiseProduct(theta_dd);
}

Eigen::MatrixXd VirtualJointDynamics::massMatrix(const Eigen::VectorXd& theta) const {
  // tau = M(theta) e_k with zero gravity and zero velocity.
  KDL::TreeIdSolver_RNE rne(tree_, KDL::Vector::Zero());
  const KDL::JntArray q = toTree(theta), zero(size());
  KDL::JntArray qdd(size()), tau(size());
  const KDL::WrenchMap none;
  Eigen::MatrixXd M(size(), size());
  for (int k = 0; k < size(); ++k) {
    qdd.data.setZero();
    qdd(index_[k]) = 1.0;
    if (rne.CartToJnt(q, zero, qdd, none, tau) != 0) throw std::runtime_error("virtual route: TreeIdSolver_RNE failed");
    M.col(k) = fromTree(tau);
  }
  M.diagonal() += armature_;
  return M;
}

Eigen::VectorXd VirtualJointDynamics::forwardDynamics(const Eigen::VectorXd& theta, const Eigen::VectorXd& theta_d,
                                                      const Eigen::VectorXd& tau, const KDL::Vector& gravity,
                                                      const KDL::WrenchMap& f_ext) const {
  if (tau.size() != n_) throw std::invalid_argument("virtual route: tau of wrong size");
  Eigen::VectorXd tau_full = Eigen::VectorXd::Zero(size());
  tau_full.tail(n_) = tau;
  const Eigen::VectorXd c = inverseDynamics(theta, theta_d, Eigen::VectorXd::Zero(size()), gravity, f_ext);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(massMatrix(theta));
  if (ldlt.info() != Eigen::Success) throw std::runtime_error("virtual route: LDLT failed");
  return ldlt.solve(tau_full - c);
}

KDL::Frame VirtualJointDynamics::pose(const Eigen::VectorXd& theta, const std::string& link) const {
  KDL::Frame f;
  if (solvers_->fk.JntToCart(toTree(theta), f, link) < 0) throw std::invalid_argument("virtual route: no link " + link);
  return f;
}

// --- Locked joints --------------------------------------------------------------------------

namespace {
void copyLocked(const KDL::SegmentMap::const_iterator& src, const std::string& parent_name,
                const std::map<std::string, double>& locked_at, KDL::Tree& dst, std::size_t& found) {
  for (const auto& child : GetTreeElementChildren(src->second)) {
    const KDL::Segment& seg = GetTreeElementSegment(child->second);
    const auto it = locked_at.find(seg.getJoint().getName());
    const bool lock = seg.getJoint().getType() != KDL::Joint::None && it != locked_at.end();
    const KDL::Segment copy =
        lock ? KDL::Segment(seg.getName(), KDL::Joint(seg.getJoint().getName(), KDL::Joint::None),
                            seg.pose(it->second), seg.getInertia())
             : seg;
    found += lock ? 1 : 0;
    if (!dst.addSegment(copy, parent_name))
      throw std::runtime_error("virtual route: cannot add segment " + child->first);
    copyLocked(child, child->first, locked_at, dst, found);
  }
}
}  // namespace

KDL::Tree lockJoints(const KDL::Tree& tree, const std::map<std::string, double>& locked_at) {
  const KDL::SegmentMap::const_iterator root = tree.getRootSegment();
  KDL::Tree out(root->first);
  std::size_t found = 0;
  copyLocked(root, root->first, locked_at, out, found);
  if (found != locked_at.size()) throw std::invalid_argument("virtual route: a joint to lock is not in the tree");
  return out;
}

}  // namespace kdl_space::test
