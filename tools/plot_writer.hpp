// The plot of `kdl_space simulate --plot FILE` (.svg or .png), drawn by gnuplot: base attitude,
// joint positions, the change of momentum and energy since the start, and the joint torques when a
// controller runs. Many joints are drawn in several panels (at most kJointsPerPanel each), so
// that a legend never squeezes a panel.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "kdl_space/operation/motion_sample.hpp"

namespace kdl_space::cli {

constexpr std::size_t kJointsPerPanel = 10;

/// The gnuplot terminal for a plot file name and its number of panels; throws UsageError for
/// another extension.
std::string plotTerminal(const std::string& path, std::size_t panels = 3);

/// \brief Draws the samples into out.tmp() with gnuplot (the caller commits it); throws
/// InputError if gnuplot fails or its scratch files cannot be written.
/// `torques`: draw the joint torques too. `capture_time` (finite): a vertical line marks the
/// capture on every panel. With samples of the approach, a panel shows the hand-to-grasp distance.
/// The momentum and energy balance of each phase is measured from the phase's first sample.
void writePlot(const AtomicFile& out, const std::vector<MotionSample>& samples, const std::vector<std::string>& joints,
               const std::string& title, bool torques,
               double capture_time = std::numeric_limits<double>::quiet_NaN());

}  // namespace kdl_space::cli
