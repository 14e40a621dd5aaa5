#include "capture_text.hpp"

#include <iomanip>
#include <optional>
#include <sstream>

#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/report/capture_report.hpp"

namespace kdl_space::cli {
namespace {


const char* lawName(ImpactKind k) {
  switch (k) {
    case ImpactKind::Capture: return "capture (rigid 6-D grasp, eq. 24-25)";
    case ImpactKind::PointImpact: return "point impact, frictionless, Newton restitution";
    case ImpactKind::FrictionalImpact: return "point impact, Newton restitution and Coulomb friction";
    case ImpactKind::TranslationalCapture: return "translational capture (linear velocities equal, rotation free)";
  }
  return "";
}

std::string row(const Eigen::VectorXd& v) {
  std::ostringstream s;
  s << std::setprecision(6) << "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s << (i ? ", " : "") << v(i);
  return s.str() + "]";
}

}  // namespace

void printCaptureSummary(std::ostream& out, const Scenario& sc, const CaptureResult& r) {
  const CaptureProblem& p = sc.capture;
  const ImpactLaw& law = p.law;
  const FloatingSideResult& robot = r.robot;
  const double T0 = r.energy_before, T1 = r.energy_after;
  const std::vector<std::string>& joints = p.robot.model->jointNames();
  out << "Scenario " << sc.file << "\n";
  out << "Law: " << lawName(law.kind);
  if (law.kind == ImpactKind::PointImpact || law.kind == ImpactKind::FrictionalImpact)
    out << ", e = " << law.restitution << ", normal " << row(law.normal)
        << (law.kind == ImpactKind::FrictionalImpact ? ", mu = " + std::to_string(law.friction) : "");
  out << "\n";
  if (r.impulse.separating) out << "The bodies are already separating along the normal: no impulse.\n";
  if (law.kind == ImpactKind::FrictionalImpact && !r.impulse.separating)
    out << (r.impulse.sticking ? "Contact sticks at the end of the impact.\n" : "Contact slides at the end of the impact.\n");
  out << "Contact point " << row(r.contact_point) << " m on link '"
      << p.robot.model->bodies()[p.robot.contact.body].name << "'";
  if (const std::optional<Vector3d> in_target = pointInTargetFrame(p, r.contact_point))
    out << ", " << row(*in_target) << " m in the target's frame";
  out << "\n";
  if (sc.grasp_solution)
    out << "Grasp (robot.place: grasp): the contact frame holds robot.grasp.target_frame to "
        << sc.grasp_solution->position_residual << " m, " << sc.grasp_solution->orientation_residual << " rad ("
        << sc.grasp_solution->iterations << " iterations, " << sc.grasp_solution->attempts
        << (sc.grasp_solution->attempts == 1 ? " start)\n" : " starts)\n");
  if (sc.grasp_solution) {  // the angles it solved, which robot.q did not give
    out << "  at";
    for (int j : sc.grasp_solution->chain_joints)
      out << " " << p.robot.model->jointNames()[j] << " = " << sc.grasp_solution->q(j);
    out << " [rad or m]\n";
  }
  const std::vector<std::string> braked = lockedNames(p.robot);
  if (!braked.empty()) {
    out << "Braked joints (locked at the impact, rates stay 0):";
    for (std::size_t k = 0; k < braked.size(); ++k) out << (k ? ", '" : " '") << braked[k] << "'";
    out << "\n";
  }
  out << "Impulse on the robot (f; n) [N s; N m s]: " << row(r.impulse.F) << "\n";
  out << "Robot contact twist (v; w): before " << row(robot.contact_twist_before) << "\n"
      << "                            after  " << row(robot.contact_twist_after) << "\n";
  out << "Target twist at its CoM:    before " << row(r.target_twist_before) << "\n"
      << "                            after  " << row(r.target_twist_after) << "\n";
  out << "Base twist:                 before " << row(toEigen(robot.before.base_twist)) << "\n"
      << "                            after  " << row(toEigen(robot.after.base_twist)) << "\n"
      << "                            jump   "
      << row(toEigen(robot.after.base_twist) - toEigen(robot.before.base_twist)) << "\n";
  printMatrix(out, "Joint rates [rad/s or m/s]",
              (Eigen::MatrixXd(joints.size(), 3) << robot.before.qdot.data, robot.after.qdot.data,
               robot.after.qdot.data - robot.before.qdot.data).finished(),
              joints, {"before", "after", "jump"});
  out << "Momentum (P; L about the world origin): before " << row(r.momentum_before) << "\n"
      << "                                        after  " << row(r.momentum_after) << "\n";
  out << "Kinetic energy: before " << T0 << " J, after " << T1 << " J, lost " << T0 - T1 << " J ("
      << (T0 > 0 ? 100.0 * (T0 - T1) / T0 : 0.0) << " %)\n";
  if (p.has_normal) {
    out << "Virtual mass of the robot along the normal: ";
    if (r.virtual_mass)
      out << *r.virtual_mass << " kg\n";
    else
      out << "infinite (the robot cannot move its contact point along the normal here)\n";
  }
}

void printCompliantSummary(std::ostream& out, const CompliantCaptureResult& c, const CaptureResult& r) {
  const char* ends[4] = {"caught (the grasp locked)", "opened (a bounce)", "timed out (law.max_duration)",
                         "settled (the relative motion died out; the grasp stays compliant, law.lock: never)"};
  const char* rules[3] = {"", ": the relative speed fell below law.catch_tolerance",
                          ": the springs' energy passed its maximum (the hand stopped closing)"};
  const bool stays = c.lock == GraspLock::Never && c.end == ContactEnd::TimedOut;  // the springs go on holding
  out << "\nCompliant contact (law.type compliant; the impulsive capture above is its limit):\n"
      << "  end " << ends[static_cast<int>(c.end)] << (stays ? "; the grasp stays compliant (law.lock: never)" : "")
      << rules[static_cast<int>(c.catch_rule)] << " after " << c.duration << " s (" << c.history.size()
      << " samples, " << c.steps << " steps)\n"
      << "  peak force " << c.peak_force << " N, peak moment " << c.peak_moment << " N m\n"
      << "  impulse (f; n)   " << row(c.impulse) << "\n"
      << "  impulsive        " << row(r.impulse.F) << "\n"
      << "  energy dissipated " << c.dissipated << " J, locked in the springs " << c.spring_energy
      << " J, taken by the lock " << c.lock_loss << " J\n"
      << "  the lock's share: " << 100.0 * c.lock_share.linear_impulse << " % of the force's impulse, "
      << 100.0 * c.lock_share.angular_impulse << " % of the moment's, " << 100.0 * c.lock_share.energy
      << " % of the energy taken\n";
}

}  // namespace kdl_space::cli
