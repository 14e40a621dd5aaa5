// The pieces of the --html page's JSON and frames that its writer's files share (html_writer,
// html_meshes, html_plots, html_target): private to the report layer.
#pragma once

#include <kdl/frames.hpp>
#include <string>
#include <vector>

#include "kdl_space/multibody/model.hpp"
#include "kdl_space/parsers/urdf/urdf_visuals.hpp"
#include "kdl_space/report/json.hpp"

namespace kdl_space::report::page {

/// Base64 of raw bytes (the page decodes it with atob into typed arrays).
std::string base64(const void* bytes, std::size_t n);
/// Position and quaternion (x y z w) of a frame, appended as floats.
void pushPose(std::vector<float>& out, const KDL::Frame& f);
/// Seven NaNs: a link or a target not drawn in this frame.
void pushHidden(std::vector<float>& out);
/// A frame as [x, y, z, qx, qy, qz, qw] (the page's poses).
Json poseJson(const KDL::Frame& f);
/// A body's box of inertia in its own frame (what a link without a drawable visual shows).
Json inertiaBoxJson(const Body& b);
/// A URDF visual (box, cylinder, sphere, mesh) with its origin and colour.
Json visualJson(const LinkVisual& v);
/// A mesh visual drawn from the page's mesh `index` (D.meshes), scaled by the URDF's scale.
Json meshVisualJson(const LinkVisual& v, int index);

}  // namespace kdl_space::report::page
