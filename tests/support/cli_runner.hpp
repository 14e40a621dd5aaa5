// Runs the kdl_space tool as a user would and captures what it says.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace kdl_space::test {

struct ToolRun {
  int rc;
  std::string out, err;
};

/// Runs the tool with `args` (already shell-quoted where needed).
inline ToolRun kdlSpace(const std::string& args) {
  // One file per process: ctest runs tests in parallel.
  const std::string err_file = ::testing::TempDir() + "kdl_space_stderr_" + std::to_string(getpid()) + ".txt";
  const std::string cmd = std::string(KDL_SPACE_CLI) + " " + args + " 2>" + err_file;
  FILE* pipe = popen(cmd.c_str(), "r");
  std::string out;
  char buffer[4096];
  while (std::size_t n = fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
  const int status = pclose(pipe);
  std::ifstream e(err_file);
  std::stringstream err;
  err << e.rdbuf();
  std::remove(err_file.c_str());
  return {WEXITSTATUS(status), out, err.str()};
}

/// A path `name` in a folder of this test process (ctest runs tests in parallel processes): the
/// folder `tag`_PID under gtest's temporary folder, created.
inline std::string scratchIn(const std::string& tag, const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / (tag + "_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

/// A file's bytes ("" when it cannot be read).
inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Writes `text` to `path` as it is (no newline conversion).
inline void spit(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

}  // namespace kdl_space::test
