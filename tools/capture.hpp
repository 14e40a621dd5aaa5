// `kdl_space capture SCENARIO [--json]`: the impact of the robot with its target, everything
// before and after.
#pragma once

#include <CLI/CLI.hpp>
#include <ostream>
#include <string>

namespace kdl_space::cli {

struct CaptureOptions {
  std::string scenario;
  bool json = false;
};

CLI::App* addCapture(CLI::App& app, CaptureOptions& options);
void runCapture(const CaptureOptions& options, std::ostream& out);

}  // namespace kdl_space::cli
