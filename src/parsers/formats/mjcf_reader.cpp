// mjcfToUrdf: the MJCF subset writeMjcf writes, read back as one URDF document (mjcf.hpp). TinyXML,
// as the URDF readers; numbers by the library's one reader (readNumber).
#include <tinyxml.h>

#include <Eigen/Core>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <sstream>

#include "kdl_space/parsers/formats/mjcf.hpp"
#include "kdl_space/parsers/input_file.hpp"
#include "kdl_space/spatial/errors.hpp"
#include "parsers/formats/urdf_builder.hpp"
#include "spatial/message_text.hpp"

namespace kdl_space {
namespace {
namespace mjcf_in {  // a namespace of its own: the unity build puts other files' helpers beside these

std::string num(double v) { return formats::exactNumber(v); }  // reads back exactly

std::string triple(const KDL::Vector& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }

std::string attribute(const TiXmlElement* e, const char* name) {
  const char* v = e->Attribute(name);
  return v ? v : "";
}

/// One document's reading: where it stands, what it found, the URDF it builds.
class Reader {
 public:
  Reader(const std::string& source, std::vector<Diagnostic>& notes) : source_(source), notes_(notes) {}
  std::string read(const std::string& xml);

 private:
  /// InputError "SOURCE:LINE: <TAG>: what", or "<TAG ATTR="VALUE">: what" for an attribute.
  [[noreturn]] void fail(const TiXmlElement* e, const std::string& what, const char* attr = nullptr) const;
  /// Attribute `attr` of `e` as `count` finite numbers into `out`; false (out untouched) if absent.
  bool numbers(const TiXmlElement* e, const char* attr, std::size_t count, double* out) const;
  double number(const TiXmlElement* e, const char* attr, double fallback) const {
    double v = fallback;
    numbers(e, attr, 1, &v);
    return v;
  }
  KDL::Vector vector(const TiXmlElement* e, const char* attr, const KDL::Vector& fallback = KDL::Vector::Zero()) const {
    double v[3];
    return numbers(e, attr, 3, v) ? KDL::Vector(v[0], v[1], v[2]) : fallback;
  }
  /// The frame orientation `e` gives (quat, axisangle, euler, xyaxes or zaxis; identity if none).
  KDL::Rotation orientation(const TiXmlElement* e) const;
  double angle(double a) const { return degrees_ ? a * M_PI / 180.0 : a; }
  void compiler(const TiXmlElement* mujoco);
  void refuseUnread(const TiXmlElement* e) const;
  /// The body `b` as a link (and its joint from `parent`, whose joint stands at `parent_pos`).
  void body(const TiXmlElement* b, const std::string& parent, const KDL::Vector& parent_pos);
  /// The single joint of a body below the base (null: none); refuses what URDF cannot hold.
  const TiXmlElement* bodyJoint(const TiXmlElement* b) const;
  void urdfJoint(const TiXmlElement* j, const std::string& name, const std::string& parent, const std::string& child,
                 const KDL::Frame& origin);
  /// `<link>` with the inertial of body `b` moved to the link frame at `joint_pos` (body frame).
  TiXmlElement link(const TiXmlElement* b, const std::string& name, const KDL::Vector& joint_pos) const;
  std::string unique(const std::string& name, std::set<std::string>& used) const {
    std::string n = name;
    for (int k = 2; used.count(n); ++k) n = name + "_" + std::to_string(k);
    used.insert(n);
    return n;
  }

