#include "kdl_space/parsers/urdf/urdf_visuals.hpp"

#include <urdf_parser/urdf_parser.h>

#include <filesystem>

#include "kdl_space/spatial/errors.hpp"
#include "parsers/urdf/urdf_parse.hpp"
#include "parsers/urdf/urdf_text.hpp"

namespace kdl_space {
namespace {

KDL::Frame frameOf(const urdf::Pose& p) {
  return KDL::Frame(KDL::Rotation::Quaternion(p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w),
                    KDL::Vector(p.position.x, p.position.y, p.position.z));
}

/// The visual's shape; false for a <visual> without a geometry urdfdom understood.
bool shapeOf(const urdf::Geometry& g, LinkVisual& v) {
  switch (g.type) {
    case urdf::Geometry::BOX: {
      const auto& b = static_cast<const urdf::Box&>(g);
      v.shape = LinkVisual::Shape::Box;
      v.size = Eigen::Vector3d(b.dim.x, b.dim.y, b.dim.z);
      return true;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& c = static_cast<const urdf::Cylinder&>(g);
      v.shape = LinkVisual::Shape::Cylinder;
      v.size = Eigen::Vector3d(c.radius, c.length, 0.0);
      return true;
    }
    case urdf::Geometry::SPHERE:
      v.shape = LinkVisual::Shape::Sphere;
      v.size = Eigen::Vector3d(static_cast<const urdf::Sphere&>(g).radius, 0.0, 0.0);
      return true;
    case urdf::Geometry::MESH: {
      const auto& m = static_cast<const urdf::Mesh&>(g);
      v.shape = LinkVisual::Shape::Mesh;
      v.mesh_file = m.filename;
      v.mesh_scale = Eigen::Vector3d(m.scale.x, m.scale.y, m.scale.z);
      return true;
    }
  }
  return false;
}

}  // namespace

std::map<std::string, std::vector<LinkVisual>> readUrdfVisualsString(const std::string& xml, const std::string& source,
                                                                      const std::vector<std::string>& package_path) {
  const std::string urdf_dir = std::filesystem::path(source).parent_path().string();
  const detail::UrdfText utf8 = detail::urdfText(xml);
  if (!utf8.problem.empty()) throw ModelError(source + ": " + utf8.problem);
  const urdf::ModelInterfaceSharedPtr model = parseUrdfXml(utf8.text, source);
  std::map<std::string, std::vector<LinkVisual>> out;
  for (const auto& [name, link] : model->links_) {
    if (!link) continue;
    for (const urdf::VisualSharedPtr& visual : link->visual_array) {
      if (!visual || !visual->geometry) continue;
      LinkVisual v;
      if (!shapeOf(*visual->geometry, v)) continue;
      if (v.shape == LinkVisual::Shape::Mesh) {
        MeshLocation found = resolveMeshFile(v.mesh_file, urdf_dir.empty() ? "." : urdf_dir, package_path);
        v.mesh_path = std::move(found.path);
        v.mesh_problem = std::move(found.problem);
      }
      v.origin = frameOf(visual->origin);
      urdf::MaterialSharedPtr material = visual->material;
      // urdfdom leaves a named robot-level material's colour on the visual's material already;
      // a reference by name alone is looked up here.
      if (!material && !visual->material_name.empty()) material = model->getMaterial(visual->material_name);
      if (material && (material->color.r || material->color.g || material->color.b || material->color.a))
        v.rgba = Eigen::Vector4d(material->color.r, material->color.g, material->color.b, material->color.a);
      out[name].push_back(std::move(v));
    }
  }
  return out;
}

std::map<std::string, std::vector<LinkVisual>> readUrdfVisuals(const std::string& path,
                                                                const std::vector<std::string>& package_path) {
  return readUrdfVisualsString(readUrdfText(path), path, package_path);
}

}  // namespace kdl_space
