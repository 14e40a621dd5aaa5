// What a message says when an input is odd (issue 35, item 10): what is wrong, where, and what to
// do, before the work that would fail (a servo too stiff for the integrator), instead of the
// parser's or the dynamics' words ("end of map flow not found", "bad file", an armature blamed for
// an overflowing mimic multiplier), with the system's reason for a write that failed.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <string>

#include "cli_runner.hpp"

namespace kdl_space::test {
namespace {

const std::string kSource = KDL_SPACE_SOURCE_DIR;

std::string edited(const std::string& from, const std::string& name, const std::string& find, const std::string& replace) {
  std::string text = slurp(from);
  const std::size_t at = text.find(find);
  EXPECT_NE(at, std::string::npos) << find;
  if (at != std::string::npos) text.replace(at, find.size(), replace);
  const std::string path = scratchIn("kdl_space_messages", name);
  spit(path, text);
  return path;
}

TEST(Messages, AServoTooStiffForTheIntegratorIsRefusedBeforeTheRun) {
  const std::string sc = edited(kSource + "/scenarios/approach_tumbling_box.yaml", "stiff.yaml",
                                "servo_bandwidth: 20 ", "servo_bandwidth: 1.0e9 ");
  std::string text = slurp(sc);
  const std::string urdf = "../urdf/space_arm7.urdf";
  text.replace(text.find(urdf), urdf.size(), kSource + "/urdf/space_arm7.urdf");
  spit(sc, text);
  const auto start = std::chrono::steady_clock::now();
  const ToolRun r = kdlSpace("simulate " + sc);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0) << "refused at once";
  EXPECT_EQ(r.rc, 3) << r.err;
  for (const char* needle : {"approach.servo_bandwidth: 1e+09 1/s needs explicit steps below about 3e-09 s",
                             "simulation.max_steps", "integrator: rosenbrock"})
    EXPECT_NE(r.err.find(needle), std::string::npos) << needle << " in " << r.err;
}

TEST(Messages, AKeyLongerThanYamlReadsIsNamedWithItsLine) {
  const std::string path = scratchIn("kdl_space_messages", "longkey.json");
  spit(path, "{\"robot\": {\"urdf\": \"" + kSource + "/urdf/space_arm7.urdf\"},\n \"" + std::string(1100, 'k') + "\": 1}\n");
  const ToolRun r = kdlSpace("capture " + path);
  EXPECT_EQ(r.rc, 3);
  EXPECT_NE(r.err.find("a key of 1100 characters at line 2: YAML reads keys of at most 1024"), std::string::npos) << r.err;
}

TEST(Messages, NestingDeeperThanTheReaderFollowsSaysSo) {
  const std::string path = scratchIn("kdl_space_messages", "deep.yaml");
  spit(path, "robot:\n  urdf: x.urdf\nx: " + std::string(5000, '[') + "1" + std::string(5000, ']') + "\n");
  const ToolRun r = kdlSpace("capture " + path);
  EXPECT_EQ(r.rc, 3);
  EXPECT_NE(r.err.find("levels deep, deeper than the reader follows"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("bad file"), std::string::npos) << r.err;
}

TEST(Messages, AnOverflowingMimicMultiplierIsNamedNotTheArmature) {
  const std::string urdf = edited(kSource + "/tests/data/families/mimic_gripper.urdf", "mimic.urdf", "multiplier=\"1\"",
                                  "multiplier=\"1e300\"");
  for (const std::string& command : {"check " + urdf, "inspect --urdf " + urdf + " --tip base"}) {
    const ToolRun r = kdlSpace(command);
    EXPECT_NE(r.rc, 0) << command;
    EXPECT_NE((r.out + r.err).find("multiplier 1e+300 is beyond +-1e+06"), std::string::npos) << r.out << r.err;
    EXPECT_EQ((r.out + r.err).find("armature"), std::string::npos) << r.out << r.err;
  }
}

TEST(Messages, AFailedPageWriteSaysTheSystemsReason) {
  // Files of at most 32 KiB (ulimit -f 64; SIGXFSZ ignored): the page (three.js inlined) is larger.
  const std::string page = scratchIn("kdl_space_messages", "page.html");
  const std::string command = "/bin/sh -c 'trap \"\" XFSZ; ulimit -f 64 && exec " + std::string(KDL_SPACE_CLI) +
                              " capture " + kSource + "/scenarios/tumbling_box_capture.yaml --html " + page + "' 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  std::string out;
  char buffer[4096];
  while (std::size_t n = fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
  EXPECT_NE(pclose(pipe), 0);
  EXPECT_NE(out.find("--html " + page + ": cannot write the page: File too large"), std::string::npos) << out;
}

}  // namespace
}  // namespace kdl_space::test
