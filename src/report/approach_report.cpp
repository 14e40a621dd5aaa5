#include "kdl_space/report/approach_report.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

namespace kdl_space::report {

Json approachJson(const Scenario& sc, const ApproachOutcome& o) {
  const ApproachRecord& r = o.record;
  const ApproachSpec& spec = *sc.approach;
  const std::vector<std::string>& joints = sc.capture.robot.model->jointNames();
  Json kv = Json::object();
  for (std::size_t j = 0; j < joints.size(); ++j) kv[joints[j]] = r.kv[j];
  Json timeAtLimit = Json::object();
  for (std::size_t j = 0; j < joints.size() && j < r.time_at_limit.size(); ++j) timeAtLimit[joints[j]] = r.time_at_limit[j];
  Json preGrasp = nullptr;
  if (spec.pre_grasp) {
    Json q = Json::object();
    for (std::size_t j = 0; j < joints.size() && j < r.pre_grasp_q.size(); ++j) q[joints[j]] = r.pre_grasp_q[j];
    preGrasp = Json{{"standoff", spec.pre_grasp->standoff},
                    {"duration", r.pre_grasp_duration},
                    {"q_by_name", q},
                    {"miss", r.pre_grasp_q.empty() ? Json(nullptr) : Json(r.pre_grasp_miss)}};
  }
  return Json{{"reached", r.reached},
              {"t_contact", r.reached ? Json(r.t_contact) : Json(nullptr)},
              {"duration", r.duration},
              {"final_position_error", r.final_distance},
              {"final_orientation_error", r.final_angle},
              {"closest_distance", r.closest_distance},
              {"closest_time", r.closest_time},
              {"min_singular_value", r.min_sigma},
              {"max_damping", r.max_damping},
              {"min_rate_scale", r.min_scale},
              {"base_attitude_change", r.base_rotation},
              {"track", spec.orientation ? "pose" : "position"},
              {"null_space", spec.null_space == NullSpaceTask::Reaction ? "reaction" : "none"},
              {"gain", spec.gain},
              {"servo_gains", kv},
              {"target_at_contact", Json{{"position", toJson(toEigen(o.target_at_contact.pose.p))},
                                         {"twist", toJson(o.target_at_contact.twist)}}},
              // Added with the approach from stowed (issue 38): the Jacobian, the limits, the
              // pre-grasp move, and why it failed.
              {"jacobian", toString(r.base)},
              {"time_at_limit_by_name", timeAtLimit},
              {"time_rate_limited", r.time_rate_limited},
              {"time_near_singular", r.time_near_singular},
              {"pre_grasp", preGrasp},
              {"cause", r.reached ? Json(nullptr) : Json(r.cause)}};
}

void printApproach(std::ostream& out, const Scenario& sc, const ApproachOutcome& o) {
  const ApproachRecord& r = o.record;
  const ApproachSpec& spec = *sc.approach;
  out << std::setprecision(6) << "Approach (resolved motion rate control with the " << toString(r.base) << " Jacobian, "
      << (spec.orientation ? "pose" : "position")
      << (spec.null_space == NullSpaceTask::Reaction ? ", reaction null space" : "") << "): reached the grasp point at t = "
      << r.t_contact << " s, within " << r.final_distance << " m and " << r.final_angle << " rad\n";
  if (spec.pre_grasp)
    out << "  first a joint-space move of " << r.pre_grasp_duration << " s to the pre-grasp pose "
        << spec.pre_grasp->standoff << " m back from the grasp (the hand ended " << r.pre_grasp_miss
        << " m from it: the base moved under it)\n";
  out << "  smallest singular value " << r.min_sigma << " (damping up to " << r.max_damping
      << "); rate limits scaled the command down to " << r.min_scale << "; the base turned "
      << r.base_rotation * 180 / M_PI << " deg\n";
  for (std::size_t j = 0; j < r.time_at_limit.size(); ++j)
    if (r.time_at_limit[j] > 0.0)
      out << "  joint " << sc.capture.robot.model->jointNames()[j] << " held at its limit guard for " << r.time_at_limit[j]
          << " s (kept inside its limits)\n";
  out << "\n";
}

}  // namespace kdl_space::report
