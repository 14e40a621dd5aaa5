// The module libkdl_space_sdf.so (sdf_module.hpp): Gazebo's model files through Debian's SDFormat.
#include <sdf/Box.hh>
#include <sdf/Console.hh>
#include <sdf/Element.hh>
#include <sdf/Cylinder.hh>
#include <sdf/Geometry.hh>
#include <sdf/Joint.hh>
#include <sdf/JointAxis.hh>
#include <sdf/Link.hh>
#include <sdf/Material.hh>
#include <sdf/Mesh.hh>
#include <sdf/Model.hh>
#include <sdf/Root.hh>
#include <sdf/Sphere.hh>
#include <sdf/Visual.hh>

#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>

#include "kdl_space/parsers/input_file.hpp"
#include "kdl_space/spatial/errors.hpp"
#include "parsers/formats/sdf_module.hpp"
#include "parsers/formats/urdf_builder.hpp"
#include "spatial/message_text.hpp"

namespace kdl_space {
namespace {
namespace fs = std::filesystem;
using formats::UrdfJoint;
using formats::UrdfLink;
using formats::UrdfVisual;

constexpr double inf = std::numeric_limits<double>::infinity();

KDL::Frame frame(const ignition::math::Pose3d& p) {
  const auto& q = p.Rot();
  return KDL::Frame(KDL::Rotation::Quaternion(q.X(), q.Y(), q.Z(), q.W()), KDL::Vector(p.Pos().X(), p.Pos().Y(), p.Pos().Z()));
}

/// SDFormat's errors as one InputError: "FILE:LINE: message" for the first, the count of the rest.
[[noreturn]] void refuse(const std::string& path, const sdf::Errors& errors) {
  const sdf::Error& e = errors.front();
  std::string where = e.FilePath().value_or(path);
  if (e.LineNumber()) where += ":" + std::to_string(*e.LineNumber());
  std::string more = errors.size() > 1 ? " (and " + std::to_string(errors.size() - 1) + " more)" : "";
  throw InputError(where + ": SDF: " + e.Message() + more);
}

/// "FILE:LINE" of an element SDFormat read (its line when it kept one).
std::string where(const std::string& path, const sdf::ElementPtr& e) {
  const std::optional<int> line = e ? e->LineNumber() : std::nullopt;
  return line ? path + ":" + std::to_string(*line) : path;
}

/// A pose resolved in the model frame, or the error naming what.
KDL::Frame inModel(const sdf::SemanticPose& pose, const std::string& path, const std::string& what) {
  ignition::math::Pose3d p;
  const sdf::Errors e = pose.Resolve(p, "__model__");
  if (!e.empty()) throw InputError(path + ": SDF: " + what + ": its pose does not resolve: " + e.front().Message());
  return frame(p);
}

JointProperties properties(const sdf::JointAxis& a, bool bounded) {
  JointProperties p;
  if (bounded && std::abs(a.Lower()) < 1e15) p.lower = a.Lower();  // SDFormat's "no limit": +-1e16
  if (bounded && std::abs(a.Upper()) < 1e15) p.upper = a.Upper();
  p.effort = a.Effort() >= 0.0 ? a.Effort() : inf;  // -1: none
  p.velocity = a.MaxVelocity() >= 0.0 ? a.MaxVelocity() : inf;
  p.damping = a.Damping();
  p.friction = a.Friction();
  return p;
}

std::string meshFile(const std::string& uri, const std::string& sdf_file) {
  std::string file = uri.rfind("file://", 0) == 0 ? uri.substr(7) : uri;
  if (file.find("://") != std::string::npos) return "";  // model://, package://, https://: no file here
  const fs::path p(file);
  return p.is_absolute() ? p.lexically_normal().string() : (fs::path(sdf_file).parent_path() / p).lexically_normal().string();
}

/// The visuals SDFormat gives `link`, in the URDF frame `link_T_urdf`^-1 (box, cylinder, sphere, mesh).
std::vector<UrdfVisual> visuals(const sdf::Link& link, const KDL::Frame& urdf_T_link, const std::string& path,
                                std::vector<Diagnostic>& notes) {
  std::vector<UrdfVisual> out;
  for (uint64_t i = 0; i < link.VisualCount(); ++i) {
    const sdf::Visual& v = *link.VisualByIndex(i);
    ignition::math::Pose3d pose;
    if (!v.SemanticPose().Resolve(pose, link.Name()).empty()) continue;
    UrdfVisual u;
    u.origin = urdf_T_link * frame(pose);
    const sdf::Geometry& g = *v.Geom();
    if (g.Type() == sdf::GeometryType::BOX) {
      u.geometry = "box";
      u.size = {g.BoxShape()->Size().X(), g.BoxShape()->Size().Y(), g.BoxShape()->Size().Z()};
    } else if (g.Type() == sdf::GeometryType::CYLINDER) {
      u.geometry = "cylinder";
      u.size = {g.CylinderShape()->Radius(), g.CylinderShape()->Length(), 0.0};
    } else if (g.Type() == sdf::GeometryType::SPHERE) {
      u.geometry = "sphere";
      u.size = {g.SphereShape()->Radius(), 0.0, 0.0};
    } else if (g.Type() == sdf::GeometryType::MESH) {
      u.geometry = "mesh";
      u.mesh = meshFile(g.MeshShape()->Uri(), path);
      u.size = {g.MeshShape()->Scale().X(), g.MeshShape()->Scale().Y(), g.MeshShape()->Scale().Z()};
      if (u.mesh.empty()) {
        notes.push_back({link.Name(), "visual " + detail::quoted(v.Name()) + ": mesh " + detail::quoted(g.MeshShape()->Uri()) +
                                          " is not a file path here: left out of the picture", "", Severity::Note});
        continue;
      }
    } else {
      notes.push_back({link.Name(), "visual " + detail::quoted(v.Name()) + ": a geometry other than box, cylinder, sphere or mesh: left out of the picture",
                       "", Severity::Note});
      continue;
    }
    if (v.Material()) {
      const auto c = v.Material()->Diffuse();
      u.rgba = Eigen::Vector4d(c.R(), c.G(), c.B(), c.A());
    }
    out.push_back(u);
  }
  return out;
}

struct Reader {
  std::string path;
  const sdf::Model* model = nullptr;
  std::vector<Diagnostic>& notes;
  std::map<std::string, KDL::Frame> model_T_urdf;   ///< each link's URDF frame in the model frame
  std::map<std::string, const sdf::Joint*> joint_of;  ///< the joint that carries each link
  std::vector<const sdf::Joint*> order;               ///< the joints read, in the file's order

