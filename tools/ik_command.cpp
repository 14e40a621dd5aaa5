#include "ik_command.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>

#include "cli_common.hpp"

namespace kdl_space::cli {
namespace {

std::string linkName(const Scenario& sc) { return sc.capture.robot.model->bodies()[sc.capture.robot.contact.body].name; }

}  // namespace

CLI::App* addIk(CLI::App& app, IkCliOptions& o) {
  CLI::App* cmd = app.add_subcommand(
      "ik", "Inverse kinematics: the joint angles that put the scenario robot's contact frame at a world pose");
  cmd->add_option("SCENARIO", o.scenario, "Scenario file (YAML or JSON): robot.urdf, robot.contact, robot.base, robot.q")
      ->required();
  cmd->add_option("--position", o.position, "The contact frame's world position X Y Z (or X,Y,Z) [m]")
      ->required()->expected(3)->delimiter(',')->check(finiteNumber());
  cmd->add_option("--rpy", o.rpy, "Its roll pitch yaw about fixed world axes (or R,P,Y) [rad]; default 0 0 0")
      ->expected(3)->delimiter(',')->check(finiteNumber());
  cmd->add_option("--prefer", o.prefer,
                  "Which solution a redundant arm takes: 'posture' (default: the one closest to robot.q), NAME=VALUE "
                  "[rad or m] ... (closest to that posture; unnamed joints as in robot.q), or 'reaction' (the one from "
                  "which a unit hand motion turns the base least: the least reaction_measure)")
      ->expected(1, -1)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--position-tolerance", o.position_tolerance, "Largest accepted position residual [m]")
      ->check(positiveNumber());
  cmd->add_option("--orientation-tolerance", o.orientation_tolerance, "Largest accepted orientation residual [rad]")
      ->check(positiveNumber());
  cmd->add_option("--restarts", o.restarts, "Deterministic starts tried after the scenario's posture")
      ->check(CLI::Range(0u, 1000u));
  cmd->add_flag("--json", o.json, "Print one JSON object instead of the summary");
  return cmd;
}

void runIk(const IkCliOptions& o, std::ostream& out) {
  const Scenario sc = loadScenario(o.scenario);
  const FloatingSystem& robot = sc.capture.robot;
  if (robot.contact.body == 0 && robot.contact.offset == KDL::Vector::Zero())
    throw InputError(sc.file + ": robot.contact: missing: ik places the contact frame (give robot.contact.link, and "
                     "its offset)");
  IkOptions options;
  options.position_tolerance = o.position_tolerance;
  options.orientation_tolerance = o.orientation_tolerance;
  options.restarts = o.restarts;
  options.cancelled = [] { return interruptFlag().load(std::memory_order_relaxed); };  // Ctrl-C: Cancelled
  const bool reaction = std::find(o.prefer.begin(), o.prefer.end(), "reaction") != o.prefer.end();
  if (reaction && o.prefer.size() > 1)
    throw UsageError("--prefer reaction: takes no posture (NAME=VALUE) and no second preference; give one of them");
  if (reaction) options.prefer = IkPreference::Reaction;
  if (!reaction && !o.prefer.empty()) {
    KDL::JntArray preferred = robot.state.q;
    for (const std::string& text : o.prefer) {
      if (text == "posture") continue;  // the default: robot.q, or the NAME=VALUE given with it
      const auto [name, value] = parseAssignment(text, "--prefer");
      const int j = robot.model->jointIndex(name);
      if (j < 0) throw UsageError("--prefer " + text + ": the robot has no movable joint '" + name + "'");
      preferred(j) = value;
    }
    options.preferred = preferred;
  }
  const KDL::Frame goal(KDL::Rotation::RPY(o.rpy[0], o.rpy[1], o.rpy[2]), KDL::Vector(o.position[0], o.position[1], o.position[2]));
  const IkResult r = inScenario(sc, [&] { return solveInverseKinematics(*robot.model, robot.state, robot.contact, goal, options); });
  if (o.json) {
    out << jsonText(ikJson(sc, goal, r), 2) << "\n";
    return;
  }
  const FloatingModel& model = *robot.model;
  out << "kdl_space ik " << sc.file << ": the contact frame of link '" << linkName(sc) << "' at position ["
      << o.position[0] << ", " << o.position[1] << ", " << o.position[2] << "] m, rpy [" << o.rpy[0] << ", " << o.rpy[1]
      << ", " << o.rpy[2] << "] rad (world), the base as the scenario puts it; preferring "
      << (reaction ? "the least reaction of the base" : "the posture") << "\n";
  out << std::setprecision(3) << "reached: residual " << r.position_residual << " m, " << r.orientation_residual
      << " rad; " << r.iterations << " iterations, " << r.attempts << (r.attempts == 1 ? " start" : " starts") << "\n";
  if (std::isfinite(r.reaction_measure))
    out << "reaction measure (base angular rate per unit hand twist, ||W J_h^+||_F): " << r.reaction_measure << "\n";
  out << "joint angles [rad or m] (* moved; the others keep robot.q):\n" << std::setprecision(12);
  std::size_t width = 0;
  for (const std::string& n : model.jointNames()) width = std::max(width, n.size());
  for (unsigned int j = 0; j < model.nj(); ++j) {
    const bool moved = std::find(r.chain_joints.begin(), r.chain_joints.end(), static_cast<int>(j)) != r.chain_joints.end();
    out << "  " << (moved ? "* " : "  ") << std::left << std::setw(static_cast<int>(width)) << model.jointNames()[j]
        << std::right << "  " << std::setw(16) << r.q(j) << "\n";
  }
}

}  // namespace kdl_space::cli
