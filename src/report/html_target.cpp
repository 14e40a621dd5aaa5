// The target of the --html page: a rigid target's tumble and visuals, a free-floating target's links,
// the grasp frame.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "kdl_space/report/html_writer.hpp"
#include "report/page_parts.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/report/scene_writer.hpp"

namespace kdl_space::report {

using namespace page;

/// The operation's result does not carry a separated free-floating target's own motion after a
/// point impact: the page draws it as one rigid body (its joints frozen where the impact found
/// them, rigidSubtree) moving torque-free from its base twist after the impact (FreeRigidMotion:
/// its momentum kept). Returns world_new_T_world_at_contact at time t, or none (not drawn).
std::optional<KDL::Frame> HtmlWriter::driftingTargetBase(const OperationResult& so_far, double t) {
  const auto* other = std::get_if<FloatingSystem>(&so_far.at_contact.target);
  const bool bounced = so_far.compliant && !so_far.joined;  // a compliant contact that opened
  const double t0 = so_far.t_capture + (bounced ? so_far.compliant->duration : 0.0);
  if (!other || so_far.joined || t < t0) return std::nullopt;
  if (!bounced && (!so_far.capture || !so_far.capture->floating_target)) return std::nullopt;
  if (!drift_) {
    try {
      FloatingSystem from = bounced ? so_far.compliant->target_end : *other;
      if (!bounced) from.velocity = so_far.capture->floating_target->after;
      RigidTarget whole = rigidSubtree(*from.model, from.state, 0, from.velocity.base_twist);
      // The frozen body keeps the target's momentum (P; L): its CoM at P / m, turning at
      // I^-1 (L - c x P) (the base's own twist would ignore what the joint rates carry).
      Kinematics kin(*from.model);
      MomentumSolver momentum(from.model);
      if (forwardKinematics(*from.model, from.state, kin) || momentum.compute(kin, from.velocity)) return std::nullopt;
      const Vector6d h = momentum.momentum();
      const RigidBody body = whole.toWorld();
      whole.twist << h.head<3>() / body.mass, body.I_com.ldlt().solve(h.tail<3>() - body.com.cross(h.head<3>()));
      drift_.emplace(whole);
      drift_start_ = whole.pose;
    } catch (const Error&) {
      return std::nullopt;  // no mass to move: not drawn
    }
  }
  RigidTarget now;
  if (drift_->at(t - t0, now) != E_NOERROR) return std::nullopt;
  return now.pose * drift_start_.Inverse();
}

void HtmlWriter::writeTargetAndGrasp(Json& data, const OperationResult& r) const {
  data["targetLinks"] = nullptr;
  if (target_model_) {
    Json links = Json::array();
    for (const Body& b : target_model_->bodies()) {
      Json visuals = Json::array();
      if (const auto it = target_visuals_.find(b.name); it != target_visuals_.end())
        for (const LinkVisual& v : it->second)
          visuals.push_back(v.shape != LinkVisual::Shape::Mesh ? visualJson(v)
                            : v.mesh_path.empty() ? inertiaBoxJson(b)  // warned about
                                                  : meshVisualJson(v, meshIndex(v.mesh_path)));
      if (visuals.empty()) visuals.push_back(inertiaBoxJson(b));
      for (Json& v : visuals)
        if (!v.contains("rgba") || v.value("inertia_box", false)) v["rgba"] = {1.0, 0.5, 0.05, 0.55};  // the target's orange
      links.push_back({{"name", b.name}, {"visuals", visuals}});
    }
    data["targetLinks"] = links;
  }
  if (target_ && data["target"].is_object()) data["target"]["visuals"] = rigidTargetVisualsJson();
  data["targetDrift"] = drift_.has_value();  // drawn after a point impact as a rigid body (driftingTargetBase)
  // The grasp frame rides on the target's frame (a rigid target's, a free-floating one's base).
  data["grasp"] = nullptr;
  if (sc_.grasp_frame && (target_ || target_model_)) data["grasp"] = {{"pose", poseJson(*sc_.grasp_frame)}};
  // A failed approach: how close the hand came to the grasp point, and when.
  data["closest"] = nullptr;
  if (r.approach && !r.approach->record.reached && std::isfinite(r.approach->record.closest_distance))
    data["closest"] = {{"distance", r.approach->record.closest_distance}, {"time", r.approach->record.closest_time}};
  if (r.approach && !r.approach->record.reached) data["tCapture"] = nullptr;  // no contact: no impact to step to
}

bool HtmlWriter::drawsTargetVisuals(const Scenario& sc) {
  if (!sc.impact || sc.target_urdf.empty()) return false;
  return sc.rigid_target_system || std::holds_alternative<FloatingSystem>(sc.capture.target);
}

void HtmlWriter::useTargetVisuals(std::map<std::string, std::vector<LinkVisual>> visuals) {
  if (!drawsTargetVisuals(sc_)) return;
  target_visuals_ = std::move(visuals);
  for (auto& [link, list] : target_visuals_)
    for (LinkVisual& v : list) readMesh("target " + link, v);
}

Json HtmlWriter::rigidTargetVisualsJson() const {
  Json out = Json::array();
  if (!sc_.rigid_target_system || target_visuals_.empty()) return out;
  const FloatingSystem& t = *sc_.rigid_target_system;
  const std::vector<Body>& bodies = t.model->bodies();
  Kinematics kin(*t.model);
  if (forwardKinematics(*t.model, t.state, kin) != E_NOERROR) return out;  // the scenario computed it: not here
  // The subtree from the target's body (bodies come parents first), each link in the target's
  // frame at the scenario's state: the visuals then ride on the target's pose per frame.
  const int root = sc_.rigid_target_body;
  std::vector<char> in(bodies.size(), 0);
  in[root] = 1;
  for (std::size_t j = root + 1; j < bodies.size(); ++j) in[j] = bodies[j].parent >= 0 && in[bodies[j].parent];
  bool any = false;
  for (std::size_t j = 0; j < bodies.size(); ++j) {
    if (!in[j]) continue;
    const KDL::Frame target_T_link = kin.pose(root).Inverse() * kin.pose(static_cast<int>(j));
    const auto it = target_visuals_.find(bodies[j].name);
    const std::vector<LinkVisual> none;
    const std::vector<LinkVisual>& list = it != target_visuals_.end() ? it->second : none;
    any = any || !list.empty();
    std::vector<Json> visuals;
    for (const LinkVisual& v : list) {
      Json vj = v.shape != LinkVisual::Shape::Mesh ? visualJson(v)
               : v.mesh_path.empty()               ? inertiaBoxJson(bodies[j])  // warned about
                                                   : meshVisualJson(v, meshIndex(v.mesh_path));
      const bool box = vj.value("inertia_box", false);
      vj["origin"] = poseJson(target_T_link * (box ? equivalentBox(bodies[j].mass, bodies[j].I_com, bodies[j].com).pose : v.origin));
      visuals.push_back(vj);
    }
    if (list.empty() && bodies[j].mass > 0.0) {  // a link with mass but no visual: its box of inertia
      Json vj = inertiaBoxJson(bodies[j]);
      vj["origin"] = poseJson(target_T_link * equivalentBox(bodies[j].mass, bodies[j].I_com, bodies[j].com).pose);
      visuals.push_back(vj);
    }
    for (Json& v : visuals) {
      if (!v.contains("rgba") || v.value("inertia_box", false)) v["rgba"] = {1.0, 0.5, 0.05, 0.55};  // the target's orange
      v["link"] = bodies[j].name;
      out.push_back(v);
    }
  }
  return any ? out : Json::array();
}

}  // namespace kdl_space::report
