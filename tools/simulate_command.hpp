// `kdl_space simulate SCENARIO [--duration T] [--csv FILE] [--plot FILE] [--json]`: the impact of
// `capture`, then the motion after it. The CSV's and the plot's rows are written as they come
// (memory does not grow with the duration); their number is checked before the run.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace kdl_space::cli {

struct SimulateOptions {
  std::string scenario;
  std::optional<double> duration;
  std::string csv, plot, scene, html;
  std::vector<std::string> mesh_path;  ///< --mesh-path folders (the page's package:// meshes)
  bool json = false;
  /// The most output rows a run may produce (approach and motion: estimatedOutputRows); a double,
  /// so that 1e9 can be written as such.
  double max_output_rows = 1e7;
};

CLI::App* addSimulate(CLI::App& app, SimulateOptions& options);
void runSimulate(const SimulateOptions& options, std::ostream& out);

}  // namespace kdl_space::cli
