#include "cli_common.hpp"

#include <csignal>

#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

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

Json toJsonRows(const Eigen::MatrixXd& m) {
  Json rows = Json::array();
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

std::size_t outputWidth() {
  const char* columns = std::getenv("COLUMNS");
  if (columns == nullptr || *columns == '\0') return kDefaultOutputWidth;
  const std::string text(columns);
  for (char c : text)
    if (c < '0' || c > '9') return kDefaultOutputWidth;
  // More digits than any terminal has columns: as wide as asked, without overflowing.
  const std::size_t width = text.size() > 6 ? 999999 : std::stoul(text);
  return std::max(width, kMinOutputWidth);
}

void printWrapped(std::ostream& os, const std::string& text, std::size_t width, const std::string& first_indent,
                  const std::string& indent) {
  std::istringstream paragraphs(text);
  for (std::string paragraph; std::getline(paragraphs, paragraph);) {
    // Words between single spaces (an empty one for each further space: a file name keeps its
    // spaces); a line breaks at a space, which it drops.
    std::string line = first_indent;
    bool has_word = false;
    std::istringstream words(paragraph);
    for (std::string word; std::getline(words, word, ' ');) {
      if (has_word && line.size() + 1 + word.size() > width) {
        os << line << "\n";
        line = indent;
        has_word = false;
      }
      line += (has_word ? " " : "") + word;
      has_word = true;
    }
    os << (has_word ? line : std::string()) << "\n";
  }
}

void printMatrix(std::ostream& os, const std::string& title, const Eigen::MatrixXd& m,
                 const std::vector<std::string>& row_labels, const std::vector<std::string>& col_labels,
                 std::size_t width) {
  constexpr std::size_t kIndent = 2;         // before the row label
  constexpr std::size_t kNumber = 13;        // -1.234567e+00
  constexpr std::size_t kStep = kNumber + 1; // a space, then the number
  width = std::max(width, kMinOutputWidth);
  printWrapped(os, title, width, "", "  ");
  if (m.size() == 0) {
    os << "  (empty)\n";
    return;
  }
  std::size_t label_width = 4, longest_column = 0;
  for (const auto& l : row_labels) label_width = std::max(label_width, l.size());
  for (const auto& c : col_labels) longest_column = std::max(longest_column, c.size());
  // A column label that does not fit over its number stands on a header line of its own, ending
  // above its column: the first column's must fit after the row-label field.
  if (longest_column > kNumber && longest_column > kIndent + kStep)
    label_width = std::max(label_width, longest_column - kIndent - kStep);
  const std::size_t fixed = kIndent + label_width;
  const std::size_t n = static_cast<std::size_t>(m.cols());
  std::size_t per_block = width > fixed + kStep ? (width - fixed) / kStep : 1;
  const std::size_t blocks = (n + per_block - 1) / per_block;
  per_block = (n + blocks - 1) / blocks;  // blocks of even size: 7 columns as 4 + 3, not 6 + 1

  const std::ios::fmtflags flags = os.flags();
  const std::streamsize precision = os.precision();
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::size_t first = b * per_block, last = std::min(n, first + per_block);
    if (blocks > 1) os << (b ? "\n" : "") << "  columns " << first + 1 << " to " << last << " of " << n << "\n";
    bool short_labels = true;
    for (std::size_t j = first; j < last; ++j) short_labels &= col_labels.at(j).size() <= kNumber;
    if (short_labels) {
      os << std::string(fixed, ' ');
      for (std::size_t j = first; j < last; ++j) os << " " << std::setw(static_cast<int>(kNumber)) << col_labels[j];
      os << "\n";
    } else {
      for (std::size_t j = first; j < last; ++j) {
        const std::size_t end = fixed + (j - first + 1) * kStep;
        const std::string& label = col_labels[j];
        os << std::string(end > label.size() ? end - label.size() : 0, ' ') << label << "\n";
      }
    }
    for (Eigen::Index i = 0; i < m.rows(); ++i) {
      os << std::string(kIndent, ' ') << std::left << std::setw(static_cast<int>(label_width)) << row_labels.at(i)
         << std::right << std::scientific << std::setprecision(6);
      for (std::size_t j = first; j < last; ++j)
        os << " " << std::setw(static_cast<int>(kNumber)) << m(i, static_cast<Eigen::Index>(j));
      os.flags(flags);
      os.precision(precision);
      os << "\n";
    }
  }
}

