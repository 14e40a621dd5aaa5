#include "kdl_space/urdf_check.hpp"

#include <tinyxml.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <locale>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "kdl_space/errors.hpp"
#include "kdl_space/free_floating_solver.hpp"
#include "kdl_space/urdf_loader.hpp"
#include "model_rules.hpp"

namespace kdl_space {
namespace {

/// Above this ratio of the base mass to the lightest moving link's, H* and G* are ill-conditioned.
constexpr double kMassRatioLimit = 1e6;

std::string named(const std::string& s) { return "'" + s + "'"; }

std::string number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// A value as written, printable and short enough for a message.
std::string shown(const std::string& text) {
  std::string s;
  for (const char c : text) s += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
  return s.size() > 40 ? s.substr(0, 37) + "..." : s;
}

std::string list(const std::vector<std::string>& names, std::size_t at_most = 20) {
  std::string s;
  for (std::size_t i = 0; i < names.size() && i < at_most; ++i) s += (i ? ", " : "") + named(names[i]);
  if (names.size() > at_most) s += " and " + std::to_string(names.size() - at_most) + " more";
  return s;
}

// --- Numbers, read as urdfdom reads them ------------------------------------------------------

enum class Parsed { Ok, NotFinite, Bad };

/// True for a decimal number's syntax (sign, digits, point, exponent), after leading space.
bool decimalSyntax(const std::string& text) {
  std::size_t i = text.find_first_not_of(" \t\n\r\f\v");
  if (i == std::string::npos) return false;
  if (text[i] == '+' || text[i] == '-') ++i;
  std::size_t digits = 0;
  while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i, ++digits;
  if (i < text.size() && text[i] == '.') {
    ++i;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i, ++digits;
  }
  if (digits == 0) return false;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
    std::size_t exponent = 0;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i, ++exponent;
    if (exponent == 0) return false;
  }
  return i == text.size();
}

/// One number as urdfdom reads it (urdf::strToDouble: the C locale's stream extraction, space
/// allowed before, nothing after). What urdfdom refuses is `NotFinite` for NaN, infinities and
/// numbers too large for a double, `Bad` otherwise.
Parsed parseNumber(const std::string& text, double& value) {
  std::istringstream in(text);
  in.imbue(std::locale::classic());
  in >> value;
  if (!in.fail() && in.eof()) return std::isfinite(value) ? Parsed::Ok : Parsed::NotFinite;
  if (decimalSyntax(text)) return Parsed::NotFinite;  // well formed, yet refused: overflow
  std::string t;
  for (const char c : text)
    if (!std::isspace(static_cast<unsigned char>(c))) t += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (!t.empty() && (t[0] == '+' || t[0] == '-')) t.erase(0, 1);
  if (t == "nan" || t == "inf" || t == "infinity" || t.rfind("nan(", 0) == 0) return Parsed::NotFinite;
  return Parsed::Bad;
}

/// The pieces of a vector as urdfdom splits them (urdf::Vector3::init): at single spaces, empty
/// pieces skipped.
std::vector<std::string> pieces(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(' ', start), text.size());
    if (end > start) out.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

// --- The walk over the document ---------------------------------------------------------------

struct Owner {
  ElementType type;
  std::string name;
};

struct LinkInfo {
  std::string name;
  int row = 0;
  bool has_inertial = false;
  double mass = 0.0;               ///< [kg]; NaN when its <inertial> has no readable mass
  std::vector<int> parent_joints;  ///< joints that name it as child (and whose parent exists or not)
  std::vector<int> child_joints;   ///< joints that name it as parent and whose child exists
};

struct JointInfo {
  std::string name;
  int row = 0;
  std::string type;    ///< as written ("" if missing)
  bool known_type = false;
  std::string parent, child;  ///< link names ("" if missing)
  int parent_link = -1, child_link = -1;
};

/// One pass over a document: every element read as urdfdom reads it (reporting what urdfdom
/// would refuse), then the links and joints as a graph, the rules of model_rules.hpp on the
/// tree, the tips; the model is loaded (condition numbers) only when nothing is wrong.
class Checker {
 public:
  Checker(const std::string& source, const std::vector<std::string>& tips) : tips_(tips) {
    report_.source = source;
  }

