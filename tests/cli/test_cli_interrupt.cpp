// Ctrl-C in every command (issue 35, item 6): ik, check, inspect and capture poll the flag the
// handler sets (as simulate and study do), exit 130 with "interrupted" on stderr, and write
// nothing: no stdout, no output file.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "cli_runner.hpp"

namespace kdl_space::test {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

/// A tree of `links` links (20 arms of revolute joints from a heavy base), written once.
std::string bigRobot(int links) {
  const std::string path = scratchIn("kdl_space_interrupt", "tree" + std::to_string(links) + ".urdf");
  if (fs::exists(path)) return path;
  std::ostringstream x;
  const auto link = [&](const std::string& name, double mass) {
    x << "<link name=\"" << name << "\"><inertial><mass value=\"" << mass
      << "\"/><inertia ixx=\"0.01\" iyy=\"0.01\" izz=\"0.01\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>\n";
  };
  x << "<robot name=\"tree\">\n";
  link("base", 100.0);
  const int arm = links / 20;
  for (int i = 1; i < links; ++i) {
    link("l" + std::to_string(i), 1.0);
    const std::string parent = i % arm == 1 ? "base" : "l" + std::to_string(i - 1);
    x << "<joint name=\"j" << i << "\" type=\"revolute\"><parent link=\"" << parent << "\"/><child link=\"l" << i
      << "\"/><origin xyz=\"0.1 0 0\" rpy=\"0 0 " << 0.3 * (i % arm == 1 ? i / arm : 0)
      << "\"/><axis xyz=\"0 " << (i % 2) << " " << (1 - i % 2)
      << "\"/><limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/></joint>\n";
  }
  x << "</robot>\n";
  spit(path, x.str());
  return path;
}

struct Stopped {
  int status = 0;
  double latency = 0.0;
  std::string out, err;
};

/// True once process `pid` is the tool (the shell has exec'd it) and catches SIGINT (its handler
/// is installed: /proc's SigCgt mask; the shell catches it too).
bool catchesSigint(pid_t pid) {
  std::ifstream comm("/proc/" + std::to_string(pid) + "/comm");
  std::string name;
  if (!std::getline(comm, name) || name != "kdl_space") return false;
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("SigCgt:", 0) == 0) return (std::stoull(line.substr(7), nullptr, 16) >> (SIGINT - 1)) & 1u;
  return false;
}

/// Starts the tool with `args` (stdout and stderr to files), sends SIGINT `after` s after its
/// handler is installed (right after the command line is parsed), and waits for it. The shell
/// `exec`s the tool: the PID is the tool's.
Stopped interruptAfter(const std::string& args, double after) {
  const std::string out = scratchIn("kdl_space_interrupt", "out.txt"), err = scratchIn("kdl_space_interrupt", "err.txt");
  const pid_t pid = fork();
  if (pid == 0) {
    const std::string command = "exec " + std::string(KDL_SPACE_CLI) + " " + args + " >" + out + " 2>" + err;
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  for (int k = 0; k < 20000 && !catchesSigint(pid); ++k) std::this_thread::sleep_for(std::chrono::microseconds(500));
  std::this_thread::sleep_for(std::chrono::duration<double>(after));
  Stopped s;
  if (waitpid(pid, &s.status, WNOHANG) == pid) return s;  // done before the signal: latency 0, status as is
  const auto signalled = Clock::now();
  kill(pid, SIGINT);
  waitpid(pid, &s.status, 0);
  s.latency = std::chrono::duration<double>(Clock::now() - signalled).count();
  s.out = slurp(out);
  s.err = slurp(err);
  return s;
}

void expectInterrupted(const Stopped& s, const std::string& what) {
  ASSERT_TRUE(WIFEXITED(s.status)) << what << ": ended by the signal itself, not by the tool";
  EXPECT_EQ(WEXITSTATUS(s.status), 130) << what << ": " << s.err;
  EXPECT_NE(s.err.find("kdl_space: interrupted: "), std::string::npos) << what << ": " << s.err;
  EXPECT_EQ(s.out, "") << what << ": no output";
}

TEST(Interrupt, IkStopsWithinASecond) {
  // Out of reach with 1,000 restarts: 18 s of work; stopped between two iterations.
  const std::string scenario = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/tumbling_box_capture.yaml";
  const Stopped s = interruptAfter("ik " + scenario + " --position 50,0,0 --restarts 1000 --json", 1.0);
  expectInterrupted(s, "ik");
  EXPECT_LT(s.latency, 1.0);
  EXPECT_NE(s.err.find("inverse kinematics: cancelled after "), std::string::npos) << s.err;
}

TEST(Interrupt, CheckInspectAndCaptureStopBeforeTheyWrite) {
  // A robot large enough that each command runs past the signal (sent as it works).
  const std::string urdf = bigRobot(1500);
  const std::string scenario = scratchIn("kdl_space_interrupt", "capture.yaml");
  spit(scenario, "robot:\n  urdf: " + urdf + "\n  contact: {link: l74}\n  mode: free\n"
                 "target:\n  mass: 50\n  inertia: [[2, 0, 0], [0, 2, 0], [0, 0, 2]]\n"
                 "  pose: {position: [30, 0, 0], rpy: [0, 0, 0]}\n  twist: [-0.1, 0, 0, 0, 0, 0]\n"
                 "law:\n  type: capture\n");
  const std::string page = scratchIn("kdl_space_interrupt", "capture.html");
  struct Case {
    std::string what, args;
  };
  for (const Case& c : std::vector<Case>{{"check", "check " + urdf + " --json"},
                                         {"inspect", "inspect --urdf " + urdf + " --tip l74 --tip l149 --json"},
                                         {"capture", "capture " + scenario + " --json --html " + page}}) {
    // As soon as the handler is there: the command is loading the robot (0.2 s to 0.9 s of work).
    const Stopped s = interruptAfter(c.args, 0.0);
    if (s.latency == 0.0 && WIFEXITED(s.status) && WEXITSTATUS(s.status) == 0) {
      ADD_FAILURE() << c.what << " finished before the signal: make the robot larger";
      continue;
    }
    expectInterrupted(s, c.what);
    EXPECT_LT(s.latency, 1.0) << c.what;
  }
  EXPECT_FALSE(fs::exists(page));
  for (const auto& entry : fs::directory_iterator(fs::path(page).parent_path()))
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << "left: " << entry.path();
}

}  // namespace
}  // namespace kdl_space::test