std::vector<Diagnostic> diagnosticsForGivenJoints(const std::vector<Diagnostic>& diagnostics,
                                                  const std::vector<std::string>& given_joints) {
  std::vector<Diagnostic> kept;
  for (const Diagnostic& d : diagnostics) {
    const bool given = std::find(given_joints.begin(), given_joints.end(), d.element) != given_joints.end();
    if (given && d.kind == "limits_exclude_zero") continue;
    kept.push_back(d);
  }
  return kept;
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
  unlink(createFreshFile(folder.string(), "." + fs::path(path).filename().string() + ".probe", where).c_str());
}

namespace {
/// The process's file mode creation mask, read without changing it (/proc/self/status; umask()
/// would set it, racing other threads); 022 when it cannot be read.
mode_t processUmask() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("Umask:", 0) == 0) return static_cast<mode_t>(std::strtoul(line.c_str() + 6, nullptr, 8));
  return 022;
}
}  // namespace

std::string createFreshFile(const std::string& folder, const std::string& stem, const std::string& where, int* fd) {
  std::string name = (fs::path(folder.empty() ? "." : folder) / (stem + std::to_string(getpid()) + "-XXXXXX")).string();
  const int created = mkostemp(name.data(), O_CLOEXEC);  // O_CREAT | O_EXCL, mode 0600
  if (created < 0)
    throw InputError(where + "cannot create a file in the folder " + quoted(folder.empty() ? "." : folder) + ": " +
                     std::strerror(errno));
  fchmod(created, 0666 & ~processUmask());  // the mode any new file of the user's gets (0644 by default)
  if (fd) *fd = created;
  else close(created);
  return name;
}

void refuseOverwritingInputs(const std::string& option, const std::string& path, const std::vector<InputFile>& inputs) {
  if (path.empty()) return;
  std::error_code ec;
  const fs::path out = fs::weakly_canonical(path, ec);
  for (const InputFile& in : inputs) {
    if (in.path.empty()) continue;
    std::error_code e1, e2;
    const bool same_name = !ec && fs::weakly_canonical(in.path, e1) == out && !e1;
    if (same_name || fs::equivalent(path, in.path, e2))
      throw UsageError(option + " " + path + ": is " + in.what + (in.path == path ? "" : " " + in.path) +
                       "; it would be overwritten: give the output another name");
  }
}

namespace {
std::atomic<bool> interrupt_flag{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the flag is set from a signal handler");

extern "C" void onInterrupt(int signal) {
  interrupt_flag.store(true);
  std::signal(signal, SIG_DFL);  // a second Ctrl-C ends the process at once
}
}  // namespace

void installInterruptHandler() {
  std::signal(SIGINT, onInterrupt);
  std::signal(SIGTERM, onInterrupt);
}

const std::atomic<bool>& interruptFlag() { return interrupt_flag; }

std::string writeFailure() { return errno ? std::string(std::strerror(errno)) : std::string("disk full?"); }

void stopIfInterrupted(const std::string& where) {
  if (interrupt_flag.load()) throw Interrupted(where + "; no output written");
}

AtomicFile::AtomicFile(std::string path, std::string option)
    : path_(std::move(path)), option_(std::move(option)) {
  // Same folder (the rename is atomic there), a name that says what it is and that no one can
  // plant a link at beforehand.
  const fs::path p(path_);
  tmp_ = createFreshFile(p.parent_path().string(), "." + p.filename().string() + ".tmp", option_ + " " + path_ + ": ");
}

AtomicFile::~AtomicFile() {
  if (!committed_) std::remove(tmp_.c_str());
}

namespace {
/// Flushes a file or a folder to the disk (best effort where the file system cannot: EINVAL).
bool syncPath(const std::string& path, int flags) {
  const int fd = open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = fsync(fd) == 0 || errno == EINVAL || errno == EROFS;
  close(fd);
  return ok;
}
}  // namespace

void AtomicFile::commit() {
  // The data on the disk before the name: a crash (power, kernel) after the rename never leaves a
  // file that has its name but not its bytes. Then the folder, so that the rename itself lasts.
  if (!syncPath(tmp_, O_RDONLY))
    throw InputError(option_ + " " + path_ + ": cannot write (fsync): " + std::strerror(errno));
  std::error_code ec;
  fs::rename(tmp_, path_, ec);
  if (ec) throw InputError(option_ + " " + path_ + ": cannot write: " + ec.message());
  committed_ = true;
  const fs::path folder = fs::path(path_).parent_path();
  syncPath(folder.empty() ? "." : folder.string(), O_RDONLY | O_DIRECTORY);
}

void AtomicFile::retract() {
  if (committed_) std::remove(path_.c_str());
}

}  // namespace kdl_space::cli
