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

namespace CLI {
class Validator;
}

namespace kdl_space::cli {

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
/// \brief Why the last write failed, for a message: the system's reason (strerror(errno): "No
/// space left on device"), or "disk full?" when the stream kept none.
std::string writeFailure();

/// \brief Throws Interrupted(`where` + "; no output written") once interruptFlag() is set: the
/// commands without a long loop of their own (check, inspect, capture) poll it between their steps
/// and before they write anything.
void stopIfInterrupted(const std::string& where);

/// A command-line mistake (exit 2).
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// A model or an input that cannot be used (exit 3): the library's, which the scenario loader
/// and the capture throw too.
using InputError = kdl_space::InputError;

using Json = nlohmann::ordered_json;

/// \brief A JSON document as text (`indent` -1: one line). Whatever bytes a string holds are
/// written: control characters escaped (`\u001b`), bytes that are not UTF-8 replaced by U+FFFD,
/// never an exception at the end of a run (nlohmann's default throws type_error 316).
inline std::string jsonText(const Json& j, int indent = -1) {
  return j.dump(indent, ' ', false, Json::error_handler_t::replace);
}

/// A matrix as a JSON array of rows; a column vector as a flat array.
Json toJson(const Eigen::MatrixXd& m);

/// The joints of the description that are not coordinates: [{"joint", "reason"}] (JSON key
/// `joints_treated_as_fixed` beside every `joint_names`).
Json fixedJointsJson(const FloatingModel& model);
/// A matrix as a JSON array of rows, always: an r x c matrix is r arrays of c numbers, a column
/// (c = 1) included (for matrices whose column count is the number of joints: J*, H*).
Json toJsonRows(const Eigen::MatrixXd& m);

/// Row labels of a twist or wrench: vx vy vz wx wy wz.
const std::vector<std::string>& twistLabels();

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

/// \brief Refuses, before any work, an output file that could not be written: its folder is
/// missing, not a folder or not writable, or the path is a folder. Throws InputError naming the
/// option (e.g. "--csv run.csv: the folder 'out' does not exist").
void checkOutputFile(const std::string& path, const std::string& option);

/// A file a run reads, with what it is for messages ("the scenario file", "the robot's URDF").
struct InputFile {
  std::string what, path;
};

/// \brief No output replaces an input: throws UsageError (exit 2, before any work) when the output
/// `path` of `option` is one of `inputs`, by canonical path or as the same file (device and inode:
/// a hard or symbolic link to it), naming both ("--csv a.urdf: is the robot's URDF
/// robots/a.urdf; it would be overwritten").
void refuseOverwritingInputs(const std::string& option, const std::string& path, const std::vector<InputFile>& inputs);

/// \brief Creates a new empty file `folder`/`stem`PID-XXXXXX (six random characters), exclusively
/// (O_CREAT | O_EXCL: an existing name, a planted symbolic link included, is never opened or
/// followed; mkostemp draws another), mode 0600, and returns its path; `fd`, if given, receives
/// the open descriptor (else it is closed). The PID in the name lets a later run remove the
/// temporaries of runs that are gone (removeStaleTemporaries). Throws InputError `where` +
/// "cannot create a file in the folder ...: REASON".
std::string createFreshFile(const std::string& folder, const std::string& stem, const std::string& where,
                            int* fd = nullptr);

/// \brief A file written under a fresh temporary name in the same folder (createFreshFile: created
/// at construction, unpredictable, never through a link someone planted) and renamed into place by
/// commit(), so that a failed run never leaves a partial file that looks complete; the temporary
/// is removed if the object is destroyed without a commit.
class AtomicFile {
 public:
  /// `option` names the file in messages (e.g. "--csv"). Creates the temporary `.NAME.tmpPID-XXXXXX`
  /// beside `path`; throws InputError if it cannot.
  AtomicFile(std::string path, std::string option);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  const std::string& path() const { return path_; }
  const std::string& tmp() const { return tmp_; }
  /// Renames the temporary to the final name; throws InputError if that fails.
  void commit();
  /// Removes the final file after a commit (a later output failed); best effort.
  void retract();

 private:
  std::string path_, option_, tmp_;
  bool committed_ = false;
};

}  // namespace kdl_space::cli
