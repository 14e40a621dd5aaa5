#include "parsers/scenario/scenario_mount.hpp"

#include <filesystem>
#include <vector>

#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space::sections {
namespace {

using fields::Field;

/// `bus`: {mass, box (uniform density) | inertia [, com], name} or {urdf}.
BusBody bus(const Field& b, const std::string& folder) {
  b.onlyKeys({"urdf", "name", "mass", "inertia", "com", "box"});
  BusBody bus;
  if (b.has("urdf")) {
    for (const char* k : {"name", "mass", "inertia", "com", "box"})
      if (b.has(k)) b.at(k).fail("the bus is its URDF file (bus.urdf) or a body (mass, box or inertia), not both");
    bus.urdf = filePath(b.at("urdf"), folder);
    return bus;
  }
  if (b.has("name")) bus.name = b.at("name").text();
  if (bus.name.empty()) b.at("name").fail("the bus link's name is empty");
  bus.mass = b.at("mass").number();
  if (!(bus.mass > 0.0)) b.at("mass").fail("must be > 0 kg, got " + b.at("mass").text());
  if (b.has("com")) bus.com = b.at("com").vector(3);
  if (b.has("box")) {
    bus.box = b.at("box").vector(3);
    if (!(bus.box.array() > 0.0).all()) b.at("box").fail("its edges must be > 0 m");
  }
  if (b.has("inertia"))
    bus.inertia = b.at("inertia").matrix3();
  else if (b.has("box"))
    bus.inertia = boxInertia(bus.mass, bus.box);  // a uniform box about its centre, the CoM
  else
    b.fail("give the bus's inertia (about its CoM) or a box (uniform density): bus: {mass, box: [x, y, z]}");
  return bus;
}

/// One arm: its `urdf`, and the `link` and `pose` (position, rpy) that `holder` may give.
ArmMount arm(const Field& urdf, const Field& holder, const std::string& folder) {
  ArmMount a;
  a.urdf = filePath(urdf, folder);
  if (holder.has("link")) a.link = holder.at("link").text();
  if (holder.has("pose")) {
    holder.at("pose").onlyKeys({"position", "rpy"});
    a.pose = fields::pose(holder.at("pose"));
  }
  return a;
}

}  // namespace

std::string filePath(const Field& f, const std::string& folder) {
  std::string path = f.text();
  if (path.empty()) f.fail("the file name is empty");
  if (std::filesystem::path(path).is_relative())
    path = (std::filesystem::path(folder) / path).lexically_normal().string();
  return path;
}

MountedRobot mounted(const Field& f, const std::string& folder) {
  const Field m = f.at("mount");
  m.onlyKeys({"bus", "link", "pose", "arms"});
  std::vector<ArmMount> arms;
  if (m.has("arms")) {
    if (f.has("urdf")) f.at("urdf").fail("with mount.arms each arm names its urdf there: remove robot.urdf");
    for (const char* k : {"link", "pose"})
      if (m.has(k)) m.at(k).fail("with mount.arms each arm has its own link and pose there");
    for (const Field& a : m.at("arms").items("arms {urdf, link, pose}")) {
      a.onlyKeys({"urdf", "link", "pose"});
      arms.push_back(arm(a.at("urdf"), a, folder));
    }
    if (arms.empty()) m.at("arms").fail("give at least one arm");
  } else {
    arms.push_back(arm(f.at("urdf"), m, folder));
  }
  const BusBody b = bus(m.at("bus"), folder);
  try {
    return mountArms(b, arms);
  } catch (const Error& e) {  // a file that cannot be read, a bus link missing
    e.rethrowWithContext(m.where());
  }
}

}  // namespace kdl_space::sections

namespace kdl_space {

std::map<std::string, std::vector<LinkVisual>> robotVisuals(const Scenario& sc, const std::vector<std::string>& package_path) {
  if (!sc.robot_document.empty()) return readUrdfVisualsString(sc.robot_document, sc.file, package_path);
  if (!sc.robot_urdf.empty()) return readUrdfVisuals(sc.robot_urdf, package_path);
  return {};
}

std::map<std::string, std::vector<LinkVisual>> targetVisuals(const Scenario& sc, const std::vector<std::string>& package_path) {
  if (!sc.target_document.empty()) return readUrdfVisualsString(sc.target_document, sc.target_urdf, package_path);
  if (!sc.target_urdf.empty()) return readUrdfVisuals(sc.target_urdf, package_path);
  return {};
}

}  // namespace kdl_space
