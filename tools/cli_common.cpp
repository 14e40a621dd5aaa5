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

#include "spatial/message_text.hpp"

namespace kdl_space::cli {

void writeTextFile(const std::string& path, const std::string& option, const std::string& text) {
  AtomicFile file(path, option);
  errno = 0;
  std::ofstream f(file.tmp(), std::ios::binary);
  f << text;
  f.close();
  if (!f) throw InputError(option + " " + path + ": cannot write the file: " + writeFailure());
  file.commit();
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

CLI::Option* addMeshPathOption(CLI::App* cmd, std::vector<std::string>& dirs) {
  const CLI::Validator folder(
      [](std::string& dir) {
        std::error_code ec;
        return std::filesystem::is_directory(dir, ec) ? std::string() : dir + " is not a folder (give the folder that holds the package folders)";
      },
      "");
  return cmd->add_option("--mesh-path", dirs,
                         "A folder where the URDF's package://PACKAGE/... meshes are looked for (as DIR/PACKAGE/..., or "
                         "DIR/... when DIR is named PACKAGE); repeatable, searched in order before ROS_PACKAGE_PATH")
      ->type_name("DIR")->check(folder)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
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

void stopIfInterrupted(const std::string& where) {
  if (interrupt_flag.load()) throw Interrupted(where + "; no output written");
}

void printWarnings(std::ostream& out, const std::vector<Diagnostic>& warnings) {
  for (const Diagnostic& d : warnings)
    out << "Warning: " << (d.element.empty() ? "" : d.element + ": ") << d.message << "\n";
}

void warnOnStderr(const std::vector<Diagnostic>& warnings) {
  for (const Diagnostic& d : warnings)
    std::cerr << "kdl_space: warning: " << (d.element.empty() ? "" : d.element + ": ") << d.message << "\n";
}

}  // namespace kdl_space::cli