  UrdfReport run(const std::string& xml);

 private:
  void add(Finding f) { (f.severity == Severity::Error ? report_.errors : report_.warnings).push_back(std::move(f)); }
  void addAll(const std::vector<Finding>& findings) {
    for (const Finding& f : findings) add(f);
  }
  void fileError(const std::string& kind, const std::string& message) {
    add(rules::error(kind, ElementType::File, "", message));
  }
  void error(const std::string& kind, const Owner& o, const std::string& message) {
    add(rules::error(kind, o.type, o.name, message));
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
  void readPose(const TiXmlElement* parent, const Owner& owner, const std::string& path);
  void readMaterial(const TiXmlElement* e, const Owner& owner, const std::string& path, bool robot_level);
  void readShape(const TiXmlElement* geometry, const Owner& owner, const std::string& path);
  void readLink(const TiXmlElement* e);
  void readJoint(const TiXmlElement* e);
  /// The name of a <link> or <joint>, entered in `index` as the next of `entered`; null
  /// (reported) when it has none or is taken.
  template <typename Info>
  const char* registerName(const TiXmlElement* e, const char* tag, ElementType type,
                           std::map<std::string, int>& index, const std::vector<Info>& entered);
  void checkGraph();
  void checkTree();
  void checkTips();
  void loadAndMeasure(const std::string& xml);

  std::vector<std::string> tips_;
  UrdfReport report_;
  Owner robot_{ElementType::Robot, ""};
  std::vector<LinkInfo> links_;
  std::vector<JointInfo> joints_;
  std::map<std::string, int> link_index_, joint_index_;
  std::set<std::string> materials_;  ///< names of the robot's own <material> elements
  bool graph_ok_ = true;     ///< the links and joints form one tree
  int root_ = -1;            ///< the URDF root link (the largest tree's when there are several)
  int base_ = -1;            ///< the free-floating base link
  int dropped_joint_ = -1;   ///< the floating joint from a massless root, dropped
  int lightest_ = -1;        ///< the lightest moving link with mass (for the mass ratio)
};

bool Checker::readNumbers(const TiXmlElement* e, const char* attribute, std::size_t count, const Owner& owner,
                          const std::string& path, double* out, bool unit_interval) {
  const std::string text = e->Attribute(attribute);
  const std::string where = path + " " + attribute + "=\"" + shown(text) + "\">: ";
  std::vector<std::string> values = count == 1 ? std::vector<std::string>{text} : pieces(text);
  if (count == 0) {
    count = values.size();  // any number of values (urdfdom ignores an rgba of the wrong size)
  } else if (values.size() != count) {
    error("bad_number", owner, where + std::to_string(count) + " numbers expected, " +
                                   std::to_string(values.size()) + " found");
    return false;
  }
  for (std::size_t i = 0; i < count; ++i) {
    const std::string& v = values[i];
    switch (parseNumber(v, out[i])) {
      case Parsed::Ok:
        break;
      case Parsed::NotFinite:
        error("not_finite", owner, where + named(shown(v)) + " is not a finite number");
        return false;
      case Parsed::Bad: {
        double trimmed = 0.0;
        const std::size_t last = v.find_last_not_of(" \t\n\r\f\v");
        const bool trailing_space = last != std::string::npos && last + 1 < v.size() &&
                                    parseNumber(v.substr(0, last + 1), trimmed) == Parsed::Ok;
        error("bad_number", owner,
              where + named(shown(v)) +
                  (trailing_space ? " is not a number for urdfdom (no space may follow a number)"
                                  : " is not a number"));
        return false;
      }
    }
    if (unit_interval && !(out[i] >= 0.0 && out[i] <= 1.0)) {
      error("bad_number", owner, where + named(shown(v)) + " is outside [0, 1]");
      return false;
    }
  }
  return true;
}

bool Checker::readRequired(const TiXmlElement* e, const std::vector<const char*>& attributes,
                           const Owner& owner, const std::string& path) {
  std::vector<std::string> missing;
  for (const char* a : attributes)
    if (!e->Attribute(a)) missing.push_back(a);
  if (missing.empty()) return true;
  std::string names;
  for (std::size_t i = 0; i < attributes.size(); ++i)
    names += std::string(i == 0 ? "" : i + 1 == attributes.size() ? " and " : ", ") + attributes[i];
  std::string which;
  for (const std::string& m : missing) which += (which.empty() ? "" : ", ") + m;
  error("malformed", owner, path + "> needs " + names + " (missing: " + which + ")");
  return false;
}

void Checker::readPose(const TiXmlElement* parent, const Owner& owner, const std::string& path) {
  const TiXmlElement* origin = parent->FirstChildElement("origin");
  if (!origin) return;
  double v[3];
  if (origin->Attribute("xyz")) readNumbers(origin, "xyz", 3, owner, path + "<origin", v);
  if (origin->Attribute("rpy")) readNumbers(origin, "rpy", 3, owner, path + "<origin", v);
}

void Checker::readMaterial(const TiXmlElement* e, const Owner& owner, const std::string& path, bool robot_level) {
  if (!e->Attribute("name")) {
    error("malformed", owner, path + "<material> has no name attribute");
    return;
  }
  const TiXmlElement* color = e->FirstChildElement("color");
  const TiXmlElement* texture = e->FirstChildElement("texture");
  if (color && color->Attribute("rgba")) {
    std::vector<double> rgba(pieces(color->Attribute("rgba")).size());
    readNumbers(color, "rgba", 0, owner, path + "<material><color", rgba.data(), true);
  }
  if (robot_level && !materials_.insert(e->Attribute("name")).second)
    error("duplicate_name", owner, "material " + named(e->Attribute("name")) + " defined twice: material names must be unique");
  if (robot_level && !(color && color->Attribute("rgba")) && !(texture && texture->Attribute("filename")))
    error("malformed", owner,
          "material " + named(e->Attribute("name")) + " has neither <color rgba=...> nor <texture filename=...>");
}

void Checker::readShape(const TiXmlElement* geometry, const Owner& owner, const std::string& path) {
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
const char* Checker::registerName(const TiXmlElement* e, const char* tag, ElementType type,
                                  std::map<std::string, int>& index, const std::vector<Info>& entered) {
  const char* name = e->Attribute("name");
  if (!name) {
    error("malformed", robot_, std::string("the <") + tag + "> at line " + std::to_string(e->Row()) +
                                   " has no name attribute");
    graph_ok_ = false;
    return nullptr;
  }
  if (const auto it = index.find(name); it != index.end()) {
    error("duplicate_name", Owner{type, name},
          "defined twice (lines " + std::to_string(entered[it->second].row) + " and " + std::to_string(e->Row()) + "): " +
              tag + " names must be unique");
    graph_ok_ = false;
    return nullptr;
  }
  index[name] = static_cast<int>(entered.size());
  return name;
}

void Checker::readLink(const TiXmlElement* e) {
  ++report_.model.links;
  const char* name = registerName(e, "link", ElementType::Link, link_index_, links_);
  if (!name) return;
  const Owner owner{ElementType::Link, name};
  LinkInfo link;
  link.name = name;
  link.row = e->Row();

  if (const TiXmlElement* inertial = e->FirstChildElement("inertial")) {
    link.has_inertial = true;
    link.mass = std::numeric_limits<double>::quiet_NaN();
    readPose(inertial, owner, "<inertial>");
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
      std::vector<Finding> found;
      rules::checkInertia(link.name, m, I_com, found);
      addAll(found);
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
  links_.push_back(std::move(link));
}

void Checker::readJoint(const TiXmlElement* e) {
  ++report_.model.joints;
  const char* name = registerName(e, "joint", ElementType::Joint, joint_index_, joints_);
  if (!name) return;
  const Owner owner{ElementType::Joint, name};
  JointInfo joint;
  joint.name = name;
  joint.row = e->Row();

  readPose(e, owner, "");
  for (const char* end : {"parent", "child"}) {
    const TiXmlElement* x = e->FirstChildElement(end);
    const char* link = x ? x->Attribute("link") : nullptr;
    if (!link || !*link) {
      error("malformed", owner, std::string("has no <") + end + " link=\"...\"/>");
      graph_ok_ = false;
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
            "unknown type " + named(shown(type)) + " (revolute, continuous, prismatic, fixed, floating or planar)");
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
      std::vector<Finding> found;
      rules::checkAxis(joint.name, axis, found);
      addAll(found);
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
      std::vector<Finding> found;
      rules::checkLimits(joint.name, lower, upper, found);
      addAll(found);
    }
  } else if (limited) {
    error("malformed", owner,
          "a " + joint.type + " joint needs <limit lower=... upper=... effort=... velocity=.../> (urdfdom "
          "refuses it without)" + (joint.type == "revolute" ? "; for an unlimited rotation use a continuous joint" : ""));
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
    readRequired(mimic, {"joint"}, owner, "<mimic");
    for (const char* a : {"multiplier", "offset"}) readOptional(mimic, a, owner, "<mimic", unused);
  }
  if (const TiXmlElement* dynamics = e->FirstChildElement("dynamics")) {
    if (!dynamics->Attribute("damping") && !dynamics->Attribute("friction"))
      error("malformed", owner, "<dynamics> needs damping or friction (or no <dynamics> at all)");
    for (const char* a : {"damping", "friction"}) readOptional(dynamics, a, owner, "<dynamics", unused);
  }
  joints_.push_back(std::move(joint));
}

/// Links and joints as a graph: missing links, roots, loops; the base.
void Checker::checkGraph() {
  for (std::size_t j = 0; j < joints_.size(); ++j) {
    JointInfo& joint = joints_[j];
    const Owner owner{ElementType::Joint, joint.name};
    for (const bool parent : {true, false}) {
      const std::string& link = parent ? joint.parent : joint.child;
      if (link.empty()) continue;
      const auto it = link_index_.find(link);
      if (it == link_index_.end()) {
        error("missing_link", owner,
              std::string(parent ? "parent" : "child") + " link " + named(link) +
                  " does not exist: add <link name=\"" + link + "\"/>, or correct the name");
        graph_ok_ = false;
      } else {
        (parent ? joint.parent_link : joint.child_link) = it->second;
      }
    }
    if (joint.child_link >= 0) links_[joint.child_link].parent_joints.push_back(static_cast<int>(j));
    if (joint.parent_link >= 0 && joint.child_link >= 0)
      links_[joint.parent_link].child_joints.push_back(static_cast<int>(j));
  }
  // A link is named as a child even by a joint whose parent does not exist: not a root.
  std::vector<bool> named_child(links_.size(), false);
  for (const JointInfo& joint : joints_)
    if (const auto it = link_index_.find(joint.child); !joint.child.empty() && it != link_index_.end())
      named_child[it->second] = true;

  if (links_.empty()) {
    error("no_root", robot_, "no link: the robot has no <link name=\"...\">");
    graph_ok_ = false;
    return;
  }
  std::vector<int> roots;
  for (std::size_t i = 0; i < links_.size(); ++i)
    if (!named_child[i]) roots.push_back(static_cast<int>(i));
  if (roots.empty()) {
    error("no_root", robot_, "no root link: every link is the child of a joint (the joints form a loop)");
    graph_ok_ = false;
  }

  // Closed loops: a link with several parents.
  for (const LinkInfo& link : links_) {
    if (link.parent_joints.size() < 2) continue;
    std::vector<std::string> names;
    for (const int j : link.parent_joints) names.push_back(joints_[j].name);
    error("loop", {ElementType::Link, link.name},
          "the child of " + std::to_string(names.size()) + " joints (" + list(names) +
              "): they close a kinematic loop, and a URDF describes a tree; keep one of them "
              "(kdl_space cannot model closed chains)");
    graph_ok_ = false;
  }

  // What each root reaches, and the cycles among the links no root reaches.
  std::vector<int> reached_from(links_.size(), -1);
  std::vector<int> tree_size(links_.size(), 0);
  for (const int r : roots) {
    std::vector<int> stack{r};
    while (!stack.empty()) {
      const int l = stack.back();
      stack.pop_back();
      if (reached_from[l] >= 0) continue;
      reached_from[l] = r;
      ++tree_size[r];
      for (const int j : links_[l].child_joints) stack.push_back(joints_[j].child_link);
    }
  }
  std::vector<int> state(links_.size(), 0);  // 0 unvisited, 1 on the current path, 2 done
  for (std::size_t start = 0; start < links_.size(); ++start) {
    if (reached_from[start] >= 0 || state[start] != 0) continue;
    std::vector<int> path;  // child to parent
    int l = static_cast<int>(start);
    while (l >= 0 && state[l] == 0) {
      state[l] = 1;
      path.push_back(l);
      const std::vector<int>& up = links_[l].parent_joints;
      l = up.empty() ? -1 : joints_[up.front()].parent_link;
    }
    if (l >= 0 && state[l] == 1) {
      // The cycle, parent to child, from its link that comes first in the file.
      std::vector<int> cycle(std::find(path.begin(), path.end(), l), path.end());
      std::reverse(cycle.begin(), cycle.end());
      std::rotate(cycle.begin(), std::min_element(cycle.begin(), cycle.end()), cycle.end());
      std::string chain;
      std::vector<std::string> joint_names;
      for (std::size_t k = 0; k < cycle.size(); ++k) {
        chain += links_[cycle[k]].name + " -> ";
        // the joint from cycle[k] to the next link of the cycle
        const int next = cycle[(k + 1) % cycle.size()];
        joint_names.push_back(joints_[links_[next].parent_joints.front()].name);
      }
      chain += links_[cycle.front()].name;
      error("loop", {ElementType::Link, links_[cycle.front()].name},
            (joint_names.size() == 1 ? "joint " + named(joint_names.front()) + " makes the link its own parent"
                                     : "joints " + list(joint_names) + " form a cycle") +
                " (" + chain + "): a URDF describes a tree");
      graph_ok_ = false;
    }
    for (const int p : path) state[p] = 2;
  }

  if (roots.empty()) return;
  root_ = roots.front();
  for (const int r : roots)
    if (tree_size[r] > tree_size[root_]) root_ = r;
  for (const int r : roots) {
    if (r == root_) continue;
    error("several_roots", {ElementType::Link, links_[r].name},
          "a second root: no joint has it as child, so it is not part of the tree of the root " +
              named(links_[root_].name) + "; attach it with a joint, or remove it");
    graph_ok_ = false;
  }

  // The base: the root, or the only child of a floating joint from a massless root.
  const LinkInfo& root = links_[root_];
  const std::vector<int>& from_root = root.child_joints;
  if (rules::dropsRootJoint(!root.has_inertial || root.mass == 0.0, from_root.size(),
                            from_root.empty() ? "" : joints_[from_root.front()].type))
    dropped_joint_ = from_root.front();
  base_ = dropped_joint_ >= 0 ? joints_[dropped_joint_].child_link : root_;
}

/// Rules on the tree: free joints, the base, massless links, the mass ratio.
void Checker::checkTree() {
  std::vector<Finding> found;
  for (std::size_t j = 0; j < joints_.size(); ++j)
    if (joints_[j].known_type && static_cast<int>(j) != dropped_joint_)
      rules::checkJointType(joints_[j].name, joints_[j].type, found);
  if (base_ >= 0) {
    rules::checkBaseMass(links_[base_].name, links_[base_].has_inertial ? links_[base_].mass : 0.0, found);
    if (base_ == root_) rules::checkRootInertia(links_[root_].name, links_[root_].has_inertial, found);
  }
  if (graph_ok_ && base_ >= 0) {
    // Depth first from the base: parents precede children.
    std::vector<rules::MassNode> nodes;
    std::vector<bool> moving;  // a movable joint between the base and the link
    std::vector<int> depth;    // joints between the base and the link
    std::vector<std::pair<int, int>> stack{{base_, -1}};  // link, parent node
    std::vector<int> node_link;
    while (!stack.empty()) {
      const auto [l, parent] = stack.back();
      stack.pop_back();
      const LinkInfo& link = links_[l];
      rules::MassNode node;
      node.link = link.name;
      node.parent = parent;
      node.mass = link.has_inertial ? link.mass : 0.0;
      bool moves = false;
      if (parent >= 0) {
        const JointInfo& joint = joints_[link.parent_joints.front()];
        node.joint = joint.name;
        node.movable = joint.known_type && rules::isMovable(joint.type);
        moves = node.movable || moving[parent];
      }
      const int index = static_cast<int>(nodes.size());
      nodes.push_back(node);
      moving.push_back(moves);
      depth.push_back(parent >= 0 ? depth[parent] + 1 : 0);
      node_link.push_back(l);
      for (auto it = link.child_joints.rbegin(); it != link.child_joints.rend(); ++it)
        stack.push_back({joints_[*it].child_link, index});
    }
    rules::checkMassDistribution(nodes, found);
    for (std::size_t i = 0; i < nodes.size(); ++i)
      if (depth[i] > rules::kMaxTreeDepth) {
        rules::checkDepth(nodes[i].link, depth[i], found);  // the first link too deep is enough
        break;
      }
    for (std::size_t i = 1; i < nodes.size(); ++i)
      if (moving[i] && nodes[i].mass > 0.0 && std::isfinite(nodes[i].mass) &&
          (lightest_ < 0 || nodes[i].mass < links_[lightest_].mass))
        lightest_ = node_link[i];
  }
  addAll(found);
}

void Checker::checkTips() {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < links_.size(); ++i)
    if (dropped_joint_ < 0 || static_cast<int>(i) != root_) names.push_back(links_[i].name);
  for (const std::string& tip : tips_)
    if (std::find(names.begin(), names.end(), tip) == names.end())
      add(rules::error("unknown_tip", ElementType::Tip, tip, "not a link of the model (its links: " + list(names) + ")"));
}

/// Loads the model (only without errors: the loader applies the same rules) and computes the
/// condition numbers at q = 0; the mass-ratio warning.
void Checker::loadAndMeasure(const std::string& xml) {
  ModelSummary& summary = report_.model;
  std::string conditions = "condition numbers not computed: the model has errors";
  if (report_.errors.empty()) {
    try {
      const auto model = std::make_shared<const FloatingModel>(loadUrdfString(xml, report_.source));
      summary.loaded = true;
      summary.base = model->bodies()[0].name;
      summary.joint_names = model->jointNames();
      summary.total_mass = model->totalMass();
      FreeFloatingSolver solver(model);
      const double inf = std::numeric_limits<double>::infinity();
      if (solver.compute(State(*model)) != E_NOERROR) {
        add(rules::error("singular_inertia", ElementType::File, "",
                         "H* (generalized inertia) is singular at q = 0: some joints move the bodies in the "
                         "same way (e.g. coincident axes with only massless links between them)"));
        summary.condition_H_star = inf;
      } else if (model->nj() == 0) {
        summary.condition_H_star = std::numeric_limits<double>::quiet_NaN();
      } else {
        const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(solver.H_star().data, Eigen::EigenvaluesOnly);
        const Eigen::VectorXd& l = eig.eigenvalues();
        summary.condition_H_star = l(0) > 0.0 ? l(l.size() - 1) / l(0) : inf;
      }
      // G* at the tips, else at every link that carries no other link.
      std::vector<std::string> contacts = tips_;
      if (contacts.empty()) {
        const std::vector<Body>& bodies = model->bodies();
        std::vector<bool> carries(bodies.size(), false);
        for (const Body& b : bodies)
          if (b.parent >= 0) carries[b.parent] = true;
        for (std::size_t i = 1; i < bodies.size(); ++i)
          if (!carries[i]) contacts.push_back(bodies[i].name);
      }
      for (const std::string& link : contacts) {
        Matrix6d G;
        const int rc = solver.G_star(model->contact(link), G);
        summary.condition_G_star.emplace_back(link, rc == E_NOERROR ? spectralFigures(G).condition : inf);
      }
      conditions = "at q = 0, cond(H*) = " + number(summary.condition_H_star);
      for (std::size_t i = 0; i < summary.condition_G_star.size(); ++i)
        conditions += (i == 0 ? ", cond(G*) = " : ", ") + number(summary.condition_G_star[i].second) + " at " +
                      named(summary.condition_G_star[i].first);
    } catch (const std::exception& e) {
      // The loader applies the same rules: whatever it still refuses, say it in its words.
      std::string why = e.what();
      if (why.rfind(report_.source + ": ", 0) == 0) why.erase(0, report_.source.size() + 2);
      add(rules::error("refused_by_loader", ElementType::File, "", "the loader refuses the file: " + why));
    }
  }
  if (lightest_ >= 0 && base_ >= 0 && links_[base_].mass > 0.0) {
    const double ratio = links_[base_].mass / links_[lightest_].mass;
    if (ratio > kMassRatioLimit)
      add(rules::warning("mass_ratio", ElementType::Link, links_[lightest_].name,
                         "the base " + named(links_[base_].name) + " (" + number(links_[base_].mass) +
                             " kg) is " + number(ratio) + " times heavier than this moving link (" +
                             number(links_[lightest_].mass) + " kg), above " + number(kMassRatioLimit) +
                             ": H* and G* may be ill-conditioned (" + conditions + ")"));
  }
}

UrdfReport Checker::run(const std::string& xml) {
  if (xml.find_first_not_of(" \t\n\r") == std::string::npos) {
    fileError("not_xml", "not XML: the file is empty");
    return report_;
  }
  if (const std::string problem = rules::xmlDepthProblem(xml); !problem.empty()) {
    fileError("not_xml", "not XML that can be read safely: " + problem);
    return report_;
  }
  TiXmlDocument doc;
  const std::string padded = xml + "    ";  // TinyXML reads past a final UTF-8 lead byte: see urdf_loader.cpp
  doc.Parse(padded.c_str());
  if (doc.Error()) {
    std::string why = doc.ErrorDesc();  // e.g. "Error reading end tag."
    if (!why.empty() && why.back() == '.') why.pop_back();
    if (!why.empty()) why[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(why[0])));
    fileError("not_xml", "not XML: " + why + " (line " + std::to_string(doc.ErrorRow()) + ", column " +
                             std::to_string(doc.ErrorCol()) + ")");
    return report_;
  }
  const TiXmlElement* robot = doc.FirstChildElement("robot");
  if (!robot) {
    const TiXmlElement* top = doc.FirstChildElement();
    fileError("not_urdf", top ? "not URDF: the top element is <" + shown(top->Value()) + ">, not <robot>"
                              : "not URDF: no <robot> element");
    return report_;
  }
  if (const char* name = robot->Attribute("name")) {
    report_.model.robot = robot_.name = name;
  } else {
    error("malformed", robot_, "the <robot> element has no name attribute");
  }
  if (const char* version = robot->Attribute("version"); version && std::string(version) != "1.0")
    error("malformed", robot_, "version " + named(shown(version)) + ": urdfdom reads only version 1.0");

