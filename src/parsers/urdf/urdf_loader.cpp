#include "kdl_space/parsers/urdf/urdf_loader.hpp"

#include <console_bridge/console.h>
#include <kdl_parser/kdl_parser.hpp>
#include <urdf_parser/urdf_parser.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/parsers/input_file.hpp"
#include "spatial/message_text.hpp"
#include "parsers/urdf/urdf_rules.hpp"
#include "parsers/urdf/urdf_graph.hpp"
#include "parsers/urdf/urdf_parse.hpp"
#include "parsers/urdf/urdf_text.hpp"
#include "parsers/urdf/urdf_xml.hpp"

namespace kdl_space {
namespace {

/// Collects urdfdom's console_bridge messages instead of letting them reach stderr.
class CapturedLog : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) errors.push_back(text);
  }
  std::vector<std::string> errors;
};

}  // namespace

/// Parses with urdfdom; its error messages become the error text. urdfdom returns a model even
/// after some errors (an unparsable number in <inertial> leaves the link massless): any logged
/// error refuses the file.
urdf::ModelInterfaceSharedPtr parseUrdfXml(const std::string& xml, const std::string& source) {
  static std::mutex console_mutex;  // console_bridge's handler is process-wide
  std::lock_guard<std::mutex> lock(console_mutex);
  CapturedLog log;
  console_bridge::useOutputHandler(&log);
  urdf::ModelInterfaceSharedPtr model;
  try {
    // Four trailing spaces: TinyXML 2.6.2 (urdfdom's XML parser) steps over a whole UTF-8
    // sequence after a lead byte, past the terminating NUL when the text ends inside one, and
    // reads on beyond the buffer (fuzz regression tests/data/fuzz_regressions/urdf/
    // utf8_lead_byte_at_end.urdf). Whitespace after the document changes nothing else.
    model = urdf::parseURDF(xml + "    ");
  } catch (const std::exception& e) {
    log.errors.push_back(e.what());
  }
  console_bridge::restorePreviousOutputHandler();
  if (!model || !log.errors.empty()) {
    std::string why;
    for (const std::string& m : log.errors) why += (why.empty() ? "" : "; ") + m;
    throw ModelError(source + ": not XML or not a usable URDF" + (why.empty() ? "" : ": " + why));
  }
  return model;
}

namespace {

/// The base inertia in the base link's frame, from urdfdom (kdl_parser would drop it).
KDL::RigidBodyInertia baseInertia(const urdf::Link& base) {
  if (!base.inertial) return KDL::RigidBodyInertia::Zero();
  const urdf::Inertial& in = *base.inertial;
  const urdf::Rotation& q = in.origin.rotation;
  const KDL::Rotation R = KDL::Rotation::Quaternion(q.x, q.y, q.z, q.w);
  // URDF gives the inertia in the <inertial> frame; KDL wants it in the link frame: R I R^T.
  const KDL::RigidBodyInertia in_link_axes =
      R * KDL::RigidBodyInertia(0.0, KDL::Vector::Zero(),
                                KDL::RotationalInertia(in.ixx, in.iyy, in.izz, in.ixy, in.ixz, in.iyz));
  const urdf::Vector3& c = in.origin.position;
  return KDL::RigidBodyInertia(in.mass, KDL::Vector(c.x, c.y, c.z), in_link_axes.getRotationalInertia());
}

/// The URDF name of a joint type, as the shared rules (urdf_rules.hpp, model_rules.hpp) take it.
std::string typeName(const urdf::Joint& j) {
  switch (j.type) {
    case urdf::Joint::REVOLUTE: return "revolute";
    case urdf::Joint::CONTINUOUS: return "continuous";
    case urdf::Joint::PRISMATIC: return "prismatic";
    case urdf::Joint::FLOATING: return "floating";
    case urdf::Joint::PLANAR: return "planar";
    case urdf::Joint::FIXED: return "fixed";
    default: return "unknown";
  }
}

/// Limits, damping and friction of the movable joints, as urdfdom read them. An effort or velocity
/// limit of 0 (files write it for "not given": no joint could move) is no limit.
std::map<std::string, JointProperties> properties(const urdf::ModelInterface& model) {
  std::map<std::string, JointProperties> by_name;
  for (const auto& [name, joint] : model.joints_) {
    if (!rules::isMovable(typeName(*joint))) continue;
    JointProperties p;
    if (const urdf::JointLimitsSharedPtr& l = joint->limits) {
      if (joint->type != urdf::Joint::CONTINUOUS) p.lower = l->lower, p.upper = l->upper;
      if (l->effort > 0.0) p.effort = l->effort;
      if (l->velocity > 0.0) p.velocity = l->velocity;
    }
    if (const urdf::JointDynamicsSharedPtr& d = joint->dynamics) p.damping = d->damping, p.friction = d->friction;
    by_name[name] = p;
  }
  return by_name;
}

}  // namespace

