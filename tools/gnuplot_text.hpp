// What the gnuplot writers of the tool (plot_writer, scene_writer) share: scratch files that
// remove themselves, and texts quoted for gnuplot's scripts.
#pragma once

#include <cstdio>
#include <string>

namespace kdl_space::cli {

/// A scratch file removed when it goes out of scope (gnuplot's data, script and log).
class ScratchFile {
 public:
  explicit ScratchFile(std::string path) : path_(std::move(path)) {}
  ~ScratchFile() { std::remove(path_.c_str()); }
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

}  // namespace kdl_space::cli
