#include "plan_command.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "cli_common.hpp"

namespace kdl_space::cli {
namespace {

PlanRange rangeOf(const std::vector<double>& ab, const std::string& option) {
  if (ab[0] > ab[1]) throw UsageError(option + ": the range's lower end must not exceed its upper end");
  return PlanRange{ab[0], ab[1]};
}

std::string termList() {
  std::string list;
  for (const std::string& t : planObjectiveTerms()) list += (list.empty() ? "" : ", ") + t;
  return list;
}

void checkTerm(const std::string& name, const std::string& option) {
  const std::vector<std::string>& terms = planObjectiveTerms();
  if (std::find(terms.begin(), terms.end(), name) == terms.end())
    throw UsageError(option + ": unknown objective '" + name + "' (choose from " + termList() + ")");
}

/// The library refuses a range or finds nothing to plan: a usage mistake, the option named (exit 2).
void usageOrInput(const InputError& e) {
  const std::string what = e.what();
  for (const auto& [field, option] : {std::pair<std::string, std::string>{"self_motion: ", "--self-motion: "},
                                      {"wrist_roll: ", "--wrist-roll: "}, {"timing: ", "--timing: "},
                                      {"closing_speed: ", "--closing-speed: "},
                                      {"objective: ", "--weights: "}, {"scan: ", "--scan: "},
                                      {"horizon: ", "--horizon: "}, {"settling_band: ", "--settling-band: "}})
    if (what.rfind(field, 0) == 0) throw UsageError(option + what.substr(field.size()));
  if (what.rfind("plan: nothing to plan", 0) == 0)
    throw UsageError(what + "; give a range with --self-motion (a redundant arm), --wrist-roll, --timing or "
                     "--closing-speed");
}

void printTerms(std::ostream& out, const char* label, const PlanTerms& t) {
  out << "  " << std::left << std::setw(9) << label << std::right << std::setprecision(6) << "objective "
      << std::setw(12) << t.objective << "   base_rate " << t.base_rate << " rad/s, impulse " << t.impulse
      << " N s, largest joint-rate jump " << t.joint_rate_jump << "\n";
  if (!t.feasible) out << "           not within the limits: " << t.infeasible << "\n";
  if (!t.motion) return;
  const MotionMeasures& m = *t.motion;
  out << "           after: peak base rate " << m.peak_base_rate << " rad/s, final " << m.final_base_rate
      << " rad/s, attitude excursion " << m.attitude_excursion * 180.0 / M_PI << " deg, settling " << m.settling_time
      << " s, detumbled ";
  if (std::isnan(m.time_to_detumble)) out << "not within the horizon";
  else out << "after " << m.time_to_detumble << " s";
  if (!std::isnan(m.wheel_momentum_fraction)) out << ", wheels at " << m.wheel_momentum_fraction * 100.0 << " % of capacity";
  out << "\n";
  out << "                  peak joint torque ";
  if (m.peak_torque_joint.empty()) out << "(no effort limits)";
  else out << m.peak_torque_ratio * 100.0 << " % of " << m.peak_torque_joint << "'s effort limit";
  if (!std::isnan(m.peak_grasp_force))
    out << ", peak grasp force " << m.peak_grasp_force << " N, moment " << m.peak_grasp_moment << " N m";
  out << "\n";
}

}  // namespace

CLI::App* addPlan(CLI::App& app, PlanCliOptions& o) {
  CLI::App* cmd = app.add_subcommand(
      "plan", "Capture planning: over the self-motion, the wrist roll, the capture instant and the hand's closing "
              "speed, the arm configuration "
              "whose capture disturbs the servicer least, within the joints' position and velocity limits");
  cmd->add_option("SCENARIO", o.scenario, "Scenario file (YAML or JSON) with a capture: robot, target, law")->required();
  cmd->add_option("--objective", o.objective,
                  "What to minimise. At the capture's instant: base_rate (|w| of the base after), impulse (|f| of the "
                  "impulse), joint_rate_jump (largest |dqdot|). Over the motion after it (--horizon): peak_base_rate, "
                  "final_base_rate, attitude_excursion, settling_time, peak_torque_ratio (|tau|/effort), "
                  "peak_grasp_force, peak_grasp_moment (a law that holds the target), time_to_detumble (the base's rate below "
                  "simulation.detumble_rate for good; not detumbled: the horizon times the final rate over it), "
                  "wheel_momentum_fraction (robot.base_actuators). Default base_rate");
  cmd->add_option("--weights", o.weights, "A weighted sum instead: NAME=W,... (e.g. base_rate=1,impulse=0.01)");
  cmd->add_option("--horizon", o.horizon,
                  "Seconds of motion after each capture that the operation terms read, the scenario's servos holding "
                  "its configuration and its base control acting (default: the scenario's simulation.duration); "
                  "given, the optimum and the nominal report that motion whatever the objective")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--settling-band", o.settling_band,
                  "The settling time's band about the base's final angular velocity, relative to its farthest (0, 1)")
      ->check(CLI::Range(1e-6, 0.999999));
  cmd->add_option("--self-motion", o.self_motion, "A redundant arm's self-motion range A,B [rad] (default -1,1)")
      ->expected(2)->delimiter(',')->check(finiteNumber());
  cmd->add_option("--wrist-roll", o.wrist_roll, "The hand's roll about the contact frame's z: range A,B [rad] "
                                                "(default -pi/2,pi/2; 0,0 keeps the scenario's)")
      ->expected(2)->delimiter(',')->check(finiteNumber());
  cmd->add_option("--timing", o.timing, "The capture instant's range A,B [s] later along the target's tumble "
                                        "(default 0,0: now)")
      ->expected(2)->delimiter(',')->check(finiteNumber());
  cmd->add_option("--closing-speed", o.closing_speed,
                  "The hand's velocity before the grasp: its closing speed along the contact frame's z, range A,B "
                  "[m/s] (A >= 0; the joint rates before the capture are then planned; default: the scenario's)")
      ->expected(2)->delimiter(',')->check(finiteNumber());
  cmd->add_option("--scan", o.scan, "Points per searched parameter of the first scan")->check(CLI::Range(2u, 201u));
  cmd->add_option("--polish-starts", o.polish_starts, "Local polishes from the scan's best local minima")
      ->check(CLI::Range(0u, 100u));
  cmd->add_flag("--json", o.json, "Print one JSON object instead of the summary");
  return cmd;
}

