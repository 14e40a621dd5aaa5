#include "kdl_space/multibody/model.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <map>
#include <set>
#include <cmath>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/spatial/spatial.hpp"
#include "multibody/joint_motion.hpp"
#include "spatial/message_text.hpp"
#include "multibody/model_build.hpp"
#include "multibody/mimic_route.hpp"
#include "multibody/model_rules.hpp"

namespace kdl_space {
namespace {

/// The links of a KDL tree, depth first (parents first), as the mass rules read them.
struct ReadLink {
  KDL::SegmentMap::const_iterator element;
  Body body;  ///< name, parent, mass properties (the joint fields are not used here)
  rules::MassNode node;
};

using detail::fail;

std::vector<ReadLink> readLinks(const KDL::Tree& tree, const KDL::RigidBodyInertia& base_inertia,
                                const std::vector<double>& armature) {
  std::vector<ReadLink> links;
  std::vector<std::pair<KDL::SegmentMap::const_iterator, int>> stack{{tree.getRootSegment(), -1}};
  while (!stack.empty()) {
    const auto [element, parent] = stack.back();
    stack.pop_back();
    const KDL::Segment& segment = GetTreeElementSegment(element->second);
    ReadLink link;
    link.element = element;
    link.body.name = link.node.link = element->first;
    link.body.parent = link.node.parent = parent;
    detail::splitInertia(parent < 0 ? base_inertia : segment.getInertia(), link.body);
    link.node.mass = link.body.mass;
    link.node.rotational = !link.body.I_com.isZero(0.0);
    link.node.inertia_known = true;
    link.node.com = link.body.com;
    link.node.I_com = link.body.I_com;
    if (parent >= 0) {  // the fixed pose (a movable joint's at q = 0 is not used by the rules)
      const KDL::Frame pose = segment.pose(0.0);
      link.node.R = toEigen(pose.M);
      link.node.p = toEigen(pose.p);
    }
    if (parent >= 0 && segment.getJoint().getType() != KDL::Joint::None) {
      link.node.joint = segment.getJoint().getName();
      link.node.movable = true;
      const unsigned int q_nr = GetTreeElementQNr(element->second);
      if (q_nr < armature.size()) link.node.armature = armature[q_nr];
    } else if (parent >= 0) {
      link.node.joint = segment.getJoint().getName();
    }
    const int index = static_cast<int>(links.size());
    links.push_back(std::move(link));
    const auto& children = GetTreeElementChildren(element->second);
    for (auto it = children.rbegin(); it != children.rend(); ++it) stack.push_back({*it, index});
  }
  return links;
}


/// The given tree as the dynamics read it: the joints in `fixed` made fixed (at q = 0), the
/// links in `corrected` with those inertias.
KDL::Tree rebuiltTree(const std::vector<ReadLink>& links, const std::vector<bool>& fixed,
                      const std::vector<bool>& corrected) {
  KDL::Tree tree(links.front().body.name);
  for (std::size_t i = 1; i < links.size(); ++i) {
    const KDL::Segment& seg = GetTreeElementSegment(links[i].element->second);
    const KDL::Joint joint = fixed[i] ? KDL::Joint(seg.getJoint().getName(), KDL::Joint::Fixed) : seg.getJoint();
    const KDL::RigidBodyInertia inertia = corrected[i] ? detail::kdlInertia(links[i].body) : seg.getInertia();
    tree.addSegment(KDL::Segment(seg.getName(), joint, seg.pose(0.0), inertia), links[links[i].body.parent].body.name);
  }
  return tree;
}

}  // namespace

FloatingModel::FloatingModel(const KDL::Tree& tree, const KDL::RigidBodyInertia& base_inertia,
                             std::vector<double> armature, std::vector<Diagnostic> diagnostics,
                             std::vector<Mimic> mimic)
    : diagnostics_(std::move(diagnostics)), mimic_(std::move(mimic)) {
  if (!armature.empty() && armature.size() != tree.getNrOfJoints())
    throw ModelError("armature: " + std::to_string(armature.size()) + " values given for " +
                     std::to_string(tree.getNrOfJoints()) + " joints");
  // The links as written, and the rules on their inertias and masses (model_rules.hpp, the
  // checker's too); the first error refuses the tree.
  std::vector<ReadLink> links = readLinks(tree, base_inertia, armature);
  std::vector<Finding> findings;
  std::vector<rules::MassNode> nodes;
  for (const ReadLink& l : links) {
    if (!l.body.com.allFinite()) fail("link", l.body.name, "its inertial values hold NaN or infinite numbers");
    rules::checkInertia(l.body.name, l.body.mass, l.body.I_com, findings);
    nodes.push_back(l.node);
  }
  rules::checkRigidBodies(nodes, findings);
  rules::checkMassDistribution(nodes, findings);
  if (const Finding* e = rules::firstError(findings)) throw rules::RuleError(*e);
  // What the dynamics read: a joint that moves no mass is fixed, round-off below zero is zero.
  std::set<std::string> moves_no_mass;
  for (const Finding& f : findings)
    if (f.kind == "joint_moves_no_mass") {
      moves_no_mass.insert(f.element);
      fixed_joints_.push_back({f.element, f.message});
    }
  std::vector<bool> fixed(links.size(), false), corrected(links.size(), false);
  for (std::size_t i = 0; i < links.size(); ++i) {
    fixed[i] = links[i].node.movable && moves_no_mass.count(links[i].node.joint) > 0;
    const Matrix3d I = rules::withoutNegativeMoments(links[i].body.mass, links[i].body.I_com);
    corrected[i] = I != links[i].body.I_com;
    links[i].body.I_com = I;
  }
  for (const Finding& f : findings) diagnostics_.push_back({f.element, f.message, f.kind, f.severity});
  const bool rebuild = std::find(fixed.begin(), fixed.end(), true) != fixed.end() ||
                       std::find(corrected.begin() + 1, corrected.end(), true) != corrected.end();
  tree_ = rebuild ? rebuiltTree(links, fixed, corrected) : tree;
  if (rebuild && !armature.empty()) {  // the coordinates' armature, by joint name (the numbering changed)
    armature.assign(tree_.getNrOfJoints(), 0.0);
    for (std::size_t i = 1; i < links.size(); ++i)
      if (links[i].node.movable && !fixed[i])
        armature[GetTreeElementQNr(tree_.getSegment(links[i].body.name)->second)] = links[i].node.armature;
  }
  // A mimic joint made fixed (it moves no mass) follows nothing.
  mimic_.erase(std::remove_if(mimic_.begin(), mimic_.end(),
                              [&](const Mimic& m) {
                                for (const FixedJoint& f : fixed_joints_)
                                  if (f.joint == m.joint) return true;
                                return false;
                              }),
               mimic_.end());
  build(detail::kdlInertia(links.front().body), armature);
  // The note's kind says where G* runs: `dense_route` (the kind of this note before the recursion
  // took mimic joints, kept for the same meaning), `mimic_constraints` when the recursion takes it.
  if (!mimic_.empty()) {
    const bool recursion = detail::mimicGStarTakesRecursion(nj(), mimic_.size());
    diagnostics_.push_back({"", std::to_string(mimic_.size()) + " mimic joint(s) follow other joints: the motion's "
                                "O(n) recursion imposes the couplings as constraints; G*, the velocity jumps "
                                "and the capture take " +
                                    std::string(recursion ? "it too (few mimic joints: 4 k <= n, faster there)"
                                                          : "the dense route (many mimic joints: 4 k > n, faster there)"),
                            recursion ? "mimic_constraints" : "dense_route", Severity::Note});
  }
  joint_properties_.assign(nj(), JointProperties{});
  checkArmature();
  validate();
  detail::checkMassMatrix(*this, diagnostics_);
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

void FloatingModel::checkArmature() const {
  if (armature_.size() != nj())
    throw ModelError("armature: " + std::to_string(armature_.size()) + " values given for " +
                     std::to_string(nj()) + " joints");
  for (unsigned int j = 0; j < nj(); ++j)
    if (!std::isfinite(armature_[j]) || armature_[j] < 0.0)
      fail("joint", joint_names_[j], "armature must be a finite value >= 0");
}

void FloatingModel::validate() {
  // KDL-level checks of the frames (the inertias were checked as read), then the composites.
  for (const Body& b : bodies_) {
    if (b.parent < 0) continue;
    const KDL::Joint& joint = b.segment.getJoint();
    if (!allFinite(b.segment.pose(0.0)))
      fail("link", b.name, "the pose of its frame (joint origin) holds NaN or infinite values");
    if (joint.getType() != KDL::Joint::None) {
      const KDL::Vector axis = joint.JointAxis();
      if (!allFinite(axis) || !allFinite(joint.JointOrigin()) || std::abs(axis.Norm() - 1.0) > 1e-9)
        fail("joint", joint.getName(), "its axis is zero, NaN or infinite");
    }
  }
  checkComposites();
  total_mass_ = 0.0;
  for (const Body& b : bodies_) total_mass_ += b.mass;
  motions_ = std::make_shared<const detail::MotionTable>(bodies_);
}

void FloatingModel::checkComposites() {
  // Each rigid body of the dynamics (the base, or a link on a movable joint, with every link
  // fixed to it): its inertia about its own CoM, from its links' at their fixed poses.
  const std::size_t nb = bodies_.size();
  std::vector<int> head(nb, 0);
  std::vector<KDL::Frame> in_head(nb, KDL::Frame::Identity());  // pose of each link in its head's frame
  for (std::size_t i = 1; i < nb; ++i) {
    const Body& b = bodies_[i];
    if (b.joint >= 0) {
      head[i] = static_cast<int>(i);
    } else {
      head[i] = head[b.parent];
      in_head[i] = in_head[b.parent] * b.segment.pose(0.0);
    }
  }
  for (std::size_t h = 0; h < nb; ++h) {
    if (head[h] != static_cast<int>(h)) continue;
    double m = 0.0;
    Vector3d first = Vector3d::Zero();
    Matrix3d I_origin = Matrix3d::Zero();
    std::vector<std::string> names;
    for (std::size_t i = h; i < nb; ++i) {
      if (head[i] != static_cast<int>(h)) continue;
      const Body& b = bodies_[i];
      names.push_back(detail::quoted(b.name));
      if (!(b.mass > 0.0) && b.I_com.isZero(0.0)) continue;  // a frame
      const Matrix3d R = toEigen(in_head[i].M);
      const Vector3d c = R * b.com + toEigen(in_head[i].p);
      m += b.mass;
      first += b.mass * c;
      I_origin += R * b.I_com * R.transpose() + b.mass * (c.squaredNorm() * Matrix3d::Identity() - c * c.transpose());
    }
    if (!(m > 0.0)) continue;  // massless: the mass rules have spoken
    const Vector3d r = first / m;
    const Matrix3d I_c = I_origin - m * (r.squaredNorm() * Matrix3d::Identity() - r * r.transpose());
    const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(0.5 * (I_c + I_c.transpose()), Eigen::EigenvaluesOnly);
    const Vector3d l = eig.eigenvalues();
    if (l(0) > 1e-9 * l(2)) continue;
    const std::string what = names.size() == 1 ? "link " + names.front() : "links " + detail::listNames(names);
    diagnostics_.push_back(
        {bodies_[h].name,
         "the rigid body of " + what + " (" + rules::number(m) + " kg) has " +
             (l(2) <= 0.0 ? "no rotational inertia (a point mass)" : "no rotational inertia about one axis (a rod)") +
             ", principal moments " + rules::number(l(0)) + ", " + rules::number(l(1)) + ", " + rules::number(l(2)) +
             " kg m^2 about its CoM: the mass matrix is positive definite only where the other bodies supply "
             "that inertia (compute calls return E_NOT_POSITIVE_DEFINITE where they do not)",
         "singular_composite", Severity::Warning});
  }
}

void FloatingModel::refuseMimic(const std::string& who) const {
  if (mimic_.empty()) return;
  std::vector<std::string> names;
  for (const Mimic& m : mimic_) names.push_back(detail::quoted(m.joint));
  throw ModelError(who + ": the model has mimic joints (" + detail::listNames(names) +
                   "): coupled joints are not supported here; remove the <mimic> elements to treat them as "
                   "free joints");
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

FloatingModel FloatingModel::withJointProperties(const std::map<std::string, JointProperties>& by_name) const {
  FloatingModel copy(*this);
  for (const auto& [name, p] : by_name) {
    const int j = jointIndex(name);
    if (j < 0) {
      bool not_coordinate = false;  // fixed (it moves no mass), or a mimic joint
      for (const FixedJoint& f : fixed_joints_) not_coordinate |= f.joint == name;
      for (const Mimic& m : mimic_) not_coordinate |= m.joint == name;
      if (not_coordinate) continue;
      throw ModelError("joint properties: the model has no joint " + detail::quoted(name));
    }
    if (std::isnan(p.lower) || std::isnan(p.upper) || !(p.lower <= p.upper))
      fail("joint", name, "position limits [" + rules::number(p.lower) + ", " + rules::number(p.upper) + "] are not an interval");
    for (const double v : {p.effort, p.velocity, p.damping, p.friction})
      if (!(v >= 0.0)) fail("joint", name, "effort and velocity limits, damping and friction must be >= 0");
    copy.joint_properties_[j] = p;
  }
  return copy;
}

std::vector<double> FloatingModel::treeArmature() const {
  // Back to the tree's joints (q_nr order): a coordinate's on its own joint, none on mimic joints.
  std::vector<double> tree(tree_.getNrOfJoints(), 0.0);
  for (unsigned int j = 0; j < nj(); ++j)
    tree[GetTreeElementQNr(tree_.getSegment(bodies_[joint_body_[j]].name)->second)] = armature_[j];
  return tree;
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
  diagnostics.push_back(
      {link, "carries a rigid payload of " + std::to_string(inertia.getMass()) + " kg", "payload", Severity::Warning});
  FloatingModel merged(tree, base, treeArmature(), {}, mimic_);
  merged.diagnostics_ = std::move(diagnostics);
  merged.fixed_joints_ = fixed_joints_;
  merged.joint_properties_ = joint_properties_;
  return merged;
}

}  // namespace kdl_space
