#include "parsers/urdf/urdf_xml.hpp"

#include <tinyxml.h>

#include <Eigen/Geometry>
#include <cctype>
#include <limits>
#include <map>
#include <set>

#include "spatial/message_text.hpp"
#include "parsers/urdf/urdf_numbers.hpp"
#include "parsers/urdf/urdf_rules.hpp"

namespace kdl_space::detail {
namespace {

/// A value as written, printable and short enough for a message.
std::string shown(const std::string& text) {
  std::string s;
  for (const char c : text) s += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
  return s.size() > 40 ? s.substr(0, 37) + "..." : s;
}

/// The element a finding is about.
struct Owner {
  ElementType type;
  std::string name;
};

/// One pass over a document: every element read as urdfdom reads it, reporting what urdfdom
/// would refuse; the links and joints kept for the graph.
class Reader {
 public:
  Reader(UrdfDocument& doc, std::vector<Finding>& findings) : doc_(doc), findings_(findings) {}

  bool read(const std::string& xml);

 private:
  void fileError(const std::string& kind, const std::string& message) {
    findings_.push_back(rules::error(kind, ElementType::File, "", message));
  }
  void error(const std::string& kind, const Owner& o, const std::string& message) {
    findings_.push_back(rules::error(kind, o.type, o.name, message));
  }

  /// Reads attribute `attribute` of `e` (present) as `count` numbers (0: as many as written)
  /// into `out`, as urdfdom would; reports what it cannot read (`path` locates it in `owner`).
  bool readNumbers(const TiXmlElement* e, const char* attribute, std::size_t count, const Owner& owner,
                   const std::string& path, double* out, bool unit_interval = false);
  bool readOptional(const TiXmlElement* e, const char* attribute, const Owner& owner, const std::string& path,
                    double& out) {
    return !e->Attribute(attribute) || readNumbers(e, attribute, 1, owner, path, &out);
  }
  bool readRequired(const TiXmlElement* e, const std::vector<const char*>& attributes, const Owner& owner,
                    const std::string& path);
  /// Reads an <origin> (reported as readNumbers does); its pose into R and p when given.
  void readPose(const TiXmlElement* parent, const Owner& owner, const std::string& path,
                Eigen::Matrix3d* R = nullptr, Eigen::Vector3d* p = nullptr);
  void readMaterial(const TiXmlElement* e, const Owner& owner, const std::string& path, bool robot_level);
  void readShape(const TiXmlElement* geometry, const Owner& owner, const std::string& path);
  void readLink(const TiXmlElement* e);
  void readJoint(const TiXmlElement* e);
  /// The name of a <link> or <joint>, entered in `index` as the next of `entered`; null
  /// (reported) when it has none or is taken.
  template <typename Info>
  const char* registerName(const TiXmlElement* e, const char* tag, ElementType type,
                           std::map<std::string, int>& index, const std::vector<Info>& entered);