PlanOptions planOptions(const PlanCliOptions& o) {
  PlanOptions p;
  if (o.weights.empty()) {
    checkTerm(o.objective, "--objective");
    p.weights = {{o.objective, 1.0}};
  } else {
    p.weights.clear();
    std::stringstream list(o.weights);
    std::string item;
    while (std::getline(list, item, ',')) {
      const auto [name, weight] = parseAssignment(item, "--weights");
      checkTerm(name, "--weights");
      if (!(weight > 0.0)) throw UsageError("--weights " + item + ": a weight must be > 0");
      for (const auto& [seen, w] : p.weights)
        if (seen == name) throw UsageError("--weights: " + name + " is given twice");
      p.weights.emplace_back(name, weight);
    }
    if (p.weights.empty()) throw UsageError("--weights: give NAME=W,... (terms: " + termList() + ")");
  }
  if (!o.self_motion.empty()) p.self_motion = rangeOf(o.self_motion, "--self-motion");
  if (!o.wrist_roll.empty()) p.wrist_roll = rangeOf(o.wrist_roll, "--wrist-roll");
  if (!o.timing.empty()) p.timing = rangeOf(o.timing, "--timing");
  if (!o.closing_speed.empty()) p.closing_speed = rangeOf(o.closing_speed, "--closing-speed");
  p.scan = o.scan;
  p.polish_starts = o.polish_starts;
  if (o.horizon > 0.0) p.horizon = o.horizon;
  p.settling_band = o.settling_band;
  p.cancelled = [] { return interruptFlag().load(std::memory_order_relaxed); };
  return p;
}

void runPlan(const PlanCliOptions& o, std::ostream& out) {
  const PlanOptions options = planOptions(o);  // or UsageError, before the scenario is read
  const Scenario sc = loadScenario(o.scenario);
  CapturePlan plan;
  try {
    plan = planCapture(sc, options);
  } catch (const InputError& e) {
    usageOrInput(e);  // the options' names (exit 2), else the scenario's problem (exit 3)
    e.rethrowWithContext(sc.file + ": ");
  } catch (const Error& e) {
    e.rethrowWithContext(sc.file + ": ");
  }
  if (plan.cancelled) throw Interrupted("plan: stopped during the search; nothing written");
  if (o.json) {
    out << jsonText(planJson(sc, options, plan), 2) << "\n";
    return;
  }
  out << "kdl_space plan " << sc.file << ": minimising";
  for (std::size_t k = 0; k < options.weights.size(); ++k)
    out << (k ? " +" : "") << " " << options.weights[k].second << " " << options.weights[k].first;
  out << " over";
  for (const std::string& s : plan.searched) out << " " << s;
  out << " (" << plan.evaluations << " captures computed)\n";
  printTerms(out, "optimum", plan.optimum);
  printTerms(out, "nominal", plan.nominal);
  if (plan.horizon > 0.0 && plan.optimum.motion)
    out << "over " << plan.horizon << " s after the capture (servos holding, the scenario's base control); the "
        << "stack's momentum-determined rate once its joints are still: " << plan.optimum.motion->momentum_rate
        << " rad/s at the optimum (" << (plan.nominal.motion ? plan.nominal.motion->momentum_rate : std::nan(""))
        << " nominal): its momentum is the same in every configuration, only its inertia differs; the base "
           "control or a detumble removes it\n";
  out << "parameters:";
  for (const auto& [name, value] : plan.parameters) out << " " << name << " = " << std::setprecision(9) << value;
  out << (plan.parameters.empty() ? " none" : "") << "\njoint angles at the optimum [rad or m] (nominal in brackets):\n";
  std::size_t width = 0;
  for (const std::string& n : plan.joint_names) width = std::max(width, n.size());
  for (std::size_t j = 0; j < plan.joint_names.size(); ++j)
    out << "  " << std::left << std::setw(static_cast<int>(width)) << plan.joint_names[j] << std::right << "  "
        << std::setprecision(12) << std::setw(18) << plan.q[j] << "  (" << plan.nominal_q[j] << ")\n";
  if (!options.closing_speed) return;
  out << "before the capture, closing on the grasp: joint rates [rad/s or m/s]\n";
  for (std::size_t j = 0; j < plan.joint_names.size(); ++j)
    out << "  " << std::left << std::setw(static_cast<int>(width)) << plan.joint_names[j] << std::right << "  "
        << std::setprecision(12) << std::setw(18) << plan.qdot_before[j] << "\n";
  out << "  base twist (v [m/s]; w [rad/s]):";
  for (const double v : plan.base_twist_before) out << " " << std::setprecision(9) << v;
  out << "\n";
}

}  // namespace kdl_space::cli
