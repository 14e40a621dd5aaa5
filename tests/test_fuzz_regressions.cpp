// Inputs found by the fuzzers (tools/fuzz.sh) that once misbehaved, kept as regression tests.
// Every file in data/fuzz_regressions/urdf/ is a URDF that must be refused cleanly: a ModelError
// naming the file (never a crash, another exception, or a model that silently lost links).
// Each file's header comment says what went wrong. To add one: copy the crashing input there
// (shrunk with `build-fuzz/fuzz/fuzz_urdf -minimize_crash=1 -runs=10000 FILE` if large).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>
#include <vector>

#include "kdl_space/errors.hpp"
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

INSTANTIATE_TEST_SUITE_P(Inputs, FuzzRegressionUrdf, ::testing::ValuesIn(regressionFiles("urdf")),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

}  // namespace
}  // namespace kdl_space::test
