// `kdl_space simulate` at any duration: the outputs' size checked before the run
// (--max-output-rows), the rows streamed to disk in bounded memory (under `ulimit -v`), a full
// disk that stops the run at once, and Ctrl-C that stops it within half a second; none of them
// leaves a partial file.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "cli_runner.hpp"

namespace kdl_space::test {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

/// A folder of its own per test (outputs, scenarios), removed at the end.
class SimulateBounded : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::path(::testing::TempDir()) /
          ("kdl_space_bounded_" + std::to_string(getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }

  std::string path(const std::string& name) const { return (dir / name).string(); }

  /// SpaceDyn's two-link arm servoed by PD joints (a plain motion): `simulation` is the rest of
  /// the scenario's simulation section.
  std::string scenario(const std::string& simulation) const {
    const std::string file = path("twolink.yaml");
    std::ofstream(file) << "robot:\n  urdf: " << KDL_SPACE_SOURCE_DIR << "/urdf/spacedyn_twolink.urdf\n"
                        << "  q: {joint1: 0.5, joint2: -1.0}\n"
                        << "simulation:\n" << simulation << "  joints:\n    \"*\": {pd: {kp: 10, kd: 5, set_point: 0}}\n";
    return file;
  }

  /// What is in the folder besides the scenario: what a run left.
  std::vector<std::string> leftovers() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.path().filename() != "twolink.yaml" && entry.path().filename() != "bin") names.push_back(entry.path().filename());
    return names;
  }

  fs::path dir;
};

using Strings = std::vector<std::string>;

/// Runs a shell command line (which starts the tool in its own way) as kdlSpace() runs the tool.
ToolRun shell(const std::string& command) {
  const std::string err_file = ::testing::TempDir() + "kdl_space_stderr_" + std::to_string(getpid()) + ".txt";
  FILE* pipe = popen(("{ " + command + "; } 2>" + err_file).c_str(), "r");
  std::string out;
  char buffer[4096];
  while (std::size_t n = fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
  const int status = pclose(pipe);
  std::ifstream e(err_file);
  const std::string err((std::istreambuf_iterator<char>(e)), std::istreambuf_iterator<char>());
  std::remove(err_file.c_str());
  return {WEXITSTATUS(status), out, err};
}

TEST_F(SimulateBounded, RunWithMoreRowsThanTheLimitIsRefusedBeforeItStarts) {
  // By hand: 100 s at 0.01 s gives 10,001 rows (t = 0, 0.01, ..., 100).
  const std::string s = scenario("  duration: 100\n  output_step: 0.01\n");
  const std::string csv = path("run.csv");
  ToolRun r = kdlSpace("simulate " + s + " --csv " + csv + " --max-output-rows 10000");
  EXPECT_EQ(r.rc, 2) << r.err;
  for (const char* needle : {"10001 output rows", "--max-output-rows 10000", "simulation.output_step", "--duration"})
    EXPECT_NE(r.err.find(needle), std::string::npos) << needle << " in " << r.err;
  EXPECT_EQ(leftovers(), Strings{});
  r = kdlSpace("simulate " + s + " --csv " + csv + " --max-output-rows 10001");
  EXPECT_EQ(r.rc, 0) << r.err;
  // The default allows 10 million rows: 1e5 s at 1e-4 s (1e9 rows) is refused at once.
  const auto start = Clock::now();
  r = kdlSpace("simulate " + scenario("  duration: 100000\n  output_step: 1.0e-4\n") + " --csv " + csv);
  EXPECT_EQ(r.rc, 2) << r.err;
  EXPECT_NE(r.err.find("1000000001 output rows"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("more than --max-output-rows 10000000"), std::string::npos) << r.err;
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - start).count(), 5.0);
}

TEST_F(SimulateBounded, AFailedWriteStopsTheRunAtOnceAndLeavesNothing) {
  // 1000 s at 1 ms would take minutes; the files may grow to 32 KiB only (`ulimit -f 64`, 512-byte
  // blocks, SIGXFSZ ignored: a write past it fails with EFBIG, as a full disk's with ENOSPC).
  const std::string s = scenario("  duration: 1000\n  output_step: 1.0e-3\n  integrator: rk4\n  step: 1.0e-3\n");
  for (const std::string option : {"--csv", "--plot"}) {
    const std::string out = path(option == "--csv" ? "run.csv" : "run.svg");
    const auto start = Clock::now();
    const ToolRun r = shell("/bin/sh -c 'trap \"\" XFSZ; ulimit -f 64 && exec " + std::string(KDL_SPACE_CLI) + " simulate " +
                            s + " " + option + " " + out + "'");
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    EXPECT_EQ(r.rc, 3) << r.err;
    EXPECT_NE(r.err.find(option + " " + out + ": cannot write"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(" rows (disk full?): File too large"), std::string::npos) << r.err;
    EXPECT_LT(elapsed, 3.0) << "the run stops at the first failed write";
    EXPECT_EQ(leftovers(), Strings{}) << option << ": the temporary is removed, no output named";
  }
}

TEST_F(SimulateBounded, ALinkPlantedAtTheTemporarysNameIsNeverFollowed) {
  // Earlier versions wrote `.NAME.tmpPID` with create+truncate: a link planted there (the shell's
  // PID is the tool's after exec) had its target overwritten. Links at that name and at every
  // name a run could have used before this one are left alone, their target untouched.
  const std::string victim = path("precious.txt");
  std::ofstream(victim) << "the user's own file\n";
  const std::string s = scenario("  duration: 1\n  output_step: 0.1\n");
  for (const std::string option : {"--csv", "--plot", "--html"}) {
    const std::string name = option == "--csv" ? "run.csv" : option == "--plot" ? "run.svg" : "run.html";
    const std::string out = path(name), link = path("." + name + ".tmp");
    const ToolRun r = shell("/bin/sh -c 'ln -s " + victim + " " + link + "$$ && ln -s " + victim + " " + link + "$$.dat && exec " +
                            KDL_SPACE_CLI + " simulate " + s + " " + option + " " + out + "'");
    EXPECT_EQ(r.rc, 0) << r.err;
    std::ifstream v(victim);
    EXPECT_EQ(std::string((std::istreambuf_iterator<char>(v)), std::istreambuf_iterator<char>()), "the user's own file\n")
        << option;
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(out))) << option << ": written, as a file of its own";
    EXPECT_GT(fs::file_size(out), 100u) << option;
    // With the mode any new file of the user's gets (not the temporary's private 0600).
    const mode_t mask = umask(0);
    umask(mask);
    EXPECT_EQ(static_cast<unsigned>(fs::status(out).permissions()), 0666u & ~static_cast<unsigned>(mask)) << option;
    for (const auto& entry : fs::directory_iterator(dir))
      if (fs::is_symlink(entry.symlink_status())) fs::remove(entry.path());
    fs::remove(out);
  }
  fs::remove(victim);
  EXPECT_EQ(leftovers(), Strings{});
}