  UrdfDocument& doc_;
  std::vector<Finding>& findings_;
  Owner robot_{ElementType::Robot, ""};
  std::map<std::string, int> link_index_, joint_index_;
  std::set<std::string> materials_;  ///< names of the robot's own <material> elements
};

bool Reader::readNumbers(const TiXmlElement* e, const char* attribute, std::size_t count, const Owner& owner,
                          const std::string& path, double* out, bool unit_interval) {
  const std::string text = e->Attribute(attribute);
  const std::string where = path + " " + attribute + "=\"" + shown(text) + "\">: ";
  std::vector<std::string> values = count == 1 ? std::vector<std::string>{text} : vectorPieces(text);
  if (count == 0) {
    count = values.size();  // any number of values (urdfdom ignores an rgba of the wrong size)
  } else if (values.size() != count) {
    error("bad_number", owner, where + std::to_string(count) + " numbers expected, " +
                                   std::to_string(values.size()) + " found");
    return false;
  }
  for (std::size_t i = 0; i < count; ++i) {
    const std::string& v = values[i];
    switch (urdfNumber(v, out[i])) {
      case NumberText::Finite:
        break;
      case NumberText::TooLarge:  // urdfdom refuses both alike
      case NumberText::NotFinite:
        error("not_finite", owner, where + detail::quoted(shown(v)) + " is not a finite number");
        return false;
      case NumberText::NotANumber: {
        double trimmed = 0.0;
        const std::size_t last = v.find_last_not_of(" \t\n\r\f\v");
        const bool trailing_space = last != std::string::npos && last + 1 < v.size() &&
                                    urdfNumber(v.substr(0, last + 1), trimmed) == NumberText::Finite;
        error("bad_number", owner,
              where + detail::quoted(shown(v)) +
                  (trailing_space ? " is not a number for urdfdom (no space may follow a number)"
                                  : " is not a number"));
        return false;
      }
    }
    if (unit_interval && !(out[i] >= 0.0 && out[i] <= 1.0)) {
      error("bad_number", owner, where + detail::quoted(shown(v)) + " is outside [0, 1]");
      return false;
    }
  }
  return true;
}

bool Reader::readRequired(const TiXmlElement* e, const std::vector<const char*>& attributes,
                           const Owner& owner, const std::string& path) {
  std::vector<std::string> missing;
  for (const char* a : attributes)
    if (!e->Attribute(a)) missing.push_back(a);
  if (missing.empty()) return true;
  std::string names;
  for (std::size_t i = 0; i < attributes.size(); ++i)
    names += std::string(i == 0 ? "" : i + 1 == attributes.size() ? " and " : ", ") + attributes[i];
  error("malformed", owner, path + "> needs " + names + " (missing: " + detail::listNames(missing) + ")");
  return false;
}

void Reader::readPose(const TiXmlElement* parent, const Owner& owner, const std::string& path, Eigen::Matrix3d* R,
                      Eigen::Vector3d* p) {
  const TiXmlElement* origin = parent->FirstChildElement("origin");
  if (!origin) return;
  double xyz[3] = {0.0, 0.0, 0.0}, rpy[3] = {0.0, 0.0, 0.0};
  if (origin->Attribute("xyz") && readNumbers(origin, "xyz", 3, owner, path + "<origin", xyz) && p)
    *p = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
  if (origin->Attribute("rpy") && readNumbers(origin, "rpy", 3, owner, path + "<origin", rpy) && R)  // urdfdom's order
    *R = (Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX())).toRotationMatrix();
}

void Reader::readMaterial(const TiXmlElement* e, const Owner& owner, const std::string& path, bool robot_level) {
  if (!e->Attribute("name")) {
    error("malformed", owner, path + "<material> has no name attribute");
    return;
  }
  const TiXmlElement* color = e->FirstChildElement("color");
  const TiXmlElement* texture = e->FirstChildElement("texture");
  if (color && color->Attribute("rgba")) {
    std::vector<double> rgba(vectorPieces(color->Attribute("rgba")).size());
    readNumbers(color, "rgba", 0, owner, path + "<material><color", rgba.data(), true);
  }
  if (robot_level && !materials_.insert(e->Attribute("name")).second)
    error("duplicate_name", owner, "material " + detail::quoted(e->Attribute("name")) + " defined twice: material names must be unique");
  if (robot_level && !(color && color->Attribute("rgba")) && !(texture && texture->Attribute("filename")))
    error("malformed", owner,
          "material " + detail::quoted(e->Attribute("name")) + " has neither <color rgba=...> nor <texture filename=...>");
}

void Reader::readShape(const TiXmlElement* geometry, const Owner& owner, const std::string& path) {
  if (!geometry) {
    error("malformed", owner, path + "> has no <geometry>");
    return;
  }
  const TiXmlElement* shape = geometry->FirstChildElement();
  const std::string where = path + "<geometry>";
  if (!shape) {
    error("malformed", owner, where + " has no shape (box, cylinder, sphere or mesh)");
    return;
  }
  const std::string type = shape->Value();
  const std::string at = path + "<geometry><" + type;
  double v[3];
  if (type == "sphere") {
    if (readRequired(shape, {"radius"}, owner, at)) readNumbers(shape, "radius", 1, owner, at, v);
  } else if (type == "box") {
    if (readRequired(shape, {"size"}, owner, at)) readNumbers(shape, "size", 3, owner, at, v);
  } else if (type == "cylinder") {
    if (readRequired(shape, {"length", "radius"}, owner, at)) {
      readNumbers(shape, "length", 1, owner, at, v);
      readNumbers(shape, "radius", 1, owner, at, v);
    }
  } else if (type == "mesh") {
    readRequired(shape, {"filename"}, owner, at);
    if (shape->Attribute("scale")) readNumbers(shape, "scale", 3, owner, at, v);
  } else {
    error("malformed", owner, where + " holds an unknown shape <" + shown(type) + "> (box, cylinder, sphere or mesh)");
  }
}

template <typename Info>
const char* Reader::registerName(const TiXmlElement* e, const char* tag, ElementType type,
                                  std::map<std::string, int>& index, const std::vector<Info>& entered) {
  const char* name = e->Attribute("name");
  if (!name) {
    error("malformed", robot_, std::string("the <") + tag + "> at line " + std::to_string(e->Row()) +
                                   " has no name attribute");
    doc_.names_complete = false;
    return nullptr;
  }
  if (const auto it = index.find(name); it != index.end()) {
    error("duplicate_name", Owner{type, name},
          "defined twice (lines " + std::to_string(entered[it->second].row) + " and " + std::to_string(e->Row()) + "): " +
              tag + " names must be unique");
    doc_.names_complete = false;
    return nullptr;
  }
  index[name] = static_cast<int>(entered.size());
  return name;
}

void Reader::readLink(const TiXmlElement* e) {
  ++doc_.link_elements;
  const char* name = registerName(e, "link", ElementType::Link, link_index_, doc_.links);
  if (!name) return;
  const Owner owner{ElementType::Link, name};
  XmlLink link;
  link.name = name;
  link.row = e->Row();

  if (const TiXmlElement* inertial = e->FirstChildElement("inertial")) {
    link.has_inertial = true;
    link.mass = std::numeric_limits<double>::quiet_NaN();
    Eigen::Matrix3d R_inertial = Eigen::Matrix3d::Identity();
    readPose(inertial, owner, "<inertial>", &R_inertial, &link.com);
    const TiXmlElement* mass = inertial->FirstChildElement("mass");
    double m = 0.0;
    bool mass_read = false;
    if (!mass || !mass->Attribute("value"))
      error("malformed", owner, "<inertial> has no <mass value=\"...\"/>");
    else
      mass_read = readNumbers(mass, "value", 1, owner, "<inertial><mass", &m);
    const TiXmlElement* inertia = inertial->FirstChildElement("inertia");
    const std::vector<const char*> moments{"ixx", "ixy", "ixz", "iyy", "iyz", "izz"};
    double I[6];
    bool inertia_read = false;
    if (!inertia) {
      error("malformed", owner, "<inertial> has no <inertia ixx=... ixy=... ixz=... iyy=... iyz=... izz=.../>");
    } else if (readRequired(inertia, moments, owner, "<inertial><inertia")) {
      inertia_read = true;
      for (std::size_t k = 0; k < moments.size(); ++k)
        inertia_read &= readNumbers(inertia, moments[k], 1, owner, "<inertial><inertia", &I[k]);
    }
    if (mass_read) link.mass = m;
    if (mass_read && inertia_read) {
      Eigen::Matrix3d I_com;
      I_com << I[0], I[1], I[2], I[1], I[3], I[4], I[2], I[4], I[5];
      rules::checkInertia(link.name, m, I_com, findings_);
      link.inertia_read = true;
      link.I_com = R_inertial * I_com * R_inertial.transpose();  // in the link's axes
    }
  }
  for (const TiXmlElement* v = e->FirstChildElement("visual"); v; v = v->NextSiblingElement("visual")) {
    readPose(v, owner, "<visual>");
    readShape(v->FirstChildElement("geometry"), owner, "<visual>");
    if (const TiXmlElement* material = v->FirstChildElement("material"))
      readMaterial(material, owner, "<visual>", false);
  }
  for (const TiXmlElement* c = e->FirstChildElement("collision"); c; c = c->NextSiblingElement("collision")) {
    readPose(c, owner, "<collision>");
    readShape(c->FirstChildElement("geometry"), owner, "<collision>");
  }
  doc_.links.push_back(std::move(link));
}

void Reader::readJoint(const TiXmlElement* e) {
  ++doc_.joint_elements;
  const char* name = registerName(e, "joint", ElementType::Joint, joint_index_, doc_.joints);
  if (!name) return;
  const Owner owner{ElementType::Joint, name};
  XmlJoint joint;
  joint.name = name;
  joint.row = e->Row();

  readPose(e, owner, "", &joint.R, &joint.p);
  for (const char* end : {"parent", "child"}) {
    const TiXmlElement* x = e->FirstChildElement(end);
    const char* link = x ? x->Attribute("link") : nullptr;
    if (!link || !*link) {
      error("malformed", owner, std::string("has no <") + end + " link=\"...\"/>");
      doc_.names_complete = false;
    } else {
      (std::string(end) == "parent" ? joint.parent : joint.child) = link;
    }
  }

  const char* type = e->Attribute("type");
  if (!type) {
    error("malformed", owner, "has no type attribute (revolute, continuous, prismatic, fixed, floating or planar)");
  } else {
    joint.type = type;
    joint.known_type = rules::isMovable(type) || joint.type == "fixed" || joint.type == "floating" ||
                       joint.type == "planar";
    if (!joint.known_type)
      error("unknown_joint_type", owner,
            "unknown type " + detail::quoted(shown(type)) + " (revolute, continuous, prismatic, fixed, floating or planar)");
  }

  // The axis, as urdfdom reads it: (1, 0, 0) without <axis>, (0, 0, 0) for an <axis> without xyz.
  if (joint.known_type && joint.type != "fixed" && joint.type != "floating") {
    Eigen::Vector3d axis(1.0, 0.0, 0.0);
    bool axis_read = true;
    if (const TiXmlElement* a = e->FirstChildElement("axis")) {
      axis.setZero();
      if (a->Attribute("xyz")) axis_read = readNumbers(a, "xyz", 3, owner, "<axis", axis.data());
    }
    if (axis_read && rules::isMovable(joint.type)) {
      rules::checkAxis(joint.name, axis, findings_);
    }
  }

  const bool limited = joint.type == "revolute" || joint.type == "prismatic";
  if (const TiXmlElement* limit = e->FirstChildElement("limit")) {
    double lower = 0.0, upper = 0.0, effort = 0.0, velocity = 0.0;
    bool ok = readOptional(limit, "lower", owner, "<limit", lower);
    ok &= readOptional(limit, "upper", owner, "<limit", upper);
    if (readRequired(limit, {"effort", "velocity"}, owner, "<limit")) {
      ok &= readNumbers(limit, "effort", 1, owner, "<limit", &effort);
      ok &= readNumbers(limit, "velocity", 1, owner, "<limit", &velocity);
    }
    if (ok && limited) {
      rules::checkLimits(joint.name, lower, upper, findings_);
    }
  } else if (joint.type == "revolute") {
    rules::checkRevoluteWithoutLimit(joint.name, findings_);
  } else if (limited) {
    error("malformed", owner,
          "a " + joint.type + " joint needs <limit lower=... upper=... effort=... velocity=.../> (urdfdom "
          "refuses it without)");
  }
  double unused = 0.0;
  if (const TiXmlElement* safety = e->FirstChildElement("safety_controller")) {
    for (const char* a : {"soft_lower_limit", "soft_upper_limit", "k_position"})
      readOptional(safety, a, owner, "<safety_controller", unused);
    if (readRequired(safety, {"k_velocity"}, owner, "<safety_controller"))
      readNumbers(safety, "k_velocity", 1, owner, "<safety_controller", &unused);
  }
  if (const TiXmlElement* calibration = e->FirstChildElement("calibration"))
    for (const char* a : {"rising", "falling"}) readOptional(calibration, a, owner, "<calibration", unused);
  if (const TiXmlElement* mimic = e->FirstChildElement("mimic")) {
    double multiplier = 1.0, offset = 0.0;
    const bool multiplier_ok = readOptional(mimic, "multiplier", owner, "<mimic", multiplier);
    const bool ok = readOptional(mimic, "offset", owner, "<mimic", offset) && multiplier_ok;  // both read, both reported
    if (readRequired(mimic, {"joint"}, owner, "<mimic") && ok && rules::isMovable(joint.type)) {
      joint.has_mimic = true;
      joint.mimic_leader = mimic->Attribute("joint");
      joint.mimic_multiplier = multiplier;
      joint.mimic_offset = offset;
    }
  }
  if (const TiXmlElement* dynamics = e->FirstChildElement("dynamics")) {
    if (!dynamics->Attribute("damping") && !dynamics->Attribute("friction"))
      error("malformed", owner, "<dynamics> needs damping or friction (or no <dynamics> at all)");
    for (const char* a : {"damping", "friction"}) readOptional(dynamics, a, owner, "<dynamics", unused);
  }
  doc_.joints.push_back(std::move(joint));
}

bool Reader::read(const std::string& xml) {
  if (xml.find_first_not_of(" \t\n\r") == std::string::npos) {
    fileError("not_xml", "not XML: the file is empty");
    return false;
  }
  if (const std::string problem = rules::xmlDepthProblem(xml); !problem.empty()) {
    fileError("not_xml", "not XML that can be read safely: " + problem);
    return false;
  }
  if (const std::string problem = rules::xacroProblem(xml); !problem.empty()) {
    fileError("xacro", "not a URDF yet: " + problem);
    return false;
  }
  TiXmlDocument document;
  const std::string padded = xml + "    ";  // TinyXML reads past a final UTF-8 lead byte: see urdf_loader.cpp
  document.Parse(padded.c_str());
  if (document.Error()) {
    std::string why = document.ErrorDesc();  // e.g. "Error reading end tag."
    if (!why.empty() && why.back() == '.') why.pop_back();
    if (!why.empty()) why[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(why[0])));
    fileError("not_xml", "not XML: " + why + " (line " + std::to_string(document.ErrorRow()) + ", column " +
                             std::to_string(document.ErrorCol()) + ")");
    return false;
  }
  const TiXmlElement* robot = document.FirstChildElement("robot");
  if (!robot) {
    const TiXmlElement* top = document.FirstChildElement();
    fileError("not_urdf", top ? "not URDF: the top element is <" + shown(top->Value()) + ">, not <robot>"
                              : "not URDF: no <robot> element");
    return false;
  }
  if (const char* name = robot->Attribute("name")) {
    doc_.robot = robot_.name = name;
  } else {
    error("malformed", robot_, "the <robot> element has no name attribute");
  }
  if (const char* version = robot->Attribute("version"); version && std::string(version) != "1.0")
    error("malformed", robot_, "version " + detail::quoted(shown(version)) + ": urdfdom reads only version 1.0");

