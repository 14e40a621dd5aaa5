// writeMjcf: a scenario's robot, state and target as an MJCF document (mjcf.hpp). Plain text: the
// library does not link MuJoCo.
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

#include "kdl_space/parsers/formats/mjcf.hpp"
#include "kdl_space/spatial/errors.hpp"
#include "parsers/formats/urdf_builder.hpp"
#include "spatial/message_text.hpp"

namespace kdl_space {
namespace {
namespace mjcf_out {  // a namespace of its own: the unity build puts other files' helpers beside these

std::string num(double v) { return formats::exactNumber(v); }  // reads back exactly

std::string numbers(std::initializer_list<double> values) {
  std::string s;
  for (const double v : values) s += (s.empty() ? "" : " ") + num(v);
  return s;
}

std::string vec(const KDL::Vector& v) { return numbers({v.x(), v.y(), v.z()}); }

/// w x y z, MJCF's order.
std::string quat(const KDL::Rotation& R) {
  double x = 0, y = 0, z = 0, w = 1;
  R.GetQuaternion(x, y, z, w);
  return numbers({w, x, y, z});
}

/// A text as an XML attribute value.
std::string escaped(const std::string& s) {
  std::string e;
  for (const char c : s) {
    switch (c) {
      case '&': e += "&amp;"; break;
      case '<': e += "&lt;"; break;
      case '>': e += "&gt;"; break;
      case '"': e += "&quot;"; break;
      default: e += c;
    }
  }
  return e;
}

/// A name not yet in `used` (`name`, else name_2, name_3, ...), added to it.
std::string uniqueName(const std::string& name, std::set<std::string>& used) {
  std::string n = name;
  for (int k = 2; used.count(n); ++k) n = name + "_" + std::to_string(k);
  used.insert(n);
  return n;
}

bool finite(const KDL::Frame& f) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (!std::isfinite(f.M(i, j))) return false;
  return std::isfinite(f.p.x()) && std::isfinite(f.p.y()) && std::isfinite(f.p.z());
}

bool finite(const KDL::Twist& t) {
  return std::isfinite(t.vel.x()) && std::isfinite(t.vel.y()) && std::isfinite(t.vel.z()) &&
         std::isfinite(t.rot.x()) && std::isfinite(t.rot.y()) && std::isfinite(t.rot.z());
}

/// `<inertial>` of a body of `mass` with its CoM at `com` and inertia `I` about it (body axes):
/// the principal axes by a symmetric eigen-decomposition in double precision (a right-handed
/// frame), the principal moments as diaginertia. "" for a body without mass nor inertia.
std::string inertial(double mass, const Eigen::Vector3d& com, const Eigen::Matrix3d& I) {
  if (mass == 0.0 && I.isZero(0.0)) return "";
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (I + I.transpose()));
  Eigen::Matrix3d V = eig.eigenvectors();
  if (V.determinant() < 0.0) V.col(2) = -V.col(2);
  const Eigen::Vector3d d = eig.eigenvalues().cwiseMax(0.0);  // a moment negative by round-off: 0
  const Eigen::Quaterniond q(V);
  return "<inertial pos=\"" + numbers({com.x(), com.y(), com.z()}) + "\" quat=\"" +
         numbers({q.w(), q.x(), q.y(), q.z()}) + "\" mass=\"" + num(mass) + "\" diaginertia=\"" +
         numbers({d.x(), d.y(), d.z()}) + "\"/>";
}

/// The document, written element by element; the keyframe's qpos and qvel gathered in the
/// document's joint order (MuJoCo's).
class Writer {
 public:
  void line(const std::string& text) { out_ << std::string(2 * depth_, ' ') << text << '\n'; }
  void open(const std::string& text) { line(text), ++depth_; }
  void close(const std::string& tag) { --depth_, line("</" + tag + ">"); }

  /// A free-floating system as a free tree; names prefixed `prefix`, its contact the site `site`.
  void system(const FloatingSystem& s, const std::string& prefix, const std::string& site);
  /// A rigid target as one free body.
  void rigid(const RigidTarget& t);
  std::string keyframe() const;
  std::string text() const { return out_.str(); }

 private:
  void body(const FloatingSystem& s, const std::vector<std::vector<int>>& children, int i,
            const std::string& prefix, const std::string& site);
  void joint(const FloatingSystem& s, int i, const KDL::Frame& F0, const std::string& prefix);
  void freeJoint(const std::string& body, const KDL::Frame& pose, const KDL::Twist& twist);

