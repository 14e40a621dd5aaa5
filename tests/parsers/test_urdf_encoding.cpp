// Any bytes in a name (issue 35, items 5 and 9): an ISO-8859-1 file that says so is read (its
// names converted to UTF-8, a note says what was assumed); bytes that are not UTF-8 and control
// characters (raw or as &#27;) are refused at load, by the loader, the checker and the visuals'
// reader alike, with the file, the line and the text around them.
#include <gtest/gtest.h>

#include <string>

#include "kdl_space/parsers/urdf/urdf_check.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "kdl_space/parsers/urdf/urdf_visuals.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space::test {
namespace {

/// A base and one arm link on a revolute joint named `joint` (bytes as given), after `declaration`.
std::string robot(const std::string& declaration, const std::string& joint) {
  return declaration + R"(
<robot name="r">
  <link name="base"><inertial><mass value="10"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name=")" + joint + R"(" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>)";
}

const std::string kLatin1 = R"(<?xml version="1.0" encoding="ISO-8859-1"?>)";

/// The loader's message for `xml` ("" when it loads).
std::string refusal(const std::string& xml) {
  try {
    loadUrdfString(xml, "robot.urdf");
    return "";
  } catch (const ModelError& e) {
    return e.what();
  }
}

TEST(UrdfEncoding, AnIso88591FileThatSaysSoIsReadInUtf8AndSaysWhatWasAssumed) {
  const std::string xml = robot(kLatin1, "Handgelenk_\xE4");  // ä in ISO-8859-1: one byte
  const FloatingModel model = loadUrdfString(xml, "robot.urdf");
  ASSERT_EQ(model.jointNames().size(), 1u);
  EXPECT_EQ(model.jointNames()[0], "Handgelenk_\xC3\xA4");  // ä in UTF-8
  bool noted = false;
  for (const Diagnostic& d : model.diagnostics()) noted |= d.kind == "encoding" && d.message.find("ISO-8859-1") != std::string::npos;
  EXPECT_TRUE(noted);
  const UrdfReport report = checkUrdfString(xml, "robot.urdf", {});
  EXPECT_TRUE(report.errors.empty()) << report.errors.front().message;
  ASSERT_FALSE(report.notes.empty());
  EXPECT_EQ(report.notes.front().kind, "encoding");
  EXPECT_EQ(readUrdfVisualsString(xml, "robot.urdf").size(), 0u);  // read, no visuals
  // The declared name in any case, and latin1, read the same.
  EXPECT_EQ(loadUrdfString(robot(R"(<?xml version='1.0' encoding='latin1'?>)", "Gelenk_\xFC"), "r.urdf").jointNames()[0],
            "Gelenk_\xC3\xBC");
}

TEST(UrdfEncoding, Utf8NamesAreKeptAsTheyAre) {
  for (const std::string& name : {std::string("Gelenk_\xC3\xBC"), std::string("\xE9\x96\xA2\xE7\xAF\x80"),  // 関節
                                  std::string("joint_\xF0\x9F\xA6\xBE")}) {                                 // 🦾
    EXPECT_EQ(loadUrdfString(robot("", name), "r.urdf").jointNames()[0], name);
    EXPECT_EQ(loadUrdfString(robot(R"(<?xml version="1.0" encoding="UTF-8"?>)", name), "r.urdf").jointNames()[0], name);
  }
}

TEST(UrdfEncoding, BytesThatAreNotUtf8AreRefusedWithTheFileTheLineAndTheName) {
  const std::string why = refusal(robot("", "Handgelenk_\xE4"));
  EXPECT_NE(why.find("robot.urdf: line 5"), std::string::npos) << why;
  EXPECT_NE(why.find("Handgelenk_\\xE4"), std::string::npos) << why;
  EXPECT_NE(why.find("not UTF-8"), std::string::npos) << why;
  EXPECT_NE(why.find("encoding=\"ISO-8859-1\""), std::string::npos) << "says what to do: " << why;
  const UrdfReport report = checkUrdfString(robot("", "Handgelenk_\xE4"), "robot.urdf", {});
  ASSERT_EQ(report.errors.size(), 1u);
  EXPECT_EQ(report.errors[0].kind, "encoding");
  EXPECT_NE(report.errors[0].message.find("line 5"), std::string::npos);
  EXPECT_THROW(readUrdfVisualsString(robot("", "Handgelenk_\xE4"), "robot.urdf"), ModelError);
  // Overlong forms, surrogates and a cut sequence are no UTF-8 either.
  for (const char* bytes : {"\xC0\xAF", "\xED\xA0\x80", "\xE9\x96", "\xF8\x88\x80\x80\x80"})
    EXPECT_NE(refusal(robot("", std::string("j") + bytes)).find("not UTF-8"), std::string::npos) << bytes;
  // Another declared encoding: refused, with the command that converts it.
  const std::string other = refusal(robot(R"(<?xml version="1.0" encoding="windows-1252"?>)", "j"));
  EXPECT_NE(other.find("'windows-1252'"), std::string::npos) << other;
  EXPECT_NE(other.find("iconv -f windows-1252 -t UTF-8"), std::string::npos) << other;
}

TEST(UrdfEncoding, ControlCharactersRawOrReferencedAreRefused) {
  struct Case {
    std::string name, code;
  };
  for (const Case& c : std::vector<Case>{{"red\x1b[31m", "U+001B"},
                                         {"bell\x07", "U+0007"},
                                         {"esc&#27;x", "U+001B"},
                                         {"bel&#x7;x", "U+0007"},
                                         {"csi\xC2\x9B", "U+009B"},
                                         {"csi&#155;", "U+009B"},
                                         {"del\x7F", "U+007F"}}) {
    const std::string why = refusal(robot("", c.name));
    EXPECT_NE(why.find("robot.urdf: line 5"), std::string::npos) << why;
    EXPECT_NE(why.find("control character " + c.code), std::string::npos) << c.code << ": " << why;
    EXPECT_EQ(why.find('\x1b'), std::string::npos) << "the message itself holds no ESC";
    EXPECT_EQ(checkUrdfString(robot("", c.name), "robot.urdf", {}).errors.at(0).kind, "encoding");
  }
  // Tab, line feed and carriage return are text: a file written on Windows loads.
  std::string windows = robot("", "j");
  for (std::size_t at = windows.find('\n'); at != std::string::npos; at = windows.find('\n', at + 2)) windows.insert(at, "\r");
  EXPECT_EQ(refusal(windows), "");
}

}  // namespace
}  // namespace kdl_space::test
