// `kdl_space check FILE.urdf [--tip LINK ...] [--json] [--strict]`: every problem of a URDF file
// as a free-floating model, one line each, like a compiler's diagnostics.
#pragma once

#include <CLI/CLI.hpp>
#include <ostream>
#include <string>
#include <vector>

namespace kdl_space::cli {

struct CheckOptions {
  std::string urdf;
  std::vector<std::string> tips;
  bool json = false;
  bool strict = false;
};

/// Registers the subcommand and its options on `app`.
CLI::App* addCheck(CLI::App& app, CheckOptions& options);

/// Checks the file and prints the report on `out`; returns the exit code: 0 without errors
/// (and, with --strict, without warnings), 3 otherwise.
int runCheck(const CheckOptions& options, std::ostream& out);

}  // namespace kdl_space::cli
