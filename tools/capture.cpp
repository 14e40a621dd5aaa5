#include "capture.hpp"

#include <iomanip>
#include <memory>
#include <sstream>

#include "cli_common.hpp"
#include "scenario.hpp"

namespace kdl_space::cli {
namespace {

/// A solver at the system's state, or an InputError naming the scenario's fields.
std::unique_ptr<FreeFloatingSolver> computed(const std::string& file, const std::string& who, const ScenarioSystem& s) {
  auto solver = std::make_unique<FreeFloatingSolver>(s.model);
  if (const int rc = solver->compute(s.state))
    throw InputError(file + ": " + who + ": the free-floating quantities cannot be computed at this state (" + who +
                     ".base, " + who + ".q): " + strError(rc));
  return solver;
}

std::unique_ptr<FloatingSide> side(FreeFloatingSolver& solver, const std::string& file, const ScenarioSystem& s,
                                   const std::string& who) {
  try {
    return std::make_unique<FloatingSide>(solver.sharedModel(), s.state, s.contact, s.velocity, s.response);
  } catch (const ModelError& e) {
    throw InputError(file + ": " + who + ": " + e.what());
  }
}

Json twist(const KDL::Twist& t) { return toJson(toEigen(t)); }

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

CLI::App* addCapture(CLI::App& app, CaptureOptions& o) {
  CLI::App* cmd = app.add_subcommand("capture", "Solve the impact or capture of a scenario (YAML or JSON)");
  cmd->add_option("SCENARIO", o.scenario, "Scenario file (YAML or JSON)")->required();
  cmd->add_flag("--json", o.json, "Print one JSON object instead of the summary");
  return cmd;
}

CaptureRun solveCapture(const Scenario& sc) {
  CaptureRun run;
  run.robot_solver = computed(sc.file, "robot", sc.robot);
  run.robot = side(*run.robot_solver, sc.file, sc.robot, "robot");
  run.robot_solver->contactPoint(sc.robot.contact, run.p_h);
  if (sc.rigid_target) {
    try {
      run.target = std::make_unique<RigidBodySide>(*sc.rigid_target, run.p_h);
    } catch (const ModelError& e) {
      throw InputError(sc.file + ": " + e.what());
    }
  } else {
    run.target_solver = computed(sc.file, "target", *sc.floating_target);
    run.target = side(*run.target_solver, sc.file, *sc.floating_target, "target");
    Vector3d p_c;
    run.target_solver->contactPoint(sc.floating_target->contact, p_c);
    if ((p_c - run.p_h).norm() > 1e-3) {
      std::ostringstream why;
      why << sc.file << ": target.contact: the target's contact point is " << std::setprecision(6)
          << (p_c - run.p_h).norm() << " m from the robot's; they must touch (within 1 mm)";
      throw InputError(why.str());
    }
  }
  ImpactFault fault = ImpactFault::None;
  if (const int rc = collide(*run.robot, *run.target, sc.law, run.impulse, &fault)) {
    switch (fault) {
      case ImpactFault::SideA:
        throw InputError(sc.file + ": robot: the impulse cannot be applied to the robot: " + strError(rc));
      case ImpactFault::SideB:
        throw InputError(sc.file + ": target: the impulse cannot be applied to the target: " + strError(rc));
      default:
        throw InputError(sc.file + ": law: the impact cannot be solved: " + std::string(strError(rc)) +
                         (rc == E_NOT_POSITIVE_DEFINITE ? " (the robot's and the target's inverse inertias at the "
                                                          "contact point, G_robot + G_target, are singular there)"
                                                        : ""));
    }
  }
  return run;
}

namespace {
/// The target's twist at its CoM before / after (for a free-floating target: its locked twist).
std::pair<Vector6d, Vector6d> targetTwists(const Scenario& sc, const CaptureRun& r) {
  if (sc.rigid_target) {
    const auto& rigid = static_cast<const RigidBodySide&>(*r.target);
    return {rigid.twistBefore(), rigid.twistAfter()};
  }
  const auto& other = static_cast<const FloatingSide&>(*r.target);
  return {other.centroidTwistBefore(), other.centroidTwistAfter()};
}
}  // namespace

Json captureJson(const Scenario& sc, const CaptureRun& r) {
  const FloatingSide& robot = *r.robot;
  const ImpactSide& target = *r.target;
  const auto [target_before, target_after] = targetTwists(sc, r);
  Json jt;
  jt["twist_before"] = toJson(target_before);
  jt["twist_after"] = toJson(target_after);
  if (sc.floating_target) {
    // Another free-floating system: its locked twist at its CoM above, and its whole state.
    const auto& other = static_cast<const FloatingSide&>(target);
    jt["base_twist_before"] = twist(other.before().base_twist);
    jt["base_twist_after"] = twist(other.after().base_twist);
    jt["joint_names"] = sc.floating_target->model->jointNames();
    jt["qdot_before"] = toJson(other.before().qdot.data);
    jt["qdot_after"] = toJson(other.after().qdot.data);
  }
  const double T0 = robot.energyBefore() + target.energyBefore();
  const double T1 = robot.energyAfter() + target.energyAfter();
  Json j;
  j["impulse"] = toJson(r.impulse.F);
  j["robot"] = Json{{"base_twist_before", twist(robot.before().base_twist)},
                    {"base_twist_after", twist(robot.after().base_twist)},
                    {"joint_names", sc.robot.model->jointNames()},
                    {"qdot_before", toJson(robot.before().qdot.data)},
                    {"qdot_after", toJson(robot.after().qdot.data)},
                    {"contact_twist_before", toJson(robot.contactTwistBefore())},
                    {"contact_twist_after", toJson(robot.contactTwistAfter())}};
  j["target"] = jt;
  j["momentum_before"] = toJson(robot.momentumBefore() + target.momentumBefore());
  j["momentum_after"] = toJson(robot.momentumAfter() + target.momentumAfter());
  j["energy_before"] = T0;
  j["energy_after"] = T1;
  j["energy_lost"] = T0 - T1;
  double m_v = 0.0;
  // null without a normal, and where the robot cannot move its contact point along it (infinite)
  j["virtual_mass"] = sc.has_normal && virtualMass(robot.G(), sc.law.normal, m_v) == E_NOERROR ? Json(m_v) : Json(nullptr);
  j["G_star"] = toJson(robot.G());
  j["G_B"] = toJson(target.G());
  return j;
}

void printCaptureSummary(std::ostream& out, const Scenario& sc, const CaptureRun& r) {
  const FloatingSide& robot = *r.robot;
  const ImpactSide& target = *r.target;
  const auto [target_before, target_after] = targetTwists(sc, r);
  const double T0 = robot.energyBefore() + target.energyBefore();
  const double T1 = robot.energyAfter() + target.energyAfter();
  const Vector6d momentum_before = robot.momentumBefore() + target.momentumBefore();
  const Vector6d momentum_after = robot.momentumAfter() + target.momentumAfter();
  const std::vector<std::string>& joints = sc.robot.model->jointNames();
  out << "Scenario " << sc.file << "\n";
  out << "Law: " << lawName(sc.law.kind);
  if (sc.law.kind == ImpactKind::PointImpact || sc.law.kind == ImpactKind::FrictionalImpact)
    out << ", e = " << sc.law.restitution << ", normal " << row(sc.law.normal)
        << (sc.law.kind == ImpactKind::FrictionalImpact ? ", mu = " + std::to_string(sc.law.friction) : "");
  out << "\n";
  if (r.impulse.separating) out << "The bodies are already separating along the normal: no impulse.\n";
  if (sc.law.kind == ImpactKind::FrictionalImpact && !r.impulse.separating)
    out << (r.impulse.sticking ? "Contact sticks at the end of the impact.\n" : "Contact slides at the end of the impact.\n");
  out << "Contact point " << row(r.p_h) << " m on link '" << sc.robot.contact_link << "'\n";
  out << "Impulse on the robot (f; n) [N s; N m s]: " << row(r.impulse.F) << "\n";
  out << "Robot contact twist (v; w): before " << row(robot.contactTwistBefore()) << "\n"
      << "                            after  " << row(robot.contactTwistAfter()) << "\n";
  out << "Target twist at its CoM:    before " << row(target_before) << "\n"
      << "                            after  " << row(target_after) << "\n";
  out << "Base twist:                 before " << row(toEigen(robot.before().base_twist)) << "\n"
      << "                            after  " << row(toEigen(robot.after().base_twist)) << "\n"
      << "                            jump   "
      << row(toEigen(robot.after().base_twist) - toEigen(robot.before().base_twist)) << "\n";
  printMatrix(out, "Joint rates [rad/s or m/s]",
              (Eigen::MatrixXd(joints.size(), 3) << robot.before().qdot.data, robot.after().qdot.data,
               robot.after().qdot.data - robot.before().qdot.data).finished(),
              joints, {"before", "after", "jump"});
  out << "Momentum (P; L about the world origin): before " << row(momentum_before) << "\n"
      << "                                        after  " << row(momentum_after) << "\n";
  out << "Kinetic energy: before " << T0 << " J, after " << T1 << " J, lost " << T0 - T1 << " J ("
      << (T0 > 0 ? 100.0 * (T0 - T1) / T0 : 0.0) << " %)\n";
  if (sc.has_normal) {
    double m_v = 0.0;
    out << "Virtual mass of the robot along the normal: ";
    if (virtualMass(robot.G(), sc.law.normal, m_v) == E_NOERROR)
      out << m_v << " kg\n";
    else
      out << "infinite (the robot cannot move its contact point along the normal here)\n";
  }
}

void runCapture(const CaptureOptions& o, std::ostream& out) {
  const Scenario sc = loadScenario(o.scenario);
  const CaptureRun run = solveCapture(sc);
  if (o.json)
    out << captureJson(sc, run).dump(2) << "\n";
  else
    printCaptureSummary(out, sc, run);
}

}  // namespace kdl_space::cli
