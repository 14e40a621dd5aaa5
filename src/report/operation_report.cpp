#include "kdl_space/report/operation_report.hpp"

#include <cmath>
#include <sstream>

#include "kdl_space/report/approach_report.hpp"
#include "kdl_space/report/capture_report.hpp"
#include "spatial/message_text.hpp"
#include "kdl_space/report/inspection_json.hpp"
#include "kdl_space/report/motion_report.hpp"

namespace kdl_space::report {

/// The scene at the start, at the contact (the impact, at t_contact) and at the end of the run.
std::vector<SceneSnapshot> sceneSnapshots(const Scenario& sc, const OperationResult& r) {
  const CaptureProblem& at_contact = r.at_contact;
  const std::optional<CaptureResult>& capture = r.capture;
  const bool joined = r.joined.has_value();
  const std::shared_ptr<const FloatingModel>& model = r.model;
  const SimulationState& end = r.end;
  const double t_contact = r.t_capture;
  const SimulationState* target_end = r.target_motion ? &r.target_motion->end : nullptr;
  // The grasp point of an approach: fixed in the (rigid) target's frame.
  const auto grasp = [&](const CaptureTarget& target) -> std::optional<Vector3d> {
    const auto* rigid = std::get_if<RigidTarget>(&target);
    if (!sc.approach || !rigid) return std::nullopt;
    return toEigen(rigid->pose * sc.approach->grasp.p);
  };
  const auto at = [&](const CaptureProblem& problem, const char* label, double t) {
    Scenario then = sc;
    then.capture = problem;
    SceneSnapshot snap = impactSnapshot(then);
    if (!sc.impact) snap.target_body.reset();  // a plain motion: no target
    if (const std::optional<Vector3d> g = grasp(problem.target)) snap.grasp_point = g;
    snap.label = label;
    snap.t = t;
    return snap;
  };
  std::vector<SceneSnapshot> out;
  if (sc.approach || !sc.impact) out.push_back(at(sc.capture, "start", 0.0));
  if (sc.impact) out.push_back(at(at_contact, sc.approach ? "contact" : "impact", t_contact));
  SceneSnapshot last;
  last.label = "end";
  last.t = end.t;
  last.robot = model;  // the joined system, the robot with its payload, or the robot alone
  last.robot_state = end.state;
  last.robot_contact = joined ? Contact{-1, KDL::Vector::Zero()} : at_contact.robot.contact;
  if (capture && model == at_contact.robot.model) {  // the target separated: a rigid one tumbles on
    if (const auto* rigid = std::get_if<RigidTarget>(&at_contact.target)) {
      RigidTarget after = *rigid;
      after.twist = capture->target_twist_after;
      RigidTarget later;
      if (FreeRigidMotion(after).at(end.t - t_contact, later) == E_NOERROR) {
        last.target_body = later.toWorld();
        last.target_frame = later.pose;
      }
    }
  }
  if (const auto* floating = std::get_if<FloatingSystem>(&at_contact.target); floating && target_end) {
    last.target_robot = floating->model;  // separated after a point impact: where it went
    last.target_state = target_end->state;
  }
  out.push_back(last);
  return out;
}

/// The target's joints in the joined model, by their name there, and the sign of their coordinate
/// (-1: reversed by the re-rooting).
Json targetSigns(const JoinedSystem& joint, const std::shared_ptr<const FloatingModel>& model) {
  Json signs = Json::object();
  for (std::size_t j = 0; j < joint.target_joints.size(); ++j)
    signs[model->jointNames()[joint.target_joints[j]]] = joint.target_joint_sign[j];
  return signs;
}

namespace {

Json targetMotionJson(const OperationResult& r) {
  if (!r.target_motion) return nullptr;  // else a free-floating target that separated: its own motion
  const SimulationState& e = r.target_motion->end;
  Eigen::Vector4d quat;
  e.state.world_T_base.M.GetQuaternion(quat(0), quat(1), quat(2), quat(3));
  return Json{{"final", Json{{"t", e.t},
                             {"base_position", toJson(toEigen(e.state.world_T_base.p))},
                             {"base_quaternion", toJson(quat)},
                             {"base_twist", toJson(toEigen(e.velocity.base_twist))},
                             {"q", toJson(e.state.q.data)},
                             {"qdot", toJson(e.velocity.qdot.data)}}},
              {"joint_names", std::get<FloatingSystem>(r.at_contact.target).model->jointNames()},
              {"energy", r.target_motion->T},
              {"max_linear_momentum_change", r.target_motion->dP},
              {"max_angular_momentum_change", r.target_motion->dL}};
}

/// Where the scenario's base control acts (`base_control.phases`) and where it did in this run:
/// null without one.
Json baseControlPhasesJson(const Scenario& sc, const OperationResult& r) {
  const BaseControl& c = sc.simulation.base_control;
  if (!c.on()) return nullptr;
  Json phases = Json::array();
  if (c.in_approach) phases.push_back("approach");
  if (c.after_capture) phases.push_back("after");
  return Json{{"phases", phases}, {"acted_in", r.base_control_phases}};
}

// --- The states at the contact instant of an approach (issue 28) -------------------------------

/// A system's state (what a `kdl_space capture` scenario takes back: base.position, base.rpy,
/// base.twist, q and qdot by joint name).
Json systemStateJson(const FloatingSystem& s) {
  const std::vector<std::string>& names = s.model->jointNames();
  Json q = Json::object(), qdot = Json::object();
  for (std::size_t j = 0; j < names.size(); ++j) {
    q[names[j]] = s.state.q(static_cast<unsigned int>(j));
    qdot[names[j]] = s.velocity.qdot(static_cast<unsigned int>(j));
  }
  Eigen::Vector4d quat;
  s.state.world_T_base.M.GetQuaternion(quat(0), quat(1), quat(2), quat(3));
  double roll, pitch, yaw;
  s.state.world_T_base.M.GetRPY(roll, pitch, yaw);
  return Json{{"base_position", toJson(toEigen(s.state.world_T_base.p))},
              {"base_rpy", Json::array({roll, pitch, yaw})},
              {"base_quaternion", toJson(quat)},
              {"base_twist", toJson(toEigen(s.velocity.base_twist))},
              {"q", q},
              {"qdot", qdot}};
}

/// The robot's and a robot target's states at the contact instant (null target: a rigid one,
/// whose state is approach.target_at_contact).
Json statesAtContactJson(const OperationResult& r) {
  const auto* target = std::get_if<FloatingSystem>(&r.at_contact.target);
  return Json{{"t", r.t_capture},
              {"robot", systemStateJson(r.at_contact.robot)},
              {"target", target ? systemStateJson(*target) : Json(nullptr)}};
}

// -------------------------------------------------------------------------------------------------

}  // namespace

Json operationJson(const Scenario& sc, const OperationResult& r, const OperationFiles& files) {
  const MotionRecord& record = r.record;
  const MotionSample& last = record.last;
  const bool grounded = record.options.grounded;
  Json j;
  j["capture"] = r.capture ? captureJson(sc, *r.capture) : Json(nullptr);
  if (r.capture) {  // the target where it was at the contact instant (an approach moved it)
    const std::optional<Vector3d> in_target = pointInTargetFrame(r.at_contact, r.capture->contact_point);
    j["capture"]["contact_point_in_target"] = in_target ? toJson(*in_target) : Json(nullptr);
  }
  j["approach"] = r.approach ? approachJson(sc, *r.approach) : Json(nullptr);
  if (r.approach) {
    j["approach"]["states_at_contact"] = statesAtContactJson(r);
    if (const auto* target = std::get_if<FloatingSystem>(&r.at_contact.target))  // not a rigid body's
      j["approach"]["target_at_contact"] = Json{{"position", toJson(toEigen(target->state.world_T_base.p))},
                                                {"twist", toJson(toEigen(target->velocity.base_twist))},
                                                {"of", "base"}};
  }
  j["target_motion"] = targetMotionJson(r);
  if (r.compliant) {  // the contact that lasted, beside its impulsive limit (`capture`)
    j["compliant"] = compliantJson(*r.compliant);
    j["compliant"]["t_start"] = r.t_capture;
    j["compliant"]["t_end"] = r.t_capture + r.compliant->duration;
  } else {
    j["compliant"] = nullptr;
  }
  // The robot's configuration at the capture (the contact instant of an approach).
  // The pose an approach started from first, then the configuration at the capture, then what the
  // motion found (a sampled controller's gains, a stiff servo).
  std::vector<Diagnostic> warnings = r.approach ? r.approach->start_warnings : std::vector<Diagnostic>{};
  if (r.approach) warnings.insert(warnings.end(), r.approach->overlaps.begin(), r.approach->overlaps.end());
  if (r.capture)
    for (Diagnostic& d : captureWarnings(sc, r.at_contact)) warnings.push_back(std::move(d));
  warnings.insert(warnings.end(), r.warnings.begin(), r.warnings.end());
  j["warnings"] = warningsJson(warnings);
  j["base_control"] = baseControlPhasesJson(sc, r);
  if (record.samples == 0) {  // stopped at the capture (OperationOptions::motion false)
    j["simulation"] = nullptr;
    return j;
  }
  const Json final_state{{"t", last.t},
                         {"base_position", toJson(last.p)},
                         {"base_quaternion", toJson(last.quat)},
                         {"base_twist", toJson(last.twist)},
                         {"q", toJson(last.q)},
                         {"qdot", toJson(last.qd)}};
  const Json joined = r.joined ? Json{{"grasp", r.joined->grasp == GraspJoint::Rigid       ? "rigid"
                                                : r.joined->grasp == GraspJoint::Spherical ? "spherical"
                                                                                           : "compliant"},
                                      {"target_prefix", r.joined->target_prefix},
                                      {"target_joint_signs", targetSigns(*r.joined, r.model)},
                                      {"min_chart_margin", r.min_chart_margin}}
                               : Json(nullptr);
  j["simulation"] = Json{{"duration", r.duration},
                         {"integrator", toString(record.options.integrator)},
                         {"accepted_steps", record.stats.accepted_steps},
                         {"rejected_steps", record.stats.rejected_steps},
                         {"payload_attached", r.payload_attached},
                         {"target_joined", joined},
                         {"joint_names", r.model->jointNames()},
                         {"joints_treated_as_fixed", fixedJointsJson(*r.model)},
                         {"final", final_state},
                         {"max_linear_momentum_change", record.max_linear_momentum_change},
                         {"max_angular_momentum_change", record.max_angular_momentum_change},
                         {"max_energy_change", record.max_energy_change},
                         {"energy", record.first.T},
                         {"csv", files.csv.empty() ? Json(nullptr) : Json(files.csv)},
                         {"plot", files.plot.empty() ? Json(nullptr) : Json(files.plot)},
                         {"html", files.html.empty() ? Json(nullptr) : Json(files.html)},
                         {"base", grounded ? "grounded" : "free"},
                         {"locked_joints", record.lockedJoints()},
                         {"momentum_balance_error", grounded ? Json(nullptr)
                                                             : Json{{"linear", record.balance_linear},
                                                                    {"angular", record.balance_angular}}},
                         {"limit_violations", limitViolationsJson(record)},
                         {"saturation", saturationJson(record)},
                         {"energy_split", energySplitJson(record)},
                         {"base_control", baseControlJson(record)},
                         {"stiffness", stiffnessJson(record)},
                         {"friction", frictionJson(record)},
                         {"wheels", wheelsJson(record)},
                         {"detumble", detumbleJson(record)},
                         {"grasp_load", graspLoadJson(record, sc.max_grasp_force, sc.max_grasp_moment)},
                         {"joint_torques", jointTorquesJson(record)}};
  return j;
}

}  // namespace kdl_space::report