  for (const TiXmlElement* e = robot->FirstChildElement(); e; e = e->NextSiblingElement()) {
    const std::string tag = e->Value();
    if (tag == "link") readLink(e);
    else if (tag == "joint") readJoint(e);
    else if (tag == "material") readMaterial(e, robot_, "", true);
  }
  return true;
}

}  // namespace

bool readUrdfXml(const std::string& xml, UrdfDocument& doc, std::vector<Finding>& findings) {
  return Reader(doc, findings).read(xml);
}

std::string withUnlimitedRevolutesContinuous(const std::string& xml, std::vector<std::string>& changed) {
  TiXmlDocument document;
  const std::string padded = xml + "    ";  // see urdf_loader.cpp
  document.Parse(padded.c_str());
  TiXmlElement* robot = document.Error() ? nullptr : document.FirstChildElement("robot");
  if (!robot) return xml;  // urdfdom will say what is wrong
  for (TiXmlElement* e = robot->FirstChildElement("joint"); e; e = e->NextSiblingElement("joint")) {
    const char* type = e->Attribute("type");
    const char* name = e->Attribute("name");
    if (type && std::string(type) == "revolute" && !e->FirstChildElement("limit")) {
      e->SetAttribute("type", "continuous");
      changed.push_back(name ? name : "");
    }
  }
  if (changed.empty()) return xml;
  TiXmlPrinter printer;
  document.Accept(&printer);
  return printer.CStr();
}

LinkGraph linkGraph(const UrdfDocument& doc) {
  std::vector<std::string> links;
  for (const XmlLink& link : doc.links) links.push_back(link.name);
  std::vector<GraphJoint> joints;
  for (const XmlJoint& joint : doc.joints) joints.push_back({joint.name, joint.parent, joint.child});
  return LinkGraph(std::move(links), std::move(joints));
}

}  // namespace kdl_space::detail