  const std::string& source_;
  std::vector<Diagnostic>& notes_;
  bool degrees_ = true;         ///< MuJoCo's default: <compiler angle="degree">
  std::string eulerseq_ = "xyz";
  TiXmlElement robot_{"robot"};
  std::set<std::string> links_, joints_;
  int geoms_ = 0, sites_ = 0;
};

void Reader::fail(const TiXmlElement* e, const std::string& what, const char* attr) const {
  std::string where = source_ + ":" + std::to_string(e->Row()) + ": <" + e->Value();
  if (attr) {
    const std::string shown = detail::echo(attribute(e, attr));  // 'value', cut and printable
    where += std::string(" ") + attr + "=\"" + shown.substr(1, shown.size() - 2) + "\"";
  }
  throw InputError(where + ">: " + what);
}

bool Reader::numbers(const TiXmlElement* e, const char* attr, std::size_t count, double* out) const {
  const char* text = e->Attribute(attr);
  if (!text) return false;
  std::istringstream in(text);
  std::vector<double> values;
  for (std::string piece; in >> piece;) {
    double v = 0.0;
    switch (readNumber(piece, v)) {
      case NumberText::Finite: values.push_back(v); break;
      case NumberText::NotANumber: fail(e, detail::quoted(piece) + " is not a number", attr);
      default: fail(e, detail::quoted(piece) + " is not a finite number", attr);
    }
  }
  if (values.size() != count)
    fail(e, std::to_string(count) + (count == 1 ? " number" : " numbers") + " expected, " +
                std::to_string(values.size()) + " found", attr);
  std::copy(values.begin(), values.end(), out);
  return true;
}

KDL::Rotation Reader::orientation(const TiXmlElement* e) const {
  const char* given = nullptr;
  for (const char* a : {"quat", "axisangle", "euler", "xyaxes", "zaxis"})
    if (e->Attribute(a)) {
      if (given) fail(e, std::string("gives its orientation twice (") + given + " and " + a + ")", a);
      given = a;
    }
  double v[6];
  if (numbers(e, "quat", 4, v)) {
    const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
    if (!(n > 0.0)) fail(e, "a zero quaternion is no orientation", "quat");
    return KDL::Rotation::Quaternion(v[1] / n, v[2] / n, v[3] / n, v[0] / n);
  }
  if (numbers(e, "axisangle", 4, v)) {
    const KDL::Vector axis(v[0], v[1], v[2]);
    if (!(axis.Norm() > 0.0)) fail(e, "a zero axis is no orientation", "axisangle");
    return KDL::Rotation::Rot(axis, angle(v[3]));
  }
  if (numbers(e, "euler", 3, v)) {  // lowercase: axes that turn with the frame; uppercase: fixed axes
    KDL::Rotation R = KDL::Rotation::Identity();
    for (int k = 0; k < 3; ++k) {
      const char c = eulerseq_[k];
      const int i = std::tolower(c) - 'x';
      const KDL::Rotation step = KDL::Rotation::Rot2(KDL::Vector(i == 0, i == 1, i == 2), angle(v[k]));
      R = std::islower(c) ? R * step : step * R;
    }
    return R;
  }
  if (numbers(e, "xyaxes", 6, v)) {
    KDL::Vector x(v[0], v[1], v[2]), y(v[3], v[4], v[5]);
    if (!(x.Normalize() > 0.0)) fail(e, "a zero x axis", "xyaxes");
    y = y - dot(x, y) * x;
    if (!(y.Normalize() > 1e-12)) fail(e, "the y axis is parallel to the x axis", "xyaxes");
    return KDL::Rotation(x, y, x * y);
  }
  if (numbers(e, "zaxis", 3, v)) {  // the shortest turn from (0, 0, 1) to z
    KDL::Vector z(v[0], v[1], v[2]);
    if (!(z.Normalize() > 0.0)) fail(e, "a zero axis is no orientation", "zaxis");
    const KDL::Vector n = KDL::Vector(0, 0, 1) * z;
    const double s = n.Norm();
    if (s < 1e-15) return z.z() > 0 ? KDL::Rotation::Identity() : KDL::Rotation::RotX(M_PI);
    return KDL::Rotation::Rot2(n / s, std::atan2(s, z.z()));
  }
  return KDL::Rotation::Identity();
}

/// Refuses what this reader would read wrong: another file's elements, default classes.
void Reader::refuseUnread(const TiXmlElement* e) const {
  for (const TiXmlElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
    const std::string tag = c->Value();
    if (tag == "include") fail(c, "included files are not read: write one document (MuJoCo's compile and save it)", "file");
    if (tag == "default" && c->FirstChildElement())
      fail(c, "default classes are not read: write each attribute on its element");
    for (const char* a : {"class", "childclass"})
      if (c->Attribute(a)) fail(c, "default classes are not read: write each attribute on its element", a);
    refuseUnread(c);
  }
}

void Reader::compiler(const TiXmlElement* mujoco) {
  for (const TiXmlElement* c = mujoco->FirstChildElement("compiler"); c; c = c->NextSiblingElement("compiler")) {
    if (const char* a = c->Attribute("angle")) {
      if (std::string(a) != "radian" && std::string(a) != "degree") fail(c, "is neither radian nor degree", "angle");
      degrees_ = std::string(a) == "degree";
    }
    if (c->Attribute("coordinate") && attribute(c, "coordinate") != "local")
      fail(c, "only local coordinates are read (each body's pose in its parent's frame)", "coordinate");
    if (const char* s = c->Attribute("eulerseq")) {
      const std::string seq = s;
      bool ok = seq.size() == 3;
      for (const char ch : seq) ok = ok && std::string("xyzXYZ").find(ch) != std::string::npos;
      if (!ok) fail(c, "is not three of x, y, z, X, Y, Z", "eulerseq");
      eulerseq_ = seq;
    }
  }
}

TiXmlElement Reader::link(const TiXmlElement* b, const std::string& name, const KDL::Vector& joint_pos) const {
  TiXmlElement link("link");
  link.SetAttribute("name", name);
  const TiXmlElement* in = b->FirstChildElement("inertial");
  if (!in) return link;
  if (in->NextSiblingElement("inertial")) fail(in->NextSiblingElement("inertial"), "a second <inertial> in one body");
  double mass = 0.0, d[6];
  if (!numbers(in, "mass", 1, &mass)) fail(in, "has no mass attribute");
  if (mass < 0.0) fail(in, "a negative mass", "mass");
  Eigen::Matrix3d I;
  if (numbers(in, "diaginertia", 3, d)) {
    if (in->Attribute("fullinertia")) fail(in, "gives its inertia twice (diaginertia and fullinertia)", "fullinertia");
    const KDL::Rotation R = orientation(in);  // the principal axes in the body frame
    Eigen::Matrix3d Re;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) Re(i, j) = R(i, j);
    I = Re * Eigen::Vector3d(d[0], d[1], d[2]).asDiagonal() * Re.transpose();
  } else if (numbers(in, "fullinertia", 6, d)) {  // xx yy zz xy xz yz, body axes
    for (const char* a : {"quat", "axisangle", "euler", "xyaxes", "zaxis"})
      if (in->Attribute(a)) fail(in, "fullinertia is read in the body's axes: no orientation with it", a);
    I << d[0], d[3], d[4], d[3], d[1], d[5], d[4], d[5], d[2];
  } else {
    fail(in, "has neither diaginertia nor fullinertia");
  }
  if (mass == 0.0 && I.isZero(0.0)) return link;
  formats::UrdfInertial inertial;
  inertial.mass = mass;
  inertial.origin = KDL::Frame(vector(in, "pos") - joint_pos);  // the CoM in the link frame
  inertial.inertia = I;
  formats::appendInertial(link, inertial);
  return link;
}

const TiXmlElement* Reader::bodyJoint(const TiXmlElement* b) const {
  if (const TiXmlElement* f = b->FirstChildElement("freejoint"))
    fail(f, "a free joint below the robot's top-level body: URDF has none (only the base floats)");
  const TiXmlElement* joint = b->FirstChildElement("joint");
  if (!joint) return nullptr;
  if (const TiXmlElement* second = joint->NextSiblingElement("joint"))
    fail(second, "a second joint in one body: URDF moves a link by one joint (split the body)");
  const std::string type = joint->Attribute("type") ? attribute(joint, "type") : "hinge";
  if (type == "ball") fail(joint, "a ball joint has no URDF form", "type");
  if (type == "free") fail(joint, "a free joint below the robot's top-level body: URDF has none (only the base floats)", "type");
  if (type != "hinge" && type != "slide") fail(joint, "an unknown joint type (hinge, slide, ball or free)", "type");
  if (number(joint, "ref", 0.0) != 0.0)
    fail(joint, "a reference position other than 0 is not read (write the body at the joint's zero)", "ref");
  return joint;
}

void Reader::urdfJoint(const TiXmlElement* j, const std::string& name, const std::string& parent,
                       const std::string& child, const KDL::Frame& origin) {
  TiXmlElement joint("joint"), o("origin"), p("parent"), c("child");
  joint.SetAttribute("name", name);
  o.SetAttribute("xyz", triple(origin.p));
  o.SetAttribute("rpy", triple(formats::urdfRpy(origin.M)));  // exact near pitch = +-pi/2 (not GetRPY's)
  p.SetAttribute("link", parent);
  c.SetAttribute("link", child);
  joint.InsertEndChild(o);
  joint.InsertEndChild(p);
  joint.InsertEndChild(c);
  if (!j) {
    joint.SetAttribute("type", "fixed");
    robot_.InsertEndChild(joint);
    return;
  }
  const bool hinge = attribute(j, "type") != "slide";
  KDL::Vector axis = vector(j, "axis", KDL::Vector(0, 0, 1));
  if (!(axis.Normalize() > 0.0)) fail(j, "a zero axis", "axis");
  TiXmlElement a("axis"), limit("limit"), dynamics("dynamics");
  a.SetAttribute("xyz", triple(axis));
  joint.InsertEndChild(a);
  double range[2];
  const bool has_range = numbers(j, "range", 2, range);
  const std::string limited = attribute(j, "limited");
  if (!limited.empty() && limited != "true" && limited != "false" && limited != "auto")
    fail(j, "is neither true, false nor auto", "limited");
  const bool bounded = has_range && limited != "false";
  if (has_range && range[0] > range[1]) fail(j, "its lower limit is above its upper", "range");
  joint.SetAttribute("type", hinge ? (bounded ? "revolute" : "continuous") : "prismatic");
  if (bounded || !hinge) {
    const double big = std::numeric_limits<double>::max();
    limit.SetAttribute("lower", num(bounded ? (hinge ? angle(range[0]) : range[0]) : -big));
    limit.SetAttribute("upper", num(bounded ? (hinge ? angle(range[1]) : range[1]) : big));
    limit.SetAttribute("effort", "0");  // none given (MJCF's are the actuators')
    limit.SetAttribute("velocity", "0");
    joint.InsertEndChild(limit);
    if (!bounded)
      notes_.push_back({name, "a slide joint without a range: a prismatic joint with the limits of a double", "", Severity::Note});
  }
  dynamics.SetAttribute("damping", num(number(j, "damping", 0.0)));
  dynamics.SetAttribute("friction", num(number(j, "frictionloss", 0.0)));
  joint.InsertEndChild(dynamics);
  if (const double armature = number(j, "armature", 0.0); armature != 0.0)
    notes_.push_back({name, "armature " + num(armature) + " (a rotor inertia URDF cannot hold): apply it with "
                      "FloatingModel::withArmature", "armature", Severity::Note, {{"armature", armature}}});
  if (number(j, "stiffness", 0.0) != 0.0)
    notes_.push_back({name, "its spring (stiffness) is not read: URDF has none", "", Severity::Note});
  robot_.InsertEndChild(joint);
}

void Reader::body(const TiXmlElement* b, const std::string& parent, const KDL::Vector& parent_pos) {
  const bool root = parent.empty();
  const std::string name = unique(b->Attribute("name") ? attribute(b, "name") : "body_" + std::to_string(b->Row()), links_);
  const TiXmlElement* j = root ? nullptr : bodyJoint(b);
  // The URDF link frame is the body frame moved to the joint's point (the base: its own frame).
  const KDL::Vector joint_pos = j ? vector(j, "pos") : KDL::Vector::Zero();
  robot_.InsertEndChild(link(b, name, joint_pos));
  if (!root) {
    const KDL::Frame F_B(orientation(b), vector(b, "pos"));  // the body in its parent body's frame
    const KDL::Frame origin(F_B.M, F_B.p - parent_pos + F_B.M * joint_pos);
    const std::string joint_name = j && j->Attribute("name") ? attribute(j, "name") : name + (j ? "_joint" : "_fixed");
    urdfJoint(j, unique(joint_name, joints_), parent, name, origin);
  }
  for (const TiXmlElement* c = b->FirstChildElement(); c; c = c->NextSiblingElement()) {
    const std::string tag = c->Value();
    geoms_ += tag == "geom";
    sites_ += tag == "site";
    if (tag == "body") body(c, name, joint_pos);
  }
}

std::string Reader::read(const std::string& xml) {
  TiXmlDocument doc;
  doc.Parse(xml.c_str());
  if (doc.Error())
    throw InputError(source_ + ":" + std::to_string(doc.ErrorRow()) + ": not an XML document (" + doc.ErrorDesc() + ")");
  const TiXmlElement* mujoco = doc.FirstChildElement("mujoco");
  if (!mujoco) throw InputError(source_ + ": no <mujoco> element: not an MJCF file");
  refuseUnread(mujoco);
  compiler(mujoco);
  const TiXmlElement* world = mujoco->FirstChildElement("worldbody");
  if (!world) fail(mujoco, "has no <worldbody>");
  const TiXmlElement* robot = nullptr;
  for (const TiXmlElement* b = world->FirstChildElement("body"); b && !robot; b = b->NextSiblingElement("body")) {
    const TiXmlElement* j = b->FirstChildElement("joint");
    if (b->FirstChildElement("freejoint") || (j && attribute(j, "type") == "free")) robot = b;
  }
  if (!robot) robot = world->FirstChildElement("body");
  if (!robot) fail(world, "holds no <body>: no robot");
  for (const TiXmlElement* j = robot->FirstChildElement("joint"); j; j = j->NextSiblingElement("joint"))
    if (attribute(j, "type") != "free") fail(j, "the robot's top-level body moves by a free joint or none", "type");
  if (!robot->FirstChildElement("freejoint") && !robot->FirstChildElement("joint"))
    notes_.push_back({"", "the robot's top-level body has no free joint: read as free-floating", "", Severity::Note});
  robot_.SetAttribute("name", mujoco->Attribute("model") ? attribute(mujoco, "model") : "mjcf");
  body(robot, "", KDL::Vector::Zero());
  for (const TiXmlElement* b = world->FirstChildElement("body"); b; b = b->NextSiblingElement("body"))
    if (b != robot)
      notes_.push_back({attribute(b, "name"), "line " + std::to_string(b->Row()) + ": a top-level body besides the robot "
                        "(a target?): not read", "", Severity::Note});
  if (geoms_ + sites_ > 0)
    notes_.push_back({"", std::to_string(geoms_) + " geoms and " + std::to_string(sites_) + " sites of the robot not read "
                      "(no mass is taken from geoms)", "", Severity::Note});
  return formats::xmlText(robot_);
}

}  // namespace mjcf_in
}  // namespace

std::string mjcfToUrdf(const std::string& xml, const std::string& source, std::vector<Diagnostic>& notes) {
  return mjcf_in::Reader(source, notes).read(xml);
}

}  // namespace kdl_space
