// What the gnuplot writers of the tool (plot_writer, scene_writer) share: scratch files that
// remove themselves, texts quoted for gnuplot's scripts, and gnuplot run on a script.
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "kdl_space/report/json.hpp"
#include "kdl_space/parsers/output_file.hpp"

namespace kdl_space::report {

/// A scratch file removed when it goes out of scope (gnuplot's data, script and log), beside an
/// AtomicFile's fresh temporary (its name + ".dat", ".gp"): created empty at once, exclusively
/// (O_EXCL | O_NOFOLLOW: a link planted at the name is refused, never followed).
class ScratchFile {
 public:
  explicit ScratchFile(std::string path) : path_(std::move(path)) {
    const int fd = open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (fd < 0) {
      const std::string why = "cannot create the scratch file " + path_ + ": " + std::strerror(errno);
      path_.clear();  // not ours: never removed
      throw InputError(why);
    }
    close(fd);
  }
  ~ScratchFile() {
    if (!path_.empty()) std::remove(path_.c_str());
  }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// A text in gnuplot's single quotes (a quote inside doubled).
inline std::string gnuplotQuoted(const std::string& p) {
  std::string q = "'";
  for (char c : p) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

/// A label for gnuplot's enhanced text: '_', '^' and the like printed as themselves.
inline std::string gnuplotLabel(const std::string& text) {
  std::string escaped;
  for (char c : text)
    escaped += (c == '_' || c == '^' || c == '{' || c == '}' || c == '@' || c == '&') ? std::string("\\") + c
                                                                                      : std::string(1, c);
  return gnuplotQuoted(escaped);
}

/// \brief Runs gnuplot on `script`, which draws into `output`; throws InputError "WHERE gnuplot
/// failed: its log" if gnuplot fails or draws nothing (`where` names the output: "--plot FILE: ").
inline void runGnuplot(const std::string& script, const std::string& output, const std::string& where) {
  const ScratchFile log(script + ".log");
  const int rc = std::system(("gnuplot " + gnuplotQuoted(script) + " >" + gnuplotQuoted(log.path()) + " 2>&1").c_str());
  std::ifstream l(log.path());
  std::stringstream why;
  why << l.rdbuf();
  std::error_code ec;
  if (rc != 0 || !std::filesystem::is_regular_file(output, ec) || std::filesystem::file_size(output, ec) == 0)
    throw InputError(where + "gnuplot failed" + (why.str().empty() ? std::string() : ": " + why.str()));
}

}  // namespace kdl_space::report