FloatingModel loadUrdfString(const std::string& bytes, const std::string& source, std::vector<Diagnostic> notes) {
  // Its names in UTF-8, without control characters, whatever writer they reach.
  const detail::UrdfText utf8 = detail::urdfText(bytes);
  if (!utf8.problem.empty()) throw ModelError(source + ": " + utf8.problem);
  const std::string& written = utf8.text;
  // Before TinyXML's recursive descent sees the text (parse, twice below).
  if (const std::string problem = rules::xmlDepthProblem(written); !problem.empty())
    throw ModelError(source + ": not XML that can be read safely: " + problem);
  if (const std::string problem = rules::xacroProblem(written); !problem.empty())
    throw ModelError(source + ": not a URDF yet: " + problem);
  // Lenient readings of what urdfdom refuses, each a finding (the checker's too).
  std::vector<Finding> findings;
  std::vector<std::string> unlimited;
  const std::string xml = detail::withUnlimitedRevolutesContinuous(written, unlimited);
  for (const std::string& joint : unlimited) rules::checkRevoluteWithoutLimit(joint, findings);
  const urdf::ModelInterfaceSharedPtr model = parseUrdfXml(xml, source);
  std::vector<Diagnostic> diagnostics;
  if (!utf8.note.empty()) diagnostics.push_back({"", utf8.note, "encoding", Severity::Note});
  auto fail = [&](const std::string& what) -> void { throw ModelError(source + ": " + what); };

  // The links and joints as a graph, walked as the checker walks them (urdf_graph.hpp). urdfdom
  // refuses several roots and none; it accepts a link with several parents, and cycles no root
  // reaches.
  const detail::LinkGraph graph = detail::linkGraph(*model);
  const std::vector<int> roots = graph.roots();
  if (roots.empty()) fail("no root link");

  // The base: the root link, or the child of a floating joint hanging from a massless root.
  const urdf::LinkConstSharedPtr root = model->getLink(graph.link(roots.front()));
  urdf::LinkConstSharedPtr base = root;
  std::string dropped_joint;
  if (rules::dropsRootJoint(!root->inertial || root->inertial->mass == 0.0, root->child_joints.size(),
                            root->child_joints.empty() ? "" : typeName(*root->child_joints[0]))) {
    const urdf::JointSharedPtr& free_joint = root->child_joints[0];
    dropped_joint = free_joint->name;
    diagnostics.push_back(
        {free_joint->name, typeName(*free_joint) + " joint from the massless root " + detail::quoted(root->name) +
                               " dropped: link " + detail::quoted(free_joint->child_link_name) +
                               " is the free-floating base",
         "floating_root_joint_dropped", Severity::Note});
    base = model->getLink(free_joint->child_link_name);
  }

  // The shared rules (the same as checkUrdfFile's); the first error refuses the file.
  std::vector<Mimic> mimic;
  for (const auto& [name, joint] : model->joints_) {
    if (name == dropped_joint) continue;
    const std::string type = typeName(*joint);
    rules::checkJointType(name, type, findings);
    if (joint->mimic && rules::isMovable(type)) {
      const urdf::JointConstSharedPtr leader = model->getJoint(joint->mimic->joint_name);
      rules::checkMimic(name, joint->mimic->joint_name, leader && rules::isMovable(typeName(*leader)),
                        joint->mimic->multiplier, joint->mimic->offset, findings);
      mimic.push_back({name, joint->mimic->joint_name, joint->mimic->multiplier, joint->mimic->offset});
    }
    if (rules::isMovable(type))
      rules::checkAxis(name, Eigen::Vector3d(joint->axis.x, joint->axis.y, joint->axis.z), findings);
    if ((type == "revolute" || type == "prismatic") && joint->limits)
      rules::checkLimits(name, joint->limits->lower, joint->limits->upper, findings);
  }
  std::vector<std::pair<std::string, std::string>> follows;
  for (const Mimic& m : mimic) follows.emplace_back(m.joint, m.leader);
  rules::checkMimicCycles(follows, findings);
  if (base == root) rules::checkRootInertia(root->name, root->inertial != nullptr, findings);
  // Below the base, breadth first: the problem nearest the base, a link reached twice (its joints
  // close a loop) or the first link too deep.
  const detail::Walk below = graph.walk(graph.find(base->name), detail::WalkOrder::BreadthFirst);
  const int deep = detail::firstDeeperThan(below, rules::kMaxTreeDepth);
  if (below.reached_twice >= 0 && (deep < 0 || below.reached_twice_from < deep))
    findings.push_back(rules::error("loop", ElementType::Link, graph.link(below.reached_twice),
                                    "reached twice from the base: its joints close a loop, and a URDF "
                                    "describes a tree"));
  else if (deep >= 0)
    rules::checkDepth(graph.link(below.steps[deep].link), below.steps[deep].depth, findings);
  if (const Finding* e = rules::firstError(findings)) fail(describe(*e));
  for (const Finding& f : findings) diagnostics.push_back({f.element, f.message, f.kind, f.severity});

  // kdl_parser on a copy prepared so it has nothing to warn about (PITFALLS.md #2): no root
  // inertia, the dropped floating joint gone.
  const urdf::ModelInterfaceSharedPtr for_kdl = parseUrdfXml(xml, source);
  for_kdl->root_link_ = for_kdl->links_.at(base->name);
  for_kdl->root_link_->inertial.reset();
  KDL::Tree tree;
  if (!kdl_parser::treeFromUrdfModel(*for_kdl, tree)) fail("kdl_parser could not build a KDL tree");
  // urdfdom accepts joints that form a loop no root reaches (e.g. a joint whose parent is its own
  // child); kdl_parser, walking from the base, leaves the links the walk did not reach out silently.
  for (int l = 0; l < graph.size(); ++l)
    if (!below.reached[l] && graph.link(l) != root->name)
      fail("link " + detail::quoted(graph.link(l)) + " is not connected to the base " + detail::quoted(base->name) +
           ": its joints form a loop (a URDF describes a tree)");

  notes.insert(notes.end(), diagnostics.begin(), diagnostics.end());  // a conversion's notes first
  try {
    return FloatingModel(tree, baseInertia(*base), {}, std::move(notes), std::move(mimic))
        .withJointProperties(properties(*model));
  } catch (const Error& e) {
    e.rethrowWithContext(source + ": ");
  }
}

std::string readUrdfText(const std::string& path) {
  // Before it is read: a device never ends, and a file of gigabytes is no robot.
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
    throw ModelError(detail::shownPath(path) + ": is not a regular file; expected a URDF file");
  if (const std::string why = fileTooLarge(path, "URDF file", max_input_file_bytes); !why.empty())
    throw ModelError(detail::shownPath(path) + ": " + why);
  std::ifstream in(path);
  if (!in) throw ModelError(detail::shownPath(path) + ": cannot open the file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw ModelError(detail::shownPath(path) + ": cannot read the file");
  return text.str();
}

FloatingModel loadUrdfFile(const std::string& path) { return loadUrdfString(readUrdfText(path), path); }

}  // namespace kdl_space
