// `kdl_space capture SCENARIO [--scene FILE] [--html FILE [--mesh-path DIR]...] [--json]`: the impact of the robot with its target,
// everything before and after (the library's loadScenario and solveCapture, printed), and a
// picture of the impact instant (--scene), or an interactive 3-D page of it (--html).
#pragma once

#include <CLI/CLI.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "cli_common.hpp"

namespace kdl_space::cli {

struct CaptureOptions {
  std::string scenario;
  std::string scene;  ///< --scene FILE (.svg or .png); empty: none
  std::string html;   ///< --html FILE: the instant as an interactive 3-D page; empty: none
  std::vector<std::string> mesh_path;  ///< --mesh-path DIR...: where the page's package:// meshes are found
  bool json = false;
};

CLI::App* addCapture(CLI::App& app, CaptureOptions& options);

void runCapture(const CaptureOptions& options, std::ostream& out);

}  // namespace kdl_space::cli
