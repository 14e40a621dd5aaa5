#include "operation_text.hpp"

#include <cmath>
#include <sstream>

#include "capture_text.hpp"
#include "spatial/message_text.hpp"
#include "kdl_space/report/approach_report.hpp"
#include "kdl_space/report/motion_report.hpp"

namespace kdl_space::cli {

void printOperation(std::ostream& out, const Scenario& sc, const OperationResult& r, const OperationFiles& files) {
  const MotionRecord& record = r.record;
  const std::vector<std::string>& joints = r.model->jointNames();
  if (r.approach) {
    printApproach(out, sc, *r.approach);
    printWarnings(out, r.approach->start_warnings);
    printWarnings(out, r.approach->overlaps);
  }
  if (r.capture) {
    printCaptureSummary(out, sc, *r.capture);
    printWarnings(out, captureWarnings(sc, r.at_contact));
  }
  if (r.compliant && r.capture) printCompliantSummary(out, *r.compliant, *r.capture);
  if (sc.simulation.base_control.on()) {
    const BaseControl& c = sc.simulation.base_control;
    out << "Base control acts " << (c.in_approach && c.after_capture ? "in the approach and after the capture"
                                    : c.in_approach                  ? "in the approach only"
                                                                     : "after the capture only")
        << " (base_control.phases); in this run: "
        << (r.base_control_phases.empty() ? std::string("none") : detail::listNames(r.base_control_phases)) << "\n";
  }
  if (record.samples == 0) return;  // stopped at the capture
  if (r.capture) {
    const std::string& contact_link = r.at_contact.robot.model->bodies()[r.at_contact.robot.contact.body].name;
    const std::string after = r.compliant ? "compliant contact (from t = " +
                                                detail::number(r.t_capture + r.compliant->duration) + " s)"
                                          : std::string("impact");
    out << "\nAfter the " << after << ": "
        << (r.joined ? "the target joins the robot's tree at link '" + contact_link + "' by " +
                           (r.joined->grasp == GraspJoint::Rigid       ? "a fixed joint"
                            : r.joined->grasp == GraspJoint::Spherical ? "a ball joint (grasp_rz, grasp_ry, grasp_rx)"
                                                                       : r.compliant && r.compliant->lock == GraspLock::Never
                                                                       ? "six grasp joints held by the gripper's springs and dampers (grasp_x ... grasp_rx; law.lock: never)"
                                                                       : "six grasp joints braked at their deflection (grasp_x ... grasp_rx)")
            : r.payload_attached ? "the target is attached to link '" + contact_link + "'"
            : r.target_motion    ? std::string("the target separates; both move on")
                                 : std::string("the target separates; the robot alone"));
  } else {
    out << "Plain motion of " << (sc.robot_urdf.empty() ? "the mounted robot" : sc.robot_urdf)
        << " from its initial state (no impact)";
  }
  out << ", " << r.duration << " s with " << toString(record.options.integrator) << " ("
      << record.stats.accepted_steps << " steps, " << record.stats.rejected_steps << " rejected)"
      << (record.options.grounded ? ", base grounded" : "") << "\n";
  const std::vector<std::string> locked_joints = record.lockedJoints();
  if (!locked_joints.empty()) out << "Braked joints: " << locked_joints.size() << " (" << detail::listNames(locked_joints) << ")\n";
  const MotionSample& last = record.last;
  double roll, pitch, yaw;
  KDL::Rotation::Quaternion(last.quat(0), last.quat(1), last.quat(2), last.quat(3)).GetRPY(roll, pitch, yaw);
  out << "Final base position [m]: " << last.p.transpose() << "\n"
      << "Final base attitude (roll, pitch, yaw) [deg]: " << roll * 180 / M_PI << ", " << pitch * 180 / M_PI << ", "
      << yaw * 180 / M_PI << "\n"
      << "Final base twist (v; w): " << last.twist.transpose() << "\n";
  printMatrix(out, "Joints at the end", (Eigen::MatrixXd(joints.size(), 2) << last.q, last.qd).finished(), joints,
              {"position", "rate"});
  out << "Largest change over the run: linear momentum " << record.max_linear_momentum_change << " N s, angular momentum "
      << record.max_angular_momentum_change << " N m s, kinetic energy " << record.max_energy_change << " J (of "
      << record.first.T << " J)\n";
  printMotionReport(out, record);
  if (r.target_motion)
    out << "The target after the impact: base at " << toEigen(r.target_motion->end.state.world_T_base.p).transpose()
        << " m at t = " << r.target_motion->end.t << " s; its momentum changed by at most " << r.target_motion->dP
        << " N s, " << r.target_motion->dL << " N m s\n";
  if (r.joined && r.joined->grasp == GraspJoint::Spherical && r.min_chart_margin < 0.1)
    out << "Warning: the ball joint came within " << r.min_chart_margin
        << " of its chart's singularity (|cos grasp_ry|): its angles are ill-conditioned there\n";
  if (!files.csv.empty()) out << "CSV: " << files.csv << "\n";
  if (!files.plot.empty()) out << "Plot: " << files.plot << "\n";
  if (!files.html.empty()) out << "Page: " << files.html << " (open it in a browser)\n";
}

}  // namespace kdl_space::cli