  void joints();
  UrdfJoint joint(const sdf::Joint& j) const;
  UrdfLink link(const sdf::Link& l);
};

void Reader::joints() {
  for (uint64_t i = 0; i < model->JointCount(); ++i) {
    const sdf::Joint& j = *model->JointByIndex(i);
    const std::string what = "joint " + detail::quoted(j.Name());
    const sdf::JointType t = j.Type();
    if (t != sdf::JointType::REVOLUTE && t != sdf::JointType::CONTINUOUS && t != sdf::JointType::PRISMATIC && t != sdf::JointType::FIXED)
      throw InputError(where(path, j.Element()) + ": SDF: " + what + ": only revolute, continuous, prismatic and fixed joints are read (a ball, universal, "
                       "screw or gearbox joint has no KDL counterpart)");
    std::string parent, child;
    if (!j.ResolveParentLink(parent).empty() || !j.ResolveChildLink(child).empty())
      throw InputError(where(path, j.Element()) + ": SDF: " + what + ": its parent or child does not resolve to a link of the model");
    if (parent == "world") {
      notes.push_back({j.Name(), "a joint to the world: dropped, the base floats", "", Severity::Note});
      continue;
    }
    if (joint_of.count(child)) throw InputError(where(path, j.Element()) + ": SDF: " + what + ": link " + detail::quoted(child) + " already has a parent joint");
    joint_of[child] = &j;
    order.push_back(&j);
    model_T_urdf[child] = inModel(j.SemanticPose(), path, what);  // the URDF link frame is its joint's frame
  }
}

UrdfJoint Reader::joint(const sdf::Joint& j) const {
  UrdfJoint u;
  u.name = j.Name();
  j.ResolveParentLink(u.parent);
  j.ResolveChildLink(u.child);
  u.origin = model_T_urdf.at(u.parent).Inverse() * model_T_urdf.at(u.child);
  const sdf::JointType t = j.Type();
  u.type = t == sdf::JointType::REVOLUTE ? "revolute" : t == sdf::JointType::CONTINUOUS ? "continuous"
           : t == sdf::JointType::PRISMATIC ? "prismatic" : "fixed";
  if (t == sdf::JointType::FIXED) return u;
  const sdf::JointAxis* a = j.Axis(0);
  if (!a) throw InputError(where(path, j.Element()) + ": SDF: joint " + detail::quoted(j.Name()) + ": no <axis>");
  ignition::math::Vector3d xyz;
  if (!a->ResolveXyz(xyz, "__model__").empty())
    throw InputError(where(path, j.Element()) + ": SDF: joint " + detail::quoted(j.Name()) + ": its axis does not resolve");
  const KDL::Vector axis = model_T_urdf.at(u.child).M.Inverse() * KDL::Vector(xyz.X(), xyz.Y(), xyz.Z());
  u.axis = Eigen::Vector3d(axis.x(), axis.y(), axis.z()).normalized();
  u.properties = properties(*a, t != sdf::JointType::CONTINUOUS);
  return u;
}

UrdfLink Reader::link(const sdf::Link& l) {
  UrdfLink u;
  u.name = l.Name();
  const KDL::Frame urdf_T_link = model_T_urdf.at(l.Name()).Inverse() * inModel(l.SemanticPose(), path, "link " + detail::quoted(l.Name()));
  const auto& in = l.Inertial();
  formats::UrdfInertial i;
  i.mass = in.MassMatrix().Mass();
  i.origin = urdf_T_link * frame(in.Pose());
  const auto moi = in.MassMatrix().Moi();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) i.inertia(r, c) = moi(r, c);
  u.inertial = i;
  u.visuals = visuals(l, urdf_T_link, path, notes);
  return u;
}

}  // namespace

