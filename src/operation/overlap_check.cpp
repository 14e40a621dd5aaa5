#include "kdl_space/operation/overlap_check.hpp"

#include <algorithm>
#include <sstream>

#include "spatial/message_text.hpp"

namespace kdl_space {
namespace {

/// A visual's bounding box in its link's frame; false for a mesh (its extent is in its file).
bool boundingBox(const LinkVisual& v, OrientedBox& box) {
  box.pose = v.origin;
  switch (v.shape) {
    case LinkVisual::Shape::Box: box.size = v.size; return true;
    case LinkVisual::Shape::Cylinder: box.size = Vector3d(2.0 * v.size(0), 2.0 * v.size(0), v.size(1)); return true;
    case LinkVisual::Shape::Sphere: box.size = Vector3d::Constant(2.0 * v.size(0)); return true;
    case LinkVisual::Shape::Mesh: return false;
  }
  return false;
}

/// The target's boxes in world terms at the problem's state, and what each is called.
void targetBoxes(const CaptureProblem& p, std::vector<OrientedBox>& boxes, std::vector<std::string>& names) {
  if (const auto* rigid = std::get_if<RigidTarget>(&p.target)) {
    if (!(rigid->mass > 0.0)) return;
    boxes.push_back(inWorld(rigid->pose, inertiaBox(rigid->mass, rigid->inertia, rigid->com)));
    names.push_back("target");
    return;
  }
  const FloatingSystem& t = std::get<FloatingSystem>(p.target);
  Kinematics kin(*t.model);
  if (forwardKinematics(*t.model, t.state, kin) != E_NOERROR) return;
  const std::vector<std::vector<OrientedBox>> own = inertiaBoxes(*t.model);
  for (std::size_t i = 0; i < own.size(); ++i)
    for (const OrientedBox& b : own[i]) {
      boxes.push_back(inWorld(kin.pose(static_cast<int>(i)), b));
      names.push_back("target link '" + t.model->bodies()[i].name + "'");
    }
}

}  // namespace

LinkGeometry linkGeometry(const FloatingModel& model, const std::map<std::string, std::vector<LinkVisual>>& visuals) {
  LinkGeometry g;
  g.boxes = inertiaBoxes(model);
  g.from_visuals.assign(g.boxes.size(), false);
  for (std::size_t i = 0; i < g.boxes.size(); ++i) {
    const auto it = visuals.find(model.bodies()[i].name);
    if (it == visuals.end() || it->second.empty()) continue;
    std::vector<OrientedBox> boxes;
    bool mesh = false;
    for (const LinkVisual& v : it->second) {
      OrientedBox box;
      if (boundingBox(v, box)) boxes.push_back(box);
      else mesh = true;
    }
    if (mesh) continue;  // the box of inertia stands for the whole link (a mesh's extent is unknown)
    g.boxes[i] = std::move(boxes);
    g.from_visuals[i] = true;
  }
  return g;
}

std::vector<Diagnostic> overlapWarnings(const CaptureProblem& problem, const LinkGeometry& robot,
                                        const std::string& moment, double allowance) {
  const FloatingSystem& r = problem.robot;
  std::vector<OrientedBox> obstacles;
  std::vector<std::string> names;
  targetBoxes(problem, obstacles, names);
  Kinematics kin(*r.model);
  if (obstacles.empty() || forwardKinematics(*r.model, r.state, kin) != E_NOERROR) return {};
  const std::vector<bool> hand = contactBodies(*r.model, r.contact.body);
  // The link that carries the hand (the wrist) reaches as deep as the grasp point: where that
  // point lies inside the target's box, the target is smaller there than its box; the wrist's
  // allowance grows by that depth. Every other link keeps `allowance`.
  int wrist = -1;
  for (std::size_t i = 0; i < hand.size(); ++i)
    if (hand[i] && r.model->bodies()[i].parent >= 0 && !hand[r.model->bodies()[i].parent]) wrist = r.model->bodies()[i].parent;
  double grasp_depth = 0.0;
  const OrientedBox grasp{KDL::Frame(toKDL(kin.point(r.contact))), Vector3d::Zero()};
  for (const OrientedBox& b : obstacles) grasp_depth = std::max(grasp_depth, penetrationDepth(grasp, b));
  std::vector<bool> skip = hand, only_wrist(hand.size(), true);
  if (wrist >= 0) skip[wrist] = true, only_wrist[wrist] = false;
  std::vector<BoxPenetration> found = penetrations(kin, robot.boxes, obstacles, skip, allowance);
  if (wrist >= 0)
    for (const BoxPenetration& p : penetrations(kin, robot.boxes, obstacles, only_wrist, allowance + grasp_depth))
      found.push_back(p);
  std::stable_sort(found.begin(), found.end(), [](const BoxPenetration& x, const BoxPenetration& y) { return x.depth > y.depth; });
  std::vector<Diagnostic> out;
  for (const BoxPenetration& p : found) {
    const double allowed = p.body == wrist ? allowance + grasp_depth : allowance;
    const std::string& link = r.model->bodies()[p.body].name;
    const bool visuals = p.body < static_cast<int>(robot.from_visuals.size()) && robot.from_visuals[p.body];
    std::ostringstream s;
    if (moment == "capture") s << "at the capture: ";
    s << "link '" << link << "' (" << (visuals ? "its visuals' bounding boxes" : "its box of inertia")
      << ") penetrates the " << names[p.obstacle] << "'s box of inertia by " << detail::number(p.depth)
      << " m (more than " << detail::number(allowed) << " m"
      << (p.body == wrist && grasp_depth > 0.0 ? ": the hand's link may reach as deep as the grasp point, " +
                                                     detail::number(grasp_depth) + " m inside the box, plus " + detail::number(allowance) + " m"
                                               : std::string())
      << "): check the target's pose and the grasp (the robot's placing, the target's pose and com)"
      << (visuals ? "" : "; a box of inertia only bounds a link's geometry: give the link a <visual> box, cylinder "
                         "or sphere in its URDF for a closer one");
    Diagnostic d{link, s.str(), "overlap", Severity::Warning};
    d.details = {{"link", link},
                 {"target", names[p.obstacle]},
                 {"depth", p.depth},
                 {"moment", moment},
                 {"geometry", std::string(visuals ? "visuals" : "inertia_box")}};
    out.push_back(std::move(d));
  }
  return out;
}

std::vector<Diagnostic> overlapWarnings(const CaptureProblem& problem, const std::string& robot_urdf,
                                        const std::string& moment, double allowance) {
  const LinkGeometry g =
      linkGeometry(*problem.robot.model, robot_urdf.empty() ? std::map<std::string, std::vector<LinkVisual>>{}
                                                            : readUrdfVisuals(robot_urdf));
  return overlapWarnings(problem, g, moment, allowance);
}

std::vector<Diagnostic> busOverlapWarnings(const FloatingModel& model, const State& state, const LinkGeometry& robot,
                                           const std::string& moment, double allowance) {
  Kinematics kin(model);
  if (robot.boxes.empty() || forwardKinematics(model, state, kin) != E_NOERROR) return {};
  std::vector<OrientedBox> bus;
  for (const OrientedBox& b : robot.boxes[0]) bus.push_back(inWorld(kin.pose(0), b));
  // The joints between each body and the base: the first two links of an arm are not checked.
  std::vector<bool> skip(model.bodies().size(), true);
  std::vector<int> joints(model.bodies().size(), 0);
  for (std::size_t i = 1; i < model.bodies().size(); ++i) {
    const Body& b = model.bodies()[i];
    joints[i] = joints[static_cast<std::size_t>(b.parent)] + (b.joint >= 0 ? 1 : 0);
    skip[i] = joints[i] <= 2;
  }
  std::vector<Diagnostic> out;
  for (const BoxPenetration& p : penetrations(kin, robot.boxes, bus, skip, allowance)) {
    const std::string& link = model.bodies()[static_cast<std::size_t>(p.body)].name;
    Diagnostic d{link,
                 "link '" + link + "' penetrates its own bus's box by " + detail::number(p.depth) + " m (more than " +
                     detail::number(allowance) + " m)",
                 "overlap", Severity::Warning};
    d.details = {{"link", link}, {"target", std::string("bus")}, {"depth", p.depth}, {"moment", moment}};
    out.push_back(std::move(d));
  }
  return out;
}

std::vector<Diagnostic> overlapWarnings(const Scenario& scenario, const CaptureProblem& at, const std::string& moment) {
  if (!scenario.impact) return {};
  return overlapWarnings(at, linkGeometry(*at.robot.model, robotVisuals(scenario)), moment);
}

}  // namespace kdl_space
