// Runs the kdl_space tool as a user would and captures what it says.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
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

}  // namespace kdl_space::test