/// sdfToUrdf's reading (kdl_space/parsers/formats/sdf_reader.hpp has the rules): one model's links
/// and joints.
void readSdf(const std::string& path, std::vector<Diagnostic>& notes, formats::SdfModel& model) {
  checkInputFile(path, "SDF file", max_input_file_bytes);
  sdf::Console::Instance()->SetQuiet(true);  // the library prints nothing: the errors come back as data
  sdf::Root root;
  const sdf::Errors errors = root.Load(path);
  if (!errors.empty()) refuse(path, errors);
  if (root.WorldCount() > 0 || !root.Model())
    throw InputError(path + ": SDF: expected one <model> (a <world> holds a scene: give the robot's model file)");
  Reader r{path, root.Model(), notes, {}, {}, {}};
  if (r.model->ModelCount() > 0)
    throw InputError(path + ": SDF: model " + detail::quoted(r.model->Name()) + ": nested models are not read: give one model's file");
  const sdf::Link* canonical = r.model->CanonicalLink();
  if (!canonical) throw InputError(path + ": SDF: model " + detail::quoted(r.model->Name()) + ": no link");
  r.joints();
  if (r.joint_of.count(canonical->Name()))
    throw InputError(path + ": SDF: the canonical link " + detail::quoted(canonical->Name()) + " has a parent joint: the base must be the tree's root");
  r.model_T_urdf[canonical->Name()] = inModel(canonical->SemanticPose(), path, "link " + detail::quoted(canonical->Name()));
  model.name = r.model->Name();
  for (uint64_t i = 0; i < r.model->LinkCount(); ++i) {
    const sdf::Link& l = *r.model->LinkByIndex(i);
    if (!r.model_T_urdf.count(l.Name()))
      throw InputError(where(path, l.Element()) + ": SDF: link " + detail::quoted(l.Name()) + ": no joint joins it to the model (a tree rooted at the canonical link " +
                       detail::quoted(canonical->Name()) + " is read)");
    model.links.push_back(r.link(l));
  }
  for (const sdf::Joint* j : r.order) model.joints.push_back(r.joint(*j));
}

}  // namespace kdl_space

// The module's one export (the rest of it is hidden): formats::ReadSdf, found by sdf_entry_name.
extern "C" __attribute__((visibility("default"))) void kdl_space_read_sdf(const std::string& path,
    std::vector<kdl_space::Diagnostic>& notes, kdl_space::formats::SdfModel& model) {
  kdl_space::readSdf(path, notes, model);
}
