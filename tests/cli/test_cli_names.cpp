// Any bytes in a name, end to end (issue 35, items 5 and 9): a URDF in ISO-8859-1 that says so is
// read by every command, its names written in UTF-8 to the JSON, the CSV and the terminal; names
// with bytes that are not UTF-8 or with control characters are refused at load naming the line;
// and whatever the tool prints (a path given on the command line included) reaches the terminal
// without ESC or BEL.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <string>

#include "cli_runner.hpp"

namespace kdl_space::test {
namespace {

const std::string kArm = std::string(KDL_SPACE_SOURCE_DIR) + "/urdf/space_arm7.urdf";

/// The shipped arm with joint3 renamed to `name` (bytes as given) after `declaration`, written
/// to `file` in this test's folder; its path.
std::string armWith(const std::string& file, const std::string& declaration, const std::string& name) {
  std::string xml = slurp(kArm);
  if (xml.rfind("<?xml", 0) == 0) xml.erase(0, xml.find("?>") + 2);
  for (std::size_t at = xml.find("\"joint3\""); at != std::string::npos; at = xml.find("\"joint3\"", at))
    xml.replace(at, 8, "\"" + name + "\"");
  const std::string path = scratchIn("kdl_space_names", file);
  spit(path, declaration + xml);
  return path;
}

bool hasControlBytes(const std::string& text) {
  for (const char c : text)
    if ((static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t' && c != '\r') || c == 0x7f) return true;
  return false;
}

TEST(Names, AnIso88591UrdfIsReadByEveryCommandAndWrittenInUtf8) {
  const std::string urdf = armWith("latin1.urdf", R"(<?xml version="1.0" encoding="ISO-8859-1"?>)", "Handgelenk_\xE4");
  const std::string utf8 = "Handgelenk_\xC3\xA4";
  ToolRun r = kdlSpace("check " + urdf + " --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("read as ISO-8859-1"), std::string::npos) << r.out;
  r = kdlSpace("inspect --urdf " + urdf + " --tip end_effector --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);  // throws on bytes that are not UTF-8
  EXPECT_NE(j.dump().find(utf8), std::string::npos);
  r = kdlSpace("inspect --urdf " + urdf + " --tip end_effector");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find(utf8), std::string::npos) << r.out;
}

TEST(Names, BytesThatAreNotUtf8AreRefusedAtLoadWithTheFileAndLine) {
  const std::string urdf = armWith("undeclared.urdf", "", "Handgelenk_\xE4");
  for (const std::string& command : {"check " + urdf, "inspect --urdf " + urdf + " --tip end_effector"}) {
    const ToolRun r = kdlSpace(command);
    EXPECT_NE(r.rc, 0) << command;
    EXPECT_NE((r.out + r.err).find(urdf + ": error: line 48 (near "), std::string::npos) << r.out << r.err;
    EXPECT_NE((r.out + r.err).find("Handgelenk_\\xE4"), std::string::npos) << r.out << r.err;
    EXPECT_NE((r.out + r.err).find("not UTF-8"), std::string::npos) << r.out << r.err;
  }
}

TEST(Names, ControlCharactersInANameAreRefusedAndNeverReachTheTerminal) {
  for (const std::string& name : {std::string("joint\x1b[2J"), std::string("bell\x07"), std::string("esc&#27;[31m")}) {
    const std::string urdf = armWith("control.urdf", "", name);
    for (const std::string& command : {"check " + urdf, "check " + urdf + " --json",
                                       "inspect --urdf " + urdf + " --tip end_effector"}) {
      const ToolRun r = kdlSpace(command);
      EXPECT_NE(r.rc, 0) << command;
      EXPECT_NE((r.out + r.err).find("control character U+00"), std::string::npos) << r.out << r.err;
      EXPECT_FALSE(hasControlBytes(r.out + r.err)) << command << ": " << r.out << r.err;
    }
  }
}

TEST(Names, WhatTheToolPrintsHoldsNoControlBytesWhateverTheInput) {
  // A path given on the command line (a file that does not exist) is echoed in the message.
  const std::string path = "'/nonexistent/robot\x1b[31m\x07.urdf'";
  for (const std::string& command : {"check " + path, "inspect --urdf " + path + " --tip x", "check " + path + " --json"}) {
    const ToolRun r = kdlSpace(command);
    EXPECT_NE(r.rc, 0) << command;
    EXPECT_FALSE(hasControlBytes(r.out + r.err)) << command << ": " << r.out << r.err;
    EXPECT_NE((r.out + r.err).find("robot"), std::string::npos) << r.out << r.err;
  }
}

}  // namespace
}  // namespace kdl_space::test
