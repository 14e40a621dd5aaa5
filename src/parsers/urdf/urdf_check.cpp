#include "kdl_space/parsers/urdf/urdf_check.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "spatial/message_text.hpp"
#include "kdl_space/parsers/input_file.hpp"
#include "parsers/urdf/urdf_rules.hpp"
#include "parsers/urdf/urdf_graph.hpp"
#include "parsers/urdf/urdf_summary.hpp"
#include "parsers/urdf/urdf_text.hpp"
#include "parsers/urdf/urdf_xml.hpp"

namespace kdl_space {
namespace {


/// Above this ratio of the base mass to the lightest moving link's, H* and G* are ill-conditioned.
constexpr double kMassRatioLimit = 1e6;

/// "'a', 'b', 'c'" of at most `at_most` names, then how many more.
std::string quotedList(const std::vector<std::string>& names, std::size_t at_most = 20) {
  std::vector<std::string> shown;
  for (std::size_t i = 0; i < names.size() && i < at_most; ++i) shown.push_back(detail::quoted(names[i]));
  std::string list = shown.empty() ? "" : detail::listNames(shown);
  if (names.size() > at_most) list += " and " + std::to_string(names.size() - at_most) + " more";
  return list;
}

/// The checker: the document read as urdfdom reads it (urdf_xml.hpp), its links and joints as a
/// graph (urdf_graph.hpp, the walk the loader uses), the rules of urdf_rules.hpp and model_rules.hpp on the tree,
/// the tips; the model is loaded and measured (urdf_summary.hpp) only when nothing is wrong.
class Checker {
 public:
  Checker(const std::string& source, const std::vector<std::string>& tips) : tips_(tips) {
    report_.source = source;
  }

  UrdfReport run(const std::string& xml);

 private:
  void add(Finding f) {
    (f.severity == Severity::Error ? report_.errors : f.severity == Severity::Warning ? report_.warnings : report_.notes)
        .push_back(std::move(f));
  }
  void addAll(const std::vector<Finding>& findings) {
    for (const Finding& f : findings) add(f);
  }
  void checkGraph();
  void checkTree();
  void checkTips();
  void checkMassRatio(const std::string& conditions);

