// Inputs found by the fuzzers (tools/fuzz.sh) that once misbehaved, kept as regression tests.
// Every file in data/fuzz_regressions/urdf/ is a URDF that must be refused cleanly: a ModelError
// naming the file (never a crash, another exception, or a model that silently lost links).
// Each file's header comment says what went wrong. To add one: copy the crashing input there
// (shrunk with `build-fuzz/fuzz/fuzz_urdf -minimize_crash=1 -runs=10000 FILE` if large).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/parsers/urdf/urdf_check.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

std::vector<std::string> regressionFiles(const std::string& kind) {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(dataDir() + "/fuzz_regressions/" + kind))
    if (entry.is_regular_file()) files.push_back(entry.path().filename().string());
  std::sort(files.begin(), files.end());
  return files;
}

class FuzzRegressionUrdf : public ::testing::TestWithParam<std::string> {};

TEST_P(FuzzRegressionUrdf, IsRefusedWithAModelError) {
  const std::string path = dataDir() + "/fuzz_regressions/urdf/" + GetParam();
  try {
    const FloatingModel model = loadUrdfFile(path);
    ADD_FAILURE() << path << " was loaded (" << model.bodies().size() << " bodies), expected a ModelError";
  } catch (const ModelError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
  }
}

// TinyXML (under urdfdom) once read past the end of a text ending in a UTF-8 lead byte. Bytes
// after the end must not matter: here the string's own spare capacity, after the terminating
// NUL, holds a "</robot>" that would complete the document if read -- defined memory, so the
// check is exact in every build, not only under ASan.
TEST(FuzzRegression, NothingPastTheEndOfTheTextIsRead) {
  const std::string path = dataDir() + "/fuzz_regressions/urdf/utf8_lead_byte_at_end.urdf";
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  ASSERT_EQ(static_cast<unsigned char>(text.back()), 0xD7u);
  std::string dirty = text + std::string(1, '\0') + "</robot>" + std::string(1, '\0');
  dirty.resize(text.size());  // the same text; "</robot>" stays in the capacity after the NUL
  ASSERT_EQ(dirty, text);
  EXPECT_THROW(loadUrdfString(dirty, path), ModelError);
  EXPECT_THROW(loadUrdfString(text, path), ModelError);
  EXPECT_FALSE(checkUrdfString(dirty, path).errors.empty());
}

// TinyXML (under urdfdom, and under checkUrdfString) descends recursively, once per nesting
// level: 200,000 levels overflowed the stack (SIGSEGV, a 1.4 MB file). Each document below nests
// that deep for TinyXML, and the ones after the first hide their depth from a naive count of
// tags in a way TinyXML reads differently from XML; all must be refused, by both entry points,
// with the same clear error.
struct DeepDocument {
  std::string name;
  std::string head, level, tail;  ///< head + level x 200,000 + tail
  std::string why;                ///< the expected reason, after "not XML that can be read safely: "
                                  ///< ("": refused before, as bytes that are not UTF-8)
};

class FuzzRegressionDeepXml : public ::testing::TestWithParam<DeepDocument> {};

TEST_P(FuzzRegressionDeepXml, IsRefusedNotAStackOverflow) {
  const DeepDocument& d = GetParam();
  std::string xml = d.head;
  for (int i = 0; i < 200000; ++i) xml += d.level;
  xml += d.tail;
  const std::string expected = d.why.empty() ? "deep.urdf: line 2 (near `obot name=\"deep\"><a>\\xF0</a><a>\\xF0</a><a>"
                                               "\\xF0</a`): bytes that are not UTF-8; save the file as UTF-8, or "
                                               "declare its encoding (<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?>)"
                                             : "deep.urdf: not XML that can be read safely: " + d.why;
  try {
    loadUrdfString(xml, "deep.urdf");
    ADD_FAILURE() << "loaded";
  } catch (const ModelError& e) {
    EXPECT_EQ(std::string(e.what()), expected);
  }
  const UrdfReport report = checkUrdfString(xml, "deep.urdf");
  ASSERT_EQ(report.errors.size(), 1u);
  EXPECT_EQ(report.errors[0].kind, d.why.empty() ? "encoding" : "not_xml");
  EXPECT_EQ("deep.urdf: " + report.errors[0].message, expected);
}

const std::string kDeep = "elements nested more than 2000 deep (a URDF nests 4 or 5)";

INSTANTIATE_TEST_SUITE_P(
    Documents, FuzzRegressionDeepXml,
    ::testing::Values(
        DeepDocument{"Plain", "<?xml version=\"1.0\"?>\n<robot name=\"deep\">", "<a>", "</robot>\n", kDeep},
        // Ends of elements in comments: XML's and TinyXML's reading agree, the depth is real.
        DeepDocument{"ClosingTagsInComments", "<robot name=\"deep\">", "<a><!--</a>-->", "</robot>", kDeep},
        // A '/>' inside an attribute value does not close the element.
        DeepDocument{"SlashInAttribute", "<robot name=\"deep\">", "<a x=\"/>\">", "</robot>", kDeep},
        // TinyXML reads "<?xml" anywhere as a declaration, quoted values and all, and its end
        // at the first '>' after them: the "</a>" is inside the declaration for TinyXML.
        DeepDocument{"DeclarationInsideElements", "<robot name=\"deep\">", "<a><?xml version=\"x>\"</a>\"?>",
                     "</robot>",
                     "line 1: XML or text declaration not at start of entity (a file of more than 2000 elements "
                     "is read only when it is well-formed XML)"},
        // In a UTF-8 document TinyXML takes a lead byte and the next three bytes as one
        // character: "\xF0</a" is text for TinyXML, an end tag after a bad byte for XML. Such
        // bytes are no UTF-8: refused before any XML reader sees them (urdfText).
        DeepDocument{"EndTagsEatenByUtf8LeadBytes",
                     "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<robot name=\"deep\">", "<a>\xF0</a>", "</robot>", ""},
        // TinyXML ends a DOCTYPE at its first '>', inside the internal subset: the entity's
        // text becomes elements for TinyXML, an unused declaration for XML.
        DeepDocument{"ElementsInADoctype", "<!DOCTYPE robot [<!ENTITY e \"<a>", "<a>",
                     "\">]>\n<robot name=\"deep\"/>",
                     "a DOCTYPE at line 1 (a URDF needs none; TinyXML reads it differently from XML), in a file "
                     "of more than 2000 elements"},
        // TinyXML reads "<?xml-..." as a declaration too, ending at the first '>'.
        DeepDocument{"ElementsInAnInstruction", "<robot name=\"deep\"><?xml-model x=\"a>", "<a>",
                     "\"?></robot>",
                     "a processing instruction at line 1 (a URDF needs none; TinyXML reads it differently from "
                     "XML), in a file of more than 2000 elements"}),
    [](const ::testing::TestParamInfo<DeepDocument>& info) { return info.param.name; });

INSTANTIATE_TEST_SUITE_P(Inputs, FuzzRegressionUrdf, ::testing::ValuesIn(regressionFiles("urdf")),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

}  // namespace
}  // namespace kdl_space::test
