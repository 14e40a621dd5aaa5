// `kdl_space export INPUT (--spacedyn DIR | --mjcf FILE | --urdf FILE)`: a robot (a description in
// any format read, or a scenario's robot with its state, contact and target) written for another
// tool: SpaceDyn's LP and SV function files, a MuJoCo scene, or one URDF document.
#pragma once

#include <CLI/CLI.hpp>
#include <ostream>
#include <string>

namespace kdl_space::cli {

struct ExportOptions {
  std::string input;     ///< a scenario (.yaml, .yml, .json) or a robot description (URDF, SDF, MJCF, LP)
  std::string spacedyn;  ///< --spacedyn DIR
  std::string mjcf;      ///< --mjcf FILE.xml
  std::string urdf;      ///< --urdf FILE.urdf
  std::string name;      ///< --name: the SpaceDyn functions' stem (default: the input's)
  bool json = false;
};

CLI::App* addExport(CLI::App& app, ExportOptions& options);

/// Writes the files (never over an input, each whole or not at all) and prints what they hold.
void runExport(const ExportOptions& options, std::ostream& out);

}  // namespace kdl_space::cli
