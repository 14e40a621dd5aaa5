#include "kdl_space/model.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <sstream>

#include "kdl_space/errors.hpp"
#include "kdl_space/spatial.hpp"

namespace kdl_space {
namespace {

bool finite(const KDL::Vector& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

/// Mass, CoM and inertia about the CoM of a KDL inertia (KDL keeps the inertia about the
/// reference frame's origin).
void splitInertia(const KDL::RigidBodyInertia& I, Body& body) {
  body.mass = I.getMass();
  body.com = toEigen(I.getCOG());
  const KDL::RotationalInertia Io = I.getRotationalInertia();
  Matrix3d I_origin;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) I_origin(i, j) = Io.data[3 * i + j];
  const Matrix3d C = skew(body.com);
  body.I_com = I_origin + body.mass * C * C;  // parallel-axis theorem, back to the CoM
}

std::string quoted(const std::string& s) { return "'" + s + "'"; }

}  // namespace

FloatingModel::FloatingModel(const KDL::Tree& tree, const KDL::RigidBodyInertia& base_inertia,
                             std::vector<double> armature, std::vector<Diagnostic> diagnostics)
    : tree_(tree), diagnostics_(std::move(diagnostics)) {
  const KDL::SegmentMap::const_iterator root = tree_.getRootSegment();
  joint_names_.assign(tree_.getNrOfJoints(), std::string());
  joint_body_.assign(tree_.getNrOfJoints(), -1);

  // Depth-first traversal, computed once: parents precede children.
  struct Item {
    KDL::SegmentMap::const_iterator element;
    int parent;
  };
  std::vector<Item> stack{{root, -1}};
  while (!stack.empty()) {
    const Item item = stack.back();
    stack.pop_back();
    const KDL::Segment& segment = GetTreeElementSegment(item.element->second);
    Body body;
    body.name = item.element->first;
    body.parent = item.parent;
    body.segment = segment;
    if (item.parent < 0) {
      splitInertia(base_inertia, body);
    } else {
      splitInertia(segment.getInertia(), body);
      if (segment.getJoint().getType() != KDL::Joint::None) {
        // KDL gives the twist at the tip; the rotation axis (or sliding direction) is fixed in
        // the parent frame, so at the parent's origin the twist does not depend on q.
        body.joint_twist = toEigen(segment.twist(0.0, 1.0).RefPoint(-segment.pose(0.0).p));
        body.joint = static_cast<int>(GetTreeElementQNr(item.element->second));
        joint_names_[body.joint] = segment.getJoint().getName();
        joint_body_[body.joint] = static_cast<int>(bodies_.size());
      }
    }
    const int index = static_cast<int>(bodies_.size());
    bodies_.push_back(body);
    const auto& children = GetTreeElementChildren(item.element->second);
    for (auto it = children.rbegin(); it != children.rend(); ++it) stack.push_back({*it, index});
  }

  if (armature.empty()) armature.assign(nj(), 0.0);
  armature_ = std::move(armature);
  checkArmature();
  validate();
}

namespace {
KDL::Tree chainAsTree(const KDL::Chain& chain, const std::string& base_name) {
  KDL::Tree tree(base_name);
  if (!tree.addChain(chain, base_name))
    throw ModelError("chain: cannot hang the chain on base " + quoted(base_name) +
                     " (duplicate segment names?)");
  return tree;
}
}  // namespace

FloatingModel::FloatingModel(const KDL::Chain& chain, const KDL::RigidBodyInertia& base_inertia,
                             const std::string& base_name, std::vector<double> armature)
    : FloatingModel(chainAsTree(chain, base_name), base_inertia, std::move(armature)) {}

namespace {
[[noreturn]] void fail(const std::string& what, const std::string& name, const std::string& message) {
  throw ModelError(what + " " + quoted(name) + ": " + message);
}
}  // namespace

void FloatingModel::checkArmature() const {
  if (armature_.size() != nj())
    throw ModelError("armature: " + std::to_string(armature_.size()) + " values given for " +
                     std::to_string(nj()) + " joints");
  for (unsigned int j = 0; j < nj(); ++j)
    if (!std::isfinite(armature_[j]) || armature_[j] < 0.0)
      fail("joint", joint_names_[j], "armature must be a finite value >= 0");
}

void FloatingModel::validate() {

  std::vector<double> subtree_mass(bodies_.size(), 0.0);
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const Body& b = bodies_[i];
    const std::string& link = b.name;
    const bool base = b.parent < 0;
    if (!base) {
      const KDL::Joint& joint = b.segment.getJoint();
      if (!allFinite(b.segment.pose(0.0)))
        fail("link", link, "the pose of its frame (joint origin) holds NaN or infinite values");
      if (joint.getType() != KDL::Joint::None) {
        const KDL::Vector axis = joint.JointAxis();
        if (!finite(axis) || !finite(joint.JointOrigin()) || std::abs(axis.Norm() - 1.0) > 1e-9)
          fail("joint", joint.getName(), "its axis is zero, NaN or infinite");
      }
    }
    if (!std::isfinite(b.mass) || !b.com.allFinite() || !b.I_com.allFinite())
      fail("link", link, "its inertial values hold NaN or infinite numbers");
    if (b.mass < 0.0) fail("link", link, "negative mass " + std::to_string(b.mass) + " kg");
    if (base && b.mass <= 0.0)
      fail("base link", link,
           "has no mass: a free-floating base needs its mass and inertia (kdl_space reads the "
           "root link's <inertial>, which kdl_parser drops)");
    if (b.mass == 0.0) {
      if (!b.I_com.isZero(0.0)) fail("link", link, "has rotational inertia but zero mass");
      // Whether a massless link is acceptable is decided below from its subtree.
    } else {
      Eigen::SelfAdjointEigenSolver<Matrix3d> eig(0.5 * (b.I_com + b.I_com.transpose()),
                                                  Eigen::EigenvaluesOnly);
      const Vector3d l = eig.eigenvalues();  // ascending
      std::ostringstream moments;
      moments << "(principal moments " << l(0) << ", " << l(1) << ", " << l(2) << " kg m^2)";
      if (!(l(0) > 0.0))
        fail("link", link, "its inertia about the CoM is not positive definite " + moments.str());
      if (l(0) + l(1) < l(2) * (1.0 - 1e-9))
        fail("link", link,
             "its principal moments break the triangle inequality I1 + I2 >= I3 " + moments.str());
    }
    subtree_mass[i] = b.mass;
  }
  for (std::size_t i = bodies_.size(); i-- > 1;) subtree_mass[bodies_[i].parent] += subtree_mass[i];
  total_mass_ = subtree_mass[0];