  std::ostringstream out_;
  int depth_ = 0;
  std::set<std::string> bodies_, joints_, sites_;
  std::vector<double> qpos_, qvel_;
};

void Writer::freeJoint(const std::string& body, const KDL::Frame& pose, const KDL::Twist& twist) {
  line("<freejoint name=\"" + escaped(uniqueName(body + "_free", joints_)) + "\"/>");
  double x = 0, y = 0, z = 0, w = 1;
  pose.M.GetQuaternion(x, y, z, w);
  qpos_.insert(qpos_.end(), {pose.p.x(), pose.p.y(), pose.p.z(), w, x, y, z});
  const KDL::Vector w_body = pose.M.Inverse(twist.rot);  // MuJoCo: the angular velocity in body axes
  qvel_.insert(qvel_.end(), {twist.vel.x(), twist.vel.y(), twist.vel.z(), w_body.x(), w_body.y(), w_body.z()});
}

void Writer::joint(const FloatingSystem& s, int i, const KDL::Frame& F0, const std::string& prefix) {
  const FloatingModel& m = *s.model;
  const Body& b = m.bodies()[i];
  const KDL::Joint& j = b.segment.getJoint();
  const bool slide = j.getType() == KDL::Joint::TransAxis || j.getType() == KDL::Joint::TransX ||
                     j.getType() == KDL::Joint::TransY || j.getType() == KDL::Joint::TransZ;
  // The joint's axis and a point on it, given in the parent's frame by KDL, in the child body's.
  const KDL::Vector axis = F0.M.Inverse(j.JointAxis());
  const KDL::Vector pos = F0.Inverse(j.JointOrigin());
  const JointProperties& p = m.jointProperties()[b.joint];
  std::string e = "<joint name=\"" + escaped(uniqueName(prefix + m.jointNames()[b.joint], joints_)) +
                  "\" type=\"" + (slide ? "slide" : "hinge") + "\" pos=\"" + vec(pos) + "\" axis=\"" + vec(axis) + "\"";
  if (std::isfinite(p.lower) && std::isfinite(p.upper))
    e += " limited=\"true\" range=\"" + numbers({p.lower, p.upper}) + "\"";
  else
    e += " limited=\"false\"";
  if (p.damping != 0.0) e += " damping=\"" + num(p.damping) + "\"";
  if (p.friction != 0.0) e += " frictionloss=\"" + num(p.friction) + "\"";
  if (!m.armature().empty() && m.armature()[b.joint] != 0.0) e += " armature=\"" + num(m.armature()[b.joint]) + "\"";
  line(e + "/>");
  qpos_.push_back(s.state.q(b.joint));
  qvel_.push_back(s.velocity.qdot.rows() == 0 ? 0.0 : s.velocity.qdot(b.joint));
}

void Writer::body(const FloatingSystem& s, const std::vector<std::vector<int>>& children, int i,
                  const std::string& prefix, const std::string& site) {
  const FloatingModel& m = *s.model;
  const Body& b = m.bodies()[i];
  // The body's frame for q = 0 in its parent's (the base: its pose in the world).
  const KDL::Frame F0 = i == 0 ? s.state.world_T_base : b.segment.pose(0.0);
  const std::string name = uniqueName(prefix + b.name, bodies_);
  open("<body name=\"" + escaped(name) + "\" pos=\"" + vec(F0.p) + "\" quat=\"" + quat(F0.M) + "\">");
  if (i == 0)
    freeJoint(name, s.state.world_T_base, s.velocity.base_twist);
  else if (b.joint >= 0)
    joint(s, i, F0, prefix);
  if (const std::string e = inertial(b.mass, b.com, b.I_com); !e.empty()) line(e);
  if (i == s.contact.body)
    line("<site name=\"" + escaped(uniqueName(site, sites_)) + "\" pos=\"" + vec(s.contact.offset) + "\"/>");
  for (const int c : children[i]) body(s, children, c, prefix, site);
  close("body");
}

void Writer::system(const FloatingSystem& s, const std::string& prefix, const std::string& site) {
  const std::vector<Body>& bodies = s.model->bodies();
  std::vector<std::vector<int>> children(bodies.size());
  for (std::size_t i = 1; i < bodies.size(); ++i) children[bodies[i].parent].push_back(static_cast<int>(i));
  body(s, children, 0, prefix, site);
}

void Writer::rigid(const RigidTarget& t) {
  const std::string name = uniqueName("target", bodies_);
  open("<body name=\"" + escaped(name) + "\" pos=\"" + vec(t.pose.p) + "\" quat=\"" + quat(t.pose.M) + "\">");
  // The twist is the CoM's (world): the free joint's is the body origin's.
  const KDL::Vector w(t.twist(3), t.twist(4), t.twist(5));
  const KDL::Vector com_world = t.pose.M * KDL::Vector(t.com.x(), t.com.y(), t.com.z());
  const KDL::Vector v_origin = KDL::Vector(t.twist(0), t.twist(1), t.twist(2)) + w * (-com_world);
  freeJoint(name, t.pose, KDL::Twist(v_origin, w));
  line(inertial(t.mass, t.com, t.inertia));
  close("body");
}

std::string Writer::keyframe() const {
  std::string qpos, qvel;
  for (const double v : qpos_) qpos += (qpos.empty() ? "" : " ") + num(v);
  for (const double v : qvel_) qvel += (qvel.empty() ? "" : " ") + num(v);
  return "<key name=\"scenario\" qpos=\"" + qpos + "\" qvel=\"" + qvel + "\"/>";
}

/// ModelError "writeMjcf: WHO: what" when a system cannot be written.
void checkSystem(const FloatingSystem& s, const std::string& who) {
  const auto fail = [&](const std::string& what) { throw ModelError("writeMjcf: " + who + ": " + what); };
  if (!s.model) fail("no model");
  const FloatingModel& m = *s.model;
  if (!m.mimic().empty()) {
    std::vector<std::string> names;
    for (const Mimic& x : m.mimic()) names.push_back(x.joint);
    fail("mimic joints (" + detail::listNames(names) + ") have no exact MJCF form (MuJoCo's equality constraints are "
         "soft: the file would not be the same dynamics)");
  }
  if (s.state.q.rows() != m.nj())
    fail("the state has " + std::to_string(s.state.q.rows()) + " joint positions, the model " + std::to_string(m.nj()) + " joints");
  if (s.velocity.qdot.rows() != 0 && s.velocity.qdot.rows() != m.nj())
    fail("the velocity has " + std::to_string(s.velocity.qdot.rows()) + " joint rates, the model " + std::to_string(m.nj()) + " joints");
  if (s.contact.body < -1 || (s.contact.body >= 0 && static_cast<std::size_t>(s.contact.body) >= m.bodies().size()))  // -1: none
    fail("the contact's body " + std::to_string(s.contact.body) + " is no body of the model");
  bool ok = finite(s.state.world_T_base) && finite(s.velocity.base_twist) && std::isfinite(s.contact.offset.Norm());
  for (unsigned int j = 0; j < s.state.q.rows(); ++j) ok = ok && std::isfinite(s.state.q(j));
  for (unsigned int j = 0; j < s.velocity.qdot.rows(); ++j) ok = ok && std::isfinite(s.velocity.qdot(j));
  if (!ok) fail("its state, velocity or contact offset is not finite");
}

void checkRigid(const RigidTarget& t) {
  if (!std::isfinite(t.mass) || !t.inertia.allFinite() || !t.com.allFinite() || !t.twist.allFinite() || !finite(t.pose))
    throw ModelError("writeMjcf: target: its mass, inertia, CoM, pose or twist is not finite");
}

}  // namespace mjcf_out
}  // namespace

std::string writeMjcf(const MjcfScene& scene) {
  using mjcf_out::checkRigid, mjcf_out::checkSystem, mjcf_out::escaped;
  checkSystem(scene.robot, "robot");
  if (scene.target) {
    if (const auto* t = std::get_if<RigidTarget>(&*scene.target)) checkRigid(*t);
    else checkSystem(std::get<FloatingSystem>(*scene.target), "target");
  }
  mjcf_out::Writer w;
  w.open("<mujoco model=\"" + escaped(scene.name) + "\">");
  w.line("<compiler angle=\"radian\" inertiafromgeom=\"false\"/>");
  w.open("<option gravity=\"0 0 0\">");
  w.line("<flag contact=\"disable\"/>");
  w.close("option");
  w.open("<worldbody>");
  w.system(scene.robot, "", "contact");
  if (scene.target) {
    if (const auto* t = std::get_if<RigidTarget>(&*scene.target)) w.rigid(*t);
    else w.system(std::get<FloatingSystem>(*scene.target), "target/", "target_contact");
  }
  w.close("worldbody");
  w.open("<keyframe>");
  w.line(w.keyframe());
  w.close("keyframe");
  w.close("mujoco");
  return w.text();
}

}  // namespace kdl_space
