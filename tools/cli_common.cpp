#include "cli_common.hpp"

#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>

#include "detail/text.hpp"

namespace kdl_space::cli {

Json fixedJointsJson(const FloatingModel& model) {
  Json list = Json::array();
  for (const FixedJoint& f : model.fixedJoints()) list.push_back(Json{{"joint", f.joint}, {"reason", f.reason}});
  return list;
}

Json toJson(const Eigen::MatrixXd& m) {
  Json rows = Json::array();
  if (m.cols() == 1) {
    for (Eigen::Index i = 0; i < m.rows(); ++i) rows.push_back(m(i, 0));
    return rows;
  }
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    Json row = Json::array();
    for (Eigen::Index j = 0; j < m.cols(); ++j) row.push_back(m(i, j));
    rows.push_back(row);
  }
  return rows;
}

const std::vector<std::string>& twistLabels() {
  static const std::vector<std::string> labels{"vx", "vy", "vz", "wx", "wy", "wz"};
  return labels;
}

void printMatrix(std::ostream& os, const std::string& title, const Eigen::MatrixXd& m,
                 const std::vector<std::string>& row_labels, const std::vector<std::string>& col_labels) {
  std::size_t width = 4;
  for (const auto& l : row_labels) width = std::max(width, l.size());
  os << title << "\n";
  if (m.size() == 0) {
    os << "  (empty)\n";
    return;
  }
  os << "  " << std::setw(static_cast<int>(width)) << "";
  for (const auto& c : col_labels) os << " " << std::setw(13) << c.substr(0, 13);
  os << "\n";
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    os << "  " << std::left << std::setw(static_cast<int>(width)) << row_labels.at(i) << std::right;
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      os << " " << std::setw(13) << std::setprecision(6) << std::scientific << m(i, j);
    os << std::defaultfloat << "\n";
  }
}

std::pair<std::string, double> parseAssignment(const std::string& text, const std::string& option) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw UsageError(option + " expects NAME=VALUE, got '" + text + "'");
  const std::string name = text.substr(0, eq), value = text.substr(eq + 1);
  double v = 0.0;
  std::string why;
  if (!parseFiniteNumber(value, v, why)) throw UsageError(option + " " + name + ": " + why);
  return {name, v};
}

CLI::Validator finiteNumber() {
  return CLI::Validator(
      [](std::string& text) {
        double v;
        std::string why;
        return parseFiniteNumber(text, v, why) ? std::string() : why;
      },
      "", "finite number");
}

CLI::Validator positiveNumber() {
  return CLI::Validator(
      [](std::string& text) {
        double v;
        std::string why;
        if (!parseFiniteNumber(text, v, why)) return why;
        return v > 0.0 ? std::string() : "'" + text + "' is not > 0";
      },
      "", "positive number");
}

namespace {
namespace fs = std::filesystem;
using detail::quoted;
}  // namespace

void checkOutputFile(const std::string& path, const std::string& option) {
  const std::string where = option + " " + path + ": ";
  if (path.empty()) throw UsageError(option + ": the file name is empty");
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(where + "is a folder; give a file name");
  // The finished file is renamed over the name: that would replace a device such as /dev/null.
  if (fs::exists(path, ec) && !fs::is_regular_file(path, ec))
    throw InputError(where + "exists and is not a regular file; give the name of a file");
  fs::path folder = fs::path(path).parent_path();
  if (folder.empty()) folder = ".";
  const fs::file_status status = fs::status(folder, ec);
  if (ec || !fs::exists(status)) throw InputError(where + "the folder " + quoted(folder.string()) + " does not exist");
  if (!fs::is_directory(status)) throw InputError(where + quoted(folder.string()) + " is not a folder");
  // Whether a file can be created there is known only by creating one (access() says yes to
  // root on a read-only /sys).
  const fs::path probe = folder / ("." + fs::path(path).filename().string() + ".probe" + std::to_string(getpid()));
  const int fd = open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
  if (fd < 0)
    throw InputError(where + "cannot create a file in the folder " + quoted(folder.string()) + ": " + std::strerror(errno));
  close(fd);
  unlink(probe.c_str());
}

AtomicFile::AtomicFile(std::string path, std::string option)
    : path_(std::move(path)), option_(std::move(option)) {
  // Same folder (the rename is atomic there), a name that says what it is.
  const fs::path p(path_);
  tmp_ = (p.parent_path() / ("." + p.filename().string() + ".tmp" + std::to_string(getpid()))).string();
}

AtomicFile::~AtomicFile() {
  if (!committed_) std::remove(tmp_.c_str());
}

void AtomicFile::commit() {
  std::error_code ec;
  fs::rename(tmp_, path_, ec);
  if (ec) throw InputError(option_ + " " + path_ + ": cannot write: " + ec.message());
  committed_ = true;
}

void AtomicFile::retract() {
  if (committed_) std::remove(path_.c_str());
}

}  // namespace kdl_space::cli
