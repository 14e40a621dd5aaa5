#include "kdl_space/model.hpp"

#include <cmath>

#include "kdl_space/errors.hpp"
#include "kdl_space/spatial.hpp"
#include "detail/joint_motion.hpp"
#include "detail/text.hpp"
#include "model_rules.hpp"

namespace kdl_space {
namespace {

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
    throw ModelError("chain: cannot hang the chain on base " + detail::quoted(base_name) +
                     " (duplicate segment names?)");
  return tree;
}
}  // namespace

FloatingModel::FloatingModel(const KDL::Chain& chain, const KDL::RigidBodyInertia& base_inertia,
                             const std::string& base_name, std::vector<double> armature)
    : FloatingModel(chainAsTree(chain, base_name), base_inertia, std::move(armature)) {}

namespace {
[[noreturn]] void fail(const std::string& what, const std::string& name, const std::string& message) {
  throw ModelError(what + " " + detail::quoted(name) + ": " + message);
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
  // KDL-level checks of the frames, then the shared rules (model_rules.hpp) on the inertias.
  std::vector<Finding> findings;
  std::vector<rules::MassNode> nodes;
  for (const Body& b : bodies_) {
    const std::string& link = b.name;
    if (b.parent >= 0) {
      const KDL::Joint& joint = b.segment.getJoint();
      if (!allFinite(b.segment.pose(0.0)))
        fail("link", link, "the pose of its frame (joint origin) holds NaN or infinite values");
      if (joint.getType() != KDL::Joint::None) {
        const KDL::Vector axis = joint.JointAxis();
        if (!allFinite(axis) || !allFinite(joint.JointOrigin()) || std::abs(axis.Norm() - 1.0) > 1e-9)
          fail("joint", joint.getName(), "its axis is zero, NaN or infinite");
      }
    }
    if (!b.com.allFinite()) fail("link", link, "its inertial values hold NaN or infinite numbers");
    const std::size_t before = findings.size();
    rules::checkInertia(link, b.mass, b.I_com, findings);
    if (b.parent < 0 && findings.size() == before) rules::checkBaseMass(link, b.mass, findings);
    if (const Finding* e = rules::firstError(findings)) throw ModelError(describe(*e));
    nodes.push_back({link, b.parent, b.joint >= 0 ? joint_names_[b.joint] : std::string(), b.joint >= 0, b.mass});
  }
  rules::checkMassDistribution(nodes, findings);
  if (const Finding* e = rules::firstError(findings)) throw ModelError(describe(*e));
  for (const Finding& f : findings) diagnostics_.push_back({f.element, f.message});

  total_mass_ = 0.0;
  for (const Body& b : bodies_) total_mass_ += b.mass;
  motions_ = std::make_shared<const detail::MotionTable>(bodies_);
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
  if (body < 0) throw ModelError("contact: the model has no link " + detail::quoted(link));
  if (!allFinite(offset)) throw ModelError("contact on link " + detail::quoted(link) + ": offset is not finite");
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
  if (body < 0) throw ModelError("payload: the model has no link " + detail::quoted(link));
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
