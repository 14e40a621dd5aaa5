// Shared pieces of the kdl_space command-line tool: exit codes, errors, printing helpers.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <nlohmann/json.hpp>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "kdl_space/multibody/model.hpp"
#include "kdl_space/multibody/diagnostics.hpp"
#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/parsers/input_file.hpp"  // checkInputFile, parseFiniteNumber
#include "kdl_space/report/json.hpp"
#include "kdl_space/parsers/output_file.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/parsers/scenario/scenario_errors.hpp"

namespace CLI {
class App;
class Option;
class Validator;
}

namespace kdl_space::cli {

/// \brief Writes `text` to `path` whole or not at all (AtomicFile); InputError naming `option` when
/// it cannot. The caller has refused an input as `path` (refuseOverwritingInputs).
void writeTextFile(const std::string& path, const std::string& option, const std::string& text);

/// Exit codes of every subcommand (kInterrupted: 128 + SIGINT, as a shell reports Ctrl-C).
enum Exit : int { kOk = 0, kUsage = 2, kUnusable = 3, kInterrupted = 130 };

/// \brief Ctrl-C (SIGINT) and SIGTERM set interruptFlag(), which the long runs poll (a study
/// between samples, a simulation between steps) to stop within a fraction of a second and leave
/// what they promised; a second signal ends the process at once (the default action). Installed
/// once by main().
void installInterruptHandler();
/// True once SIGINT or SIGTERM has arrived (lock-free: safe to set from a signal handler).
const std::atomic<bool>& interruptFlag();
/// A run stopped by interruptFlag(): main() prints its message and exits kInterrupted.
struct Interrupted : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// \brief Throws Interrupted(`where` + "; no output written") once interruptFlag() is set: the
/// commands without a long loop of their own (check, inspect, capture) poll it between their steps
/// and before they write anything.
void stopIfInterrupted(const std::string& where);

// The report layer (JSON, output files, the writers) by its names: the shell calls it.
using namespace kdl_space::report;
/// A command-line mistake (exit 2): the report layer's, which refuses an output that would
/// replace an input.


/// A model or an input that cannot be used (exit 3): the library's, which the scenario loader
/// and the capture throw too.
using InputError = kdl_space::InputError;

/// Smallest output width the text reports are laid out for.
constexpr std::size_t kMinOutputWidth = 40;
/// Width used when COLUMNS is not set or not a number.
constexpr std::size_t kDefaultOutputWidth = 100;

/// The width, in characters, the text reports fit: the COLUMNS environment variable when it is
/// set and a decimal number (at least kMinOutputWidth), else kDefaultOutputWidth.
std::size_t outputWidth();

/// \brief Prints `text` word-wrapped to `width` characters, breaking only at spaces: each line
/// of `text` after `first_indent`, its continuation lines after `indent`. A word longer than a
/// line is never cut (its line is longer than `width`).
void printWrapped(std::ostream& os, const std::string& text, std::size_t width, const std::string& first_indent = "",
                  const std::string& indent = "    ");

/// \brief Prints `title`, then one row per matrix row with its label, columns headed by
/// `col_labels`, every line at most `width` characters.
///
/// A matrix wider than `width` is printed in blocks of columns, each headed by the full labels
/// of its columns ("columns i to j of n" before each block); rows keep their labels in every
/// block. Labels are never cut: when a column label is longer than a number (13 characters),
/// each column's label gets a header line of its own, ending above its column (the row-label
/// field widens so that the first column's label fits). Only a label longer than the whole
/// width makes a line longer than `width`.
void printMatrix(std::ostream& os, const std::string& title, const Eigen::MatrixXd& m,
                 const std::vector<std::string>& row_labels, const std::vector<std::string>& col_labels,
                 std::size_t width = outputWidth());

/// \brief The model's diagnostics the user still needs: without the "limits exclude 0" warning
/// (finding `limits_exclude_zero`) of a joint in `given_joints`, whose position the user gave
/// (that warning is about joints left at 0).
std::vector<Diagnostic> diagnosticsForGivenJoints(const std::vector<Diagnostic>& diagnostics,
                                                  const std::vector<std::string>& given_joints);

/// Parses "NAME=VALUE"; throws UsageError naming `option` if malformed.
std::pair<std::string, double> parseAssignment(const std::string& text, const std::string& option);

/// CLI11 validators with messages a user can act on (CLI11's own Range prints 300-digit bounds).
CLI::Validator finiteNumber();   ///< any finite number
CLI::Validator positiveNumber(); ///< a finite number > 0

/// \brief `--mesh-path DIR` (repeatable) on a subcommand that writes a page: folders where a
/// URDF's package:// meshes are looked for (DIR/PACKAGE/..., or DIR itself when it is named
/// PACKAGE), before ROS_PACKAGE_PATH's. A DIR that is not a folder is a usage error.
CLI::Option* addMeshPathOption(CLI::App* cmd, std::vector<std::string>& dirs);


/// \brief Runs `f` (a library call on the scenario's capture problem); an Error it throws
/// ("target: ...") comes back of the same kind with the scenario's file in front ("FILE: target:
/// ...").
template <typename F>
auto inScenario(const Scenario& scenario, F&& f) -> decltype(f()) {
  return inScenarioFile(scenario, std::forward<F>(f));
}

/// One line "Warning: ELEMENT: MESSAGE" per warning (the text reports' form of a warning).
void printWarnings(std::ostream& out, const std::vector<Diagnostic>& warnings);
/// \brief One line "kdl_space: warning: ELEMENT: MESSAGE" per warning on stderr (the text runs'
/// warnings, and an approach's start warnings before it runs, which a failed run shows no other way).
void warnOnStderr(const std::vector<Diagnostic>& warnings);


}  // namespace kdl_space::cli
