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
                                         {"twist", toJson(o.target_at_contact.twist)}}}};
}

void printApproach(std::ostream& out, const Scenario& sc, const ApproachOutcome& o) {
  const ApproachRecord& r = o.record;
  const ApproachSpec& spec = *sc.approach;
  out << std::setprecision(6) << "Approach (resolved motion rate control with J*, " << (spec.orientation ? "pose" : "position")
      << (spec.null_space == NullSpaceTask::Reaction ? ", reaction null space" : "") << "): reached the grasp point at t = "
      << r.t_contact << " s, within " << r.final_distance << " m and " << r.final_angle << " rad\n"
      << "  smallest singular value of J* " << r.min_sigma << " (damping up to " << r.max_damping
      << "); rate limits scaled the command down to " << r.min_scale << "; the base turned "
      << r.base_rotation * 180 / M_PI << " deg\n\n";
}

}  // namespace kdl_space::report
