// Shared pieces of the kdl_space command-line tool: exit codes, errors, printing helpers.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace kdl_space::cli {

/// Exit codes of every subcommand.
enum Exit : int { kOk = 0, kUsage = 2, kUnusable = 3 };

/// A command-line mistake (exit 2).
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// A model or an input that cannot be used (exit 3).
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

using Json = nlohmann::ordered_json;

/// A matrix as a JSON array of rows; a column vector as a flat array.
Json toJson(const Eigen::MatrixXd& m);

/// Row labels of a twist or wrench: vx vy vz wx wy wz.
const std::vector<std::string>& twistLabels();

/// Prints `title`, then one row per matrix row with its label, columns headed by `col_labels`.
void printMatrix(std::ostream& os, const std::string& title, const Eigen::MatrixXd& m,
                 const std::vector<std::string>& row_labels, const std::vector<std::string>& col_labels);

/// Parses "NAME=VALUE"; throws UsageError naming `option` if malformed.
std::pair<std::string, double> parseAssignment(const std::string& text, const std::string& option);

}  // namespace kdl_space::cli