  for (std::size_t i = 1; i < bodies_.size(); ++i) {
    const Body& b = bodies_[i];
    if (b.joint >= 0 && subtree_mass[i] == 0.0)
      fail("joint", joint_names_[b.joint],
           "moves only massless links (" + quoted(b.name) +
               " and below): its inertia is zero and the dynamics are singular");
    if (b.mass == 0.0) {
      const bool leaf = subtree_mass[i] == 0.0;
      diagnostics_.push_back(
          {b.name, leaf ? "massless link: it only carries a frame"
                        : "massless link: it carries no inertia of its own"});
    }
  }
}

int FloatingModel::jointIndex(const std::string& name) const {
  for (std::size_t j = 0; j < joint_names_.size(); ++j)
    if (joint_names_[j] == name) return static_cast<int>(j);
  return -1;
}

int FloatingModel::bodyIndex(const std::string& name) const {
  for (std::size_t i = 0; i < bodies_.size(); ++i)
    if (bodies_[i].name == name) return static_cast<int>(i);
  return -1;
}

Contact FloatingModel::contact(const std::string& link, const KDL::Vector& offset) const {
  const int body = bodyIndex(link);
  if (body < 0) throw ModelError("contact: the model has no link " + quoted(link));
  if (!finite(offset)) throw ModelError("contact on link " + quoted(link) + ": offset is not finite");
  return Contact{body, offset};
}

FloatingModel FloatingModel::withArmature(std::vector<double> armature) const {
  FloatingModel copy(*this);
  copy.armature_ = std::move(armature);
  copy.checkArmature();
  return copy;
}

namespace {
/// Copies the children of `from` (in `source`) below `hook` in `target`, adding `payload` to
/// the segment named `link`.
void copyChildren(const KDL::Tree& source, KDL::SegmentMap::const_iterator from, const std::string& hook,
                  KDL::Tree& target, const std::string& link, const KDL::RigidBodyInertia& payload) {
  for (const auto& child : GetTreeElementChildren(from->second)) {
    const KDL::Segment& seg = GetTreeElementSegment(child->second);
    const KDL::RigidBodyInertia inertia = seg.getName() == link ? seg.getInertia() + payload : seg.getInertia();
    target.addSegment(KDL::Segment(seg.getName(), seg.getJoint(), seg.pose(0.0), inertia), hook);
    copyChildren(source, child, seg.getName(), target, link, payload);
  }
}
}  // namespace

FloatingModel FloatingModel::withPayload(const std::string& link, const KDL::RigidBodyInertia& inertia) const {
  const int body = bodyIndex(link);
  if (body < 0) throw ModelError("payload: the model has no link " + quoted(link));
  // Rebuild the tree with the payload in the link's segment (the base's inertia lives apart).
  const KDL::SegmentMap::const_iterator root = tree_.getRootSegment();
  KDL::Tree tree(root->first);
  copyChildren(tree_, root, root->first, tree, link, inertia);
  const Matrix3d& I = bodies_[0].I_com;
  KDL::RigidBodyInertia base(bodies_[0].mass, toKDL(bodies_[0].com),
                             KDL::RotationalInertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)));
  if (body == 0) base = base + inertia;
  std::vector<Diagnostic> diagnostics = diagnostics_;
  diagnostics.push_back({link, "carries a rigid payload of " + std::to_string(inertia.getMass()) + " kg"});
  FloatingModel merged(tree, base, armature_, {});
  merged.diagnostics_ = std::move(diagnostics);
  return merged;
}

}  // namespace kdl_space
