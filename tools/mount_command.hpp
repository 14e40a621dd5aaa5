// `kdl_space mount SCENARIO -o FILE.urdf [--json]`: the robot of a scenario whose arms are mounted
// on a bus (robot.mount) written as one URDF file, for other tools (and for `inspect --urdf`).
#pragma once

#include <CLI/CLI.hpp>
#include <ostream>
#include <string>

namespace kdl_space::cli {

struct MountOptions {
  std::string scenario;
  std::string output;  ///< -o FILE.urdf
  bool json = false;
};

CLI::App* addMount(CLI::App& app, MountOptions& options);

/// Writes the joined URDF (never over an input) and prints what it holds.
void runMount(const MountOptions& options, std::ostream& out);

}  // namespace kdl_space::cli
