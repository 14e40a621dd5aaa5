// `kdl_space simulate SCENARIO [--duration T] [--csv FILE] [--plot FILE] [--json]`: the impact of
// `capture`, then the motion after it.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <ostream>
#include <string>

namespace kdl_space::cli {

struct SimulateOptions {
  std::string scenario;
  std::optional<double> duration;
  std::string csv, plot, scene;
  bool json = false;
};

CLI::App* addSimulate(CLI::App& app, SimulateOptions& options);
void runSimulate(const SimulateOptions& options, std::ostream& out);

}  // namespace kdl_space::cli
