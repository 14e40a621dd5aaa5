// The plot of `kdl_space simulate --plot FILE` (.svg or .png), drawn by gnuplot: base attitude
// and angular rate, the base control's torque (and force) when the scenario has one, joint
// positions (the servos' hold error q - set point for the joints a PD servo holds), the change of
// momentum and energy since the start, and the joint torques when a controller runs. Many joints are drawn in several panels (at most kJointsPerPanel each), so
// that a legend never squeezes a panel. The samples are streamed to gnuplot's data file as they
// come (PlotWriter): the memory a plot takes does not grow with the run.
#pragma once

#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "kdl_space/report/json.hpp"
#include "kdl_space/parsers/output_file.hpp"
#include "kdl_space/report/gnuplot_text.hpp"
#include "kdl_space/operation/motion_sample.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"

namespace kdl_space::report {

constexpr std::size_t kJointsPerPanel = 10;

/// The gnuplot terminal for a plot file name and its number of panels; throws UsageError for
/// another extension.
std::string plotTerminal(const std::string& path, std::size_t panels = 3);

/// \brief The plot of a run, its rows written to gnuplot's data file (a scratch file next to
/// out.tmp()) as the samples come, then drawn into out.tmp() (the caller commits it). What the
/// script needs of the whole run (its time span, whether an approach's distance was seen) is kept
/// as it goes; the momentum and energy balance of each phase is measured from the phase's first
/// sample (the balance restarts at the capture).
class PlotWriter {
 public:
  /// Opens the data file; throws InputError if it cannot. `joints`: the samples' joints. `sc`
  /// (optional): the scenario whose servos (simulation.joints' PD, by the robot's joint names) and
  /// base control the plot shows.
  PlotWriter(const AtomicFile& out, std::vector<std::string> joints, const Scenario* sc = nullptr);
  PlotWriter(const PlotWriter&) = delete;
  PlotWriter& operator=(const PlotWriter&) = delete;
  /// One row; throws InputError when it cannot be written (a full disk) at once.
  void add(const MotionSample& s);
  std::size_t rows() const { return rows_; }
  /// \brief Closes the data file and draws the rows with gnuplot; throws InputError if gnuplot
  /// fails, if the script cannot be written or no row was added. `torques`: draw the joint torques
  /// too. `capture_time` (finite): a vertical line marks the capture on every panel. With samples
  /// of the approach, a panel shows the hand-to-grasp distance.
  void draw(const std::string& title, bool torques, double capture_time = std::numeric_limits<double>::quiet_NaN());

 private:
  const AtomicFile& out_;
  std::vector<std::string> joints_;
  ScratchFile data_;
  std::ofstream d_;
  std::size_t rows_ = 0;
  double t_first_ = 0.0, t_last_ = 0.0;
  bool distance_ = false;  ///< an approach: its distance to the grasp point
  // The first sample of the phase: what its balance is measured from.
  Phase phase0_ = Phase::Post;
  Vector6d h0_ = Vector6d::Zero();
  double T0_ = 0.0;
  // What the scenario adds (plotScenario): by sample joint, its PD servo's set point (NaN: `hold`,
  // the joint's position where the servo's phase begins), none for a joint without a servo.
  std::vector<std::optional<double>> set_points_;
  std::vector<double> held_;  ///< the set points in force (NaN before the servo's phase)
  bool servos_ = false, base_torque_ = false, base_force_ = false;
};

/// The plot of samples held in memory (an approach that never reached its grasp), through PlotWriter.
void writePlot(const AtomicFile& out, const std::vector<MotionSample>& samples, const std::vector<std::string>& joints,
               const std::string& title, bool torques,
               double capture_time = std::numeric_limits<double>::quiet_NaN());

}  // namespace kdl_space::report
