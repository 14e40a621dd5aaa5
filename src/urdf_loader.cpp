#include "kdl_space/urdf_loader.hpp"

#include <console_bridge/console.h>
#include <kdl_parser/kdl_parser.hpp>
#include <urdf_parser/urdf_parser.h>

#include <cmath>
#include <fstream>
#include <mutex>
#include <sstream>

#include "kdl_space/errors.hpp"

namespace kdl_space {
namespace {

std::string quoted(const std::string& s) { return "'" + s + "'"; }

/// Collects urdfdom's console_bridge messages instead of letting them reach stderr.
class CapturedLog : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) errors.push_back(text);
  }
  std::vector<std::string> errors;
};

/// Parses with urdfdom; its error messages become the error text. urdfdom returns a model even
/// after some errors (an unparsable number in <inertial> leaves the link massless): any logged
/// error refuses the file.
urdf::ModelInterfaceSharedPtr parse(const std::string& xml, const std::string& source) {
  static std::mutex console_mutex;  // console_bridge's handler is process-wide
  std::lock_guard<std::mutex> lock(console_mutex);
  CapturedLog log;
  console_bridge::useOutputHandler(&log);
  urdf::ModelInterfaceSharedPtr model;
  try {
    model = urdf::parseURDF(xml);
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

bool isFreeJoint(const urdf::Joint& j) {
  return j.type == urdf::Joint::FLOATING || j.type == urdf::Joint::PLANAR;
}

std::string typeName(const urdf::Joint& j) {
  return j.type == urdf::Joint::FLOATING ? "floating" : j.type == urdf::Joint::PLANAR ? "planar" : "unknown";
}

}  // namespace

FloatingModel loadUrdfString(const std::string& xml, const std::string& source) {
  const urdf::ModelInterfaceSharedPtr model = parse(xml, source);
  std::vector<Diagnostic> diagnostics;
  auto fail = [&](const std::string& what) -> void { throw ModelError(source + ": " + what); };

  // The base: the root link, or the child of a floating joint hanging from a massless root.
  urdf::LinkConstSharedPtr base = model->getRoot();
  std::string dropped_joint;
  if (!base) fail("no root link");
  if (base->child_joints.size() == 1 && base->child_joints[0]->type == urdf::Joint::FLOATING &&
      (!base->inertial || base->inertial->mass == 0.0)) {
    const urdf::JointSharedPtr& free_joint = base->child_joints[0];
    dropped_joint = free_joint->name;
    diagnostics.push_back(
        {free_joint->name, "floating joint from the massless root " + quoted(base->name) +
                               " dropped: link " + quoted(free_joint->child_link_name) +
                               " is the free-floating base"});
    base = model->getLink(free_joint->child_link_name);
  }

  for (const auto& [name, joint] : model->joints_) {
    if (name == dropped_joint) continue;
    if (isFreeJoint(*joint))
      fail("joint " + quoted(name) + ": a " + typeName(*joint) +
           " joint inside the tree is not supported (only the base floats; use revolute, "
           "continuous, prismatic or fixed joints)");
    if (joint->type == urdf::Joint::REVOLUTE || joint->type == urdf::Joint::CONTINUOUS ||
        joint->type == urdf::Joint::PRISMATIC) {
      const urdf::Vector3& a = joint->axis;
      const double norm = std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
      if (!std::isfinite(norm) || norm == 0.0)
        fail("joint " + quoted(name) + ": its axis has zero length (or is not finite)");
      if (std::abs(norm - 1.0) > 1e-9)
        diagnostics.push_back({name, "axis is not unit length (norm " + std::to_string(norm) +
                                         "): normalised"});
    }
  }
  if (base->inertial)
    diagnostics.push_back({base->name, "root link inertia kept as the base body's inertia "
                                       "(kdl_parser drops it)"});

  // kdl_parser on a copy prepared so it has nothing to warn about (PITFALLS.md #2): no root
  // inertia, the dropped floating joint gone.
  const urdf::ModelInterfaceSharedPtr for_kdl = parse(xml, source);
  for_kdl->root_link_ = for_kdl->links_.at(base->name);
  for_kdl->root_link_->inertial.reset();
  KDL::Tree tree;
  if (!kdl_parser::treeFromUrdfModel(*for_kdl, tree)) fail("kdl_parser could not build a KDL tree");

  try {
    return FloatingModel(tree, baseInertia(*base), {}, std::move(diagnostics));
  } catch (const ModelError& e) {
    throw ModelError(source + ": " + e.what());
  }
}

FloatingModel loadUrdfFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ModelError(path + ": cannot open the file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw ModelError(path + ": cannot read the file");
  return loadUrdfString(text.str(), path);
}

}  // namespace kdl_space
