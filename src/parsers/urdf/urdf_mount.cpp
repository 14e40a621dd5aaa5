#include "kdl_space/parsers/urdf/urdf_mount.hpp"

#include <tinyxml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "kdl_space/parsers/input_file.hpp"
#include "kdl_space/spatial/errors.hpp"
#include "parsers/formats/urdf_builder.hpp"
#include "spatial/message_text.hpp"

namespace kdl_space {
namespace {
namespace fs = std::filesystem;


std::string num(double v) { return formats::exactNumber(v); }  // reads back exactly

std::string triple(double a, double b, double c) { return num(a) + " " + num(b) + " " + num(c); }

/// A URDF file read by TinyXML (as urdfdom reads it): its <robot> element, or InputError "FILE[:LINE]: why".
struct Document {
  std::string path;
  TiXmlDocument doc;
  TiXmlElement* robot = nullptr;
};

void readDocument(const std::string& path, const std::string& what, Document& d) {
  d.path = path;
  checkInputFile(path, "URDF file", max_input_file_bytes);
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  d.doc.Parse(text.str().c_str());
  if (d.doc.Error())
    throw InputError(path + ":" + std::to_string(d.doc.ErrorRow()) + ": " + what + ": not an XML document (" +
                     d.doc.ErrorDesc() + ")");
  d.robot = d.doc.FirstChildElement("robot");
  if (!d.robot) throw InputError(path + ": " + what + ": no <robot> element: not a URDF file");
}

/// Each child element of <robot> named `tag`, in document order.
std::vector<TiXmlElement*> elements(TiXmlElement* robot, const char* tag) {
  std::vector<TiXmlElement*> list;
  for (TiXmlElement* e = robot->FirstChildElement(tag); e; e = e->NextSiblingElement(tag)) list.push_back(e);
  return list;
}

std::string attribute(const TiXmlElement* e, const char* name) {
  const char* v = e ? e->Attribute(name) : nullptr;
  return v ? v : "";
}

std::set<std::string> namesOf(TiXmlElement* robot, const char* tag) {
  std::set<std::string> names;
  for (TiXmlElement* e : elements(robot, tag)) names.insert(attribute(e, "name"));
  return names;
}

/// The one link no joint has as its child.
std::string rootLink(const Document& d, const std::string& what) {
  std::set<std::string> roots = namesOf(d.robot, "link");
  for (TiXmlElement* j : elements(d.robot, "joint")) roots.erase(attribute(j->FirstChildElement("child"), "link"));
  if (roots.size() != 1)
    throw InputError(d.path + ": " + what + ": expected one root link (a link no joint has as its child), found " +
                     std::to_string(roots.size()) + (roots.empty() ? " (a loop of joints?)" : ""));
  return *roots.begin();
}

/// Every visual's and collision's mesh with a relative path made absolute (from `folder`).
/// \return whether one was.
bool absoluteMeshes(TiXmlElement* robot, const fs::path& folder) {
  bool changed = false;
  for (TiXmlElement* link : elements(robot, "link"))
    for (const char* part : {"visual", "collision"})
      for (TiXmlElement* v = link->FirstChildElement(part); v; v = v->NextSiblingElement(part)) {
        TiXmlElement* mesh = v->FirstChildElement("geometry") ? v->FirstChildElement("geometry")->FirstChildElement("mesh") : nullptr;
        const std::string file = attribute(mesh, "filename");
        if (file.empty() || file.find("://") != std::string::npos || fs::path(file).is_absolute()) continue;
        mesh->SetAttribute("filename", fs::absolute(folder / file).lexically_normal().string());
        changed = true;
      }
  return changed;
}

/// Renames every link and joint `prefix` + name, and the references to them (a joint's parent
/// and child, a mimic's joint).
void prefixNames(TiXmlElement* robot, const std::string& prefix) {
  for (TiXmlElement* l : elements(robot, "link")) l->SetAttribute("name", prefix + attribute(l, "name"));
  for (TiXmlElement* j : elements(robot, "joint")) {
    j->SetAttribute("name", prefix + attribute(j, "name"));
    for (const char* end : {"parent", "child"})
      if (TiXmlElement* e = j->FirstChildElement(end)) e->SetAttribute("link", prefix + attribute(e, "link"));
    if (TiXmlElement* m = j->FirstChildElement("mimic")) m->SetAttribute("joint", prefix + attribute(m, "joint"));
  }
}

/// The robot-level materials of `robot` into `out`: one the document already has the same way is
/// left out; one of the same name defined otherwise is renamed NAME_`suffix` (and its uses).
void copyMaterials(TiXmlElement* robot, TiXmlElement& out, const std::string& suffix) {
  std::map<std::string, std::string> renamed;
  for (TiXmlElement* m : elements(robot, "material")) {
    const std::string name = attribute(m, "name");
    TiXmlPrinter mine;
    m->Accept(&mine);
    bool same = false, clash = false;
    for (TiXmlElement* o : elements(&out, "material")) {
      if (attribute(o, "name") != name) continue;
      TiXmlPrinter theirs;
      o->Accept(&theirs);
      (std::string(theirs.CStr()) == mine.CStr() ? same : clash) = true;
    }
    if (same) continue;
    if (clash) m->SetAttribute("name", renamed[name] = name + "_" + suffix);
    out.InsertEndChild(*m);
  }
  if (renamed.empty()) return;
  for (TiXmlElement* link : elements(robot, "link"))
    for (TiXmlElement* v = link->FirstChildElement("visual"); v; v = v->NextSiblingElement("visual"))
      if (TiXmlElement* m = v->FirstChildElement("material")) {
        const auto r = renamed.find(attribute(m, "name"));
        if (r != renamed.end()) m->SetAttribute("name", r->second);
      }
}

/// The bus as one link of the given mass, inertia and CoM (and its box, drawn).
TiXmlElement busLink(const BusBody& bus) {
  const auto finite = [](const auto& m) { return m.allFinite(); };
  if (!(bus.mass > 0.0) || !std::isfinite(bus.mass))
    throw InputError("bus.mass: must be a finite mass > 0 kg, got " + num(bus.mass));
  if (!finite(bus.inertia) || !finite(bus.com) || !finite(bus.box) || (bus.box.array() < 0.0).any())
    throw InputError("bus: its inertia, com and box must be finite (a box's edges >= 0)");
  TiXmlElement link("link");
  link.SetAttribute("name", bus.name);
  formats::appendInertial(link, {bus.mass, KDL::Frame(KDL::Vector(bus.com.x(), bus.com.y(), bus.com.z())), bus.inertia});
  if ((bus.box.array() > 0.0).all()) {
    for (const char* part : {"visual", "collision"}) {
      TiXmlElement v(part), geometry("geometry"), box("box"), origin("origin");  // the box at the CoM
      origin.SetAttribute("xyz", triple(bus.com.x(), bus.com.y(), bus.com.z()));
      origin.SetAttribute("rpy", "0 0 0");
      box.SetAttribute("size", triple(bus.box.x(), bus.box.y(), bus.box.z()));
      geometry.InsertEndChild(box);
      v.InsertEndChild(origin);
      v.InsertEndChild(geometry);
      link.InsertEndChild(v);
    }
  }
  return link;
}

/// A name not in `used` (`name`, else name_2, name_3, ...), added to it.
std::string unique(const std::string& name, std::set<std::string>& used) {
  std::string n = name;
  for (int k = 2; used.count(n); ++k) n = name + "_" + std::to_string(k);
  used.insert(n);
  return n;
}

}  // namespace

Eigen::Matrix3d boxInertia(double mass, const Eigen::Vector3d& size) {
  const Eigen::Vector3d s2 = size.cwiseProduct(size);
  return (mass / 12.0) * Eigen::Vector3d(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y()).asDiagonal();
}

MountedRobot mountArms(const BusBody& bus, const std::vector<ArmMount>& arms) {
  MountedRobot result;
  TiXmlElement out("robot");
  std::set<std::string> links, joints;
  std::string bus_root = bus.name;
  if (!bus.urdf.empty()) {
    Document b;
    readDocument(bus.urdf, "the bus", b);
    result.files.push_back(bus.urdf);
    bus_root = rootLink(b, "the bus");
    if (absoluteMeshes(b.robot, fs::path(bus.urdf).parent_path()))
      result.notes.push_back({"", bus.urdf + ": relative mesh paths made absolute (from its folder)", "", Severity::Note});
    copyMaterials(b.robot, out, "bus");
    for (const char* tag : {"link", "joint"})
      for (TiXmlElement* e : elements(b.robot, tag)) out.InsertEndChild(*e);
    links = namesOf(b.robot, "link"), joints = namesOf(b.robot, "joint");
    out.SetAttribute("name", attribute(b.robot, "name"));
  } else {
    out.InsertEndChild(busLink(bus));
    links.insert(bus.name);
  }
  for (std::size_t k = 0; k < arms.size(); ++k) {
    const ArmMount& arm = arms[k];
    const std::string what = "arm " + std::to_string(k + 1);
    Document a;
    readDocument(arm.urdf, what, a);
    result.files.push_back(arm.urdf);
    if (k == 0 && bus.urdf.empty()) out.SetAttribute("name", attribute(a.robot, "name") + "_on_" + bus.name);
    const std::string hook = arm.link.empty() ? bus_root : arm.link;
    if (!links.count(hook))
      throw InputError(arm.urdf + ": " + what + " hangs on the bus link " + detail::quoted(hook) + ", which the bus has not");
    std::string root = rootLink(a, what);
    std::string clash;
    for (const std::string& n : namesOf(a.robot, "link"))
      if (links.count(n)) clash = n;
    for (const std::string& n : namesOf(a.robot, "joint"))
      if (joints.count(n)) clash = n;
    if (!clash.empty()) {
      const std::string prefix = "arm" + std::to_string(k + 1) + "/";
      prefixNames(a.robot, prefix);
      root = prefix + root;
      result.notes.push_back({"", arm.urdf + ": its names meet the bus's or an earlier arm's (" + detail::quoted(clash) +
                                      "): every link and joint of it prefixed " + detail::quoted(prefix), "", Severity::Note});
    }
    if (absoluteMeshes(a.robot, fs::path(arm.urdf).parent_path()))
      result.notes.push_back({"", arm.urdf + ": relative mesh paths made absolute (from its folder)", "", Severity::Note});
    copyMaterials(a.robot, out, "arm" + std::to_string(k + 1));
    for (TiXmlElement* e : elements(a.robot, "link")) out.InsertEndChild(*e), links.insert(attribute(e, "name"));
    for (TiXmlElement* e : elements(a.robot, "joint")) out.InsertEndChild(*e), joints.insert(attribute(e, "name"));
    // The mount: the arm's root link on its bus link, at its pose.
    TiXmlElement joint("joint"), origin("origin"), parent("parent"), child("child");
    joint.SetAttribute("name", unique(root + "_mount", joints));
    joint.SetAttribute("type", "fixed");
    const KDL::Vector rpy = formats::urdfRpy(arm.pose.M);  // exact near pitch = +-pi/2
    origin.SetAttribute("xyz", triple(arm.pose.p.x(), arm.pose.p.y(), arm.pose.p.z()));
    origin.SetAttribute("rpy", triple(rpy.x(), rpy.y(), rpy.z()));
    parent.SetAttribute("link", hook);
    child.SetAttribute("link", root);
    joint.InsertEndChild(origin);
    joint.InsertEndChild(parent);
    joint.InsertEndChild(child);
    out.InsertEndChild(joint);
  }
  result.urdf = formats::xmlText(out);
  return result;
}

}  // namespace kdl_space