/// Starts `command` (through sh, which `exec`s the tool: the PID is the tool's), stderr to `err`.
pid_t start(const std::string& command, const std::string& err) {
  const pid_t pid = fork();
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", ("exec " + command + " >/dev/null 2>" + err).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

TEST_F(SimulateBounded, CtrlCStopsTheRunWithinHalfASecondAndLeavesNothing) {
  // 1e5 s of motion: minutes of work, outputs every 10 s (rare); Ctrl-C after 1 s.
  const std::string s = scenario("  duration: 100000\n  output_step: 10\n  max_steps: 1.0e8\n");
  const std::string err = path("stderr.txt");
  const pid_t pid = start(std::string(KDL_SPACE_CLI) + " simulate " + s + " --csv " + path("run.csv") + " --plot " +
                              path("run.svg") + " --scene " + path("scene.svg"),
                          err);
  ASSERT_GT(pid, 0);
  // Signalled once the run is under way (its CSV's temporary exists: the first sample is written),
  // not after a fixed time: a loaded machine or a sanitizer build may still be loading at 1 s.
  // (createFreshFile's .run.csv.tmpPID-XXXXXX: it exists once the writer is made, after the set-up).
  const std::string temporary = ".run.csv.tmp" + std::to_string(pid) + "-";
  const auto started = [&] {
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.path().filename().string().rfind(temporary, 0) == 0 && entry.file_size() > 0) return true;
    return false;
  };
  for (int k = 0; k < 600 && !started(); ++k) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(started()) << "the run did not start within 60 s";
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, WNOHANG), 0) << "the run is still going";
  const auto signalled = Clock::now();
  ASSERT_EQ(kill(pid, SIGINT), 0);
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  const double latency = std::chrono::duration<double>(Clock::now() - signalled).count();
  ASSERT_TRUE(WIFEXITED(status)) << "ended by the signal itself, not by the tool";
  EXPECT_EQ(WEXITSTATUS(status), 130);
  EXPECT_LT(latency, 0.5);
  std::ifstream e(err);
  const std::string message((std::istreambuf_iterator<char>(e)), std::istreambuf_iterator<char>());
  EXPECT_NE(message.find("interrupted: " + s + ": the simulation was cancelled at t = "), std::string::npos) << message;
  EXPECT_NE(message.find(" s of 100000 s; no output written"), std::string::npos) << message;
  fs::remove(err);
  EXPECT_EQ(leftovers(), Strings{}) << "no output, no temporary";
}

TEST_F(SimulateBounded, LongRunAtAFineOutputStepStreamsToDiskInBoundedMemory) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space: ulimit -v cannot bound it";
#endif
  // 160,001 rows: held in memory (main's tool before this change, for its plot) they need more
  // than the limit (the tool alone takes 63 MB of address space; a sample about 470 B, and the
  // vector's doubling: std::bad_alloc), streamed they need a row's worth. The tool alone is bounded: gnuplot,
  // which draws every point it is given, gets its own limit back (a soft limit it may raise).
  const std::string bin = path("bin");
  fs::create_directories(bin);
  std::ofstream(bin + "/gnuplot") << "#!/bin/sh\nulimit -S -v unlimited\nexec /usr/bin/gnuplot \"$@\"\n";
  fs::permissions(bin + "/gnuplot", fs::perms::owner_all);
  const std::string s = scenario("  duration: 40\n  output_step: 2.5e-4\n  integrator: rk4\n  step: 2.5e-4\n");
  const std::string csv = path("run.csv"), plot = path("run.png");
  const ToolRun r = shell("PATH=" + bin + ":$PATH /bin/sh -c 'ulimit -S -v 200000 && exec " + KDL_SPACE_CLI + " simulate " + s +
                          " --csv " + csv + " --plot " + plot + "'");
  ASSERT_EQ(r.rc, 0) << r.err;
  std::ifstream in(csv);
  long lines = 0;
  for (std::string line; std::getline(in, line);) ++lines;
  EXPECT_EQ(lines, 1 + 160001) << "the header and every row";
  EXPECT_GT(fs::file_size(plot), 1000u);
}

}  // namespace
}  // namespace kdl_space::test
