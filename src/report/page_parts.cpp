#include "report/page_parts.hpp"

#include <cmath>

#include "kdl_space/report/scene_writer.hpp"

namespace kdl_space::report::page {

/// Base64 of raw bytes (the page decodes it with atob into typed arrays).
std::string base64(const void* bytes, std::size_t n) {
  static const char* const abc = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = static_cast<const unsigned char*>(bytes);
  std::string out;
  out.reserve((n + 2) / 3 * 4);
  for (std::size_t i = 0; i < n; i += 3) {
    const unsigned v = (p[i] << 16) | ((i + 1 < n ? p[i + 1] : 0) << 8) | (i + 2 < n ? p[i + 2] : 0);
    out += abc[(v >> 18) & 63];
    out += abc[(v >> 12) & 63];
    out += i + 1 < n ? abc[(v >> 6) & 63] : '=';
    out += i + 2 < n ? abc[v & 63] : '=';
  }
  return out;
}

/// Position and quaternion (x y z w) of a frame, appended as floats.
void pushPose(std::vector<float>& out, const KDL::Frame& f) {
  double x, y, z, w;
  f.M.GetQuaternion(x, y, z, w);
  for (double v : {f.p.x(), f.p.y(), f.p.z(), x, y, z, w}) out.push_back(static_cast<float>(v));
}

void pushHidden(std::vector<float>& out) {
  for (int k = 0; k < 7; ++k) out.push_back(std::nanf(""));
}

Json poseJson(const KDL::Frame& f) {
  double x, y, z, w;
  f.M.GetQuaternion(x, y, z, w);
  return Json::array({f.p.x(), f.p.y(), f.p.z(), x, y, z, w});
}

/// A body's box of inertia in its own frame (what a link without a drawable visual shows).
Json inertiaBoxJson(const Body& b) {
  const SceneBox box = equivalentBox(b.mass, b.I_com, b.com);
  const Vector3d size = box.size.cwiseMax(1e-3);  // a point mass still shows
  return {{"shape", "box"}, {"size", {size.x(), size.y(), size.z()}}, {"origin", poseJson(box.pose)},
          {"rgba", {0.75, 0.75, 0.78, 0.5}}, {"inertia_box", true}};
}

Json visualJson(const LinkVisual& v) {
  static const char* const shapes[] = {"box", "cylinder", "sphere", "mesh"};
  Json j = {{"shape", shapes[static_cast<int>(v.shape)]},
            {"size", {v.size.x(), v.size.y(), v.size.z()}},
            {"origin", poseJson(v.origin)}};
  if (v.rgba) j["rgba"] = {(*v.rgba)(0), (*v.rgba)(1), (*v.rgba)(2), (*v.rgba)(3)};
  return j;
}

/// A mesh visual drawn from the page's mesh `index` (D.meshes), scaled by the URDF's scale.
Json meshVisualJson(const LinkVisual& v, int index) {
  Json j = visualJson(v);
  j["mesh"] = index;
  j["scale"] = {v.mesh_scale.x(), v.mesh_scale.y(), v.mesh_scale.z()};
  j["file"] = v.mesh_file;
  return j;
}

}  // namespace kdl_space::report::page