  for (const TiXmlElement* e = robot->FirstChildElement(); e; e = e->NextSiblingElement()) {
    const std::string tag = e->Value();
    if (tag == "link") readLink(e);
    else if (tag == "joint") readJoint(e);
    else if (tag == "material") readMaterial(e, robot_, "", true);
  }
  checkGraph();
  checkTree();
  checkTips();
  if (base_ >= 0) report_.model.base = links_[base_].name;
  if (dropped_joint_ >= 0) --report_.model.links, --report_.model.joints;  // not in the model
  loadAndMeasure(xml);
  return report_;
}

}  // namespace

std::string describe(const Finding& f) {
  switch (f.element_type) {
    case ElementType::File: return f.message;
    case ElementType::Robot: return (f.element.empty() ? "robot" : "robot '" + f.element + "'") + ": " + f.message;
    case ElementType::Link: return "link '" + f.element + "': " + f.message;
    case ElementType::Joint: return "joint '" + f.element + "': " + f.message;
    case ElementType::Tip: return "tip '" + f.element + "': " + f.message;
  }
  return f.message;
}

UrdfReport checkUrdfString(const std::string& xml, const std::string& source, const std::vector<std::string>& tips) {
  return Checker(source, tips).run(xml);
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
  constexpr std::uintmax_t kMaxBytes = 256u << 20;
  if (const std::uintmax_t size = std::filesystem::file_size(path, ec); !ec && size > kMaxBytes)
    return unreadable("larger than 256 MiB (" + std::to_string(size) + " bytes): not a URDF file");
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) return unreadable(std::string("cannot open the file") + (errno ? std::string(": ") + std::strerror(errno) : ""));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return unreadable("cannot read the file");
  return checkUrdfString(text.str(), path, tips);
}

}  // namespace kdl_space
