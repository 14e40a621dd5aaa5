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

#include "kdl_space/errors.hpp"
#include "kdl_space/urdf_check.hpp"
#include "kdl_space/urdf_loader.hpp"
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

// Known, not fixed yet (found next to the fuzzers' findings, beyond fuzz_urdf's -max_len):
// loadUrdfString hands any nesting depth to TinyXML, whose recursive descent overflows the stack
// (SIGSEGV here at 200,000 levels, a 1.4 MB file); checkUrdfString refuses more than 2,000
// levels before parsing. Enable when the loader applies the same limit.
TEST(FuzzRegression, DISABLED_DeeplyNestedXmlIsRefusedNotAStackOverflow) {
  const int levels = 200000;
  std::string xml = "<?xml version=\"1.0\"?>\n<robot name=\"deep\">";
  for (int i = 0; i < levels; ++i) xml += "<a>";
  for (int i = 0; i < levels; ++i) xml += "</a>";
  xml += "</robot>\n";
  EXPECT_THROW(loadUrdfString(xml, "deep.urdf"), ModelError);
}

INSTANTIATE_TEST_SUITE_P(Inputs, FuzzRegressionUrdf, ::testing::ValuesIn(regressionFiles("urdf")),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

}  // namespace
}  // namespace kdl_space::test
