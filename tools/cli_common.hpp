// Shared pieces of the kdl_space command-line tool: exit codes, errors, printing helpers.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "kdl_space/model.hpp"
#include "kdl_space/errors.hpp"
#include "kdl_space/input_file.hpp"  // checkInputFile, parseFiniteNumber

namespace CLI {
class Validator;
}

namespace kdl_space::cli {

/// Exit codes of every subcommand.
enum Exit : int { kOk = 0, kUsage = 2, kUnusable = 3 };

/// A command-line mistake (exit 2).
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// A model or an input that cannot be used (exit 3): the library's, which the scenario loader
/// and the capture throw too.
using InputError = kdl_space::InputError;

using Json = nlohmann::ordered_json;

/// A matrix as a JSON array of rows; a column vector as a flat array.
Json toJson(const Eigen::MatrixXd& m);

/// The joints of the description that are not coordinates: [{"joint", "reason"}] (JSON key
/// `joints_treated_as_fixed` beside every `joint_names`).
Json fixedJointsJson(const FloatingModel& model);

/// Row labels of a twist or wrench: vx vy vz wx wy wz.
const std::vector<std::string>& twistLabels();

/// Prints `title`, then one row per matrix row with its label, columns headed by `col_labels`.
void printMatrix(std::ostream& os, const std::string& title, const Eigen::MatrixXd& m,
                 const std::vector<std::string>& row_labels, const std::vector<std::string>& col_labels);

/// Parses "NAME=VALUE"; throws UsageError naming `option` if malformed.
std::pair<std::string, double> parseAssignment(const std::string& text, const std::string& option);

/// CLI11 validators with messages a user can act on (CLI11's own Range prints 300-digit bounds).
CLI::Validator finiteNumber();   ///< any finite number
CLI::Validator positiveNumber(); ///< a finite number > 0

/// \brief Refuses, before any work, an output file that could not be written: its folder is
/// missing, not a folder or not writable, or the path is a folder. Throws InputError naming the
/// option (e.g. "--csv run.csv: the folder 'out' does not exist").
void checkOutputFile(const std::string& path, const std::string& option);

/// \brief A file written under a temporary name in the same folder and renamed into place by
/// commit(), so that a failed run never leaves a partial file that looks complete; the temporary
/// is removed if the object is destroyed without a commit.
class AtomicFile {
 public:
  /// `option` names the file in messages (e.g. "--csv").
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
