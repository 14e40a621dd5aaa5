// `kdl_space inspect`: the free-floating quantities of a URDF robot at one state.
#pragma once

#include <CLI/CLI.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "kdl_space/report/inspection_json.hpp"
#include "kdl_space/algorithm/conditioning.hpp"
#include "kdl_space/multibody/poses.hpp"

namespace kdl_space::cli {

struct InspectOptions {
  std::string urdf;
  std::vector<std::string> tips;
  std::vector<double> offsets;          ///< 3 values per --offset, paired with the preceding --tip
  std::vector<std::string> q;           ///< NAME=VALUE
  std::vector<double> base_pos{0, 0, 0};
  std::vector<double> base_rpy{0, 0, 0};
  bool json = false;
};

/// Registers the subcommand and its options on `app`.
CLI::App* addInspect(CLI::App& app, InspectOptions& options);

/// Runs it after parsing; throws UsageError, or the library's Error (InputError, ModelError).
void runInspect(const CLI::App& command, const InspectOptions& options, std::ostream& out);

}  // namespace kdl_space::cli
