// The commands' fuzz target's inputs replayed (fuzz/fuzz_commands.cpp): its seeds over the model
// families (fuzz/corpus/commands/) and every input it found that once misbehaved
// (data/fuzz_regressions/commands/), each driven through the library calls behind inspect,
// capture, ik and plan (fuzz/commands_driver.hpp): every outcome a result, a code or a
// kdl_space::Error, nothing else escapes. To add a finding: copy the input the fuzzer wrote
// (build-fuzz/artifacts/commands/...) into data/fuzz_regressions/commands/ with a comment line
// saying what went wrong.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "commands_driver.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> inputs() {
  std::vector<std::string> files;
  for (const std::string dir : {std::string(KDL_SPACE_SOURCE_DIR) + "/fuzz/corpus/commands",
                                dataDir() + "/fuzz_regressions/commands"}) {
    if (!fs::is_directory(dir)) continue;
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.is_regular_file()) files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

class CommandInputs : public ::testing::TestWithParam<std::string> {};

TEST_P(CommandInputs, EveryOutcomeIsAResultACodeOrAnError) {
  // The fuzz target's layout: the input at scenarios/input.yaml, the families at ../families.
  const fs::path root = fs::path(::testing::TempDir()) / ("command_inputs_" + std::to_string(::getpid()));
  fs::create_directories(root / "scenarios");
  if (!fs::exists(root / "families")) fs::create_directory_symlink(dataDir() + "/families", root / "families");
  const fs::path input = root / "scenarios" / "input.yaml";
  fs::copy_file(GetParam(), input, fs::copy_options::overwrite_existing);
  EXPECT_NO_THROW(fuzz::driveCommands(input.string())) << GetParam();
}

std::string inputName(const ::testing::TestParamInfo<std::string>& info) {
  std::string name = fs::path(info.param).stem().string();
  std::replace_if(name.begin(), name.end(), [](char c) { return !std::isalnum(static_cast<unsigned char>(c)); }, '_');
  return name + "_" + std::to_string(info.index);
}
INSTANTIATE_TEST_SUITE_P(SeedsAndFindings, CommandInputs, ::testing::ValuesIn(inputs()), inputName);

}  // namespace
}  // namespace kdl_space::test