  std::vector<std::string> tips_;
  UrdfReport report_;
  detail::UrdfDocument doc_;
  detail::LinkGraph graph_;  ///< doc_'s links and joints, same indices
  bool graph_ok_ = true;     ///< the links and joints form one tree
  int root_ = -1;            ///< the URDF root link (the largest tree's when there are several)
  int base_ = -1;            ///< the free-floating base link
  int dropped_joint_ = -1;   ///< the floating joint from a massless root, dropped
  int lightest_ = -1;        ///< the lightest moving link with mass (for the mass ratio)
  bool lightest_fixed_ = false;  ///< it hangs on a fixed joint (below a moving one)
};

/// Links and joints as a graph: missing links, roots, loops; the base.
void Checker::checkGraph() {
  const detail::LinkGraph& g = graph_;
  for (const detail::GraphJoint& joint : g.joints())
    for (const bool parent : {true, false}) {
      const std::string& link = parent ? joint.parent_link : joint.child_link;
      if (link.empty() || (parent ? joint.parent : joint.child) >= 0) continue;
      add(rules::error("missing_link", ElementType::Joint, joint.name,
                       std::string(parent ? "parent" : "child") + " link " + detail::quoted(link) +
                           " does not exist: add <link name=\"" + link + "\"/>, or correct the name"));
      graph_ok_ = false;
    }

  if (g.size() == 0) {
    add(rules::error("no_root", ElementType::Robot, doc_.robot, "no link: the robot has no <link name=\"...\">"));
    graph_ok_ = false;
    return;
  }
  // A link is named as a child even by a joint whose parent does not exist: not a root.
  const std::vector<int> roots = g.roots();
  if (roots.empty()) {
    add(rules::error("no_root", ElementType::Robot, doc_.robot,
                     "no root link: every link is the child of a joint (the joints form a loop)"));
    graph_ok_ = false;
  }

  // Closed loops: a link with several parents.
  for (const int l : g.severalParents()) {
    std::vector<std::string> names;
    for (const int j : g.parentJoints(l)) names.push_back(g.joints()[j].name);
    add(rules::error("loop", ElementType::Link, g.link(l),
                     "the child of " + std::to_string(names.size()) + " joints (" + quotedList(names) +
                         "): they close a kinematic loop, and a URDF describes a tree; keep one of them "
                         "(kdl_space cannot model closed chains)"));
    graph_ok_ = false;
  }

  // What each root reaches (a link reached from two roots counts for the first), and the cycles
  // among the links no root reaches.
  std::vector<bool> reached(g.size(), false);
  std::vector<std::size_t> tree_size(g.size(), 0);
  for (const int r : roots) {
    detail::Walk tree = g.walk(r, detail::WalkOrder::DepthFirst, std::move(reached));
    tree_size[r] = tree.steps.size();
    reached = std::move(tree.reached);
  }
  for (const detail::LinkGraph::Cycle& cycle : g.cycles(reached)) {
    std::string chain;
    std::vector<std::string> joint_names;
    for (std::size_t k = 0; k < cycle.links.size(); ++k) {
      chain += g.link(cycle.links[k]) + " -> ";
      joint_names.push_back(g.joints()[cycle.joints[k]].name);
    }
    chain += g.link(cycle.links.front());
    const std::string what = joint_names.size() == 1
                                 ? "joint " + detail::quoted(joint_names.front()) + " makes the link its own parent"
                                 : "joints " + quotedList(joint_names) + " form a cycle";
    add(rules::error("loop", ElementType::Link, g.link(cycle.links.front()),
                     what + " (" + chain + "): a URDF describes a tree"));
    graph_ok_ = false;
  }

  if (roots.empty()) return;
  root_ = roots.front();
  for (const int r : roots)
    if (tree_size[r] > tree_size[root_]) root_ = r;
  for (const int r : roots) {
    if (r == root_) continue;
    add(rules::error("several_roots", ElementType::Link, g.link(r),
                     "a second root: no joint has it as child, so it is not part of the tree of the root " +
                         detail::quoted(g.link(root_)) + "; attach it with a joint, or remove it"));
    graph_ok_ = false;
  }

  // The base: the root, or the only child of a floating joint from a massless root.
  const detail::XmlLink& root = doc_.links[root_];
  const std::vector<int>& from_root = g.childJoints(root_);
  if (rules::dropsRootJoint(!root.has_inertial || root.mass == 0.0, from_root.size(),
                            from_root.empty() ? "" : doc_.joints[from_root.front()].type))
    dropped_joint_ = from_root.front();
  base_ = dropped_joint_ >= 0 ? g.joints()[dropped_joint_].child : root_;
}

/// Rules on the tree: free joints, the base, massless links, the depth, the mass ratio's lightest link.
void Checker::checkTree() {
  std::vector<Finding> found;
  for (std::size_t j = 0; j < doc_.joints.size(); ++j)
    if (doc_.joints[j].known_type && static_cast<int>(j) != dropped_joint_)
      rules::checkJointType(doc_.joints[j].name, doc_.joints[j].type, found);
  for (const detail::XmlJoint& joint : doc_.joints) {
    if (!joint.has_mimic) continue;
    bool leader_movable = false;
    for (const detail::XmlJoint& other : doc_.joints)
      leader_movable |= other.name == joint.mimic_leader && other.known_type && rules::isMovable(other.type);
    rules::checkMimic(joint.name, joint.mimic_leader, leader_movable, joint.mimic_multiplier, joint.mimic_offset, found);
  }
  std::vector<std::pair<std::string, std::string>> follows;
  for (const detail::XmlJoint& joint : doc_.joints)
    if (joint.has_mimic) follows.emplace_back(joint.name, joint.mimic_leader);
  rules::checkMimicCycles(follows, found);
  if (base_ >= 0) {
    const detail::XmlLink& base = doc_.links[base_];
    if (base_ == root_) rules::checkRootInertia(base.name, base.has_inertial, found);
  }
  if (graph_ok_ && base_ >= 0) {
    const detail::Walk below = graph_.walk(base_, detail::WalkOrder::DepthFirst);
    std::vector<rules::MassNode> nodes;
    std::vector<bool> moving;  // a movable joint between the base and the link
    for (const detail::WalkStep& step : below.steps) {
      const detail::XmlLink& link = doc_.links[step.link];
      rules::MassNode node;
      node.link = link.name;
      node.parent = step.parent_step;
      node.mass = link.has_inertial ? link.mass : 0.0;
      node.rotational = link.inertia_read && !link.I_com.isZero(0.0);
      node.inertia_known = link.inertia_read;
      node.com = link.com;
      node.I_com = link.I_com;
      bool moves = false;
      if (step.parent_step >= 0) {
        const detail::XmlJoint& joint = doc_.joints[step.joint];
        node.joint = joint.name;
        node.movable = joint.known_type && rules::isMovable(joint.type);
        node.R = joint.R;
        node.p = joint.p;
        moves = node.movable || moving[step.parent_step];
      }
      nodes.push_back(node);
      moving.push_back(moves);
    }
    rules::checkRigidBodies(nodes, found);
    rules::checkMassDistribution(nodes, found);
    if (const int deep = detail::firstDeeperThan(below, rules::kMaxTreeDepth); deep >= 0)  // the first is enough
      rules::checkDepth(nodes[deep].link, below.steps[deep].depth, found);
    for (std::size_t i = 1; i < nodes.size(); ++i)
      if (moving[i] && nodes[i].mass > 0.0 && std::isfinite(nodes[i].mass) &&
          (lightest_ < 0 || nodes[i].mass < doc_.links[lightest_].mass)) {
        lightest_ = below.steps[i].link;
        lightest_fixed_ = !nodes[i].movable;
      }
  } else {  // no tree, so no rigid bodies: each link's inertia is judged alone
    for (const detail::XmlLink& link : doc_.links) {
      rules::MassNode node;
      node.link = link.name;
      node.mass = link.mass;
      node.inertia_known = link.inertia_read;
      node.com = link.com;
      node.I_com = link.I_com;
      rules::checkRigidBodies({node}, found);
    }
  }
  addAll(found);
}

void Checker::checkTips() {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < doc_.links.size(); ++i)
    if (dropped_joint_ < 0 || static_cast<int>(i) != root_) names.push_back(doc_.links[i].name);
  for (const std::string& tip : tips_)
    if (std::find(names.begin(), names.end(), tip) == names.end())
      add(rules::error("unknown_tip", ElementType::Tip, tip,
                       "not a link of the model (its links: " + quotedList(names) + ")"));
}

/// The warning for a base much heavier than the lightest moving link, with the condition numbers.
void Checker::checkMassRatio(const std::string& conditions) {
  if (lightest_ < 0 || base_ < 0 || !(doc_.links[base_].mass > 0.0)) return;
  const double base = doc_.links[base_].mass, lightest = doc_.links[lightest_].mass;
  const double ratio = base / lightest;
  const std::string which = lightest_fixed_ ? "this link on a fixed joint (it moves with its parent)" : "this moving link";
  if (ratio > kMassRatioLimit)
    add(rules::warning("mass_ratio", ElementType::Link, doc_.links[lightest_].name,
                       "the base " + detail::quoted(doc_.links[base_].name) + " (" + rules::number(base) + " kg) is " +
                           rules::number(ratio) + " times heavier than " + which + " (" + rules::number(lightest) +
                           " kg), above " + rules::number(kMassRatioLimit) + ": H* and G* may be ill-conditioned (" +
                           conditions + ")"));
}

UrdfReport Checker::run(const std::string& xml) {
  std::vector<Finding> read;
  const bool document = detail::readUrdfXml(xml, doc_, read);
  addAll(read);
  if (!document) return report_;
  report_.model.robot = doc_.robot;
  report_.model.links = doc_.link_elements;
  report_.model.joints = doc_.joint_elements;
  graph_ok_ = doc_.names_complete;
  graph_ = detail::linkGraph(doc_);
  checkGraph();
  checkTree();
  checkTips();
  if (base_ >= 0) report_.model.base = doc_.links[base_].name;
  if (dropped_joint_ >= 0) --report_.model.links, --report_.model.joints;  // not in the model
  checkMassRatio(detail::measureModel(xml, tips_, report_));
  return report_;
}

}  // namespace

