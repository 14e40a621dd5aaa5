#include "multibody/model_build.hpp"

#include <cmath>
#include <map>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/spatial/spatial.hpp"
#include "spatial/message_text.hpp"

namespace kdl_space {
namespace detail {

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

KDL::RigidBodyInertia kdlInertia(const Body& b) {
  const Matrix3d& I = b.I_com;
  return KDL::RigidBodyInertia(b.mass, toKDL(b.com),
                               KDL::RotationalInertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)));
}

void fail(const std::string& what, const std::string& name, const std::string& message) {
  throw ModelError(what + " " + quoted(name) + ": " + message);
}

}  // namespace detail

namespace {
using detail::fail;

/// The name of the tree's joint number t.
std::string treeJointName(const std::map<std::string, unsigned int>& q_nr, unsigned int t) {
  for (const auto& [name, nr] : q_nr)
    if (nr == t) return name;
  return "?";
}

/// The tree's movable joints by name: their q_nr.
std::map<std::string, unsigned int> treeJoints(const KDL::Tree& tree) {
  std::map<std::string, unsigned int> q_nr;
  for (const auto& [name, element] : tree.getSegments()) {
    const KDL::Joint& joint = GetTreeElementSegment(element).getJoint();
    if (joint.getType() != KDL::Joint::None) q_nr[joint.getName()] = GetTreeElementQNr(element);
  }
  return q_nr;
}
}  // namespace

void FloatingModel::build(const KDL::RigidBodyInertia& base_inertia, const std::vector<double>& tree_armature) {
  // Coordinates: the tree's movable joints (q_nr order) but the mimic ones, each of which follows
  // a coordinate: its value is multiplier * q + offset (a chain of mimics composed).
  const std::map<std::string, unsigned int> q_nr = treeJoints(tree_);
  const unsigned int n_tree = tree_.getNrOfJoints();
  struct Follow {
    int leader = -1;  ///< tree joint (q_nr); -1: a coordinate
    double multiplier = 1.0, offset = 0.0;
  };
  std::vector<Follow> follow(n_tree);
  for (const Mimic& m : mimic_) {
    const auto joint = q_nr.find(m.joint), leader = q_nr.find(m.leader);
    if (joint == q_nr.end()) fail("joint", m.joint, "has a <mimic>, but is no movable joint of the model");
    if (leader == q_nr.end())
      fail("joint", m.joint, "mimics " + detail::quoted(m.leader) + ", which is no movable joint of the model" +
                                 " (fixed, or moving no mass)");
    if (!std::isfinite(m.multiplier) || !std::isfinite(m.offset) || m.multiplier == 0.0)
      fail("joint", m.joint, "its <mimic> multiplier must be finite and non-zero, its offset finite");
    follow[joint->second] = {static_cast<int>(leader->second), m.multiplier, m.offset};
  }
  // Compose chains (a mimic of a mimic) down to a coordinate; a cycle has none.
  std::vector<Follow> resolved(n_tree);
  for (unsigned int t = 0; t < n_tree; ++t) {
    Follow f{static_cast<int>(t), 1.0, 0.0};
    for (unsigned int steps = 0; follow[f.leader].leader >= 0; ++steps) {
      if (steps > n_tree) fail("joint", treeJointName(q_nr, t), "its <mimic> joints form a cycle: none is a coordinate");
      const Follow& next = follow[f.leader];
      f = {next.leader, f.multiplier * next.multiplier, f.multiplier * next.offset + f.offset};
    }
    resolved[t] = f;
  }
  std::vector<int> coordinate(n_tree, -1);
  unsigned int n = 0;
  for (unsigned int t = 0; t < n_tree; ++t)
    if (follow[t].leader < 0) coordinate[t] = static_cast<int>(n++);
  joint_names_.assign(n, std::string());
  joint_body_.assign(n, -1);
  armature_.assign(n, 0.0);

  // Depth-first traversal, computed once: parents precede children.
  struct Item {
    KDL::SegmentMap::const_iterator element;
    int parent;
  };
  std::vector<Item> stack{{tree_.getRootSegment(), -1}};
  while (!stack.empty()) {
    const Item item = stack.back();
    stack.pop_back();
    const KDL::Segment& segment = GetTreeElementSegment(item.element->second);
    Body body;
    body.name = item.element->first;
    body.parent = item.parent;
    body.segment = segment;
    if (item.parent < 0) {
      detail::splitInertia(base_inertia, body);
    } else {
      detail::splitInertia(segment.getInertia(), body);
      if (segment.getJoint().getType() != KDL::Joint::None) {
        const unsigned int t = GetTreeElementQNr(item.element->second);
        const Follow& f = resolved[t];
        body.joint = coordinate[f.leader];
        body.multiplier = f.multiplier;
        body.offset = f.offset;
        // KDL gives the twist at the tip; the rotation axis (or sliding direction) is fixed in
        // the parent frame, so at the parent's origin the twist does not depend on q.
        body.joint_twist =
            f.multiplier * toEigen(segment.twist(f.offset, 1.0).RefPoint(-segment.pose(f.offset).p));
        const double armature = t < tree_armature.size() ? tree_armature[t] : 0.0;
        armature_[body.joint] += f.multiplier * f.multiplier * armature;  // reflected onto the leader
        if (follow[t].leader < 0) {
          joint_names_[body.joint] = segment.getJoint().getName();
          joint_body_[body.joint] = static_cast<int>(bodies_.size());
        }
      }
    }
    const int index = static_cast<int>(bodies_.size());
    bodies_.push_back(body);
    const auto& children = GetTreeElementChildren(item.element->second);
    for (auto it = children.rbegin(); it != children.rend(); ++it) stack.push_back({*it, index});
  }
}

}  // namespace kdl_space
