// The plot of `kdl_space simulate --plot FILE` (.svg or .png), drawn by gnuplot: base attitude,
// joint positions, and the change of momentum and energy since the start.
#pragma once

#include <string>
#include <vector>

#include "cli_common.hpp"
#include "sample.hpp"

namespace kdl_space::cli {

/// The gnuplot terminal for a plot file name; throws UsageError for another extension.
std::string plotTerminal(const std::string& path);

/// \brief Draws the samples into out.tmp() with gnuplot (the caller commits it); throws
/// InputError if gnuplot fails or its scratch files cannot be written.
void writePlot(const AtomicFile& out, const std::vector<Sample>& samples, const std::vector<std::string>& joints,
               const std::string& title);

}  // namespace kdl_space::cli
