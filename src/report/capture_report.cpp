#include "kdl_space/report/capture_report.hpp"

#include <algorithm>

#include <optional>

#include "kdl_space/algorithm/conditioning.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/operation/overlap_check.hpp"
#include "kdl_space/simulation/compliant_capture.hpp"

namespace kdl_space::report {
namespace {

Json twist(const KDL::Twist& t) { return toJson(toEigen(t)); }

}  // namespace

std::vector<std::string> lockedNames(const FloatingSystem& s) {
  std::vector<std::string> names;
  for (std::size_t j = 0; j < s.locked.size(); ++j)
    if (s.locked[j]) names.push_back(s.model->jointNames()[j]);
  return names;
}

std::optional<Vector3d> pointInTargetFrame(const CaptureProblem& p, const Vector3d& point) {
  if (const auto* rigid = std::get_if<RigidTarget>(&p.target)) return toEigen(rigid->pose.Inverse() * toKDL(point));
  if (const auto* other = std::get_if<FloatingSystem>(&p.target))
    return toEigen(other->state.world_T_base.Inverse() * toKDL(point));
  return std::nullopt;
}

Json graspJson(const Scenario& sc) {
  if (!sc.grasp_solution) return nullptr;
  const IkResult& g = *sc.grasp_solution;
  const FloatingModel& m = *sc.capture.robot.model;
  Json q = Json::object();  // the angles the solve put the arm at, by joint name (the chain's joints)
  for (int j : g.chain_joints) q[m.jointNames()[j]] = g.q(j);
  return Json{{"residual_position", g.position_residual},
              {"residual_rotation", g.orientation_residual},
              {"iterations", g.iterations},
              {"attempts", g.attempts},
              {"q", q}};
}

Json captureJson(const Scenario& sc, const CaptureResult& r) {
  const CaptureProblem& p = sc.capture;
  Json jt;
  jt["twist_before"] = toJson(r.target_twist_before);
  jt["twist_after"] = toJson(r.target_twist_after);
  if (r.floating_target) {
    // Another free-floating system: its locked twist at its CoM above, and its whole state.
    const FloatingSideResult& other = *r.floating_target;
    jt["base_twist_before"] = twist(other.before.base_twist);
    jt["base_twist_after"] = twist(other.after.base_twist);
    jt["joint_names"] = std::get<FloatingSystem>(p.target).model->jointNames();
    jt["joints_treated_as_fixed"] = fixedJointsJson(*std::get<FloatingSystem>(p.target).model);
    jt["qdot_before"] = toJson(other.before.qdot.data);
    jt["qdot_after"] = toJson(other.after.qdot.data);
    jt["locked_joints"] = lockedNames(std::get<FloatingSystem>(p.target));
  }
  Json j;
  j["impulse"] = toJson(r.impulse.F);
  j["robot"] = Json{{"base_twist_before", twist(r.robot.before.base_twist)},
                    {"base_twist_after", twist(r.robot.after.base_twist)},
                    {"joint_names", p.robot.model->jointNames()},
                    {"joints_treated_as_fixed", fixedJointsJson(*p.robot.model)},
                    {"qdot_before", toJson(r.robot.before.qdot.data)},
                    {"qdot_after", toJson(r.robot.after.qdot.data)},
                    {"contact_twist_before", toJson(r.robot.contact_twist_before)},
                    {"contact_twist_after", toJson(r.robot.contact_twist_after)},
                    {"locked_joints", lockedNames(p.robot)}};
  j["target"] = jt;
  j["momentum_before"] = toJson(r.momentum_before);
  j["momentum_after"] = toJson(r.momentum_after);
  j["energy_before"] = r.energy_before;
  j["energy_after"] = r.energy_after;
  j["energy_lost"] = r.energyLost();
  // null without a normal, and where the robot cannot move its contact point along it (infinite)
  j["virtual_mass"] = r.virtual_mass ? Json(*r.virtual_mass) : Json(nullptr);
  // Where the hand holds the target, in the target's frame (a rigid target's `pose` frame, a
  // free-floating target's base frame), at the scenario's states.
  const std::optional<Vector3d> in_target = pointInTargetFrame(p, r.contact_point);
  j["contact_point"] = toJson(r.contact_point);
  j["contact_point_in_target"] = in_target ? toJson(*in_target) : Json(nullptr);
  j["grasp"] = graspJson(sc);  // robot.place: grasp: how well the solved arm holds the grasp frame
  j["G_star"] = toJson(r.G_robot);
  j["G_B"] = toJson(r.G_target);
  return j;
}

namespace {
/// A joint outside its limits at the capture: what put it there, where the scenario says (the
/// library's hint is robot.q's rule, which holds for a configuration the user gave).
void sayWhatPutTheJointThere(const Scenario& sc, const FloatingModel& model, std::vector<Diagnostic>& warnings) {
  const std::string given = " (a joint left out of q is at 0): give its position inside the limits";
  for (Diagnostic& d : warnings) {
    const auto at = d.message.find(given);
    if (d.kind != "joint_outside_limits" || at == std::string::npos) continue;
    const int j = model.jointIndex(d.element);
    const bool solved = sc.grasp_solution && std::find(sc.grasp_solution->chain_joints.begin(),
                                                        sc.grasp_solution->chain_joints.end(), j) != sc.grasp_solution->chain_joints.end();
    if (sc.approach)
      d.message.replace(at, given.size(), ": the approach's controller drove it there (it does not keep joints inside their limits)");
    else if (solved)
      d.message.replace(at, given.size(), ": robot.place: grasp's inverse kinematics put it there (no solution inside the limits was found)");
  }
}
}  // namespace

std::vector<Diagnostic> captureWarnings(const Scenario& sc, const CaptureProblem& p) {
  Conditioning c;
  std::vector<Diagnostic> warnings;
  // A state the solver refuses has failed the capture already; the limit warnings stand alone then.
  checkConfiguration(p.robot.model, p.robot.state, p.robot.contact, c, warnings);
  sayWhatPutTheJointThere(sc, *p.robot.model, warnings);
  for (Diagnostic& d : overlapWarnings(sc, p, "capture")) warnings.push_back(std::move(d));
  return warnings;
}

SceneSnapshot impactSnapshot(const Scenario& sc) {
  const CaptureProblem& p = sc.capture;
  SceneSnapshot s;
  s.label = "impact";
  s.robot = p.robot.model;
  s.robot_state = p.robot.state;
  s.robot_contact = p.robot.contact;
  if (const auto* rigid = std::get_if<RigidTarget>(&p.target)) {
    s.target_body = rigid->toWorld();
    s.target_frame = rigid->pose;
  } else if (const auto* other = std::get_if<FloatingSystem>(&p.target)) {
    s.target_robot = other->model;
    s.target_state = other->state;
    Kinematics kin(*other->model);
    if (forwardKinematics(*other->model, other->state, kin) == E_NOERROR && other->contact.body >= 0)
      s.grasp_point = kin.point(other->contact);
  }
  return s;
}

std::vector<InputFile> scenarioInputs(const Scenario& sc) {
  std::vector<InputFile> inputs{{"the scenario file", sc.file}};
  for (const std::string& f : sc.robot_files) inputs.push_back({"the robot's URDF", f});  // a mounted robot's bus and arms
  inputs.push_back({"the target's URDF", sc.target_urdf});
  return inputs;
}

/// The compliant contact beside the impulsive capture (`law: {type: compliant}`): what the
/// contact gave, in the terms of captureJson's keys, and its history as columns.

Json compliantJson(const CompliantCaptureResult& c) {
  const char* ends[4] = {"caught", "opened", "timed_out", "settled"};
  Json history;
  std::vector<double> t;
  std::vector<Json> wrench, deflection, impulse;
  for (const ContactSample& s : c.history) {
    t.push_back(s.t);
    wrench.push_back(toJson(s.wrench));
    deflection.push_back(toJson(s.deflection));
    impulse.push_back(toJson(s.impulse));
  }
  history["t"] = t;
  history["wrench"] = wrench;  // on the robot, (f; n about its contact point), world
  history["deflection"] = deflection;  // x, y, z, rz, ry, rx of the grasp
  history["impulse"] = impulse;  // on the robot so far (its momentum's change), as `impulse`
  const auto side = [](const FloatingSystem& end, const FloatingVelocity& after, const Vector6d& momentum) {
    return Json{{"base_twist_after", twist(after.base_twist)},
                {"qdot_after", toJson(after.qdot.data)},
                {"joint_names", end.model ? Json(end.model->jointNames()) : Json::array()},
                {"momentum_after", toJson(momentum)}};  // its own, (P; L about the world origin)
  };
  const char* rules[3] = {nullptr, "tolerance", "spring_maximum"};  // what caught it (null unless caught)
  const char* locks[3] = {"spring_maximum", "tolerance", "never"};   // law.lock
  return Json{{"end", ends[static_cast<int>(c.end)]},
              {"catch_rule", c.catch_rule == CatchRule::None ? Json(nullptr) : Json(rules[static_cast<int>(c.catch_rule)])},
              {"duration", c.duration},
              {"peak_force", c.peak_force},
              {"peak_moment", c.peak_moment},
              {"peak_force_wrench", toJson(c.peak_force_wrench)},
              {"impulse", toJson(c.impulse)},
              {"lock_impulse", toJson(c.lock_impulse)},
              {"lock", locks[static_cast<int>(c.lock)]},
              {"lock_share", Json{{"linear_impulse", c.lock_share.linear_impulse},
                                  {"angular_impulse", c.lock_share.angular_impulse},
                                  {"energy", c.lock_share.energy}}},
              {"robot", side(c.robot_end, c.robot_after, c.robot_momentum_after)},
              {"target", side(c.target_end, c.target_after, c.target_momentum_after)},
              {"momentum_before", toJson(c.momentum_before)},
              {"momentum_after", toJson(c.momentum_after)},
              {"energy_before", c.energy_before},
              {"energy_after", c.energy_after},
              {"energy_dissipated", c.dissipated},
              {"spring_energy", c.spring_energy},
              {"lock_loss", c.lock_loss},
              {"steps", c.steps},
              {"history", history}};
}

}  // namespace kdl_space::report
