// `kdl_space plan SCENARIO [--objective NAME | --weights NAME=W,...] [--self-motion A,B]
// [--wrist-roll A,B] [--timing A,B] [--closing-speed A,B] [--horizon S] [--scan N] [--json]`: the arm
// configuration whose capture disturbs the servicer least, at its instant or over the motion after
// it (the library's planCapture, printed): the joint angles by name, the parameters, the objective
// at the optimum and at the scenario as written, and with a horizon what the bus feels over it. Exit 2 for a usage
// mistake (an unknown objective, bad weights, nothing to plan), 3 for a scenario it cannot plan.
#pragma once

#include <CLI/CLI.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "kdl_space/report/plan_json.hpp"
#include "kdl_space/planning/capture_plan.hpp"

namespace kdl_space::cli {

struct PlanCliOptions {
  std::string scenario;
  std::string objective = "base_rate";
  std::string weights;                 ///< NAME=W,NAME=W (overrides --objective)
  std::vector<double> self_motion;     ///< A B [rad]; empty: the library's default
  std::vector<double> wrist_roll;      ///< A B [rad]
  std::vector<double> timing;          ///< A B [s]
  std::vector<double> closing_speed;   ///< A B [m/s]; empty: the scenario's rates before
  unsigned int scan = 21;
  unsigned int polish_starts = 5;
  double horizon = 0.0;                ///< [s]; 0: unset (the scenario's, if an operation term asks)
  double settling_band = 0.05;
  bool json = false;
};

CLI::App* addPlan(CLI::App& app, PlanCliOptions& options);

/// \brief The library's options from the command line's. \throws UsageError naming the option.
PlanOptions planOptions(const PlanCliOptions& options);

void runPlan(const PlanCliOptions& options, std::ostream& out);

}  // namespace kdl_space::cli