UrdfReport checkUrdfString(const std::string& bytes, const std::string& source, const std::vector<std::string>& tips) {
  const detail::UrdfText utf8 = detail::urdfText(bytes);
  if (!utf8.problem.empty()) {
    UrdfReport report;
    report.source = source;
    report.errors.push_back(rules::error("encoding", ElementType::File, "", utf8.problem));
    return report;
  }
  UrdfReport report = Checker(source, tips).run(utf8.text);
  if (!utf8.note.empty()) report.notes.insert(report.notes.begin(), rules::note("encoding", ElementType::File, "", utf8.note));
  return report;
}

UrdfReport checkUrdfFile(const std::string& path, const std::vector<std::string>& tips) {
  UrdfReport report;
  report.source = path;
  auto unreadable = [&](const std::string& why) {
    report.errors.push_back(rules::error("unreadable", ElementType::File, "", why));
    return report;
  };
  // Only regular files: a device such as /dev/zero never ends, a pipe may never open.
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (status.type() == std::filesystem::file_type::directory) return unreadable("is a directory, not a URDF file");
  if (std::filesystem::exists(status) && status.type() != std::filesystem::file_type::regular)
    return unreadable("not a regular file (a device, pipe or socket)");
  if (const std::string why = fileTooLarge(path, "URDF file", max_input_file_bytes); !why.empty()) return unreadable(why);
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) return unreadable(std::string("cannot open the file") + (errno ? std::string(": ") + std::strerror(errno) : ""));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return unreadable("cannot read the file");
  return checkUrdfString(text.str(), path, tips);
}

}  // namespace kdl_space
