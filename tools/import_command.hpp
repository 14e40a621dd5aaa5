// `kdl_space import (--spacedyn LP.m | --mjcf FILE | --sdf FILE) -o FILE.urdf`: a robot described
// for another tool written as one URDF file (what every command also reads directly).
#pragma once

#include <CLI/CLI.hpp>
#include <ostream>
#include <string>

namespace kdl_space::cli {

struct ImportOptions {
  std::string spacedyn, mjcf, sdf;  ///< exactly one: the file to read
  std::string output;               ///< -o FILE.urdf
  bool json = false;
};

CLI::App* addImport(CLI::App& app, ImportOptions& options);

/// Reads the file in its format, checks the model it describes, writes its URDF, prints a summary.
void runImport(const ImportOptions& options, std::ostream& out);

}  // namespace kdl_space::cli
